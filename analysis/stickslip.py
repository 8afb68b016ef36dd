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
from dataclasses import dataclass

import numpy as np

from filmfriction.reduced_model.cycles import CycleTable, stats

from .noise import CYCLE_NOISE_FACTOR, cycle_noise, increment_noise, noise_level_and_bound

__all__ = ["Regime", "sliding_steadily", "STEADY_VELOCITY_TOLERANCE", "SlipEvents", "detect_slips",
           "classify_regime", "REGIME_CV_MAX"]

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
    inner_resticks : int
        Re-sticks found inside the slips of the hysteresis scan, each of which the slip
        it was in was split at (see ``restick_fraction`` in :func:`detect_slips`).
    unfinished_yield : int or None
        A yield whose drop was seen but whose re-stick was not confirmed
        before the end of the trace (not counted as a slip).
    cycle_noise : float
        Standard deviation of what does not repeat from one cycle to the next
        (:func:`cycle_noise`), the floor of the noise the threshold is set from
        where the local estimate is blind to correlated noise (see
        :func:`detect_slips`); 0 where it was not computed (a rough trace whose
        noise estimate converged, a noise or threshold given, fewer than 2 slips).
    increment_noise : float
        The noise's scale at its own time scale, from the trace's increments
        (:func:`~filmfriction.analysis.noise.increment_noise`), the cap of the threshold
        where the local estimate is blind (see :func:`detect_slips`); 0 where it was not
        computed.
    """

    yield_index: np.ndarray
    stick_index: np.ndarray
    threshold: float
    noise: float
    unfinished_yield: int | None = None
    lag: int = 1
    cycle_noise: float = 0.0
    increment_noise: float = 0.0
    inner_resticks: int = 0

    @property
    def count(self) -> int:
        return int(self.yield_index.size)



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


#: The default ``restick_rate`` of :func:`detect_slips`: a rise inside a slip is a re-stick
#: when, over it, the force rises at no more than this many times the sticks' loading rate:
#: dF/dt = K(V − ẋ), so 2 K·V is a wall whose mean velocity is −V, and a wall at rest within
#: ±V gives at most 2.
RESTICK_RATE = 2.0

#: at most this many raises of the threshold by the cycle noise (each re-scans the trace);
#: the increments' cap bounds them, so they run to where they stop rising
RAISES = 10


def detect_slips(time, spring_force, *, threshold: float | None = None,
                 noise: float | None = None, k: float | None = None,
                 min_drop: float = 0.0, relative_drop: float = 0.1,
                 ringing_window: float = 3.0, restick_fraction: float = 1.0 / 3.0,
                 restick_rate: float = RESTICK_RATE,
                 loading_rate: float | None = None) -> SlipEvents:
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
    it is a lower bound.  There the slips found set a second floor: what does not
    repeat from one cycle to the next (:func:`cycle_noise`) is noise too.  Where it
    exceeds σ by more than :data:`CYCLE_NOISE_FACTOR` (it also holds the slips' own
    variation from cycle to cycle, so within that factor the two agree), ``h`` is
    raised to k times it and the scan repeated (at most :data:`RAISES` times).  Each
    raise re-estimates it from the slips the last scan kept, and a slip that scan
    missed counts as noise in the next estimate, so on slips of irregular size the
    raises would feed on themselves: ``h`` is capped at k' times the noise's scale at
    its own time scale L, read from the trace's increments (:func:`increment_noise`,
    which needs no slips found first; k' from N/L independent samples).  Where fewer
    than 2 slips are left to compare cycles, the cap sets ``h``.  A trace that is
    rough at its sampling keeps its local estimate (it sees white and correlated
    noise alike): an irregular noise-free sawtooth is not noise.

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
        ``ringing_window`` × that slip's duration, whose drop is less than
        half of that slip's drop, and whose force is back at its yield value in
        less than 3/4 of the time the drive takes to reload the drop, is the wall
        ringing after the re-stick, not a new slip (default 3; 0 turns the rule
        off).  A slip unloads the spring, which the drive reloads at the sticks'
        loading rate; a bounce of the ringing comes back within a part of its period.
    restick_fraction : float
        A slip found by the scan holds slips smaller than ``h`` (their sticks reload the
        spring by less than ``h``): inside it, a rise of the force above its running
        minimum by more than r = max(``restick_fraction`` × ``h``, k σ) is a re-stick when
        the force rises over it at no more than ``restick_rate`` times the loading
        rate (the wall at rest within ±V; a wall ringing back, faster, is not stuck).  k σ
        is the largest peak-to-trough excursion of the noise seen at the sampling over the
        slips' samples (k = 2 √(2 ln N) + 1, N those samples over the lag): on white noise
        it is about ``h``, and no rise inside a slip is told from the noise.  The slip is
        split there: the first ends at the minimum, the next yields at the rise's top (the
        highest force before it falls r again).  The rule needs 2 slips from the scan (a
        trace merged into one slip is not split) and a positive loading rate.  Default
        1/3; 0 turns the rule off.  Ground truth: docs/analysis.md ("Slips inside slips").
    restick_rate : float
        The fastest rise, in loading rates, that counts as a re-stick (default
        :data:`RESTICK_RATE`, 2; must be positive).
    loading_rate : float, optional
        K·V, the rate at which the drive loads the spring while the wall is at rest (force
        per time), for the re-stick rule; default: the median rise rate of the scan's
        sticks (which sticks that hold slips the scan missed pull down).

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
        noise, lag, blind = noise_level_and_bound(f, time=t)
    kk = _peak_to_trough(f.size / lag) if k is None else k
    threshold_given = threshold
    if threshold is None:
        lo, hi = np.percentile(f, [0.5, 99.5])
        floor = 1e-6 * max(hi - lo, abs(hi), abs(lo), np.finfo(float).tiny)
        threshold = max(kk * noise, floor)
    h = float(threshold)
    rules = (min_drop, relative_drop, ringing_window)
    yi, si, unfinished = _scan(t, f, h, *rules)
    cyc = inc = 0.0
    if blind and threshold_given is None:
        # the local estimate does not see noise correlated over longer than its lags
        # (sampled finely, a trace is smooth at its sampling), but what does not
        # repeat from cycle to cycle is noise too, and so are the increments at the
        # noise's own time scale, which cap it
        inc, inc_lag = increment_noise(f)
        cap = max(h, (_peak_to_trough(f.size / inc_lag) if k is None else k) * inc)
        for _ in range(RAISES):
            # with fewer than 2 slips left there is no cycle to compare: the cap
            cyc = max(cyc, cycle_noise(t, f, yi)) if yi.size >= 2 else math.inf
            new = min(kk * cyc, cap)
            if cyc <= CYCLE_NOISE_FACTOR * noise or new <= h:
                break
            h = new
            yi, si, unfinished = _scan(t, f, h, *rules)
        cyc = cyc if math.isfinite(cyc) else 0.0
    # the slips the scan merged, split where the wall stopped inside them (after the
    # threshold is set: h is the scan's, with or without the split)
    inner = 0
    if yi.size > 1 and restick_fraction > 0:
        if not restick_rate > 0.0:
            raise ValueError(f"restick_rate {restick_rate!r}: must be positive (in loading "
                             "rates; default 2)")
        rate = (float(loading_rate) if loading_rate is not None
                else _loading_rate(t, f, yi, si, max(ringing_window, 1.0)))
        # no smaller than the largest excursion the noise seen at the sampling gives over
        # the slips' samples: on white noise that is about h, and nothing is split
        inside = int(np.sum(si - yi)) + yi.size
        rise = max(restick_fraction * h, _peak_to_trough(inside / lag) * float(noise))
        if rate > 0.0:
            pairs = [q for a, b in zip(yi, si)
                     for q in _split_at_resticks(t, f, int(a), int(b), rise,
                                                 restick_rate * rate)]
            inner = len(pairs) - yi.size
            yi = np.array([q[0] for q in pairs], np.int64)
            si = np.array([q[1] for q in pairs], np.int64)
    return SlipEvents(yi, si, h, float(noise), unfinished, lag, cyc, inc, inner)


def _peak_to_trough(n_eff: float) -> float:
    """k = 2 √(2 ln N_eff) + 1: the largest peak-to-trough excursion of N_eff independent
    Gaussian samples, in σ, with a margin of one σ (N_eff at least 2)."""
    return 2.0 * math.sqrt(2.0 * math.log(max(n_eff, 2.0))) + 1.0


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


def _loading_rate(t, f, yi, si, window):
    """The sticks' loading rate: the median rise from a re-stick to the next yield, over
    the sticks that no ringing can be (longer than ``window`` slips), else over all."""
    stick = t[yi[1:]] - t[si[:-1]]
    rates = (f[yi[1:]] - f[si[:-1]]) / stick
    long = stick >= window * (t[si[:-1]] - t[yi[:-1]])
    return float(np.median(rates[long] if long.any() else rates))


def _split_at_resticks(t, f, y, s, rise, fastest):
    """Slip (y, s) as the slips it holds (see ``restick_fraction`` in :func:`detect_slips`;
    ``fastest`` the fastest re-stick's rise rate): a list of (yield, re-stick) index pairs."""
    out, base = [], y
    while True:
        seg = f[base:s + 1]
        above = np.flatnonzero(seg - np.minimum.accumulate(seg) > rise)
        if above.size == 0:
            break
        j = int(above[0])
        low = int(np.argmin(seg[:j + 1]))
        # the rise's top: the highest force before it falls ``rise`` below it
        fall = np.flatnonzero(seg[j:] < np.maximum.accumulate(seg[j:]) - rise)
        end = j + int(fall[0]) if fall.size else seg.size
        top = j + int(np.argmax(seg[j:end]))
        if seg[top] - seg[low] <= fastest * (t[base + top] - t[base + low]):
            out.append((y, base + low))     # a re-stick: the wall stopped, the drive reloads
            y = base + top
        base += top                         # else a bounce: search on after its top
        if base >= s:
            break
    out.append((y, s))
    return out


def _drop_ringing(t, f, yi, si, window):
    """Remove candidates that are the ringing of the wall after a re-stick (see
    ``ringing_window`` in :func:`detect_slips`)."""
    rate = _loading_rate(t, f, yi, si, window)
    kept = [0]
    for i in range(1, yi.size):
        j = kept[-1]
        stick = t[yi[i]] - t[si[j]]
        slip = t[si[j]] - t[yi[j]]
        drop = f[yi[i]] - f[si[i]]
        if stick < window * slip and drop < 0.5 * (f[yi[j]] - f[si[j]]):
            if not rate > 0.0:
                continue
            # a bounce regains its yield force sooner than the drive could reload it:
            # only the samples within that time are searched
            reload = 0.75 * drop / rate
            end = int(np.searchsorted(t, t[si[i]] + reload, side="left"))
            if np.any(f[si[i]:end] >= f[yi[i]]):
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
