"""Friction laws for the spring-block model, one small frozen dataclass each.

One law (or one family) a file: ``coulomb.py``, ``stribeck.py`` (the
velocity-weakening curves), ``films.py`` (Newtonian and shear-thinning films),
``contact_age.py``, ``rate_state.py``, ``lubricated.py``; the interface, the
conventions every law follows and the registry are in ``base.py``.

Every module of this package is imported here, and every law it defines is
re-exported under its class name (``laws.Coulomb``), so adding a law is one
file: a :class:`FrictionLaw` subclass with ``example()`` and
``invalid_examples()``, which registers itself in :data:`REGISTRY`; the
contract test (``tests/reduced_model/test_law_contract.py``) then runs it
through the energy ledger, validation and the closed-form/ODE comparison.

Example
-------
>>> from filmfriction.reduced_model import laws
>>> law = laws.Coulomb(static=1.0, kinetic=0.5)
>>> law.static_force(law.steady_state(0.0), 1.0), law.sliding_force(2.0, (), 1.0)
(1.0, 0.5)
>>> laws.REGISTRY["Coulomb"] is laws.Coulomb and laws.Coulomb in laws.registered()
True
"""
from __future__ import annotations

import importlib
import pkgutil
from typing import TYPE_CHECKING

from .base import REGISTRY, FrictionLaw, registered
from .films import carreau_viscosity, newtonian_damping

if TYPE_CHECKING:
    # the laws by name for type checkers, which do not run the registration below
    # (tests/reduced_model/test_law_contract.py checks this list is every law)
    from .contact_age import ContactAge
    from .coulomb import Coulomb
    from .films import NewtonianFilm, ShearThinningFilm, ThinningFilmWithSliding
    from .lubricated import LubricatedFilm
    from .rate_state import RateState
    from .stribeck import ExponentialWeakening, StribeckExponential, StribeckSchnelle


def _import_every_module() -> dict[str, type[FrictionLaw]]:
    """Import each module of the package (its laws register); return the laws it defines."""
    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")
    return {name: cls for name, cls in REGISTRY.items() if cls.__module__.startswith(f"{__name__}.")}


_LAWS = _import_every_module()
globals().update(_LAWS)

__all__ = ["FrictionLaw", "REGISTRY", "registered", *sorted(_LAWS),
           "newtonian_damping", "carreau_viscosity"]
