"""Drive LAMMPS to its end and record how the run ended.

:func:`drive` runs the engine (:func:`~.lammps_output.run_engine`), records the restart
files LAMMPS has finished as it goes (:func:`watch`) and hands the end to :func:`finish`:
the trace converted (``trace.csv``), the checks of :mod:`.sanity` (the contract, lost
atoms, NaN, the energy ledger: a run fails; the physics: warnings) and ``run.json`` in
its final state (``completed``, ``completed_with_warnings``, ``failed`` with the engine's
own message, or ``interrupted``: :func:`interrupted`).  Every early exit leaves
``run.json`` in a final state (:func:`abandoned`).  Used by a new run
(:func:`.runner.execute`) and a resumed one (:func:`.resume.resume`).
"""
from __future__ import annotations

import os
from datetime import datetime, timezone
from pathlib import Path

from filmfriction.md_inputs.contract import RUN_FILE, TRACE_DAT_FILE, TRACE_FILE

from . import engine, lammps_build, restarts
from .output.lammps_output import ranks_problem, run_engine
from .run_record import resume_command, start_again_advice, write_json
from .output.sanity import (contract_message, contract_problem, lost_atoms_hint, rows_problem,
                     sanity_warnings, trace_problem)
from .scene import Scene
from .signals import Terminated
from .output.trace_dat import read_trace_dat, write_trace_csv

__all__ = ["RunFailed", "ContractBroken", "abandoned", "interrupted", "watch", "drive",
           "finish"]


class RunFailed(RuntimeError):
    """LAMMPS stopped with an error, lost atoms, or produced NaN; see ``run.json``.

    ``resumable`` is True when the run stopped for a reason outside the simulation (its
    engine ended with a nonzero exit and no error message of its own, i.e. it was
    killed; a full disk) and holds a usable restart file: :func:`.resume.resume` continues it.
    A failure of the simulation itself (LAMMPS's ERROR, lost atoms, NaN, a short or
    broken trace) is not: a resume would repeat it.
    """

    def __init__(self, message: str, run_dir: Path, resumable: bool = False):
        super().__init__(message)
        self.run_dir = run_dir
        self.resumable = resumable


class ContractBroken(RuntimeError):
    """The script's ``trace.dat`` does not follow ``md_inputs/contract.py``."""


def abandoned(run_dir: Path, record: dict | None, exc: BaseException) -> None:
    """A run or a resume left by an exception other than an interruption: a record
    still ``running`` is set ``failed`` with the exception's text (every early exit
    leaves ``run.json`` in a final state)."""
    if record is None or record.get("status") != "running":
        return
    record.update(status="failed", error=str(exc) or type(exc).__name__,
                  finished=datetime.now(timezone.utc).isoformat())
    try:
        write_json(run_dir / RUN_FILE, record)
    except OSError:
        pass


def interrupted(run_dir: Path, record: dict | None, scene: Scene, exc: KeyboardInterrupt):
    """Record an interruption (Ctrl-C, SIGTERM, SIGHUP) at any stage of a run or a resume:
    ``run.json`` says ``interrupted``, with the resume command when a usable restart
    exists, and never stays ``running``.  Sets ``exc.run_dir`` and ``exc.resume_command``
    (None: nothing to resume) for the command line.  Once recorded, does nothing."""
    if getattr(exc, "run_dir", None) is not None:
        return
    exc.run_dir, exc.resume_command = run_dir, None
    why = f"by {exc}" if isinstance(exc, Terminated) else "by the user (SIGINT)"
    if record is None:          # before the record was built: the least that says what ran
        record = {"schema": "filmfriction.run/1", "scene": scene.as_dict(), "segments": [],
                  "started": datetime.now(timezone.utc).isoformat()}
    started = (run_dir / "lammps.screen").exists()
    if restarts.usable(run_dir):
        exc.resume_command = record["resume_command"] = resume_command(run_dir)
        message = f"interrupted {why}; resume with {exc.resume_command}"
    else:
        record.pop("resume_command", None)
        stage = "before LAMMPS started" if not started else "before the first restart file"
        message = (f"interrupted {why} {stage}: nothing to resume (no usable restart file); "
                   + start_again_advice(run_dir, record.get("np")))
    try:
        if started:
            finish(run_dir, record, scene, None, message, status="interrupted")
        else:
            record.update(status="interrupted", error=message, warnings=[],
                          finished=datetime.now(timezone.utc).isoformat())
            write_json(run_dir / RUN_FILE, record)
    except OSError:
        pass                    # a full disk: the interruption is still reported


def watch(run_dir: Path, scene: Scene):
    """``on_step`` for the engine: record the restarts LAMMPS has finished; for a
    scene's own script, check the trace contract on the first rows (ContractBroken
    stops LAMMPS).  The shipped script is held to it by tests/test_md_contract.py."""
    ledger = restarts.RestartLedger(run_dir)
    checked = not scene.script

    def on_step(step: int) -> None:
        nonlocal checked
        ledger.record_below(step)
        if not checked:
            problem, rows = contract_problem(run_dir, scene)
            if problem:
                raise ContractBroken(contract_message(problem))
            checked = rows >= 4
    return on_step


def drive(scene, run_dir, record, cmd, total, start_step, progress):
    """Run the engine's command ``cmd`` from slide step ``start_step`` of ``total`` and
    record the end (:func:`finish`); returns ``run_dir``, raises :class:`RunFailed`."""
    lmp = record.get("lammps", {}).get("path")
    try:
        outcome = run_engine(cmd, run_dir, total, progress=progress, start_step=start_step,
                             label=scene.name, on_step=watch(run_dir, scene),
                             env=engine.engine_env(lmp=Path(lmp) if lmp else None))
    except KeyboardInterrupt as exc:
        interrupted(run_dir, record, scene, exc)
        raise
    except ContractBroken as exc:
        return finish(run_dir, record, scene, None, str(exc))
    except engine.EngineNotFound as exc:
        finish(run_dir, record, scene, None, str(exc))
        raise RunFailed(str(exc), run_dir) from exc
    except OSError as exc:
        # the launcher or the engine could not be started (gone, not executable)
        program = exc.filename or cmd[0]
        named = (f" (from {lammps_build.LAUNCHER_ENV})"
                 if os.environ.get(lammps_build.LAUNCHER_ENV) and program == cmd[0] else "")
        message = f"cannot start {program}{named}: {exc.strerror or exc}"
        finish(run_dir, record, scene, None, message)
        raise RunFailed(f"run failed: {message}", run_dir) from None
    if outcome.error is None and "-log" in cmd:
        outcome.error = ranks_problem(run_dir / cmd[cmd.index("-log") + 1],
                                      record["layout"]["mpi_ranks"])
    try:
        return finish(run_dir, record, scene, outcome, outcome.error)
    except OSError as exc:
        # a full disk (or another write error): say so, keep the restart files
        good = [p.name for _, p in restarts.usable(run_dir)]
        message = (f"cannot write {exc.filename or run_dir}: {exc.strerror or exc}; the "
                   f"restart files are kept ({good[-1] if good else 'none'} the newest "
                   f"usable): free space, then {resume_command(run_dir)}")
        record.update(status="failed", error=message)
        try:
            write_json(run_dir / RUN_FILE, record)
        except OSError:
            pass
        raise RunFailed(f"run failed: {message}", run_dir, resumable=bool(good)) from None


def finish(run_dir, record, scene, outcome, error, status=None):
    """The end of a run: restarts recorded, ``trace.csv`` written, the checks of
    :mod:`.sanity`, ``run.json`` in its final state (``status`` given: that one);
    :class:`RunFailed` on an ``error`` (the run's own or a check's)."""
    dat = read_trace_dat(run_dir / TRACE_DAT_FILE)
    # LAMMPS has stopped: a clean exit closed every restart file, otherwise the
    # trace's last row vouches for the restarts before it
    clean = outcome is not None and outcome.returncode == 0
    try:
        restarts.RestartLedger(run_dir).record_below(
            None if clean else int(dat[-1, 0]) if len(dat) else 0)
    except OSError:
        pass                    # a full disk: resume then checks the markers only
    write_trace_csv(dat, run_dir / TRACE_FILE)
    if error is None and outcome is not None:
        problem = contract_problem(run_dir, scene)[0] if scene.script else None
        error = contract_message(problem) if problem else trace_problem(dat, scene)
        # fix print writes on multiples of trace_every: the last row is the last
        # such multiple, which is below slide_steps when trace_every does not divide it
        error = error or rows_problem(run_dir, dat, scene, outcome.returncode)
    if error and "Lost atoms" in error:
        error += lost_atoms_hint(scene)
    seg = {"finished": datetime.now(timezone.utc).isoformat(), "rows": int(len(dat))}
    if outcome is not None:
        seg.update(wall_time=outcome.wall_time, returncode=outcome.returncode,
                   atom_steps_per_second=outcome.atom_steps_per_second)
        if outcome.film_atoms is not None:
            record["atoms"] = {"film": outcome.film_atoms, "top_wall": outcome.top_atoms,
                               "total": outcome.total_atoms}
            record["trace_parameters"]["area"] = outcome.area
            record["trace_parameters"]["film_mass"] = float(outcome.film_atoms) or None
    record["segments"].append(seg)
    record["wall_time"] = sum(s.get("wall_time", 0.0) for s in record["segments"])
    perf = [x for s in record["segments"] for x in s.get("atom_steps_per_second") or []]
    if perf:
        # the last figure is the slide, the one that matters for cost
        record["atom_steps_per_second"] = perf[-1]
    record["finished"] = seg["finished"]
    warnings = sanity_warnings(dat, scene) if not error and status is None else []
    record["warnings"] = warnings
    record["status"] = status or ("failed" if error else
                                  "completed_with_warnings" if warnings else "completed")
    record["error"] = error
    write_json(run_dir / RUN_FILE, record)
    if status == "interrupted":
        return run_dir
    if error:
        killed = outcome is not None and outcome.killed and error == outcome.error
        raise RunFailed(f"run failed: {error}\n(partial results kept in {run_dir})", run_dir,
                        resumable=killed and bool(restarts.usable(run_dir)))
    restarts.prune(run_dir)
    return run_dir
