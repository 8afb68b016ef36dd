"""The slip law's MD positive control (docs/results/slip-law.md): liquid-release runs fitted.

    filmfriction run liquid-release --np 1 --md-only --set seed=S --out RUN_S   # per seed
    python benchmarks/fit_release_runs.py --viscosity ETA ETA_ERR RUN_1 RUN_2 ...

Prints the slip law fitted to the runs' release slips together
(:func:`filmfriction.analysis.groundtruth.release_control.fit_releases`: the verdict,
the decelerating branch and the whole slip), each run's layer velocity shares, where
the shear sits and the width W = D + 2b of its profile, and B = η·A/W with η the
liquid's viscosity at the film's state point (``filmfriction viscosity``).
"""
from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np

from filmfriction.analysis.groundtruth.release_control import fit_releases, release_profile


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--viscosity", nargs=2, type=float, metavar=("ETA", "ERR"), required=True)
    a = ap.parse_args(argv)
    traces, mass = [], None
    for run in a.runs:
        tr = np.genfromtxt(f"{run}/trace.csv", delimiter=",", names=True)
        traces.append({k: tr[k] for k in tr.dtype.names})
        p = json.load(open(f"{run}/run.json"))["trace_parameters"]
        mass = p["mass"]
    fit = fit_releases(traces, mass=mass)
    print(f"{len(traces)} releases, M = {mass:g}: verdict {fit.verdict} ({fit.reason})")
    for br in (fit.decelerating, fit.accelerating, fit.whole):
        print(f"  {br.branch:12s} F_k = {br.kinetic_force:.2f} ± {br.kinetic_force_stderr:.2f}, "
              f"B = {br.damping:.2f} ± {br.damping_stderr:.2f}; verdict {br.verdict}")
    widths = []
    for run in a.runs:
        prof = release_profile(run)
        widths.append((prof["width"], prof["width_stderr"]))
        print(f"  {run}: shares {np.round(prof['share'], 2).tolist()} ± "
              f"{np.round(prof['share_stderr'], 2).tolist()}; jumps {np.round(prof['jump'], 2).tolist()}"
              f"; {prof['location']}; W = {prof['width']:.2f} ± {prof['width_stderr']:.2f}")
    w = np.array(widths)
    wm = float(w[:, 0].mean())
    wse = float(w[:, 0].std(ddof=1) / math.sqrt(len(w))) if len(w) > 1 else float(w[0, 1])
    eta, eta_se = a.viscosity
    b = eta * prof["area"] / wm
    b_se = b * math.hypot(eta_se / eta, wse / wm)
    whole = fit.whole
    print(f"W = {wm:.2f} ± {wse:.2f}, A = {prof['area']:.2f}: eta*A/W = {b:.2f} ± {b_se:.2f}; "
          f"whole-slip B / (eta*A/W) = {whole.damping / b:.2f} ± "
          f"{whole.damping / b * math.hypot(whole.damping_stderr / whole.damping, b_se / b):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
