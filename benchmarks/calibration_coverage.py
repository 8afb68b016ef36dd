"""Does the calibration's slip fit recover F_k and B, and do its error bars cover them?

    .venv/bin/python benchmarks/calibration_coverage.py [--cases N] [--seed S] [--sets a,b]

Each case is a trace with known parameters, written as a run directory, analysed by
``filmfriction analyze``'s own analysis and fitted by
:func:`filmfriction.analysis.calibration.slipfit.fit_slip_law` as ``filmfriction calibrate`` does.
Per set the table gives the cases whose analysis found at least 3 slips to fit, the
fraction of them whose ±1 and ±2 standard errors cover the truth (nominal 68 % and
95 %), the mean and spread of z = (fit − truth)/stderr (nominal 0 and 1), the median
relative error, and how often the parameter ended at its bound (no error bar).

Sets (each drawn at random per case):

``lj``, ``si``
    Coulomb + viscous blocks of the reduced model (:class:`~filmfriction.reduced_model.SpringBlock`,
    exact events, sampled on a regular grid): F_k/F_s in [0.1, 0.6], slip damping
    ratio (B + d)/2√(KM) in [0.12, 0.45], stick 4–10 times the slip, 15–80 samples per
    slip, white noise 0.5–5 % of the force drop.  ``lj``: an MD-like wall (K = 100, M = 500,
    mount d = 50, F_s = 60, LJ units); ``si``: Klein's SFB (K = 97 N/m, M = 1.47 g,
    F_s = 9.7 µN, no mount dashpot, SI units).
``lj-ar1``
    As ``lj`` with AR(1) noise of lag-one correlation 0.5–0.9 (the MD's film force is
    correlated over many samples).
``klein``
    Klein's slip (:func:`~filmfriction.analysis.groundtruth.synthetic.klein_trace`: F_k = 0, the film
    freezes when the force has fallen to F_b) in SI: damping ratio B/2√(KM) in
    [0.3, 3], F_b/F_s in [0.2, 0.5], 20–80 samples per slip, noise 0.5–3 %.  The
    truth F_k = 0 is the bound of its range: where the fit ends there it has no error
    bar and counts as recovered.

The ranges are those the analysis' slip detector takes reliably (a slip much longer
than its stick is not detected as stick-slip).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402
from scipy.signal import lfilter  # noqa: E402

from filmfriction.analysis.calibration.rundata import load_run  # noqa: E402
from filmfriction.analysis.calibration.slipfit import fit_slip_law  # noqa: E402
from filmfriction.analysis.groundtruth.synthetic import klein_trace, write_csv  # noqa: E402
from filmfriction.reduced_model import SpringBlock, laws  # noqa: E402

WALLS = {
    "lj": dict(k=100.0, m=500.0, d=50.0, fs=60.0, area=60.0, gap=3.7, units="lj"),
    "si": dict(k=97.0, m=1.47e-3, d=0.0, fs=9.7e-6, area=4.0e-10, gap=3.5e-9, units="si"),
}


def _noise(rng, n, sigma, rho):
    if not rho:
        return rng.normal(0.0, sigma, n)
    return lfilter([1.0], [1.0, -rho], rng.normal(0.0, sigma * math.sqrt(1 - rho ** 2), n))


def _write(directory, wall, t, force, drive, v):
    directory.mkdir(parents=True)
    write_csv(directory / "trace.csv", {"time": t, "spring_force": force, "drive_position": drive,
                                        "gap": np.full(t.size, wall["gap"])})
    run = {"schema": "filmfriction.run/1", "status": "completed",
           "scene": {"name": "synthetic", "parameters": {"drive_velocity": v}},
           "trace_parameters": {"spring_constant": wall["k"], "mass": wall["m"],
                                "area": wall["area"], "thickness": None, "drive_velocity": v,
                                "mount_damping": wall["d"] or None, "units": wall["units"]}}
    (directory / "run.json").write_text(json.dumps(run))


def coulomb_case(directory, rng, wall_name, rho_range=None):
    """A Coulomb + viscous trace; returns its truth."""
    w = WALLS[wall_name]
    k, m, d, fs = w["k"], w["m"], w["d"], w["fs"]
    critical = 2.0 * math.sqrt(k * m)
    fk = fs * rng.uniform(0.1, 0.6)
    b = critical * rng.uniform(0.12, 0.45) - d
    drop = fs - fk
    slip = math.pi * math.sqrt(m / k)
    dt = slip / rng.uniform(15, 80)
    v = 2.0 * drop / (k * rng.uniform(4.0, 10.0) * slip)
    duration = 7.5 * 2.0 * drop / (k * v)
    rho = rng.uniform(*rho_range) if rho_range else 0.0
    sigma = drop * rng.uniform(0.005, 0.05)
    t = np.arange(0.0, duration, dt)
    r = SpringBlock(mass=m, stiffness=k, drive_velocity=v, damping=d,
                    law=laws.Coulomb(static=fs, kinetic=fk, viscous=b)).simulate(duration, t_eval=t)
    i = r.eval_index
    _write(directory, w, t, r.spring_force[i] + _noise(rng, t.size, sigma, rho),
           r.drive_position[i], v)
    return {"kinetic_force": fk, "film_damping": b}


def klein_case(directory, rng):
    """Klein's slip with a freeze at F_b (F_k = 0), SI; returns its truth."""
    w = WALLS["si"]
    k, m, fs = w["k"], w["m"], w["fs"]
    b = 2.0 * math.sqrt(k * m) * rng.uniform(0.3, 3.0)
    fb = fs * rng.uniform(0.2, 0.5)
    slip = max(math.pi * math.sqrt(m / k), b / k)
    v = (fs - fb) / (k * rng.uniform(4.0, 10.0) * slip)
    tr = klein_trace(spring_constant=k, mass=m, damping=b, drive_velocity=v, static_force=fs,
                     backward_force=fb, cycles=6, dt=slip / rng.uniform(20, 80),
                     noise=(fs - fb) * rng.uniform(0.005, 0.03), seed=int(rng.integers(2 ** 31)))
    _write(directory, w, tr["time"], tr["spring_force"], tr["drive_position"], v)
    return {"kinetic_force": 0.0, "film_damping": b}


SETS = {"lj": lambda d, rng: coulomb_case(d, rng, "lj"),
        "si": lambda d, rng: coulomb_case(d, rng, "si"),
        "lj-ar1": lambda d, rng: coulomb_case(d, rng, "lj", (0.5, 0.9)),
        "klein": klein_case}


def run_set(name, cases, seed, log=None):
    """Rows {parameter: (fit, stderr, at_bound, truth)} of the cases with >= 3 fitted slips,
    and the number of cases."""
    rng = np.random.default_rng(seed)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(cases):
            d = Path(tmp) / f"case{i}"
            truth = SETS[name](d, rng)
            try:
                fit = fit_slip_law(load_run(d), jackknife=False)
            except ValueError as exc:
                if log:
                    print(f"{name} {i}: {exc}", file=log)
                continue
            if fit.n_slips < 3:
                continue
            row = {q: (getattr(fit, q).value, getattr(fit, q).stderr, getattr(fit, q).at_bound,
                       truth[q]) for q in ("kinetic_force", "film_damping")}
            rows.append(row)
            if log:
                print(name, i, json.dumps(row), file=log, flush=True)
    return rows


def summary(rows, q):
    """Coverage figures of parameter ``q`` over the rows."""
    free = [r[q] for r in rows if not r[q][2]]
    bound = [r[q] for r in rows if r[q][2]]
    z = np.array([(v - t) / s for v, s, _, t in free])
    rel = np.array([abs(v - t) / abs(t) for v, _, _, t in free if t])
    return {"free": len(free), "at_bound": len(bound),
            "bound_truth": sum(1 for v, _, _, t in bound if abs(v - t) <= 1e-9 * max(abs(t), 1e-300)
                               or t == v),
            "cover1": float(np.mean(np.abs(z) < 1)) if z.size else math.nan,
            "cover2": float(np.mean(np.abs(z) < 2)) if z.size else math.nan,
            "mean_z": float(np.mean(z)) if z.size else math.nan,
            "sd_z": float(np.std(z, ddof=1)) if z.size > 1 else math.nan,
            "median_rel": float(np.median(rel)) if rel.size else math.nan}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=60, help="cases per set (default 60)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--sets", default=",".join(SETS), help=f"comma-separated, of {', '.join(SETS)}")
    ap.add_argument("--log", type=Path, help="write every case's fit and truth to this file")
    args = ap.parse_args(argv)
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
