"""The bulk LJ shear viscosity by Green-Kubo in LAMMPS: one run of
``md_inputs/viscosity_gk.lmp`` in a run directory, its blocks read as they finish, and
η ± error (:mod:`filmfriction.analysis.green_kubo`).  A failed run raises the runner's
:class:`~filmfriction.workflows.md.runner.RunFailed`.  The command is
``filmfriction viscosity`` (``workflows/cli/viscosity_cli.py``).
"""
from __future__ import annotations

import io
import json
import math
import subprocess
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from filmfriction import md_inputs
from filmfriction.analysis import green_kubo as gk
from filmfriction.analysis.files.provenance import provenance
from filmfriction.analysis.files.util import write_atomic
from filmfriction.md_inputs.contract import COMMAND_FILE, LOG_FILE
from filmfriction.reduced_model import units as U

from . import engine
from .runner import RunFailed

__all__ = ["Settings", "DEFAULTS", "run", "analyse", "format_result"]


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


def _progress(message: str) -> None:
    from ..progress import note

    note(message)


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
                        f"LAMMPS exited with code {proc.returncode}; see {screen_path}", run_dir)
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
        raise RunFailed(f"{result.n_blocks} of {settings.blocks} blocks finished", run_dir)
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
        "provenance": provenance(),
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
