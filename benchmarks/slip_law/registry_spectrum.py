"""Is a film's force modulated by the walls' registry?  Its Fourier amplitude over the wall's
position, slip by slip, from MD runs.

    python benchmarks/slip_law/registry_spectrum.py RUN_DIR... [--periods 0.55 1.1 ...]
        [--window 20]

Commensurate walls pass a force that repeats with their lattice's period along the slide:
the film's force during a slip is then F_k + B·v plus a periodic function of the wall's
position x.  Per run, the film's force F_spring − M·a − γM·(v − V) is taken sample by
sample (Savitzky–Golay, order 2, over ``--window`` τ, of the spring force and the wall's
position), over each analysed slip's slipping samples (half a window off each end); a
line in v is removed by least squares over all runs' samples, and the residual's Fourier
amplitude |2·mean(r·exp(2πi·x/λ))| is printed for each period λ, over the wall's absolute
position and over the distance slid since each slip's yield (a force locked to the
lattice shows in the first; one locked to the yield, in the second; a period that is
neither reads the noise's level).  Then the line fitted with 0–3 harmonics of the runs'
registry period (``trace_parameters.registry_period``, the walls' spacing for aligned
walls): F_k, B, each harmonic's amplitude and phase (A·sin(2πhx/λ + φ)) and the residual's
rms.
"""
from __future__ import annotations

import argparse
import math
import sys

import numpy as np
from scipy.signal import savgol_filter

from filmfriction.analysis.calibration.slip_law_runs import fit_arguments, read_runs

PERIODS = (0.318, 0.55, 0.635, 0.7, 0.8, 0.953, 1.1, 1.27, 1.5, 1.905, 2.2)


def slipping_samples(runs, kw, window: float):
    """The film's force, the wall's position, the distance since the yield and the velocity
    at every slipping sample of the runs' analysed slips."""
    out = [], [], [], []
    mass, gamma, drive = kw["mass"], kw["mount_damping"], kw["drive_velocity"]
    for r in runs:
        dt = float(r.time[1] - r.time[0])
        w = max(5, int(window / dt) | 1)
        x = (r.wall_position if r.wall_position is not None
             else np.concatenate([[0.0], np.cumsum(r.wall_velocity[1:]) * dt]))
        v = savgol_filter(x, w, 2, deriv=1, delta=dt)
        a = savgol_filter(x, w, 2, deriv=2, delta=dt)
        force = savgol_filter(r.spring_force, w, 2) - mass * a - gamma * (v - drive)
        for y, s in zip(r.table.yield_index, r.table.stick_index):
            k = slice(int(y) + w // 2, int(s) - w // 2)
            for o, q in zip(out, (force[k], x[k], x[k] - x[int(y)], v[k])):
                o.append(q)
    return tuple(np.concatenate(o) for o in out)


def harmonic_fit(force, x, v, period: float, harmonics: int):
    cols = [np.ones_like(v), v]
    for h in range(1, harmonics + 1):
        cols += [np.sin(2 * math.pi * h * x / period), np.cos(2 * math.pi * h * x / period)]
    a = np.column_stack(cols)
    c, *_ = np.linalg.lstsq(a, force, rcond=None)
    return c, float(np.std(force - a @ c))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", metavar="RUN_DIR")
    ap.add_argument("--periods", nargs="+", type=float, default=list(PERIODS))
    ap.add_argument("--window", type=float, default=20.0,
                    help="the smoothing window of the force and the position (τ)")
    args = ap.parse_args(argv)
    if not all(math.isfinite(p) and p > 0 for p in args.periods):
        ap.error(f"--periods {' '.join(map(str, args.periods))}: each > 0, finite")
    if not (math.isfinite(args.window) and args.window > 0):
        ap.error(f"--window {args.window!r}: > 0, finite")
    try:
        runs, shared, _ = read_runs(args.runs, analyse=False)
    except ValueError as exc:
        print(f"registry_spectrum: {exc}", file=sys.stderr)
        return 1
    kw = fit_arguments(shared)
    force, x, slid, v = slipping_samples(runs, kw, args.window)
    c, rms = harmonic_fit(force, x, v, 1.0, 0)
    resid = force - (c[0] + c[1] * v)
    print(f"{len(runs)} runs, {sum(len(r.table) for r in runs)} slips, {force.size} slipping "
          f"samples; the line F_k {c[0]:.2f}, B {c[1]:.0f}; residual rms {rms:.1f}")
    for lam in args.periods:
        amp = [2 * np.mean(resid * np.exp(2j * math.pi * pos / lam)) for pos in (x, slid)]
        print(f"  λ {lam:5.3f}: amplitude over the position {abs(amp[0]):5.2f}, over the "
              f"distance since the yield {abs(amp[1]):5.2f}")
    period = shared.get("registry_period")
    if period is None:
        print("the runs record no registry period (twisted walls, or not an MD run)")
        return 0
    for h in range(4):
        c, rms = harmonic_fit(force, x, v, period, h)
        parts = [f"{math.hypot(c[2 + 2 * k], c[3 + 2 * k]):.1f} at "
                 f"{math.atan2(c[3 + 2 * k], c[2 + 2 * k]):+.2f} rad" for k in range(h)]
        print(f"  {h} harmonic(s) of λ = {period:g}: F_k {c[0]:.2f}, B {c[1]:.0f}"
              + (f"; amplitudes {', '.join(parts)}" if parts else "") + f"; residual rms {rms:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
