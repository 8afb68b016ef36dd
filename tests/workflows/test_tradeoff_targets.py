"""``filmfriction tradeoff --targets`` (workflows/cost/tradeoff_targets.py) without LAMMPS: the
time to each target read from a study's checks, the pairs summarized, the refusals."""
from __future__ import annotations

import math

import pytest

from filmfriction.analysis.ensemble import TargetError, check_target
from filmfriction.workflows.cost import tradeoff_targets as tt


def _check(rel, n):
    return {"met": False, "relative_error": rel, "n_slips": n, "reason": "", "estimate": {}}


def _record(rows, observables=("static_force", "eta_eff")):
    """A study record: one segment per row (slide, elapsed, [(rel, n) per observable])."""
    return {"rule": {"targets": [{"observable": o, "relative": 0.03, "min_slips": 8}
                                 for o in observables]},
            "segments": [{"slide_steps": s, "elapsed": t,
                          "checks": [_check(r, n) for r, n in checks]}
                         for s, t, checks in rows]}


def test_check_met_is_the_rules_own_test():
    rng = __import__("numpy").random.default_rng(1)
    for n in (5, 8, 20):
        for level in (0.1, 0.05, 0.03):
            values = [list(10 + rng.normal(0, 1.2, n))]
            c = check_target(values, TargetError("static_force", level))
            assert tt.check_met({"relative_error": c.relative_error, "n_slips": c.n_slips},
                                level) == c.met
    assert not tt.check_met({"relative_error": None, "n_slips": 30}, 0.1)
    assert not tt.check_met({"relative_error": math.nan, "n_slips": 30}, 0.1)


def test_time_to_each_target_is_the_first_check_meeting_it():
    record = _record([(100, 30.0, [(0.2, 6), (0.5, 6)]),       # the pilot not reached
                      (200, 55.0, [(0.08, 12), (0.2, 12)]),
                      (300, 80.0, [(0.045, 18), (0.12, 18)]),
                      (400, 99.0, [(0.031, 24), (0.09, 24)])])
    got = tt.times_to_target(record, levels=(0.1, 0.05, 0.03),
                             observables=("static_force", "eta_eff", "slip_duration"))
    fs = got["static_force"]
    assert fs["0.1"] == {"seconds": 55.0, "slide_steps": 200, "n_slips": 12,
                         "relative_error": 0.08}
    assert fs["0.05"]["seconds"] == 80.0 and fs["0.03"] is None       # 3.1 % > 3 %
    assert got["eta_eff"]["0.1"]["seconds"] == 99.0
    assert got["eta_eff"]["0.05"] is None
    # an observable the study had no target on has no time
    assert got["slip_duration"] == {"0.1": None, "0.05": None, "0.03": None}


def test_pairs_summarized_with_the_ratio_of_pairs_that_reached_both():
    def side(seconds):
        return {"to_target": {"static_force": {"0.1": None if seconds is None else
                                                 {"seconds": seconds}}}}
    pairs = [{"replicas": side(40.0), "ranks": side(60.0)},
             {"replicas": side(50.0), "ranks": side(50.0)},
             {"replicas": side(None), "ranks": side(70.0)}]
    s = tt.summarize(pairs, levels=(0.1,), observables=("static_force",))["static_force"]["0.1"]
    assert s["replicas"]["seconds"] == {"median": 45.0, "min": 40.0, "max": 50.0, "n": 2}
    assert (s["replicas"]["reached"], s["ranks"]["reached"], s["ranks"]["pairs"]) == (2, 3, 3)
    assert s["ranks"]["seconds"]["median"] == 60.0
    assert s["ratio"] == {"median": 1.25, "min": 1.0, "max": 1.5, "n": 2}


def test_the_table_says_each_time_ratio_and_preset():
    to = {"static_force": {"0.1": {"seconds": 10.0}, "0.05": None}}
    pair = {"replicas": {"to_target": to}, "ranks": {"to_target": to}}
    doc = {"elapsed": 100.0, "cpus": 2, "other_cpu_seconds": 50.0,
           "scenes": {"stick-slip": {
               "pairs": [pair],
               "summary": tt.summarize([pair], (0.1, 0.05), ("static_force",)),
               "presets": {"standard": {"slide_steps": 100000, "seconds": 20.0,
                                        "errors": {"static_force": {"relative_error": 0.041,
                                                                    "n_slips": 7,
                                                                    "meets": 0.1}}}}}}}
    text = tt.markdown(doc)
    assert "OTHER WORK RAN BESIDE IT" in text
    assert "| static_force | ± 10 % | 10 s (10–10) 1/1 | 10 s (10–10) 1/1 | 1.00 (1.00–1.00) |" \
        in text
    assert "| static_force | ± 5 % | - 0/1 | - 0/1 | - |" in text
    assert "| standard | 100000 | 20 | ± 4.1 % (7 slips) → ± 10 % |" in text


def test_side_commands_ask_the_tightest_level_of_every_observable():
    args = tt.side_command("sfb-similar", tt.SIDES[1], tt.Path("d"), budget="2h",
                           sets=("seed=3",))
    assert args[:6] == ["run", "sfb-similar", "--replicas", "1", "--np", "2"]
    assert [args[i + 1] for i, a in enumerate(args) if a == "--target"] == [
        "static_force=0.03", "slip_duration=0.03", "eta_eff=0.03"]
    assert args[args.index("--budget") + 1] == "2h" and "seed=3" in args
    assert [s.label for s in tt.SIDES] == ["2 replicas × 1 rank", "1 replica × 2 ranks"]


@pytest.mark.parametrize("args, message", [
    (["--levels", "0.1,2"], "--levels '0.1,2'"),
    (["--pairs", "0"], "--pairs 0"),
    (["--budget", "soon"], "--budget 'soon'"),
    (["--quick"], "not accepted with it"),
    (["--scene", "nosuch"], "nosuch"),
    (["--set", "restart_every=0"], "restart_every = 0"),
])
def test_targets_refuses_bad_input_before_any_run(tmp_path, run_cli, args, message):
    r = run_cli("tradeoff", "--targets", *args, "--out", tmp_path / "t")
    assert r.code == 2 and message in r.err, r.err
    assert not (tmp_path / "t").exists()


def test_a_preset_whose_key_is_set_is_not_run():
    assert tt.preset_clash("stick-slip", "preview") == []
    assert tt.preset_clash("stick-slip", "preview", ("slide_steps=20000",)) == ["slide_steps"]
    assert tt.preset_clash("stick-slip", "reference", ("cells_x=5", "seed=3")) == ["cells_x"]
    assert tt.preset_clash("stick-slip", "standard", ("slide_steps=20000",)) == []
