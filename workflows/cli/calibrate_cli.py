"""``filmfriction calibrate RUN_DIR... [--json]``: fit the reduced model to MD runs.

Writes ``calibration.json`` (and the replay's trace, ``calibration_replay.csv``)
into the first run directory and prints the fitted parameters (in the runs' units:
LJ for MD runs, SI for a measured trace analysed with ``--units si``; ± one
standard error), the replay's errors and the MD calibration handed to the SFB
check; ``--json`` prints the document.  The calibration itself is
:func:`filmfriction.analysis.calibrate`.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

from filmfriction.workflows.inputs import UserError

__all__ = ["register", "run", "format_calibration"]


def register(subparsers) -> None:
    """Add the ``calibrate`` sub-command."""
    p = subparsers.add_parser(
        "calibrate", help="fit the reduced model (static/kinetic force, film damping, rate law) to MD runs",
        description="Calibrate the spring-block model (Coulomb static/kinetic + viscous film + the "
                    "MD mount dashpot) on one or several run directories, replay the MD trace with "
                    "it, and write calibration.json into the first run directory.")
    p.add_argument("run_dirs", nargs="+", type=Path, metavar="RUN_DIR",
                   help="run directories (trace.csv + run.json), finished sweeps "
                        "(aggregate.json) or directories of analysed trace files "
                        "(analysis.json); several runs give the shear-rate law")
    p.add_argument("--json", action="store_true", help="print calibration.json")
    p.add_argument("--out", type=Path, default=None, metavar="FILE.json",
                   help="where to write calibration.json, its folder created if missing "
                        "(default: in the first run directory; the replay's trace goes "
                        "beside it)")
    p.set_defaults(func=run)


def _fmt(e) -> str:
    if e is None:
        return "-"
    err = "" if e.stderr is None or not math.isfinite(e.stderr) else f" ± {e.stderr:.2g}"
    if e.at_bound and math.isfinite(e.limit):
        return f"{e.value:.4g} {e.units} (at bound; below {e.limit:.2g} {e.units} at 95 %)"
    return f"{e.value:.4g}{err} {e.units}" + (" (at bound)" if e.at_bound else "")


def format_calibration(cal) -> str:
    """Human-readable summary of a :class:`filmfriction.analysis.calibration.calibrate.Calibration`:
    an MD run's (LJ units) or a measured trace's (SI units, "trace" for "MD")."""
    from filmfriction.analysis.files.trace import unit
    from filmfriction.analysis.files.util import format_pm

    source = "MD" if cal.units == "lj" else "trace"
    out = []
    for r in cal.runs:
        out.append(f"{r.run.run_dir}: {r.regime}, {r.run.n_slips} slips")
        for name in ("static_force", "kinetic_force", "restick_force", "first_yield_force",
                     "film_damping", "eta_eff", "shear_rate", "ageing"):
            out.append(f"  {name:18s} {_fmt(getattr(r, name))}")
        if r.replay is not None:
            for q, e in r.replay.errors.items():
                if q == "backward_force":
                    continue
                rel = e["rel_error"]
                out.append(f"  replay {q:12s} {source} {e['md']:.4g}, model {e['model']:.4g}, error "
                           + ("-" if rel is None or not math.isfinite(rel) else f"{rel:+.1%}"))
        for k, v in r.failures.items():
            out.append(f"  not computed: {k}: {v}")
    if cal.rate_law is not None:
        law = cal.rate_law
        out.append(f"rate law: eta_eff = {law.prefactor:.3g} * rate^({law.exponent:.3f} ± "
                   f"{law.exponent_stderr:.2g}) over {law.n} runs")
    md = cal.md_calibration
    if md is not None:
        stress, visc = unit(cal.units, "stress"), unit(cal.units, "viscosity")
        out.append(f"{source} film calibration ({cal.units.upper()} units): yield stress "
                   f"{format_pm(md.yield_stress, md.yield_stress_err)} {stress}, sliding stress "
                   f"{format_pm(md.sliding_stress, md.sliding_stress_err)} {stress}, eta0 "
                   f"{format_pm(md.eta_zero, md.eta_zero_err)} {visc}, "
                   f"n = {md.thinning_exponent:.3g}")
    for k, v in cal.failures.items():
        out.append(f"not computed: {k}: {v}")
    out += [f"note: {n}" for n in cal.notes]
    return "\n".join(out)


def run(args) -> int:
    """Entry point; returns the exit code."""
    from filmfriction.analysis import calibrate, write_calibration

    from filmfriction.workflows.rundir import checked_runs

    # a sweep contributes its stick-slip runs (aggregate.json: calibration_runs)
    run_dirs = checked_runs(args.run_dirs, args.out)
    from filmfriction.analysis.calibration.calibrate import REPLAY_TRACE_SUFFIX
    from filmfriction.workflows.outputs import check_output, is_project_json, names_in

    if run_dirs:
        # a sweep's runs are inputs too: the calibration goes into the first
        sources = [*args.run_dirs, *run_dirs]
        out = Path(run_dirs[0]) / "calibration.json"
        check_output(out, "calibration.json", inputs=sources, ours=is_project_json)
        check_output(out.with_name(out.stem + REPLAY_TRACE_SUFFIX), "calibration.json",
                     inputs=sources, ours=names_in(out), what="its replay trace")
    try:
        cal = calibrate(run_dirs)
    except ValueError as exc:
        raise UserError(str(exc)) from None
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
    path = write_calibration(cal, args.out)
    if args.json:
        sys.stdout.write(path.read_text())     # the document as written
    else:
        print(format_calibration(cal))
        print(f"calibration: {path}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    from filmfriction.workflows.cli.main import main
    sys.exit(main(["calibrate"] + sys.argv[1:]))
