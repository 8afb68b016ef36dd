"""The slip law's bulk film damping η_bulk·A/D takes η_bulk at the film's own state point.

A Coulomb block's trace, given a film temperature and a gap: at kT 0.71 the
Klein-similar film's η (3.55), at kT 0.63 the colder films' (4.25), at a temperature where
no bulk viscosity was measured the 0.71 one with a note saying so.
"""
import numpy as np
import pytest

from filmfriction.analysis.analyze import analyze
from filmfriction.analysis.groundtruth.slip_law_controls import control_trace
from filmfriction.reduced_model.units import LJ_BULK_VISCOSITIES, lj_bulk_viscosity

AREA, GAP = 30.8, 4.7


@pytest.fixture(scope="module")
def columns():
    tr = control_trace("coulomb", 4)        # the Klein-similar scale: K 2, M 30, V 0.1
    return tr | {"gap": np.full(tr["time"].size, GAP)}


def section(columns, temperature):
    cols = columns | {"film_temperature": np.full(columns["time"].size, temperature)}
    doc = analyze(cols, structure=False, mass=30.0, spring_constant=2.0, drive_velocity=0.1,
                  area=AREA).document
    assert doc["slips"]["count"] >= 4
    return doc["slip_law"]


@pytest.mark.parametrize("temperature, eta", [(0.71, 3.55), (0.725, 3.55), (0.64, 4.25)])
def test_the_film_s_state_point_picks_its_bulk_viscosity(columns, temperature, eta):
    law = section(columns, temperature)
    assert law["bulk_viscosity"]["mean"] == pytest.approx(eta)
    assert "note" not in law["bulk_viscosity"]
    assert law["bulk_film_damping"]["mean"] == pytest.approx(eta * AREA / GAP, rel=1e-9)
    assert law["damping_over_bulk"] == pytest.approx(law["damping"]["mean"]
                                                     / (eta * AREA / GAP), rel=1e-9)
    at = lj_bulk_viscosity(temperature)
    assert law["bulk_viscosity"]["command"] == at.command


def test_an_unmeasured_state_point_says_so(columns):
    law = section(columns, 1.0)
    assert law["bulk_viscosity"]["mean"] == pytest.approx(3.55)
    assert "no bulk viscosity measured at the film's mean temperature 1" in (
        law["bulk_viscosity"]["note"])


def test_the_table_s_state_points_are_apart():
    temps = sorted(b.temperature for b in LJ_BULK_VISCOSITIES)
    # nearest-within-tolerance is unambiguous only if no two points share a window
    assert min(np.diff(temps)) > 2 * 0.03
    assert all(0 < b.stderr < 0.15 * b.viscosity for b in LJ_BULK_VISCOSITIES)
