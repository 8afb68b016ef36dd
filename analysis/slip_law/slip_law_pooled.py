"""The slip law of several runs of one scene pooled: the mean of all their slips, errors by
the jackknife over the runs.

One driven run of the heavy slider holds 7–10 slips, too few for the slip-law test to
have power (docs/results/slip-law.md, "Controls at the heavy slider's scale": Klein's
viscous slips read ``viscous`` in 22 of 200 runs of 8 slips, in 186 of 200 of 30), and
runs of one scene that differ only in their seed differ by more than the jackknife over
each run's slips says (their exponents scatter with χ² 36 over 5 degrees of freedom:
docs/results/mass-ladder.md).  Runs of one scene (the same slider mass, spring, drive,
mount dashpot and sampling) are replicas of one experiment: their slips, each aligned
at its yield and held at its end (:func:`~filmfriction.analysis.slip_law.slip_law_cycles.held_slips`),
are one ensemble, whose mean obeys the law as each slip does (the integrated equation of
motion is linear).  The mean of all the slips is fitted as one slip
(:func:`~filmfriction.analysis.slip_law.slip_law_cycles.fit_held_ensemble`), and the
errors are the jackknife's over the runs, the means that leave one run out (G − 1
degrees of freedom for G runs): whatever makes runs differ — their yield forces, the
film's state after each start-up, which slips the detector took — enters the errors,
which the jackknife over slips, treating the slips as independent, leaves out.  The
verdict and its power follow from those errors as for one run.

The controls at the heavy slider's scale check it
(:mod:`~filmfriction.analysis.groundtruth.pooled_controls`, ``python
benchmarks/slip_law/pooled_controls_rates.py``; docs/results/slip-law.md, "Runs pooled").

Example
-------
Three noise-free runs of a Coulomb + viscous slider (F_k = 20, B = 15) pooled give the
law back:

>>> from filmfriction.analysis.groundtruth.random_force import slide
>>> from filmfriction.reduced_model.cycles import cycle_table
>>> runs = []
>>> for f0 in (30.0, 33.0, 36.0):
...     r = slide("coulomb-viscous", (20.0, 15.0), mass=30.0, stiffness=2.0,
...               drive_velocity=0.1, static_force=48.0, armed_below=34.0, initial_force=f0,
...               stop_velocity=0.15, duration=700.0, dt=0.25)[0]
...     tab = cycle_table(r["time"], r["spring_force"], r["yield_index"], r["stick_index"],
...                       spring_constant=2.0)[1:]
...     runs.append(RunSlips(r["time"], r["spring_force"], r["wall_velocity"], tab,
...                          wall_position=r["wall_position"]))
>>> fit = fit_pooled_ensemble(runs, mass=30.0, drive_velocity=0.1)
>>> round(fit.kinetic_force, 2), round(fit.damping, 2), fit.law.slips
(20.0, 15.0, 3)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from filmfriction.reduced_model.cycles import CycleTable

from .slip_law import MIN_RELAXATION, SMOOTHING, FilmForceFit, checked_fit_inputs
from .slip_law_cycles import (fit_held_ensemble, fitted_registry_period, held_keys, held_slips,
                              slipped, uniform_step)

__all__ = ["RunSlips", "fit_pooled_ensemble", "MIN_RUNS", "JACKKNIFE"]

#: The fewest runs pooled: the jackknife over runs has G − 1 degrees of freedom.
MIN_RUNS = 3
#: The replicas of the jackknife: the runs, or the slips as if they were one run's.
JACKKNIFE = ("runs", "slips")


@dataclass(frozen=True)
class RunSlips:
    """One run's trace and its analysed slips (the start-up slip left out): the time,
    the spring force, the wall's velocity (and position: the integral of the velocity
    when None), the slips' table; ``name`` says which run in errors."""

    time: np.ndarray
    spring_force: np.ndarray
    wall_velocity: np.ndarray
    table: CycleTable
    wall_position: np.ndarray | None = None
    name: str = ""


def _held(run: RunSlips, i: int, *, mass, drive_velocity, mount_damping,
          min_velocity_fraction, smoothing,
          registry_period=None, viscous_lag=None) -> tuple[dict, float, np.ndarray]:
    """The run's slips held at their ends, its sampling interval and its slips' durations
    (ValueError naming the run when its sampling is not uniform or no slip is left)."""
    name = run.name or f"run {i + 1}"
    try:
        t, f, v, x = checked_fit_inputs(run.time, run.spring_force, run.wall_velocity,
                                        run.wall_position, mass,
                                        min_velocity_fraction=min_velocity_fraction,
                                        smoothing=smoothing)
    except ValueError as err:
        raise ValueError(f"{name}: {err}") from None
    dt = uniform_step(t, f"{name}: the pooled slips")
    tab = run.table
    y, s = np.asarray(tab.yield_index, int), np.asarray(tab.stick_index, int)
    keep = slipped(tab)
    if not keep.any():
        raise ValueError(f"{name}: no slip relaxes the spring by {100 * MIN_RELAXATION:g} % "
                         f"or more ({len(tab)} in its table)")
    held = held_slips(t, f, v, x, y[keep], s[keep], mount_damping=mount_damping,
                      drive_velocity=drive_velocity, registry_period=registry_period,
                      viscous_lag=viscous_lag)
    return held, dt, t[s[keep]] - t[y[keep]]


def fit_pooled_ensemble(runs, *, mass: float, drive_velocity: float = 0.0,
                        mount_damping: float = 0.0, min_velocity_fraction: float = 0.2,
                        smoothing: float = SMOOTHING, comoving_mass: bool = False,
                        min_window_time: float = 0.0, jackknife: str = "runs",
                        film_mass: float | None = None,
                        registry_period: float | None = None,
                        viscous_lag: float | None = None) -> FilmForceFit:
    """The slip law of the mean of the slips of ``runs`` (module text), errors by the
    jackknife over the runs.

    Parameters
    ----------
    runs : sequence of RunSlips
        :data:`MIN_RUNS` or more runs of one scene, sampled at one interval.
    mass, drive_velocity, mount_damping, min_velocity_fraction, smoothing, comoving_mass, min_window_time
        As for :func:`~filmfriction.analysis.slip_law.slip_law_cycles.fit_cycle_ensemble`
        (the runs share them); the window is ``smoothing`` of the median slip of all runs.
    film_mass : float, optional
        The film's own mass (the runs share it; None: not known), the most a co-moving
        mass can be (:func:`~filmfriction.analysis.slip_law.slip_law_verdict.choose_law`).
    jackknife : {"runs", "slips"}
        The jackknife's replicas: the runs (the errors), or each slip on its own (as if
        the slips were one run's: the comparison that leaves the runs' differences out).
    registry_period : float, optional
        The period λ of the walls' registry along the slide (the runs' wall positions
        share its origin): a force periodic in the wall's position, of
        :data:`~filmfriction.analysis.slip_law.slip_law_cycles.REGISTRY_HARMONICS`
        harmonics, is fitted beside the law where the median slip spans two periods
        (:func:`~filmfriction.analysis.slip_law.slip_law_cycles.fitted_registry_period`;
        None: none).
    viscous_lag : float, optional
        τ_r of a film whose viscous force lags the shear rate, dψ/dt = (B·v − ψ)/τ_r from
        ψ = 0 at each yield: B's regressor is then ∫v_f dt
        (:func:`~filmfriction.analysis.slip_law.slip_law_cycles.held_slips`), τ_r given,
        not fitted (a profile over τ_r: ``benchmarks/slip_law/viscous_lag_profile.py``).
        None: the viscous force B·v.

    Returns
    -------
    FilmForceFit
        The mean's fit; its errors, verdict and power the jackknife's over the runs (the
        per-slip arrays hold one pseudo-value per run, ``slips`` counts the runs).

    Raises
    ------
    ValueError
        Fewer than :data:`MIN_RUNS` runs, runs sampled at different intervals, a run with
        no slip that relaxes the spring.
    """
    runs = list(runs)
    if jackknife not in JACKKNIFE:
        raise ValueError(f"jackknife = {jackknife!r}: one of {', '.join(JACKKNIFE)}")
    if len(runs) < MIN_RUNS:
        raise ValueError(f"{len(runs)} run(s): pooling needs {MIN_RUNS} or more (the "
                         "jackknife over runs)")
    if not (math.isfinite(min_window_time) and min_window_time >= 0):
        raise ValueError(f"min_window_time = {min_window_time!r}: must be >= 0 and finite")
    for name, value in (("registry_period", registry_period), ("viscous_lag", viscous_lag)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r}: a time or period > 0, finite, or None")
    registry_period = fitted_registry_period(
        registry_period, np.concatenate([np.asarray(r.table.slip_distance)[slipped(r.table)]
                                         for r in runs]))
    parts = [_held(r, i, mass=mass, drive_velocity=drive_velocity, mount_damping=mount_damping,
                   min_velocity_fraction=min_velocity_fraction, smoothing=smoothing,
                   registry_period=registry_period, viscous_lag=viscous_lag)
             for i, r in enumerate(runs)]
    dt = parts[0][1]
    for i, (_, d, _) in enumerate(parts):
        if not math.isclose(d, dt, rel_tol=1e-6):
            raise ValueError(f"{runs[i].name or f'run {i + 1}'} is sampled every {d:g}, "
                             f"{runs[0].name or 'run 1'} every {dt:g}: pooled runs share "
                             "one sampling")
    lags = max(h["impulse"].shape[1] for h, _, _ in parts)
    held = {k: np.concatenate([np.pad(h[k], ((0, 0), (0, lags - h[k].shape[1])), mode="edge")
                               for h, _, _ in parts])
            for k in held_keys(parts[0][0])}
    groups = (np.concatenate([np.full(h["impulse"].shape[0], i) for i, (h, _, _) in
                              enumerate(parts)])
              if jackknife == "runs" else np.arange(held["impulse"].shape[0]))
    durations = np.concatenate([d for _, _, d in parts])
    # smoothing_samples' rule (odd, >= 5 samples, else none) on the median slip of all runs
    window = int(round(smoothing * float(np.median(durations)) / dt)) if smoothing > 0 else 0
    window += 1 - window % 2
    window = max(window if 5 <= window < lags else 0, int(math.ceil(min_window_time / dt)))
    window += (1 - window % 2) if window else 0
    fit = fit_held_ensemble(held, groups, window=window, dt=dt, mass=mass,
                            min_velocity_fraction=min_velocity_fraction,
                            comoving_mass=comoving_mass, replicas=jackknife,
                            film_mass=film_mass)
    return replace(fit, registry_period=registry_period, viscous_lag=viscous_lag)
