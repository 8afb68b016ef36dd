"""The bad-input tables' harness: the input builders and the check that a command is refused.

Bad input, table-driven: every case ends in one line naming the input, exit
code 2, no traceback, and nothing written (the working directory, where
``runs/`` and ``sweeps/`` would go, and every input directory are unchanged).

Each case builds its inputs under ``tmp`` with the builders ``b`` (:data:`BUILDERS`) and
returns the command line; none
reaches LAMMPS (the checks come first), so the table runs without an engine.
"""
from __future__ import annotations

import os
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest


def _csv(path: Path, header: str, rows) -> Path:
    path.write_text(header + "\n" + "".join(",".join(repr(float(v)) for v in r) + "\n"
                                            for r in rows))
    return path


def _trace(tmp: Path, n: int = 400, wall=None, name: str = "trace.csv") -> Path:
    t = np.arange(n) * 0.5
    force = 10 * np.sin(t) + t % 20
    x = np.cumsum(np.abs(force)) * 0.01
    wall = x if wall is None else wall
    return _csv(tmp / name, "time,spring_force,drive_position,wall_position",
                zip(t, force, x, wall))


def _latin1(tmp: Path, name: str, text: str) -> Path:
    (tmp / name).write_bytes(text.encode("latin-1"))
    return tmp / name


def _link(target: Path, link: Path) -> Path:
    link.symlink_to(target)
    return link


def _afile(tmp: Path) -> Path:
    (tmp / "afile").write_text("x")
    return tmp / "afile"


def _run_with(tmp: Path, name: str, run_json: str) -> Path:
    """A directory with a trace and the given run.json text."""
    d = tmp / name
    d.mkdir()
    _trace(d)
    (d / "run.json").write_text(run_json)
    return d


def _list_run(tmp: Path) -> Path:
    return _run_with(tmp, "run-list", "[1, 2]")


def _run_dir(tmp: Path) -> Path:
    return _run_with(tmp, "run", "{}")


def _md_run(tmp: Path) -> Path:
    return _run_with(tmp, "md-run", '{"trace_parameters": {"spring_constant": 100.0, "mass": 500.0, '
                                    '"area": 58.7, "thickness": null, "drive_velocity": 0.02, '
                                    '"units": "lj"}}')


def _with_runs_file(tmp: Path, args: list) -> list:
    """``args``, with a file called runs in the working directory (the cases' cwd is
    tmp/../work), where a run's default directory would go."""
    (tmp.parent / "work" / "runs").write_text("not a directory")
    return args


def _sweep_dir(tmp: Path) -> Path:
    d = tmp / "sweep"
    (d / "points").mkdir(parents=True)
    (d / "sweep.json").write_text("{}")
    return d


def _foreign_rung(tmp: Path) -> Path:
    """A ladder root whose first rung's folder holds someone's file, no sweep.json."""
    (tmp / "ladder" / "M=240000").mkdir(parents=True)
    (tmp / "ladder" / "M=240000" / "notes.txt").write_text("mine")
    return tmp / "ladder"


def _empty_rung(tmp: Path) -> Path:
    """A ladder root with one rung's sweep planned, no point finished."""
    (tmp / "ladder" / "M=30" / "points").mkdir(parents=True)
    (tmp / "ladder" / "M=30" / "sweep.json").write_text('{"fixed": {}}')
    return tmp / "ladder"


def _analysed_file_dir(tmp: Path) -> Path:
    d = tmp / "measured"
    d.mkdir()
    (d / "analysis.json").write_text("{}")
    return d


def _huge(tmp: Path) -> Path:
    t = np.arange(400) * 0.5
    force = (10 * np.sin(t) + t % 20) * 1e306     # finite, but its square is not
    return _csv(tmp / "huge.csv", "time,spring_force", zip(t, force))


def _sparse(tmp: Path) -> Path:
    """A small trace padded to 2 GiB with NUL bytes (sparse: no disk space taken)."""
    path = _trace(tmp, name="big.csv")
    with open(path, "r+b") as fh:
        fh.truncate(2 << 30)
    return path


def _with_nul(tmp: Path) -> Path:
    path = _trace(tmp, name="nul.csv")
    with open(path, "ab") as fh:
        fh.write(b"\0" * 100)
    return path


def _toml(tmp: Path, name: str, text: str) -> Path:
    (tmp / name).write_text(text)
    return tmp / name


def _edited(tmp: Path, name: str, file: str, edit, analysed: bool = False) -> Path:
    """A synthetic run directory (analysed when ``analysed``) whose JSON ``file`` is passed
    through ``edit`` (a hand-edited or foreign document)."""
    import json

    from filmfriction.analysis.analyze import analyse_run
    from filmfriction.analysis.groundtruth.synthetic import run_directory

    d = run_directory(tmp / name, trajectory=False)
    if analysed:
        analyse_run(d)
    doc = json.loads((d / file).read_text())
    edit(doc)
    (d / file).write_text(json.dumps(doc))
    return d


def _set(path: str, value):
    """An edit setting the entry at the dotted ``path``."""
    def edit(doc):
        *head, last = path.split(".")
        for key in head:
            doc = doc[key]
        doc[last] = value
    return edit


def _analysed_file(tmp: Path, edit=None) -> Path:
    """The directory of an analysed trace file (analysis.json beside the trace), its
    analysis.json passed through ``edit``."""
    import json

    from filmfriction.analysis.analyze import analyze, write_outputs
    from filmfriction.analysis.files.trace_reader import read_trace

    d = tmp / "measured"
    d.mkdir()
    trace = _trace(d, name="scan.csv")
    doc, per_cycle = analyze(read_trace(trace, units="si", spring_constant=97.0), structure=False)
    doc["source"]["path"] = "scan.csv"
    if edit is not None:
        edit(doc)
    write_outputs(doc, per_cycle, d / "analysis.json")
    (d / "analysis.json").write_text(json.dumps(doc))
    return d


def _resumable(tmp: Path, edit) -> Path:
    """An interrupted run's record, passed through ``edit``, for --resume."""
    import json

    d = tmp / "stopped"
    d.mkdir()
    doc = {"schema": "filmfriction.run/1", "status": "interrupted", "np": 1,
           "scene": {"name": "stick-slip", "description": "x", "models": [],
                     "expected_cost": "", "parameters": {}}}
    edit(doc)
    (d / "run.json").write_text(json.dumps(doc))
    return d


def _fifo(tmp: Path) -> Path:
    os.mkfifo(tmp / "pipe")
    return tmp / "pipe"


def _user_file(tmp: Path, name: str, text: str = "the user's own notes\n") -> Path:
    (tmp / name).write_text(text)
    return tmp / name


def _setup_file(tmp: Path) -> Path:
    return _toml(tmp, "mine.toml", "name = 'mine'\nspring_constant = 97\nmass = 0.002\n"
                                   "contact_area = 1e-8\nfilm_thickness = 3.6e-9\nload = 1e-3\n"
                                   "drive_velocity = 1e-6\n")



def _snapshot(root: Path) -> dict:
    """Every path under root; files with their size and time (a directory's own
    time changes when the writability probe creates and removes its file)."""
    return {str(p.relative_to(root)): (p.stat().st_size, p.stat().st_mtime_ns)
            if p.is_file() else "dir" for p in root.rglob("*")}



#: the input builders by name, without the underscore (``b.trace(tmp)`` in a case), and
#: ``snapshot(root)``
BUILDERS = SimpleNamespace(**{name[1:]: value for name, value in list(globals().items())
                              if name.startswith("_") and not name.startswith("__")
                              and callable(value)})


@pytest.fixture
def input_files() -> SimpleNamespace:
    """The input builders of the bad-input tables (see :data:`BUILDERS`)."""
    return BUILDERS


@pytest.fixture
def refused(tmp_path, monkeypatch, run_cli):
    """``refused(build, fragment, code=2)``: the command line ``build(inputs, builders)``
    run from a working directory of its own (where runs/ and sweeps/ would go) ends
    with exit ``code``, one line naming ``fragment``, no traceback, nothing written."""
    def check(build, fragment, code=2):
        inputs = tmp_path / "in"
        inputs.mkdir()
        work = tmp_path / "work"            # the working directory: runs/, sweeps/ go here
        work.mkdir()
        monkeypatch.chdir(work)
        args = build(inputs, BUILDERS)
        before = _snapshot(tmp_path)
        rc, out, err = run_cli(*args)
        assert rc == code, (rc, err)
        assert fragment in err, err
        assert "Traceback" not in err + out
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert lines[-1].startswith("filmfriction ") and "error" in lines[-1], err
        assert _snapshot(tmp_path) == before, "something was written"
    return check
