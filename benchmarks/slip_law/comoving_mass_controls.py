"""The slip law pooled over runs whose film carries a co-moving mass: what the decelerating
branch and the one law read, at the light sliders' scales.

    python benchmarks/slip_law/comoving_mass_controls.py [--scale m1e2] [--kinetic 29.1]
        [--damping 30] [--comoving-mass 179] [--runs 20] [--slips 10] [--replicas 100]
        [--law-spread 0.1] [--static-spread 0.2] [--noise U RHO RATTLE] [--noise-free]
        [--stop-velocity V]

Each replica is G runs of the scale's slider (:data:`~filmfriction.analysis.groundtruth.
slip_law_controls.SCALES`; each run with its own yield force, ± ``--static-spread``, and with
``--law-spread`` its own film) slipping by F_k + B·v while the film carries m_c with the
wall (:func:`~filmfriction.analysis.groundtruth.pooled_controls.pooled_runs`; the fit is given
the slider's M alone), pooled and fitted as the MD's runs are (jackknife over the runs).
The law is given by F_k and B; its force at the scale's slip velocity sets the mix.  Printed
for m_c = 0 and for ``--comoving-mass``: the runs' median slip duration, the rule's branch
and verdicts, and per branch
(decelerating, one law) the replicas' mean ± its standard error of F_k, B, the exponent n and
m_c, the truth beside them (F_k, B; n = B·v̄/(F_k + B·v̄) at the branch's own mean v̄
over the replicas) and how many replicas' 2 σ cover F_k and B.  Seeds fixed: counts are
deterministic.
"""
from __future__ import annotations

import argparse
import math
import sys
from collections import Counter
from dataclasses import replace

import numpy as np

from filmfriction.analysis.groundtruth.pooled_controls import pooled_runs
from filmfriction.analysis.groundtruth.random_force import NOISE_FREE
from filmfriction.analysis.groundtruth.slip_law_controls import SCALES
from filmfriction.analysis.slip_law.slip_law_cycles import MD_NOISE_TIME
from filmfriction.analysis.slip_law.slip_law_pooled import fit_pooled_ensemble
from filmfriction.analysis.slip_law.slip_law_stats import sigmas



def summary(fits, branch: str, fk: float, b: float) -> str:
    xs = [getattr(f, branch) for f in fits]

    def ms(attr):
        a = np.array([getattr(x, attr) for x in xs], float)
        a = a[np.isfinite(a)]
        if not a.size:
            return "–"
        return f"{a.mean():.3g} ± {a.std(ddof=1) / math.sqrt(a.size) if a.size > 1 else 0:.2g}"

    cov = [sum(abs(sigmas(getattr(x, a) - t, getattr(x, f"{a}_stderr"), x.dof)) < 2
               for x in xs) for a, t in (("kinetic_force", fk), ("damping", b))]
    vbar = float(np.nanmean([x.mean_velocity for x in xs]))
    n_true = b * vbar / (fk + b * vbar)
    return (f"F_k {ms('kinetic_force')} (truth {fk:.3g}, covered {cov[0]}/{len(xs)}); "
            f"B {ms('damping')} (truth {b:.3g}, covered {cov[1]}/{len(xs)}); "
            f"n {ms('exponent')} (truth {n_true:.2f} at v̄ {vbar:.3g}); "
            f"m_c {ms('comoving_mass')}")


def fits_of(sc, a, share, noise, mc) -> tuple[list, int, float]:
    """The pooled fits of the replicas, how many were left out because one of their runs
    slid without a complete slip (a film drawn off the law that slides smoothly), and the
    median slip duration of the fitted runs."""
    fits, skipped, durations = [], 0, []
    for k in range(a.replicas):
        runs, vd = pooled_runs("", a.runs, a.slips, share=share, scale=sc,
                               law_spread=a.law_spread, static_spread=a.static_spread,
                               noise=noise, comoving_mass=mc,
                               seed=(0, k))
        try:
            fits.append(fit_pooled_ensemble(runs, mass=sc.mass, drive_velocity=vd,
                                            mount_damping=sc.mount_damping,
                                            film_mass=sc.film_mass,
                                            min_window_time=MD_NOISE_TIME))
        except ValueError:          # a run without a slip that relaxes the spring
            skipped += 1
            continue
        durations += [d for r in runs for d in r.table.slip_duration]
    return fits, skipped, float(np.median(durations)) if durations else math.nan


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scale", default="m1e2", choices=list(SCALES))
    ap.add_argument("--kinetic", type=float, default=29.1, help="F_k (ε/σ)")
    ap.add_argument("--damping", type=float, default=30.0, help="B (m/τ)")
    ap.add_argument("--comoving-mass", type=float, default=179.0, help="m_c (m)")
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--slips", type=int, default=10)
    ap.add_argument("--replicas", type=int, default=100)
    ap.add_argument("--law-spread", type=float, default=0.1,
                    help="the runs' films drawn this share off the law (0.15 makes some "
                         "runs slide without a slip at these scales)")
    ap.add_argument("--static-spread", type=float, default=0.2)
    ap.add_argument("--noise", nargs=3, type=float, default=None,
                    metavar=("U", "RHO", "RATTLE"), help="the film's random force (default: "
                                                         "the scale's)")
    ap.add_argument("--noise-free", action="store_true")
    ap.add_argument("--stop-velocity", type=float, default=None,
                    help="the velocity (σ/τ) at which a slip re-sticks once armed (default: "
                         "the scale's, a quarter of its slip velocity; 0: where the wall stops; "
                         "--stop-velocity=-inf: only at the scale's backward force)")
    a = ap.parse_args(argv)
    problems = [f"{k} {v!r}: must be finite and >= 0" for k, v in (
        ("--kinetic", a.kinetic), ("--damping", a.damping), ("--comoving-mass", a.comoving_mass))
        if not (math.isfinite(v) and v >= 0)]
    if not problems and a.kinetic + a.damping <= 0:
        problems.append("--kinetic 0 --damping 0: the law needs a force")
    problems += [f"{k} {v}: must be >= {lo}" for k, v, lo in (
        ("--runs", a.runs, 3), ("--slips", a.slips, 1), ("--replicas", a.replicas, 1)) if v < lo]
    problems += [f"{k} {v!r}: must be in [0, 1)" for k, v in (
        ("--law-spread", a.law_spread), ("--static-spread", a.static_spread))
        if not 0 <= v < 1]
    if a.noise is not None and not (all(math.isfinite(x) for x in a.noise)
                                    and a.noise[0] >= 0 and 0 <= a.noise[1] < 1
                                    and a.noise[2] >= 0):
        problems.append(f"--noise {' '.join(map(str, a.noise))}: U >= 0, RHO in [0, 1), "
                        "RATTLE >= 0")
    if a.stop_velocity is not None and not (a.stop_velocity == -math.inf or (
            math.isfinite(a.stop_velocity) and a.stop_velocity >= 0)):
        problems.append(f"--stop-velocity {a.stop_velocity!r}: must be finite and >= 0, or -inf")
    if problems:
        for p in problems:
            print(f"error: {p}", file=sys.stderr)
        return 2
    sc = SCALES[a.scale]
    v = sc.mix["slip_velocity"]
    force = a.kinetic + a.damping * v
    sc = replace(sc, mix={**sc.mix, "film_force": force} | (
        {} if a.stop_velocity is None else {"stop_velocity": a.stop_velocity}))
    share = a.damping * v / force
    noise = (NOISE_FREE if a.noise_free else
             None if a.noise is None else dict(zip(("velocity_noise", "velocity_correlation",
                                                    "rattle"), a.noise)))
    print(f"co-moving mass controls at the {a.scale} scale: F_k {a.kinetic:g}, B {a.damping:g} "
          f"(viscous share {share:.3f} of {force:.3g} ε/σ at {v:g} σ/τ), M {sc.mass:g}, "
          f"{a.replicas} replicas of {a.runs} runs x {a.slips} slips, law spread "
          f"{a.law_spread:g}, yields ± {a.static_spread:g}, noise {noise or sc.noise}, "
          f"re-stick at {sc.mix['stop_velocity']:g} σ/τ once armed", flush=True)
    for mc in (0.0, a.comoving_mass):
        fits, skipped, slip = fits_of(sc, a, share, noise, mc)
        print(f"\n## m_c = {mc:g}: {len(fits)} replicas fitted ({skipped} left out: a run "
              f"without a complete slip), median slip {slip:.3g}; verdict {dict(Counter(f.verdict for f in fits))}, "
              f"from {dict(Counter(f.verdict_from for f in fits))}")
        if not fits:
            continue
        for branch in ("decelerating", "one_law"):
            print(f"  {branch:12s} {summary(fits, branch, a.kinetic, a.damping)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
