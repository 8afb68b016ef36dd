"""Replicas and a target error (workflows/md/replicas/replica_study.py, target.py): the parts without LAMMPS.

The statistics (combine_replicas, check_target) are tested on ground truth in
tests/analysis/ensemble/test_ensemble.py; the command on real LAMMPS in test_replicas_md.py.
"""
from __future__ import annotations

import copy

import numpy as np

import pytest

from filmfriction.analysis.ensemble import TargetError
from filmfriction.workflows.md.replicas.replica_study import MAX_REPLICAS, ensemble_markdown, replica_seeds
from filmfriction.workflows.md.scene import SceneError
from filmfriction.workflows.md.replicas.target import (OBSERVABLES, Budget, TargetInputError,
                                              extend_record, next_slide, parse_budget,
                                              parse_target, parse_targets)


def test_target_parsed():
    assert parse_target(" static_force = 0.03") == TargetError("static_force", 0.03)
    assert [t.observable for t in parse_targets(["static_force=0.1", "slip_duration=0.2"])] \
        == ["static_force", "slip_duration"]
    # every observable a target may name is a per-slip column of the cycle table
    assert "static_force" in OBSERVABLES and "yield_index" not in OBSERVABLES
    assert "spring_constant" not in OBSERVABLES


@pytest.mark.parametrize("text", ["static_force", "static_force=", "static_force=0",
                                  "static_force=1", "static_force=1.5", "static_force=-0.1",
                                  "static_force=nan", "static_force=inf", "force=0.1",
                                  "=0.1"])
def test_target_refused(text):
    with pytest.raises(TargetInputError, match="--target"):
        parse_target(text)


def test_budget_parsed():
    assert parse_budget("400000") == Budget(steps=400000)
    assert parse_budget("400_000") == Budget(steps=400000)
    assert parse_budget("45s") == Budget(seconds=45.0)
    assert parse_budget("1.5h") == Budget(seconds=5400.0)
    assert parse_budget("2 min") == Budget(seconds=120.0)
    assert parse_budget("1d") == Budget(seconds=86400.0)


@pytest.mark.parametrize("text", ["0", "-5", "0s", "5 parsecs", "h", "1e6", "",
                                  "3000000000", "1.5"])
def test_budget_refused(text):
    with pytest.raises(TargetInputError, match="--budget"):
        parse_budget(text)


def test_next_slide():
    # 8 % now, 5 % asked: (8/5)^2 = 2.56 times the slide would do; a third of the way
    # there (52 000 steps) in whole restart intervals of 20 000
    assert next_slide(100000, 20000, relative=0.08, target=0.05, budget_steps=None) == 160000
    # at least one restart interval, at most the first segment
    assert next_slide(100000, 20000, relative=0.051, target=0.05, budget_steps=None) == 120000
    assert next_slide(100000, 20000, relative=0.5, target=0.05, budget_steps=None) == 200000
    assert next_slide(300000, 20000, relative=0.5, target=0.05, budget_steps=None,
                      first=100000) == 400000
    # no error yet: one more first segment
    assert next_slide(100000, 20000, relative=float("nan"), target=0.05,
                      budget_steps=None) == 200000
    # never past the budget
    assert next_slide(100000, 20000, relative=0.5, target=0.05, budget_steps=130000) == 130000


def test_replica_seeds():
    seeds = replica_seeds(4928459, 20)
    assert seeds[0] == 4928459 and len(set(seeds)) == 20
    assert seeds == replica_seeds(4928459, 20)           # recorded and reproducible
    assert replica_seeds(4928459, 3) == seeds[:3]
    assert replica_seeds(17, 3) != seeds[:3]
    # LAMMPS's fix langevin (Marsaglia) refuses seeds above 900 000 000
    assert all(1 <= s <= 800_000_000 for s in replica_seeds(4928459, 200)[1:])
    assert MAX_REPLICAS >= 20


def _record(status="completed", slide=100000, restart_every=20000):
    return {"status": status, "scene": {"parameters": {"slide_steps": slide,
                                                       "restart_every": restart_every}}}


def test_extend_record():
    rec = _record()
    extend_record("d", rec, 160000)
    assert rec["scene"]["parameters"]["slide_steps"] == 160000
    assert rec["extensions"][0]["from"] == 100000 and rec["extensions"][0]["to"] == 160000
    assert rec["extensions"][0]["status_before"] == "completed"
    # an interrupted extension resumed to the same slide: nothing to change
    rec2 = _record(status="interrupted", slide=160000)
    before = copy.deepcopy(rec2)
    extend_record("d", rec2, 160000)
    assert rec2 == before


@pytest.mark.parametrize("record, steps, match", [
    (_record(), 50000, "give a longer slide"),
    (_record(), 100000, "already completed"),
    (_record(restart_every=0), 200000, "restart_every = 0"),
    (_record(), True, "give a longer slide"),
])
def test_extend_record_refused(record, steps, match):
    before = copy.deepcopy(record)
    with pytest.raises(SceneError, match=match):
        extend_record("d", record, steps)
    assert record == before


def test_ensemble_markdown_keeps_every_replica():
    from filmfriction.analysis.ensemble import combine_replicas

    est = combine_replicas([[10.0, 10.4, 9.8], [11.0, 11.3, 10.9]]).as_dict()
    doc = {"observables": {"static_force": est}}
    record = {"scene": "stick-slip", "replicas": [{"dir": "replica-1", "seed": 1},
                                                  {"dir": "replica-2", "seed": 2}],
              "stop": {"reason": "every target met"},
              "segments": [{"slide_steps": 100, "checks": [{"reason": "static_force: ok"}]}]}
    text = ensemble_markdown(doc, record)
    assert "| replica-1 | 1 | 10.07 ±" in text and "| replica-2 | 2 | 11.07 ±" in text
    assert f"| static_force | {est['mean']:.4g} | {est['half_width']:.4g} |" in text
    assert "| 100 | static_force: ok |" in text


# ---------------------------------------------------------------- the replica's own analysis
def test_the_check_reads_the_replicas_own_analysis(tmp_path, monkeypatch):
    """slip_values reads analysis_cycles.csv beside the run's analysis.json (the project's
    analysis), analyses once, and again only when the run's files changed."""
    import json

    from filmfriction.analysis import analyze as analyze_mod
    from filmfriction.analysis.files.cycles_csv import read_cycles_csv
    from filmfriction.analysis.groundtruth.synthetic import run_directory
    from filmfriction.workflows.md.replicas.target import slip_values

    run_dir = run_directory(tmp_path / "run", trajectory=False)
    calls = []
    real = analyze_mod.analyse_run
    monkeypatch.setattr(analyze_mod, "analyse_run", lambda d: calls.append(d) or real(d))

    first = slip_values(run_dir, ["static_force", "eta_eff"])
    assert len(calls) == 1 and (run_dir / "analysis.json").is_file()
    # exactly the analysis's per-slip values, the start-up slip (first row) left out
    cycles = read_cycles_csv(run_dir / "analysis_cycles.csv")
    assert first["static_force"] == [float(v) for v in cycles["static_force"][1:]]
    assert len(first["static_force"]) == len(cycles["static_force"]) - 1 >= 2
    assert np.allclose(first["static_force"], 3.0, rtol=0.05)     # the trace's Fs
    assert len(first["eta_eff"]) == len(first["static_force"])
    # current: read again, not analysed again
    stamp = (run_dir / "analysis.json").stat().st_mtime_ns
    assert slip_values(run_dir, ["static_force"]) == {"static_force": first["static_force"]}
    assert len(calls) == 1 and (run_dir / "analysis.json").stat().st_mtime_ns == stamp
    # a changed run (a slide extended: a new trace) is analysed again
    trace = (run_dir / "trace.csv").read_text().splitlines()
    (run_dir / "trace.csv").write_text("\n".join(trace[:len(trace) * 3 // 4]) + "\n")
    shorter = slip_values(run_dir, ["static_force"])["static_force"]
    assert len(calls) == 2 and len(shorter) < len(first["static_force"])
    # and a changed run.json too (its status is part of what the analysis read)
    record = json.loads((run_dir / "run.json").read_text())
    (run_dir / "run.json").write_text(json.dumps({**record, "status": "completed"}))
    slip_values(run_dir, ["static_force"])
    assert len(calls) == 3


def test_a_trace_too_short_to_analyse_has_no_slips(tmp_path):
    from filmfriction.analysis.groundtruth.synthetic import run_directory
    from filmfriction.workflows.md.replicas.target import slip_values

    run_dir = run_directory(tmp_path / "run", trajectory=False)
    lines = (run_dir / "trace.csv").read_text().splitlines()
    (run_dir / "trace.csv").write_text("\n".join(lines[:5]) + "\n")
    assert slip_values(run_dir, ["static_force", "period"]) == {"static_force": [],
                                                                "period": []}
    assert (run_dir / "analysis.json").is_file()
