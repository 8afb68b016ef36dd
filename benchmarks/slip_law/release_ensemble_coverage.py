"""The release fits on the fluctuating Newtonian film: coverage, bias and verdicts (docs/results/slip-law.md).

    python benchmarks/slip_law/release_ensemble_coverage.py [--replicas 100] [--releases 67] [--seed 1]
    python benchmarks/slip_law/release_ensemble_coverage.py --bins SEED   # one replica, binned as the MD

Replicas of ``--releases`` releases each of the wall on the fluctuating Newtonian film at
the ``liquid-release`` scene's scale (:mod:`filmfriction.analysis.groundtruth.film_release`:
η = 0.783, ρ = 0.485, A = 94.3, W = 6.1, M = 500, K = 1, x0 = 20, kT = 1.5, sampled every
0.05 τ), fitted by the ensemble fit (:func:`~filmfriction.analysis.groundtruth.release_control.fit_release_ensemble`:
the mean release, jackknife errors) and the per-release fit (:func:`~filmfriction.analysis.groundtruth.release_control.fit_releases`).
Prints, per fit: the mean and standard deviation over the replicas of the loop step, the one
law's F_k, B and m_c, how often ±2 standard errors cover the truth (loop step 0, F_k 0,
B = η·A/W and the noise-free film's own fitted B; m_c = ρ·A·W/3), and the verdicts; then the
two negative controls with the ensemble fit: a yield of ``--yield-force`` on the accelerating
branch (up to the noise-free peak velocity) and a kinetic force ``--kinetic-force`` on the wall.
``--bins SEED``: instead, one replica of the null (seed SEED) binned as
``benchmarks/slip_law/fit_release_runs.py`` bins the MD releases (``branch_bins``: the film force
minus the ensemble fit's one law and minus each release's own law fitted to its smoothed
samples, per branch and bin of v / v_peak).
"""
from __future__ import annotations

import argparse
import sys
from collections import Counter

import numpy as np

from filmfriction.analysis.groundtruth.film_release import (Film, film_release, held_until,
                                                            peak_time, release_traces)
from filmfriction.analysis.groundtruth.release_control import fit_release_ensemble, fit_releases

FIELDS = ("loop step", "F_k", "B", "m_c")


def numbers(fit) -> dict:
    """(estimate, standard error) of the loop step and the one law's F_k, B, m_c."""
    o = fit.one_law
    return {"loop step": (fit.loop_step, fit.loop_step_stderr),
            "F_k": (o.kinetic_force, o.kinetic_force_stderr),
            "B": (o.damping, o.damping_stderr), "m_c": (o.comoving_mass, o.comoving_mass_stderr)}


def summary(name: str, rows: list[dict], verdicts: list[str], truths: dict) -> None:
    print(f"{name} ({len(rows)} replicas):")
    for f in FIELDS:
        est = np.array([r[f][0] for r in rows])
        se = np.array([r[f][1] for r in rows])
        cover = "; ".join(f"±2 s.e. covers {label} {val:.3g} in "
                          f"{np.mean(np.abs(est - val) <= 2 * se):.2f}"
                          for label, val in truths[f])
        print(f"  {f:9s} mean {est.mean():+.3f} (s.e. of the mean {est.std(ddof=1) / np.sqrt(est.size):.3f}), "
              f"sd over replicas {est.std(ddof=1):.3f}, mean s.e. {se.mean():.3f}; {cover}")
    print("  verdicts: " + ", ".join(f"{k} {v}" for k, v in Counter(verdicts).most_common()))


def bins(seed: int, releases: int) -> int:
    """One replica of the null binned as the MD releases are (module text)."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location(
        "fit_release_runs", Path(__file__).with_name("fit_release_runs.py"))
    runs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(runs)
    film = Film()
    trs = [tr | {"gap": np.full(tr["time"].size, film.width)}    # no gap change: no load term
           for tr in release_traces(film_release(releases, film, seed=seed))]
    o = fit_release_ensemble(trs, mass=film.mass).one_law
    out = runs.branch_bins(trs, film.mass, (o.kinetic_force, o.damping, o.comoving_mass), 0.0)
    (fk, sfk), (b, sb), (mc, smc) = out.pop("samples' law")
    print(f"{releases} releases on the fluctuating film (seed {seed}); the one law (ensemble fit) "
          f"F_k {o.kinetic_force:.2f}, B {o.damping:.2f}, m_c {o.comoving_mass:.1f}; the samples' "
          f"law F_k {fk:.2f} ± {sfk:.2f}, B {b:.2f} ± {sb:.2f}, m_c {mc:.1f} ± {smc:.1f}")
    print("bins of v/v_peak 0.2-0.4-0.6-0.8-1:")
    for (branch, name), vals in out.items():
        if name != "P·A·dD/dx":
            print(f"  {branch:12s} {name:30s} " + "  ".join(f"{m:+.2f} ± {e:.2f}" for m, e in vals))
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--replicas", type=int, default=100)
    ap.add_argument("--releases", type=int, default=67)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--negative-replicas", type=int, default=40)
    ap.add_argument("--yield-force", type=float, default=3.0)
    ap.add_argument("--kinetic-force", type=float, default=2.5)
    ap.add_argument("--bins", type=int, metavar="SEED")
    a = ap.parse_args(argv)
    if a.bins is not None:
        return bins(a.bins, a.releases)
    if a.replicas < 2 or a.releases < 3 or a.negative_replicas < 0:
        print(f"error: --replicas {a.replicas} (>= 2), --releases {a.releases} (>= 3), "
              f"--negative-replicas {a.negative_replicas} (>= 0)", file=sys.stderr)
        return 2
    film = Film()
    exact = fit_releases(release_traces(film_release(1, film, kT=0.0)) * 3, mass=film.mass)
    truths = {"loop step": [("0", 0.0)], "F_k": [("0", 0.0)],
              "B": [("η·A/W", film.damping), ("the noise-free fit's", exact.one_law.damping)],
              "m_c": [("ρ·A·W/3", film.comoving_mass),
                      ("the noise-free fit's", exact.one_law.comoving_mass)]}
    print(f"film: B = η·A/W = {film.damping:.3f}, m_c = ρ·A·W/3 = {film.comoving_mass:.2f}; "
          f"noise-free fit: loop step {exact.loop_step:.3f}, F_k {exact.one_law.kinetic_force:.3f}, "
          f"B {exact.one_law.damping:.3f}, m_c {exact.one_law.comoving_mass:.2f}")
    seeds = np.random.SeedSequence(a.seed).spawn(a.replicas + 2 * a.negative_replicas)
    ens, per, v_ens, v_per = [], [], [], []
    for s in seeds[:a.replicas]:
        trs = release_traces(film_release(a.releases, film, seed=s))
        f = fit_release_ensemble(trs, mass=film.mass)
        g = fit_releases(trs, mass=film.mass)
        ens.append(numbers(f)); v_ens.append(f"{f.verdict} ({f.verdict_from})")
        per.append(numbers(g)); v_per.append(f"{g.verdict} ({g.verdict_from})")
    print(f"{a.releases} releases per replica, seed {a.seed}")
    summary("ensemble fit (mean release, jackknife errors)", ens, v_ens, truths)
    summary("per-release fit (the slips' scatter)", per, v_per, truths)
    if a.negative_replicas:
        t_peak = peak_time(film)
        rows, verdicts = [], []
        for s in seeds[a.replicas:a.replicas + a.negative_replicas]:
            trs = held_until(release_traces(film_release(a.releases, film, seed=s)),
                             a.yield_force, t_peak)
            f = fit_release_ensemble(trs, mass=film.mass)
            rows.append(numbers(f)); verdicts.append(f"{f.verdict} ({f.verdict_from})")
        summary(f"yield of {a.yield_force:g} on the accelerating branch (to t = {t_peak:.2f})",
                rows, verdicts, truths | {"loop step": [(f"{a.yield_force:g}", a.yield_force)]})
        rows, verdicts = [], []
        for s in seeds[a.replicas + a.negative_replicas:]:
            trs = release_traces(film_release(a.releases, film, seed=s,
                                              kinetic_force=a.kinetic_force))
            f = fit_release_ensemble(trs, mass=film.mass)
            rows.append(numbers(f)); verdicts.append(f"{f.verdict} ({f.verdict_from})")
        summary(f"kinetic force {a.kinetic_force:g} on the wall", rows, verdicts,
                truths | {"F_k": [(f"{a.kinetic_force:g}", a.kinetic_force)]})
    return 0


if __name__ == "__main__":
    sys.exit(main())
