"""What a user gives, checked before any compute: the one error of bad input
(:class:`UserError`), the exit codes, and the checks every command shares.

Exit codes: 0 done, 1 a run or computation failed (:data:`EXIT_FAILED`), 2 bad
input (:data:`EXIT_BAD_INPUT`), 130 interrupted.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from filmfriction.analysis.util import read_json_object
from filmfriction.md_inputs.contract import AGGREGATE_FILE, ANALYSIS_FILE, RUN_FILE, TRACE_FILE

from .md.scene import SceneError, parse_assignment

__all__ = ["UserError", "EXIT_FAILED", "EXIT_BAD_INPUT", "check_writable", "check_run_json",
           "check_run_source", "check_ranks", "parse_overrides"]


class UserError(Exception):
    """A problem with the user's input: printed without a traceback, exit code 2."""


EXIT_FAILED = 1
EXIT_BAD_INPUT = 2


def check_writable(path, flag: str, *, directory: bool = False) -> None:
    """Refuse (UserError) an output path that cannot be written, before any compute.

    ``directory``: the path is a directory to create or write into; otherwise a
    file (an existing directory there is refused).  Nothing is created.
    """
    path = Path(path)
    if not directory and path.is_dir():
        raise UserError(f"{flag} {path}: is a directory; give a file name")
    if directory and path.exists() and not path.is_dir():
        raise UserError(f"{flag} {path}: is a file; give a directory")
    # the nearest existing ancestor must be a writable directory
    probe = path if directory and path.exists() else path.parent
    probe = probe if str(probe) else Path(".")
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if not probe.is_dir():
        raise UserError(f"{flag} {path}: {probe} is a file, not a directory")
    # a real probe (os.access says yes to root, and knows nothing of /proc):
    # create and remove one hidden file
    try:
        fd, name = tempfile.mkstemp(prefix=".ff-probe-", dir=probe)
    except OSError as exc:
        raise UserError(f"{flag} {path}: cannot write in {probe}: "
                        f"{exc.strerror or exc}") from None
    os.close(fd)
    os.unlink(name)


def check_run_json(run_dir, flag: str = "", kind: str = "run") -> dict | None:
    """``RUN_DIR/run.json`` as a dict (None when absent); UserError when it is not
    UTF-8, not JSON, not a JSON object, or not of the form of a run record (``kind``:
    ``"run"``, or ``"run-resume"`` for what a resume reads;
    :func:`filmfriction.analysis.documents.check_document`)."""
    path = Path(run_dir) / RUN_FILE
    if not path.is_file():
        return None
    where = f"{flag} {path}" if flag else str(path)
    from filmfriction.analysis.documents import check_document

    try:
        return check_document(read_json_object(path, where, what="a JSON object (a run record)"),
                              kind, where)
    except ValueError as exc:
        raise UserError(str(exc)) from None


def check_run_source(path) -> None:
    """``path`` holds something to calibrate or report on: a run directory
    (``trace.csv``), a finished sweep (``aggregate.json``) or an analysed trace
    file (``analysis.json``), with a readable ``run.json`` if any; UserError
    otherwise."""
    path = Path(path)
    if not any((path / name).exists() for name in (TRACE_FILE, AGGREGATE_FILE,
                                                   ANALYSIS_FILE)):
        raise UserError(f"{path}: neither a run directory (trace.csv), a finished sweep "
                        "(aggregate.json) nor an analysed trace file (analysis.json; "
                        "'filmfriction analyze TRACE_FILE' writes it)")
    check_run_json(path)


def parse_overrides(texts) -> dict:
    """``--set KEY=VALUE`` texts as a dict; a key given twice is refused."""
    values: dict = {}
    for text in texts:
        key, value = parse_assignment(text)
        if key in values:
            raise SceneError(f"--set {key} given twice ({values[key]!r} and {value!r}): "
                             "give each key once")
        values[key] = value
    return values


def check_ranks(nprocs: int | None, flag: str = "--np", more: str = "") -> None:
    """MPI ranks on this machine: at least 1, at most its CPUs (mpiexec would
    oversubscribe, or fail after the setup).  ``more``: where more ranks are
    accepted, appended to the message."""
    if nprocs is None:
        return
    cpus = os.cpu_count() or 1
    if not 1 <= nprocs <= cpus:
        raise UserError(f"{flag} {nprocs}: need between 1 and {cpus} MPI ranks "
                        f"(the CPUs of this machine){more}")
