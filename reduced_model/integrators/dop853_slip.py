"""One slip of a stateless law with static friction on Hairer's DOP853 (the fast path
of :mod:`~filmfriction.reduced_model.integrators.event_driven`): the right-hand side on
plain floats, the displacement counted from the slip's start, the re-stick located by
Newton's method on the RK step map (:func:`restick_root`)."""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

__all__ = ["slip_dop853", "restick_root"]


def slip_dop853(law, N, M, K, d, u, va, f0, v0, sigma, t_end, rtol, atol, max_step):
    """One slip of a stateless law with static friction, ended at s = 0.

    Hairer's Fortran DOP853 (scipy.integrate.ode): the step loop runs in
    Fortran; the right-hand side is a closure on plain floats (no NumPy in the
    per-evaluation path) and a Python callback per accepted step watches the
    sign of the slip velocity.  The state is (displacement since the slip began,
    velocity, drive work, friction and damper dissipation), all starting at 0
    but the velocity; ``f0`` is the spring force at the start.

    The re-stick is the root of the slip velocity of the RK solution itself
    (not of an interpolant): bracketed between two accepted steps, first guessed
    by a cubic Hermite fit, then refined by Newton's method on the map "one
    DOP853 step from the last accepted point to t" (its derivative is the
    acceleration, known from the right-hand side), falling back to brentq on the
    same map should Newton leave the bracket.
    Returns (times, states, ended_at_restick, n_evaluations).
    """
    from scipy.integrate import ode

    # scipy's dop853 wrapper takes a scalar atol: integrate z = y / scale with the
    # per-component tolerances folded into the scale
    scale = np.asarray(atol, dtype=float) / 1e-12
    s0, s1, s2, s3, s4 = (float(c) for c in scale)
    i0, i1, i2, i3, i4 = 1.0 / s0, 1.0 / s1, 1.0 / s2, 1.0 / s3, 1.0 / s4
    # plain Python floats throughout: NumPy scalars would cost ~10x per operation
    N, M, K, d, u, va, f0, sig = (float(c) for c in (N, M, K, d, u, va, f0, sigma))
    sliding, Kva = law.scalar_sliding(N), K * va
    ks0, a1, v0_scale, u_i2, dv_i4 = K * s0, i1 / M, s1 * i0, u * i2, d * i4
    count = [0]

    def f(tau, z):
        count[0] += 1
        z0, z1, _, _, _ = z.tolist()
        vb = z1 * s1
        f_spring = f0 + Kva * tau - ks0 * z0
        s = vb - u
        ss = sig * s
        fr = sig * sliding(ss if ss > 0.0 else 0.0)
        return [z1 * v0_scale, (f_spring - d * vb - fr) * a1, f_spring * va * i2 - fr * u_i2,
                fr * s * i3, dv_i4 * vb * vb]

    def slip_of(z):
        return sig * (float(z[1]) * s1 - u)

    ts, zs = [0.0], [np.array([0.0, v0 * i1, 0.0, 0.0, 0.0])]

    def watch(tau, z):
        if tau > ts[-1]:
            ts.append(tau)
            zs.append(np.array(z))
            if slip_of(z) < 0.0:
                return -1                       # crossed s = 0: stop and bracket
        return 0

    def solver(first_step=0.0):
        return ode(f).set_integrator("dop853", rtol=rtol, atol=1e-12, nsteps=10 ** 8,
                                     max_step=max_step, first_step=first_step)

    main = solver()
    main.set_solout(watch)
    main.set_initial_value(zs[0], 0.0)
    main.integrate(t_end)
    if not slip_of(zs[-1]) < 0.0:
        return np.array(ts), (np.array(zs) * scale).T, False, count[0]
    t_a, z_a, t_b = ts[-2], zs[-2], ts[-1]

    last = {t_a: z_a}

    def state_at(tau):
        if tau not in last:
            sub = solver(first_step=tau - t_a)  # one step (if its error test passes)
            sub.set_initial_value(z_a, t_a)
            last.clear()
            last[t_a], last[tau] = z_a, sub.integrate(tau)
        return last[tau]

    def slip_rate(tau, z):
        return sig * f(tau, z)[1] * s1

    t_root = restick_root(state_at, slip_of, slip_rate, t_a, z_a, t_b, zs[-1])
    y_root = state_at(t_root) * scale
    y_root[1] = u                               # the root: slip velocity exactly zero
    ys = np.array(zs) * scale
    ts[-1], ys[-1] = t_root, y_root
    return np.array(ts), ys.T, True, count[0]


def restick_root(state_at, slip_of, slip_rate, t_a, z_a, t_b, z_b):
    """Root of ``slip_of(state_at(t))`` in [t_a, t_b] (slip >= 0 at t_a, < 0 at t_b)."""
    g_a, g_b = slip_of(z_a), slip_of(z_b)
    if g_a <= 0.0:
        return t_a
    h = t_b - t_a
    xtol = max(1e-15 * abs(t_b), 1e-300)
    # cubic Hermite guess from values and slopes at both ends, solved by Newton from
    # the secant guess (the cubic is monotone enough on a bracket this short)
    d_a, d_b = slip_rate(t_a, z_a) * h, slip_rate(t_b, z_b) * h
    c2, c3 = 3.0 * (g_b - g_a) - 2.0 * d_a - d_b, 2.0 * (g_a - g_b) + d_a + d_b
    theta = g_a / (g_a - g_b)
    for _ in range(6):
        slope = d_a + theta * (2.0 * c2 + 3.0 * c3 * theta)
        if not slope < 0.0:
            theta = g_a / (g_a - g_b)
            break
        theta -= (g_a + theta * (d_a + theta * (c2 + theta * c3))) / slope
        if not 0.0 < theta < 1.0:
            theta = g_a / (g_a - g_b)
            break
    lo, hi = t_a, t_b
    t = t_a + theta * h
    for _ in range(8):
        t = min(max(t, lo), hi)
        z = state_at(t)
        g = slip_of(z)
        if g == 0.0:
            return t
        if g > 0.0:
            lo = t
        else:
            hi = t
        rate = slip_rate(t, z)
        step = -g / rate if rate != 0.0 else math.inf
        if abs(step) <= xtol:
            return t
        t_new = t + step
        if not lo < t_new < hi:
            break                               # Newton left the bracket: bisect the rest
        t = t_new
    if hi == t_b and not slip_of(state_at(t_b)) < 0.0:
        return t_b      # re-integrating the last step lands on s = 0 within round-off
    return brentq(lambda tt: slip_of(state_at(tt)), lo, hi, xtol=xtol, rtol=8.9e-16)
