"""Lubricated friction with the film thickness as state (boundary to full film)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .base import FrictionLaw, finite, in_range, non_negative, positive

__all__ = ["LubricatedFilm"]


@dataclass(frozen=True)
class LubricatedFilm(FrictionLaw):
    """Lubricated friction with film thickness as state (Perret-Liaudet & Majdoub, seed 001).

    ``T = (1 - alpha(y)) mu N sign(v) + alpha(y) eta N |v|**p sign(v)``,
    ``y' = (Y_ss(v) - y)/tau``, ``alpha(y) = 1/(1 + exp(-(y - y_c)/w))`` rising
    from 0 (boundary) to 1 (full film).  The paper leaves ``Y_ss`` open; we
    take an EHL-like power law ``Y_ss = film_scale (|v|/velocity_scale)**q``.
    At rest the boundary part is a static threshold ``(1 - alpha(y)) mu N``.

    Example
    -------
    >>> law = LubricatedFilm(boundary=0.3, hydrodynamic=0.05)
    >>> law.static_force(law.steady_state(0.0), 1.0) < 0.3
    True
    """

    boundary: float
    hydrodynamic: float
    power: float = 1.0
    relaxation_time: float = 0.1
    film_scale: float = 1.0
    velocity_scale: float = 1.0
    thickness_exponent: float = 0.67
    transition_thickness: float = 0.5
    transition_width: float = 0.1
    state_names = ("film_thickness",)

    def __post_init__(self):
        non_negative("LubricatedFilm.boundary", self.boundary, "boundary friction coefficient mu")
        non_negative("LubricatedFilm.hydrodynamic", self.hydrodynamic, "film friction coefficient eta")
        in_range("LubricatedFilm.power", self.power, 0.0, 3.0, "exponent p of the film friction", low_open=True)
        positive("LubricatedFilm.relaxation_time", self.relaxation_time, "film relaxation time tau")
        positive("LubricatedFilm.film_scale", self.film_scale, "film thickness at velocity_scale")
        positive("LubricatedFilm.velocity_scale", self.velocity_scale, "velocity scale of Y_ss")
        positive("LubricatedFilm.thickness_exponent", self.thickness_exponent, "exponent q of Y_ss")
        finite("LubricatedFilm.transition_thickness", self.transition_thickness)
        positive("LubricatedFilm.transition_width", self.transition_width, "width of the sigmoid alpha(y)")

    @classmethod
    def example(cls):
        return cls(boundary=1.0, hydrodynamic=0.3)

    @classmethod
    def invalid_examples(cls):
        return [{"boundary": -0.1}, {"hydrodynamic": -0.1}, {"power": 0.0}, {"power": 3.5},
                {"relaxation_time": -1.0}, {"film_scale": 0.0}, {"velocity_scale": 0.0},
                {"thickness_exponent": 0.0}, {"transition_thickness": float("inf")},
                {"transition_width": 0.0}]

    def film_fraction(self, y):
        """alpha(y): share of the load carried by the film."""
        return 0.5 * (1.0 + np.tanh(0.5 * (y - self.transition_thickness) / self.transition_width))

    def steady_thickness(self, speed):
        """Y_ss(|v|)."""
        return self.film_scale * (speed / self.velocity_scale) ** self.thickness_exponent

    def steady_state(self, speed):
        return np.array([float(self.steady_thickness(speed))])

    def sliding_force(self, speed, state, normal_load):
        alpha = self.film_fraction(state[0])
        return normal_load * ((1.0 - alpha) * self.boundary + alpha * self.hydrodynamic * speed ** self.power)

    def state_rate(self, speed, state):
        return np.array([(self.steady_thickness(speed) - state[0]) / self.relaxation_time])

    def static_force(self, state, normal_load):
        return float(normal_load * (1.0 - self.film_fraction(state[0])) * self.boundary)

    def stick_state(self, state, elapsed):
        # at rest Y_ss = 0: the film drains exponentially
        return np.array([state[0] * math.exp(-elapsed / self.relaxation_time)])

    def stick_timescale(self):
        return self.relaxation_time

    def state_relaxation_rate(self, speed):
        return 1.0 / self.relaxation_time
