"""Read a stick-slip trace: a run directory or a plain CSV file.

A plain CSV has a header line naming its columns (``time`` and
``spring_force`` required; ``drive_position``, ``wall_position``,
``wall_velocity``, ``gap`` and the MD ledger columns optional).  Lines
starting with ``#`` before the header are ignored.  The parameters a trace
needs (spring constant, wall mass, contact area, film thickness, drive
velocity) and the unit system come from the command line or, for a run
directory, from ``run.json``'s ``trace_parameters`` (the command line wins).

A run directory holds ``trace.csv`` (the columns of the MD script's contract,
:data:`filmfriction.md_inputs.contract.TRACE`, whose ``quantity`` names the
entry of :data:`UNITS` that labels it) and ``run.json``, and optionally
``profiles/density.profile``, ``profiles/velocity.profile`` (``fix
ave/chunk``) and ``trajectory.dcd`` + ``topology.data``.

The unit system is only reported, never converted: ``lj`` or ``si``.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["MissingInput", "TraceParameters", "Trace", "read_trace",
           "read_csv_trace", "UNITS", "unit"]

REQUIRED_COLUMNS = ("time", "spring_force")
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
    """

    columns: dict
    parameters: TraceParameters
    path: Path
    run_dir: Path | None = None
    run: dict = field(default_factory=dict)
    notes: tuple = ()

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


def _read_table(path: Path) -> tuple[list[str], np.ndarray, list[str]]:
    notes = []
    with path.open("rb") as fh:
        raw = fh.read()
    text_head = raw[:65536].decode("utf-8", errors="replace").splitlines()
    start = 0
    while start < len(text_head) and (not text_head[start].strip()
                                      or text_head[start].lstrip().startswith("#")):
        start += 1
    if start == len(text_head):
        raise ValueError(f"{path}: empty file (no header line)")
    header = text_head[start]
    names = [h.strip() for h in header.split(",")]
    if any(not n for n in names) or len(set(names)) != len(names):
        raise ValueError(f"{path}: bad header {header!r} "
                         "(need unique comma-separated column names)")
    body = raw.rstrip(b"\n\r\t ")
    n_lines = body.count(b"\n") + 1 if body else 0
    n_rows = n_lines - start - 1
    if n_rows > 0 and not raw.endswith(b"\n"):
        last = body[body.rfind(b"\n") + 1:].decode("utf-8", errors="replace")
        if last.count(",") != len(names) - 1 or last.rstrip().endswith(","):
            n_rows -= 1
            notes.append(f"dropped truncated last line {n_lines}")
    if n_rows <= 0:
        raise ValueError(f"{path}: no data rows after the header")
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=start + 1, max_rows=n_rows,
                          ndmin=2, dtype=float, comments=None)
    except ValueError as exc:
        raise ValueError(f"{path}: cannot parse data rows: {exc}") from None
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: header has {len(names)} columns, "
                         f"rows have {data.shape[1]}")
    return names, data, notes


def read_csv_trace(path, parameters: TraceParameters | None = None) -> Trace:
    """Read a plain CSV trace.

    Raises
    ------
    ValueError
        Unreadable file, missing ``time``/``spring_force``, non-increasing time.
    """
    path = Path(path)
    names, data, notes = _read_table(path)
    for req in REQUIRED_COLUMNS:
        if req not in names:
            raise ValueError(f"{path}: required column '{req}' missing "
                             f"(header: {', '.join(names)})")
    cols = {n: np.ascontiguousarray(data[:, j]) for j, n in enumerate(names)}
    t = cols["time"]
    if not np.all(np.isfinite(t)):
        raise ValueError(f"{path}: column 'time' has non-finite values")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise ValueError(f"{path}: time not increasing at data row {i + 2}")
    return Trace(cols, parameters or TraceParameters(), path, notes=tuple(notes))


def read_trace(path, **overrides) -> Trace:
    """Read a run directory or a CSV trace.

    Parameters
    ----------
    path : path-like
        A run directory (with ``trace.csv`` and ``run.json``) or a CSV file.
    **overrides
        ``spring_constant``, ``mass``, ``area``, ``thickness``,
        ``drive_velocity``, ``units``; ``None`` values are ignored.

    Examples
    --------
    >>> tr = read_trace("runs/default", spring_constant=10.0)  # doctest: +SKIP
    """
    path = Path(path)
    if path.is_dir():
        csv_path = path / "trace.csv"
        if not csv_path.exists():
            raise ValueError(f"{path}: run directory without trace.csv")
        run = {}
        if (path / "run.json").exists():
            try:
                run = json.loads((path / "run.json").read_text())
            except json.JSONDecodeError as exc:
                raise ValueError(f"{path / 'run.json'}: not valid JSON: {exc}") from None
        given = dict(run.get("trace_parameters") or {})
        base = {k: given.get(k) for k in PARAMETERS}
        base["units"] = given.get("units", "lj")
        params = TraceParameters(**base).updated(**overrides)
        tr = read_csv_trace(csv_path, params)
        return Trace(tr.columns, params, csv_path, path, run, tr.notes)
    if not path.exists():
        raise ValueError(f"{path}: no such file or directory")
    return read_csv_trace(path, TraceParameters().updated(**overrides))
