"""The film's lasting change of state (analysis/film_state.py) and the analysis stopping there."""
import csv
import json

import numpy as np
import pytest

from filmfriction.analysis.film_state import GAP_LAYER_CHANGE, lasting_gap_change

LAYERS = 4
GAP = 4.7                       # four layers: five spacings of 0.94


def _gap(t, rng, steps=(), noise=0.03):
    g = GAP + noise * rng.standard_normal(t.size)
    for start, stop, layers in steps:
        g[(t >= start) & (t < stop)] += layers * GAP / (LAYERS + 1)
    return g


def test_a_melt_that_lasts_is_found_at_its_onset():
    rng = np.random.default_rng(0)
    t = np.arange(40000) * 0.25
    change = lasting_gap_change(t, _gap(t, rng, [(6000.0, np.inf, 1.0)]), LAYERS)
    assert change is not None
    assert 5990.0 <= change.time <= 6000.0 and change.layers == pytest.approx(1.0, abs=0.05)
    assert 23960 <= change.index <= 24000                    # t = 6000 is sample 24000


def test_the_change_is_the_same_in_other_units():
    # SI: seconds and metres (a layer of 0.8 nm, τ of 2 ps): the rule is of ratios only
    rng = np.random.default_rng(0)
    t = np.arange(40000) * 0.25
    g = _gap(t, rng, [(6000.0, np.inf, 1.0)])
    lj = lasting_gap_change(t, g, LAYERS)
    si = lasting_gap_change(t * 2e-12, g * 0.85e-9, LAYERS)
    assert si.index == lj.index and si.layers == pytest.approx(lj.layers)
    assert si.time == pytest.approx(lj.time * 2e-12)


@pytest.mark.parametrize("steps", [
    [],                                                        # a film that keeps its layers
    [(float(s), s + 25.0, 0.45) for s in range(500, 9500, 300)],   # a slip's dilation, each slip
    [(6000.0, 8000.0, 1.0)],                                   # a layer taken and given back
    [(9000.0, np.inf, 0.3)],                                   # a drift under half a layer
    [(9999.5, np.inf, 1.0)],                                   # the last two samples
    [(9000.0, np.inf, 0.3), (9975.0, np.inf, 0.25)],           # a drift, then a slip at the end
])
def test_no_change_where_the_film_keeps_or_regains_its_gap(steps):
    rng = np.random.default_rng(1)
    t = np.arange(40000) * 0.25
    assert lasting_gap_change(t, _gap(t, rng, steps), LAYERS) is None


def test_a_lost_layer_counts_as_well():
    rng = np.random.default_rng(2)
    t = np.arange(20000) * 0.25
    change = lasting_gap_change(t, _gap(t, rng, [(3000.0, np.inf, -2 * GAP_LAYER_CHANGE - 0.1)]),
                                LAYERS)
    assert change is not None and change.layers < -GAP_LAYER_CHANGE


def _melt_late(run):
    """The synthetic run's trace with its gap one layer wider from 70 % of its time on."""
    path = run / "trace.csv"
    rows = list(csv.DictReader(path.open()))
    t_end = float(rows[-1]["time"])
    n = json.loads((run / "run.json").read_text())["scene"]["parameters"]["film_layers"]
    gap0 = float(rows[0]["gap"])
    for r in rows:
        if float(r["time"]) >= 0.7 * t_end:
            r["gap"] = repr(float(r["gap"]) + gap0 / (n + 1))
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return 0.7 * t_end


def test_the_analysis_stops_where_the_film_changed_state(synthetic_run, run_cli, tmp_path):
    whole = run_cli("analyze", synthetic_run, "--json", "--no-figure", "--out",
                    tmp_path / "before.json")
    assert whole.code == 0, whole.err
    assert "film_state_change" not in whole.json()
    t_melt = _melt_late(synthetic_run)
    r = run_cli("analyze", synthetic_run, "--json", "--no-figure")
    assert r.code == 0, r.err
    doc = r.json()
    change = doc["film_state_change"]
    assert change["time"] == pytest.approx(t_melt, abs=0.5) and change["layers"] == pytest.approx(1.0, abs=0.1)
    assert doc["source"]["samples"] == change["index"] < change["samples_before"]
    assert "changed state" in " ".join(doc["source"]["notes"])
    cycles = list(csv.DictReader((synthetic_run / "analysis_cycles.csv").open()))
    assert cycles and all(float(c["stick_time"]) < change["time"] for c in cycles)
    from filmfriction.analysis.calibration.rundata import load_run

    assert len(load_run(synthetic_run).trace) == change["index"]   # calibration: the same samples
    doc_path = synthetic_run / "analysis.json"
    stale = json.loads(doc_path.read_text())
    stale["film_state_change"]["samples_before"] += 1           # a trace changed since
    doc_path.write_text(json.dumps(stale))
    with pytest.raises(ValueError, match="analyse it again"):
        load_run(synthetic_run)
    foreign = dict(stale, schema="someone.else/2")                # another tool's, or version
    doc_path.write_text(json.dumps(foreign))
    with pytest.raises(ValueError, match=r"schema 'someone.else/2'.*analyse it again"):
        load_run(synthetic_run)
    kept = run_cli("analyze", synthetic_run, "--json", "--no-figure", "--whole-trace",
                   "--out", tmp_path / "whole.json")
    assert kept.code == 0, kept.err
    assert "film_state_change" not in kept.json()
    assert kept.json()["slips"]["count"] >= doc["slips"]["count"]
