"""Read a stick-slip trace: a run directory, a plain trace file, or an analysed one.

A plain trace file has a header line naming its columns (``time`` and
``spring_force`` required; ``drive_position``, ``wall_position``,
``wall_velocity``, ``gap`` and the MD ledger columns optional), separated by
commas, tabs, semicolons or whitespace (detected from the header,
:func:`detect_delimiter`).  A file with its own column names is read through a
mapping, analysis name → the file's name (:func:`map_columns`; ``filmfriction
analyze --column time=t_s``), a column in its own unit converted into the trace's unit
system (``column_units``, ``--column spring_force=F:uN``; the conversion is
:func:`filmfriction.reduced_model.units.column_factor`).  Comment lines (``#``, or the
``comments`` given) and the first ``skip_rows`` lines are skipped; when the first other
line is numbers, the header is the comment line before it (LAMMPS's ``fix print`` and
``fix ave/time`` files).  A LAMMPS log is read by its thermo runs
(:mod:`filmfriction.analysis.files.lammps_log`).  Rows with an empty, NaN or infinite cell in a
column the analysis reads are dropped and said, never interpolated.  The parameters a trace needs (spring constant, wall mass, contact
area, film thickness, drive velocity) and the unit system come from the
command line or, for a run directory, from ``run.json``'s ``trace_parameters``
(the command line wins).  A directory holding the ``analysis.json`` of a plain
trace file (and no ``trace.csv``) reads that file again with the mapping,
units and parameters the analysis recorded.

A run directory holds ``trace.csv`` (the columns of the MD script's contract,
:data:`filmfriction.md_inputs.contract.TRACE`, whose ``quantity`` names the
entry of :data:`UNITS` that labels it) and ``run.json``, and optionally
``profiles/density.profile``, ``profiles/velocity.profile`` (``fix
ave/chunk``) and ``trajectory.dcd`` + ``topology.data``.


The table of a text file is read by :mod:`~filmfriction.analysis.files.trace_table`, a
large one from its binary copy (:mod:`~filmfriction.analysis.files.trace_cache`); the
:class:`~filmfriction.analysis.files.trace.Trace` returned is
:mod:`~filmfriction.analysis.files.trace`'s.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from filmfriction.md_inputs.contract import ANALYSIS_FILE, RUN_FILE, SWEEP_FILE, TRACE_FILE

from .trace import (PARAMETERS, REQUIRED_COLUMNS, UNITS, Trace, TraceLayout, TraceParameters,
                    trace_column_names)
from .trace_cache import cache_digest, read_binary_copy
from .trace_table import COMMENTS, DELIMITER_NAMES, SKIP_HINT, head_bytes, read_header, \
    read_table, split_header

__all__ = ["read_trace", "read_csv_trace", "map_columns"]

def map_columns(names, mapping: dict | None, where="", aliases: dict | None = None) -> dict:
    """Check a column mapping (analysis name → the file's column name) against a header.

    ``aliases`` (the file's name → an analysis name, e.g. a LAMMPS log's thermo
    keywords, :data:`~filmfriction.analysis.files.lammps_log.LAMMPS_NAMES`) name the
    columns that the mapping leaves and the header does not name itself.

    Returns
    -------
    dict
        The file's column name → the name the analysis gives it (identity for
        columns not mapped).

    Raises
    ------
    ValueError
        A target that the analysis does not know, a source column not in the
        header (both list what exists), two sources for one name, or one source
        for two names.

    Examples
    --------
    >>> map_columns(["t_s", "F_N"], {"time": "t_s", "spring_force": "F_N"})
    {'t_s': 'time', 'F_N': 'spring_force'}
    >>> map_columns(["t_s"], {"tme": "t_s"})
    Traceback (most recent call last):
    ...
    ValueError: --column tme=t_s: unknown name 'tme'; the analysis reads time, step, drive_position, spring_force, wall_position, wall_velocity, wall_z, gap, film_temperature, drive_work, load_work, thermostat_heat, potential_energy, kinetic_energy, spring_energy, mount_heat
    """
    known = trace_column_names()
    where = f"{where}: " if where else ""
    renames = {n: n for n in names}
    mapping = mapping or {}
    for src, target in (aliases or {}).items():
        if (src in renames and target not in names and target not in mapping
                and src not in mapping.values()):
            renames[src] = target
    for target, src in mapping.items():
        if target not in known:
            raise ValueError(f"--column {target}={src}: unknown name {target!r}; the analysis "
                             f"reads {', '.join(known)}")
        if src not in names:
            lost = not any(s in names for s in mapping.values())
            raise ValueError(f"{where}--column {target}={src}: no column {src!r} in the header "
                             f"(columns: {', '.join(names)}"
                             + (f"; {SKIP_HINT})" if lost and len(mapping) > 1 else ")"))
        first = next((t for t, s in mapping.items() if s == src), target)
        if first != target:
            raise ValueError(f"{where}--column {first}={src} and --column {target}={src}: one "
                             f"column given for two names; each name reads a column of its own")
        renames[src] = target
    targets = list(renames.values())
    for target in set(targets):
        if targets.count(target) > 1:
            srcs = [s for s, t in renames.items() if t == target]
            raise ValueError(f"{where}columns {', '.join(srcs)} would all be called {target!r}; "
                             f"map one of them with --column {target}=NAME and rename the others")
    return renames


def _lines(numbers, most: int = 8) -> str:
    numbers = [int(n) for n in numbers]
    shown = ", ".join(str(n) for n in numbers[:most])
    return shown + (f", ... ({len(numbers) - most} more)" if len(numbers) > most else "")


def _drop_missing(cols: dict, numbers, notes: list) -> tuple[dict, object, dict]:
    """``cols`` (and their line ``numbers``) without the rows where a column the analysis
    reads is NaN, infinite or empty; what was dropped (``{"count", "lines" or "rows",
    "columns"}``) is noted."""
    known = [n for n in cols if n in trace_column_names()]
    bad_by = {n: ~np.isfinite(cols[n]) for n in known}
    bad = np.logical_or.reduce(list(bad_by.values())) if known else None
    if bad is None or not bad.any():
        return cols, numbers, {}
    idx = np.flatnonzero(bad)
    per_column = {n: int(b.sum()) for n, b in bad_by.items() if b.any()}
    dropped = {"count": int(idx.size), "columns": per_column}
    if numbers is not None:
        dropped["lines"] = [int(n) for n in np.asarray(numbers)[idx[:20]]]
        at = f"line{'s' if idx.size > 1 else ''} {_lines(np.asarray(numbers)[idx])}"
    else:
        dropped["rows"] = [int(i) + 1 for i in idx[:20]]
        at = f"data row{'s' if idx.size > 1 else ''} {_lines(idx + 1)}"
    notes.append(f"dropped {idx.size} row{'s' if idx.size > 1 else ''} with empty, NaN or "
                 f"infinite cells ({at}; " + ", ".join(f"{n} {k}" for n, k in per_column.items())
                 + "); not interpolated")
    keep = ~bad
    return ({n: np.ascontiguousarray(v[keep]) for n, v in cols.items()},
            None if numbers is None else np.asarray(numbers)[keep], dropped)


def _drop_repeated_steps(cols: dict, numbers, notes: list) -> tuple[dict, object]:
    """A LAMMPS run in segments prints a segment's first step twice (the last row of one,
    the first of the next): of rows with equal ``step``, the later is kept."""
    if "step" not in cols or cols["step"].size < 2:
        return cols, numbers
    step = cols["step"]
    later = np.append(step[1:] != step[:-1], True)
    if later.all():
        return cols, numbers
    n = int((~later).sum())
    notes.append(f"{n} row{'s' if n > 1 else ''} repeating the next row's step (a LAMMPS run's "
                 "segment boundary) dropped, the later kept")
    return ({k: np.ascontiguousarray(v[later]) for k, v in cols.items()},
            None if numbers is None else np.asarray(numbers)[later])


def _convert_units(cols: dict, column_units: dict, system: str, notes: list) -> dict:
    """Columns given in their own units, brought into the trace's unit system."""
    from filmfriction.md_inputs.contract import column as contract_column
    from filmfriction.reduced_model.units import OMCTS, column_factor

    out = dict(cols)
    for name, text in (column_units or {}).items():
        if name not in out:
            continue
        quantity = contract_column(name).quantity
        if quantity == "1":
            raise ValueError(f"--column {name}=...:{text}: {name} is a count, it has no unit")
        try:
            factor = column_factor(text, quantity, system, OMCTS)
        except ValueError as exc:
            raise ValueError(f"--column {name}=...:{text}: {exc}") from None
        target = UNITS[system][quantity]
        via = (" with the OMCTS mapping (filmfriction.reduced_model.units.OMCTS)"
               if _unit_system(text) != system else "")
        if factor != 1.0:
            out[name] = out[name] * factor
        notes.append(f"{name} read in {text}: x {factor:.6g} to {target}{via}")
    return out


def _unit_system(text: str) -> str:
    from filmfriction.reduced_model.units import parse_unit

    return parse_unit(text).system


def read_csv_trace(path, parameters: TraceParameters | None = None,
                   columns: dict | None = None, *, column_units: dict | None = None,
                   skip_rows: int = 0, comments=COMMENTS, log_run: str | None = None) -> Trace:
    """Read a plain trace file (comma-, tab-, semicolon- or whitespace-separated), a
    LAMMPS ``fix print`` / ``fix ave/time`` file (the header in the comment line before
    the data) or a LAMMPS log's thermo output.

    Parameters
    ----------
    path : path-like
    parameters : TraceParameters, optional
    columns : dict, optional
        Analysis name → the file's column name, e.g. ``{"time": "t_s",
        "spring_force": "F_N"}`` (:func:`map_columns`).
    column_units : dict, optional
        Analysis name → the unit its column is in (``{"spring_force": "uN", "time":
        "ms"}``): the column is converted into the trace's unit system
        (``parameters.units``) by :func:`filmfriction.reduced_model.units.column_factor`.
    skip_rows : int
        Lines skipped at the top before the header is looked for (an instrument's
        metadata).
    comments : tuple of str
        What starts a comment line (skipped before the header and among the rows).
    log_run : str, optional
        The thermo run(s) of a LAMMPS log to read: ``N``, ``N-M``, ``N-``
        (:func:`filmfriction.analysis.files.lammps_log.read_log_table`); a log is
        recognised by its first line, ``LAMMPS (...)``.

    Rows where a column the analysis reads is empty, NaN or infinite are dropped
    (never interpolated), as are rows repeating the next row's ``step``; the trace's
    ``notes`` and ``layout.dropped`` say which.

    Raises
    ------
    ValueError
        Unreadable file, a bad mapping or unit, missing ``time``/``spring_force``,
        non-increasing time.
    """
    from .lammps_log import LAMMPS_NAMES, is_lammps_log, read_log_table

    path = Path(path)
    params = parameters or TraceParameters()
    comments = tuple(comments) or COMMENTS
    column_units = dict(column_units or {})
    numbers, from_binary, dropped, digest = None, False, {}, None
    if log_run is not None or is_lammps_log(path):
        if skip_rows:
            raise ValueError(f"--skip-rows {skip_rows}: {path} is a LAMMPS log, read by its "
                             "thermo blocks (choose them with --log-run); leave --skip-rows out")

        def usable(keys):
            try:
                names = map_columns(keys, {k: v for k, v in (columns or {}).items()
                                           if v in keys}, aliases=LAMMPS_NAMES).values()
            except ValueError:
                return False
            return all(r in names for r in REQUIRED_COLUMNS)

        names, data, notes, dropped = read_log_table(path, log_run, usable)
        renames = map_columns(names, columns, str(path), aliases=LAMMPS_NAMES)
        cols = {n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)}
        delimiter, kind = "whitespace", "lammps-log"
    else:
        raw_head = path.read_bytes() if skip_rows else head_bytes(path)
        start, header, sep = read_header(raw_head, path, skip_rows, comments)
        renames = map_columns(split_header(header, sep), columns, str(path))
        digest = cache_digest(path)
        cols = read_binary_copy(path, list(renames), digest)
        notes, from_binary = [], cols is not None
        if cols is None:
            names, data, numbers, notes, sep = read_table(path, skip_rows, comments)
            cols = {n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)}
        delimiter, kind = DELIMITER_NAMES[sep], "table"
    cols = {renames[n]: v for n, v in cols.items()}
    for req in REQUIRED_COLUMNS:
        if req not in cols:
            what = "thermo keywords" if kind == "lammps-log" else "header"
            raise ValueError(f"{path}: required column '{req}' missing ({what}: "
                             f"{', '.join(renames)}); name it with --column {req}=NAME")
    for name in column_units:
        if name not in cols:
            raise ValueError(f"--column {name}=...:{column_units[name]}: {path} has no column "
                             f"read as {name}")
    notes = list(notes)
    cols, numbers, more = _drop_missing(cols, numbers, notes)
    dropped = _merge_dropped(dropped, more)
    cols, numbers = _drop_repeated_steps(cols, numbers, notes)
    cols = _convert_units(cols, column_units, params.units, notes)
    t = cols["time"]
    if t.size == 0:
        raise ValueError(f"{path}: no data rows left once the rows with missing values are "
                         "dropped")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0])
        at = (f"line {numbers[i + 1]}" if numbers is not None else
              f"row {i + 2}" + (f" (step {cols['step'][i + 1]:g})" if "step" in cols else ""))
        raise ValueError(f"{path}: time not increasing at {at} ({t[i]:g} then {t[i + 1]:g})")
    mapped = {renames[s]: s for s in renames if renames[s] != s}
    layout = TraceLayout(delimiter, mapped, from_binary, kind=kind, column_units=column_units,
                         skip_rows=skip_rows, comments=comments, log_run=log_run,
                         dropped=dropped, content_sha256=digest)
    return Trace(cols, params, path, notes=tuple(notes), layout=layout)


def _merge_dropped(a: dict, b: dict) -> dict:
    if not a:
        return b
    if not b:
        return a
    out = dict(b)
    out["count"] = a["count"] + b["count"]
    out["lines"] = (a.get("lines", []) + b.get("lines", []))[:20]
    return out


def _analysed_trace_file(directory: Path) -> tuple[Path, dict] | None:
    """The plain trace file an ``analysis.json`` in ``directory`` was made from, and
    that document, when the directory holds no ``trace.csv`` (a measured trace)."""
    doc_path = directory / ANALYSIS_FILE
    if not doc_path.is_file():
        return None
    from .documents import read_document

    doc = read_document(doc_path, "analysis")
    source = doc.get("source") or {}
    if source.get("run_dir") or not source.get("path"):
        return None
    given = Path(source["path"])          # relative to the directory (older: to the cwd)
    for candidate in (directory / given.name, directory / given, given):
        if candidate.is_file():
            return candidate, doc
    raise ValueError(f"{doc_path}: the trace it was made from, {given}, is not there "
                     f"(nor in {directory})")


def _run_record(directory: Path) -> dict:
    """``run.json`` of a run directory (empty when there is none)."""
    if not (directory / RUN_FILE).exists():
        return {}
    from .documents import read_document

    return read_document(directory / RUN_FILE, "run")


def _run_parameters(run: dict) -> dict:
    given = dict(run.get("trace_parameters") or {})
    base = {k: given.get(k) for k in PARAMETERS}
    base["units"] = given.get("units", "lj")
    film = (run.get("atoms") or {}).get("film")
    if base["film_mass"] is None and base["units"] == "lj" and isinstance(film, int) and film > 0:
        # a run recorded before its trace parameters carried the film's mass: its film
        # atoms, 1 m each (the LJ unit of mass is a film atom's)
        base["film_mass"] = float(film)
    scene = (run.get("scene") or {}).get("parameters") or {}
    if ("registry_period" not in given and base["units"] == "lj"
            and scene.get("top_wall_twist", "aligned") == "aligned"
            and isinstance(scene.get("wall_spacing"), (int, float))):
        # a run recorded before its trace parameters carried the registry's period: its
        # walls' spacing, the period of aligned walls along the slide
        base["registry_period"] = float(scene["wall_spacing"])
    return base


def read_trace(path, *, columns: dict | None = None, column_units: dict | None = None,
               skip_rows: int | None = None, comments=None, log_run: str | None = None,
               **overrides) -> Trace:
    """Read a run directory, a trace file, or the directory of an analysed trace.

    Parameters
    ----------
    path : path-like
        A run directory (with ``trace.csv`` and ``run.json``), a trace file (a text
        table, a LAMMPS ``fix print``/``fix ave/time`` file or log), or a directory
        with the ``analysis.json`` of a trace file (``filmfriction analyze`` records
        the file, how it was read, its units and parameters there).  A file beside a
        ``run.json`` (a run's ``trace.dat`` or LAMMPS log) is read with that run's
        parameters and units.
    columns : dict, optional
        Analysis name → the file's column name (:func:`map_columns`).
    column_units, skip_rows, comments, log_run
        As for :func:`read_csv_trace` (for a file; an analysed file's directory
        reads them from its ``analysis.json`` unless given).
    **overrides
        ``spring_constant``, ``mass``, ``area``, ``thickness``,
        ``drive_velocity``, ``units``; ``None`` values are ignored.

    Examples
    --------
    >>> tr = read_trace("runs/default", spring_constant=10.0)  # doctest: +SKIP
    """
    path = Path(path)
    reading = {"column_units": column_units, "skip_rows": skip_rows, "comments": comments,
               "log_run": log_run}
    if path.is_dir():
        csv_path = path / TRACE_FILE
        if not csv_path.exists():
            analysed = _analysed_trace_file(path)
            if analysed is None and (path / SWEEP_FILE).is_file():
                raise ValueError(f"{path}: a sweep directory, not a run: give one of its runs, "
                                 f"{path}/points/<point>")
            if analysed is None:
                raise ValueError(f"{path}: run directory without trace.csv (and no "
                                 "analysis.json of a trace file)")
            file, doc = analysed
            source = doc["source"]
            base = {k: v for k, v in (source.get("parameters") or {}).items() if k in PARAMETERS}
            base["units"] = doc.get("units", "lj")
            params = TraceParameters(**base).updated(**overrides)
            mapping = dict(source.get("columns") or {})
            mapping.update(columns or {})
            recorded = {"column_units": dict(source.get("column_units") or {}),
                        "skip_rows": int(source.get("skip_rows") or 0),
                        "comments": tuple(source.get("comments") or COMMENTS),
                        "log_run": source.get("log_run")}
            # what is given wins: units name by name, as the mapping
            recorded["column_units"].update(column_units or {})
            recorded.update({k: v for k, v in reading.items()
                             if v is not None and k != "column_units"})
            tr = read_csv_trace(file, params, mapping, **recorded)
            return Trace(tr.columns, params, tr.path, None, _run_record(file.parent), tr.notes,
                         tr.layout)
        run = _run_record(path)
        params = TraceParameters(**_run_parameters(run)).updated(**overrides)
        tr = read_csv_trace(csv_path, params, columns)
        return Trace(tr.columns, params, csv_path, path, run, tr.notes, tr.layout)
    if not path.exists():
        raise ValueError(f"{path}: no such file or directory")
    run = _run_record(path.parent)
    base, notes = {}, ()
    if run.get("trace_parameters"):
        base = _run_parameters(run)
        notes = (f"parameters and units from {path.parent / 'run.json'} (the run that wrote "
                 "the file)",)
    params = TraceParameters(**base).updated(**overrides)
    tr = read_csv_trace(path, params, columns,
                        **{k: v for k, v in reading.items() if v is not None})
    return Trace(tr.columns, params, tr.path, None, run, notes + tr.notes, tr.layout)
