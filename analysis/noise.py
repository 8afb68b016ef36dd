"""The noise of a spring-force trace: its standard deviation and decorrelation lag from
the trace's own local differences (:func:`noise_level`), the scale of its increments at
the noise's own time scale (:func:`increment_noise`), and what does not repeat from one
stick-slip cycle to the next (:func:`cycle_noise`).

Both serve the slip detector (:func:`filmfriction.analysis.stickslip.detect_slips`),
whose threshold they set, and the error bars of the yield and re-stick points
(:mod:`filmfriction.analysis.extrema`).  Nothing here depends on the unit system.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["noise_level", "noise_correlation", "cycle_noise", "increment_noise",
           "NOISE_QUANTILE", "CYCLE_NOISE_FACTOR"]

# s(2L)/s(L) beyond what stationary noise gives to second differences (at most 4, for a
# smooth process): the windows at 2L straddle slips
STRADDLE_RATIO = 4.5
# the same for fourth differences, which grow as L⁴ (16 per doubling) on a smooth curve;
# white noise gives 1, AR(1) noise about √2, an MD wall's thermal motion 2-4
STRADDLE_RATIO_SMOOTH = 8.0
# fourth differences below this share of the second differences at lag 1: the trace is
# smooth at its sampling (a noise-free slip), not noisy
SMOOTH_RATIO = 0.25
# second differences of AR(1) noise grow by at most √2 per doubling of the lag (a random
# walk's); beyond this the trace's curvature has entered s(L)
CURVATURE_GROWTH = 2.0


def _chord_residuals(t, f, lag):
    """Residuals of f[i] from the straight line through f[i − lag] and f[i + lag], scaled
    to the noise's standard deviation: zero on a straight ramp however it is sampled,
    ∝ lag² on a smooth curve, of standard deviation σ for white noise σ."""
    t0, t1, t2 = t[:-2 * lag], t[lag:-lag], t[2 * lag:]
    w = (t1 - t0) / (t2 - t0)
    r = f[lag:-lag] - (1.0 - w) * f[:-2 * lag] - w * f[2 * lag:]
    return r / np.sqrt(1.0 + w ** 2 + (1.0 - w) ** 2)


def _line_residuals(t, f, lag):
    """Residuals of f[i] from the cubic through f[i − 2 lag], f[i − lag], f[i + lag] and
    f[i + 2 lag], scaled to the noise's standard deviation: zero on a straight ramp
    however it is sampled, ∝ lag⁴ on a smooth curve, of standard deviation σ for
    white noise σ (uniform sampling or not)."""
    n = t.size
    c = slice(2 * lag, n - 2 * lag)
    if c.stop - c.start <= 0:
        return np.empty(0)
    nodes = [slice(0, n - 4 * lag), slice(lag, n - 3 * lag), slice(3 * lag, n - lag),
             slice(4 * lag, n)]
    x = t[c]
    r = f[c].copy()
    norm = np.ones_like(x)
    for j, sj in enumerate(nodes):
        w = np.ones_like(x)
        for k, sk in enumerate(nodes):
            if k != j:
                w *= (x - t[sk]) / (t[sj] - t[sk])
        r -= w * f[sj]
        norm += w * w
    return r / np.sqrt(norm)


#: the quantile of |residual| the noise is read from (see :func:`noise_level`)
NOISE_QUANTILE = 0.25
# 0.25 quantile of |N(0, 1)|
_Q_NORMAL = 0.31863936396437514


def noise_level(spring_force, *, max_lag: int | None = None,
                plateau: float = 1.15, time=None) -> tuple[float, int]:
    """Robust standard deviation of the fluctuations of a trace.

    Uses the residual of each sample from the straight line through its
    neighbours at lag L (a second difference, weighted by the sample times when
    they are not uniform), which vanishes on straight stick ramps of any slope.
    s(L) is read from the lower quartile of |residual| (``NOISE_QUANTILE``,
    scaled to a Gaussian's σ): the curved slips, however much of the trace they
    take, give the large residuals, and the straight ramps, as long as they are
    a quarter of the trace, set the quartile.  For white noise s(L) = σ at every
    L; for correlated (thermal) noise s(L) grows with L until L exceeds the
    correlation time.  The estimate is s(2L) at the first lag with
    s(2L)/s(L) < ``plateau``.  A ratio above 4.5 (``STRADDLE_RATIO``) stops the
    search at s(L): no stationary noise grows that fast (a smooth process at
    most as L², 4×), so at 2L most windows straddle a slip or its ringing.

    A trace that is smooth at its sampling (a noise-free slip sampled finely, or
    by the model's own output with a handful of samples per stick) has fourth
    differences (the residual from the cubic through the neighbours at ±L and
    ±2L) far below its second differences at lag 1 (below ``SMOOTH_RATIO``):
    its second differences are the slip's curvature, not noise.  The same search
    then runs on the fourth differences, which grow as L⁴ on a smooth curve
    (stop above ``STRADDLE_RATIO_SMOOTH`` = 8× per doubling; s(L) is then an
    upper bound of the noise).

    Parameters
    ----------
    spring_force : array_like
    max_lag : int, optional
        Largest lag tried (default N/20).
    plateau : float
    time : array_like, optional
        Sample times (default: uniform).

    Returns
    -------
    sigma : float
        Noise standard deviation (0 for a noise-free piecewise-linear trace).
    lag : int
        Decorrelation lag in samples (1 for white noise).
    """
    sigma, lag, _ = noise_level_and_bound(spring_force, max_lag=max_lag, plateau=plateau, time=time)
    return sigma, lag


def noise_level_and_bound(spring_force, *, max_lag=None, plateau=1.15, time=None):
    """:func:`noise_level`, and whether the estimate is only a lower bound of correlated
    noise: the trace is smooth at its sampling (the fourth differences' search), or
    the search reached its longest lag with s(L) still growing."""
    f = np.asarray(spring_force, float)
    n = f.size
    if n < 9:
        return 0.0, 1, False
    t = np.arange(n, dtype=float) if time is None else np.asarray(time, float)

    def s(lag, residuals):
        return _residual_scale(t, f, lag, residuals)

    max_lag = max(1, n // 20) if max_lag is None else max_lag
    residuals = _lag_one_residuals(t, f)
    smooth = residuals is _line_residuals
    straddle = STRADDLE_RATIO_SMOOTH if smooth else STRADDLE_RATIO
    lag, prev = 1, s(1, residuals)
    scales = {1: prev}
    result = None
    while 2 * lag <= max_lag and 8 * lag < n:
        cur = s(2 * lag, residuals)
        scales[2 * lag] = cur
        if prev == 0.0 or cur < plateau * prev:
            result = (cur if prev else 0.0), lag, smooth
            break
        if cur > straddle * prev:
            result = prev, lag, smooth
            break
        if not smooth and cur > CURVATURE_GROWTH * prev:
            # faster than any AR(1) noise grows (a random walk's √2): the trace's own
            # curvature (a creeping stick, a slip's turn) has entered, and s(L) is a
            # lower bound of noise correlated over longer lags
            result = prev, lag, True
            break
        lag, prev = 2 * lag, cur
    if result is None:
        # the search ended at its longest lag still growing: the noise is correlated over
        # longer than the estimate sees (a lower bound, as on a smooth trace)
        result = prev, lag, True
    if smooth:
        return result
    ar1 = _ar1_plateau(scales)
    if ar1 is not None and ar1[0] < result[0]:
        return ar1[0], ar1[1], result[2]
    return result


#: the growth of s(L) per doubling of L that AR(1) noise of any coefficient stays
#: below (√2, a random walk's), with room for the quartiles' own scatter
AR1_GROWTH_MAX = 1.5


def _ar1_scale2(rho_l):
    """s(L)²/σ² of the second differences for AR(1) noise whose correlation at lag L
    is ``rho_l`` (see :func:`noise_correlation`)."""
    return (1.0 - rho_l) * (3.0 - rho_l) / 3.0


def _ar1_plateau(scales):
    """σ and the decorrelation lag of AR(1) noise fitted to s(L) at the lags before the
    trace's curvature enters (each doubling grows s by less than ``AR1_GROWTH_MAX``),
    or None when fewer than three lags qualify or the fit does not converge."""
    lags = sorted(scales)
    keep = [lags[0]]
    for a, b in zip(lags, lags[1:]):
        if not (scales[a] > 0.0 and scales[b] < AR1_GROWTH_MAX * scales[a]):
            break
        keep.append(b)
    if len(keep) < 3:
        return None
    L = np.asarray(keep, float)
    y = np.log([scales[k] for k in keep])
    best = None
    for rho in np.linspace(0.0, 0.99, 199):
        g = 0.5 * np.log(_ar1_scale2(rho ** L))
        log_sigma = float(np.mean(y - g))
        rss = float(np.sum((y - g - log_sigma) ** 2))
        if best is None or rss < best[0]:
            best = (rss, rho, log_sigma)
    _, rho, log_sigma = best
    lag = 1
    while rho ** lag > 0.2 and lag < keep[-1]:
        lag *= 2
    return math.exp(log_sigma), lag


def _residual_scale(t, f, lag, residuals):
    """s(L): the lower quartile of |residual| at lag L, scaled to a Gaussian's σ."""
    r = np.abs(residuals(t, f, lag))
    return float(np.quantile(r, NOISE_QUANTILE)) / _Q_NORMAL if r.size else 0.0


def _lag_one_residuals(t, f):
    """The residuals the noise is read from: the fourth differences' on a trace whose
    second differences at lag 1 are mostly a smooth curve's (a slip sampled finely, or
    by the model's own output: its fourth differences are far below them), else the
    second differences'."""
    smooth = (_residual_scale(t, f, 1, _line_residuals)
              < SMOOTH_RATIO * _residual_scale(t, f, 1, _chord_residuals))
    return _line_residuals if smooth else _chord_residuals


def noise_correlation(spring_force, sigma: float, *, time=None) -> float:
    """The noise's correlation from one sample to the next, as an AR(1) coefficient ρ.

    AR(1) noise of standard deviation σ and coefficient ρ gives the residuals of
    :func:`noise_level` at lag 1 a scale s(1) below σ: the neighbours it is compared
    with share part of its noise.  For the second differences (uniform sampling)
    s(1)²/σ² = (1 − ρ)(3 − ρ)/3, so ρ = 2 − √(1 + 3 s(1)²/σ²); for the fourth
    differences (a trace smooth at its sampling) the same relation is solved
    numerically.  White noise gives 0; ρ is at most 0.99.  Noise that is not AR(1)
    (an MD wall's thermal vibration) gets the AR(1) with its lag-1 correlation.

    Parameters
    ----------
    spring_force : array_like
    sigma : float
        The noise's standard deviation (:func:`noise_level`).
    time : array_like, optional

    Returns
    -------
    float

    Examples
    --------
    >>> from scipy.signal import lfilter
    >>> e = np.random.default_rng(2).normal(0.0, 1.0, 20000)
    >>> round(noise_correlation(e, 1.0), 1)
    0.0
    >>> ar = lfilter([1.0], [1.0, -0.9], e) * np.sqrt(1 - 0.81)
    >>> round(noise_correlation(ar, 1.0), 1)
    0.9
    """
    f = np.asarray(spring_force, float)
    if not sigma > 0.0 or f.size < 9:
        return 0.0
    t = np.arange(f.size, dtype=float) if time is None else np.asarray(time, float)
    residuals = _lag_one_residuals(t, f)
    ratio2 = min((_residual_scale(t, f, 1, residuals) / float(sigma)) ** 2, 1.0)
    if residuals is _chord_residuals:
        rho = 2.0 - math.sqrt(1.0 + 3.0 * ratio2)
    else:
        # the cubic through the neighbours at ±1, ±2 at the centre: weights (−1, 4, 4, −1)/6
        c = np.array([1.0, -4.0, 6.0, -4.0, 1.0]) / 6.0
        lags = np.abs(np.subtract.outer(np.arange(5), np.arange(5)))

        def share(r):
            return float(c @ (r ** lags) @ c) / float(c @ c) - ratio2
        from scipy.optimize import brentq
        rho = brentq(share, 0.0, 0.999999) if share(0.0) > 0.0 > share(0.999999) else (
            0.0 if share(0.0) <= 0.0 else 1.0)
    return min(max(rho, 0.0), 0.99)


#: the cycle-to-cycle noise sets the threshold where it exceeds the local noise
#: estimate by more than this factor (it also holds the slips' own cycle-to-cycle
#: variation, so it is an upper estimate of the noise: within the factor the two agree)
CYCLE_NOISE_FACTOR = 2.0


def cycle_noise(time, spring_force, yield_index) -> float:
    """Robust standard deviation of what does not repeat from one cycle to the next.

    The trace is compared with itself one period P later (P the median time
    between the yields, adjusted within ±2 sample spacings to the shift that
    aligns the cycles best; the later trace interpolated linearly at t + P):
    d(t) = f(t + P) − f(t), less its median within each stretch where neither f(t)
    nor f(t + P) passes a yield (the force levels a cycle starts from: a drift, or an
    irregular stick-slip's scattered re-stick forces, whose cycles repeat in shape from
    different offsets; stretches shorter than 8 samples are left out).  A
    periodic trace of any shape, however smooth or coarsely sampled, repeats
    (d ≈ 0); noise does not, white or correlated over any time shorter than
    P, and neither does a trace that only fluctuates (a stuck wall's thermal
    vibration, sampled so finely that it is smooth at its sampling and the
    local estimate of :func:`noise_level` sees no noise).  The scale is read
    from the lower quartile of |d| as in :func:`noise_level` (the slips, where
    cycles differ in timing, give the large |d|), each d scaled by its
    variance for white noise of standard deviation σ (1 + w² + (1 − w)², w the
    interpolation weight), so that white noise gives σ; correlated noise gives
    up to 15 % more.

    Parameters
    ----------
    time, spring_force : array_like
    yield_index : array_like of int
        The yields (at least 2; else 0 is returned).

    Returns
    -------
    float

    Examples
    --------
    >>> t = np.arange(0.0, 40.0, 0.05)
    >>> saw = t % 5.0
    >>> round(cycle_noise(t, saw, np.flatnonzero(np.diff(saw) < 0)), 12)
    0.0
    >>> noisy = saw + np.random.default_rng(1).normal(0, 0.1, t.size)
    >>> round(cycle_noise(t, noisy, np.flatnonzero(np.diff(saw) < 0)), 1)
    0.1
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    yi = np.asarray(yield_index, np.int64)
    if yi.size < 2:
        return 0.0
    period = float(np.median(np.diff(t[yi])))
    if period <= 0.0 or np.count_nonzero(t + period <= t[-1]) < 8:
        return 0.0
    # the period of a noisy trace's yields is uncertain by a few samples: the shift
    # that aligns the cycles best, within two median sample spacings
    step = float(np.median(np.diff(t)))
    if np.all(np.abs(np.diff(t) - step) <= 1e-4 * step):
        # uniform sampling: shifts of whole and half sample spacings on the sample grid,
        # whatever the last digits of the times (a unit's rounding must not move them)
        k = round(2.0 * period / step) / 2.0
        idx = np.arange(f.size, dtype=float)
        best = min(_unrepeated(idx, f, k + s, yi) for s in np.linspace(-2.0, 2.0, 9)
                   if k + s > 0)
    else:
        shifts = period + step * np.linspace(-2.0, 2.0, 9)
        best = min(_unrepeated(t, f, p, t[yi]) for p in shifts if p > 0.0)
    return best if math.isfinite(best) else 0.0


def _unrepeated(t, f, period, yields=None):
    """The scale of f(t + period) − f(t) (see :func:`cycle_noise`); inf when fewer
    than 8 samples overlap.  With ``yields`` (times on the axis of ``t``), d less its
    median within each stretch where neither f(t) nor f(t + period) passes a yield:
    cycles that repeat in shape but start from different force levels (an irregular
    stick-slip's re-stick forces) are offsets there, not noise."""
    # a sample whose shifted time lands on the last one (a period of whole sample
    # spacings) is in, however the times round in the trace's unit
    ok = t + period <= t[-1] + 1e-6 * (t[-1] - t[0]) / max(t.size - 1, 1)
    if np.count_nonzero(ok) < 8:
        return math.inf
    x = t[ok] + period
    j = np.clip(np.searchsorted(t, x), 1, t.size - 1)
    w = (x - t[j - 1]) / (t[j] - t[j - 1])
    d = ((1.0 - w) * f[j - 1] + w * f[j] - f[ok]) / np.sqrt(1.0 + w * w + (1.0 - w) ** 2)
    d = d - np.median(d)
    if yields is not None and len(yields) >= 2:
        ty = np.asarray(yields, float)
        key = np.searchsorted(ty, t[ok]) * (ty.size + 1) + np.searchsorted(ty, x)
        _, group, size = np.unique(key, return_inverse=True, return_counts=True)
        # stretches of 8 samples or more (shorter ones: the slips' edges, left out);
        # each residual scaled for the median it lost, (1 - 1/n) of the variance
        big = size[group] >= 8
        if np.count_nonzero(big) >= 8:
            # each stretch's median at once: d sorted within stretches, its middle values
            ds = d[np.lexsort((d, group))]
            start = np.cumsum(size) - size
            med = 0.5 * (ds[start + (size - 1) // 2] + ds[start + size // 2])
            d = (d - med[group])[big] / np.sqrt(1.0 - 1.0 / size[group][big])
    return float(np.quantile(np.abs(d), NOISE_QUANTILE)) / _Q_NORMAL



#: the increments' scale has stopped growing (the noise has decorrelated, or an oscillating
#: noise has passed half its period) when a doubling of the lag grows it by less than this
INCREMENT_PLATEAU = 1.15
#: a doubling of the lag that grows the increments' scale by more than this has let the
#: slips into the windows: smooth noise grows at most as the lag (2× per doubling)
INCREMENT_JUMP = 2.5


def increment_noise(spring_force, *, max_lag: int | None = None) -> tuple[float, int]:
    """The noise's scale at its own time scale, from the trace's increments: (scale, lag).

    s(L) is the robust scale of f[i + L] − f[i] about its median, over √2 (read from the
    lower quartile of the absolute values as in :func:`noise_level`): the loading ramp
    adds the same K·V·L to every increment in a stick, and the median takes it out; the
    slips, a minority of the windows while L is short against the sticks, give the large
    ones, which the quartile leaves out.  For white noise s(L) = σ at every L; correlated
    noise grows it until L passes its decorrelation time; an oscillating one (a wall
    ringing on the film) until half its period, where its increments are largest.  The
    lag is doubled from 1 until a doubling grows s by less than ``INCREMENT_PLATEAU``
    (the scale is s(L) there) or by more than ``INCREMENT_JUMP`` (the slips have entered
    the windows: s(L) before the jump), at most to ``max_lag`` (default N/20).

    It needs no slips to be found first, so it cannot be biased by slips that were missed:
    it is the noise estimate of :func:`~filmfriction.analysis.stickslip.detect_slips` where
    the local one is blind (a trace sampled so finely that it is smooth at its sampling).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> white = rng.normal(0.0, 0.5, 20000)
    >>> round(increment_noise(white)[0], 1)
    0.5
    >>> ramp = 0.01 * np.arange(20000) + white            # a loading ramp changes nothing
    >>> round(increment_noise(ramp)[0], 1)
    0.5
    """
    f = np.asarray(spring_force, float)
    n = f.size
    if n < 8:
        return 0.0, 1
    max_lag = max(1, n // 20) if max_lag is None else int(max_lag)

    def scale(lag):
        d = f[lag:] - f[:-lag]
        d = np.abs(d - np.median(d))
        return float(np.quantile(d, NOISE_QUANTILE)) / _Q_NORMAL / math.sqrt(2.0)

    lag, prev = 1, scale(1)
    while 2 * lag <= max_lag:
        cur = scale(2 * lag)
        if cur < INCREMENT_PLATEAU * prev or (prev > 0.0 and cur > INCREMENT_JUMP * prev):
            break
        lag, prev = 2 * lag, cur
    return prev, lag
