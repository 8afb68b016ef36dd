"""Similarity numbers: Klein's from his printed parameters (worked by hand), and the rows."""
import math

import pytest

from filmfriction.reduced_model import sfb_check
from filmfriction.reduced_model.sfb.similarity import (NUMBERS, SlidingContact, klein_contact,
                                                       klein_ranges, similarity_numbers,
                                                       similarity_rows)


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


def test_klein_dispute_numbers_by_hand():
    # eta_eff/eta_bulk = 27/2.5e-3 (A and D cancel); a bulk film's B = A eta_bulk/D
    n = similarity_numbers(klein_contact())
    assert n["bingham_number"].value == pytest.approx(27 / 2.5e-3)                   # 1.08e4
    root = math.sqrt(97 * 1.47e-3)
    assert n["bulk_film_damping_ratio"].value == pytest.approx(
        4e-10 * 2.5e-3 / 3.5e-9 / (2 * root))                                          # 3.8e-4
    assert n["slip_heating"].value == pytest.approx(0.6 / 295)                        # 2.0e-3
    # dx0/tau_s over sqrt(kT/m) of one OMCTS molecule (296.62 g/mol) at 295 K
    x0 = 1e-14 / (97 * 1e-9)
    dx0 = x0 - math.sqrt(x0 ** 2 - 2 * 4e-13 / 97)
    thermal = math.sqrt(1.380649e-23 * 295 / (296.62e-3 / 6.02214076e23))           # 90.9 m/s
    assert n["slip_velocity_over_thermal"].value == pytest.approx(dx0 / 25e-3 / thermal)  # 2.4e-8
    assert n["contact_width_over_sigma"].value == pytest.approx(2e-5 / 0.82e-9)       # 2.4e4
    assert n["backward_over_static"].value == pytest.approx(1 - dx0 / x0)             # 0.47


def test_klein_numbers_he_did_not_print_carry_their_range():
    r = klein_ranges()
    # dE_f = 0.9 or 1.1e-14 J: dx0/x0 from 0.795 to 0.401 (the 0.40-0.79)
    for e, want in ((0.9e-14, 0.795), (1.1e-14, 0.401)):
        x0 = e / (97 * 1e-9)
        dx0 = x0 - math.sqrt(x0 ** 2 - 2 * 4e-13 / 97)
        assert dx0 / x0 == pytest.approx(want, abs=1e-3)
    assert r["slip_over_extension"] == pytest.approx((0.401, 0.795), abs=1e-3)
    assert r["backward_over_static"] == pytest.approx((1 - 0.795, 1 - 0.401), abs=1e-3)
    # from printed numbers alone: no range
    for name in ("bingham_number", "bulk_film_damping_ratio", "film_damping_ratio",
                 "viscous_fraction", "mount_damping_ratio"):
        assert r[name] is None, name
    rows = {row["name"]: row for row in similarity_rows(SlidingContact(
        spring_constant=2.0, mass=30.0, drive_velocity=0.02, static_force=48.0,
        restick_force=22.0, film_damping=60.0, bulk_damping=55.0))}
    assert rows["bingham_number"]["klein_source"] == "printed"
    assert rows["slip_over_extension"]["klein_source"] == "derived"
    assert rows["slip_over_extension"]["klein_range"] == pytest.approx([0.401, 0.795], abs=1e-3)
    assert rows["bingham_number"]["model"] == pytest.approx(60 / 55)
    assert "derived" in rows["slip_over_extension"]["note"]


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
