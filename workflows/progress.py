"""What a command says while it works: its verbosity (``--quiet``, ``--verbose``)
and the progress of its long stages.

One place decides how progress is shown: a progress bar (tqdm) when standard
error is a terminal, otherwise one line per stage (a log file or a pipe gets no
``\\r`` frames), nothing with ``--quiet``.  ``--verbose`` adds the details: the
commands started, and in a log a line at every tenth of a stage's steps.

>>> set_level(QUIET); note("not shown"); set_level(NORMAL)
"""
from __future__ import annotations

import sys
import time

__all__ = ["QUIET", "NORMAL", "VERBOSE", "set_level", "level", "note", "detail",
           "progress_bar"]

QUIET, NORMAL, VERBOSE = 0, 1, 2
_level = NORMAL


def set_level(value: int) -> None:
    """The verbosity of this process: :data:`QUIET`, :data:`NORMAL` or :data:`VERBOSE`."""
    global _level
    if value not in (QUIET, NORMAL, VERBOSE):
        raise ValueError(f"verbosity {value!r}: give QUIET, NORMAL or VERBOSE")
    _level = value


def level() -> int:
    """The verbosity set by :func:`set_level` (:data:`NORMAL` unless set)."""
    return _level


def note(message: str) -> None:
    """A line on standard error about the work under way, unless ``--quiet``."""
    if _level >= NORMAL:
        print(message, file=sys.stderr, flush=True)


def detail(message: str) -> None:
    """A line on standard error with ``--verbose`` only."""
    if _level >= VERBOSE:
        print(message, file=sys.stderr, flush=True)


class StageLines:
    """Progress as lines: one when a stage starts, one when it ends (with
    ``--verbose``, one more at every tenth of the steps); the part of tqdm's
    interface that the engine uses (``update``, ``set_description``, ``close``)."""

    def __init__(self, total: int, initial: int = 0, desc: str = "", stream=None):
        self.total, self.n, self.desc = total, initial, desc
        self._stream = stream or sys.stderr
        self._stage_start = (time.monotonic(), initial)
        self._tenth = self._tenths(initial)
        self._closed = False
        self._say(f"{desc}: started at step {initial} of {total}")

    def _tenths(self, n: int) -> int:
        return int(10 * n / self.total) if self.total > 0 else 0

    def _say(self, text: str) -> None:
        print(text, file=self._stream, flush=True)

    def _end_stage(self) -> None:
        seconds = time.monotonic() - self._stage_start[0]
        self._say(f"{self.desc}: at step {self.n} of {self.total} "
                  f"({self.n - self._stage_start[1]} steps in {seconds:.0f} s)")

    def set_description(self, desc: str) -> None:
        if desc == self.desc:
            return
        self._end_stage()
        self.desc, self._stage_start = desc, (time.monotonic(), self.n)
        self._say(f"{desc}: started at step {self.n} of {self.total}")

    def update(self, steps: int) -> None:
        self.n += steps
        tenth = self._tenths(self.n)
        if tenth > self._tenth:
            self._tenth = tenth
            if _level >= VERBOSE:
                self._say(f"{self.desc}: step {self.n} of {self.total} ({10 * tenth} %)")

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._end_stage()


class _Silent:
    """No progress (``--quiet``, or a caller that asked for none)."""

    n = 0

    def update(self, steps: int) -> None:
        pass

    def set_description(self, desc: str) -> None:
        pass

    def close(self) -> None:
        pass


def progress_bar(total: int, initial: int = 0, desc: str = "", *, enabled: bool = True):
    """The progress display of a stage of ``total`` steps: a tqdm bar on a terminal,
    :class:`StageLines` otherwise, nothing when not ``enabled`` or ``--quiet``."""
    if not enabled or _level <= QUIET:
        return _Silent()
    stream = sys.stderr
    if getattr(stream, "isatty", lambda: False)():
        from tqdm import tqdm

        return tqdm(total=total, initial=initial, unit="step", desc=desc,
                    dynamic_ncols=True, file=stream, smoothing=0.1)
    return StageLines(total, initial, desc, stream)
