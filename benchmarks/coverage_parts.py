"""The coverage of ±1 s.e. on noisy model traces, split by what enters the error.

    .venv/bin/python benchmarks/coverage_parts.py [--seed 99] [--per-cell 2]

Random blocks of every friction law (:mod:`filmfriction.analysis.groundtruth.cases`),
50 samples per slip, white or AR(1) (ρ = 0.9) noise of 0.3, 1, 3 and 10 % of the force
drop, ``per-cell`` cases per law, noise level and correlation, half LJ and half SI;
each analysed as ``filmfriction analyze`` does.  Over the cases with at least 3 slips,
per observable: the coverage of the reported s.e. (s/√n with the mean systematic error:
the sampling's resolution, or half the bias the noisy fit corrected),
of the same scaled by Student's t for n − 1 degrees of freedom (what ±1 s.e. of a mean
of n values covers 68 % with), and of the s.e. with each slip's own noise error added
(s² + e²)/n; the mean and median |z| of z = error/(s/√n) (for n = 7 slips and unbiased
errors, Student's t gives median |z| = 0.72), on all cases and on those whose slip
count is right.  Coverages carry their binomial standard error.
"""
from __future__ import annotations

import argparse
import math
import sys

import numpy as np
from scipy import stats

from filmfriction.analysis.analyze import context
from filmfriction.analysis.groundtruth import cases as gt

NAMES = ("static_force", "backward_force", "slip_distance", "slip_duration")


def case_parts(case):
    """Per observable: error of the mean, scatter s, n, rms per-slip noise error and mean
    resolution, all in units of the drop (forces) or of the truth; None below 3 slips."""
    r = gt.simulate(case)
    tr = gt.truth(case, r)
    cols, params = gt.sample(case, r, tr)
    ctx = context(gt.as_trace(cols, params), structure=False)
    tab = ctx.all_slips
    if len(tab) < 3:
        return None
    scale = gt._scale(case)
    ty = tr.yield_time * scale["time"]
    match = np.abs(np.asarray(tab.yield_time)[:, None] - ty[None, :]).argmin(axis=1)[ctx.skip:]
    drop = float(np.mean(tr.static_force[match] - tr.backward_force[match])) * scale["force"]
    out = {"right_count": len(tab) == len(tr)}
    for name in NAMES:
        attr, how = gt.OBSERVABLES[name]
        true = np.asarray(getattr(tr, attr), float)[match] * scale[gt._QUANTITY[name]]
        est = np.asarray(getattr(tab, name), float)[ctx.skip:]
        noise, res = (np.asarray(a, float)[ctx.skip:] for a in tab.uncertainty[name])
        ok = np.isfinite(est) & np.isfinite(true)
        if ok.sum() < 2:
            continue
        denom = drop if how == "drop" else abs(float(np.mean(true[ok])))
        out[name] = dict(err=(est[ok].mean() - true[ok].mean()) / denom,
                         s=est[ok].std(ddof=1) / denom, n=int(ok.sum()),
                         noise=math.sqrt(float(np.mean(noise[ok] ** 2))) / denom,
                         res=float(np.mean(res[ok])) / denom)
    return out


def share(flags):
    n = len(flags)
    if not n:
        return "–"
    p = sum(flags) / n
    return f"{100 * p:.0f} ± {100 * math.sqrt(p * (1 - p) / n):.0f} % of {n}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=99)
    ap.add_argument("--per-cell", type=int, default=2)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    parts = []
    for noise in (0.003, 0.01, 0.03, 0.1):
        for rho in (0.0, 0.9):
            for family in gt.FAMILIES:
                for k in range(args.per_cell):
                    case = gt.random_case(family, rng, sampling="uniform", samples_per_slip=50,
                                          noise=noise, correlation=rho,
                                          units=("lj", "si")[k % 2], seed=len(parts) + 1000)
                    try:
                        parts.append(case_parts(case))
                    except Exception as exc:   # noqa: BLE001 -- counted, not fatal
                        print(f"{case.label()}: {type(exc).__name__}: {exc}", file=sys.stderr)
                        parts.append(None)
    found = [p for p in parts if p is not None]
    print(f"{len(parts)} cases, {len(found)} with >= 3 slips, "
          f"{sum(p['right_count'] for p in found)} with the right count\n")
    print("| observable | cases | ±1 s.e. | t-scaled | + noise error | mean z | median abs z |")
    print("|---|---|---|---|---|---|---|")
    for label, sel in (("all", found), ("right count", [p for p in found if p["right_count"]])):
        for name in NAMES:
            o = [p[name] for p in sel if name in p]
            se = [math.hypot(x["s"] / math.sqrt(x["n"]), x["res"]) for x in o]
            tse = [math.hypot(x["s"] / math.sqrt(x["n"]) * stats.t.ppf(0.8413, x["n"] - 1),
                              x["res"]) for x in o]
            nse = [math.sqrt((x["s"] ** 2 + x["noise"] ** 2) / x["n"] + x["res"] ** 2) for x in o]
            z = np.array([x["err"] / (x["s"] / math.sqrt(x["n"])) for x in o if x["s"] > 0])
            print(f"| {name} ({label}) | {len(o)} | "
                  f"{share([abs(x['err']) <= e for x, e in zip(o, se)])} | "
                  f"{share([abs(x['err']) <= e for x, e in zip(o, tse)])} | "
                  f"{share([abs(x['err']) <= e for x, e in zip(o, nse)])} | "
                  f"{z.mean():+.2f} | {np.median(np.abs(z)):.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
