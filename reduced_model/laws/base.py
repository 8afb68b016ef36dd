"""The friction-law interface, the registry, and what the laws share.

Conventions (all laws)
----------------------
* ``s`` is the slip velocity of the block relative to the surface under it.
  The friction force on the block is ``-sign(s) * sliding_force(|s|, state, N)``.
* Dry-friction parameters (``static``, ``kinetic``, ``backward``, ``mu0`` ...)
  are *coefficients*: the force is coefficient x normal load ``N``.  With the
  block's default ``normal_load=1`` they are the forces themselves.  Viscous
  parameters (``viscous``, film viscosity x area / thickness) are absolute:
  force per unit velocity, independent of ``N``.
* Units are whatever consistent set the caller uses (SI or LJ).
* A law with ``static_force(...)`` not ``None`` has a true stick phase: while
  stuck the block moves with the surface and friction is whatever reaction keeps
  it there, up to the static threshold.  Laws without static friction are
  smooth (friction continuous through ``s = 0``) and are integrated as one ODE.
* Laws with an internal state (contact age, film thickness, rate-and-state
  theta) expose ``state_names``, ``state_rate`` and ``stick_state`` (the state
  after sticking for a given time, in closed form).

Registry
--------
Every subclass of :class:`FrictionLaw` registers itself under its class name
in :data:`REGISTRY` when its class statement runs (``__init_subclass__``): a
law in this package, or a user's law in a file of their own, alike.  A
subclass that is not a law of its own (a helper base, a deliberately broken
variant in a test) opts out with ``class X(FrictionLaw, register=False)``.
Each law declares what the contract test
(``tests/reduced_model/test_law_contract.py``) needs to build and refuse it:
``example()`` and ``invalid_examples()``.

The validation helpers (:func:`positive`, :func:`non_negative`,
:func:`at_least`, :func:`in_range`, :func:`finite`) are importable from here
for a law's ``__post_init__``.
"""
from __future__ import annotations

import math

import numpy as np

from .._checks import at_least, finite, in_range, non_negative, positive

__all__ = ["FrictionLaw", "REGISTRY", "registered",
           "at_least", "finite", "in_range", "non_negative", "positive"]

#: class name -> law class, for every registered :class:`FrictionLaw` subclass
REGISTRY: dict[str, type[FrictionLaw]] = {}

_EMPTY = np.empty(0)


def registered() -> tuple[type[FrictionLaw], ...]:
    """Every registered law class, sorted by name."""
    return tuple(REGISTRY[name] for name in sorted(REGISTRY))


def _register(cls) -> None:
    name = cls.__name__
    other = REGISTRY.get(name)
    if other is not None and (other.__module__, other.__qualname__) != (cls.__module__, cls.__qualname__):
        raise TypeError(f"friction law {name!r} ({cls.__module__}) is already registered by "
                        f"{other.__module__}.{other.__qualname__}: rename the class, or define it "
                        "with register=False")
    REGISTRY[name] = cls      # (the same class statement run again, e.g. a reload, replaces it)


def scalar_exp(x):
    """math.exp on floats (the ODE hot loop: ~10x cheaper than numpy scalars), np.exp on arrays."""
    return math.exp(x) if isinstance(x, float) else np.exp(x)


class FrictionLaw:
    """Interface shared by all friction laws (defaults: stateless, no stick)."""

    state_names: tuple = ()
    #: friction so steep in v that explicit steps stall at low speed (use an implicit solver)
    stiff: bool = False

    def __init_subclass__(cls, register: bool = True, **kwargs):
        super().__init_subclass__(**kwargs)
        if register:
            _register(cls)

    # -- the contract: what the contract test builds and refuses ---------------
    @classmethod
    def example(cls) -> FrictionLaw:
        """An instance with typical parameters for a block with M = K = N = 1 driven at
        V = 0.1: stick-slip, or a smooth oscillation, within ~100 time units."""
        raise NotImplementedError(f"{cls.__name__}.example(): every registered law declares one")

    @classmethod
    def invalid_examples(cls) -> list[dict]:
        """Parameter changes to :meth:`example` that the constructor must refuse, one dict
        each (``{"kinetic": -0.1}``); the ValueError names the parameter first."""
        raise NotImplementedError(f"{cls.__name__}.invalid_examples(): every registered law "
                                  "declares what it refuses")

    # -- sliding -----------------------------------------------------------
    def sliding_force(self, speed, state, normal_load):
        """Friction magnitude when sliding at ``speed = |s| >= 0``."""
        raise NotImplementedError

    def friction(self, s, state, normal_load):
        """Signed friction (opposes ``s``); smooth laws are odd in ``s``."""
        return math.copysign(1.0, s) * self.sliding_force(abs(s), state, normal_load) if s else 0.0

    # -- state -------------------------------------------------------------
    def steady_state(self, speed: float) -> np.ndarray:
        """State reached after sliding steadily at ``speed`` (initial default)."""
        return _EMPTY

    def state_rate(self, speed, state) -> np.ndarray:
        """Time derivative of the state while sliding at ``speed``."""
        return _EMPTY

    # -- sticking ----------------------------------------------------------
    def static_force(self, state, normal_load):
        """Largest friction the contact can hold at rest, or ``None`` (smooth law)."""
        return None

    def stick_state(self, state, elapsed: float) -> np.ndarray:
        """State after ``elapsed`` time at rest (closed form)."""
        return np.asarray(state, dtype=float)

    def stick_timescale(self):
        """Time over which the static threshold changes while stuck (None: constant)."""
        return None

    def state_relaxation_rate(self, speed: float) -> float:
        """Rate (1/time) at which the state relaxes when sliding at ``speed`` (0: no state)."""
        return 0.0

    def low_speed_drag(self) -> float:
        """dF/dv at small slip speed (force per velocity); large values make the slip stiff."""
        return 0.0

    # -- fast paths --------------------------------------------------------
    def scalar_sliding(self, normal_load):
        """``speed -> sliding_force(speed, (), normal_load)`` for a stateless law on
        Python floats (the ODE hot loop calls it at every evaluation); laws may
        return a specialised closure, which must agree with ``sliding_force``."""
        sliding = self.sliding_force

        def force(speed):
            return sliding(speed, (), normal_load)
        return force

    def scalar_state_rates(self, normal_load):
        """``(s, state) -> (friction(s, state, N), state_rate(|s|, state))`` on Python floats
        (``state`` a sequence, the rates a list), for a smooth law with one state variable,
        or ``None``.

        A cheap evaluation of the law for scalar work (the right-hand side of the general
        ODE path, the fast path's damping check in ``reduced_model/integrators/limit_cycle.py``,
        benchmarks); it must agree with ``friction`` and
        ``state_rate`` (the contract test checks it).  The compiled fast path itself is
        rate-and-state's (``reduced_model/integrators/smooth_steps.py``)."""
        return None

    def closed_form(self, normal_load):
        """``(static or None, kinetic, viscous)`` forces if the law is Coulomb + viscous.

        Not ``None`` means ``SpringBlock.simulate(method="auto")`` takes the closed
        form (``reduced_model/integrators/closed_form.py``) instead of the ODE path."""
        return None

    def outside_domain(self, t, slip_velocity):
        """A message if a run's slip velocities (at times ``t``) left where the law holds,
        else ``None``; ``simulate`` turns it into a warning."""
        return None

    def quasi_static_speed(self, force, state, normal_load):
        """Slip speed at which friction equals ``force`` (massless limit), or None."""
        return None
