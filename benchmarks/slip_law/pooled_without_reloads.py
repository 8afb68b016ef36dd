"""The pooled slip law of MD runs with the detector's split at re-sticks, without it, and
without the slips that still hold a rise.

    python benchmarks/slip_law/pooled_without_reloads.py RUN_DIR... [--rise 5]

The detector's scan merges slips whose sticks reload the spring by less than its threshold
h; it then splits each slip it found where, inside it, the force rises by more than h/3 at
no more than twice the loading rate K·V (the wall stopped: ``restick_fraction`` in
:func:`~filmfriction.analysis.stickslip.detect_slips`).  The runs' slips are pooled
(:func:`~filmfriction.analysis.slip_law.slip_law_pooled.fit_pooled_ensemble`, the jackknife
over the runs) three ways: as analysed (split); as the scan alone finds them
(``restick_fraction=0``, or re-detected with other fractions: ``--fractions``; each table
built as the analysis builds it, with K·V as the loading rate: the extrema refined,
the start-up slips the analysis left out, left out); and as analysed without the slips
inside which the force still rises by more than ``--rise`` (ε/σ) above its running minimum
(rises the rule did not take for re-sticks: faster than 2 K·V, a wall ringing back): how
much the verdict rests on the split and on those.  Prints the three fits and how many slips
each run has fewer than as analysed (for the scan alone: the splits, less any start-up slip
that held one), and the reloads the split found: each by how much the spring reloaded before
the slip it begins (over the run's h) and how fast (over K·V; the drive reloads a stuck wall
at K·V, a wall ringing back rises faster), the test of whether the wall stopped there
(tests/analysis/stickslip/test_irregular_slips.py: the same at this noise on model slips).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from dataclasses import replace

import numpy as np

from filmfriction.analysis.calibration.slip_law_runs import fit_arguments, read_runs
from filmfriction.analysis.analyze import slip_table
from filmfriction.analysis.stickslip import detect_slips
from filmfriction.analysis.slip_law.slip_law_pooled import fit_pooled_ensemble
from filmfriction.reduced_model.cycles import cycle_table


def inner_rise(force: np.ndarray, a: int, b: int) -> float:
    """The largest rise of ``force`` over its running minimum between samples a and b."""
    seg = force[a:b + 1]
    return float(np.max(seg - np.minimum.accumulate(seg)))


def redetected(rs, spring_constant: float, drive_velocity: float, restick_fraction: float):
    """Run ``rs``'s slips as the detector finds them with ``restick_fraction`` (0: the scan
    alone, without the split), tabulated as the analysis tabulates (:func:`slip_table`; the
    slips its analysis left out at the start left out: ``summary_skips_first`` of its
    ``analysis.json``)."""
    _, table = slip_table(rs.time, rs.spring_force, spring_constant=spring_constant,
                          drive_velocity=drive_velocity, wall_position=rs.wall_position,
                          restick_fraction=restick_fraction)
    doc = json.loads((Path(rs.name) / "analysis.json").read_text())
    skip = int((doc.get("slips") or {}).get("summary_skips_first") or 0)
    return table.yield_index[skip:], table.stick_index[skip:]


def split_reloads(rs, spring_constant: float, drive_velocity: float) -> list[tuple[float, float]]:
    """Each slip the split at re-sticks adds to run ``rs`` (a yield the scan alone does not
    have): (the reload before it over h, its rate over K·V)."""
    t, f = rs.time, rs.spring_force
    kv, out = spring_constant * drive_velocity, []
    # the detector's events only: the table's refined extrema are not needed here
    split = detect_slips(t, f, loading_rate=kv)
    scan = detect_slips(t, f, loading_rate=kv, restick_fraction=0)
    for i in range(1, split.count):
        y, s = split.yield_index[i], split.stick_index[i - 1]
        if y not in scan.yield_index:
            rise = f[y] - f[s]
            out.append((rise / split.threshold, rise / (t[y] - t[s]) / kv))
    return out


def pooled(runs, shared, how, rise: float):
    """The pooled fit of ``runs`` (with ``shared``, as :func:`read_runs` gives them), their
    slips as analysed (``how`` "analysed"), without
    those holding a rise > ``rise`` ("left out"), or re-detected with ``how`` as the
    re-stick fraction (a number; 0 the scan alone)."""
    k = shared["spring_constant"]
    out, fewer = [], []
    for rs in runs:
        f = rs.spring_force
        y, s = rs.table.yield_index, rs.table.stick_index
        if not isinstance(how, str):
            ya, sa = redetected(rs, k, shared["drive_velocity"], how)
        elif how == "left out":
            keep = np.array([inner_rise(f, a, b) <= rise for a, b in zip(y, s)], bool)
            ya, sa = y[keep], s[keep]
        else:
            ya, sa = y, s
        fewer.append(len(y) - len(ya))
        out.append(replace(rs, table=cycle_table(rs.time, f, np.asarray(ya, int),
                                                 np.asarray(sa, int), spring_constant=k,
                                                 wall_position=rs.wall_position)))
    fit = fit_pooled_ensemble(out, **fit_arguments(shared))
    return fit, sum(len(r.table) for r in out), fewer


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dirs", nargs="+")
    ap.add_argument("--rise", type=float, default=5.0, help="ε/σ (default 5)")
    ap.add_argument("--fractions", type=float, nargs="+", default=[0.0],
                    help="re-stick fractions to re-detect with (default 0: the scan alone); "
                         "e.g. 0 0.25 0.5 for the split's sensitivity")
    args = ap.parse_args(argv)
    runs, shared, _ = read_runs(args.run_dirs)        # each trace parsed once
    for how in ("analysed", *args.fractions, "left out"):
        fit, n, fewer = pooled(runs, shared, how, args.rise)
        law = fit.law
        what = ("as analysed (split at re-sticks)" if how == "analysed"
                else f"as analysed, no inner rise > {args.rise:g}" if how == "left out"
                else "the scan alone (no split)" if how == 0
                else f"re-detected, re-stick fraction {how:g}")
        print(f"{what}: {len(args.run_dirs)} runs, {n} slips (fewer per run: {fewer}): "
              f"{fit.verdict}; F_k {law.kinetic_force:.1f} ± {law.kinetic_force_stderr:.1f}, "
              f"B {law.damping:.0f} ± {law.damping_stderr:.0f} ({law.damping_sigmas:+.1f} σ), "
              f"n {law.exponent:+.2f} ± {law.exponent_stderr:.2f}, v̄ {law.mean_velocity:.3f}")
    reloads = np.array([r for rs in runs for r in split_reloads(rs, shared["spring_constant"],
                                                                 shared["drive_velocity"])])
    if reloads.size:
        size, rate = reloads[:, 0], reloads[:, 1]
        print(f"the split's reloads: {len(size)}; by h/3-h/2 {int(np.sum(size < 0.5))}, "
              f"h/2-h {int(np.sum(size >= 0.5))}; rate {rate.min():.2f}-{rate.max():.2f} K·V "
              f"(median {np.median(rate):.2f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
