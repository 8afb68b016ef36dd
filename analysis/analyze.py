"""The ``analysis.json`` document: every analysis that the inputs allow.

:func:`analyze` finds the slips, tabulates them and decides the regime
(:func:`context`) on a :class:`~filmfriction.analysis.files.trace.Trace`, then runs
every registered observable (:mod:`filmfriction.analysis.observables`, one file
each: the slips, the energy, the sliding state, the viscosity, the structure,
the slip law ...; :func:`run_observable`) in their order, and returns a
JSON-ready dict; an output whose input is missing is listed under ``skipped``
with the reason instead.  :func:`write_outputs` writes the document and the
per-cycle CSV atomically.  The schema is documented in docs/analysis.md
("Schema").
"""
from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from filmfriction.md_inputs.contract import ANALYSIS_FILE

from filmfriction.reduced_model.cycles import cycle_table

from . import observables, stickslip
from .extrema import refine_extrema
from .film_state import lasting_gap_change
from .files.cycles_csv import write_cycles_csv
from .observables.observable import Context, Observable
from .results import AnalysisResult, trace_from_columns
from .sliding import last_half, not_sliding, sliding_state
from .stickslip import Regime
from .files.trace import MissingInput, Trace, unit
from .files.util import finite_or_none as _num, json_safe, write_atomic

SCHEMA = "filmfriction.analysis/1"

#: Fewest trace rows the analysis classifies: below this a trace cannot show one
#: stick and one slip, and any verdict would be a guess (``unresolved``).
MIN_ROWS = 10

REGIME_CRITERION = (
    f"smooth: < 2 slips; stick-slip: >= 2 slips with CV(Fs) and CV(period) "
    f"<= {stickslip.REGIME_CV_MAX} (first slip excluded when >= 3); "
    "irregular: otherwise; unresolved: < 2 slips and the last half not steady sliding "
    "(stuck, or a slip in the last half: too short to tell)")


def _source(trace: Trace) -> dict:
    p = trace.parameters
    source = {"path": str(trace.path),
              "run_dir": str(trace.run_dir) if trace.run_dir else None,
              "samples": len(trace),
              "parameters": {k: getattr(p, k) for k in
                             ("spring_constant", "mass", "area", "thickness", "drive_velocity")},
              "notes": list(trace.notes)}
    if trace.layout is not None and trace.run_dir is None:
        # how the file was read, so that it is read again the same way
        source.update(trace.layout.source())
    elif trace.layout is not None and trace.layout.dropped:
        source["dropped_rows"] = dict(trace.layout.dropped)
    if trace.run:
        source["run_status"] = trace.run.get("status")
    return source


def _provenance(trace: Trace) -> dict:
    """The document's provenance: the package and the trace's (and run record's) SHA-256."""
    from filmfriction.md_inputs.contract import RUN_FILE

    from .files.provenance import provenance

    inputs = {"trace": trace.path}
    if trace.run_dir is not None:
        inputs["run.json"] = Path(trace.run_dir) / RUN_FILE
    return provenance(inputs)


def slip_table(time, spring_force, *, spring_constant=None, drive_velocity=None,
               wall_position=None, **detection):
    """The slips of a trace as the analysis tabulates them: (events, table).

    Detected by :func:`~filmfriction.analysis.stickslip.detect_slips` (``detection``: its
    keywords; the loading rate K·V where both are known), tabulated with ``wall_position``
    and their extrema refined (:func:`~filmfriction.analysis.extrema.refine_extrema`)."""
    k, v = spring_constant, drive_velocity
    detection.setdefault("loading_rate", k * v if k and v else None)
    events = stickslip.detect_slips(time, spring_force, **detection)
    table = cycle_table(time, spring_force, events.yield_index, events.stick_index,
                        spring_constant=k, wall_position=wall_position)
    table = refine_extrema(time, spring_force, table, noise=events.noise, lag=events.lag,
                           spring_constant=k, drive_velocity=v, wall_position=wall_position)
    return events, table


def context(trace: Trace, *, skip: int | None = None, structure: bool = True) -> Context:
    """What every section starts from: the slips detected and tabulated, the
    regime (with the sliding check of the last half), the start-up slips left out.

    The trace must have at least :data:`MIN_ROWS` rows (:func:`analyze` says
    ``unresolved`` for a shorter one)."""
    t = trace.time
    v_drive, _ = trace.drive_velocity()
    events, table = slip_table(t, trace.spring_force,
                               spring_constant=trace.parameters.spring_constant,
                               drive_velocity=v_drive, wall_position=trace.wall_position())
    regime = stickslip.classify_regime(table)
    if skip is None:
        skip = 1 if len(table) >= 3 else 0
    half = last_half(trace)
    state = sliding_state(trace, half)
    # fewer than 2 slips is smooth sliding only if the wall slides: a wall stuck
    # (V -> 0, a soft spring) or a run too short for a second yield has as few
    why = not_sliding(state) if regime == Regime.SMOOTH else None
    if regime == Regime.SMOOTH and not why:
        # a start-up yield is followed by sliding; one late in the trace (or one
        # still under way at its end) is not
        late = list(events.yield_index)
        if events.unfinished_yield is not None:
            late.append(events.unfinished_yield)
        if late and t[max(late)] > t[half.start]:
            why = "its slip comes in the last half: too short to tell"
    note = None
    if why:
        regime, note = Regime.UNRESOLVED, f"fewer than 2 slips, but {why}"
    return Context(trace=trace, all_slips=table, skip=skip, events=events, regime=regime,
                   regime_note=note, last_half=half, sliding=state,
                   trajectory_analyses=structure)


def until_state_change(trace: Trace) -> tuple[Trace, dict | None]:
    """The trace up to the film's lasting change of state (a run's ``gap`` column beyond
    half a layer to its end: :mod:`filmfriction.analysis.film_state`), and the change as
    ``analysis.json`` records it (None: no change, or no gap column or film layers)."""
    n = trace.scene_parameter("film_layers")
    if not (trace.has("gap") and isinstance(n, int) and n >= 1):
        return trace, None
    change = lasting_gap_change(trace.time, trace.columns["gap"], n)
    if change is None:
        return trace, None
    note = change.note(unit(trace.units, "time"))
    return trace.head(change.index, note), {**change.to_dict(), "samples_before": len(trace),
                                            "note": note}


def as_analysed(trace: Trace, doc: dict) -> Trace:
    """The part of ``trace`` its ``analysis.json`` ``doc`` covers: the samples before a
    recorded ``film_state_change`` (the whole trace without one), so that what reads the
    analysis with the trace (the calibration, its replay) reads the same samples."""
    change = doc.get("film_state_change") or {}
    if not change:
        return trace
    index, before = change.get("index"), change.get("samples_before")
    if not (isinstance(index, int) and before == len(trace) and 0 < index < len(trace)):
        raise ValueError(f"{trace.path}: the analysis was cut at sample {index} of {before}, "
                         f"the trace now has {len(trace)} samples; analyse it again "
                         f"(filmfriction analyze)")
    return trace.head(index)


def analyze(trace, *, skip: int | None = None, structure: bool = True,
            units: str | None = None, whole_trace: bool = False,
            **parameters) -> AnalysisResult:
    """Analyse a trace: the detection and the regime (:func:`context`), then
    every observable (:mod:`filmfriction.analysis.observables`) in its order.

    Parameters
    ----------
    trace : Trace, dict of arrays or pandas DataFrame
        A trace read from a file, or its columns in memory named as the analysis
        names them (``time``, ``spring_force``, ``drive_position`` ...).
    skip : int, optional
        Slips left out of the summaries (default: 1, the start-up yield, when
        3 or more slips are found, else 0).
    structure : bool
        Run the trajectory analyses when the run has a trajectory.
    whole_trace : bool
        Analyse every sample even after the film changed state (by default a run's
        trace is analysed up to a lasting change of its gap by half a layer,
        :func:`until_state_change`, recorded as ``film_state_change``).
    units, **parameters
        For columns in memory only: their unit system (``"lj"``, the default, or
        ``"si"``) and the trace's parameters (``spring_constant``, ``mass``,
        ``area``, ``thickness``, ``drive_velocity``, ``mount_damping``).

    Returns
    -------
    AnalysisResult
        ``.document`` (the ``analysis.json`` content, also ``.to_dict()``; its
        sections as attributes), ``.per_cycle`` (per-cycle columns, also
        ``.slips_table()``), ``.plot_trace()``, ``.plot_slips()``; it unpacks as
        ``document, per_cycle``.

    Examples
    --------
    >>> from filmfriction.analysis.groundtruth.synthetic import klein_trace
    >>> r = analyze(klein_trace(), units="si", spring_constant=97.0, mass=1.47e-3,
    ...             drive_velocity=1e-7)
    >>> r.status, r.slips["count"]
    ('stick-slip', 4)

    A trace of fewer than :data:`MIN_ROWS` rows is ``unresolved``: its
    ``regime_note`` says why, and every section is in ``skipped`` with that reason.
    """
    if not isinstance(trace, Trace):
        trace = trace_from_columns(trace, units=units or "lj", **parameters)
    elif units is not None or parameters:
        raise TypeError("units and parameters go with columns in memory; a Trace has its own")
    change = None
    if not whole_trace:
        trace, change = until_state_change(trace)
    doc: dict = {"schema": SCHEMA, "units": trace.units, "source": _source(trace),
                 "provenance": _provenance(trace)}
    if change is not None:
        doc["film_state_change"] = change
    skipped: dict[str, str] = {}
    if len(trace) < MIN_ROWS:
        n = len(trace)
        why = (f"{n} data row{'' if n == 1 else 's'}: too short to classify (a stick and a "
               f"slip need at least {MIN_ROWS})")
        doc.update(regime=Regime.UNRESOLVED, regime_criterion=REGIME_CRITERION, regime_note=why)
        skipped["detection"] = why
        none = cycle_table(trace.time, trace.spring_force, [], [])
        ctx = Context(trace=trace, all_slips=none, skip=0, events=None, regime=Regime.UNRESOLVED,
                      regime_note=why, trajectory_analyses=structure)
        for obs in observables.registered():
            if obs.applies(ctx):
                skipped[obs.key] = why
        doc["skipped"] = skipped
        return AnalysisResult(doc, {}, trace)
    ctx = context(trace, skip=skip, structure=structure)
    ctx = replace(ctx, sections=doc, skipped=skipped)
    t, events = trace.time, ctx.events
    lab = lambda q: unit(trace.units, q)  # noqa: E731
    doc["regime"] = ctx.regime
    doc["regime_criterion"] = REGIME_CRITERION
    if ctx.regime_note:
        doc["regime_note"] = ctx.regime_note
    doc["detection"] = {
        "noise": {"mean": _num(events.noise), "units": lab("force")},
        "threshold": {"mean": _num(events.threshold), "units": lab("force")},
        "unfinished_yield_time": (_num(t[events.unfinished_yield])
                                  if events.unfinished_yield is not None else None),
        # slips the hysteresis scan merged, split where the wall stopped inside them
        "inner_resticks": int(events.inner_resticks)}
    per_cycle: dict = {}
    for obs in observables.registered():
        if not obs.applies(ctx):
            continue
        try:
            section, columns = run_observable(obs, ctx)
        except MissingInput as exc:
            skipped[obs.key] = str(exc)
            continue
        if section is not None:
            doc[obs.key] = section
        pad = [math.nan] * ctx.skip if obs.per_slip == "analysed" else []
        for name, values in columns.items():
            column = obs.column_name(name)
            if column in per_cycle:
                raise ValueError(f"observable {obs.key!r}: per-slip column {column!r} is "
                                 "already written by another observable")
            per_cycle[column] = pad + values
    doc["skipped"] = skipped
    return AnalysisResult(doc, per_cycle, trace)


def run_observable(obs: Observable, ctx: Context) -> tuple[dict, dict]:
    """``obs``'s section (made JSON-safe) and per-slip columns (as lists) on ``ctx``.

    Raises
    ------
    MissingInput
        One of ``obs.needs`` is absent (the first, in their order), or ``compute``
        found an input missing.
    TypeError, ValueError
        ``compute`` broke its contract: a section that is not a dict or not JSON
        data, a per-slip column without one value per analysed slip.
    """
    for need in obs.needs:
        missing = need.missing(ctx.trace)
        if missing is not None:
            raise missing
    section, columns = obs.compute(ctx)
    who = f"observable {obs.key!r} ({type(obs).__module__}.{type(obs).__qualname__})"
    if section is not None:
        if not isinstance(section, dict):
            raise TypeError(f"{who}: compute() gave a {type(section).__name__} section, "
                            "not a dict")
        section = json_safe(section)
        try:
            json.dumps(section, allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise TypeError(f"{who}: its section is not JSON data: {exc}") from None
    rows = len(ctx.table) if obs.per_slip == "analysed" else len(ctx.all_slips)
    out = {}
    for name, values in (columns or {}).items():
        values = np.asarray(values).ravel()
        # whole numbers (the slips' sample indices) stay whole in the CSV
        values = (values.tolist() if values.dtype.kind in "iub"
                  else [float(v) for v in values.astype(float)])
        if len(values) != rows:
            raise ValueError(f"{who}: per-slip column {name!r} has {len(values)} values for "
                             f"{rows} {obs.per_slip} slips")
        out[name] = values
    return section, out


def to_json(doc: dict) -> str:
    """Strict JSON (NaN → null)."""
    return json.dumps(json_safe(doc), indent=2, ensure_ascii=False, allow_nan=False)



def write_outputs(doc: dict, per_cycle: dict, json_path: Path) -> tuple[Path, Path]:
    """Write ``analysis.json`` and ``analysis_cycles.csv`` atomically."""
    json_path = Path(json_path)
    csv_path = json_path.with_name(json_path.stem + "_cycles.csv")
    doc = dict(doc)
    doc["cycles_csv"] = csv_path.name
    write_cycles_csv(per_cycle, csv_path)
    write_atomic(json_path, to_json(doc) + "\n")
    return json_path, csv_path


def analyse_run(run_dir) -> dict:
    """Analyse the trace of ``run_dir`` and write its ``analysis.json`` (and
    ``analysis_cycles.csv``) there; returns the document."""
    from .files.trace_reader import read_trace

    run_dir = Path(run_dir)
    doc, per_cycle = analyze(read_trace(run_dir))
    write_outputs(doc, per_cycle, run_dir / ANALYSIS_FILE)
    return doc
