"""The calibration's Coulomb + viscous slip fit on random-force replicas of known F_k and B
(docs/results/calibration.md, "At the MD's noise").

    python benchmarks/calibration_random_force.py [--replicas 40] [--slips 8]
                                                  [--kinetic-force 19] [--damping 27]
                                                  [--noises none MD_NOISE RESIDUAL_AS_NOISE]
                                                  [--freeze-only] [--slip-ends]

Slips of F_k·sign(v) + B·v at the Klein-similar scene's scale (K = 2, M = 30, F_s = 48,
sampled every 0.25 τ, V = 0.1 σ/τ; the film re-freezes where the spring force has fallen
to 24 ε/σ, as Klein's and the viscous control's, or the wall stops once it has fallen
to 34; ``--freeze-only``: at the freeze alone), the film pushing the wall with the controls' random force
(:mod:`~filmfriction.analysis.groundtruth.random_force`) of each named process of
:mod:`~filmfriction.analysis.groundtruth.film_noise` (none, ``MD_NOISE``,
``RESIDUAL_AS_NOISE``), fitted by :func:`~filmfriction.analysis.calibration.slipfit.fit_slips` as
``filmfriction calibrate`` fits a run (the slips after the start-up one; no jackknife).
Per noise: the mean estimate with its standard error over the replicas (the bias), the
spread, the mean standard error, and how often ±2 standard errors cover the truth.  The
defaults are what the calibration finds on ``sfb-similar`` (F_k ≈ 19 ε/σ, B ≈ 27 m/τ).
"""
from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from filmfriction.analysis.calibration.slipfit import fit_slips
from filmfriction.analysis.groundtruth import film_noise, slip_law_controls as controls
from filmfriction.analysis.groundtruth.random_force import slide

NOISES = ("none", "MD_NOISE", "RESIDUAL_AS_NOISE")


def replica_runs(noise: dict, replicas: int, slips: int, fk: float, b: float,
                 freeze_only: bool = False) -> list:
    s = controls.SCALE
    # the wall stops where its velocity falls to 0 (the noise can bring it to rest before
    # the freeze), or with ``freeze_only`` at the freeze alone (Klein's control's re-stick)
    stop = -math.inf if freeze_only else 0.0
    runs = slide("coulomb-viscous", (fk, b), mass=s["mass"], stiffness=s["spring_constant"],
                 drive_velocity=0.1, static_force=s["static_force"], backward_force=24.0,
                 armed_below=34.0, initial_force=24.0, stop_velocity=stop,
                 duration=(slips + 2) * 2 * s["static_force"] / s["spring_constant"] / 0.1 * 1.1,
                 dt=s["dt"], replicas=replicas, seed=0, **noise)
    return runs


def slip_ends(runs: list, slips: int) -> str:
    """Where the fitted slips end: the spring force's quantiles (5, 25, 50, 75, 95 %) and the
    share ending at the freeze (24 ε/σ)."""
    f = np.concatenate([r["spring_force"][r["stick_index"][1:slips + 1]] for r in runs])
    q = ", ".join(f"{x:.1f}" for x in np.percentile(f, [5, 25, 50, 75, 95]))
    return (f"{f.size} slips end at spring force {q} (5–95 %); "
            f"at the freeze in {np.mean(f <= 24.5):.2f}")


def replica_fits(runs: list, slips: int) -> list:
    s = controls.SCALE
    out = []
    for k, tr in enumerate(runs):
        y, st = tr["yield_index"][1:slips + 1], tr["stick_index"][1:slips + 1]
        f = tr["spring_force"]
        try:
            out.append(fit_slips(tr["time"], f, [(a, c, f[a]) for a, c in zip(y, st)],
                                 spring_constant=s["spring_constant"], mass=s["mass"],
                                 drive_velocity=0.1, jackknife=False))
        except ValueError as e:                     # a replica with no slip to fit
            print(f"  replica {k} not fitted: {e}", file=sys.stderr)
            continue
        f = out[-1]
        print(f"  replica {k}: F_k {f.kinetic_force.value:.2f} ± {f.kinetic_force.stderr:.2f}, "
              f"B {f.film_damping.value:.2f} ± {f.film_damping.stderr:.2f}", file=sys.stderr,
              flush=True)
    return out


def line(name: str, est, truth: float) -> str:
    v = np.array([e.value for e in est])
    se = np.array([e.stderr for e in est])
    ok = np.isfinite(se)
    cover = np.abs(v[ok] - truth) <= 2 * se[ok]
    return (f"  {name}: mean {v.mean():.2f} ± {v.std(ddof=1) / math.sqrt(v.size):.2f} "
            f"(truth {truth:g}, bias {v.mean() - truth:+.2f}), sd {v.std(ddof=1):.2f}, "
            f"mean s.e. {np.nanmean(se):.2f}; ±2 s.e. covers in {cover.sum()} of {ok.sum()} "
            f"(at bound {int((~ok).sum())})")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--replicas", type=int, default=40)
    ap.add_argument("--slips", type=int, default=8)
    ap.add_argument("--kinetic-force", type=float, default=19.0)
    ap.add_argument("--damping", type=float, default=27.0)
    ap.add_argument("--noises", nargs="+", default=list(NOISES), choices=NOISES)
    ap.add_argument("--slip-ends", action="store_true",
                    help="only where the slips end (no fits)")
    ap.add_argument("--freeze-only", action="store_true",
                    help="the slips end at the freeze force only, never where the wall stops")
    a = ap.parse_args(argv)
    if a.replicas < 2 or a.slips < 3 or not 0 <= a.kinetic_force < 48 or a.damping < 0:
        print(f"error: --replicas {a.replicas} (>= 2), --slips {a.slips} (>= 3), "
              f"--kinetic-force {a.kinetic_force} (0 to 48), --damping {a.damping} (>= 0)",
              file=sys.stderr)
        return 2
    for name in a.noises:
        noise = ({"velocity_noise": 0.0, "velocity_correlation": 0.0, "rattle": 0.0}
                 if name == "none" else getattr(film_noise, name))
        n = 1 if name == "none" else a.replicas
        runs = replica_runs(noise, n, a.slips, a.kinetic_force, a.damping, a.freeze_only)
        if a.slip_ends:
            print(f"## {name} {noise}: {slip_ends(runs, a.slips)}", flush=True)
            continue
        fits = replica_fits(runs, a.slips)
        print(f"## {name} {noise}: {len(fits)} replicas of {a.slips} slips", flush=True)
        if n == 1:
            f = fits[0]
            print(f"  F_k {f.kinetic_force.value:.2f}, B {f.film_damping.value:.2f}", flush=True)
            continue
        print(line("F_k", [f.kinetic_force for f in fits], a.kinetic_force))
        print(line("B", [f.film_damping for f in fits], a.damping), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
