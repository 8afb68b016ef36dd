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

Speed: a text trace is parsed by NumPy's C reader (~0.2 s per 10⁶ rows of three
columns); a binary copy (:func:`write_binary_copy`, written by ``filmfriction analyze``
for traces of :data:`BINARY_MIN_ROWS` rows or more) is read instead while the text's
content is the one it was made from (~0.01 s; see ``benchmarks/bench_analysis.py``).
The copy lives in the project's cache folder beside the text, ``.filmfriction/``, under
a name keyed by the SHA-256 of the text's bytes (:func:`binary_copy_path`): it never
takes a name the user may use, and a text replaced by another (of any date) is read
again.

The unit system, ``lj`` or ``si``, labels the outputs; only columns given with a unit of
their own are converted into it.
"""
from __future__ import annotations

import io
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from filmfriction.md_inputs.contract import ANALYSIS_FILE, RUN_FILE, SWEEP_FILE, TRACE_FILE

__all__ = ["MissingInput", "TraceParameters", "TraceLayout", "Trace", "read_trace",
           "read_csv_trace", "map_columns", "detect_delimiter", "trace_column_names",
           "write_binary_copy", "binary_copy_path", "content_sha256", "BINARY_MIN_ROWS",
           "CACHE_DIR", "CACHE_MIN_BYTES", "UNITS", "unit"]

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
        Read from the binary copy of the text (:func:`write_binary_copy`).
    kind : str
        ``"table"`` (a text table, LAMMPS's ``fix print`` and ``fix ave/time`` files
        among them) or ``"lammps-log"`` (a log's thermo output).
    column_units : dict
        Analysis name → the unit its column was given in (converted on reading).
    skip_rows : int
        Lines skipped before the header.
    comments : tuple of str
        The comment prefixes.
    log_run : str or None
        The log's thermo run(s) read (``--log-run``).
    dropped : dict
        The rows dropped for empty, NaN or infinite cells: ``count``, ``lines`` (the
        file's line numbers, at most 20) or ``rows``, and per column ``columns``
        (empty: none).
    content_sha256 : str or None
        The SHA-256 of the text file's bytes as read (a text table of
        :data:`CACHE_MIN_BYTES` or more): the key of its binary copy.
    """

    delimiter: str = "comma"
    columns: dict = field(default_factory=dict)
    binary: bool = False
    kind: str = "table"
    column_units: dict = field(default_factory=dict)
    skip_rows: int = 0
    comments: tuple = ("#",)
    log_run: str | None = None
    dropped: dict = field(default_factory=dict)
    content_sha256: str | None = None

    def source(self) -> dict:
        """What ``analysis.json``'s ``source`` records to read the file again so."""
        out = {"delimiter": self.delimiter, "columns": dict(self.columns)}
        if self.kind != "table":
            out["format"] = self.kind
        if self.column_units:
            out["column_units"] = dict(self.column_units)
        if self.skip_rows:
            out["skip_rows"] = self.skip_rows
        if tuple(self.comments) != COMMENTS:
            out["comments"] = list(self.comments)
        if self.log_run is not None:
            out["log_run"] = self.log_run
        if self.dropped:
            out["dropped_rows"] = dict(self.dropped)
        return out


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


#: What starts a comment line by default (``--comment`` gives others).
COMMENTS = ("#",)
_SKIP_HINT = ("instrument lines before the header? skip them with --skip-rows N or a "
              "comment prefix --comment TEXT")


def _is_comment(line: str, comments) -> bool:
    stripped = line.lstrip()
    return any(stripped.startswith(c) for c in comments)


def _numbers(line: str, sep: str | None) -> bool:
    """Whether every field of ``line`` is a number (a data row, not a header)."""
    fields = line.split(sep) if sep is not None else line.split()
    try:
        [float(f) for f in fields]
    except ValueError:
        return False
    return bool(fields)


def _head_bytes(path: Path, lines: int = 64) -> bytes:
    """The file's first 64 kB, or more until it holds ``lines`` whole lines (a header
    wider than 64 kB is read whole) or the file ends."""
    with open(path, "rb") as fh:
        raw = fh.read(65536)
        while raw.count(b"\n") <= lines:
            more = fh.read(1 << 20)
            if not more:
                break
            raw += more
    return raw


def _header(raw: bytes, path: Path, skip_rows: int = 0,
            comments=COMMENTS) -> tuple[int, str, str | None]:
    """Where the data rows start (line index), the header's text and the delimiter.

    The header is the first line after ``skip_rows`` lines, blank lines and comment
    lines; when that line is a row of numbers, it is the last comment line before it,
    its prefix removed: LAMMPS's convention (``fix print``'s ``title "# step time
    ..."``, ``fix ave/time``'s ``# TimeStep v_a v_b``).
    """
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise ValueError(f"{path}: UTF-16 text (a spreadsheet's 'Unicode text' export): save it "
                         "as UTF-8 or plain CSV")
    if b"\0" in raw[:65536]:
        raise ValueError(f"{path}: binary data (compressed, NumPy, an image, ...), not a text "
                         "trace: give a header line, then rows of numbers (decompress or export "
                         "it as text first)")
    # utf-8-sig: a spreadsheet's CSV export may start with a byte-order mark
    head_bytes = raw[:65536] if raw[:65536].count(b"\n") > skip_rows + 64 else raw
    head = head_bytes.decode("utf-8-sig", errors="replace").splitlines()
    if skip_rows and skip_rows >= len(head):
        raise ValueError(f"--skip-rows {skip_rows}: {path} has {len(head)} lines")
    start, last_comment = skip_rows, None
    while start < len(head) and (not head[start].strip() or _is_comment(head[start], comments)):
        if head[start].strip():
            last_comment = head[start]
        start += 1
    if start == len(head):
        raise ValueError(f"{path}: empty file (no header line" +
                         (f" after the {skip_rows} rows skipped)" if skip_rows else ")"))
    first = head[start]
    plain = detect_delimiter(first)
    if _numbers(first, plain):
        if last_comment is None:
            raise ValueError(f"{path}: line {start + 1} is a row of numbers, not a header: give "
                             "a line naming the columns before the data (or LAMMPS's '# name "
                             "name ...' comment line)")
        text = last_comment.lstrip()
        text = text[next(len(c) for c in comments if text.startswith(c)):].strip()
        sep = detect_delimiter(text, first)
        return start, text, sep
    first_row = head[start + 1] if start + 1 < len(head) else None
    sep = detect_delimiter(first, first_row)
    named = next((s for s in (",", "\t", ";") if s in first), None)
    if sep is None and named is not None and first_row is not None and named in first_row:
        raise ValueError(f"{path}: the header has {len(first.split(named))} "
                         f"{_DELIMITER_NAMES[named]}-separated columns, the first data row (line "
                         f"{start + 2}) {len(first_row.split(named))}: every row needs one value "
                         f"per column ({_SKIP_HINT})")
    return start + 1, first, sep


def _cell(text: str) -> float:
    """One cell: a number; an empty cell is NaN (a missing value)."""
    text = text.strip().strip('"')
    return float(text) if text else math.nan


def _parse_rows(lines: list[str], numbers: np.ndarray, sep: str | None, names: list[str],
                path: Path) -> np.ndarray:
    """Rows parsed one by one: empty cells are NaN; a cell that is neither a number nor
    empty, or a row of the wrong length, is an error naming its line."""
    data = np.empty((len(lines), len(names)))
    for i, line in enumerate(lines):
        fields = line.split(sep) if sep is not None else line.split()
        if len(fields) != len(names):
            raise ValueError(f"{path}: line {numbers[i]} has {len(fields)} "
                             f"{_DELIMITER_NAMES[sep]}-separated values, the header "
                             f"{len(names)} ({_SKIP_HINT})")
        for j, field_ in enumerate(fields):
            try:
                data[i, j] = _cell(field_)
            except ValueError:
                raise ValueError(f"{path}: line {numbers[i]}, column {names[j]}: "
                                 f"{field_.strip()!r} is not a number (a missing value is an "
                                 "empty cell or NaN)") from None
    return data


def _row_lines(body: bytes, start: int, comments) -> tuple[np.ndarray, int]:
    """The file's line number of each data row of ``body`` (the text after the header,
    which starts at line index ``start``), and how many comment lines lie among them."""
    numbers, n_comments = [], 0
    for i, line in enumerate(body.decode("utf-8", errors="replace").splitlines()):
        if _is_comment(line, comments):
            n_comments += 1
        elif line.strip():
            numbers.append(start + 1 + i)
    return np.asarray(numbers, dtype=int), n_comments


def _read_table(path: Path, skip_rows: int = 0, comments=COMMENTS):
    """The header's names, the data rows (2-D), each row's line number in the file,
    remarks, and the delimiter of a text trace."""
    notes = []
    raw = path.read_bytes()
    start, header, sep = _header(raw, path, skip_rows, comments)
    names = _split(header, sep)
    if any(not n for n in names) or len(set(names)) != len(names):
        raise ValueError(f"{path}: bad header {header!r} (need unique column names separated "
                         f"by commas, tabs, semicolons or spaces; {_SKIP_HINT})")
    body = raw.split(b"\n", start)[-1] if raw.count(b"\n") >= start else b""
    decimal_commas = sep == ";" and b"," in body
    if not decimal_commas and body.strip():
        # the common case, parsed by NumPy's C reader from the file (comment and blank
        # lines skipped); anything it refuses goes the slow way below
        import warnings

        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                data = np.loadtxt(path, delimiter=sep, skiprows=start, ndmin=2, dtype=float,
                                  comments=list(comments), encoding="utf-8")
        except ValueError:
            data = None
        if data is not None and data.shape[0] and data.shape[1] == len(names):
            n_lines = body.count(b"\n") + (not body.endswith(b"\n"))
            if data.shape[0] == n_lines:
                return names, data, np.arange(start + 1, start + 1 + n_lines), notes, sep
            numbers, n_comments = _row_lines(body, start, comments)
            if numbers.size == data.shape[0]:
                if n_comments:
                    notes.append(f"skipped {n_comments} comment line"
                                 f"{'s' if n_comments > 1 else ''} among the data rows")
                return names, data, numbers, notes, sep
    text = body.decode("utf-8", errors="replace")
    if decimal_commas:
        # a semicolon-separated table may write decimal commas (1,5;2,25)
        text = text.replace(",", ".")
        notes.append("decimal commas read as decimal points")
    lines = text.splitlines()
    numbers = np.arange(start + 1, start + 1 + len(lines))
    keep = [i for i, line in enumerate(lines) if line.strip() and not _is_comment(line, comments)]
    if len(keep) != len(lines):
        n_comments = sum(1 for line in lines if line.strip() and _is_comment(line, comments))
        if n_comments:
            notes.append(f"skipped {n_comments} comment line{'s' if n_comments > 1 else ''} "
                         "among the data rows")
        lines, numbers = [lines[i] for i in keep], numbers[keep]
    if lines and not raw.endswith(b"\n"):
        fields = lines[-1].split(sep) if sep is not None else lines[-1].split()
        if len(fields) != len(names) or not fields[-1].strip():
            notes.append(f"dropped truncated last line {numbers[-1]}")
            lines, numbers = lines[:-1], numbers[:-1]
    if not lines:
        raise ValueError(f"{path}: no data rows after the header")
    try:
        data = np.loadtxt(lines, delimiter=sep, ndmin=2, dtype=float, comments=None)
    except ValueError:
        data = _parse_rows(lines, numbers, sep, names, path)
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: header has {len(names)} columns ({_DELIMITER_NAMES[sep]}-"
                         f"separated), rows have {data.shape[1]} ({_SKIP_HINT})")
    return names, data, numbers, notes, sep


_DELIMITER_NAMES = {",": "comma", "\t": "tab", ";": "semicolon", None: "whitespace"}

#: A text trace of at least this many rows gets a binary copy when
#: ``filmfriction analyze`` reads it (:func:`write_binary_copy`).
BINARY_MIN_ROWS = 100_000
#: Text files smaller than this are read as text (their hash is not taken).
CACHE_MIN_BYTES = 1 << 20
#: The project's cache folder, beside a trace file.
CACHE_DIR = ".filmfriction"


def content_sha256(path) -> str:
    """The SHA-256 of the file's bytes (hex)."""
    import hashlib

    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def binary_copy_path(path, digest: str | None = None) -> Path:
    """Where the binary copy of the text trace ``path`` lives: the cache folder beside it,
    keyed by the text's content, ``.filmfriction/<name>.<sha256>.npy`` (``digest``: the
    SHA-256 already taken)."""
    path = Path(path)
    digest = digest or content_sha256(path)
    return path.parent / CACHE_DIR / f"{path.name}.{digest}.npy"


def write_binary_copy(trace: "Trace") -> Path:
    """Write the binary copy of ``trace``'s text file (atomically) into the cache folder
    beside it: a NumPy structured array whose fields are the file's columns, named as
    in its header, under the SHA-256 of the text as read (``trace.layout.content_sha256``).

    :func:`read_csv_trace` reads it instead of the text while the text's bytes are the
    ones it was made from and it has the header's names; older copies of the same file
    are removed.
    """
    import io

    from .util import write_atomic

    layout = trace.layout or TraceLayout()
    if layout.column_units or layout.dropped or layout.kind != "table" or trace.notes:
        raise ValueError(f"{trace.path}: read with unit conversions, dropped rows or notes "
                         f"({'; '.join(trace.notes)}): a binary copy holds a text table's "
                         "columns as written, so none is made")
    if layout.binary or not layout.content_sha256:
        raise ValueError(f"{trace.path}: not read from a text file of {CACHE_MIN_BYTES} bytes "
                         "or more; no binary copy is made")
    names = [layout.columns.get(name, name) for name in trace.columns]
    table = np.empty(len(trace), dtype=[(name, "<f8") for name in names])
    for name, values in zip(names, trace.columns.values()):
        table[name] = values
    buf = io.BytesIO()
    np.save(buf, table, allow_pickle=False)
    copy = binary_copy_path(trace.path, layout.content_sha256)
    cache = copy.parent
    if cache.exists() and (cache.is_symlink() or not cache.is_dir()):
        raise ValueError(f"{cache}: not the project's cache folder (a file or a link); "
                         "no binary copy is made")
    cache.mkdir(exist_ok=True)
    write_atomic(copy, buf.getvalue())
    import glob
    import re

    ours = re.compile(re.escape(Path(trace.path).name) + r"\.[0-9a-f]{64}\.npy")
    for old in cache.glob(glob.escape(Path(trace.path).name) + ".*.npy"):
        if old != copy and ours.fullmatch(old.name):
            old.unlink(missing_ok=True)
    return copy


def _read_binary_copy(path: Path, names: list[str], digest: str | None) -> dict | None:
    """The columns of ``path``'s binary copy, or None when there is none for the text's
    content ``digest`` or its fields are not the header's ``names``."""
    if digest is None:
        return None
    copy = binary_copy_path(path, digest)
    try:
        table = np.load(copy, allow_pickle=False)
    except (OSError, ValueError):
        return None
    if table.ndim != 1 or table.dtype.names is None or list(table.dtype.names) != names:
        return None
    return {name: np.ascontiguousarray(table[name], dtype=float) for name in names}


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
                             + (f"; {_SKIP_HINT})" if lost and len(mapping) > 1 else ")"))
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
        raw_head = path.read_bytes() if skip_rows else _head_bytes(path)
        start, header, sep = _header(raw_head, path, skip_rows, comments)
        renames = map_columns(_split(header, sep), columns, str(path))
        digest = (content_sha256(path) if path.is_file()
                  and path.stat().st_size >= CACHE_MIN_BYTES else None)
        cols = _read_binary_copy(path, list(renames), digest)
        notes, from_binary = [], cols is not None
        if cols is None:
            names, data, numbers, notes, sep = _read_table(path, skip_rows, comments)
            cols = {n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)}
        delimiter, kind = _DELIMITER_NAMES[sep], "table"
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
