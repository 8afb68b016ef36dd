"""The per-slip CSV (``analysis_cycles.csv``): one writer and one reader.

A header line of column names, then one row per slip; an empty cell is a value
that does not exist (NaN, e.g. the period of the last slip).

Example
-------
>>> import math
>>> text = cycles_csv_text({"static_force": [1.0, 2.0], "period": [3.0, math.nan]})
>>> text.splitlines()
['static_force,period', '1.0,3.0', '2.0,']
>>> cols = parse_cycles_csv(text)
>>> cols["period"].tolist()[0], math.isnan(cols["period"][1])
(3.0, True)
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .util import write_atomic

__all__ = ["cycles_csv_text", "write_cycles_csv", "parse_cycles_csv", "read_cycles_csv"]


def _cell(v) -> str:
    if v is None:
        return ""
    if hasattr(v, "item"):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return ""
    return repr(v)


def cycles_csv_text(columns: dict) -> str:
    """The CSV text of ``{name: per-slip values}`` (columns of equal length)."""
    names = list(columns)
    rows = [",".join(names)]
    for row in zip(*(columns[n] for n in names)):
        rows.append(",".join(_cell(v) for v in row))
    return "\n".join(rows) + "\n"


def write_cycles_csv(columns: dict, path) -> Path:
    """Write :func:`cycles_csv_text` of ``columns`` to ``path`` atomically."""
    path = Path(path)
    write_atomic(path, cycles_csv_text(columns))
    return path


def parse_cycles_csv(text: str) -> dict:
    """``{name: float array}`` from the CSV text; an empty or non-numeric cell is NaN."""
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines:
        return {}
    names = lines[0].split(",")
    cols = {n: [] for n in names}
    for ln in lines[1:]:
        for n, cell in zip(names, ln.split(",")):
            try:
                cols[n].append(float(cell) if cell else math.nan)
            except ValueError:
                cols[n].append(math.nan)
    return {n: np.asarray(v, dtype=float) for n, v in cols.items()}


def read_cycles_csv(path) -> dict:
    """:func:`parse_cycles_csv` of the file at ``path``."""
    return parse_cycles_csv(Path(path).read_text(encoding="utf-8"))
