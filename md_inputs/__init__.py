"""LAMMPS input scripts of filmfriction, shipped as package data.

The scripts are plain LAMMPS inputs runnable by hand::

    mpiexec -n 2 lmp -in $(python -c 'from filmfriction import md_inputs; print(md_inputs.script("film_slide.lmp"))')
"""

if __name__ != "filmfriction.md_inputs":  # one name only: two would give two copies of every class
    raise ImportError(f"import filmfriction.md_inputs, not {__name__}")
from pathlib import Path

DIRECTORY = Path(__file__).resolve().parent


def script(name: str) -> Path:
    """Absolute path of the input script ``name`` (e.g. ``"film_slide.lmp"``)."""
    path = DIRECTORY / name
    if not path.is_file():
        known = ", ".join(sorted(p.name for p in DIRECTORY.glob("*.lmp")))
        raise FileNotFoundError(f"no LAMMPS script {name!r} in {DIRECTORY}; have: {known}")
    return path
