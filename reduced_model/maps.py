"""Regime maps and stability thresholds of the spring-block slider.

Nakano-Maegawa plane
--------------------
For Coulomb friction (static Fs, kinetic Fk, drop dF = Fs - Fk) with a damper d,
``lambda = dF / (V sqrt(K M))`` and ``zeta = d / (2 sqrt(K M))`` fix the motion
after breakaway completely: in units of V and 1/omega the slip starts from
``e = 2 zeta - lambda``, ``e' = -1`` about steady sliding, and the block re-sticks
iff the velocity ``1 + e'(t)`` returns to zero, i.e. iff the first minimum of
``e'`` after breakaway reaches -1.  :func:`critical_lambda` solves that
condition exactly; it gives ``lambda^2 -> 4 pi zeta`` as zeta -> 0 (Nakano &
Maegawa's asymptote, also in Schnelle, seed 003) and no stick-slip for
zeta >= 1 (an overdamped slip cannot bring the velocity back to zero).

:func:`lambda_zeta_map` does not use that formula: it simulates every cell
with :class:`SpringBlock` (closed-form Coulomb path) on both cores, so the map
and the boundary check each other.

Velocity-stiffness plane
------------------------
:func:`velocity_stiffness_map` simulates the contact-age model (Braun,
seed 000) over (V, K): smooth sliding at high V / stiff springs, stick-slip
otherwise, with Persson's estimate ``v_c ~ N (f_s - f_b)/(K tau)``
(:meth:`laws.ContactAge.critical_velocity`).  For rate-and-state,
:func:`rate_state_critical_stiffness` gives ``k_c = N (b - a)/dc [1 + M V^2/(N a dc)]``.

Example
-------
>>> from filmfriction.reduced_model.maps import critical_lambda
>>> lam = critical_lambda(1e-4)
>>> round(lam ** 2 / (4 * 3.141592653589793e-4), 2)
1.0
"""
from __future__ import annotations

import math
import os
from pathlib import Path
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ._checks import non_negative, positive
from .laws import ContactAge, Coulomb, RateState
from .integrators.oscillator import DampedOscillator
from .springblock import SpringBlock

__all__ = ["stick_slip_parameter", "damping_ratio", "critical_lambda", "coulomb_critical_velocity",
           "coulomb_stick_slip",
           "lambda_zeta_map", "velocity_stiffness_map", "rate_state_critical_stiffness",
           "contact_age_critical_velocity", "RegimeMap"]


def stick_slip_parameter(force_drop, velocity, stiffness, mass):
    """Nakano-Maegawa lambda = dF / (V sqrt(K M))."""
    return force_drop / (velocity * np.sqrt(stiffness * mass))


def damping_ratio(damping, stiffness, mass):
    """zeta = d / (2 sqrt(K M))."""
    return damping / (2.0 * np.sqrt(stiffness * mass))


def _first_slip_margin(lam: float, zeta: float) -> float:
    """Deepest dimensionless velocity reached in the first slip (<= 0: re-stick)."""
    osc = DampedOscillator(1.0, 2.0 * zeta, 1.0)
    e0, ed0 = 2.0 * zeta - lam, -1.0
    a0 = -2.0 * zeta * ed0 - e0                 # = lam, the net force at breakaway
    j0 = -2.0 * zeta * a0 - ed0
    zeros = osc.zeros(a0, j0, math.inf)
    next(zeros, None)                           # first zero of e'': the velocity maximum
    t_min = next(zeros, None)                   # second: the first velocity minimum
    if t_min is None:
        return 1.0 if osc.regime != "under" else float(1.0 + osc.value(math.inf, ed0, a0))
    return float(1.0 + osc.value(t_min, ed0, a0))


def _critical_lambda_scalar(zeta: float) -> float:
    if zeta >= 1.0:
        return math.inf
    if zeta == 0.0:
        return 0.0
    hi = max(1.0, 4.0 * math.sqrt(4.0 * math.pi * zeta))
    while _first_slip_margin(hi, zeta) > 0.0:
        hi *= 2.0
        if hi > 1e12:
            return math.inf
    return brentq(lambda lam: _first_slip_margin(lam, zeta), 0.0, hi, xtol=1e-14, rtol=1e-13)


def critical_lambda(zeta):
    """Smallest lambda giving stick-slip at damping ratio zeta (Coulomb friction).

    Parameters
    ----------
    zeta : float or array_like
        Damping ratio(s) >= 0.

    Returns
    -------
    float or ndarray
        ``inf`` for zeta >= 1 (no stick-slip at all); -> sqrt(4 pi zeta) as zeta -> 0.

    Example
    -------
    >>> critical_lambda(1.5)
    inf
    """
    z = np.asarray(zeta, dtype=float)
    if np.any(~np.isfinite(z) & ~np.isposinf(z)) or np.any(z < 0):
        raise ValueError(f"zeta = {zeta!r}: allowed range is [0, inf) (a damping ratio)")
    if z.ndim == 0:
        return _critical_lambda_scalar(float(z))
    return np.vectorize(_critical_lambda_scalar, otypes=[float])(z)


def coulomb_critical_velocity(force_drop, damping, stiffness, mass):
    """Drive velocity below which a Coulomb (+ viscous) block sticks and slips.

    Stick-slip iff ``lambda = dF/(V sqrt(K M)) > lambda_c(zeta)`` with
    ``zeta = d/(2 sqrt(K M))`` (:func:`critical_lambda`), so
    ``V_c = dF / (lambda_c(zeta) sqrt(K M))``; 0 for zeta >= 1 (no stick-slip).

    Parameters
    ----------
    force_drop : float
        dF = Fs - Fk.
    damping : float
        All the damping of the slip (film's viscous B plus any damper d).
    stiffness : float or array_like
        K (one V_c per value).
    mass : float
        M.

    Returns
    -------
    numpy.ndarray
        V_c for each K.

    Example
    -------
    >>> coulomb_critical_velocity(1.0, 3.0, [1.0], 1.0).tolist()      # zeta = 1.5: never
    [0.0]
    """
    k = np.asarray(stiffness, float)
    lam = np.atleast_1d(critical_lambda(damping_ratio(damping, k, mass)))
    with np.errstate(divide="ignore"):
        return np.where(np.isfinite(lam), force_drop / (lam * np.sqrt(k * mass)), 0.0)


def coulomb_stick_slip(lam: float, zeta: float) -> bool:
    """Whether the Coulomb block with (lambda, zeta) sticks again after breakaway (by simulation)."""
    lam = positive("lambda", lam, "the force drop Fs - Fk in units of V sqrt(K M)")
    zeta = non_negative("zeta", zeta, "damping ratio")
    # unit mass, stiffness, velocity; Fk = 0 so Fs = lambda.  One stick (lambda) plus
    # two periods is more than enough: the first velocity minimum comes within one.
    block = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=1.0, damping=2.0 * zeta,
                        law=Coulomb(static=lam, kinetic=0.0))
    result = block.simulate(lam + 4.0 * math.pi, samples_per_segment=2, max_events=64)
    return any(e.kind == "stick" for e in result.events)


def _row_lambda_zeta(args):
    lams, zeta = args
    return [coulomb_stick_slip(lam, zeta) for lam in lams]


@dataclass(frozen=True, eq=False)
class RegimeMap:
    """A regime map: ``stick_slip[i, j]`` for ``y[i]``, ``x[j]``.

    ``x_name``/``y_name`` label the axes; ``boundary`` is the analytic
    threshold sampled on ``boundary_x`` (same axis as x), when there is one.
    """

    x_name: str
    y_name: str
    x: np.ndarray
    y: np.ndarray
    stick_slip: np.ndarray
    boundary_x: np.ndarray
    boundary: np.ndarray
    seconds: float

    def csv_text(self) -> str:
        """The map as CSV text: a header, then ``x, y, stick_slip`` rows."""
        import io

        X, Y = np.meshgrid(self.x, self.y)
        data = np.column_stack([X.ravel(), Y.ravel(), self.stick_slip.ravel().astype(int)])
        buf = io.StringIO()
        np.savetxt(buf, data, delimiter=",", header=f"{self.x_name},{self.y_name},stick_slip",
                   comments="", fmt=["%.10g", "%.10g", "%d"])
        return buf.getvalue()

    def to_csv(self, path) -> str:
        """Write ``x, y, stick_slip`` rows."""
        Path(path).write_text(self.csv_text())
        return str(path)


def _pool_map(func, jobs, processes):
    processes = min(processes or os.cpu_count() or 1, len(jobs))
    if processes <= 1:
        return [func(j) for j in jobs]
    with ProcessPoolExecutor(max_workers=processes) as pool:
        return list(pool.map(func, jobs))


def lambda_zeta_map(lambdas=None, zetas=None, processes: int | None = 2) -> RegimeMap:
    """Simulate the Coulomb block over a (zeta, lambda) grid (rows: lambda).

    Defaults: 100 x 100 log-spaced, zeta in [1e-3, 10], lambda in [1e-2, 1e2].
    """
    import time
    lambdas = np.logspace(-2, 2, 100) if lambdas is None else np.asarray(lambdas, dtype=float)
    zetas = np.logspace(-3, 1, 100) if zetas is None else np.asarray(zetas, dtype=float)
    if np.any(lambdas <= 0) or np.any(zetas < 0):
        raise ValueError("lambdas must be > 0 and zetas >= 0")
    start = time.perf_counter()
    cols = _pool_map(_row_lambda_zeta, [(lambdas, z) for z in zetas], processes)
    grid = np.array(cols, dtype=bool).T           # rows: lambda, columns: zeta
    return RegimeMap("zeta", "lambda", zetas, lambdas, grid, zetas, critical_lambda(zetas),
                     time.perf_counter() - start)


def _contact_age_regime(args):
    """Stick-slip (True) or smooth sliding for one (V, K) cell of the contact-age block."""
    from ._checks import SimulationLimitError
    law, mass, damping, V, K, N = args
    block = SpringBlock(mass=mass, stiffness=K, drive_velocity=V, damping=damping, law=law, normal_load=N)
    stick_time = N * law.static / (K * V)           # longest possible stick (aged contact)
    settle = 20.0 * block.natural_period + 10.0 * law.age_time
    # stage 1: the start-up stick, the first slip and a settling time.  No re-stick in it:
    # smooth sliding.  Three re-sticks (event cap hit): stick-slip.
    for duration in (stick_time + settle, 4.0 * stick_time + 4.0 * settle):
        try:
            r = block.simulate(duration, samples_per_segment=4, max_events=6)
        except SimulationLimitError:
            return True
        sticks = [e.time for e in r.events if e.kind == "stick"]
        if not sticks:
            return False
    return sticks[-1] > 0.5 * duration


def velocity_stiffness_map(velocities=None, stiffnesses=None, *, law: ContactAge | None = None,
                           mass: float = 1.0, damping: float = 0.1, normal_load: float = 1.0,
                           processes: int | None = 2) -> RegimeMap:
    """Simulate the contact-age block over (V, K) (rows: K); boundary = Persson's v_c(K)."""
    import time
    law = law or ContactAge(static=1.0, backward=0.5, age_time=1.0, memory_length=1e-3)
    velocities = np.logspace(-3, 0, 16) if velocities is None else np.asarray(velocities, dtype=float)
    stiffnesses = np.logspace(-1, 2, 16) if stiffnesses is None else np.asarray(stiffnesses, dtype=float)
    if np.any(velocities <= 0) or np.any(stiffnesses <= 0):
        raise ValueError("velocities and stiffnesses must be > 0")
    start = time.perf_counter()
    jobs = [(law, mass, damping, V, K, normal_load) for K in stiffnesses for V in velocities]
    flags = np.array(_pool_map(_contact_age_regime, jobs, processes), dtype=bool)
    grid = flags.reshape(stiffnesses.size, velocities.size)
    boundary_k = stiffnesses
    boundary_v = np.array([law.critical_velocity(K, normal_load) for K in stiffnesses])
    return RegimeMap("velocity", "stiffness", velocities, stiffnesses, grid, boundary_v, boundary_k,
                     time.perf_counter() - start)


def rate_state_critical_stiffness(law: RateState, normal_load: float, mass: float = 0.0,
                                  velocity: float = 0.0) -> float:
    """k_c = N (b - a)/dc [1 + M V^2 / (N a dc)] (Ruina 1983 for M -> 0)."""
    return law.critical_stiffness(normal_load, mass, velocity)


def contact_age_critical_velocity(law: ContactAge, stiffness: float, normal_load: float = 1.0) -> float:
    """Persson's v_c ~ N (f_s - f_b)/(K tau) for the contact-age model."""
    return law.critical_velocity(stiffness, normal_load)
