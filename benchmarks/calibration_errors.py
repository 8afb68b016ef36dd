"""The calibration's standard errors set by set: are they the scatter of the estimates?

    python benchmarks/calibration_errors.py [--cases 80] [--seed 7]

The calibration sets of ``benchmarks/validate.py`` (Coulomb + viscous blocks in LJ and SI
numbers, white and AR(1) noise, and Klein's slip, F_k = 0), ``--cases`` each, fitted as
``filmfriction calibrate`` does (``validate.calibration_scores``).  Per set and observable
(F_k, B), z = (estimate − truth)/standard error over the fits off their bound: how often
|z| < 1 (68 % nominal), the rms of z (1 nominal) and its median |z| (0.67 nominal); on
Klein's set the fits whose F_k sits at its bound of 0 and the others apart.  A set whose
errors are right has all three near nominal; errors too wide give small z, too narrow
large ones.  Then the fits whose F_k or B sits at its bound of 0: how often their one-sided
95 % upper limit (the fit's χ² profile) lies at or above the truth, apart for a truth at the
bound (covered whatever the limit) and above it.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

# run as a script, this folder is on the path: validate.py's calibration sets
from validate import calibration_scores


def line(label: str, z: np.ndarray) -> str:
    if not z.size:
        return f"| {label} | 0 | – | – | – |"
    return (f"| {label} | {z.size} | {np.mean(np.abs(z) < 1):.0%} | "
            f"{np.sqrt(np.mean(z ** 2)):.2f} | {np.median(np.abs(z)):.2f} |")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=80)
    ap.add_argument("--seed", type=int, default=7)
    a = ap.parse_args(argv)
    if a.cases < 3:
        print(f"error: --cases {a.cases}: must be >= 3", file=sys.stderr)
        return 2
    scores = calibration_scores(a.cases, a.seed, klein_cases=a.cases)
    print("| set, observable | fits | |z| < 1 | rms z | median |z| |\n|---|---|---|---|---|")
    for name, (_, rows) in scores.items():
        for obs, label in (("kinetic_force", "F_k"), ("film_damping", "B")):
            z, bound = [], []
            for r in rows:
                est, err, at_bound, truth = r[obs]
                if at_bound or not err > 0 or truth == 0:
                    continue
                z.append((est - truth) / err)
                bound.append(bool(r["kinetic_force"][2]))
            z, bound = np.asarray(z), np.asarray(bound, bool)
            print(line(f"{name}, {label}", z))
            if name == "klein" and obs == "film_damping":
                print(line(f"{name}, {label}, F_k at its bound", z[bound]))
                print(line(f"{name}, {label}, F_k off its bound", z[~bound]))
    print("\n| set, observable at its bound | fits | truth 0: limit ≥ truth | truth > 0: "
          "limit ≥ truth | median limit / its set's median estimate off the bound |\n"
          "|---|---|---|---|---|")
    for name, (_, rows) in scores.items():
        for obs, label in (("kinetic_force", "F_k"), ("film_damping", "B")):
            pinned = [(r[obs][3], r["limits"][obs]) for r in rows if r[obs][2]]
            if not pinned:
                continue
            free = [r[obs][0] for r in rows if not r[obs][2]]
            zero = [lim >= t for t, lim in pinned if t == 0]
            above = [lim >= t for t, lim in pinned if t > 0]
            lims = np.array([lim for _, lim in pinned])
            scale = np.median(free) if free else np.nan
            print(f"| {name}, {label} | {len(pinned)} | {sum(zero)}/{len(zero)} | "
                  f"{sum(above)}/{len(above)} | {np.nanmedian(lims) / scale:.3g} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
