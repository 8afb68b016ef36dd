"""The one guard of every file a command writes: no output replaces an input or
another run's file.

:func:`check_output` is called by every writer of the command line (``analyze``,
``calibrate``, ``sfb``, ``report`` and its Markdown twin, ``geometry``, ``map``,
``sweep``) before any compute.  It refuses (:class:`~filmfriction.workflows.inputs.UserError`,
exit 2, naming both paths) a target that

* is not a regular file (a device such as ``/dev/null``, a FIFO, a socket): writing
  atomically would replace the node with a regular file;
* is one of the command's inputs, however it is written (a symlink, ``./x``, a hard
  link: ``os.path.samefile``);
* is a file of a run directory (a directory with ``run.json``) that is not one of
  the command's own runs (the runs among its inputs), or one of the files
  ``filmfriction run`` writes there (``run.json``, ``trace.csv``, ``lammps.log``,
  restart files, ...), which only a run writes;
* exists and was not written by the project, when ``ours`` says how to recognise
  the project's file (a side file such as the report's Markdown twin, or the main
  document: a JSON of the project carries ``"schema": "filmfriction..."``).

Examples
--------
>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> _ = (d / "t.csv").write_text("time,spring_force\\n0,1\\n")
>>> check_output(d / "t.csv", "--out", inputs=[d / "t.csv"])
Traceback (most recent call last):
...
filmfriction.workflows.inputs.UserError: --out ...t.csv: is the input ...t.csv; give another file name
"""
from __future__ import annotations

import json
import os
import stat
from pathlib import Path
from typing import Callable, Iterable

from filmfriction.md_inputs.contract import (COMMAND_FILE, DATA_FILE, LOG_FILE, RESTARTS_FILE,
                                             RUN_FILE, SCENE_FILE, SLIDE_ORIGIN_FILE,
                                             TRACE_DAT_FILE, TRACE_FILE)

from .inputs import UserError, check_writable

__all__ = ["check_output", "run_directory_of", "own_runs", "RUN_OWN_FILES", "is_project_json",
           "names_in", "head_has", "any_of"]

#: The files ``filmfriction run`` writes into its run directory; no other command
#: replaces them (restart files ``restart.<step>`` too).
RUN_OWN_FILES = frozenset({RUN_FILE, SCENE_FILE, COMMAND_FILE, LOG_FILE, TRACE_DAT_FILE,
                           TRACE_FILE, RESTARTS_FILE, SLIDE_ORIGIN_FILE, DATA_FILE})

_KINDS = ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"),
          (stat.S_ISDIR, "a directory"))


def run_directory_of(path) -> Path | None:
    """The run directory (a directory holding ``run.json``) ``path`` is in or is, if any."""
    path = Path(os.path.abspath(path))
    for d in (path, path.parent):
        if d.is_dir() and (d / RUN_FILE).is_file():
            return d.resolve()
    return None


def own_runs(inputs: Iterable) -> set[Path]:
    """The run directories among ``inputs`` (a run directory, or a file in one)."""
    return {d for d in (run_directory_of(p) for p in inputs if p is not None) if d is not None}


def _same(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def is_project_json(path: Path) -> bool:
    """Whether ``path`` holds a JSON object of the project (``"schema": "filmfriction..."``)."""
    try:
        with open(path, "rb") as fh:
            data = json.loads(fh.read(64 << 20).decode("utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and str(data.get("schema", "")).startswith("filmfriction")


def head_has(mark: bytes, size: int = 4096) -> Callable[[Path], bool]:
    """A test of a file of the project by a mark in its first ``size`` bytes (the report's
    page: ``b"<title>filmfriction report"``)."""
    def test(path: Path) -> bool:
        try:
            with open(path, "rb") as fh:
                return mark in fh.read(size)
        except OSError:
            return False
    return test


def names_in(document: Path) -> Callable[[Path], bool]:
    """A test of a side file of the project: the project's ``document`` beside it (an
    ``analysis.json``, a ``report.md``) names it.  (``document`` as it is before the
    command writes it.)"""
    def test(path: Path) -> bool:
        try:
            if not Path(document).is_file():
                return False
            with open(document, "rb") as fh:
                text = fh.read(64 << 20).decode("utf-8", "replace")
        except OSError:
            return False
        return f'"{path.name}"' in text or f"({path.name})" in text
    return test


def any_of(*tests: Callable[[Path], bool]) -> Callable[[Path], bool]:
    """A test passed when one of ``tests`` is."""
    return lambda path: any(test(path) for test in tests)


def check_output(path, flag: str, *, inputs: Iterable = (), ours: Callable[[Path], bool] | None = None,
                 what: str = "") -> None:
    """Refuse (UserError) writing ``path`` when it would replace an input or a file
    that is not the command's to replace (see the module's docstring).

    Parameters
    ----------
    path : path-like
        The file the command writes.
    flag : str
        How the user named it (``--out``, ``--output``, ``the Markdown twin of --out``).
    inputs : iterable of path-like
        The command's inputs (files and directories); their run directories are the
        command's own runs.
    ours : callable, optional
        ``ours(path)`` says whether an existing ``path`` was written by the project;
        when given, an existing file it does not recognise is refused.
    what : str
        What the file is, for the message (``"its Markdown twin"``).
    """
    path = Path(path)
    shown = f"{flag} {path}" + (f" ({what})" if what else "")
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise UserError(f"{shown}: {exc.strerror or exc}") from None
    if st is not None:
        for test, kind in _KINDS:
            if test(st.st_mode):
                raise UserError(f"{shown}: is {kind}, not a regular file; give a file name")
    inputs = [Path(p) for p in inputs if p is not None]
    for p in inputs:
        if st is not None and p.exists() and not p.is_dir() and _same(path, p):
            raise UserError(f"{shown}: is the input {p}; give another file name")
    run = run_directory_of(path.parent) if path.parent.exists() else None
    if run is not None:
        name = path.name
        if name in RUN_OWN_FILES or name.startswith("restart."):
            raise UserError(f"{shown}: is the file {name} of the run directory {run}, which only "
                            "'filmfriction run' writes; give another file name")
        mine = own_runs(inputs)
        if run not in mine:
            raise UserError(f"{shown}: a file of the run directory {run}, which is not an input "
                            "of this command; give a file outside it")
    if st is not None and ours is not None and not ours(path):
        raise UserError(f"{shown}: exists and was not written by filmfriction; choose another "
                        "name, or remove it")
    if st is None or not stat.S_ISDIR(st.st_mode):
        check_writable(path, flag)
