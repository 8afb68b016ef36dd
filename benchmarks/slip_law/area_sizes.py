"""The yield stress and the pooled slip law of one scene at several lateral areas.

    python benchmarks/slip_law/area_sizes.py LABEL=RUN_DIR... [LABEL=RUN_DIR...] [--json OUT]

Each group ``LABEL=DIR`` is a sweep over seeds (its ``points/*`` are the runs) or one run
directory; repeat a label to add runs to its group.  The groups are one scene at several box
sizes with the spring, the slider's mass and the preload scaled with the area, so that a film
whose friction is extensive reads the same per area in every group.  Per group, from each
run's ``run.json`` and ``analysis.json``:

- the area A (σ²) and the runs' slips;
- the first yield F_s1 (the start-up yield; ε/σ) and the later yields' mean, each over A:
  the yield stress (ε/σ³), mean ± standard error over the runs;
- the runs whose film changed state (``film_state_change``: a lasting change of the gap by
  half a layer or more, the analysis cut there) and the gap's change;
- the slips of all its runs pooled (:func:`~filmfriction.analysis.calibration.slip_law_runs.pooled_slip_law`,
  errors by the jackknife over the runs, the walls' registry fitted beside the law as
  ``filmfriction slip-law`` fits it): F_k/A, B over the run's no-slip bulk film's damping
  η_bulk·A/D (Bi of the law's viscous term), n, the loop step per area and the verdict.

Nothing is fitted to the sizes: the table says whether per-area numbers agree within their
errors (the film's friction is extensive at these sizes) or not.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from filmfriction.analysis.calibration.slip_law_runs import pooled_slip_law, to_document
from filmfriction.analysis.files.cycles_csv import read_cycles_csv


def _groups(items: list[str]) -> dict[str, list[Path]]:
    groups: dict[str, list[Path]] = {}
    for item in items:
        label, sep, path = item.partition("=")
        if not sep or not label or not path:
            sys.exit(f"area_sizes: {item!r}: give LABEL=RUN_DIR (a sweep or one run)")
        d = Path(path)
        runs = sorted(p for p in (d / "points").glob("*") if (p / "analysis.json").is_file()) \
            if (d / "points").is_dir() else [d]
        if not runs or not all((r / "analysis.json").is_file() for r in runs):
            sys.exit(f"area_sizes: {d}: no analysed runs (run.json + analysis.json) there")
        groups.setdefault(label, []).extend(runs)
    return groups


def _mean_se(values) -> tuple[float, float]:
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], float)
    if v.size == 0:
        return math.nan, math.nan
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(v.size)) if v.size > 1 else math.nan


def run_row(run: Path) -> dict:
    """One run: its area, yields and film state."""
    rj = json.loads((run / "run.json").read_text())
    aj = json.loads((run / "analysis.json").read_text())
    area = rj["trace_parameters"]["area"]
    yields = read_cycles_csv(run / aj["cycles_csv"]).get("static_force", []) \
        if aj.get("cycles_csv") else []
    first = float(yields[0]) if len(yields) else None
    later = aj.get("slips", {}).get("static_force", {}).get("mean")
    change = aj.get("film_state_change") or {}
    law = aj.get("slip_law", {})
    return {"run": str(run), "seed": rj["scene"]["parameters"].get("seed"), "area": area,
            "atoms": (rj.get("atoms") or {}).get("total"), "status": rj["status"],
            "slips": aj.get("slips", {}).get("count", 0),
            "first_yield": first, "later_yields_mean": later,
            "state_change_time": change.get("time"), "layers_gained": change.get("layers"),
            "bulk_film_damping": (law.get("bulk_film_damping") or {}).get("mean")}


def group_summary(label: str, runs: list[Path]) -> dict:
    rows = [run_row(r) for r in runs]
    area = rows[0]["area"]
    if any(abs(r["area"] - area) > 1e-6 * area for r in rows):
        sys.exit(f"area_sizes: group {label!r} mixes areas {sorted({r['area'] for r in rows})}")
    s1, s1e = _mean_se(r["first_yield"] for r in rows)
    sl, sle = _mean_se(r["later_yields_mean"] for r in rows)
    out = {"label": label, "area": area, "runs": len(rows), "atoms": rows[0]["atoms"],
           "slips": sum(r["slips"] for r in rows),
           "first_yield_stress": [s1 / area, s1e / area],
           "later_yield_stress": [sl / area, sle / area],
           "changed_state": sum(r["state_change_time"] is not None for r in rows),
           "per_run": rows}
    bulk = [r["bulk_film_damping"] for r in rows if r["bulk_film_damping"]]
    usable = [Path(r["run"]) for r in rows if r["slips"] >= 2]
    if len(usable) >= 3:
        doc = to_document(pooled_slip_law(usable, analyse=False))
        p = doc["pooled"]
        b_bulk = float(np.mean(bulk)) if bulk else math.nan

        def q(name, scale=1.0):
            x = p[name]
            return [None if x["mean"] is None else x["mean"] / scale,
                    None if x.get("stderr") is None else x["stderr"] / scale]
        out["pooled"] = {"runs": p["replicas"], "verdict": p["verdict"],
                         "verdict_from": p["verdict_from"],
                         "kinetic_stress": q("kinetic_force", area),
                         "damping_per_area": q("damping", area),
                         "damping_over_bulk": q("damping", b_bulk),
                         "bulk_film_damping": b_bulk, "exponent": q("exponent"),
                         "mean_stress": p["mean_force"]["mean"] / area,
                         "mean_slip_velocity": p["mean_slip_velocity"]["mean"],
                         "loop_step_stress": q("loop_step", area)}
    return out


def _pm(pair, fmt=".3f") -> str:
    m, e = pair
    if m is None or not math.isfinite(m):
        return "–"
    return f"{m:{fmt}}" + ("" if e is None or not math.isfinite(e) else f" ± {e:{fmt}}")


def table(groups: list[dict]) -> str:
    lines = ["| box | A (σ²) | atoms | runs, slips | film changed state | first yield F_s1/A (ε/σ³) "
             "| later yields F_s/A | F_k/A (ε/σ³) | B/A (m/(τσ²)) | B/B_bulk | n | loop step/A "
             "| v̄ (σ/τ) | verdict |",
             "|" + "---|" * 14]
    for g in groups:
        p = g.get("pooled")
        law = ("| " + " | ".join([_pm(p["kinetic_stress"]), _pm(p["damping_per_area"]),
                                  _pm(p["damping_over_bulk"], ".2f"),
                                  _pm(p["exponent"], ".2f"), _pm(p["loop_step_stress"]),
                                  f"{p['mean_slip_velocity']:.3f}",
                                  f"`{p['verdict']}` ({p['verdict_from']})"]) + " |") if p \
            else "| – | – | – | – | – | – | fewer than 3 runs with slips |"
        lines.append(f"| {g['label']} | {g['area']:.1f} | {g['atoms']} | {g['runs']}, {g['slips']} "
                     f"| {g['changed_state']} of {g['runs']} | {_pm(g['first_yield_stress'])} "
                     f"| {_pm(g['later_yield_stress'])} " + law)
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("groups", nargs="+", metavar="LABEL=RUN_DIR")
    ap.add_argument("--json", type=Path, default=None, metavar="OUT")
    args = ap.parse_args(argv)
    summaries = [group_summary(k, v) for k, v in _groups(args.groups).items()]
    print(table(summaries))
    for g in summaries:
        for r in g["per_run"]:
            if r["state_change_time"] is not None:
                print(f"{g['label']} seed {r['seed']}: film changed state at t = "
                      f"{r['state_change_time']:.1f} ({r['layers_gained']:+.2f} of a layer)")
    if args.json:
        args.json.write_text(json.dumps(summaries, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
