"""Structure of the confined film from a trajectory (MDAnalysis).

* :mod:`.layering` — :class:`~.layering.DensityProfile`: number density across the gap,
  layer count and spacing (peaks of the profile); :class:`~.layering.FilmThickness`: the
  gap between the walls' facing planes per frame (dilation at slip);
* :mod:`.hexatic` — :class:`~.hexatic.HexaticOrder`: in-plane bond-orientational order
  ψ6 of each layer per frame, to contrast stick (crystalline, |ψ6| high) with slip
  (shear melted, |ψ6| low), from a Verlet list of in-plane neighbours;
* :mod:`.slip_planes` — :class:`~.slip_planes.LayerDisplacement`: each layer's and each
  wall's mean position along the slide per frame; :func:`~.slip_planes.active_plane`: the
  plane (wall | layer or layer | layer) that carries the slide at each frame;
* :mod:`.trajectory_reader` — a run's DCD trajectory opened with times in τ, and its
  atoms picked by type.

All follow MDAnalysis conventions: ``AnalysisBase`` subclasses, results in
``.results``, ``run(start, stop, step, verbose=True)`` with a progress bar.
Velocity profiles come from ``fix ave/chunk`` files (see
:mod:`filmfriction.analysis.analyze`), not from trajectories (DCD holds positions only).
Lengths are in the trajectory's units (σ for an LJ run).

Atom types of a filmfriction run are the script's contract
(:mod:`filmfriction.md_inputs.contract`): the film, and each wall as all of
its types (its rigid part and, with ``wall_model = flexible``, its mobile
planes facing the film).  The structure section of ``analysis.json`` is built
from these by :mod:`filmfriction.analysis.observables.structure_section`.
"""
