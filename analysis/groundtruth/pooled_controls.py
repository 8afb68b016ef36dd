"""Controls of the slip law pooled over runs: known laws, several runs of each, and how often
each verdict comes out and how often the errors cover the truth.

The pooled fit (:mod:`~filmfriction.analysis.slip_law.slip_law_pooled`) is the mean of the
slips of G runs with the jackknife over the runs.  Each control replica here is G runs of
one law at a scale of :data:`~filmfriction.analysis.groundtruth.slip_law_controls.SCALES`
(the heavy slider's by default), slid by the random-force slider
(:func:`~filmfriction.analysis.groundtruth.random_force.slide`) with the scale's noise,
each run with its own noise and, as the MD's runs of one scene, its own yield force
(``static_spread``: uniform within ± that share of the scale's; the MD's six K = 8 runs
yield at 30–60 ε/σ) and, with ``law_spread``, its own film (the law's parameters times
1 + law_spread·z, z standard normal per run: runs that differ by more than their noise,
whose mean law is the truth).  The slips are the slider's own (the detector is not under
test); each run's start-up slip is left out and its next ``slips`` fitted.

Example
-------
>>> fits = pooled_fits("viscous", replicas=1, runs=3, slips=3)
>>> fits[0].law.slips, fits[0].law.reason.count("runs")
(3, 1)
"""
from __future__ import annotations

import math

import numpy as np

from filmfriction.reduced_model.cycles import cycle_table

from ..slip_law.slip_law import FilmForceFit
from ..slip_law.slip_law_cycles import MD_NOISE_TIME
from ..slip_law.slip_law_pooled import RunSlips, fit_pooled_ensemble
from .random_force import LOOP_LAWS, slide
from .slip_law_controls import Scale, scale_named

__all__ = ["pooled_runs", "pooled_fits", "yield_loop", "branch_weights", "STATIC_SPREAD",
           "SLIP_ENDS"]

#: The runs' yield forces spread uniformly within ± this share of the scale's (the MD's six
#: K = 8 runs: 30–60 ε/σ about 45).
STATIC_SPREAD = 0.3
#: Where a control's slip ends in its table: ``slider``, where the slider re-sticks (its stop
#: velocity, or a recoil that fast); ``force-minimum``, at the lowest spring force between
#: its yield and that re-stick, an approximation of where the MD's detector ends a slip
#: (:func:`~filmfriction.analysis.stickslip.detect_slips`: the running minimum before the
#: force rises again by more than its threshold), so that a rest of the wall before the
#: slider re-sticks is left out as the MD's slips leave it.
SLIP_ENDS = ("slider", "force-minimum")


def yield_loop(law: str, w, d, laws=LOOP_LAWS) -> tuple[str, float, float]:
    """A yield loop as the benchmarks' ``--loop LAW W D`` gives it, checked: (``law``, W, D)
    with W (a share of the yield's excess over F_k) in [0, 1] and D > 0, finite (the
    distance, velocity or time it fades over), ``law`` one of ``laws``; ValueError
    otherwise.

    >>> yield_loop("slip-weakening", "0.5", "2")
    ('slip-weakening', 0.5, 2.0)
    """
    try:
        w, d = float(w), float(d)
    except (TypeError, ValueError):
        w = d = math.nan
    if law not in laws or not (0 <= w <= 1 and math.isfinite(d) and d > 0):
        raise ValueError(f"LAW {' or '.join(laws)}, W in [0, 1], D > 0")
    return law, w, d


def branch_weights(values) -> tuple[float, ...]:
    """A branch-weighted registry as the benchmarks' ``--branching DF2 PHI2 W1 W2 DPHI``
    gives it, checked: (ΔF₂, φ₂, w₁, w₂, δφ) finite, with no amplitude below 0 (ΔF₂ >= 0,
    w₁ <= 1, w₂ >= -1); ValueError otherwise.

    >>> branch_weights([10, -1.58, 0.3, 0.7, 0.6])
    (10.0, -1.58, 0.3, 0.7, 0.6)
    """
    b = tuple(float(c) for c in values)
    if len(b) != 5 or not (all(map(math.isfinite, b)) and b[0] >= 0 and b[2] <= 1
                           and b[3] >= -1):
        raise ValueError("five values, finite, DF2 >= 0, W1 <= 1, W2 >= -1")
    return b


def pooled_runs(name: str, runs: int, slips: int = 8, *, share: float | None = None,
                scale: str | Scale = "stiff", static_spread: float = STATIC_SPREAD,
                law_spread: float = 0.0, noise: dict | None = None,
                comoving_mass: float = 0.0, weakening: tuple[float, float] | None = None,
                loop_law: str = "melting", lag: float | None = None,
                corrugation: tuple[float, float, float] | None = None,
                registry_lag: float | None = None,
                branching: tuple[float, float, float, float, float] | None = None,
                lag_distance: float | None = None, lag_yield_exponent: float = 0.0,
                seed=0, slip_end: str = "slider") -> tuple[list[RunSlips], float]:
    """``runs`` runs of control ``name`` (or the Coulomb + viscous law of viscous ``share``)
    at ``scale``, each with its yield force and film (module text), as the pooled fit takes
    them, and the drive velocity.  ``comoving_mass``: the film's mass m_c the slipping wall
    carries (:func:`~filmfriction.analysis.groundtruth.random_force.slide`; the fit is given
    the scale's M alone).  ``weakening`` = (w, D): the mix with a yield loop of
    ``loop_law`` (:data:`~filmfriction.analysis.groundtruth.random_force.LOOP_LAWS`:
    ``melting``, D a velocity, or ``slip-weakening``, a distance), ΔF = w·(F_s − F_k) of
    each run's yield force F_s
    (:meth:`~filmfriction.analysis.groundtruth.slip_law_controls.Scale.law`); ``lag`` = τ_r:
    the mix with its viscous force lagging the velocity by τ_r (``maxwell``); ``corrugation``
    = (ΔF, λ, φ): the mix with a force ΔF·sin(2π·x/λ + φ) of the wall's position x, the
    registry of commensurate walls (``corrugated``, with ``weakening`` ``corrugated-loop``;
    every run starts at x = 0, as the MD's runs start from one geometry; ``law_spread``
    leaves it alone; with ``lag``, the viscous force lags too); ``registry_lag`` = τ_g: that
    registry force following the wall's position late, relaxing over τ_g
    (``lagged-registry``; not with a loop or a viscous lag); ``branching`` = (ΔF₂, φ₂, w₁,
    w₂, δφ): that registry force with a second harmonic, both weighted by the slip's branch
    (``branching-registry``; not with a loop, a viscous lag or ``registry_lag``);
    ``lag_distance`` = d: the viscous force lagging by the slip distance d, not a time
    (``distance-lag``; with ``branching``, ``distance-lag-branching``).
    ``lag_yield_exponent`` = α: each run's lag τ_r·(F̄_s/F_s)^α, F_s its yield force, F̄_s the
    scale's: a lag longer in the runs that yield weaker, whose slips are the slower (with
    ``lag``, on the plain or the corrugated mix, without a loop).  ``seed``: an int or a tuple
    of ints.  ``slip_end``: one of :data:`SLIP_ENDS`."""
    if not 0 <= static_spread < 1 or not 0 <= law_spread < 1:
        raise ValueError(f"static_spread = {static_spread!r}, law_spread = {law_spread!r}: "
                         "each in [0, 1)")
    if slip_end not in SLIP_ENDS:
        raise ValueError(f"slip_end = {slip_end!r}: one of {', '.join(SLIP_ENDS)}")
    if lag_yield_exponent and not (math.isfinite(lag_yield_exponent) and lag
                                   and weakening is None and registry_lag is None
                                   and branching is None and lag_distance is None):
        raise ValueError(f"lag_yield_exponent = {lag_yield_exponent!r}: finite, with a lag "
                         f"(lag = {lag!r}), without a loop, a registry lag, branching or a "
                         "lag in distance")
    sc = scale_named(scale)
    law = sc.law(name, share, weakening, loop_law, lag)
    period = law.pop("period")
    film = 2                # the film's own parameters, before the registry's
    if corrugation is not None:
        if share is None or len(corrugation) != 3 or (weakening is not None
                                                       and loop_law == "maxwell"):
            raise ValueError(f"corrugation = {corrugation!r} (control {name!r}, share "
                             f"{share!r}, loop law {loop_law!r}): (ΔF, λ, φ), on a Coulomb + "
                             "viscous mix of a share (with a lag or not; with a loop, "
                             "melting or slip-weakening)")
        reg = tuple(float(c) for c in corrugation) + (float(lag or 0.0),)
        if lag_distance is not None:
            if (weakening is not None or lag or registry_lag is not None
                    or not (math.isfinite(lag_distance) and lag_distance > 0)
                    or (branching is not None and len(branching) != 5)):
                raise ValueError(f"lag_distance = {lag_distance!r}: a distance > 0, finite, "
                                 "without a loop, a viscous lag or a registry lag (with "
                                 "branching = (ΔF₂, φ₂, w₁, w₂, δφ) or none)")
            law |= {"law": "distance-lag" if branching is None else "distance-lag-branching",
                    "parameters": law["parameters"][:2] + reg[:3] + (float(lag_distance),)
                    + (() if branching is None else tuple(float(c) for c in branching))}
        elif branching is not None:
            if (weakening is not None or lag or registry_lag is not None
                    or len(branching) != 5):
                raise ValueError(f"branching = {branching!r}: (ΔF₂, φ₂, w₁, w₂, δφ), without "
                                 "a loop, a viscous lag or a registry lag")
            law |= {"law": "branching-registry", "parameters": law["parameters"][:2]
                    + reg[:3] + tuple(float(c) for c in branching)}
        elif registry_lag is not None:
            if weakening is not None or lag or not (math.isfinite(registry_lag)
                                                    and registry_lag > 0):
                raise ValueError(f"registry_lag = {registry_lag!r}: a time > 0, finite, "
                                 "without a loop or a viscous lag")
            law |= {"law": "lagged-registry", "parameters": law["parameters"][:2]
                    + reg[:3] + (float(registry_lag),)}
        elif weakening is None:
            law |= {"law": "corrugated", "parameters": law["parameters"][:2] + reg}
        else:
            film = 4
            law |= {"law": "corrugated-loop", "parameters": law["parameters"][:4] + reg
                    + (float(loop_law == "melting"),)}
    elif registry_lag is not None or branching is not None or lag_distance is not None:
        raise ValueError(f"registry_lag = {registry_lag!r}, branching = {branching!r}, "
                         f"lag_distance = {lag_distance!r}: only with a corrugation")
    noise = sc.noise if noise is None else noise
    key = list(seed) if isinstance(seed, (tuple, list)) else [seed]
    rng = np.random.default_rng(key + [7919])
    out = []
    for g in range(runs):
        fs = law["static_force"] * (1 + static_spread * rng.uniform(-1, 1))
        par = tuple(float(p) * (1 + law_spread * rng.standard_normal())
                    for p in law["parameters"])
        if weakening is not None:
            # the film yields at its own F_s: ΔF the loop's share of the run's F_s − F_k
            par = par[:2] + (par[2] * max(fs - par[0], 0.0),) + par[3:]
        if corrugation is not None:
            # the registry is the walls' (one geometry for every run), not the film's
            par = par[:film] + law["parameters"][film:]
        if lag_yield_exponent:
            # τ_r is the law's last parameter (``maxwell``, ``corrugated``)
            par = par[:-1] + (par[-1] * (law["static_force"] / fs) ** lag_yield_exponent,)
        r = slide(**{**law, "static_force": fs, "parameters": par}, mass=sc.mass,
                  stiffness=sc.spring_constant,
                  duration=(slips + 3) * period * 1.3 * (1 + static_spread), dt=sc.dt,
                  seed=tuple(key + [g]), mount_damping=sc.mount_damping,
                  comoving_mass=comoving_mass, **noise)[0]
        ends = r["stick_index"]
        if slip_end == "force-minimum":
            ends = np.array([y + int(np.argmin(r["spring_force"][y:s + 1]))
                             for y, s in zip(r["yield_index"], ends)], int)
        tab = cycle_table(r["time"], r["spring_force"], r["yield_index"], ends,
                          spring_constant=sc.spring_constant,
                          wall_position=r["wall_position"])[1:slips + 1]
        out.append(RunSlips(r["time"], r["spring_force"], r["wall_velocity"], tab,
                            wall_position=r["wall_position"], name=f"run {g + 1}"))
    return out, law["drive_velocity"]


def pooled_fits(name: str, replicas: int, runs: int = 6, slips: int = 8, *,
                share: float | None = None, scale: str | Scale = "stiff",
                static_spread: float = STATIC_SPREAD, law_spread: float = 0.0,
                noise: dict | None = None, comoving_mass: float = 0.0,
                weakening: tuple[float, float] | None = None, loop_law: str = "melting",
                lag: float | None = None, corrugation=None, seed: int = 0,
                jackknife: str = "runs", slip_end: str = "slider",
                registry_period: float | None = None) -> list[FilmForceFit]:
    """The pooled fit (the jackknife over ``jackknife``: ``runs`` or ``slips``; with the
    registry's force of period ``registry_period``) of ``replicas`` replicas of
    :func:`pooled_runs` (replica k from the seed (``seed``, k))."""
    sc = scale_named(scale)
    out = []
    for k in range(replicas):
        rs, velocity = pooled_runs(name, runs, slips, share=share, scale=sc,
                                   static_spread=static_spread, law_spread=law_spread,
                                   noise=noise, comoving_mass=comoving_mass,
                                   weakening=weakening, loop_law=loop_law, lag=lag,
                                   corrugation=corrugation, seed=(seed, k),
                                   slip_end=slip_end)
        out.append(fit_pooled_ensemble(rs, mass=sc.mass, drive_velocity=velocity,
                                       film_mass=sc.film_mass,
                                       mount_damping=sc.mount_damping,
                                       min_window_time=MD_NOISE_TIME, jackknife=jackknife,
                                       registry_period=registry_period))
    return out
