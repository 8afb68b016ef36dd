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
import re
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from filmfriction import md_inputs
from filmfriction.analysis import energy
from filmfriction.analysis.util import json_default, write_atomic
from filmfriction.md_inputs import contract
from . import engine
from .locks import DirectoryLock
from .scene import Scene, SceneError

SCRIPT = "film_slide.lmp"

# the columns of trace.dat (fix print) and trace.csv, and their LJ units: the
# script's contract (md_inputs/contract.py), re-exported here for callers
DAT_COLUMNS = contract.DAT_COLUMNS
TRACE_COLUMNS = contract.TRACE_COLUMNS
TRACE_UNITS = contract.TRACE_UNITS
DATA_FILE = contract.DATA_FILE


class RunFailed(RuntimeError):
    """LAMMPS stopped with an error, lost atoms, or produced NaN; see ``run.json``."""

    def __init__(self, message: str, run_dir: Path):
        super().__init__(message)
        self.run_dir = run_dir


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
    raise Terminated(signal.Signals(signum).name)


class _TerminationAsInterrupt:
    """While active, SIGTERM and SIGHUP raise :class:`Terminated` (main thread only)."""

    SIGNALS = (signal.SIGTERM, signal.SIGHUP)

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


def write_json(path: Path, data: dict) -> None:
    write_atomic(path, json.dumps(data, indent=2, default=json_default) + "\n")


def versions() -> dict:
    from importlib import metadata

    out = {"python": platform.python_version()}
    for pkg in ("filmfriction", "lammps", "mpich", "numpy", "scipy", "MDAnalysis"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def new_run_dir(scene_name: str, out: Path | None) -> Path:
    """Create a fresh run directory; never reuse an existing one."""
    from .scene import SAFE_NAME

    if not SAFE_NAME.fullmatch(scene_name):
        raise SceneError(f"scene name {scene_name!r} is not a safe directory name")
    if out is None:
        stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
        base = Path("runs") / f"{scene_name}-{stamp}"
        base.parent.mkdir(parents=True, exist_ok=True)
        for i in range(1000):
            candidate = base if i == 0 else base.with_name(f"{base.name}-{i}")
            try:
                candidate.mkdir()
                return candidate
            except FileExistsError:
                continue
        raise SceneError(f"could not create a new run directory under {base.parent}")
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        out.mkdir()
    except FileExistsError:
        raise SceneError(
            f"run directory {out} already exists: a run never overwrites another; "
            f"choose a new --out, or continue it with --resume {out}") from None
    return out


def scene_toml(scene: Scene) -> str:
    lines = [f"# resolved scene, as run ({datetime.now(timezone.utc).isoformat()})",
             f"name = {json.dumps(scene.name)}",
             f"description = {json.dumps(scene.description)}",
             f"models = {json.dumps(scene.models)}",
             f"observables = {json.dumps(list(scene.observables))}",
             f"expected_cost = {json.dumps(scene.expected_cost)}",
             "", "[parameters]"]
    from .scene import PARAMETERS

    for name, value in scene.parameters.items():
        lines.append(f"{name} = {value!r}  # {PARAMETERS[name].unit}")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- the engine
_THERMO_LINE = re.compile(r"^\s*(\d+)\s+[-+0-9.eE]+")
_STAGE = re.compile(r"^FILMFRICTION stage (\w+) (\d+)")
_ATOMS = re.compile(r"^FILMFRICTION atoms film=(\d+) top=(\d+) area=([0-9.eE+-]+)")
_PERF = re.compile(r"Performance: .*?([0-9.]+) timesteps/s, ([0-9.]+) (\w?)atom-step/s")
_ATOMS_TOTAL = re.compile(r"Loop time of [0-9.]+ on \d+ procs for \d+ steps with (\d+) atoms")
_SI_PREFIX = {"": 1.0, "k": 1e3, "M": 1e6, "G": 1e9}


def atom_steps_per_second(line: str) -> float | None:
    """Throughput from a LAMMPS "Performance:" line (None for any other line)."""
    m = _PERF.search(line)
    return float(m.group(2)) * _SI_PREFIX.get(m.group(3), 1.0) if m else None


def loop_atoms(line: str) -> int | None:
    """Atom count from a LAMMPS "Loop time of ..." line (None for any other line)."""
    m = _ATOMS_TOTAL.search(line)
    return int(m.group(1)) if m else None


@dataclass
class EngineOutcome:
    returncode: int
    error: str | None
    film_atoms: int | None = None
    top_atoms: int | None = None
    total_atoms: int | None = None
    area: float | None = None
    atom_steps_per_second: list | None = None
    wall_time: float = 0.0


def run_engine(cmd: list[str], cwd: Path, total_steps: int, progress: bool = True,
               start_step: int = 0, label: str = "") -> EngineOutcome:
    """Run LAMMPS, stream a progress bar from its thermo lines, collect errors."""
    from tqdm import tqdm

    t0 = time.perf_counter()
    stage_offset = 0
    stage_name = "resume" if start_step else "setup"
    errors: list[str] = []
    outcome = EngineOutcome(returncode=0, error=None, atom_steps_per_second=[])
    bar = tqdm(total=total_steps, initial=start_step, unit="step", disable=not progress,
               desc=label or "lammps", dynamic_ncols=True, file=sys.stderr, smoothing=0.1)
    with open(cwd / "lammps.screen", "a") as screen:
        proc = subprocess.Popen(cmd, cwd=cwd, env=engine.engine_env(), stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, bufsize=1,
                                start_new_session=True)
        done = start_step
        try:
            for line in proc.stdout:
                screen.write(line)
                if "ERROR" in line or "Lost atoms" in line:
                    errors.append(line.strip())
                m = _STAGE.match(line)
                if m:
                    if m.group(1) == "slide" and stage_name == "equilibrate":
                        stage_offset = done
                    stage_name = m.group(1)
                    bar.set_description(f"{label} {stage_name}".strip())
                    continue
                m = _ATOMS.match(line)
                if m:
                    outcome.film_atoms, outcome.top_atoms = int(m.group(1)), int(m.group(2))
                    outcome.area = float(m.group(3))
                    continue
                rate = atom_steps_per_second(line)
                if rate is not None:
                    outcome.atom_steps_per_second.append(rate)
                    continue
                atoms = loop_atoms(line)
                if atoms is not None:
                    outcome.total_atoms = atoms
                    continue
                m = _THERMO_LINE.match(line)
                if m and stage_name in ("equilibrate", "slide", "resume"):
                    step = int(m.group(1)) + (stage_offset if stage_name == "slide" else 0)
                    if step > done:
                        bar.update(min(step, total_steps) - done)
                        done = min(step, total_steps)
            proc.wait()
        except KeyboardInterrupt:
            os.killpg(proc.pid, signal.SIGTERM)
            proc.wait()
            bar.close()
            raise
        finally:
            bar.close()
    outcome.returncode = proc.returncode
    outcome.wall_time = time.perf_counter() - t0
    if errors:
        outcome.error = errors[0]
    elif proc.returncode != 0:
        outcome.error = f"LAMMPS exited with code {proc.returncode} (see lammps.screen)"
    return outcome


# ---------------------------------------------------------------- the trace
def read_trace_dat(path: Path, raw: bool = False) -> np.ndarray:
    """Rows of ``trace.dat``; a final line cut off by a crash is dropped.

    A segment's first row repeats the previous segment's last step (the script
    prints at each segment's start): the later row is kept, the one a resumed
    job prints; ``raw`` keeps every row as printed.
    """
    rows = []
    if not path.exists():
        return np.empty((0, len(DAT_COLUMNS)))
    for line in path.read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        parts = line.split()
        if len(parts) != len(DAT_COLUMNS):
            continue
        try:
            rows.append([float(x) for x in parts])
        except ValueError:
            continue
    table = np.array(rows, dtype=float).reshape(-1, len(DAT_COLUMNS))
    if raw or len(table) < 2:
        return table
    later = np.append(table[1:, 0] != table[:-1, 0], True)   # last of each run of a step
    return table[later]


def write_trace_csv(dat: np.ndarray, path: Path) -> None:
    """trace.csv in TRACE_COLUMNS order, written atomically."""
    index = [DAT_COLUMNS.index(c) for c in TRACE_COLUMNS]
    table = dat[:, index] if len(dat) else np.empty((0, len(TRACE_COLUMNS)))
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    fmt = ["%d" if c == "step" else "%.10g" for c in TRACE_COLUMNS]
    np.savetxt(tmp, table, delimiter=",", header=",".join(TRACE_COLUMNS), comments="", fmt=fmt)
    os.replace(tmp, path)


# Largest energy-ledger residual accepted, as a fraction of the energy turned
# over (work in or heat out).  Validated runs stay below 1 % (the default run
# 0.2 %; the LJ-limit step, the highest load, the lightest wall 0.5-1 %); a
# timestep twice the LJ limit (validator bypassed) leaves 8-16 % while the
# thermostat keeps the temperature looking normal, so only the ledger shows it.
LEDGER_LIMIT = 0.05


def trace_problem(dat: np.ndarray, scene: Scene) -> str | None:
    """A blow-up the engine did not flag itself: NaN, runaway temperature, broken ledger."""
    if not len(dat):
        return None
    if not np.all(np.isfinite(dat)):
        row = int(np.argmax(~np.all(np.isfinite(dat), axis=1)))
        return f"NaN or infinite value in the trace at step {int(dat[row, 0])}"
    T = dat[:, DAT_COLUMNS.index("film_temperature")]
    limit = max(20.0 * scene.parameters["temperature"], 5.0)
    if np.any(T > limit):
        row = int(np.argmax(T > limit))
        return (f"film temperature {T[row]:.3g} epsilon/k_B at step {int(dat[row, 0])} exceeds "
                f"{limit:.3g}: the integration blew up (timestep too large for the forces?)")
    return ledger_problem(dat, scene)


def lost_atoms_hint(scene: Scene) -> str:
    """Why atoms leave the box, for the engine's bare "Lost atoms" message: the
    likely causes found in the actual parameters, most likely first."""
    from .scene import FLEXIBLE_WALL_MAX_TEMPERATURE, derived_quantities

    p = scene.parameters
    d = derived_quantities(p)
    causes = []
    limit = d["timestep_limit"]
    if p["timestep"] > limit:
        causes.append(f"timestep {p['timestep']:g} tau is above the stability limit "
                      f"{limit:.3g} tau")
    elif p["timestep"] > 0.7 * limit:
        causes.append(f"timestep {p['timestep']:g} tau is close to the stability limit "
                      f"{limit:.3g} tau")
    mismatch = p["film_spacing"] / p["wall_spacing"] - 1.0
    strain = max(abs(d["film_strain_x"]), abs(d["film_strain_y"]))
    if p["film_spacing"] < 1.0 or abs(mismatch) > 0.1 or strain > 0.05:
        causes.append(f"film_spacing {p['film_spacing']:g} sigma against wall_spacing "
                      f"{p['wall_spacing']:g} sigma (mismatch {100 * mismatch:+.0f} %, film "
                      f"strained {100 * strain:.0f} %): overlapping atoms start with huge "
                      f"forces")
    if p["temperature"] > 1.3:
        causes.append(f"temperature {p['temperature']:g} epsilon/k_B is above the LJ "
                      f"critical temperature 1.3: the film boils and pushes the wall off")
    elif p["wall_model"] == "flexible" and p["temperature"] > 0.8 * FLEXIBLE_WALL_MAX_TEMPERATURE:
        causes.append(f"temperature {p['temperature']:g} epsilon/k_B is near the flexible "
                      f"walls' limit {FLEXIBLE_WALL_MAX_TEMPERATURE:g}")
    if p["normal_pressure"] < 0.5 * max(p["temperature"], 0.1):
        causes.append(f"normal_pressure {p['normal_pressure']:g} is low for temperature "
                      f"{p['temperature']:g}: the film can push the top wall off")
    if p["drive_velocity"] > 1.0:
        causes.append(f"drive_velocity {p['drive_velocity']:g} sigma/tau is fast: the film "
                      f"heats faster than the thermostat cools it")
    if not causes:
        return (" (atoms left the box: none of timestep, spacing, temperature, pressure or "
                "velocity looks extreme; see lammps.screen)")
    return " (atoms left the box; likely cause: " + "; ".join(causes) + ")"


# Physics sanity of a finished run: a run outside one of these is
# "completed_with_warnings" (it still counts, but read it with care).
# Validated runs: the thermostat holds the film within ~10 % of its set point,
# the gap moves by a few % (dilation at slips), the ledger closes below 1 %.
TEMPERATURE_TOLERANCE = 0.3     # |<T_film> - T| / T over the slide's second half
GAP_DRIFT_TOLERANCE = 0.15      # |gap(end) - gap(start)| / gap(start), 10 % windows
WALL_SPEED_TOLERANCE = 0.2      # |<v_wall> - V| / V in steady sliding (never stuck)
LEDGER_WARNING = 0.02           # residual / turnover (a run fails at LEDGER_LIMIT)


def sanity_warnings(dat: np.ndarray, scene: Scene) -> list[str]:
    """The physics checks of a run that completed: each broken one as a line
    naming the check and the values (empty: all passed)."""
    if len(dat) < 10:
        return []
    p = scene.parameters
    col = {c: dat[:, i] for i, c in enumerate(DAT_COLUMNS)}
    n = len(dat)
    half = slice(n // 2, None)
    out = []
    T = float(np.mean(col["film_temperature"][half]))
    tol = TEMPERATURE_TOLERANCE * (1.5 if p["thermostat_placement"] == "walls" else 1.0)
    ref = max(p["temperature"], 0.05)
    if abs(T - p["temperature"]) > tol * ref:
        out.append(f"film temperature: mean {T:.3g} epsilon/k_B over the slide's second half "
                   f"against the set point {p['temperature']:g} (tolerance "
                   f"{100 * tol:.0f} %): the thermostat does not hold the film (drive_velocity "
                   f"{p['drive_velocity']:g}, thermostat_damping {p['thermostat_damping']:g})")
    w = max(1, n // 10)
    g0, g1 = float(np.mean(col["gap"][:w])), float(np.mean(col["gap"][-w:]))
    if g0 > 0 and abs(g1 - g0) > GAP_DRIFT_TOLERANCE * g0:
        out.append(f"gap drift: the gap went from {g0:.3g} to {g1:.3g} sigma over the slide "
                   f"({100 * (g1 / g0 - 1):+.0f} %, tolerance {100 * GAP_DRIFT_TOLERANCE:.0f} "
                   f"%): the film is expanding or squeezed out")
    V = p["drive_velocity"]
    v = col["wall_velocity"][half]
    if V > 0 and np.min(v) > 0.2 * V:       # steady sliding: the wall never sticks
        t, x = col["time"][half], col["wall_position"][half]
        mean_v = float((x[-1] - x[0]) / (t[-1] - t[0])) if t[-1] > t[0] else float(np.mean(v))
        if abs(mean_v - V) > WALL_SPEED_TOLERANCE * V:
            out.append(f"wall speed: {mean_v:.3g} sigma/tau in steady sliding against the drive "
                       f"V = {V:g} (tolerance {100 * WALL_SPEED_TOLERANCE:.0f} %): not yet "
                       f"steady, or the wall slips past the drive")
    led = energy.ledger({c: col[c] for c in energy.LEDGER_COLUMNS + ("mount_heat",)})
    residual, turnover = float(led["residual"][-1]), led["turnover"]
    if turnover > 0 and abs(residual) > LEDGER_WARNING * turnover:
        out.append(f"energy ledger: residual {residual:.3g} epsilon is "
                   f"{100 * abs(residual) / turnover:.1f} % of the turnover {turnover:.3g} "
                   f"epsilon (warning above {100 * LEDGER_WARNING:.0f} %, failure above "
                   f"{100 * LEDGER_LIMIT:.0f} %)")
    return out


def ledger_problem(dat: np.ndarray, scene: Scene) -> str | None:
    """The integrator created or destroyed energy beyond LEDGER_LIMIT of the turnover."""
    led = energy.ledger({n: dat[:, DAT_COLUMNS.index(n)]
                         for n in energy.LEDGER_COLUMNS + ("mount_heat",)})
    residual, turnover = float(led["residual"][-1]), led["turnover"]
    if turnover > 0 and abs(residual) > LEDGER_LIMIT * turnover:
        return (f"energy ledger does not close: residual {residual:.3g} epsilon is "
                f"{100 * abs(residual) / turnover:.0f} % of the energy turned over "
                f"({turnover:.3g} epsilon; limit {100 * LEDGER_LIMIT:.0f} %): the integration "
                f"is inaccurate (timestep {scene.parameters['timestep']:g} tau too large for "
                f"the forces?)")
    return None


# ---------------------------------------------------------------- the run
def _record(scene: Scene, run_dir: Path, cmd: list[str], nprocs: int) -> dict:
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
            "area": d["area"], "thickness": None, "drive_velocity": p["drive_velocity"],
            "mount_damping": (p["mount_damping"] * p["wall_mass"]) or None,
            "units": "lj",
        },
        "trace_units": TRACE_UNITS,
        "command": cmd, "np": nprocs, "cwd": str(run_dir.resolve()),
        "seeds": {"seed": p["seed"]},
        "versions": versions(),
        "host": {"machine": platform.machine(), "cpus": os.cpu_count()},
        "started": datetime.now(timezone.utc).isoformat(),
        "segments": [],
    }


def execute(scene: Scene, out: Path | None = None, nprocs: int = 2,
            progress: bool = True, launcher: list[str] | None = None) -> Path:
    """Run ``scene`` in a new directory and return it; raise RunFailed on failure.

    ``launcher`` starts the MPI ranks instead of the venv's ``mpiexec`` (e.g.
    ``["srun"]`` for a sweep point inside a Slurm allocation).
    """
    run_dir = new_run_dir(scene.name, out)
    lock = RunLock(run_dir).acquire()
    try:
        return _execute(scene, run_dir, nprocs, progress, launcher)
    finally:
        lock.release()


def _execute(scene, run_dir, nprocs, progress, launcher):
    if scene.writes_profiles:
        (run_dir / "profiles").mkdir()
    variables = scene.lammps_variables()
    total = scene.parameters["equilibrate_steps"] + scene.parameters["slide_steps"]
    variables["thermo_every"] = str(max(100, min(2000, total // 200)))
    cmd = engine.lmp_command(nprocs, md_inputs.script(SCRIPT), variables, log=Path("lammps.log"),
                             launcher=launcher)
    write_atomic(run_dir / "scene.toml", scene_toml(scene))
    # the walls and the film, built with ASE: the script reads them (read_data)
    write_atomic(run_dir / DATA_FILE, scene.geometry().lammps_data())
    write_atomic(run_dir / "command.txt", _shell_line(cmd) + "\n")
    record = _record(scene, run_dir, cmd, nprocs)
    write_json(run_dir / "run.json", record)
    return _drive(scene, run_dir, record, cmd, total, 0, progress)


def resume_command(run_dir: Path) -> str:
    return f"filmfriction run --resume {_shell_line([str(run_dir)])}"


def _drive(scene, run_dir, record, cmd, total, start_step, progress):
    try:
        with _TerminationAsInterrupt():
            outcome = run_engine(cmd, run_dir, total, progress=progress,
                                 start_step=start_step, label=scene.name)
    except KeyboardInterrupt as exc:
        why = f"by {exc}" if isinstance(exc, Terminated) else "by the user (SIGINT)"
        record["resume_command"] = resume_command(run_dir)
        _finish(run_dir, record, scene, None, f"interrupted {why}; resume with "
                f"{record['resume_command']}", status="interrupted")
        exc.run_dir = run_dir
        raise
    except engine.EngineNotFound as exc:
        _finish(run_dir, record, scene, None, str(exc))
        raise RunFailed(str(exc), run_dir) from exc
    try:
        return _finish(run_dir, record, scene, outcome, outcome.error)
    except OSError as exc:
        # a full disk (or another write error): say so, keep the restart files
        restarts = [p.name for _, p in _usable_restarts(run_dir)]
        message = (f"cannot write {exc.filename or run_dir}: {exc.strerror or exc}; the "
                   f"restart files are kept ({restarts[-1] if restarts else 'none'} the newest "
                   f"usable): free space, then {resume_command(run_dir)}")
        record.update(status="failed", error=message)
        try:
            write_json(run_dir / "run.json", record)
        except OSError:
            pass
        raise RunFailed(f"run failed: {message}", run_dir) from None


def _finish(run_dir, record, scene, outcome, error, status=None):
    dat = read_trace_dat(run_dir / "trace.dat")
    write_trace_csv(dat, run_dir / "trace.csv")
    if error is None and outcome is not None:
        error = trace_problem(dat, scene)
        # fix print writes on multiples of trace_every: the last row is the last
        # such multiple, which is below slide_steps when trace_every does not divide it
        every = scene.parameters["trace_every"]
        last_row = scene.parameters["slide_steps"] // every * every
        if error is None and len(dat) and dat[-1, 0] < last_row:
            error = (f"LAMMPS stopped at step {int(dat[-1, 0])} of "
                     f"{scene.parameters['slide_steps']} without an error message")
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
    write_json(run_dir / "run.json", record)
    if status == "interrupted":
        return run_dir
    if error:
        raise RunFailed(f"run failed: {error}\n(partial results kept in {run_dir})", run_dir)
    _prune_restarts(run_dir)
    return run_dir


def _prune_restarts(run_dir: Path) -> None:
    """Keep only the newest restart file: the one --resume would use."""
    files = _restart_files(run_dir)
    for _, path in files[:-1]:
        path.unlink(missing_ok=True)


def _usable_restarts(run_dir: Path) -> list[tuple[int, Path]]:
    """Restart files that were written whole: every restart of a run has the same
    size (same atoms), so a shorter one was cut off (a full disk, a kill)."""
    files = _restart_files(run_dir)
    sizes = [p.stat().st_size for _, p in files]
    full = max(sizes, default=0)
    return [(step, p) for (step, p), size in zip(files, sizes) if size == full and size > 0]


def _restart_files(run_dir: Path) -> list[tuple[int, Path]]:
    found = []
    for p in run_dir.glob("restart.*"):
        suffix = p.name.split(".", 1)[1]
        if suffix.isdigit():
            found.append((int(suffix), p))
    return sorted(found)


def resume(run_dir: Path, nprocs: int | None = None, progress: bool = True) -> Path:
    """Continue an interrupted or failed run from its newest restart file.

    ``nprocs`` None: the ranks the run last ran on (``run.json``'s ``np``).
    The directory is locked for the whole resume: a second one is refused.
    """
    run_dir = Path(run_dir)
    if not (run_dir / "run.json").exists():
        raise SceneError(f"{run_dir} is not a run directory (no run.json)")
    lock = RunLock(run_dir).acquire()
    try:
        return _resume(run_dir, nprocs, progress)
    finally:
        lock.release()


def _resume(run_dir: Path, nprocs: int | None, progress: bool) -> Path:
    from . import scene as scene_mod

    record_path = run_dir / "run.json"
    try:
        record = json.loads(record_path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise SceneError(f"{record_path}: not a readable run record ({exc})") from None
    if not isinstance(record, dict) or not isinstance(record.get("scene"), dict):
        raise SceneError(f"{record_path}: not a run record (a JSON object with a scene)")
    if record.get("status") in ("completed", "completed_with_warnings"):
        raise SceneError(f"{run_dir} already completed; nothing to resume")
    restarts = _usable_restarts(run_dir)
    if not restarts:
        raise SceneError(f"{run_dir} has no usable restart file to resume from (restart_every = "
                         f"{record['scene']['parameters'].get('restart_every')}); start a new run")
    params = record["scene"]["parameters"]
    scene = scene_mod.Scene(
        name=record["scene"]["name"], description=record["scene"]["description"],
        models=record["scene"]["models"], observables=tuple(record["scene"]["observables"]),
        expected_cost=record["scene"]["expected_cost"],
        parameters=scene_mod.resolve(params), source=record["scene"].get("source", ""))
    dat = read_trace_dat(run_dir / "trace.dat", raw=True)
    col = {c: i for i, c in enumerate(DAT_COLUMNS)}
    # the ledger's running sums at the restart step: the first row printed there
    # (remembered in run.json, so a resume cut off before LAMMPS prints that row
    # again, then resumed, starts from the same sums).  The newest restart whose
    # sums are known: a trace cut short (a full disk) may lack the newest's row.
    offsets = record.setdefault("resume_offsets", {})
    for step, restart in reversed(restarts):
        at = dat[dat[:, 0] == step] if len(dat) else dat
        if len(at):
            offsets.setdefault(str(step), {n: float(at[0][col[n]]) for n in LEDGER_SUMS})
        if str(step) in offsets:
            sums = offsets[str(step)]
            break
    else:
        raise SceneError(f"{run_dir}/trace.dat has no row at any restart step "
                         f"({', '.join(p.name for _, p in restarts)}): cannot carry the energy "
                         "ledger exactly; start a new run")
    keep = read_trace_dat(run_dir / "trace.dat")
    keep = keep[keep[:, 0] < step] if len(keep) else keep
    # trace positions are relative to the slide's start; LAMMPS saved that origin
    # (read before trace.dat is trimmed, so a refusal loses nothing)
    origin = _slide_origin(run_dir)
    nprocs = nprocs or int(record.get("np", 2))
    # the record first (the sums at the restart step), then the trimmed trace
    record["status"] = "running"
    record["resumed_from"] = restart.name
    record["np"] = nprocs
    variables = scene.lammps_variables()
    variables.update({"resume": "1", "restart_file": restart.name})
    variables["drive_origin"], variables["wall_z0"] = origin
    variables["drive_work0"] = repr(sums["drive_work"])
    variables["heat0"] = repr(sums["thermostat_heat"])
    variables["mount_heat0"] = repr(sums["mount_heat"])
    total = scene.parameters["equilibrate_steps"] + scene.parameters["slide_steps"]
    variables["thermo_every"] = str(max(100, min(2000, total // 200)))
    cmd = engine.lmp_command(nprocs, md_inputs.script(SCRIPT), variables,
                             log=Path(f"lammps.resume{step}.log"))
    record.setdefault("commands", [record["command"]]).append(cmd)
    write_json(record_path, record)
    _rewrite_trace_dat(run_dir / "trace.dat", keep)
    return _drive(scene, run_dir, record, cmd, total,
                  scene.parameters["equilibrate_steps"] + step, progress)


# the running sums of the ledger that a resumed LAMMPS continues from
LEDGER_SUMS = ("drive_work", "thermostat_heat", "mount_heat")


def _slide_origin(run_dir: Path) -> tuple[str, str]:
    """Absolute wall x and z at the slide's start (slide_origin.txt, written by LAMMPS)."""
    origin_file = run_dir / "slide_origin.txt"
    if not origin_file.exists():
        raise SceneError(f"{origin_file} is missing: cannot resume")
    x0, z0 = origin_file.read_text().split()
    return repr(float(x0)), repr(float(z0))


def _rewrite_trace_dat(path: Path, rows: np.ndarray) -> None:
    header = "# " + " ".join(DAT_COLUMNS)
    lines = [header] + [" ".join(f"{v:.10g}" for v in r) for r in rows]
    write_atomic(path, "\n".join(lines) + "\n")


def _shell_line(cmd: list[str]) -> str:
    import shlex

    return " ".join(shlex.quote(c) for c in cmd)
