"""The controls' noise calibrated to the MD's: slip residuals and the wall's jitter of MD runs and
of random-force replicas, measured the same way (docs/results/slip-law.md, "The MD's noise").

    python benchmarks/slip_law/md_noise_calibration.py RUN [RUN ...] [--replicas 40] [--scan]
    python benchmarks/slip_law/md_noise_calibration.py RUN ... --scale stiff [--noise U RHO RATTLE ...]
                                                       [--share S] [--comoving-mass MC]
                                                       [--lags 1 4 16 64 256]
                                                       [--registry-period L]
                                                       [--corrugation DF L PHI]

For the runs' analysed slips pooled, and for the random-force replicas of the ``viscous``
control (:func:`~filmfriction.analysis.groundtruth.md_noise.replica_slips`, seed 0) at each
process of :data:`PROCESSES` (the named ones of
:mod:`~filmfriction.analysis.groundtruth.film_noise` and the u whose plain residual
has the MD's rms): the rms of the wall velocity's change over 0.25, 1, 2 τ; the residual's
rms (mean over the slips ± its standard error) and autocorrelation at 0.25, 1, 2, 4 τ, with
F_k + B·v fitted (``trend 1``; and the share of its variance the slips' mean shape carries,
:func:`~filmfriction.analysis.groundtruth.md_noise.common_shape_share`) and with Δt², Δt³
fitted besides (``trend 3``).  ``--scan``: besides, u of 1 σ/τ at correlations 0.8–0.999 per
sample (rattling 0.15): how slow a residual this family of noise can leave.

``--scale stiff``: the replicas are the heavy slider's (``m1e4``: the K = 8 film's slider at
M = 10⁴'s) (:data:`~filmfriction.analysis.groundtruth.slip_law_controls.SCALES`, its ``viscous``
control, 10 slips each, its mount dashpot), the processes its calibrated noise and each
``--noise`` (u's rms, its correlation per sample, the rattling); ``--share S``: the
replicas slip by the scale's Coulomb + viscous mix of viscous share S, not its ``viscous``
control (the light sliders' viscous controls slip too briefly); ``--comoving-mass``: the
film's mass their slipping wall carries (the fit knows the scale's M); ``--lags`` (samples) the
lags of the residual's autocorrelation, the first three (or, with five or more, the first
four) those of the jitter; the numbers are printed to 3 significant digits.
``--registry-period L``: the residuals of the MD and of the replicas alike with the walls'
registry force of period L fitted besides (what is left is the noise beside it, as the
slip-law fit sees it); ``--corrugation DF L PHI``: the replicas' mix of ``--share`` carries
the registry force DF·sin(2π·x/L + PHI), each replica a run with its own yield force
(:func:`~filmfriction.analysis.groundtruth.pooled_controls.pooled_runs`).
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from filmfriction.analysis.groundtruth.md_noise import (common_shape_share, increment_rms,
                                                        replica_slips,
                                                        residual_statistics, residuals, run_slips,
                                                        slip_velocities)
from filmfriction.analysis.groundtruth.md_noise import LAGS
from filmfriction.analysis.groundtruth.film_noise import MD_NOISE, RESIDUAL_AS_NOISE
from filmfriction.analysis.groundtruth.slip_law_controls import SCALES

PROCESSES = {"MD_NOISE": MD_NOISE, "RESIDUAL_AS_NOISE": RESIDUAL_AS_NOISE,
             "the plain residual's rms": {"velocity_noise": 1.9, "velocity_correlation": 0.95,
                                          "rattle": 0.15}}


def row(name: str, slips: list[dict], lags=LAGS, fmt: str = ".3f",
        registry_period: float | None = None) -> str:
    inc = increment_rms([v for sl in slips for v in slip_velocities(
        sl["wall_velocity"], sl["yields"], sl["sticks"])],
        lags=tuple(lags[:3] if len(lags) < 5 else lags[:4]))
    cells = [", ".join(f"{x:{fmt}}" for x in inc)]
    for trend in (1, 3):
        rs = [r for sl in slips
              for r in residuals(sl, trend=trend, registry_period=registry_period)]
        st = residual_statistics(rs, lags=tuple(lags))
        cells.append(f"{st['rms']:{fmt}} ± {st['rms_stderr']:{fmt}}; " + ", ".join(
            f"{a:.2f} ± {e:.2f}" for a, e in zip(st["autocorrelation"],
                                                  st["autocorrelation_stderr"])))
        if trend == 1:
            cells.append(f"{common_shape_share(rs):.2f}")
    return f"| {name} | {st['slips']} | " + " | ".join(cells) + " |"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", metavar="RUN", help="run directories (analysed slips)")
    ap.add_argument("--replicas", type=int, default=40)
    ap.add_argument("--scan", action="store_true", help="also u of 1 σ/τ at several correlations")
    ap.add_argument("--scale", default="klein", choices=list(SCALES),
                    help="the replicas' scale (stiff: the heavy slider's)")
    ap.add_argument("--noise", nargs=3, type=float, action="append", default=[],
                    metavar=("U", "RHO", "RATTLE"), help="a process besides (repeatable)")
    ap.add_argument("--share", type=float, default=None,
                    help="the replicas slip by the scale's Coulomb + viscous mix of this "
                         "viscous share (default: its viscous control)")
    ap.add_argument("--comoving-mass", type=float, default=0.0,
                    help="the film's mass the replicas' slipping wall carries (m)")
    ap.add_argument("--lags", nargs="+", type=int, default=list(LAGS),
                    help="lags in samples (residual's autocorrelation; the jitter's)")
    ap.add_argument("--registry-period", type=float, default=None, metavar="L",
                    help="fit the walls' registry force of period L (σ) in every residual")
    ap.add_argument("--corrugation", nargs=3, type=float, default=None,
                    metavar=("DF", "L", "PHI"),
                    help="the replicas' mix (--share) carries DF·sin(2π·x/L + PHI)")
    a = ap.parse_args(argv)
    missing = [r for r in a.runs if not (Path(r) / "trace.csv").is_file()]
    if missing:
        print(f"error: RUN without trace.csv: {', '.join(missing)}", file=sys.stderr)
        return 2
    if a.replicas < 1:
        print(f"error: --replicas {a.replicas}: must be >= 1", file=sys.stderr)
        return 2
    if a.share is not None and not 0 <= a.share <= 1:
        print(f"error: --share {a.share}: must be in [0, 1]", file=sys.stderr)
        return 2
    if not (math.isfinite(a.comoving_mass) and a.comoving_mass >= 0):
        print(f"error: --comoving-mass {a.comoving_mass}: must be finite and >= 0",
              file=sys.stderr)
        return 2
    if a.registry_period is not None and not (math.isfinite(a.registry_period)
                                              and a.registry_period > 0):
        print(f"error: --registry-period {a.registry_period}: must be finite and > 0",
              file=sys.stderr)
        return 2
    if a.corrugation is not None and (a.share is None or not all(
            map(math.isfinite, a.corrugation)) or not a.corrugation[1] > 0):
        print(f"error: --corrugation {a.corrugation}: finite, L > 0, and with --share",
              file=sys.stderr)
        return 2
    if (a.scale != "klein" or a.noise or a.lags != list(LAGS) or a.share is not None
            or a.comoving_mass or a.registry_period is not None):
        return other_scale(a)
    print("| noise | slips | wall velocity's change over 0.25, 1, 2 τ (rms, σ/τ) | residual, "
          "F_k + B·v: rms; autocorrelation at 0.25, 1, 2, 4 τ | its mean shape's share | "
          "residual, + Δt², Δt³ |\n|---|---|---|---|---|---|")
    print(row(f"MD ({len(a.runs)} runs)", [run_slips(r) for r in a.runs]), flush=True)
    processes = dict(PROCESSES)
    if a.scan:
        processes |= {f"scan {rho}": {"velocity_noise": 1.0, "velocity_correlation": rho,
                                      "rattle": 0.15} for rho in (0.8, 0.9, 0.95, 0.99, 0.999)}
    for name, noise in processes.items():
        print(row(f"{name} {noise}", replica_slips(noise, replicas=a.replicas)), flush=True)
    return 0


def other_scale(a) -> int:
    """The table at ``a.scale`` with ``a.lags``: the MD, the scale's noise, each ``--noise``."""
    sc = SCALES[a.scale]
    dt = sc.dt
    lags = a.lags
    jit = lags[:3] if len(lags) < 5 else lags[:4]
    print(f"| noise | slips | wall velocity's change over {', '.join(f'{k * dt:g}' for k in jit)} τ "
          f"(rms, σ/τ) | residual, F_k + B·v: rms; autocorrelation at "
          f"{', '.join(f'{k * dt:g}' for k in lags)} τ | its mean shape's share | "
          "residual, + Δt², Δt³ |\n|---|---|---|---|---|---|")
    reg = a.registry_period
    if reg is not None:
        print(f"(every residual with the registry force of period {reg:g} σ fitted besides"
              + (", the replicas' mix carrying {:g}·sin(2π·x/{:g} + {:g}))".format(*a.corrugation)
                 if a.corrugation else ")"))
    print(row(f"MD ({len(a.runs)} runs)", [run_slips(r) for r in a.runs], lags, ".3g", reg),
          flush=True)
    processes = {f"{a.scale} noise": sc.noise} | {
        f"u {u:g}, {rho:g}, rattle {r:g}": {"velocity_noise": u, "velocity_correlation": rho,
                                            "rattle": r} for u, rho, r in a.noise}
    for name, noise in processes.items():
        print(row(f"{name} {noise}", replica_slips(noise, replicas=a.replicas, scale=sc,
                                                   share=a.share, duration=None, slips=10,
                                                   comoving_mass=a.comoving_mass,
                                                   corrugation=a.corrugation),
                  lags, ".3g", reg),
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
