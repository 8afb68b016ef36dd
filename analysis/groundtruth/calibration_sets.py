"""The calibration's ground-truth sets: traces whose F_k and B are known, written as run
directories, and the slip fit's score on them (:func:`run_set`, :func:`summary`).

Sets (each drawn at random per case, :data:`SETS`):

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
than its stick is not detected as stick-slip).  Used by ``benchmarks/calibration_coverage.py``,
``benchmarks/validate.py`` and the calibration's tests.
"""
from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import numpy as np
from scipy.signal import lfilter

from filmfriction.reduced_model import SpringBlock, laws

from .synthetic import klein_trace, write_csv

__all__ = ["WALLS", "SETS", "noise", "write_run", "coulomb_case", "klein_slip", "klein_case", "run_set",
           "summary"]

WALLS = {
    "lj": dict(k=100.0, m=500.0, d=50.0, fs=60.0, area=60.0, gap=3.7, units="lj"),
    "si": dict(k=97.0, m=1.47e-3, d=0.0, fs=9.7e-6, area=4.0e-10, gap=3.5e-9, units="si"),
}


def noise(rng, n, sigma, rho):
    """n samples of white (``rho`` = 0) or AR(1) noise of standard deviation ``sigma``."""
    if not rho:
        return rng.normal(0.0, sigma, n)
    return lfilter([1.0], [1.0, -rho], rng.normal(0.0, sigma * math.sqrt(1 - rho ** 2), n))


def write_run(directory, wall, t, force, drive, v):
    """A run directory (trace.csv, run.json) of the trace on ``wall`` at drive velocity v."""
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
    write_run(directory, w, t, r.spring_force[i] + noise(rng, t.size, sigma, rho),
           r.drive_position[i], v)
    return {"kinetic_force": fk, "film_damping": b}


def klein_slip(rng, spring_constant, mass, static_force):
    """A random Klein slip's parameters (damping ratio 0.3-3, F_b 0.2-0.5 F_s, a stick 4-10
    slips long, 20-80 samples a slip): :func:`klein_trace`'s keywords but noise and seed."""
    k, m, fs = spring_constant, mass, static_force
    b = 2.0 * math.sqrt(k * m) * rng.uniform(0.3, 3.0)
    fb = fs * rng.uniform(0.2, 0.5)
    slip = max(math.pi * math.sqrt(m / k), b / k)
    v = (fs - fb) / (k * rng.uniform(4.0, 10.0) * slip)
    return dict(spring_constant=k, mass=m, damping=b, drive_velocity=v, static_force=fs,
                backward_force=fb, cycles=6, dt=slip / rng.uniform(20, 80))


def klein_case(directory, rng):
    """Klein's slip with a freeze at F_b (F_k = 0), SI; returns its truth."""
    w = WALLS["si"]
    kw = klein_slip(rng, w["k"], w["m"], w["fs"])
    drop = kw["static_force"] - kw["backward_force"]
    tr = klein_trace(noise=drop * rng.uniform(0.005, 0.03), seed=int(rng.integers(2 ** 31)), **kw)
    write_run(directory, w, tr["time"], tr["spring_force"], tr["drive_position"],
              kw["drive_velocity"])
    return {"kinetic_force": 0.0, "film_damping": kw["damping"]}


SETS = {"lj": lambda d, rng: coulomb_case(d, rng, "lj"),
        "si": lambda d, rng: coulomb_case(d, rng, "si"),
        "lj-ar1": lambda d, rng: coulomb_case(d, rng, "lj", (0.5, 0.9)),
        "klein": klein_case}


def run_set(name, cases, seed, log=None):
    """Rows {parameter: (fit, stderr, at_bound, truth)} of the cases with >= 3 fitted slips,
    and the number of cases."""
    from ..calibration.rundata import load_run
    from ..calibration.slipfit import fit_slip_law

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
