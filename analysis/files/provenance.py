"""Provenance of every JSON document the project writes: which filmfriction made it
(the package's version; the git commit and whether the checkout had changes, when it
runs from a git checkout) and the SHA-256 of the files it was made from.

:func:`provenance` is the one helper; every writer puts its result under the key
``"provenance"`` (``run.json``, ``analysis.json``, ``calibration.json``, ``sfb.json``,
a sweep's ``aggregate.json``).  Outside a git checkout (an installed wheel) the
commit is ``null``; no git, or a git that fails, is never an error.

:func:`input_digests` gives the inputs' digests; a reader compares them with the
files as they are now to tell a document made from other data (``report`` says a
``calibration.json`` is out of date by content, not by file times: a copied run is
not out of date).

Examples
--------
>>> import tempfile, pathlib
>>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
>>> _ = p.write_text("time,spring_force\\n0,1\\n")
>>> doc = provenance({"trace": p})
>>> sorted(doc), doc["package"]
(['git_commit', 'git_dirty', 'inputs', 'package', 'version'], 'filmfriction')
>>> doc["inputs"]["trace"]["sha256"][:12]
'aa595aa61d6e'
"""
from __future__ import annotations

import functools
import hashlib
import os
import subprocess
from pathlib import Path

__all__ = ["provenance", "input_digests", "file_sha256", "git_state", "checkout_state"]


def file_sha256(path) -> str:
    """The SHA-256 of the file's bytes (hex)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


@functools.lru_cache(maxsize=1)
def git_state() -> tuple[str | None, bool | None]:
    """``(commit, dirty)`` of the git checkout the package runs from, ``(None, None)``
    when it does not run from one (or git is missing or fails)."""
    return checkout_state(Path(__file__).resolve().parents[2])


def checkout_state(root: Path) -> tuple[str | None, bool | None]:
    """``(commit, dirty)`` of the git checkout whose top folder is ``root`` (``(None,
    None)`` when ``root`` is not one)."""
    root = Path(root)
    if not (root / ".git").exists():
        return None, None
    env = {k: v for k, v in os.environ.items() if not k.startswith("GIT_")}
    try:
        commit = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], env=env,
                                capture_output=True, text=True, timeout=10)
        if commit.returncode != 0:
            return None, None
        status = subprocess.run(["git", "-C", str(root), "status", "--porcelain",
                                 "--untracked-files=no"], env=env, capture_output=True,
                                text=True, timeout=20)
    except (OSError, subprocess.SubprocessError):
        return None, None
    dirty = bool(status.stdout.strip()) if status.returncode == 0 else None
    return commit.stdout.strip() or None, dirty


def input_digests(inputs: dict) -> dict:
    """``{role: {"path", "sha256"}}`` of the input files (a role whose path is None or not
    a regular file is left out; a directory's digest is not taken)."""
    out = {}
    for role, path in inputs.items():
        if path is None:
            continue
        path = Path(path)
        try:
            if not path.is_file():
                continue
            out[role] = {"path": str(path), "sha256": file_sha256(path)}
        except OSError:
            continue
    return out


def provenance(inputs: dict | None = None) -> dict:
    """The ``provenance`` entry of a document: package, version, git commit and state, and
    the SHA-256 of ``inputs`` (role -> path; see :func:`input_digests`)."""
    from filmfriction import __version__

    commit, dirty = git_state()
    return {"package": "filmfriction", "version": __version__, "git_commit": commit,
            "git_dirty": dirty, "inputs": input_digests(inputs or {})}
