"""What a user gives, checked before any compute: the one error of bad input
(:class:`UserError`), the exit codes, and the checks every command shares.

Exit codes: 0 done, 1 a run or computation failed (:data:`EXIT_FAILED`), 2 bad
input (:data:`EXIT_BAD_INPUT`), 130 interrupted.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from filmfriction.analysis.files.util import read_json_object
from filmfriction.md_inputs.contract import AGGREGATE_FILE, ANALYSIS_FILE, RUN_FILE, TRACE_FILE

from .md.scene import SceneError
from .md.scenes.parameters import parse_assignment

__all__ = ["UserError", "EXIT_FAILED", "EXIT_BAD_INPUT", "check_writable", "check_run_json",
           "check_run_source", "check_ranks", "parse_overrides", "usable_cpus", "cap_workers",
           "env_count", "check_not_in_run", "check_input_file", "is_stream", "read_stream_once",
           "MAX_INPUT_BYTES"]


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
    :func:`filmfriction.analysis.files.documents.check_document`)."""
    path = Path(run_dir) / RUN_FILE
    if not path.is_file():
        return None
    where = f"{flag} {path}" if flag else str(path)
    from filmfriction.analysis.files.documents import check_document

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
    """MPI ranks on this machine: at least 1, at most the CPUs this process may use
    (:func:`usable_cpus`; mpiexec would oversubscribe, or fail after the setup).
    ``more``: where more ranks are accepted, appended to the message."""
    if nprocs is None:
        return
    cpus = usable_cpus()
    if not 1 <= nprocs <= cpus:
        raise UserError(f"{flag} {nprocs}: need between 1 and {cpus} MPI ranks "
                        f"(the CPUs this process may use){more}")


def usable_cpus() -> int:
    """The CPUs this process may run on (its affinity mask, e.g. under taskset or
    Slurm; the machine's count where the platform has no mask)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:          # pragma: no cover -- macOS, Windows
        return os.cpu_count() or 1


def cap_workers(count: int, flag: str) -> int:
    """Worker processes to start for ``flag count``: at least 1 (UserError below),
    at most :func:`usable_cpus` (capped, with a note on stderr)."""
    if count < 1:
        raise UserError(f"{flag} {count}: need at least 1 worker process")
    cpus = usable_cpus()
    if count > cpus:
        from .progress import note

        note(f"{flag} {count}: capped to {cpus}, the CPUs this process may use")
        return cpus
    return count


def env_count(name: str, default: int, low: int = 1, high: int = 10**12) -> int:
    """The whole number of the environment variable ``name`` (``default`` when unset
    or empty); UserError naming the variable, its value and the accepted range
    otherwise."""
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    try:
        value = int(text.replace("_", ""))
    except ValueError:
        value = None
    if value is None or not low <= value <= high:
        accepted = f"in [{low}, {high}]" if high < 10**12 else f">= {low}"
        raise UserError(f"environment variable {name}={text!r}: give a whole number "
                        f"{accepted} (default {default}), or unset it")
    return value


def check_not_in_run(path, flag: str) -> None:
    """Refuse (UserError) a directory to create at or under a run directory (one
    with ``run.json``): a run or a sweep is never written into another run."""
    given = Path(path)
    full = given.absolute()
    for folder in (full, *full.parents):
        if (folder / RUN_FILE).is_file():
            where = ("is a run directory" if folder == full else
                     f"is inside the run directory {folder}")
            raise UserError(f"{flag} {given}: {where} (its {RUN_FILE}); nothing is created "
                            "inside a run directory: give a directory outside any run")


#: largest input file read (bytes) unless FILMFRICTION_MAX_INPUT_BYTES says otherwise
MAX_INPUT_BYTES = 1 << 30
_SNIFF = 65536


def check_input_file(path, flag: str = "") -> None:
    """Refuse (UserError), before parsing, a regular file that is larger than
    ``$FILMFRICTION_MAX_INPUT_BYTES`` (default 1 GiB) or holds a NUL byte in its
    first or last 64 KiB (a binary file, not text)."""
    path = Path(path)
    where = f"{flag} {path}" if flag else str(path)
    if not path.is_file():
        return
    limit = env_count("FILMFRICTION_MAX_INPUT_BYTES", MAX_INPUT_BYTES)
    size = path.stat().st_size
    if size > limit:
        raise UserError(f"{where}: {size:,} bytes, above the limit of {limit:,} bytes for a "
                        "text input (set FILMFRICTION_MAX_INPUT_BYTES to raise it)")
    with open(path, "rb") as fh:
        head = fh.read(_SNIFF)
        if size > 2 * _SNIFF:
            fh.seek(size - _SNIFF)
        tail = fh.read(_SNIFF)
    for part, at in ((head, 0), (tail, max(size - len(tail), 0))):
        _refuse_binary(part, at, where)


def _refuse_binary(chunk: bytes, at: int, where: str) -> None:
    nul = chunk.find(b"\0")
    if nul >= 0:
        raise UserError(f"{where}: a NUL byte at byte {at + nul}: a binary file, not a text "
                        "trace; give a text file (comma-, tab-, semicolon- or "
                        "space-separated columns)")


def is_stream(path) -> bool:
    """``path`` exists and is neither a regular file nor a directory: a pipe such as
    ``<(cmd)``, a FIFO or a device, which can be read once only."""
    path = Path(path)
    return path.exists() and not path.is_file() and not path.is_dir()


def read_stream_once(path, folder, flag: str = "") -> Path:
    """Copy the stream ``path`` (see :func:`is_stream`) into a file of ``folder``,
    reading it once, and return that file; UserError, as soon as it shows, for a NUL
    byte or more than ``$FILMFRICTION_MAX_INPUT_BYTES`` bytes (as
    :func:`check_input_file`)."""
    path = Path(path)
    where = f"{flag} {path}" if flag else str(path)
    limit = env_count("FILMFRICTION_MAX_INPUT_BYTES", MAX_INPUT_BYTES)
    copy = Path(folder) / (path.name or "stream")
    size = 0
    with open(path, "rb") as src, open(copy, "wb") as dst:
        while chunk := src.read(1 << 20):
            _refuse_binary(chunk, size, where)
            size += len(chunk)
            if size > limit:
                raise UserError(f"{where}: more than {limit:,} bytes, the limit for a text "
                                "input (set FILMFRICTION_MAX_INPUT_BYTES to raise it)")
            dst.write(chunk)
    return copy
