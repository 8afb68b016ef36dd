"""One's own SFB set-up in the SFB check: validation, the measured slip in Klein's place,
and the propagation of the set-up's errors."""
from __future__ import annotations

import math
from dataclasses import replace

import pytest

from filmfriction.reduced_model.klein import KLEIN, klein_slip_geometry
from filmfriction.reduced_model.sfb import sfb_check
from filmfriction.reduced_model.sfb_setup import (MeasuredSlip, SFBSetup, setup_experiment,
                                                 sfb_check_setup)

BASE = {"spring_constant": 97.0, "mass": 1.47e-3, "contact_area": 4e-10,
        "film_thickness": 3.5e-9, "load": 42e-6, "drive_velocity": 1e-7}
SLIP = MeasuredSlip(static_force=9.7e-6, slip_distance=7.0e-8, slip_time=0.04,
                    cycle_time=0.73, eta_eff=27.0)


def test_radius_gives_area_and_its_error():
    data = dict(BASE)
    data.pop("contact_area")
    data["contact_radius"] = {"value": 10e-6, "error": 1e-6}
    s = SFBSetup.from_dict(data)
    assert s.contact_area == pytest.approx(math.pi * 1e-10)
    assert s.contact_area_err / s.contact_area == pytest.approx(0.2)


@pytest.mark.parametrize("change,message", [
    ({"mass": 0.0}, "mass = 0.0: must be positive"),
    ({"mass": "1 g"}, "give a number"),
    ({"load": {"value": 1e-5, "error": -1.0}}, "load error = -1.0"),
    ({"load": {"error": 1.0}}, "give a number or"),
    ({"spring_constnat": 1.0}, "unknown set-up key(s) spring_constnat"),
    ({"contact_radius": 1e-5}, "not both"),
])
def test_bad_setups_are_refused(change, message):
    with pytest.raises(ValueError) as exc:
        SFBSetup.from_dict({**BASE, **change})
    assert message in str(exc.value)


def test_missing_quantities_are_listed_with_units():
    with pytest.raises(ValueError, match=r"lacks film_thickness, load \(SI units: film_thickness "
                                         r"in m, load in N\)"):
        SFBSetup.from_dict({k: v for k, v in BASE.items() if k not in ("film_thickness", "load")})


def test_the_measured_slip_is_the_geometry_klein_reads_back():
    ex = setup_experiment(SFBSetup.from_dict(BASE), SLIP)
    geo = klein_slip_geometry(ex)
    assert geo.x0 == pytest.approx(SLIP.static_force / 97.0, rel=1e-12)
    assert geo.slip_distance == pytest.approx(SLIP.slip_distance, rel=1e-9)
    with pytest.raises(ValueError, match="exceeds the spring's extension"):
        setup_experiment(SFBSetup.from_dict(BASE), replace(SLIP, slip_distance=2e-7))


def test_klein_as_a_setup_gives_klein_rows():
    """Klein's own numbers through the set-up path give the model numbers of Klein's check."""
    geo = klein_slip_geometry(KLEIN)
    setup = SFBSetup.from_dict({**BASE, "film_thickness": KLEIN.film_thickness})
    slip = MeasuredSlip(static_force=geo.x0 * KLEIN.spring_constant,
                        slip_distance=geo.slip_distance, slip_time=KLEIN.slip_time,
                        cycle_time=KLEIN.cycle_time, eta_eff=KLEIN.eta_eff)
    mine, klein = sfb_check_setup(setup, slip), sfb_check()
    for name in ("slip_time", "viscous_energy", "residual_kinetic_energy", "temperature_rise"):
        assert mine.row(name)["model"] == pytest.approx(klein.row(name)["model"], rel=1e-9)


def test_one_error_gives_the_interval_of_that_input_moved():
    """With η_eff's error alone, the upper end of each interval is the model at η + σ
    (Klein's check computes that run itself for B + 1σ)."""
    setup = SFBSetup.from_dict(BASE)
    eta_err = 0.1 * SLIP.eta_eff
    check = sfb_check_setup(setup, replace(SLIP, eta_eff_err=eta_err))
    direct = sfb_check(experiment=replace(setup_experiment(setup, SLIP),
                                          eta_eff=SLIP.eta_eff + eta_err))
    row = check.row("slip_time")
    assert row["uncertainty"][1] == pytest.approx(direct.row("slip_time")["model"], rel=1e-9)
    # without any error: a zero-width interval, and the note says so
    exact = sfb_check_setup(setup, SLIP)
    lo, hi = exact.row("slip_time")["uncertainty"]
    assert lo == hi == exact.row("slip_time")["model"]
    assert "no input (no errors given)" in exact.notes[0]


def test_errors_add_in_quadrature():
    setup = SFBSetup.from_dict({**BASE, "spring_constant": {"value": 97.0, "error": 5.0},
                                "mass": {"value": 1.47e-3, "error": 0.1e-3}})
    half = {}
    for name in ("spring_constant", "mass"):
        only = replace(setup, **{("mass_err" if name == "spring_constant"
                                  else "spring_constant_err"): 0.0})
        lo, hi = sfb_check_setup(only, SLIP).row("slip_time")["uncertainty"]
        half[name] = (hi - lo) / 2
    lo, hi = sfb_check_setup(setup, SLIP).row("slip_time")["uncertainty"]
    assert (hi - lo) / 2 == pytest.approx(math.hypot(*half.values()), rel=1e-9)
    assert all(h > 0 for h in half.values())


def test_unmeasured_rows_have_no_measured_number():
    check = sfb_check_setup(SFBSetup.from_dict(BASE), SLIP)
    for name in ("ringing_energy", "temperature_rise", "viscous_fraction"):
        assert check.row(name)["klein"] is None and check.row(name)["ratio"] is None
    assert check.row("slip_time")["klein"] == SLIP.slip_time
