"""The Snakefiles' jobs: ``python -m filmfriction.workflows.sweep point|analyse|aggregate|replica ...``."""
from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

from . import aggregate, analyse_point, load_aggregate, run_point, summary
from .jobs import interrupt


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
    r = sub.add_parser("replica")
    r.add_argument("study", type=Path)
    r.add_argument("index", type=int)
    r.add_argument("--slide-steps", type=int, required=True)
    r.add_argument("--np", type=int, required=True)
    r.add_argument("--launcher", default="mpiexec")
    r.add_argument("--lmp", default=None)
    r.add_argument("--done", type=Path, required=True)
    args = parser.parse_args(argv)
    # Snakemake stops jobs with SIGTERM or SIGINT: both become an interrupt, so the runner
    # stops its LAMMPS child (which runs in its own session) instead of leaving it behind
    signal.signal(signal.SIGTERM, interrupt)
    signal.signal(signal.SIGINT, interrupt)
    if args.job == "replica":
        from .replica_jobs import replica_main

        return replica_main(args)
    if args.job == "point":
        from ..md.runner import RunFailed

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
