"""LJ <-> SI conversions: round trips, known values, the OMCTS defaults."""
import math

import numpy as np
import pytest
from scipy import constants

from filmfriction.reduced_model import units as U
from filmfriction.reduced_model.units import OMCTS, QUANTITIES, LJUnits

# The reference notes' example: σ = 0.8 nm, ε/k_B = 450 K, m = 296.62 g/mol.
NOTES = LJUnits.from_molecule(sigma_nm=0.8, epsilon_over_kB=450.0, molar_mass_g=296.62)


@pytest.mark.parametrize("quantity", QUANTITIES)
@pytest.mark.parametrize("units", [OMCTS, NOTES], ids=["OMCTS", "notes"])
def test_round_trip_every_quantity(quantity, units):
    values = np.array([1e-3, 0.37, 1.0, 42.0])
    si = units.to_si(values, quantity)
    back = units.from_si(si, quantity)
    np.testing.assert_allclose(back, values, rtol=1e-12)
    # scalar in, float out (JSON-friendly)
    assert isinstance(units.to_si(2.0, quantity), float)
    assert units.from_si(units.to_si(2.0, quantity), quantity) == pytest.approx(2.0, rel=1e-12)


def test_required_quantities_are_present():
    required = {"length", "time", "velocity", "force", "energy", "stress", "pressure",
                "viscosity", "shear_rate", "temperature", "spring_constant", "mass",
                "area", "damping"}
    assert required <= set(QUANTITIES)


def test_unknown_quantity_lists_allowed_names():
    with pytest.raises(ValueError) as err:
        OMCTS.to_si(1.0, "viscosity_typo")
    message = str(err.value)
    assert "viscosity_typo" in message
    for name in ("viscosity", "stress", "damping"):
        assert name in message
    with pytest.raises(ValueError):
        OMCTS.from_si(1.0, "furlongs")


def test_reference_note_values():
    # Independent arithmetic, not the module's formulas.
    sigma, eps, m = 0.8e-9, 450.0 * 1.380649e-23, 296.62e-3 / 6.02214076e23
    tau = sigma * math.sqrt(m / eps)
    assert tau == pytest.approx(7.1e-12, rel=0.01)
    assert NOTES.tau == pytest.approx(tau, rel=1e-9)
    # the numbers quoted in /work/shared/reference/README.md, with their rounding
    assert NOTES.to_si(1.0, "time") == pytest.approx(7.1e-12, rel=0.01)
    assert NOTES.to_si(1.0, "velocity") == pytest.approx(112.0, rel=0.01)
    assert NOTES.to_si(1.0, "stress") == pytest.approx(12e6, rel=0.02)
    assert NOTES.to_si(1.0, "viscosity") == pytest.approx(0.086e-3, rel=0.01)
    assert NOTES.to_si(1.0, "force") == pytest.approx(7.8e-12, rel=0.01)
    assert NOTES.to_si(1.0, "temperature") == pytest.approx(450.0, rel=1e-12)


def test_derived_scales_are_consistent():
    u = OMCTS
    assert u.velocity == pytest.approx(u.sigma / u.tau)
    assert u.viscosity == pytest.approx(u.stress * u.tau)          # Pa·s = Pa × s
    assert u.damping == pytest.approx(u.force / u.velocity)        # N·s/m
    assert u.spring_constant == pytest.approx(u.force / u.sigma)
    assert u.energy == pytest.approx(u.force * u.sigma)
    assert u.shear_rate == pytest.approx(1.0 / u.time)
    assert u.area == pytest.approx(u.sigma**2)
    assert u.to_si(1.0, "mass") == pytest.approx(u.mass)
    # ε/τ is a power: force × velocity
    assert u.to_si(1.0, "power") == pytest.approx(u.force * u.velocity)
    # a Newtonian film's damping is η A / D in any consistent unit system
    eta, area, gap = 3.0, 100.0, 5.0                                # LJ
    b_si = u.to_si(eta, "viscosity") * u.to_si(area, "area") / u.to_si(gap, "length")
    assert u.to_si(eta * area / gap, "damping") == pytest.approx(b_si, rel=1e-12)


def test_omcts_defaults_and_sources():
    assert OMCTS.sigma == pytest.approx(0.82e-9)
    assert OMCTS.temperature == pytest.approx(290.25 / 0.69)
    assert 420.0 <= OMCTS.temperature <= 450.0                     # the notes' range
    assert OMCTS.molar_mass_g == pytest.approx(296.62)
    assert OMCTS.mass == pytest.approx(296.62e-3 / constants.N_A)
    # room temperature lands near the LJ liquid just above its triple point
    assert 0.66 <= OMCTS.from_si(298.15, "temperature") <= 0.72
    assert "Attard" in OMCTS.source and "triple" in OMCTS.source


def test_overridable_units_in_module_functions():
    klein_layer = LJUnits.from_molecule(sigma_nm=0.875)            # 3.5 nm / 4 layers
    assert U.to_si(1.0, "length") == pytest.approx(OMCTS.sigma)
    assert U.to_si(1.0, "length", units=klein_layer) == pytest.approx(0.875e-9)
    assert U.from_si(0.875e-9, "length", units=klein_layer) == pytest.approx(1.0)


def test_invalid_units_rejected():
    with pytest.raises(ValueError):
        LJUnits(sigma=-1.0, epsilon=1.0, mass=1.0)
    with pytest.raises(ValueError):
        LJUnits(sigma=1.0, epsilon=float("nan"), mass=1.0)


def test_units_are_frozen():
    import dataclasses

    sigma = OMCTS.sigma
    with pytest.raises(dataclasses.FrozenInstanceError):
        OMCTS.sigma = 1.0
    assert OMCTS.sigma == sigma == 0.82e-9
