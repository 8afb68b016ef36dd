"""One MD energy ledger (analysis/energy/ledger.py): the runner's check uses it."""
import numpy as np
import pytest

from filmfriction.analysis.energy import ledger
from filmfriction.md_inputs import contract
from filmfriction.workflows.md.output import sanity
from filmfriction.workflows.md.scene import load


def _dat(leak: float, mount: float = 2.0) -> np.ndarray:
    """trace.dat rows of a slide that takes 10 epsilon of drive work; the thermostat
    takes what the mount dashpot does not, less ``leak`` (energy created from nothing)."""
    n = 11
    s = np.linspace(0.0, 1.0, n)
    cols = {name: np.zeros(n) for name in contract.DAT_COLUMNS}
    cols["step"] = np.arange(n) * 50.0
    cols["film_temperature"] = np.full(n, 0.7)
    cols["drive_work"] = 10.0 * s
    cols["potential_energy"] = -100.0 + 0.5 * s
    cols["kinetic_energy"] = 20.0 + 0.25 * s
    cols["spring_energy"] = 0.25 * s
    cols["mount_heat"] = mount * s
    cols["thermostat_heat"] = (9.0 - mount - leak) * s
    return np.column_stack([cols[name] for name in contract.DAT_COLUMNS])


def _columns(dat):
    return {name: dat[:, i] for i, name in enumerate(contract.DAT_COLUMNS)}


def test_the_ledger_counts_every_sink():
    led = ledger.ledger(_columns(_dat(0.0)))
    assert led["residual"] == pytest.approx(np.zeros(11), abs=1e-12)
    assert led["input"] == pytest.approx(10.0)
    assert led["mount_heat"] == pytest.approx(2.0)
    assert led["thermostat_heat"] == pytest.approx(7.0)
    assert led["turnover"] == pytest.approx(10.0)
    leaky = ledger.ledger(_columns(_dat(1.0)))
    assert leaky["residual"][-1] == pytest.approx(1.0)
    assert leaky["closure"] == pytest.approx(0.1)
    # the turnover is heat out when more heat leaves than work comes in
    assert ledger.ledger(_columns(_dat(-5.0)))["turnover"] == pytest.approx(14.0)


def test_the_runner_fails_a_run_whose_ledger_does_not_close():
    scene = load("stick-slip")
    assert sanity.ledger_problem(_dat(0.0), scene) is None
    assert sanity.ledger_problem(_dat(0.4), scene) is None          # 4 %: within the limit
    msg = sanity.ledger_problem(_dat(0.6), scene)                   # 6 %
    assert msg.startswith("energy ledger does not close: residual 0.6 epsilon is 6 % of "
                          "the energy turned over (10 epsilon; limit 5 %)")
    assert sanity.trace_problem(_dat(0.6), scene) == msg


def test_the_runner_has_no_ledger_of_its_own(monkeypatch):
    # the runner's verdict is the analysis ledger's numbers: change them, and it follows
    real = ledger.ledger

    def inflated(columns):
        out = real(columns)
        return {**out, "residual": out["residual"] * 20.0}

    scene = load("stick-slip")
    monkeypatch.setattr(ledger, "ledger", inflated)
    assert sanity.ledger_problem(_dat(0.1), scene).startswith(
        "energy ledger does not close: residual 2 epsilon")


def test_a_released_spring_counts_as_energy_turned_over():
    # a wall let go from a stretched spring: 200 epsilon of spring energy become the film's
    # kinetic and potential energy before the thermostat has taken any heat out; a residual
    # of 0.2 epsilon is 0.1 % of what was turned over, not 8 % of the heat
    dat = _dat(0.0)
    cols = _columns(dat)
    s = np.linspace(0.0, 1.0, 11)
    cols["drive_work"] = np.zeros(11)
    cols["spring_energy"] = 200.0 * (1.0 - s)
    cols["kinetic_energy"] = 20.0 + 150.0 * s
    cols["potential_energy"] = -100.0 + 47.3 * s
    cols["mount_heat"] = np.zeros(11)
    cols["thermostat_heat"] = 2.5 * s
    led = ledger.ledger(cols)
    assert led["residual"][-1] == pytest.approx(0.2)
    assert led["turnover"] == pytest.approx(200.0)
