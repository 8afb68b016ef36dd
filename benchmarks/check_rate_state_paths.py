"""The compiled rate-and-state fast path against the general LSODA path on random blocks.

    .venv/bin/python benchmarks/check_rate_state_paths.py [--blocks N] [--seed S]

Each block draws a, b/a, d_c, v0, the evolution law, the regularization, K, M, V, a
damper or none and the starting velocity over wide ranges (below), runs ~40 natural
periods with ``simulate`` as users call it, then again with the fast path switched
off.  Printed per block where they differ, and in a summary: which path ran, the event
kinds, the largest difference of the event forces (relative to the force level),
the end position, and the CPU time of each side.  A spring-force extremum of a decaying
oscillation whose amplitude is near the 10^-6 threshold below which an extremum counts
as round-off can be kept on one path and dropped on the other: such blocks are counted
apart ("threshold").
"""
from __future__ import annotations

import argparse
import math
import sys
import time
import warnings

import numpy as np

from filmfriction.reduced_model import SpringBlock, laws
from filmfriction.reduced_model.integrators import limit_cycle


def draw(rng):
    a = 10 ** rng.uniform(-3, -1.5)
    law = laws.RateState(mu0=0.6, a=a, b=a * rng.uniform(0.5, 2.5), dc=10 ** rng.uniform(-3, -1),
                         v0=10 ** rng.uniform(-2, 0), evolution=str(rng.choice(["aging", "slip"])),
                         regularized=bool(rng.integers(2)))
    K, M, V = 10 ** rng.uniform(-0.5, 2), 10 ** rng.uniform(-2, 1), 10 ** rng.uniform(-2, 0)
    block = SpringBlock(mass=M, stiffness=K, drive_velocity=V, damping=float(rng.choice([0.0, 0.05])),
                        law=law)
    period = 2 * math.pi * math.sqrt(M / K)
    return block, min(40 * period, 60 * law.dc / V + 20 * period), V * rng.uniform(0.2, 1.5)


def run(block, duration, v_start, fast):
    used, run_smooth = [], limit_cycle.run_smooth

    def spy(*args, **kwargs):
        out = run_smooth(*args, **kwargs) if fast else None
        used.append(out is not None)
        return out
    limit_cycle.run_smooth = spy
    try:
        start = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = block.simulate(duration, initial_velocity=v_start)
        return r, time.process_time() - start, bool(used and used[0])
    finally:
        limit_cycle.run_smooth = run_smooth


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--blocks", type=int, default=100)
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    tally = {"same": 0, "threshold": 0, "handed over": 0, "differ": 0}
    cpu = {"fast": 0.0, "general": 0.0}
    for k in range(args.blocks):
        block, duration, v_start = draw(rng)
        fast, t_fast, used = run(block, duration, v_start, True)
        general, t_general, _ = run(block, duration, v_start, False)
        cpu["fast"] += t_fast
        cpu["general"] += t_general
        kf, kg = [e.kind for e in fast.events], [e.kind for e in general.events]
        ff, fg = (np.array([e.spring_force for e in r.events]) for r in (fast, general))
        level = max(np.ptp(fg) if fg.size else 0.0, abs(fg).max() if fg.size else 0.0, 1e-300)
        n = min(ff.size, fg.size)
        dforce = float(np.max(np.abs(ff[:n] - fg[:n]))) / level if n else 0.0
        dx = abs(fast.x[-1] - general.x[-1]) / max(abs(general.x[-1]), 1e-300)
        if not used:
            verdict = "handed over"
        elif kf == kg and dforce < 1e-6 and dx < 1e-6:
            verdict = "same"
        elif abs(len(kf) - len(kg)) == 1 and kf[:n] == kg[:n] and dforce < 1e-6 and dx < 1e-6:
            verdict = "threshold"
        else:
            verdict = "differ"
        tally[verdict] += 1
        if verdict != "same":
            law = block.law
            print(f"block {k:3d}: {verdict:11s} events {len(kf)}/{len(kg)}, force difference "
                  f"{dforce:.1e} of the level, end x {dx:.1e}; CPU {1e3 * t_fast:.0f} / "
                  f"{1e3 * t_general:.0f} ms  [a={law.a:.3g} b={law.b:.3g} dc={law.dc:.3g} "
                  f"v0={law.v0:.3g} {law.evolution} regularized={law.regularized} "
                  f"K={block.stiffness:.3g} M={block.mass:.3g} V={block.drive_velocity:.3g} "
                  f"d={block.damping} T={duration:.4g} v={v_start:.3g}]")
    print(f"{args.blocks} blocks (seed {args.seed}): " + ", ".join(f"{v} {k}" for k, v in tally.items())
          + f"; CPU fast path {cpu['fast']:.2f} s, general path {cpu['general']:.2f} s")
    return 1 if tally["differ"] else 0


if __name__ == "__main__":
    sys.exit(main())
