"""The MD's noise as the slip-law fit sees it, measured the same way on MD runs and on model replicas.

Within a slip, fit the integrated equation of motion with F_k + B·v,

    ∫F_spring dt − γ(Δx − V·Δt) − M·v = c + F_k·Δt + B·Δx + M·r,

over the whole slip less ``edge`` samples at each end (2.5 τ at the 0.25 τ sampling: the
yield and the re-stick are left out), γ the mount's damping.  The residual r (a velocity)
is what the law does not explain: on a slip whose law is F_k + B·v it is the velocity the
film's random force gives the wall, ∫ξ dt/M, less the part of it the fit takes up.  Its
root-mean-square per slip and its autocorrelation (each slip's, at lags of whole samples,
then averaged over the slips) are the numbers a noise model must reproduce when pushed
through the same fit (:func:`residual_statistics`).

:func:`run_residuals` measures them on a run directory (its analysed slips);
:func:`replica_residuals` on the random-force replicas of
:mod:`~filmfriction.analysis.groundtruth.slip_law_controls` (one control law, a noise
process).  Slips shorter than ``min_samples`` after the edges are left out in both.

Example
-------
A white residual has no autocorrelation beyond lag 0:

>>> rng = np.random.default_rng(0)
>>> s = residual_statistics([rng.normal(0, 0.5, 400) for _ in range(20)], lags=(1, 4))
>>> round(s["rms"], 1), [abs(a) < 0.05 for a in s["autocorrelation"]]
(0.5, [True, True])
"""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import cumulative_trapezoid

__all__ = ["slip_residuals", "residual_statistics", "run_residuals", "replica_residuals",
           "LAGS", "EDGE", "MIN_SAMPLES"]

#: The lags (in samples: 0.25, 1, 2 and 4 τ at the 0.25 τ sampling) the statistics report.
LAGS = (1, 4, 8, 16)
#: Samples left out at each end of a slip (the yield and the re-stick).
EDGE = 10
#: Fewest samples a slip keeps after the edges to be measured.
MIN_SAMPLES = 60


def slip_residuals(time, spring_force, wall_velocity, wall_position, yields, sticks, *,
                   mass: float, mount_damping: float = 0.0, drive_velocity: float = 0.0,
                   edge: int = EDGE, min_samples: int = MIN_SAMPLES,
                   trend: int = 1) -> list[np.ndarray]:
    """The integral-form residual over M of each slip (module text), one array per slip
    long enough.  ``trend`` > 1 fits Δt², …, Δt^trend besides: what is left is the part of
    the residual faster than the slip's own shape (a law's misfit over the slip, or a noise
    slower than the slip, is taken out with it)."""
    t, f, v, x = (np.asarray(a, float) for a in (time, spring_force, wall_velocity,
                                                 wall_position))
    imp = cumulative_trapezoid(f, t, initial=0.0)
    out = []
    for y, s in zip(np.asarray(yields, int), np.asarray(sticks, int)):
        i = np.arange(y + edge, s - edge)
        if i.size < min_samples:
            continue
        dt, dx = t[i] - t[i[0]], x[i] - x[i[0]]
        resp = imp[i] - imp[i[0]] - mount_damping * (dx - drive_velocity * dt) - mass * v[i]
        X = np.column_stack([np.ones(i.size), dt, dx] + [dt ** k for k in range(2, trend + 1)])
        out.append((resp - X @ np.linalg.lstsq(X, resp, rcond=None)[0]) / mass)
    return out


def residual_statistics(residuals, lags=LAGS) -> dict:
    """rms and autocorrelation of per-slip residuals: ``rms`` (the mean over the slips of
    each slip's rms) with ``rms_stderr`` (over the slips), ``per_slip_rms``,
    ``autocorrelation`` at ``lags`` (each slip's, Σ r_i r_{i+k} / Σ r_i², averaged over the
    slips) with ``autocorrelation_stderr``, and ``slips``."""
    rs = [np.asarray(r, float) - np.mean(r) for r in residuals]
    if not rs:
        raise ValueError("no slip long enough to measure a residual")
    rms = np.array([r.std() for r in rs])
    acf = np.array([[(r[:r.size - k] @ r[k:]) / (r @ r) for k in lags] for r in rs])
    n = len(rs)
    se = (lambda a: a.std(axis=0, ddof=1) / math.sqrt(n)) if n > 1 else (
        lambda a: np.full(np.shape(a)[1:], math.nan))
    return {"slips": n, "rms": float(rms.mean()), "rms_stderr": float(se(rms)),
            "per_slip_rms": rms.tolist(), "lags": list(lags),
            "autocorrelation": acf.mean(axis=0).tolist(),
            "autocorrelation_stderr": np.atleast_1d(se(acf)).tolist()}


def run_residuals(run_dir, **kwargs) -> list[np.ndarray]:
    """The residuals of a run directory's analysed slips (those its analysis keeps;
    ``kwargs`` to :func:`slip_residuals`)."""
    from ..calibration.rundata import load_run

    run = load_run(run_dir)
    tr, p = run.trace, run.trace.parameters
    vd, _ = tr.drive_velocity()
    return slip_residuals(tr.time, tr.spring_force, tr.columns["wall_velocity"],
                          tr.wall_position(), np.asarray(run.cycles["yield_index"])[run.skip:],
                          np.asarray(run.cycles["stick_index"])[run.skip:], mass=p.mass,
                          mount_damping=p.mount_damping or 0.0, drive_velocity=vd or 0.0,
                          **kwargs)


def replica_residuals(noise: dict, *, law: str = "viscous", share: float | None = None,
                      replicas: int = 40, duration: float = 1500.0, seed: int = 0,
                      **kwargs) -> list[np.ndarray]:
    """The residuals of the random-force replicas of control ``law`` (or of slips of viscous
    ``share``: :func:`~filmfriction.analysis.groundtruth.slip_law_controls.coulomb_viscous`)
    with the film's random force of ``noise`` (the keywords of
    :func:`~filmfriction.analysis.groundtruth.random_force.slide`), the start-up slip left
    out; ``kwargs`` to :func:`slip_residuals`."""
    from .random_force import slide
    from .slip_law_controls import SCALE, _dynamical_law

    args = _dynamical_law(law, share)
    args.pop("period")
    runs = slide(**args, mass=SCALE["mass"], stiffness=SCALE["spring_constant"],
                 duration=duration, dt=SCALE["dt"], replicas=replicas, seed=seed, **noise)
    out = []
    for tr in runs:
        out += slip_residuals(tr["time"], tr["spring_force"], tr["wall_velocity"],
                              tr["wall_position"], tr["yield_index"][1:],
                              tr["stick_index"][1:], mass=SCALE["mass"], **kwargs)
    return out
