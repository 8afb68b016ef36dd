"""The SFB check against Klein's numbers (seed 004), its CLI and its MD path."""
import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from filmfriction.reduced_model.sfb import klein, check as sfb
from filmfriction.reduced_model.sfb.klein import KLEIN
from filmfriction.reduced_model.sfb.md_calibration import MDCalibration
from filmfriction.reduced_model.sfb.check import ROW_KEYS, SOURCES
from filmfriction.reduced_model.units import OMCTS, LJUnits
from filmfriction.workflows.cli import main as cli

K, M, A, D = KLEIN.spring_constant, KLEIN.mass, KLEIN.contact_area, KLEIN.film_thickness


@pytest.fixture(scope="module")
def check():
    return sfb.sfb_check()


def rows_by_name(rows, source="sfb-parameters"):
    return {r["name"]: r for r in rows if r["source"] == source}


# -- Klein's parameters -----------------------------------------------------------
def test_slip_time_reproduces_klein_within_20_percent(check):
    row = check.row("slip_time")
    assert row["klein"] == pytest.approx(25e-3)
    assert abs(row["model"] / 25e-3 - 1.0) < 0.20, row
    # the ±1σ damping interval brackets the model value
    lo, hi = row["uncertainty"]
    assert lo < row["model"] < hi


def test_viscous_energy_equals_spring_energy_within_5_percent(check):
    rows = rows_by_name(check.rows)
    spring = rows["spring_energy_released"]["model"]
    viscous = rows["viscous_energy"]["model"]
    assert viscous == pytest.approx(spring, rel=0.05)
    assert viscous == pytest.approx(KLEIN.spring_energy_released, rel=0.05)
    assert rows["viscous_fraction"]["model"] >= KLEIN.viscous_fraction    # Klein: "90 % or more"


def test_energy_ledger_of_the_slip(check):
    for run in check.slips.values():
        assert run.ledger_closure < 1e-8, run.label
        # spring energy released = viscous heat + kinetic energy left at s
        total = run.viscous_energy + run.kinetic_energy_at_stick
        assert total == pytest.approx(run.spring_energy_released, rel=1e-6), run.label


def test_model_slip_matches_klein_closed_form(check):
    assert check.closed_form_deviation < 1e-8
    assert check.ode_deviation < 1e-6


@pytest.mark.parametrize("eta", [27.0, 2.5e-3, 0.3])   # over-, under-damped, near critical
def test_closed_form_against_direct_integration(eta):
    B = klein.newtonian_damping(A, eta, D)
    x0 = 100e-9

    def rhs(t, y):
        return [y[1], (K * (x0 - y[0]) - B * y[1]) / M]

    t = np.linspace(0.0, 0.05, 400)
    sol = solve_ivp(rhs, (0, 0.05), [0.0, 0.0], t_eval=t, rtol=1e-11, atol=1e-20, method="DOP853")
    np.testing.assert_allclose(klein.klein_closed_form(t, x0, M, K, B), sol.y[0], atol=1e-7 * x0)


def test_slip_geometry_from_klein_statements():
    geo = klein.klein_slip_geometry()
    assert geo.x0 == pytest.approx(1e-14 / (97 * 1e-9))
    assert K * (geo.x0 - geo.slip_distance / 2) * geo.slip_distance == pytest.approx(4e-13, rel=1e-12)
    assert 0 < geo.slip_distance < geo.x0
    full = klein.klein_slip_geometry(assumption="full-relaxation")
    assert full.x0 == full.slip_distance == pytest.approx(math.sqrt(2 * 4e-13 / 97))
    with pytest.raises(ValueError):
        klein.klein_slip_geometry(assumption="guess")
    with pytest.raises(ValueError):      # dE_f too small to store dE_spring
        klein.klein_slip_geometry(klein.KleinExperiment(film_energy=5e-15))


def test_bulk_viscosity_cannot_give_kleins_slip(check):
    rows = rows_by_name(check.rows)
    # Klein's point: with the bulk viscosity the slip is inertial, far faster than observed,
    # and overshoots to ~2 x0
    assert rows["inertial_slip_time"]["model"] < 0.3 * KLEIN.slip_time
    assert rows["inertial_peak_slip"]["model"] == pytest.approx(2 * check.geometry.x0, rel=0.02)
    assert rows["inertial_residual_kinetic_energy"]["ratio"] > 10


def test_ringing_and_temperature_rows(check):
    rows = rows_by_name(check.rows)
    assert rows["ringing_energy"]["model"] == pytest.approx(0.5 * 15e-3 * (2 * 12e-9 * 45) ** 2)
    assert 0.5 < rows["ringing_energy"]["ratio"] < 2            # Klein: "~1e-14 J"
    heat = rows["viscous_energy"]["model"] / (956.0 * 1490.0 * A * D)
    assert rows["temperature_rise"]["model"] == pytest.approx(heat)
    assert rows["temperature_rise"]["klein"] == 0.6


def test_alternative_full_relaxation_reading_is_reported(check):
    rows = rows_by_name(check.rows)
    t63 = rows["slip_time_full_relaxation_63"]["model"]
    assert t63 == pytest.approx(KLEIN.damping / K, rel=0.05)     # ~ B/K for an overdamped slip
    assert rows["slip_time_full_relaxation_95"]["model"] > 2.5 * t63


def test_braun_tosatti_note_is_in_the_notes(check):
    assert check.notes[-1] == klein.BRAUN_TOSATTI_NOTE
    assert "Braun" in klein.BRAUN_TOSATTI_NOTE and "normal" in klein.BRAUN_TOSATTI_NOTE


def test_rows_schema_and_ratios(check):
    for r in check.rows:
        assert tuple(r) == ROW_KEYS
        assert r["source"] in SOURCES
        if r["klein"] and r["model"] is not None:
            assert r["ratio"] == pytest.approx(r["model"] / r["klein"])
        else:
            assert r["ratio"] is None
    required = {"slip_time", "spring_energy_released", "viscous_energy", "viscous_fraction",
                "ringing_energy", "temperature_rise"}
    assert required <= {r["name"] for r in check.rows}


# -- the MD path --------------------------------------------------------------------
def klein_as_md(units=OMCTS, **extra):
    """Klein's own film written as an MD calibration in LJ units."""
    geo = klein.klein_slip_geometry()
    return MDCalibration(
        yield_stress=units.from_si(K * geo.x0 / A, "stress"),
        restick_stress=units.from_si(geo.restick_force(K) / A, "stress"),
        eta_zero=units.from_si(KLEIN.eta_eff, "viscosity"), **extra)


def test_md_path_with_kleins_film_reproduces_part_one(check):
    md = sfb.sfb_check(klein_as_md(yield_stress_err=1e-6))
    part1 = rows_by_name(md.rows)
    part2 = rows_by_name(md.rows, "md-calibrated")
    for name in ("slip_time", "viscous_energy", "spring_energy_released", "temperature_rise"):
        assert part2[name]["model"] == pytest.approx(part1[name]["model"], rel=1e-6), name
    assert part2["eta_eff"]["model"] == pytest.approx(KLEIN.eta_eff, rel=1e-9)
    assert part2["yield_stress"]["ratio"] == pytest.approx(1.0, rel=1e-9)


def test_md_rows_use_the_units_module():
    cal = MDCalibration(yield_stress=0.5, restick_stress=0.25, eta_zero=50.0)
    for units in (OMCTS, LJUnits.from_molecule(sigma_nm=0.875)):
        rows = rows_by_name(sfb.sfb_table(cal, units=units), "md-calibrated")
        assert rows["yield_stress"]["model"] == pytest.approx(0.5 * units.stress)
        assert rows["static_force"]["model"] == pytest.approx(0.5 * units.stress * A)
        assert rows["eta_eff"]["model"] == pytest.approx(50.0 * units.viscosity, rel=1e-6)


def test_md_shear_thinning_carried_to_sfb_rate():
    cal = MDCalibration(yield_stress=0.05, restick_stress=0.02, eta_zero=2e6, thinning_exponent=0.5,
                        onset_rate=1e-10, eta_zero_err=2e5, thinning_exponent_err=0.05,
                        shear_rate_range=(1e-4, 1e-1))
    check = sfb.sfb_check(cal)
    rows = rows_by_name(check.rows, "md-calibrated")
    geo = check.geometry
    rate_lj = OMCTS.from_si(geo.slip_distance / KLEIN.slip_time / D, "shear_rate")
    expected = OMCTS.to_si(cal.eta(rate_lj), "viscosity")
    assert rows["eta_eff"]["model"] == pytest.approx(expected, rel=1e-9)
    assert expected < OMCTS.to_si(cal.eta_zero, "viscosity")         # thinned below the plateau
    lo, hi = rows["eta_eff"]["uncertainty"]
    assert lo < expected < hi
    assert rows["eta_eff_power_law"]["model"] > 0
    run = check.slips["md"]
    assert math.isfinite(run.slip_time) and run.slip_time > 0
    assert run.spring_force[0] == pytest.approx(OMCTS.to_si(0.05, "stress") * A, rel=1e-6)


def test_md_calibration_validation():
    with pytest.raises(ValueError):
        MDCalibration(yield_stress=0.5, eta_zero=1.0, restick_stress=0.6)
    with pytest.raises(ValueError):
        MDCalibration(yield_stress=0.5, eta_zero=1.0, thinning_exponent=1.0)
    with pytest.raises(ValueError):
        MDCalibration(yield_stress=-1.0, eta_zero=1.0)
    with pytest.raises(ValueError, match="unknown calibration field"):
        MDCalibration.from_dict({"yield_stress": 0.5, "eta_zero": 1.0, "viscosity": 3})
    with pytest.raises(ValueError, match="missing"):
        MDCalibration.from_dict({"yield_stress": 0.5})


# -- the CLI ---------------------------------------------------------------------------
def test_cli_json_schema(capsys):
    assert cli.main(["sfb", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert isinstance(rows, list) and rows
    for r in rows:
        assert set(ROW_KEYS) == set(r)
        assert isinstance(r["name"], str) and isinstance(r["units"], str)
        assert r["source"] == "sfb-parameters"
        for key in ("klein", "model", "ratio"):
            assert r[key] is None or isinstance(r[key], float)
    names = [r["name"] for r in rows]
    assert len(names) == len(set(names))
    assert "slip_time" in names


def test_cli_table_is_human_readable(capsys):
    assert cli.main(["sfb"]) == 0
    out = capsys.readouterr().out
    assert "slip_time" in out and "ratio" in out and "Braun & Tosatti" in out


def test_cli_with_calibration_file(tmp_path, capsys):
    path = tmp_path / "cal.json"
    path.write_text(json.dumps({"yield_stress": 0.5, "restick_stress": 0.25, "eta_zero": 50.0,
                                "yield_stress_err": 0.05, "source": "test"}))
    assert cli.main(["sfb", "--json", "--calibration", str(path)]) == 0
    rows = json.loads(capsys.readouterr().out)
    md = rows_by_name(rows, "md-calibrated")
    assert md["yield_stress"]["model"] == pytest.approx(0.5 * OMCTS.stress)
    assert md["yield_stress"]["uncertainty"][0] < md["yield_stress"]["model"]
    # the unit mapping can be overridden from the command line
    assert cli.main(["sfb", "--json", "--calibration", str(path), "--sigma-nm", "0.875"]) == 0
    md2 = rows_by_name(json.loads(capsys.readouterr().out), "md-calibrated")
    assert md2["yield_stress"]["model"] == pytest.approx(md["yield_stress"]["model"] * (0.82 / 0.875) ** 3)


def test_cli_reads_a_calibration_json_and_writes_what_the_report_reads(tmp_path, capsys):
    from filmfriction.workflows.rundir import read_sfb

    md = {"yield_stress": 0.5, "restick_stress": 0.25, "eta_zero": 50.0}
    cal = tmp_path / "calibration.json"
    cal.write_text(json.dumps({"schema": "filmfriction.calibration/1", "md_calibration": md}))
    out = tmp_path / "sfb.json"
    assert cli.main(["sfb", "--json", "--calibration", str(cal), "--out", str(out)]) == 0
    rows = json.loads(capsys.readouterr().out)
    doc = read_sfb(out)
    assert doc.rows == rows
    assert doc.calibration == MDCalibration.from_dict(md).as_dict()
    assert doc.notes[-1] == klein.BRAUN_TOSATTI_NOTE
    assert doc.row("slip_time", "md-calibrated")["model"] == rows_by_name(rows, "md-calibrated")["slip_time"]["model"]
    run = doc.slips["klein"]
    assert run.t[0] == 0.0 and run.t[-1] <= 2 * run.slip_time and run.x.size == run.t.size
    # a calibration.json whose calibration failed has nothing for the SFB check
    cal.write_text(json.dumps({"schema": "filmfriction.calibration/1", "md_calibration": None,
                               "failures": {"md_calibration": "no slips"}}))
    assert cli.main(["sfb", "--calibration", str(cal)]) == 2
    assert "no slips" in capsys.readouterr().err


@pytest.mark.parametrize("content, message", [
    (None, "does not exist"),
    ("{not json", "cannot read"),
    ('{"yield_stress": 0.5, "eta_zero": 1.0, "bogus": 1}', "unknown calibration field"),
    ('{"yield_stress": 0.5, "eta_zero": 1.0, "restick_stress": 0.9}', "restick_stress"),
])
def test_cli_bad_calibration_is_a_user_error(tmp_path, capsys, content, message):
    path = tmp_path / "cal.json"
    if content is not None:
        path.write_text(content)
    assert cli.main(["sfb", "--calibration", str(path)]) == 2
    assert message in capsys.readouterr().err


def test_md_sliding_stress_with_thinning_film():
    # a rate-independent sliding stress plus a thinning film: the slip oscillates about
    # x0 - F_k/K (here underdamped: it stops at v = 0 past it) and the ledger still closes
    cal = MDCalibration(yield_stress=0.05, sliding_stress=0.02, eta_zero=2e6, thinning_exponent=0.5,
                        onset_rate=1e-10)
    run = sfb.sfb_check(cal).slips["md"]
    assert run.ledger_closure < 1e-6
    f_k = OMCTS.to_si(0.02, "stress") * A
    final = run.x0 - f_k / K
    assert final < run.slip_distance < 2 * final
    assert "stick" in run.end_rule
    assert run.viscous_energy + run.kinetic_energy_at_stick == pytest.approx(
        run.spring_energy_released, rel=1e-3)
