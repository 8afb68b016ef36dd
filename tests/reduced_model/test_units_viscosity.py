"""The viscosity-matched OMCTS time unit: algebra and round trips."""
import math

import numpy as np
import pytest
from scipy import constants

from filmfriction.reduced_model import units as U
from filmfriction.reduced_model.units import OMCTS, QUANTITIES


@pytest.mark.parametrize("eta_lj", [0.5, 3.0, 3.3])
def test_time_unit_maps_eta_onto_the_target(eta_lj):
    tau = U.viscosity_time_unit(eta_lj)
    # independent arithmetic: sigma = 0.82 nm, eps = 290.25/0.69 K
    sigma, eps = 0.82e-9, 290.25 / 0.69 * constants.k
    assert tau == pytest.approx(2.5e-3 * sigma**3 / (eta_lj * eps), rel=1e-12)
    # and back: eta* eps tau / sigma^3 is 2.5 mPa s
    assert eta_lj * eps * tau / sigma**3 == pytest.approx(2.5e-3, rel=1e-12)


def test_matched_units_round_trip():
    eta_lj = 3.1
    m = U.viscosity_matched(eta_lj)
    assert m.sigma == OMCTS.sigma and m.epsilon == OMCTS.epsilon
    assert m.tau == pytest.approx(U.viscosity_time_unit(eta_lj), rel=1e-12)
    assert m.to_si(eta_lj, "viscosity") == pytest.approx(U.OMCTS_BULK_VISCOSITY, rel=1e-12)
    assert m.from_si(U.OMCTS_BULK_VISCOSITY, "viscosity") == pytest.approx(eta_lj, rel=1e-12)
    # what only sigma and epsilon set is unchanged
    for q in ("length", "energy", "force", "stress", "spring_constant", "temperature"):
        assert m.scale(q) == pytest.approx(OMCTS.scale(q), rel=1e-12)
    # every quantity still round-trips, and times scale by tau_eta / tau
    ratio = m.tau / OMCTS.tau
    for q in QUANTITIES:
        assert m.from_si(m.to_si(1.7, q), q) == pytest.approx(1.7, rel=1e-12)
    assert m.to_si(1.0, "time") == pytest.approx(OMCTS.to_si(1.0, "time") * ratio, rel=1e-12)
    assert m.to_si(1.0, "velocity") == pytest.approx(OMCTS.velocity / ratio, rel=1e-12)
    assert m.to_si(1.0, "viscosity") == pytest.approx(OMCTS.viscosity * ratio, rel=1e-12)
    assert "viscosity-matched" in m.name and "3.1" in m.source


def test_other_targets_and_units():
    base = U.LJUnits.from_molecule(sigma_nm=0.875, epsilon_over_kB=450.0, molar_mass_g=296.62)
    m = U.viscosity_matched(2.0, eta_si=1e-3, units=base, name="water-ish")
    assert m.name == "water-ish"
    assert m.to_si(2.0, "viscosity") == pytest.approx(1e-3, rel=1e-12)
    assert np.allclose(m.to_si(np.array([1.0, 2.0]), "viscosity"), [0.5e-3, 1e-3])


@pytest.mark.parametrize("bad", [0.0, -3.0, math.nan, math.inf, "3"])
def test_bad_viscosities_raise(bad):
    with pytest.raises(ValueError, match="eta_lj"):
        U.viscosity_time_unit(bad)
    with pytest.raises(ValueError, match="eta_si"):
        U.viscosity_time_unit(3.0, eta_si=bad)


def test_the_film_state_point_mapping():
    m = U.OMCTS_VISCOSITY_MATCHED
    assert m.to_si(U.LJ_ETA_FILM, "viscosity") == pytest.approx(2.5e-3, rel=1e-12)
    assert m.tau == pytest.approx(U.viscosity_time_unit(U.LJ_ETA_FILM), rel=1e-12)
    # tau_eta ~ 67 ps, ~9 times the mapping's sigma sqrt(m/eps) ~ 7.6 ps
    assert m.tau == pytest.approx(66.9e-12, rel=0.01)
    assert OMCTS.tau == pytest.approx(7.55e-12, rel=0.01)
    # with the usual tau the LJ liquid is ~0.28 mPa s, ~9 times less viscous than OMCTS
    assert OMCTS.to_si(U.LJ_ETA_FILM, "viscosity") == pytest.approx(0.28e-3, rel=0.02)
    assert 0 < U.LJ_ETA_FILM_STDERR < 0.1 * U.LJ_ETA_FILM
