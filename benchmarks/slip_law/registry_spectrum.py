"""Is a film's force modulated by the walls' registry?  Its Fourier amplitude over the wall's
position, slip by slip, from MD runs.

    python benchmarks/slip_law/registry_spectrum.py RUN_DIR... [--periods 0.55 1.1 ...]
        [--window 20] [--branches]
    python benchmarks/slip_law/registry_spectrum.py --control SCALE RUNS SLIPS [--lag TAU]
        [--registry-lag TAU_G | --branching DF2 PHI2 W1 W2 DPHI] [--pools 3] [--window 5]

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
rms.  ``--branches``: besides, the line and two harmonics fitted on each part of the
slips apart (the accelerating and decelerating branches, split at each slip's peak
velocity; the first and second halves of the distance slid), each ± the jackknife's error
over the runs: a registry force that depends on the film's state reads differently on them.
``--control SCALE RUNS SLIPS``: that table for ``--pools`` pools of RUNS random-force runs of
SLIPS slips at a scale of the controls (the Coulomb + viscous mix of share 0.5, its
viscous force lagging by ``--lag`` τ, carrying a registry force of constant amplitude,
``--corrugation`` DF·sin(2π·x/L + PHI), by default 20·sin(2π·x/1.1 − 0.97), at the scale's
noise beside the registry, re-sticking on a recoil at the drive's velocity): what the estimator reads where the truth is one amplitude and
phase on every part; ``--registry-lag TAU_G``: that force trailing the wall's position,
relaxing over TAU_G (``lagged-registry`` of
:mod:`~filmfriction.analysis.groundtruth.random_force`); ``--branching DF2 PHI2 W1 W2 DPHI``:
with a second harmonic DF2·sin(4π·x/1.1 + PHI2), the first harmonic's amplitude times
1 − W1·r and its phase plus DPHI·r, the second's times 1 + W2·r, r = |v|/(the slip's fastest
|v| so far): 1 while the slip speeds up, falling to 0 as it slows (``branching-registry``).
The smoothing attenuates the registry's force where a period passes in less than a few windows: at a light slider take a window of a fifth of that passage.
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import replace

import numpy as np
from scipy.signal import savgol_filter

from filmfriction.analysis.calibration.slip_law_runs import fit_arguments, read_runs

#: The controls' registry force (ΔF ε/σ, λ σ, φ): the MD's first harmonic at M = 10⁵.
CONTROL_REGISTRY = (20.0, 1.1, -0.97)
PERIODS = (0.318, 0.55, 0.635, 0.7, 0.8, 0.953, 1.1, 1.27, 1.5, 1.905, 2.2)


def slipping_samples(runs, kw, window: float):
    """The film's force, the wall's position, the distance since the yield and the velocity
    at every slipping sample of the runs' analysed slips."""
    out = [], [], [], []
    for _, _, k, y, _, force, x, v in _slips(runs, kw, window):
        for o, q in zip(out, (force[k], x[k], x[k] - x[int(y)], v[k])):
            o.append(q)
    return tuple(np.concatenate(o) for o in out)


def _slips(runs, kw, window: float):
    """Per analysed slip: the run's number and sampling interval, the slip's slipping
    samples (half a window off each end), its yield, the window in samples and the run's
    smoothed film force, position and velocity."""
    mass, gamma, drive = kw["mass"], kw["mount_damping"], kw["drive_velocity"]
    for run_no, r in enumerate(runs):
        dt = float(r.time[1] - r.time[0])
        w = max(5, int(window / dt) | 1)
        x = (r.wall_position if r.wall_position is not None
             else np.concatenate([[0.0], np.cumsum(r.wall_velocity[1:]) * dt]))
        v = savgol_filter(x, w, 2, deriv=1, delta=dt)
        a = savgol_filter(x, w, 2, deriv=2, delta=dt)
        force = savgol_filter(r.spring_force, w, 2) - mass * a - gamma * (v - drive)
        for y, s in zip(r.table.yield_index, r.table.stick_index):
            yield run_no, dt, slice(int(y) + w // 2, int(s) - w // 2), y, w, force, x, v


def branch_samples(runs, kw, window: float, period: float) -> dict:
    """The slipping samples as :func:`branch_table` fits them: the film's force, the
    velocity and the registry's two harmonics at the wall's position smoothed as the force
    is (``cols``), each sample's run, whether it is before its slip's peak velocity (the
    velocity smoothed over five windows, so that the registry's ripple does not place the
    peak) and whether it is in the first half of its slip's own distance."""
    out = {k: [] for k in ("force", "v", "cols", "run", "accelerating", "first_half")}
    smooth = {}                 # per run: the slow velocity and the smoothed harmonics
    for run_no, dt, k, y, w, force, x, v in _slips(runs, kw, window):
        if run_no not in smooth:
            slow = savgol_filter(x, min(5 * w, x.size - (1 - x.size % 2)) | 1, 2, deriv=1,
                                 delta=dt)
            cols = np.column_stack([savgol_filter(f(2 * math.pi * h * x / period), w, 2)
                                    for h in (1, 2) for f in (np.sin, np.cos)])
            smooth = {run_no: (slow, cols)}
        slow, cols = smooth[run_no]
        n = max(0, k.stop - k.start)
        if n == 0:
            continue
        slid = x[k] - x[int(y)]
        for key, q in (("force", force[k]), ("v", v[k]), ("cols", cols[k]),
                       ("run", np.full(n, run_no)),
                       ("accelerating", np.arange(n) < int(np.argmax(slow[k]))),
                       ("first_half", slid < 0.5 * slid[-1])):
            out[key].append(q)
    return {key: np.concatenate(q) for key, q in out.items()}


def harmonic_fit(force, x, v, period: float, harmonics: int):
    cols = [np.ones_like(v), v]
    for h in range(1, harmonics + 1):
        cols += [np.sin(2 * math.pi * h * x / period), np.cos(2 * math.pi * h * x / period)]
    a = np.column_stack(cols)
    c, *_ = np.linalg.lstsq(a, force, rcond=None)
    return c, float(np.std(force - a @ c))


def control(scale: str, runs: int, slips: int, lag: float, pools: int, window: float,
            registry_lag: float | None = None, branching=None,
            corrugation=CONTROL_REGISTRY) -> int:
    """The branch table of ``pools`` pools of controls whose registry force is constant
    (or trails the wall, or is weighted by the slip's branch)."""
    from filmfriction.analysis.groundtruth.pooled_controls import pooled_runs
    from filmfriction.analysis.groundtruth.slip_law_controls import SCALES

    sc = SCALES[scale]
    sc = replace(sc, mix={**sc.mix, "stop_velocity": -sc.drive_velocity})
    kw = dict(mass=sc.mass, mount_damping=sc.mount_damping, drive_velocity=sc.drive_velocity)
    df, lam, phi = corrugation
    what = (f"the registry force {df:g}·sin(2π·x/{lam:g} {'+' if phi >= 0 else '−'} "
            f"{abs(phi):g})")
    if registry_lag is not None:
        what += f" trailing the wall over {registry_lag:g} τ"
    if branching is not None:
        what += f", branching (ΔF₂, φ₂, w₁, w₂, δφ) = {tuple(branching)}"
    print(f"controls at the {scale} scale: share 0.5, {what}, lag {lag:g} τ, {runs} runs × "
          f"{slips} slips, window {window:g} τ")
    for seed in range(pools):
        rs, _ = pooled_runs("x", runs, slips, share=0.5, scale=sc, noise=sc.registry_noise,
                            corrugation=tuple(corrugation), seed=(seed, 0),
                            registry_lag=registry_lag, branching=branching,
                            **({"lag": lag} if lag else {}))
        print(f"pool {seed + 1}:\n" + branch_table(
            branch_samples(rs, kw, window, lam), len(rs)))
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="*", metavar="RUN_DIR")
    ap.add_argument("--control", nargs=3, default=None, metavar=("SCALE", "RUNS", "SLIPS"))
    ap.add_argument("--lag", type=float, default=0.0, help="the controls' viscous lag (τ)")
    ap.add_argument("--pools", type=int, default=3)
    ap.add_argument("--registry-lag", type=float, default=None, metavar="TAU_G",
                    help="the controls' registry force trails the wall over TAU_G (τ)")
    ap.add_argument("--branching", nargs=5, type=float, default=None,
                    metavar=("DF2", "PHI2", "W1", "W2", "DPHI"),
                    help="the controls' registry with a second harmonic, weighted by the "
                         "slip's branch (branching-registry)")
    ap.add_argument("--corrugation", nargs=3, type=float, default=list(CONTROL_REGISTRY),
                    metavar=("DF", "L", "PHI"), help="the controls' registry force")
    ap.add_argument("--periods", nargs="+", type=float, default=list(PERIODS))
    ap.add_argument("--branches", action="store_true",
                    help="the line and the registry's harmonics on each part of the slips")
    ap.add_argument("--window", type=float, default=20.0,
                    help="the smoothing window of the force and the position (τ)")
    args = ap.parse_args(argv)
    if not all(math.isfinite(p) and p > 0 for p in args.periods):
        ap.error(f"--periods {' '.join(map(str, args.periods))}: each > 0, finite")
    if not (math.isfinite(args.window) and args.window > 0):
        ap.error(f"--window {args.window!r}: > 0, finite")
    if (args.control is None) == (not args.runs):
        ap.error("RUN_DIR… or --control SCALE RUNS SLIPS (one of them)")
    if args.control is not None:
        from filmfriction.analysis.groundtruth.slip_law_controls import SCALES
        scale, runs, slips = args.control
        try:
            runs, slips = int(runs), int(slips)
        except ValueError:
            runs = slips = 0
        if scale not in SCALES or scale == "klein" or runs < 3 or slips < 1:
            ap.error(f"--control {' '.join(args.control)}: SCALE one of "
                     f"{', '.join(s for s in SCALES if s != 'klein')}, RUNS >= 3, SLIPS >= 1")
        if not (math.isfinite(args.lag) and args.lag >= 0) or args.pools < 1:
            ap.error(f"--lag {args.lag} >= 0 (τ), --pools {args.pools} >= 1")
        if args.registry_lag is not None and (args.lag or not (
                math.isfinite(args.registry_lag) and args.registry_lag > 0)):
            ap.error(f"--registry-lag {args.registry_lag}: a time > 0 (τ), without --lag")
        if args.branching is not None:
            from filmfriction.analysis.groundtruth.pooled_controls import branch_weights
            try:
                branch_weights(args.branching)
            except ValueError as exc:
                ap.error(f"--branching {' '.join(map(str, args.branching))}: {exc}")
            if args.lag or args.registry_lag is not None:
                ap.error("--branching: without --lag or --registry-lag")
        if not (all(map(math.isfinite, args.corrugation)) and args.corrugation[0] >= 0
                and args.corrugation[1] > 0):
            ap.error(f"--corrugation {' '.join(map(str, args.corrugation))}: finite, DF >= 0, "
                     "L > 0")
        return control(scale, runs, slips, args.lag, args.pools, args.window,
                       args.registry_lag, args.branching, args.corrugation)
    if (args.lag or args.registry_lag is not None or args.branching is not None
            or args.pools != 3 or args.corrugation != list(CONTROL_REGISTRY)):
        ap.error("--lag, --registry-lag, --branching, --corrugation and --pools are the "
                 "controls' (with --control)")
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
        print("the runs record no registry period (twisted walls, or not an MD run)"
              + ("; no --branches table without one" if args.branches else ""))
        return 0
    for h in range(4):
        c, rms = harmonic_fit(force, x, v, period, h)
        parts = [f"{math.hypot(c[2 + 2 * k], c[3 + 2 * k]):.1f} at "
                 f"{math.atan2(c[3 + 2 * k], c[2 + 2 * k]):+.2f} rad" for k in range(h)]
        print(f"  {h} harmonic(s) of λ = {period:g}: F_k {c[0]:.2f}, B {c[1]:.0f}"
              + (f"; amplitudes {', '.join(parts)}" if parts else "") + f"; residual rms {rms:.2f}")
    if args.branches:
        print(branch_table(branch_samples(runs, kw, args.window, period), len(runs)))
    return 0


def _amplitudes(force, v, cols, phase_near=None):
    """F_k, B, the first harmonic's amplitude and phase, the second's amplitude, fitted on
    the samples (the phase within π of ``phase_near`` when given)."""
    c, *_ = np.linalg.lstsq(np.column_stack([np.ones_like(v), v, cols]), force, rcond=None)
    phase = math.atan2(c[3], c[2])
    if phase_near is not None:
        phase += 2 * math.pi * round((phase_near - phase) / (2 * math.pi))
    return np.array([c[0], c[1], math.hypot(c[2], c[3]), phase, math.hypot(c[4], c[5])])


def branch_table(samples: dict, runs: int) -> str:
    """The line and two registry harmonics fitted on each part of the slips apart (the
    accelerating and decelerating branches; the first and second halves of each slip's
    distance), and the differences between the two parts of each split, each ± the
    jackknife's error over the runs (of the difference itself, the two parts sharing their
    runs)."""
    f, v, cols, run = (samples[k] for k in ("force", "v", "cols", "run"))

    def fit(part, near=None):
        est = _amplitudes(f[part], v[part], cols[part], near)
        loo = np.array([_amplitudes(f[part & (run != r)], v[part & (run != r)],
                                    cols[part & (run != r)], est[3]) for r in range(runs)])
        return est, loo

    def err(loo):
        return np.sqrt((runs - 1) / runs * ((loo - loo.mean(axis=0)) ** 2).sum(axis=0))

    rows = ["| part of the slips | samples | F_k (ε/σ) | B (m/τ) | first harmonic (ε/σ) | "
            "its phase (rad) | second harmonic (ε/σ) |", "|---|---|---|---|---|---|---|"]
    digits = (2, 0, 1, 2, 1)
    for names, first in ((("accelerating branch", "decelerating branch"),
                          samples["accelerating"]),
                         (("first half of the slip's distance", "second half"),
                          samples["first_half"])):
        a, la = fit(first)
        b, lb = fit(~first, a[3])
        for name, part, est, loo in ((names[0], first, a, la), (names[1], ~first, b, lb)):
            rows.append(f"| {name} | {int(part.sum())} | " + " | ".join(
                f"{e:.{d}f} ± {s:.{d}f}" for e, s, d in zip(est, err(loo), digits)) + " |")
        rows.append(f"| {names[0].split()[0]} − {names[1].split()[0]} | | " + " | ".join(
            f"{e:+.{d}f} ± {s:.{d}f}" for e, s, d in zip(a - b, err(la - lb), digits)) + " |")
    return "\n".join(rows)


if __name__ == "__main__":
    sys.exit(main())
