"""A driven slider whose film pushes it with a random force: noise that moves the wall.

The slip-law controls (:mod:`~filmfriction.analysis.groundtruth.slip_law_controls`) need
the MD's noise as the MD has it: the film's random force ξ acts on the wall, and the
wall's position and velocity respond to it, so the regressors of the integral-form fit
(Δx, and the v whose M·v is in the response) carry the noise the response carries.
This module integrates that slider, many replicas at once:

    (M + m_c) dv/dt = K(x_d − x) − F(v, ψ) − γM·(v − V) + ξ(t),   dx/dt = v,   x_d = x_d0 + V·t

with F the friction law of the slip (one of :data:`LAWS`) and ψ its state (rate and state;
the yield-loop laws' slip distance or fastest velocity since the yield; the Maxwell film's
viscous force), γM an MD run's
mount dashpot (``mount_damping``, 0 by default), m_c the film's mass that moves with the
slipping wall (``comoving_mass``, 0 by default: the fit, which knows M alone, reads its
m_c·a as film force), and

    ξ = (M + m_c)·du/dt   while the wall slips, 0 while it is stuck,

u an Ornstein–Uhlenbeck velocity: sampled every ``dt`` it is AR(1) of rms
``velocity_noise`` and lag-one correlation ``velocity_correlation`` (or a sum of
independent such terms, one per pair of the two sequences).  So the
residual of the integrated equation of motion over M, ∫ξ dt/M over a slip, is
u(t) − u(t_yield): the noise the MD's was measured as
(:data:`~filmfriction.analysis.groundtruth.film_noise.MD_NOISE`), here a
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
M·Δu per step is exact), compiled (numba); events fall on the steps.  Noise-free, the slips are the
law's to the step's accuracy (``tests/analysis/groundtruth/test_random_force.py``).

Example
-------
A Coulomb slider with and without the random force:

>>> run = slide("coulomb-viscous", (36.0, 0.0), mass=30.0, stiffness=2.0, drive_velocity=0.1, static_force=48.0,
...             duration=400.0, dt=0.25, replicas=2, velocity_noise=0.75,
...             velocity_correlation=0.9, seed=1)
>>> len(run), sorted(run[0])[:3]
(2, ['drive_position', 'spring_force', 'stick_index'])
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.signal import lfilter

__all__ = ["slide", "LAWS", "LOOP_LAWS", "NOISE_FREE"]

#: The friction laws of the slip, F(v, ψ), and their parameters:
#:
#: * ``linear`` (F_k, B): F_k + B·v whatever the sign of v (a sliding film's force,
#:   exactly the fit's law on every sample);
#: * ``coulomb-viscous`` (F_k, B): F_k·sign(v) + B·v (sign(0) = +1);
#: * ``weakening`` (F_k, F_s, v_c): sign(v)·(F_k + (F_s − F_k)·exp(−|v|/v_c));
#: * ``rate-state`` (μ0, a, b, d_c, v0): a·asinh(v/(2v0)·exp((μ0 + bψ)/a)) (the regularized
#:   Dieterich–Ruina law, :class:`~filmfriction.reduced_model.laws.RateState` at N = 1),
#:   aging: dψ/dt = (v0·e^{−ψ} − |v|)/d_c;
#: * ``slip-weakening`` (F_k, B, ΔF, D_c): sign(v)·(F_k + ΔF·exp(−ψ/D_c)) + B·v, ψ the
#:   distance slid since the yield (dψ/dt = |v|, 0 at each yield): a film that yields
#:   solid-like and melts over the slip distance D_c, so the accelerating part of a slip
#:   meets more force than the decelerating part at the same velocity (a yield loop);
#: * ``melting`` (F_k, B, ΔF, v_c): sign(v)·(F_k + ΔF·exp(−ψ/v_c)) + B·v, ψ the fastest
#:   |v| of the slip so far (0 at each yield): a film that melts with the shear rate and
#:   stays melted until it re-sticks (another yield loop);
#: * ``maxwell`` (F_k, B, ΔF, τ_r): sign(v)·F_k + ψ, ψ the film's shear force beyond F_k
#:   relaxing to B·v over τ_r (dψ/dt = (B·v − ψ)/τ_r), ΔF at each yield: a viscoelastic film
#:   whose shear force lags the shear rate (the one law reads the lag as a co-moving mass of
#:   about −B·τ_r) and, with ΔF > 0, still holds at the yield a stress it releases over τ_r
#:   (a yield loop that fades with time, on the slip's early, accelerating part);
#: * ``maxwell-weakening`` (F_k, B, ΔF, D_c, τ_r): sign(v)·(F_k + ΔF·exp(−s/D_c)) + ψ, s the
#:   distance slid since the yield, ψ the ``maxwell`` film's lagging viscous force (0 at
#:   each yield): a film that melts over the slip distance and whose viscous force lags;
#: * ``corrugated`` (F_k, B, ΔF, λ, φ, τ_r): sign(v)·F_k + B·v + ΔF·sin(2π·x/λ + φ), x the
#:   wall's position: a film whose force is modulated by the registry of commensurate walls
#:   (the lattice's period λ along the slide; φ, the registry at x = 0); with τ_r > 0 its
#:   viscous force lags as the ``maxwell`` film's (ψ in place of B·v, 0 at each yield);
#: * ``corrugated-loop`` (F_k, B, W, D, ΔF, λ, φ, τ_r, kind): the ``corrugated`` film with a
#:   yield loop, sign(v)·(F_k + W·exp(−s/D)) + B·v (or ψ) + ΔF·sin(2π·x/λ + φ): kind 0,
#:   s the distance slid since the yield (``slip-weakening``); kind 1, s the fastest |v| of
#:   the slip so far (``melting``, without a lag: ψ holds that velocity);
#: * ``lagged-registry`` (F_k, B, ΔF, λ, φ, τ_g): sign(v)·F_k + B·v + ΔF·sin(2π·(x − ψ)/λ + φ),
#:   ψ the distance by which the film's registry trails the wall, relaxing over τ_g
#:   (dψ/dt = v − ψ/τ_g, 0 at each yield: at rest the film sits in the walls' registry): a
#:   registry force that follows the wall's position late, by ≈ v·τ_g in a steady slide, less
#:   while the slip speeds up than while it slows down (τ_g no shorter than the integration
#:   step, dt/substeps: the step must resolve the trail's relaxation);
#: * ``branching-registry`` (F_k, B, ΔF₁, λ, φ₁, ΔF₂, φ₂, w₁, w₂, δφ): sign(v)·F_k + B·v
#:   + ΔF₁·(1 − w₁·r)·sin(θ + φ₁ + δφ·r) + ΔF₂·(1 + w₂·r)·sin(2θ + φ₂), θ = 2π·x/λ,
#:   r = |v| over the fastest |v| of the slip so far (0 at each yield): r = 1 while the
#:   slip speeds up and falls to 0 as it slows down, so a registry force of two harmonics
#:   whose amplitudes and phase differ between the accelerating and the decelerating branch
#:   of the slip at one velocity (w₁ > 0: the first harmonic weaker while accelerating;
#:   w₂ > 0: the second stronger; δφ > 0: the phase ahead), each amplitude ≥ 0 throughout
#:   (w₁ ≤ 1, w₂ ≥ −1);
#: * ``distance-lag`` (F_k, B, ΔF, λ, φ, d): sign(v)·F_k + ψ + ΔF·sin(2π·x/λ + φ), ψ the
#:   film's viscous force relaxing to B·v over a slip distance d (dψ/dt = |v|·(B·v − ψ)/d,
#:   0 at each yield): the ``corrugated`` film whose viscous force lags by a distance, not
#:   a time (a lag of d/|v|: long where the slip is slow, short at its peak);
#: * ``distance-lag-branching`` (F_k, B, ΔF₁, λ, φ₁, d, ΔF₂, φ₂, w₁, w₂, δφ): that film
#:   with the ``branching-registry``'s force in place of its registry, sign(v)·F_k + ψ
#:   + ΔF₁·(1 − w₁·r)·sin(θ + φ₁ + δφ·r) + ΔF₂·(1 + w₂·r)·sin(2θ + φ₂) (r from the slip's
#:   fastest |v| so far, kept beside ψ).
LAWS = {"linear": 2, "coulomb-viscous": 2, "weakening": 3, "rate-state": 5,
        "slip-weakening": 4, "melting": 4, "maxwell": 4, "maxwell-weakening": 5,
        "corrugated": 6, "corrugated-loop": 9, "lagged-registry": 6,
        "branching-registry": 10, "distance-lag": 6,
        "distance-lag-branching": 11}
#: :func:`slide`'s random-force keywords for none (the noise-free slider).
NOISE_FREE = {"velocity_noise": 0.0, "velocity_correlation": 0.0, "rattle": 0.0}
#: The laws with a yield loop, (F_k, B, ΔF, D) each: ΔF fades over D since the yield (a
#: distance, a velocity, a time).
LOOP_LAWS = ("melting", "slip-weakening", "maxwell")
_CODE = {name: k for k, name in enumerate(LAWS)}
#: Where the branch-weighted laws keep ΔF₁, ΔF₂, w₁ and w₂ among their parameters.
_BRANCH_WEIGHTS = {"branching-registry": (2, 5, 7, 8), "distance-lag-branching": (2, 6, 8, 9)}


@njit(cache=True)
def _branched_registry(x, v, top, df1, lam, phi1, df2, phi2, w1, w2, dphi):
    """The branch-weighted registry force at x (``branching-registry``): r = |v| over the
    slip's fastest |v| so far (``top``), 1 while the slip speeds up."""
    fastest = max(top, abs(v))
    r = abs(v) / fastest if fastest > 0.0 else 1.0
    theta = 2.0 * math.pi * x / lam
    return (df1 * (1.0 - w1 * r) * math.sin(theta + phi1 + dphi * r)
            + df2 * (1.0 + w2 * r) * math.sin(2.0 * theta + phi2))


@njit(cache=True)
def _friction(code, p, v, psi, x, x_yield, top):
    if code == 0:
        return p[0] + p[1] * v
    if code == 1:
        return (p[0] if v >= 0.0 else -p[0]) + p[1] * v
    if code == 2:
        f = p[0] + (p[1] - p[0]) * math.exp(-abs(v) / p[2])
        return f if v >= 0.0 else -f
    if code == 4:
        f = p[0] + p[2] * math.exp(-psi / p[3])
        return (f if v >= 0.0 else -f) + p[1] * v
    if code == 5:
        f = p[0] + p[2] * math.exp(-max(psi, abs(v)) / p[3])
        return (f if v >= 0.0 else -f) + p[1] * v
    if code == 6:
        return (p[0] if v >= 0.0 else -p[0]) + psi
    if code == 7:
        f = p[0] + p[2] * math.exp(-(x - x_yield) / p[3])
        return (f if v >= 0.0 else -f) + psi
    if code == 8:
        return ((p[0] if v >= 0.0 else -p[0]) + (psi if p[5] > 0.0 else p[1] * v)
                + p[2] * math.sin(2.0 * math.pi * x / p[3] + p[4]))
    if code == 9:
        s = (x - x_yield) if p[8] == 0.0 else max(psi, abs(v))
        f = p[0] + p[2] * math.exp(-s / p[3])
        return ((f if v >= 0.0 else -f) + (psi if p[7] > 0.0 else p[1] * v)
                + p[4] * math.sin(2.0 * math.pi * x / p[5] + p[6]))
    if code == 10:
        return ((p[0] if v >= 0.0 else -p[0]) + p[1] * v
                + p[2] * math.sin(2.0 * math.pi * (x - psi) / p[3] + p[4]))
    if code == 11:
        return ((p[0] if v >= 0.0 else -p[0]) + p[1] * v
                + _branched_registry(x, v, top, p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9]))
    if code == 12:
        return ((p[0] if v >= 0.0 else -p[0]) + psi
                + p[2] * math.sin(2.0 * math.pi * x / p[3] + p[4]))
    if code == 13:
        return ((p[0] if v >= 0.0 else -p[0]) + psi
                + _branched_registry(x, v, top, p[2], p[3], p[4], p[6], p[7], p[8], p[9],
                                     p[10]))
    return p[1] * math.asinh(v / (2.0 * p[4]) * math.exp((p[0] + p[2] * psi) / p[1]))


@njit(cache=True)
def _state_rate(code, p, v, psi):
    if code == 3:
        return (p[4] * math.exp(-psi) - abs(v)) / p[3]
    if code == 4:
        return abs(v)
    if code == 6:
        return (p[1] * v - psi) / p[3]
    if code == 7:
        return (p[1] * v - psi) / p[4]
    if code == 8 and p[5] > 0.0:
        return (p[1] * v - psi) / p[5]
    if code == 9 and p[7] > 0.0:
        return (p[1] * v - psi) / p[7]
    if code == 10:
        return v - psi / p[5]
    if code == 12 or code == 13:
        return abs(v) * (p[1] * v - psi) / p[5]
    return 0.0


@njit(cache=True)
def _run(code, p, mass, k, vd, xd0, gamma, static, start_v, stop_v, backward, armed_below,
         psi0, h, n_sub, du, out_x, out_v, yields, sticks, counts):
    samples, reps = out_x.shape
    for r in range(reps):
        x, v, psi, x_yield, top = 0.0, 0.0, psi0, 0.0, 0.0
        slipping, armed = False, False
        ny, ns = 0, 0
        for i in range(samples):
            out_x[i, r] = x
            out_v[i, r] = v
            for j in range(n_sub):
                t = (i * n_sub + j) * h
                if slipping:
                    xi = mass * du[i * n_sub + j, r] / h
                    a1 = (k * (xd0 + vd * t - x) - _friction(code, p, v, psi, x, x_yield, top)
                          - gamma * (v - vd) + xi) / mass
                    p1 = _state_rate(code, p, v, psi)
                    x2, v2, s2 = x + 0.5 * h * v, v + 0.5 * h * a1, psi + 0.5 * h * p1
                    a2 = (k * (xd0 + vd * (t + 0.5 * h) - x2)
                          - _friction(code, p, v2, s2, x2, x_yield, top) - gamma * (v2 - vd) + xi) / mass
                    p2 = _state_rate(code, p, v2, s2)
                    x3, v3, s3 = x + 0.5 * h * v2, v + 0.5 * h * a2, psi + 0.5 * h * p2
                    a3 = (k * (xd0 + vd * (t + 0.5 * h) - x3)
                          - _friction(code, p, v3, s3, x3, x_yield, top) - gamma * (v3 - vd) + xi) / mass
                    p3 = _state_rate(code, p, v3, s3)
                    x4, v4, s4 = x + h * v3, v + h * a3, psi + h * p3
                    a4 = (k * (xd0 + vd * (t + h) - x4)
                          - _friction(code, p, v4, s4, x4, x_yield, top) - gamma * (v4 - vd) + xi) / mass
                    p4 = _state_rate(code, p, v4, s4)
                    x = x + h * (v + 2 * v2 + 2 * v3 + v4) / 6
                    vn = v + h * (a1 + 2 * a2 + 2 * a3 + a4) / 6
                    psi = psi + h * (p1 + 2 * p2 + 2 * p3 + p4) / 6
                    force = k * (xd0 + vd * (t + h) - x)
                    if force <= armed_below:
                        armed = True
                    # the re-stick: the velocity at the step's end or at any of its stages
                    # fell to the stop (a stage's sign of a Coulomb force flips at v = 0)
                    low = min(min(v2, v3), min(v4, vn)) <= stop_v
                    if (armed and low) or force <= backward:
                        slipping, armed, v = False, False, 0.0
                        if ns < sticks.shape[1]:
                            # the last sample on which the wall slid (the detector's
                            # re-stick): sample i + 1 has the wall stopped, the static
                            # friction's impulse in the step before it
                            sticks[r, ns] = i
                        ns += 1
                    else:
                        v = vn
                        if code == 5 or (code == 9 and p[8] == 1.0):
                            psi = max(psi, abs(v))
                        top = max(top, abs(v))     # the slip's fastest |v| so far
                else:
                    # stuck: at rest, the state aging
                    psi = psi + h * _state_rate(code, p, 0.0, psi)
                    force = k * (xd0 + vd * (t + h) - x)
                    thr = static if code != 3 else _friction(code, p, start_v, psi, x, x, 0.0)
                    if force >= thr:
                        slipping, v = True, start_v
                        x_yield = x
                        if code == 4 or code == 5 or code >= 7:
                            psi = 0.0       # the slip's state starts at each yield
                        elif code == 6:
                            psi = p[2]      # the stress the film still holds at the yield
                        top = 0.0
                        if ny < yields.shape[1]:
                            yields[r, ny] = i
                        ny += 1
        counts[r, 0] = min(ny, yields.shape[1])
        counts[r, 1] = min(ns, sticks.shape[1])


def slide(law: str, parameters, *, mass: float, stiffness: float, drive_velocity: float,
          static_force: float = math.inf, duration: float, dt: float, replicas: int = 1,
          velocity_noise=0.0, velocity_correlation=0.0, rattle: float = 0.0,
          seed: int = 0, initial_force: float = 0.0, stop_velocity: float = 0.0,
          backward_force: float = -math.inf, armed_below: float = math.inf,
          start_velocity: float = 0.0, initial_state: float = 0.0,
          substeps: int = 1, mount_damping: float = 0.0,
          comoving_mass: float = 0.0) -> list[dict]:
    """``replicas`` runs of the slider (module text), each with its own noise.

    Parameters
    ----------
    law : str
        One of :data:`LAWS`.
    parameters : sequence of float
        Its parameters (:data:`LAWS`).
    mass, stiffness, drive_velocity : float
        M, K and V (the spring end moves at V from x_d0 = ``initial_force``/K).
    static_force : float
        The spring force at which a stuck wall yields (``rate-state``: the law's force at
        ``start_velocity`` and the aged state).
    duration, dt : float
        Length of the run and the sampling step.
    velocity_noise, velocity_correlation : float or sequence of float
        rms and lag-one (per ``dt``) correlation of u, the random force's velocity; with
        sequences (one correlation per rms) u is the sum of independent such terms.
    rattle : float
        rms of the white noise added to the sampled velocity.
    stop_velocity, backward_force, armed_below, start_velocity : float
        The re-stick and the yield (module text).
    initial_state : float
        ψ at t = 0 (``rate-state``: ln(θ·v0/d_c)); while stuck ψ ages (dθ/dt = 1).
    substeps : int
        Runge–Kutta steps per sample.
    mount_damping : float
        γM of an MD run's mount dashpot (force per velocity): −γM·(v − V) acts on the
        slipping wall besides the law (a stuck wall is at rest); 0, none.
    comoving_mass : float
        m_c, the film's mass carried by the slipping wall (module text); 0, none.

    Returns
    -------
    list of dict
        Per replica: ``time, spring_force, drive_position, wall_position, wall_velocity``
        (the sampled velocity, rattle included) and ``yield_index``, ``stick_index`` (the
        sample at or just before each yield, the last sample of each slip; complete
        slips only).
    """
    if law not in LAWS:
        raise ValueError(f"law = {law!r}: one of {', '.join(LAWS)}")
    p = np.asarray(parameters, float)
    if p.shape != (LAWS[law],) or not np.all(np.isfinite(p)):
        raise ValueError(f"parameters = {parameters!r}: {LAWS[law]} finite values for {law!r}")
    if (law in LOOP_LAWS or law == "maxwell-weakening") and not p[3] > 0:
        raise ValueError(f"parameters = {parameters!r}: the loop's scale D_c, v_c or τ_r "
                         "(the fourth) must be > 0")
    if law == "corrugated" and not (p[3] > 0 and p[5] >= 0):
        raise ValueError(f"parameters = {parameters!r}: the registry's period λ (the fourth) "
                         "must be > 0, the lag τ_r (the sixth) >= 0")
    if law == "corrugated-loop" and not (p[3] > 0 and p[5] > 0 and p[7] >= 0
                                         and (p[8] == 0 or (p[8] == 1 and p[7] == 0))):
        raise ValueError(f"parameters = {parameters!r}: the loop's scale D and the registry's "
                         "period λ (the fourth, sixth) must be > 0, the lag τ_r (the eighth) "
                         ">= 0, the kind (the ninth) 0 (slip-weakening) or 1 (melting, "
                         "without a lag)")
    if law == "lagged-registry" and not (p[3] > 0 and p[5] > 0):
        raise ValueError(f"parameters = {parameters!r}: the registry's period λ and its lag "
                         "τ_g (the fourth, sixth) must be > 0")
    if law == "lagged-registry" and dt / max(int(substeps), 1) > p[5]:
        raise ValueError(f"parameters = {parameters!r}: the registry's lag τ_g = {p[5]!r} is "
                         f"shorter than the integration step dt/substeps = "
                         f"{dt / max(int(substeps), 1)!r}, which would not resolve it (take "
                         f"substeps >= {math.ceil(dt / p[5])})")
    if law in _BRANCH_WEIGHTS:
        a1, a2, w1, w2 = (p[k] for k in _BRANCH_WEIGHTS[law])
        lagged = law == "distance-lag-branching"
        if not (p[3] > 0 and (p[5] > 0 or not lagged) and a1 >= 0 and a2 >= 0 and w1 <= 1
                and w2 >= -1):
            raise ValueError(f"parameters = {parameters!r}: the registry's period λ (the "
                             "fourth)" + (" and the lag's distance d (the sixth)" if lagged
                                          else "") + " must be > 0, the amplitudes ΔF₁, ΔF₂ "
                             ">= 0, w₁ <= 1 and w₂ >= -1 (no amplitude below 0)")
    if law == "distance-lag" and not (p[3] > 0 and p[5] > 0):
        raise ValueError(f"parameters = {parameters!r}: the registry's period λ and the lag's "
                         "distance d (the fourth, sixth) must be > 0")
    if law == "maxwell-weakening" and not p[4] > 0:
        raise ValueError(f"parameters = {parameters!r}: the relaxation time τ_r (the fifth) "
                         "must be > 0")
    for name, val in (("mass", mass), ("stiffness", stiffness), ("duration", duration),
                      ("dt", dt)):
        if not (math.isfinite(val) and val > 0):
            raise ValueError(f"{name} = {val!r}: must be positive and finite")
    for name, val in (("mount_damping", mount_damping), ("comoving_mass", comoving_mass)):
        if not (math.isfinite(val) and val >= 0):
            raise ValueError(f"{name} = {val!r}: must be >= 0 and finite")
    if int(replicas) < 1 or int(substeps) < 1:
        raise ValueError(f"replicas = {replicas!r}, substeps = {substeps!r}: must be >= 1")
    sig, rho = np.atleast_1d(np.asarray(velocity_noise, float)), np.atleast_1d(
        np.asarray(velocity_correlation, float))
    if (sig.ndim != 1 or sig.shape != rho.shape or not np.all((0 <= rho) & (rho < 1))
            or not np.all(sig >= 0) or not rattle >= 0):
        raise ValueError(f"velocity_noise = {velocity_noise!r}, velocity_correlation = "
                         f"{velocity_correlation!r}, rattle = {rattle!r}: rms >= 0 and "
                         "correlations in [0, 1), one correlation per rms")
    reps, n_sub = int(replicas), int(substeps)
    rng = np.random.default_rng(seed)
    h = dt / n_sub
    samples = int(math.floor(duration / dt + 1e-9))
    # u: a sum of Ornstein–Uhlenbeck terms at the steps, each AR(1) of rms σ_j and
    # correlation ρ_j per sample
    du = np.zeros((samples * n_sub, reps))
    for s_j, r_j in zip(sig, rho):
        rho_h = float(r_j) ** (1.0 / n_sub)
        kicks = rng.normal(0.0, s_j * math.sqrt(1.0 - rho_h ** 2), (samples * n_sub, reps))
        u0 = rng.normal(0.0, s_j, reps)
        u = lfilter([1.0], [1.0, -rho_h], kicks, axis=0, zi=(rho_h * u0)[None, :])[0]
        du += np.diff(np.vstack([u0[None, :], u]), axis=0)
    out_x, out_v = np.empty((samples, reps)), np.empty((samples, reps))
    most = samples // 2 + 2
    yields = np.zeros((reps, most), np.int64)
    sticks = np.zeros((reps, most), np.int64)
    counts = np.zeros((reps, 2), np.int64)
    # the inertia of the slipping wall and the film it carries (the random force moves it
    # by du whatever m_c is: u is the wall's velocity noise the MD's was measured as)
    _run(_CODE[law], p, float(mass) + float(comoving_mass), float(stiffness), float(drive_velocity),
         float(initial_force) / stiffness, float(mount_damping), float(static_force),
         float(start_velocity),
         float(stop_velocity), float(backward_force), float(armed_below), float(initial_state),
         h, n_sub, du, out_x, out_v, yields, sticks, counts)
    t = dt * np.arange(samples)
    xd = initial_force / stiffness + drive_velocity * t
    runs = []
    for r in range(reps):
        y, s = _alternating(yields[r, :counts[r, 0]], sticks[r, :counts[r, 1]])
        runs.append({"time": t, "spring_force": stiffness * (xd - out_x[:, r]),
                     "drive_position": xd, "wall_position": out_x[:, r].copy(),
                     "wall_velocity": out_v[:, r] + rng.normal(0.0, rattle, samples),
                     "yield_index": y, "stick_index": s})
    return runs


def _alternating(yields, sticks) -> tuple[np.ndarray, np.ndarray]:
    """The complete slips' (yield, re-stick) samples; a re-stick and a yield within one
    sample interval (a pause shorter than the sampling) join their two slips into one."""
    y, s = [], []
    for a, b in zip(yields, sticks):
        if s and a < s[-1]:
            s[-1] = int(b)
        else:
            y.append(int(a))
            s.append(int(b))
    return np.asarray(y, int), np.asarray(s, int)
