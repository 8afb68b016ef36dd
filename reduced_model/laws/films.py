"""Confined films: Newtonian and shear-thinning drag, optionally solid at rest.

The Newtonian film (Klein's ``B = A eta / D``) has a closed form; the
shear-thinning films take the ODE path.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .base import FrictionLaw, non_negative, in_range, positive

__all__ = ["newtonian_damping", "carreau_viscosity", "NewtonianFilm", "ShearThinningFilm",
           "ThinningFilmWithSliding"]


def newtonian_damping(area, viscosity, thickness):
    """B = A η / D: drag per unit slip velocity of a Newtonian film with no-slip walls.

    Klein's damping (PRL 98, 056101, Eq. 1); any consistent units.

    Example
    -------
    >>> round(newtonian_damping(4e-10, 27.0, 3.5e-9), 4)      # Klein's B, N s/m
    3.0857
    """
    return area * viscosity / thickness


def carreau_viscosity(viscosity, shear_rate, onset_rate, exponent):
    """Carreau law ``eta0 (1 + (rate/onset_rate)**2) ** (-exponent/2)``.

    Newtonian (``eta0``) below the onset rate, ``eta ~ rate**-exponent`` above it.

    Example
    -------
    >>> carreau_viscosity(8.0, 1.0, 1.0, 2.0)     # at the onset: eta0 / 2**(n/2)
    4.0
    """
    return viscosity * (1.0 + (shear_rate / onset_rate) ** 2) ** (-0.5 * exponent)


@dataclass(frozen=True)
class NewtonianFilm(FrictionLaw):
    """Newtonian film of viscosity eta, contact area A, thickness D (Klein, seed 004).

    Slip friction ``B s`` with ``B = A eta / D``, independent of the load.  With
    ``yield_force`` the film is solid at rest and holds up to that force (the
    yield point y of the SFB trace); without it the law is purely viscous.
    Solved in closed form.

    Example
    -------
    >>> film = NewtonianFilm(viscosity=27.0, area=4e-10, thickness=3.5e-9)
    >>> round(film.drag_coefficient, 4)
    3.0857
    """

    viscosity: float
    area: float
    thickness: float
    yield_force: float | None = None

    def __post_init__(self):
        positive("NewtonianFilm.viscosity", self.viscosity, "film viscosity")
        positive("NewtonianFilm.area", self.area, "contact area")
        positive("NewtonianFilm.thickness", self.thickness, "film thickness D in B = A eta / D")
        if self.yield_force is not None:
            non_negative("NewtonianFilm.yield_force", self.yield_force, "force the solid film holds at rest")

    @classmethod
    def example(cls):
        return cls(viscosity=0.2, area=1.0, thickness=1.0, yield_force=1.0)

    @classmethod
    def invalid_examples(cls):
        return [{"viscosity": 0.0}, {"area": -1.0}, {"thickness": 0.0}, {"yield_force": -1.0}]

    @property
    def drag_coefficient(self) -> float:
        """B = A eta / D, force per unit slip velocity."""
        return newtonian_damping(self.area, self.viscosity, self.thickness)

    def sliding_force(self, speed, state, normal_load):
        return self.drag_coefficient * speed

    def low_speed_drag(self):
        return self.drag_coefficient

    def friction(self, s, state, normal_load):
        return self.drag_coefficient * s

    def static_force(self, state, normal_load):
        return self.yield_force

    def closed_form(self, normal_load):
        return (self.yield_force, 0.0, self.drag_coefficient)

    def quasi_static_speed(self, force, state, normal_load):
        return force / self.drag_coefficient


#: the shear-thinning films' example() (a block with M = K = 1, driven at V = 0.1)
_EXAMPLE_FILM = dict(viscosity=0.5, area=1.0, thickness=1.0, exponent=0.6, onset_rate=0.05)


@dataclass(frozen=True)
class ShearThinningFilm(FrictionLaw):
    """Shear-thinning film: eta falls as a power of the shear rate gamma = s / D.

    ``eta(gamma) = eta0 (1 + (gamma/onset_rate)**2) ** (-exponent/2)`` (Carreau
    form): Newtonian below the onset rate, ``eta ~ gamma**-exponent`` above it
    (Thompson, Grest & Robbins report exponents ~2/3 for glassy films).  The
    friction is ``A eta gamma``; it keeps rising with speed for exponent < 1.

    Example
    -------
    >>> film = ShearThinningFilm(viscosity=27.0, area=4e-10, thickness=3.5e-9,
    ...                          exponent=2/3, onset_rate=1e3)
    >>> film.sliding_force(0.0, (), 1.0)
    0.0
    """

    viscosity: float
    area: float
    thickness: float
    exponent: float = 2.0 / 3.0
    onset_rate: float = 1.0
    yield_force: float | None = None

    def __post_init__(self):
        positive("ShearThinningFilm.viscosity", self.viscosity, "zero-shear film viscosity")
        positive("ShearThinningFilm.area", self.area, "contact area")
        positive("ShearThinningFilm.thickness", self.thickness, "film thickness")
        in_range("ShearThinningFilm.exponent", self.exponent, 0.0, 1.0,
                 "measured confined films lie between 0 (Newtonian) and 1 (solid-like); "
                 "exponent 1 would make friction independent of speed", high_open=True)
        positive("ShearThinningFilm.onset_rate", self.onset_rate, "shear rate where thinning starts")
        if self.yield_force is not None:
            non_negative("ShearThinningFilm.yield_force", self.yield_force, "force the solid film holds at rest")

    @classmethod
    def example(cls):
        return cls(**_EXAMPLE_FILM, yield_force=1.0)

    @classmethod
    def invalid_examples(cls):
        return [{"viscosity": 0.0}, {"area": 0.0}, {"thickness": -1.0}, {"exponent": 1.0},
                {"exponent": -0.1}, {"onset_rate": 0.0}, {"yield_force": -1.0}]

    def low_speed_drag(self):
        return newtonian_damping(self.area, self.viscosity, self.thickness)

    def viscosity_at(self, shear_rate):
        """Effective viscosity at the given shear rate (:func:`carreau_viscosity`)."""
        return carreau_viscosity(self.viscosity, shear_rate, self.onset_rate, self.exponent)

    def sliding_force(self, speed, state, normal_load):
        rate = speed / self.thickness
        return self.area * self.viscosity_at(rate) * rate

    def friction(self, s, state, normal_load):
        rate = s / self.thickness
        return self.area * self.viscosity_at(abs(rate)) * rate

    def static_force(self, state, normal_load):
        return self.yield_force


@dataclass(frozen=True)
class ThinningFilmWithSliding(ShearThinningFilm):
    """Shear-thinning film that also carries a rate-independent sliding force.

    Friction ``sign(s) kinetic + A eta(gamma) gamma`` while sliding; at rest the
    film holds up to ``kinetic`` (so a block released below it stays put).  The
    MD film carried to the SFB (a molten film dragging over the walls'
    corrugation) in :mod:`filmfriction.reduced_model.sfb.md_calibration`.

    Example
    -------
    >>> film = ThinningFilmWithSliding(viscosity=27.0, area=4e-10, thickness=3.5e-9,
    ...                                exponent=0.5, onset_rate=1e3, kinetic=2e-6)
    >>> film.static_force((), 1.0), film.sliding_force(0.0, (), 1.0)
    (2e-06, 2e-06)
    """

    kinetic: float = 0.0

    def __post_init__(self):
        super().__post_init__()
        non_negative("ThinningFilmWithSliding.kinetic", self.kinetic, "a sliding force")

    @classmethod
    def example(cls):
        return cls(**_EXAMPLE_FILM, kinetic=0.5)

    @classmethod
    def invalid_examples(cls):
        return super().invalid_examples() + [{"kinetic": -0.1}]

    def sliding_force(self, speed, state, normal_load):
        return self.kinetic + super().sliding_force(speed, state, normal_load)

    def friction(self, s, state, normal_load):
        return (math.copysign(self.kinetic, s) if s else 0.0) + super().friction(s, state, normal_load)

    def static_force(self, state, normal_load):
        return self.kinetic
