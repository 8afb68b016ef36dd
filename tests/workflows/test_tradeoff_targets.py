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


def _study(d, rows, status="target_not_met", finished=True):
    """A side's study directory: study.json with one segment per row."""
    d.mkdir(parents=True)
    record = {**_record(rows, tt.OBSERVABLES), "status": status,
              "elapsed": rows[-1][1] if rows else None}
    if finished:
        record["finished"] = "2026-01-01T00:00:00+00:00"
    (d / "study.json").write_text(tt.json.dumps(record))


_ROWS = [(100, 30.0, [(0.08, 12), (0.2, 12), (0.4, 12)]),
         (200, 61.0, [(0.045, 20), (0.09, 20), (0.3, 20)])]


def test_an_interrupted_study_keeps_what_it_measured(tmp_path, monkeypatch):
    calls = []

    def fake_run(args):
        out = tt.Path(args[args.index("--out") + 1])
        calls.append(out)
        if len(calls) == 3:                       # pair 2's first side: interrupted
            raise KeyboardInterrupt
        _study(out, _ROWS)
        return 40.0 + len(calls), 1.5

    monkeypatch.setattr(tt, "_run", fake_run)
    monkeypatch.setattr(tt, "cpu_snapshot", lambda: (None, 0.0))
    with pytest.raises(KeyboardInterrupt):
        tt.run_targets(tmp_path / "t", scenes=("stick-slip",), pairs=2, presets=(),
                       log=lambda m: None)
    doc = tt.json.loads((tmp_path / "t" / "targets.json").read_text())
    assert doc["complete"] is False and "pair 2 of 2" in doc["missing"]
    pair = doc["scenes"]["stick-slip"]["pairs"][0]
    assert (pair["replicas"]["wall"], pair["ranks"]["wall"]) == (41.0, 42.0)
    assert pair["replicas"]["other_cpu_seconds"] == 1.5
    fs = doc["scenes"]["stick-slip"]["summary"]["static_force"]
    assert fs["0.1"]["replicas"]["seconds"]["median"] == 30.0
    assert fs["0.05"]["ranks"]["seconds"]["median"] == 61.0 and fs["0.03"]["ranks"]["reached"] == 0
    assert (tmp_path / "t" / "targets.md").read_text().startswith(
        "# Wall time to a target error")
    assert "INCOMPLETE: the study stopped before stick-slip: pair 2 of 2" in \
        (tmp_path / "t" / "targets.md").read_text()


def test_collect_rebuilds_the_tables_from_the_finished_runs(tmp_path):
    out = tmp_path / "t"
    for k, side in [(1, "replicas"), (1, "ranks"), (2, "replicas")]:
        _study(out / "sfb-similar" / f"pair-{k}" / side, _ROWS)
    _study(out / "sfb-similar" / "pair-2" / "ranks", _ROWS[:1], finished=False)
    (out / "sfb-similar" / "preset-reference").mkdir()
    (out / "sfb-similar" / "preset-reference" / "run.json").write_text('{"status": "running"}')
    doc = tt.collect_targets(out, presets=("standard", "reference"))
    entry = doc["scenes"]["sfb-similar"]
    assert len(entry["pairs"]) == 1 and entry["pairs"][0]["ranks"]["wall"] == 61.0
    assert doc["complete"] is False
    assert "pair-2 1 replica × 2 ranks" in doc["missing"]
    assert "preset reference (running)" in doc["missing"]
    std = entry["presets"]["standard"]
    assert std["seconds"] == 30.0 and std["errors"]["static_force"]["meets"] == 0.1
    text = tt.markdown(doc)
    assert "not known" in text and "INCOMPLETE" in text


def test_measurements_beside_other_work_are_named():
    side = {"wall": 100.0, "other_cpu_seconds": 10.0, "to_target": {}}
    idle = {"wall": 100.0, "other_cpu_seconds": 1.0, "to_target": {}}
    doc = {"cpus": 2, "scenes": {"s": {"pairs": [{"replicas": side, "ranks": idle}],
                                       "presets": {"preview": {"seconds": 50.0,
                                                               "other_cpu_seconds": 20.0}}}}}
    assert tt._busy_measurements(doc) == ["s pair 1 2 replicas × 1 rank 5 %", "s preset preview 20 %"]


def test_presets_and_collect_refuse_bad_input(tmp_path, run_cli):
    r = run_cli("tradeoff", "--targets", "--presets", "preview,best", "--out", tmp_path / "t")
    assert r.code == 2 and "best is no preset" in r.err, r.err
    r = run_cli("tradeoff", "--targets", "--collect", tmp_path)
    assert r.code == 2 and "not a tradeoff --targets directory" in r.err, r.err
