"""Amontons-Coulomb friction, with a viscous term: the law with a closed form.

``SpringBlock.simulate(method="auto")`` solves it exactly (``reduced_model/integrators/closed_form.py``,
through :meth:`Coulomb.closed_form`); ``freeze_velocity`` and ``shear_stiffness``
exist in that closed form only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .base import FrictionLaw, at_least, non_negative

__all__ = ["Coulomb"]


@dataclass(frozen=True)
class Coulomb(FrictionLaw):
    """Amontons-Coulomb friction: static threshold, constant kinetic friction.

    Parameters
    ----------
    static : float
        Static coefficient mu_s (force = mu_s N), >= kinetic.
    kinetic : float
        Kinetic coefficient mu_k >= 0.
    viscous : float, optional
        Extra viscous friction while slipping, force per unit slip velocity
        (Coulomb + viscous; still solved in closed form).
    freeze_velocity : float, optional
        The contact re-solidifies when the slip velocity falls to this value
        (0: only when the block comes to rest on the surface).  An overdamped
        slip (viscous + damping >= 2 sqrt(K M)) never comes to rest: a film
        that freezes while still moving (a confined film re-crystallising)
        needs this rule to stick again.  The kinetic energy the block still
        has relative to the surface is dissipated by the freezing film.
        Closed form only.
    shear_stiffness : float, optional
        Elastic shear stiffness of the stuck contact, force per displacement
        (inf: rigid).  A solid-like film strains before it yields: the block
        creeps while stuck and the force rises at K k_f/(K + k_f) times the
        drive, not K.  The elastic energy is released as heat when the film
        melts at breakaway.  Closed form only.

    Example
    -------
    >>> Coulomb(static=1.0, kinetic=0.5, viscous=0.1).closed_form(2.0)
    (2.0, 1.0, 0.1)
    """

    static: float
    kinetic: float
    viscous: float = 0.0
    freeze_velocity: float = 0.0
    shear_stiffness: float = math.inf

    def __post_init__(self):
        non_negative("Coulomb.kinetic", self.kinetic, "a friction coefficient")
        non_negative("Coulomb.viscous", self.viscous, "negative viscous friction would feed energy")
        non_negative("Coulomb.freeze_velocity", self.freeze_velocity,
                     "a slip speed at which the film re-solidifies")
        if not self.shear_stiffness > 0.0:
            raise ValueError(f"Coulomb.shear_stiffness = {self.shear_stiffness!r}: allowed range "
                             "is (0, inf] (a stiffness; inf = a rigid contact)")
        non_negative("Coulomb.static", self.static, "a friction coefficient")
        at_least("Coulomb.static", self.static, "kinetic", self.kinetic,
                 "static friction below kinetic would make the block stick while the kinetic "
                 "force exceeds the load")

    @classmethod
    def example(cls):
        return cls(static=1.0, kinetic=0.5, viscous=0.1)

    @classmethod
    def invalid_examples(cls):
        return [{"kinetic": -0.1}, {"viscous": -0.1}, {"freeze_velocity": -1.0},
                {"shear_stiffness": 0.0}, {"static": -1.0}, {"static": 0.4}]

    def sliding_force(self, speed, state, normal_load):
        return self.kinetic * normal_load + self.viscous * speed

    def static_force(self, state, normal_load):
        return self.static * normal_load

    def closed_form(self, normal_load):
        return (self.static * normal_load, self.kinetic * normal_load, self.viscous)
