"""Friction laws for the spring-block model, one small frozen dataclass each.

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

Adding a law is one class: subclass :class:`FrictionLaw` as a frozen dataclass
and implement ``sliding_force`` (plus the state methods if it has a state).

Example
-------
>>> from filmfriction.reduced_model import laws
>>> law = laws.Coulomb(static=1.0, kinetic=0.5)
>>> law.static_force(law.steady_state(0.0), 1.0), law.sliding_force(2.0, (), 1.0)
(1.0, 0.5)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._checks import at_least, finite, in_range, non_negative, positive

__all__ = [
    "FrictionLaw", "Coulomb", "StribeckExponential", "StribeckSchnelle",
    "ExponentialWeakening", "NewtonianFilm", "ShearThinningFilm", "ThinningFilmWithSliding",
    "ContactAge", "RateState", "LubricatedFilm", "newtonian_damping", "carreau_viscosity",
]

_EMPTY = np.empty(0)


def _exp(x):
    """math.exp on floats (the ODE hot loop: ~10x cheaper than numpy scalars), np.exp on arrays."""
    return math.exp(x) if isinstance(x, float) else np.exp(x)


class FrictionLaw:
    """Interface shared by all friction laws (defaults: stateless, no stick)."""

    state_names: tuple = ()
    #: friction so steep in v that explicit steps stall at low speed (use an implicit solver)
    stiff: bool = False

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

    def closed_form(self, normal_load):
        """``(static or None, kinetic, viscous)`` forces if the law is Coulomb + viscous."""
        return None

    def quasi_static_speed(self, force, state, normal_load):
        """Slip speed at which friction equals ``force`` (massless limit), or None."""
        return None


# ---------------------------------------------------------------------------
# Dry friction with a static threshold
# ---------------------------------------------------------------------------
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

    def sliding_force(self, speed, state, normal_load):
        return self.kinetic * normal_load + self.viscous * speed

    def static_force(self, state, normal_load):
        return self.static * normal_load

    def closed_form(self, normal_load):
        return (self.static * normal_load, self.kinetic * normal_load, self.viscous)


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

    def sliding_force(self, speed, state, normal_load):
        v = speed if isinstance(speed, float) else np.asarray(speed, dtype=float)
        mu = self.g * (_exp(-self.a * v ** self.b)
                       + (1.0 - _exp(-self.c * v ** self.d)) * self.e * v ** self.f)
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

    def sliding_force(self, speed, state, normal_load):
        return normal_load * (self.kinetic + (self.static - self.kinetic)
                              * _exp(-speed / self.velocity_scale))

    def static_force(self, state, normal_load):
        return self.static * normal_load


# ---------------------------------------------------------------------------
# Confined films
# ---------------------------------------------------------------------------
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
    corrugation) in :mod:`filmfriction.reduced_model.md_film`.

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

    def sliding_force(self, speed, state, normal_load):
        return self.kinetic + super().sliding_force(speed, state, normal_load)

    def friction(self, s, state, normal_load):
        return (math.copysign(self.kinetic, s) if s else 0.0) + super().friction(s, state, normal_load)

    def static_force(self, state, normal_load):
        return self.kinetic


# ---------------------------------------------------------------------------
# Laws with memory
# ---------------------------------------------------------------------------
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
