"""Signals during a run: SIGTERM and SIGHUP handled as Ctrl-C (SIGINT).

While :class:`TerminationAsInterrupt` is active (for the whole of a run or a resume, from
the run directory's creation on), the first of SIGINT, SIGTERM and SIGHUP raises
KeyboardInterrupt (:class:`Terminated` for the last two), and a second one is ignored: a
signal during the set-up ends the same way as one while LAMMPS runs, and a second one
cannot cut short the stopping of LAMMPS or the record of the interruption
(:func:`filmfriction.workflows.md.finish.interrupted`).
"""
from __future__ import annotations

import signal

__all__ = ["Terminated", "TerminationAsInterrupt"]


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP, handled like Ctrl-C (SIGINT)."""


def _raise_terminated(signum, frame):
    # the first signal only: a second one (a second Ctrl-C included) while the runner
    # stops LAMMPS and records the interruption is ignored (the context restores the
    # handlers at its end)
    for sig in TerminationAsInterrupt.SIGNALS:
        signal.signal(sig, signal.SIG_IGN)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated(signal.Signals(signum).name)


class TerminationAsInterrupt:
    """While active, SIGTERM and SIGHUP raise :class:`Terminated` and SIGINT raises
    KeyboardInterrupt, the first of them only (main thread only).

    Active for the whole of a run or a resume, from the run directory's creation
    on: a signal during the set-up ends the same way as one while LAMMPS runs, and
    a second one cannot cut short the stopping of LAMMPS or the record of the
    interruption.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)

    def __enter__(self):
        import threading

        self.saved = {}
        if threading.current_thread() is threading.main_thread():
            for sig in self.SIGNALS:
                self.saved[sig] = signal.signal(sig, _raise_terminated)
        return self

    def __exit__(self, *exc):
        for sig, handler in self.saved.items():
            signal.signal(sig, handler)
        return False
