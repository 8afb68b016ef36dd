"""Stop an engine and every process it started, however it was started.

MPICH's ``mpiexec`` (hydra) starts a proxy that calls ``setsid``, and the proxy
starts each MPI rank in a session of its own: signalling the launcher's
process group reaches the launcher only, and a launcher killed outright leaves
its proxy and ranks running.  :func:`stop` therefore follows the process tree
(parent pids in ``/proc``), asks every process in it to stop (SIGTERM), waits
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

__all__ = ["GRACE", "descendants", "stop"]

#: seconds an engine has between SIGTERM and SIGKILL
GRACE = 5.0

_Proc = tuple[int, int]         # (pid, start time in clock ticks)


def _stat(pid: int) -> tuple[int, str, int] | None:
    """(parent pid, state, start time) of ``pid``; None when it does not exist."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            text = fh.read().decode(errors="replace")
    except OSError:
        return None
    fields = text[text.rfind(")") + 2:].split()     # after "pid (comm) "
    return int(fields[1]), fields[0], int(fields[19])


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
    try:
        tree = set(descendants(popen.pid))
        if popen.poll() is None:
            try:
                os.killpg(popen.pid, signal.SIGTERM)    # the launcher (its own session)
            except OSError:
                popen.send_signal(signal.SIGTERM)
        _signal(tree, signal.SIGTERM)
        deadline = time.monotonic() + grace
        while time.monotonic() < deadline:
            if popen.poll() is None:
                tree |= set(descendants(popen.pid))     # started while stopping
            if popen.poll() is not None and not any(_alive(p) for p in tree):
                return []
            time.sleep(0.05)
        if popen.poll() is None:
            tree |= set(descendants(popen.pid))
        killed = [p[0] for p in tree if _alive(p)] + ([popen.pid] if popen.poll() is None
                                                      else [])
        _signal(tree, signal.SIGKILL)
        if popen.poll() is None:
            popen.kill()
        popen.wait()
        # a killed rank whose parent also died is reaped by init: wait for that too
        while any(_alive(p) for p in tree):
            time.sleep(0.02)
        return killed
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, saved)
