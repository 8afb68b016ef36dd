# Over 500 lines as one module: the three kinds of trace (run directory, plain file,
# analysed file) share the reader, the column mapping and the units; split, each part would
# import the others.
"""Read a stick-slip trace: a run directory, a plain trace file, or an analysed one.

A plain trace file has a header line naming its columns (``time`` and
``spring_force`` required; ``drive_position``, ``wall_position``,
``wall_velocity``, ``gap`` and the MD ledger columns optional), separated by
commas, tabs, semicolons or whitespace (detected from the header,
:func:`detect_delimiter`).  A file with its own column names is read through a
mapping, analysis name → the file's name (:func:`map_columns`; ``filmfriction
analyze --column time=t_s``).  Lines starting with ``#`` before the header are
ignored.  The parameters a trace needs (spring constant, wall mass, contact
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

Speed: a text trace is parsed by NumPy's C reader (~0.2 s per 10⁶ rows of three
columns); a binary copy beside it (``trace.npy``, :func:`write_binary_copy`, written
by ``filmfriction analyze`` for traces of :data:`BINARY_MIN_ROWS` rows or more) is
read instead while it is at least as new as the text (~0.01 s; see
``benchmarks/bench_analysis.py``).

The unit system is only reported, never converted: ``lj`` or ``si``.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from filmfriction.md_inputs.contract import ANALYSIS_FILE, RUN_FILE, SWEEP_FILE, TRACE_FILE

__all__ = ["MissingInput", "TraceParameters", "TraceLayout", "Trace", "read_trace",
           "read_csv_trace", "map_columns", "detect_delimiter", "trace_column_names",
           "write_binary_copy", "binary_copy_path", "BINARY_MIN_ROWS", "UNITS", "unit"]

REQUIRED_COLUMNS = ("time", "spring_force")


def trace_column_names() -> tuple[str, ...]:
    """The column names the analysis reads (the targets of a column mapping): the MD
    trace contract's, :data:`filmfriction.md_inputs.contract.TRACE_COLUMNS`."""
    from filmfriction.md_inputs.contract import TRACE_COLUMNS
    return TRACE_COLUMNS
PARAMETERS = ("spring_constant", "mass", "area", "thickness", "drive_velocity",
              "mount_damping")

#: Unit labels per quantity, per unit system (labels only: no conversion).
UNITS = {
    "lj": {"time": "τ", "force": "ε/σ", "length": "σ", "energy": "ε",
           "velocity": "σ/τ", "mass": "m", "area": "σ²", "stiffness": "ε/σ²",
           "damping": "m/τ", "viscosity": "ετ/σ³", "shear_rate": "1/τ",
           "stress": "ε/σ³", "number_density": "σ⁻³", "temperature": "ε/k_B", "1": "1"},
    "si": {"time": "s", "force": "N", "length": "m", "energy": "J",
           "velocity": "m/s", "mass": "kg", "area": "m²", "stiffness": "N/m",
           "damping": "kg/s", "viscosity": "Pa·s", "shear_rate": "1/s",
           "stress": "Pa", "number_density": "m⁻³", "temperature": "K", "1": "1"},
}


def unit(units: str, quantity: str) -> str:
    """Label of ``quantity`` (e.g. ``"force"``) in unit system ``units``."""
    return UNITS[units][quantity]


class MissingInput(LookupError):
    """A column or parameter an output needs is absent.

    Attributes
    ----------
    name : str
        The missing column or parameter (as spelled in the CSV header or on
        the command line, e.g. ``wall_velocity`` or ``--spring-constant``).
    """

    def __init__(self, name: str, needed_for: str = ""):
        self.name = name
        self.needed_for = needed_for
        msg = f"missing {name}"
        if needed_for:
            msg += f" (needed for {needed_for})"
        super().__init__(msg)


@dataclass(frozen=True)
class TraceParameters:
    """Physical parameters of the driven spring and the contact.

    ``None`` marks a parameter that was not given.
    """

    spring_constant: float | None = None
    mass: float | None = None
    area: float | None = None
    thickness: float | None = None
    drive_velocity: float | None = None
    # damping of the wall's mount (force per velocity) that is not the film's:
    # an MD run's dashpot gamma*M, in parallel with the spring (it acts on the
    # wall's velocity relative to the drive); subtracted from the fitted slip
    # damping
    mount_damping: float | None = None
    units: str = "lj"

    def __post_init__(self):
        if self.units not in UNITS:
            raise ValueError(f"units must be 'lj' or 'si', got {self.units!r}")
        for name in PARAMETERS:
            v = getattr(self, name)
            if v is not None and not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a positive number, got {v!r}")

    def require(self, name: str, needed_for: str = "") -> float:
        """The parameter's value, or :class:`MissingInput` naming the flag."""
        v = getattr(self, name)
        if v is None:
            raise MissingInput("--" + name.replace("_", "-"), needed_for)
        return float(v)

    def updated(self, **overrides) -> "TraceParameters":
        """A copy with the non-``None`` overrides applied."""
        values = {n: getattr(self, n) for n in PARAMETERS + ("units",)}
        values.update({k: v for k, v in overrides.items() if v is not None})
        return TraceParameters(**values)


@dataclass(frozen=True)
class TraceLayout:
    """How a trace file was read.

    Attributes
    ----------
    delimiter : str
        ``"comma"``, ``"tab"``, ``"semicolon"`` or ``"whitespace"``.
    columns : dict
        Analysis name → the file's column name, for the columns renamed.
    binary : bool
        Read from the binary copy beside the text (:func:`write_binary_copy`).
    """

    delimiter: str = "comma"
    columns: dict = field(default_factory=dict)
    binary: bool = False


@dataclass(frozen=True, eq=False)
class Trace:
    """A time series with named columns plus its parameters.

    Attributes
    ----------
    columns : dict of str to ndarray
        All columns read (each of the length of ``time``).
    parameters : TraceParameters
    path : Path
        The CSV file read.
    run_dir : Path or None
        The run directory, when the trace came from one.
    run : dict
        ``run.json`` content (empty for a plain CSV).
    notes : tuple of str
        Remarks made while reading (e.g. a dropped truncated last line).
    layout : TraceLayout or None
        How the file was read: delimiter, column mapping, binary copy.
    """

    columns: dict
    parameters: TraceParameters
    path: Path
    run_dir: Path | None = None
    run: dict = field(default_factory=dict)
    notes: tuple = ()
    layout: "TraceLayout | None" = None

    @property
    def time(self) -> np.ndarray:
        return self.columns["time"]

    @property
    def spring_force(self) -> np.ndarray:
        return self.columns["spring_force"]

    @property
    def units(self) -> str:
        return self.parameters.units

    def __len__(self) -> int:
        return int(self.time.size)

    def has(self, name: str) -> bool:
        return name in self.columns

    def column(self, name: str, needed_for: str = "") -> np.ndarray:
        """The named column, or :class:`MissingInput` naming it."""
        try:
            return self.columns[name]
        except KeyError:
            raise MissingInput(f"column '{name}'", needed_for) from None

    def wall_position(self) -> np.ndarray | None:
        """Wall position: the column, else drive_position − F/K, else None."""
        if self.has("wall_position"):
            return self.columns["wall_position"]
        k = self.parameters.spring_constant
        if self.has("drive_position") and k:
            return self.columns["drive_position"] - self.spring_force / k
        return None

    def drive_velocity(self) -> tuple[float | None, str]:
        """The spring end's velocity V and where it came from: ``--drive-velocity``,
        else the slope of ``drive_position``, else ``(None, "")``."""
        v = self.parameters.drive_velocity
        if v is not None:
            return v, "--drive-velocity"
        if self.has("drive_position") and len(self) > 1:
            slope = np.polyfit(self.time, self.columns["drive_position"], 1)[0]
            return float(slope), "slope of drive_position"
        return None, ""

    def film_thickness(self, sel=slice(None)) -> tuple[float, str]:
        """The film thickness D, as Klein counts it: n layers times their spacing,
        and where it came from.

        The ``gap`` column is the distance between the walls' innermost atom planes;
        n film layers between them sit n + 1 layer spacings apart, so D = gap·n/(n+1)
        (the mean gap over the samples ``sel``) when the run records its film layers
        (Klein: D = 3.5 nm for n = 4), else the gap itself.  A ``--thickness`` given
        by the user is taken as it is; without it and without ``gap``,
        :class:`MissingInput` names the flag.
        """
        if self.parameters.thickness is not None:
            return float(self.parameters.thickness), "--thickness"
        if self.has("gap"):
            gap = float(np.mean(self.columns["gap"][sel]))
            n = ((self.run or {}).get("scene") or {}).get("parameters", {}).get("film_layers")
            if n:
                return gap * n / (n + 1), (f"film layers x layer spacing: mean gap x n/(n+1), "
                                           f"n = {n} (the gap between the walls' innermost planes "
                                           f"holds n + 1 spacings)")
            return gap, "mean of gap column (wall plane to wall plane)"
        return self.parameters.require("thickness", "viscosity"), "--thickness"

    def optional_path(self, relative: str) -> Path | None:
        """A file of the run directory when it exists."""
        if self.run_dir is None:
            return None
        p = self.run_dir / relative
        return p if p.exists() else None


def detect_delimiter(header: str, first_row: str | None = None) -> str | None:
    """The delimiter of a trace's header line: ``","``, ``"\\t"`` or ``";"``, the first
    of these that the header holds (and the first data row, when given, splits into as
    many fields with), else ``None``: runs of whitespace.

    >>> detect_delimiter("t_s\\tF_N"), detect_delimiter("time;force"), detect_delimiter("a  b")
    ('\\t', ';', None)
    """
    for sep in (",", "\t", ";"):
        if sep in header and (first_row is None
                              or len(first_row.split(sep)) == len(header.split(sep))):
            return sep
    return None


def _split(line: str, sep: str | None) -> list[str]:
    """A header line's names: split at ``sep``, blanks and quotes stripped."""
    return [h.strip().strip('"').strip("'").strip() for h in
            (line.split(sep) if sep is not None else line.split())]


def _header(raw: bytes, path: Path) -> tuple[int, str, str | None]:
    """Index of the header line (after blank and ``#`` lines), its text, the delimiter."""
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise ValueError(f"{path}: UTF-16 text (a spreadsheet's 'Unicode text' export): save it "
                         "as UTF-8 or plain CSV")
    if b"\0" in raw[:65536]:
        raise ValueError(f"{path}: binary data (compressed, NumPy, an image, ...), not a text "
                         "trace: give a header line, then rows of numbers (decompress or export "
                         "it as text first)")
    # utf-8-sig: a spreadsheet's CSV export may start with a byte-order mark
    head = raw[:65536].decode("utf-8-sig", errors="replace").splitlines()
    start = 0
    while start < len(head) and (not head[start].strip() or head[start].lstrip().startswith("#")):
        start += 1
    if start == len(head):
        raise ValueError(f"{path}: empty file (no header line)")
    first_row = head[start + 1] if start + 1 < len(head) else None
    sep = detect_delimiter(head[start], first_row)
    named = next((s for s in (",", "\t", ";") if s in head[start]), None)
    if sep is None and named is not None and first_row is not None and named in first_row:
        raise ValueError(f"{path}: the header has {len(head[start].split(named))} "
                         f"{_DELIMITER_NAMES[named]}-separated columns, the first data row (line "
                         f"{start + 2}) {len(first_row.split(named))}: every row needs one value "
                         "per column")
    return start, head[start], sep


def _read_table(path: Path) -> tuple[list[str], np.ndarray, list[str], str | None]:
    """The header's names, the data rows (2-D), remarks, and the delimiter of a text trace."""
    notes = []
    raw = path.read_bytes()
    start, header, sep = _header(raw, path)
    names = _split(header, sep)
    if any(not n for n in names) or len(set(names)) != len(names):
        raise ValueError(f"{path}: bad header {header!r} (need unique column names separated "
                         "by commas, tabs, semicolons or spaces)")
    body = raw.rstrip(b"\n\r\t ")
    n_lines = body.count(b"\n") + 1 if body else 0
    n_rows = n_lines - start - 1
    if n_rows > 0 and not raw.endswith(b"\n"):
        last = body[body.rfind(b"\n") + 1:].decode("utf-8", errors="replace")
        fields = last.split(sep) if sep is not None else last.split()
        if len(fields) != len(names) or not fields[-1].strip():
            n_rows -= 1
            notes.append(f"dropped truncated last line {n_lines}")
    if n_rows <= 0:
        raise ValueError(f"{path}: no data rows after the header")
    source = path
    if sep == ";":
        # a semicolon-separated table may write decimal commas (1,5;2,25)
        rows = raw.split(b"\n", start + 1)[-1]
        if b"," in rows:
            import io
            source = io.StringIO(rows.decode("utf-8").replace(",", "."))
            start = -1
            notes.append("decimal commas read as decimal points")
    try:
        data = np.loadtxt(source, delimiter=sep, skiprows=start + 1, max_rows=n_rows,
                          ndmin=2, dtype=float, comments=None)
    except ValueError as exc:
        raise ValueError(f"{path}: cannot parse data rows "
                         f"({_DELIMITER_NAMES[sep]}-separated): {exc}") from None
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: header has {len(names)} columns ({_DELIMITER_NAMES[sep]}-"
                         f"separated), rows have {data.shape[1]}")
    return names, data, notes, sep


_DELIMITER_NAMES = {",": "comma", "\t": "tab", ";": "semicolon", None: "whitespace"}

#: A text trace of at least this many rows gets a binary copy beside it when
#: ``filmfriction analyze`` reads it (:func:`write_binary_copy`).
BINARY_MIN_ROWS = 100_000


def binary_copy_path(path) -> Path:
    """Where the binary copy of the text trace ``path`` lives: ``trace.csv`` → ``trace.npy``."""
    return Path(path).with_suffix(".npy")


def write_binary_copy(trace: "Trace") -> Path:
    """Write the binary copy of ``trace``'s text file beside it (atomically): a NumPy
    structured array whose fields are the file's columns, named as in its header.

    :func:`read_csv_trace` reads it instead of the text when it is at least as new
    as the text and has the header's names; text edited later is read again.
    """
    import io

    from .util import write_atomic

    layout = trace.layout or TraceLayout()
    names = [layout.columns.get(name, name) for name in trace.columns]
    table = np.empty(len(trace), dtype=[(name, "<f8") for name in names])
    for name, values in zip(names, trace.columns.values()):
        table[name] = values
    buf = io.BytesIO()
    np.save(buf, table, allow_pickle=False)
    return write_atomic(binary_copy_path(trace.path), buf.getvalue())


def _read_binary_copy(path: Path, names: list[str]) -> dict | None:
    """The columns of ``path``'s binary copy, or None when there is none, it is older
    than the text, or its fields are not the header's ``names``."""
    copy = binary_copy_path(path)
    if copy == path:
        return None
    try:
        if copy.stat().st_mtime_ns < path.stat().st_mtime_ns:
            return None
        table = np.load(copy, allow_pickle=False)
    except (OSError, ValueError):
        return None
    if table.ndim != 1 or table.dtype.names is None or list(table.dtype.names) != names:
        return None
    return {name: np.ascontiguousarray(table[name], dtype=float) for name in names}


def map_columns(names, mapping: dict | None, where="") -> dict:
    """Check a column mapping (analysis name → the file's column name) against a header.

    Returns
    -------
    dict
        The file's column name → the name the analysis gives it (identity for
        columns not mapped).

    Raises
    ------
    ValueError
        A target that the analysis does not know, a source column not in the
        header (both list what exists), or two sources for one name.

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
    for target, src in (mapping or {}).items():
        if target not in known:
            raise ValueError(f"--column {target}={src}: unknown name {target!r}; the analysis "
                             f"reads {', '.join(known)}")
        if src not in names:
            raise ValueError(f"{where}--column {target}={src}: no column {src!r} in the header "
                             f"(columns: {', '.join(names)})")
        renames[src] = target
    targets = list(renames.values())
    for target in set(targets):
        if targets.count(target) > 1:
            srcs = [s for s, t in renames.items() if t == target]
            raise ValueError(f"{where}columns {', '.join(srcs)} would all be called {target!r}; "
                             f"map one of them with --column {target}=NAME and rename the others")
    return renames


def read_csv_trace(path, parameters: TraceParameters | None = None,
                   columns: dict | None = None) -> Trace:
    """Read a plain trace file (comma-, tab-, semicolon- or whitespace-separated).

    Parameters
    ----------
    path : path-like
    parameters : TraceParameters, optional
    columns : dict, optional
        Analysis name → the file's column name, e.g. ``{"time": "t_s",
        "spring_force": "F_N"}`` (:func:`map_columns`).

    Raises
    ------
    ValueError
        Unreadable file, a bad mapping, missing ``time``/``spring_force``,
        non-increasing time.
    """
    path = Path(path)
    raw_head = path.open("rb").read(65536)
    start, header, sep = _header(raw_head, path)
    renames = map_columns(_split(header, sep), columns, str(path))
    cols = _read_binary_copy(path, list(renames))
    notes, from_binary = [], cols is not None
    if cols is None:
        names, data, notes, sep = _read_table(path)
        cols = {n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)}
    cols = {renames[n]: v for n, v in cols.items()}
    for req in REQUIRED_COLUMNS:
        if req not in cols:
            raise ValueError(f"{path}: required column '{req}' missing (header: "
                             f"{', '.join(renames)}); name it with --column {req}=NAME")
    t = cols["time"]
    if not np.all(np.isfinite(t)):
        raise ValueError(f"{path}: column 'time' has non-finite values")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise ValueError(f"{path}: time not increasing at data row {i + 2}")
    mapped = {renames[s]: s for s in renames if renames[s] != s}
    return Trace(cols, parameters or TraceParameters(), path, notes=tuple(notes),
                 layout=TraceLayout(_DELIMITER_NAMES[sep], mapped, from_binary))


def _analysed_trace_file(directory: Path) -> tuple[Path, dict] | None:
    """The plain trace file an ``analysis.json`` in ``directory`` was made from, and
    that document, when the directory holds no ``trace.csv`` (a measured trace)."""
    doc_path = directory / ANALYSIS_FILE
    if not doc_path.is_file():
        return None
    from .util import read_json_object

    doc = read_json_object(doc_path)
    source = doc.get("source") or {}
    if source.get("run_dir") or not source.get("path"):
        return None
    given = Path(source["path"])          # relative to the directory (older: to the cwd)
    for candidate in (directory / given.name, directory / given, given):
        if candidate.is_file():
            return candidate, doc
    raise ValueError(f"{doc_path}: the trace it was made from, {given}, is not there "
                     f"(nor in {directory})")


def read_trace(path, *, columns: dict | None = None, **overrides) -> Trace:
    """Read a run directory, a plain trace file, or the directory of an analysed trace.

    Parameters
    ----------
    path : path-like
        A run directory (with ``trace.csv`` and ``run.json``), a trace file, or a
        directory with the ``analysis.json`` of a trace file (``filmfriction analyze``
        records the file, its column mapping, units and parameters there).
    columns : dict, optional
        Analysis name → the file's column name (:func:`map_columns`).
    **overrides
        ``spring_constant``, ``mass``, ``area``, ``thickness``,
        ``drive_velocity``, ``units``; ``None`` values are ignored.

    Examples
    --------
    >>> tr = read_trace("runs/default", spring_constant=10.0)  # doctest: +SKIP
    """
    path = Path(path)
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
            return read_csv_trace(file, params, mapping)
        run = {}
        if (path / RUN_FILE).exists():
            try:
                run = json.loads((path / RUN_FILE).read_text())
            except json.JSONDecodeError as exc:
                raise ValueError(f"{path / 'run.json'}: not valid JSON: {exc}") from None
        given = dict(run.get("trace_parameters") or {})
        base = {k: given.get(k) for k in PARAMETERS}
        base["units"] = given.get("units", "lj")
        params = TraceParameters(**base).updated(**overrides)
        tr = read_csv_trace(csv_path, params, columns)
        return Trace(tr.columns, params, csv_path, path, run, tr.notes, tr.layout)
    if not path.exists():
        raise ValueError(f"{path}: no such file or directory")
    return read_csv_trace(path, TraceParameters().updated(**overrides), columns)
