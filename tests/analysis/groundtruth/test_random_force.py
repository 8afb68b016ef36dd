"""The random-force slider (analysis/groundtruth/random_force.py): the law's slips when
noise-free, and the noise the integral-form fit sees when not."""
import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid, solve_ivp

from filmfriction.analysis.groundtruth.random_force import slide

K, M, FS, FK = 2.0, 30.0, 48.0, 36.0


def _run(**kw):
    args = dict(mass=M, stiffness=K, drive_velocity=0.1, static_force=FS, duration=800.0,
                dt=0.25, armed_below=FK)
    args.update(kw)
    return slide("coulomb-viscous", (FK, 0.0), **args)


def test_noise_free_coulomb_slips_are_the_closed_form():
    # a Coulomb slip from rest at F_s: Δx = 2(F_s − F_k)/K, peak velocity (F_s − F_k)/√(KM)
    # (plus about the drive's V·τ_s during the slip, τ_s = π√(M/K); the yield and the re-stick
    # fall on the steps)
    run = _run()[0]
    y, s = run["yield_index"], run["stick_index"]
    assert y.size >= 4
    x, v, f = run["wall_position"], run["wall_velocity"], run["spring_force"]
    tau = math.pi * math.sqrt(M / K)
    for a, b in zip(y[1:], s[1:]):
        assert x[b] - x[a] == pytest.approx(2 * (FS - FK) / K + 0.1 * tau, abs=0.1)
        assert v[a:b + 1].max() == pytest.approx((FS - FK) / math.sqrt(K * M) + 0.1, abs=0.02)
        assert f[b] == pytest.approx(2 * FK - FS, abs=0.1)      # K(Δx − V·τ_s) = 2(F_s − F_k)


def test_the_integral_form_residual_is_the_random_force_velocity():
    # [∫(F_spring − F_k) dt − M(v − v_y)]/M over a slip is −(u − u_y): AR(1) of rms σ and
    # lag-one correlation ρ, so its lag-one increments have variance 2σ²(1 − ρ)
    sigma, rho = 0.75, 0.9
    runs = _run(replicas=16, duration=1200.0, velocity_noise=sigma, velocity_correlation=rho, seed=3)
    steps, late = [], []
    for run in runs:
        t, f, v = run["time"], run["spring_force"], run["wall_velocity"]
        imp = cumulative_trapezoid(f - FK, t, initial=0.0)
        for a, b in zip(run["yield_index"], run["stick_index"]):
            i = np.arange(a + 1, b)          # the wall moving (the Coulomb force is F_k)
            if i.size < 12:
                continue
            r = (imp[i] - imp[i[0]]) / M - (v[i] - v[i[0]])
            steps.append(np.diff(r))
            late.append(r[8:])
    d = np.concatenate(steps)
    assert d.size > 500
    # the trapezoid impulse's own error is O(dt²·jerk): a few % of the increments at most
    assert np.sqrt(np.mean(d ** 2)) == pytest.approx(sigma * math.sqrt(2 * (1 - rho)), rel=0.12)
    # far from the yield: the variance 2σ²(1 − ρ^k) approaches 2σ²
    late = np.concatenate(late)
    assert np.sqrt(np.mean(late ** 2)) == pytest.approx(sigma * math.sqrt(2), rel=0.3)


def test_the_wall_moves_with_the_noise_and_rattle_is_on_the_velocity_only():
    quiet, noisy = _run()[0], _run(velocity_noise=0.75, velocity_correlation=0.9,
                                   rattle=0.25, seed=1)[0]
    assert not np.allclose(quiet["wall_position"], noisy["wall_position"])
    rattled = _run(rattle=0.25, seed=1)[0]
    assert np.array_equal(rattled["wall_position"], quiet["wall_position"])
    assert np.std(rattled["wall_velocity"] - quiet["wall_velocity"]) == pytest.approx(0.25,
                                                                                     rel=0.1)


def test_a_comoving_film_mass_slows_the_slip_as_a_heavier_wall():
    # the film's m_c adds to the wall's inertia while it slips: a Coulomb slip of M + m_c,
    # peak velocity (F_s − F_k)/√(K(M + m_c)) (+ about V), the slip distance 2(F_s − F_k)/K
    # plus about V·τ_s of the longer slip (without m_c: 1.55 σ/τ and 13.2 σ)
    mc = 90.0
    run = _run(comoving_mass=mc)[0]
    y, s = run["yield_index"], run["stick_index"]
    x, v = run["wall_position"], run["wall_velocity"]
    tau = math.pi * math.sqrt((M + mc) / K)
    for a, b in zip(y[1:], s[1:]):
        assert x[b] - x[a] == pytest.approx(2 * (FS - FK) / K + 0.1 * tau, abs=0.3)
        assert v[a:b + 1].max() == pytest.approx((FS - FK) / math.sqrt(K * (M + mc)) + 0.1,
                                                 abs=0.02)


def _slip_by_ode(friction_up, friction_down, v0=0.1, f0=FS):
    """A slip from rest at spring force ``f0`` integrated by solve_ivp, the friction
    ``friction_up(v, s)`` until the peak velocity, then ``friction_down(v, s, v_peak)`` until
    the wall stops (s the distance slid): its distance, peak velocity and duration."""
    def rhs(law):
        return lambda t, y: [y[1], (f0 + K * (v0 * t - y[0]) - law(y[1], y[0])) / M]
    peak = lambda t, y: f0 + K * (v0 * t - y[0]) - friction_up(y[1], y[0])
    peak.terminal, peak.direction = True, -1
    up = solve_ivp(rhs(friction_up), (0, 500), [0.0, 0.0], events=peak, rtol=1e-10,
                   atol=1e-12, first_step=1e-6)
    (t1,), (y1,) = up.t_events[0], up.y_events[0]
    stop = lambda t, y: y[1]
    stop.terminal, stop.direction = True, -1
    down = solve_ivp(rhs(lambda v, s: friction_down(v, s, y1[1])), (t1, 500), y1,
                     events=stop, rtol=1e-10, atol=1e-12)
    return down.y_events[0][0][0], y1[1], down.t_events[0][0]


@pytest.mark.parametrize("law, parameters, up, down", [
    # a film that weakens over the slip distance D_c = 1 σ
    ("slip-weakening", (30.0, 2.0, 15.0, 1.0),
     lambda v, s: 30.0 + 15.0 * math.exp(-s) + 2.0 * v,
     lambda v, s, vp: 30.0 + 15.0 * math.exp(-s) + 2.0 * v),
    # a film that melts with the fastest velocity reached, v_c = 0.5 σ/τ, and stays melted
    ("melting", (30.0, 2.0, 15.0, 0.5),
     lambda v, s: 30.0 + 15.0 * math.exp(-v / 0.5) + 2.0 * v,
     lambda v, s, vp: 30.0 + 15.0 * math.exp(-vp / 0.5) + 2.0 * v)])
def test_noise_free_yield_loop_slips_are_the_ode(law, parameters, up, down):
    # the laws with a yield loop, noise-free, slip as solve_ivp integrates them: the slip's
    # distance, peak velocity and duration (the yield and the stop fall on the sub-steps)
    run = slide(law, parameters, mass=M, stiffness=K, drive_velocity=0.1, static_force=FS,
                duration=600.0, dt=0.25, substeps=8)[0]
    y, s = run["yield_index"], run["stick_index"]
    assert y.size >= 2
    x, v, t = run["wall_position"], run["wall_velocity"], run["time"]
    dist, vpeak, dur = _slip_by_ode(up, down)
    for a, b in zip(y, s):
        assert x[b + 1] - x[a] == pytest.approx(dist, rel=2e-3)
        assert v[a:b + 1].max() == pytest.approx(vpeak, rel=2e-3)
        assert t[b + 1] - t[a] == pytest.approx(dur, abs=0.5)


@pytest.mark.parametrize("bad", [{"mass": 0.0}, {"dt": -1.0}, {"replicas": 0},
                                 {"velocity_correlation": 1.0}, {"rattle": -0.1},
                                 {"comoving_mass": -1.0}, {"comoving_mass": math.inf}])
def test_bad_arguments_are_refused(bad):
    with pytest.raises(ValueError):
        _run(**bad)


@pytest.mark.parametrize("law, parameters", [("stribeck", (1.0,)), ("linear", (1.0,)),
                                             ("weakening", (25.0, 48.0, math.nan)),
                                             ("melting", (25.0, 0.0, 10.0, 0.0)),
                                             ("slip-weakening", (25.0, 0.0, 10.0, -1.0)),
                                             ("maxwell", (25.0, 3.0, 1.0, 0.0)),
                                             ("maxwell-weakening", (25.0, 3.0, 1.0, 1.0, 0.0)),
                                             ("corrugated", (25.0, 3.0, 1.0, 0.0, 0.0, 0.0)),
                                             ("corrugated", (25.0, 3.0, 1.0, 1.1, 0.0, -1.0)),
                                             ("corrugated-loop",
                                              (25.0, 3.0, 1.0, 0.0, 2.0, 1.1, 0.0, 0.0, 0.0)),
                                             ("corrugated-loop",
                                              (25.0, 3.0, 1.0, 0.1, 2.0, 1.1, 0.0, 5.0, 1.0)),
                                             ("corrugated-loop",
                                              (25.0, 3.0, 1.0, 0.1, 2.0, 1.1, 0.0, 0.0, 2.0))])
def test_a_bad_law_is_refused(law, parameters):
    with pytest.raises(ValueError, match=law if law == "stribeck" else "parameters"):
        slide(law, parameters, mass=M, stiffness=K, drive_velocity=0.1, static_force=FS,
              duration=10.0, dt=0.25)


@pytest.mark.parametrize("law, parameters, held, excess", [
    ("maxwell", (36.0, 6.0, 0.0, 3.0), 0.0, lambda x: 0.0),
    # the film still holds 6 ε/σ at the yield and releases it over τ_r
    ("maxwell", (36.0, 6.0, 6.0, 3.0), 6.0, lambda x: 0.0),
    # the lagging film melts over the slip distance D_c = 1 σ from 36 + 6
    ("maxwell-weakening", (36.0, 6.0, 6.0, 1.0, 3.0), 0.0, lambda x: 6.0 * math.exp(-x))])
def test_a_maxwell_film_slips_as_the_ode(law, parameters, held, excess):
    # a viscoelastic film, F = F_k (+ the excess) + ψ with ψ relaxing to B·v over τ_r
    # (``held`` at the yield), noise-free: its slips are solve_ivp's (distance, peak
    # velocity, duration)
    fk, b, tau_r = parameters[0], parameters[1], parameters[-1]
    run = slide(law, parameters, mass=M, stiffness=K, drive_velocity=0.1,
                static_force=FS, duration=600.0, dt=0.25, substeps=8)[0]
    y, s = run["yield_index"], run["stick_index"]
    assert y.size >= 2
    rhs = lambda t, q: [q[1], (FS + K * (0.1 * t - q[0]) - fk - excess(q[0]) - q[2]) / M,
                        (b * q[1] - q[2]) / tau_r]
    stop = lambda t, q: q[1]
    stop.terminal, stop.direction = True, -1
    ode = solve_ivp(rhs, (0, 500), [0.0, 1e-12, held], events=stop, rtol=1e-10, atol=1e-12)
    dist, dur = ode.y_events[0][0][0], ode.t_events[0][0]
    x, v, t = run["wall_position"], run["wall_velocity"], run["time"]
    for a, c in zip(y, s):
        assert x[c + 1] - x[a] == pytest.approx(dist, rel=2e-3)
        assert v[a:c + 1].max() == pytest.approx(ode.y[1].max(), rel=2e-3)
        assert t[c + 1] - t[a] == pytest.approx(dur, abs=0.5)


def test_a_corrugated_films_first_slip_is_the_ode():
    # a film between commensurate walls: F_k + B·v + ΔF·sin(2π·x/λ + φ) at the wall's
    # position x; the slider starts stuck at x = 0, so its first slip starts there, as the
    # ODE's (later slips start at other registries and differ)
    fk, b, df, lam, phi = 36.0, 2.0, 4.0, 1.1, 0.5
    run = slide("corrugated", (fk, b, df, lam, phi, 0.0), mass=M, stiffness=K, drive_velocity=0.1,
                static_force=FS, duration=400.0, dt=0.25, substeps=8)[0]
    y, s = run["yield_index"], run["stick_index"]
    assert y.size >= 1
    rhs = lambda t, q: [q[1], (FS + K * (0.1 * t - q[0]) - fk - b * q[1]
                               - df * math.sin(2 * math.pi * q[0] / lam + phi)) / M]
    stop = lambda t, q: q[1]
    stop.terminal, stop.direction = True, -1
    ode = solve_ivp(rhs, (0, 300), [0.0, 1e-12], events=stop, rtol=1e-10, atol=1e-12)
    x, v, t = run["wall_position"], run["wall_velocity"], run["time"]
    a, c = y[0], s[0]
    assert x[c + 1] - x[a] == pytest.approx(ode.y_events[0][0][0], rel=2e-3)
    assert v[a:c + 1].max() == pytest.approx(ode.y[1].max(), rel=2e-3)
    assert t[c + 1] - t[a] == pytest.approx(ode.t_events[0][0], abs=0.5)


REGISTRY = lambda x: 4.0 * math.sin(2 * math.pi * x / 1.1 + 0.5)


@pytest.mark.parametrize("kind, friction", [
    # the corrugated film weakening over the slip distance D = 1 σ
    (0.0, lambda v, x, vmax: 30.0 + 15.0 * math.exp(-x) + 2.0 * v + REGISTRY(x)),
    # melting with the fastest velocity reached, v_c = 0.5 σ/τ
    (1.0, lambda v, x, vmax: 30.0 + 15.0 * math.exp(-vmax / 0.5) + 2.0 * v + REGISTRY(x))])
def test_a_corrugated_films_yield_loop_slips_as_the_ode(kind, friction):
    # a yield loop beside the walls' registry force: the first slip (from x = 0, where the
    # ODE starts) is solve_ivp's, the fastest velocity so far a state of its own (the wall
    # can speed up again past a crest of the registry)
    run = slide("corrugated-loop", (30.0, 2.0, 15.0, 1.0 if kind == 0 else 0.5, 4.0, 1.1,
                                    0.5, 0.0, kind),
                mass=M, stiffness=K, drive_velocity=0.1, static_force=FS, duration=400.0,
                dt=0.25, substeps=8)[0]
    y, s = run["yield_index"], run["stick_index"]
    assert y.size >= 1

    def rhs(t, q):
        x, v, vmax = q
        a = (FS + K * (0.1 * t - x) - friction(v, x, max(vmax, v))) / M
        return [v, a, a if (v >= vmax and a > 0) else 0.0]
    stop = lambda t, q: q[1] if t > 1.0 else 1.0
    stop.terminal, stop.direction = True, -1
    ode = solve_ivp(rhs, (0, 500), [0.0, 0.0, 0.0], events=stop, rtol=1e-10, atol=1e-12,
                    first_step=1e-6, max_step=0.05)
    x, v, t = run["wall_position"], run["wall_velocity"], run["time"]
    a, c = y[0], s[0]
    assert x[c + 1] - x[a] == pytest.approx(ode.y_events[0][0][0], rel=2e-3)
    assert v[a:c + 1].max() == pytest.approx(ode.y[1].max(), rel=2e-3)
    assert t[c + 1] - t[a] == pytest.approx(ode.t_events[0][0], abs=0.5)


def test_a_corrugated_loop_without_its_loop_or_registry_is_the_plain_film():
    # W = 0: the ``corrugated`` film's slips, to the last digit; ΔF = 0: the loop law's, with
    # a lag or not (the slip-weakening law's distance is ∫|v| dt, the loop's x − x_yield:
    # the same but for the integrator's rounding)
    kw = dict(mass=1e5, stiffness=8.0, drive_velocity=0.0025, static_force=45.0,
              duration=6000.0, dt=0.25, velocity_noise=0.0028, velocity_correlation=0.993,
              seed=3, mount_damping=34.0, stop_velocity=0.004, armed_below=27.0)
    pairs = [(("corrugated-loop", (21.6, 318.0, 0.0, 0.3, 20.0, 1.1, -0.97, 12.0, 0.0)),
              ("corrugated", (21.6, 318.0, 20.0, 1.1, -0.97, 12.0))),
             (("corrugated-loop", (21.6, 318.0, 10.0, 0.3, 0.0, 1.1, -0.97, 0.0, 0.0)),
              ("slip-weakening", (21.6, 318.0, 10.0, 0.3))),
             (("corrugated-loop", (21.6, 318.0, 10.0, 0.02, 0.0, 1.1, -0.97, 0.0, 1.0)),
              ("melting", (21.6, 318.0, 10.0, 0.02))),
             # a lagging film that melts over the slip distance
             (("corrugated-loop", (21.6, 318.0, 10.0, 0.3, 0.0, 1.1, -0.97, 12.0, 0.0)),
              ("maxwell-weakening", (21.6, 318.0, 10.0, 0.3, 12.0)))]
    for k, (one, other) in enumerate(pairs):
        a, b = (slide(law, par, **kw)[0] for law, par in (one, other))
        assert a["yield_index"].size >= 2
        np.testing.assert_allclose(a["wall_position"], b["wall_position"], rtol=0,
                                   atol=0 if k == 0 else 1e-3)
        np.testing.assert_array_equal(a["stick_index"], b["stick_index"])


def test_a_lagging_film_reads_as_a_negative_comoving_mass():
    # the heavy slider's film with a force that lags by τ_r = 12 τ: the one law (F_k + B·v +
    # m_c·a) takes the lag for a co-moving mass of about −B·τ_r (the MD's one law at
    # M = 10⁵ reads −5 590 ± 1 820 m); without the lag, none
    from filmfriction.analysis.slip_law.slip_law_pooled import RunSlips, fit_pooled_ensemble
    from filmfriction.reduced_model.cycles import cycle_table

    def one_law(tau):
        runs = []
        for fs in (38.0, 45.0, 52.0):
            r = slide("maxwell" if tau else "linear",
                      (20.0, 473.0, 0.0, tau) if tau else (20.0, 473.0),
                      mass=1e5, stiffness=8.0, drive_velocity=0.0025, static_force=fs,
                      duration=16000.0, dt=0.25, substeps=4, mount_damping=34.0,
                      armed_below=27.0, initial_force=10.0)[0]
            tab = cycle_table(r["time"], r["spring_force"], r["yield_index"], r["stick_index"],
                              spring_constant=8.0, wall_position=r["wall_position"])[1:]
            runs.append(RunSlips(r["time"], r["spring_force"], r["wall_velocity"], tab,
                                 wall_position=r["wall_position"]))
        return fit_pooled_ensemble(runs, mass=1e5, drive_velocity=0.0025, mount_damping=34.0,
                                   min_window_time=3.0).one_law
    lagged, plain = one_law(12.0), one_law(0.0)
    assert lagged.comoving_mass == pytest.approx(-473.0 * 12.0, rel=0.15), lagged.comoving_mass
    assert abs(plain.comoving_mass) < 100.0, plain.comoving_mass


def test_a_lagged_registrys_first_slip_is_the_ode():
    # the registry force at the film's registry y = x − ψ, which trails the wall
    # (dy/dt = (x − y)/τ_g, y = x at the yield): the first slip, from x = 0, is solve_ivp's
    # with y a state of its own
    fk, b, df, lam, phi, tau_g = 36.0, 2.0, 4.0, 1.1, 0.5, 1.5
    run = slide("lagged-registry", (fk, b, df, lam, phi, tau_g), mass=M, stiffness=K,
                drive_velocity=0.1, static_force=FS, duration=400.0, dt=0.25, substeps=8)[0]
    y, s = run["yield_index"], run["stick_index"]
    assert y.size >= 1
    rhs = lambda t, q: [q[1], (FS + K * (0.1 * t - q[0]) - fk - b * q[1]
                               - df * math.sin(2 * math.pi * q[2] / lam + phi)) / M,
                        (q[0] - q[2]) / tau_g]
    stop = lambda t, q: q[1] if t > 1.0 else 1.0
    stop.terminal, stop.direction = True, -1
    ode = solve_ivp(rhs, (0, 300), [0.0, 1e-12, 0.0], events=stop, rtol=1e-10, atol=1e-12,
                    max_step=0.05)
    x, v, t = run["wall_position"], run["wall_velocity"], run["time"]
    a, c = y[0], s[0]
    assert x[c + 1] - x[a] == pytest.approx(ode.y_events[0][0][0], rel=2e-3)
    # the sampled peak (every 0.25 τ) of a velocity the registry ripples
    assert v[a:c + 1].max() == pytest.approx(ode.y[1].max(), rel=5e-3)
    assert t[c + 1] - t[a] == pytest.approx(ode.t_events[0][0], abs=0.5)
    # and a registry that barely trails (τ_g 10⁻³ τ, the step 0.6 of it) is the
    # ``corrugated`` film's
    kw = dict(mass=M, stiffness=K, drive_velocity=0.1, static_force=FS, duration=400.0,
              dt=0.25, substeps=400)
    near = slide("lagged-registry", (fk, b, df, lam, phi, 1e-3), **kw)[0]
    plain = slide("corrugated", (fk, b, df, lam, phi, 0.0), **kw)[0]
    np.testing.assert_array_equal(near["stick_index"], plain["stick_index"])
    # (to the lag's own trail, v·τ_g ≈ 1.3e-3 σ at the slips' speed)
    np.testing.assert_allclose(near["wall_position"], plain["wall_position"], atol=4e-3)
    with pytest.raises(ValueError, match="τ_g"):
        slide("lagged-registry", (fk, b, df, lam, phi, 0.0), **kw)
    # a lag the integration step does not resolve (RK4 would blow the trail up): refused
    with pytest.raises(ValueError, match="shorter than the integration step"):
        slide("lagged-registry", (fk, b, df, lam, phi, 0.1), **{**kw, "substeps": 1})


def _branching_first_slip(df1, lam, phi1, df2, phi2, w1, w2, dphi, film, q0):
    """The first slip of a branch-weighted registry solved by solve_ivp in pieces: r = 1
    while the velocity is at its running maximum (until the acceleration turns negative),
    r = v/v_max after (until v passes v_max again, or stops).  ``film(t, q)``: the film's
    force besides the registry and the extra states' rates; ``q0``: x, v and those states at
    the yield.  Returns (the slip's end time, its distance, the number of pieces)."""
    def rhs(r):
        def f(t, q):
            th = 2 * math.pi * q[0] / lam
            reg = (df1 * (1 - w1 * r(q)) * math.sin(th + phi1 + dphi * r(q))
                   + df2 * (1 + w2 * r(q)) * math.sin(2 * th + phi2))
            force, rates = film(t, q)
            return [q[1], (FS + K * (0.1 * t - q[0]) - force - reg) / M] + rates
        return f
    t0, pieces = 0.0, 0
    ode = dict(rtol=1e-10, atol=1e-12, max_step=0.05)
    while True:
        pieces += 1
        rising = rhs(lambda q: 1.0)
        peak = lambda t, q, t0=t0: rising(t, q)[1] if t > t0 + 1e-6 or t0 == 0 else 1.0
        peak.terminal, peak.direction = True, -1
        up = solve_ivp(rising, (t0, 300), q0, events=peak, **ode)
        t0, q0 = up.t_events[0][0], list(up.y_events[0][0])
        vmax = q0[1]
        stop = lambda t, q, t0=t0: q[1] if t > t0 + 1e-6 else 1.0
        again = lambda t, q, m=vmax: q[1] - m * (1 + 1e-9)
        stop.terminal, again.terminal, stop.direction, again.direction = True, True, -1, 1
        down = solve_ivp(rhs(lambda q, m=vmax: q[1] / m), (t0, 300), q0,
                         events=(stop, again), **ode)
        if down.t_events[0].size:
            return down.t_events[0][0], down.y_events[0][0][0], pieces
        t0, q0 = down.t_events[1][0], list(down.y_events[1][0])


def test_a_branching_registrys_first_slip_is_the_ode():
    # the registry's harmonics weighted by r = |v|/(the slip's fastest |v| so far)
    fk, b, df1, lam, phi1, df2, phi2, w1, w2, dphi = 36.0, 2.0, 4.0, 1.1, 0.5, 2.0, -1.5, \
        0.4, 0.6, 0.3
    par = (fk, b, df1, lam, phi1, df2, phi2, w1, w2, dphi)
    run = slide("branching-registry", par, mass=M, stiffness=K, drive_velocity=0.1,
                static_force=FS, duration=400.0, dt=0.25, substeps=8)[0]
    end, x_end, pieces = _branching_first_slip(
        df1, lam, phi1, df2, phi2, w1, w2, dphi,
        lambda t, q: (fk + b * q[1], []), [0.0, 1e-12])
    assert pieces > 1      # the registry ripples the velocity past its peak: several maxima
    x, v, t = run["wall_position"], run["wall_velocity"], run["time"]
    a, c = run["yield_index"][0], run["stick_index"][0]
    # (to 10⁻⁵: the branch weights move the slip's end by 10⁻³ of it)
    assert x[c + 1] - x[a] == pytest.approx(x_end, rel=1e-5)
    assert t[c + 1] - t[a] == pytest.approx(end, abs=0.5)
    # no branch difference and no second harmonic: the ``corrugated`` film, step for step
    kw = dict(mass=M, stiffness=K, drive_velocity=0.1, static_force=FS, duration=400.0,
              dt=0.25, substeps=8)
    flat = slide("branching-registry", (fk, b, df1, lam, phi1, 0.0, phi2, 0.0, 0.0, 0.0),
                 **kw)[0]
    plain = slide("corrugated", (fk, b, df1, lam, phi1, 0.0), **kw)[0]
    np.testing.assert_array_equal(flat["wall_position"], plain["wall_position"])
    # and the branch weights change the slip
    assert not np.array_equal(run["wall_position"], plain["wall_position"])
    for bad in ((fk, b, df1, lam, phi1, df2, phi2, 1.5, w2, dphi),
                (fk, b, df1, lam, phi1, df2, phi2, w1, -1.5, dphi),
                (fk, b, df1, 0.0, phi1, df2, phi2, w1, w2, dphi)):
        with pytest.raises(ValueError, match="no amplitude below 0"):
            slide("branching-registry", bad, **kw)


def test_a_viscous_force_lagging_by_a_distance_is_the_ode():
    # ψ relaxes to B·v over the slip distance d (dψ/dt = |v|·(B·v − ψ)/d, ψ = 0 at the
    # yield): the first slip is solve_ivp's with ψ a state of its own, and a lag of a
    # distance moves the slip's end where a lag of the time d/v̄ moves it otherwise
    fk, b, df, lam, phi, d = 36.0, 6.0, 4.0, 1.1, 0.5, 0.5
    kw = dict(mass=M, stiffness=K, drive_velocity=0.1, static_force=FS, duration=400.0,
              dt=0.25, substeps=8)
    run = slide("distance-lag", (fk, b, df, lam, phi, d), **kw)[0]
    rhs = lambda t, q: [q[1], (FS + K * (0.1 * t - q[0]) - fk - q[2]
                               - df * math.sin(2 * math.pi * q[0] / lam + phi)) / M,
                        abs(q[1]) * (b * q[1] - q[2]) / d]
    stop = lambda t, q: q[1] if t > 1.0 else 1.0
    stop.terminal, stop.direction = True, -1
    ode = solve_ivp(rhs, (0, 300), [0.0, 1e-12, 0.0], events=stop, rtol=1e-10, atol=1e-12,
                    max_step=0.05)
    x, t = run["wall_position"], run["time"]
    a, c = run["yield_index"][0], run["stick_index"][0]
    assert x[c + 1] - x[a] == pytest.approx(ode.y_events[0][0][0], rel=1e-4)
    assert t[c + 1] - t[a] == pytest.approx(ode.t_events[0][0], abs=0.5)
    vbar = ode.y_events[0][0][0] / ode.t_events[0][0]
    in_time = slide("corrugated", (fk, b, df, lam, phi, d / vbar), **kw)[0]
    # (the lag in time d/v̄ ends the slip 0.08 σ, 10⁻² of it, away: 100 times the tolerance)
    assert abs(in_time["wall_position"][c + 1] - x[c + 1]) > 0.05
    with pytest.raises(ValueError, match="distance d"):
        slide("distance-lag", (fk, b, df, lam, phi, 0.0), **kw)


def test_a_lag_in_distance_beside_a_branching_registry_is_the_ode():
    # ``distance-lag-branching``: the viscous force ψ lagging by a slip distance and the
    # branch-weighted registry together; the first slip is solve_ivp's in pieces with ψ a
    # state of its own, and without weights and second harmonic the law is ``distance-lag``
    fk, b, df1, lam, phi1, d, df2, phi2, w1, w2, dphi = 36.0, 6.0, 4.0, 1.1, 0.5, 0.5, 2.0, \
        -1.5, 0.4, 0.6, 0.3
    kw = dict(mass=M, stiffness=K, drive_velocity=0.1, static_force=FS, duration=400.0,
              dt=0.25, substeps=8)
    run = slide("distance-lag-branching", (fk, b, df1, lam, phi1, d, df2, phi2, w1, w2, dphi),
                **kw)[0]
    end, x_end, pieces = _branching_first_slip(
        df1, lam, phi1, df2, phi2, w1, w2, dphi,
        lambda t, q: (fk + q[2], [abs(q[1]) * (b * q[1] - q[2]) / d]), [0.0, 1e-12, 0.0])
    assert pieces > 1
    x, t = run["wall_position"], run["time"]
    a, c = run["yield_index"][0], run["stick_index"][0]
    assert x[c + 1] - x[a] == pytest.approx(x_end, rel=1e-4)
    assert t[c + 1] - t[a] == pytest.approx(end, abs=0.5)
    flat = slide("distance-lag-branching", (fk, b, df1, lam, phi1, d, 0.0, phi2, 0.0, 0.0,
                                            0.0), **kw)[0]
    plain = slide("distance-lag", (fk, b, df1, lam, phi1, d), **kw)[0]
    np.testing.assert_array_equal(flat["wall_position"], plain["wall_position"])
    assert abs(plain["wall_position"][c + 1] - x[c + 1]) > 1e-2
    with pytest.raises(ValueError, match="no amplitude below 0"):
        slide("distance-lag-branching", (fk, b, df1, lam, phi1, d, df2, phi2, 1.5, w2, dphi),
              **kw)
    with pytest.raises(ValueError, match="lag's distance d"):
        slide("distance-lag-branching", (fk, b, df1, lam, phi1, 0.0, df2, phi2, w1, w2, dphi),
              **kw)
