"""Stick-slip events in a spring-force trace, in Klein's notation.

A driven spring (constant K, far end moving at V) pulls a wall across a
confined film.  During *stick* the spring force rises; at the *yield point*
``y`` the film shear-melts and the wall slips, the force drops, and at the
*re-stick point* ``s`` the film solidifies and the force rises again.

Per cycle (Klein, seed 004): static force Fs = K x0 at y, backward force Fb
at s, spring extension at yield x0, slip distance Δx0, slip duration τ_s
(y → s), stick duration (s → next y) and period τ_ss (y → next y).

Event detection (:func:`detect_slips`) is a hysteresis ("zig-zag") detector:
a yield is a running maximum of the force that is followed by a drop of more
than ``h`` before any higher value; the re-stick is the running minimum after
it that is followed by a rise of more than ``h``.  ``h`` is set from a robust
estimate of the noise so that a stationary noisy trace gives no events (see
:func:`detect_slips`).  The regime criterion is in :func:`classify_regime`.

The same functions serve MD traces (LJ units), SFB traces (SI) and
reduced-model traces: nothing here depends on the unit system.
"""
from __future__ import annotations

import enum
import math
from dataclasses import dataclass, replace

import numpy as np

from filmfriction.reduced_model.cycles import CycleTable, cycle_table, stats

__all__ = ["Regime", "sliding_steadily", "STEADY_VELOCITY_TOLERANCE", "CycleTable", "SlipEvents",
           "StickStiffness", "stick_stiffness", "cycle_table", "detect_slips",
           "noise_level", "cycle_noise", "classify_regime", "ramp_forces", "refine_extrema", "REGIME_CV_MAX"]

class Regime(enum.StrEnum):
    """The sliding regime of a run (the one rule: :func:`classify_regime`, then the
    analysis' check for a wall that does not slide, :func:`filmfriction.analysis.analyze.analyze`).

    A member is its string (``Regime.STICK_SLIP == "stick-slip"``), as written in
    ``analysis.json``.
    """

    STICK_SLIP = "stick-slip"  #: >= 2 slips, regular (CV of Fs and period <= REGIME_CV_MAX)
    IRREGULAR = "irregular"    #: >= 2 slips that fail the regularity test
    SMOOTH = "smooth"          #: < 2 slips and the wall slides steadily
    UNRESOLVED = "unresolved"  #: < 2 slips without steady sliding: stuck, or too short to tell


#: Steady sliding: the wall's mean velocity within this fraction of the drive's.
STEADY_VELOCITY_TOLERANCE = 0.2


def sliding_steadily(wall_velocity_ratio: float) -> bool:
    """Whether a wall moving at ``wall_velocity_ratio`` × V slides steadily (the one rule
    that tells a ``smooth`` run from an ``unresolved`` one: a stuck wall has no slips either).

    >>> sliding_steadily(0.95), sliding_steadily(0.3)
    (True, False)
    """
    return abs(float(wall_velocity_ratio) - 1.0) <= STEADY_VELOCITY_TOLERANCE


#: Largest coefficient of variation of Fs and of the period still called
#: periodic ``stick-slip`` (see :func:`classify_regime`).
REGIME_CV_MAX = 0.2

# --------------------------------------------------------------------------
# event detection
# --------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class SlipEvents:
    """Slips found by :func:`detect_slips`.

    Attributes
    ----------
    yield_index, stick_index : ndarray of int
        Complete slips y → s (the re-stick is confirmed by a rise of more
        than ``threshold`` after it).
    threshold : float
        Hysteresis ``h`` used (force units).
    noise : float
        Estimated (or given) noise standard deviation of the force.
    lag : int
        Decorrelation lag of the noise in samples (1: white, or noise given).
    unfinished_yield : int or None
        A yield whose drop was seen but whose re-stick was not confirmed
        before the end of the trace (not counted as a slip).
    cycle_noise : float
        Standard deviation of what does not repeat from one cycle to the next
        (:func:`cycle_noise`), the floor of the noise the threshold is set from
        where the local estimate is blind to correlated noise (see
        :func:`detect_slips`); 0 where it was not computed (a rough trace whose
        noise estimate converged, a noise or threshold given, fewer than 2 slips).
    """

    yield_index: np.ndarray
    stick_index: np.ndarray
    threshold: float
    noise: float
    unfinished_yield: int | None = None
    lag: int = 1
    cycle_noise: float = 0.0

    @property
    def count(self) -> int:
        return int(self.yield_index.size)


def _mad_std(x: np.ndarray) -> float:
    if x.size == 0:
        return 0.0
    return 1.4826 * float(np.median(np.abs(x - np.median(x))))


# s(2L)/s(L) beyond what stationary noise gives to second differences (at most 4, for a
# smooth process): the windows at 2L straddle slips
STRADDLE_RATIO = 4.5
# the same for fourth differences, which grow as L⁴ (16 per doubling) on a smooth curve;
# white noise gives 1, AR(1) noise about √2, an MD wall's thermal motion 2-4
STRADDLE_RATIO_SMOOTH = 8.0
# fourth differences below this share of the second differences at lag 1: the trace is
# smooth at its sampling (a noise-free slip), not noisy
SMOOTH_RATIO = 0.25


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
    sigma, lag, _ = _noise_level(spring_force, max_lag=max_lag, plateau=plateau, time=time)
    return sigma, lag


def _noise_level(spring_force, *, max_lag=None, plateau=1.15, time=None):
    """:func:`noise_level`, and whether the estimate is a lower bound of correlated
    noise: the trace is smooth at its sampling (the fourth differences' search), or
    the search reached its longest lag with s(L) still growing."""
    f = np.asarray(spring_force, float)
    n = f.size
    if n < 9:
        return 0.0, 1, False
    t = np.arange(n, dtype=float) if time is None else np.asarray(time, float)

    def s(lag, residuals):
        r = np.abs(residuals(t, f, lag))
        return float(np.quantile(r, NOISE_QUANTILE)) / _Q_NORMAL if r.size else 0.0

    max_lag = max(1, n // 20) if max_lag is None else max_lag
    # a trace whose second differences at lag 1 are mostly a smooth curve's (a slip
    # sampled finely, or by the model's own output) has fourth differences far below them
    smooth = s(1, _line_residuals) < SMOOTH_RATIO * s(1, _chord_residuals)
    residuals, straddle = ((_line_residuals, STRADDLE_RATIO_SMOOTH) if smooth
                           else (_chord_residuals, STRADDLE_RATIO))
    lag, prev = 1, s(1, residuals)
    while 2 * lag <= max_lag and 8 * lag < n:
        cur = s(2 * lag, residuals)
        if prev == 0.0 or cur < plateau * prev:
            return (cur if prev else 0.0), lag, smooth
        if cur > straddle * prev:
            return prev, lag, smooth
        lag, prev = 2 * lag, cur
    # the search ended at its longest lag still growing: the noise is correlated over
    # longer than the estimate sees (a lower bound, as on a smooth trace)
    return prev, lag, True


#: the cycle-to-cycle noise sets the threshold where it exceeds the local noise
#: estimate by more than this factor (it also holds the slips' own cycle-to-cycle
#: variation, so it is an upper estimate of the noise: within the factor the two agree)
CYCLE_NOISE_FACTOR = 2.0


def cycle_noise(time, spring_force, yield_index) -> float:
    """Robust standard deviation of what does not repeat from one cycle to the next.

    The trace is compared with itself one period P later (P the median time
    between the yields, adjusted within ±2 sample spacings to the shift that
    aligns the cycles best; the later trace interpolated linearly at t + P):
    d(t) = f(t + P) − f(t), less its median (a drift of the force levels).  A
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
    shifts = period + step * np.linspace(-2.0, 2.0, 9)
    best = min(_unrepeated(t, f, p) for p in shifts if p > 0.0)
    return best if math.isfinite(best) else 0.0


def _unrepeated(t, f, period):
    """The scale of f(t + period) − f(t) (see :func:`cycle_noise`); inf when fewer
    than 8 samples overlap."""
    ok = t + period <= t[-1]
    if np.count_nonzero(ok) < 8:
        return math.inf
    x = t[ok] + period
    j = np.clip(np.searchsorted(t, x), 1, t.size - 1)
    w = (x - t[j - 1]) / (t[j] - t[j - 1])
    d = (1.0 - w) * f[j - 1] + w * f[j] - f[ok]
    d = (d - np.median(d)) / np.sqrt(1.0 + w * w + (1.0 - w) ** 2)
    return float(np.quantile(np.abs(d), NOISE_QUANTILE)) / _Q_NORMAL


def _first_excursion(f: np.ndarray, start: int, h: float, up: bool,
                     size: int) -> int | None:
    """First index i > start where f[i] is more than h below the running
    maximum of f[start:i] (``up=False``) or more than h above the running
    minimum (``up=True``).  Scans in doubling chunks: O(distance)."""
    n = f.size
    while True:
        stop = min(n, start + size)
        seg = f[start:stop]
        if up:
            hit = np.flatnonzero(seg > np.minimum.accumulate(seg) + h)
        else:
            hit = np.flatnonzero(seg < np.maximum.accumulate(seg) - h)
        if hit.size:
            return start + int(hit[0])
        if stop == n:
            return None
        size *= 2


def detect_slips(time, spring_force, *, threshold: float | None = None,
                 noise: float | None = None, k: float | None = None,
                 min_drop: float = 0.0, relative_drop: float = 0.1,
                 ringing_window: float = 3.0) -> SlipEvents:
    """Find yield (y) and re-stick (s) points in a noisy spring-force trace.

    Criterion: a slip is a fall of the force by more than ``h`` from a
    running maximum (the yield y, the highest force before the fall) to a
    running minimum (the re-stick s, the lowest force before the force rises
    again by more than ``h``).  By default ``h = k σ`` with σ the robust
    noise level (:func:`noise_level`) and ``k = 2 √(2 ln N_eff) + 1``,
    N_eff = N / lag the number of independent noise samples: the largest
    peak-to-trough excursion of N_eff Gaussian samples is ≈ 2 √(2 ln N_eff) σ,
    so a stationary noisy trace gives no event.  A floor of 1e-6 of the
    force range keeps a noise-free trace from counting rounding errors.

    On a trace that is smooth at its sampling (σ estimated from fourth
    differences, see :func:`noise_level`) the local estimate is blind to
    correlated noise sampled finely (an MD wall's thermal vibration with
    ``trace_every`` well below its period), whose dips would be counted as
    slips; where its search reached the longest lag with s(L) still growing,
    it is a lower bound.  There the slips found set a second floor: what does not repeat from
    one cycle to the next (:func:`cycle_noise`) is noise too.  Where it exceeds
    σ by more than :data:`CYCLE_NOISE_FACTOR` (it also holds the slips' own
    variation from cycle to cycle, so within that factor the two agree), ``h``
    is raised to k times it and the scan repeated (at most 3 times).  A trace
    that is rough at its sampling keeps its local estimate (it sees white and
    correlated noise alike): an irregular noise-free sawtooth is not noise.

    Parameters
    ----------
    time, spring_force : array_like, shape (n,)
        The trace (time must increase; NaN is rejected).
    threshold : float, optional
        Hysteresis h in force units (overrides ``noise`` and ``k``).
    noise : float, optional
        Noise standard deviation σ (default: estimated).
    k : float, optional
        Threshold in units of σ (default: as above).
    min_drop : float
        Additionally require Fs − Fb >= min_drop.
    relative_drop : float
        Additionally require Fs − Fb >= relative_drop × the largest drop
        found (default 0.1): ringing after a re-stick, or small stress
        relaxations during a stick, are not slips.
    ringing_window : float
        A candidate that follows the previous re-stick after less than
        ``ringing_window`` × that slip's duration, and whose drop is less than
        half of that slip's drop, is the wall ringing after the re-stick, not
        a new slip (default 3; 0 turns the rule off).

    Returns
    -------
    SlipEvents

    Examples
    --------
    >>> t = np.linspace(0, 10, 1001)
    >>> f = (t % 2.0) + np.random.default_rng(0).normal(0, 0.01, t.size)
    >>> detect_slips(t, f).count
    4
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    if t.ndim != 1 or t.shape != f.shape:
        raise ValueError(f"time and spring_force must be 1-D of equal length, "
                         f"got {t.shape} and {f.shape}")
    bad = ~np.isfinite(f)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        raise ValueError(f"spring_force has {int(bad.sum())} non-finite values "
                         f"(first at index {first}, time {t[first]!r})")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ValueError("time must be finite and strictly increasing")
    empty = np.empty(0, np.int64)
    if f.size < 3:
        return SlipEvents(empty, empty, math.inf, 0.0)
    lag, blind = 1, False
    if noise is None:
        noise, lag, blind = _noise_level(f, time=t)
    n_eff = max(f.size / lag, 2.0)
    kk = (2.0 * math.sqrt(2.0 * math.log(n_eff)) + 1.0) if k is None else k
    threshold_given = threshold
    if threshold is None:
        lo, hi = np.percentile(f, [0.5, 99.5])
        floor = 1e-6 * max(hi - lo, abs(hi), abs(lo), np.finfo(float).tiny)
        threshold = max(kk * noise, floor)
    h = float(threshold)
    yi, si, unfinished = _scan(t, f, h, min_drop, relative_drop, ringing_window)
    cyc = 0.0
    if blind and threshold_given is None:
        # the local estimate does not see noise correlated over longer than its lags
        # (sampled finely, a trace is smooth at its sampling), but what does not
        # repeat from cycle to cycle is noise too
        for _ in range(3):
            cyc = max(cyc, cycle_noise(t, f, yi))
            if cyc <= CYCLE_NOISE_FACTOR * noise or kk * cyc <= h:
                break
            h = kk * cyc
            yi, si, unfinished = _scan(t, f, h, min_drop, relative_drop, ringing_window)
    return SlipEvents(yi, si, h, float(noise), unfinished, lag, cyc)


def _scan(t, f, h, min_drop, relative_drop, ringing_window):
    """The hysteresis scan of :func:`detect_slips` at threshold ``h``: (yields,
    re-sticks, unfinished yield)."""
    yields, sticks = [], []
    unfinished = None
    p, n, size = 0, f.size, 1024
    while p < n - 1:
        i = _first_excursion(f, p, h, up=False, size=size)
        if i is None:
            break
        y = p + int(np.argmax(f[p:i]))
        j = _first_excursion(f, y, h, up=True, size=size)
        if j is None:
            unfinished = y
            break
        s = y + int(np.argmin(f[y:j]))
        if y > 0 and f[y] - f[s] >= min_drop:   # y == 0: slip began before the trace
            yields.append(y)
            sticks.append(s)
        size = max(256, 2 * (j - p))
        p = s
    yi, si = np.asarray(yields, np.int64), np.asarray(sticks, np.int64)
    if yi.size:
        drop = f[yi] - f[si]
        keep = drop >= relative_drop * drop.max()
        yi, si = yi[keep], si[keep]
    if yi.size > 1 and ringing_window > 0:
        yi, si = _drop_ringing(t, f, yi, si, ringing_window)
    return yi, si, unfinished


def _drop_ringing(t, f, yi, si, window):
    """Remove candidates that are the ringing of the wall after a re-stick."""
    kept = [0]
    for i in range(1, yi.size):
        j = kept[-1]
        stick = t[yi[i]] - t[si[j]]
        slip = t[si[j]] - t[yi[j]]
        if stick < window * slip and (f[yi[i]] - f[si[i]]) < 0.5 * (f[yi[j]] - f[si[j]]):
            continue
        kept.append(i)
    return yi[kept], si[kept]


def classify_regime(table: CycleTable, max_cv: float = REGIME_CV_MAX) -> Regime:
    """Sliding regime from the detected slips.

    * ``smooth`` — fewer than 2 slips (none, or a single start-up yield
      followed by steady sliding);
    * ``stick-slip`` — at least 2 slips and, leaving out the first slip
      (start-up from a relaxed spring) when 3 or more were found, the
      coefficients of variation of the static force Fs and of the period τ_ss
      are both <= ``max_cv`` (0.2) (a CV that cannot be computed for lack
      of cycles does not count against it);
    * ``irregular`` — at least 2 slips that fail the CV test.
    """
    n = len(table)
    if n < 2:
        return Regime.SMOOTH
    skip = 1 if n >= 3 else 0
    for name in ("static_force", "period"):
        st = stats(np.asarray(getattr(table, name), float)[skip:])
        if st["n"] >= 2 and st["mean"] != 0:
            if st["std"] / abs(st["mean"]) > max_cv:
                return Regime.IRREGULAR
    return Regime.STICK_SLIP


def _line(t: np.ndarray, f: np.ndarray, lo: int, hi: int):
    """Straight-line fit of f over [lo, hi): (slope, value at t[lo], rms)."""
    if hi - lo < 3:
        return None
    tt = t[lo:hi] - t[lo]
    coef = np.polyfit(tt, f[lo:hi], 1)
    resid = f[lo:hi] - np.polyval(coef, tt)
    return lambda x: np.polyval(coef, x - t[lo]), float(resid.std())


def ramp_forces(time, spring_force, table: CycleTable, *, wall_position=None,
                fraction: float = 0.5, tolerance: float = 3.0) -> CycleTable:
    """Noise-robust yield and re-stick points from straight-line fits to the
    stick ramps.

    With noise, the detector's y is the highest sample near the top of the
    ramp (biased upward, and often a few samples early) and its s the lowest
    sample near the bottom.  Here a line is fitted to the last ``fraction``
    of the stick before y and another to the first ``fraction`` of the stick
    after s.  The refined y is the last sample between y and s still within
    ``tolerance`` × (rms residual) of the first line, the refined s the first
    sample at or below the second line (within its band only if the force never
    reaches it), and Fs, Fb are the lines' values there (which also averages out ringing after the stick).  Where a
    ramp has fewer than 3 samples the detector's point and value are kept.

    Returns
    -------
    CycleTable
        Rebuilt with :func:`cycle_table` at the refined points, with
        ``static_force`` and ``backward_force`` (and x0, and Δx0 when derived
        from the forces) from the fitted lines.
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    yi = table.yield_index.copy()
    si = table.stick_index.copy()
    fs = np.array(table.static_force, float)
    fb = np.array(table.backward_force, float)
    m = len(table)
    for i in range(m):
        y, s = yi[i], si[i]
        start = si[i - 1] if i else 0
        pre = _line(t, f, y - int(fraction * (y - start)), y + 1)
        stop = yi[i + 1] if i + 1 < m else f.size
        post = _line(t, f, s, s + int(fraction * (stop - s)) + 1)
        if pre is not None:
            line, rms = pre
            on = np.flatnonzero(f[y:s + 1] >= line(t[y:s + 1]) - tolerance * rms)
            y = y + int(on[-1]) if on.size else y
            fs[i] = line(t[y])
        if post is not None:
            line, rms = post
            # the force must come down to the next ramp's line itself: a band of
            # tolerance x rms (large when the wall rings) is met halfway down the fall
            level = line(t[y:s + 1])
            on = np.flatnonzero(f[y:s + 1] <= level)
            if not on.size:
                on = np.flatnonzero(f[y:s + 1] <= level + tolerance * rms)
            s = y + int(on[0]) if on.size else s
            s = max(s, y)
            fb[i] = line(t[s])
        yi[i], si[i] = y, s
    k = table.spring_constant
    new = cycle_table(t, f, yi, si, spring_constant=k, wall_position=wall_position)
    changes = dict(static_force=fs, backward_force=fb)
    if k:
        changes["spring_extension"] = fs / k
        if wall_position is None:
            changes["slip_distance"] = (fs - fb) / k
    for a in changes.values():
        a.setflags(write=False)
    return replace(new, **changes)


#: an extreme sample that stands this many noise standard deviations above the chord
#: of its neighbours is refined as on a noise-free trace (see :func:`refine_extrema`)
EXTREMUM_WINDOW_SIGMAS = 4.0
#: a flat extremum's samples lie within this many noise standard deviations of the
#: extreme sample (see :func:`refine_extrema`)
PLATEAU_SIGMAS = 2.0


def _quadratic(t, g, lo, hi, centre):
    """Least-squares parabola through g[lo:hi+1] (times relative to ``centre``):
    coefficients (a, b, c) of a u² + b u + c and their covariance (unscaled)."""
    u = t[lo:hi + 1] - centre
    # solved in times scaled to the window (u/h): in raw units u² and 1 can differ by
    # more than float64 resolves (LJ times of 1e11), and the fit would depend on the unit
    h = float(np.max(np.abs(u))) or 1.0
    us = u / h
    xs = np.column_stack([us * us, us, np.ones_like(us)])
    coef_s, *_ = np.linalg.lstsq(xs, g[lo:hi + 1], rcond=None)
    d = np.array([1.0 / (h * h), 1.0 / h, 1.0])
    cov = np.linalg.pinv(xs.T @ xs) * np.outer(d, d)
    return coef_s * d, cov, xs / d


def _secant_bound(t, g, i, lo, hi):
    """Highest value a concave curve through the samples can reach next to sample i,
    and where: the meeting point of the neighbouring pairs' secants, extended
    ((t[i], g[i]) when none meet above it)."""
    best = (t[i], g[i])
    for a, b, c, d in ((i - 2, i - 1, i, i + 1), (i - 1, i, i + 1, i + 2)):
        if a < lo or d > hi:
            continue
        s1 = (g[b] - g[a]) / (t[b] - t[a])
        s2 = (g[d] - g[c]) / (t[d] - t[c])
        if s1 <= s2:
            continue
        tx = (g[c] - g[b] + s1 * t[b] - s2 * t[c]) / (s1 - s2)
        if not t[b] <= tx <= t[c]:
            continue
        value = g[b] + s1 * (tx - t[b])
        if value > best[1]:
            best = (tx, value)
    return best


def _ramp_side(t, g, i, lo, hi, step, tol):
    """Indices of the straight (stick-ramp) samples next to the extremum i on the
    side ``step`` (−1: before, +1: after), nearest first (i itself when it lies on
    the ramp), or [] when that side is curved.  Three samples must be collinear;
    a stick sampled by fewer (the model's own output: a stick is one straight
    segment between its events) is taken as straight."""
    pts = [j for j in (i + step * k for k in (1, 2, 3)) if lo <= j <= hi]
    if not pts:
        return []
    near, far = pts[0], pts[-1]

    def off(j):
        w = (t[j] - t[far]) / (t[near] - t[far])
        return abs(g[j] - (1 - w) * g[far] - w * g[near])
    if len(pts) == 3:
        if off(pts[1]) > tol:
            return []
        return [i] + pts if off(i) <= tol else pts
    if len(pts) == 2:
        # the stick's two events: the steeper rise towards i is the ramp (the other pair
        # reaches into the previous slip)
        def rise(a, b):
            return (g[a] - g[b]) / abs(t[a] - t[b])
        return [i, near] if rise(i, near) >= rise(near, far) else [near, far]
    return [i, near]


def _kink_extremum(t, g, i, lo, hi, tol):
    """The extremum next to a stick ramp: (time, value) or None.

    At a yield the force leaves its straight stick ramp L(t) and bends over (at a
    re-stick it joins the next ramp): f = L + q with q = 0 on the ramp side and
    smooth on the slip side (−K times the wall's displacement since it left the
    ramp).  q is the parabola through the first three slip-side samples; the
    extremum is where f' = L' + q' = 0, or the joint itself (q = 0) when f has
    no turning point on the slip side (a slip that ends by freezing)."""
    for step in (-1, 1):
        ramp = _ramp_side(t, g, i, lo, hi, step, tol)
        if ramp:
            break
    else:
        return None
    a, b = ramp[-1], ramp[-2]
    slope = (g[b] - g[a]) / (t[b] - t[a])
    if not slope * step < 0:             # the ramp rises towards the extremum
        return None
    line = lambda x: g[a] + slope * (x - t[a])  # noqa: E731
    first = ramp[0] - step                     # first slip-side sample
    curved = [first - step * k for k in range(3)]
    if min(curved) < lo or max(curved) > hi:
        return None
    tc = t[curved]
    q = g[curved] - line(tc)
    if not np.all(q < 0):
        return None
    q2, q1, q0 = np.polyfit(tc - t[ramp[0]], q, 2)
    edge = t[ramp[0]]
    # the joint: where q returns to 0 between the last ramp sample and the first slip one
    lo_t, hi_t = sorted((0.0, t[first] - edge))
    roots = np.roots([q2, q1, q0]) if q2 else (np.array([-q0 / q1]) if q1 else np.array([]))
    roots = roots[np.isreal(roots)].real
    roots = roots[(roots >= lo_t) & (roots <= hi_t)]
    joint = float(roots[np.argmin(np.abs(roots))]) if roots.size else (
        float(np.clip(-q1 / (2 * q2), lo_t, hi_t)) if q2 else 0.0)
    if q2 < 0:
        turn = (-slope - q1) / (2 * q2)
        # the turning point lies on the slip side of the joint
        if (turn - joint) * (-step) > 0:
            if abs(turn) > abs(t[curved[-1]] - edge):
                return None
            return edge + turn, float(line(edge + turn) + q2 * turn * turn + q1 * turn + q0)
    return edge + joint, float(line(edge + joint))


#: the window of a noisy extremum's fit reaches where the (lightly smoothed) force
#: has fallen this many noise standard deviations below it, at most
#: ``NOISY_WINDOW_MAX`` samples on each side
NOISY_WINDOW_SIGMAS = 6.0
NOISY_WINDOW_MAX = 120


def _design(u, model, knot):
    one = np.ones_like(u)
    if model == "quadratic":
        return np.column_stack([one, u, u * u])
    d = np.clip(u - knot, 0.0, None) if model == "slip-after" else np.clip(knot - u, 0.0, None)
    return np.column_stack([one, u, d, d * d])


def _noisy_extremum(t, g, i, lo, hi, sigma, lag):
    """Maximum of g about sample i on a noisy trace, from a least-squares fit.

    The window reaches where the force, smoothed over ``lag`` samples, has fallen
    :data:`NOISY_WINDOW_SIGMAS` σ below the extremum on each side.  Two shapes are
    fitted: a parabola (a smooth turn), and a stick ramp that a slip leaves (or
    joins) at a knot, a line on one side and a line plus a parabola on the other
    (the knot scanned over the window); the one with the lower Bayesian
    information criterion gives the extremum (the highest point of the fitted
    curve).  Returns (time, value, value's noise error)."""
    from scipy.ndimage import uniform_filter1d

    m = max(1, int(lag))
    seg = g[lo:hi + 1]
    sm = uniform_filter1d(seg, size=2 * m + 1, mode="nearest") if m > 1 or seg.size > 4 else seg
    k = i - lo
    top = sm[max(k - m, 0):k + m + 1].max()
    floor = top - NOISY_WINDOW_SIGMAS * sigma
    left = np.flatnonzero(sm[:k] < floor)
    right = np.flatnonzero(sm[k + 1:] < floor)
    a = max(k - NOISY_WINDOW_MAX, (int(left[-1]) if left.size else 0), k - seg.size)
    b = min(k + NOISY_WINDOW_MAX, (k + 1 + int(right[0])) if right.size else seg.size - 1)
    a, b = max(0, min(a, k - 2)), min(seg.size - 1, max(b, k + 2))
    u = t[lo + a:lo + b + 1] - t[i]
    h = float(np.max(np.abs(u))) or 1.0
    u = u / h             # the window's own time scale: the fit is the same in any unit
    y = seg[a:b + 1]
    n = u.size
    best = None
    candidates = [("quadratic", 0.0)]
    if n >= 6:
        knots = u[1:-1]
        candidates += [(side, kn) for side in ("slip-after", "slip-before") for kn in knots]
    for model, knot in candidates:
        x = _design(u, model, knot)
        coef, *_ = np.linalg.lstsq(x, y, rcond=None)
        rss = float(np.sum((y - x @ coef) ** 2))
        p = x.shape[1] + (0 if model == "quadratic" else 1)
        bic = n * math.log(max(rss, 1e-300) / n) + p * math.log(n)
        if best is None or bic < best[0]:
            best = (bic, model, knot, coef, x)
    _, model, knot, coef, x = best
    fine = np.linspace(u[0], u[-1], 4 * n + 1)
    xf = _design(fine, model, knot)
    curve = xf @ coef
    j = int(np.argmax(curve))
    row = xf[j]
    cov = np.linalg.pinv(x.T @ x)
    err = sigma * math.sqrt(max(float(row @ cov @ row), 0.0) * m)
    return t[i] + float(fine[j]) * h, float(curve[j]), err


def _extremum(t, g, i, lo, hi, sigma, lag):
    """Refined maximum of g about sample i (the highest in [lo, hi]).

    Returns (time, value, noise error of value, noise error of time, sampling
    error of value, sampling error of time)."""
    n_lo, n_hi = i - lo, hi - i
    if n_lo < 1 or n_hi < 1:              # at the end of its range: the sample itself
        dt = t[min(i + 1, hi)] - t[max(i - 1, lo)]
        return t[i], g[i], 0.0, 0.0, 0.0, dt / math.sqrt(12.0)
    a_, b_ = i - 1, i + 1
    coef, cov, _ = _quadratic(t, g, a_, b_, t[i])
    a = coef[0]
    # how far the extreme sample stands above the chord of its neighbours, in σ
    x = (t[i] - t[a_]) / (t[b_] - t[a_])
    bump = g[i] - (1.0 - x) * g[a_] - x * g[b_]
    # unevenly spaced samples (a model's output: long sticks, dense slips) are a
    # noise-free trace's; the noisy fit assumes an even sampling
    gaps = (t[i] - t[a_], t[b_] - t[i])
    uneven = max(gaps) > 3.0 * min(gaps)
    w = 1 if sigma == 0.0 or uneven or bump >= EXTREMUM_WINDOW_SIGMAS * sigma else 2
    if w > 1:      # the noise is comparable to the turn over three samples
        tp, vp, ev = _noisy_extremum(t, g, i, lo, hi, sigma, lag)
        return tp, vp, ev, 0.0, 0.0, 0.0
    a, b, c = coef
    u_lo, u_hi = t[a_] - t[i], t[b_] - t[i]
    if a < 0 and u_lo <= -b / (2 * a) <= u_hi:
        tv = -b / (2 * a)
        value = c - b * b / (4 * a)
        grad_v = np.array([b * b / (4 * a * a), -b / (2 * a), 1.0])
        grad_t = np.array([b / (2 * a * a), -1.0 / (2 * a), 0.0])
    else:                                 # no interior vertex: the highest sample
        tv, value = 0.0, g[i]
        grad_v = grad_t = None
    t_peak = t[i] + tv
    if w == 1:
        # noise-free regime: the sampling bounds the peak between the highest
        # sample and where the neighbouring secants meet
        t_bound, bound = _secant_bound(t, g, i, lo, hi)
        value = min(max(value, g[i]), bound)
        if not t[i - 1] <= t_peak <= t[i + 1]:
            t_peak = t[i]
        dt = 0.5 * (t[min(i + 1, hi)] - t[max(i - 1, lo)])
        scale = float(np.ptp(g[lo:hi + 1])) if hi > lo else 0.0
        kink = _kink_extremum(t, g, i, lo, hi, 1e-9 * scale + 4.0 * sigma)
        if kink is not None:
            if not g[i] <= kink[1] <= bound:
                # a sharp corner the slip-side parabola overshoots: where the secants meet
                kink = (t_bound, bound)
            dv, dtk = abs(kink[1] - value), abs(kink[0] - t_peak)
            return kink[0], kink[1], 0.0, 0.0, dv / 2.0, dtk / 2.0
        ev = et = 0.0
        if sigma and grad_v is not None:
            var = sigma * sigma * max(lag, 1)
            ev = math.sqrt(max(float(grad_v @ cov @ grad_v) * var, 0.0))
            et = math.sqrt(max(float(grad_t @ cov @ grad_t) * var, 0.0))
        return t_peak, value, ev, et, (bound - g[i]) / math.sqrt(12.0), dt / math.sqrt(12.0)
    if grad_v is None:
        return t_peak, value, sigma, 0.0, 0.0, 0.0
    var = sigma * sigma * max(lag, 1)
    ev = math.sqrt(max(float(grad_v @ cov @ grad_v) * var, 0.0))
    et = math.sqrt(max(float(grad_t @ cov @ grad_t) * var, 0.0))
    return t_peak, value, ev, et, 0.0, 0.0


def refine_extrema(time, spring_force, table: CycleTable, *, noise: float = 0.0, lag: int = 1,
                   spring_constant: float | None = None, drive_velocity: float | None = None,
                   wall_position=None) -> CycleTable:
    """The yield and re-stick points between the samples: each slip's force maximum
    (y, F_s) and minimum (s, F_b), with their errors.

    The detector's y and s are the highest and lowest samples.  The extremum is
    refined by a least-squares parabola about that sample: through it and its two
    neighbours on a noise-free trace (the value kept between the highest sample
    and the bound of the neighbouring secants, which a concave peak cannot
    exceed), over a window whose ends lie :data:`EXTREMUM_WINDOW_SIGMAS` noise
    standard deviations below the peak on a noisy one.  Its errors: on a
    noise-free trace the sampling's (the range the samples allow, as a uniform
    distribution), on a noisy one the fit's (σ² × ``lag`` per sample, the noise's
    decorrelation).

    Slip distance: the wall's displacement x(s) − x(y) = (F_s − F_b)/K + V τ_s
    with K and V; else from ``wall_position`` interpolated at the refined times;
    else (F_s − F_b)/K (the spring's relaxation, short of the slip by V τ_s).

    Returns
    -------
    CycleTable
        With the refined times and forces, the durations between the refined
        times, and ``uncertainty``: per column, the per-slip noise error and
        sampling error (see :meth:`CycleTable.summary`).
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    yi, si = table.yield_index, table.stick_index
    m = len(table)
    sigma = float(noise)
    cols = {n: np.full(m, math.nan) for n in ("ty", "fy", "ts", "fs")}
    errs = {n: np.zeros(m) for n in ("ty_n", "fy_n", "ts_n", "fs_n",
                                     "ty_r", "fy_r", "ts_r", "fs_r")}
    for j in range(m):
        lo_y = si[j - 1] if j else 0
        hi_s = yi[j + 1] if j + 1 < m else t.size - 1
        y, s = yi[j], si[j]
        if sigma > 0.0:
            # a flat top (the wall creeping with the drive before it slips) or a flat
            # bottom: y is its end, s its start -- the samples within the noise's
            # reach of the extreme one nearest the fall
            band = PLATEAU_SIGMAS * sigma
            y = y + int(np.flatnonzero(f[y:s + 1] >= f[y] - band)[-1])
            s = y + int(np.flatnonzero(f[y:s + 1] <= f[s] + band)[0])
        ty, vy, evy, ety, rvy, rty = _extremum(t, f, y, lo_y, s, sigma, lag)
        ts, vs, evs, ets, rvs, rts = _extremum(t, -f, s, y, hi_s, sigma, lag)
        cols["ty"][j], cols["fy"][j], cols["ts"][j], cols["fs"][j] = ty, vy, ts, -vs
        for key, val in (("ty_n", ety), ("fy_n", evy), ("ts_n", ets), ("fs_n", evs),
                         ("ty_r", rty), ("fy_r", rvy), ("ts_r", rts), ("fs_r", rvs)):
            errs[key][j] = val
    ty, ts = cols["ty"], cols["ts"]
    fs, fb = cols["fy"], cols["fs"]
    nan = np.full(m, math.nan)
    period, stick = nan.copy(), nan.copy()
    if m > 1:
        period[:-1] = np.diff(ty)
        stick[:-1] = ty[1:] - ts[:-1]
    k = None if spring_constant is None else float(spring_constant)
    x0 = fs / k if k else nan.copy()
    tau = ts - ty
    unc = {}
    for kind in ("n", "r"):
        e = {name: errs[f"{name}_{kind}"] for name in ("ty", "fy", "ts", "fs")}
        nxt = np.append(e["ty"][1:], math.nan)
        unc[kind] = {"static_force": e["fy"], "backward_force": e["fs"],
                     "spring_extension": e["fy"] / k if k else nan.copy(),
                     "slip_duration": np.hypot(e["ty"], e["ts"]),
                     "stick_duration": np.hypot(e["ts"], nxt),
                     "period": np.hypot(e["ty"], nxt),
                     "yield_time": e["ty"], "stick_time": e["ts"]}
    if k and drive_velocity:
        dist = (fs - fb) / k + float(drive_velocity) * tau
        for kind in ("n", "r"):
            u = unc[kind]
            u["slip_distance"] = np.hypot(np.hypot(u["static_force"], u["backward_force"]) / k,
                                          float(drive_velocity) * u["slip_duration"])
    elif wall_position is not None:
        x = np.asarray(wall_position, float)
        dist = np.interp(ts, t, x) - np.interp(ty, t, x)
        for kind in ("n", "r"):
            unc[kind]["slip_distance"] = np.zeros(m)
    elif k:
        dist = (fs - fb) / k
        for kind in ("n", "r"):
            u = unc[kind]
            u["slip_distance"] = np.hypot(u["static_force"], u["backward_force"]) / k
    else:
        dist = nan.copy()
    # the samples nearest the refined points (the energy windows, the figures)
    near = lambda x: np.clip(np.searchsorted(t, x), 1, t.size - 1) - (  # noqa: E731
        np.abs(x - t[np.clip(np.searchsorted(t, x), 1, t.size - 1) - 1])
        <= np.abs(t[np.clip(np.searchsorted(t, x), 1, t.size - 1)] - x))
    new_y, new_s = near(ty).astype(np.int64), near(ts).astype(np.int64)
    new_s = np.maximum(new_s, new_y)
    if m > 1:
        new_y[1:] = np.maximum(new_y[1:], new_s[:-1])
    arrays = dict(yield_index=new_y, stick_index=new_s,
                  yield_time=ty, stick_time=ts, static_force=fs, backward_force=fb,
                  spring_extension=x0, slip_distance=dist, slip_duration=tau,
                  stick_duration=stick, period=period)
    for a in arrays.values():
        a.setflags(write=False)
    uncertainty = {name: (unc["n"][name], unc["r"][name]) for name in unc["n"]}
    return replace(table, **arrays, uncertainty=uncertainty)


@dataclass(frozen=True)
class StickStiffness:
    """The stuck film's shear stiffness from the stick ramps (:func:`stick_stiffness`).

    Attributes
    ----------
    film_stiffness, film_stiffness_stderr : float
        k_f = K K_eff / (K − K_eff) and its error (propagated from K_eff's).
    effective_stiffness, effective_stiffness_stderr : float
        K_eff = ramp slope / V, mean over the ramps and its standard error.
    ramps : int
    """

    film_stiffness: float
    film_stiffness_stderr: float
    effective_stiffness: float
    effective_stiffness_stderr: float
    ramps: int


def stick_stiffness(time, spring_force, table: CycleTable, *, spring_constant: float,
                    drive_velocity: float) -> StickStiffness | None:
    """The stuck film's elastic shear stiffness k_f from the slopes of the stick ramps.

    A stuck film strains like a spring in series with the drive spring: the
    force rises at K_eff V with 1/K_eff = 1/K + 1/k_f.  Each ramp (re-stick to
    the next yield, its first quarter and last tenth left out: ringing and
    creep before the yield) gives a slope; k_f = K K_eff/(K − K_eff) from
    their mean, its error propagated from theirs.

    Returns
    -------
    StickStiffness or None
        None with fewer than 2 ramps or when K_eff is not 2 standard errors
        below K (no measurable compliance).

    Examples
    --------
    Ramps at 0.8 K V: k_f = 4 K.

    >>> t = np.arange(0.0, 40.0, 0.1)
    >>> f = 0.8 * (t % 10.0)                       # K = 1, V = 1, a sawtooth
    >>> tab = cycle_table(t, f, [99, 199, 299], [100, 200, 300])
    >>> round(stick_stiffness(t, f, tab, spring_constant=1.0, drive_velocity=1.0).film_stiffness, 6)
    4.0
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    k, v = float(spring_constant), float(drive_velocity)
    if not (k > 0 and v > 0):
        return None
    slopes = []
    for i0, i1 in zip(table.stick_index[:-1], table.yield_index[1:]):
        lo, hi = i0 + (i1 - i0) // 4, i1 - (i1 - i0) // 10
        if hi - lo >= 5:
            slopes.append(np.polyfit(t[lo:hi], f[lo:hi], 1)[0] / v)
    if len(slopes) < 2:
        return None
    k_eff = float(np.mean(slopes))
    se = float(np.std(slopes, ddof=1) / math.sqrt(len(slopes)))
    if not 0.0 < k_eff < k - 2.0 * se:
        return None
    k_f = k * k_eff / (k - k_eff)
    dk = se * (k / (k - k_eff)) ** 2          # d k_f / d K_eff
    return StickStiffness(k_f, dk, k_eff, se, len(slopes))
