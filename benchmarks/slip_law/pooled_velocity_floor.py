"""The pooled slip law of MD runs, or of controls of known law, against the fit's velocity floor.

    python benchmarks/slip_law/pooled_velocity_floor.py RUN_DIR... [--floors 0.1 0.2 0.3 0.4]
    python benchmarks/slip_law/pooled_velocity_floor.py --control RUNS REPLICAS [--share 0.2]
        [--lag TAU] [--stop-velocity V] [--floors ...]

The pooled fit (:func:`~filmfriction.analysis.slip_law.slip_law_pooled.fit_pooled_ensemble`)
keeps the lags of the mean slip whose velocity exceeds a floor, ``min_velocity_fraction``
(0.2) of its peak.  What a slip's slow ends carry (the yield's breaking, the re-stick) moves
with that floor; what is spread over the branches does not, and a branch's line keeps its
B over any floor only where its F(v) is a line.  Printed per floor: the decelerating
branch's F_k and B, the one law's co-moving mass, the loop step and the loop force (each
± its jackknife error over the runs).  With ``--control RUNS REPLICAS``: REPLICAS pools of
RUNS runs × 9 slips of the heavy slider's Coulomb + viscous mix (``SCALES["stiff"]``, its
noise, law spread 0.15; ``--share``, ``--lag`` as
:mod:`~filmfriction.analysis.groundtruth.pooled_controls`, ``--stop-velocity`` the mixes'
re-stick, negative: once the wall recoils that fast), each fitted at every floor: the
mean ± its standard error over the pools per floor, and the shift from the lowest floor
to the highest per pool (mean ± standard error, and its spread: what one pool's shift may
be by chance, to set an MD pool's shift against).  Seeds are fixed.
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import replace

import numpy as np

from filmfriction.analysis.calibration.slip_law_runs import fit_arguments, read_runs
from filmfriction.analysis.groundtruth.pooled_controls import pooled_runs
from filmfriction.analysis.groundtruth.slip_law_controls import SCALES
from filmfriction.analysis.slip_law.slip_law_cycles import MD_NOISE_TIME
from filmfriction.analysis.slip_law.slip_law_pooled import fit_pooled_ensemble

#: What is printed of each fit: (label, value, its error).
COLUMNS = (("decelerating F_k", lambda f: f.decelerating.kinetic_force,
            lambda f: f.decelerating.kinetic_force_stderr),
           ("decelerating B", lambda f: f.decelerating.damping,
            lambda f: f.decelerating.damping_stderr),
           ("one law m_c", lambda f: f.one_law.comoving_mass,
            lambda f: f.one_law.comoving_mass_stderr),
           ("loop step", lambda f: f.loop_step, lambda f: f.loop_step_stderr),
           ("loop force", lambda f: f.loop_force, lambda f: f.loop_force_stderr))


def md(run_dirs, floors) -> None:
    runs, shared, _ = read_runs(run_dirs, analyse=False)
    kw = fit_arguments(shared)
    print(f"{len(runs)} runs, {sum(len(r.table) for r in runs)} slips")
    first = None
    for fl in floors:
        f = fit_pooled_ensemble(runs, **kw, min_velocity_fraction=fl)
        first = first or f
        print(f"  floor {fl:g}: " + "; ".join(
            f"{name} {val(f):.4g} ± {err(f):.2g}" for name, val, err in COLUMNS)
            + f"; the rule: {f.verdict_from} {f.verdict}")
    print(f"  shift {floors[0]:g} → {floors[-1]:g}: " + "; ".join(
        f"{name} {val(f) - val(first):+.3g}" for name, val, _ in COLUMNS))


def controls(runs: int, replicas: int, floors, share: float, lag, stop) -> None:
    sc = SCALES["stiff"]
    if stop is not None:
        sc = replace(sc, mix={**sc.mix, "stop_velocity": stop})
    got = np.full((replicas, len(floors), len(COLUMNS)), math.nan)
    for k in range(replicas):
        rs, v = pooled_runs("coulomb", runs, 9, share=share, scale=sc, law_spread=0.15, lag=lag,
                            seed=(0, k))
        for i, fl in enumerate(floors):
            f = fit_pooled_ensemble(rs, mass=sc.mass, drive_velocity=v, film_mass=sc.film_mass,
                                    mount_damping=sc.mount_damping,
                                    min_window_time=MD_NOISE_TIME, min_velocity_fraction=fl)
            got[k, i] = [val(f) for _, val, _ in COLUMNS]
    print(f"{replicas} pools of {runs} runs x 9 slips, share {share:g}"
          + (f", lagging by {lag:g} τ" if lag else "")
          + (f", re-sticking at v <= {stop:g} σ/τ" if stop is not None else ""))
    se = lambda x: np.nanstd(x, ddof=1) / math.sqrt(np.isfinite(x).sum())
    for i, fl in enumerate(floors):
        print(f"  floor {fl:g}: " + "; ".join(
            f"{name} {np.nanmean(got[:, i, j]):.4g} ± {se(got[:, i, j]):.2g}"
            for j, (name, _, _) in enumerate(COLUMNS)))
    shift = got[:, -1] - got[:, 0]
    print(f"  shift {floors[0]:g} → {floors[-1]:g} per pool: " + "; ".join(
        f"{name} {np.nanmean(shift[:, j]):+.3g} ± {se(shift[:, j]):.2g} "
        f"(sd {np.nanstd(shift[:, j], ddof=1):.3g})" for j, (name, _, _) in enumerate(COLUMNS)))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="*", metavar="RUN_DIR")
    ap.add_argument("--floors", nargs="+", type=float, default=[0.1, 0.2, 0.3, 0.4])
    ap.add_argument("--control", nargs=2, type=int, metavar=("RUNS", "REPLICAS"))
    ap.add_argument("--share", type=float, default=0.2)
    ap.add_argument("--lag", type=float, default=None, metavar="TAU")
    ap.add_argument("--stop-velocity", type=float, default=None)
    args = ap.parse_args(argv)
    if bool(args.runs) == bool(args.control):
        ap.error("RUN_DIR… or --control RUNS REPLICAS, one of the two")
    if not all(0 < f < 1 for f in args.floors) or sorted(args.floors) != args.floors:
        ap.error(f"--floors {' '.join(map(str, args.floors))}: increasing, each in (0, 1)")
    if args.control and (args.control[0] < 3 or args.control[1] < 2):
        ap.error(f"--control {args.control[0]} {args.control[1]}: RUNS >= 3, REPLICAS >= 2")
    if args.lag is not None and not (math.isfinite(args.lag) and args.lag > 0):
        ap.error(f"--lag {args.lag!r}: a relaxation time > 0, finite")
    if not 0 <= args.share <= 1:
        ap.error(f"--share {args.share!r}: in [0, 1]")
    if args.stop_velocity is not None and not math.isfinite(args.stop_velocity):
        ap.error(f"--stop-velocity {args.stop_velocity!r}: finite")
    try:
        if args.control:
            controls(*args.control, args.floors, args.share, args.lag, args.stop_velocity)
        else:
            md(args.runs, args.floors)
    except ValueError as exc:
        print(f"pooled_velocity_floor: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
