"""What needs no cluster of the Slurm side of sweeps (workflows/sweep/slurm.py, the ranks
check of the runner): the correction of the executor plugin's job states, the jobs read
from Snakemake's log, the report of a sweep's missing points, and a launcher whose ranks
do not join one MPI job.  The real cluster: tests/slurm/test_slurm_sweep.py."""
from __future__ import annotations

import asyncio
import json
import logging
from pathlib import Path

import pytest

from filmfriction.workflows.md import runner
from filmfriction.workflows.sweep import slurm as sweep_slurm
from filmfriction.workflows.md.runner import RunFailed
from filmfriction.workflows.sweep.slurm import SlurmJob, report, submitted_jobs

#: lines as the Slurm executor plugin writes them into Snakemake's log
LOG = """\
Job 3 has been submitted with SLURM jobid 14 (log: /s/.snakemake/slurm_logs/rule_point/seed=1/14.log).
Job 9 has been submitted with SLURM jobid 16 (log: /s/.snakemake/slurm_logs/rule_point/drive_velocity=0.05__seed=4/16.log).
[Fri Nov 27 02:59:09 2026]
Job 2 has been submitted with SLURM jobid 18 (log: /s/.snakemake/slurm_logs/rule_analyse/seed=1/18.log).
"""


def test_the_plugin_reads_cancelled_by_uid_as_cancelled():
    plugin = pytest.importorskip("snakemake_executor_plugin_slurm",
                                 reason="pip install -e '.[sweep]' (the Slurm executor plugin)")
    original = plugin.query_job_status
    try:
        sweep_slurm._patch_plugin()
        sweep_slurm._patch_plugin()                  # twice: still one correction
        assert plugin.query_job_status.__wrapped__ is original
        # what `sacct -X --parsable2 --format=JobIdRaw,State` prints for these jobs
        command = "printf '16|CANCELLED by 0\\n17|FAILED\\n18|COMPLETED\\n19|RUNNING\\n'"
        states, seconds = asyncio.run(plugin.query_job_status(command, logging.getLogger()))
        assert states == {"16": "CANCELLED", "17": "FAILED", "18": "COMPLETED",
                          "19": "RUNNING"}
        assert seconds >= 0
        # and without the correction the plugin gets the whole state, not one it knows
        raw, _ = asyncio.run(original(command, logging.getLogger()))
        assert raw["16"] == "CANCELLED by 0"
        # a failed query stays a failed query
        assert asyncio.run(plugin.query_job_status("false", logging.getLogger())) == (None, None)
    finally:
        plugin.query_job_status = original


def test_submitted_jobs_are_read_from_snakemakes_log():
    assert submitted_jobs(LOG) == [SlurmJob("14", "point", "seed=1"),
                                   SlurmJob("16", "point", "drive_velocity=0.05__seed=4"),
                                   SlurmJob("18", "analyse", "seed=1")]
    assert submitted_jobs("Building DAG of jobs...\n") == []


def test_the_report_names_each_missing_point_with_its_jobs_log_and_failed_runs(tmp_path):
    (tmp_path / "points" / "seed=1").mkdir(parents=True)
    (tmp_path / "points" / "seed=1" / "analysis.json").write_text("{}")
    (tmp_path / "logs").mkdir()
    (tmp_path / "logs" / "seed=3.run.log").write_text(
        "run failed; kept in failed/seed=3.20260101-000000\n"
        "run failed: ERROR: Lost atoms: original 330 current 329\n"
        "(partial results kept in points/.seed=3.tmp-1)\n")
    (tmp_path / "failed" / "seed=3.20260101-000000").mkdir(parents=True)
    (tmp_path / "failed" / "seed=30.20260101-000000").mkdir()     # another point's
    jobs = [SlurmJob("14", "point", "seed=1", "COMPLETED", "0:0", "00:00:30"),
            SlurmJob("15", "analyse", "seed=1", "COMPLETED", "0:0", "00:00:20"),
            SlurmJob("16", "point", "seed=4", "CANCELLED by 0", "0:0", "00:00:00"),
            SlurmJob("17", "point", "seed=3", "FAILED", "1:0", "00:00:26")]
    lines = report(tmp_path, ["seed=1", "seed=3", "seed=4"], jobs).splitlines()
    assert lines[0] == ("Slurm: 4 job(s) submitted, 2 completed; job 16 (point seed=4): "
                        "CANCELLED by 0; job 17 (point seed=3): FAILED, exit code 1:0")
    assert lines[1] == ("point seed=3: no result; Slurm job(s) 17 point FAILED; "
                        "logs/seed=3.run.log: run failed: ERROR: Lost atoms: original 330 "
                        "current 329; failed runs kept in failed/ (seed=3.20260101-000000)")
    assert lines[2] == "point seed=4: no result; Slurm job(s) 16 point CANCELLED by 0"
    assert len(lines) == 3
    # a local sweep (no Slurm jobs) that left nothing undone has nothing to report
    assert report(tmp_path, ["seed=1"]) == ""


def test_slurm_jobs_are_those_of_the_run_that_wrote_the_newest_log(tmp_path):
    assert sweep_slurm.slurm_jobs(tmp_path) == []
    logs = tmp_path / ".snakemake" / "log"
    logs.mkdir(parents=True)
    (logs / "2026-01-01T000000.000000.snakemake.log").write_text(LOG)
    (logs / "2026-01-02T000000.000000.snakemake.log").write_text(LOG.splitlines()[0] + "\n")
    assert [j.job_id for j in sweep_slurm.slurm_jobs(tmp_path)] == ["14"]
    # a sweep that started after that log was written (its Snakemake wrote none): no jobs
    newest = (logs / "2026-01-02T000000.000000.snakemake.log").stat().st_mtime
    assert sweep_slurm.slurm_jobs(tmp_path, since=newest + 1) == []
    assert [j.job_id for j in sweep_slurm.slurm_jobs(tmp_path, since=newest)] == ["14"]


def test_a_log_of_separate_one_rank_copies_is_refused(tmp_path):
    log = tmp_path / "lammps.log"
    log.write_text("Loop time of 0.4 on 1 procs for 1000 steps with 330 atoms\n"
                   "98.1% CPU use with 1 MPI tasks x 1 OpenMP threads\n" * 2)
    problem = runner.ranks_problem(log, 2)
    assert problem.startswith("LAMMPS ran on 1 MPI rank(s), not the 2 asked")
    assert "srun --mpi=pmi2" in problem
    assert runner.ranks_problem(log, 1) is None
    # ranks of several threads count as ranks ("on 4 procs" is 2 ranks x 2 threads)
    log.write_text("Loop time of 5.6 on 4 procs for 1000 steps with 330 atoms\n"
                   "18.1% CPU use with 2 MPI tasks x 2 OpenMP threads\n")
    assert runner.ranks_problem(log, 2) is None
    # a log that does not say (an old LAMMPS, a run that stopped early): no verdict
    log.write_text("LAMMPS (2 Aug 2023)\n")
    assert runner.ranks_problem(log, 2) is None
    assert runner.ranks_problem(tmp_path / "none.log", 2) is None


@pytest.mark.md
def test_a_launcher_that_starts_separate_copies_fails_the_run(md, tmp_path):
    """A launcher that starts the ranks as independent one-rank LAMMPS runs (srun without
    the PMI of the MPI library does this): the run completes twice over, and is refused."""
    copies = tmp_path / "two-copies"
    copies.write_text('#!/bin/sh\n# "-n N lmp ...": N separate runs of lmp\nn=$2; shift 2\n'
                      'i=0; while [ $i -lt $n ]; do "$@" & i=$((i+1)); done; wait\n')
    copies.chmod(0o755)
    scene = md.scene("stick-slip", equilibrate_steps=200, slide_steps=400, trace_every=20)
    with pytest.raises(RunFailed) as err:
        runner.execute(scene, out=tmp_path / "run", nprocs=2, progress=False,
                       launcher=[str(copies)])
    assert "LAMMPS ran on 1 MPI rank(s), not the 2 asked" in str(err.value)
    record = json.loads((Path(err.value.run_dir) / "run.json").read_text())
    assert record["status"] == "failed" and "not the 2 asked" in record["error"]


def test_a_sweep_with_an_lmp_that_is_none_is_refused_before_anything(run_cli, tmp_path):
    out = tmp_path / "sweep"
    r = run_cli("sweep", "stick-slip", "--grid", "seed=1,2", "--lmp", tmp_path / "no-lmp",
                "--profile", "slurm", "--dry-run", "--out", out)
    assert r.code == 2
    assert r.err.strip().splitlines() == [
        f"filmfriction sweep: error: --lmp {tmp_path / 'no-lmp'}: no such file; give the path "
        "of a LAMMPS executable (lmp)"]
    assert not out.exists()
