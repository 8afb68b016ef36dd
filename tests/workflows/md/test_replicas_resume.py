"""Resume, locks and sanity checks of a study of replicas, per replica and for the whole
(workflows/md/replicas/replica_study.py, afresh.py, workflows/sweep/replica_jobs.py),
without LAMMPS.

The replicas' run directories are built as runs leave them (``interrupted_run``: restart
files of LAMMPS's markers, recorded as finished); who runs a segment's replicas is replaced
by a fake that records what it was asked and leaves each replica completed.  The same
study on real LAMMPS, interrupted before the first restart file and resumed:
test_replicas_md.py.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from filmfriction.workflows.md import restarts, runner
from filmfriction.workflows.md.locks import RunLock
from filmfriction.workflows.md.replicas import afresh, replica_study
from filmfriction.workflows.md.replicas.replica_study import (_lock, ensemble_markdown,
                                                               replica_dir, resume_study)
from filmfriction.workflows.md.run_record import scene_toml
from filmfriction.workflows.md.scene import SceneError, load

SLIDE = 8000
SEEDS = [4928459, 123457]


def _stuck(run_dir: Path, interrupted_run, status: str = "interrupted") -> Path:
    """A run directory its run left before LAMMPS wrote the first restart file."""
    interrupted_run(run_dir)
    for _, path in restarts.restart_files(run_dir):
        path.unlink()
    (run_dir / restarts.LEDGER).unlink()
    record = json.loads((run_dir / "run.json").read_text())
    (run_dir / "run.json").write_text(json.dumps({**record, "status": status}))
    return run_dir


def _completed(run_dir: Path, seed: int, slide: int = SLIDE, status: str = "completed",
               warnings=()) -> None:
    run_dir.mkdir(exist_ok=True)
    scene = load("stick-slip", {"seed": seed, "slide_steps": slide})
    (run_dir / "run.json").write_text(json.dumps({
        "schema": "filmfriction.run/1", "status": status, "scene": scene.as_dict(),
        "np": 1, "warnings": list(warnings)}))


@pytest.fixture
def study(tmp_path):
    """An interrupted study of two replicas at its first segment (no replica run yet)."""
    study = tmp_path / "study"
    study.mkdir()
    (study / "scene.toml").write_text(scene_toml(load("stick-slip", {"slide_steps": SLIDE})))
    (study / "study.json").write_text(json.dumps({
        "schema": replica_study.SCHEMA, "status": "interrupted", "scene": "stick-slip",
        "command": [], "np": 1, "lmp": None, "profile": None,
        "replicas": [{"dir": f"replica-{i + 1}", "seed": s} for i, s in enumerate(SEEDS)],
        "rule": None, "segments": [{"slide_steps": SLIDE}], "started": "then"}))
    return study


def _record(study: Path) -> dict:
    return json.loads((study / "study.json").read_text())


def _fake_jobs(monkeypatch, seen: dict, outcome=None):
    """This process's children replaced: each job's command recorded, its replica left
    completed (or as ``outcome(index, run_dir)`` leaves it: its exit code)."""
    def run_jobs(study, jobs, workers):
        codes = {}
        for i, cmd in jobs.items():
            seen[i] = {"cmd": cmd, "dir_then": replica_dir(study, i).exists()}
            if outcome is None:
                _completed(replica_dir(study, i), SEEDS[i - 1])
                codes[i] = 0
            else:
                codes[i] = outcome(i, replica_dir(study, i))
        return codes

    monkeypatch.setattr(replica_study, "_run_jobs", run_jobs)


# ---------------------------------------------------------------- what state a replica is in
@pytest.mark.parametrize("make, state", [
    (lambda d, ir: None, "start"),
    (lambda d, ir: d.mkdir(), "start"),                             # empty: removed
    (lambda d, ir: (d.mkdir(), (d / "scene.toml").write_text("x")), "restart"),  # no run.json
    (lambda d, ir: (d.mkdir(), (d / "run.json").write_text("{cut")), "restart"),
    (lambda d, ir: _stuck(d, ir), "restart"),
    (lambda d, ir: _stuck(d, ir, status="running"), "restart"),    # killed (SIGKILL, lost node)
    (lambda d, ir: ir(d), "resume"),
    (lambda d, ir: _completed(d, 1), "done"),
    (lambda d, ir: (ir(d), _completed(d, 1, slide=4000)), "resume"),   # extended from restart
    (lambda d, ir: _completed(d, 1, slide=4000), "restart"),       # shorter, nothing to extend
], ids=["none", "empty", "no run.json", "unreadable run.json", "interrupted before restart",
        "killed before restart", "interrupted", "done", "shorter with restart",
        "shorter without restart"])
def test_replica_state(tmp_path, interrupted_run, make, state):
    run_dir = tmp_path / "replica-1"
    make(run_dir, interrupted_run)
    assert afresh.replica_state(run_dir, SLIDE) == state
    assert (state == "start") == (not run_dir.exists())


def test_damaged_restarts_are_named_as_the_reason(tmp_path, interrupted_run):
    run_dir = interrupted_run(tmp_path / "replica-1")
    for _, path in restarts.restart_files(run_dir):
        path.write_bytes(b"cut short")
    assert afresh.replica_state(run_dir, SLIDE) == "restart"
    why = afresh.why_not_resumable(run_dir)
    assert why.startswith("it holds no usable restart file (restart.2000: ") and \
        "restart.4000: " in why


# ---------------------------------------------------------------- a replica with nothing to resume
def test_a_replica_stopped_before_its_first_restart_starts_again(study, interrupted_run,
                                                                 monkeypatch):
    """Replica 1 stopped before its first restart file, replica 2 can resume: the study
    resumes, replica 1 from its beginning with its seed (its directory moved intact to
    superseded/, listed in study.json), replica 2 from its restart file."""
    old = _stuck(replica_dir(study, 1), interrupted_run)
    before = {p.name: p.read_bytes() for p in old.iterdir()}
    interrupted_run(replica_dir(study, 2))
    seen = {}
    _fake_jobs(monkeypatch, seen)
    assert resume_study(study) == 0

    cmd1, cmd2 = seen[1]["cmd"], seen[2]["cmd"]
    assert not seen[1]["dir_then"], "moved aside before its run started"
    assert "--resume" not in cmd1 and f"seed={SEEDS[0]}" in cmd1
    assert cmd1[cmd1.index("--out") + 1] == str(replica_dir(study, 1))
    assert f"slide_steps={SLIDE}" in cmd1 and cmd1[cmd1.index("--np") + 1] == "1"
    assert cmd2[cmd2.index("--resume") + 1] == str(replica_dir(study, 2))

    record = _record(study)
    assert record["status"] == "completed"
    (entry,) = record["replicas"][0]["superseded"]
    assert entry["dir"].startswith("superseded/replica-1.") and entry["slide_steps"] == SLIDE
    assert "no usable restart file" in entry["why"] and entry["at"]
    aside = study / entry["dir"]
    assert {p.name: p.read_bytes() for p in aside.iterdir() if p.name != ".lock"} == \
        {k: v for k, v in before.items() if k != ".lock"}, "kept intact"
    assert "superseded" not in record["replicas"][1]
    assert [r["status"] for r in record["replicas"]] == ["completed", "completed"]


def test_the_start_again_is_the_same_for_snakemake_jobs(study, interrupted_run):
    """With a profile the driver moves the directory aside the same way before the
    segment's jobs start: the job of that replica starts it."""
    _stuck(replica_dir(study, 1), interrupted_run)
    record = _record(study)
    record["profile"] = "fake"
    (study / "study.json").write_text(json.dumps(record))
    asked = []

    def jobs(study_, record_, slide, indices, workers):
        for i in indices:
            asked.append((i, afresh.replica_state(replica_dir(study_, i), slide)))
            _completed(replica_dir(study_, i), SEEDS[i - 1])
        return {i: 0 for i in indices}

    assert resume_study(study, executor=lambda profile, ranks: jobs) == 0
    assert asked == [(1, "start"), (2, "start")]
    assert len(_record(study)["replicas"][0]["superseded"]) == 1


def test_a_replica_job_starts_again_and_the_driver_lists_it(study, interrupted_run,
                                                            monkeypatch, capsys):
    """A replica's Snakemake job (a Slurm retry after the first try was lost before its
    first restart file) finds nothing to resume: it moves the directory aside itself and
    starts the replica with its seed; the study's record lists the move."""
    from filmfriction.workflows.sweep import replica_jobs

    started = []

    def execute(scene, out, **kw):
        started.append((scene.parameters["seed"], scene.parameters["slide_steps"], out))
        _completed(out, scene.parameters["seed"])
        return out

    def resume(*args, **kw):
        raise AssertionError("nothing to resume")

    monkeypatch.setattr(runner, "execute", execute)
    monkeypatch.setattr(runner, "resume", resume)
    monkeypatch.setenv("OMP_NUM_THREADS", "1")          # run_replica sets it
    record = _record(study)
    record["profile"] = "fake"
    (study / "study.json").write_text(json.dumps(record))

    def jobs(study_, record_, slide, indices, workers):
        for i in indices:
            _stuck(replica_dir(study_, i), interrupted_run, status="running")   # first try lost
            replica_jobs.run_replica(study_, i, slide, 1)                       # the retry
        return {i: 0 for i in indices}

    assert resume_study(study, executor=lambda profile, ranks: jobs) == 0
    assert started == [(SEEDS[0], SLIDE, replica_dir(study, 1)),
                       (SEEDS[1], SLIDE, replica_dir(study, 2))]
    out = capsys.readouterr().out
    assert "# replica 1: cannot be resumed (it holds no usable restart file" in out
    assert "# replica 1: start to slide step 8000" in out
    record = _record(study)
    for i in (1, 2):
        (entry,) = record["replicas"][i - 1]["superseded"]
        assert entry["dir"].startswith(f"superseded/replica-{i}.")
        assert entry["why"] == f"moved aside by the replica's job (see replica-{i}.log)"
        assert json.loads((study / entry["dir"] / "run.json").read_text())["status"] == "running"


def test_a_replica_driven_by_another_process_is_not_moved(study, interrupted_run, monkeypatch):
    _stuck(replica_dir(study, 1), interrupted_run)
    _fake_jobs(monkeypatch, seen := {})
    with RunLock(replica_dir(study, 1)):
        with pytest.raises(SceneError, match="in use"):
            resume_study(study)
    assert (replica_dir(study, 1) / "run.json").is_file() and not (study / "superseded").exists()
    assert seen == {}
    assert _record(study)["status"] == "failed"       # and a resume carries on
    assert resume_study(study) == 0 and (study / "superseded").is_dir()


# ---------------------------------------------------------------- locks
def test_a_second_driver_of_a_study_is_refused_and_changes_nothing(study, monkeypatch):
    _fake_jobs(monkeypatch, seen := {})
    before = (study / "study.json").read_bytes()
    with _lock(study):
        with pytest.raises(SceneError, match=re.escape(f"study directory {study} is in use")):
            resume_study(study)
    assert (study / "study.json").read_bytes() == before and seen == {}


# ---------------------------------------------------------------- sanity checks per replica
def test_a_failed_replica_is_named_in_the_record(study, monkeypatch):
    def outcome(i, run_dir):
        _completed(run_dir, SEEDS[i - 1], status="completed" if i == 1 else "failed")
        if i == 2:
            (study / "replica-2.log").write_text("filmfriction run: LAMMPS: Lost atoms\n")
        return 0 if i == 1 else 1

    _fake_jobs(monkeypatch, {}, outcome)
    assert resume_study(study) == 1
    record = _record(study)
    assert record["status"] == "failed" and record["stop"]["met"] is False
    assert record["stop"]["reason"].startswith("replica 2 (replica-2) exited with code 1")
    assert "Lost atoms" in record["stop"]["reason"]
    assert [r["status"] for r in record["replicas"]] == ["completed", "failed"]


def test_a_replica_with_broken_sanity_checks_shows_in_record_and_report(study, monkeypatch):
    from filmfriction.analysis.ensemble import combine_replicas

    def outcome(i, run_dir):
        _completed(run_dir, SEEDS[i - 1], status="completed_with_warnings" if i == 2 else
                   "completed", warnings=["film temperature 1.06 vs 0.7"] if i == 2 else ())
        return 0

    _fake_jobs(monkeypatch, {}, outcome)
    assert resume_study(study) == 0
    record = _record(study)
    assert record["warnings"] == ["replica 2: film temperature 1.06 vs 0.7"]
    assert [r["status"] for r in record["replicas"]] == ["completed", "completed_with_warnings"]
    doc = {"observables": {"static_force": combine_replicas([[10.0, 10.4], [11.0, 11.3]])
                           .as_dict()}}
    text = ensemble_markdown(doc, record)
    row = next(line for line in text.splitlines() if line.startswith("| replica-2 |"))
    assert row.endswith("| completed_with_warnings |")
    assert "- replica 2: film temperature 1.06 vs 0.7" in text


# ---------------------------------------------------------------- one run
def test_a_single_run_with_nothing_to_resume_says_how_to_run_it_again(tmp_path,
                                                                      interrupted_run):
    run_dir = _stuck(tmp_path / "run", interrupted_run)
    (run_dir / "scene.toml").write_text(scene_toml(load("stick-slip", {"seed": 77})))
    before = {p.name: p.read_bytes() for p in run_dir.iterdir()}
    with pytest.raises(SceneError) as info:
        runner.resume(run_dir, progress=False)
    assert "no usable restart file" in str(info.value)
    assert f"start it again from the beginning with filmfriction run {run_dir}/scene.toml " \
           "--np 1 (the same scene, seed and ranks" in str(info.value)
    after = {p.name: p.read_bytes() for p in run_dir.iterdir()}
    assert {k: v for k, v in after.items() if k != ".lock"} == \
        {k: v for k, v in before.items() if k != ".lock"}


def test_a_replica_with_nothing_to_resume_points_to_its_study(study, interrupted_run):
    run_dir = _stuck(replica_dir(study, 1), interrupted_run)
    with pytest.raises(SceneError, match=re.escape(
            f"resume its study instead, filmfriction run --resume {study}: it starts this "
            "replica again")):
        runner.resume(run_dir, progress=False)
    assert (run_dir / "run.json").is_file() and not (study / "superseded").exists()
