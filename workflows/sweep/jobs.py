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



from ..inputs import UserError as _user_error
from .plan import SweepLock, SweepPlan, write_plan

SNAKEFILE = Path(__file__).with_name("sweep.smk")
PROFILES = Path(__file__).with_name("profiles")

# set by the job's SIGTERM/SIGINT handler (see workflows/sweep/__main__.py)
_INTERRUPTED = False


def _interrupt(signum, frame):
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
                      profile: Path | None = None, extra: list[str] | None = None) -> list[str]:
    """The ``python -m snakemake`` command line for a sweep directory (through
    :mod:`.slurm`, which corrects the Slurm executor's reading of job states)."""
    cmd = [sys.executable, "-m", "filmfriction.workflows.sweep.slurm",
           "--snakefile", str(SNAKEFILE),
           "--directory", str(Path(out).resolve()), "--cores", str(cores),
           # resume: a job that was running when the sweep was killed is redone
           "--rerun-incomplete",
           # one failed point does not stop the others
           "--keep-going", "--show-failed-logs",
           "--config", f"python={sys.executable}"]
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


def run_point(inputs: Path, run_dir: Path, np_: int, launcher: str = "mpiexec") -> Path:
    """Run one grid point into ``run_dir``, atomically.

    LAMMPS runs in a fresh hidden directory next to ``run_dir``; only a
    completed run is renamed to ``run_dir``.  A stale ``run_dir`` (an older
    run whose parameters changed) moves to ``superseded/``, a failed run to
    ``failed/``; nothing is deleted except this job's own interrupted run.

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
    import shutil

    from ..md.runner import RunFailed, execute
    from ..md.scene import load

    doc = json.loads(Path(inputs).read_text())
    scene = load(doc["scene_source"], doc["overrides"])
    if scene.parameters != doc["parameters"]:
        raise RuntimeError(f"{inputs}: the scene file changed since the sweep was planned; "
                           "run the sweep command again")
    run_dir = Path(run_dir)
    sweep_dir = run_dir.parent.parent
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    # leftovers of this point's jobs that died without cleaning up
    for old in run_dir.parent.glob(f".{run_dir.name}.tmp-*"):
        pid = old.name.rsplit("-", 1)[-1]
        if pid.isdigit() and not _pid_alive(int(pid)):
            shutil.rmtree(old, ignore_errors=True)
    tmp = run_dir.with_name(f".{run_dir.name}.tmp-{os.getpid()}")
    # ranks of one thread: Snakemake exports OMP_NUM_THREADS = the rule's threads (the
    # point's cores, --np), which would give every rank that many OpenMP threads
    os.environ["OMP_NUM_THREADS"] = "1"
    stamp = time.strftime("%Y%m%d-%H%M%S")
    try:
        words = shlex.split(launcher)
        execute(scene, out=tmp, nprocs=np_, progress=False,
                launcher=None if words in ([], ["mpiexec"]) else words)
    except RunFailed:
        if _INTERRUPTED:
            # the runner turns an interrupt into a failed run; for a sweep it is neither
            # a result nor a failure: the next sweep starts this point afresh
            shutil.rmtree(tmp, ignore_errors=True)
            raise KeyboardInterrupt from None
        failed = sweep_dir / "failed" / f"{run_dir.name}.{stamp}"
        failed.parent.mkdir(exist_ok=True)
        os.replace(tmp, failed)
        print(f"run failed; kept in {failed}", file=sys.stderr)
        raise
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)   # interrupted: the next sweep starts it afresh
        raise
    if run_dir.exists():
        if any(run_dir.iterdir()):
            superseded = sweep_dir / "superseded" / f"{run_dir.name}.{stamp}"
            superseded.parent.mkdir(exist_ok=True)
            os.replace(run_dir, superseded)
        else:
            run_dir.rmdir()      # Snakemake made it as the parent of run.json
    os.replace(tmp, run_dir)
    return run_dir


def analyse_point(run_dir: Path) -> dict:
    """Write ``analysis.json`` (and ``analysis_cycles.csv``) into a completed run."""
    from filmfriction.analysis.analyze import analyse_run as analyse

    return analyse(Path(run_dir))


