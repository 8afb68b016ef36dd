"""``filmfriction tradeoff``: the cost and error of each numerical knob
(:mod:`filmfriction.workflows.cost.tradeoff`)."""
from __future__ import annotations

import argparse
import json
import sys
from datetime import datetime
from pathlib import Path

from ..cost.tradeoff import study
from ..cost.tradeoff_table import summary
from ..inputs import check_not_in_run, check_ranks, check_writable, UserError


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "tradeoff", help="cost and error of each numerical knob (timestep, cutoff, box, ...)",
        description="Run the stick-slip scene once per knob setting and tabulate the cost "
                    "and the error of the observables against each knob's reference, "
                    "with the statistical uncertainty of each error.")
    p.add_argument("--quick", action="store_true",
                   help="300 tau runs, few values (a few minutes on 2 cores)")
    p.add_argument("--json", action="store_true", help="print the rows as JSON on stdout")
    p.add_argument("--out", type=Path, default=None,
                   help="directory to create (default runs/tradeoff-<time>)")
    p.add_argument("--np", type=int, default=2, help="MPI ranks per run (default 2)")
    p.add_argument("--seeds", type=int, default=1,
                   help="runs per setting with successive seeds (default 1); with 2 or more "
                        "each error's uncertainty is the scatter over the runs, which one "
                        "run's slips can understate (N times the cost)")
    p.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    if args.np < 1:
        raise UserError(f"--np {args.np}: need at least 1 MPI rank")
    if not 1 <= args.seeds <= 100:
        raise UserError(f"--seeds {args.seeds}: allowed 1 to 100 runs per setting")
    out = args.out or Path("runs") / f"tradeoff-{datetime.now():%Y%m%d-%H%M%S}"
    if out.exists():
        raise UserError(f"{out} already exists: the study never overwrites; choose a new --out")

    check_ranks(args.np)
    check_writable(out, "--out", directory=True)
    check_not_in_run(out, "--out")
    stream = sys.stderr if args.json else sys.stdout
    # flushed: the progress lines must show while the study runs, even in a log file

    def log(msg):
        if not args.quiet:
            print(msg, file=stream, flush=True)
    try:
        rows = study(args.quick, out, args.np, log, args.seeds)
    except RuntimeError as exc:
        print(f"filmfriction tradeoff: {exc}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(rows, indent=1, allow_nan=False))
    else:
        print(summary(rows))
        print(f"table: {out / 'tradeoff.csv'}; figures: {out}/pareto_*.png")
    return 0
