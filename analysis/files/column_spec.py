"""How a trace file is to be read, as the user says it: ``--column NAME=COLUMN[:UNIT]``,
``--skip-rows N``, ``--comment TEXT``, or the ``[trace]`` table of an SFB set-up file.

A column's unit is any unit :func:`filmfriction.reduced_model.units.parse_unit`
reads (``uN``, ``ms``, ``nm``, ``Å``, ``kcal/mol/Å``, ``epsilon/sigma`` ...) of the
quantity the analysis name stands for (the trace contract's ``quantity``:
``spring_force`` is a force, ``time`` a time); the trace reader converts the column
into the trace's unit system.

A set-up file (``filmfriction analyze --setup my_sfb.toml``) may say how its
instrument writes traces, so that every trace of it is read alike::

    [trace]
    skip_rows = 3                      # lines of metadata before the header
    comments = ["#", "%"]              # comment prefixes (default "#")
    [trace.columns]                    # NAME = "COLUMN[:UNIT]"
    time = "t:ms"
    spring_force = "F:uN"
    drive_position = "x:nm"

Example
-------
>>> parse_column("spring_force=F:uN"), parse_column("time=t_s")
(('spring_force', 'F', 'uN'), ('time', 't_s', None))
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["parse_column", "trace_table", "TRACE_KEYS"]

#: The keys of a set-up file's ``[trace]`` table.
TRACE_KEYS = ("columns", "skip_rows", "comments")


def _check_unit(name: str, unit: str, where: str) -> None:
    from filmfriction.md_inputs.contract import column
    from filmfriction.reduced_model.units import column_factor

    try:
        quantity = column(name).quantity
    except KeyError:
        return                       # an unknown name: the mapping says which exist
    if quantity == "1":
        raise ValueError(f"{where}: {name} is a count, it has no unit")
    try:
        column_factor(unit, quantity, "si")
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def parse_column(text: str, where: str | None = None) -> tuple[str, str, str | None]:
    """``NAME=COLUMN[:UNIT]`` as (name, column, unit or None).

    The unit is what follows the last ``:``; it must measure the quantity ``NAME``
    stands for.

    Raises
    ------
    ValueError
        No ``=``, an empty name, column or unit, an unreadable unit or one of the
        wrong quantity (the message begins with ``where``, default ``--column TEXT``).
    """
    where = where or f"--column {text}"
    name, sep, rest = str(text).partition("=")
    name, rest = name.strip(), rest.strip()
    if not sep or not name or not rest:
        raise ValueError(f"{where}: give NAME=COLUMN or NAME=COLUMN:UNIT, e.g. time=t_s or "
                         "spring_force=F:uN")
    column, colon, unit = rest.rpartition(":")
    if not colon:
        return name, rest, None
    column, unit = column.strip(), unit.strip()
    if not column or not unit:
        raise ValueError(f"{where}: give NAME=COLUMN:UNIT with both the column and the unit, "
                         "e.g. spring_force=F:uN")
    _check_unit(name, unit, where)
    return name, column, unit


def trace_table(path) -> dict:
    """The ``[trace]`` table of the set-up file ``path``, checked: ``columns`` (name ->
    (column, unit or None)), ``skip_rows`` (int), ``comments`` (tuple of str); keys
    absent from the file are absent here (an empty dict for a file without the table).

    Raises
    ------
    ValueError
        An unknown key, a column that is not ``"COLUMN[:UNIT]"``, a bad unit, a
        negative or non-integer ``skip_rows``, ``comments`` that are not strings; the
        message names the file and the key.
    """
    from filmfriction.reduced_model.sfb.user_setup import read_setup_file

    path = Path(path)
    table = read_setup_file(path).get("trace", {})
    out = {}
    if not isinstance(table, dict):
        raise ValueError(f"{path}: trace = {table!r}: give a table [trace] with "
                         f"{', '.join(TRACE_KEYS)}")
    unknown = sorted(set(table) - set(TRACE_KEYS))
    if unknown:
        raise ValueError(f"{path}: unknown key(s) {', '.join(unknown)} in [trace]; accepted: "
                         f"{', '.join(TRACE_KEYS)}")
    if "columns" in table:
        columns = table["columns"]
        if not isinstance(columns, dict):
            raise ValueError(f"{path}: [trace] columns = {columns!r}: give a table NAME = "
                             '"COLUMN[:UNIT]", e.g. spring_force = "F:uN"')
        out["columns"] = {}
        for name, spec in columns.items():
            where = f"{path}: [trace.columns] {name} = {spec!r}"
            if not isinstance(spec, str):
                raise ValueError(f'{where}: give "COLUMN" or "COLUMN:UNIT", e.g. "F:uN"')
            parsed = parse_column(f"{name}={spec}", where)
            out["columns"][parsed[0]] = parsed[1:]
    if "skip_rows" in table:
        n = table["skip_rows"]
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise ValueError(f"{path}: [trace] skip_rows = {n!r}: give a whole number, 0 or "
                             "more")
        out["skip_rows"] = n
    if "comments" in table:
        c = table["comments"]
        c = [c] if isinstance(c, str) else c
        if (not isinstance(c, list) or not c
                or not all(isinstance(x, str) and x.strip() for x in c)):
            raise ValueError(f"{path}: [trace] comments = {table['comments']!r}: give a "
                             'prefix or a list of them, e.g. ["#", "%"]')
        out["comments"] = tuple(x.strip() for x in c)
    return out
