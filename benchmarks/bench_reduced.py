"""Speed of the reduced model against an event-driven scipy reference (prints figures).

    .venv/bin/python benchmarks/bench_reduced.py [--repeat N] [--radau] [--map]

The default sections.  The reference (benchmarks/reference_event_driven.py)
is what an efficient scipy user writes: the stick solved in closed form, each
slip ``solve_ivp(method="LSODA", rtol=1e-7, atol=1e-12)`` with a terminal event
on the slip velocity; for rate-and-state one LSODA run (rtol 1e-7) with an event
on v - V marking the spring-force extrema.  Both sides produce the cycle table
(ours: ``simulate`` + ``result.cycles()``, at our default rtol 1e-10 on the ODE
paths, i.e. at least as accurate).  Times are CPU seconds of this process
(``time.process_time``), median, spread (min-max) and best of N repeats.
Problems: M = K = 1, V = 0.1, d = 0.02, 100 cycles (Coulomb Fs = 1, Fk = 0.5;
exponential Stribeck with v_s = 0.05); rate-and-state mu0 = 0.6, a = 0.01,
b = 0.015, dc = 0.01, v0 = 0.1, K = 10, ~100 cycles from v = 0.05 (and ~500 cycles,
where the converged limit cycle is tiled), with the yield times and peak forces
of both sides against a tight DOP853 run (rtol 1e-13), and the reference's LSODA
on the law's plain-float closure for scale; then what the first run of a new
process costs (numba's import, the compiled steps loaded from the cache or, with
an empty cache, compiled).  Then the creeping hold (M = 1e-6,
K = 1e5, 1 s) and the slide-hold-slide healing.

Older sections: ``--radau`` (against Radau at equal accuracy), ``--map``.

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

from filmfriction.reduced_model import SpringBlock, laws, maps

M, K, V, D, T = 1.0, 1.0, 0.1, 0.02, 300.0
MATCH = 1e-6


def reference_events(law, rtol, method="Radau"):
    """Event-driven stick/slip with solve_ivp in every phase; returns event times."""
    N = 1.0
    Fs = law.static_force((), N)
    t, x, events = 0.0, 0.0, []
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


def timings(func, repeat):
    """CPU times of ``repeat`` calls (after one warm-up call)."""
    func()
    out = []
    for _ in range(repeat):
        start = time.process_time()
        func()
        out.append(time.process_time() - start)
    return np.array(out)


def fmt(ts):
    return (f"median {1e3 * np.median(ts):8.2f} ms  (min {1e3 * ts.min():.2f}, "
            f"max {1e3 * ts.max():.2f}, n={ts.size})")


def _rs_start(law, K):
    psi0 = float(law.steady_state(V)[0])
    return [float(law.friction(V, [psi0], 1.0)) / K, 0.05, psi0]     # extension, v, psi


def _rs_rhs(law, K):
    rates = law.scalar_state_rates(1.0)

    def rhs(t, y):
        fr, r = rates(y[1], [y[2]])
        return [V - y[1], (K * y[0] - fr) / M, r[0]]
    return rhs


def rate_state_truth(law, K, duration):
    """Yield times and peak forces of a tight DOP853 run (the reference's rule for yields)."""
    rhs = _rs_rhs(law, K)

    def extremum(t, y):
        return y[1] - V
    sol = solve_ivp(rhs, (0.0, duration), _rs_start(law, K), method="DOP853", rtol=1e-13,
                    atol=1e-15, events=extremum)
    te, ye = sol.t_events[0], sol.y_events[0]
    rising = np.array([rhs(t, y)[1] > 0.0 for t, y in zip(te, ye)])
    return {"yield_time": te[rising], "static_force": K * ye[rising, 0]}


def lean_reference(law, K, duration):
    """The reference's LSODA (rtol 1e-7) with the law as a plain-float closure, no events."""
    return solve_ivp(_rs_rhs(law, K), (0.0, duration), _rs_start(law, K), method="LSODA",
                     rtol=1e-7, atol=[1e-12, 1e-12, 1e-10])


def against_event_driven(repeat):
    import reference_event_driven as ref

    print("== the reduced model against the event-driven LSODA reference ==")
    print(f"(CPU time per run; repeat={repeat}; the reference gets max(3, repeat // 5) repeats)")
    rows = []
    for name, law in (("Coulomb", laws.Coulomb(static=1.0, kinetic=0.5)),
                      ("Stribeck", laws.StribeckExponential(static=1.0, kinetic=0.5, stribeck_velocity=0.05))):
        block = SpringBlock(mass=M, stiffness=K, drive_velocity=V, damping=D, law=law)
        period = float(np.nanmedian(block.simulate(400.0).cycles().period))
        T100 = 100.5 * period + 1.0 / V          # first stick Fs/(K V), then 100 cycles
        sliding = law.scalar_sliding(1.0)

        def reference():
            return ref.stick_slip(sliding, law.static_force((), 1.0), M=M, K=K, V=V, d=D, duration=T100)

        def reduced():
            return block.simulate(T100).cycles()
        cyc, table = reduced(), reference()
        n = min(len(cyc), table["yield_time"].size)
        err = np.max(np.abs(cyc.stick_time[:n] - table["stick_time"][:n]))
        t_ours, t_ref = timings(reduced, repeat), timings(reference, max(3, repeat // 5))
        print(f"{name:9s} {len(cyc)} cycles (reference {table['yield_time'].size}); re-stick times "
              f"differ by <= {err:.1e}")
        print(f"  reduced_model simulate+cycles: {fmt(t_ours)}")
        print(f"  reference LSODA rtol 1e-7:     {fmt(t_ref)}")
        print(f"  speed ratio: {np.median(t_ref) / np.median(t_ours):6.1f}x of the medians "
              f"({t_ref.min() / t_ours.min():.1f}x of the best); target "
              f"{'>= 100x' if name == 'Coulomb' else '>= 20x'}")
        rows.append((name, np.median(t_ref) / np.median(t_ours)))

    law = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1)
    k_rs, T_rs = 10.0, 200.0
    block = SpringBlock(mass=M, stiffness=k_rs, drive_velocity=V, law=law)
    rs_repeat = max(3, repeat // 5)
    truth = rate_state_truth(law, k_rs, T_rs)
    print(f"RateState, K = {k_rs}, {T_rs:g} time units from v = 0.05; truth: solve_ivp DOP853 rtol 1e-13, "
          f"atol 1e-15 ({truth['yield_time'].size} yields)")
    for T_run in (T_rs, 5 * T_rs):
        def reduced_rs(rtol=1e-10):
            return block.simulate(T_run, initial_velocity=0.05, rtol=rtol).cycles()

        def reference_rs():
            return ref.rate_state(law, M=M, K=k_rs, V=V, duration=T_run, v_start=0.05)
        ours10, ours7, table = reduced_rs(), reduced_rs(1e-7), reference_rs()
        if T_run == T_rs:
            for label, yt, fy in (("reduced_model rtol 1e-10", ours10.yield_time, ours10.static_force),
                                  ("reduced_model rtol 1e-7 ", ours7.yield_time, ours7.static_force),
                                  ("reference LSODA rtol 1e-7", table["yield_time"], table["static_force"])):
                n = min(yt.size, truth["yield_time"].size)
                print(f"  {label}: {yt.size} cycles; against the truth yield times within "
                      f"{np.max(np.abs(yt[:n] - truth['yield_time'][:n])):.1e}, peak forces within "
                      f"{np.max(np.abs(fy[:n] - truth['static_force'][:n])):.1e}")
        t_ours, t_ours7, t_ref = (timings(reduced_rs, rs_repeat), timings(lambda: reduced_rs(1e-7), rs_repeat),
                                  timings(reference_rs, rs_repeat))
        print(f"  {T_run:g} time units ({len(ours10)} cycles):")
        print(f"    reduced_model rtol 1e-10:      {fmt(t_ours)}")
        print(f"    reduced_model rtol 1e-7:       {fmt(t_ours7)}")
        print(f"    reference LSODA rtol 1e-7:     {fmt(t_ref)}")
        if T_run == T_rs:
            t_lean = timings(lambda: lean_reference(law, k_rs, T_run), rs_repeat)
            print(f"    the reference's LSODA on the law's plain-float closure (scalar_state_rates), "
                  f"events off: {fmt(t_lean)}")
        print(f"    speed ratio: {np.median(t_ref) / np.median(t_ours):6.2f}x (rtol 1e-10), "
              f"{np.median(t_ref) / np.median(t_ours7):.2f}x (rtol 1e-7); target >= 20x")

    fresh_process(rs_repeat)

    rs = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-5, v0=1e-6)
    hold = SpringBlock(mass=1e-6, stiffness=1e5, drive_velocity=0.0, drive="fixed", law=rs)
    psi0 = rs.steady_state(1e-6)

    def creeping_hold():
        return hold.simulate(1.0, initial_extension=0.6 / 1e5 * 0.98, initial_velocity=1e-7,
                             initial_state=psi0)
    r = creeping_hold()
    t_hold = timings(creeping_hold, rs_repeat)
    print(f"creeping hold, rate-and-state, M = 1e-6, K = 1e5, 1 s: {fmt(t_hold)}; nfev {r.nfev}, "
          f"end x = {r.x[-1]:.12e}, psi = {r.psi[-1]:.12f} (target <= 0.5 s; 30.9 s at 8f90a69)")

    from filmfriction.reduced_model import DriveSchedule
    V_shs, theta_ss = 1e-6, rs.dc / 1e-6
    print(f"slide-hold-slide healing, massless, K = 1e5, V = {V_shs:g}, theta_ss = {theta_ss:g} "
          "(one simulate call each):")
    print("   t_hold   ln(t_hold/theta_ss)   delta mu   b ln(t_hold/theta_ss)   theta after hold   CPU")
    for th in (10.0, 100.0, 1000.0, 10000.0, 100000.0):
        sched = DriveSchedule.slide_hold_slide(V_shs, 20 * theta_ss, th, 20 * theta_ss)
        start = time.process_time()
        r = SpringBlock(0.0, 1e5, V_shs, law=rs).simulate(drive=sched, t_eval=[20 * theta_ss, 20 * theta_ss + th])
        cpu = time.process_time() - start
        i0, i1 = r.eval_index
        dmu = r.spring_force[i1:].max() - r.spring_force[i0]
        print(f"  {th:7.0f}   {math.log(th / theta_ss):8.3f}   {dmu:10.5f}   {rs.b * math.log(th / theta_ss):10.5f}"
              f"   {r.theta[i1]:12.1f}   {cpu:.2f} s")
    return rows


FRESH = """
import time
t0 = time.perf_counter()
from filmfriction.reduced_model import SpringBlock, laws
law = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1)
block = SpringBlock(mass=1.0, stiffness=10.0, drive_velocity=0.1, law=law)
t1 = time.perf_counter()
block.simulate(200.0, initial_velocity=0.05)
t2 = time.perf_counter()
block.simulate(200.0, initial_velocity=0.05)
t3 = time.perf_counter()
print(t1 - t0, t2 - t1, t3 - t2)
"""


def fresh_process(repeat):
    """What a script's first rate-and-state run costs: numba's import and the compiled steps,
    loaded from numba's cache or (empty cache) compiled.  Wall time in a new process each."""
    import os
    import subprocess
    import tempfile

    def once(env):
        out = subprocess.run([sys.executable, "-c", FRESH], env=env, check=True, capture_output=True,
                             text=True).stdout.split()
        return [float(c) for c in out]
    print("  a new process, the 200-time-unit run at rtol 1e-10 (wall time; numba's cache as "
          "the package leaves it, then empty):")
    for label, empty in (("cache filled", False), ("cache empty ", True)):
        rows = []
        for _ in range(repeat if not empty else 1):
            env = dict(os.environ)
            with tempfile.TemporaryDirectory() as cache:
                if empty:
                    env["NUMBA_CACHE_DIR"] = cache      # numba compiles into a new cache
                rows.append(once(env))
        first, second = np.median([r[1] for r in rows]), np.median([r[2] for r in rows])
        print(f"    {label}: first simulate {first:.3f} s, the second {1e3 * second:.1f} ms "
              f"(import of filmfriction.reduced_model {np.median([r[0] for r in rows]):.2f} s; n={len(rows)})")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=25, help="repeats of the fast runs (default 25)")
    p.add_argument("--radau", action="store_true", help="also the older comparison against Radau")
    p.add_argument("--map", action="store_true", help="also time the 100 x 100 (lambda, zeta) map")
    p.add_argument("--quick", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    against_event_driven(args.repeat)
    if args.radau:
        print(f"== against Radau at equal accuracy: M={M} K={K} V={V} d={D} duration={T}; "
              f"match criterion {MATCH:g} on every event time ==")
        compare("Coulomb", laws.Coulomb(static=1.0, kinetic=0.5), args.quick)
        compare("Stribeck", laws.StribeckExponential(static=1.0, kinetic=0.5, stribeck_velocity=0.05), args.quick)
    if args.map:
        m = maps.lambda_zeta_map(np.logspace(-2, 2, 100), np.logspace(-3, 1, 100), processes=2)
        print(f"lambda-zeta map 100 x 100 (10^4 simulations, 2 processes): {m.seconds:.2f} s "
              f"(target <= 30 s); stick-slip in {100 * m.stick_slip.mean():.1f} % of cells")


if __name__ == "__main__":
    main()
