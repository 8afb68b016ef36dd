"""The slip-law test's controls and power at the MD's noise (docs/results/slip-law.md).

    python benchmarks/slip_law_power.py                 # verdict rates and the power
    python benchmarks/slip_law_power.py --measure RUN   # the MD noise of a run directory

``--measure`` fits each analysed slip of RUN (its whole slip, F_k + B·v in the
integrated equation of motion) and prints how far the wall's velocity strays from
the fitted law's (rms) and the autocorrelation of that residual: the numbers
behind :data:`filmfriction.analysis.groundtruth.slip_law_controls.MD_NOISE`.

Without it: for each control law (:data:`~filmfriction.analysis.groundtruth.slip_law_controls.CONTROLS`)
the verdicts of 40 noisy replicas at 4, 8 and 30 slips, at the MD's noise and at a
tenth of it (the noise a random force that moves the wall; with ``--injected`` added to
the noise-free law's trace); then the power (the noise added to the trace): the share of replicas of slips resisted by F_k + B·v
(re-sticking as Klein's) whose B is resolved (2 σ), against the viscous share.
"""
from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np
from scipy.integrate import cumulative_trapezoid

from filmfriction.analysis.slip_law.slip_law import ONE_LAW, VERDICTS, sigmas
from filmfriction.analysis.groundtruth.slip_law_controls import (CONTROLS, MD_NOISE, control_fits,
                                                                 coulomb_viscous, replica_fits)

REPLICAS = 40
QUIET = {k: (v if k == "velocity_correlation" else v / 10) for k, v in MD_NOISE.items()}


def measure(run_dir: Path) -> dict:
    """The integral-form residual of the run's analysed slips (whole slips)."""
    from filmfriction.analysis.calibration.rundata import load_run

    run = load_run(run_dir)
    tr, p = run.trace, run.trace.parameters
    t, f, v = tr.time, tr.spring_force, tr.columns["wall_velocity"]
    x = tr.wall_position()
    vd, _ = tr.drive_velocity()
    gm = p.mount_damping or 0.0
    imp = cumulative_trapezoid(f, t, initial=0.0)
    yi = np.asarray(run.cycles["yield_index"], int)[run.skip:]
    si = np.asarray(run.cycles["stick_index"], int)[run.skip:]
    rms, acf = [], np.zeros(41)
    for y, s in zip(yi, si):
        i = np.arange(y + 10, s - 10)       # 2.5 τ off the yield and the re-stick
        if i.size < 60:
            continue
        dt, dx = t[i] - t[i[0]], x[i] - x[i[0]]
        resp = imp[i] - imp[i[0]] - gm * (dx - (vd or 0.0) * dt) - p.mass * v[i]
        X = np.column_stack([np.ones(i.size), dt, dx])
        r = (resp - X @ np.linalg.lstsq(X, resp, rcond=None)[0]) / p.mass
        rms.append(float(r.std()))
        r = r - r.mean()
        a = np.array([r[:r.size - k] @ r[k:] for k in range(41)])
        acf += a / a[0]
    acf /= max(len(rms), 1)
    return {"slips": len(rms), "velocity_residual_rms": rms,
            "mean_rms": float(np.mean(rms)) if rms else None,
            "acf_at_lags_0_1_4_8_16": [round(float(acf[k]), 2) for k in (0, 1, 4, 8, 16)],
            "sample_interval": float(t[1] - t[0])}


def rates(injected: bool = False) -> None:
    for noise_name, noise in (("MD noise", MD_NOISE), ("a tenth of it", QUIET)):
        how = "added to the law's trace" if injected else "a random force moving the wall"
        print(f"\n## verdicts of {REPLICAS} replicas, {noise_name} ({how}): {noise}")
        for law, what in CONTROLS.items():
            for slips in (4, 8, 30):
                fits = control_fits(law, REPLICAS, slips, noise=noise, injected=injected)
                r = Counter(f.verdict for f in fits)
                shown = ", ".join(f"{k} {r[k]}" for k in VERDICTS if r[k])
                one = sum(f.verdict_from == ONE_LAW for f in fits)
                print(f"{law:10s} {slips:3d} slips: {shown}; the one law's in {one}   ({what})",
                      flush=True)


def power() -> None:
    print(f"\n## power at the MD noise: share of {REPLICAS} replicas with B resolved (2 σ)")
    for slips in (8, 30):
        for share in (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0):
            fits = replica_fits(coulomb_viscous(share, slips=slips), REPLICAS, slips=slips)
            hit = sum(sigmas(f.damping, f.damping_stderr, f.law.dof) >= 2 for f in fits)
            verdicts = {}
            for f in fits:
                verdicts[f.verdict] = verdicts.get(f.verdict, 0) + 1
            one = sum(f.verdict_from == ONE_LAW for f in fits)
            print(f"{slips:3d} slips, viscous share {share:.1f}: B resolved in {hit}/{REPLICAS}; "
                  f"verdicts {verdicts}; the one law's in {one}", flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--measure", metavar="RUN", help="print the MD noise of a run directory")
    ap.add_argument("--power-only", action="store_true", help="only the power scan")
    ap.add_argument("--rates-only", action="store_true", help="only the verdict rates")
    ap.add_argument("--injected", action="store_true",
                    help="the rates with the noise added to the law's trace (not moving the wall)")
    a = ap.parse_args(argv)
    if a.measure:
        print(json.dumps(measure(Path(a.measure)), indent=1))
        return 0
    if not a.power_only:
        rates(a.injected)
    if not a.rates_only:
        power()
    return 0


if __name__ == "__main__":
    sys.exit(main())
