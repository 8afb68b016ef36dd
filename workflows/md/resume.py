"""Continue a run from its newest usable restart file (``filmfriction run --resume``).

The run's record (``run.json``) is read back and checked, the restart files checked
(:mod:`.restarts`), the energy ledger's running sums at the restart step taken from the
trace, the trace trimmed to the restart step, and LAMMPS started from the restart file;
its end is recorded as a new run's (:mod:`.finish`).  ``slide_steps`` continues a run (a
completed one too) to a longer slide (:func:`.target.extend_record`).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from filmfriction import md_inputs
from filmfriction.analysis.files.util import write_atomic
from filmfriction.md_inputs.contract import (DAT_COLUMNS, RESUME_OFFSETS, RUN_FILE, SCENE_FILE,
                                             TRACE_DAT_FILE)

from . import engine, finish, lammps_build, restarts
from .locks import RunLock
from .run_record import (OWN_SCRIPT, SCRIPT, resume_command, scene_toml, start_again_advice,
                         write_json)
from .scene import SceneError
from .signals import TerminationAsInterrupt
from .output.trace_dat import read_trace_dat, rewrite_trace_dat, slide_origin

__all__ = ["resume"]


def resume(run_dir: Path, nprocs: int | None = None, progress: bool = True,
           lmp: str | Path | None = None, launcher: list[str] | None = None,
           slide_steps: int | None = None) -> Path:
    """Continue an interrupted or failed run from its newest usable restart file.

    ``nprocs`` None: the ranks the run last ran on (``run.json``'s ``np``).
    ``launcher``: what starts the MPI ranks, as for :func:`execute` (None: the venv's
    ``mpiexec``, or ``$FILMFRICTION_MPIEXEC`` for a site build); a sweep point that
    started under ``srun`` resumes under ``srun``.
    ``lmp`` None: as for a new run (``$FILMFRICTION_LMP``, else the wheel's); the
    path ``run.json`` records is never run.  When the build differs from the
    recorded one (version, packages or the executable's SHA-256), one line on
    stderr says so and ``run.json``'s ``notes`` keep it.
    The directory is locked for the whole resume: a second one is refused.
    ``slide_steps``: continue to a longer slide (a completed run too), from the newest
    restart file (:func:`filmfriction.workflows.md.replicas.target.extend_parameters` says what is
    accepted); ``run.json`` and ``scene.toml`` then hold the longer slide.
    """
    run_dir = Path(run_dir)
    if not (run_dir / RUN_FILE).exists():
        raise SceneError(f"{run_dir} is not a run directory (no run.json)")
    with TerminationAsInterrupt():
        lock = RunLock(run_dir).acquire()
        state = {"record": None, "scene": None}
        try:
            return _resume(run_dir, nprocs, progress, state, lmp, launcher, slide_steps)
        except KeyboardInterrupt as exc:
            if state["record"] is not None:      # run.json was (being) set to running
                finish.interrupted(run_dir, state["record"], state["scene"], exc)
            elif getattr(exc, "run_dir", None) is None:   # run.json untouched: as it was
                exc.run_dir = run_dir
                exc.resume_command = resume_command(run_dir) if restarts.usable(run_dir) else None
            raise
        except BaseException as exc:
            finish.abandoned(run_dir, state["record"], exc)
            raise
        finally:
            lock.release()


def _resume(run_dir: Path, nprocs: int | None, progress: bool, state: dict, lmp,
            launcher: list[str] | None = None, slide_steps: int | None = None) -> Path:
    from . import scene as scene_mod

    record_path = run_dir / RUN_FILE
    try:
        record = json.loads(record_path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise SceneError(f"{record_path}: not a readable run record ({exc})") from None
    if not isinstance(record, dict) or not isinstance(record.get("scene"), dict):
        raise SceneError(f"{record_path}: not a run record (a JSON object with a scene)")
    from filmfriction.analysis.files.documents import check_document

    try:
        check_document(record, "run-resume", record_path)
    except ValueError as exc:
        raise SceneError(str(exc)) from None
    if slide_steps is not None:
        from .replicas.target import extend_record

        extend_record(run_dir, record, slide_steps)
    elif record.get("status") in ("completed", "completed_with_warnings"):
        raise SceneError(f"{run_dir} already completed; nothing to resume")
    good, bad = restarts.check(run_dir)
    if bad:
        record["unusable_restarts"] = bad
    if not good:
        why = "".join(f"; {name}: {reason}" for name, reason in bad.items())
        raise SceneError(f"{run_dir} has no usable restart file to resume from (restart_every = "
                         f"{record['scene']['parameters'].get('restart_every')}{why}); "
                         + start_again_advice(run_dir, record.get("np")))
    params = record["scene"]["parameters"]
    scene = scene_mod.Scene(
        name=record["scene"]["name"], description=record["scene"]["description"],
        models=record["scene"]["models"],
        # a run directory of a version that called the outputs "observables"
        outputs=tuple(record["scene"].get("outputs", record["scene"].get("observables", ()))),
        expected_cost=record["scene"]["expected_cost"],
        parameters=scene_mod.resolve(params), source=record["scene"].get("source", ""),
        script=record["scene"].get("script", ""),
        lammps_packages=tuple(record["scene"].get("lammps_packages", ["RIGID"])))
    script = (run_dir / OWN_SCRIPT).resolve() if scene.script else md_inputs.script(SCRIPT)
    if scene.script and not script.is_file():
        raise SceneError(f"{script} is missing: the run's own LAMMPS script; cannot resume")
    nprocs = nprocs or int(record.get("np", 2))
    threads = int((record.get("layout") or {}).get("omp_threads", 1))
    # the LAMMPS of this installation (or --lmp), never a path read from the
    # directory: a run directory is data, not a program to execute
    build, launcher = lammps_build.choose(lmp, "--lmp", scene, nprocs, launcher, script, threads)
    changed = lammps_build.differs(record.get("lammps"), build)
    if changed:
        record.setdefault("notes", []).append(changed)
        print(f"filmfriction run: note: {changed}", file=sys.stderr)
    dat = read_trace_dat(run_dir / TRACE_DAT_FILE, raw=True)
    col = {c: i for i, c in enumerate(DAT_COLUMNS)}
    # the ledger's running sums at the restart step: the first row printed there
    # (remembered in run.json, so a resume cut off before LAMMPS prints that row
    # again, then resumed, starts from the same sums).  The newest restart whose
    # sums are known: a trace cut short (a full disk) may lack the newest's row.
    offsets = record.setdefault("resume_offsets", {})
    for step, restart in reversed(good):
        at = dat[dat[:, 0] == step] if len(dat) else dat
        if len(at):
            offsets.setdefault(str(step), {n: float(at[0][col[n]]) for n in RESUME_OFFSETS})
        if str(step) in offsets:
            sums = offsets[str(step)]
            break
    else:
        raise SceneError(f"{run_dir}/trace.dat has no row at any restart step "
                         f"({', '.join(p.name for _, p in good)}): cannot carry the energy "
                         "ledger exactly; start a new run")
    keep = read_trace_dat(run_dir / TRACE_DAT_FILE)
    keep = keep[keep[:, 0] < step] if len(keep) else keep
    # trace positions are relative to the slide's start; LAMMPS saved that origin
    # (read before trace.dat is trimmed, so a refusal loses nothing)
    origin = slide_origin(run_dir)
    # the record first (the sums at the restart step), then the trimmed trace
    record["status"] = "running"
    record["resumed_from"] = restart.name
    record["np"] = nprocs
    record["layout"] = {"cores": nprocs * threads, "mpi_ranks": nprocs, "omp_threads": threads}
    variables = scene.lammps_variables()
    variables.update({"resume": "1", "restart_file": restart.name})
    variables["drive_origin"], variables["wall_z0"] = origin
    variables.update({name: repr(sums[column]) for column, name in RESUME_OFFSETS.items()})
    total = scene.parameters["equilibrate_steps"] + scene.parameters["slide_steps"]
    variables["thermo_every"] = str(max(100, min(2000, total // 200)))
    cmd = engine.lmp_command(nprocs, script, variables, log=Path(f"lammps.resume{step}.log"),
                             launcher=launcher, lmp=build.path, threads=threads)
    record["lammps"] = build.as_dict()
    record.setdefault("commands", [record["command"]]).append(cmd)
    state["record"], state["scene"] = record, scene
    if slide_steps is not None:
        record["derived"] = scene.derived()
    write_json(record_path, record)
    if slide_steps is not None:
        write_atomic(run_dir / SCENE_FILE, scene_toml(scene))
    rewrite_trace_dat(run_dir / TRACE_DAT_FILE, keep)
    return finish.drive(scene, run_dir, record, cmd, total,
                  scene.parameters["equilibrate_steps"] + step, progress)
