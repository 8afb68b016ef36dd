"""One's own SFB set-up in the SFB check: validation, the measured slip in Klein's place,
and the propagation of the set-up's errors."""
from __future__ import annotations

import math
import re
from dataclasses import replace

import pytest

from filmfriction.reduced_model.sfb.klein import KLEIN, klein_slip_geometry
from filmfriction.reduced_model.sfb.check import sfb_check
from filmfriction.reduced_model.sfb.user_setup import (MeasuredSlip, SFBSetup, setup_experiment,
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


# -- the words of the notes: the set-up's, not Klein's text --------------------------
#: What only Klein's printed numbers make true: x0 from his dE_f, his error bars, his ringing,
#: his contact area and slip rate.
KLEIN_ONLY = ("dE_f", "Klein's area", "Klein's contact area", "Klein's mean slip rate",
              "Klein's dx0", "Klein's errors", "Klein's v0", "Klein's K x0", "Klein:",
              "sensitivity to x0", "alternative reading", "x0 ambiguity")


def _si_calibration(setup, slip):
    """A calibrated film in SI (a measured trace's) that yields at the measured F_s."""
    from filmfriction.reduced_model.sfb.md_calibration import MDCalibration
    A = setup.contact_area
    return MDCalibration(yield_stress=slip.static_force / A,
                         restick_stress=0.3 * slip.static_force / A, eta_zero=slip.eta_eff,
                         yield_stress_err=0.05 * slip.static_force / A)


def _texts(check):
    """Every note and row note but Braun & Tosatti's reading (said of Klein on purpose)."""
    from filmfriction.reduced_model.sfb.klein import BRAUN_TOSATTI_NOTE
    return [n for n in check.notes if n != BRAUN_TOSATTI_NOTE] + [r["note"] for r in check.rows]


@pytest.fixture(scope="module")
def checks():
    """Klein's check and a named set-up's, both with an SI-calibrated film."""
    from filmfriction.reduced_model.units import SI_IDENTITY
    setup = SFBSetup.from_dict({**BASE, "mass": {"value": 1.47e-3, "error": 0.05e-3}},
                               name="rig 7")
    mine = sfb_check_setup(setup, SLIP, calibration=_si_calibration(setup, SLIP),
                           units=SI_IDENTITY)
    klein = sfb_check(_si_calibration(setup, SLIP), units=SI_IDENTITY)
    return klein, mine


@pytest.mark.parametrize("phrase", KLEIN_ONLY)
def test_kleins_readings_are_said_of_klein_only(checks, phrase):
    klein, mine = checks
    assert any(phrase in t for t in _texts(klein)), phrase          # Klein's check keeps them
    assert not [t for t in _texts(mine) if phrase in t]


def test_setup_notes_take_x0_from_the_trace_and_name_the_setup(checks):
    _, mine = checks
    x0_notes = [n for n in mine.notes if re.search(r"\bx0 = [^;]* nm\b", n)]   # x0's value
    assert len(x0_notes) == 1 and "F_s/K" in x0_notes[0] and "measured" in x0_notes[0]
    assert mine.notes[0].startswith("rig 7: ")
    # the calibrated film is carried to the set-up's contact, by its name
    md = [r["note"] for r in mine.rows if r["source"] == "md-calibrated"
          and r["name"] in ("yield_stress", "static_force", "restick_stress")]
    assert len(md) == 3 and all("rig 7" in n for n in md)
    assert any("the contact area of rig 7" in n for n in mine.notes)


def test_kleins_notes_are_his_assumptions_and_his_geometry(checks):
    """Klein's check: every assumption, his slip geometry from dE_f, the dE_f sensitivity."""
    from filmfriction.reduced_model.sfb.check import ASSUMPTIONS
    klein, _ = checks
    assert klein.notes[:len(ASSUMPTIONS)] == ASSUMPTIONS
    assert klein.notes[len(ASSUMPTIONS)] == f"slip geometry: {klein.geometry.derivation}"
    assert klein.row("slip_time")["note"].count("dE_f = ") == 2


def test_a_setup_beyond_kleins_film_energy_runs():
    """A slip storing more than Klein's dE_f could give (x0 = 1 um): the check runs on it
    (Klein's dE_f sensitivity runs are not made for a set-up)."""
    big = replace(SLIP, static_force=97.0 * 1e-6, slip_distance=6e-7)
    check = sfb_check_setup(SFBSetup.from_dict(BASE), big)
    assert check.geometry.x0 == pytest.approx(1e-6)
    assert check.row("slip_time")["model"] > 0
