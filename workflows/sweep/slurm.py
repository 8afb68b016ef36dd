"""Sweeps on Slurm: Snakemake with its Slurm executor, and what became of the Slurm jobs.

Part of :mod:`filmfriction.workflows.sweep`.

``python -m filmfriction.workflows.sweep.slurm ARGS`` is ``python -m snakemake ARGS``
with one correction to the Slurm executor plugin (snakemake-executor-plugin-slurm 2.8):
``sacct`` gives the state of a job cancelled with ``scancel`` as ``CANCELLED by <uid>``,
which the plugin compares whole with its failed states, so it took such a job for a
running one and the sweep waited for it forever.  The states are cut at their first space
before the plugin reads them (``CANCELLED``), so a cancelled point is reported (and retried
once, as the Slurm profile says, like any failed job).

After a Slurm sweep, :func:`report` says what became of its jobs: it reads the Slurm job
ids and the point of each from Snakemake's log of the run, asks ``sacct`` for their
states, and names every point without a result with its jobs, its log and its failed runs.
"""
from __future__ import annotations

import functools
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

#: the plugin's line for each submission, e.g. "Job 3 has been submitted with SLURM jobid
#: 14 (log: /sweep/.snakemake/slurm_logs/rule_point/seed=1/14.log)."
_SUBMITTED = re.compile(r"submitted with SLURM jobid (\d+) \(log: .*?/slurm_logs/rule_(\w+)/"
                        r"([^/]+)/\d+\.log\)")


def _patch_plugin() -> None:
    """Cut the states the Slurm executor plugin reads at their first space (see above)."""
    try:
        import snakemake_executor_plugin_slurm as plugin
    except ImportError:
        return
    query = getattr(plugin, "query_job_status", None)
    if query is None or getattr(query, "cuts_states", False):
        return

    @functools.wraps(query)
    async def query_job_status(command, logger):
        states, seconds = await query(command, logger)
        if states is not None:
            states = {job: state.split(" ", 1)[0] for job, state in states.items()}
        return states, seconds

    query_job_status.cuts_states = True
    plugin.query_job_status = query_job_status


def snakemake_main(argv: list[str]) -> None:
    """``snakemake ARGV``, with the Slurm executor's states corrected (exits)."""
    _patch_plugin()
    from snakemake.cli import main

    main(argv)


# ---------------------------------------------------------------------------
# what became of the jobs
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class SlurmJob:
    """One Slurm job of a sweep: its id, the Snakefile rule and point it ran, and what
    ``sacct`` says of it (``state`` e.g. ``COMPLETED``, ``FAILED``, ``CANCELLED by 0``,
    ``TIMEOUT``; empty when sacct did not answer)."""

    job_id: str
    rule: str
    point: str
    state: str = ""
    exit_code: str = ""
    elapsed: str = ""


def snakemake_log(sweep_dir: Path, since: float | None = None) -> Path | None:
    """Snakemake's log of the newest run in ``sweep_dir`` (None when there is none, or
    when it was last written before the time ``since``: a run that wrote no log)."""
    logs = sorted((Path(sweep_dir) / ".snakemake" / "log").glob("*.snakemake.log"))
    if not logs or (since is not None and logs[-1].stat().st_mtime < since):
        return None
    return logs[-1]


def submitted_jobs(log_text: str) -> list[SlurmJob]:
    """The Slurm jobs a Snakemake log says were submitted, in order (no states yet)."""
    return [SlurmJob(job_id, rule, point) for job_id, rule, point in _SUBMITTED.findall(log_text)]


def sacct_states(job_ids: list[str]) -> dict[str, tuple[str, str, str]]:
    """``{job id: (state, exit code, elapsed)}`` from ``sacct`` ({} when it cannot answer)."""
    if not job_ids or shutil.which("sacct") is None:
        return {}
    try:
        out = subprocess.run(["sacct", "-X", "-n", "-P", "-j", ",".join(job_ids),
                              "-o", "JobIDRaw,State,ExitCode,Elapsed"],
                             capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return {}
    states = {}
    for line in out.stdout.splitlines():
        fields = line.split("|")
        if len(fields) == 4:
            states[fields[0]] = (fields[1], fields[2], fields[3])
    return states


def slurm_jobs(sweep_dir: Path, since: float | None = None) -> list[SlurmJob]:
    """The Slurm jobs of the newest Snakemake run in ``sweep_dir`` (one that wrote its log
    after the time ``since``), with their states."""
    log = snakemake_log(sweep_dir, since)
    if log is None:
        return []
    jobs = submitted_jobs(log.read_text(errors="replace"))
    states = sacct_states([j.job_id for j in jobs])
    return [SlurmJob(j.job_id, j.rule, j.point, *states.get(j.job_id, ("", "", "")))
            for j in jobs]


def _last_error(log: Path) -> str:
    """The runner's "run failed: ..." line of a point's log (else its last line)."""
    try:
        lines = [ln.strip() for ln in log.read_text(errors="replace").splitlines() if ln.strip()]
    except OSError:
        return ""
    failed = [ln for ln in lines if ln.startswith("run failed:")]
    return (failed or lines or [""])[-1]


def report(sweep_dir: Path, points: list[str], jobs: list[SlurmJob] | None = None) -> str:
    """Lines on what a sweep left undone: every point of ``points`` without an
    ``analysis.json``, with its Slurm jobs (``jobs``, e.g. :func:`slurm_jobs`), the error of
    its log, its partial run kept for the next sweep and its failed runs; and the Slurm jobs that did not complete.  Empty when
    every point has its analysis and every job completed."""
    sweep_dir = Path(sweep_dir)
    jobs = jobs or []
    lines = []
    unfinished = [j for j in jobs if j.state and j.state != "COMPLETED"]
    if jobs:
        lines.append(f"Slurm: {len(jobs)} job(s) submitted, "
                     f"{sum(j.state == 'COMPLETED' for j in jobs)} completed"
                     + "".join(f"; job {j.job_id} ({j.rule} {j.point}): {j.state}"
                               + (f", exit code {j.exit_code}" if j.state.startswith("FAILED")
                                  else "")
                               for j in unfinished))
    for point in points:
        if (sweep_dir / "points" / point / "analysis.json").exists():
            continue
        mine = [j for j in jobs if j.point == point]
        what = [f"point {point}: no result"]
        if mine:
            what.append("Slurm job(s) " + ", ".join(f"{j.job_id} {j.rule} {j.state or '?'}"
                                                      for j in mine))
        for rule in ("run", "analyse"):
            log = sweep_dir / "logs" / f"{point}.{rule}.log"
            error = _last_error(log) if log.exists() else ""
            if error:
                what.append(f"{log.relative_to(sweep_dir)}: {error}")
        partial = sweep_dir / "points" / f".{point}.partial"
        if partial.is_dir():
            from ..md import restarts

            good = restarts.usable(partial)
            what.append(f"partial run kept in {partial.relative_to(sweep_dir)} ("
                        + (f"newest usable restart {good[-1][1].name}; the next sweep resumes "
                           "it)" if good else "no usable restart file: the next sweep starts "
                           "afresh and moves it to superseded/)"))
        kept = sweep_dir / "failed"
        failed = sorted(p.name for p in kept.iterdir()
                        if p.name.startswith(f"{point}.")) if kept.is_dir() else []
        if failed:
            what.append(f"failed runs kept in failed/ ({', '.join(failed)})")
        lines.append("; ".join(what))
    return "\n".join(lines)


if __name__ == "__main__":
    snakemake_main(sys.argv[1:])
