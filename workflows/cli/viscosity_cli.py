"""``filmfriction viscosity``: the bulk LJ shear viscosity by Green-Kubo, in LAMMPS.

    filmfriction viscosity --temperature 0.722 --density 0.8442 [--cutoff 2.5]
                           [--steps N] [--np 1] [--json] [--out DIR]

Runs ``md_inputs/viscosity_gk.lmp`` (fcc start, melt, Nose-Hoover
equilibration, NVE production) through :mod:`filmfriction.workflows.md.engine`.
LAMMPS autocorrelates P_xy, P_xz and P_yz (``fix ave/correlate``) and
integrates them (``trap()``) in each of ``--blocks`` independent production
segments; η is the mean of the block values and its error the standard error
of that mean (one seed, block averages).  Prints η ± error in ετ/σ³ and what it
means for OMCTS: the mapping's τ = σ√(m/ε) and the time unit τ_η that maps
this η onto OMCTS's 2.5 mPa·s (:func:`filmfriction.reduced_model.units.viscosity_time_unit`).

The run directory (``--out``, never an existing one; by default a fresh
``runs/viscosity-...``) keeps LAMMPS's log and files, ``viscosity.json`` (the
result) and ``gk_integral.csv`` (η as a function of the correlation time, to
see the plateau).

Defaults: chosen at the LJ triple point (T = 0.722, ρ = 0.8442, rc = 2.5) as
the cheapest settings whose standard error is below 10 % there (see
docs/viscosity.md); at higher viscosity (denser, colder) ask for more steps.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from ..inputs import check_not_in_run, check_ranks, check_writable, UserError
from ..md import engine
from ..md.run_record import new_run_dir
from ..md.runner import RunFailed
from ..md.scene import SceneError
from ..md.viscosity_run import CLOSE_PACKING, DEFAULTS, Settings, format_result, run

__all__ = ["register", "settings_from_args", "main", "MAX_TEMPERATURE", "MAX_T_DT2"]

#: highest temperature accepted (epsilon/k_B): 7.6 times the LJ critical temperature
MAX_TEMPERATURE = 10.0
#: largest T dt^2 accepted (T in epsilon/k_B, dt in tau): the hottest liquid whose
#: collisions the time step resolves.  A 108-atom liquid at rho = 0.8442 (2000
#: equilibration + 2000 production steps) runs at T = 10, dt = 0.005 and at T = 2.5,
#: dt = 0.01 (T dt^2 = 2.5e-4), and loses atoms at T = 30, dt = 0.005 (7.5e-4) and at
#: T = 10, dt = 0.01 (1e-3).
MAX_T_DT2 = 2.5e-4


def register(subparsers) -> None:
    """Add the ``viscosity`` sub-command."""
    d = DEFAULTS
    p = subparsers.add_parser(
        "viscosity", help="bulk LJ shear viscosity by Green-Kubo (LAMMPS fix ave/correlate)",
        description="Shear viscosity of a periodic LJ liquid by Green-Kubo: LAMMPS's "
                    "fix ave/correlate + trap() of the off-diagonal pressure tensor, NVE "
                    "production cut into independent blocks; prints eta +- standard error in "
                    "epsilon*tau/sigma^3 and the OMCTS time units it implies.")
    p.add_argument("--temperature", type=float, required=True, metavar="T",
                   help="temperature, epsilon/k_B (the LJ triple point: 0.722)")
    p.add_argument("--density", type=float, required=True, metavar="RHO",
                   help="number density, sigma^-3 (the LJ triple point: 0.8442)")
    p.add_argument("--cutoff", type=float, default=d["cutoff"], metavar="RC",
                   help="LJ cutoff, sigma, truncated (default %(default)s)")
    p.add_argument("--steps", type=int, default=d["steps"], metavar="N",
                   help="production steps, cut into --blocks blocks (default %(default)s)")
    p.add_argument("--blocks", type=int, default=d["blocks"],
                   help="independent blocks for the error bar (default %(default)s)")
    p.add_argument("--cells", type=int, default=d["cells"],
                   help="fcc cells per box edge, 4 atoms each (default %(default)s: "
                        f"{4 * d['cells'] ** 3} atoms)")
    p.add_argument("--timestep", type=float, default=d["timestep"],
                   help="MD time step, tau (default %(default)s)")
    p.add_argument("--correlation-time", type=float, default=d["correlation_time"],
                   metavar="TC", help="upper limit of the Green-Kubo integral, tau "
                                      "(default %(default)s)")
    p.add_argument("--sample-every", type=int, default=d["sample_every"], metavar="STEPS",
                   help="pressure-tensor sampling interval, steps (default %(default)s)")
    p.add_argument("--equilibrate-steps", type=int, default=d["equilibrate_steps"],
                   metavar="STEPS", help="Nose-Hoover steps at T before the production "
                                         "(default %(default)s)")
    p.add_argument("--seed", type=int, default=d["seed"], help="velocity seed (default %(default)s)")
    p.add_argument("--np", type=int, default=d["np"], help="MPI ranks (default %(default)s)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--out", type=Path, metavar="DIR",
                   help="run directory; must not exist (default: a fresh runs/viscosity-...)")
    p.set_defaults(func=main)


def _fail(message: str):
    raise UserError(message)


def _ok(value, low: float, high: float = math.inf, *, low_open=True, high_open=False) -> bool:
    """``value`` is a finite number within the interval (NaN and inf never are)."""
    if not isinstance(value, (int, float)) or not math.isfinite(value):
        return False
    above = value > low if low_open else value >= low
    below = value < high if high_open else value <= high
    return above and below


def settings_from_args(args: argparse.Namespace) -> Settings:
    """Check every input before anything runs; a bad one raises UserError naming it and its range."""
    get = lambda name: getattr(args, name, DEFAULTS.get(name))  # noqa: E731
    t = args.temperature
    if not _ok(t, 0.0):
        _fail(f"--temperature {t:g}: must be > 0 (epsilon/k_B; the LJ triple point is 0.722)")
    if t > MAX_TEMPERATURE:
        _fail(f"--temperature {t:g}: at most {MAX_TEMPERATURE:g} epsilon/k_B (the LJ triple "
              f"point is 0.722, the critical point 1.31; above {MAX_TEMPERATURE:g} the fluid "
              "is a hot gas, not a liquid)")
    rho = args.density
    if not _ok(rho, 0.0, CLOSE_PACKING, high_open=True):
        _fail(f"--density {rho:g}: must be in (0, {CLOSE_PACKING:.4f}) sigma^-3 "
              "(sqrt(2) is fcc close packing of spheres of diameter sigma)")
    cells = get("cells")
    if not isinstance(cells, int) or not 2 <= cells <= 40:
        _fail(f"--cells {cells!r}: must be an integer in [2, 40] (4*cells^3 atoms)")
    edge = cells * (4.0 / rho) ** (1.0 / 3.0)
    rc = get("cutoff")
    if not _ok(rc, 1.0, edge / 2, low_open=False):
        _fail(f"--cutoff {rc:g}: must be in [1, {edge / 2:.3g}] sigma (half the box edge "
              f"{edge:.3g} sigma at --cells {cells}; more cells allow a longer cutoff)")
    dt = get("timestep")
    if not _ok(dt, 0.0, 0.01):
        _fail(f"--timestep {dt:g}: must be in (0, 0.01] tau (LJ liquid stability)")
    if t * dt ** 2 > MAX_T_DT2 * (1 + 1e-9):
        _fail(f"--temperature {t:g}: at most {MAX_T_DT2 / dt ** 2:.3g} epsilon/k_B with "
              f"--timestep {dt:g} (T dt^2 <= {MAX_T_DT2:g}: hotter collisions need a shorter "
              "step, or atoms are lost); give a lower --temperature or a shorter --timestep")
    every = get("sample_every")
    if not isinstance(every, int) or every < 1:
        _fail(f"--sample-every {every!r}: must be an integer >= 1 step")
    tc = get("correlation_time")
    if not _ok(tc, 2 * every * dt, low_open=False):
        _fail(f"--correlation-time {tc:g}: must be >= {2 * every * dt:g} tau "
              f"(two sampling intervals of {every} steps)")
    blocks = get("blocks")
    if not isinstance(blocks, int) or blocks < 2:
        _fail(f"--blocks {blocks!r}: must be an integer >= 2 (the error bar needs two blocks)")
    steps = get("steps")
    window = int(round(tc / (every * dt))) * every          # steps spanned by one window
    if not isinstance(steps, int) or steps < blocks * max(2 * window, every):
        _fail(f"--steps {steps!r}: must be an integer >= {blocks * 2 * window} "
              f"({blocks} blocks, each at least twice the {tc:g}-tau correlation window)")
    eq = get("equilibrate_steps")
    if not isinstance(eq, int) or eq < 20:
        _fail(f"--equilibrate-steps {eq!r}: must be an integer >= 20")
    seed = get("seed")
    if not isinstance(seed, int) or not 1 <= seed < 2**31:
        _fail(f"--seed {seed!r}: must be an integer in [1, 2^31)")
    nprocs = get("np")
    if not isinstance(nprocs, int) or nprocs < 1:
        _fail(f"--np {nprocs!r}: must be an integer >= 1 (MPI ranks)")
    # whole blocks of whole sampling intervals; the equilibration's mean
    # potential energy is sampled every 10 steps over its second half
    block = (steps // blocks) // every * every
    return Settings(temperature=t, density=rho, cutoff=rc, steps=block * blocks, blocks=blocks,
                    cells=cells, timestep=dt, correlation_time=tc, sample_every=every,
                    equilibrate_steps=(eq + 19) // 20 * 20, melt_steps=DEFAULTS["melt_steps"],
                    seed=seed, np=nprocs)


def main(args: argparse.Namespace) -> int:
    settings = settings_from_args(args)
    if args.out is not None and Path(args.out).exists():
        _fail(f"--out {args.out}: already exists; a run never overwrites another, "
              "choose a new directory")

    check_ranks(args.np)
    check_writable(args.out if args.out is not None else Path("runs"),
                   "--out" if args.out is not None else "the default --out,", directory=True)
    if args.out is not None:
        check_not_in_run(args.out, "--out")
    try:
        run_dir = new_run_dir(f"viscosity-T{settings.temperature:g}-rho{settings.density:g}",
                              args.out)
    except SceneError as exc:        # created by someone else in the meantime
        _fail(f"--out {args.out}: {exc}")
    try:
        result = run(settings, run_dir)
    except (RunFailed, engine.EngineNotFound) as exc:
        print(f"filmfriction viscosity: LAMMPS failed: {exc} (run directory {run_dir})",
              file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps({k: v for k, v in result.items() if k != "settings"}, indent=2))
    else:
        print(format_result(result))
    return 0
