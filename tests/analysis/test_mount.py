"""Damping outside the film (an MD run's mount dashpot) is not the film's."""
import numpy as np

from filmfriction.analysis import viscosity
from filmfriction.analysis.energy.ledger import ledger


def test_steady_viscosity_removes_mount_dashpot():
    eta, area, v, d, mount = 3.0, 50.0, 0.4, 2.0, 120.0
    force = eta * area * v / d + mount * v
    rng = np.random.default_rng(1)
    f = force + rng.normal(0, 0.5, 5000)
    got = viscosity.steady_viscosity(f, area, v, d, mount_damping=mount)
    assert abs(got.eta_eff - eta) < 0.01 * eta
    naive = viscosity.steady_viscosity(f, area, v, d)
    assert naive.eta_eff > 1.5 * eta  # the dashpot would otherwise count as film


def test_ledger_counts_mount_heat():
    n = 100
    work = np.linspace(0, 10, n)
    cols = {"drive_work": work, "load_work": np.zeros(n), "potential_energy": np.zeros(n),
            "kinetic_energy": np.zeros(n), "spring_energy": np.zeros(n),
            "thermostat_heat": 0.6 * work, "mount_heat": 0.4 * work}
    led = ledger(cols)
    assert abs(led["residual"][-1]) < 1e-12 and led["mount_heat"] == 4.0
    del cols["mount_heat"]
    assert abs(ledger(cols)["residual"][-1] - 4.0) < 1e-12
