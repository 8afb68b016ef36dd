"""``filmfriction sfb``: the reduced model against Klein's SFB numbers.

    filmfriction sfb [--json] [--calibration FILE.json] [--run RUN_DIR] [--out sfb.json] [--sigma-nm S] [--epsilon-K E]
    filmfriction sfb --setup MY_SFB.toml --measured DIR [--calibration DIR/calibration.json] [--out sfb.json]

Prints the comparison table (name, Klein, model, ratio, units, source) and
the assumptions behind it; ``--json`` prints the rows as a JSON list instead.
``--calibration`` reads an :class:`filmfriction.reduced_model.MDCalibration` (LJ units) from
a JSON object with its field names, or the ``md_calibration`` of a
``calibration.json`` (``filmfriction calibrate``), and adds the ``md-calibrated``
rows; ``--sigma-nm`` / ``--epsilon-K`` override the OMCTS unit mapping used to
carry it to SI.  ``--run`` adds the ``similarity`` rows: the dimensionless
numbers of an analysed MD run beside Klein's.  ``--out`` also writes the check as the study does
(``sfb.json`` + ``sfb_slips.csv``), for ``filmfriction report`` to read.
``--setup`` / ``--measured`` run the check on one's own SFB set-up (a TOML file,
:func:`filmfriction.reduced_model.sfb.user_setup.load_setup`) and the slip of an analysed
SI trace (:func:`filmfriction.analysis.calibration.measured.measured_slip`); an SI calibration
(a measured trace's ``calibration.json``) is taken without any LJ mapping.
The check itself is :func:`filmfriction.reduced_model.sfb_check`
(:func:`filmfriction.reduced_model.sfb.user_setup.sfb_check_setup` with a set-up).
"""
from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

from filmfriction.reduced_model.units import OMCTS, LJUnits
from filmfriction.workflows.inputs import check_writable, UserError
from filmfriction.md_inputs.contract import ANALYSIS_FILE, RUN_FILE, SWEEP_FILE

__all__ = ["register", "run", "format_table"]


def register(subparsers) -> None:
    """Add the ``sfb`` sub-command."""
    p = subparsers.add_parser(
        "sfb", help="compare the reduced model with Klein's SFB stick-slip on OMCTS",
        description="Klein's SFB parameters (PRL 98, 056101) in the reduced model, each "
                    "quantity beside Klein's number with the ratio; optional MD-calibrated rows.")
    p.add_argument("--json", action="store_true", help="print the table as a JSON list")
    p.add_argument("--setup", metavar="FILE.toml", type=Path, default=None,
                   help="your own SFB set-up in SI units (spring_constant, mass, contact_area or "
                        "contact_radius, film_thickness, load, drive_velocity; each a number or "
                        "{value = ..., error = ...}); with --measured, the check runs on it "
                        "instead of Klein's, errors propagated (see docs/measured-traces.md)")
    p.add_argument("--measured", metavar="DIR", type=Path, default=None,
                   help="with --setup: the analysed SI trace (a directory with its analysis.json, "
                        "or the analysis.json) whose slip takes the place of Klein's numbers")
    p.add_argument("--calibration", metavar="FILE.json", type=Path,
                   help="MD calibration to add md-calibrated rows: MDCalibration fields (LJ units) "
                        "or a calibration.json from 'filmfriction calibrate'")
    p.add_argument("--run", metavar="RUN_DIR", type=Path, default=None,
                   help="an analysed MD run (analysis.json + run.json): adds the similarity rows, "
                        "its dimensionless numbers beside Klein's")
    p.add_argument("--out", metavar="FILE.json", type=Path, default=None,
                   help="also write the check as the study does (e.g. RUN_DIR/sfb.json, with its "
                        "slips' traces beside it), for 'filmfriction report'; its folder is "
                        "created if missing")
    p.add_argument("--time-unit", choices=("mass", "viscosity"), default="mass",
                   help="the LJ time unit carried to SI: sigma*sqrt(m/eps) of the OMCTS molecule "
                        "(mass, default) or the one that maps the LJ liquid's eta onto OMCTS's "
                        "2.5 mPa s (viscosity; see docs/viscosity.md)")
    from .analyze_cli import positive_number

    p.add_argument("--sigma-nm", type=positive_number, default=None,
                   help=f"override sigma of the LJ->SI mapping (default {OMCTS.sigma * 1e9:g} nm)")
    p.add_argument("--epsilon-K", type=positive_number, default=None,
                   help=f"override eps/k_B of the mapping (default {OMCTS.temperature:.1f} K)")
    p.set_defaults(func=run)


def _units(args) -> LJUnits:
    if getattr(args, "time_unit", "mass") == "viscosity":
        if args.sigma_nm is not None or args.epsilon_K is not None:
            raise UserError("--time-unit viscosity: the matched mapping keeps OMCTS's sigma and "
                            "epsilon; --sigma-nm/--epsilon-K are accepted with --time-unit mass only")
        from filmfriction.reduced_model.units import OMCTS_VISCOSITY_MATCHED
        return OMCTS_VISCOSITY_MATCHED
    if args.sigma_nm is None and args.epsilon_K is None:
        return OMCTS
    try:
        return LJUnits.from_molecule(
            sigma_nm=OMCTS.sigma * 1e9 if args.sigma_nm is None else args.sigma_nm,
            epsilon_over_kB=OMCTS.temperature if args.epsilon_K is None else args.epsilon_K,
            molar_mass_g=OMCTS.molar_mass_g, name="OMCTS (overridden)")
    except ValueError as exc:
        raise UserError(str(exc)) from None


def _calibration(path: Path | None):
    """The calibration file's MDCalibration and whether it is in SI (a measured trace's)."""
    if path is None:
        return None, False
    from filmfriction.reduced_model import MDCalibration
    from filmfriction.analysis.files.util import read_json_object

    if path.is_dir():
        raise UserError(f"--calibration {path}: a directory; give its calibration.json "
                        f"({path / 'calibration.json'}, from 'filmfriction calibrate {path}')")
    try:
        data = read_json_object(path, f"cannot read calibration file {path}")
    except FileNotFoundError:
        raise UserError(f"calibration file {path} does not exist") from None
    except OSError as exc:
        raise UserError(f"cannot read calibration file {path}: {exc}") from None
    except ValueError as exc:
        raise UserError(str(exc)) from None
    from filmfriction.analysis.files.documents import check_document

    calibration_json = str(data.get("schema", "")).startswith("filmfriction.calibration/")
    try:
        check_document(data, "calibration" if calibration_json else "md_calibration",
                       f"calibration file {path}")
    except ValueError as exc:
        raise UserError(str(exc)) from None
    if calibration_json:
        # a calibration.json: its md_calibration is what the SFB check takes
        if data.get("md_calibration") is None:
            why = (data.get("failures") or {}).get("md_calibration", "no md_calibration in it")
            raise UserError(f"calibration file {path}: no MD calibration for the SFB check ({why})")
        si = data.get("units") == "si"
        data = data["md_calibration"]
    else:
        si = False
    try:
        return MDCalibration.from_dict(data), si
    except (ValueError, TypeError) as exc:
        raise UserError(f"calibration file {path}: {exc}") from None


def _setup(args):
    """The set-up (--setup) and the measured slip (--measured), or (None, None)."""
    if args.setup is None and args.measured is None:
        return None, None
    if args.setup is None or args.measured is None:
        raise UserError("--setup FILE.toml and --measured DIR go together: the set-up of your "
                        "SFB and the analysed trace whose slip it measured")
    from filmfriction.analysis.calibration.measured import measured_slip
    from filmfriction.analysis.files.util import read_json_object
    from filmfriction.reduced_model.sfb.user_setup import load_setup

    try:
        setup = load_setup(args.setup)
    except ValueError as exc:
        raise UserError(f"--setup {exc}") from None
    doc_path = args.measured / ANALYSIS_FILE if args.measured.is_dir() else args.measured
    if not doc_path.is_file():
        raise UserError(f"--measured {args.measured}: no analysis.json there (run 'filmfriction "
                        "analyze TRACE_FILE --units si ...' first)")
    try:
        from filmfriction.analysis.files.documents import check_document

        doc = check_document(read_json_object(doc_path, f"--measured {doc_path}"), "analysis",
                             f"--measured {doc_path}")
        slip = measured_slip(doc, f"--measured {doc_path}")
    except ValueError as exc:
        raise UserError(str(exc)) from None
    # the analysis and the set-up must describe the same instrument
    used = (doc.get("source") or {}).get("parameters") or {}
    for key, value in (("spring_constant", setup.spring_constant), ("mass", setup.mass),
                       ("area", setup.contact_area), ("thickness", setup.film_thickness)):
        if used.get(key) is not None and abs(used[key] - value) > 1e-6 * abs(value):
            raise UserError(f"--setup {args.setup}: {key} {value:g} differs from the {used[key]:g} "
                            f"the analysis {doc_path} used; analyse with the set-up's values")
    return setup, slip


def _fmt(value) -> str:
    if value is None:
        return "-"
    return f"{value:.3g}"


def format_table(rows, notes=(), measured: str = "Klein") -> str:
    """The rows as an aligned text table (``measured`` heads the column of the
    experiment's numbers), then the notes as a numbered list."""
    header = ("quantity", measured, "model", "ratio", "model range", "units", "source")
    body = []
    for r in rows:
        unc = r.get("uncertainty")
        rng = "-" if not unc else f"{_fmt(unc[0])}..{_fmt(unc[1])}"
        body.append((r["name"], _fmt(r["klein"]), _fmt(r["model"]),
                     "-" if r["ratio"] is None else f"{r['ratio']:.3g}", rng, r["units"], r["source"]))
    widths = [max(len(line[i]) for line in [header] + body) for i in range(len(header))]
    out = ["  ".join(h.ljust(w) for h, w in zip(header, widths)),
           "  ".join("-" * w for w in widths)]
    out += ["  ".join(c.ljust(w) for c, w in zip(line, widths)).rstrip() for line in body]
    if notes:
        out.append("")
        out.append("Assumptions and readings:")
        out += [f"  {i}. {n}" for i, n in enumerate(notes, 1)]
    return "\n".join(out)


def run(args) -> int:
    """Entry point of ``filmfriction sfb``; returns the exit code."""
    from filmfriction.reduced_model import sfb_check

    if args.out is not None:
        check_writable(args.out, "--out")
        from filmfriction.workflows.outputs import (any_of, check_output, head_has,
                                                    is_project_json, names_in)
        from filmfriction.workflows.rundir import SFB_TRACES_SUFFIX

        sources = [args.calibration, args.setup, args.measured, args.run]
        if args.measured is not None and args.measured.is_dir():
            sources.append(args.measured / ANALYSIS_FILE)
        check_output(args.out, "--out", inputs=sources, ours=is_project_json)
        check_output(args.out.with_name(args.out.stem + SFB_TRACES_SUFFIX), "--out",
                     inputs=sources, what="its slips' traces",
                     ours=any_of(names_in(args.out), head_has(b"slip,time,x\n", 16)))
    units = _units(args)
    setup, slip = _setup(args)
    calibration, si = _calibration(args.calibration)
    if si:
        # a measured trace's calibration is SI already: no LJ mapping to apply
        if args.sigma_nm is not None or args.epsilon_K is not None or args.time_unit != "mass":
            raise UserError(f"--calibration {args.calibration}: an SI calibration (a measured "
                            "trace's); --sigma-nm, --epsilon-K and --time-unit map LJ units and "
                            "do not apply")
        from filmfriction.reduced_model.units import SI_IDENTITY
        units = SI_IDENTITY
    contact = None
    if args.run is not None:
        from filmfriction.analysis.calibration.contact import contact_from_run
        if not (args.run / RUN_FILE).is_file():
            sweep = (args.run / SWEEP_FILE).is_file()
            raise UserError(f"--run {args.run}: not a run directory of 'filmfriction run' (no "
                            "run.json)" + (f"; a sweep's runs are {args.run}/points/<point>"
                                           if sweep else ""))
        if not (args.run / ANALYSIS_FILE).is_file():
            raise UserError(f"--run {args.run}: no analysis.json there (run 'filmfriction "
                            f"analyze {args.run}' first)")
        try:
            contact = contact_from_run(args.run)
        except (ValueError, KeyError, TypeError) as exc:
            raise UserError(f"--run {args.run}: {exc}") from None
    try:
        if setup is not None:
            from filmfriction.reduced_model.sfb.user_setup import sfb_check_setup
            if contact is not None:
                raise UserError("--run (an MD run's similarity with Klein's contact) does not "
                                "apply with --setup")
            check = sfb_check_setup(setup, slip, calibration=calibration, units=units)
        else:
            check = sfb_check(calibration=calibration, units=units, contact=contact)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    path = None
    if args.out is not None:
        from filmfriction.workflows.rundir import write_sfb
        extra = None if setup is None else {"setup": setup.as_dict(),
                                            "measured": dataclasses.asdict(slip)}
        args.out.parent.mkdir(parents=True, exist_ok=True)
        measured = (None if args.measured is None else args.measured / ANALYSIS_FILE
                    if args.measured.is_dir() else args.measured)
        path = write_sfb(check, args.out, extra,
                         inputs={"calibration": args.calibration, "setup": args.setup,
                                 "measured": measured,
                                 "run analysis.json": None if args.run is None
                                 else args.run / ANALYSIS_FILE})
    if args.json:
        from filmfriction.workflows.rundir import measured_keys

        rows = check.rows if setup is None else measured_keys(
            {"rows": check.rows, "slips": {}})["rows"]   # keyed as sfb.json keys them
        print(json.dumps(rows, indent=2, allow_nan=False))
        if path is not None:
            print(f"sfb check: {path}", file=sys.stderr)
        return 0
    ex = check.experiment
    what = ("Klein, PRL 98, 056101 (2007), OMCTS, n = 4 layers" if setup is None else
            f"{setup.name}, the slip measured in {slip.source}")
    print(f"SFB check: {what} "
          f"(K = {ex.spring_constant:g} N/m, M = {ex.mass * 1e3:g} g, "
          f"A = {ex.contact_area:.2g} m2, D = {ex.film_thickness * 1e9:g} nm, "
          f"eta_eff = {ex.eta_eff:.3g} Pa s)")
    print()
    print(format_table(check.rows, check.notes, measured="Klein" if setup is None else "measured"))
    notes_by_row = [(r["name"], r["source"], r["note"]) for r in check.rows if r["note"]]
    print()
    print("Row notes:")
    for name, source, note in notes_by_row:
        print(f"  {name} [{source}]: {note}")
    if path is not None:
        print(f"\nsfb check: {path}")
    return 0
