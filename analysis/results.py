"""What :func:`filmfriction.analysis.analyze` returns: the analysis as an object for
scripts and notebooks.

Like MDAnalysis' ``Results``, every section of ``analysis.json`` is an attribute
(``result.slips``, ``result.energy``, ``result.regime`` ...); ``to_dict()`` is the
document ``analysis.json`` holds, ``slips_table()`` the per-slip table (a pandas
DataFrame when pandas is installed), and ``plot_trace()`` / ``plot_slips()`` draw
its figures.  Like the results of ``scipy.stats``, it unpacks as a pair,
``document, per_cycle = analyze(trace)``.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from .files.trace import Trace

__all__ = ["AnalysisResult"]


@dataclass(frozen=True)
class AnalysisResult:
    """The analysis of one trace.

    Attributes
    ----------
    document : dict
        The ``analysis.json`` content.
    per_cycle : dict
        Per-slip columns (``analysis_cycles.csv``), one value per detected slip.
    trace : Trace
        The trace analysed.

    Every top-level entry of ``document`` is also an attribute: ``result.regime``,
    ``result.slips``, ``result.skipped`` ...; ``status`` is the regime and
    ``message`` says what was found (as scipy's results say theirs).
    """

    document: dict
    per_cycle: dict
    trace: Trace

    def __iter__(self):
        return iter((self.document, self.per_cycle))

    def __getattr__(self, name: str):
        if name.startswith("_") or name in ("document", "per_cycle", "trace"):
            raise AttributeError(name)
        try:
            return self.document[name]
        except KeyError:
            raise AttributeError(f"the analysis has no section {name!r} (it has: "
                                 f"{', '.join(self.document)})") from None

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self.document))

    @property
    def status(self) -> str:
        """The regime: ``stick-slip``, ``smooth``, ``irregular`` or ``unresolved``."""
        regime = self.document.get("regime", "unresolved")
        return str(getattr(regime, "value", regime))

    @property
    def message(self) -> str:
        """One line: the regime, the slips found, the static force."""
        s = self.document.get("slips") or {}
        fs = s.get("static_force") or {}
        text = f"{self.status}, {s.get('count', 0)} slips"
        if fs.get("mean") is not None:
            text += f", static force {fs['mean']:.4g}"
            if fs.get("stderr") is not None:
                text += f" ± {fs['stderr']:.2g}"
            text += f" {fs.get('units', '')}".rstrip()
        if self.document.get("regime_note"):
            text += f" ({self.document['regime_note']})"
        return text

    def __repr__(self) -> str:
        return f"<AnalysisResult: {self.message}>"

    def to_dict(self) -> dict:
        """The ``analysis.json`` document (a deep copy)."""
        return copy.deepcopy(self.document)

    def slips_table(self):
        """The per-slip table: a pandas DataFrame (one row per detected slip) when pandas
        is installed, else a dict of NumPy arrays."""
        cols = {k: np.asarray(v) for k, v in self.per_cycle.items() if not isinstance(v, str)}
        try:
            import pandas as pd
        except ImportError:
            return cols
        return pd.DataFrame(cols)

    def _indices(self):
        y = np.asarray(self.per_cycle.get("yield_index", []), float).astype(int)
        s = np.asarray(self.per_cycle.get("stick_index", []), float).astype(int)
        return y, s

    def plot_trace(self):
        """The spring force over time with each slip's y and s marked (the figure
        ``filmfriction analyze`` writes); returns the matplotlib Figure."""
        from .trace_figure import trace_figure

        y, s = self._indices()
        return trace_figure(self.trace, y, s)

    def plot_slips(self, ax=None):
        """Static force and slip distance of each slip against its number, the start-up
        slips left out of the means marked; returns the matplotlib Axes (two, twinned)."""
        from .trace_figure import scaled_unit
        from .files.util import pyplot

        if ax is None:
            _, ax = pyplot().subplots(figsize=(6, 3.2))
        units = self.document.get("units", self.trace.units)
        fs = np.asarray(self.per_cycle.get("static_force", []), float)
        dx = np.asarray(self.per_cycle.get("slip_distance", []), float)
        n = np.arange(1, fs.size + 1)
        skip = int((self.document.get("slips") or {}).get("summary_skips_first", 0) or 0)
        ff, lf = scaled_unit(fs, units, "force")
        fx, lx = scaled_unit(dx, units, "length")
        ax.plot(n, fs * ff, "o-", color="tab:blue", label="static force F_s")
        if skip:
            ax.plot(n[:skip], fs[:skip] * ff, "o", mfc="white", color="tab:blue",
                    label="left out of the means")
        ax.set_xlabel("slip number [1]")
        ax.set_ylabel(f"F_s [{lf}]", color="tab:blue")
        twin = ax.twinx()
        twin.plot(n, dx * fx, "s--", color="tab:orange", label="slip distance Δx0")
        twin.set_ylabel(f"Δx0 [{lx}]", color="tab:orange")
        ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), fontsize=8, ncol=2,
                  frameon=False)
        return ax, twin


def trace_from_columns(data, *, units: str = "lj", **parameters) -> Trace:
    """A :class:`Trace` of columns in memory: ``data`` maps the analysis' column names
    (``time``, ``spring_force``, ``drive_position``, ``wall_velocity`` ...) to arrays
    (a dict, or a pandas DataFrame); ``parameters`` are those of
    :class:`~filmfriction.analysis.files.trace.TraceParameters` (``spring_constant``,
    ``mass``, ``area``, ``thickness``, ``drive_velocity``, ``mount_damping``), in
    ``units`` (``"lj"`` or ``"si"``).

    Raises
    ------
    ValueError
        A column the analysis does not know, a missing ``time`` or ``spring_force``,
        columns of different lengths, or a parameter that is not a positive number.
    TypeError
        A parameter the analysis does not know.
    """
    from pathlib import Path

    from .files.trace import PARAMETERS, TraceParameters, trace_column_names

    names = list(data.keys())
    known = set(trace_column_names())
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ValueError(f"column(s) {', '.join(map(repr, unknown))} are not the analysis' "
                         f"(accepted: {', '.join(sorted(known))})")
    for need in ("time", "spring_force"):
        if need not in names:
            raise ValueError(f"no {need!r} column: the analysis needs time and spring_force")
    cols = {n: np.asarray(data[n], dtype=float).ravel() for n in names}
    lengths = {n: c.size for n, c in cols.items()}
    if len(set(lengths.values())) != 1:
        raise ValueError(f"columns of different lengths: {lengths}")
    bad = [k for k in parameters if k not in PARAMETERS]
    if bad:
        raise TypeError(f"unknown parameter(s) {', '.join(bad)} (accepted: "
                        f"{', '.join(PARAMETERS)})")
    return Trace(columns=cols, parameters=TraceParameters(units=units, **parameters),
                 path=Path("<arrays>"))
