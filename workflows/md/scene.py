"""Scenes: what a run models, its parameters, and their validation.

A scene is a TOML file (see ``workflows/md/scenes/``)::

    name = "stick-slip"
    description = "one line"
    models = "a paragraph: what physics this scene stands for"
    outputs = ["stick_slip", "energy", "viscosity_from_slip"]
    expected_cost = "about 1 minute on 2 cores"

    [parameters]          # LJ reduced units, names as in scenes/parameters.py
    drive_velocity = 0.02
    ...

Two optional keys bring one's own LAMMPS script: ``script = "my_slide.lmp"``
(a path, relative to the TOML file) runs instead of ``film_slide.lmp`` with the
same ``-var`` variables, and must write ``trace.dat`` as
``md_inputs/contract.py`` says (checked on its first rows); ``lammps_packages
= ["RIGID", ...]`` lists the LAMMPS packages it needs (default: those of the
shipped script).

Every value that reaches LAMMPS passes through
:func:`~filmfriction.workflows.md.scenes.parameters.resolve`: it must be a
known name, of the declared type, finite and inside the declared range, and is
formatted here as a plain number.  Nothing a user writes is ever pasted into
an input script as text, so a scene cannot smuggle LAMMPS commands (``shell``)
into a run.  (A scene's own ``script`` is a file its author wrote, run as it is.)
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from filmfriction.md_inputs.geometry import ConfinedFilm

from .scenes.parameters import (FLEXIBLE_WALL_ATOM_MASS, FLEXIBLE_WALL_EPSILON, NEEDS_PROFILES,
                                NEEDS_TRAJECTORY, OUTPUTS, PARAMETERS, WORK_EVERY, SceneError,
                                derived_quantities, geometry, resolve)

# A scene name: it names the run directory, so no path separators, no "..".
SAFE_NAME = __import__("re").compile(r"[A-Za-z0-9_][A-Za-z0-9._-]{0,63}")



@dataclass(frozen=True)
class Scene:
    """A resolved scene: every parameter present, typed and range-checked."""

    name: str
    description: str
    models: str
    outputs: tuple[str, ...]
    expected_cost: str
    parameters: dict[str, float | int] = field(hash=False)
    source: str = ""
    script: str = ""              # the scene's own LAMMPS script ("": film_slide.lmp)
    lammps_packages: tuple[str, ...] = ("RIGID",)   # what the script needs of LAMMPS

    @property
    def writes_trajectory(self) -> bool:
        return bool(NEEDS_TRAJECTORY & set(self.outputs))

    @property
    def writes_profiles(self) -> bool:
        return bool(NEEDS_PROFILES & set(self.outputs))

    def derived(self) -> dict[str, float]:
        return derived_quantities(self.parameters)

    def geometry(self) -> ConfinedFilm:
        """The walls and the film: :meth:`ConfinedFilm.lammps_data` is the script's data file."""
        return geometry(self.parameters)

    def lammps_variables(self) -> dict[str, str]:
        """``-var`` values for ``film_slide.lmp``: numbers formatted here, nothing else."""
        p = dict(self.parameters)
        if not self.writes_trajectory:
            p["dump_every"] = 0
        if not self.writes_profiles:
            p["profile_every"] = 0
        out = {}
        for name, value in p.items():
            spec = PARAMETERS[name]
            if spec.choices:
                out[name] = str(spec.choices.index(value))
            else:
                out[name] = str(int(value)) if spec.kind is int else repr(float(value))
        out["wall_epsilon"] = repr(FLEXIBLE_WALL_EPSILON)
        out["wall_atom_mass"] = repr(FLEXIBLE_WALL_ATOM_MASS)
        # the drive and mount powers are integrated from samples every work_every
        # steps; the trace and the restarts must fall on samples
        out["work_every"] = str(math.gcd(WORK_EVERY, p["trace_every"], p["restart_every"]))
        return out

    def as_dict(self) -> dict:
        return {"name": self.name, "description": self.description, "models": self.models,
                "outputs": list(self.outputs), "expected_cost": self.expected_cost,
                "parameters": dict(self.parameters), "source": self.source,
                "script": self.script, "lammps_packages": list(self.lammps_packages)}


def scenes_directory() -> Path:
    return Path(str(resources.files("filmfriction.workflows.md") / "scenes")).resolve()


def available() -> dict[str, Path]:
    return {p.stem: p for p in sorted(scenes_directory().glob("*.toml"))}


def load(name_or_path: str, overrides: dict[str, Any] | None = None) -> Scene:
    """Load a scene by name (``stick-slip``) or from a TOML file path."""
    scenes = available()
    if name_or_path in scenes:
        path = scenes[name_or_path]
    else:
        path = Path(name_or_path)
        if not path.is_file():
            raise SceneError(f"no scene {name_or_path!r}; known scenes: "
                             f"{', '.join(scenes)} (or give a path to a .toml file)")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8-sig"))  # a BOM is accepted
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise SceneError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start}); "
                         "a scene is a UTF-8 TOML file") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if "observables" in data:
        raise SceneError(f"{path}: 'observables' is not a scene key: the engine's outputs are "
                         f"listed as outputs = [...] ({', '.join(OUTPUTS)}); rename the key")
    allowed = {"name", "description", "models", "outputs", "expected_cost", "parameters",
               "script", "lammps_packages"}
    unknown = set(data) - allowed
    if unknown:
        raise SceneError(f"{path}: unknown keys {sorted(unknown)}; allowed: {sorted(allowed)}")
    outputs = data.get("outputs", ["stick_slip", "energy"])
    if not isinstance(outputs, list) or not all(isinstance(o, str) for o in outputs):
        raise SceneError(f"{path}: outputs must be a list of names")
    bad = [o for o in outputs if o not in OUTPUTS]
    if bad:
        raise SceneError(f"{path}: unknown outputs {bad}; known: {sorted(OUTPUTS)}")
    # a user who sets a recording interval asks for that recording: honoured, not zeroed
    asked = {"dump_every": "structure", "profile_every": "profiles"}
    outputs = list(outputs) + [o for k, o in asked.items()
                               if k in (overrides or {}) and o not in outputs]
    params = data.get("parameters", {})
    if not isinstance(params, dict):
        raise SceneError(f"{path}: [parameters] must be a table")
    try:
        resolved = resolve(params, overrides)
    except SceneError as exc:
        raise SceneError(f"scene {data.get('name', path.stem)!r}: {exc}") from None
    name = data.get("name", path.stem)
    if not isinstance(name, str) or not SAFE_NAME.fullmatch(name):
        raise SceneError(f"{path}: name = {name!r}: a scene name is 1-64 characters from "
                         "letters, digits, '.', '_', '-', not starting with '.' or '-' "
                         "(it names the run directory)")
    return Scene(name=name,
                 description=str(data.get("description", "")),
                 models=str(data.get("models", "")),
                 outputs=tuple(outputs),
                 expected_cost=str(data.get("expected_cost", "")),
                 parameters=resolved, source=str(path),
                 script=_own_script(path, data.get("script")),
                 lammps_packages=_packages(path, data.get("lammps_packages", ["RIGID"])))


def _own_script(path: Path, script) -> str:
    """The absolute path of a scene's own LAMMPS script ("" for none)."""
    if script is None:
        return ""
    if not isinstance(script, str) or not script.strip():
        raise SceneError(f"{path}: script = {script!r}: give the path of a LAMMPS input "
                         "script (relative to the scene file)")
    full = (path.parent / script).resolve()
    if not full.is_file():
        raise SceneError(f"{path}: script = {script!r}: no such file ({full})")
    return str(full)


def _packages(path: Path, packages) -> tuple[str, ...]:
    """LAMMPS package names as ``lmp -h`` lists them (e.g. RIGID, EXTRA-DUMP)."""
    import re

    if (not isinstance(packages, list)
            or not all(isinstance(p, str) and re.fullmatch(r"[A-Z0-9][A-Z0-9-]*", p)
                       for p in packages)):
        raise SceneError(f"{path}: lammps_packages = {packages!r}: give a list of LAMMPS "
                         "package names in capitals, e.g. [\"RIGID\", \"EXTRA-DUMP\"]")
    return tuple(packages)
