"""Does the calibration's slip fit recover F_k and B, and do its error bars cover them?

    .venv/bin/python benchmarks/calibration_coverage.py [--cases N] [--seed S] [--sets a,b]

Each case is a trace with known parameters, written as a run directory, analysed by
``filmfriction analyze``'s own analysis and fitted by
:func:`filmfriction.analysis.calibration.slipfit.fit_slip_law` as ``filmfriction calibrate`` does.
Per set the table gives the cases whose analysis found at least 3 slips to fit, the
fraction of them whose ±1 and ±2 standard errors cover the truth (nominal 68 % and
95 %), the mean and spread of z = (fit − truth)/stderr (nominal 0 and 1), the median
relative error, and how often the parameter ended at its bound (no error bar).

The sets are those of :mod:`filmfriction.analysis.groundtruth.calibration_sets`.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from filmfriction.analysis.groundtruth.calibration_sets import SETS, run_set, summary


def _one_blas_thread():
    """One BLAS thread (the small fits gain nothing from more, and the machine is shared),
    by threadpoolctl where it is installed; else OMP_NUM_THREADS=1 in the environment
    does it."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return
    threadpool_limits(1)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=60, help="cases per set (default 60)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--sets", default=",".join(SETS), help=f"comma-separated, of {', '.join(SETS)}")
    ap.add_argument("--log", type=Path, help="write every case's fit and truth to this file")
    args = ap.parse_args(argv)
    _one_blas_thread()
    log = args.log.open("w") if args.log else None
    names = [s for s in args.sets.split(",") if s]
    unknown = [s for s in names if s not in SETS]
    if unknown:
        print(f"calibration_coverage: unknown set(s) {', '.join(unknown)} (have {', '.join(SETS)})",
              file=sys.stderr)
        return 2
    print("| set | cases (fitted) | parameter | at bound | ±1 s.e. covers | ±2 s.e. covers "
          "| mean z | sd z | median rel. error |")
    print("|---|---|---|---|---|---|---|---|---|")
    for j, name in enumerate(names):
        rows = run_set(name, args.cases, args.seed + 1000 * j, log)
        for q, label in (("kinetic_force", "F_k"), ("film_damping", "B")):
            s = summary(rows, q)
            bound = f"{s['at_bound']}" + (f" (truth 0: {s['bound_truth']})" if s["at_bound"] else "")

            def num(x, fmt):
                return "–" if not math.isfinite(x) else format(x, fmt)
            print(f"| {name} | {args.cases} ({len(rows)}) | {label} | {bound} | "
                  f"{num(s['cover1'], '.0%')} of {s['free']} | {num(s['cover2'], '.0%')} | "
                  f"{num(s['mean_z'], '+.2f')} | {num(s['sd_z'], '.2f')} | "
                  f"{num(s['median_rel'], '.1%')} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
