"""The slip law of a driven stick-slip trace fitted to its cycles' mean, errors by the jackknife.

A film's random force moves the wall: the wall's displacement Δx, the regressor of
the integral-form fit (:mod:`~filmfriction.analysis.slip_law.slip_law`), carries the
noise that its response carries, and a fit of each slip is biased whatever the
number of slips (Klein's viscous slips come out ``mixed``; every law gets a loop step
of the noise: docs/results/slip-law.md, "The controls with a random force that moves
the wall").  Releases have the remedy (:func:`~filmfriction.analysis.slip_law.slip_law.jackknife_fit`):
fit the mean of replicas, whose noise averages out of the regressors, and take the
errors from the jackknife over the replicas.  The slips of one driven run are such
replicas once each is aligned at its yield, with one difference: they do not last
equally long, and where a slip ends is set by the noise (a wall re-sticks where its
velocity, law plus noise, falls to zero), so a mean over the slips still slipping at a
lag, or over the window of the shortest one, selects on the noise.

The ensemble here keeps every slip at every lag.  Slip i, from its yield y_i to its
re-stick s_i = y_i + d_i, is *held at its end* after it: at lag k its impulse
I_i(k) = ∫ (F_spring − γM(v − V)) dt, displacement x_i(k) − x_i(0), velocity v_i(k) and
slipping time are those of lag min(k, d_i).  The re-stick is the last sample on which
the wall slid (the detector's: the spring force's minimum, where the wall still moves at
the drive's velocity); a sample after the wall stopped carries the impulse of the static
friction that stopped it, which is not the law's (a control slider that marked its
re-stick there, with v = 0, biased the ensemble by a bias that grew with the share of
slips ended: docs/results/slip-law.md, "Holding a slip at its last slipping sample").
The wall's integrated equation of motion holds for each slip so held (the film's force
is the law's while the wall slips), and it is linear, so it holds for the mean over the
slips:

    Ī(k) − M·v̄(k) = c + F_k·S̄(k) + B·x̄(k) [+ m_c·v̄(k)] + M·ū(k)

with S̄(k) the mean time spent slipping by lag k (the kinetic force acts only while a
slip lasts) and ū the mean of the noise, whose share in the regressors x̄ and v̄
averages down as 1/√N over N slips.  The mean is fitted as one slip
(:func:`~filmfriction.analysis.slip_law.slip_law.fit_segments`: the branches split at
the mean's peak velocity, the samples above ``min_velocity_fraction`` of it, the one
law and its loop step, S̄ in place of the time), and the errors, the verdict and the
power are the jackknife's over the slips (the N means that leave one slip out:
N − 1 degrees of freedom; :func:`~filmfriction.analysis.slip_law.slip_law.jackknife_fit`).

What is left of the noise's selection, measured on the controls
(``python benchmarks/slip_law/slip_law_random_force.py --ensemble``, docs/results/slip-law.md):
on Klein's slips at the MD's noise the decelerating branch is unbiased (F_k +0.04 ± 0.05,
B −0.07 ± 0.08 over 1000 replicas of 30 slips); where a wall re-sticks when its velocity
falls (Coulomb), it re-sticks where the noise slowed it, and the decelerating branch's F_k
is low by ~1.4 ε/σ (the one-law figures there were measured before the m_c regressor
became the held velocity).  The one law's co-moving mass has as regressor the mean's held
velocity smoothed (Klein's overdamped slips noise-free: m_c −0.02 m of a 30 m wall with a
3 τ window; 44 m while the wall's own M·v was smoothed with it).  Each slip's held
velocity, m_c's regressor, is its own positions' derivative, not the sampled velocity,
whose white noise (a wall's rattle) the positions do not carry: frozen at each slip's end
in the regressor it biased the one law (a loop step of +2.1 ± 0.2 ε/σ on Klein's slips,
share 0.3, with a rattle of 0.15 σ/τ alone; now −0.3 ± 0.3).  The rattle stays in the
response y − M·v (the wall's own momentum, sampled), where it is noise: unbiased, at a
cost in precision (the loop step's scatter over those replicas 1.05 → 1.98 ε/σ).  Without
positions (``wall_position`` None) the integral of the sampled velocity stands in for them
and keeps most of the end sample's rattle (loop step +2.0 ± 0.2 there, as before).

Example
-------
Noise-free slips of a Coulomb + viscous slider (F_k = 20, B = 15) give the law back:

>>> from filmfriction.analysis.groundtruth.random_force import slide
>>> from filmfriction.reduced_model.cycles import cycle_table
>>> run = slide("coulomb-viscous", (20.0, 15.0), mass=30.0, stiffness=2.0,
...             drive_velocity=0.1, static_force=48.0, armed_below=34.0, initial_force=30.0,
...             stop_velocity=0.15, duration=1500.0, dt=0.25)[0]
>>> table = cycle_table(run["time"], run["spring_force"], run["yield_index"],
...                     run["stick_index"], spring_constant=2.0)[1:]
>>> fit = fit_cycle_ensemble(run["time"], run["spring_force"], run["wall_velocity"], table,
...                          mass=30.0, drive_velocity=0.1, wall_position=run["wall_position"])
>>> len(table), round(fit.kinetic_force, 2), round(fit.damping, 2), fit.verdict
(9, 20.0, 15.0, 'mixed')
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.signal import lfilter, savgol_filter

from filmfriction.reduced_model.cycles import CycleTable

from .slip_law import (MIN_RELAXATION, SMOOTHING, FilmForceFit, checked_fit_inputs,
                       fit_segments, jackknife_fit, smoothing_samples)
from .slip_law_branches import Segment

__all__ = ["fit_cycle_ensemble", "fit_held_ensemble", "held_slips", "held_keys", "slipped",
           "fitted_registry_period", "registry_integrals", "REGISTRY_MIN_PERIODS",
           "uniform_step", "MIN_CYCLES", "MD_NOISE_TIME", "REGISTRY_HARMONICS", "LAGGED"]

#: The fewest slips the ensemble is fitted from (the jackknife needs a scatter).
MIN_CYCLES = 3
#: The time over which the MD's wall noise stays correlated (LJ τ): its autocorrelation is
#: 0.44 at 2 τ and 0.08 at 4 τ (docs/results/slip-law.md, "The MD's noise").  The mean
#: slip's velocity is smoothed over at least this long (``min_window_time``).
MD_NOISE_TIME = 3.0
#: The per-slip, per-lag arrays of :func:`held_slips`.
HELD = ("impulse", "velocity", "held_velocity", "displacement", "slipping_time")
#: The per-slip array of a viscous force that lags (:func:`held_slips` with ``viscous_lag``).
LAGGED = "lagged_displacement"
#: The harmonics of the walls' registry force fitted where its period is given: the
#: force of commensurate walls repeats with the lattice's period along the slide, and the
#: MD's has a second harmonic of half the first's amplitude (docs/results/slip-law.md,
#: "The walls' registry in the film's force").
REGISTRY_HARMONICS = 2
#: The fewest periods of the registry the median slip must span for its force to be fitted:
#: over a shorter slip a periodic force is a smooth function of the distance, which the
#: terms cannot tell from the law's (the fit would lose the branches).
REGISTRY_MIN_PERIODS = 2.0


def fitted_registry_period(registry_period: float | None, slip_distances) -> float | None:
    """The registry period the slips are fitted with: ``registry_period`` where their median
    distance spans :data:`REGISTRY_MIN_PERIODS` of it, else None (the law alone).

    >>> fitted_registry_period(1.1, [3.0, 4.8, 6.0]), fitted_registry_period(1.1, [0.4, 1.0])
    (1.1, None)
    """
    d = np.asarray(slip_distances, float)
    d = d[np.isfinite(d)]
    if registry_period is None or not d.size:
        return None
    return registry_period if np.median(np.abs(d)) >= REGISTRY_MIN_PERIODS * registry_period else None


def registry_integrals(time, position, registry_period: float) -> dict:
    """The regressors of a force periodic in the walls' registry over one stretch of slide:
    ``registry_sin1``, ``registry_cos1``, … to :data:`REGISTRY_HARMONICS`, the time integrals
    from its start of sin and cos(2π·h·x/λ) at the wall's position x.

    >>> t = np.linspace(0.0, 1.0, 101)
    >>> r = registry_integrals(t, 0.25 * t, 1.0)     # x/λ from 0 to 1/4 at a steady pace
    >>> list(r), round(float(r["registry_sin1"][-1]), 4)    # ∫ sin(π t/2) dt = 2/π
    (['registry_sin1', 'registry_cos1', 'registry_sin2', 'registry_cos2'], 0.6366)
    """
    t, x = np.asarray(time, float), np.asarray(position, float)
    return {f"registry_{wave.__name__}{h}":
            cumulative_trapezoid(wave(2 * math.pi * h * x / registry_period), t, initial=0.0)
            for h in range(1, REGISTRY_HARMONICS + 1) for wave in (np.sin, np.cos)}


def held_keys(held: dict) -> tuple:
    """The per-slip arrays of ``held``: :data:`HELD`, the registry's and :data:`LAGGED`,
    where fitted."""
    return HELD + tuple(k for k in held if k.startswith("registry_") or k == LAGGED)


def uniform_step(t: np.ndarray, what: str) -> float:
    """The sampling interval of ``t``, which ``what`` (named in the error) needs uniform
    (ValueError otherwise)."""
    dts = np.diff(t)
    if not np.allclose(dts, dts[0], rtol=1e-6, atol=0):
        raise ValueError(f"{what} needs a uniform sampling")
    return float(dts[0])


def slipped(table: CycleTable) -> np.ndarray:
    """Which windows of ``table`` are slips: the spring relaxed over them by at least
    :data:`~filmfriction.analysis.slip_law.slip_law.MIN_RELAXATION` of its force at the
    yield, and the re-stick comes after the yield."""
    fs, fb = (np.asarray(table.static_force, float), np.asarray(table.backward_force, float))
    with np.errstate(invalid="ignore", divide="ignore"):
        relaxed = (fs - fb) / np.abs(fs)
    return (relaxed >= MIN_RELAXATION) & (np.asarray(table.stick_index, int)
                                           > np.asarray(table.yield_index, int))


def held_slips(time, spring_force, wall_velocity, wall_position, yields, sticks, *,
               mount_damping: float = 0.0, drive_velocity: float = 0.0,
               registry_period: float | None = None, viscous_lag: float | None = None) -> dict:
    """Each slip aligned at its yield and held at its end (module text), per slip and lag.

    Returns a dict of arrays of shape (slips, lags): ``impulse``, ``velocity`` (the
    sampled one), ``held_velocity`` (the slip's own positions' derivative, second order,
    one-sided at its ends: what a sampled velocity's noise does not reach, since the
    positions integrate the wall's motion), ``displacement``, ``slipping_time``; the lags
    run to the longest slip's end, and ``lag_time`` (lags,) holds their times from the
    yield.  With ``registry_period`` λ: ``registry_sin1``, ``registry_cos1``, … to
    :data:`REGISTRY_HARMONICS`, the time integrals over the slip of sin and cos(2π·h·x/λ)
    at the wall's position x (the regressors of a force periodic in the walls' registry).
    With ``viscous_lag`` τ_r: :data:`LAGGED`, ∫v_f dt, v_f the slip's velocity (its
    positions' derivative) relaxed to over τ_r from 0 at the yield, dv_f/dt = (v − v_f)/τ_r:
    the regressor of B for a film whose viscous force lags the shear rate (a Maxwell film,
    the ``maxwell`` law of :mod:`~filmfriction.analysis.groundtruth.random_force`).
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    v = np.asarray(wall_velocity, float)
    x = np.asarray(wall_position, float)
    y = np.asarray(yields, int)
    s = np.asarray(sticks, int)
    d = s - y
    n = int(d.max()) + 1
    dt = float(t[1] - t[0])
    lag = np.arange(n)
    reg = (tuple(registry_integrals(t[:1], x[:1], registry_period))
           if registry_period is not None else ())
    lagged = (LAGGED,) if viscous_lag is not None else ()
    out = {k: np.empty((y.size, n)) for k in HELD + reg + lagged}
    # v_f of a first-order relaxation, exact over a sample for the mean of its ends' v
    relax = -math.expm1(-dt / viscous_lag) if viscous_lag is not None else 0.0
    for i, (a, b) in enumerate(zip(y, s)):
        k = np.minimum(lag, b - a) + a
        seg = np.arange(a, b + 1)
        force = f[seg] - mount_damping * (v[seg] - drive_velocity)
        imp = cumulative_trapezoid(force, t[seg], initial=0.0)
        out["impulse"][i] = imp[k - a]
        out["velocity"][i] = v[k]
        own = np.gradient(x[seg], t[seg], edge_order=2 if seg.size > 2 else 1)
        out["held_velocity"][i] = own[k - a]
        if lagged:
            vf = np.concatenate(([0.0], lfilter([relax], [1.0, relax - 1.0],
                                                0.5 * (own[1:] + own[:-1]))))
            out[LAGGED][i] = cumulative_trapezoid(vf, t[seg], initial=0.0)[k - a]
        out["displacement"][i] = x[k] - x[a]
        out["slipping_time"][i] = t[k] - t[a]
        if reg:
            for key, r in registry_integrals(t[seg], x[seg], registry_period).items():
                out[key][i] = r[k - a]
    out["lag_time"] = lag * dt
    return out


def _guide(x: np.ndarray, window: int, dt: float, deriv: int = 1) -> np.ndarray:
    """The velocity from the displacement along the last axis (Savitzky–Golay of
    ``window``); with ``deriv`` 0, ``x`` itself smoothed alike."""
    w = window if 5 <= window < x.shape[-1] else 0
    if not w:
        return np.gradient(x, dt, axis=-1) if deriv else x
    return savgol_filter(x, w, 2, deriv=deriv, delta=dt, axis=-1)


def _selection(guide: np.ndarray, window: int, floor: float):
    """The peak and the fitted lags of each branch of the mean slip (or None): the lags
    whose velocity exceeds ``floor`` of the peak, half a window off the ends."""
    n = guide.size
    p = int(np.argmax(guide))
    peak = float(guide[p])
    if not peak > 0:
        return p, peak, {}
    w = window if 5 <= window < n else 0
    fast = guide > floor * peak
    edge = w // 2 + 1
    fast[:edge] = False
    fast[max(n - edge, 0):] = False
    lags = {}
    for name, (lo, hi) in (("accelerating", (0, p + 1)), ("decelerating", (p, n)),
                           ("whole", (0, n))):
        k = np.flatnonzero(fast[lo:hi]) + lo
        if k.size:
            lags[name] = np.arange(k[0], k[-1] + 1)
    return p, peak, lags


def _segments(mean: dict, window: int, dt: float, p: int, lags: dict, mass: float) -> dict:
    """The mean slip's segments (:func:`fit_segments`'s input) at the lags chosen.  The m_c
    term's regressor is the mean's held velocity (each slip's from its own positions)
    smoothed over ``window``: a slip held at its end keeps the velocity it ended with in
    the law's m_c·(v − v0), where the derivative of the mean displacement counts it as
    stopped (slips that end before they stop, pooled with longer ones, would bias m_c
    and with it F_k and B); the positions' velocity, not the sampled one, because a
    sampled velocity's white noise (a wall's rattle) would be frozen into the held lags,
    an error in the regressor that biases the one law and its loop step.  The wall's own
    M·v is the sampled velocity's, in the response (Segment.response)."""
    x, s, v = mean["displacement"], mean["slipping_time"], mean["velocity"]
    carried = _guide(mean["held_velocity"], window, dt, deriv=0)
    reg = [mean[k] for k in held_keys(mean) if k.startswith("registry_")]
    lagged = mean.get(LAGGED)
    segs = {name: [None] for name in ("decelerating", "accelerating", "whole")}
    for name, i in lags.items():
        segs[name] = [Segment(mean["impulse"][i] - mean["impulse"][i[0]], v[i],
                              s[i] - s[i[0]], x[i] - x[i[0]], carried[i] - carried[i[0]], mass,
                              np.maximum(s[i] - s[p], 0.0),
                              np.column_stack([r[i] - r[i[0]] for r in reg]) if reg else None,
                              None if lagged is None else lagged[i] - lagged[i[0]])]
    return segs


def fit_cycle_ensemble(time, spring_force, wall_velocity, table: CycleTable, *, mass: float,
                       drive_velocity: float = 0.0, mount_damping: float = 0.0,
                       wall_position=None, min_velocity_fraction: float = 0.2,
                       smoothing: float = SMOOTHING, comoving_mass: bool = False,
                       min_window_time: float = 0.0, film_mass: float | None = None,
                       registry_period: float | None = None) -> FilmForceFit:
    """The slip law of the mean of the slips of ``table`` (module text), errors by the
    jackknife over the slips; with ``registry_period``, beside the law a force periodic in
    the wall's position (:func:`held_slips`; where the slips span enough of it:
    :func:`fitted_registry_period`).

    Arguments as :func:`~filmfriction.analysis.slip_law.slip_law.fit_film_force` (the
    sampling must be uniform).  The slips in which the wall did not slip (the spring
    relaxed by less than :data:`~filmfriction.analysis.slip_law.slip_law.MIN_RELAXATION`
    of its force) are left out of the ensemble; at least :data:`MIN_CYCLES` slips must
    be left.  The per-slip arrays of the result hold the jackknife's pseudo-values, one
    per slip; ``smoothing_window`` is the window of the mean's velocity: ``smoothing`` of
    the median slip, and at least ``min_window_time`` (the time over which the film's
    noise stays correlated, :data:`MD_NOISE_TIME` for an MD run in LJ units; 0: none).
    The mean's velocity (from the mean displacement) sets the branches' split and the
    fitted lags, and the mean's held velocity, smoothed alike, is the m_c term's regressor
    (:func:`_segments`), so their noise biases the loop step (a window much shorter than the
    noise's correlation leaves them as noisy as their samples: on the Coulomb controls at
    the MD's noise, 8 slips, a loop step of +7.5 ε/σ with a window of 1.2 τ, +1.4 with 3 τ,
    measured with the displacement's derivative as the regressor).

    Raises
    ------
    ValueError
        Fewer than :data:`MIN_CYCLES` slips, or a sampling that is not uniform.
    """
    t, f, v, x = checked_fit_inputs(time, spring_force, wall_velocity, wall_position, mass,
                                    min_velocity_fraction=min_velocity_fraction,
                                    smoothing=smoothing)
    dt = uniform_step(t, "the cycle ensemble")
    y, s = np.asarray(table.yield_index, int), np.asarray(table.stick_index, int)
    keep = slipped(table)
    if keep.sum() < MIN_CYCLES:
        raise ValueError(f"{int(keep.sum())} slip(s) that relax the spring by "
                         f"{100 * MIN_RELAXATION:g} % or more: the cycle ensemble needs "
                         f"{MIN_CYCLES} or more")
    registry_period = fitted_registry_period(registry_period,
                                             np.asarray(table.slip_distance)[keep])
    held = held_slips(t, f, v, x, y[keep], s[keep], mount_damping=mount_damping,
                      drive_velocity=drive_velocity, registry_period=registry_period)
    if not (math.isfinite(min_window_time) and min_window_time >= 0):
        raise ValueError(f"min_window_time = {min_window_time!r}: must be >= 0 and finite")
    window = max(smoothing_samples(t, table, smoothing), int(math.ceil(min_window_time / dt)))
    window += (1 - window % 2) if window else 0
    fit = fit_held_ensemble(held, np.arange(int(keep.sum())), window=window, dt=dt, mass=mass,
                            min_velocity_fraction=min_velocity_fraction,
                            comoving_mass=comoving_mass, replicas="slips", film_mass=film_mass)
    return replace(fit, registry_period=registry_period)


def fit_held_ensemble(held: dict, groups, *, window: int, dt: float, mass: float,
                      min_velocity_fraction: float = 0.2, comoving_mass: bool = False,
                      replicas: str = "slips", film_mass: float | None = None) -> FilmForceFit:
    """The fit of the mean of held slips (:func:`held_slips`' arrays, shape (slips, lags)),
    the errors by the jackknife over the groups of slips that ``groups`` labels (one label
    per slip: each slip its own for one run, the run for slips pooled over runs) — the
    means that leave one group out, G − 1 degrees of freedom.  ``window``: the mean's
    velocity's smoothing in samples of ``dt``; ``replicas`` names the groups; ``film_mass``
    the film's own mass (None: not known), the most a co-moving mass can be."""
    groups = np.asarray(groups)
    labels = list(dict.fromkeys(groups.tolist()))
    if len(labels) < 2:
        raise ValueError(f"{len(labels)} group(s) of slips: the jackknife needs 2 or more")
    n = groups.size
    # the peak and the fitted lags are the whole ensemble's, for its fit and for the
    # jackknife's (the errors are the data's, not a re-selection's)
    p, peak, lags = _selection(_guide(held["displacement"].mean(axis=0), window, dt), window,
                               min_velocity_fraction)
    ranges = [(min_velocity_fraction * peak, peak) if lags else (math.nan, math.nan)]

    keys = held_keys(held)
    total = {k: held[k].sum(axis=0) for k in keys}

    def fit(mean):
        segs = _segments(mean, window, dt, p, lags, mass)
        return fit_segments(segs, ranges, mass=mass, comoving_mass=comoving_mass,
                            smoothing_window=window, film_mass=film_mass)

    loo = []
    for g in labels:
        out = groups == g
        loo.append(fit({k: (total[k] - held[k][out].sum(axis=0)) / (n - int(out.sum()))
                        for k in keys}))
    return jackknife_fit(fit({k: total[k] / n for k in keys}), loo, mass=mass,
                         replicas=replicas, film_mass=film_mass)
