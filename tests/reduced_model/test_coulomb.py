"""Coulomb spring-block: the exact results of the reference notes, to round-off."""
import math

import numpy as np
import pytest

from filmfriction.reduced_model import SimulationLimitError, SpringBlock, laws

FS, FK, K, M, V = 1.0, 0.5, 1.0, 1.0, 0.1
OMEGA = math.sqrt(K / M)


def block(**kw):
    args = dict(mass=M, stiffness=K, drive_velocity=V, damping=0.0, law=laws.Coulomb(static=FS, kinetic=FK))
    args.update(kw)
    return SpringBlock(**args)


def test_public_api_shape():
    r = block().simulate(duration=200.0)
    for name in ("t", "x", "v", "spring_force"):
        assert getattr(r, name).shape == r.t.shape
    assert r.y.shape == (2, r.t.size) and r.success and r.status == 0
    assert {e.kind for e in r.events} == {"slip", "stick"}
    for e in r.events:                       # every event is a sample, exactly
        assert r.t[e.index] == e.time
    led = r.energy
    assert {"drive_work", "kinetic", "spring", "friction_dissipation", "damper_dissipation",
            "closure"} <= set(led.as_dict())
    assert led.closure <= 1e-12


def test_stick_slip_cycle_exact():
    r = block().simulate(200.0)
    slips = np.array([e.time for e in r.events if e.kind == "slip"])
    sticks = np.array([e.time for e in r.events if e.kind == "stick"])
    # first stick from a relaxed spring: Fs/(K V)
    assert slips[0] == pytest.approx(FS / (K * V), rel=1e-14)
    phi = math.atan(K * V / (OMEGA * (FS - FK)))
    slip_time = (math.pi + 2 * phi) / OMEGA
    np.testing.assert_allclose(sticks - slips[: sticks.size], slip_time, rtol=1e-12)
    np.testing.assert_allclose(slips[1:] - sticks[: slips.size - 1], 2 * (FS - FK) / (K * V), rtol=1e-12)
    f_stick = np.array([e.spring_force for e in r.events if e.kind == "stick"])
    np.testing.assert_allclose(f_stick, 2 * FK - FS, atol=1e-12)
    f_slip = np.array([e.spring_force for e in r.events if e.kind == "slip"])
    np.testing.assert_allclose(f_slip, FS, rtol=1e-12)
    # jump of the block in one slip = (Fs - (2Fk - Fs))/K + V * slip time
    x_jump = np.diff(r.x[r.yield_index[0]: r.stick_index[0] + 1][[0, -1]])[0]
    assert x_jump == pytest.approx(2 * (FS - FK) / K + V * slip_time, rel=1e-12)


def test_peak_velocity_and_mean_force():
    r = block().simulate(60.0, samples_per_segment=4001)
    u0 = (FS - FK) / K
    assert r.v.max() == pytest.approx(V + math.sqrt((OMEGA * u0) ** 2 + V ** 2), rel=1e-6)
    # time average of the spring force over one steady cycle (yield to yield) = Fk
    i0, i1 = r.yield_index[1], r.yield_index[2]
    t, f = r.t[i0: i1 + 1], r.spring_force[i0: i1 + 1]
    assert np.trapezoid(f, t) / (t[-1] - t[0]) == pytest.approx(FK, rel=1e-6)


def test_cycles_use_analysis_ruler():
    table = block().simulate(200.0).cycles()
    np.testing.assert_allclose(table.static_force, FS, rtol=1e-12)
    np.testing.assert_allclose(table.backward_force, 2 * FK - FS, atol=1e-12)
    np.testing.assert_allclose(table.stick_duration[:-1], 2 * (FS - FK) / (K * V), rtol=1e-12)
    assert np.all(table.slip_distance > 0)


def test_closed_form_matches_ode_path():
    b = block(damping=0.05)
    exact = b.simulate(100.0)
    ode = b.simulate(100.0, method="ode")
    te = np.array([e.time for e in exact.events])
    to = np.array([e.time for e in ode.events])
    assert te.size == to.size
    np.testing.assert_allclose(to, te, rtol=0, atol=1e-7)
    assert ode.energy.closure < 1e-8


def test_free_coulomb_oscillator_decay():
    F = 0.1
    b = SpringBlock(mass=M, stiffness=K, drive_velocity=0.0, drive="fixed",
                    law=laws.Coulomb(static=F, kinetic=F))
    x0 = 1.05
    r = b.simulate(50.0, initial_extension=x0)        # spring end at +x0: block pulled towards it
    turns = [e for e in r.events if e.kind in ("stick", "reversal")]
    amplitude = np.abs([x0 - r.x[e.index] for e in turns])
    expected = x0 - 2 * F / K * np.arange(1, len(turns) + 1)
    np.testing.assert_allclose(amplitude, expected, atol=1e-12)
    np.testing.assert_allclose(np.diff([0.0] + [e.time for e in turns]), math.pi / OMEGA, rtol=1e-12)
    # it stops at the first turning point inside |x| <= Fs/K, and stays there
    assert turns[-1].kind == "stick" and abs(amplitude[-1]) <= F / K
    assert all(abs(a) > F / K for a in amplitude[:-1])
    assert np.all(r.v[turns[-1].index:] == 0.0)


def test_belt_drive_stick_moves_with_belt():
    b = block(drive="belt", damping=0.02)
    r = b.simulate(150.0)
    stuck = [(e.index, n.index) for e, n in zip(r.events, r.events[1:]) if e.kind == "stick"]
    assert stuck
    for i, j in stuck:
        assert np.all(r.v[i: j + 1] == V)         # v = belt speed exactly: no creep
    assert r.energy.closure < 1e-12


def test_viscous_coulomb_ledger_and_damper():
    r = block(damping=0.1, law=laws.Coulomb(static=FS, kinetic=FK, viscous=0.2)).simulate(300.0)
    assert r.energy.damper_dissipation > 0 and r.energy.closure < 1e-12


# -- extremes -------------------------------------------------------------------
def test_very_stiff_spring():
    r = block(stiffness=1e10).simulate(1e-8 * 30)
    f = [e.spring_force for e in r.events if e.kind == "stick"]
    np.testing.assert_allclose(f, 2 * FK - FS, atol=1e-6)
    assert r.energy.closure < 1e-10


def test_tiny_mass_keeps_exact_cycle():
    r = block(mass=1e-12).simulate(100.0)
    f = [e.spring_force for e in r.events if e.kind == "stick"]
    np.testing.assert_allclose(f, 2 * FK - FS, atol=1e-9)


def test_zero_mass_with_static_friction_is_a_clear_error():
    with pytest.raises(ValueError, match="mass = 0"):
        block(mass=0.0)


def test_heavy_damping_no_stick_slip_no_overflow():
    r = block(damping=1e4).simulate(1e3)
    assert [e.kind for e in r.events] == ["slip"]     # breaks once, then slides smoothly
    assert np.all(np.isfinite(r.x)) and r.energy.closure < 1e-10


def test_vanishing_drive_velocity_long_stick():
    r = block(drive_velocity=1e-12).simulate(3e12)
    assert r.events[0].time == pytest.approx(FS / (K * 1e-12), rel=1e-12)
    assert len(r.events) < 10


def test_large_drive_velocity():
    # undamped Coulomb sticks at any V (lambda_c(0) = 0): the cycle stays exact
    r = block(drive_velocity=1e6).simulate(1e-4)
    f = [e.spring_force for e in r.events if e.kind == "stick"]
    np.testing.assert_allclose(f, 2 * FK - FS, atol=1e-9)
    # with a little damping (zeta = 0.1, lambda = 5e-7 << lambda_c) the slide is smooth
    r = block(drive_velocity=1e6, damping=0.2).simulate(100.0)
    assert [e.kind for e in r.events] == ["slip"]


def test_equal_static_and_kinetic_no_chatter():
    r = block(law=laws.Coulomb(static=0.5, kinetic=0.5)).simulate(5.0 + 100 * 2 * math.pi)
    assert len(r.events) <= 2 * 100 + 4           # at most a zero-length stick per period
    assert r.v.min() >= -1e-12
    assert r.energy.closure < 1e-12


def test_zero_load_is_frictionless():
    r = block(normal_load=0.0).simulate(50.0)
    assert r.events == ()
    exact = V * r.t - V / OMEGA * np.sin(OMEGA * r.t)
    np.testing.assert_allclose(r.x, exact, atol=1e-12)


def test_event_cap_is_a_clear_error():
    with pytest.raises(SimulationLimitError, match="max_events"):
        block().simulate(1e4, max_events=10)


@pytest.mark.parametrize("kw, match", [
    (dict(mass=-1.0), "mass"), (dict(stiffness=0.0), "stiffness"), (dict(damping=-1.0), "damping"),
    (dict(drive_velocity=float("nan")), "drive_velocity"), (dict(drive="rope"), "drive"),
    (dict(normal_load=-2.0), "normal_load"), (dict(drive="fixed"), "drive_velocity"),
])
def test_bad_block_parameters(kw, match):
    with pytest.raises(ValueError, match=match):
        block(**kw)


def test_bad_law_and_run_parameters():
    with pytest.raises(ValueError, match="static"):
        laws.Coulomb(static=0.4, kinetic=0.5)
    with pytest.raises(ValueError, match="duration"):
        block().simulate(0.0)
    with pytest.raises(ValueError, match="samples_per_segment"):
        block().simulate(1.0, samples_per_segment=1)


# ---------------------------------------------------------------- freeze velocity
# the energy-partition scene's calibrated film: overdamped (B = 97 > 2 sqrt(K M) = 89)
OVERDAMPED = dict(mass=20.0, stiffness=100.0, drive_velocity=0.02, damping=0.0)


def test_an_overdamped_slip_never_rests_without_a_freeze_velocity():
    r = SpringBlock(**OVERDAMPED, law=laws.Coulomb(97.3, 0.0, viscous=97.0)).simulate(500.0)
    assert len(r.cycles()) == 0
    # it relaxes to steady sliding at V: the spring force tends to B V
    assert r.spring_force[-1] == pytest.approx(97.0 * 0.02, rel=1e-3)


def test_freeze_velocity_re_sticks_at_that_speed_and_the_ledger_closes():
    vf = 0.2
    r = SpringBlock(**OVERDAMPED, law=laws.Coulomb(97.3, 0.0, viscous=97.0,
                                                 freeze_velocity=vf)).simulate(500.0)
    table = r.cycles()
    assert len(table) >= 9
    assert r.energy.closure < 1e-12
    # every slip ends on the freeze: just before each stick the block moves at vf
    for e in (e for e in r.events if e.kind == "stick"):
        i = np.searchsorted(r.t, e.time)
        assert r.v[i - 1] == pytest.approx(vf, rel=0.05)
    # the re-stick force is below B vf: the block still decelerates when it freezes
    assert 0.0 < table.backward_force[-1] < 97.0 * vf
    with pytest.raises(ValueError, match="closed form only"):
        SpringBlock(**OVERDAMPED, law=laws.Coulomb(97.3, 0.0, 97.0, freeze_velocity=vf)
                    ).simulate(100.0, method="ode")
    with pytest.raises(ValueError, match="freeze_velocity"):
        laws.Coulomb(1.0, 0.5, freeze_velocity=-1.0)


def test_calibration_recovers_the_freeze_velocity_from_the_restick_force():
    from filmfriction.reduced_model.integrators.closed_form import freeze_velocity_for

    law = laws.Coulomb(97.3, 0.0, viscous=97.0, freeze_velocity=0.2)
    fb = SpringBlock(**OVERDAMPED, law=law).simulate(500.0).cycles().backward_force[-1]
    block = SpringBlock(**OVERDAMPED, law=laws.Coulomb(97.3, 0.0, viscous=97.0))
    assert freeze_velocity_for(block, 97.3, fb) == pytest.approx(0.2, rel=1e-6)
    with pytest.raises(ValueError, match="outside what a freeze velocity"):
        freeze_velocity_for(block, 97.3, 200.0)


def test_an_elastic_film_creeps_while_stuck_and_the_ledger_closes():
    k, kf, v = 100.0, 233.0, 0.02
    law = laws.Coulomb(98.0, 60.0, viscous=11.0, shear_stiffness=kf)
    r = SpringBlock(mass=500.0, stiffness=k, drive_velocity=v, damping=150.0,
                    law=law).simulate(600.0)
    assert r.energy.closure < 1e-12
    table = r.cycles()
    # the held force rises at K k_f/(K + k_f) V, and the block creeps at K V/(K + k_f)
    k_eff = k * kf / (k + kf)
    sticks = [e.time for e in r.events if e.kind == "stick"]
    slips = [e.time for e in r.events if e.kind == "slip"]
    for t0, t1 in zip(sticks, [t for t in slips if t > sticks[0]]):
        inside = (r.t > t0) & (r.t < t1)
        assert inside.any() and np.allclose(r.v[inside], k * v / (k + kf), rtol=1e-9)
    # stick i runs from re-stick i to yield i+1
    rise = np.asarray(table.static_force[1:]) - np.asarray(table.backward_force[:-1])
    stick = np.asarray(table.stick_duration[:-1])
    assert np.allclose(stick, rise / (k_eff * v), rtol=1e-6)
    rigid = SpringBlock(mass=500.0, stiffness=k, drive_velocity=v, damping=150.0,
                        law=laws.Coulomb(98.0, 60.0, viscous=11.0)).simulate(600.0).cycles()
    assert np.mean(table.period[1:-1]) > 1.3 * np.mean(rigid.period[1:-1])
    with pytest.raises(ValueError, match="shear_stiffness"):
        laws.Coulomb(1.0, 0.5, shear_stiffness=0.0)
    with pytest.raises(ValueError, match="closed form only|solved in closed"):
        SpringBlock(1.0, 1.0, 0.1, law=law).simulate(10.0, method="ode")
