"""The pooled slip law of MD runs with and without the slips inside which the spring reloaded.

    python benchmarks/slip_law/pooled_without_reloads.py RUN_DIR... [--rise 5]

A detected slip whose spring force rises, somewhere between its yield and its re-stick, by
more than ``--rise`` (ε/σ) above its running minimum is not one slip: the wall stopped and the
drive reloaded the spring (smaller slips merged, their drops below the detector's threshold),
or it rang.  The runs' slips are pooled (:func:`~filmfriction.analysis.slip_law.slip_law_pooled.fit_pooled_ensemble`,
the jackknife over the runs) with every analysed slip, and again without those: how much the
verdict rests on them; and a third time with those slips split where the spring reloads
(:func:`split`: each sub-slip from its yield to the running minimum before the rise, the next
from the top of the rise), as a detector that confirmed each re-stick would find them.  Prints
the three fits and how many slips each run loses or gains.
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import replace

import numpy as np

from filmfriction.analysis.calibration.slip_law_runs import fit_arguments, read_runs
from filmfriction.analysis.slip_law.slip_law_pooled import fit_pooled_ensemble
from filmfriction.reduced_model.cycles import cycle_table


def inner_rise(force: np.ndarray, a: int, b: int) -> float:
    """The largest rise of ``force`` over its running minimum between samples a and b."""
    seg = force[a:b + 1]
    return float(np.max(seg - np.minimum.accumulate(seg)))


def split(force: np.ndarray, a: int, b: int, rise: float) -> list[tuple[int, int]]:
    """Slip (a, b) as the slips it holds: cut at the running minimum before each rise of more
    than ``rise``, the next slip yielding at the top of that rise (the highest force before it
    falls ``rise`` below it)."""
    seg = force[a:b + 1]
    up = np.flatnonzero(seg - np.minimum.accumulate(seg) > rise)
    if up.size == 0:
        return [(a, b)]
    j = int(up[0])
    stick = int(np.argmin(seg[:j + 1]))
    peak = j
    for k in range(j, seg.size):
        if seg[k] > seg[peak]:
            peak = k
        if seg[peak] - seg[k] > rise:
            break
    return [(a, a + stick)] + split(force, a + peak, b, rise)


def pooled(dirs, rise: float | None, cut: bool = False):
    runs, shared, _ = read_runs(dirs)
    out, lost = [], []
    for rs in runs:
        f = rs.spring_force
        y, s = rs.table.yield_index, rs.table.stick_index
        if cut:
            pairs = [q for a, b in zip(y, s) for q in split(f, int(a), int(b), rise)]
        else:
            pairs = [(a, b) for a, b in zip(y, s) if rise is None or inner_rise(f, a, b) <= rise]
        lost.append(len(y) - len(pairs))
        ya, sa = (np.array([q[i] for q in pairs], int) for i in (0, 1))
        out.append(replace(rs, table=cycle_table(rs.time, f, ya, sa,
                                                 spring_constant=shared["spring_constant"],
                                                 wall_position=rs.wall_position)))
    fit = fit_pooled_ensemble(out, **fit_arguments(shared))
    return fit, sum(len(r.table) for r in out), lost


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dirs", nargs="+")
    ap.add_argument("--rise", type=float, default=5.0, help="ε/σ (default 5)")
    args = ap.parse_args(argv)
    for rise, cut in ((None, False), (args.rise, False), (args.rise, True)):
        fit, n, lost = pooled(args.run_dirs, rise, cut)
        law = fit.law
        what = ("every slip" if rise is None else f"split at each inner rise > {rise:g}" if cut
                else f"no inner rise > {rise:g}")
        print(f"{what}: {len(args.run_dirs)} runs, {n} slips (fewer per run: {lost}): "
              f"{fit.verdict}; F_k {law.kinetic_force:.1f} ± {law.kinetic_force_stderr:.1f}, "
              f"B {law.damping:.0f} ± {law.damping_stderr:.0f} ({law.damping_sigmas:+.1f} σ), "
              f"n {law.exponent:+.2f} ± {law.exponent_stderr:.2f}, v̄ {law.mean_velocity:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
