"""The event-driven reference the reduced model is timed against.

What an efficient scipy user writes for a spring-block slider, M x'' = K (V t - x)
- d x' - F:

* laws with static friction (Coulomb, Stribeck): the stick is solved in closed
  form (the spring force K (V t - x) grows linearly until it reaches F_s, so the
  breakaway time is one division); each slip is ``solve_ivp(method="LSODA",
  rtol=1e-7, atol=1e-12)`` on (x, v) with a terminal event on the slip velocity
  (v = 0, falling), the slip direction frozen (friction -F(max(v, 0))).
* rate-and-state (no stick): one ``solve_ivp(LSODA, rtol=1e-7)`` on (x, v, psi)
  with a non-terminal event on v - V, which marks the maxima (yield) and minima
  (re-stick) of the spring force.

Both return the cycle table a user needs (yield and re-stick times and forces,
slip distance, period) from NumPy arrays: no trajectory bookkeeping, no energy
ledger -- a lean competitor.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp


def stick_slip(sliding_force, static: float, *, M: float, K: float, V: float, d: float,
               duration: float, rtol: float = 1e-7, atol: float = 1e-12):
    """Event-driven stick-slip from rest on a relaxed spring; returns a dict of cycle arrays."""
    t, x = 0.0, 0.0
    yields, sticks, f_y, f_s, x_y, x_s = [], [], [], [], [], []
    while True:
        # stick (closed form): the block is at rest, the spring force K (V t - x) rises to F_s
        t_break = x + static / K
        t_break = t_break / V
        if t_break >= duration:
            break
        t = t_break
        yields.append(t)
        f_y.append(K * (V * t - x))
        x_y.append(x)

        def rhs(tt, y):
            return [y[1], (K * (V * tt - y[0]) - d * y[1] - sliding_force(max(y[1], 0.0))) / M]

        def stop(tt, y):
            return y[1]
        stop.terminal, stop.direction = True, -1
        sol = solve_ivp(rhs, (t, duration), [x, 0.0], method="LSODA", rtol=rtol, atol=atol,
                        events=stop, first_step=1e-6)
        if sol.status != 1:
            break
        t, x = float(sol.t_events[0][0]), float(sol.y_events[0][0][0])
        sticks.append(t)
        f_s.append(K * (V * t - x))
        x_s.append(x)
    return _table(yields, sticks, f_y, f_s, x_y, x_s)


def rate_state(law, *, M: float, K: float, V: float, duration: float, v_start: float,
               rtol: float = 1e-7, atol=(1e-12, 1e-12, 1e-10)):
    """One LSODA run of a rate-and-state block; yields/re-sticks at the spring-force extrema.

    Starts at the steady state at V with the block moving at ``v_start`` (as
    ``SpringBlock.simulate(initial_velocity=v_start)`` does)."""
    psi0 = float(law.steady_state(V)[0])
    f0 = float(law.friction(V, [psi0], 1.0))
    x0 = -f0 / K                                  # spring stretched by the steady friction

    def rhs(tt, y):
        s = y[1]
        return [s, (K * (V * tt - y[0]) - float(law.friction(s, y[2:], 1.0))) / M,
                float(law.state_rate(abs(s), y[2:])[0])]

    def extremum(tt, y):
        return y[1] - V
    sol = solve_ivp(rhs, (0.0, duration), [x0, v_start, psi0], method="LSODA", rtol=rtol,
                    atol=list(atol), events=extremum)
    te, ye = sol.t_events[0], sol.y_events[0]
    force = K * (V * te - ye[:, 0])
    # a spring-force maximum is where v - V turns positive (v rising through V)
    acc = np.array([rhs(tt, y)[1] for tt, y in zip(te, ye)])
    is_yield = acc > 0.0
    yields, sticks, f_y, f_s, x_y, x_s = [], [], [], [], [], []
    pending = None
    for k in range(te.size):
        if is_yield[k]:
            pending = k
        elif pending is not None:
            yields.append(te[pending]); f_y.append(force[pending]); x_y.append(ye[pending, 0])
            sticks.append(te[k]); f_s.append(force[k]); x_s.append(ye[k, 0])
            pending = None
    return _table(yields, sticks, f_y, f_s, x_y, x_s)


def _table(yields, sticks, f_y, f_s, x_y, x_s):
    n = min(len(yields), len(sticks))
    ty, ts = np.array(yields[:n]), np.array(sticks[:n])
    period = np.full(n, math.nan)
    period[:-1] = np.diff(ty)
    return {"yield_time": ty, "stick_time": ts, "static_force": np.array(f_y[:n]),
            "backward_force": np.array(f_s[:n]), "slip_distance": np.array(x_s[:n]) - np.array(x_y[:n]),
            "slip_duration": ts - ty, "period": period}
