"""``filmfriction bench``: the film scene's engine throughput beside bulk LJ.

Both run in the same invocation, on the same MPI ranks, with the same atom
count (to within one fcc cell layer) and cutoff; the figure of merit is
atom-steps per second (LAMMPS's own "Performance:" line) and their ratio.
The film should be at least as fast per atom: wall-wall pairs are excluded,
the bottom wall is not integrated and the top wall moves as one body.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import tempfile
from pathlib import Path

from filmfriction import md_inputs
from . import engine
from .runner import atom_steps_per_second, loop_atoms
from .scene import load



def register(subparsers) -> None:
    p = subparsers.add_parser("bench", help="film-scene throughput beside bulk LJ (prints the ratio)")
    p.add_argument("scene", nargs="?", default="stick-slip")
    p.add_argument("--np", type=int, default=2)
    p.add_argument("--steps", type=int, default=20000, help="timed steps of each system")
    p.add_argument("--repeat", type=int, default=2,
                   help="alternate film and bulk runs this many times; the best of each counts")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=main)


def _run(cmd, cwd) -> tuple[float, int]:
    out = subprocess.run(cmd, cwd=cwd, env=engine.engine_env(), capture_output=True, text=True)
    if out.returncode != 0 or "ERROR" in out.stdout:
        err = [l for l in out.stdout.splitlines() if "ERROR" in l] or [out.stderr.strip()]
        raise RuntimeError(f"LAMMPS failed: {err[0]}")
    lines = out.stdout.splitlines()
    rates = [r for r in map(atom_steps_per_second, lines) if r is not None]
    atoms = [n for n in map(loop_atoms, lines) if n is not None]
    return rates[-1], atoms[-1]


def bulk_cells(n_atoms: int) -> tuple[int, int, int]:
    """fcc cells (4 atoms each) of a near-cubic box holding about n_atoms."""
    best = None
    for nx in range(2, 40):
        for nz in range(2, 40):
            ny = max(2, round(n_atoms / (4 * nx * nz)))
            n = 4 * nx * ny * nz
            score = (abs(n - n_atoms), max(nx, ny, nz) - min(nx, ny, nz))
            if best is None or score < best[0]:
                best = (score, (nx, ny, nz))
    return best[1]


def main(args: argparse.Namespace) -> int:
    from .cli import UserError
    from .run_cli import check_ranks, overrides as parse_overrides

    if args.steps < 1:
        raise UserError(f"--steps {args.steps}: need at least 1 timed step")
    if args.repeat < 1:
        raise UserError(f"--repeat {args.repeat}: need at least 1 repetition")
    check_ranks(args.np)
    overrides = parse_overrides(args.overrides)
    overrides.update(equilibrate_steps=0, slide_steps=args.steps, restart_every=0,
                     trace_every=max(100, args.steps // 100))
    scene = load(args.scene, overrides)
    film_vars = scene.lammps_variables()
    film_vars["thermo_every"] = str(max(100, args.steps // 10))
    results = {"film": [], "bulk": []}
    with tempfile.TemporaryDirectory(prefix="ff-bench-") as tmp:
        tmp = Path(tmp)
        film_cmd = engine.lmp_command(args.np, md_inputs.script("film_slide.lmp"), film_vars)
        n_film = None
        for i in range(args.repeat):
            d = tmp / f"film{i}"
            d.mkdir()
            rate, n_film = _run(film_cmd, d)
            results["film"].append(rate)
            nx, ny, nz = bulk_cells(n_film)
            bulk_cmd = engine.lmp_command(args.np, md_inputs.script("bulk_lj.lmp"), {
                "cells_x": str(nx), "cells_y": str(ny), "cells_z": str(nz),
                "cutoff": repr(scene.parameters["cutoff"]), "steps": str(args.steps),
                "timestep": repr(scene.parameters["timestep"])})
            d = tmp / f"bulk{i}"
            d.mkdir()
            rate, n_bulk = _run(bulk_cmd, d)
            results["bulk"].append(rate)
    film, bulk = max(results["film"]), max(results["bulk"])
    summary = {"scene": scene.name, "np": args.np, "steps": args.steps,
               "film_atoms": n_film, "bulk_atoms": n_bulk, "cutoff": scene.parameters["cutoff"],
               "film_atom_steps_per_second": film, "bulk_atom_steps_per_second": bulk,
               "ratio": film / bulk, "all": results}
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"engine throughput, {args.np} MPI ranks, cutoff {scene.parameters['cutoff']:g} sigma, "
              f"{args.steps} steps, best of {args.repeat}")
        print(f"  film scene '{scene.name}' ({n_film} atoms): {film / 1e6:.3f} Matom-step/s")
        print(f"  bulk LJ liquid ({n_bulk} atoms):      {bulk / 1e6:.3f} Matom-step/s")
        print(f"  ratio film / bulk: {film / bulk:.2f}  (target >= 1.0)")
    return 0
