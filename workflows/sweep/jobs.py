"""Sweep jobs: the Snakemake command and the per-point jobs the Snakefile runs.

Part of :mod:`filmfriction.workflows.sweep`.
"""
from __future__ import annotations

import contextlib
import json
import os
import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path



from filmfriction.md_inputs.contract import RUN_FILE

from ..inputs import UserError as _user_error
from ..md.run_record import set_aside
from .plan import SweepLock, SweepPlan, write_plan

SNAKEFILE = Path(__file__).with_name("sweep.smk")
PROFILES = Path(__file__).with_name("profiles")

# set by the job's SIGTERM/SIGINT handler (see workflows/sweep/__main__.py)
_INTERRUPTED = False


def interrupt(signum, frame):
    """The sweep job's SIGTERM/SIGINT handler: remember the interrupt, then stop as Ctrl-C."""
    global _INTERRUPTED
    _INTERRUPTED = True
    raise KeyboardInterrupt


# ---------------------------------------------------------------------------
# Snakemake
# ---------------------------------------------------------------------------
def profile_path(profile: str) -> Path:
    """A profile by name (``slurm``, ``local``: shipped in ``workflows/sweep/profiles/``) or path."""
    shipped = PROFILES / profile
    if (shipped / "config.yaml").is_file():
        return shipped
    path = Path(profile)
    if (path / "config.yaml").is_file():
        return path.resolve()
    known = sorted(p.name for p in PROFILES.iterdir() if (p / "config.yaml").is_file())
    raise _user_error(f"--profile {profile!r}: no such profile; shipped: {', '.join(known)} "
                      "(or a directory holding config.yaml)")


def snakemake_command(out: Path, cores: int, *, dry_run: bool = False,
                      profile: Path | None = None, extra: list[str] | None = None,
                      snakefile: Path = SNAKEFILE, config: dict | None = None) -> list[str]:
    """The ``python -m snakemake`` command line for a sweep directory (through
    :mod:`.slurm`, which corrects the Slurm executor's reading of job states); a study's
    replicas give their own ``snakefile`` and ``config``."""
    cmd = [sys.executable, "-m", "filmfriction.workflows.sweep.slurm",
           "--snakefile", str(snakefile),
           "--directory", str(Path(out).resolve()), "--cores", str(cores),
           # resume: a job that was running when the sweep was killed is redone
           "--rerun-incomplete",
           # one failed point does not stop the others
           "--keep-going", "--show-failed-logs",
           "--config", f"python={sys.executable}",
           *(f"{k}={v}" for k, v in (config or {}).items())]
    if profile is not None:
        cmd += ["--profile", str(profile)]
    if dry_run:
        cmd += ["--dry-run"]
    return cmd + list(extra or [])


def _stale_snakemake_lock(out: Path) -> bool:
    locks = Path(out) / ".snakemake" / "locks"
    return locks.is_dir() and any(locks.iterdir())


def run_sweep(plan: SweepPlan, out: Path, cores: int = 2, *, dry_run: bool = False,
              profile: Path | None = None, extra: list[str] | None = None) -> int:
    """Write the plan into ``out`` and run Snakemake on it; return its exit code.

    SIGINT and SIGTERM stop the whole sweep: Snakemake and its jobs get SIGINT
    (each point then stops its LAMMPS child), and running the same command
    again resumes.
    """
    out = Path(out)
    with SweepLock(out) as lock:
        changed = write_plan(plan, out)
        if changed and not dry_run:
            print(f"sweep: {len(changed)} of {len(plan.points)} point input(s) new or changed",
                  file=sys.stderr)
        if _stale_snakemake_lock(out):
            # we hold the sweep lock, so no Snakemake of ours is alive here: its lock is
            # left over from a killed sweep
            subprocess.run(snakemake_command(out, cores, extra=["--unlock"]),
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
        cmd = snakemake_command(out, cores, dry_run=dry_run, profile=profile, extra=extra)
        proc = subprocess.Popen(cmd, pass_fds=(lock.fd,), start_new_session=True)
        stop = {"signal": None}

        def forward(signum, frame):
            stop["signal"] = signum
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGINT)

        old = {s: signal.signal(s, forward) for s in (signal.SIGINT, signal.SIGTERM)}
        try:
            rc = proc.wait()
        finally:
            for s, h in old.items():
                signal.signal(s, h)
            if stop["signal"] is not None:
                # Snakemake can start a job while it shuts down; stop any straggler
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, signal.SIGINT)
    if stop["signal"] is not None:
        print(f"sweep interrupted; run the same command again to resume ({out})",
              file=sys.stderr)
        return 130
    return rc


# ---------------------------------------------------------------------------
# the jobs (called from the Snakefile)
# ---------------------------------------------------------------------------
def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def partial_dir(run_dir: Path) -> Path:
    """Where a point's run lives until it completes: ``points/.<point>.partial/``.

    An interrupted run stays there with its restart files, and the next sweep of the
    same plan resumes it (:func:`run_point`)."""
    run_dir = Path(run_dir)
    return run_dir.with_name(f".{run_dir.name}.partial")


def _adopt_leftovers(run_dir: Path, partial: Path, sweep_dir: Path, stamp: str) -> None:
    """Hidden ``.<point>.tmp-<pid>`` run directories of jobs that died (the layout of
    earlier sweeps): the first becomes the partial run, any other goes to ``superseded/``."""
    for old in sorted(run_dir.parent.glob(f".{run_dir.name}.tmp-*")):
        pid = old.name.rsplit("-", 1)[-1]
        if not pid.isdigit() or _pid_alive(int(pid)):
            continue
        if not partial.exists():
            os.replace(old, partial)
        else:
            set_aside(old, sweep_dir, "superseded", run_dir.name, stamp)


def why_not_resumable(partial: Path, parameters: dict) -> str | None:
    """Why the partial run cannot be resumed for a point of ``parameters`` (None: it can,
    or it completed and only needs to be put in place)."""
    from ..md import restarts

    try:
        record = json.loads((partial / RUN_FILE).read_text(encoding="utf-8"))
        recorded = record["scene"]["parameters"]
    except FileNotFoundError:
        return "it has no run.json"
    except (OSError, ValueError, KeyError, TypeError) as exc:
        return f"its run.json is not a readable run record ({exc})"
    if recorded != parameters:
        changed = sorted(k for k in set(recorded) | set(parameters)
                         if recorded.get(k) != parameters.get(k))
        return f"its parameters differ from the plan's ({', '.join(changed)})"
    if record.get("status") in ("completed", "completed_with_warnings"):
        return None
    if not restarts.usable(partial):
        return "it holds no usable restart file"
    return None


def _keep_partial(partial: Path, sweep_dir: Path, name: str, stamp: str) -> None:
    """After an interrupt: the partial run stays for the next sweep to resume, unless it
    holds no restart file (stopped before the first one: nothing to resume); then it
    moves to ``superseded/`` (kept, as a study's replica's) and the point starts afresh."""
    from ..md import restarts

    if not partial.is_dir():
        return
    if restarts.restart_files(partial):
        print(f"partial run kept in {partial}: the next sweep resumes it", file=sys.stderr)
    else:
        moved = set_aside(partial, sweep_dir, "superseded", name, stamp)
        print(f"stopped before the first restart file: nothing to resume, kept in {moved}; "
              "the next sweep starts this point afresh", file=sys.stderr)


def run_point(inputs: Path, run_dir: Path, np_: int, launcher: str = "mpiexec") -> Path:
    """Run one grid point into ``run_dir``, atomically, resuming its interrupted run.

    LAMMPS runs in ``points/.<point>.partial/`` (:func:`partial_dir`); only a
    completed run is renamed to ``run_dir``.  A run stopped by SIGINT, SIGTERM or
    SIGHUP, or killed from outside (:attr:`~filmfriction.workflows.md.runner.RunFailed.resumable`),
    stays there with its restart files, and the next job of the same point continues
    it from the newest one (:func:`filmfriction.workflows.md.runner.resume`, under the
    same launcher) instead of starting afresh.  A partial run that cannot be resumed
    (the point's parameters changed, no usable restart file) moves to ``superseded/``
    and the point starts afresh; a run that failed in the simulation itself (LAMMPS's
    ERROR, lost atoms, NaN) moves to ``failed/``; a stale ``run_dir`` (an older run
    whose parameters changed) moves to ``superseded/``, and so does an interrupted run
    that holds no restart file (nothing to resume).  Nothing is deleted.

    Parameters
    ----------
    inputs : Path
        ``inputs/<point>.json``.
    run_dir : Path
        ``points/<point>``.
    np_ : int
        MPI ranks.
    launcher : str
        ``mpiexec`` (the venv's) or a command such as ``srun --mpi=pmi2`` (the Snakefile's
        ``launcher`` resource, set by the profile).
    """
    from ..md.runner import RunFailed, RunLock, execute, resume
    from ..md.scene import load

    doc = json.loads(Path(inputs).read_text())
    scene = load(doc["scene_source"], doc["overrides"])
    if scene.parameters != doc["parameters"]:
        raise RuntimeError(f"{inputs}: the scene file changed since the sweep was planned; "
                           "run the sweep command again")
    run_dir = Path(run_dir)
    sweep_dir = run_dir.parent.parent
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    partial = partial_dir(run_dir)
    _adopt_leftovers(run_dir, partial, sweep_dir, stamp)
    resuming = partial.exists()
    if resuming:
        # a job of this point still driving it (its lock is held): refused, nothing moved
        RunLock(partial).acquire().release()
        why = why_not_resumable(partial, doc["parameters"])
        if why:
            moved = set_aside(partial, sweep_dir, "superseded", run_dir.name, stamp)
            print(f"the partial run of this point cannot be resumed: {why}; moved to "
                  f"{moved}, starting afresh", file=sys.stderr)
            resuming = False
    # ranks of one thread: Snakemake exports OMP_NUM_THREADS = the rule's threads (the
    # point's cores, --np), which would give every rank that many OpenMP threads
    os.environ["OMP_NUM_THREADS"] = "1"
    words = shlex.split(launcher)
    words = None if words in ([], ["mpiexec"]) else words
    try:
        if not resuming:
            execute(scene, out=partial, nprocs=np_, progress=False, launcher=words)
        elif json.loads((partial / RUN_FILE).read_text())["status"].startswith("completed"):
            print(f"the partial run {partial} completed before its job ended; "
                  "putting it in place", file=sys.stderr)
        else:
            print(f"resuming the partial run {partial}", file=sys.stderr)
            resume(partial, nprocs=np_, progress=False, launcher=words)
    except RunFailed as exc:
        if not (_INTERRUPTED or exc.resumable):
            failed = set_aside(partial, sweep_dir, "failed", run_dir.name, stamp)
            print(f"run failed; kept in {failed}", file=sys.stderr)
            raise
        # an interrupt, or an engine killed from outside: for a sweep neither is a
        # result; the next sweep resumes the run
        _keep_partial(partial, sweep_dir, run_dir.name, stamp)
        if _INTERRUPTED:
            raise KeyboardInterrupt from None
        raise
    except KeyboardInterrupt:
        _keep_partial(partial, sweep_dir, run_dir.name, stamp)
        raise
    if run_dir.exists():
        if any(run_dir.iterdir()):
            set_aside(run_dir, sweep_dir, "superseded", run_dir.name, stamp)
        else:
            run_dir.rmdir()      # Snakemake made it as the parent of run.json
    os.replace(partial, run_dir)
    return run_dir


def analyse_point(run_dir: Path) -> dict:
    """Write ``analysis.json`` (and ``analysis_cycles.csv``) into a completed run."""
    from filmfriction.analysis.analyze import analyse_run as analyse

    return analyse(Path(run_dir))


