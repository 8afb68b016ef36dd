"""A filmfriction run's trajectory (DCD) opened as an MDAnalysis ``Universe`` with times
in τ, its frames' MD steps, atoms picked by type, and the film's layers in one call."""
from __future__ import annotations

import numpy as np

from .layering import DensityProfile

__all__ = ["film_layers", "frame_steps", "lammps_frame_interval", "open_trajectory",
           "select_types"]


def select_types(universe, types):
    return universe.select_atoms("type " + " ".join(str(int(t)) for t in types))


def frame_steps(universe) -> np.ndarray | None:
    """MD step of each frame of a DCD trajectory (istart + i·nsavc), or None."""
    header = getattr(getattr(universe.trajectory, "_file", None), "header", None)
    if not header or not header.get("nsavc"):
        return None
    n = universe.trajectory.n_frames
    return header["istart"] + header["nsavc"] * np.arange(n)


def lammps_frame_interval(trajectory) -> float | None:
    """Time between frames of a DCD that LAMMPS wrote, in the run's units (τ in LJ), or None.

    LAMMPS writes its own timestep, unconverted, as the DCD header's float32
    ``delta`` and the dump interval as ``nsavc``; MDAnalysis reads ``delta`` as
    CHARMM's AKMA time unit (48.9 fs) and so reports a wrong time.  The
    interval is nsavc × the timestep, the timestep being the shortest
    decimal that rounds to ``delta`` in float32 (0.005, not 0.004999999888).
    """
    import struct

    with open(trajectory, "rb") as f:
        head = f.read(100)
    if len(head) < 48 or head[4:8] != b"CORD":
        return None
    order = "<" if struct.unpack("<i", head[:4])[0] == 84 else ">"
    nsavc = struct.unpack(order + "i", head[16:20])[0]      # CORD, NSET, ISTART, NSAVC
    delta = struct.unpack(order + "f", head[44:48])[0]
    if nsavc <= 0 or not delta > 0:
        return None
    return nsavc * float(str(np.float32(delta)))


def open_trajectory(topology, trajectory, dt: float | None = None):
    """A filmfriction run's trajectory as an MDAnalysis ``Universe``, with times in τ.

    ``dt``: the time between frames (dump_every × timestep); default from
    the DCD header (:func:`lammps_frame_interval`).  ``u.trajectory.time`` is
    then step × timestep, the trace's ``time``; lengths are in σ (MDAnalysis
    labels them Å and times ps, but converts neither).

    For a user's own script the same is::

        mda.Universe("topology.data", "trajectory.dcd", atom_style="id type x y z",
                     dt=dump_every * timestep)
    """
    import warnings

    import MDAnalysis as mda

    if dt is None:
        dt = lammps_frame_interval(trajectory)
    with warnings.catch_warnings():      # DCDReader's 3.0 deprecation notice
        warnings.simplefilter("ignore", DeprecationWarning)
        return mda.Universe(str(topology), str(trajectory), format="DCD",
                            topology_format="DATA", atom_style="id type x y z",
                            **({"dt": dt} if dt else {}))


def film_layers(topology, trajectory, film_types, step: int = 1):
    """A run's trajectory opened (:func:`open_trajectory`), its film atoms (``film_types``)
    and their :class:`DensityProfile` over every ``step``-th frame: ``(universe, film,
    profile)``; ``profile.results.layers`` holds the layers and their ``edges``.

    Raises
    ------
    ValueError
        No atom of ``film_types`` in ``topology``.
    """
    u = open_trajectory(topology, trajectory)
    film = select_types(u, film_types)
    if film.n_atoms == 0:
        raise ValueError(f"no film atoms (type {' '.join(map(str, map(int, film_types)))}) "
                         f"in {topology}")
    return u, film, DensityProfile(film).run(step=step)
