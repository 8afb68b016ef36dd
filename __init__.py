"""filmfriction: molecular-dynamics studies of friction in confined films.

One import name for the whole toolkit; its parts are the project's folders:

* :mod:`filmfriction.md_inputs` — the LAMMPS scripts and their output contract;
* :mod:`filmfriction.reduced_model` — spring-block models, units, Klein's SFB model;
* :mod:`filmfriction.analysis` — stick-slip traces, energy, viscosity, structure,
  calibration of the reduced model;
* :mod:`filmfriction.workflows` — scenes, runs, sweeps, reports and the command line.

Example
-------
>>> import filmfriction
>>> from filmfriction.reduced_model import SpringBlock, laws
>>> isinstance(filmfriction.__version__, str)
True
"""
from importlib import metadata as _metadata

try:
    __version__ = _metadata.version("filmfriction")
except _metadata.PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"

__all__ = ["__version__"]
