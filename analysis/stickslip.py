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
           "noise_level", "classify_regime", "ramp_forces", "REGIME_CV_MAX"]

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
    unfinished_yield : int or None
        A yield whose drop was seen but whose re-stick was not confirmed
        before the end of the trace (not counted as a slip).
    """

    yield_index: np.ndarray
    stick_index: np.ndarray
    threshold: float
    noise: float
    unfinished_yield: int | None = None

    @property
    def count(self) -> int:
        return int(self.yield_index.size)


def _mad_std(x: np.ndarray) -> float:
    if x.size == 0:
        return 0.0
    return 1.4826 * float(np.median(np.abs(x - np.median(x))))


# s(2L)/s(L) beyond what any stationary noise gives (at most 4, for a smooth
# process): the windows at 2L straddle slips
STRADDLE_RATIO = 4.5


def noise_level(spring_force, *, max_lag: int | None = None,
                plateau: float = 1.15) -> tuple[float, int]:
    """Robust standard deviation of the fluctuations of a trace.

    Uses second differences at lag L, d = f[i+2L] − 2 f[i+L] + f[i], which
    vanish on straight stick ramps of any slope; s(L) = MAD(d)/√6 (the
    median absolute deviation ignores the few differences that straddle a
    slip).  For white noise s(L) = σ at every L; for correlated (thermal)
    noise s(L) grows with L until L exceeds the correlation time.  The
    estimate is s(2L) at the first lag with s(2L)/s(L) < ``plateau``.

    A ratio s(2L)/s(L) above 4.5 stops the search at s(L): no stationary
    process grows that fast (a smooth one at most as L², a factor 4), so at 2L
    most windows straddle a slip or its ringing.  Without this a coarse trace
    (≈ 1 τ per sample, a few samples per ringing period) reached lags of a
    quarter period before any plateau and took the slips for noise.

    Returns
    -------
    sigma : float
        Noise standard deviation (0 for a noise-free piecewise-linear trace).
    lag : int
        Decorrelation lag in samples (1 for white noise).
    """
    f = np.asarray(spring_force, float)
    n = f.size
    if n < 5:
        return 0.0, 1

    def s(lag):
        return _mad_std(f[2 * lag:] - 2 * f[lag:-lag] + f[:-2 * lag]) / math.sqrt(6)

    max_lag = max(1, n // 20) if max_lag is None else max_lag
    lag, prev = 1, s(1)
    while 2 * lag <= max_lag and 4 * lag < n:
        cur = s(2 * lag)
        if prev == 0.0 or cur < plateau * prev:
            return (cur if prev else 0.0), lag
        if cur > STRADDLE_RATIO * prev:
            return prev, lag
        lag, prev = 2 * lag, cur
    return prev, lag


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
    lag = 1
    if noise is None:
        noise, lag = noise_level(f)
    if threshold is None:
        n_eff = max(f.size / lag, 2.0)
        kk = (2.0 * math.sqrt(2.0 * math.log(n_eff)) + 1.0) if k is None else k
        lo, hi = np.percentile(f, [0.5, 99.5])
        floor = 1e-6 * max(hi - lo, abs(hi), abs(lo), np.finfo(float).tiny)
        threshold = max(kk * noise, floor)
    h = float(threshold)

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
    return SlipEvents(yi, si, h, float(noise), unfinished)


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
