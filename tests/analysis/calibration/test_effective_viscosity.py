"""One effective viscosity per run: the primary is named with its reason, the others are
cross-checks that say what they rest on, unphysical per-slip values are flagged, and the
calibration's friction law is set beside the slip law's."""
import json
import math

import jsonschema
import pytest

from filmfriction.analysis.calibration.effective_viscosity import choose
from filmfriction.analysis.calibration.estimators import Estimate
from filmfriction.analysis.files.util import json_schema

U = "ετ/σ³"


def analysis(regime="stick-slip", slips=None, slip_law=None, steady=None, unphysical=None):
    visc = {}
    if slips is not None:
        visc["from_slip"] = {"eta_eff": {"mean": slips[0], "stderr": slips[1], "units": U}}
        if unphysical:
            visc["from_slip"]["unphysical"] = {"slips": unphysical, "note": "negative"}
    if steady is not None:
        visc["steady"] = {"eta_eff": {"mean": steady[0], "stderr": steady[1], "units": U},
                          "thickness": {"mean": 3.0, "units": "σ"}}
    doc = {"regime": regime, "viscosity": visc}
    if slip_law is not None:
        fk, b, verdict = slip_law
        doc["slip_law"] = {"kinetic_force": {"mean": fk[0], "stderr": fk[1], "units": "ε/σ"},
                           "damping": {"mean": b[0], "stderr": b[1], "units": "m/τ"},
                           "eta_from_damping": {"mean": b[0] * 3.0 / 60.0,
                                                "stderr": b[1] * 3.0 / 60.0, "units": U},
                           "verdict": verdict, "reason": "its numbers"}
    return doc


def fit(fk, b):
    """The calibration's (F_k, B): (value, stderr) or None for at the bound 0."""
    def est(x, units):
        if x is None:
            return Estimate(0.0, math.nan, units, "", at_bound=True)
        return Estimate(x[0], x[1], units, "")
    return {"kinetic_force": est(fk, "ε/σ"), "film_damping": est(b, "m/τ"),
            "thickness": 3.0, "area": 60.0}


def test_a_smooth_run_takes_the_steady_viscosity_less_the_mount():
    c = choose(analysis("smooth", steady=(5.0, 0.5)), mount_damping=10.0, area=60.0)
    assert c.status == "resolved" and c.estimator == "steady"
    assert c.primary.value == pytest.approx(5.0 - 10.0 * 3.0 / 60.0)


def test_a_resolved_damping_makes_the_calibration_primary_and_the_rest_cross_checks():
    doc = analysis(slips=(9.0, 1.0), slip_law=((1.0, 3.0), (100.0, 20.0), "viscous"))
    c = choose(doc, **fit((30.0, 2.0), (100.0, 10.0)))
    assert c.estimator == "calibration" and c.primary.value == pytest.approx(5.0)
    checks = {x.estimator: x for x in c.cross_checks}
    assert set(checks) == {"slips", "slip_law"}
    # Klein's purely viscous reading is higher: it takes the resolved F_k for viscosity
    assert "+3.6 standard errors" in checks["slips"].difference
    assert "reads the rate-independent F_k = 30 ε/σ as viscosity" in checks["slips"].difference
    assert checks["slip_law"].difference == ("+0.0 standard errors from the primary: they agree "
                                             "within their errors")
    assert "all sliding friction viscous" in checks["slips"].rests_on
    # the calibration resolves both terms, the slip law the drag only: said, with the evidence
    law = c.friction_law
    assert (law["calibration"], law["slip_law"], law["agree"]) == ("mixed", "viscous", False)
    assert "spring force" in law["calibration_rests_on"] and "wall's velocity" in law[
        "slip_law_rests_on"]
    assert "neither reading is established until they agree" in law["note"]


@pytest.mark.parametrize("b, scatter, why", [
    (None, math.nan, "at its bound 0"),
    ((15.0, 10.0), math.nan, "within 2 standard errors of 0"),
    ((100.0, 40.0), 60.0, "2.5 standard errors from 0 by the fit's error but 1.7 by the slips' "
                          "scatter"),
])
def test_an_unresolved_damping_names_no_primary_and_says_why(b, scatter, why):
    doc = analysis(slips=(4.0, 2.0), slip_law=((-10.0, 14.0), (85.0, 67.0), "kinetic"),
                   unphysical=[4])
    c = choose(doc, damping_scatter=scatter, **fit(None, b))
    assert c.status == "not resolved" and c.primary is None and c.estimator is None
    assert why in c.reason, c.reason
    assert "calibration" in {x.estimator for x in c.cross_checks}
    slips = next(x for x in c.cross_checks if x.estimator == "slips")
    assert slips.unphysical.startswith("slip 4: η_eff < 0"), slips
    # neither fit resolves a term: no contradiction, and the slip law's label is explained
    assert c.friction_law["agree"] and c.friction_law["calibration"] == "neither"
    assert "its rule for a drag it does not resolve" in c.friction_law["note"]


def test_a_negative_estimate_is_flagged_unphysical():
    c = choose(analysis(slips=(-2.0, 1.0)), **fit((30.0, 2.0), (100.0, 10.0)))
    slips = next(x for x in c.cross_checks if x.estimator == "slips")
    assert "unphysical" in slips.unphysical


def test_the_analysis_flags_slips_with_negative_viscosity(tmp_path):
    """A mount dashpot larger than the film's damping: every slip's (B - d) D/A < 0,
    flagged slip by slip in analysis.json (which still validates) and kept in the mean."""
    from filmfriction.analysis.groundtruth.synthetic import klein_trace, write_csv
    from filmfriction.workflows.cli.main import main

    d = tmp_path / "run"
    d.mkdir()
    tr = klein_trace(spring_constant=8.0, mass=500.0, damping=40.0, drive_velocity=0.01,
                     static_force=3.0, backward_force=1.0, cycles=4, dt=0.5, noise=0.01)
    write_csv(d / "trace.csv", {k: tr[k] for k in ("time", "spring_force", "drive_position")})
    (d / "run.json").write_text(json.dumps({"status": "done", "scene": {"name": "synthetic"},
        "trace_parameters": {"spring_constant": 8.0, "mass": 500.0, "area": 60.0,
                             "thickness": 3.0, "drive_velocity": 0.01, "mount_damping": 45.0,
                             "units": "lj"}}))
    assert main(["analyze", str(d)]) == 0
    doc = json.loads((d / "analysis.json").read_text())
    jsonschema.validate(doc, json_schema("analysis"))
    slip = doc["viscosity"]["from_slip"]
    n = slip["eta_eff"]["n"]
    assert slip["eta_eff"]["mean"] < 0
    assert slip["unphysical"]["slips"] == list(range(2, n + 2)), slip["unphysical"]
    assert f"{n} of {n} slips give η_eff < 0" in slip["unphysical"]["note"]


def test_the_slip_law_is_read_by_its_own_significance():
    # 7 slips: F_k = 60.8 ± 24.4 is 2.5 standard errors by value/stderr but 1.99 by the
    # slip law's own test (the few slips' t distribution): the law says "neither term
    # resolved", and the friction-law row must read it so, not as a kinetic part
    doc = analysis(slips=(8.4, 3.3), slip_law=((60.8, 24.4), (-34.7, 122.7), "inconclusive"))
    doc["slip_law"]["verdict_from"] = "decelerating"
    doc["slip_law"]["branches"] = {"decelerating": {
        "kinetic_force": {"mean": 60.8, "stderr": 24.4, "units": "ε/σ", "sigmas": 1.99},
        "damping": {"mean": -34.7, "stderr": 122.7, "units": "m/τ", "sigmas": -0.27}}}
    c = choose(doc, **fit((32.6, 24.0), None))
    assert c.friction_law["slip_law"] == "neither" and c.friction_law["agree"]
    # where the law's own test resolves F_k, the row says so
    doc["slip_law"]["branches"]["decelerating"]["kinetic_force"]["sigmas"] = 2.6
    assert choose(doc, **fit((32.6, 24.0), None)).friction_law["slip_law"] == "kinetic"
    # without the law's significance (an older analysis.json) value/stderr decides
    del doc["slip_law"]["branches"]
    assert choose(doc, **fit((32.6, 24.0), None)).friction_law["slip_law"] == "kinetic"
