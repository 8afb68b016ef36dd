"""Similarity numbers: Klein's from his printed parameters (worked by hand), and the rows."""
import math

import pytest

from filmfriction.reduced_model import sfb_check
from filmfriction.reduced_model.sfb.similarity import (NUMBERS, SlidingContact, klein_contact,
                                                       similarity_numbers, similarity_rows)


def test_klein_numbers_by_hand():
    # K = 97 N/m, M = 1.47 g, A = 4e-10 m2, D = 3.5 nm, eta = 27 Pa s, L = 42 uN,
    # dE_f = 1e-14 J with delta = 1 nm -> K x0 = 1e-5 N, x0 = 103.09 nm;
    # dE_spring = 4e-13 J -> dx0 = x0 - sqrt(x0^2 - 2 dE/K) = 54.30 nm; tau_ss = 1 s
    n = similarity_numbers(klein_contact())
    x0 = 1e-14 / (97 * 1e-9)
    dx0 = x0 - math.sqrt(x0 ** 2 - 2 * 4e-13 / 97)
    assert n["static_friction_coefficient"].value == pytest.approx(1e-5 / 42e-6)      # 0.238
    assert n["kinetic_friction_coefficient"].value == pytest.approx(
        97 * (x0 - dx0 / 2) / 42e-6)                                                    # 0.175
    assert n["extension_over_lattice"].value == pytest.approx(x0 / 0.82e-9)           # 125.7
    assert n["slip_over_extension"].value == pytest.approx(dx0 / x0)                  # 0.527
    root = math.sqrt(97 * 1.47e-3)
    assert n["film_damping_ratio"].value == pytest.approx(4e-10 * 27 / 3.5e-9 / (2 * root))  # 4.09
    assert n["film_damping_ratio"].stderr == pytest.approx(0.20 * 4.0858, rel=0.02)   # B +-20 %
    assert n["mount_damping_ratio"].value == pytest.approx(1 / (2 * math.pi * 45 * 0.08))  # 0.044
    assert n["compliance_ratio"].value == pytest.approx(1e-9 / x0)                    # 0.0097
    assert n["viscous_fraction"].value == pytest.approx(4e-13 / 4.1e-13)              # 0.976
    # V = dx0 / tau_ss: lambda = K dx0 / (2 V sqrt(KM)) = sqrt(K/M) * 1 s / 2
    assert n["lambda"].value == pytest.approx(math.sqrt(97 / 1.47e-3) / 2)            # 128.4
    assert math.isinf(n["lambda_critical"].value)                                     # zeta > 1
    eps_over_sigma3 = 290.25 / 0.69 * 1.380649e-23 / (0.82e-9) ** 3
    assert n["reduced_pressure"].value == pytest.approx(42e-6 / 4e-10 / eps_over_sigma3, rel=1e-6)


def test_coulomb_numbers_and_errors():
    c = SlidingContact(spring_constant=4.0, mass=1.0, drive_velocity=0.5, static_force=3.0,
                       restick_force=1.0, normal_load=10.0, slip_distance=0.5,
                       film_damping=0.4, film_stiffness=40.0, molecular_diameter=0.5,
                       static_force_err=0.3)
    n = similarity_numbers(c)
    assert n["lambda"].value == pytest.approx((3.0 - 2.0) / (0.5 * 2.0))
    assert n["film_damping_ratio"].value == pytest.approx(0.1)
    assert n["compliance_ratio"].value == pytest.approx(0.1)
    assert n["extension_over_lattice"].value == pytest.approx(1.5)
    # F_s's error moves mu_s by 0.03 and lambda by (0.3/2)/(0.5*2) = 0.15
    assert n["static_friction_coefficient"].stderr == pytest.approx(0.03)
    assert n["lambda"].stderr == pytest.approx(0.15)
    assert 0 < n["lambda_critical"].value < math.inf
    assert math.isnan(n["reduced_pressure"].value)            # no pressure given
    with pytest.raises(ValueError, match="mass"):
        SlidingContact(spring_constant=1.0, mass=0.0, drive_velocity=1.0, static_force=1.0,
                       restick_force=0.0)


def test_rows_in_the_sfb_check():
    md = SlidingContact(spring_constant=100.0, mass=500.0, drive_velocity=0.02, static_force=90.0,
                        restick_force=20.0, normal_load=60.0, slip_distance=0.8,
                        film_damping=-30.0, film_damping_err=80.0, film_stiffness=250.0,
                        molecular_diameter=1.0, pressure=1.0, stress_unit=1.0)
    check = sfb_check(contact=md)
    rows = [r for r in check.rows if r["source"] == "similarity"]
    assert [r["name"] for r in rows] == list(NUMBERS)
    by = {r["name"]: r for r in rows}
    assert by["static_friction_coefficient"]["ratio"] == pytest.approx(1.5 / (1e-5 / 42e-6))
    # an unresolved B (interval through zero): no ratio, and the row says why
    assert by["film_damping_ratio"]["ratio"] is None
    assert "no ratio" in by["film_damping_ratio"]["note"]
    assert similarity_rows(md) == rows
    assert not [r for r in sfb_check().rows if r["source"] == "similarity"]
