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
import io
import json
import math
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from filmfriction import md_inputs
from filmfriction.analysis import green_kubo as gk
from filmfriction.analysis.util import write_atomic
from filmfriction.reduced_model import units as U
from filmfriction.md_inputs.contract import COMMAND_FILE, LOG_FILE
from ..md import engine
from ..inputs import check_ranks, check_writable, UserError

__all__ = ["register", "Settings", "settings_from_args", "run", "main", "DEFAULTS"]

SCRIPT = "viscosity_gk.lmp"
#: fcc close packing of spheres of diameter σ, σ⁻³: no liquid is denser.
CLOSE_PACKING = math.sqrt(2.0)
UNITS = "epsilon*tau/sigma^3"

#: Defaults of the options (LJ units); see the module docstring.
DEFAULTS = {
    "cutoff": 2.5,
    "steps": 150_000,            # production steps (10 blocks of 75 tau)
    "blocks": 10,                # independent Green-Kubo blocks
    "cells": 6,                  # 6^3 fcc cells = 864 atoms
    "timestep": 0.005,
    "correlation_time": 3.0,     # tau: upper limit of the Green-Kubo integral
    "sample_every": 5,           # steps between pressure-tensor samples
    "equilibrate_steps": 10_000,
    "melt_steps": 2_000,
    "seed": 87287,
    "np": 1,
}


@dataclass(frozen=True)
class Settings:
    """Validated inputs of one Green-Kubo run (LJ units)."""

    temperature: float
    density: float
    cutoff: float
    steps: int
    blocks: int
    cells: int
    timestep: float
    correlation_time: float
    sample_every: int
    equilibrate_steps: int
    melt_steps: int
    seed: int
    np: int

    @property
    def n_atoms(self) -> int:
        return 4 * self.cells ** 3

    @property
    def box_edge(self) -> float:
        return self.cells * (4.0 / self.density) ** (1.0 / 3.0)

    @property
    def correlation_length(self) -> int:
        """Samples in one correlation window (fix ave/correlate's Nrepeat)."""
        return int(round(self.correlation_time / (self.sample_every * self.timestep))) + 1

    @property
    def block_steps(self) -> int:
        return self.steps // self.blocks

    def lammps_variables(self) -> dict[str, str]:
        return {"temperature": repr(self.temperature), "density": repr(self.density),
                "cutoff": repr(self.cutoff), "cells": str(self.cells),
                "timestep": repr(self.timestep), "sample_every": str(self.sample_every),
                "correlation_length": str(self.correlation_length),
                "block_steps": str(self.block_steps), "blocks": str(self.blocks),
                "equilibrate_steps": str(self.equilibrate_steps),
                "melt_steps": str(self.melt_steps), "seed": str(self.seed),
                "thermo_every": str(max(1000, self.block_steps))}


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


# ---------------------------------------------------------------- running
class RunFailed(RuntimeError):
    """LAMMPS stopped with an error; the run directory keeps its log."""


def _progress(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run(settings: Settings, run_dir: Path, progress=_progress) -> dict:
    """Run the Green-Kubo script in ``run_dir`` (which must exist) and return the result dict."""
    script = md_inputs.script(SCRIPT)
    # LAMMPS runs in run_dir: a relative path (the default runs/...) would not be found there
    cmd = engine.lmp_command(settings.np, script, settings.lammps_variables(),
                             log=Path(run_dir).resolve() / LOG_FILE)
    write_atomic(run_dir / COMMAND_FILE, " ".join(cmd) + "\n")
    total = settings.melt_steps + settings.equilibrate_steps + settings.steps
    progress(f"viscosity: {settings.n_atoms} atoms, T = {settings.temperature:g}, "
             f"rho = {settings.density:g}, rc = {settings.cutoff:g}; {total} steps on "
             f"{settings.np} rank(s) in {run_dir}")
    start = time.monotonic()
    screen_path, blocks_path = run_dir / "lammps.screen", run_dir / "gk.blocks"
    reported, first = 0, None
    # LAMMPS's screen output is block-buffered in a pipe, so progress comes
    # from gk.blocks, which LAMMPS opens, appends and closes once per block
    with open(screen_path, "w") as screen, \
            subprocess.Popen(cmd, cwd=run_dir, env=engine.engine_env(), stdout=screen,
                             stderr=subprocess.STDOUT) as proc:
        try:
            while True:
                done = proc.poll() is not None
                rows = _block_rows(blocks_path)
                for row in rows[reported:]:
                    reported += 1
                    now = time.monotonic()
                    first = first or now
                    left = ""
                    if reported > 1:
                        per_block = (now - first) / (reported - 1)
                        left = f", about {per_block * (settings.blocks - reported):.0f} s to go"
                    progress(f"  block {reported}/{settings.blocks}: eta = {row[-1]:.3g}, "
                             f"T = {row[1]:.4g}  ({now - start:.0f} s elapsed{left})")
                if done:
                    break
                time.sleep(0.5)
        except KeyboardInterrupt:
            proc.terminate()
            proc.wait()
            raise
    wall = time.monotonic() - start
    text = screen_path.read_text(errors="replace")
    errors = [l.strip() for l in text.splitlines() if l.startswith("ERROR")]
    if proc.returncode != 0 or errors:
        raise RunFailed(errors[0] if errors else
                        f"LAMMPS exited with code {proc.returncode}; see {screen_path}")
    return analyse(settings, run_dir, wall_time=wall)


def _block_rows(path: Path) -> list[list[float]]:
    """The finished rows of gk.blocks so far (none before the file exists)."""
    try:
        # only whole lines: LAMMPS may be writing the last one
        lines = path.read_text().split("\n")[:-1]
    except FileNotFoundError:
        return []
    rows = []
    for line in lines:
        fields = line.split()
        if fields and not line.startswith("#") and len(fields) == len(gk.BLOCK_COLUMNS):
            rows.append([float(x) for x in fields])
    return rows


def analyse(settings: Settings, run_dir: Path, wall_time: float = math.nan) -> dict:
    """η ± error from a finished run directory; writes viscosity.json and gk_integral.csv."""
    blocks = gk.read_blocks(run_dir / "gk.blocks")
    result = gk.green_kubo(blocks, timestep=settings.timestep)
    if result.n_blocks != settings.blocks:
        raise RunFailed(f"{result.n_blocks} of {settings.blocks} blocks finished")
    volume = settings.n_atoms / settings.density
    corr = gk.read_correlate(run_dir / "gk.correlate")
    t, eta_t, err_t = gk.running_integral(corr, volume=volume,
                                          temperature=blocks["temperature"],
                                          timestep=settings.timestep)
    buf = io.StringIO()
    np.savetxt(buf, np.column_stack([t, eta_t, err_t]), delimiter=",",
               header="correlation_time_tau,eta,eta_stderr", comments="", fmt="%.8g")
    write_atomic(run_dir / "gk_integral.csv", buf.getvalue())
    # the last quarter of the window: a plateau has stopped moving there
    late = int(np.searchsorted(t, 0.75 * t[-1]))
    notes = []
    if abs(eta_t[-1] - eta_t[late]) > 2 * err_t[-1]:
        notes.append(f"the integral still moves over the last quarter of the window "
                     f"({eta_t[late]:.3g} at {t[late]:.3g} tau -> {eta_t[-1]:.3g} at {t[-1]:.3g} tau, "
                     "more than twice the error): try a longer --correlation-time")
    if result.diffusion < 0.005:
        notes.append(f"the sample barely diffuses (D = {result.diffusion:.2g} sigma^2/tau): it "
                     "may have crystallised, and eta is then not a liquid's")
    rel = result.eta_stderr / result.eta if result.eta > 0 else math.inf
    if rel > 0.1:
        notes.append(f"the error is {100 * rel:.0f} % of eta: more --steps shrink it as "
                     "1/sqrt(steps)")
    tau_eta = U.viscosity_time_unit(result.eta) if result.eta > 0 else math.nan
    out = {
        "eta": result.eta,
        "eta_stderr": result.eta_stderr,
        "units": UNITS,
        "temperature": settings.temperature,
        "density": settings.density,
        "cutoff": settings.cutoff,
        "n_atoms": settings.n_atoms,
        "steps": settings.steps,
        "method": ("Green-Kubo: LAMMPS fix ave/correlate autocorrelations of Pxy, Pxz, Pyz "
                   "integrated by trap() up to the correlation time and averaged over the three "
                   "components; NVE production after Nose-Hoover equilibration; error = standard "
                   f"error of the mean over {settings.blocks} independent blocks (one seed)"),
        "blocks": settings.blocks,
        "block_steps": settings.block_steps,
        "eta_blocks": [float(x) for x in result.eta_blocks],
        "eta_components": result.components,
        "correlation_time": float(t[-1]),
        "eta_three_quarter_correlation_time": float(eta_t[late]),
        "measured_temperature": result.temperature,
        "measured_temperature_stderr": result.temperature_stderr,
        "pressure": result.pressure,
        "pressure_stderr": result.pressure_stderr,
        "diffusion": result.diffusion,
        "timestep": settings.timestep,
        "sample_every": settings.sample_every,
        "equilibrate_steps": settings.equilibrate_steps,
        "seed": settings.seed,
        "np": settings.np,
        "wall_time_s": wall_time,
        "run_dir": str(run_dir),
        "omcts": {
            "tau_s": U.OMCTS.tau,
            "tau_eta_s": tau_eta,
            "eta_si_Pa_s": U.OMCTS.to_si(result.eta, "viscosity"),
            "eta_target_Pa_s": U.OMCTS_BULK_VISCOSITY,
        },
        "notes": notes,
        "settings": asdict(settings),
    }
    write_atomic(run_dir / "viscosity.json", json.dumps(out, indent=2) + "\n")
    return out


def format_result(r: dict) -> str:
    c = r["eta_components"]
    o = r["omcts"]
    lines = [
        f"eta = {r['eta']:.3f} +- {r['eta_stderr']:.3f} {r['units']}  "
        f"({100 * r['eta_stderr'] / r['eta']:.1f} %, standard error over {r['blocks']} blocks)"
        if r["eta"] > 0 else f"eta = {r['eta']:.3f} +- {r['eta_stderr']:.3f} {r['units']}",
        f"  state: T = {r['temperature']:g} (measured {r['measured_temperature']:.4f}), "
        f"rho = {r['density']:g}, rc = {r['cutoff']:g} (truncated), {r['n_atoms']} atoms; "
        f"P = {r['pressure']:.3f} epsilon/sigma^3, D = {r['diffusion']:.4f} sigma^2/tau",
        f"  Green-Kubo: {r['steps']} NVE steps of {r['timestep']:g} tau, integral to "
        f"{r['correlation_time']:g} tau (at 3/4 of it: {r['eta_three_quarter_correlation_time']:.3f}); "
        f"xy {c['xy']:.3f}, xz {c['xz']:.3f}, yz {c['yz']:.3f}",
        f"  OMCTS: tau = sigma sqrt(m/epsilon) = {o['tau_s'] * 1e12:.2f} ps gives "
        f"eta = {o['eta_si_Pa_s'] * 1e3:.3f} mPa s; the viscosity-matched "
        f"tau_eta = {o['tau_eta_s'] * 1e12:.1f} ps gives {o['eta_target_Pa_s'] * 1e3:g} mPa s "
        f"({o['tau_eta_s'] / o['tau_s']:.2f} x tau)",
        f"  wall time {r['wall_time_s']:.0f} s on {r['np']} rank(s); run directory {r['run_dir']}",
    ]
    lines += [f"  note: {n}" for n in r["notes"]]
    return "\n".join(lines)


def main(args: argparse.Namespace) -> int:
    settings = settings_from_args(args)
    from ..md.runner import new_run_dir
    from ..md.scene import SceneError

    if args.out is not None and Path(args.out).exists():
        _fail(f"--out {args.out}: already exists; a run never overwrites another, "
              "choose a new directory")

    check_ranks(args.np)
    check_writable(args.out if args.out is not None else Path("runs"),
                   "--out" if args.out is not None else "the default --out,", directory=True)
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
