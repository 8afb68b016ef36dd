"""One MD run's directory: created new (never an existing one), and its record
(``run.json``) and resolved scene (``scene.toml``) written."""
from __future__ import annotations

import json
import os
import platform
from datetime import datetime, timezone
from pathlib import Path

from filmfriction.analysis.files.util import json_default, write_atomic
from filmfriction.md_inputs.contract import SCENE_FILE, STUDY_FILE

from .scene import Scene, SceneError

#: the shipped LAMMPS script (md_inputs/)
SCRIPT = "film_slide.lmp"
# a scene's own script, as copied into the run directory
OWN_SCRIPT = "script.lmp"


def write_json(path: Path, data: dict) -> None:
    write_atomic(path, json.dumps(data, indent=2, default=json_default) + "\n")


def versions() -> dict:
    from importlib import metadata

    out = {"python": platform.python_version()}
    for pkg in ("filmfriction", "lammps", "mpich", "numpy", "scipy", "MDAnalysis"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def new_run_dir(scene_name: str, out: Path | None) -> Path:
    """Create a fresh run directory; never reuse an existing one."""
    from .scene import SAFE_NAME

    if not SAFE_NAME.fullmatch(scene_name):
        raise SceneError(f"scene name {scene_name!r} is not a safe directory name")
    if out is None:
        stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
        base = Path("runs") / f"{scene_name}-{stamp}"
        base.parent.mkdir(parents=True, exist_ok=True)
        for i in range(1000):
            candidate = base if i == 0 else base.with_name(f"{base.name}-{i}")
            try:
                candidate.mkdir()
                return candidate
            except FileExistsError:
                continue
        raise SceneError(f"could not create a new run directory under {base.parent}")
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        out.mkdir()
    except FileExistsError:
        raise SceneError(
            f"run directory {out} already exists: a run never overwrites another; "
            f"choose a new --out, or continue it with --resume {out}") from None
    return out


def set_aside(path: Path, parent: Path, kind: str, name: str, stamp: str) -> Path:
    """Move the directory ``path`` to ``parent/kind/name.stamp`` (``kind``: ``superseded``
    or ``failed``), intact, under a new name: nothing is replaced or deleted.  The
    convention of a sweep's points and a study's replicas that cannot be resumed."""
    target = Path(parent) / kind / f"{name}.{stamp}"
    target.parent.mkdir(exist_ok=True)
    for i in range(1, 1000):
        if not target.exists():
            break
        target = Path(parent) / kind / f"{name}.{stamp}-{i}"
    os.replace(path, target)
    return target


def start_again_advice(run_dir: Path, nprocs: int | None = None) -> str:
    """What to do with a run that holds nothing to resume (no usable restart file): run
    it again from its beginning in a new directory, ``run_dir`` kept as it is.  Its
    resolved scene (``scene.toml``: the same parameters and seed) on its ``nprocs``
    ranks is the same run.  A study's replica starts again when its study resumes (a
    sweep's point when the sweep runs again)."""
    run_dir = Path(run_dir)
    if (run_dir.parent / STUDY_FILE).is_file():     # a study's replica: the study does it
        return (f"resume its study instead, filmfriction run --resume "
                f"{shell_line([str(run_dir.parent)])}: it starts this replica again from its "
                "beginning with its seed")
    if not (run_dir / SCENE_FILE).is_file():        # stopped before it was written
        return "start the run again with the command that started it"
    ranks = f" --np {int(nprocs)}" if nprocs else ""
    return (f"start it again from the beginning with filmfriction run "
            f"{shell_line([str(run_dir / SCENE_FILE)])}{ranks} (the same scene, seed and "
            f"ranks: the same run, in a new directory; {run_dir} stays as it is)")


def scene_toml(scene: Scene) -> str:
    lines = [f"# resolved scene, as run ({datetime.now(timezone.utc).isoformat()})",
             f"name = {json.dumps(scene.name)}",
             f"description = {json.dumps(scene.description)}",
             f"models = {json.dumps(scene.models)}",
             f"outputs = {json.dumps(list(scene.outputs))}",
             f"expected_cost = {json.dumps(scene.expected_cost)}",
             "", "[parameters]"]
    from .scenes.parameters import PARAMETERS

    if scene.script:        # the copy next to this file (OWN_SCRIPT)
        lines[-2:-2] = [f"script = {json.dumps(OWN_SCRIPT)}",
                        f"lammps_packages = {json.dumps(list(scene.lammps_packages))}"]
    for name, value in scene.parameters.items():
        lines.append(f"{name} = {value!r}  # {PARAMETERS[name].unit}")
    return "\n".join(lines) + "\n"


def shell_line(cmd: list[str]) -> str:
    """A command line as a shell reads it (each word quoted as needed)."""
    import shlex

    return " ".join(shlex.quote(c) for c in cmd)


def resume_command(run_dir: Path) -> str:
    """The command that continues the run in ``run_dir``."""
    return f"filmfriction run --resume {shell_line([str(run_dir)])}"
