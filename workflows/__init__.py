"""Scenes, the LAMMPS runner, sweeps and comparison reports."""

if __name__ != "filmfriction.workflows":  # one name only: two would give two copies of every class
    raise ImportError(f"import filmfriction.workflows, not {__name__}")
