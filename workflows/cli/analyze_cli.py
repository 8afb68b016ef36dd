"""``filmfriction analyze PATH``: analyse a run directory or a CSV trace."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from filmfriction.workflows.inputs import (check_input_file, check_run_json, check_writable,
                                          is_stream, read_stream_once, UserError)
from filmfriction.md_inputs.contract import ANALYSIS_FILE


def positive_number(text: str) -> float:
    """An argparse type: a finite number > 0."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not v > 0 or v == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number: {text!r}")
    return v


def _count(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if v < 0:
        raise argparse.ArgumentTypeError(f"{v}: must be 0 or more (slips left out)")
    return v


# Largest magnitude accepted in a trace: the analysis squares and sums values
# (variances, energies); beyond this they overflow to inf and the verdict is noise.
MAX_MAGNITUDE = 1e100


def _reading_options(args) -> None:
    """Check --column, --skip-rows, --comment and --log-run (one-line errors naming the
    option, its value and what is accepted); ``args`` gets their parsed values."""
    from filmfriction.analysis.files.column_spec import parse_column
    from filmfriction.analysis.files.lammps_log import parse_runs

    parsed = []
    for text in args.column:
        try:
            parsed.append(parse_column(text))
        except ValueError as exc:
            raise UserError(str(exc)) from None
    args.column = parsed
    if args.skip_rows is not None:
        try:
            n = int(args.skip_rows)
        except ValueError:
            n = -1
        if n < 0:
            raise UserError(f"--skip-rows {args.skip_rows}: give a whole number, 0 or more "
                            "(lines skipped before the header)")
        args.skip_rows = n
    for prefix in args.comment or ():
        if not prefix.strip() or prefix != prefix.strip():
            raise UserError(f"--comment {prefix!r}: give the text a comment line starts with, "
                            "e.g. '#' or '%' (no blanks)")
    if args.log_run is not None:
        try:
            parse_runs(args.log_run)
        except ValueError as exc:
            raise UserError(str(exc)) from None
        args.log_run = args.log_run.strip()


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "analyze", help="stick-slip events, energy partition, viscosity, structure",
        description="Analyse a run directory (trace.csv + run.json), a trace file "
                    "(a header line, then rows separated by commas, tabs, semicolons or "
                    "spaces; columns time, spring_force, optional drive_position, "
                    "wall_position, wall_velocity, gap, or the file's own names mapped with "
                    "--column, in their own units), a LAMMPS fix print / fix ave/time file "
                    "('# name ...' header) or a LAMMPS log (its thermo output, --log-run). "
                    "Rows with empty or NaN cells are dropped with a note. Writes "
                    "analysis.json, analysis_cycles.csv and analysis_trace.png (the trace "
                    "with its slips) next to the trace.")
    p.add_argument("path", type=Path, help="run directory, trace file, or the directory of an "
                                           "analysed trace file (its analysis.json)")
    p.add_argument("--column", action="append", default=[],
                   metavar="NAME=COLUMN[:UNIT]",
                   help="read the file's column COLUMN as NAME (time, spring_force, "
                        "drive_position, wall_position, wall_velocity, gap, ...), in UNIT when "
                        "given (SI with a prefix: uN, nm, ms, ...; Å, eV, kcal/mol; LJ: "
                        "epsilon/sigma, sigma, tau); repeat per column, e.g. --column "
                        "time=t:ms --column spring_force=F:uN")
    p.add_argument("--skip-rows", default=None, metavar="N",
                   help="skip the first N lines of the file (an instrument's metadata) before "
                        "the header")
    p.add_argument("--comment", action="append", default=None, metavar="TEXT",
                   help="lines starting with TEXT are comments (default '#'; given, only those "
                        "given); repeat for more, e.g. --comment '#' --comment '%%'")
    p.add_argument("--log-run", default=None, metavar="N",
                   help="a LAMMPS log: read its thermo run N (counted from 1), or N-M to join "
                        "runs N to M (a run in segments), N- to the last")
    p.add_argument("--json", action="store_true", help="also print the document")
    p.add_argument("--setup", type=Path, default=None, metavar="FILE.toml",
                   help="an SFB set-up (SI; as for 'filmfriction sfb --setup'): its spring "
                        "constant, mass, contact area, film thickness and drive velocity, "
                        "unless given below; implies --units si")
    p.add_argument("--spring-constant", type=positive_number, help="K of the drive spring")
    p.add_argument("--mass", type=positive_number, help="M of the driven wall/surface")
    p.add_argument("--area", type=positive_number, help="contact area A")
    p.add_argument("--thickness", type=positive_number, help="film thickness D")
    p.add_argument("--drive-velocity", type=positive_number, help="spring-end velocity V")
    p.add_argument("--units", choices=("lj", "si"), default=None,
                   help="unit system of the trace (default: run.json's, else lj)")
    p.add_argument("--skip", type=_count, default=None,
                   help="slips left out of the summaries (default: 1 when >= 3 slips)")
    p.add_argument("--no-structure", action="store_true",
                   help="skip the trajectory analyses")
    p.add_argument("--out", "--output", dest="output", type=Path, default=None,
                   metavar="FILE.json",
                   help="where to write analysis.json, its folder created if missing "
                        "(default: next to the trace; for a stream such as <(cmd), the "
                        "working directory); --output is an accepted alias")
    p.add_argument("--no-figure", action="store_true",
                   help="do not draw analysis_trace.png")
    p.add_argument("--whole-trace", action="store_true",
                   help="analyse every sample of a run even after its film changed state (by "
                        "default the analysis stops where the gap changed by half a layer for "
                        "good, a melted film: analysis.json film_state_change)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Entry point; a stream (``<(cmd)``, a FIFO) is read once into a private copy."""
    if not is_stream(args.path):
        check_input_file(args.path)
        return _analyze(args)
    import tempfile

    stream = args.path
    with tempfile.TemporaryDirectory(prefix="filmfriction-stream-") as folder:
        args.path = read_stream_once(stream, folder)
        if args.output is None:
            args.output = Path(ANALYSIS_FILE)
        return _analyze(args, stream=stream)


def _analyze(args: argparse.Namespace, stream: Path | None = None) -> int:
    import numpy as np

    from filmfriction.analysis.analyze import analyze, to_json, write_outputs
    from filmfriction.analysis.files.trace_reader import read_trace
    from filmfriction.analysis.files.trace_cache import BINARY_MIN_ROWS, write_binary_copy

    _reading_options(args)
    record = check_run_json(args.path) if args.path.is_dir() else None
    recorded = (record or {}).get("trace_parameters") or {}
    if recorded:
        # a run of `filmfriction run` is analysed with the parameters it ran with
        if args.setup is not None:
            raise UserError(f"--setup {args.setup}: {args.path} is an MD run directory, analysed "
                            "with the K, M, A, V of its run.json; --setup is for a trace file")
        for flag, name, value in (("--units", "units", args.units),
                                  ("--spring-constant", "spring_constant", args.spring_constant),
                                  ("--mass", "mass", args.mass), ("--area", "area", args.area),
                                  ("--thickness", "thickness", args.thickness),
                                  ("--drive-velocity", "drive_velocity", args.drive_velocity)):
            ran = recorded.get(name, "lj" if name == "units" else None)
            if value is not None and ran is not None and value != ran:
                raise UserError(f"{flag} {value}: {args.path} ran with {name} = {ran} (its "
                                f"run.json), and is analysed with it; leave {flag} out")
    if args.output is not None:
        check_writable(args.output, "--out")
    table = {}
    if args.setup is not None:
        from filmfriction.analysis.files.column_spec import trace_table
        from filmfriction.reduced_model.sfb.user_setup import load_setup

        try:
            setup = load_setup(args.setup)
            table = trace_table(args.setup)
        except ValueError as exc:
            raise UserError(f"--setup {exc}") from None
        if args.units == "lj":
            raise UserError(f"--units lj with --setup {args.setup}: a set-up is in SI units")
        args.units = "si"
        for flag, value in (("spring_constant", setup.spring_constant), ("mass", setup.mass),
                            ("area", setup.contact_area), ("thickness", setup.film_thickness),
                            ("drive_velocity", setup.drive_velocity)):
            if getattr(args, flag) is None:
                setattr(args, flag, value)
    # the set-up's [trace] table, then the command line (which wins, name by name)
    columns, units_of = {}, {}
    for name, (column, unit_) in (table.get("columns") or {}).items():
        columns[name] = column
        if unit_:
            units_of[name] = unit_
    given = {}
    for name, column, unit_ in args.column:
        shown = f"--column {name}={column}" + (f":{unit_}" if unit_ else "")
        if name in given and given[name] != (column, unit_):
            raise UserError(f"{shown}: {name} is already read from {given[name][0]!r}; give "
                            "each name once")
        given[name] = (column, unit_)
        columns[name] = column
        units_of.pop(name, None)
        if unit_:
            units_of[name] = unit_
    skip_rows = args.skip_rows if args.skip_rows is not None else table.get("skip_rows")
    comments = tuple(args.comment) if args.comment else table.get("comments")
    if units_of and args.units is None and not recorded:
        # the columns' units say the system: SI units -> si, LJ units -> lj
        from filmfriction.reduced_model.units import parse_unit

        systems = {parse_unit(u).system for u in units_of.values()}
        if len(systems) > 1:
            raise UserError("--column: units of SI and of LJ mixed ("
                            + ", ".join(f"{n}:{u}" for n, u in units_of.items())
                            + "); say which system the analysis is in with --units si or "
                              "--units lj (the others are converted with the OMCTS mapping)")
        args.units = systems.pop()
    if args.path.is_dir() and (args.skip_rows is not None or args.comment or args.log_run):
        flag = (f"--skip-rows {args.skip_rows}" if args.skip_rows is not None else
                f"--comment {args.comment[0]}" if args.comment else f"--log-run {args.log_run}")
        if record:
            raise UserError(f"{flag}: {args.path} is a run directory (its trace.csv is read "
                            "as written); give the file itself, e.g. "
                            f"{args.path / 'lammps.log'}")
    if not args.path.is_dir() and args.path.exists():
        beside = args.path.parent
        if (args.output is None and (beside / "run.json").is_file()
                and args.path.name != "trace.csv"):
            raise UserError(f"{args.path}: a file of the run directory {beside}, whose "
                            "analysis.json is of its trace.csv; give --out FILE.json for "
                            "this file's analysis")
    try:
        trace = read_trace(args.path, columns=columns, column_units=units_of,
                           skip_rows=skip_rows, comments=comments, log_run=args.log_run,
                           spring_constant=args.spring_constant,
                           mass=args.mass, area=args.area, thickness=args.thickness,
                           drive_velocity=args.drive_velocity, units=args.units)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    where = trace.path
    from filmfriction.analysis.files.trace import trace_column_names

    for name, column in trace.columns.items():
        if name not in trace_column_names():
            continue            # a column the analysis does not read
        big = np.abs(np.asarray(column, dtype=float)) > MAX_MAGNITUDE
        if big.any():
            first = int(np.flatnonzero(big)[0])
            raise UserError(f"{where}: column {name} has {int(big.sum())} values beyond "
                            f"±{MAX_MAGNITUDE:g} (first {float(column[first]):g} at data row "
                            f"{first + 2}): arithmetic on them overflows; rescale the trace")
    out = args.output or ((trace.run_dir or trace.path.parent) / ANALYSIS_FILE)
    check_writable(out, "output")
    # no output replaces an input, another run's file or a file not of the project
    from filmfriction.workflows.outputs import (any_of, check_output, head_has,
                                                is_project_json, names_in)

    flag = "--output" if args.output is not None else "output"
    sources = [args.path, trace.path, args.setup]
    check_output(out, flag, inputs=sources, ours=is_project_json)
    side = Path(out).with_name(Path(out).stem + "_cycles.csv")
    check_output(side, flag, inputs=sources, what="its cycles table",
                 ours=any_of(names_in(Path(out)), head_has(b"yield_index,stick_index,", 64)))
    if not args.no_figure:
        side = Path(out).with_name(Path(out).stem + "_trace.png")
        check_output(side, flag, inputs=sources, ours=names_in(Path(out)), what="its figure")
    try:
        doc, per_cycle = analyze(trace, skip=args.skip, structure=not args.no_structure,
                                 whole_trace=args.whole_trace)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    slips = doc.get("slips", {}).get("count", 0)
    if args.skip is not None and args.skip > 0 and args.skip >= slips:
        raise UserError(f"--skip {args.skip}: the trace has {slips} slips; give a value in "
                        f"[0, {slips})" if slips else
                        f"--skip {args.skip}: the trace has no slips; give --skip 0")
    layout = trace.layout
    if trace.run_dir is None and layout is not None:
        # the file as seen from analysis.json (not from this working directory), so that
        # `calibrate`/`report` of its directory find it from anywhere, --output elsewhere too
        import os

        doc["source"]["path"] = (str(stream) if stream is not None else
                                 os.path.relpath(Path(trace.path).resolve(),
                                                 Path(out).parent.resolve()))
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    if not args.no_figure:
        from filmfriction.analysis.trace_figure import write_trace_figure

        figure = Path(out).with_name(Path(out).stem + "_trace.png")
        write_trace_figure(trace, per_cycle.get("yield_index", []),
                           per_cycle.get("stick_index", []), figure)
        doc["figure"] = figure.name
    json_path, csv_path = write_outputs(doc, per_cycle, out)
    if (stream is None and layout is not None and not layout.binary and not trace.notes
            and len(trace) >= BINARY_MIN_ROWS):
        # long text traces: later reads (calibrate, report, analyze again) take the copy
        try:
            write_binary_copy(trace)
        except (OSError, ValueError):
            pass
    for warning in (doc.get("units_check") or {}).get("warnings", []):
        print(f"warning: {warning}", file=sys.stderr)
    if args.json:
        print(to_json(dict(doc, cycles_csv=csv_path.name)))
    else:
        note = f" ({doc['regime_note']})" if doc.get("regime_note") else ""
        names = [csv_path.name] + ([doc["figure"]] if "figure" in doc else [])
        print(f"{doc['regime']}{note}: {slips} slips; wrote {json_path}, {', '.join(names)}",
              file=sys.stdout)
        for key, why in doc["skipped"].items():
            print(f"  skipped {key}: {why}", file=sys.stdout)
    return 0
