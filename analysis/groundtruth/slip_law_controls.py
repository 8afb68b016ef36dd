"""Controls of the slip-law test: known laws at the MD's noise, and how often each verdict comes out.

A verdict is trusted once the method returns it for laws whose answer is known, at
the noise of the runs it is used on (:mod:`filmfriction.analysis.slip_law.slip_law`).  The
laws here are slid in the reduced model at the Klein-similar MD scene's scale
(``sfb-similar``: K = 2 ε/σ², M = 30 m, F_s = 48 ε/σ, sampled every 0.25 τ); the
drive is faster than the scene's 0.02 σ/τ (0.1, or 0.3 for the weakening law),
which shortens the sticks and leaves the slips (at ~1 σ/τ) nearly as they are.
Each replica's film pushes the wall with the MD's noise as a random force ξ = M·du/dt, u the
velocity noise of :data:`~.film_noise.MD_NOISE`
(:mod:`~filmfriction.analysis.groundtruth.random_force`; calibrated on the MD's slips, :mod:`~filmfriction.analysis.groundtruth.md_noise`): the wall's
position and velocity respond to it, as an MD wall's do, and the residual of the integrated
equation of motion over M, ∫ξ dt/M, is u. The slips are fitted as the driven analysis fits them, as
their mean (:func:`~filmfriction.analysis.slip_law.slip_law_cycles.fit_cycle_ensemble`, each slip
held at its end, the jackknife's errors over the slips); ``ensemble=False`` fits each slip on its
own, which fails the controls so: its regressors (Δx, and the branch split at the noisy peak
velocity) carry the noise of its response (at :data:`MD_NOISE` Klein's viscous slips come out
``mixed`` in 40 of 40 with 30 slips, decelerating B = 48 of 62 m/τ, F_k = 7.5 of 0 ε/σ; every other
law's loop step is resolved, +13 to +14 ε/σ). The rates of the mean: ``python
benchmarks/slip_law/slip_law_random_force.py --ensemble`` (docs/results/slip-law.md). The noise
added to the noise-free law's trace instead (``injected=True``: the spring force carries M·du/dt,
the motion is the law's; :func:`replica_fits`, fitted slip by slip) is kept as the comparison.

``coulomb``      Coulomb, F_s = 48, F_k = 36 ε/σ (B = 0; with the random force F_k while
                 slipping, whatever the sign of a recoil)
``rate-state``   Dieterich–Ruina aging law, μ0 = 36, a = 1, b = 4 ε/σ, d_c = 1 σ, v0 = 0.1 σ/τ
``weakening``    exponential weakening 48 → 25 ε/σ over 1 σ/τ
``viscous``      Klein's Eq. 1 with ζ = 4 (B = 62 m/τ), the re-stick imposed at
                 F_b = 24 ε/σ, as in his trace

:func:`coulomb_viscous` makes slips resisted by F_k + B·v of any viscous share, re-sticking
as Klein's (the power: the smallest share the test resolves).

Example
-------
>>> rates = verdict_rates("coulomb", replicas=2, slips=3)
>>> sorted(rates) == sorted(VERDICTS) and sum(rates.values()) == 2
True
"""
from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field
from functools import lru_cache, partial

import numpy as np

from filmfriction.reduced_model import SpringBlock, laws
from filmfriction.reduced_model.cycles import cycle_table

from ..slip_law.slip_law import VERDICTS, FilmForceFit, fit_film_force
from ..slip_law.slip_law_cycles import MD_NOISE_TIME, fit_cycle_ensemble
from ..stickslip import detect_slips
from .film_noise import (K4M3E3_REGISTRY_NOISE, K16M3E3_REGISTRY_NOISE, LIGHT_NOISE,
                         LIGHT_REGISTRY_NOISE, M1E4_NOISE, M1E4_REGISTRY_NOISE,
                         M25E3_REGISTRY_NOISE, M3E3_NOISE, M3E3_REGISTRY_NOISE, MD_NOISE,
                         STIFF_NOISE, STIFF_REGISTRY_NOISE)
from .random_force import LOOP_LAWS, slide
from .synthetic import block_trace, klein_trace, with_wall_noise

__all__ = ["SCALE", "Scale", "SCALES", "scale_named", "CONTROLS",
           "control_trace", "coulomb_viscous", "replica_fits",
           "random_force_runs", "dynamical_fits", "control_fits", "verdict_rates", "RATE_STATE_CREEP"]

#: The Klein-similar scene's slider and sampling (LJ units).
SCALE = {"spring_constant": 2.0, "mass": 30.0, "dt": 0.25, "static_force": 48.0}

@dataclass(frozen=True)
class Scale:
    """A slider's scale for the random-force controls: its spring, wall mass, mount dashpot
    (γM, force per velocity) and sampling, the film's noise calibrated to the MD there, and
    the controls' laws (the keywords of
    :func:`~filmfriction.analysis.groundtruth.random_force.slide` and ``period``, a slip
    cycle's length or a little more).  ``laws`` maps a control's name to them; ``mix``
    gives the Coulomb + viscous laws of any viscous share: the film force ``film_force``
    at ``slip_velocity`` split F_k = (1 − share)·F, B = share·F/v, and the rest of the
    keywords.  ``chunk``: replicas slid at a time (memory), 0 all at once.  ``film_mass``:
    the mass of the MD film the scale stands for (its atoms, 1 m each), which the fits are
    given as the MD's are (the most a co-moving mass can be); None: not given.
    ``registry_noise``: the film's noise beside the walls' registry force, for controls that
    carry one (:mod:`~filmfriction.analysis.groundtruth.film_noise`); None: not calibrated."""

    name: str
    spring_constant: float
    mass: float
    dt: float
    static_force: float
    drive_velocity: float
    noise: dict
    laws: dict = field(default_factory=dict)
    mix: dict = field(default_factory=dict)
    mount_damping: float = 0.0
    chunk: int = 0
    film_mass: float | None = None
    registry_noise: dict | None = None

    def law(self, name: str, share: float | None = None,
            weakening: tuple[float, float] | None = None, law: str = "melting",
            lag: float | None = None) -> dict:
        """The arguments of :func:`~filmfriction.analysis.groundtruth.random_force.slide` for
        control ``name`` (or the Coulomb + viscous law of viscous ``share``) at this scale:
        the law, its yield and re-stick, and ``period``, a slip cycle's length or a little
        more.  ``weakening`` = (w, D), with ``share``: that mix with a yield loop of ``law``
        (``melting``: the kinetic force higher at the yield by w times its parameter slot,
        fading over the fastest velocity D; ``slip-weakening``: over the slip distance D;
        ``maxwell``: over the time D, the viscous force lagging the velocity by D too;
        :func:`~filmfriction.analysis.groundtruth.pooled_controls.pooled_runs` makes the
        slot ΔF = w·(F_s − F_k) of each run's yield force F_s).  ``lag`` = τ_r: the viscous
        force lagging by τ_r (``maxwell``, w 0; with a ``slip-weakening`` loop,
        ``maxwell-weakening``)."""
        base = {"static_force": self.static_force, "drive_velocity": self.drive_velocity}
        if share is not None:
            if not 0 <= share <= 1:
                raise ValueError(f"share = {share!r}: must be in [0, 1]")
            m = dict(self.mix)
            f, v = m.pop("film_force"), m.pop("slip_velocity")
            par = ((1 - share) * f, share * f / v)
            if lag is not None and not (math.isfinite(lag) and lag > 0):
                raise ValueError(f"lag = {lag!r}: a relaxation time > 0, finite")
            if weakening is None:
                return {**base, **({"law": "maxwell", "parameters": par + (0.0, float(lag))}
                                   if lag else {"law": "coulomb-viscous", "parameters": par}), **m}
            df, dc = (float(w) for w in weakening)
            if not (0 <= df <= 1 and math.isfinite(dc) and dc > 0):
                raise ValueError(f"weakening = {weakening!r}: w in [0, 1] (a share of the "
                                 "yield's excess over F_k) and D > 0, finite")
            if law not in LOOP_LAWS or (lag and law != "slip-weakening"):
                raise ValueError(f"law = {law!r}: one of {', '.join(LOOP_LAWS)}"
                                 + (f"; with lag = {lag!r}, slip-weakening" if lag else ""))
            return {**base, **({"law": "maxwell-weakening", "parameters": par + (df, dc, lag)}
                               if lag else {"law": law, "parameters": par + (df, dc)}), **m}
        if weakening is not None or lag is not None:
            raise ValueError(f"weakening = {weakening!r}, lag = {lag!r}: only with a viscous "
                             "share")
        if name not in self.laws:
            raise ValueError(f"control {name!r} at the {self.name} scale: one of "
                             f"{', '.join(self.laws)}")
        # a law's own yield force or drive (the Klein-similar scale's weakening law is
        # driven faster) overrides the scale's
        return {**base, **self.laws[name]}


#: The heavy slider's scale, the scene ``sfb-thick-stiff`` (K = 8 ε/σ², M = 10⁵ m, V = 0.0025
#: σ/τ, the mount dashpot γ = 0.00034 /τ, i.e. γM = 34 m/τ, sampled every 0.25 τ; static
#: forces 30–60, F_k ≈ 25 ε/σ, slips of 300–1 000 τ at 0.007–0.02 σ/τ).  Its controls:
#:
#: ``coulomb``  F_s = 45, F_k = 25 ε/σ (F_k + 0·v on every sample), re-sticking where the
#:              wall stops (a noise-free slip: 351 τ, 5 σ, to F_b = 5 ε/σ)
#: ``weakening`` exponential weakening F_s = 45 → F_k = 25 ε/σ over v_c = 0.01 σ/τ (noise-free a
#:              slip of 489 τ, 0.021 σ/τ peak, to F_b = 12.7; decelerating B = −430 m/τ)
#: ``viscous``  Klein's Eq. 1 with ζ = B/(2√(KM)) = 1 (B = 1 789 m/τ, Eq. (1)'s Bingham
#:              number of the runs: 32–87), re-stick imposed at F_b = STIFF_BACKWARD
#: mixes        F_k + B·v of viscous share s of F = 27 ε/σ at 0.017 σ/τ (the runs' F̄ and v̄),
#:              re-sticking at F_b = STIFF_BACKWARD or once slowed to STIFF_STOP
STIFF_B = 2.0 * math.sqrt(8.0 * 1e5)
STIFF_BACKWARD = 8.0
STIFF_STOP = 0.004

#: The K = 8 film's slider at M = 10⁴ m, the rung of the mass ladder whose pooled slips are
#: ``kinetic`` (K = 8 ε/σ², V = 0.0079 σ/τ, the mount dashpot γ = 0.00107 /τ, i.e. γM = 10.7
#: m/τ, sampled every 0.25 τ; static forces ≈ 45 (34–58), re-stick forces ≈ 16 (10–22) ε/σ,
#: slips of 50–400 τ, median 115, at ≈ 0.045 σ/τ; F̄ 31.7, F_k ≈ 27 ε/σ).  Its controls, as
#: the stiff scale's with √(M/K) √10 shorter:
#:
#: ``coulomb``  F_s = 45, F_k = 27 ε/σ (F_k + 0·v on every sample), re-sticking where the
#:              wall stops (noise-free a slip of 120 τ at 0.044 σ/τ mean, 0.070 peak, to
#:              F_b = 10.0 ε/σ; a cycle of 673 τ)
#: ``weakening`` exponential weakening F_s = 45 → F_k = 27 ε/σ over v_c = 0.03 σ/τ (the stiff
#:              scale's 0.01 times the slips' speed-up, 0.045/0.017; noise-free a slip of
#:              155 τ, 0.061 σ/τ peak, to F_b = 16.1; a cycle of 612 τ)
#: ``viscous``  Klein's Eq. 1 with ζ = B/(2√(KM)) = 1 (B = 566 m/τ), re-stick imposed at
#:              F_b = M1E4_BACKWARD (the MD runs' re-stick force; noise-free a slip of 97 τ
#:              at 0.047 σ/τ mean, 0.060 peak; a cycle of 573 τ)
#: mixes        F_k + B·v of viscous share s of F = 32 ε/σ at 0.045 σ/τ (the runs' F̄ and v̄),
#:              re-sticking at F_b = M1E4_BACKWARD or once slowed to M1E4_STOP (the stiff
#:              scale's 0.004 times 0.045/0.017; noise-free cycles of 535 and 612 τ at
#:              shares 0.3 and 0.6), once the spring force is below 27 ε/σ (as at the stiff
#:              scale, 4.5 ε/σ below the lowest yield force of the pooled controls' runs,
#:              45 × 0.7: a slip from there is not ended by the noise at once)
#:
#: ``period``: the noise-free slip cycle's length (measured on :func:`random_force_runs`'
#: noise-free runs) or a little more.
M1E4_B = 2.0 * math.sqrt(8.0 * 1e4)
M1E4_BACKWARD = 15.0
M1E4_STOP = 0.011

#: The K = 8 film's light sliders, M = 10² and 10³ m (V = 0.079 and 0.025 σ/τ, the mount
#: dashpots γM = 1.07 and 3.4 m/τ, sampled every 0.25 τ; yields ≈ 57 and 50 ε/σ, re-sticks
#: ≈ 20 and 22 ε/σ, slips at ≈ 0.34 and 0.11 σ/τ; F̄ 40 and 35 ε/σ), where the film's
#: co-moving mass is comparable with M (the one law reads 179 and 243 m).  Their controls as
#: the M = 10⁴ scale's, √(M/K) shorter; the mixes' F at v̄ are the runs' F̄ and v̄, the stop
#: velocity a quarter of v̄, armed 4.5 ε/σ below the lowest yield of pooled runs whose yields
#: spread by ± 20 % (the MD's runs: 47–66 ε/σ at M = 10², 10–90 %).
#: The Coulomb control's F_k is 8 ε/σ under F̄ (as the M = 10⁴ scale's 27 is 5 under its 32),
#: re-sticking where the wall stops.  The noise: :data:`LIGHT_NOISE`.
#: M = 3×10³ (V = 0.0144 σ/τ, γM = 5.88 m/τ; yields ≈ 46 (34–60), re-sticks ≈ 20 (14–26)
#: ε/σ, slips of 65 τ (46–120) at ≈ 0.061 σ/τ; F̄ 33.5 ε/σ: the rung's eight runs, 10–90 %),
#: the rung between, as these, with its own noise (:data:`~.film_noise.M3E3_NOISE`).
#: ``m25e3``: M = 2.5×10³ (V = 0.0158 σ/τ, γM = 5.375 m/τ; yields ≈ 47 (36–59), re-sticks
#: ≈ 19 (10–25) ε/σ, slips of 64 τ (42–108) at ≈ 0.076 σ/τ; F̄ 32.2 ε/σ: that rung's sixteen
#: runs), its noise beside the registry calibrated on them, alone the M = 3×10³ rung's.
#: ``k16m3e3``: the M = 3×10³ slider on a spring twice as stiff, K = 16 (V = 0.0102 σ/τ,
#: γM = 8.31 m/τ; yields ≈ 52 (36–61), re-sticks ≈ 14 (7–21) ε/σ, slips of 49 τ (34–87) at
#: ≈ 0.058 σ/τ; F̄ 33.3 ε/σ: that rung's eight runs, 10–90 %), its noise beside the registry
#: calibrated on them (:data:`~.film_noise.K16M3E3_REGISTRY_NOISE`), alone the K = 8 rung's.
#: ``k4m3e3``: the same slider on a spring half as stiff, K = 4 (V = 0.0144 σ/τ, γM = 4.16
#: m/τ; yields ≈ 45 (32–56), re-sticks ≈ 23 (17–28) ε/σ, slips of 90 τ (51–154) and 6.5 σ
#: (2.8–11) at ≈ 0.079 σ/τ; F̄ 33.4 ε/σ: that rung's sixteen runs, their start-up slips
#: among them; without them yields ≈ 42), its noise calibrated on
#: them against its mix of share 0.3 (the rung's viscous share; the others' is 0.5), one
#: period for every law, the Coulomb control's cycle (750 τ) the longest.
#: Their viscous controls: Klein's Eq. 1 with ζ = 1, B = 2√(KM).
#:
#: The mass of the six-layer film of ``sfb-thick-stiff`` and the K = 8 mass ladder's rungs
#: (336 atoms, 1 m each), and of the Klein-similar scene's (224).
THICK_FILM_MASS, KLEIN_FILM_MASS = 336.0, 224.0


def _light_scale(name, mass, velocity, damping, static, backward, force, slip_velocity,
                 armed, period, noise=None, registry_noise=None,
                 spring_constant=8.0) -> Scale:
    return Scale(
        name, spring_constant, mass, 0.25, static, velocity, noise or LIGHT_NOISE[mass],
        laws={"coulomb": dict(law="linear", parameters=(force - 8.0, 0.0),
                              armed_below=force - 8.0, initial_force=backward, period=period),
              "viscous": dict(law="linear",
                              parameters=(0.0, 2.0 * math.sqrt(spring_constant * mass)),
                              backward_force=backward, stop_velocity=-math.inf,
                              initial_force=backward, period=period)},
        mix=dict(film_force=force, slip_velocity=slip_velocity, backward_force=backward,
                 stop_velocity=slip_velocity / 4, armed_below=armed, initial_force=backward,
                 period=period),
        mount_damping=damping, chunk=10, film_mass=THICK_FILM_MASS,
        registry_noise=registry_noise or LIGHT_REGISTRY_NOISE.get(mass))


#: The scales of the random-force controls, by name.
#: The controls' laws as the random-force slider integrates them: the rate-and-state slider
#: yields from, and re-sticks at, this velocity (σ/τ).
RATE_STATE_CREEP = 0.01

SCALES = {
    "klein": Scale(
        "klein", SCALE["spring_constant"], SCALE["mass"], SCALE["dt"], SCALE["static_force"],
        0.1, MD_NOISE,
        # Coulomb: F_k while slipping, whatever the sign of a recoil the random force gives
        # the wall: the law is F_k + 0·v on every sample (F_k·sign(v) would make the
        # noise-averaged force grow with v, a law of its own: docs/results/slip-law.md)
        laws={"coulomb": dict(law="linear", parameters=(36.0, 0.0), armed_below=36.0,
                              period=135.0),
              "weakening": dict(law="weakening", parameters=(25.0, 48.0, 1.0), armed_below=27.5,
                                drive_velocity=0.3, period=90.0),
              "viscous": dict(law="linear",
                              parameters=(0.0, 2 * 4.0 * math.sqrt(SCALE["spring_constant"]
                                                                 * SCALE["mass"])),
                              backward_force=24.0, stop_velocity=-math.inf, initial_force=24.0,
                              period=150.0),
              # the rate-and-state slider yields where its law's force at the creep
              # velocity and the aged state is reached: no yield force of its own
              "rate-state": dict(law="rate-state", parameters=(36.0, 1.0, 4.0, 1.0, 0.1),
                                 static_force=math.inf, start_velocity=RATE_STATE_CREEP,
                                 stop_velocity=RATE_STATE_CREEP, armed_below=30.5,
                                 initial_force=36.0, period=180.0)},
        mix=dict(film_force=28.0, slip_velocity=0.55, backward_force=20.0, stop_velocity=0.15,
                 armed_below=34.0, initial_force=20.0, period=150.0),
        film_mass=KLEIN_FILM_MASS),
    "stiff": Scale(
        "stiff", 8.0, 1e5, 0.25, 45.0, 0.0025,
        STIFF_NOISE,
        laws={"coulomb": dict(law="linear", parameters=(25.0, 0.0), armed_below=25.0,
                              initial_force=5.0, period=2400.0),
              "weakening": dict(law="weakening", parameters=(25.0, 45.0, 0.01),
                                armed_below=27.0, initial_force=5.0, period=2200.0),
              "viscous": dict(law="linear", parameters=(0.0, STIFF_B),
                              backward_force=STIFF_BACKWARD, stop_velocity=-math.inf,
                              initial_force=STIFF_BACKWARD, period=2300.0)},
        mix=dict(film_force=27.0, slip_velocity=0.017, backward_force=STIFF_BACKWARD,
                 stop_velocity=STIFF_STOP, armed_below=27.0, initial_force=STIFF_BACKWARD,
                 period=2500.0),
        mount_damping=34.0, chunk=10, film_mass=THICK_FILM_MASS,
        registry_noise=STIFF_REGISTRY_NOISE),
    "m1e4": Scale(
        "m1e4", 8.0, 1e4, 0.25, 45.0, 0.0079,
        M1E4_NOISE,
        laws={"coulomb": dict(law="linear", parameters=(27.0, 0.0), armed_below=27.0,
                              initial_force=9.0, period=700.0),
              "weakening": dict(law="weakening", parameters=(27.0, 45.0, 0.03),
                                armed_below=29.0, initial_force=9.0, period=650.0),
              "viscous": dict(law="linear", parameters=(0.0, M1E4_B),
                              backward_force=M1E4_BACKWARD, stop_velocity=-math.inf,
                              initial_force=M1E4_BACKWARD, period=600.0)},
        mix=dict(film_force=32.0, slip_velocity=0.045, backward_force=M1E4_BACKWARD,
                 stop_velocity=M1E4_STOP, armed_below=27.0, initial_force=M1E4_BACKWARD,
                 period=700.0),
        mount_damping=10.7, chunk=10, film_mass=THICK_FILM_MASS,
        registry_noise=M1E4_REGISTRY_NOISE),
    "m1e2": _light_scale("m1e2", 1e2, 0.079, 1.07, 57.0, 20.0, 40.0, 0.34, 41.0, 100.0),
    "m1e3": _light_scale("m1e3", 1e3, 0.025, 3.4, 50.0, 22.0, 35.0, 0.11, 35.5, 250.0),
    "m3e3": _light_scale("m3e3", 3e3, 0.0144, 5.88, 46.0, 20.0, 33.5, 0.061, 32.3, 420.0,
                         M3E3_NOISE, M3E3_REGISTRY_NOISE),
    "m25e3": _light_scale("m25e3", 2.5e3, 0.0158, 5.375, 47.0, 19.0, 32.2, 0.076, 33.1, 420.0,
                          M3E3_NOISE, M25E3_REGISTRY_NOISE),
    "k16m3e3": _light_scale("k16m3e3", 3e3, 0.0102, 8.31, 52.0, 14.0, 33.3, 0.058, 37.1,
                            400.0, M3E3_NOISE, K16M3E3_REGISTRY_NOISE, spring_constant=16.0),
    "k4m3e3": _light_scale("k4m3e3", 3e3, 0.0144, 4.158, 45.0, 23.0, 33.4, 0.079, 31.5,
                           900.0, M3E3_NOISE, K4M3E3_REGISTRY_NOISE, spring_constant=4.0),
}


def scale_named(scale) -> Scale:
    """The :class:`Scale` ``scale`` names (a key of :data:`SCALES`), or ``scale`` itself.

    >>> scale_named("stiff").spring_constant
    8.0
    """
    if isinstance(scale, Scale):
        return scale
    if scale not in SCALES:
        raise ValueError(f"scale {scale!r}: one of {', '.join(SCALES)}")
    return SCALES[scale]


#: Control name -> what it is.
CONTROLS = {
    "coulomb": "Coulomb F_s = 48, F_k = 36 ε/σ (V = 0.1 σ/τ)",
    "rate-state": "rate-and-state (aging), μ0 = 36, a = 1, b = 4 ε/σ, d_c = 1 σ, v0 = 0.1 σ/τ "
                  "(V = 0.1 σ/τ)",
    "weakening": "exponential weakening F_s = 48 → F_k = 25 ε/σ over 1 σ/τ (V = 0.3 σ/τ)",
    "viscous": "Klein's Eq. 1, ζ = 4 (B = 62 m/τ), re-stick at F_b = 24 ε/σ (V = 0.1 σ/τ)",
}
_PERIOD = {"coulomb": 125.0, "rate-state": 190.0, "weakening": 90.0, "viscous": 140.0}


def _block(law, drive_velocity, damping=0.0) -> SpringBlock:
    return SpringBlock(mass=SCALE["mass"], stiffness=SCALE["spring_constant"],
                       drive_velocity=drive_velocity, damping=damping, law=law)


def coulomb_viscous(share: float, *, slips: int = 8, film_force: float | None = None,
                    slip_velocity: float | None = None) -> dict:
    """Slips resisted by F_k + B·v whose viscous part is ``share`` of ``film_force`` at
    ``slip_velocity`` (the MD's mean film force and slip velocity: the Klein-similar
    scale's mix, 28 ε/σ at 0.55 σ/τ, by default), re-sticking at F_b = 20 ε/σ (the MD's)
    or once slowed to 0.15 σ/τ (a law with F_k would otherwise slide on), noise-free,
    ``slips`` + 1 slips."""
    if not 0 <= share <= 1:
        raise ValueError(f"share = {share!r}: must be in [0, 1]")
    s, mix = SCALE, SCALES["klein"].mix
    film_force = mix["film_force"] if film_force is None else film_force
    slip_velocity = mix["slip_velocity"] if slip_velocity is None else slip_velocity
    return klein_trace(spring_constant=s["spring_constant"], mass=s["mass"],
                       damping=share * film_force / slip_velocity,
                       kinetic_force=(1 - share) * film_force,
                       drive_velocity=SCALES["klein"].drive_velocity,
                       static_force=s["static_force"], backward_force=mix["backward_force"],
                       restick_velocity=mix["stop_velocity"], cycles=slips + 1, dt=s["dt"])


@lru_cache(maxsize=16)
def _noise_free(name: str, slips: int):
    # the laws the random-force slider integrates (SCALES["klein"]), as the reduced
    # model's spring-block slides them
    if name not in CONTROLS:
        raise ValueError(f"control {name!r}: one of {', '.join(CONTROLS)}")
    s, law = SCALE, SCALES["klein"].law(name)
    v, p = law["drive_velocity"], law["parameters"]
    duration = (slips + 2.5) * _PERIOD[name]
    if name == "coulomb":
        tr = block_trace(_block(laws.Coulomb(static=law["static_force"], kinetic=p[0]), v),
                         duration, s["dt"])
    elif name == "rate-state":
        law = laws.RateState(mu0=p[0], a=p[1], b=p[2], dc=p[3], v0=p[4])
        tr = block_trace(_block(law, v), duration, s["dt"], initial_velocity=0.05)
    elif name == "weakening":
        law = laws.ExponentialWeakening(static=p[1], kinetic=p[0], velocity_scale=p[2])
        tr = block_trace(_block(law, v), duration, s["dt"])
    else:                                          # viscous
        tr = klein_trace(spring_constant=s["spring_constant"], mass=s["mass"], damping=p[1],
                         drive_velocity=v, static_force=law["static_force"],
                         backward_force=law["backward_force"], cycles=slips + 1, dt=s["dt"])
    return {k: np.asarray(a, float) for k, a in tr.items()}


def control_trace(name: str, slips: int = 8) -> dict:
    """The noise-free trace of control ``name`` (one of :data:`CONTROLS`), with at least
    ``slips`` slips after the start-up one."""
    return dict(_noise_free(name, int(slips)))


def replica_fits(trace: dict, replicas: int, *, slips: int | None = None,
                 drive_velocity: float = 0.1, noise: dict | None = None, seed: int = 0,
                 **fit) -> list[FilmForceFit]:
    """The slip-law fit of ``replicas`` noisy copies of ``trace`` (MD noise by default).

    The slips are found on the noise-free spring force (the detector is not under
    test here); the start-up slip is left out and the next ``slips`` (all: None)
    are fitted; ``fit`` goes to :func:`~filmfriction.analysis.slip_law.slip_law.fit_film_force`.
    """
    noise = MD_NOISE if noise is None else noise
    t, f = trace["time"], trace["spring_force"]
    v = np.asarray(trace["wall_velocity"], float)
    ev = detect_slips(t, f)
    tab = cycle_table(t, f, ev.yield_index, ev.stick_index,
                      spring_constant=SCALE["spring_constant"],
                      wall_position=trace.get("wall_position"))
    tab = tab[1:] if slips is None else tab[1:slips + 1]
    out = []
    for k in range(replicas):
        # the noise as a random force of the film whose impulse over M is the velocity
        # noise: it enters the integrated equation of motion as M·u whatever is fitted
        u = with_wall_noise(trace, seed=seed + k, **noise)["wall_velocity"] - v
        force = np.asarray(f, float) + SCALE["mass"] * np.gradient(u, t)
        out.append(fit_film_force(t, force, v, tab,
                                  mass=SCALE["mass"], drive_velocity=drive_velocity,
                                  wall_position=trace.get("wall_position"), **fit))
    return out


def random_force_runs(name: str, replicas: int, *, slips: int = 8, duration: float | None = None,
                      noise: dict | None = None, seed: int = 0, share: float | None = None,
                      scale: str | Scale = "klein",
                      comoving_mass: float = 0.0) -> tuple[list[dict], float]:
    """``replicas`` runs of control ``name`` (or of :func:`coulomb_viscous`'s law of viscous
    ``share``) at ``scale`` whose film pushes the wall with ``noise`` (the scale's
    calibrated noise, :data:`MD_NOISE` at the Klein-similar one, by default) as a random
    force (:func:`~filmfriction.analysis.groundtruth.random_force.slide`; the film carrying
    ``comoving_mass`` with the slipping wall), long enough for ``slips`` slips after the
    start-up one (or ``duration`` long), and the law's drive velocity."""
    sc = scale_named(scale)
    noise = sc.noise if noise is None else noise
    law = sc.law(name, share)
    period = law.pop("period")
    duration = (slips + 3) * period * 1.3 if duration is None else duration
    runs = slide(**law, mass=sc.mass, stiffness=sc.spring_constant, duration=duration,
                 dt=sc.dt, replicas=replicas, seed=seed, mount_damping=sc.mount_damping,
                 comoving_mass=comoving_mass, **noise)
    return runs, law["drive_velocity"]


def dynamical_fits(name: str, replicas: int, slips: int = 8, *, noise: dict | None = None,
                   seed: int = 0, share: float | None = None, ensemble: bool = True,
                   unfitted: bool = False, scale: str | Scale = "klein",
                   **fit) -> list[FilmForceFit | None]:
    """The slip-law fit of ``replicas`` runs of control ``name`` whose film pushes the wall
    with the MD's noise as a random force (:mod:`~filmfriction.analysis.groundtruth.random_force`):
    the wall's position and velocity respond to it, as an MD wall's do.

    With ``share`` the law is :func:`coulomb_viscous`'s of that viscous share (``name``
    is then ignored).  The slips are the slider's own (its yields and re-sticks: the
    detector is not under test); the start-up slip is left out and the next ``slips``
    fitted by the cycle ensemble
    (:func:`~filmfriction.analysis.slip_law.slip_law_cycles.fit_cycle_ensemble`, the
    driven analysis's fit) or, with ``ensemble=False``, slip by slip
    (:func:`~filmfriction.analysis.slip_law.slip_law.fit_film_force`); ``fit`` goes to
    the one called.  With ``unfitted`` a replica the fit refuses (too few slips in the
    run, at a large noise) is None in the list; else its error is raised.  At ``scale``
    (a name of :data:`SCALES` or a :class:`Scale`; its mount dashpot is the slider's and
    the fit's) the replicas are slid ``Scale.chunk`` at a time, chunk j from the seed
    (``seed``, j) (at the Klein-similar scale all at once from ``seed``).
    """
    sc = scale_named(scale)
    fitter = (partial(fit_cycle_ensemble, min_window_time=MD_NOISE_TIME) if ensemble
              else fit_film_force)
    if sc.mount_damping:
        fitter = partial(fitter, mount_damping=sc.mount_damping)
    chunks = ([(replicas, seed)] if not sc.chunk else
              [(min(sc.chunk, replicas - a), (seed, j))
               for j, a in enumerate(range(0, replicas, sc.chunk))])
    out = []
    for n, sd in chunks:
        runs, velocity = random_force_runs(name, n, slips=slips, noise=noise, seed=sd,
                                           share=share, scale=sc)
        for tr in runs:
            t, f = tr["time"], tr["spring_force"]
            tab = cycle_table(t, f, tr["yield_index"], tr["stick_index"],
                              spring_constant=sc.spring_constant,
                              wall_position=tr["wall_position"])[1:slips + 1]
            try:
                out.append(fitter(t, f, tr["wall_velocity"], tab, mass=sc.mass,
                                  drive_velocity=velocity, film_mass=sc.film_mass,
                                  wall_position=tr["wall_position"], **fit))
            except ValueError:
                if not unfitted:
                    raise
                out.append(None)
        del runs
    return out


def control_fits(name: str, replicas: int = 40, slips: int = 8, *, injected: bool = False,
                 **kwargs) -> list[FilmForceFit]:
    """The fits of ``replicas`` noisy runs of control ``name`` (``slips`` slips fitted):
    the noise a random force that moves the wall (:func:`dynamical_fits`), or with
    ``injected`` added to the noise-free law's trace (:func:`replica_fits`); ``kwargs``
    go to the one called."""
    if injected:
        return replica_fits(control_trace(name, slips), replicas, slips=slips,
                            drive_velocity=SCALES["klein"].law(name)["drive_velocity"],
                            **kwargs)
    return dynamical_fits(name, replicas, slips, **kwargs)


def verdict_rates(name: str, replicas: int = 40, slips: int = 8, **kwargs) -> dict[str, int]:
    """How many of ``replicas`` noisy copies of control ``name`` (``slips`` slips fitted)
    get each verdict."""
    counts = Counter(f.verdict for f in control_fits(name, replicas, slips, **kwargs))
    return {v: counts.get(v, 0) for v in VERDICTS}
