"""``filmfriction report RUN_DIR... [--out FILE]``: the study report (HTML + Markdown).

Computes the calibration and the SFB check (with the MD-calibrated rows)
from the run directories and writes ``report.html`` (self-contained) and
``report.md`` (with ``report-*.png``) into the first run directory, or to
``--out`` and next to it.
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["register", "run"]


def register(subparsers) -> None:
    """Add the ``report`` sub-command."""
    p = subparsers.add_parser(
        "report", help="write the study report (HTML with embedded figures + Markdown twin)",
        description="Scene, stick-slip trace, energy partition, viscosity, film structure, calibrated "
                    "model, SFB comparison, cost and provenance of one or several runs.")
    p.add_argument("run_dirs", nargs="+", type=Path, metavar="RUN_DIR",
                   help="run directories (the first is the main run; several give the rate law) "
                        "or finished sweep directories (a sweep section and their runs)")
    p.add_argument("--out", type=Path, default=None, metavar="FILE",
                   help="HTML file to write (default RUN_DIR/report.html; the .md goes next to it)")
    p.set_defaults(func=run)


def run(args) -> int:
    """Entry point; returns the exit code."""
    from filmfriction.workflows.cli import UserError
    from filmfriction.workflows.report import build_report

    for d in args.run_dirs:
        if not (d / "trace.csv").exists() and not (d / "aggregate.json").exists():
            raise UserError(f"{d}: neither a run directory (trace.csv) nor a finished sweep "
                            "(aggregate.json)")
    if args.out is not None and not args.out.parent.is_dir():
        raise UserError(f"--out {args.out}: directory {args.out.parent} does not exist")
    try:
        path = build_report(args.run_dirs, out=args.out)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    print(f"report: {path}")
    print(f"markdown: {path.with_suffix('.md')}")
    return 0
