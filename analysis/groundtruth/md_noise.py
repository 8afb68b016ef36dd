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

:func:`increment_rms` reads the wall's jitter without a fit: the rms of its velocity's
change over 0.25, 1 and 2 τ within the same windows.  A slip's own smooth change of
velocity is small at those lags, so it measures the random force's effect on the wall
whatever the law; the residual of the fit carries, besides the noise, whatever of the
slip's law F_k + B·v misses (with ``trend`` = 3 the slip-long part of that is fitted out).

:func:`run_slips` reads a run directory's analysed slips, :func:`replica_slips` makes the
random-force replicas of :mod:`~filmfriction.analysis.groundtruth.slip_law_controls` (one
control law, a noise process); both feed :func:`residuals` and :func:`slip_velocities`.
Slips shorter than ``min_samples`` after the edges are left out in both.

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

from ..slip_law.slip_law_cycles import registry_integrals

__all__ = ["slip_residuals", "residual_statistics", "common_shape_share", "slip_velocities", "increment_rms",
           "run_slips", "replica_slips", "residuals", "run_residuals", "replica_residuals",
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
                   trend: int = 1, registry_period: float | None = None) -> list[np.ndarray]:
    """The integral-form residual over M of each slip (module text), one array per slip
    long enough.  ``trend`` > 1 fits Δt², …, Δt^trend besides: what is left is the part of
    the residual faster than the slip's own shape (a law's misfit over the slip, or a noise
    slower than the slip, is taken out with it).  With ``registry_period`` λ the walls'
    registry force is fitted besides, as the slip-law fit fits it
    (:func:`~filmfriction.analysis.slip_law.slip_law_cycles.registry_integrals`): what is
    left is the noise beside a force periodic in the wall's position."""
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
        cols = [np.ones(i.size), dt, dx] + [dt ** k for k in range(2, trend + 1)]
        if registry_period is not None:
            cols += list(registry_integrals(t[i], x[i], registry_period).values())
        X = np.column_stack(cols)
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
    # a lag as long as a slip's residual has no pair in it: that slip leaves that lag out
    acf = np.array([[(r[:r.size - k] @ r[k:]) / (r @ r) if k < r.size else math.nan
                     for k in lags] for r in rs]).reshape(len(rs), len(lags))
    n = len(rs)

    def se(a):
        cols = [c[np.isfinite(c)] for c in np.atleast_2d(np.asarray(a).T)]
        return np.array([c.std(ddof=1) / math.sqrt(c.size) if c.size > 1 else math.nan
                         for c in cols])

    mean_acf = [float(c[np.isfinite(c)].mean()) if np.isfinite(c).any() else math.nan
                for c in acf.T]
    return {"slips": n, "rms": float(rms.mean()), "rms_stderr": float(se(rms)[0]),
            "per_slip_rms": rms.tolist(), "lags": list(lags),
            "autocorrelation": mean_acf,
            "autocorrelation_stderr": np.atleast_1d(se(acf)).tolist()}


def common_shape_share(residuals, points: int = 40) -> float:
    """The share of the residuals' variance that their mean shape carries: each slip's
    residual resampled on ``points`` equal parts of its own duration, averaged over the
    slips; a noise of zero mean leaves a share of order 1/slips, a shape every slip has
    (a law's misfit) a share of order 1."""
    grid = np.linspace(0.0, 1.0, points)
    rs = np.array([np.interp(grid, np.linspace(0.0, 1.0, r.size), r - np.mean(r))
                   for r in residuals])
    return float(np.mean(rs.mean(axis=0) ** 2) / np.mean(rs ** 2))


def slip_velocities(wall_velocity, yields, sticks, *, edge: int = EDGE,
                    min_samples: int = MIN_SAMPLES) -> list[np.ndarray]:
    """The wall's sampled velocity within each slip, the same windows as
    :func:`slip_residuals`."""
    v = np.asarray(wall_velocity, float)
    return [v[y + edge:s - edge] for y, s in zip(np.asarray(yields, int), np.asarray(sticks, int))
            if s - y - 2 * edge >= min_samples]


def increment_rms(velocities, lags=(1, 4, 8)) -> list[float]:
    """rms of the velocity's change over each lag (samples), pooled over the slips: how much
    the wall's motion jitters, read without a fit (a slip's own smooth change of velocity
    over 2 τ is a few hundredths of σ/τ at the controls' scale)."""
    out = []
    for k in lags:
        d = np.concatenate([v[k:] - v[:-k] for v in velocities if v.size > k])
        out.append(float(np.sqrt(np.mean(d ** 2))))
    return out


def run_slips(run_dir) -> dict:
    """A run directory's analysed slips as :func:`slip_residuals` takes them: its columns,
    ``yields``, ``sticks`` (the slips its analysis keeps), ``mass``, ``mount_damping``,
    ``drive_velocity``, ``registry_period`` (None where the walls' registry is not known)."""
    from ..calibration.rundata import load_run

    run = load_run(run_dir)
    tr, p = run.trace, run.trace.parameters
    vd, _ = tr.drive_velocity()
    return {"time": tr.time, "spring_force": tr.spring_force,
            "wall_velocity": tr.columns["wall_velocity"], "wall_position": tr.wall_position(),
            "yields": np.asarray(run.cycles["yield_index"])[run.skip:],
            "sticks": np.asarray(run.cycles["stick_index"])[run.skip:], "mass": p.mass,
            "mount_damping": p.mount_damping or 0.0, "drive_velocity": vd or 0.0,
            "registry_period": p.registry_period}


def replica_slips(noise: dict, *, law: str = "viscous", share: float | None = None,
                  replicas: int = 40, duration: float | None = 1500.0, seed: int = 0,
                  scale="klein", slips: int = 8, comoving_mass: float = 0.0,
                  corrugation: tuple[float, float, float] | None = None) -> list[dict]:
    """The random-force replicas of control ``law`` (or of slips of viscous ``share``:
    :func:`~filmfriction.analysis.groundtruth.slip_law_controls.coulomb_viscous`) with the
    film's random force of ``noise`` (the keywords of
    :func:`~filmfriction.analysis.groundtruth.random_force.slide`), as :func:`run_slips`
    gives a run (the start-up slip left out).  At ``scale`` (a name of
    :data:`~filmfriction.analysis.groundtruth.slip_law_controls.SCALES`; ``duration``
    None: long enough for ``slips`` slips) its mount dashpot and drive are the slips'; the
    film carries ``comoving_mass`` with the slipping wall (the fit's mass is the scale's).
    With ``corrugation`` = (ΔF, λ, φ) the mix of ``share`` carries the walls' registry force
    ΔF·sin(2π·x/λ + φ) and each replica is a run of
    :func:`~filmfriction.analysis.groundtruth.pooled_controls.pooled_runs` (its own yield
    force, as the MD's runs; ``duration`` not used)."""
    from .slip_law_controls import random_force_runs, scale_named

    sc = scale_named(scale)
    extra = {"mass": sc.mass} | ({"mount_damping": sc.mount_damping} if sc.mount_damping else {})
    if corrugation is not None:
        from .pooled_controls import pooled_runs

        rs, vd = pooled_runs(law, replicas, slips, share=share, scale=sc, noise=noise,
                             comoving_mass=comoving_mass, corrugation=corrugation, seed=seed)
        return [{"time": r.time, "spring_force": r.spring_force,
                 "wall_velocity": r.wall_velocity, "wall_position": r.wall_position,
                 "yields": np.asarray(r.table.yield_index),
                 "sticks": np.asarray(r.table.stick_index), "drive_velocity": vd} | extra
                for r in rs]
    runs, vd = random_force_runs(law, replicas, duration=duration, noise=noise, seed=seed,
                                 share=share, scale=sc, slips=slips,
                                 comoving_mass=comoving_mass)
    if sc.mount_damping:
        extra["drive_velocity"] = vd
    return [{k: tr[k] for k in ("time", "spring_force", "wall_velocity", "wall_position")}
            | {"yields": tr["yield_index"][1:], "sticks": tr["stick_index"][1:]} | extra
            for tr in runs]


def residuals(slips: dict, **kwargs) -> list[np.ndarray]:
    """:func:`slip_residuals` of a :func:`run_slips` or :func:`replica_slips` item."""
    keys = ("time", "spring_force", "wall_velocity", "wall_position", "yields", "sticks")
    opt = {k: slips[k] for k in ("mass", "mount_damping", "drive_velocity") if k in slips}
    return slip_residuals(*(slips[k] for k in keys), **opt, **kwargs)


def run_residuals(run_dir, **kwargs) -> list[np.ndarray]:
    """The residuals of a run directory's analysed slips (``kwargs`` to
    :func:`slip_residuals`)."""
    return residuals(run_slips(run_dir), **kwargs)


def replica_residuals(noise: dict, *, law: str = "viscous", share: float | None = None,
                      replicas: int = 40, seed: int = 0, **kwargs) -> list[np.ndarray]:
    """The residuals of :func:`replica_slips` (``kwargs`` to :func:`slip_residuals`)."""
    return [r for sl in replica_slips(noise, law=law, share=share, replicas=replicas, seed=seed)
            for r in residuals(sl, **kwargs)]
