"""``filmfriction ladder plan|run|collect``: the slider-mass ladder (the rungs and their
collection are :mod:`filmfriction.workflows.ladder`; each rung is one ``filmfriction sweep``)."""
from __future__ import annotations

import argparse
import fcntl
import json
import math
import sys
from pathlib import Path

from .. import ladder
from ..inputs import UserError, check_not_in_run, check_ranks, check_writable
from ..md.scene import SceneError
from ..progress import note
from ..sweep.jobs import profile_path
from ..sweep.plan import plan_sweep
from .sweep_cli import check_sweep_dir, main_sweep, uses_slurm

DEFAULT_ROOT = Path("sweeps/ladder")


def register(subparsers) -> None:
    """Add the ``ladder`` sub-command and its ``plan``, ``run`` and ``collect``."""
    p = subparsers.add_parser(
        "ladder", help="the slider-mass ladder: sweeps of the Klein-similar scene from "
                       "M = 30 to 2.4e6 m (plan, run, collect)",
        description=ladder.__doc__.split("\n\n")[0].replace("\n", " ")
        + " Each rung is one 'filmfriction sweep' over the seeds (Snakemake: local or Slurm).")
    # what it writes is named by its sub-commands (run --root, collect --out)
    p.set_defaults(writes=False)
    sub = p.add_subparsers(dest="ladder_command", metavar="plan|run|collect", required=True)
    a = sub.add_parser("plan", help="print the rungs, their sweep commands and their steps")
    a.add_argument("--steps-per-second", type=float, default=None, metavar="R",
                   help="also print each run's time at R steps per second (a rate you "
                        "measured; nothing is timed here)")
    a.add_argument("--root", type=Path, default=DEFAULT_ROOT,
                   help=f"the ladder's directory, one sweep per rung (default {DEFAULT_ROOT})")
    a.set_defaults(func=main_plan)
    a = sub.add_parser("run", help="run the rungs' sweeps one after another (resumable)")
    a.add_argument("--root", type=Path, default=DEFAULT_ROOT,
                   help=f"the ladder's directory, one sweep per rung (default {DEFAULT_ROOT})")
    a.add_argument("--np", type=int, default=1,
                   help="MPI ranks per run, and the sweep's --cores: one run at a time "
                        "(default 1)")
    a.add_argument("--profile", default=None,
                   help="Snakemake profile of every sweep: 'slurm', 'local' or a directory")
    a.add_argument("--lmp", metavar="PATH", default=None,
                   help="the LAMMPS executable of every run (as for 'filmfriction sweep')")
    a.add_argument("--dry-run", action="store_true",
                   help="list the jobs each sweep would run, run nothing")
    a.set_defaults(func=main_run)
    a = sub.add_parser("collect", help="the rungs' results, seeds combined, as a table")
    a.add_argument("--root", type=Path, default=DEFAULT_ROOT,
                   help=f"the ladder's directory (default {DEFAULT_ROOT})")
    a.add_argument("--out", "--output", "--json", dest="out", type=Path, default=None,
                   metavar="FILE", help="also write the rungs as JSON (schema "
                                        "filmfriction.mass-ladder/1)")
    a.set_defaults(func=main_collect)


def main_plan(args: argparse.Namespace) -> int:
    rate = args.steps_per_second
    if rate is not None and not (math.isfinite(rate) and rate > 0):
        raise UserError(f"--steps-per-second {rate:g}: give a positive rate (steps per "
                        "second, as measured)")
    for r in ladder.RUNGS:
        steps = f"{r.slide_steps} slide steps"
        if r.step_factor != 1:
            steps += f" (the cost model's {r.model_steps} × {r.step_factor:g})"
        cost = (f", {r.run_steps / rate / 60:.0f} min at {rate:g} steps/s" if rate else "")
        measured = " (measured)" if r.measured_slip_velocity is not None else ""
        print(f"{r.name}: V = {r.drive_velocity:g}, γ = {r.mount_damping:g}, v̄_slip ≈ "
              f"{r.slip_velocity_estimate:.2g}{measured}, {r.slips} slips, {steps}, "
              f"{r.run_steps} steps a run{cost}"
              + (" (not in the campaign: over 30 min a run on 2 cores)" if r.planned else ""))
        print("    " + " ".join(ladder.sweep_command(r, ladder.SEEDS, args.root)))
    runs, steps = ladder.campaign_steps()
    cost = f", {steps / rate / 3600:.1f} h at {rate:g} steps/s" if rate else ""
    print(f"campaign ('filmfriction ladder run'): {runs} runs, {steps} steps{cost}; the "
          "wall time is the steps over a rate measured on the machine that runs them")
    return 0


def _stages_checked(args: argparse.Namespace) -> list:
    """Every stage's sweep, validated before the first one runs: (rung, seeds, out)."""
    profile = profile_path(args.profile) if args.profile else None
    if args.np < 1 or not uses_slurm(profile):
        check_ranks(args.np, more="; a ladder on Slurm (--profile slurm) may ask for more")
    check_writable(args.root, "--root", directory=True)
    check_not_in_run(args.root, "--root")
    stages = []
    for rung, seeds in ladder.STAGES:
        out = Path(args.root) / rung.name
        check_sweep_dir(out)
        try:
            plan_sweep(ladder.SCENE, ["seed=" + ",".join(map(str, seeds))], rung.sets(),
                       args.np)
        except SceneError as exc:
            raise UserError(f"rung {rung.name}: {exc}") from None
        stages.append((rung, seeds, out))
    return stages


def _wait_for_lock(sweep_dir: Path) -> None:
    """Wait until no sweep holds ``sweep_dir`` (e.g. one started by hand)."""
    lock = sweep_dir / ".sweep.lock"
    if not lock.exists():
        return
    with open(lock, "a") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            note(f"ladder: another sweep holds {sweep_dir}; waiting for it to end")
            fcntl.flock(fh, fcntl.LOCK_EX)
        fcntl.flock(fh, fcntl.LOCK_UN)


def main_run(args: argparse.Namespace) -> int:
    stages = _stages_checked(args)
    for rung, seeds, out in stages:
        _wait_for_lock(out)
        command = ladder.sweep_command(rung, seeds, args.root, args.np, args.profile)
        print("ladder:", " ".join(command), flush=True)
        sweep_args = argparse.Namespace(
            scene=ladder.SCENE, grid=["seed=" + ",".join(map(str, seeds))],
            overrides=rung.sets(), np=args.np, cores=args.np, out=out, profile=args.profile,
            lmp=args.lmp, calibration=None, dry_run=args.dry_run)
        code = main_sweep(sweep_args)
        if code == 130:
            print(f"ladder: interrupted in {rung.name}; run the same command again to resume",
                  file=sys.stderr)
            return 130
        if code:
            print(f"ladder: {rung.name} seeds {seeds}: exit {code} (going on)", flush=True)
    return 0


def main_collect(args: argparse.Namespace) -> int:
    root = Path(args.root)
    if not root.is_dir():
        raise UserError(f"--root {root}: no such directory (the ladder's, as given to "
                        "'filmfriction ladder run')")
    found = [r for r in ladder.RUNGS if (root / r.name / "sweep.json").is_file()]
    if not found:
        raise UserError(f"--root {root}: holds no rung's sweep (none of "
                        f"{', '.join(r.name for r in ladder.RUNGS)} has a sweep.json)")
    if args.out is not None:
        from ..outputs import check_output, is_project_json

        check_output(args.out, "--out", inputs=[root / r.name for r in found],
                     ours=is_project_json)
    rungs = []
    for r in found:
        got = ladder.collect_rung(root / r.name)
        got.update(mass=r.mass, drive_velocity=r.drive_velocity,
                   mount_damping=r.mount_damping, slide_steps=r.slide_steps)
        rungs.append(got)
    print(ladder.table(rungs))
    if args.out is not None:
        from filmfriction.analysis.files.util import write_atomic

        write_atomic(Path(args.out), json.dumps({"schema": "filmfriction.mass-ladder/1",
                                                 "rungs": rungs}, indent=1))
    return 0
