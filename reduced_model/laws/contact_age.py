"""The contact-age law: static friction that strengthens while the contact rests."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .base import FrictionLaw, at_least, non_negative, positive

__all__ = ["ContactAge"]


@dataclass(frozen=True)
class ContactAge(FrictionLaw):
    """Contact-age model of Heslot, Baumberger and Persson (seed 000, Braun).

    ``F = N [f_b + (f_s - f_b)(1 - exp(-phi/age_time))]`` with the contact age
    ``phi' = 1 - |s| phi / memory_length``: at rest phi grows like time (static
    friction strengthens from f_b to f_s), in steady sliding phi = a_phi / v.
    The static threshold while stuck is the same expression.

    Example
    -------
    >>> law = ContactAge(static=1.0, backward=0.5, age_time=1.0, memory_length=0.1)
    >>> float(law.steady_state(0.1)[0])
    1.0
    """

    static: float
    backward: float
    age_time: float
    memory_length: float
    state_names = ("contact_age",)

    def __post_init__(self):
        non_negative("ContactAge.backward", self.backward, "friction coefficient of a fresh contact")
        at_least("ContactAge.static", self.static, "backward", self.backward,
                 "contacts strengthen with age")
        positive("ContactAge.age_time", self.age_time, "ageing time tau of the static friction")
        positive("ContactAge.memory_length", self.memory_length, "slip distance a_phi that renews contacts")

    @classmethod
    def example(cls):
        return cls(static=1.0, backward=0.5, age_time=1.0, memory_length=0.05)

    @classmethod
    def invalid_examples(cls):
        return [{"backward": -0.1}, {"static": 0.4}, {"age_time": 0.0}, {"memory_length": -1.0}]

    def _force(self, age, normal_load):
        return normal_load * (self.backward + (self.static - self.backward)
                              * -np.expm1(-np.maximum(age, 0.0) / self.age_time))

    def steady_state(self, speed):
        # capped: beyond ~50 ageing times the threshold is saturated anyway
        cap = 50.0 * self.age_time
        age = cap if speed <= self.memory_length / cap else self.memory_length / speed
        return np.array([age])

    def sliding_force(self, speed, state, normal_load):
        return self._force(state[0], normal_load)

    def state_rate(self, speed, state):
        return np.array([1.0 - speed * state[0] / self.memory_length])

    def static_force(self, state, normal_load):
        return float(self._force(state[0], normal_load))

    def stick_state(self, state, elapsed):
        return np.array([state[0] + elapsed])

    def stick_timescale(self):
        return self.age_time

    def state_relaxation_rate(self, speed):
        return speed / self.memory_length

    def critical_velocity(self, stiffness: float, normal_load: float = 1.0) -> float:
        """Persson's estimate ``v_c ~ (1/K) dF_s/dt|_0 = N (f_s - f_b) / (K tau)``.

        Stick-slip below, smooth sliding above (order of magnitude: the map in
        :mod:`filmfriction.reduced_model.maps` gives the boundary the model really has).
        """
        k = positive("stiffness", stiffness, "spring constant")
        return normal_load * (self.static - self.backward) / (k * self.age_time)
