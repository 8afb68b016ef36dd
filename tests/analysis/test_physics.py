"""Energy partition and effective viscosity on traces with known answers."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from filmfriction.analysis.energy.ledger import ledger, LEDGER_COLUMNS
from filmfriction.analysis.energy.partition import energy_table
from filmfriction.analysis.groundtruth.synthetic import klein_trace
from filmfriction.analysis.viscosity import (power_law_fit, profile_shear, slip_force,
                                slip_viscosity, steady_viscosity)

KLEIN = dict(spring_constant=97.0, mass=1.47e-3, damping=3.09,
             drive_velocity=100e-9, static_force=9.7e-6, backward_force=3.0e-6)


@pytest.mark.parametrize("v", [0.0, 100e-9])
@pytest.mark.parametrize("damping", [3.09, 0.3])   # over- and under-damped
def test_slip_force_closed_form_matches_ode(v, damping):
    k, m, fs = 97.0, 1.47e-3, 9.7e-6
    t = np.linspace(0, 0.05, 400)
    sol = solve_ivp(lambda tt, s: [s[1], (k * (fs / k + v * tt - s[0]) - damping * s[1]) / m],
                    (0, 0.05), [0, 0], t_eval=t, rtol=1e-11, atol=1e-18)
    expected = k * (fs / k + v * t - sol.y[0])
    np.testing.assert_allclose(slip_force(t, fs, damping, m, k, v), expected,
                               atol=1e-6 * fs)


def test_klein_eq2_fixed_spring_end():
    k, m, b, fs = 97.0, 1.47e-3, 3.09, 9.7e-6
    x0 = fs / k
    t = np.linspace(0, 0.03, 50)
    tau0, w = 2 * m / b, np.sqrt(1 - 4 * m * k / b ** 2)
    x = x0 * (1 - np.exp(-t / tau0) * (np.cosh(w * t / tau0) + np.sinh(w * t / tau0) / w))
    np.testing.assert_allclose(slip_force(t, fs, b, m, k), k * (x0 - x), rtol=1e-9,
                               atol=1e-12 * fs)


@pytest.mark.parametrize("seed", [0, 1])
def test_klein_slips_recover_damping_within_2_percent(slip_table, seed):
    tr = klein_trace(**KLEIN, cycles=4, noise=0.005 * KLEIN["static_force"], seed=seed)
    tab, _ = slip_table(tr, KLEIN["spring_constant"])
    assert len(tab) == 4
    area, d = 4e-10, 3.5e-9
    sv = slip_viscosity(tr["time"], tr["spring_force"], tab, mass=KLEIN["mass"],
                        spring_constant=KLEIN["spring_constant"], area=area,
                        thickness=d, drive_velocity=KLEIN["drive_velocity"])
    assert np.nanmean(sv.damping) == pytest.approx(KLEIN["damping"], rel=0.02)
    assert sv.eta_eff == pytest.approx(KLEIN["damping"] * d / area, rel=0.02)
    assert 0 < sv.eta_eff_stderr < 0.02 * sv.eta_eff


def test_heavy_wall_md_like_slips(slip_table):
    p = dict(spring_constant=8.0, mass=500.0, damping=40.0, drive_velocity=0.01,
             static_force=3.0, backward_force=1.0)
    tr = klein_trace(**p, cycles=4, dt=0.1, noise=0.01, seed=3)
    tab, _ = slip_table(tr, 8.0)
    sv = slip_viscosity(tr["time"], tr["spring_force"], tab, mass=500.0,
                        spring_constant=8.0, area=1.0, thickness=1.0,
                        drive_velocity=0.01)
    assert np.nanmean(sv.damping) == pytest.approx(40.0, rel=0.02)


def test_energy_partition_klein_trace(slip_table):
    ring = 2e-7
    tr = klein_trace(**KLEIN, cycles=4, noise=0.002 * KLEIN["static_force"], ringing=ring)
    k = KLEIN["spring_constant"]
    tab, ev = slip_table(tr, k)
    # the synthetic trace rings in its force only (the wall's motion has no ringing):
    # Klein's amplitude estimate is the one to check here
    et = energy_table(tr["time"], tr["spring_force"], tab, k, mass=KLEIN["mass"],
                      wall_velocity=tr["wall_velocity"],
                      drive_position=tr["drive_position"], noise=ev.noise,
                      ringing="force-amplitude")
    assert et.ringing_method == "force-amplitude"
    fs, dx0 = tab.static_force, tab.slip_distance
    np.testing.assert_allclose(et.spring_released, k * (fs / k - dx0 / 2) * dx0)
    # the wall's equation of motion: everything the spring delivers goes to the film
    np.testing.assert_allclose(et.film_dissipation,
                               et.spring_released_exact + et.drive_work_slip, rtol=0.01)
    # ringing energy ≈ A²/(2K), A the largest excursion of the injected
    # ringing (45 Hz, 20 ms decay); noise biases the peak upward a little
    tt = np.linspace(0, 0.05, 5001)
    a = ring * np.max(np.exp(-tt / 0.02) * np.abs(np.sin(2 * np.pi * 45 * tt)))
    assert np.all(et.ringing_energy > 0.9 * a ** 2 / (2 * k))
    assert np.all(et.ringing_energy < 1.4 * a ** 2 / (2 * k))
    np.testing.assert_allclose(et.viscous_fraction + et.at_stick_fraction, 1.0)
    assert np.all(et.viscous_fraction > 0.99)
    # Klein's numbers: ΔE_spring of order 4e-13 J
    assert 1e-13 < np.mean(et.spring_released) < 1e-12


def test_energy_without_wall_kinematics_uses_eq1(slip_table):
    tr = klein_trace(**KLEIN, cycles=3)
    tab, ev = slip_table(tr, KLEIN["spring_constant"])
    et = energy_table(tr["time"], tr["spring_force"], tab, KLEIN["spring_constant"])
    assert et.film_dissipation_method == "klein-eq1"
    np.testing.assert_allclose(et.film_dissipation, et.spring_released_exact)
    assert np.all(et.ringing_energy < 1e-9 * et.spring_released)


def test_ledger_closure_detects_missing_energy():
    t = np.linspace(0, 10, 101)
    cols = {c: np.zeros_like(t) for c in LEDGER_COLUMNS}
    cols["drive_work"] = 2.0 * t
    cols["spring_energy"] = 0.5 * t
    cols["thermostat_heat"] = 1.5 * t
    assert ledger(cols)["closure"] == pytest.approx(0.0, abs=1e-12)
    cols["thermostat_heat"] = 1.4 * t        # 0.1 t unaccounted of 2 t
    assert ledger(cols)["closure"] == pytest.approx(0.05)


def test_steady_viscosity():
    rng = np.random.default_rng(0)
    f = 2.0 + rng.normal(0, 0.1, 10000)
    sv = steady_viscosity(f, area=4.0, velocity=0.5, thickness=np.full(10, 2.0))
    assert sv.shear_rate == pytest.approx(0.25)
    assert sv.eta_eff == pytest.approx(2.0, rel=0.01)
    assert sv.eta_eff_stderr == pytest.approx(0.1 / 100 / 4 / 0.25, rel=0.5)


def test_profile_shear_with_wall_slip():
    z = np.linspace(0, 5, 51)
    rho = np.where((z > 1) & (z < 4), 1.0, 0.0)
    vx = 0.1 + 0.2 * (z - 1)                 # film from 0.1 to 0.7
    ps = profile_shear(z, vx, rho, wall_velocity_top=1.0)
    assert ps.shear_rate == pytest.approx(0.2)
    assert ps.slip_bottom == pytest.approx(0.1 + 0.2 * (ps.z_bottom - 1))
    assert ps.slip_top == pytest.approx(1.0 - (0.1 + 0.2 * (ps.z_top - 1)))


def test_power_law_exponent_with_uncertainty():
    rng = np.random.default_rng(1)
    g = np.geomspace(1e-4, 1e-1, 12)
    eta = 3.0 * g ** (-2 / 3) * np.exp(rng.normal(0, 0.05, g.size))
    fit = power_law_fit(g, eta, eta_stderr=0.05 * eta)
    assert abs(fit.exponent + 2 / 3) < 3 * fit.exponent_stderr
    assert 0.005 < fit.exponent_stderr < 0.05
    with pytest.raises(ValueError, match=">= 3"):
        power_law_fit(g[:2], eta[:2])
