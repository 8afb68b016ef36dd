"""The restart files of a run directory: which ones ``--resume`` may trust.

LAMMPS writes ``restart.<step>`` every ``restart_every`` steps of the slide.
A restart file can be unusable while looking complete: cut off by a full disk
or a kill (shorter than the others), or of its full size with a tail that
never reached the disk (a crash of the machine) or damaged since.  So the
runner records each restart's size and SHA-256 in ``restarts.json`` as soon as
it knows LAMMPS has finished writing it: when the engine reports a step past
the restart's, or exits cleanly.  ``--resume`` takes the newest restart file
that

* begins and ends with LAMMPS's restart marker (``LammpS RestartT``), and
* has the size and checksum recorded for it; a restart the runner never saw
  complete (LAMMPS outlived a runner killed with SIGKILL) has no record: the
  markers and the size of the recorded ones vouch for it,

and falls back to the previous one otherwise.

Example
-------
>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> for step in (2000, 4000):
...     _ = (d / f"restart.{step}").write_bytes(MAGIC + bytes(100) + MAGIC)
>>> RestartLedger(d).record_below(None)
['restart.2000', 'restart.4000']
>>> with open(d / "restart.4000", "r+b") as f:   # same size, damaged inside
...     _ = f.seek(50)
...     _ = f.write(b"x")
>>> [p.name for _, p in usable(d)]
['restart.2000']
>>> unusable(d)
{'restart.4000': 'its SHA-256 differs from the one recorded when LAMMPS wrote it (damaged)'}
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

from filmfriction.analysis.files.util import write_atomic

__all__ = ["MAGIC", "LEDGER", "RestartLedger", "restart_files", "usable", "unusable", "prune"]

#: LAMMPS's marker at the start and the end of a restart file (``MAGIC_STRING`` and its NUL)
MAGIC = b"LammpS RestartT\0"
#: the record of the restarts seen complete: {name: {"bytes": size, "sha256": hex}}
LEDGER = "restarts.json"


def restart_files(run_dir: Path) -> list[tuple[int, Path]]:
    """``(step, path)`` of every ``restart.<step>`` in the run directory, oldest first."""
    found = []
    for p in Path(run_dir).glob("restart.*"):
        suffix = p.name.split(".", 1)[1]
        if suffix.isdigit():
            found.append((int(suffix), p))
    return sorted(found)


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _read_ledger(run_dir: Path) -> dict:
    try:
        data = json.loads((Path(run_dir) / LEDGER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}        # none yet (or unreadable: every restart is then unrecorded)
    return data if isinstance(data, dict) else {}


class RestartLedger:
    """``restarts.json`` of one run directory, kept in memory while LAMMPS runs."""

    def __init__(self, run_dir: Path):
        self.run_dir = Path(run_dir)
        self.entries = _read_ledger(self.run_dir)

    def record_below(self, step: int | None) -> list[str]:
        """Record every unrecorded restart of a step below ``step`` (None: all of them,
        LAMMPS has exited cleanly); return the names recorded now.

        LAMMPS writes a restart at the end of its step, after that step's trace row
        and before any later step: a later step proves the file closed.  A recorded
        file is never re-recorded, so a file damaged later stays detectably damaged.
        """
        new = []
        for s, path in restart_files(self.run_dir):
            if (step is None or s < step) and path.name not in self.entries:
                try:
                    self.entries[path.name] = {"bytes": path.stat().st_size,
                                               "sha256": _sha256(path)}
                except FileNotFoundError:
                    continue
                new.append(path.name)
        if new:
            write_atomic(self.run_dir / LEDGER, json.dumps(self.entries, indent=1) + "\n")
        return new

    def forget(self, names) -> None:
        """Drop the entries of deleted restart files."""
        if any(self.entries.pop(n, None) is not None for n in list(names)):
            write_atomic(self.run_dir / LEDGER, json.dumps(self.entries, indent=1) + "\n")


def _problem(path: Path, entry: dict | None, full_size: int) -> str | None:
    """Why ``path`` cannot be resumed from (None: it can)."""
    size = path.stat().st_size
    if entry is not None and size != entry.get("bytes"):
        return f"{size} bytes, {entry.get('bytes')} when LAMMPS wrote it (cut off)"
    if entry is None and size != full_size:
        return f"{size} bytes against {full_size} for the others (cut off)"
    if size < 2 * len(MAGIC):
        return f"{size} bytes: too short for a restart file"
    with open(path, "rb") as fh:
        head = fh.read(len(MAGIC))
        fh.seek(-len(MAGIC), 2)
        tail = fh.read(len(MAGIC))
    if head != MAGIC:
        return "no LAMMPS restart marker at its start"
    if tail != MAGIC:
        return "no LAMMPS restart marker at its end (written only in part)"
    if entry is not None and _sha256(path) != entry.get("sha256"):
        return "its SHA-256 differs from the one recorded when LAMMPS wrote it (damaged)"
    return None


def check(run_dir: Path) -> tuple[list[tuple[int, Path]], dict[str, str]]:
    """The usable restarts ``(step, path)`` oldest first, and ``{name: reason}`` of the others."""
    entries = _read_ledger(run_dir)
    files = restart_files(run_dir)
    sizes = [e.get("bytes") for e in entries.values() if isinstance(e, dict)]
    # every restart of a run has the same size (the same atoms): the recorded one,
    # else the largest on disk
    full = max(sizes or [p.stat().st_size for _, p in files] or [0])
    good, bad = [], {}
    for step, path in files:
        entry = entries.get(path.name)
        reason = _problem(path, entry if isinstance(entry, dict) else None, full)
        if reason is None:
            good.append((step, path))
        else:
            bad[path.name] = reason
    return good, bad


def usable(run_dir: Path) -> list[tuple[int, Path]]:
    """Restart files ``--resume`` may use, oldest first."""
    return check(run_dir)[0]


def unusable(run_dir: Path) -> dict[str, str]:
    """``{name: reason}`` of the restart files ``--resume`` refuses."""
    return check(run_dir)[1]


def prune(run_dir: Path) -> None:
    """Keep only the newest restart file (the one ``--resume`` would use) and its record."""
    ledger = RestartLedger(run_dir)
    old = restart_files(run_dir)[:-1]
    for _, path in old:
        path.unlink(missing_ok=True)
    ledger.forget(p.name for _, p in old)
