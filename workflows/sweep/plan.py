"""Sweep planning: the grid, its points, and the sweep directory's plan and lock.

Part of :mod:`filmfriction.workflows.sweep` (which documents the sweep directory).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from filmfriction.analysis.files.util import json_default, read_json_object, write_atomic
from filmfriction.md_inputs.contract import SWEEP_FILE

from ..md.locks import DirectoryLock
from ..inputs import UserError


PLAN_SCHEMA = "filmfriction.sweep/1"
POINT_SCHEMA = "filmfriction.sweep-point/1"
SEPARATOR = "__"          # between key=value pairs in a point name
SIGNIFICANT = 6           # grid values are rounded to this many digits (name == value)
# Most points a sweep plans unless FILMFRICTION_MAX_POINTS says otherwise:
# counted before any value is built (a typo of N must not allocate GiBs).
MAX_POINTS = 10000


def max_points() -> int:
    """The cap on a sweep's points: ``$FILMFRICTION_MAX_POINTS`` (a whole number >= 1,
    checked) or :data:`MAX_POINTS`."""
    from ..inputs import env_count

    return env_count("FILMFRICTION_MAX_POINTS", MAX_POINTS)


# ---------------------------------------------------------------------------
# the grid
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class GridAxis:
    """One swept parameter.

    Attributes
    ----------
    key : str
        A scene parameter (:data:`filmfriction.workflows.md.scenes.parameters.PARAMETERS`).
    values : tuple
        The values, typed as the parameter (int or float), in the order given.
    spec : str
        The ``--grid`` text it came from (for messages).
    """

    key: str
    values: tuple
    spec: str


def _round(value: float) -> float:
    return float(f"{value:.{SIGNIFICANT}g}")


def format_value(value) -> str:
    """A grid value as it appears in a point name (ints plain, floats ``%.6g``)."""
    if isinstance(value, str):
        return value
    return str(value) if isinstance(value, int) else f"{value:.{SIGNIFICANT}g}"


def parse_grid(text: str) -> GridAxis:
    """Parse ``KEY=START:STOP:N[:log]`` or ``KEY=V1,V2,...``.

    ``N`` values from START to STOP inclusive, evenly spaced, or evenly in
    log with ``:log`` (START and STOP > 0).  Float values are rounded to
    six significant digits, so a point's name and its value agree.

    Parameters
    ----------
    text : str

    Returns
    -------
    GridAxis

    Raises
    ------
    workflows.scene.SceneError
        Unknown key, malformed range, or values that collapse (an integer
        parameter asked for more values than its range holds).

    Examples
    --------
    >>> parse_grid("drive_velocity=0.01:1:3:log").values
    (0.01, 0.1, 1.0)
    >>> parse_grid("seed=1,2").values
    (1, 2)
    """
    from ..md.scene import SceneError
    from ..md.scenes.parameters import PARAMETERS, split_parameter

    key, body = split_parameter(text, "--grid", "KEY=START:STOP:N[:log] or KEY=V1,V2,...")
    kind = PARAMETERS[key].kind
    if PARAMETERS[key].choices:
        names = tuple(PARAMETERS[key].check(v.strip()) for v in body.split(",") if v.strip())
        if not names or len(set(names)) != len(names):
            raise SceneError(f"--grid {text!r}: give distinct values from "
                             f"{', '.join(PARAMETERS[key].choices)}, comma-separated")
        return GridAxis(key=key, values=names, spec=text)

    def number(s: str, what: str) -> float:
        try:
            x = float(s)
        except ValueError:
            raise SceneError(f"--grid {text!r}: {what} {s!r} is not a number") from None
        if not math.isfinite(x):
            raise SceneError(f"--grid {text!r}: {what} {s!r} is not finite")
        return x

    if ":" in body:
        parts = body.split(":")
        if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("log", "lin")):
            raise SceneError(f"--grid {text!r}: expected KEY=START:STOP:N or "
                             "KEY=START:STOP:N:log")
        start, stop = number(parts[0], "START"), number(parts[1], "STOP")
        try:
            n = int(parts[2])
        except ValueError:
            raise SceneError(f"--grid {text!r}: N {parts[2]!r} is not a whole number") from None
        if n < 1:
            raise SceneError(f"--grid {text!r}: N = {n}: need at least 1 value")
        if n > max_points():
            raise SceneError(f"--grid {text!r}: N = {n} values is above the cap of "
                             f"{max_points()} points (set FILMFRICTION_MAX_POINTS to raise it)")
        log = len(parts) == 4 and parts[3] == "log"
        if log and (start <= 0 or stop <= 0):
            raise SceneError(f"--grid {text!r}: a log range needs START > 0 and STOP > 0")
        if n == 1:
            raw = [start]
        else:
            raw = list(np.geomspace(start, stop, n) if log else np.linspace(start, stop, n))
    else:
        raw = [number(s.strip(), "value") for s in body.split(",") if s.strip()]
        if not raw:
            raise SceneError(f"--grid {text!r}: no values")
    if kind is int and ":" not in body:
        spec = PARAMETERS[key]
        odd = [x for x in raw if not float(x).is_integer()]
        if odd:
            raise SceneError(f"--grid {text!r}: {key} takes whole numbers in "
                             f"[{spec.low}, {spec.high}]; {odd[0]:g} is not one")
    if kind is int:
        values = tuple(int(round(x)) for x in raw)
    else:
        values = tuple(_round(x) for x in raw)
    if len(set(values)) != len(values):
        raise SceneError(f"--grid {text!r}: values repeat after rounding to "
                         f"{'whole numbers' if kind is int else 'six digits'}: "
                         f"{', '.join(format_value(v) for v in values)}")
    return GridAxis(key=key, values=values, spec=text)


@dataclass(frozen=True)
class SweepPoint:
    """One grid point: its name and its grid values (the fixed overrides are the plan's)."""

    name: str
    values: dict = field(hash=False)


@dataclass(frozen=True)
class SweepPlan:
    """What a sweep runs; validated, not yet written.

    Attributes
    ----------
    scene : str
        Scene name.
    scene_source : str
        Absolute path of the scene's TOML file.
    grid : tuple of GridAxis
    fixed : dict
        ``--set`` overrides applied to every point.
    np : int
        MPI ranks per point (the Slurm profile may set its own ``tasks``).
    points : tuple of SweepPoint
        The full product of the grid, first axis slowest.
    parameters : dict
        Point name → resolved parameters (every scene parameter).
    calibration : str or None
        A ``calibration.json`` whose reduced model is overlaid on the (V, K) map.
    """

    scene: str
    scene_source: str
    grid: tuple
    fixed: dict = field(hash=False)
    np: int = 2
    points: tuple = ()
    parameters: dict = field(default_factory=dict, hash=False)
    calibration: str | None = None

    def as_dict(self) -> dict:
        return {"schema": PLAN_SCHEMA, "scene": self.scene, "scene_source": self.scene_source,
                "grid": [{"key": a.key, "values": list(a.values), "spec": a.spec}
                         for a in self.grid],
                "fixed": dict(self.fixed), "np": self.np,
                "points": [{"name": p.name, "values": dict(p.values)} for p in self.points],
                "calibration": self.calibration}


def point_name(values: dict) -> str:
    """``key=value`` pairs joined by ``__``, in grid order."""
    return SEPARATOR.join(f"{k}={format_value(v)}" for k, v in values.items())


def plan_sweep(scene: str, grid: list[str], sets: list[str] | None = None, np_: int = 2,
               calibration: Path | None = None) -> SweepPlan:
    """Parse and validate a sweep; every point is resolved before anything runs.

    Parameters
    ----------
    scene : str
        Scene name or TOML path.
    grid : list of str
        ``--grid`` texts; several make the full product.
    sets : list of str, optional
        ``--set KEY=VALUE`` texts applied to every point.
    np_ : int
        MPI ranks per point.
    calibration : Path, optional
        ``calibration.json`` for the reduced model's boundary on the (V, K) map.

    Raises
    ------
    workflows.scene.SceneError
        With the grid point, the key, the value and the allowed range.
    """
    import itertools

    from ..md.scene import SceneError, load
    from ..md.scenes.parameters import parse_assignment

    if not grid:
        raise SceneError("give at least one --grid KEY=START:STOP:N[:log]")
    if np_ < 1:
        raise SceneError(f"--np {np_}: need at least 1 MPI rank")
    axes = [parse_grid(g) for g in grid]
    keys = [a.key for a in axes]
    dup = sorted({k for k in keys if keys.count(k) > 1})
    if dup:
        raise SceneError(f"--grid given twice for {', '.join(dup)}: give each key once "
                         "(use KEY=V1,V2,... for an irregular set)")
    total = math.prod(len(a.values) for a in axes)
    if total > max_points():
        raise SceneError(f"--grid: {' x '.join(str(len(a.values)) for a in axes)} = {total} "
                         f"points is above the cap of {max_points()} (set "
                         "FILMFRICTION_MAX_POINTS to raise it)")
    fixed: dict = {}
    for text in sets or []:
        k, v = parse_assignment(text)
        if k in keys:
            raise SceneError(f"--set {text!r}: {k} is already swept by --grid")
        if k in fixed:
            raise SceneError(f"--set {k} given twice: give each key once")
        fixed[k] = v
    base = load(scene, fixed)       # the scene itself and the fixed values, checked once
    points, params = [], {}
    for combo in itertools.product(*(a.values for a in axes)):
        values = dict(zip(keys, combo))
        name = point_name(values)
        try:
            resolved = load(scene, {**fixed, **values}).parameters
        except SceneError as exc:
            spec = "; ".join(a.spec for a in axes)
            raise SceneError(f"grid point {name} (from --grid {spec}): {exc}") from None
        points.append(SweepPoint(name=name, values=values))
        params[name] = resolved
    if calibration is not None:
        calibration = Path(calibration).resolve()
        if not calibration.is_file():
            raise SceneError(f"--calibration {calibration}: no such file")
        try:
            cal = read_json_object(calibration, f"--calibration {calibration}",
                                   what="a JSON object (calibration.json)")
        except ValueError as exc:
            raise SceneError(str(exc)) from None
        # checked now, not after the whole sweep has run (the map's boundary is drawn last)
        if not str(cal.get("schema", "")).startswith("filmfriction.calibration/"):
            raise SceneError(f"--calibration {calibration}: not a calibration.json (schema "
                             f"{cal.get('schema')!r}; 'filmfriction calibrate RUN_DIR' writes one)")
        if cal.get("units", "lj") != "lj":
            raise SceneError(f"--calibration {calibration}: in {cal.get('units')!r} units (a "
                             "measured trace's); the (V, K) map of MD runs needs an MD "
                             "calibration, in LJ units")
    return SweepPlan(scene=base.name, scene_source=str(Path(base.source).resolve()),
                     grid=tuple(axes), fixed=fixed, np=np_, points=tuple(points),
                     parameters=params,
                     calibration=str(calibration) if calibration else None)


# ---------------------------------------------------------------------------
# the sweep directory
# ---------------------------------------------------------------------------
def json_text(doc) -> str:
    """A sweep document as the sweep directory holds it: indented, keys sorted."""
    return json.dumps(doc, indent=2, sort_keys=True, default=json_default) + "\n"


def _write_if_changed(path: Path, text: str) -> bool:
    """Atomic write, skipped when the content is the same: an unchanged mtime is what
    keeps Snakemake from re-running a point whose parameters did not change."""
    if path.exists() and path.read_text() == text:
        return False
    write_atomic(path, text)
    return True


def write_plan(plan: SweepPlan, out: Path) -> list[str]:
    """Write ``sweep.json`` and ``inputs/<point>.json``; return the points whose input changed."""
    out = Path(out)
    (out / "inputs").mkdir(parents=True, exist_ok=True)
    changed = []
    for p in plan.points:
        doc = {"schema": POINT_SCHEMA, "scene": plan.scene, "scene_source": plan.scene_source,
               "overrides": {**plan.fixed, **p.values}, "parameters": plan.parameters[p.name]}
        if _write_if_changed(out / "inputs" / f"{p.name}.json", json_text(doc)):
            changed.append(p.name)
    _write_if_changed(out / SWEEP_FILE, json_text(plan.as_dict()))
    return changed


def SweepLock(directory: Path) -> DirectoryLock:
    """The lock on ``<sweep>/.sweep.lock``: one sweep per directory.  Its descriptor is
    passed to the Snakemake child, so the lock lasts as long as either process does."""
    directory = Path(directory)
    return DirectoryLock(directory / ".sweep.lock", lambda holder: UserError(
        f"another sweep is running in {directory} ({holder}); wait for it, "
        "or give this sweep its own --out"), inheritable=True)


