"""A stick-slip trace: its columns, its parameters and units, and how it was read.

:class:`Trace` holds the columns (``time`` and ``spring_force`` required; the names
the analysis reads are the MD script's contract, :func:`trace_column_names`), the
:class:`TraceParameters` a trace needs (spring constant, wall mass, contact area,
film thickness, drive velocity, unit system) and the :class:`TraceLayout` it was read
with.  :data:`UNITS` labels each quantity in each unit system; :class:`MissingInput`
names what an analysis needed and did not get.  Reading a trace from a run directory,
a plain file or an analysed one is :mod:`~filmfriction.analysis.files.trace_reader`.
"""
from __future__ import annotations

import math
from dataclasses import replace, dataclass, field
from pathlib import Path

import numpy as np

from .trace_table import COMMENTS

__all__ = ["MissingInput", "TraceParameters", "TraceLayout", "Trace", "trace_column_names",
           "UNITS", "unit", "PARAMETERS", "REQUIRED_COLUMNS"]

REQUIRED_COLUMNS = ("time", "spring_force")


def trace_column_names() -> tuple[str, ...]:
    """The column names the analysis reads (the targets of a column mapping): the MD
    trace contract's, :data:`filmfriction.md_inputs.contract.TRACE_COLUMNS`."""
    from filmfriction.md_inputs.contract import TRACE_COLUMNS
    return TRACE_COLUMNS
PARAMETERS = ("spring_constant", "mass", "area", "thickness", "drive_velocity",
              "mount_damping", "film_mass", "registry_period")

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
    # the mass of the film between the walls (an MD run's film atoms, 1 m each): the most
    # a co-moving mass can be (the slip law's rule takes more for a yield loop)
    film_mass: float | None = None
    # the period of the walls' registry along the slide (an MD run's commensurate walls:
    # their lattice's): the slip law fits a force periodic in the wall's position beside
    # the film's law
    registry_period: float | None = None
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
            n = self.scene_parameter("film_layers")
            if n:
                return gap * n / (n + 1), (f"film layers x layer spacing: mean gap x n/(n+1), "
                                           f"n = {n} (the gap between the walls' innermost planes "
                                           f"holds n + 1 spacings)")
            return gap, "mean of gap column (wall plane to wall plane)"
        return self.parameters.require("thickness", "viscosity"), "--thickness"

    def scene_parameter(self, name: str):
        """A parameter of the scene the run recorded in ``run.json`` (None: not a run, or
        not recorded)."""
        return (((self.run or {}).get("scene") or {}).get("parameters") or {}).get(name)

    def head(self, n: int, note: str | None = None) -> "Trace":
        """The first ``n`` samples of every column (with ``note`` added to the notes)."""
        notes = tuple(self.notes) + ((note,) if note else ())
        return replace(self, columns={k: v[:n] for k, v in self.columns.items()}, notes=notes)

    def optional_path(self, relative: str) -> Path | None:
        """A file of the run directory when it exists."""
        if self.run_dir is None:
            return None
        p = self.run_dir / relative
        return p if p.exists() else None
