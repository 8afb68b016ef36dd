"""Stop an engine and every process it started, however it was started.

MPICH's ``mpiexec`` (hydra) starts a proxy that calls ``setsid``, and the proxy
starts each MPI rank in a session of its own: signalling the launcher's
process group reaches the launcher only, and a launcher killed outright leaves
its proxy and ranks running.  :func:`stop` therefore follows the process tree
(parent pids in ``/proc``) and the sessions of its processes (a process orphaned when its
parent dies keeps its session), asks every process in it to stop (SIGTERM), waits
:data:`GRACE` seconds, kills what is left (SIGKILL), and returns once none of
them runs any more.  A process is known by its pid and its start time, so a pid
the kernel reuses is never signalled.

Example
-------
>>> import subprocess, sys
>>> child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"],
...                          start_new_session=True)
>>> stop(child, grace=1.0)
[]
>>> child.returncode
-15
"""
from __future__ import annotations

import os
import signal
import subprocess
import time

__all__ = ["GRACE", "descendants", "in_sessions", "stop"]

#: seconds an engine has between SIGTERM and SIGKILL
GRACE = 5.0

_Proc = tuple[int, int]         # (pid, start time in clock ticks)


def _stat(pid: int) -> tuple[int, str, int, int] | None:
    """(parent pid, state, start time, session id) of ``pid``; None when it does not exist."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            text = fh.read().decode(errors="replace")
    except OSError:
        return None
    fields = text[text.rfind(")") + 2:].split()     # after "pid (comm) "
    return int(fields[1]), fields[0], int(fields[19]), int(fields[3])


def descendants(pid: int) -> list[_Proc]:
    """Every living process below ``pid`` in the process tree, as (pid, start time)."""
    children: dict[int, list[_Proc]] = {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            info = _stat(int(name))
            if info is not None:
                children.setdefault(info[0], []).append((int(name), info[2]))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child[0])
    return found


def in_sessions(sessions: set[int]) -> list[_Proc]:
    """Every living process whose session is one of ``sessions``, as (pid, start time): a
    process orphaned by its parent's death (reparented to init) keeps its session."""
    found = []
    for name in os.listdir("/proc"):
        if name.isdigit():
            info = _stat(int(name))
            if info is not None and info[3] in sessions and info[1] not in ("Z", "X"):
                found.append((int(name), info[2]))
    return found


def _sessions(procs, own: int) -> set[int]:
    """The sessions of the living ``procs``, the caller's own left out."""
    out = set()
    for proc in procs:
        info = _stat(proc[0])
        if info is not None and info[2] == proc[1]:
            out.add(info[3])
    return out - {own}


def _alive(proc: _Proc) -> bool:
    info = _stat(proc[0])
    return info is not None and info[2] == proc[1] and info[1] not in ("Z", "X")


def _signal(procs, sig) -> None:
    for proc in procs:
        if _alive(proc):
            try:
                os.kill(proc[0], sig)
            except OSError:
                pass


def stop(popen: subprocess.Popen, grace: float = GRACE) -> list[int]:
    """Stop ``popen`` and all its descendants: SIGTERM, then SIGKILL after ``grace``
    seconds for whatever still runs; returns once every one of them is gone.  Signals
    arriving meanwhile (a second Ctrl-C) are held until then.  Returns the pids that
    needed SIGKILL."""
    held = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
    saved = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    own = os.getsid(0)
    try:
        tree = set(descendants(popen.pid))
        sessions = _sessions(tree | {(popen.pid, (_stat(popen.pid) or (0, "", 0, 0))[2])}, own)

        def grow() -> None:
            # the launcher's descendants, and every process of the engine's sessions: a
            # child started while stopping, or orphaned when its parent died, is still found
            nonlocal tree, sessions
            if popen.poll() is None:
                tree |= set(descendants(popen.pid))
            tree |= set(in_sessions(sessions))
            sessions |= _sessions(tree, own)

        if popen.poll() is None:
            try:
                os.killpg(popen.pid, signal.SIGTERM)    # the launcher (its own session)
            except OSError:
                popen.send_signal(signal.SIGTERM)
        _signal(tree, signal.SIGTERM)
        deadline = time.monotonic() + grace
        while time.monotonic() < deadline:
            grow()
            if popen.poll() is not None and not any(_alive(p) for p in tree):
                return []
            time.sleep(0.05)
        grow()
        killed = [p[0] for p in tree if _alive(p) and p[0] != popen.pid] + (
            [popen.pid] if popen.poll() is None else [])
        _signal(tree, signal.SIGKILL)
        if popen.poll() is None:
            popen.kill()
        popen.wait()
        # a killed rank whose parent also died is reaped by init: wait for that too, and
        # kill what its last moments started (found through the engine's sessions)
        while True:
            grow()
            left = [p for p in tree if _alive(p)]
            if not left:
                break
            _signal(left, signal.SIGKILL)
            time.sleep(0.02)
        return killed
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, saved)
