"""One lock for a directory that one process at a time may drive (a run, a sweep).

An exclusive ``flock`` on a file in the directory, holding the holder's pid and
host.  The kernel releases it when every holder exits, however it exits, so a
killed process never leaves a stale lock.

Example
-------
>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> with DirectoryLock(d / ".lock", lambda holder: ValueError(f"busy: {holder}")):
...     try:
...         DirectoryLock(d / ".lock", lambda holder: ValueError("busy")).acquire()
...     except ValueError as exc:
...         print(exc)
busy
"""
from __future__ import annotations

import fcntl
import os
from pathlib import Path
from typing import Callable

__all__ = ["DirectoryLock", "RunLock"]


class DirectoryLock:
    """Exclusive lock on the file ``path``; ``refuse(holder)`` builds the exception raised
    when another process holds it (``holder``: what that process wrote).  With
    ``inheritable`` the descriptor passes to child processes (a Snakemake child keeps
    a sweep's lock as long as either process lives)."""

    def __init__(self, path: Path, refuse: Callable[[str], Exception], *,
                 inheritable: bool = False):
        self.path = Path(path)
        self.refuse = refuse
        self.inheritable = inheritable
        self.fd: int | None = None

    def acquire(self) -> "DirectoryLock":
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 200, 0).decode(errors="replace").strip() or "?"
            os.close(fd)
            raise self.refuse(holder) from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} on {os.uname().nodename}\n".encode(), 0)
        if self.inheritable:
            os.set_inheritable(fd, True)
        self.fd = fd
        return self

    def release(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


def RunLock(run_dir: Path) -> DirectoryLock:
    """The lock on ``RUN_DIR/.lock`` for as long as a run or a resume drives the directory:
    a second run or ``--resume`` of the same directory is refused (:class:`SceneError`,
    naming the holder's pid)."""
    from .scene import SceneError

    run_dir = Path(run_dir)
    return DirectoryLock(run_dir / ".lock", lambda holder: SceneError(
        f"run directory {run_dir} is in use ({holder}: a run or a resume is driving it); "
        "wait for it to finish, or stop that process first"))
