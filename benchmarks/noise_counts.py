"""The slip detector's noise estimate and slip counts on noisy model traces.

    .venv/bin/python benchmarks/noise_counts.py [--per-cell 10] [--seed 2024]

Random blocks of every friction law (:mod:`filmfriction.analysis.groundtruth.cases`),
50 samples per slip, white or AR(1) (ρ = 0.9 per sample) noise of 0.3, 1, 3 and 10 % of
the force drop, ``per-cell`` cases per law, noise level and correlation, half LJ and
half SI; each trace's slips found by :func:`~filmfriction.analysis.stickslip.detect_slips`
as ``filmfriction analyze`` does.  Per noise level: the ratio of the noise the detector's
threshold is set from (the local estimate, or the cycle-to-cycle noise where that is
larger by more than ``CYCLE_NOISE_FACTOR``) to the true σ (median and range) and the traces whose slip count differs from
the model's.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

from filmfriction.analysis.groundtruth import cases as gt
from filmfriction.analysis.noise import CYCLE_NOISE_FACTOR
from filmfriction.analysis.stickslip import detect_slips

NOISE = (0.003, 0.01, 0.03, 0.1)
CORRELATION = (0.0, 0.9)


def one(case):
    """(the noise the threshold is set from / true σ, slips found, slips made)."""
    r = gt.simulate(case)
    tr = gt.truth(case, r)
    cols, _ = gt.sample(case, r, tr)
    ev = detect_slips(cols["time"], cols["spring_force"])
    drop = float(np.mean(tr.static_force[1:] - tr.backward_force[1:])) * gt._scale(case)["force"]
    used = ev.cycle_noise if ev.cycle_noise > CYCLE_NOISE_FACTOR * ev.noise else ev.noise
    return used / (case.noise * drop), ev.count, len(tr)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-cell", type=int, default=10)
    ap.add_argument("--seed", type=int, default=2024)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    print("| noise | correlation | σ estimate / σ: median (min-max) | slip count wrong |")
    print("|---|---|---|---|")
    wrong_all = total = 0
    for noise in NOISE:
        for rho in CORRELATION:
            ratios, wrong, n = [], 0, 0
            for family in gt.FAMILIES:
                for k in range(args.per_cell):
                    case = gt.random_case(family, rng, sampling="uniform", samples_per_slip=50,
                                          noise=noise, correlation=rho,
                                          units=("lj", "si")[k % 2], seed=int(rng.integers(2**31)))
                    ratio, found, made = one(case)
                    ratios.append(ratio)
                    wrong += found != made
                    n += 1
            wrong_all += wrong
            total += n
            print(f"| {100 * noise:g} % | {rho:g} | {np.median(ratios):.2f} "
                  f"({np.min(ratios):.2f}-{np.max(ratios):.2f}) | {wrong} of {n} |")
    print(f"\nslip count wrong: {wrong_all} of {total} traces")
    return 0


if __name__ == "__main__":
    sys.exit(main())
