"""Nakano-Maegawa boundary, regime maps, Prandtl-Tomlinson transition, the map CLI."""
import math

import numpy as np
import pytest

from filmfriction.reduced_model import PrandtlTomlinson, maps


def test_critical_lambda_types_and_limits():
    assert isinstance(maps.critical_lambda(0.1), float)
    arr = maps.critical_lambda(np.array([0.01, 0.1, 1.0, 3.0]))
    assert isinstance(arr, np.ndarray) and arr.shape == (4,)
    assert np.isinf(arr[2:]).all()                       # no stick-slip for zeta >= 1
    assert maps.critical_lambda(0.0) == 0.0              # undamped: always stick-slip
    with pytest.raises(ValueError, match="zeta"):
        maps.critical_lambda(-0.1)


@pytest.mark.parametrize("zeta", [1e-6, 1e-5, 1e-4])
def test_small_zeta_asymptote(zeta):
    lam = maps.critical_lambda(zeta)
    assert lam ** 2 / (4 * math.pi * zeta) == pytest.approx(1.0, abs=10 * math.sqrt(zeta))


def test_boundary_diverges_towards_zeta_one():
    lam = maps.critical_lambda(np.array([0.5, 0.8, 0.95]))
    assert np.all(np.diff(lam) > 0) and lam[-1] > 1e3


@pytest.mark.parametrize("zeta", [0.003, 0.05, 0.3, 0.7])
def test_simulation_agrees_with_boundary(zeta):
    lam = maps.critical_lambda(zeta)
    assert not maps.coulomb_stick_slip(0.98 * lam, zeta)
    assert maps.coulomb_stick_slip(1.02 * lam, zeta)


def test_lambda_zeta_map_small_grid():
    lams, zetas = np.logspace(-1, 2, 8), np.logspace(-2, 0.5, 8)
    m = maps.lambda_zeta_map(lams, zetas, processes=2)
    assert m.stick_slip.shape == (8, 8)
    expected = lams[:, None] > maps.critical_lambda(zetas)[None, :]
    assert np.array_equal(m.stick_slip, expected)
    assert not m.stick_slip[:, zetas >= 1].any()


def test_tomlinson_quasistatic_transition():
    for eta, jumps in ((0.9, False), (0.99, False), (1.01, True), (2.0, True)):
        U0 = eta / (4 * math.pi ** 2)
        pt = PrandtlTomlinson(mass=1.0, stiffness=1.0, drive_velocity=1e-3, corrugation=U0,
                              lattice_constant=1.0, damping=2.0)
        assert pt.eta == pytest.approx(eta)
        assert (pt.quasistatic_jumps(3.0) > 0) == jumps, eta


def test_tomlinson_dynamics_slow_drive():
    def run(eta):
        pt = PrandtlTomlinson(mass=1.0, stiffness=1.0, drive_velocity=2e-3, corrugation=eta / (4 * math.pi ** 2),
                              lattice_constant=1.0, damping=2.0)
        return pt.simulate(1000.0)
    smooth, slips = run(0.5), run(3.0)
    # quasi-static smooth sliding: v <= V/(1 - eta) = 2V; stick-slip: jumps far faster than V
    assert smooth.extras["max_velocity_ratio"] < 2.5
    assert slips.extras["max_velocity_ratio"] > 50
    for r in (smooth, slips):
        assert r.energy.closure < 1e-8


def test_tomlinson_thermal_runs_and_validates():
    pt = PrandtlTomlinson(mass=1.0, stiffness=1.0, drive_velocity=1e-2, corrugation=0.05,
                          lattice_constant=1.0, damping=1.0, temperature=1e-3, seed=3)
    r = pt.simulate(200.0)
    assert np.all(np.isfinite(r.x)) and r.energy.thermal_work < 0   # the bath takes heat out
    with pytest.raises(ValueError, match="damping"):
        PrandtlTomlinson(mass=1.0, stiffness=1.0, drive_velocity=0.1, corrugation=0.1,
                         lattice_constant=1.0, damping=0.0, temperature=0.1)


def test_velocity_stiffness_map_against_perssons_velocity():
    # the default contact-age law (Fs = 1, Fb = 0.5, tau = 1) at K = 1: Persson's estimate
    # v_c ~ N (Fs - Fb)/(K tau) = 0.5; a decade either side of it the regime is clear
    m = maps.velocity_stiffness_map(np.array([1e-3, 0.05, 5.0]), np.array([1.0]), processes=1)
    assert m.boundary_x.tolist() == [pytest.approx(0.5)]
    assert m.stick_slip.tolist() == [[True, True, False]]   # stick-slip slow, smooth fast


def test_map_cli_writes_files(tmp_path, run_cli):
    r = run_cli("map", "lambda-zeta", "--out", tmp_path, "--resolution", "6")
    assert r.code == 0, r.err
    printed = r.out.split()
    assert str(tmp_path / "lambda_zeta.csv") in printed and str(tmp_path / "lambda_zeta.png") in printed
    assert (tmp_path / "lambda_zeta.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "lambda_zeta.csv").read_text().splitlines()[0] == "zeta,lambda,stick_slip"
    rows = np.loadtxt(tmp_path / "lambda_zeta.csv", delimiter=",", skiprows=1)
    assert rows.shape == (36, 3)
    zeta, lam, stick_slip = rows.T
    np.testing.assert_allclose(np.unique(zeta), np.logspace(-3, 1, 6), rtol=1e-9)
    np.testing.assert_allclose(np.unique(lam), np.logspace(-2, 2, 6), rtol=1e-9)
    # every cell is on the side of the Nakano-Maegawa boundary the module documents:
    # no stick-slip for zeta >= 1, and for small zeta the asymptote lambda^2 = 4 pi zeta
    assert not stick_slip[zeta >= 1].any()
    small = zeta == zeta.min()                                  # zeta = 1e-3: lambda_c ~ 0.11
    assert np.array_equal(stick_slip[small] == 1, lam[small] > math.sqrt(4 * math.pi * 1e-3))
    assert np.array_equal(stick_slip == 1, lam > maps.critical_lambda(zeta))
    assert 0 < stick_slip.sum() < stick_slip.size
    bad = run_cli("map", "lambda-zeta", "--out", tmp_path, "--resolution", "1")
    assert bad.code == 2 and "--resolution 1" in bad.err
