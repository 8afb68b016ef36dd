"""The files the study writes into a run directory for the report to read.

``calibration.json`` (+ ``calibration_replay.csv``) is written by
:func:`filmfriction.analysis.write_calibration` (``filmfriction calibrate``
and the study); ``sfb.json`` (+ ``sfb_slips.csv``, the slips' traces) by
:func:`write_sfb` (``filmfriction sfb --out`` and the study).  The readers
here only read: a file that is not there is ``None``, never recomputed.
"""
from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from filmfriction.analysis.atomic import write_atomic
from filmfriction.analysis.report import to_json
from filmfriction.reduced_model.sfb_rows import find_row

__all__ = ["CALIBRATION_FILE", "SFB_FILE", "SFB_TRACES_SUFFIX", "write_sfb", "read_json",
           "read_calibration", "read_sfb", "SFBDocument", "SlipTrace"]

CALIBRATION_FILE = "calibration.json"
SFB_FILE = "sfb.json"
#: The slips' traces go to ``<stem><suffix>`` beside ``sfb.json``.
SFB_TRACES_SUFFIX = "_slips.csv"
#: The traces kept run from y to this many slip times.
TRACE_SPAN = 2.0


def write_sfb(check, path) -> Path:
    """Write an SFB check (:class:`filmfriction.reduced_model.SFBCheck`) as ``sfb.json``.

    The document is ``check.as_dict()`` plus ``traces``, the name of the CSV
    (``slip,time,x``, SI) with every slip's trace from the yield point y to
    twice its slip time (the whole run when s was not reached), written
    beside it.

    Returns
    -------
    Path
        The JSON file.
    """
    path = Path(path)
    traces = path.with_name(path.stem + SFB_TRACES_SUFFIX)
    lines = ["slip,time,x\n"]
    for key, run in check.slips.items():
        t, x = np.asarray(run.t, float), np.asarray(run.x, float)
        if np.isfinite(run.slip_time):
            keep = t <= TRACE_SPAN * run.slip_time
            t, x = t[keep], x[keep]
        lines += [f"{key},{a!r},{b!r}\n" for a, b in zip(t.tolist(), x.tolist())]
    write_atomic(traces, "".join(lines))
    doc = check.as_dict()
    doc["traces"] = traces.name
    return write_atomic(path, to_json(doc) + "\n")


def read_json(path):
    """The JSON document at ``path``, or ``None`` if there is no such file.

    Raises
    ------
    ValueError
        The file is not valid JSON.
    """
    path = Path(path)
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path}: cannot read: {exc}") from None


def _columns(path: Path) -> dict:
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], rows[1:]
    return {name: [row[i] for row in body] for i, name in enumerate(header)}


def read_calibration(path):
    """``calibration.json`` with its replay trace, or ``None`` if the file is not there.

    Returns
    -------
    dict or None
        The document; ``replay_trace`` is replaced by ``{"t", "spring_force"}``
        arrays when its CSV exists (else ``None``).
    """
    path = Path(path)
    doc = read_json(path)
    if doc is None:
        return None
    name = doc.get("replay_trace")
    trace = path.with_name(name) if name else None
    if trace is not None and trace.is_file():
        cols = _columns(trace)
        doc["replay_trace"] = {"t": np.array(cols["time"], float),
                               "spring_force": np.array(cols["spring_force"], float)}
    else:
        doc["replay_trace"] = None
    return doc


@dataclass(frozen=True)
class SlipTrace:
    """One slip of ``sfb.json``: its scalars and, when written, its trace (SI)."""

    slip_time: float
    slip_distance: float
    t: np.ndarray | None = None
    x: np.ndarray | None = None


@dataclass(frozen=True)
class SFBDocument:
    """``sfb.json`` as read back: the table, the notes, the slips, the calibration used."""

    rows: list
    notes: tuple = ()
    slips: dict = field(default_factory=dict)
    calibration: dict | None = None
    doc: dict = field(default_factory=dict)

    def row(self, name: str, source: str = "sfb-parameters") -> dict:
        """The row called ``name`` from ``source``."""
        return find_row(self.rows, name, source)


def _nan(x) -> float:
    return float("nan") if x is None else float(x)


def read_sfb(path):
    """``sfb.json`` (and its traces), or ``None`` if the file is not there.

    An ``sfb.json`` of an older version (a bare list of rows) gives the rows
    only (no notes, no slips).
    """
    path = Path(path)
    doc = read_json(path)
    if doc is None:
        return None
    if isinstance(doc, list):
        return SFBDocument(rows=doc, doc={"rows": doc})
    traces = {}
    name = doc.get("traces")
    if name and path.with_name(name).is_file():
        cols = _columns(path.with_name(name))
        keys = np.array(cols["slip"])
        t, x = np.array(cols["time"], float), np.array(cols["x"], float)
        traces = {k: (t[keys == k], x[keys == k]) for k in dict.fromkeys(cols["slip"])}
    slips = {k: SlipTrace(_nan(s.get("slip_time")), _nan(s.get("slip_distance")),
                          *traces.get(k, (None, None)))
             for k, s in (doc.get("slips") or {}).items()}
    return SFBDocument(rows=doc.get("rows", []), notes=tuple(doc.get("notes", ())), slips=slips,
                       calibration=doc.get("calibration"), doc=doc)
