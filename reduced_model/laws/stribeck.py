"""Velocity-weakening dry friction: static threshold, friction falling with slip speed.

Three stateless curves (the exponential Stribeck curve, Schnelle's form, plain
exponential weakening).  None has a closed form: the ODE path integrates the
slips, on the fast DOP853 path for stateless laws with static friction.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .base import FrictionLaw, scalar_exp, at_least, in_range, non_negative, positive

__all__ = ["StribeckExponential", "StribeckSchnelle", "ExponentialWeakening"]


@dataclass(frozen=True)
class StribeckExponential(FrictionLaw):
    """Standard exponential Stribeck curve.

    ``F(v) = N [mu_k + (mu_s - mu_k) exp(-(v/v_s)**shape)] + viscous * v``,
    static threshold ``mu_s N``.

    Example
    -------
    >>> law = StribeckExponential(static=0.4, kinetic=0.25, stribeck_velocity=0.01)
    >>> round(law.sliding_force(1.0, (), 1.0), 6)
    0.25
    """

    static: float
    kinetic: float
    stribeck_velocity: float
    shape: float = 2.0
    viscous: float = 0.0

    def __post_init__(self):
        non_negative("StribeckExponential.kinetic", self.kinetic, "a friction coefficient")
        at_least("StribeckExponential.static", self.static, "kinetic", self.kinetic,
                 "static friction is the v -> 0 limit of a weakening curve")
        positive("StribeckExponential.stribeck_velocity", self.stribeck_velocity,
                 "the velocity scale of the weakening")
        in_range("StribeckExponential.shape", self.shape, 0.0, 10.0, "exponent of the Stribeck decay",
                 low_open=True)
        non_negative("StribeckExponential.viscous", self.viscous, "negative viscous friction would feed energy")

    @classmethod
    def example(cls):
        return cls(static=1.0, kinetic=0.5, stribeck_velocity=0.05)

    @classmethod
    def invalid_examples(cls):
        return [{"kinetic": -0.1}, {"static": 0.4}, {"stribeck_velocity": 0.0}, {"shape": 0.0},
                {"shape": 11.0}, {"viscous": -0.1}]

    def sliding_force(self, speed, state, normal_load):
        if isinstance(speed, float):     # scalar fast path: the ODE right-hand side
            drop = (self.static - self.kinetic) * math.exp(-(speed / self.stribeck_velocity) ** self.shape)
        else:
            drop = (self.static - self.kinetic) * np.exp(-(np.asarray(speed) / self.stribeck_velocity) ** self.shape)
        return normal_load * (self.kinetic + drop) + self.viscous * speed

    def scalar_sliding(self, normal_load):
        n_k, n_drop = normal_load * self.kinetic, normal_load * (self.static - self.kinetic)
        inv_vs, shape, viscous, exp = 1.0 / self.stribeck_velocity, self.shape, self.viscous, math.exp
        if shape == 2.0:
            def force(speed):
                w = speed * inv_vs
                return n_k + n_drop * exp(-w * w) + viscous * speed
        else:
            def force(speed):
                return n_k + n_drop * exp(-(speed * inv_vs) ** shape) + viscous * speed
        return force

    def static_force(self, state, normal_load):
        return self.static * normal_load


@dataclass(frozen=True)
class StribeckSchnelle(FrictionLaw):
    """Stribeck curve in Schnelle's seven-coefficient form (seed 003).

    ``mu(v) = g [exp(-a v**b) + (1 - exp(-c v**d)) e v**f]``: boundary friction
    ``g`` at rest decaying with ``a, b``, a hydrodynamic rise ``e v**f`` switched
    on by ``c, d``.  The printed formula in the seed is garbled; this is our
    reconstruction from its seven "shaping coefficients a to g" -- check the
    thesis before quoting coefficients from it.  Static threshold ``g N``.

    Example
    -------
    >>> law = StribeckSchnelle()
    >>> law.static_force((), 1.0)
    0.4
    """

    a: float = 20.0
    b: float = 1.0
    c: float = 5.0
    d: float = 1.0
    e: float = 0.5
    f: float = 1.0
    g: float = 0.4

    def __post_init__(self):
        for name in "abcdef":
            non_negative(f"StribeckSchnelle.{name}", getattr(self, name), "shaping coefficient of the curve")
        positive("StribeckSchnelle.g", self.g, "the friction coefficient at rest")

    @classmethod
    def example(cls):
        return cls()

    @classmethod
    def invalid_examples(cls):
        return [{name: -1.0} for name in "abcdef"] + [{"g": 0.0}]

    def sliding_force(self, speed, state, normal_load):
        v = speed if isinstance(speed, float) else np.asarray(speed, dtype=float)
        mu = self.g * (scalar_exp(-self.a * v ** self.b)
                       + (1.0 - scalar_exp(-self.c * v ** self.d)) * self.e * v ** self.f)
        return normal_load * mu

    def static_force(self, state, normal_load):
        return self.g * normal_load


@dataclass(frozen=True)
class ExponentialWeakening(FrictionLaw):
    """Exponential velocity weakening (seed 002): ``F = N [mu_k + (mu_s - mu_k) exp(-v/v_c)]``.

    With ``kinetic=0`` and ``velocity_scale=1`` (SI) this is the seed's
    ``m g mu_static exp(-v)``.

    Example
    -------
    >>> round(ExponentialWeakening(static=0.4).sliding_force(1.0, (), 1.0), 4)
    0.1472
    """

    static: float
    kinetic: float = 0.0
    velocity_scale: float = 1.0

    def __post_init__(self):
        non_negative("ExponentialWeakening.kinetic", self.kinetic, "a friction coefficient")
        at_least("ExponentialWeakening.static", self.static, "kinetic", self.kinetic,
                 "the curve weakens from static to kinetic")
        positive("ExponentialWeakening.velocity_scale", self.velocity_scale, "the weakening velocity")

    @classmethod
    def example(cls):
        return cls(static=1.0, kinetic=0.5, velocity_scale=0.1)

    @classmethod
    def invalid_examples(cls):
        return [{"kinetic": -0.1}, {"static": 0.4}, {"velocity_scale": 0.0}]

    def sliding_force(self, speed, state, normal_load):
        return normal_load * (self.kinetic + (self.static - self.kinetic)
                              * scalar_exp(-speed / self.velocity_scale))

    def static_force(self, state, normal_load):
        return self.static * normal_load
