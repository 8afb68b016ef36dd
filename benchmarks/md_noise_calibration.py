"""The controls' noise calibrated to the MD's: the slip residual of MD runs and of random-force
replicas, measured the same way (docs/results/slip-law.md, "The MD's noise").

    python benchmarks/md_noise_calibration.py RUN [RUN ...] [--replicas 40]

For the runs' analysed slips pooled, and for the random-force replicas of the ``viscous``
control (:func:`~filmfriction.analysis.groundtruth.md_noise.replica_residuals`, seed 0) at
each named process of :mod:`~filmfriction.analysis.groundtruth.slip_law_controls`
(``RESIDUAL_AS_NOISE``, ``MD_NOISE``, ``MD_NOISE_FAST``): the residual's rms (mean over the
slips ± its standard error) and autocorrelation at 0.25, 1, 2, 4 τ, with F_k + B·v fitted
(``trend 1``) and with Δt², Δt³ fitted besides (``trend 3``: the part faster than the
slip's own shape).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from filmfriction.analysis.groundtruth import slip_law_controls as controls
from filmfriction.analysis.groundtruth.md_noise import (replica_residuals, residual_statistics,
                                                        run_residuals)

PROCESSES = ("RESIDUAL_AS_NOISE", "MD_NOISE", "MD_NOISE_FAST")


def row(name: str, stats: dict) -> str:
    acf = ", ".join(f"{a:.2f} ± {e:.2f}" for a, e in zip(stats["autocorrelation"],
                                                          stats["autocorrelation_stderr"]))
    return (f"| {name} | {stats['slips']} | {stats['rms']:.3f} ± {stats['rms_stderr']:.3f} | "
            f"{acf} |")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", metavar="RUN", help="run directories (analysed slips)")
    ap.add_argument("--replicas", type=int, default=40)
    a = ap.parse_args(argv)
    missing = [r for r in a.runs if not (Path(r) / "trace.csv").is_file()]
    if missing or a.replicas < 1:
        print(f"error: {'RUN without trace.csv: ' + ', '.join(missing) if missing else ''}"
              f"{' --replicas ' + str(a.replicas) + ' (>= 1)' if a.replicas < 1 else ''}",
              file=sys.stderr)
        return 2
    for trend in (1, 3):
        print(f"\n## trend {trend}: the residual's rms (σ/τ) and autocorrelation at 0.25, 1, 2, "
              "4 τ\n\n| noise | slips | rms | autocorrelation |\n|---|---|---|---|")
        md = [r for run in a.runs for r in run_residuals(run, trend=trend)]
        print(row(f"MD ({len(a.runs)} runs)", residual_statistics(md)), flush=True)
        for name in PROCESSES:
            noise = getattr(controls, name)
            stats = residual_statistics(replica_residuals(noise, replicas=a.replicas,
                                                          trend=trend))
            print(row(f"{name} {noise}", stats), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
