"""``filmfriction bench``: the scene's MD throughput beside bulk LJ
(:mod:`filmfriction.workflows.cost.bench`)."""
from __future__ import annotations

import argparse
import json

from ..cost.bench import as_text, run_bench
from ..inputs import check_ranks, parse_overrides, UserError
from ..md.lammps_build import resolve
from ..md.scene import SceneError, load


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "bench", help="the scene's MD throughput as 'run' runs it, beside bulk LJ",
        description="Time a scene as 'filmfriction run --md-only' runs it, on 1 core and on "
                    "--np cores, beside a bulk LJ liquid with the same atoms, cutoff, steps "
                    "and ranks. Runs alternate; prints median, spread and best in "
                    "Matom-step/s, the film/bulk ratio and the scaling from 1 core.")
    p.add_argument("scene", nargs="?", default="stick-slip",
                   help="scene name or TOML file (default: stick-slip)")
    p.add_argument("--np", type=int, default=2,
                   help="cores of the parallel runs (default 2); 1 core is always timed too")
    p.add_argument("--steps", type=int, default=None,
                   help="slide steps (default: the scene's own; equilibration as the scene)")
    p.add_argument("--repeat", type=int, default=3,
                   help="repetitions of each configuration, alternating (default 3)")
    p.add_argument("--omp", action="store_true",
                   help="also time the film on 1 MPI rank x NP OpenMP threads (-sf omp)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene parameter, as for 'run'")
    p.add_argument("--json", action="store_true", help="print the figures as JSON")
    p.set_defaults(func=main, writes=False)   # prints only (its runs in a temporary folder)


def main(args: argparse.Namespace) -> int:
    if args.steps is not None and args.steps < 1:
        raise UserError(f"--steps {args.steps}: need at least 1 slide step")
    if args.repeat < 1:
        raise UserError(f"--repeat {args.repeat}: need at least 1 repetition")
    check_ranks(args.np)
    try:
        overrides = parse_overrides(args.overrides)
        if args.steps is not None:
            overrides["slide_steps"] = args.steps
        scene = load(args.scene, overrides)
        resolve(None)            # a $FILMFRICTION_LMP that is no executable: before any run
    except SceneError as exc:
        raise UserError(str(exc)) from None
    progress = None if args.json or args.quiet else (lambda text: print(text, flush=True))
    try:
        report = run_bench(scene, args.np, args.repeat, args.omp, progress)
    except RuntimeError as exc:
        print(f"filmfriction bench: {exc}")
        return 1
    print(json.dumps(report, indent=2) if args.json else as_text(report))
    return 0
