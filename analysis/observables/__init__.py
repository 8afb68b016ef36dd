"""Observables: sections of ``analysis.json`` and of the report, one file each.

Every section of the analysis is an observable: ``slips.py`` (the cycles in
Klein's notation and the force trace), ``energy.py`` (the energy partition and
the run's ledger), ``sliding.py`` (the time-averaged friction over the last half),
``viscosity.py`` (steady, per slip, from the velocity profile), ``structure.py``
(layers, ψ6 and the gap from the trajectory) and ``slip_law.py`` (Klein's slip
equation fitted on the slips).  The analysis
(:func:`filmfriction.analysis.analyze.analyze`) finds the slips and decides the
regime, then runs every registered observable in its ``order``; the report
renders each with one generic function.

Every module of this package is imported here, so adding an observable is one
file: an :class:`Observable` subclass (``base.py`` has the interface) that
declares its ``key``, ``title`` and ``needs`` and defines ``compute`` (and, for
the report, ``rows``, ``notes``, ``figure``); its class statement registers it
in :data:`REGISTRY`.  The contract test
(``tests/analysis/observables/test_observable_contract.py``) runs every registered one on a
synthetic run directory, with each of its needs taken away, and through the
report.

Example
-------
>>> from filmfriction.analysis import observables
>>> "slip_law" in observables.REGISTRY
True
>>> law = observables.REGISTRY["slip_law"]()
>>> [need.label for need in law.needs]
['wall_velocity', '--mass']
"""
from __future__ import annotations

import importlib
import pkgutil

from .observable import (REGISTRY, Context, MissingInput, Need, Observable, column, parameter,
                         registered)

__all__ = ["Observable", "Context", "Need", "MissingInput", "column", "parameter",
           "REGISTRY", "registered"]


def _import_every_module() -> None:
    """Import each module of the package: its observables register."""
    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")


_import_every_module()
