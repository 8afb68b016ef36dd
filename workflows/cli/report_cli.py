"""``filmfriction report RUN_DIR... [--out FILE]``: the study report (HTML + Markdown).

Renders what the study wrote into the first run directory (``analysis.json``,
``calibration.json``, ``sfb.json``; ``filmfriction run`` writes them all) and
writes ``report.html`` (self-contained) and ``report.md`` (with
``report-*.png``) there, or to ``--out`` and next to it.  It computes none of
them: a missing one is said in the report and printed with the command that
makes it (for several runs or a sweep, ``filmfriction calibrate RUN_DIR...``
writes the calibration across them).
"""
from __future__ import annotations

from pathlib import Path

from filmfriction.workflows.inputs import check_run_source, check_writable, UserError
from filmfriction.md_inputs.contract import ANALYSIS_FILE, RUN_FILE

__all__ = ["register", "run"]


def register(subparsers) -> None:
    """Add the ``report`` sub-command."""
    p = subparsers.add_parser(
        "report", help="write the study report (HTML with embedded figures + Markdown twin)",
        description="Scene, stick-slip trace, energy partition, viscosity, film structure, calibrated "
                    "model, SFB comparison, cost and provenance of one or several runs. The report "
                    "renders what is in the first run directory and computes nothing: analysis.json "
                    "('filmfriction analyze RUN_DIR', required), calibration.json ('filmfriction "
                    "calibrate RUN_DIR...'; across several runs or a sweep, give them all) and "
                    "sfb.json ('filmfriction sfb --calibration RUN_DIR/calibration.json --out "
                    "RUN_DIR/sfb.json'; for a measured trace 'filmfriction sfb --setup MY_SFB.toml "
                    "--measured RUN_DIR --calibration ... --out ...'). 'filmfriction run' writes all three. A file that is "
                    "missing or out of date is said in the report and printed with the command "
                    "that makes it.")
    p.add_argument("run_dirs", nargs="+", type=Path, metavar="RUN_DIR",
                   help="run directories (the first is the main run, whose calibration.json and "
                        "sfb.json are rendered) or finished sweep directories (a sweep section "
                        "and their runs)")
    p.add_argument("--compare", nargs="+", type=Path, default=[], metavar="RUN_DIR",
                   help="other analysed runs set beside the main run in the similarity section "
                        "(their sfb.json similarity rows and their points on the lambda-zeta map); "
                        "not part of the calibration")
    p.add_argument("--out", type=Path, default=None, metavar="FILE",
                   help="HTML file to write, its folder created if missing (default "
                        "RUN_DIR/report.html; the .md goes next to it)")
    p.set_defaults(func=run)


def run(args) -> int:
    """Entry point; returns the exit code."""
    from filmfriction.workflows.report.render import build_report

    for d in args.compare:
        if not (d / ANALYSIS_FILE).is_file() or not (d / RUN_FILE).is_file():
            raise UserError(f"--compare {d}: not an analysed run directory (analysis.json and "
                            "run.json; 'filmfriction analyze RUN_DIR' writes the first)")
    for d in args.run_dirs:
        check_run_source(d)
    if args.out is not None and args.out.suffix.lower() not in (".html", ".htm"):
        raise UserError(f"--out {args.out}: the report is HTML: give a .html file name (its "
                        "Markdown twin is written beside it as .md)")
    out = args.out if args.out is not None else args.run_dirs[0] / "report.html"
    check_writable(out, "--out")
    from filmfriction.workflows.outputs import check_output, head_has
    from filmfriction.workflows.report.render import REPORT_HTML_MARK, REPORT_MD_MARK

    inputs = [*args.run_dirs, *args.compare]
    check_output(out, "--out", inputs=inputs, ours=head_has(REPORT_HTML_MARK))
    check_output(out.with_suffix(".md"), "--out", inputs=inputs, ours=head_has(REPORT_MD_MARK),
                 what="its Markdown twin")
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        path = build_report(args.run_dirs, out=args.out, log=print, compare=args.compare)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    print(f"report: {path}")
    print(f"markdown: {path.with_suffix('.md')}")
    return 0
