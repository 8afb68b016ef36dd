"""What the stick ramps tell: the yield and re-stick points from straight lines fitted
to the ramps (:func:`ramp_forces`), and the stuck film's shear stiffness from their
slopes (:func:`stick_stiffness`)."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from filmfriction.reduced_model.cycles import CycleTable, cycle_table

__all__ = ["ramp_forces", "StickStiffness", "stick_stiffness"]


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
