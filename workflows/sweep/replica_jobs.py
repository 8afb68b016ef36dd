"""Replicas of a study as Snakemake jobs: one job per replica and segment.

``filmfriction run SCENE --replicas N --profile PROFILE`` (a shipped profile, ``local`` or
``slurm``, or a profile directory) drives the study exactly as without a profile
(:mod:`filmfriction.workflows.md.replicas.replica_study`: seeds, segments, the target's checks on
each replica's analysis, ``study.json``, the combined ``ensemble.json``); only who runs the
replicas of a segment differs.  :func:`snakemake_executor` writes the segment's replicas to
``segments/slide-<S>.json`` and runs ``workflows/sweep/replicas.smk`` on the study
directory, whose ``replica`` rule runs :func:`run_replica` once per replica: on this
machine (``local``), or as one Slurm job each (``slurm``: spread over the nodes).

:func:`run_replica` does what the replica's ``filmfriction run`` does without a profile
(start the run directory ``replica-<i>/`` with the replica's seed, or continue it to the
segment's slide from its newest restart file, or start it again from the beginning when it
holds nothing to resume, its directory moved to ``superseded/``:
:mod:`filmfriction.workflows.md.replicas.afresh`), under the launcher the profile names
(``srun`` on Slurm), and writes the segment's marker only when the replica got there.
"""
from __future__ import annotations

import contextlib
import json
import os
import shlex
import signal
import subprocess
import sys
from pathlib import Path

from filmfriction.md_inputs.contract import SCENE_FILE, STUDY_FILE

__all__ = ["SNAKEFILE", "segment_spec", "snakemake_executor", "run_replica"]

SNAKEFILE = Path(__file__).with_name("replicas.smk")
#: seconds Snakemake has to stop its jobs (each records its interruption) after Ctrl-C
STOP_GRACE = 120.0


def segment_spec(study: Path, slide: int) -> Path:
    """Where the replicas of the segment to ``slide`` steps are listed."""
    return Path(study) / "segments" / f"slide-{int(slide)}.json"


def marker(study: Path, slide: int, index: int) -> Path:
    """The file replica ``index``'s job writes once it slid ``slide`` steps."""
    return Path(study) / "segments" / f"slide-{int(slide)}" / f"replica-{int(index)}.done"


def snakemake_executor(profile: Path, cores: int):
    """A runner of a segment's replicas for :func:`~filmfriction.workflows.md.replicas.replica_study.run_study`:
    ``(study, record, slide, indices, workers) -> {index: exit code}`` through Snakemake
    with ``profile`` on at most ``cores`` local cores (a cluster's profile sets its own
    job limit)."""
    def run(study: Path, record: dict, slide: int, indices, workers: int) -> dict[int, int]:
        from filmfriction.analysis.files.util import write_atomic

        from .jobs import snakemake_command

        study = Path(study).resolve()
        indices = sorted(indices)
        spec = segment_spec(study, slide)
        spec.parent.mkdir(exist_ok=True)
        write_atomic(spec, json.dumps({"slide_steps": int(slide), "replicas": indices,
                                       "np": int(record.get("np") or 1),
                                       "lmp": record.get("lmp")}, indent=2) + "\n")
        for i in indices:     # a marker of an earlier try of this segment says nothing now
            marker(study, slide, i).unlink(missing_ok=True)
        config = {"spec": str(spec.relative_to(study))}
        locks = study / ".snakemake" / "locks"
        if locks.is_dir() and any(locks.iterdir()):
            # the study's own lock is held by this process: no Snakemake of ours is alive
            # here, its lock is left over from a killed one
            subprocess.run(snakemake_command(study, cores, snakefile=SNAKEFILE, config=config,
                                             extra=["--unlock"]),
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
        cmd = snakemake_command(study, max(int(cores), int(record.get("np") or 1)),
                                profile=profile, snakefile=SNAKEFILE, config=config)
        with open(study / "snakemake.log", "a") as log:
            proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT,
                                    stdin=subprocess.DEVNULL, start_new_session=True)
            try:
                proc.wait()
            except BaseException:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, signal.SIGINT)
                try:
                    proc.wait(timeout=STOP_GRACE)
                except subprocess.TimeoutExpired:
                    with contextlib.suppress(ProcessLookupError):
                        os.killpg(proc.pid, signal.SIGKILL)
                raise
        return {i: 0 if marker(study, slide, i).is_file() else (proc.returncode or 1)
                for i in indices}
    return run


def run_replica(study: Path, index: int, slide: int, np_: int, launcher: str = "mpiexec",
                lmp: str | None = None) -> Path:
    """Bring replica ``index`` of ``study`` to a slide of ``slide`` steps: start its run
    directory (the study's scene with the replica's seed) or continue it from its newest
    restart file (one with nothing to resume moves to ``superseded/`` and the replica
    starts again); nothing when it is there already.  Raises what the runner raises
    (:class:`~filmfriction.workflows.md.runner.RunFailed`, ``KeyboardInterrupt``)."""
    from ..md.replicas.afresh import move_aside, replica_state, why_not_resumable
    from ..md.replicas.replica_study import replica_dir
    from ..md.runner import execute, resume
    from ..md.scene import load

    study = Path(study)
    record = json.loads((study / STUDY_FILE).read_text(encoding="utf-8"))
    seed = int(record["replicas"][int(index) - 1]["seed"])
    run_dir = replica_dir(study, index)
    # ranks of one thread (Snakemake exports OMP_NUM_THREADS = the rule's threads)
    os.environ["OMP_NUM_THREADS"] = "1"
    words = shlex.split(launcher)
    words = None if words in ([], ["mpiexec"]) else words
    state = replica_state(run_dir, slide)
    if state == "restart":      # nothing to resume (a job lost before its first restart file)
        why = why_not_resumable(run_dir)
        moved = move_aside(study, index, why, slide)["dir"]
        print(f"# replica {index}: cannot be resumed ({why}); moved to {moved}; it starts "
              "again from the beginning with its seed", flush=True)
        state = "start"
    print(f"# replica {index}: {state} to slide step {slide} ({np_} rank(s), "
          f"{launcher}) in job {os.environ.get('SLURM_JOB_ID', 'local')}", flush=True)
    if state == "start":
        scene = load(str(study / SCENE_FILE), {"seed": seed, "slide_steps": int(slide)})
        execute(scene, out=run_dir, nprocs=np_, progress=False, launcher=words, lmp=lmp)
    elif state == "resume":
        resume(run_dir, nprocs=np_, progress=False, launcher=words, lmp=lmp,
               slide_steps=int(slide))
    print(f"run directory: {run_dir}", flush=True)
    return run_dir


def replica_main(args) -> int:
    """The ``replica`` job of ``python -m filmfriction.workflows.sweep``."""
    from ..md.runner import RunFailed
    from ..md.scene import SceneError

    try:
        run_replica(args.study, args.index, args.slide_steps, args.np, args.launcher, args.lmp)
    except (RunFailed, SceneError) as exc:
        print(f"filmfriction run: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("filmfriction run: interrupted", file=sys.stderr)
        return 130
    done = Path(args.done)
    done.parent.mkdir(parents=True, exist_ok=True)
    done.write_text("done\n")
    return 0
