"""Fixtures shared by the whole suite.

The tests mirror the package: ``tests/md_inputs``, ``tests/reduced_model``,
``tests/analysis``, ``tests/workflows``, plus the cross-cutting files at the
top (layering, installation, doctests).  Test modules never import one
another; what several of them need is here, as fixtures:

``md`` (session)
    Small real LAMMPS runs: :meth:`MD.scene` (a scene on the 5 x 3-cell box,
    ~330 atoms), :meth:`MD.execute` (one run under a watchdog),
    :meth:`MD.shared` (a run made once per session and shared read-only by
    every test that asks for the same settings), :meth:`MD.trace` and
    :meth:`MD.ledger_closure`.
``film_run`` (session)
    The small film-structure run (trajectory, profiles, several slips) that
    the runner, analysis and report tests all read.
``layered_run`` (session)
    ``layered_run(n)``: a short film-structure run with ``n`` film layers.
``run_cli``
    ``run_cli("analyze", path, "--json")``: the ``filmfriction`` command in
    process, returning its exit code and captured output.
``filmfriction_command`` (session)
    The installed ``filmfriction`` script, for tests that run it as a user does.
``synthetic_run``
    A run directory in the runner's format with a known answer
    (:func:`filmfriction.analysis.groundtruth.synthetic.run_directory`), in ``tmp_path``.

Per folder: ``analysis/conftest.py`` (``slip_table``: detection, cycle table and
ramp fits on a trace) and ``workflows/conftest.py`` (``report_study`` and
``report_checks``: the post-MD study and the checks of its report).
"""
from __future__ import annotations

import contextlib
import json
import os
import signal
import sys
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pytest

#: The small box of every real run in the suite: 5 x 3 cells, about 330 atoms
#: for 3 film layers (Lx 5.5, Ly 5.7 sigma: just above two cutoffs).
SMALL_BOX = {"cells_x": 5, "cells_y": 3}
#: Seconds one small run may take before the watchdog ends it: far above its cost.
DEADLINE = 180.0


# ---------------------------------------------------------------------------- LAMMPS runs
def _children(pid: int) -> list[int]:
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            # the command name may hold spaces: fields after the last ')'
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(entry.name))
    return out


@contextlib.contextmanager
def deadline(seconds: float = DEADLINE):
    """Fail (instead of hanging) when the body runs longer than ``seconds``.

    The runner starts ``mpiexec`` in a session of its own, so its process
    group id is its pid: ending that group ends exactly this test's engine.
    """
    from filmfriction.workflows.md import runner

    fired = threading.Event()

    def stop():
        fired.set()
        for child in _children(os.getpid()):
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(child, signal.SIGKILL)

    timer = threading.Timer(seconds, stop)
    timer.start()
    try:
        yield
    except runner.RunFailed:
        if fired.is_set():
            pytest.fail(f"the run did not finish within {seconds:.0f} s")
        raise
    finally:
        timer.cancel()


def _snapshot(directory: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(directory)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in sorted(directory.rglob("*"))}


@dataclass(frozen=True)
class MDRun:
    """A finished run: its scene and its directory."""

    scene: Any
    path: Path

    @property
    def parameters(self) -> dict:
        return self.scene.parameters

    def trace(self) -> np.ndarray:
        return MD.trace(self.path)

    def record(self) -> dict:
        return json.loads((self.path / "run.json").read_text())


class MD:
    """Small real LAMMPS runs for the tests (see the module's docstring)."""

    box = SMALL_BOX

    def __init__(self, tmp_path_factory):
        self._factory = tmp_path_factory
        self._shared: dict[tuple, MDRun] = {}
        self._snapshots: dict[Path, dict] = {}

    @staticmethod
    def scene(name: str = "stick-slip", **overrides):
        """Scene ``name`` on the small box, with ``overrides`` (validated)."""
        from filmfriction.workflows.md.scene import load

        return load(name, {**SMALL_BOX, **overrides})

    @staticmethod
    def execute(scene, out: Path, *, nprocs: int = 1) -> Path:
        """Run ``scene`` into ``out`` under the watchdog; one MPI rank by default
        (no busy-waiting ranks fighting for the shared cores)."""
        from filmfriction.workflows.md import runner

        with deadline():
            return runner.execute(scene, out=out, nprocs=nprocs, progress=False)

    def shared(self, name: str = "stick-slip", *, nprocs: int = 1, **overrides) -> MDRun:
        """Scene ``name`` with ``overrides`` on ``nprocs`` ranks, run once per session.

        Every test asking for the same settings gets the same directory; it is
        read-only (a test that writes into it fails at the end of the session).
        A test that needs to write copies it first.  (The rank count is part of
        the settings: the thermostat's random numbers are drawn per rank.)
        """
        key = (name, nprocs, tuple(sorted(overrides.items())))
        if key not in self._shared:
            scene = self.scene(name, **overrides)
            out = self._factory.mktemp(f"md-{name}") / "run"
            path = self.execute(scene, out, nprocs=nprocs)
            self._snapshots[path] = _snapshot(path)
            self._shared[key] = MDRun(scene, path)
        return self._shared[key]

    @staticmethod
    def killed_at(cmd: list[str], out: Path, marker: str = "restart.4000",
                  timeout: float = 120.0) -> None:
        """Start ``cmd`` (a ``filmfriction run`` into ``out``) and kill its whole process
        group hard (SIGKILL, nothing cleaned up) once ``out/marker`` exists or after
        ``timeout`` seconds: an interrupted run for the resume tests."""
        import os
        import signal
        import subprocess
        import time

        proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        stop = time.time() + timeout
        while time.time() < stop and not list(out.glob(marker)):
            time.sleep(0.2)
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()

    def changed_shared_runs(self) -> list[str]:
        return [str(path) for path, snap in self._snapshots.items() if _snapshot(path) != snap]

    @staticmethod
    def trace(run_dir: Path) -> np.ndarray:
        """``trace.csv`` of a run as a structured array (columns by name)."""
        return np.genfromtxt(Path(run_dir) / "trace.csv", delimiter=",", names=True)

    @staticmethod
    def ledger_residual(d) -> np.ndarray:
        """The energy ledger's residual over a trace, computed here from the contract
        columns (independently of ``analysis.energy``): work in minus energy stored
        minus heat out, zero at the first row."""
        work = d["drive_work"] + d["load_work"]
        stored = d["potential_energy"] + d["kinetic_energy"] + d["spring_energy"]
        heat = d["thermostat_heat"] + d["mount_heat"]
        return (work - work[0]) - (stored - stored[0]) - (heat - heat[0])

    @classmethod
    def ledger_closure(cls, d) -> float:
        """|final ledger residual| over the energy turned over (work in or heat out)."""
        work = d["drive_work"] + d["load_work"]
        heat = d["thermostat_heat"] + d["mount_heat"]
        turnover = max(abs(work[-1] - work[0]), np.abs(heat - heat[0]).max())
        assert turnover > 0, "no energy was turned over: nothing to close"
        return abs(cls.ledger_residual(d)[-1]) / turnover


@pytest.fixture(scope="session")
def md(tmp_path_factory):
    helper = MD(tmp_path_factory)
    yield helper
    changed = helper.changed_shared_runs()
    assert not changed, f"a test wrote into a shared (read-only) run directory: {changed}"


#: The run behind ``film_run``: film-structure (trajectory every 500 steps,
#: profiles every 1000) at 2.5x the default drive, 60 tau of sliding: several slips.
FILM_RUN = {"equilibrate_steps": 2000, "slide_steps": 12000, "trace_every": 20,
            "drive_velocity": 0.05, "dump_every": 500, "profile_every": 1000}


@pytest.fixture(scope="session")
def film_run(md) -> MDRun:
    """The small film-structure run shared by the runner, analysis and report tests."""
    return md.shared("film-structure", **FILM_RUN)


@pytest.fixture(scope="session")
def layered_run(md):
    """``layered_run(n)``: a short film-structure run with ``n`` layers (profiles every
    500 steps), shared by the runner's layer count and the MD extremes' gap checks."""
    def run(layers: int) -> MDRun:
        return md.shared("film-structure", film_layers=layers, equilibrate_steps=2000,
                         slide_steps=1000, trace_every=10, profile_every=500, restart_every=0)
    return run


# ---------------------------------------------------------------------------- command line
class CliResult(NamedTuple):
    """What ``filmfriction ARGS`` gave: ``code, out, err = run_cli(...)`` or ``r.code``."""

    code: int
    out: str
    err: str

    def json(self):
        return json.loads(self.out)


@pytest.fixture
def run_cli(capsys):
    """``run_cli(*args)``: ``filmfriction ARGS`` in process -> CliResult(code, out, err)."""
    from filmfriction.workflows.cli.main import main

    def run(*args) -> CliResult:
        capsys.readouterr()                     # drop what the test printed before
        try:
            code = main([str(a) for a in args])
        except SystemExit as exc:               # argparse's own refusals and --help
            code = exc.code
        out, err = capsys.readouterr()
        return CliResult(code, out, err)
    return run


@pytest.fixture(scope="session")
def filmfriction_command() -> str:
    """The installed ``filmfriction`` script of this interpreter's environment
    (``python -m filmfriction.workflows.cli.main`` would define a second UserError)."""
    path = Path(sys.executable).with_name("filmfriction")
    assert path.exists(), f"{path} missing: install the project (make .venv/.installed)"
    return str(path)


# ---------------------------------------------------------------------------- synthetic data
@pytest.fixture
def synthetic_run(tmp_path) -> Path:
    """A run directory in the runner's format from a Klein-type trace with a known
    answer: 4 slips, 3 film layers in a 60-frame trajectory, a ledger that closes."""
    from filmfriction.analysis.groundtruth.synthetic import run_directory

    return run_directory(tmp_path / "synthetic-run", layers=3)


@pytest.fixture
def tmpfs(tmp_path):
    """``tmpfs(name, options, why)``: a tmpfs mounted at ``tmp_path/name`` with the mount
    ``options`` (e.g. ``"ro,size=64k"``), unmounted after the test; the test is skipped,
    saying ``why``, where it cannot be made (mounting needs root)."""
    import subprocess

    mounted = []

    def make(name: str, options: str, why: str) -> Path:
        mnt = tmp_path / name
        mnt.mkdir()
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(mnt)],
                           capture_output=True, text=True)
        if r.returncode != 0:
            pytest.skip(f"cannot mount a tmpfs here ({r.stderr.strip() or r.returncode}): {why}")
        mounted.append(mnt)
        return mnt
    try:
        yield make
    finally:
        for mnt in mounted:
            subprocess.run(["umount", "-l", str(mnt)], capture_output=True)
