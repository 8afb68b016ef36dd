"""``filmfriction sfb``: the reduced model against Klein's SFB numbers.

    filmfriction sfb [--json] [--calibration FILE.json] [--run RUN_DIR] [--out sfb.json] [--sigma-nm S] [--epsilon-K E]

Prints the comparison table (name, Klein, model, ratio, units, source) and
the assumptions behind it; ``--json`` prints the rows as a JSON list instead.
``--calibration`` reads an :class:`filmfriction.reduced_model.MDCalibration` (LJ units) from
a JSON object with its field names, or the ``md_calibration`` of a
``calibration.json`` (``filmfriction calibrate``), and adds the ``md-calibrated``
rows; ``--sigma-nm`` / ``--epsilon-K`` override the OMCTS unit mapping used to
carry it to SI.  ``--run`` adds the ``similarity`` rows: the dimensionless
numbers of an analysed MD run beside Klein's.  ``--out`` also writes the check as the study does
(``sfb.json`` + ``sfb_slips.csv``), for ``filmfriction report`` to read.
The check itself is :func:`filmfriction.reduced_model.sfb_check`.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from filmfriction.reduced_model.units import OMCTS, LJUnits

__all__ = ["register", "run", "format_table"]


def register(subparsers) -> None:
    """Add the ``sfb`` sub-command."""
    p = subparsers.add_parser(
        "sfb", help="compare the reduced model with Klein's SFB stick-slip on OMCTS",
        description="Klein's SFB parameters (PRL 98, 056101) in the reduced model, each "
                    "quantity beside Klein's number with the ratio; optional MD-calibrated rows.")
    p.add_argument("--json", action="store_true", help="print the table as a JSON list")
    p.add_argument("--calibration", metavar="FILE.json", type=Path,
                   help="MD calibration to add md-calibrated rows: MDCalibration fields (LJ units) "
                        "or a calibration.json from 'filmfriction calibrate'")
    p.add_argument("--run", metavar="RUN_DIR", type=Path, default=None,
                   help="an analysed MD run (analysis.json + run.json): adds the similarity rows, "
                        "its dimensionless numbers beside Klein's")
    p.add_argument("--out", metavar="FILE.json", type=Path, default=None,
                   help="also write the check as the study does (e.g. RUN_DIR/sfb.json, with its "
                        "slips' traces beside it), for 'filmfriction report'")
    p.add_argument("--time-unit", choices=("mass", "viscosity"), default="mass",
                   help="the LJ time unit carried to SI: sigma*sqrt(m/eps) of the OMCTS molecule "
                        "(mass, default) or the one that maps the LJ liquid's eta onto OMCTS's "
                        "2.5 mPa s (viscosity; see docs/viscosity.md)")
    p.add_argument("--sigma-nm", type=float, default=None,
                   help=f"override sigma of the LJ->SI mapping (default {OMCTS.sigma * 1e9:g} nm)")
    p.add_argument("--epsilon-K", type=float, default=None,
                   help=f"override eps/k_B of the mapping (default {OMCTS.temperature:.1f} K)")
    p.set_defaults(func=run)


def _units(args) -> LJUnits:
    if getattr(args, "time_unit", "mass") == "viscosity":
        from filmfriction.workflows.cli import UserError
        if args.sigma_nm is not None or args.epsilon_K is not None:
            raise UserError("--time-unit viscosity: the matched mapping keeps OMCTS's sigma and "
                            "epsilon; --sigma-nm/--epsilon-K are accepted with --time-unit mass only")
        from filmfriction.reduced_model.units import OMCTS_VISCOSITY_MATCHED
        return OMCTS_VISCOSITY_MATCHED
    if args.sigma_nm is None and args.epsilon_K is None:
        return OMCTS
    from filmfriction.workflows.cli import UserError
    try:
        return LJUnits.from_molecule(
            sigma_nm=OMCTS.sigma * 1e9 if args.sigma_nm is None else args.sigma_nm,
            epsilon_over_kB=OMCTS.temperature if args.epsilon_K is None else args.epsilon_K,
            molar_mass_g=OMCTS.molar_mass_g, name="OMCTS (overridden)")
    except ValueError as exc:
        raise UserError(str(exc)) from None


def _calibration(path: Path | None):
    if path is None:
        return None
    from filmfriction.reduced_model import MDCalibration
    from filmfriction.workflows.cli import UserError
    from filmfriction.analysis.util import read_json_object

    try:
        data = read_json_object(path, f"cannot read calibration file {path}")
    except FileNotFoundError:
        raise UserError(f"calibration file {path} does not exist") from None
    except OSError as exc:
        raise UserError(f"cannot read calibration file {path}: {exc}") from None
    except ValueError as exc:
        raise UserError(str(exc)) from None
    if isinstance(data, dict) and str(data.get("schema", "")).startswith("filmfriction.calibration/"):
        # a calibration.json: its md_calibration is what the SFB check takes
        if data.get("md_calibration") is None:
            why = (data.get("failures") or {}).get("md_calibration", "no md_calibration in it")
            raise UserError(f"calibration file {path}: no MD calibration for the SFB check ({why})")
        data = data["md_calibration"]
    try:
        return MDCalibration.from_dict(data)
    except (ValueError, TypeError) as exc:
        raise UserError(f"calibration file {path}: {exc}") from None


def _fmt(value) -> str:
    if value is None:
        return "-"
    return f"{value:.3g}"


def format_table(rows, notes=()) -> str:
    """The rows as an aligned text table, then the notes as a numbered list."""
    header = ("quantity", "Klein", "model", "ratio", "model range", "units", "source")
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
    from filmfriction.workflows.cli import UserError

    if args.out is not None and not args.out.parent.is_dir():
        raise UserError(f"--out {args.out}: directory {args.out.parent} does not exist")
    if args.out is not None:
        from filmfriction.workflows.cli import check_writable

        check_writable(args.out, "--out")
    units = _units(args)
    calibration = _calibration(args.calibration)
    contact = None
    if args.run is not None:
        from filmfriction.analysis.contact import contact_from_run
        for name in ("analysis.json", "run.json"):
            if not (args.run / name).is_file():
                raise UserError(f"--run {args.run}: no {name} there (run 'filmfriction analyze "
                                f"{args.run}' on a run directory first)")
        try:
            contact = contact_from_run(args.run)
        except (ValueError, KeyError, TypeError) as exc:
            raise UserError(f"--run {args.run}: {exc}") from None
    try:
        check = sfb_check(calibration=calibration, units=units, contact=contact)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    path = None
    if args.out is not None:
        from filmfriction.workflows.documents import write_sfb
        path = write_sfb(check, args.out)
    if args.json:
        print(json.dumps(check.rows, indent=2, allow_nan=False))
        if path is not None:
            print(f"sfb check: {path}", file=sys.stderr)
        return 0
    print("SFB check: Klein, PRL 98, 056101 (2007), OMCTS, n = 4 layers "
          f"(K = {check.experiment.spring_constant:g} N/m, M = {check.experiment.mass * 1e3:g} g, "
          f"A = {check.experiment.contact_area:.2g} m2, D = {check.experiment.film_thickness * 1e9:g} nm, "
          f"eta_eff = {check.experiment.eta_eff:g} Pa s)")
    print()
    print(format_table(check.rows, check.notes))
    notes_by_row = [(r["name"], r["source"], r["note"]) for r in check.rows if r["note"]]
    print()
    print("Row notes:")
    for name, source, note in notes_by_row:
        print(f"  {name} [{source}]: {note}")
    if path is not None:
        print(f"\nsfb check: {path}")
    return 0
