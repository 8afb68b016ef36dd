"""A replica that cannot be resumed starts again from its beginning.

A replica's run directory holds nothing to resume when its run stopped before LAMMPS
wrote the first restart file (an interruption, a kill, a lost node), when its restart
files are damaged, or when its ``run.json`` is missing or unreadable.
``filmfriction run --resume DIR`` refuses such a directory; a study does not stop there:
the replica starts again from the beginning with its recorded seed (the MD is
deterministic for a seed and a rank count, so it is the same run), and its old directory
moves, intact, to ``superseded/replica-<i>.<stamp>`` in the study directory (the
convention of a sweep's points, :mod:`filmfriction.workflows.sweep.jobs`).  ``study.json``
lists each move under its replica (``superseded``: the directory, why, when, and the slide
the replica was brought to).

The study's driver moves such directories before each segment, for its own children and
for Snakemake jobs alike; a replica's Snakemake job moves its own too (a Slurm retry after
a lost node), and the driver lists what a job moved once the segment ends
(:func:`list_moves`).

Example
-------
>>> import json, tempfile, pathlib
>>> run_dir = pathlib.Path(tempfile.mkdtemp()) / "replica-1"
>>> run_dir.mkdir()
>>> _ = (run_dir / "run.json").write_text(json.dumps({"status": "interrupted", "scene": {}}))
>>> why_not_resumable(run_dir)
'it holds no usable restart file (its run.json says interrupted)'
"""
from __future__ import annotations

import json
import time
from datetime import datetime, timezone
from pathlib import Path

from filmfriction.md_inputs.contract import REPLICA_DIR, REPLICA_LOG, RUN_FILE

from .. import restarts
from ..locks import RunLock
from ..run_record import set_aside

__all__ = ["SUPERSEDED", "replica_state", "why_not_resumable", "move_aside", "list_moves",
           "start_again"]

#: the study's folder of replica directories that could not be resumed
SUPERSEDED = "superseded"
_DONE = ("completed", "completed_with_warnings")


def replica_state(run_dir: Path, slide: int) -> str:
    """``done`` (slid ``slide`` steps), ``start`` (no run yet; an empty directory a
    replica's run left when it stopped before writing anything is removed), ``resume``
    (from its newest restart file) or ``restart`` (nothing to resume: it starts again from
    the beginning, its directory moved aside by :func:`start_again`)."""
    try:
        rec = json.loads((run_dir / RUN_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        if run_dir.exists() and any(run_dir.iterdir()):
            return "restart"      # files, but no readable run.json: nothing to resume
        if run_dir.exists():
            run_dir.rmdir()       # an empty directory a child made before it stopped
        return "start"
    scene = rec.get("scene") if isinstance(rec, dict) else None
    params = scene.get("parameters") if isinstance(scene, dict) else None
    steps = params.get("slide_steps", 0) if isinstance(params, dict) else 0
    if isinstance(rec, dict) and rec.get("status") in _DONE and isinstance(steps, int) \
            and steps >= slide:
        return "done"
    return "resume" if why_not_resumable(run_dir) is None else "restart"


def start_again(study: Path, record: dict, slide: int) -> bool:
    """Move aside every replica's directory that holds nothing to resume (its replica then
    starts again from the beginning with its seed) and list the moves a replica's job
    made; True when ``record`` changed."""
    from ...progress import note

    changed = bool(list_moves(study, record))
    for i, rep in enumerate(record["replicas"], start=1):
        run_dir = Path(study) / REPLICA_DIR.format(index=i)
        if replica_state(run_dir, slide) != "restart":
            continue
        entry = move_aside(study, i, why_not_resumable(run_dir), slide)
        rep.setdefault("superseded", []).append(entry)
        changed = True
        note(f"replica {i}: cannot be resumed ({entry['why']}); moved to "
             f"{study / entry['dir']}; it starts again from the beginning with its seed "
             f"{rep['seed']}")
    return changed


def why_not_resumable(run_dir: Path) -> str | None:
    """Why ``filmfriction run --resume`` cannot continue the run in ``run_dir``: no
    readable run record, or no usable restart file (:mod:`..restarts`); None when it can."""
    run_dir = Path(run_dir)
    try:
        record = json.loads((run_dir / RUN_FILE).read_text(encoding="utf-8"))
    except FileNotFoundError:
        return f"it has no {RUN_FILE}"
    except (OSError, ValueError) as exc:
        return f"its {RUN_FILE} is not readable ({exc})"
    if not isinstance(record, dict) or not isinstance(record.get("scene"), dict):
        return f"its {RUN_FILE} is not a run record"
    good, bad = restarts.check(run_dir)
    if good:
        return None
    why = "; ".join(f"{name}: {reason}" for name, reason in bad.items()) or \
        f"its {RUN_FILE} says {record.get('status')}"
    return f"it holds no usable restart file ({why})"


def move_aside(study: Path, index: int, why: str, slide: int) -> dict:
    """Move replica ``index``'s run directory to the study's ``superseded/``; the entry
    ``study.json`` lists.  A process still driving the directory (its lock held): refused
    (:class:`~filmfriction.workflows.md.scene.SceneError`), nothing moved."""
    study = Path(study)
    name = REPLICA_DIR.format(index=int(index))
    RunLock(study / name).acquire().release()
    moved = set_aside(study / name, study, SUPERSEDED, name, time.strftime("%Y%m%d-%H%M%S"))
    return {"dir": moved.relative_to(study).as_posix(), "why": why,
            "at": datetime.now(timezone.utc).isoformat(), "slide_steps": int(slide)}


def list_moves(study: Path, record: dict) -> list[str]:
    """Add to each replica of ``record`` the directories of ``superseded/`` its entries do
    not list yet (moved by a replica's job, or by a driver stopped before it wrote
    ``study.json``); the directories added."""
    study = Path(study)
    added = []
    for i, rep in enumerate(record["replicas"], start=1):
        known = {e.get("dir") for e in rep.get("superseded", [])}
        for path in sorted((study / SUPERSEDED).glob(REPLICA_DIR.format(index=i) + ".*")):
            where = path.relative_to(study).as_posix()
            if path.is_dir() and where not in known:
                rep.setdefault("superseded", []).append(
                    {"dir": where, "why": "moved aside by the replica's job (see "
                                          f"{REPLICA_LOG.format(index=i)})", "at": None,
                     "slide_steps": None})
                added.append(where)
    return added
