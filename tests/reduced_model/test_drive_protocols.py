"""Drive protocols (piecewise spring-end velocity), exact output times (t_eval), theta/psi."""
import math

import numpy as np
import pytest

from filmfriction.reduced_model import DriveSchedule, SpringBlock, laws

RS = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-5, v0=1e-6)


def test_schedule_shape_and_refusals():
    s = DriveSchedule.slide_hold_slide(velocity=2.0, slide=1.0, hold=3.0, reslide=1.0)
    assert s.duration == 5.0 and s.velocities == (2.0, 0.0, 2.0)
    np.testing.assert_allclose(s.position([0.0, 1.0, 2.5, 4.0, 5.0]), [0.0, 2.0, 2.0, 2.0, 4.0])
    with pytest.raises(ValueError, match="durations"):
        DriveSchedule((1.0, -1.0), (0.1, 0.1))
    with pytest.raises(ValueError, match="velocit"):
        DriveSchedule((1.0,), (0.1, 0.2))
    block = SpringBlock(1.0, 1.0, 0.1, law=laws.Coulomb(1.0, 0.5))
    with pytest.raises(ValueError, match="duration"):
        block.simulate(3.0, drive=[(1.0, 0.1)])
    with pytest.raises(ValueError, match="t_eval"):
        block.simulate(3.0, t_eval=[4.0])
    with pytest.raises(ValueError, match="drive='spring'"):
        SpringBlock(1.0, 1.0, 0.1, drive="belt", law=laws.Coulomb(1.0, 0.5)).simulate(drive=[(1.0, 0.1)])


def test_coulomb_hold_delays_breakaway_exactly():
    # closed form: the first stick lasts Fs/(K V) of *driving*; a hold of 20 inside it adds 20
    block = SpringBlock(1.0, 1.0, 0.1, law=laws.Coulomb(1.0, 0.5))
    sched = DriveSchedule.pieces([(5.0, 0.1), (20.0, 0.0), (100.0, 0.1)])
    r = block.simulate(drive=sched)
    assert r.events[0].kind == "slip"
    assert r.events[0].time == pytest.approx(30.0, abs=1e-12)
    # x and the spring end are continuous; the spring end follows the schedule
    np.testing.assert_allclose(r.drive_position, sched.position(r.t), rtol=0, atol=1e-12)
    assert np.all(np.diff(r.t) >= 0) and r.t[-1] == 125.0
    assert np.max(np.abs(np.diff(r.x))) < 0.2
    assert r.energy.closure < 1e-10
    # after the hold the run is the plain run shifted by 20 in time
    plain = block.simulate(105.0)
    shifted = np.array([e.time for e in plain.events]) + 20.0
    np.testing.assert_allclose([e.time for e in r.events], shifted, rtol=0, atol=1e-9)


def test_t_eval_samples_are_exact():
    block = SpringBlock(1.0, 1.0, 0.1, law=laws.Coulomb(1.0, 0.5))
    times = [3.3, 17.0, 41.25]
    r = block.simulate(50.0, t_eval=times)
    np.testing.assert_array_equal(r.t[r.eval_index], times)
    for tk, i in zip(times, r.eval_index):
        alone = block.simulate(tk)
        assert r.x[i] == pytest.approx(alone.x[-1], abs=1e-12)
        assert r.v[i] == pytest.approx(alone.v[-1], abs=1e-12)
    # rate-and-state: theta at t_eval equals the end of a run that stops there
    rs = SpringBlock(1.0, 1.0, 0.1, law=laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1))
    r = rs.simulate(30.0, t_eval=[7.5, 22.0], initial_velocity=0.05)
    for tk, i in zip([7.5, 22.0], r.eval_index):
        alone = rs.simulate(tk, initial_velocity=0.05)
        assert r.t[i] == tk
        assert r.theta[i] == pytest.approx(alone.theta[-1], rel=1e-7)
        assert r.psi[i] == pytest.approx(alone.psi[-1], abs=1e-8)


def test_theta_and_psi():
    r = SpringBlock(0.0, 1e4, 1e-6, law=RS).simulate(50.0)
    np.testing.assert_allclose(r.theta, RS.dc / RS.v0 * np.exp(r.psi), rtol=1e-14)
    # steady sliding at V: theta = dc / V (closed form)
    np.testing.assert_allclose(r.theta, RS.dc / 1e-6, rtol=1e-9)
    with pytest.raises(AttributeError, match="theta"):
        _ = SpringBlock(1.0, 1.0, 0.1, law=laws.Coulomb(1.0, 0.5)).simulate(5.0).theta


@pytest.mark.parametrize("mass", [0.0, 1e-6])
def test_velocity_step_reaches_the_new_steady_state(mass):
    # closed form of the steady state: mu_ss(V) = mu0 + (a - b) ln(V / v0), theta_ss = dc / V
    V1, V2 = 1e-6, 1e-5
    r = SpringBlock(mass, 1e4, V1, law=RS).simulate(
        drive=DriveSchedule.velocity_step(V1, 50.0, V2, 50.0), t_eval=[50.0])
    assert r.success
    i = r.eval_index[0]
    assert r.spring_force[i] == pytest.approx(RS.mu0 + (RS.a - RS.b) * math.log(V1 / RS.v0), abs=1e-9)
    assert r.spring_force[-1] == pytest.approx(RS.mu0 + (RS.a - RS.b) * math.log(V2 / RS.v0), abs=1e-6)
    assert r.theta[-1] == pytest.approx(RS.dc / V2, rel=1e-4)
    # the direct effect: the friction jumps up by ~ a ln(V2/V1) before it decays
    assert r.spring_force[i:].max() - r.spring_force[i] > 0.5 * RS.a * math.log(V2 / V1)
    assert r.energy.closure < 1e-8


def healing(mass, hold, K=1e5):
    V = 1e-6
    theta_ss = RS.dc / V
    s = DriveSchedule.slide_hold_slide(V, 20 * theta_ss, hold, 20 * theta_ss)
    r = SpringBlock(mass, K, V, law=RS).simulate(drive=s, t_eval=[20 * theta_ss, 20 * theta_ss + hold])
    assert r.success and r.energy.closure < 1e-8
    i0, i1 = r.eval_index
    return r.spring_force[i1:].max() - r.spring_force[i0], r.theta[i1]


def test_slide_hold_slide_dieterich_ageing():
    # Dieterich ageing: for long holds the peak on re-sliding exceeds steady friction by
    # delta mu ~ b ln(t_hold / theta_ss), and theta grows ~ t_hold during the hold
    theta_ss = RS.dc / 1e-6
    holds = np.array([100.0, 1000.0, 10000.0])
    got = np.array([healing(0.0, h) for h in holds])
    dmu, theta_end = got[:, 0], got[:, 1]
    np.testing.assert_allclose(dmu, RS.b * np.log(holds / theta_ss), rtol=0, atol=0.15 * RS.b)
    slope = np.polyfit(np.log(holds), dmu, 1)[0]
    assert slope == pytest.approx(RS.b, rel=0.05)
    assert np.all(theta_end > 0.8 * holds) and np.all(theta_end < holds + theta_ss)
    # the inertial block (light) heals the same way
    assert healing(1e-6, 1000.0)[0] == pytest.approx(dmu[1], abs=1e-6)
