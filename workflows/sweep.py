"""Parameter sweeps: one scene fanned out over a grid, scheduled by Snakemake.

``filmfriction sweep SCENE --grid KEY=START:STOP:N[:log] ...`` plans the grid
here (every point is validated through :func:`workflows.scene.load` before
anything starts), writes it into the sweep directory, and hands the
scheduling to Snakemake (``workflows/sweep.smk``): locally on ``--cores``,
or on a Slurm cluster with ``--profile slurm``.  Nothing here schedules jobs.

A sweep directory holds::

    sweep.json                 the plan: scene, grid, fixed overrides, points
    inputs/<point>.json        resolved parameters of one point (rewritten only
                               when they change, so Snakemake re-runs only that point)
    points/<point>/            a complete run directory (run.json, trace.csv,
                               analysis.json, ...), moved into place atomically
    logs/<point>.*.log         the point's engine and analysis output
    aggregate.json, aggregate.csv, velocity_map.png, vk_map.png (when V x K)
    superseded/, failed/       old or failed run directories, never deleted
    .snakemake/                Snakemake's state (incomplete jobs, its lock)

Point names are ``key=value`` pairs of the grid joined by ``__``, e.g.
``drive_velocity=0.05__spring_constant=100``.

Safety: one sweep per directory at a time (an ``flock`` held by the command
and by Snakemake for the whole sweep, on top of Snakemake's own lock); a
point runs in a fresh hidden directory and is renamed into ``points/`` only
when the run completed, so ``points/<point>/run.json`` exists only for a
complete run; an interrupted sweep is resumed by running the same command.

The aggregate (:func:`aggregate`) reads every point's ``analysis.json`` and
trace and gives friction vs V, the regime per point, the critical velocity
with its bracket, η_eff vs γ̇ with the power-law fit, and the (V, K) map,
overlaid with the reduced model's stick-slip boundary when a calibration is
given.  :func:`load_aggregate` is what the report and the calibration read.
"""
from __future__ import annotations

import argparse
import contextlib
import csv
import fcntl
import io
import json
import math
import os
import shlex
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from analysis.atomic import write_atomic

import numpy as np

__all__ = ["GridAxis", "SweepPoint", "SweepPlan", "CriticalVelocity", "Aggregate",
           "parse_grid", "plan_sweep", "write_plan", "SweepLock", "snakemake_command",
           "run_sweep", "run_point", "analyse_point", "critical_velocity",
           "reduced_model_boundary", "aggregate", "load_aggregate", "register", "SNAKEFILE",
           "PROFILES"]

SNAKEFILE = Path(__file__).with_name("sweep.smk")
PROFILES = Path(__file__).with_name("profiles")
PLAN_SCHEMA = "filmfriction.sweep/1"
POINT_SCHEMA = "filmfriction.sweep-point/1"
AGGREGATE_SCHEMA = "filmfriction.sweep-aggregate/1"
SEPARATOR = "__"          # between key=value pairs in a point name
SIGNIFICANT = 6           # grid values are rounded to this many digits (name == value)
# regimes from analysis.stickslip.classify_regime
STICK_SLIP, SMOOTH, IRREGULAR = "stick-slip", "smooth", "irregular"
# "smooth" means fewer than 2 slips.  A run whose wall moved slower than this fraction of V
# over its last half was stuck for most of it: too short to tell its regime.  Such a point
# is "unresolved" and left out of V_c and of η_eff.
STUCK, STUCK_RATIO = "unresolved", 0.5


def _user_error(message: str) -> Exception:
    from .cli import UserError

    return UserError(message)


# ---------------------------------------------------------------------------
# the grid
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class GridAxis:
    """One swept parameter.

    Attributes
    ----------
    key : str
        A scene parameter (:data:`workflows.scene.PARAMETERS`).
    values : tuple
        The values, typed as the parameter (int or float), in the order given.
    spec : str
        The ``--grid`` text it came from (for messages).
    """

    key: str
    values: tuple
    spec: str


def _round(value: float) -> float:
    return float(f"{value:.{SIGNIFICANT}g}")


def format_value(value) -> str:
    """A grid value as it appears in a point name (ints plain, floats ``%.6g``)."""
    if isinstance(value, str):
        return value
    return str(value) if isinstance(value, int) else f"{value:.{SIGNIFICANT}g}"


def parse_grid(text: str) -> GridAxis:
    """Parse ``KEY=START:STOP:N[:log]`` or ``KEY=V1,V2,...``.

    ``N`` values from START to STOP inclusive, evenly spaced, or evenly in
    log with ``:log`` (START and STOP > 0).  Float values are rounded to
    six significant digits, so a point's name and its value agree.

    Parameters
    ----------
    text : str

    Returns
    -------
    GridAxis

    Raises
    ------
    workflows.scene.SceneError
        Unknown key, malformed range, or values that collapse (an integer
        parameter asked for more values than its range holds).

    Examples
    --------
    >>> parse_grid("drive_velocity=0.01:1:3:log").values
    (0.01, 0.1, 1.0)
    >>> parse_grid("seed=1,2").values
    (1, 2)
    """
    from .scene import PARAMETERS, SceneError, split_parameter

    key, body = split_parameter(text, "--grid", "KEY=START:STOP:N[:log] or KEY=V1,V2,...")
    kind = PARAMETERS[key].kind
    if PARAMETERS[key].choices:
        names = tuple(PARAMETERS[key].check(v.strip()) for v in body.split(",") if v.strip())
        if not names or len(set(names)) != len(names):
            raise SceneError(f"--grid {text!r}: give distinct values from "
                             f"{', '.join(PARAMETERS[key].choices)}, comma-separated")
        return GridAxis(key=key, values=names, spec=text)

    def number(s: str, what: str) -> float:
        try:
            x = float(s)
        except ValueError:
            raise SceneError(f"--grid {text!r}: {what} {s!r} is not a number") from None
        if not math.isfinite(x):
            raise SceneError(f"--grid {text!r}: {what} {s!r} is not finite")
        return x

    if ":" in body:
        parts = body.split(":")
        if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("log", "lin")):
            raise SceneError(f"--grid {text!r}: expected KEY=START:STOP:N or "
                             "KEY=START:STOP:N:log")
        start, stop = number(parts[0], "START"), number(parts[1], "STOP")
        try:
            n = int(parts[2])
        except ValueError:
            raise SceneError(f"--grid {text!r}: N {parts[2]!r} is not a whole number") from None
        if n < 1:
            raise SceneError(f"--grid {text!r}: N = {n}: need at least 1 value")
        log = len(parts) == 4 and parts[3] == "log"
        if log and (start <= 0 or stop <= 0):
            raise SceneError(f"--grid {text!r}: a log range needs START > 0 and STOP > 0")
        if n == 1:
            raw = [start]
        else:
            raw = list(np.geomspace(start, stop, n) if log else np.linspace(start, stop, n))
    else:
        raw = [number(s.strip(), "value") for s in body.split(",") if s.strip()]
        if not raw:
            raise SceneError(f"--grid {text!r}: no values")
    if kind is int:
        values = tuple(int(round(x)) for x in raw)
    else:
        values = tuple(_round(x) for x in raw)
    if len(set(values)) != len(values):
        raise SceneError(f"--grid {text!r}: values repeat after rounding to "
                         f"{'whole numbers' if kind is int else 'six digits'}: "
                         f"{', '.join(format_value(v) for v in values)}")
    return GridAxis(key=key, values=values, spec=text)


@dataclass(frozen=True)
class SweepPoint:
    """One grid point: its name and its grid values (the fixed overrides are the plan's)."""

    name: str
    values: dict = field(hash=False)


@dataclass(frozen=True)
class SweepPlan:
    """What a sweep runs; validated, not yet written.

    Attributes
    ----------
    scene : str
        Scene name.
    scene_source : str
        Absolute path of the scene's TOML file.
    grid : tuple of GridAxis
    fixed : dict
        ``--set`` overrides applied to every point.
    np : int
        MPI ranks per point (the Slurm profile may set its own ``tasks``).
    points : tuple of SweepPoint
        The full product of the grid, first axis slowest.
    parameters : dict
        Point name → resolved parameters (every scene parameter).
    calibration : str or None
        A ``calibration.json`` whose reduced model is overlaid on the (V, K) map.
    """

    scene: str
    scene_source: str
    grid: tuple
    fixed: dict = field(hash=False)
    np: int = 2
    points: tuple = ()
    parameters: dict = field(default_factory=dict, hash=False)
    calibration: str | None = None

    def as_dict(self) -> dict:
        return {"schema": PLAN_SCHEMA, "scene": self.scene, "scene_source": self.scene_source,
                "grid": [{"key": a.key, "values": list(a.values), "spec": a.spec}
                         for a in self.grid],
                "fixed": dict(self.fixed), "np": self.np,
                "points": [{"name": p.name, "values": dict(p.values)} for p in self.points],
                "calibration": self.calibration}


def point_name(values: dict) -> str:
    """``key=value`` pairs joined by ``__``, in grid order."""
    return SEPARATOR.join(f"{k}={format_value(v)}" for k, v in values.items())


def plan_sweep(scene: str, grid: list[str], sets: list[str] | None = None, np_: int = 2,
               calibration: Path | None = None) -> SweepPlan:
    """Parse and validate a sweep; every point is resolved before anything runs.

    Parameters
    ----------
    scene : str
        Scene name or TOML path.
    grid : list of str
        ``--grid`` texts; several make the full product.
    sets : list of str, optional
        ``--set KEY=VALUE`` texts applied to every point.
    np_ : int
        MPI ranks per point.
    calibration : Path, optional
        ``calibration.json`` for the reduced model's boundary on the (V, K) map.

    Raises
    ------
    workflows.scene.SceneError
        With the grid point, the key, the value and the allowed range.
    """
    import itertools

    from .scene import SceneError, load, parse_assignment

    if not grid:
        raise SceneError("give at least one --grid KEY=START:STOP:N[:log]")
    if np_ < 1:
        raise SceneError(f"--np {np_}: need at least 1 MPI rank")
    axes = [parse_grid(g) for g in grid]
    keys = [a.key for a in axes]
    dup = sorted({k for k in keys if keys.count(k) > 1})
    if dup:
        raise SceneError(f"--grid given twice for {', '.join(dup)}: give each key once "
                         "(use KEY=V1,V2,... for an irregular set)")
    fixed: dict = {}
    for text in sets or []:
        k, v = parse_assignment(text)
        if k in keys:
            raise SceneError(f"--set {text!r}: {k} is already swept by --grid")
        fixed[k] = v
    base = load(scene, fixed)       # the scene itself and the fixed values, checked once
    points, params = [], {}
    for combo in itertools.product(*(a.values for a in axes)):
        values = dict(zip(keys, combo))
        name = point_name(values)
        try:
            resolved = load(scene, {**fixed, **values}).parameters
        except SceneError as exc:
            spec = "; ".join(a.spec for a in axes)
            raise SceneError(f"grid point {name} (from --grid {spec}): {exc}") from None
        points.append(SweepPoint(name=name, values=values))
        params[name] = resolved
    if calibration is not None:
        calibration = Path(calibration).resolve()
        if not calibration.is_file():
            raise SceneError(f"--calibration {calibration}: no such file")
    return SweepPlan(scene=base.name, scene_source=str(Path(base.source).resolve()),
                     grid=tuple(axes), fixed=fixed, np=np_, points=tuple(points),
                     parameters=params,
                     calibration=str(calibration) if calibration else None)


# ---------------------------------------------------------------------------
# the sweep directory
# ---------------------------------------------------------------------------
def _dumps(doc) -> str:
    return json.dumps(doc, indent=2, sort_keys=True, default=_json_default) + "\n"


def _json_default(obj):
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating):
        return float(obj)
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(type(obj))


def _write_if_changed(path: Path, text: str) -> bool:
    """Atomic write, skipped when the content is the same: an unchanged mtime is what
    keeps Snakemake from re-running a point whose parameters did not change."""
    if path.exists() and path.read_text() == text:
        return False
    write_atomic(path, text)
    return True


def write_plan(plan: SweepPlan, out: Path) -> list[str]:
    """Write ``sweep.json`` and ``inputs/<point>.json``; return the points whose input changed."""
    out = Path(out)
    (out / "inputs").mkdir(parents=True, exist_ok=True)
    changed = []
    for p in plan.points:
        doc = {"schema": POINT_SCHEMA, "scene": plan.scene, "scene_source": plan.scene_source,
               "overrides": {**plan.fixed, **p.values}, "parameters": plan.parameters[p.name]}
        if _write_if_changed(out / "inputs" / f"{p.name}.json", _dumps(doc)):
            changed.append(p.name)
    _write_if_changed(out / "sweep.json", _dumps(plan.as_dict()))
    return changed


class SweepLock:
    """Exclusive ``flock`` on ``<sweep>/.sweep.lock``: one sweep per directory.

    The kernel releases it when every holder exits, however it exits, so a
    killed sweep never leaves a stale lock.  The file descriptor is passed to
    the Snakemake child, so the lock lasts as long as either process does.
    """

    def __init__(self, directory: Path):
        self.path = Path(directory) / ".sweep.lock"
        self.fd: int | None = None

    def acquire(self) -> "SweepLock":
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 200, 0).decode(errors="replace").strip() or "?"
            os.close(fd)
            raise _user_error(
                f"another sweep is running in {self.path.parent} ({holder}); wait for it, "
                "or give this sweep its own --out") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()} on {os.uname().nodename}\n".encode(), 0)
        os.set_inheritable(fd, True)
        self.fd = fd
        return self

    def release(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


# ---------------------------------------------------------------------------
# Snakemake
# ---------------------------------------------------------------------------
def profile_path(profile: str) -> Path:
    """A profile by name (``slurm``, ``local``: shipped in ``workflows/profiles/``) or path."""
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
    """The ``python -m snakemake`` command line for a sweep directory."""
    cmd = [sys.executable, "-m", "snakemake", "--snakefile", str(SNAKEFILE),
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
        ``mpiexec`` (the venv's) or a command such as ``srun`` (Slurm's ``mpi`` resource).
    """
    import shutil

    from .runner import RunFailed, execute
    from .scene import load

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
    from .study import analyse

    return analyse(Path(run_dir))


# ---------------------------------------------------------------------------
# aggregation
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class CriticalVelocity:
    """Where stick-slip gives way to smooth sliding along V (one group of points).

    ``status`` is ``bracketed`` (``low`` = last stick-slip V below ``high`` =
    first smooth V; ``value`` = √(low·high), the midpoint in log V, and
    ``log10_halfwidth`` = ½·log10(high/low)), ``below_range`` (all smooth:
    V_c < ``high`` = the lowest V), ``above_range`` (no smooth point: V_c >
    ``low`` = the highest V) or ``undetermined``.
    """

    status: str
    value: float | None
    low: float | None
    high: float | None
    log10_halfwidth: float | None
    monotonic: bool
    regimes: dict = field(hash=False)
    note: str = ""

    def as_dict(self) -> dict:
        return {"status": self.status, "value": self.value, "low": self.low, "high": self.high,
                "log10_halfwidth": self.log10_halfwidth,
                "factor": (10 ** self.log10_halfwidth if self.log10_halfwidth is not None
                           else None),
                "monotonic": self.monotonic,
                "regimes": {format_value(v): r for v, r in self.regimes.items()},
                "note": self.note}


def _majority(regimes: list[str]) -> str:
    """A velocity's regime over its points (seeds): the majority, else irregular."""
    for r in (STICK_SLIP, SMOOTH):
        if 2 * regimes.count(r) > len(regimes):
            return r
    return IRREGULAR


def critical_velocity(velocities, regimes) -> CriticalVelocity:
    """Bracket the critical velocity from the regime of each point.

    Parameters
    ----------
    velocities : sequence of float
        Drive velocity of each point (repeats, e.g. seeds, are combined by majority).
    regimes : sequence of str
        ``stick-slip``, ``smooth`` or ``irregular`` per point.

    Returns
    -------
    CriticalVelocity

    Examples
    --------
    >>> cv = critical_velocity([0.01, 0.1, 1.0], ["stick-slip", "stick-slip", "smooth"])
    >>> round(cv.value, 4), round(cv.log10_halfwidth, 3)
    (0.3162, 0.5)
    """
    by_v: dict = {}
    for v, r in zip(velocities, regimes):
        by_v.setdefault(float(v), []).append(r)
    per_v = {v: _majority(rs) for v, rs in sorted(by_v.items())}
    vs = list(per_v)
    ss = [v for v in vs if per_v[v] == STICK_SLIP]
    sm = [v for v in vs if per_v[v] == SMOOTH]
    if not ss and not sm:
        return CriticalVelocity("undetermined", None, None, None, None, True, per_v,
                                "no velocity is clearly stick-slip or smooth")
    if not ss:
        return CriticalVelocity("below_range", None, None, min(sm), None, True, per_v,
                                f"smooth at every V: V_c < {format_value(min(sm))}")
    above = [v for v in sm if v > min(ss)]
    if not above:
        return CriticalVelocity("above_range", None, max(ss), None, None, not sm, per_v,
                                f"no smooth sliding above a stick-slip V: V_c > "
                                f"{format_value(max(ss))}")
    high = min(above)
    low = max(v for v in ss if v < high)
    monotonic = all(v < high for v in ss) and all(v > low for v in sm)
    value = math.sqrt(low * high)
    half = 0.5 * math.log10(high / low)
    between = [format_value(v) for v in vs if low < v < high]
    note = f"stick-slip up to V = {format_value(low)}, smooth from {format_value(high)}"
    if between:
        note += f"; irregular in between at V = {', '.join(between)}"
    if not monotonic:
        note += "; not monotonic: stick-slip above or smooth below the bracket"
    return CriticalVelocity("bracketed", value, low, high, half, monotonic, per_v, note)


def _get(doc: dict, *path):
    for key in path:
        if not isinstance(doc, dict):
            return None
        doc = doc.get(key)
    return doc


def _finite(x) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def point_summary(sweep_dir: Path, point: dict) -> dict:
    """One row of the aggregate: parameters, regime, forces, η_eff for a completed point."""
    sweep_dir = Path(sweep_dir)
    name = point["name"]
    run_dir = sweep_dir / "points" / name
    inputs = json.loads((sweep_dir / "inputs" / f"{name}.json").read_text())
    p = inputs["parameters"]
    doc = json.loads((run_dir / "analysis.json").read_text())
    row = {"point": name, **{f"grid.{k}": v for k, v in point["values"].items()},
           "drive_velocity": p["drive_velocity"], "spring_constant": p["spring_constant"],
           "normal_pressure": p["normal_pressure"], "temperature": p["temperature"],
           "film_layers": p["film_layers"], "seed": p["seed"],
           "wall_mass": p["wall_mass"], "mount_damping": p["mount_damping"],
           "regime": doc.get("regime"), "slips": _get(doc, "slips", "count")}
    for q in ("static_force", "backward_force", "period", "slip_distance"):
        row[q] = _finite(_get(doc, "slips", q, "mean"))
        row[f"{q}_stderr"] = _finite(_get(doc, "slips", q, "stderr"))
    # the time-averaged friction: the spring force over the last half of the drive
    # (the start-up ramp from a relaxed spring is in the first half), as analysed
    row["mean_force"] = _finite(_get(doc, "sliding", "mean_force", "mean"))
    row["mean_force_stderr"] = _finite(_get(doc, "sliding", "mean_force", "stderr"))
    # "smooth" means fewer than 2 slips; a run too short for a second yield has as few,
    # but its wall stood still most of the time.  Sliding moves the wall at V on average.
    ratio = _finite(_get(doc, "sliding", "wall_velocity_ratio"))
    row["wall_velocity_ratio"] = ratio
    row["sweep_regime"] = row["regime"]
    if row["regime"] == SMOOTH and not (ratio is not None and ratio > STUCK_RATIO):
        row["sweep_regime"] = STUCK
    # η_eff at its shear rate: steady sliding (V/D), else the slip fits (slip velocity / D)
    eta = rate = eta_err = None
    source = None
    steady = _get(doc, "viscosity", "steady")
    slip = _get(doc, "viscosity", "from_slip")
    if steady:
        eta, eta_err = _get(steady, "eta_eff", "mean"), _get(steady, "eta_eff", "stderr")
        rate, source = _get(steady, "shear_rate", "mean"), "steady"
    elif slip and _get(slip, "eta_eff", "mean") is not None:
        d = _get(slip, "thickness", "mean")
        dx, ts = row["slip_distance"], _get(doc, "slips", "slip_duration", "mean")
        if d and dx and ts:
            eta, eta_err = _get(slip, "eta_eff", "mean"), _get(slip, "eta_eff", "stderr")
            rate, source = dx / ts / d, "from_slip"
    row.update(eta_eff=_finite(eta), eta_eff_stderr=_finite(eta_err), shear_rate=_finite(rate),
               eta_source=source, run_dir=str(run_dir.resolve()))
    return row


def _eta_points(rows: list[dict]) -> list[dict]:
    """Points with a positive η_eff and γ̇; a stuck wall has no shear rate to speak of."""
    return [r for r in rows if r["eta_eff"] and r["shear_rate"] and r["eta_eff"] > 0
            and r["shear_rate"] > 0 and r["sweep_regime"] != STUCK]


def _group_key(row: dict, keys: list[str]) -> tuple:
    return tuple(row[f"grid.{k}"] for k in keys)


def reduced_model_boundary(calibration: dict, stiffnesses, mass: float,
                           mount_damping: float) -> dict:
    """The calibrated spring-block model's stick-slip boundary V_c(K).

    The calibrated film is Coulomb (static F_s, kinetic F_k) plus a viscous
    B, on the MD's wall mass M and mount dashpot d = γ·M.  For such a block
    stick-slip happens iff λ = (F_s − F_k)/(V√(KM)) exceeds
    λ_c(ζ), ζ = (d + B)/(2√(KM)) (:func:`reduced_model.maps.critical_lambda`),
    so V_c(K) = (F_s − F_k)/(λ_c √(KM)); V_c = 0 for ζ ≥ 1.

    Parameters
    ----------
    calibration : dict
        A ``calibration.json`` document (``workflows.calibrate``); the runs
        with F_s, F_k and B are averaged.
    stiffnesses : array_like
        K values (ε/σ²).
    mass, mount_damping : float
        M (m) and d = γ·M (m/τ).

    Returns
    -------
    dict
        ``stiffness``, ``velocity`` lists and the parameters used.
    """
    from reduced_model.maps import critical_lambda, damping_ratio

    def values(name):
        out = []
        for r in calibration.get("runs", []):
            e = r.get(name) or {}
            if e.get("value") is not None:
                out.append(float(e["value"]))
        return out

    fs, fk, b = values("static_force"), values("kinetic_force"), values("film_damping")
    if not (fs and fk and b):
        raise ValueError("the calibration has no run with static_force, kinetic_force and "
                         "film_damping (a stick-slip run with fitted slips is needed)")
    drop = float(np.mean(fs) - np.mean(fk))
    damping = mount_damping + float(np.mean(b))
    k = np.asarray(stiffnesses, float)
    zeta = damping_ratio(damping, k, mass)
    lam = np.atleast_1d(critical_lambda(zeta))
    with np.errstate(divide="ignore"):
        vc = np.where(np.isfinite(lam), drop / (lam * np.sqrt(k * mass)), 0.0)
    return {"stiffness": k.tolist(), "velocity": vc.tolist(), "force_drop": drop,
            "damping": damping, "mass": mass,
            "model": "Coulomb(F_s, F_k) + viscous B + mount dashpot; V_c = (F_s - F_k) / "
                     "(lambda_c(zeta) sqrt(K M)), zeta = (d + B) / (2 sqrt(K M))"}


CSV_COLUMNS = ("point", "drive_velocity", "spring_constant", "normal_pressure", "temperature",
               "film_layers", "seed", "regime", "sweep_regime", "wall_velocity_ratio", "slips",
               "static_force", "static_force_stderr", "backward_force", "backward_force_stderr", "mean_force", "mean_force_stderr",
               "period", "period_stderr", "eta_eff", "eta_eff_stderr", "shear_rate",
               "eta_source", "run_dir")


def aggregate(sweep_dir: Path, *, figures: bool = True) -> dict:
    """Combine every point of a finished sweep; write the aggregate files.

    Writes ``aggregate.json``, ``aggregate.csv``, ``velocity_map.png`` and,
    when both V and K are swept, ``vk_map.png``, each atomically.

    Returns
    -------
    dict
        The ``aggregate.json`` document (schema ``filmfriction.sweep-aggregate/1``):
        ``points`` (one row per point: parameters, ``regime`` from the analysis and
        ``sweep_regime`` — ``unresolved`` when the run was too short to tell —, static
        and mean spring force ± standard error, η_eff at its shear rate),
        ``critical_velocity`` (one :class:`CriticalVelocity` per group of the other swept
        keys), ``power_law`` (η_eff = c·γ̇^α, or None with the reason in ``notes``),
        ``reduced_model_boundary`` (or None), ``calibration_runs``, ``run_dirs``,
        ``outputs`` and ``notes``.
    """
    from analysis.viscosity import power_law_fit

    sweep_dir = Path(sweep_dir)
    plan = json.loads((sweep_dir / "sweep.json").read_text())
    rows = [point_summary(sweep_dir, p) for p in plan["points"]]
    keys = [a["key"] for a in plan["grid"]]
    doc: dict = {"schema": AGGREGATE_SCHEMA, "units": "lj", "scene": plan["scene"],
                 "grid": plan["grid"], "fixed": plan["fixed"], "np": plan["np"],
                 "points": rows, "notes": []}
    # critical velocity, per group of the other swept keys (seeds are repeats)
    group_keys = [k for k in keys if k not in ("drive_velocity", "seed")]
    crit = []
    if "drive_velocity" in keys:
        groups: dict = {}
        for r in rows:
            groups.setdefault(_group_key(r, group_keys), []).append(r)
        for g, members in groups.items():
            cv = critical_velocity([r["drive_velocity"] for r in members],
                                   [r["sweep_regime"] for r in members])
            crit.append({"group": dict(zip(group_keys, g)), **cv.as_dict()})
    else:
        doc["notes"].append("drive_velocity is not swept: no critical velocity")
    doc["critical_velocity"] = crit
    # η_eff vs γ̇ across runs
    pts = _eta_points(rows)
    # one definition at a time: steady sliding, (F/A)/(V/D), when it has enough points;
    # the slip fits measure a different rate (the slip's) and scatter much more
    steady = [r for r in pts if r["eta_source"] == "steady"]
    if len(steady) >= 3:
        pts, used = steady, "steady sliding points only"
    else:
        used = "steady sliding and slip fits"
    law = None
    try:
        errs = [r["eta_eff_stderr"] for r in pts]
        use_err = all(e is not None and e > 0 for e in errs)
        fit = power_law_fit([r["shear_rate"] for r in pts], [r["eta_eff"] for r in pts],
                            errs if use_err else None)
        law = {"exponent": fit.exponent, "exponent_stderr": fit.exponent_stderr,
               "prefactor": fit.prefactor, "prefactor_rel_stderr": fit.prefactor_rel_stderr,
               "n": fit.n, "weighted": use_err, "points": used,
               "form": "eta_eff = prefactor * shear_rate**exponent"}
    except (ValueError, RuntimeError) as exc:
        doc["notes"].append(f"no power-law fit of eta_eff vs shear rate: {exc}")
    doc["power_law"] = law
    # the reduced model's boundary on the (V, K) map
    boundary = None
    vk = "drive_velocity" in keys and "spring_constant" in keys
    if vk and plan.get("calibration"):
        try:
            cal = json.loads(Path(plan["calibration"]).read_text())
            ks = sorted({r["spring_constant"] for r in rows})
            kk = np.geomspace(min(ks), max(ks), 40) if len(ks) > 1 else np.array(ks)
            masses = {r["wall_mass"] for r in rows}
            gammas = {r["mount_damping"] for r in rows}
            if len(masses) > 1 or len(gammas) > 1:
                raise ValueError("wall_mass or mount_damping varies across points")
            m, g = masses.pop(), gammas.pop()
            boundary = {"calibration": plan["calibration"],
                        **reduced_model_boundary(cal, kk, m, g * m)}
        except (OSError, ValueError, KeyError, ImportError) as exc:
            doc["notes"].append(f"no reduced-model boundary: {exc}")
    elif vk:
        doc["notes"].append("no reduced-model boundary on the (V, K) map: no --calibration given")
    doc["reduced_model_boundary"] = boundary
    # what the calibration takes: runs with slips to fit
    doc["calibration_runs"] = [r["run_dir"] for r in rows if r["regime"] == STICK_SLIP]
    doc["run_dirs"] = [r["run_dir"] for r in rows]
    outputs = ["aggregate.json", "aggregate.csv"]
    if figures and not _numeric_axes(doc):
        doc["notes"].append("no velocity_map.png: every grid axis is a choice (e.g. "
                            "wall_model); the table compares the points")
    elif figures:
        write_atomic(sweep_dir / "velocity_map.png", fig_velocity_map(doc))
        outputs.append("velocity_map.png")
        if vk:
            write_atomic(sweep_dir / "vk_map.png", fig_vk_map(doc))
            outputs.append("vk_map.png")
    doc["outputs"] = outputs
    write_atomic(sweep_dir / "aggregate.csv", _csv(rows).encode())
    write_atomic(sweep_dir / "aggregate.json", _dumps(_clean(doc)).encode())
    return doc


def _clean(obj):
    """NaN → None, recursively (JSON has no NaN)."""
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def _csv(rows: list[dict]) -> str:
    grid_cols = [k for k in rows[0] if k.startswith("grid.")] if rows else []
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    cols = list(CSV_COLUMNS[:1]) + grid_cols + list(CSV_COLUMNS[1:])
    w.writerow(cols)
    for r in rows:
        w.writerow(["" if r.get(c) is None else r.get(c) for c in cols])
    return buf.getvalue()




# ---------------------------------------------------------------------------
# figures
# ---------------------------------------------------------------------------
REGIME_MARKER = {STICK_SLIP: "o", SMOOTH: "s", IRREGULAR: "^", STUCK: "x"}
REGIME_COLOUR = {STICK_SLIP: "tab:red", SMOOTH: "tab:blue", IRREGULAR: "tab:orange",
                 STUCK: "0.6"}


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    _plt().close(fig)
    return buf.getvalue()


def _err(x):
    return 0.0 if x is None else x


def _numeric_axes(doc: dict) -> list[str]:
    """Grid keys with numbers for values (a choice such as wall_model cannot be an x axis)."""
    return [a["key"] for a in doc["grid"]
            if all(isinstance(v, (int, float)) for v in a["values"])]


def _plain_log_axis(axis) -> None:
    """Log axis labelled 0.01, 0.1, 1 rather than 10^-2 (and no crowded minor labels)."""
    from matplotlib.ticker import FuncFormatter, NullFormatter

    axis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    axis.set_minor_formatter(NullFormatter())


def _group_label(group: dict) -> str:
    return ", ".join(f"{k}={format_value(v)}" for k, v in group.items())


def fig_velocity_map(doc: dict) -> bytes:
    """Friction vs V (static force filled, mean spring force open; marker = regime, colour =
    group of the other swept keys; V_c bracket shaded) above η_eff vs γ̇ with the power law."""
    plt = _plt()
    rows = doc["points"]
    keys = [a["key"] for a in doc["grid"]]
    xkey = "drive_velocity" if "drive_velocity" in keys else _numeric_axes(doc)[0]
    group_keys = [k for k in keys if k not in (xkey, "seed")]
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    groups: dict = {}
    for r in rows:
        groups.setdefault(_group_key(r, group_keys), []).append(r)
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7, 9))
    handles = []
    for i, (g, members) in enumerate(groups.items()):
        colour = colours[i % len(colours)]
        members = sorted(members, key=lambda r: r[f"grid.{xkey}"])
        for r in members:
            marker = REGIME_MARKER.get(r["sweep_regime"], "x")
            x = r[f"grid.{xkey}"]
            if r["static_force"] is not None:
                ax.errorbar(x, r["static_force"], yerr=_err(r["static_force_stderr"]),
                            color=colour, marker=marker, ms=7, capsize=3, ls="none")
            if r["mean_force"] is not None:
                ax.errorbar(x, r["mean_force"], yerr=_err(r["mean_force_stderr"]), color=colour,
                            marker=marker, mfc="white", ms=7, capsize=3, ls="none")
        # a guide to the eye through the mean over repeats (seeds) at each x
        by_x: dict = {}
        for r in members:
            if r["mean_force"] is not None:
                by_x.setdefault(r[f"grid.{xkey}"], []).append(r["mean_force"])
        ax.plot(list(by_x), [np.mean(v) for v in by_x.values()], color=colour, lw=0.8,
                alpha=0.6)
        if group_keys:
            handles.append(plt.Line2D([], [], color=colour, lw=2,
                                      label=_group_label(dict(zip(group_keys, g)))))
    crit = [cv for cv in doc.get("critical_velocity", []) if cv["status"] == "bracketed"]
    for i, cv in enumerate(crit):
        gi = list(groups).index(tuple(cv["group"][k] for k in group_keys)) if group_keys else 0
        colour = colours[gi % len(colours)]
        ax.axvspan(cv["low"], cv["high"], color=colour, alpha=0.12, zorder=0)
        ax.axvline(cv["value"], color=colour, ls="--", lw=1)
        ax.text(0.99, 0.97 - 0.06 * i,
                f"$V_c$ = {cv['value']:.3g} ×/÷ {cv['factor']:.2g} σ/τ"
                + (f" ({_group_label(cv['group'])})" if cv["group"] else ""),
                transform=ax.transAxes, ha="right", va="top", fontsize=8, color=colour)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.08 * (1 + len(crit)) * (hi - lo))     # room for the V_c lines
    xs = [r[f"grid.{xkey}"] for r in rows]
    if min(xs) > 0 and max(xs) / min(xs) > 5:
        ax.set_xscale("log")
        _plain_log_axis(ax.xaxis)
    handles += [plt.Line2D([], [], color="k", marker=m, ls="none", label=reg)
                for reg, m in REGIME_MARKER.items()]
    handles += [plt.Line2D([], [], color="k", marker="o", ls="none", label="static force $F_s$"),
                plt.Line2D([], [], color="k", marker="o", mfc="white", ls="none",
                           label="mean spring force (last half)")]
    ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12),
              ncol=3, frameon=False)
    unit = {"drive_velocity": " (σ/τ)"}.get(xkey, "")
    ax.set_xlabel(f"{xkey}{unit}")
    ax.set_ylabel("friction force (ε/σ)")
    ax.set_title(f"{doc['scene']}: friction vs {xkey} ({len(rows)} runs, ± standard error; "
                 "shaded: stick-slip → smooth)", fontsize=9)
    pts = _eta_points(rows)
    for r in pts:
        steady = r["eta_source"] == "steady"
        bx.errorbar(r["shear_rate"], r["eta_eff"], yerr=_err(r["eta_eff_stderr"]),
                    color="k" if steady else "tab:purple",
                    marker=REGIME_MARKER.get(r["sweep_regime"], "x"), mfc="white", capsize=3,
                    ls="none")
    law = doc.get("power_law")
    if law:
        fitted = [r for r in pts if r["eta_source"] == "steady"] \
            if law["points"].endswith("only") else pts
        g = np.geomspace(min(r["shear_rate"] for r in fitted),
                         max(r["shear_rate"] for r in fitted), 50)
        bx.plot(g, law["prefactor"] * g ** law["exponent"], "k-", lw=1,
                label=f"η_eff ∝ γ̇^({law['exponent']:.2f} ± {law['exponent_stderr']:.2f}), "
                      f"{law['n']} runs ({law['points']})")
    if any(r["eta_source"] != "steady" for r in pts):
        bx.plot([], [], "o", color="tab:purple", mfc="white", label="from the slip fits")
    if pts:
        bx.legend(fontsize=8)
    if pts:
        bx.set_xscale("log")
        bx.set_yscale("log")
        _plain_log_axis(bx.xaxis)
        _plain_log_axis(bx.yaxis)
    else:
        bx.text(0.5, 0.5, "no η_eff in these runs", transform=bx.transAxes, ha="center")
    bx.set_xlabel("shear rate γ̇ (1/τ): V/D when smooth, slip velocity/D when stick-slip")
    bx.set_ylabel("η_eff (ετ/σ³)")
    fig.tight_layout()
    return _png(fig)


def fig_vk_map(doc: dict) -> bytes:
    """The (V, K) plane: regime per point (majority over other keys), MD's V_c per K,
    and the reduced model's boundary when calibrated."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.5, 5.5))
    cells: dict = {}
    for r in doc["points"]:
        cells.setdefault((r["drive_velocity"], r["spring_constant"]), []).append(
            r["sweep_regime"])
    for (v, k), regs in cells.items():
        regime = _majority(regs) if STUCK not in regs else STUCK
        ax.plot(v, k, marker=REGIME_MARKER.get(regime, "x"), color=REGIME_COLOUR.get(regime),
                ms=10, ls="none")
    for cv in doc.get("critical_velocity", []):
        k = cv["group"].get("spring_constant")
        if cv["status"] == "bracketed" and k is not None:
            ax.errorbar(cv["value"], k, xerr=[[cv["value"] - cv["low"]],
                                              [cv["high"] - cv["value"]]],
                        color="k", marker="|", ms=14, capsize=4, ls="none")
    handles = [plt.Line2D([], [], color=REGIME_COLOUR[reg], marker=m, ls="none", label=reg)
               for reg, m in REGIME_MARKER.items()]
    handles.append(plt.Line2D([], [], color="k", marker="|", ls="none",
                              label="MD $V_c$ (bracket)"))
    b = doc.get("reduced_model_boundary")
    if b:
        ax.plot(b["velocity"], b["stiffness"], "k--", lw=1.2)
        handles.append(plt.Line2D([], [], color="k", ls="--",
                                  label="calibrated reduced model: stick-slip left of it"))
    ax.legend(handles=handles, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13),
              ncol=3, frameon=False)
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log_axis(ax.xaxis)
    _plain_log_axis(ax.yaxis)
    ks = sorted({k for _, k in cells})
    if len(ks) <= 12:
        ax.set_yticks(ks)         # label every swept K
    ax.set_xlabel("drive velocity V (σ/τ)")
    ax.set_ylabel("spring constant K (ε/σ²)")
    title = f"{doc['scene']}: regime map"
    if not b:
        title += " (no calibration given: no reduced-model boundary)"
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    return _png(fig)


# ---------------------------------------------------------------------------
# reading a sweep (report, calibration)
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Aggregate:
    """A finished sweep, as the report and the calibration read it.

    Attributes
    ----------
    sweep_dir : Path
    doc : dict
        ``aggregate.json``.
    run_dirs : tuple of Path
        Every point's run directory, in grid order.
    calibration_runs : tuple of Path
        The stick-slip points (slips to fit), for ``workflows.calibrate.calibrate``.
    figures : dict
        ``velocity_map`` / ``vk_map`` → Path, for those written.
    """

    sweep_dir: Path
    doc: dict = field(hash=False)
    run_dirs: tuple = ()
    calibration_runs: tuple = ()
    figures: dict = field(default_factory=dict, hash=False)

    @property
    def points(self) -> list:
        return self.doc["points"]

    @property
    def critical_velocity(self) -> list:
        return self.doc["critical_velocity"]

    @property
    def power_law(self) -> dict | None:
        return self.doc["power_law"]


def load_aggregate(sweep_dir) -> Aggregate:
    """Read a finished sweep's ``aggregate.json``.

    Raises
    ------
    FileNotFoundError
        The sweep has not finished (no ``aggregate.json``).
    """
    sweep_dir = Path(sweep_dir)
    path = sweep_dir / "aggregate.json"
    if not path.exists():
        raise FileNotFoundError(f"{path}: no aggregate; run (or resume) the sweep first")
    doc = json.loads(path.read_text())
    figures = {name: sweep_dir / f"{name}.png" for name in ("velocity_map", "vk_map")
               if (sweep_dir / f"{name}.png").exists()}
    return Aggregate(sweep_dir=sweep_dir, doc=doc,
                     run_dirs=tuple(Path(p) for p in doc["run_dirs"]),
                     calibration_runs=tuple(Path(p) for p in doc["calibration_runs"]),
                     figures=figures)


# ---------------------------------------------------------------------------
# command line
# ---------------------------------------------------------------------------
def register(subparsers) -> None:
    """Add the ``sweep`` sub-command."""
    p = subparsers.add_parser(
        "sweep", help="run a scene over a parameter grid (Snakemake; local or Slurm)",
        description="Fan a scene out over a grid of parameters, run every point as an MPI "
                    "LAMMPS job, analyse it, and aggregate: friction vs V, regime per point, "
                    "critical velocity, eta_eff vs shear rate, (V, K) map. Snakemake "
                    "schedules the jobs; re-running the same command re-does only what "
                    "changed and resumes an interrupted sweep.")
    p.add_argument("scene", help="scene name or TOML file (see 'filmfriction scenes')")
    p.add_argument("--grid", action="append", default=[], metavar="KEY=START:STOP:N[:log]",
                   help="a swept parameter: N values from START to STOP (evenly, or in log "
                        "with :log), or KEY=V1,V2,...; repeat for a full product")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="fixed override for every point, e.g. --set slide_steps=20000")
    p.add_argument("--np", type=int, default=2, help="MPI ranks per point (default 2)")
    p.add_argument("--cores", type=int, default=2,
                   help="cores Snakemake may use at once on this machine (default 2)")
    p.add_argument("--out", type=Path, default=None,
                   help="sweep directory (default sweeps/<scene>-<swept keys>); re-use it to "
                        "resume or extend a sweep")
    p.add_argument("--profile", default=None,
                   help="Snakemake profile: 'slurm', 'local' (shipped) or a directory")
    p.add_argument("--calibration", type=Path, default=None, metavar="FILE",
                   help="calibration.json: overlay the reduced model's boundary on the "
                        "(V, K) map")
    p.add_argument("--dry-run", action="store_true",
                   help="list the jobs Snakemake would run, run nothing")
    p.set_defaults(func=main_sweep)


def default_out(plan: SweepPlan) -> Path:
    return Path("sweeps") / f"{plan.scene}-{'-'.join(a.key for a in plan.grid)}"


def check_installed(profile: Path | None) -> None:
    """Snakemake (and the Slurm executor plugin for a Slurm profile) must be importable."""
    import importlib.util
    import re

    if importlib.util.find_spec("snakemake") is None:
        raise _user_error("Snakemake is not installed: pip install -e '.[sweep]'")
    if profile is not None:
        text = (profile / "config.yaml").read_text()
        if (re.search(r"^executor:\s*slurm\b", text, re.M)
                and importlib.util.find_spec("snakemake_executor_plugin_slurm") is None):
            raise _user_error(f"profile {profile} uses the Slurm executor, which is not "
                              "installed: pip install snakemake-executor-plugin-slurm")


def main_sweep(args: argparse.Namespace) -> int:
    from .scene import SceneError

    if args.cores < 1:
        raise _user_error(f"--cores {args.cores}: need at least 1")
    try:
        plan = plan_sweep(args.scene, args.grid, args.overrides, args.np, args.calibration)
    except SceneError as exc:
        raise _user_error(str(exc)) from None
    profile = profile_path(args.profile) if args.profile else None
    check_installed(profile)
    out = args.out if args.out is not None else default_out(plan)
    grid = " x ".join(f"{a.key}[{len(a.values)}]" for a in plan.grid)
    print(f"sweep: {plan.scene}, {grid} = {len(plan.points)} points, {plan.np} MPI rank(s) "
          f"each -> {out}", file=sys.stderr)
    rc = run_sweep(plan, out, args.cores, dry_run=args.dry_run, profile=profile)
    if rc != 0 or args.dry_run:
        if rc not in (0, 130):
            print(f"filmfriction sweep: Snakemake exited with code {rc}; completed points are "
                  f"kept, run the same command again to retry the rest", file=sys.stderr)
        return rc
    if profile is not None and not (Path(out) / "aggregate.json").exists():
        return 0         # remote executor still owns the jobs
    print(summary(load_aggregate(out)))
    return 0


def summary(agg: Aggregate) -> str:
    """A few lines for the terminal: where the files are, V_c, the power law."""
    lines = [f"sweep directory: {agg.sweep_dir}"]
    regimes = [r["sweep_regime"] for r in agg.points]
    lines.append("regimes: " + ", ".join(f"{regimes.count(r)} {r}" for r in
                                         (STICK_SLIP, IRREGULAR, SMOOTH, STUCK)
                                         if regimes.count(r)))
    if STUCK in regimes:
        lines.append(f"note: {STUCK}: < 2 slips while the wall moved at < {STUCK_RATIO:g} V: "
                     "the run is too short to tell its regime (raise slide_steps)")
    for cv in agg.critical_velocity:
        group = ", ".join(f"{k}={format_value(v)}" for k, v in cv["group"].items())
        prefix = f"critical velocity{' (' + group + ')' if group else ''}: "
        if cv["status"] == "bracketed":
            lines.append(prefix + f"V_c = {cv['value']:.3g} σ/τ (×/÷ {cv['factor']:.3g}; "
                         f"between {cv['low']:.3g} and {cv['high']:.3g})"
                         + ("" if cv["monotonic"] else " [not monotonic]"))
        else:
            lines.append(prefix + cv["note"])
    law = agg.power_law
    if law:
        lines.append(f"eta_eff ∝ shear_rate^({law['exponent']:.3f} ± "
                     f"{law['exponent_stderr']:.3f}) over {law['n']} runs")
    for note in agg.doc.get("notes", []):
        lines.append(f"note: {note}")
    lines.append("files: " + ", ".join(str(agg.sweep_dir / o) for o in agg.doc["outputs"]))
    return "\n".join(lines)


_INTERRUPTED = False


def _interrupt(signum, frame):
    global _INTERRUPTED
    _INTERRUPTED = True
    raise KeyboardInterrupt


def _job_main(argv: list[str]) -> int:
    """The Snakefile's jobs: ``python -m workflows.sweep point|analyse|aggregate ...``."""
    parser = argparse.ArgumentParser(prog="python -m workflows.sweep")
    sub = parser.add_subparsers(dest="job", required=True)
    p = sub.add_parser("point")
    p.add_argument("inputs", type=Path)
    p.add_argument("run_dir", type=Path)
    p.add_argument("--np", type=int, required=True)
    p.add_argument("--launcher", default="mpiexec")
    a = sub.add_parser("analyse")
    a.add_argument("run_dir", type=Path)
    g = sub.add_parser("aggregate")
    g.add_argument("sweep_dir", type=Path)
    args = parser.parse_args(argv)
    # Snakemake stops jobs with SIGTERM or SIGINT: both become an interrupt, so the runner
    # stops its LAMMPS child (which runs in its own session) instead of leaving it behind
    signal.signal(signal.SIGTERM, _interrupt)
    signal.signal(signal.SIGINT, _interrupt)
    if args.job == "point":
        from .runner import RunFailed

        try:
            run_dir = run_point(args.inputs, args.run_dir, args.np, args.launcher)
        except RunFailed as exc:
            print(str(exc), file=sys.stderr)
            return 1
        except KeyboardInterrupt:
            print("interrupted", file=sys.stderr)
            return 130
        print(f"completed: {run_dir}")
    elif args.job == "analyse":
        doc = analyse_point(args.run_dir)
        print(f"{args.run_dir}: {doc['regime']}, {doc['slips']['count']} slips")
    else:
        aggregate(args.sweep_dir)
        print(summary(load_aggregate(args.sweep_dir)))
    return 0


if __name__ == "__main__":
    sys.exit(_job_main(sys.argv[1:]))
