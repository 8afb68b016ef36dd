"""The slip-law test's controls and power at the MD's noise (docs/results/slip-law.md).

    python benchmarks/slip_law/slip_law_power.py                 # verdict rates and the power
    python benchmarks/slip_law/slip_law_power.py --measure RUN   # the MD noise of a run directory

``--measure`` fits each analysed slip of RUN (its whole slip, F_k + B·v in the
integrated equation of motion) and prints how far the wall's velocity strays from
the fitted law's (rms) and the autocorrelation of that residual at 0.25, 1, 2, 4 τ
(:mod:`~filmfriction.analysis.groundtruth.md_noise`; the calibration of
:data:`filmfriction.analysis.groundtruth.film_noise.MD_NOISE` on it and on the
wall's jitter is ``benchmarks/slip_law/md_noise_calibration.py``).

Without it: for each control law (:data:`~filmfriction.analysis.groundtruth.slip_law_controls.CONTROLS`)
the verdicts of 40 noisy replicas at 4, 8 and 30 slips, at the MD's noise and at a
tenth of it (the noise a random force that moves the wall; with ``--injected`` added to
the noise-free law's trace); then the power, with the MD's noise as the random force
(:func:`~filmfriction.analysis.groundtruth.slip_law_controls.dynamical_fits` of ``share``):
the share of replicas of slips resisted by F_k + B·v (re-sticking as Klein's) whose B is
resolved (2 σ), the mean B against the truth and the median ``detectable_damping``,
against the viscous share.
"""
from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from filmfriction.analysis.groundtruth.md_noise import residual_statistics, run_residuals
from filmfriction.analysis.slip_law.slip_law import ONE_LAW, RESOLVED_SIGMAS, VERDICTS, sigmas
from filmfriction.analysis.groundtruth.film_noise import MD_NOISE, scaled
from filmfriction.analysis.groundtruth.slip_law_controls import (CONTROLS, control_fits,
                                                                 dynamical_fits)

REPLICAS = 40
QUIET = scaled(MD_NOISE, 0.1)


def measure(run_dir: Path) -> dict:
    """The integral-form residual of the run's analysed slips (whole slips;
    :func:`~filmfriction.analysis.groundtruth.md_noise.run_residuals`)."""
    s = residual_statistics(run_residuals(run_dir))
    return {"slips": s["slips"], "velocity_residual_rms": s["per_slip_rms"],
            "mean_rms": s["rms"], "mean_rms_stderr": s["rms_stderr"],
            "acf_at_lags_1_4_8_16": [round(a, 2) for a in s["autocorrelation"]]}


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
    print(f"\n## power at the MD noise (a random force moving the wall, {MD_NOISE}): share of "
          f"{REPLICAS} replicas with B resolved ({RESOLVED_SIGMAS:.3g} σ)")
    for slips in (8, 30):
        for share in (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0):
            fits = dynamical_fits("", REPLICAS, slips, share=share)
            hit = sum(sigmas(f.damping, f.damping_stderr, f.law.dof) >= RESOLVED_SIGMAS for f in fits)
            r = Counter(f.verdict for f in fits)
            one = sum(f.verdict_from == ONE_LAW for f in fits)
            truth = share * 28.0 / 0.55
            print(f"{slips:3d} slips, viscous share {share:.1f} (B {truth:.1f}): B resolved in "
                  f"{hit}/{REPLICAS}, B {np.mean([f.damping for f in fits]):.1f} ± "
                  f"{np.std([f.damping for f in fits], ddof=1) / np.sqrt(len(fits)):.1f}, "
                  f"detectable_damping {np.median([f.detectable_damping for f in fits]):.1f} "
                  f"(median); verdicts {dict(r)}; the one law's in {one}", flush=True)


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
