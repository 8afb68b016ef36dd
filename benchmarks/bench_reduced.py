"""Speed of the reduced model against plain scipy at equal accuracy (prints figures).

    .venv/bin/python benchmarks/bench_reduced.py [--quick]

Problems: Coulomb (Fs=1, Fk=0.5) and exponential-Stribeck (Fs=1, Fk=0.5,
v_s=0.05) stick-slip, M = K = 1, V = 0.1, d = 0.02, 300 time units (~20
cycles).  The competitor is what a careful scipy user writes: the same
event-driven stick/slip switching, every phase integrated by
``solve_ivp(method="Radau")`` with terminal events (re-stick v = 0 in slip;
|spring force| = Fs in stick), atol = 1e-3 rtol.

Equal accuracy, one rule for both sides: the truth is an independent tight
run (solve_ivp DOP853, rtol = 1e-12, atol = 1e-15, same event-driven
switching), cross-checked against the reduced model at rtol = 1e-13.  Each
side walks the same ladder rtol = 1e-3, 1e-4, ... and is timed at the loosest
rung whose event times *all* lie within 1e-6 of the truth and whose next
tighter rung does too (so a rung that passes by a lucky cancellation of
errors is not taken).  The closed form (Coulomb) has no tolerance.  Then a
100 x 100 (lambda, zeta) map on 2 processes is timed.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from filmfriction.reduced_model import SpringBlock, laws, maps  # noqa: E402

M, K, V, D, T = 1.0, 1.0, 0.1, 0.02, 300.0
MATCH = 1e-6


def reference_events(law, rtol, method="Radau"):
    """Event-driven stick/slip with solve_ivp in every phase; returns event times."""
    N = 1.0
    Fs = law.static_force((), N)
    t, x, v, events = 0.0, 0.0, 0.0, []
    mode = "stick"
    while t < T:
        if mode == "stick":
            def rhs(tt, y):
                return [0.0]

            def brk(tt, y):
                return K * (V * tt - y[0]) - Fs
            brk.terminal, brk.direction = True, 1
            sol = solve_ivp(rhs, (t, T), [x], method=method, rtol=rtol, atol=rtol * 1e-3, events=brk)
            if sol.status != 1:
                break
            t, x = sol.t[-1], sol.y[0, -1]
            events.append(t)
            mode = "slip"
        else:
            def rhs(tt, y):
                return [y[1], (K * (V * tt - y[0]) - D * y[1] - law.sliding_force(max(y[1], 0.0), (), N)) / M]

            def stop(tt, y):
                return y[1]
            stop.terminal, stop.direction = True, -1
            sol = solve_ivp(rhs, (t, T), [x, 0.0], method=method, rtol=rtol, atol=rtol * 1e-3, events=stop,
                            max_step=2 * math.pi / 16)
            if sol.status != 1:
                break
            t, x = sol.t[-1], sol.y[0, -1]
            events.append(t)
            mode = "stick"
    return np.array(events)


def ours(law, rtol=1e-10, method="auto"):
    b = SpringBlock(mass=M, stiffness=K, drive_velocity=V, damping=D, law=law)
    return b.simulate(T, rtol=rtol, method=method, samples_per_segment=16)


def event_times(r):
    return np.array([e.time for e in r.events if e.kind in ("slip", "stick")])


def best_time(func, repeat=3):
    """Best of ``repeat`` runs, in CPU seconds of this process (both sides are
    single-threaded; on a shared machine wall time also counts other jobs)."""
    best = math.inf
    for _ in range(repeat):
        start = time.process_time()
        func()
        best = min(best, time.process_time() - start)
    return best


LADDER = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)


def max_error(ev, truth):
    return float(np.max(np.abs(ev - truth))) if ev.size == truth.size else math.inf


def choose_rtol(events_at, truth):
    """Loosest rung of LADDER within MATCH of ``truth`` whose next tighter rung is too.

    Returns (rtol or None, its error, {rtol: error} for every rung tried)."""
    errors = {}

    def error(rtol):
        if rtol not in errors:
            errors[rtol] = max_error(events_at(rtol), truth)
        return errors[rtol]

    for i, rtol in enumerate(LADDER):
        if error(rtol) <= MATCH and (i + 1 == len(LADDER) or error(LADDER[i + 1]) <= MATCH):
            return rtol, errors[rtol], errors
    return None, math.inf, errors


def ladder_line(errors):
    return "  ".join(f"{r:.0e}:{e:.1e}" for r, e in errors.items())


def compare(name, law, quick):
    truth = reference_events(law, 1e-12, method="DOP853")
    self_check = max_error(event_times(ours(law, rtol=1e-13)), truth)
    print(f"{name}: truth = solve_ivp DOP853 rtol=1e-12 atol=1e-15, {truth.size} events "
          f"(reduced_model at rtol=1e-13 agrees to {self_check:.1e})")
    if law.closed_form(1.0) is not None:
        our_rtol, our_err = None, max_error(event_times(ours(law)), truth)
        our_call = (lambda: ours(law))
        print(f"  reduced_model closed form (no tolerance): max event-time error {our_err:.1e}")
    else:
        our_rtol, our_err, errs = choose_rtol(lambda r: event_times(ours(law, rtol=r)), truth)
        our_call = (lambda: ours(law, rtol=our_rtol or LADDER[-1]))
        print(f"  reduced_model DOP853 (atol = 1e-12 x problem scales) max error per rtol: {ladder_line(errs)}"
              f"  -> rtol={our_rtol}")
    ref_rtol, ref_err, errs = choose_rtol(lambda r: reference_events(law, r), truth)
    print(f"  solve_ivp Radau (atol = 1e-3 rtol) max error per rtol: {ladder_line(errs)}  -> rtol={ref_rtol}")
    t_ours = best_time(our_call, repeat=5 if quick else 9)
    t_ref = best_time(lambda: reference_events(law, ref_rtol or LADDER[-1]), repeat=2 if quick else 3)
    label = "closed form" if our_rtol is None else f"DOP853 rtol={our_rtol:g}"
    print(f"{name:9s} events={truth.size:3d}  reduced_model ({label}, max event-time error {our_err:.1e}): "
          f"{1e3 * t_ours:7.2f} ms   solve_ivp Radau rtol={ref_rtol:g} (max event-time error {ref_err:.1e}): "
          f"{1e3 * t_ref:8.1f} ms   speed ratio {t_ref / t_ours:6.1f}x (target >= 20x; best-of CPU times)")
    return t_ref / t_ours


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="skip the 100 x 100 map")
    args = p.parse_args(argv)
    print(__doc__.split("\n\n")[0])
    print(f"problem: M={M} K={K} V={V} d={D} duration={T}; match criterion {MATCH:g} on every event time")
    compare("Coulomb", laws.Coulomb(static=1.0, kinetic=0.5), args.quick)
    compare("Stribeck", laws.StribeckExponential(static=1.0, kinetic=0.5, stribeck_velocity=0.05), args.quick)
    if not args.quick:
        m = maps.lambda_zeta_map(np.logspace(-2, 2, 100), np.logspace(-3, 1, 100), processes=2)
        print(f"lambda-zeta map 100 x 100 (10^4 simulations, 2 processes): {m.seconds:.2f} s "
              f"(target <= 30 s); stick-slip in {100 * m.stick_slip.mean():.1f} % of cells")


if __name__ == "__main__":
    main()
