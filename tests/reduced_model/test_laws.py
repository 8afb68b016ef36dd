"""Every friction law: energy ledger, exact stick, seeds' closed forms, bad input."""
import math

import numpy as np
import pytest

from filmfriction.reduced_model import SpringBlock, laws

STICK_LAWS = {
    "coulomb": laws.Coulomb(static=1.0, kinetic=0.5),
    "coulomb_viscous": laws.Coulomb(static=1.0, kinetic=0.5, viscous=0.3),
    "stribeck_exp": laws.StribeckExponential(static=1.0, kinetic=0.5, stribeck_velocity=0.05),
    "stribeck_schnelle": laws.StribeckSchnelle(),
    "exp_weakening": laws.ExponentialWeakening(static=1.0, kinetic=0.5, velocity_scale=0.1),
    "newtonian_yield": laws.NewtonianFilm(viscosity=0.2, area=1.0, thickness=1.0, yield_force=1.0),
    "shear_thinning_yield": laws.ShearThinningFilm(viscosity=0.5, area=1.0, thickness=1.0,
                                                   exponent=0.6, onset_rate=0.05, yield_force=1.0),
    "contact_age": laws.ContactAge(static=1.0, backward=0.5, age_time=1.0, memory_length=0.05),
    "lubricated_film": laws.LubricatedFilm(boundary=1.0, hydrodynamic=0.3),
}
SMOOTH_LAWS = {
    "rate_state_aging": laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1),
    "rate_state_slip": laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1, evolution="slip"),
    "newtonian": laws.NewtonianFilm(viscosity=0.2, area=1.0, thickness=1.0),
    "shear_thinning": laws.ShearThinningFilm(viscosity=0.5, area=1.0, thickness=1.0, exponent=0.6,
                                             onset_rate=0.05),
}


@pytest.mark.parametrize("name", sorted(STICK_LAWS))
def test_ledger_and_exact_stick(name):
    law = STICK_LAWS[name]
    r = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.1, damping=0.02, law=law).simulate(120.0)
    assert r.status == 0
    assert r.energy.closure <= 1e-8, r.energy
    kinds = [e.kind for e in r.events]
    assert "slip" in kinds and "stick" in kinds, kinds
    # during every stick the block does not move at all (no creep, no chattering)
    for e, nxt in zip(r.events, r.events[1:]):
        if e.kind == "stick":
            assert np.all(r.v[e.index: nxt.index + 1] == 0.0)
            assert np.ptp(r.x[e.index: nxt.index + 1]) == 0.0
    assert r.energy.friction_dissipation > 0


@pytest.mark.parametrize("name", sorted(SMOOTH_LAWS))
def test_ledger_smooth_laws(name):
    law = SMOOTH_LAWS[name]
    K = 40.0 if "rate_state" in name else 1.0
    r = SpringBlock(mass=1.0, stiffness=K, drive_velocity=0.1, law=law).simulate(
        30.0, initial_velocity=0.13)
    assert r.status == 0 and r.energy.closure <= 1e-8, r.energy


def test_belt_and_free_oscillator_ledgers():
    law = laws.LubricatedFilm(boundary=0.2, hydrodynamic=0.05, relaxation_time=0.5)
    free = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.0, drive="fixed", law=law)
    r = free.simulate(60.0, initial_velocity=2.0)        # seed 001: launched, decays, stops
    assert r.energy.closure <= 1e-8 and r.energy.drive_work == 0.0
    assert r.events[-1].kind == "stick"
    belt = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.05, damping=0.05, drive="belt",
                       law=laws.StribeckExponential(static=0.5, kinetic=0.3, stribeck_velocity=0.1))
    r = belt.simulate(150.0)
    assert r.energy.closure <= 1e-8 and any(e.kind == "stick" for e in r.events)


def test_klein_closed_form_slip():
    """Seed 004, eq. 2: x(t) = x0[1 - e^(-t/tau0){cosh(w t/tau0) + sinh(w t/tau0)/w}]."""
    K, M = 97.0, 1.47e-3
    film = laws.NewtonianFilm(viscosity=27.0, area=4e-10, thickness=3.5e-9)
    B = film.drag_coefficient
    x0 = 40e-9
    block = SpringBlock(mass=M, stiffness=K, drive_velocity=0.0, drive="fixed", law=film)
    r = block.simulate(0.1, initial_extension=x0, samples_per_segment=501)
    tau0, w = 2 * M / B, math.sqrt(1 - 4 * M * K / B ** 2)
    t = r.t
    exact = x0 * (1 - np.exp(-t / tau0) * (np.cosh(w * t / tau0) + np.sinh(w * t / tau0) / w))
    np.testing.assert_allclose(r.x, exact, rtol=0, atol=1e-9 * x0)
    # all the released spring energy is dissipated viscously (Klein's Delta E_viscous)
    released = 0.5 * K * (x0 ** 2 - (x0 - r.x[-1]) ** 2)
    assert r.energy.friction_dissipation == pytest.approx(released, rel=1e-9)
    assert r.energy.closure < 1e-10


def test_klein_ode_path_agrees_with_closed_form():
    film = laws.NewtonianFilm(viscosity=27.0, area=4e-10, thickness=3.5e-9, yield_force=97.0 * 40e-9)
    block = SpringBlock(mass=1.47e-3, stiffness=97.0, drive_velocity=1e-6, law=film)
    a = block.simulate(0.2)
    b = block.simulate(0.2, method="ode")
    assert [e.kind for e in a.events] == [e.kind for e in b.events] == ["slip"]
    assert b.events[0].time == pytest.approx(a.events[0].time, rel=1e-12)
    # same final state (the slip relaxes to steady sliding at V: overdamped, no re-stick)
    assert b.x[-1] == pytest.approx(a.x[-1], rel=1e-8)
    assert b.v[-1] == pytest.approx(a.v[-1], rel=1e-6)


def test_dieterich_nucleation():
    """Massless slider, aging law far above steady state, no load rate:
    V(t) = (1/V0 - H t / a)^-1 with H = -K/N + b/dc."""
    law = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-5, v0=1e-6, regularized=False)
    N, K, V0 = 1.0, 500.0, 1e-6
    H = -K / N + law.b / law.dc
    psi0 = math.log(1e8)                      # theta = 1e8 dc / V0: far above steady state
    tau0 = N * (law.mu0 + law.b * psi0)       # friction at V0
    t_f = law.a / (H * V0)
    block = SpringBlock(mass=0.0, stiffness=K, drive_velocity=0.0, law=law, normal_load=N)
    r = block.simulate(0.99 * t_f, initial_extension=tau0 / K, initial_state=[psi0])
    exact = 1.0 / (1.0 / V0 - H * r.t / law.a)
    # (the neglected 1 in theta' = 1 - v theta/dc shifts t_f by ~1e-8 t_f here)
    np.testing.assert_allclose(r.v, exact, rtol=1e-5)
    assert r.v[-1] == pytest.approx(100 * V0, rel=1e-5)
    assert r.energy.closure < 1e-8


def test_rate_state_critical_stiffness():
    law = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1)
    assert law.critical_stiffness(2.0) == pytest.approx(2.0 * 0.005 / 1e-2)
    kc = law.critical_stiffness(1.0, mass=1.0, velocity=0.1)
    assert kc == pytest.approx(0.5 * (1 + 0.01 / (0.01 * 0.01)))

    def growth(K):
        r = SpringBlock(mass=1.0, stiffness=K, drive_velocity=0.1, law=law).simulate(
            60.0, initial_velocity=0.11)
        half = r.t > 30.0
        return np.ptp(r.v[half]) / np.ptp(r.v[~half])
    assert growth(0.8 * kc) > 1.0 > growth(1.2 * kc)   # unstable below k_c, stable above


def test_contact_age_strengthens_during_stick():
    law = STICK_LAWS["contact_age"]
    r = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.1, law=law).simulate(120.0)
    stick = [e for e in r.events if e.kind == "stick"][0]
    age = r.state[0]
    nxt = [e for e in r.events if e.time > stick.time][0]
    np.testing.assert_allclose(np.diff(age[stick.index: nxt.index + 1]),
                               np.diff(r.t[stick.index: nxt.index + 1]), rtol=1e-12)
    # breakaway exactly when the spring force reaches the aged threshold
    assert nxt.spring_force == pytest.approx(law.static_force(age[nxt.index: nxt.index + 1], 1.0), rel=1e-10)
    assert law.critical_velocity(2.0) == pytest.approx(0.5 / 2.0)


def test_stribeck_forms():
    s = laws.StribeckExponential(static=0.4, kinetic=0.25, stribeck_velocity=0.01)
    assert s.sliding_force(0.0, (), 2.0) == pytest.approx(0.8)
    assert s.sliding_force(1.0, (), 2.0) == pytest.approx(0.5)
    sch = laws.StribeckSchnelle()
    v = np.logspace(-3, 1, 200)
    mu = sch.sliding_force(v, (), 1.0)
    assert mu[0] == pytest.approx(0.4, rel=0.05) and mu.min() < 0.4 and mu[-1] > mu.min()


@pytest.mark.parametrize("make, match", [
    (lambda: laws.StribeckExponential(static=0.4, kinetic=0.25, stribeck_velocity=0.0), "stribeck_velocity"),
    (lambda: laws.NewtonianFilm(viscosity=1.0, area=1.0, thickness=0.0), "thickness"),
    (lambda: laws.ShearThinningFilm(viscosity=1.0, area=1.0, thickness=1.0, exponent=1.0), "exponent"),
    (lambda: laws.ContactAge(static=0.4, backward=0.5, age_time=1.0, memory_length=1.0), "static"),
    (lambda: laws.RateState(mu0=0.6, a=0.0, b=0.01, dc=1.0, v0=1.0), "RateState.a"),
    (lambda: laws.RateState(mu0=0.6, a=0.01, b=0.01, dc=1.0, v0=1.0, evolution="x"), "evolution"),
    (lambda: laws.LubricatedFilm(boundary=0.3, hydrodynamic=0.1, relaxation_time=-1), "relaxation_time"),
])
def test_bad_law_parameters(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_massless_limits():
    film = laws.NewtonianFilm(viscosity=1.0, area=1.0, thickness=1.0)
    r = SpringBlock(mass=0.0, stiffness=2.0, drive_velocity=0.5, law=film).simulate(10.0, initial_extension=0.0)
    # overdamped massless film: v = V (1 - exp(-K t / B))
    np.testing.assert_allclose(r.v, 0.5 * (1 - np.exp(-2.0 * r.t)), atol=1e-9)
    with pytest.raises(ValueError, match="mass = 0"):
        SpringBlock(mass=0.0, stiffness=1.0, drive_velocity=0.1, law=laws.StribeckSchnelle())
    with pytest.raises(ValueError, match="initial_state"):
        SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.1,
                    law=STICK_LAWS["contact_age"]).simulate(1.0, initial_state=[1.0, 2.0])


@pytest.mark.parametrize("law", [
    laws.Coulomb(static=1.0, kinetic=0.5, viscous=0.3),
    laws.StribeckExponential(static=1.0, kinetic=0.5, stribeck_velocity=0.05),
    laws.StribeckExponential(static=1.0, kinetic=0.5, stribeck_velocity=0.05, shape=1.3, viscous=0.2),
    laws.StribeckSchnelle(),
    laws.ExponentialWeakening(static=1.0, kinetic=0.5, velocity_scale=0.1),
], ids=lambda law: type(law).__name__)
def test_scalar_sliding_agrees_with_sliding_force(law):
    """The hot-loop closure of a stateless law is the same curve as sliding_force."""
    fast = law.scalar_sliding(1.7)
    for speed in (0.0, 1e-4, 0.01, 0.05, 0.3, 2.0, 40.0):
        assert fast(speed) == pytest.approx(float(law.sliding_force(speed, (), 1.7)), rel=1e-14, abs=1e-300)


def test_restick_root_newton_and_brentq_fallback():
    from filmfriction.reduced_model.integrators.dop853_slip import restick_root

    def state_at(t):
        return np.array([0.0, math.cos(t) - 0.5])

    def slip_of(z):
        return float(z[1])

    root = math.pi / 3
    exact_rate = (lambda t, z: -math.sin(t))
    assert restick_root(state_at, slip_of, exact_rate, 0.9, state_at(0.9), 1.2, state_at(1.2)) == \
        pytest.approx(root, rel=0, abs=4e-16)
    # a rate that sends Newton out of the bracket: brentq on the same map finishes the job
    wrong_rate = (lambda t, z: 1.0)
    assert restick_root(state_at, slip_of, wrong_rate, 0.9, state_at(0.9), 1.2, state_at(1.2)) == \
        pytest.approx(root, rel=0, abs=4e-16)
    # zero slip at the start of the bracket: the slip ends at once
    assert restick_root(state_at, slip_of, exact_rate, root, np.array([0.0, 0.0]), 1.2, state_at(1.2)) == root


def test_stribeck_ode_events_converge_over_many_cycles():
    """The benchmark problem: 41 events over 300 time units; per-slip errors accumulate
    (each cycle starts from the previous one), so this checks the slip integration
    and the re-stick root together."""
    law = laws.StribeckExponential(static=1.0, kinetic=0.5, stribeck_velocity=0.05)
    b = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.1, damping=0.02, law=law)

    def events(rtol):
        r = b.simulate(300.0, rtol=rtol, samples_per_segment=16)
        assert r.energy.closure <= 1e-8, r.energy
        return np.array([e.time for e in r.events])

    tight = events(1e-12)
    assert tight.size == 41
    np.testing.assert_allclose(events(1e-10), tight, rtol=0, atol=1e-8)
    np.testing.assert_allclose(events(1e-7), tight, rtol=0, atol=1e-6)


def test_stateless_ode_slip_is_mirror_symmetric():
    """Launched backwards, a free Stribeck oscillator is the mirror image of the forward one
    (slip direction -1 through the whole fast path: reversals, re-stick, ledger)."""
    law = laws.StribeckExponential(static=0.3, kinetic=0.2, stribeck_velocity=0.05)
    free = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.0, drive="fixed", damping=0.01, law=law)
    fwd = free.simulate(40.0, initial_velocity=2.0)
    bwd = free.simulate(40.0, initial_velocity=-2.0)
    assert [e.kind for e in fwd.events] == [e.kind for e in bwd.events]
    assert "reversal" in [e.kind for e in fwd.events] and fwd.events[-1].kind == "stick"
    np.testing.assert_allclose([e.time for e in bwd.events], [e.time for e in fwd.events], rtol=0, atol=1e-12)
    np.testing.assert_allclose(bwd.x, -fwd.x, rtol=0, atol=1e-12)
    assert fwd.v[-1] == 0.0 and bwd.v[-1] == 0.0
    assert fwd.energy.closure <= 1e-8 and bwd.energy.closure <= 1e-8
