"""Dieterich-Ruina rate-and-state friction: smooth, stiff near rest, one state variable."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .base import FrictionLaw, non_negative, positive

__all__ = ["RateState", "state_rates"]


@dataclass(frozen=True)
class RateState(FrictionLaw):
    """Dieterich-Ruina rate-and-state friction with aging or slip evolution.

    ``mu = mu0 + a ln(v/v0) + b psi`` with the state kept in log form,
    ``psi = ln(v0 theta / dc)``:

    * aging (Dieterich): ``theta' = 1 - v theta/dc``  ->  ``psi' = (v0/dc) e^-psi - v/dc``
    * slip (Ruina):      ``theta' = -(v theta/dc) ln(v theta/dc)``  ->  ``psi' = -(v/dc)(ln(v/v0) + psi)``

    With ``regularized=True`` (default) ``mu = a asinh[v/(2 v0) exp((mu0 + b psi)/a)]``
    (Rice, Lapusta & Ranjith), identical to the log form for v >> v0 e^-(mu0/a) but
    defined through v = 0, so the inertial block may reverse.  No static
    threshold: the block never stops exactly.

    Example
    -------
    >>> law = RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-5, v0=1e-6)
    >>> round(float(law.sliding_force(1e-5, law.steady_state(1e-5), 1.0)), 6)   # mu0 + (a-b) ln 10
    0.588487
    """

    mu0: float
    a: float
    b: float
    dc: float
    v0: float
    evolution: str = "aging"
    regularized: bool = True
    state_names = ("log_state",)
    stiff = True        # dF/dv = a N / v: the inertial slider is stiff when nearly stuck

    def __post_init__(self):
        non_negative("RateState.mu0", self.mu0, "reference friction coefficient")
        positive("RateState.a", self.a, "direct-effect coefficient; a <= 0 is ill-posed")
        non_negative("RateState.b", self.b, "evolution-effect coefficient")
        positive("RateState.dc", self.dc, "critical slip distance")
        positive("RateState.v0", self.v0, "reference velocity")
        if self.evolution not in ("aging", "slip"):
            raise ValueError(f"RateState.evolution = {self.evolution!r}: allowed values are "
                             "'aging' (Dieterich) or 'slip' (Ruina)")

    @classmethod
    def example(cls):
        return cls(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1)

    @classmethod
    def invalid_examples(cls):
        return [{"mu0": -0.1}, {"a": 0.0}, {"b": -0.01}, {"dc": 0.0}, {"v0": -1.0},
                {"evolution": "slipping"}]

    def steady_state(self, speed):
        # floor the speed: at rest theta grows without bound; 1e-12 v0 is "long at rest"
        return np.array([math.log(self.v0 / max(speed, 1e-12 * self.v0))])

    def coefficient(self, s, psi):
        """Friction coefficient at slip velocity s (signed) and log state psi."""
        if not self.regularized:
            return self.mu0 + self.a * np.log(np.abs(s) / self.v0) + self.b * psi
        # asinh(z), z = s/(2 v0) exp(L), evaluated in log form to avoid overflow
        L = (self.mu0 + self.b * psi) / self.a
        z_abs = np.abs(s) / (2.0 * self.v0)
        with np.errstate(divide="ignore"):
            logz = np.log(z_abs) + L
        big = logz > 30.0
        mag = np.where(big, logz + math.log(2.0), np.arcsinh(np.exp(np.minimum(logz, 30.0))))
        return self.a * np.sign(s) * mag

    def sliding_force(self, speed, state, normal_load):
        return normal_load * self.coefficient(speed, state[0])

    def friction(self, s, state, normal_load):
        return normal_load * float(self.coefficient(s, state[0]))

    def state_rate(self, speed, state):
        psi = state[0]
        if self.evolution == "aging":
            return np.array([(self.v0 / self.dc) * math.exp(-psi) - speed / self.dc])
        if speed <= 0.0:
            return np.array([0.0])
        return np.array([-(speed / self.dc) * (math.log(speed / self.v0) + psi)])

    def rate_parameters(self, normal_load):
        """The parameters of :func:`state_rates`: (N, mu0, a, b, v0, dc, aging, regularized)
        as a tuple of floats (the flags 1.0 or 0.0)."""
        return tuple(float(c) for c in (normal_load, self.mu0, self.a, self.b, self.v0, self.dc,
                                        self.evolution == "aging", self.regularized))

    def scalar_state_rates(self, normal_load):
        """The friction and the state rate on plain floats (:func:`state_rates`, the
        formula the compiled fast path runs); the same law as :meth:`coefficient` and
        :meth:`state_rate`."""
        params = self.rate_parameters(normal_load)

        def rates(s, state):
            friction, rate = state_rates(s, state[0], params)
            return friction, [rate]
        return rates

    def outside_domain(self, t, slip_velocity):
        """The log form (``regularized=False``) holds for forward slip only: as v -> 0+
        its friction falls without bound, so an exact solution never stops, but a
        creep below what float64 and the integrator resolve may still step to v <= 0."""
        if self.regularized or slip_velocity.size == 0:
            return None
        backward = np.flatnonzero(~(slip_velocity > 0.0))
        if backward.size == 0:
            return None
        return (f"RateState(regularized=False): the slip velocity fell to 0 at t = "
                f"{t[backward[0]]:.6g} (lowest {np.min(slip_velocity):.3g}); the log form holds for "
                "v > 0 only, so the run past that point does not follow the law. Use "
                "regularized=True (defined through v = 0).")

    def theta(self, state):
        """The state variable theta = (dc / v0) exp(psi) [time] of a (n_state, ...) state array."""
        return (self.dc / self.v0) * np.exp(np.asarray(state, dtype=float)[0])

    def state_relaxation_rate(self, speed):
        return speed / self.dc

    def quasi_static_speed(self, force, state, normal_load):
        if normal_load <= 0.0:
            return None
        tau = force / normal_load
        L = (self.mu0 + self.b * state[0]) / self.a
        if not self.regularized:
            return self.v0 * math.exp(tau / self.a - L)
        x = abs(tau) / self.a
        # 2 v0 e^-L sinh(x), without overflow
        return math.copysign(self.v0 * (math.exp(x - L) - math.exp(-x - L)), tau)

    def critical_stiffness(self, normal_load: float = 1.0, mass: float = 0.0, velocity: float = 0.0) -> float:
        """``k_c = N (b - a)/dc [1 + M V^2 / (N a dc)]`` (Ruina 1983 for M -> 0).

        Below k_c steady sliding at V is unstable (stick-slip); k_c <= 0 when
        the law is velocity strengthening (b <= a).
        """
        n = positive("normal_load", normal_load, "the critical stiffness scales with the normal load")
        m = non_negative("mass", mass, "block mass")
        return n * (self.b - self.a) / self.dc * (1.0 + m * velocity ** 2 / (n * self.a * self.dc))


def state_rates(s, psi, params):
    """Friction force and d psi/dt at slip velocity ``s`` and log state ``psi``.

    ``params`` is :meth:`RateState.rate_parameters`.  Plain float arithmetic with
    ``math`` only, so that :mod:`..smooth_steps` compiles this very function
    (numba) for the ODE's hot loop: one formula for both paths."""
    N, mu0, a, b, v0, dc, aging, regularized = params
    speed = -s if s < 0.0 else s
    if regularized == 0.0:
        mu = mu0 + a * math.log(speed / v0) + b * psi
    elif speed == 0.0:
        mu = 0.0
    else:
        # asinh(z), z = speed/(2 v0) exp((mu0 + b psi)/a), in log form past z = e^30
        logz = math.log(speed / (2.0 * v0)) + (mu0 + b * psi) / a
        mu = a * (logz + math.log(2.0) if logz > 30.0 else math.asinh(math.exp(logz)))
        if s < 0.0:
            mu = -mu
    if aging != 0.0:
        rate = (v0 / dc) * math.exp(-psi) - speed / dc
    elif speed > 0.0:
        rate = -(speed / dc) * (math.log(speed / v0) + psi)
    else:
        rate = 0.0
    return N * mu, rate
