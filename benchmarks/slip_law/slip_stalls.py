"""Stalls within slips: how long the wall rests inside a slip, on MD runs or on the heavy slider's
controls with the walls' registry force.

    python benchmarks/slip_law/slip_stalls.py RUN… [--below 0.002] [--window 10]
    python benchmarks/slip_law/slip_stalls.py --control SHARE [--noise-free] [--runs 10]
        [--slips 9] [--corrugation 20 1.1 -0.97] [--stop-velocity V] [--loop LAW W D]

Within each slip (its yield to its re-stick, ``--window`` τ off each end), the wall's velocity
averaged over ``--window`` τ; a stall is a stretch where that stays below ``--below`` (σ/τ);
printed: the slips, the share whose longest stall lasts 20 τ or more and 50 τ or more, the
median and the longest.  A wall that stops at a crest of the registry's force before its
re-stick is armed stays "slipping" while it rests: the film's force there is not a law of the
velocity (a Coulomb control's sign flips), which the slip-law fit cannot carry.
``--control SHARE``: one pool of ``--runs`` runs of the heavy slider's Coulomb + viscous mix
of that viscous share with the registry force of ``--corrugation``
(:func:`~filmfriction.analysis.groundtruth.pooled_controls.pooled_runs`, law spread 0.15,
seed 0), at ``film_noise.STIFF_REGISTRY_NOISE`` (``--noise-free``: none), re-sticking
at the scale's stop velocity or ``--stop-velocity`` (negative: once the wall recoils that fast);
``--loop LAW W D``: the mix with a yield loop besides (``melting`` or ``slip-weakening``, as
``viscous_lag_profile.py --loop``).
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np


def longest_stalls(runs, below: float, window: float) -> np.ndarray:
    """The longest stall of each slip of ``runs`` (RunSlips), in the runs' time unit."""
    out = []
    for r in runs:
        dt = float(r.time[1] - r.time[0])
        w = max(int(round(window / dt)), 1)
        for y, s in zip(r.table.yield_index, r.table.stick_index):
            v = np.convolve(r.wall_velocity[y:s + 1], np.ones(w) / w, mode="same")[w:-w]
            best = run = 0
            for slow in v < below:
                run = run + 1 if slow else 0
                best = max(best, run)
            out.append(best * dt)
    return np.array(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs_dirs", nargs="*", type=Path, metavar="RUN")
    ap.add_argument("--below", type=float, default=0.002)
    ap.add_argument("--window", type=float, default=10.0)
    ap.add_argument("--control", type=float, default=None, metavar="SHARE")
    ap.add_argument("--noise-free", action="store_true")
    ap.add_argument("--runs", type=int, default=10)
    ap.add_argument("--slips", type=int, default=9)
    ap.add_argument("--corrugation", nargs=3, type=float, default=[20.0, 1.1, -0.97])
    ap.add_argument("--stop-velocity", type=float, default=None)
    ap.add_argument("--loop", nargs=3, default=None, metavar=("LAW", "W", "D"))
    a = ap.parse_args(argv)
    if (a.control is None) == (not a.runs_dirs):
        ap.error("RUN… or --control SHARE (one of them)")
    if not (a.below > 0 and math.isfinite(a.below) and a.window > 0 and math.isfinite(a.window)):
        ap.error(f"--below {a.below}, --window {a.window}: each > 0")
    if a.control is not None:
        if not (0 <= a.control <= 1) or a.runs < 3 or a.slips < 1:
            ap.error("--control SHARE in [0, 1], --runs >= 3, --slips >= 1")
        if not (all(map(math.isfinite, a.corrugation)) and a.corrugation[1] > 0):
            ap.error(f"--corrugation {a.corrugation}: finite, L > 0")
        if a.stop_velocity is not None and not math.isfinite(a.stop_velocity):
            ap.error(f"--stop-velocity {a.stop_velocity}: finite")
        loop = {}
        from filmfriction.analysis.groundtruth.pooled_controls import pooled_runs, yield_loop
        if a.loop is not None:
            try:
                law, w, d = yield_loop(*a.loop, laws=("melting", "slip-weakening"))
            except ValueError as exc:
                ap.error(f"--loop {' '.join(a.loop)}: {exc}")
            loop = {"weakening": (w, d), "loop_law": law}
        from filmfriction.analysis.groundtruth.random_force import NOISE_FREE
        from filmfriction.analysis.groundtruth.film_noise import STIFF_REGISTRY_NOISE
        from filmfriction.analysis.groundtruth.slip_law_controls import SCALES
        sc = SCALES["stiff"]
        if a.stop_velocity is not None:
            sc = replace(sc, mix={**sc.mix, "stop_velocity": a.stop_velocity})
        try:
            runs, _ = pooled_runs("x", a.runs, a.slips, share=a.control, law_spread=0.15,
                                  scale=sc,
                                  noise=NOISE_FREE if a.noise_free else STIFF_REGISTRY_NOISE,
                                  corrugation=tuple(a.corrugation), **loop)
        except ValueError as exc:
            print(f"slip_stalls: {exc}", file=sys.stderr)
            return 1
        what = (f"control share {a.control:g}, registry force {a.corrugation}, "
                + (f"a {a.loop[0]} loop {a.loop[1]} over {a.loop[2]}, " if loop else "")
                + ("noise-free" if a.noise_free else "STIFF_REGISTRY_NOISE")
                + f", stop velocity {sc.mix['stop_velocity']:g}")
    else:
        missing = [str(r) for r in a.runs_dirs if not (r / "trace.csv").is_file()]
        if missing:
            ap.error(f"RUN without trace.csv: {', '.join(missing)}")
        from filmfriction.analysis.calibration.slip_law_runs import read_runs
        try:
            runs, _, _ = read_runs(a.runs_dirs, analyse=False)
        except ValueError as exc:
            print(f"slip_stalls: {exc}", file=sys.stderr)
            return 1
        what = f"MD, {len(runs)} runs"
    st = longest_stalls(runs, a.below, a.window)
    print(f"{what}: {st.size} slips; the longest stall (velocity over {a.window:g} below "
          f"{a.below:g}) >= 20 in {np.mean(st >= 20):.2f}, >= 50 in {np.mean(st >= 50):.2f}; "
          f"median {np.median(st):.0f}, longest {st.max():.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
