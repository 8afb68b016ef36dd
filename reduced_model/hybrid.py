"""Event-driven integration for friction laws without a closed form.

Slip phases are integrated by ``solve_ivp`` (DOP853, rtol 1e-10) with the
slip velocity, the friction state and the three energy integrals (drive work,
friction and damper dissipation) all inside the state vector, so the ledger
is integrated to the same accuracy as the motion.  For laws with static
friction:

* the slip direction sigma is frozen during a slip and friction is evaluated
  as ``sigma * F(max(sigma*s, 0))``, so the right-hand side stays continuous up
  to the terminal event ``s = 0`` (located on the dense output);
* at ``s = 0`` the block re-sticks if the force it must hold is within the
  static threshold, otherwise the slip reverses;
* a stick is solved without time stepping: the spring force is linear in
  time and the friction state evolves in closed form (``law.stick_state``), so
  breakaway is a bracketed root; ``v = u`` holds exactly, with no creep.

``max_step`` is a sixteenth of the natural period (scaled up for heavy
damping): solve_ivp only detects a sign change between steps, so a step
spanning a whole oscillation could miss two crossings.

Smooth laws (rate-and-state, films without a yield force) are one ODE; their
``slip``/``stick`` events mark the maxima/minima of the spring force.  A
massless block (M = 0) is integrated quasi-statically: the slip velocity
follows from ``friction(v) = spring force`` (``law.quasi_static_speed``).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from ._checks import SimulationLimitError
from .coulomb import stick_break_time
from .trajectory import Problem

__all__ = ["run_ode"]

MAX_STEPS = 20_000_000


def _stick_break(law, state, N, held, rate, remaining):
    """Time at which ``|held + rate t|`` first reaches the (evolving) static threshold."""
    scale = law.stick_timescale()
    if scale is None:
        return stick_break_time(held, rate, law.static_force(state, N))

    def excess(tau):
        return abs(held + rate * tau) - law.static_force(law.stick_state(state, tau), N)

    if excess(0.0) >= 0.0:
        return 0.0
    # fine grid over the ageing transient, then geometric: brackets the first crossing
    grid = list(np.linspace(0.0, 50.0 * scale, 401)[1:])
    while grid[-1] < remaining:
        grid.append(grid[-1] * 1.5)
    prev = 0.0
    for tk in grid:
        tk = min(tk, remaining)
        if excess(tk) >= 0.0:
            return brentq(excess, prev, tk, xtol=max(1e-16 * tk, 1e-300), rtol=8.9e-16)
        if tk >= remaining:
            break
        prev = tk
    return math.inf


def _scales(p: Problem):
    """Absolute tolerances per state component, from the problem's own scales."""
    law, N, K = p.law, p.normal_load, p.stiffness
    force = max(abs(K * p.xa0), abs(p.damping * (p.va or p.u)),
                abs(law.static_force(p.state0, N) or 0.0),
                abs(float(law.sliding_force(abs(p.va - p.u) or 1e-300, p.state0, N))), 1e-300)
    length = force / K
    omega = math.sqrt(K / p.mass) if p.mass > 0 else 1.0 / max(p.duration, 1e-300)
    speed = max(abs(p.va), abs(p.u), abs(p.v0), length * omega)
    energy = force * length
    atol = [1e-12 * length, 1e-12 * speed, 1e-12 * energy, 1e-12 * energy, 1e-12 * energy]
    atol += [1e-10 * (1.0 + abs(s)) for s in p.state0]
    return np.array(atol)


def run_ode(p: Problem, rtol: float = 1e-10):
    """Integrate a block with any friction law; returns a SimulationResult."""
    if p.mass == 0.0:
        return _run_massless(p, rtol)
    law, M, K, d, N, u, va = p.law, p.mass, p.stiffness, p.damping, p.normal_load, p.u, p.va
    has_stick = law.static_force(p.state0, N) is not None
    zeta = (d + law.low_speed_drag()) / (2.0 * math.sqrt(K * M))
    max_step = p.period / 16.0 * max(1.0, zeta)
    if p.duration / max_step > MAX_STEPS:
        raise SimulationLimitError(
            f"duration = {p.duration:.6g} spans {p.duration / p.period:.3g} natural periods "
            f"(2 pi sqrt(M/K) = {p.period:.3g}); integrating that with a smooth law needs more than "
            f"{MAX_STEPS:.0e} steps. Shorten the duration, or for a very stiff/light block use "
            "mass = 0 (massless formulation) or a closed-form law.")
    atol = _scales(p)
    # Rate-and-state is stiff near v = 0 (relaxation rate a N / (M v)), and a state that
    # relaxes over a slip distance (contact age, theta) becomes stiff at high slip speed:
    # laws with a state go to LSODA, which switches to BDF when (and only when) needed.
    # A heavily overdamped slip (zeta >> 1: velocity relaxes in M/B, slides in B/K) is stiff too.
    method = "LSODA" if (law.stiff or law.state_names or zeta > 10.0) else "DOP853"
    rec = p.recorder()
    n_stick = max(p.samples // 8, 2)
    T = p.duration
    t, x, v, xa, state = 0.0, p.x0, p.v0, p.xa0, np.array(p.state0, dtype=float)

    sigma, mode = 1.0, "slip"
    if has_stick and v == u:
        held = K * (xa - x) - d * u
        if abs(held) <= law.static_force(state, N):
            mode = "stick"
        else:
            sigma = math.copysign(1.0, held)
    elif v != u:
        sigma = math.copysign(1.0, v - u)

    while t < T:
        remaining = T - t
        if mode == "stick":
            held = K * (xa - x) - d * u
            rate = K * (va - u)
            tau = _stick_break(law, state, N, held, rate, remaining)
            end = min(tau, remaining)
            ts = np.linspace(0.0, end, n_stick)
            states = (np.array([law.stick_state(state, s) for s in ts]).T if state.size
                      else np.empty((0, ts.size)))
            f_spring = K * (xa - x) * ts + 0.5 * K * (va - u) * ts ** 2
            drive = va * f_spring + u * (d * u * ts - f_spring)
            rec.append(t + ts, x + u * ts, np.full_like(ts, u), xa + va * ts, states,
                       drive, np.zeros_like(ts), d * u * u * ts)
            x, xa, v, state = x + u * end, xa + va * end, u, law.stick_state(state, end)
            if tau >= remaining:
                break
            t += end
            sigma = math.copysign(1.0, held + rate * tau)
            mode = "slip"
            rec.event("slip", t, K * (xa - x))
            continue

        xa_seg, sig = xa, sigma
        if has_stick:
            def friction(s, st):
                return sig * law.sliding_force(max(sig * s, 0.0), st, N)
        else:
            def friction(s, st):
                return law.friction(s, st, N)

        if law.state_names:
            def rhs(tau, y):
                f_spring = K * (xa_seg + va * tau - y[0])
                s = y[1] - u
                fr = friction(s, y[5:])
                return np.concatenate(([y[1], (f_spring - d * y[1] - fr) / M, f_spring * va - fr * u,
                                        fr * s, d * y[1] * y[1]], law.state_rate(abs(s), y[5:])))
        else:
            # stateless law: the same equations on plain floats (this is the hot loop)
            def rhs(tau, y):
                x_, v_ = float(y[0]), float(y[1])
                f_spring = K * (xa_seg + va * tau - x_)
                s = v_ - u
                fr = float(friction(s, ()))
                return np.array((v_, (f_spring - d * v_ - fr) / M, f_spring * va - fr * u, fr * s, d * v_ * v_))

        if has_stick and method == "DOP853":
            ts, ys, ended, nfev = _slip_dop853(rhs, np.concatenate(([x, v, 0.0, 0.0, 0.0], state)),
                                               remaining, sig, u, rtol, atol, max_step)
            rec.nfev += nfev
            rec.append(t + ts, ys[0], ys[1], xa + va * ts, ys[5:], ys[2], ys[3], ys[4])
            x, v, xa, state = ys[0, -1], ys[1, -1], xa + va * ts[-1], ys[5:, -1].copy()
            if not ended:
                break
            t += ts[-1]
            held = K * (xa - x) - d * u
            if abs(held) <= law.static_force(state, N):
                mode = "stick"
                rec.event("stick", t, K * (xa - x))
            else:
                sigma = math.copysign(1.0, held)
                rec.event("reversal", t, K * (xa - x))
            continue

        events = []
        if has_stick:
            def stop(tau, y):
                return y[1] - u
            stop.terminal, stop.direction = True, -sig
            events = [stop]
        y0 = np.concatenate(([x, v, 0.0, 0.0, 0.0], state))
        sol = solve_ivp(rhs, (0.0, remaining), y0, method=method, rtol=rtol, atol=atol,
                        max_step=max_step, events=events, dense_output=not has_stick)
        rec.nfev += sol.nfev
        ts, ys = sol.t, sol.y
        if not has_stick:
            ts, ys, marks = _force_extrema(ts, ys, sol.sol, lambda tau, y: y[1] - va,
                                           lambda tau, y: K * (xa_seg + va * tau - y[0]))
        ended = has_stick and sol.status == 1
        if ended:
            ys[1, -1] = u                      # the root: slip velocity exactly zero
        rec.append(t + ts, ys[0], ys[1], xa + va * ts, ys[5:], ys[2], ys[3], ys[4])
        if not has_stick:
            rec.insert_events([t + tm for tm, _ in marks], [k for _, k in marks])
        if sol.status == -1:
            return rec.finish(status=-1, message=f"solve_ivp failed at t = {t + ts[-1]:.6g}: {sol.message}")
        x, v, xa, state = ys[0, -1], ys[1, -1], xa + va * ts[-1], ys[5:, -1].copy()
        if not ended:
            break
        t += ts[-1]
        held = K * (xa - x) - d * u
        if abs(held) <= law.static_force(state, N):
            mode = "stick"
            rec.event("stick", t, K * (xa - x))
        else:
            sigma = math.copysign(1.0, held)
            rec.event("reversal", t, K * (xa - x))
    return rec.finish()


def _slip_dop853(rhs, y0, t_end, sigma, u, rtol, atol, max_step):
    """One slip with Hairer's Fortran DOP853 (scipy.integrate.ode), ended at s = 0.

    Same method as solve_ivp's DOP853 but the step loop runs in Fortran, with a
    Python callback only per accepted step to watch the sign of the slip
    velocity; the crossing is then bracketed between two accepted steps and
    located by brentq, re-integrating the last step to each trial time (so the
    event state is an RK solution, not an interpolant).
    Returns (times, states, ended_at_restick, n_evaluations).
    """
    from scipy.integrate import ode

    # scipy's dop853 wrapper takes a scalar atol: integrate z = y / scale with the
    # per-component tolerances folded into the scale
    scale = np.asarray(atol, dtype=float) / 1e-12
    count = [0]

    def f(tau, z):
        count[0] += 1
        return rhs(tau, z * scale) / scale

    ts, zs = [0.0], [np.array(y0, dtype=float) / scale]

    def watch(tau, z):
        if tau > ts[-1]:
            ts.append(tau)
            zs.append(np.array(z))
            if sigma * (z[1] * scale[1] - u) < 0.0:
                return -1                       # crossed s = 0: stop and bracket
        return 0

    def solver():
        return ode(f).set_integrator("dop853", rtol=rtol, atol=1e-12, nsteps=10 ** 8, max_step=max_step)

    main = solver()
    main.set_solout(watch)
    main.set_initial_value(zs[0], 0.0)
    main.integrate(t_end)
    if not (sigma * (zs[-1][1] * scale[1] - u) < 0.0):
        return np.array(ts), (np.array(zs) * scale).T, False, count[0]
    t_a, z_a = ts[-2], zs[-2]
    sub = solver()

    def state_at(tau):
        sub.set_initial_value(z_a, t_a)
        return sub.integrate(tau) * scale

    def slip(tau):
        return sigma * (state_at(tau)[1] - u)

    t_root = brentq(slip, t_a, ts[-1], xtol=max(1e-15 * ts[-1], 1e-300), rtol=8.9e-16)
    y_root = state_at(t_root)
    y_root[1] = u                               # the root: slip velocity exactly zero
    ys = np.array(zs) * scale
    ts[-1], ys[-1] = t_root, y_root
    return np.array(ts), ys.T, True, count[0]


def _force_extrema(ts, ys, dense, rate, force, rel_tol=1e-6):
    """Maxima ("slip") and minima ("stick") of the spring force of a smooth run.

    Candidates are sign changes of ``rate`` (v - v_drive) between steps, refined
    on the dense output; wiggles smaller than ``rel_tol`` of the force range
    (round-off around steady sliding) are dropped, and kinds alternate.
    """
    g = np.array([rate(tt, ys[:, i]) for i, tt in enumerate(ts)])
    f_all = np.array([force(tt, ys[:, i]) for i, tt in enumerate(ts)])
    idx = np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)[0]
    found = []
    for i in idx:
        a, b = ts[i], ts[i + 1]
        fun = lambda tt: rate(tt, dense(tt))
        ga, gb = fun(a), fun(b)
        if ga == 0.0 or gb == 0.0 or np.sign(ga) == np.sign(gb):
            tt = a if abs(ga) < abs(gb) else b           # interpolant disagrees at round-off: take the end
        else:
            tt = brentq(fun, a, b, xtol=max(1e-16 * abs(b), 1e-300), rtol=8.9e-16)
        found.append((tt, "slip" if g[i] < 0 else "stick", force(tt, dense(tt))))
    threshold = rel_tol * max(np.ptp(f_all), np.max(np.abs(f_all)), 1e-300)
    kept = []
    for tt, kind, f in found:
        if kept and kept[-1][1] == kind:
            # same kind twice: keep the more extreme one
            if (kind == "slip") == (f > kept[-1][2]):
                kept[-1] = (tt, kind, f)
            continue
        if abs(f - (kept[-1][2] if kept else f_all[0])) < threshold:
            if kept:
                kept.pop()                               # a round-off wiggle: drop the pair
            continue
        kept.append((tt, kind, f))
    if not kept:
        return ts, ys, []
    ev_t = np.array([k[0] for k in kept])
    ev_y = np.array([dense(tt) for tt in ev_t]).T
    new = ~np.isin(ev_t, ts)
    where = np.searchsorted(ts, ev_t[new])
    ts = np.insert(ts, where, ev_t[new])
    ys = np.insert(ys, where, ev_y[:, new], axis=1)
    return ts, ys, [(k[0], k[1]) for k in kept]


def _run_massless(p: Problem, rtol: float):
    """Quasi-static block (M = 0): friction(v, state) = spring force at every instant."""
    law, K, N, va = p.law, p.stiffness, p.normal_load, p.va
    atol = np.delete(_scales(p), [1, 4])

    def speed(tau, y):
        return law.quasi_static_speed(K * (p.xa0 + va * tau - y[0]), y[3:], N)

    def rhs(tau, y):
        f_spring = K * (p.xa0 + va * tau - y[0])
        v = law.quasi_static_speed(f_spring, y[3:], N)
        return np.concatenate(([v, f_spring * va, f_spring * v], law.state_rate(abs(v), y[3:])))

    y0 = np.concatenate(([p.x0, 0.0, 0.0], p.state0))
    sol = solve_ivp(rhs, (0.0, p.duration), y0, method="DOP853", rtol=rtol, atol=atol,
                    max_step=p.duration / 200.0, dense_output=True)
    ts, ys, marks = _force_extrema(sol.t, sol.y, sol.sol, lambda tau, y: speed(tau, y) - va,
                                   lambda tau, y: K * (p.xa0 + va * tau - y[0]))
    p.v0 = float(speed(0.0, y0))          # the massless block starts at its equilibrium speed
    v = np.array([speed(tt, ys[:, i]) for i, tt in enumerate(ts)])
    rec = p.recorder()
    rec.nfev = sol.nfev
    rec.append(ts, ys[0], v, p.xa0 + va * ts, ys[3:], ys[1], ys[2], np.zeros_like(ts))
    rec.insert_events([tm for tm, _ in marks], [k for _, k in marks])
    if sol.status == -1:
        return rec.finish(status=-1, message=f"solve_ivp failed: {sol.message}")
    return rec.finish()
