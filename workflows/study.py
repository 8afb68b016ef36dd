"""The study that follows an MD run: analysis → calibration → SFB check → report.

The one place that chains the steps.  Each step writes its own file into the
run directory (``analysis.json``, ``calibration.json``, ``sfb.json``,
``report.html`` + ``report.md``) and the next reads what it needs; the report
only renders those files.  A step that fails is printed and recorded in the
report, and does not hide the others' results.
"""
from __future__ import annotations

import sys
import time
import traceback
from pathlib import Path

from filmfriction.analysis.analyze import analyse_run
from filmfriction.md_inputs.contract import ANALYSIS_FILE, CALIBRATION_FILE, SFB_FILE

from .rundir import write_sfb


def _step(name: str, failures: dict, fn, *args, **kwargs):
    """Run one step; on failure print and record the reason, return None."""
    try:
        return fn(*args, **kwargs)
    except Exception as exc:  # noqa: BLE001 -- one failed step must not stop the study
        failures[name] = f"{type(exc).__name__}: {exc}"
        print(f"{name}: FAILED: {failures[name]}", file=sys.stderr)
        if "--debug" in sys.argv:
            traceback.print_exc()
        return None


def _write_sfb(run_dir: Path, check) -> Path:
    return write_sfb(check, run_dir / SFB_FILE,
                     inputs={"calibration": run_dir / CALIBRATION_FILE})


def finish_study(run_dir: Path) -> int:
    """Run the post-MD steps on ``run_dir``; print where the results are.

    Returns 0 when the report was written (even if earlier steps failed and
    are recorded in it), 1 otherwise.
    """
    run_dir = Path(run_dir)
    failures: dict = {}
    t0 = time.perf_counter()

    from filmfriction.analysis.files.util import format_pm

    doc = _step("analysis", failures, analyse_run, run_dir)
    if doc is not None:
        s = doc["slips"]
        fs = s["static_force"]
        force = ("" if fs["mean"] is None else
                 f", static force {format_pm(fs['mean'], fs['stderr'])} {fs['units']}")
        print(f"analysis: {doc['regime']}, {s['count']} slips{force} -> "
              f"{run_dir / ANALYSIS_FILE}")

    from filmfriction.analysis import calibrate, write_calibration
    cal = _step("calibration", failures, calibrate, [run_dir])
    if cal is not None:
        path = _step("calibration (write)", failures, write_calibration, cal)
        rc = cal.main

        def value(e):       # "-" where the run gave none (no slips: nothing to fit)
            if e is None or e.value is None or e.value != e.value:
                return "-"
            return f"{e.value:.4g}" + (" (at bound)" if e.at_bound else "")
        print(f"calibration: F_s {value(rc.static_force)}, F_k {value(rc.kinetic_force)}, "
              f"B {value(rc.film_damping)}, η_eff {value(rc.eta_eff)}"
              + (f"; not computed: {', '.join(rc.failures)}" if rc.failures else "") + f" -> {path}")

    from filmfriction.analysis.calibration.contact import contact_from_run
    from filmfriction.reduced_model import sfb_check
    md = cal.md_calibration if cal is not None else None
    contact = _step("similarity", failures, contact_from_run, run_dir)
    check = _step("sfb", failures, sfb_check, md, contact=contact)
    if check is not None:
        path = _step("sfb (write)", failures, _write_sfb, run_dir, check)
        n_md = sum(r["source"] == "md-calibrated" for r in check.rows)
        n_sim = sum(r["source"] == "similarity" for r in check.rows)
        print(f"sfb check: {len(check.rows)} rows ({n_md} md-calibrated, {n_sim} similarity) "
              f"-> {path}")

    from .report.render import build_report
    path = _step("report", failures, lambda: build_report([run_dir], failures=dict(failures)))
    print(f"post-MD steps took {time.perf_counter() - t0:.1f} s"
          + (f"; failed: {', '.join(failures)}" if failures else ""))
    if path is None:
        return 1
    print(f"report: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(finish_study(Path(sys.argv[1])))
