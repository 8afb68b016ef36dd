"""``filmfriction map``: regime maps of the reduced model, as CSV + PNG.

    filmfriction map lambda-zeta [--out DIR] [--resolution N] [--processes P]
    filmfriction map velocity-stiffness [--out DIR] [--resolution N] [--processes P]

lambda-zeta: Coulomb block over Nakano-Maegawa's plane (100 x 100 by default)
with the exact boundary and the asymptotes lambda^2 = 4 pi zeta and zeta = 1.
velocity-stiffness: contact-age block over (V, K) (12 x 12 by default, ~20 s) with
Persson's critical-velocity estimate.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

from filmfriction.workflows.inputs import cap_workers, check_writable, env_count, UserError


KINDS = ("lambda-zeta", "velocity-stiffness")
#: grid points per axis when --resolution is not given
DEFAULT_RESOLUTION = {"lambda-zeta": 100, "velocity-stiffness": 12}
#: simulations of the block per cell: one Coulomb block per lambda-zeta cell; up to two
#: contact-age runs (the start-up run, then a longer one if it re-stuck) per (V, K) cell
SIMULATIONS_PER_CELL = {"lambda-zeta": 1, "velocity-stiffness": 2}
#: most simulations a map starts unless FILMFRICTION_MAX_MAP_SIMULATIONS says otherwise
MAX_SIMULATIONS = 40_000


def register(subparsers) -> argparse.ArgumentParser:
    """Add the ``map`` sub-command to the filmfriction dispatcher."""
    p = subparsers.add_parser(
        "map", help="regime maps of the reduced spring-block model (CSV + PNG)",
        description="Regime maps of the reduced spring-block model, written as <kind>.csv and "
                    "<kind>.png. lambda-zeta: the Coulomb block over Nakano-Maegawa's plane "
                    "(100 x 100 by default) with the exact stick-slip boundary and the "
                    "asymptotes lambda^2 = 4 pi zeta and zeta = 1. velocity-stiffness: the "
                    "contact-age block over (V, K) (12 x 12 by default, each cell a full "
                    "simulation, about 20 s) with Persson's critical-velocity estimate.")
    p.add_argument("kind", choices=KINDS, help="which plane to map")
    p.add_argument("--out", default=".", help="output directory (created if missing; default: .)")
    p.add_argument("--resolution", type=int, default=None,
                   help="grid points per axis (default 100 for lambda-zeta, 12 for "
                        "velocity-stiffness, each cell a full simulation); refused before any "
                        f"work when the map needs more than {MAX_SIMULATIONS:,} simulations "
                        "(FILMFRICTION_MAX_MAP_SIMULATIONS raises the limit)")
    p.add_argument("--processes", type=int, default=2,
                   help="worker processes (default 2; at most the CPUs this process may use, "
                        "more are capped with a note)")
    p.set_defaults(func=run)
    return p


def _user_error(message):
    return UserError(message)


def check_cost(kind: str, resolution: int | None) -> None:
    """Refuse (UserError), before any work, a map of more simulations than the limit
    (``$FILMFRICTION_MAX_MAP_SIMULATIONS``, default :data:`MAX_SIMULATIONS`)."""
    n = resolution or DEFAULT_RESOLUTION[kind]
    per_cell = SIMULATIONS_PER_CELL[kind]
    needed = n * n * per_cell
    limit = env_count("FILMFRICTION_MAX_MAP_SIMULATIONS", MAX_SIMULATIONS)
    if needed > limit:
        each = "one simulation" if per_cell == 1 else f"up to {per_cell} simulations"
        raise _user_error(f"--resolution {n}: {n} x {n} = {n * n:,} cells of {each} each, "
                          f"{needed:,} simulations, above the limit of {limit:,}; give a "
                          f"--resolution of at most {math.isqrt(limit // per_cell)}, or set "
                          "FILMFRICTION_MAX_MAP_SIMULATIONS to raise the limit")


def run(args) -> int:
    """Compute the map, write ``<kind>.csv`` and ``<kind>.png`` under ``--out``, print the paths."""
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise _user_error(f"--out {out}: exists and is not a directory")
    n = args.resolution
    if n is not None and not 2 <= n <= 1000:
        raise _user_error(f"--resolution {n}: allowed range is [2, 1000] grid points per axis")
    check_cost(args.kind, n)
    processes = cap_workers(args.processes, "--processes")

    check_writable(out, "--out", directory=True)
    from filmfriction.workflows.outputs import check_output

    stem = args.kind.replace("-", "_")
    for name in (f"{stem}.csv", f"{stem}.png"):
        check_output(out / name, "--out")
    out.mkdir(parents=True, exist_ok=True)

    import numpy as np
    from filmfriction.reduced_model import maps

    n = n or DEFAULT_RESOLUTION[args.kind]
    if args.kind == "lambda-zeta":
        result = maps.lambda_zeta_map(np.logspace(-2, 2, n), np.logspace(-3, 1, n),
                                      processes=processes)
    else:
        result = maps.velocity_stiffness_map(np.logspace(-3, 0, n), np.logspace(-1, 2, n),
                                             processes=processes)
    stem = args.kind.replace("-", "_")
    from filmfriction.analysis.files.util import write_atomic

    csv_path = write_atomic(out / f"{stem}.csv", result.csv_text())
    png_path = _plot(result, args.kind, out / f"{stem}.png")
    print(csv_path)
    print(png_path)
    print(f"# {n} x {n} map in {result.seconds:.2f} s on {processes} process(es); "
          f"stick-slip in {100 * result.stick_slip.mean():.1f} % of cells")
    return 0


def _plot(result, kind, path) -> str:
    import io

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from filmfriction.analysis.files.util import write_atomic

    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    ax.pcolormesh(result.x, result.y, result.stick_slip.astype(float), shading="nearest",
                  cmap="coolwarm", vmin=0, vmax=1)
    finite = np.isfinite(result.boundary)
    ax.plot(result.boundary_x[finite], result.boundary[finite], "k-", lw=1.5,
            label="boundary (exact)" if kind == "lambda-zeta" else "Persson estimate v_c = dF/(K tau)")
    if kind == "lambda-zeta":
        z = result.x
        ax.plot(z, np.sqrt(4 * math.pi * z), "k--", lw=1, label=r"$\lambda^2 = 4\pi\zeta$")
        ax.axvline(1.0, color="k", ls=":", lw=1, label=r"$\zeta = 1$")
        ax.set_xlabel(r"$\zeta = d / (2\sqrt{KM})$ [1]")
        ax.set_ylabel(r"$\lambda = \Delta F / (V\sqrt{KM})$ [1]")
        ax.set_ylim(result.y[0], result.y[-1])
        ax.set_title("Coulomb block: stick-slip (red) / smooth (blue)")
    else:
        # the block's own units: mass M, load times static coefficient N f_s, ageing time tau
        ax.set_xlabel("drive velocity V [N f_s τ/M]")
        ax.set_ylabel("stiffness K [M/τ²]")
        ax.set_xlim(result.x[0], result.x[-1])
        ax.set_title("contact-age block (M = N f_s = τ = 1): stick-slip (red) / smooth (blue)",
                     fontsize=10)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120)
    plt.close(fig)
    return str(write_atomic(path, buf.getvalue()))
