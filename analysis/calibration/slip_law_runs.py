"""The slip law of several run directories pooled: ``filmfriction slip-law RUN_DIR…``.

Each run is read as its analysis read it (:func:`~filmfriction.analysis.calibration.rundata.load_run`:
the trace up to a change of the film's state, the analysed slips after the start-up ones),
the runs are checked to be replicas of one experiment (one slider mass, spring, drive,
mount dashpot, unit system and sampling), and their slips are fitted together
(:func:`~filmfriction.analysis.slip_law.slip_law_pooled.fit_pooled_ensemble`: the mean
of all slips, the jackknife over the runs).  The jackknife over the slips of the same mean
is computed beside it: the errors if the runs did not differ beyond their slips' noise.

Example
-------
>>> import tempfile, pathlib
>>> from filmfriction.analysis.groundtruth.synthetic import run_directory
>>> root = pathlib.Path(tempfile.mkdtemp())
>>> dirs = [run_directory(root / f"r{i}", trajectory=False, seed=i) for i in range(3)]
>>> pooled = pooled_slip_law(dirs)
>>> pooled.fit.law.slips, [r.slips for r in pooled.runs]
(3, [3, 3, 3])
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from filmfriction.reduced_model.cycles import cycle_table

from ..slip_law.slip_law import FilmForceFit
from ..slip_law.slip_law_cycles import MD_NOISE_TIME
from ..slip_law.slip_law_pooled import RunSlips, fit_pooled_ensemble
from ..slip_law.slip_law_stats import sigmas
from .rundata import load_run

__all__ = ["PooledRun", "PooledSlipLaw", "pooled_slip_law", "read_runs", "fit_arguments",
           "to_document", "SHARED", "SCHEMA"]

#: What the pooled runs must share (a run's trace parameter, or the sampling interval).
SHARED = ("units", "mass", "spring_constant", "drive_velocity", "mount_damping", "sampling",
          "film_mass", "registry_period")


@dataclass(frozen=True)
class PooledRun:
    """One pooled run: its directory, its analysed slips, its seed (None: not recorded)."""

    run_dir: Path
    slips: int
    seed: int | None


@dataclass(frozen=True)
class PooledSlipLaw:
    """The pooled fit (jackknife over runs), the same mean with the jackknife over slips,
    the runs, what they share (:data:`SHARED`) and the unit system."""

    fit: FilmForceFit
    by_slips: FilmForceFit
    runs: tuple
    shared: dict
    units: str


def _run_slips(run_dir, analyse: bool) -> tuple[RunSlips, dict, int | None]:
    run = load_run(run_dir, analyse=analyse)
    tr = run.trace
    p = tr.parameters
    t = tr.time
    if not tr.has("wall_velocity"):
        raise ValueError(f"{run.run_dir}: the trace has no wall_velocity column (the slip "
                         "law needs the wall's velocity)")
    if p.mass is None:
        raise ValueError(f"{run.run_dir}: no slider mass (the film force F_spring − M·a "
                         "needs it)")
    v_drive, _ = tr.drive_velocity()
    dt = float(np.median(np.diff(t))) if t.size > 1 else math.nan
    shared = {"units": tr.units, "mass": p.mass, "spring_constant": p.spring_constant,
              "drive_velocity": v_drive or 0.0, "mount_damping": p.mount_damping or 0.0,
              "sampling": dt, "film_mass": p.film_mass, "registry_period": p.registry_period}
    count = (run.analysis.get("slips") or {}).get("count")
    if isinstance(count, int) and len(run.cycles["yield_index"]) != count:
        raise ValueError(f"{run.run_dir}: analysis_cycles.csv holds "
                         f"{len(run.cycles['yield_index'])} slip(s), analysis.json {count}; "
                         f"analyse it again (filmfriction analyze {run.run_dir})")
    y, s = run.cycles["yield_index"][run.skip:], run.cycles["stick_index"][run.skip:]
    x = tr.wall_position()
    table = cycle_table(t, tr.spring_force, y, s, spring_constant=p.spring_constant,
                        wall_position=x)
    seed = tr.scene_parameter("seed")
    return (RunSlips(t, tr.spring_force, tr.columns["wall_velocity"], table,
                     wall_position=x, name=str(run.run_dir)),
            shared, seed if isinstance(seed, int) else None)


def _same(name: str, a, b) -> bool:
    if isinstance(a, str) or isinstance(b, str) or a is None or b is None:
        return a == b
    return math.isclose(float(a), float(b), rel_tol=1e-6, abs_tol=0.0)


def read_runs(run_dirs, *, analyse: bool = True) -> tuple[list, dict, tuple]:
    """The runs of ``run_dirs`` as the pooled fit takes them (their analysed slips), what
    they share (:data:`SHARED`, checked alike) and each one's :class:`PooledRun`; a run
    not analysed yet is analysed (and its ``analysis.json`` written), or with
    ``analyse=False`` refused (ValueError, as :func:`pooled_slip_law`)."""
    parts = [_run_slips(d, analyse) for d in run_dirs]
    if not parts:
        raise ValueError("no run to pool")
    first = parts[0][1]
    for rs, shared, _ in parts[1:]:
        for key in SHARED:
            if not _same(key, shared[key], first[key]):
                raise ValueError(f"{rs.name}: {key} = {shared[key]!r}, {parts[0][0].name}: "
                                 f"{first[key]!r}; pooled runs are replicas of one "
                                 f"experiment and share {', '.join(SHARED)}")
    info = tuple(PooledRun(Path(rs.name), len(rs.table), seed) for rs, _, seed in parts)
    return [rs for rs, _, _ in parts], dict(first), info


def fit_arguments(shared: dict) -> dict:
    """The keywords of :func:`~filmfriction.analysis.slip_law.slip_law_pooled.fit_pooled_ensemble`
    for runs that share ``shared`` (the MD noise's correlation time as the smoothing's
    floor in LJ units; the film's own mass and the walls' registry period, None where not
    known)."""
    return dict(mass=shared["mass"], drive_velocity=shared["drive_velocity"],
                mount_damping=shared["mount_damping"], film_mass=shared.get("film_mass"),
                registry_period=shared.get("registry_period"),
                min_window_time=MD_NOISE_TIME if shared["units"] == "lj" else 0.0)


def pooled_slip_law(run_dirs, *, analyse: bool = True, registry: bool = True,
                    viscous_lag: float | None = None) -> PooledSlipLaw:
    """The slip law of the runs in ``run_dirs`` pooled (module text); a run not analysed yet
    is analysed (and its ``analysis.json`` written), or with ``analyse=False`` refused;
    ``registry=False``: the law alone, without the walls' registry force beside it (the
    comparison; ``shared["registry_period"]`` is then None); ``viscous_lag`` τ_r (the runs'
    time unit): the film's viscous force lagging the shear rate by τ_r
    (:func:`~filmfriction.analysis.slip_law.slip_law_pooled.fit_pooled_ensemble`; recorded
    as ``shared["viscous_lag"]``).

    Raises
    ------
    ValueError
        A directory that is not an analysable run, a run without the wall's velocity or
        the slider's mass, runs that differ in one of :data:`SHARED` (which run, its
        value and the first run's), or what
        :func:`~filmfriction.analysis.slip_law.slip_law_pooled.fit_pooled_ensemble`
        refuses (fewer than three runs, a run with no slip).
    """
    runs, shared, info = read_runs(run_dirs, analyse=analyse)
    kw = fit_arguments(shared if registry else {**shared, "registry_period": None})
    fit = fit_pooled_ensemble(runs, **kw, viscous_lag=viscous_lag)
    by_slips = fit_pooled_ensemble(runs, **kw, jackknife="slips", viscous_lag=viscous_lag)
    # the document records the period the slips were fitted with (None: the law alone, as
    # asked or where the slips span too little of it) and the viscous force's lag
    shared = {**shared, "registry_period": fit.registry_period, "viscous_lag": fit.viscous_lag}
    return PooledSlipLaw(fit, by_slips, info, shared, shared["units"])


#: The schema of the pooled slip law's document.
SCHEMA = "filmfriction.slip_law_pooled/1"


def _law(fit: FilmForceFit, units: str) -> dict:
    """One fit's verdict and its law's terms, each with its error and unit."""
    from ..files.trace import unit
    from ..files.util import finite_or_none as num

    law = fit.law

    def q(value, stderr, kind, **more):
        return {"mean": num(value), "stderr": num(stderr), "units": unit(units, kind), **more}
    return {"verdict": fit.verdict, "verdict_from": fit.verdict_from, "reason": fit.reason,
            "replicas": law.slips, "dof": law.dof,
            "kinetic_force": q(law.kinetic_force, law.kinetic_force_stderr, "force",
                               sigmas=num(law.kinetic_sigmas)),
            "damping": q(law.damping, law.damping_stderr, "damping",
                         sigmas=num(law.damping_sigmas),
                         detectable=num(law.detectable_damping)),
            "exponent": {"mean": num(law.exponent), "stderr": num(law.exponent_stderr),
                         "units": "1"},
            "mean_force": q(law.mean_force, None, "force"),
            "mean_slip_velocity": q(law.mean_velocity, None, "velocity"),
            "viscous_share": num(law.viscous_share),
            "loop_step": q(fit.loop_step, fit.loop_step_stderr, "force",
                           sigmas=num(fit.loop_step_sigmas)),
            # the mean gap between the two branches' own lines (no co-moving mass taken out)
            "loop_force": q(fit.loop_force, fit.loop_force_stderr, "force",
                            sigmas=num(sigmas(fit.loop_force, fit.loop_force_stderr,
                                              law.dof)))}


def to_document(pooled: PooledSlipLaw) -> dict:
    """The pooled slip law as a JSON-ready dict (what ``filmfriction slip-law --out``
    writes)."""
    return {"schema": SCHEMA, "units": pooled.units,
            "runs": [{"run_dir": str(r.run_dir), "slips": r.slips, "seed": r.seed}
                     for r in pooled.runs],
            "slips": sum(r.slips for r in pooled.runs), "shared": pooled.shared,
            "pooled": _law(pooled.fit, pooled.units) | {"jackknife": "runs"},
            "jackknife_over_slips": _law(pooled.by_slips, pooled.units)
                                    | {"jackknife": "slips",
                                       "note": "the same mean, its errors as if the slips "
                                               "were one run's: leaves the runs' differences "
                                               "out (a comparison, not the verdict)"},
            "method": "the mean of all the runs' slips, each aligned at its yield and held at "
                      "its end, fitted as one slip (F_film = F_k + B v on each branch, the "
                      "one law with a co-moving mass; where shared.registry_period is known, "
                      "with a force periodic in the wall's position beside the law, two "
                      "harmonics of that period: the walls' registry; where shared.viscous_lag "
                      "is given, the viscous force B v_f with v_f the velocity relaxed to "
                      "over that time from 0 at each yield); errors, verdict and power by "
                      "the jackknife over the runs"}
