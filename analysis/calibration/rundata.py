"""One run directory as the calibration reads it: trace, ``analysis.json`` and the per-slip table.

Example
-------
>>> import tempfile, pathlib
>>> from filmfriction.analysis.groundtruth.synthetic import run_directory
>>> run = load_run(run_directory(pathlib.Path(tempfile.mkdtemp()) / "run", trajectory=False))
>>> run.analysis["regime"] == "stick-slip", run.n_slips, run.skip
(True, 4, 1)
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from filmfriction.md_inputs.contract import ANALYSIS_FILE

__all__ = ["RunData", "load_run"]


@dataclass(frozen=True, eq=False)
class RunData:
    """One run directory's trace, analysis and per-cycle table.

    Attributes
    ----------
    run_dir : Path
    trace : analysis.files.trace.Trace
    analysis : dict
        ``analysis.json`` content.
    cycles : dict of str -> ndarray
        Per-cycle columns (``yield_index``, ``stick_index``, ``static_force`` …).
    skip : int
        Slips left out of the summaries (the analysis's choice).
    """

    run_dir: Path
    trace: object
    analysis: dict
    cycles: dict
    skip: int

    @property
    def n_slips(self) -> int:
        return int(len(self.cycles.get("yield_index", ())))

    @property
    def thickness(self) -> float:
        tr = self.trace
        if tr.has("gap"):
            return float(np.mean(tr.columns["gap"]))
        return float(tr.parameters.require("thickness", "eta_eff = B D / A"))


def _analysed_parameters(doc: dict) -> dict:
    """The unit system and the parameters an analysis used (``analysis.json``'s
    ``units`` and ``source.parameters``), as :func:`read_trace` overrides: a
    measured trace analysed with ``--units si --spring-constant ...`` is read as
    such again."""
    used = {k: v for k, v in ((doc.get("source") or {}).get("parameters") or {}).items()
            if v is not None}
    if doc.get("units") in ("lj", "si"):
        used["units"] = doc["units"]
    return used


def load_run(run_dir, *, analyse: bool = True) -> RunData:
    """Read a run directory; run the analysis (and write it) if ``analysis.json`` is missing.

    Parameters
    ----------
    run_dir : path-like
    analyse : bool
        With False a missing analysis is an error instead (for readers that
        must not compute, such as the report).

    Raises
    ------
    ValueError
        No run directory, no trace, an unreadable analysis or one of another schema, or
        (``analyse=False``) no analysis.
    """
    from filmfriction.analysis.files.cycles_csv import read_cycles_csv
    from filmfriction.analysis.analyze import SCHEMA as ANALYSIS_SCHEMA
    from filmfriction.analysis.analyze import analyze, as_analysed, write_outputs
    from filmfriction.analysis.files.trace_reader import read_trace

    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise ValueError(f"{run_dir}: not a run directory")
    apath = run_dir / ANALYSIS_FILE
    cpath = run_dir / "analysis_cycles.csv"
    if apath.exists() and cpath.exists():
        from filmfriction.analysis.files.documents import read_document

        doc = read_document(apath, "analysis")
        if doc.get("schema") not in (None, ANALYSIS_SCHEMA):
            raise ValueError(f"{apath}: schema {doc['schema']!r}, not an analysis of this "
                             f"version ({ANALYSIS_SCHEMA!r}); analyse it again "
                             f"(filmfriction analyze {run_dir})")
        cycles = read_cycles_csv(cpath)
        # read once, as analysed (not with the run's parameters, then again)
        trace = read_trace(run_dir, **_analysed_parameters(doc))
    elif not analyse:
        missing = " and ".join(p.name for p in (apath, cpath) if not p.exists())
        raise ValueError(f"{run_dir}: no {missing}; make it with `filmfriction analyze {run_dir}`")
    else:
        trace = read_trace(run_dir)
        doc, per_cycle = analyze(trace)
        try:
            write_outputs(doc, per_cycle, apath)
        except OSError:
            pass  # read-only run directory: the analysis stays in memory
        cycles = {k: np.asarray(v, dtype=float) for k, v in per_cycle.items()
                  if not isinstance(v, str)}
    trace = as_analysed(trace, doc)          # a film that changed state: the analysed part
    for key in ("yield_index", "stick_index"):
        cycles[key] = np.asarray(cycles.get(key, []), dtype=float).astype(int)
    skip = int(doc.get("slips", {}).get("summary_skips_first", 0) or 0)
    return RunData(run_dir, trace, doc, cycles, skip)
