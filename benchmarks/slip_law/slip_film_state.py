"""The film's state during the slips of MD runs, grouped by the slider's mass: how much it heats
and dilates, and where the shear sits.

    python benchmarks/slip_law/slip_film_state.py RUN… [--before 10]

For each analysed run (its ``analysis.json``, ``analysis_cycles.csv`` and ``trace.csv``) and
each of its analysed slips (yield → re-stick): the film's temperature and the walls' gap
averaged over the slip, less their means over ``--before`` τ before the yield (the slip's
heating and dilation; a mean, not a peak, which a 336-atom film's thermal noise would set);
and the run's ``shear_location`` (each plane's share of the wall's slip, averaged over its
slips).  Printed per slider mass M (the runs' ``source.parameters.mass``): runs, slips, the
mean temperature rise and dilation over the slips ± their standard errors, the median slip,
the planes' shares averaged over the runs (bottom wall → first layer … last layer → top
wall) and the runs' verdicts.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from collections import Counter, defaultdict
from pathlib import Path

import numpy as np

COLUMNS = ("time", "film_temperature", "gap")


def run_state(run: Path, before: float) -> dict:
    """One run's slips: their temperature rises, dilations and durations; its mass and
    shear planes."""
    analysis = json.loads((run / "analysis.json").read_text())
    trace = np.genfromtxt(run / "trace.csv", delimiter=",", names=True)
    cycles = np.genfromtxt(run / "analysis_cycles.csv", delimiter=",", names=True)
    t = trace["time"]
    if t.size < 2:
        raise ValueError(f"a trace of {t.size} sample(s)")
    w = max(1, int(round(before / (t[1] - t[0]))))
    rise, dilation, duration = [], [], []
    for i, j in zip(np.atleast_1d(cycles["yield_index"]).astype(int),
                    np.atleast_1d(cycles["stick_index"]).astype(int)):
        if i < w or j <= i or j >= t.size:
            continue
        for out, col in ((rise, "film_temperature"), (dilation, "gap")):
            x = trace[col]
            out.append(x[i:j + 1].mean() - x[i - w:i].mean())
        duration.append(t[j] - t[i])
    shear = analysis.get("shear_location") or {}
    return {"mass": float(analysis["source"]["parameters"]["mass"]), "rise": rise,
            "dilation": dilation, "duration": duration, "jump": shear.get("jump"),
            "location": shear.get("location", "none")}


def _mean(x) -> str:
    x = np.asarray(x, float)
    return f"{x.mean():.4f} ± {x.std(ddof=1) / math.sqrt(x.size):.4f}" if x.size > 1 else "–"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", type=Path, metavar="RUN")
    ap.add_argument("--before", type=float, default=10.0,
                    help="the reference window before each yield (τ)")
    a = ap.parse_args(argv)
    if not (math.isfinite(a.before) and a.before > 0):
        ap.error(f"--before {a.before}: a time > 0 (τ)")
    missing = [str(r) for r in a.runs if not all(
        (r / f).is_file() for f in ("analysis.json", "analysis_cycles.csv", "trace.csv"))]
    if missing:
        print("slip_film_state: not analysed runs (analysis.json, analysis_cycles.csv and "
              f"trace.csv needed; `filmfriction analyze RUN`): {', '.join(missing)}",
              file=sys.stderr)
        return 2
    by_mass = defaultdict(list)
    for r in a.runs:
        try:
            s = run_state(r, a.before)
        except (KeyError, ValueError, TypeError, IndexError) as exc:
            print(f"slip_film_state: {r}: not a run's analysis this reads (the slider's mass "
                  f"in analysis.json, a trace of time, film_temperature and gap): {exc!r}",
                  file=sys.stderr)
            return 1
        by_mass[s["mass"]].append(s)
    print("| M (m) | runs | slips | film temperature rise over the slip (ε/k) | gap's dilation "
          "(σ) | median slip (τ) | shear planes' shares (bottom → top) | shear location |\n"
          "|---|---|---|---|---|---|---|---|")
    for mass in sorted(by_mass):
        ss = by_mass[mass]
        get = lambda k: [x for s in ss for x in s[k]]      # noqa: E731
        jumps = [s["jump"] for s in ss if s["jump"]]
        planes = (", ".join(f"{x:.2f}" for x in np.mean(jumps, axis=0)) if jumps
                  and len({len(j) for j in jumps}) == 1 else "–")
        locs = ", ".join(f"{k} {n}" for k, n in Counter(s["location"] for s in ss).items())
        dur = get("duration")
        print(f"| {mass:g} | {len(ss)} | {len(get('rise'))} | {_mean(get('rise'))} | "
              f"{_mean(get('dilation'))} | {np.median(dur) if dur else math.nan:.0f} | "
              f"{planes} | {locs} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
