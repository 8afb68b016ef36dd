"""A row of the SFB comparison table: one model number beside Klein's.

Example
-------
>>> row = table_row("slip_time", 0.025, 0.02, "s", "sfb-parameters", uncertainty=(0.03, 0.01))
>>> round(row["ratio"], 12), row["uncertainty"]
(0.8, [0.01, 0.03])
>>> tuple(row) == ROW_KEYS
True
"""
from __future__ import annotations

import math

__all__ = ["ROW_KEYS", "SOURCES", "table_row", "find_row", "spans_decade", "without_unfixed_ratio"]

#: Keys of every table row (``note`` and ``uncertainty`` are extras to the issue's six;
#: ``klein_source`` says whether Klein's number is ``printed`` (computed from numbers he
#: printed) or ``derived`` (it needs one he did not), ``klein_range`` the range a derived
#: one takes over what its unprinted inputs allow; both None where not assessed).
ROW_KEYS = ("name", "klein", "model", "ratio", "units", "source", "uncertainty", "note",
            "klein_source", "klein_range")

#: The values of a row's ``source``.
SOURCES = ("sfb-parameters", "md-calibrated", "similarity")


def _finite_or_none(v):
    if v is None:
        return None
    v = float(v)
    return v if math.isfinite(v) else None


def table_row(name, klein, model, units_, source, note="", uncertainty=None,
              klein_source=None, klein_range=None) -> dict:
    """One row (keys :data:`ROW_KEYS`): non-finite numbers become ``None``, the ratio is
    model/Klein when both exist, the uncertainty and Klein's range a sorted
    [low, high] or ``None``."""
    klein, model = _finite_or_none(klein), _finite_or_none(model)
    ratio = model / klein if (klein not in (None, 0.0) and model is not None) else None
    if klein_source not in (None, "printed", "derived"):
        raise ValueError(f"klein_source = {klein_source!r}: 'printed', 'derived' or None")
    return {"name": name, "klein": klein, "model": model, "ratio": ratio, "units": units_,
            "source": source, "uncertainty": _interval(uncertainty), "note": note,
            "klein_source": klein_source, "klein_range": _interval(klein_range)}


def _interval(pair):
    if pair is None:
        return None
    lo, hi = (_finite_or_none(u) for u in pair)
    return None if lo is None or hi is None else [min(lo, hi), max(lo, hi)]


def find_row(rows, name: str, source: str = "sfb-parameters") -> dict:
    """The row called ``name`` from ``source`` (KeyError if there is none)."""
    for r in rows:
        if r["name"] == name and r["source"] == source:
            return r
    raise KeyError(f"no row {name!r} with source {source!r}")


def spans_decade(low: float, high: float) -> bool:
    """Whether the interval [low, high] of a positive quantity fails to fix it: not
    finite, reaching zero, or wider than a factor of 10.

    >>> spans_decade(1.0, 5.0), spans_decade(0.5, 6.0), spans_decade(-1.0, 2.0)
    (False, True, True)
    """
    if not (math.isfinite(low) and math.isfinite(high)):
        return True
    return low <= 0 or high / low > 10


def without_unfixed_ratio(row: dict) -> dict:
    """The row without a ratio when its model value is not positive or its interval
    :func:`spans_decade`, its note saying why; else the row as it is."""
    unc, model = row.get("uncertainty"), row.get("model")
    why = None
    if model is not None and model <= 0:
        why = "the model's value is not positive: no ratio"
    elif unc is not None and model is not None and spans_decade(*unc):
        why = "the model's interval reaches zero or spans more than a decade: no ratio"
    if why is None:
        return row
    return dict(row, ratio=None, note=(row["note"] + "; " if row["note"] else "") + why)
