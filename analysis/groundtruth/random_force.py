"""A driven slider whose film pushes it with a random force: noise that moves the wall.

The slip-law controls (:mod:`~filmfriction.analysis.groundtruth.slip_law_controls`) need
the MD's noise as the MD has it: the film's random force ξ acts on the wall, and the
wall's position and velocity respond to it, so the regressors of the integral-form fit
(Δx, and the v whose M·v is in the response) carry the noise the response carries.
This module integrates that slider, many replicas at once:

    M dv/dt = K(x_d − x) − F(v, ψ) + ξ(t),   dx/dt = v,   x_d = x_d0 + V·t

with F the friction law of the slip (odd in v, so a wall pushed backwards by ξ is
resisted forwards) and ψ its state (rate and state), and

    ξ = M·du/dt   while the wall slips, 0 while it is stuck,

u an Ornstein–Uhlenbeck velocity: sampled every ``dt`` it is AR(1) of rms
``velocity_noise`` and lag-one correlation ``velocity_correlation``.  So the
residual of the integrated equation of motion over M, ∫ξ dt/M over a slip, is
u(t) − u(t_yield): the noise the MD's was measured as
(:data:`~filmfriction.analysis.groundtruth.slip_law_controls.MD_NOISE`), here a
force that moves the wall.  The wall's thermal rattling (``rattle``, white at the
sampling) is a vibration faster than the sampling, of bounded amplitude
(rattle/ω ≪ the sampled Δx): it is added to the sampled velocity only.

Stick and slip.  A stuck wall is at rest (the film holds it and balances its own
random force); it yields when the spring force reaches ``static_force(ψ)``,
starting at ``start_velocity`` (0; the small velocity a rate-and-state law is
integrated from: below it the creep is stiff and moves the wall by nothing the
fit sees, and is taken as rest with the state aging, dθ/dt = 1).  It re-sticks,
once the spring force has fallen to ``armed_below`` (a pause of the noise early in
a slip, while the spring still pulls near the yield, is not the slip's end), when
its velocity falls to ``stop_velocity`` or the spring force to ``backward_force``.

The equation is integrated by the classical Runge–Kutta method at ``substeps``
(1) steps per sample, ξ constant within a step (u interpolated linearly: the impulse
M·Δu per step is exact); events fall on the steps.  Noise-free, the slips are the
law's to the step's accuracy (``tests/analysis/groundtruth/test_random_force.py``).

Example
-------
A Coulomb slider with and without the random force:

>>> import numpy as np
>>> coulomb = lambda v, psi: np.where(v >= 0, 36.0, -36.0)
>>> run = slide(coulomb, mass=30.0, stiffness=2.0, drive_velocity=0.1, static_force=48.0,
...             duration=400.0, dt=0.25, replicas=2, velocity_noise=0.75,
...             velocity_correlation=0.9, seed=1)
>>> len(run), sorted(run[0])[:3]
(2, ['drive_position', 'spring_force', 'stick_index'])
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

__all__ = ["slide"]


def slide(friction: Callable, *, mass: float, stiffness: float, drive_velocity: float,
          static_force, duration: float, dt: float, replicas: int = 1,
          velocity_noise: float = 0.0, velocity_correlation: float = 0.0, rattle: float = 0.0,
          seed: int = 0, initial_force: float = 0.0, stop_velocity: float = 0.0,
          backward_force: float = -math.inf, armed_below: float = math.inf,
          start_velocity: float = 0.0, state_rate: Callable | None = None,
          initial_state: float = 0.0, substeps: int = 1) -> list[dict]:
    """``replicas`` runs of the slider (module text), each with its own noise.

    Parameters
    ----------
    friction : callable
        ``friction(v, psi) -> F`` on arrays (one value per replica), odd in v.
    mass, stiffness, drive_velocity : float
        M, K and V (the spring end moves at V from x_d0 = ``initial_force``/K).
    static_force : float or callable
        The spring force at which a stuck wall yields, or ``static_force(psi)``.
    duration, dt : float
        Length of the run and the sampling step.
    velocity_noise, velocity_correlation : float
        rms and lag-one (per ``dt``) correlation of u, the random force's velocity.
    rattle : float
        rms of the white noise added to the sampled velocity.
    stop_velocity, backward_force, armed_below, start_velocity : float
        The re-stick and the yield (module text).
    state_rate : callable, optional
        ``state_rate(v, psi) -> dψ/dt`` on arrays; None: a law without state.  While
        stuck ψ ages as ψ = ln(θ·v0/d_c) with dθ/dt = 1, i.e. dψ/dt = e^{−ψ}·(v0/d_c):
        ``state_rate(0, psi)``.
    initial_state : float
        ψ at t = 0.
    substeps : int
        Runge–Kutta steps per sample.

    Returns
    -------
    list of dict
        Per replica: ``time, spring_force, drive_position, wall_position, wall_velocity``
        (the sampled velocity, rattle included) and ``yield_index``, ``stick_index`` (the
        sample at or just before each yield, at or just after each re-stick; complete
        slips only).
    """
    for name, val in (("mass", mass), ("stiffness", stiffness), ("duration", duration),
                      ("dt", dt)):
        if not (math.isfinite(val) and val > 0):
            raise ValueError(f"{name} = {val!r}: must be positive and finite")
    if int(replicas) < 1 or int(substeps) < 1:
        raise ValueError(f"replicas = {replicas!r}, substeps = {substeps!r}: must be >= 1")
    if not (0 <= velocity_correlation < 1) or velocity_noise < 0 or rattle < 0:
        raise ValueError("velocity_noise, rattle must be >= 0 and velocity_correlation in [0, 1)")
    R, n_sub = int(replicas), int(substeps)
    rng = np.random.default_rng(seed)
    h = dt / n_sub
    samples = int(math.floor(duration / dt + 1e-9))
    rho_h = velocity_correlation ** (1.0 / n_sub)
    kick = velocity_noise * math.sqrt(1.0 - rho_h ** 2)
    static = static_force if callable(static_force) else (lambda psi: np.full(R, static_force))
    xd0 = initial_force / stiffness
    x = np.zeros(R)
    v = np.zeros(R)
    psi = np.full(R, float(initial_state))
    u = rng.normal(0.0, velocity_noise, R) if velocity_noise else np.zeros(R)
    slipping = np.zeros(R, bool)
    armed = np.zeros(R, bool)
    out_x, out_v = np.empty((samples, R)), np.empty((samples, R))
    yields = [[] for _ in range(R)]
    sticks = [[] for _ in range(R)]

    def accel(t, xx, vv, pp, xi):
        return (stiffness * (xd0 + drive_velocity * t - xx) - friction(vv, pp) + xi) / mass

    def prate(vv, pp):
        return state_rate(vv, pp) if state_rate is not None else 0.0

    for k in range(samples):
        out_x[k], out_v[k] = x, v
        for j in range(n_sub):
            t = (k * n_sub + j) * h
            u_next = rho_h * u + kick * rng.normal(size=R) if velocity_noise else u
            xi = np.where(slipping, mass * (u_next - u) / h, 0.0)
            u = u_next
            # the slipping replicas: one Runge–Kutta step (the stuck ones are overwritten)
            a1 = accel(t, x, v, psi, xi)
            p1 = prate(v, psi)
            x2, v2, s2 = x + 0.5 * h * v, v + 0.5 * h * a1, psi + 0.5 * h * p1
            a2 = accel(t + 0.5 * h, x2, v2, s2, xi)
            p2 = prate(v2, s2)
            x3, v3, s3 = x + 0.5 * h * v2, v + 0.5 * h * a2, psi + 0.5 * h * p2
            a3 = accel(t + 0.5 * h, x3, v3, s3, xi)
            p3 = prate(v3, s3)
            x4, v4, s4 = x + h * v3, v + h * a3, psi + h * p3
            a4 = accel(t + h, x4, v4, s4, xi)
            p4 = prate(v4, s4)
            xn = x + h * (v + 2 * v2 + 2 * v3 + v4) / 6
            vn = v + h * (a1 + 2 * a2 + 2 * a3 + a4) / 6
            pn = psi + h * (p1 + 2 * p2 + 2 * p3 + p4) / 6
            # stuck: at rest, the state aging
            ps = psi + h * prate(np.zeros(R), psi)
            x = np.where(slipping, xn, x)
            v = np.where(slipping, vn, 0.0)
            psi = np.where(slipping, pn, ps)
            force = stiffness * (xd0 + drive_velocity * (t + h) - x)
            armed |= slipping & (force <= armed_below)
            # the re-stick: the velocity at the step's end or at any of its stages fell to
            # the stop (a stage's sign of a Coulomb force flips where v crosses 0)
            low = np.minimum(np.minimum(v2, v3), np.minimum(v4, vn)) <= stop_velocity
            stop = slipping & ((armed & low) | (force <= backward_force))
            go = ~slipping & (force >= static(psi))
            for r in np.flatnonzero(stop):
                sticks[r].append(min(k + 1, samples - 1))
            for r in np.flatnonzero(go):
                yields[r].append(k)
            v = np.where(stop, 0.0, np.where(go, start_velocity, v))
            slipping = (slipping & ~stop) | go
            armed &= slipping
    t = dt * np.arange(samples)
    xd = xd0 + drive_velocity * t
    runs = []
    for r in range(R):
        y, s = _alternating(yields[r], sticks[r])
        runs.append({"time": t, "spring_force": stiffness * (xd - out_x[:, r]),
                     "drive_position": xd, "wall_position": out_x[:, r].copy(),
                     "wall_velocity": out_v[:, r] + rng.normal(0.0, rattle, samples),
                     "yield_index": y, "stick_index": s})
    return runs


def _alternating(yields: list, sticks: list) -> tuple[np.ndarray, np.ndarray]:
    """The complete slips' (yield, re-stick) samples; a re-stick and a yield within one
    sample interval (a pause shorter than the sampling) join their two slips into one."""
    y, s = [], []
    for a, b in zip(yields, sticks):
        if s and a < s[-1]:
            s[-1] = b
        else:
            y.append(a)
            s.append(b)
    return np.asarray(y, int), np.asarray(s, int)
