"""``filmfriction slip-law RUN_DIR… [--no-registry] [--viscous-lag TAU] [--json] [--out FILE.json]``:
the slip law of runs pooled.

Runs of one scene that differ in their seed (or a finished sweep over seeds) are replicas
of one experiment: their slips are fitted together as one mean slip, and the errors, the
verdict and its power are the jackknife's over the runs
(:mod:`filmfriction.analysis.calibration.slip_law_runs`).  Prints the pooled law beside
the same mean with the jackknife over the slips; ``--out`` writes the document.
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from filmfriction.workflows.inputs import UserError

__all__ = ["register", "run", "format_pooled"]


def register(subparsers) -> None:
    """Add the ``slip-law`` sub-command."""
    p = subparsers.add_parser(
        "slip-law", help="the slip law (viscous, kinetic, mixed?) of several runs pooled",
        description="Fit Klein's slip equation F_film = F_k + B·v to the slips of several runs "
                    "of one scene (seeds) together: the mean of all their slips, errors, verdict "
                    "and power by the jackknife over the runs.")
    p.add_argument("run_dirs", nargs="+", type=Path, metavar="RUN_DIR",
                   help="three or more run directories of one scene (trace.csv + run.json), "
                        "or finished sweeps (aggregate.json) over seeds")
    p.add_argument("--no-registry", action="store_true",
                   help="fit the film's law alone, without the walls' registry force beside it "
                        "(by default fitted where the runs record its period: aligned walls)")
    p.add_argument("--viscous-lag", type=float, default=None, metavar="TAU",
                   help="the film's viscous force lagging the shear rate by TAU (the runs' time "
                        "unit: τ for MD runs), a Maxwell film relaxing from 0 at each yield "
                        "(default: B·v, no lag)")
    p.add_argument("--json", action="store_true", help="print the document")
    p.add_argument("--out", type=Path, default=None, metavar="FILE.json",
                   help="write the document there (its folder created if missing)")
    p.set_defaults(func=run)


def _row(name: str, law: dict) -> list[str]:
    def pm(q, fmt=".3g"):
        if q["mean"] is None:
            return "-"
        err = "" if q["stderr"] is None else f" ± {q['stderr']:.2g}"
        return f"{q['mean']:{fmt}}{err}"
    return [f"{name} ({law['replicas']} {law['jackknife']}, {law['dof']} dof):",
            f"  verdict          {law['verdict']} (from the {law['verdict_from']})",
            f"  F_k              {pm(law['kinetic_force'])} {law['kinetic_force']['units']}",
            f"  B                {pm(law['damping'])} {law['damping']['units']} (95 % power "
            f"for B >= {law['damping']['detectable'] or float('nan'):.3g})",
            f"  n = dlnF/dlnv    {pm(law['exponent'])}",
            f"  at F̄ = {law['mean_force']['mean'] or float('nan'):.3g} "
            f"{law['mean_force']['units']}, v̄ = "
            f"{law['mean_slip_velocity']['mean'] or float('nan'):.3g} "
            f"{law['mean_slip_velocity']['units']}",
            f"  why: {law['reason']}"]


def format_pooled(doc: dict) -> str:
    """The pooled document for people: the verdict first, then the runs."""
    out = _row("pooled, jackknife over runs", doc["pooled"])
    out += [""] + _row("the same mean, jackknife over slips (comparison)",
                       doc["jackknife_over_slips"])
    period = (doc.get("shared") or {}).get("registry_period")
    if period:
        out += ["", f"fitted beside the law: the walls' registry force, periodic in the wall's "
                    f"position with their lattice's period {period:g} (two harmonics)"]
    lag = (doc.get("shared") or {}).get("viscous_lag")
    if lag:
        from filmfriction.analysis.files.trace import unit

        out += ["", f"the viscous force lagging the shear rate by {lag:g} "
                    f"{unit(doc['units'], 'time')} (a Maxwell film "
                    f"relaxing from 0 at each yield): B is its steady coefficient"]
    out += ["", f"{len(doc['runs'])} runs, {doc['slips']} slips:"]
    out += [f"  {r['run_dir']}: {r['slips']} slips, seed {r['seed']}" for r in doc["runs"]]
    return "\n".join(out)


def run(args) -> int:
    """Entry point; returns the exit code."""
    from filmfriction.analysis.calibration.slip_law_runs import pooled_slip_law, to_document
    from filmfriction.analysis.files.util import json_safe, write_atomic
    from filmfriction.workflows.rundir import checked_runs

    lag = args.viscous_lag
    if lag is not None and not (math.isfinite(lag) and lag > 0):
        raise UserError(f"--viscous-lag {lag!r}: a relaxation time > 0 (the runs' time unit)")
    run_dirs = checked_runs(args.run_dirs, args.out)
    try:
        doc = to_document(pooled_slip_law(run_dirs, registry=not args.no_registry,
                                          viscous_lag=lag))
    except ValueError as exc:
        raise UserError(str(exc)) from None
    text = json.dumps(json_safe(doc), indent=2, ensure_ascii=False, allow_nan=False) + "\n"
    if args.out is not None:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(args.out, text)
    sys.stdout.write(text if args.json else format_pooled(doc) + "\n")
    return 0


if __name__ == "__main__":  # pragma: no cover
    from filmfriction.workflows.cli.main import main
    sys.exit(main(["slip-law"] + sys.argv[1:]))
