"""Exact stick-slip of a block with Coulomb (+ viscous) friction.

Stick: the block moves with the surface, the spring force is linear in time,
and breakaway is the time it reaches the static threshold -- solved, not
searched.  Slip: a damped oscillator about the steady-sliding equilibrium
(:mod:`filmfriction.reduced_model.integrators.oscillator`), with the re-stick time found as the exact
root of the slip velocity.  Energies over each segment come from the same
closed forms (the oscillator's own energy identity gives the integral of
v**2), so the ledger closes to round-off.

This is the fast path taken by :meth:`SpringBlock.simulate` for
``laws.Coulomb`` and ``laws.NewtonianFilm``; it needs no tolerances.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.optimize import brentq

from .oscillator import DampedOscillator
from .trajectory import Problem

__all__ = ["run_closed_form", "stick_break_time", "freeze_velocity_for"]


def settle(held_force: float, static: float) -> tuple[str, float]:
    """What a block at rest on its surface does: ``("stick", ...)`` when the
    contact can hold ``held_force`` (|F| <= static), else ``("slip", ...)``;
    the second value is the direction of the force, the way a slip goes.

    Example
    -------
    >>> settle(-2.0, 1.0)
    ('slip', -1.0)
    """
    return ("stick" if abs(held_force) <= static else "slip"), math.copysign(1.0, held_force)


def stick_break_time(held_force: float, rate: float, static: float) -> float:
    """Time until ``|held_force + rate t|`` reaches ``static`` (inf if never).

    Example
    -------
    >>> stick_break_time(0.0, 0.1, 1.0)
    10.0
    """
    if rate > 0.0:
        return max((static - held_force) / rate, 0.0)
    if rate < 0.0:
        return max((static + held_force) / -rate, 0.0)
    return math.inf


def _freeze_time(osc: DampedOscillator, e0: float, ed0: float, level: float, sigma: float,
                 freeze: float, t_end: float) -> float | None:
    """First time the slip speed sigma*(v - u) falls through ``freeze`` (None: never).

    A slip from stick starts at speed 0 and first rises through ``freeze``;
    that crossing is skipped, and so is any other rising one.
    """
    target = level + sigma * freeze            # e' at which the slip speed equals freeze
    t0, e, ed = 0.0, e0, ed0
    while True:
        tau = osc.first_crossing(e, ed, target, t_end - t0, skip_start=(ed == target))
        if tau is None:
            return None
        # e'' is a solution of the same equation: its value at tau is the acceleration
        a0 = osc.second_derivative_at_zero(e, ed)
        e_next = float(osc.value(tau, e, ed))
        acc = float(osc.value(tau, a0, osc.second_derivative_at_zero(ed, a0)))
        if sigma * acc < 0.0:                  # the slip speed is falling: the film freezes
            return t0 + tau
        t0, e, ed = t0 + tau, e_next, target


def tile_cycles(rec, cycle, sigma, t, x, xa, T):
    """At a yield: if the run since the previous yield was one slip and one stick the same
    way, the rest of the run repeats it exactly, so tile it (all but the last cycle).

    Every yield of a law without a state starts from the same relative state (at rest on
    the surface, spring force at the static threshold), so the cycle from one yield to the
    next is the solution for as long as the drive stays as it is.  Returns the updated
    (t, x, xa) and the new template mark.
    """
    if cycle is not None and cycle[1] == sigma:
        mark = cycle[0]
        dt, dx, dxa, kinds = rec.period_since(mark)
        if kinds == ["stick", "slip"] and dt > 0.0:
            copies = int((T - t) / dt)
            if t + copies * dt > T - 1e-9 * dt:
                copies -= 1                     # the generic loop runs to T itself
            if copies >= 1:
                st, sx, sxa = rec.repeat(mark, copies)
                t, x, xa = t + st, x + sx, xa + sxa
    return t, x, xa, (rec.mark(), sigma)


def run_closed_form(p: Problem, static, kinetic: float, viscous: float,
                    freeze_velocity: float = 0.0, shear_stiffness: float = math.inf):
    """Integrate a Coulomb + viscous block exactly; returns a SimulationResult.

    With ``freeze_velocity`` > 0 a slip ends when the slip speed, falling,
    reaches it (the film freezes); the block then takes the surface's velocity
    and the kinetic energy it loses is counted as friction work.

    With a finite ``shear_stiffness`` k_f the stuck film is an elastic spring
    between the surface and the block: while stuck, the block creeps at the
    constant velocity (k_f u + K V)/(k_f + K) (quasi-static: no net force), the
    held force rises at K k_f/(K + k_f) (V - u), and the work done on the film
    (its elastic energy, released as heat when it melts at breakaway) is
    friction work.  A step of the block's velocity to that creep speed at
    re-stick is counted there too, so the ledger stays exact.
    """
    M, K, d, u, va = p.mass, p.stiffness, p.damping, p.u, p.va
    D = d + viscous
    osc = DampedOscillator(M, D, K)
    # no friction force at rest and none in slip: nothing to stick with
    smooth = static is None or (static == 0.0 and kinetic == 0.0)
    rec = p.recorder()
    n_slip = max(p.samples, 2)
    n_stick = max(p.samples // 8, 2)
    T = p.duration
    t, x, v, xa = 0.0, p.x0, p.v0, p.xa0
    state = p.state0

    # the creep velocity of a stuck block on an elastic film (u when rigid)
    kf = shear_stiffness
    creep = u if math.isinf(kf) else (kf * u + K * va) / (kf + K)
    jump = 0.0      # kinetic energy lost when a re-stuck block takes the creep velocity
    sigma = 1.0
    mode = "slip"
    if not smooth and v == u:
        mode, sigma = settle(K * (xa - x) - d * creep, static)
        # an elastic film: the block takes the creep velocity as the stick begins
        jump = 0.5 * M * (v * v - creep * creep) if mode == "stick" else 0.0
    elif v != u:
        sigma = math.copysign(1.0, v - u)

    cycle = None    # (recorder mark, sigma) at the last yield: the template of a periodic run
    while t < T:
        remaining = T - t
        if mode == "stick":
            held = K * (xa - x) - d * creep    # force the contact must hold
            rate = K * (va - creep)
            tau = stick_break_time(held, rate, static)
            end = min(tau, remaining)
            ts = np.linspace(0.0, end, n_stick)
            # integral of the spring force, then spring end + belt work, and work on the film
            f_spring = K * (xa - x) * ts + 0.5 * K * (va - creep) * ts ** 2
            drive = va * f_spring + u * (d * creep * ts - f_spring)
            film = (creep - u) * (held * ts + 0.5 * rate * ts ** 2)
            if jump:
                film = film + jump
                jump = 0.0
            rec.append(t + ts, x + creep * ts, np.full_like(ts, creep), xa + va * ts, state,
                       drive, film, d * creep * creep * ts)
            x, xa, v = x + creep * end, xa + va * end, creep
            if tau >= remaining:
                break
            t += end
            sigma = math.copysign(1.0, rate)
            mode = "slip"
            rec.event("slip", t, K * (xa - x))
            t, x, xa, cycle = tile_cycles(rec, cycle, sigma, t, x, xa, T)
            continue

        f_kin = 0.0 if smooth else sigma * kinetic
        # steady-sliding equilibrium x_p = alpha + va*tau of M x'' + D x' + K x = K xa(tau) + viscous*u - f_kin
        alpha = xa + (viscous * u - f_kin - D * va) / K
        e0, ed0 = x - alpha, v - va
        level = u - va                               # e' = level  <=>  slip velocity zero
        if smooth:
            tau = None
        elif freeze_velocity > 0.0:
            tau = _freeze_time(osc, e0, ed0, level, sigma, freeze_velocity, remaining)
        else:
            tau = osc.first_crossing(e0, ed0, level, remaining, skip_start=(v == u))
        end = remaining if tau is None else tau
        ts = np.linspace(0.0, end, n_slip)
        a0 = -2.0 * osc.gamma * ed0 - osc.w0sq * e0
        e = osc.value(ts, e0, ed0)
        ed = osc.value(ts, ed0, a0)
        de = e - e0
        integral_e = -(M * (ed - ed0) + D * de) / K
        if D > 0.0:
            integral_ed2 = (0.5 * M * (ed0 ** 2 - ed ** 2) + 0.5 * K * (e0 ** 2 - e ** 2)) / D
        else:
            integral_ed2 = np.zeros_like(ts)
        integral_s = de - level * ts
        integral_s2 = integral_ed2 - 2.0 * level * de + level ** 2 * ts
        integral_v2 = va ** 2 * ts + 2.0 * va * de + integral_ed2
        drive = K * va * ((xa - alpha) * ts - integral_e) + u * (-f_kin * ts - viscous * integral_s)
        friction = f_kin * integral_s + viscous * integral_s2
        damper = d * integral_v2
        xs = alpha + va * ts + e
        vs = va + ed
        if tau is not None:
            # the root: slip velocity zero, or the film freezes at sigma*freeze_velocity and
            # the block's kinetic energy relative to the surface goes into the film
            friction[-1] += 0.5 * M * (vs[-1] ** 2 - u ** 2)
            vs[-1] = u
        rec.append(t + ts, xs, vs, xa + va * ts, state, drive, friction, damper)
        x, v, xa = xs[-1], vs[-1], xa + va * end
        if tau is None:
            break
        t += end
        mode, sigma = settle(K * (xa - x) - d * creep, static)
        jump = 0.5 * M * (u * u - creep * creep) if mode == "stick" else 0.0
        rec.event("stick" if mode == "stick" else "reversal", t, K * (xa - x))
    return rec.finish()


def freeze_velocity_for(block, static_force: float, restick_force: float) -> float:
    """Slip speed at which the film must freeze for ``block`` to re-stick at ``restick_force``.

    The re-stick force of the model's steady cycle rises monotonically with the
    freeze velocity, up to ``static_force``; brentq finds it.  An overdamped
    slip (B + d >= 2 sqrt(K M)) needs one above V to re-stick at all; an
    underdamped one that already re-sticks at or above ``restick_force`` gets 0.

    Parameters
    ----------
    block : SpringBlock
        With a :class:`~filmfriction.reduced_model.laws.Coulomb` law (its
        ``freeze_velocity`` is what is searched).
    static_force, restick_force : float
        F_s of the law, and the re-stick force F_b to reach.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        ``restick_force`` is not reachable (not between those ends).
    """
    k, v = block.stiffness, abs(block.drive_velocity)
    law = block.law
    # one cycle's stick and a slip: (Fs - Fb)/(K V) plus margin; two cycles give a steady one
    horizon = 3.0 * static_force / (k * max(v, 1e-300))

    def last_restick(result):
        fb = np.asarray(result.cycles().backward_force, float)
        return float(fb[-1]) if fb.size else -math.inf

    def run(vf):
        return replace(block, law=replace(law, freeze_velocity=vf)).simulate(horizon)

    def restick(vf):
        return last_restick(run(vf))

    # the film can only freeze below the slip's peak speed, and an overdamped
    # slip only above the steady sliding speed V, which it approaches from above
    free = run(0.0)
    peak = float(np.max(np.abs(free.v)))
    lo, hi = (v * (1.0 + 1e-3) if len(free.cycles()) == 0 else 0.0), 0.999 * peak
    # at lo = 0 the film never freezes early: that is the free run itself
    f_lo = (last_restick(free) if lo == 0.0 else restick(lo)) - restick_force
    f_hi = restick(hi) - restick_force
    if f_lo >= 0.0 and lo == 0.0:
        return 0.0      # it already re-sticks at or above F_b: freezing could only raise it
    if not (f_lo < 0.0 < f_hi):
        raise ValueError(f"re-stick force {restick_force:.4g} is outside what a freeze velocity "
                         f"in [{lo:.3g}, {hi:.3g}] gives ({f_lo + restick_force:.4g} .. "
                         f"{f_hi + restick_force:.4g})")
    return float(brentq(lambda vf: restick(vf) - restick_force, lo, hi, xtol=1e-9 * peak))
