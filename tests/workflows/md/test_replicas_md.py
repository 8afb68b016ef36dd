"""``filmfriction run --replicas N --target OBS=REL`` on real (small) LAMMPS runs.

The small box (5 x 3 cells, ~330 atoms), 1 rank per replica, two replicas at once.
At V = 0.03 the small stick-slip film slips about once per 10 000 steps: the first
segment (30 000 steps) gives too few slips for the pilot of 8, so the rule has to
extend the slide at least once before it can stop.
"""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from filmfriction.analysis.ensemble import check_target, combine_replicas
from filmfriction.workflows.md.replicas.target import slip_values

pytestmark = pytest.mark.md

CLI = [sys.executable, "-c",
       "import sys; from filmfriction.workflows.cli.main import main; sys.exit(main())"]
SMALL = ["--set", "cells_x=5", "--set", "cells_y=3", "--set", "equilibrate_steps=2000",
         "--set", "drive_velocity=0.03", "--set", "trace_every=50"]


def _run(args, **kw):
    return subprocess.run([*CLI, "run", *args], capture_output=True, text=True,
                          timeout=900, **kw)


def test_two_replicas_stop_on_their_target(tmp_path):
    study = tmp_path / "study"
    done = _run(["stick-slip", *SMALL, "--set", "slide_steps=30000",
                 "--set", "restart_every=10000", "--replicas", "2",
                 "--target", "static_force=0.2", "--budget", "100000", "--out", str(study)])
    assert done.returncode == 0, done.stderr
    record = json.loads((study / "study.json").read_text())
    # it stopped on its own, with the target met and recorded
    assert record["status"] == "completed", record["stop"]
    assert record["stop"]["met"] is True and "every target met" in record["stop"]["reason"]
    assert record["rule"]["targets"] == [{"observable": "static_force", "relative": 0.2,
                                          "min_slips": 8}]
    segments = record["segments"]
    assert len(segments) >= 2, "the first segment cannot meet the pilot of 8 slips"
    assert all("checks" in s for s in segments)
    assert [s["checks"][0]["met"] for s in segments] == [False] * (len(segments) - 1) + [True]
    slides = [s["slide_steps"] for s in segments]
    assert slides[0] == 30000 and all(b > a for a, b in zip(slides, slides[1:]))
    assert all(s % 10000 == 0 for s in slides) and slides[-1] <= 100000
    last = segments[-1]["checks"][0]
    assert last["relative_error"] <= 0.2 and last["n_slips"] >= 8
    assert last["estimate"]["n_replicas"] == 2
    # the progress line said the error against the target
    assert "static_force ± " in done.stderr and "(target ± 20.00 %)" in done.stderr

    # each replica: its own seed (recorded), a completed run slid to the last segment,
    # one unbroken trace
    seeds = [r["seed"] for r in record["replicas"]]
    assert len(set(seeds)) == 2
    values = []
    for i, seed in enumerate(seeds, start=1):
        run_dir = study / f"replica-{i}"
        run = json.loads((run_dir / "run.json").read_text())
        assert run["status"] in ("completed", "completed_with_warnings"), run["error"]
        assert run["scene"]["parameters"]["seed"] == seed
        assert run["scene"]["parameters"]["slide_steps"] == slides[-1]
        assert [e["to"] for e in run["extensions"]] == slides[1:]
        assert run["np"] == 1
        trace = np.genfromtxt(run_dir / "trace.csv", delimiter=",", names=True)
        assert len(trace) == slides[-1] // 50 + 1
        assert np.all(np.diff(trace["step"]) == 50)
        values.append(slip_values(run_dir, ["static_force"])["static_force"])
        assert (run_dir / "analysis.json").is_file()
    # the recorded check is the one the replicas' final traces give
    again = check_target(values, record_target := _target(record))
    assert again.met and again.relative_error == pytest.approx(last["relative_error"])
    assert record_target.relative == 0.2

    # the combined analysis: between- and within-run parts, every replica's row
    ens = json.loads((study / "ensemble.json").read_text())
    fs = ens["observables"]["static_force"]
    est = combine_replicas(values)
    assert fs["mean"] == pytest.approx(est.mean) and fs["n_replicas"] == 2
    assert fs["within"] > 0 and fs["between"] is not None and len(fs["replicas"]) == 2
    report = (study / "ensemble.md").read_text()
    assert "replica-1" in report and "replica-2" in report and "between" in report


def _target(record):
    from filmfriction.analysis.ensemble import TargetError

    t = record["rule"]["targets"][0]
    return TargetError(t["observable"], t["relative"], t["min_slips"])


def _wait_for(predicate, seconds=300.0):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.5)
    return False


def _interrupted_study(study, sets, ready, what, meanwhile=lambda: None) -> str:
    """A 2-replica study of the small film with ``sets``, Ctrl-C once ``ready()`` (after
    ``meanwhile()``); its stderr (the exit status 130 asserted)."""
    proc = subprocess.Popen([*CLI, "run", "stick-slip", *SMALL, *sets, "--replicas", "2",
                             "--md-only", "--out", str(study)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        assert _wait_for(ready), what
        meanwhile()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    return err


def test_study_interrupted_locked_and_resumed(tmp_path):
    study = tmp_path / "study"

    def locked():
        # the study is locked while a command drives it
        second = _run(["--resume", str(study)])
        assert second.returncode == 2 and "in use" in second.stderr, second.stderr

    # both replicas past their first restart file, then Ctrl-C
    err = _interrupted_study(
        study, ["--set", "slide_steps=40000", "--set", "restart_every=2000"],
        lambda: all(any((study / f"replica-{i}").glob("restart.*")) for i in (1, 2)),
        "the replicas never wrote a restart", meanwhile=locked)
    assert f"filmfriction run --resume {study}" in err
    record = json.loads((study / "study.json").read_text())
    assert record["status"] == "interrupted"
    for i in (1, 2):
        run = json.loads((study / f"replica-{i}" / "run.json").read_text())
        assert run["status"] in ("interrupted", "completed"), run["status"]
    # the lock went with the process that held it
    from filmfriction.workflows.md.replicas.replica_study import _lock

    _lock(study).acquire().release()

    done = _run(["--resume", str(study), "--md-only"])
    assert done.returncode == 0, done.stderr
    record = json.loads((study / "study.json").read_text())
    assert record["status"] == "completed" and len(record["resumed"]) == 1
    for i in (1, 2):
        run = json.loads((study / f"replica-{i}" / "run.json").read_text())
        assert run["status"] in ("completed", "completed_with_warnings")
        trace = np.genfromtxt(study / f"replica-{i}" / "trace.csv", delimiter=",", names=True)
        assert len(trace) == 40000 // 50 + 1 and np.all(np.diff(trace["step"]) == 50)


def test_replicas_stopped_before_their_first_restart_start_again(tmp_path):
    """Ctrl-C while the replicas run and before any restart file (restart_every = 0: none
    ever): nothing to resume, yet the study resumes. Each replica starts again from its
    beginning with its seed, its interrupted directory moved intact to superseded/ and
    listed in study.json; the replica's run is the run its old directory's scene.toml
    gives (the same scene and seed on the same rank)."""
    study = tmp_path / "study"
    _interrupted_study(
        study, ["--set", "slide_steps=20000", "--set", "restart_every=0"],
        lambda: all((study / f"replica-{i}" / "trace.dat").is_file() for i in (1, 2)),
        "the replicas never started LAMMPS")
    record = json.loads((study / "study.json").read_text())
    assert record["status"] == "interrupted"
    assert [r["status"] for r in record["replicas"]] == ["interrupted"] * 2
    old = {}
    for i in (1, 2):
        run_dir = study / f"replica-{i}"
        run = json.loads((run_dir / "run.json").read_text())
        assert "nothing to resume" in run["error"] and not list(run_dir.glob("restart.*"))
        old[i] = {p.name: p.read_bytes() for p in run_dir.iterdir() if p.is_file()}

    done = _run(["--resume", str(study), "--md-only"])
    assert done.returncode == 0, done.stderr
    assert "replica 1: cannot be resumed (it holds no usable restart file" in done.stderr
    record = json.loads((study / "study.json").read_text())
    assert record["status"] == "completed" and len(record["resumed"]) == 1
    for i, rep in enumerate(record["replicas"], start=1):
        (entry,) = rep["superseded"]
        aside = study / entry["dir"]
        assert entry["dir"].startswith(f"superseded/replica-{i}.")
        assert entry["slide_steps"] == 20000
        kept = {p.name: p.read_bytes() for p in aside.iterdir() if p.is_file()}
        assert {k: v for k, v in kept.items() if k != ".lock"} == \
            {k: v for k, v in old[i].items() if k != ".lock"}, "moved intact"
        run = json.loads((study / f"replica-{i}" / "run.json").read_text())
        assert run["status"] in ("completed", "completed_with_warnings")
        assert rep["status"] == run["status"]
        assert run["scene"]["parameters"]["seed"] == rep["seed"] and "resumed_from" not in run
        trace = np.genfromtxt(study / f"replica-{i}" / "trace.csv", delimiter=",", names=True)
        assert len(trace) == 20000 // 50 + 1 and np.all(np.diff(trace["step"]) == 50)
    # the same run as the one the old directory's scene.toml starts (the drawn seed)
    aside = study / record["replicas"][1]["superseded"][0]["dir"]
    again = _run([str(aside / "scene.toml"), "--np", "1", "--md-only", "--out",
                  str(tmp_path / "again")])
    assert again.returncode == 0, again.stderr
    assert (tmp_path / "again" / "trace.csv").read_bytes() == \
        (study / "replica-2" / "trace.csv").read_bytes()


def test_a_run_slid_further_is_the_longer_run(tmp_path, md):
    """A completed run of 4000 steps continued to 8000 (``--slide-to``, what a target's
    segments do) gives the trace of one 8000-step run byte for byte on the same single
    rank (the thermostat is re-seeded at every restart boundary in both), and its record
    says so."""
    from filmfriction.workflows.md import runner

    settings = {"equilibrate_steps": 500, "slide_steps": 8000, "trace_every": 20,
                "restart_every": 2000}
    whole = md.shared("stick-slip", **settings).path       # test_faults_md.py's run too
    out = tmp_path / "extended"
    md.execute(md.scene("stick-slip", **{**settings, "slide_steps": 4000}), out)
    assert json.loads((out / "run.json").read_text())["status"].startswith("completed")
    runner.resume(out, progress=False, slide_steps=8000)
    record = json.loads((out / "run.json").read_text())
    assert record["status"].startswith("completed") and record["np"] == 1
    assert record["scene"]["parameters"]["slide_steps"] == 8000
    assert record["derived"]["slide_time"] == pytest.approx(8000 * record["scene"]
                                                            ["parameters"]["timestep"])
    assert record["extensions"][0]["from"] == 4000 and record["resumed_from"] == "restart.4000"
    assert "slide_steps = 8000" in (out / "scene.toml").read_text()
    assert (out / "trace.csv").read_bytes() == (whole / "trace.csv").read_bytes()


# ---------------------------------------------------------------- replicas as Snakemake jobs
def _same_study(a, b):
    """Two studies of the same command, one run by this process's children and one by
    Snakemake's jobs: the same seeds, slides, checks and combined analysis; every
    replica's trace byte for byte (one rank, the same seed)."""
    ra, rb = (json.loads((s / "study.json").read_text()) for s in (a, b))
    assert ra["replicas"] == rb["replicas"]
    assert [s["slide_steps"] for s in ra["segments"]] == [s["slide_steps"] for s in rb["segments"]]
    assert [[c["relative_error"] for c in s.get("checks", [])] for s in ra["segments"]] == \
        [[c["relative_error"] for c in s.get("checks", [])] for s in rb["segments"]]
    assert (ra["status"], ra["stop"]) == (rb["status"], rb["stop"])
    for i in range(1, len(ra["replicas"]) + 1):
        assert (a / f"replica-{i}" / "trace.csv").read_bytes() == \
            (b / f"replica-{i}" / "trace.csv").read_bytes()
        run = json.loads((b / f"replica-{i}" / "run.json").read_text())
        assert run["status"].startswith("completed") and run["np"] == 1
        assert run["scene"]["parameters"]["seed"] == rb["replicas"][i - 1]["seed"]
    ea, eb = (json.loads((s / "ensemble.json").read_text())["observables"] for s in (a, b))
    assert ea == eb


def test_replicas_as_snakemake_jobs_are_the_same_study(tmp_path):
    """``--profile local``: every replica of every segment one Snakemake job
    (workflows/sweep/replicas.smk); the study directory, its checks and the combined
    analysis are those of the same study run without a profile."""
    # two segments: the first has too few slips for the pilot, the second spends the budget
    args = ["stick-slip", *SMALL, "--set", "slide_steps=10000", "--set", "restart_every=5000",
            "--replicas", "2", "--target", "static_force=0.5", "--budget", "15000"]
    plain = _run([*args, "--out", str(tmp_path / "plain")])
    assert plain.returncode == 0, plain.stderr
    jobs = _run([*args, "--profile", "local", "--out", str(tmp_path / "jobs")])
    assert jobs.returncode == 0, jobs.stderr
    assert "as Snakemake jobs (profile local)" in jobs.stderr
    study = tmp_path / "jobs"
    record = json.loads((study / "study.json").read_text())
    assert record["profile"] == "local", record["stop"]
    assert [s["slide_steps"] for s in record["segments"]] == [10000, 15000]
    _same_study(tmp_path / "plain", study)
    # one job per replica and segment, each with its marker and its lines in the replica's log
    for seg in record["segments"]:
        slide = seg["slide_steps"]
        spec = json.loads((study / "segments" / f"slide-{slide}.json").read_text())
        assert spec["replicas"] == [1, 2] and spec["np"] == 1
        for i in (1, 2):
            assert (study / "segments" / f"slide-{slide}" / f"replica-{i}.done").is_file()
    for i in (1, 2):
        log = (study / f"replica-{i}.log").read_text()
        assert log.count(f"# replica {i}: ") == len(record["segments"])
        assert f"# replica {i}: start to slide step 10000 (1 rank(s), mpiexec) in job local" in log
        assert f"# replica {i}: resume to slide step 15000 (1 rank(s), mpiexec) in job local" in log
    assert "Finished jobid" in (study / "snakemake.log").read_text()


def test_a_study_of_snakemake_jobs_is_refused_without_a_profile_it_knows(tmp_path):
    done = _run(["stick-slip", "--replicas", "2", "--profile", "nowhere",
                 "--out", str(tmp_path / "s")])
    assert done.returncode == 2 and "--profile 'nowhere': no such profile" in done.stderr
    assert not (tmp_path / "s").exists()
    done = _run(["stick-slip", "--profile", "local", "--out", str(tmp_path / "s")])
    assert done.returncode == 2 and "give it with --replicas N" in done.stderr
