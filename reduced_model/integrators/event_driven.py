# Two scipy solvers subclassed through _step_impl (_WatchedLSODA, _LocalCapRadau): that
# method is scipy's documented extension point, not a private internal.  The OdeSolver
# reference (scipy.integrate.OdeSolver, "In order to implement a new solver ...", the same
# text from scipy 1.0 to 1.18) says "A solver must implement a private method
# _step_impl(self) which propagates a solver one step further" returning (success,
# message), and solve_ivp takes any OdeSolver subclass as ``method``; a subclass that
# calls super()._step_impl() is that contract used as documented.  The public
# alternative, driving OdeSolver.step() by hand, would re-implement solve_ivp's event
# location and dense-output stitching (its helpers are private), and solve_ivp's
# ``events`` cannot change the step cap.  What the contract does not cover:
# _LocalCapRadau sets ``max_step`` before each step and Radau reads that attribute at
# every step (scipy's source, pinned by constraints.txt); tests/reduced_model/
# test_stiff_hold.py fails if a scipy release stops honouring it (the creeping hold).
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

Stateless laws with static friction (Coulomb via ``method="ode"``, the
Stribeck curves, exponential weakening, films with a yield force unless
heavily damped) take a fast path, :func:`~filmfriction.reduced_model.integrators.dop853_slip.slip_dop853`: Hairer's Fortran
DOP853 with a right-hand side on plain Python floats, the displacement counted
from the slip's start, and the re-stick located by Newton's method on the RK
step map (see its docstring).

Laws with a state (and stiff ones) run on LSODA; where a slip starts
overdamped (the local damping ratio above :data:`OVERDAMPED`, e.g. a creeping
hold of a light block) the step cap follows that ratio, on Radau
(:class:`_LocalCapRadau`), so the hold does not crawl at a sixteenth of the
natural period.

Smooth laws (rate-and-state, films without a yield force) are one ODE; their
``slip``/``stick`` events mark the maxima/minima of the spring force.  Those with
one state variable (rate-and-state) first try the fast path of :mod:`.limit_cycle`
(DOP853 and the law compiled with numba, the converged limit cycle tiled), which
hands back to LSODA here where the run is stiff.  LSODA
past ``STEPS_PER_PERIOD`` steps per natural period counts as stalled and Radau
redoes the segment.  A
massless block (M = 0) is integrated quasi-statically: the slip velocity
follows from ``friction(v) = spring force`` (``law.quasi_static_speed``).
"""
from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.integrate import LSODA, Radau, solve_ivp
from scipy.optimize import brentq

from .._checks import SimulationLimitError
from .closed_form import settle, stick_break_time, tile_cycles
from .dop853_slip import slip_dop853
from .trajectory import Problem

__all__ = ["run_ode"]

MAX_STEPS = 20_000_000


class _WatchedLSODA(LSODA):
    """LSODA with a fixed step cap that gives up when it stalls.

    A stick-slip run of a light block can trap LSODA in steps far below any
    time scale of the motion (10^5 steps per natural period where 10^2 do).  More
    than :data:`STEPS_PER_PERIOD` steps per natural period elapsed (plus as many
    to start) count as a failure, and the caller redoes the segment with
    :class:`_LocalCapRadau`.  ``cap`` is accepted for the same call as Radau's and
    not used: scipy's LSODA takes its step cap once, at the start.
    """

    def __init__(self, fun, t0, y0, t_bound, *, cap=None, period=math.inf, **kwargs):
        super().__init__(fun, t0, y0, t_bound, **kwargs)
        self._t_start, self._period, self._count = t0, period, 0

    def _step_impl(self):
        self._count += 1
        if self._count > STEPS_PER_PERIOD * (1.0 + (self.t - self._t_start) / self._period):
            return False, (f"LSODA took more than {STEPS_PER_PERIOD} steps per natural period "
                           f"by t = {self.t:.6g}")
        return super()._step_impl()


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
    check_step = max_step
    if law.state_names or law.stiff:
        # the cap is lifted where friction overdamps the slip: judge the run at its drive speed
        s_ref = abs(va - u) or abs(p.v0 - u)
        h = max(1e-6 * s_ref, 1e-300)
        try:
            drag = (float(law.friction(s_ref + h, p.state0, N)) - float(law.friction(s_ref - h, p.state0, N))) / (2 * h)
        except (ValueError, OverflowError, ZeroDivisionError):
            drag = 0.0
        zeta_ref = (d + drag) / (2.0 * math.sqrt(K * M))
        if math.isfinite(zeta_ref) and zeta_ref >= OVERDAMPED:
            check_step = max(max_step, p.period / 16.0 * zeta_ref)
        elif not math.isfinite(zeta_ref):
            check_step = math.inf
    if p.duration / check_step > MAX_STEPS:
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
    if not has_stick and law.state_names:
        from .limit_cycle import run_smooth
        fast = run_smooth(p, rtol, atol, max_step)
        if fast is not None:
            return fast
    rec = p.recorder()
    n_stick = max(p.samples // 8, 2)
    T = p.duration
    t, x, v, xa, state = 0.0, p.x0, p.v0, p.xa0, np.array(p.state0, dtype=float)

    sigma, mode = 1.0, "slip"
    cycle = None    # (recorder mark, sigma) at the last yield: template of a periodic run
    if has_stick and v == u:
        mode, sigma = settle(K * (xa - x) - d * u, law.static_force(state, N))
    elif v != u:
        sigma = math.copysign(1.0, v - u)

    # a smooth law's plain-float form (rate-and-state), built once for every segment
    rates = None if has_stick else law.scalar_state_rates(N)
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
            if not state.size:
                # stateless: every slip starts from the same relative state, the run is periodic
                t, x, xa, cycle = tile_cycles(rec, cycle, sigma, t, x, xa, T)
            continue

        marks, failure = [], None
        if has_stick and method == "DOP853":
            # stateless law: the slip runs on plain floats with the displacement counted
            # from the slip's start (rtol then applies to the slip, not to the whole run)
            ts, ys, ended, nfev = slip_dop853(law, N, M, K, d, u, va, K * (xa - x), v, sigma,
                                               remaining, rtol, atol, max_step)
            ys[0] += x
            rec.nfev += nfev
        else:
            xa_seg, sig = xa, sigma
            if has_stick:
                def friction(s, st):
                    return sig * law.sliding_force(max(sig * s, 0.0), st, N)
            else:
                def friction(s, st):
                    return law.friction(s, st, N)

            if rates is not None:
                # a smooth law with a plain-float form (rate-and-state): the hot loop on floats
                def rhs(tau, y):
                    x_, v_ = float(y[0]), float(y[1])
                    f_spring = K * (xa_seg + va * tau - x_)
                    s = v_ - u
                    fr, r = rates(s, y[5:].tolist())
                    return np.array((v_, (f_spring - d * v_ - fr) / M, f_spring * va - fr * u, fr * s,
                                     d * v_ * v_, *r))
            elif law.state_names:
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

            events = []
            if has_stick:
                def stop(tau, y):
                    return y[1] - u
                stop.terminal, stop.direction = True, -sig
                events = [stop]
            y0 = np.concatenate(([x, v, 0.0, 0.0, 0.0], state))
            solver, extra = method, {}
            if method == "LSODA":
                # the step cap follows the local damping ratio (a creeping hold of a light
                # block does not crawl at a sixteenth of the natural period): a segment that
                # starts overdamped runs on Radau, whose cap may change at every step; the
                # others on LSODA with the fixed cap, Radau redoing the segment if it stalls
                cap = _local_cap(friction, u, d, M, K, p.period, max_step)
                solver = _LocalCapRadau if cap(0.0, y0) > max_step else _WatchedLSODA
                extra = {"cap": cap, "period": p.period}
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                sol = solve_ivp(rhs, (0.0, remaining), y0, method=solver, rtol=rtol, atol=atol,
                                max_step=max_step, events=events, dense_output=not has_stick, **extra)
            if not (sol.status == -1 and solver is _WatchedLSODA):   # else Radau takes over below
                for w in caught:
                    warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            if sol.status == -1 and solver is _WatchedLSODA:
                rec.nfev += sol.nfev
                # scipy's finite-difference Jacobian may overflow while it grows an increment;
                # it recovers, and the RuntimeWarning would only alarm the user
                with np.errstate(over="ignore"):
                    sol = solve_ivp(rhs, (0.0, remaining), y0, method=_LocalCapRadau, rtol=rtol,
                                    atol=atol, max_step=max_step, events=events,
                                    dense_output=not has_stick, **extra)
            rec.nfev += sol.nfev
            ts, ys = sol.t, sol.y
            if not has_stick:
                ts, ys, marks = force_extrema(ts, ys, sol.sol, lambda tau, y: y[1] - va,
                                               lambda tau, y: K * (xa_seg + va * tau - y[0]))
            ended = has_stick and sol.status == 1
            if ended:
                ys[1, -1] = u                      # the root: slip velocity exactly zero
            if sol.status == -1:
                failure = f"solve_ivp failed at t = {t + ts[-1]:.6g}: {sol.message}"
        rec.append(t + ts, ys[0], ys[1], xa + va * ts, ys[5:], ys[2], ys[3], ys[4])
        if marks:
            rec.insert_events([t + tm for tm, _ in marks], [k for _, k in marks])
        if failure is not None:
            return rec.finish(status=-1, message=failure)
        x, v, xa, state = ys[0, -1], ys[1, -1], xa + va * ts[-1], ys[5:, -1].copy()
        if not ended:
            break
        t += ts[-1]
        mode, sigma = settle(K * (xa - x) - d * u, law.static_force(state, N))
        rec.event("stick" if mode == "stick" else "reversal", t, K * (xa - x))
    return rec.finish()


#: local damping ratio above which the step cap is lifted (far from any oscillation)
OVERDAMPED = 1000.0
#: LSODA steps per natural period beyond which it counts as stalled (Radau takes over)
STEPS_PER_PERIOD = 5_000


class _LocalCapRadau(Radau):
    """Radau whose step cap follows the local damping (``cap(t, y)`` before each step):
    the route of a segment that starts overdamped, and the one that redoes a segment
    LSODA stalled on, e.g. a hold deep in creep, where the relaxation rate a N / (M v)
    reaches 10^12 /s."""

    def __init__(self, fun, t0, y0, t_bound, *, cap=None, period=None, **kwargs):
        super().__init__(fun, t0, y0, t_bound, **kwargs)
        self._cap, self._floor = cap, self.max_step

    def _step_impl(self):
        self.max_step = self._cap(self.t, self.y)
        return super()._step_impl()


def _local_cap(friction, u, d, M, K, period, floor):
    """Step cap period/16 x the local damping ratio (d + dF/ds)/(2 sqrt(K M)) where that
    ratio exceeds OVERDAMPED, else ``floor`` (the fixed cap: runs that never get that
    overdamped integrate exactly as before).

    dF/ds is a central difference of the friction at the current slip speed and
    state; friction that weakens with speed (dF/ds < 0) gets the floor.
    """
    two_root_km = 2.0 * math.sqrt(K * M)
    base = period / 16.0

    def cap(tau, y):
        s = float(y[1]) - u
        st = y[5:]
        h = max(1e-6 * abs(s), 1e-300)
        try:
            drag = (float(friction(s + h, st)) - float(friction(s - h, st))) / (2.0 * h)
        except (ValueError, OverflowError, ZeroDivisionError):
            return floor
        zeta = (d + drag) / two_root_km
        if not math.isfinite(zeta) or zeta < OVERDAMPED:
            return floor
        return max(floor, base * zeta)
    return cap


def force_extrema(ts, ys, dense, rate, force, rel_tol=1e-6):
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
    ts, ys, marks = force_extrema(sol.t, sol.y, sol.sol, lambda tau, y: speed(tau, y) - va,
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
