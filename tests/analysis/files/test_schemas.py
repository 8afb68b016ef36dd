"""The JSON Schemas shipped in analysis/schemas/ hold for real outputs, and reject
what they should: analysis.json of an MD-like run (LJ) and of a measured trace (SI),
sfb.json of Klein's check and of a user's set-up."""
from __future__ import annotations

import copy
import json

import jsonschema
import pytest

from filmfriction.analysis.files.trace import UNITS
from filmfriction.analysis.files.util import json_schema
from filmfriction.workflows.cli.main import main


def _validator(name):
    schema = json_schema(name)
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


@pytest.fixture(scope="module")
def lj_analysis(tmp_path_factory):
    from filmfriction.analysis.groundtruth.synthetic import run_directory

    run = run_directory(tmp_path_factory.mktemp("run") / "run")
    assert main(["analyze", str(run)]) == 0
    return json.loads((run / "analysis.json").read_text())


@pytest.fixture(scope="module")
def si_analysis(tmp_path_factory):
    from filmfriction.analysis.groundtruth.synthetic import klein_trace, write_csv

    d = tmp_path_factory.mktemp("si")
    write_csv(d / "t.csv", klein_trace(cycles=4, noise=5e-8))
    assert main(["analyze", str(d / "t.csv"), "--units", "si", "--spring-constant", "97",
                 "--mass", "1.47e-3", "--area", "4e-10", "--thickness", "3.5e-9"]) == 0
    return json.loads((d / "analysis.json").read_text())


def test_the_unit_labels_of_the_schema_are_the_readers(lj_analysis):
    schema = json_schema("analysis")["$defs"]
    assert set(schema["si_unit"]["enum"]) == set(UNITS["si"].values())
    assert set(schema["lj_unit"]["enum"]) == set(UNITS["lj"].values())


def test_analysis_json_validates(lj_analysis, si_analysis):
    v = _validator("analysis")
    for doc in (lj_analysis, si_analysis):
        errors = [e.message for e in v.iter_errors(doc)]
        assert not errors, errors
    assert "structure" in lj_analysis and "slip_law" in lj_analysis     # the optional parts too


@pytest.mark.parametrize("spoil", [
    lambda d: d.pop("slips"),
    lambda d: d.update(units="cgs"),
    lambda d: d["slips"].update(count=-1),
    lambda d: d["slips"]["static_force"].pop("units"),
    lambda d: d["slips"]["static_force"].update(mean="9.7"),
    lambda d: d["viscosity"].update(guessed={"eta_eff": {"mean": 1.0, "units": "Pa·s"}}),
    # an SI document with an LJ label, deep inside
    lambda d: d["viscosity"]["from_slip"]["eta_eff"].update(units="ετ/σ³"),
    # the slip law: a verdict outside the five, a branch missing
    lambda d: d["slip_law"].update(verdict="kinetic-ish"),
    lambda d: d["slip_law"]["branches"].pop("accelerating"),
    lambda d: d["slip_law"]["branches"]["decelerating"].update(verdict="none"),
    lambda d: d["slips"]["period"].update(units="τ"),
])
def test_analysis_schema_rejects_a_spoilt_document(si_analysis, spoil):
    doc = copy.deepcopy(si_analysis)
    spoil(doc)
    assert list(_validator("analysis").iter_errors(doc))


def test_an_lj_document_with_an_si_label_is_rejected(lj_analysis):
    doc = copy.deepcopy(lj_analysis)
    doc["slips"]["static_force"]["units"] = "N"
    assert list(_validator("analysis").iter_errors(doc))


@pytest.fixture(scope="module")
def klein_sfb(tmp_path_factory):
    out = tmp_path_factory.mktemp("sfb") / "sfb.json"
    assert main(["sfb", "--out", str(out)]) == 0
    return json.loads(out.read_text())


def test_sfb_json_validates(klein_sfb):
    errors = [e.message for e in _validator("sfb").iter_errors(klein_sfb)]
    assert not errors, errors


@pytest.mark.parametrize("spoil", [
    lambda d: d["rows"][0].pop("ratio"),
    lambda d: d["rows"][0].update(source="guess"),
    lambda d: d["rows"][0].update(uncertainty=[1.0]),
    lambda d: d.update(setup={"name": "x"}),
    lambda d: d.pop("traces"),
])
def test_sfb_schema_rejects_a_spoilt_document(klein_sfb, spoil):
    doc = copy.deepcopy(klein_sfb)
    spoil(doc)
    assert list(_validator("sfb").iter_errors(doc))


def test_an_unknown_schema_is_named():
    with pytest.raises(ValueError, match="the schemas are analysis, sfb"):
        json_schema("calibration")


def test_the_heat_check_is_in_the_schema(lj_analysis):
    # the MD-like run has a thermostat column: its film heat is checked against it
    check = lj_analysis["energy"]["heat_check"]
    assert check and set(check) <= {"slip", "cycle"}
    for spoil in (lambda c: c.update(status="pass"), lambda c: c.pop("resolution"),
                  lambda c: c["difference"].pop("units")):
        doc = copy.deepcopy(lj_analysis)
        spoil(next(iter(doc["energy"]["heat_check"].values())))
        assert list(_validator("analysis").iter_errors(doc))
