"""Sweeps through Snakemake: planning and validation, a tiny real sweep, the Slurm
profile's dry run, kill-and-resume, and the per-directory lock."""
import json
import math
import os
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from filmfriction.analysis.observables.sliding_section import sliding_section
from filmfriction.analysis.files.trace_reader import read_trace
from filmfriction.workflows import sweep
from filmfriction.workflows.md.scene import SceneError

# on the md fixture's box (about 330 atoms), 4000 steps: a few seconds per point on one rank
STEPS = {"equilibrate_steps": 1000, "slide_steps": 3000, "trace_every": 20}


@pytest.fixture(scope="module")
def small_args(md):
    """``--set`` options of the small sweeps."""
    return [arg for k, v in {**md.box, **STEPS}.items() for arg in ("--set", f"{k}={v}")]


@pytest.fixture
def cli(filmfriction_command):
    """``cli(*args)``: ``filmfriction sweep ARGS`` in a subprocess (as a user runs it)."""
    def run(*args, **kw):
        return subprocess.run([filmfriction_command, "sweep", *args],
                              capture_output=True, text=True, **kw)
    return run


def completed(out: Path) -> list[Path]:
    """``points/<point>/run.json`` of the finished points (pathlib's ``*`` also matches the
    hidden directories of runs in progress)."""
    return [p for p in out.glob("points/*/run.json") if not p.parent.name.startswith(".")]


# ---------------------------------------------------------------- planning
def test_grid_linear_log_and_list():
    assert sweep.parse_grid("drive_velocity=0.005:0.5:5:log").values == (
        0.005, 0.0158114, 0.05, 0.158114, 0.5)
    assert sweep.parse_grid("spring_constant=50:150:3").values == (50.0, 100.0, 150.0)
    assert sweep.parse_grid("seed=1:4:4").values == (1, 2, 3, 4)
    assert sweep.parse_grid("film_layers=2,4").values == (2, 4)
    assert sweep.parse_grid("temperature=0.5:0.5:1").values == (0.5,)


def test_a_choice_axis_lists_names_and_plans_points():
    assert sweep.parse_grid("wall_model=rigid,flexible").values == ("rigid", "flexible")
    plan = sweep.plan_sweep("stick-slip", ["drive_velocity=0.02,0.5",
                                           "wall_model=rigid,flexible"])
    assert plan.points[1].name == "drive_velocity=0.02__wall_model=flexible"
    assert plan.parameters["drive_velocity=0.5__wall_model=flexible"]["wall_model"] == "flexible"
    # the velocity is the map's x axis; a choice can only group the points
    doc = {"grid": [{"key": "wall_model", "values": ["rigid", "flexible"]},
                    {"key": "drive_velocity", "values": [0.02, 0.5]}]}
    assert sweep.numeric_axes(doc) == ["drive_velocity"]


@pytest.mark.parametrize("text, words", [
    ("wall_model=rigid,soft", "must be one of rigid, flexible"),
    ("wall_model=rigid,rigid", "distinct values"),
    ("velocity=0.1:1:3", "unknown parameter 'velocity'"),
    ("drive_velocity=0:1:3:log", "START > 0"),
    ("drive_velocity=0.1:1:0", "at least 1"),
    ("drive_velocity=0.1:1", "KEY=START:STOP:N"),
    ("drive_velocity=a:1:2", "START 'a' is not a number"),
    ("film_layers=1:2:5", "repeat after rounding"),
])
def test_grid_errors(text, words):
    with pytest.raises(SceneError, match=words):
        sweep.parse_grid(text)


def test_plan_is_the_full_product_and_names_its_points():
    plan = sweep.plan_sweep("stick-slip", ["drive_velocity=0.02,0.5", "seed=1:3:3"],
                            ["slide_steps=3000"], 1)
    assert len(plan.points) == 6
    assert plan.points[0].name == "drive_velocity=0.02__seed=1"
    p = plan.parameters["drive_velocity=0.5__seed=3"]
    assert (p["drive_velocity"], p["seed"], p["slide_steps"]) == (0.5, 3, 3000)


def test_every_point_is_validated_with_key_value_and_range():
    with pytest.raises(SceneError) as exc:
        sweep.plan_sweep("stick-slip", ["drive_velocity=0.1:6:3"])
    text = str(exc.value)
    assert "grid point drive_velocity=6" in text and "allowed range" in text and "5.0" in text
    # a consistency check between parameters, reached only through the grid
    with pytest.raises(SceneError, match="grid point timestep=0.02 .*stability limit"):
        sweep.plan_sweep("stick-slip", ["timestep=0.005,0.02"])
    with pytest.raises(SceneError, match="already swept"):
        sweep.plan_sweep("stick-slip", ["seed=1,2"], ["seed=3"])
    with pytest.raises(SceneError, match="given twice"):
        sweep.plan_sweep("stick-slip", ["seed=1,2", "seed=3,4"])


def test_cli_refuses_a_bad_grid_before_snakemake_starts(tmp_path, cli):
    out = tmp_path / "sweep"
    r = cli("stick-slip", "--grid", "drive_velocity=0.1:6:3", "--out", str(out))
    assert r.returncode == 2
    assert "drive_velocity = 6.0" in r.stderr and "allowed range" in r.stderr
    assert not out.exists()


# ---------------------------------------------------------------- aggregation pieces
def test_critical_velocity_brackets_the_transition():
    cv = sweep.critical_velocity([0.01, 0.03, 0.1, 0.3], ["stick-slip", "stick-slip",
                                                          "irregular", "smooth"])
    assert cv.status == "bracketed" and (cv.low, cv.high) == (0.03, 0.3)
    assert cv.value == pytest.approx(math.sqrt(0.03 * 0.3))
    assert cv.log10_halfwidth == pytest.approx(0.5)
    assert cv.monotonic and "irregular in between at V = 0.1" in cv.note
    # seeds: the majority of a velocity's points decides
    cv = sweep.critical_velocity([0.1, 0.1, 0.1, 0.2, 0.2],
                                 ["stick-slip", "stick-slip", "smooth", "smooth", "smooth"])
    assert (cv.low, cv.high) == (0.1, 0.2)
    assert sweep.critical_velocity([0.1, 0.2], ["smooth", "smooth"]).status == "below_range"
    assert sweep.critical_velocity([0.1, 0.2], ["stick-slip"] * 2).status == "above_range"
    cv = sweep.critical_velocity([0.1, 0.2, 0.4], ["stick-slip", "smooth", "stick-slip"])
    assert cv.status == "bracketed" and not cv.monotonic


def test_reduced_model_boundary_follows_the_coulomb_threshold():
    from filmfriction.reduced_model.maps import critical_lambda

    cal = {"runs": [{"static_force": {"value": 60.0}, "kinetic_force": {"value": 20.0},
                     "film_damping": {"value": 10.0}}]}
    k = np.array([30.0, 100.0, 300.0])
    b = sweep.reduced_model_boundary(cal, k, mass=500.0, mount_damping=150.0)
    zeta = 160.0 / (2 * np.sqrt(k * 500.0))          # (d + B) / (2 sqrt(K M))
    expected = 40.0 / (critical_lambda(zeta) * np.sqrt(k * 500.0))
    assert np.allclose(b["velocity"], expected) and min(b["velocity"]) > 0
    # overdamped (zeta >= 1): the block cannot re-stick at any V
    assert sweep.reduced_model_boundary(cal, [10.0], 500.0, 150.0)["velocity"] == [0.0]
    with pytest.raises(ValueError, match="kinetic_force"):
        sweep.reduced_model_boundary({"runs": [{"static_force": {"value": 1.0}}]}, k, 1.0, 0.0)


def fake_point(sweep_dir, plan, name, regime, slips, eta, rate):
    """A completed point without MD: inputs, trace.csv and a minimal analysis.json."""
    p = plan.parameters[name]
    (sweep_dir / "inputs").mkdir(exist_ok=True)
    (sweep_dir / "inputs" / f"{name}.json").write_text(json.dumps({"parameters": p}))
    run_dir = sweep_dir / "points" / name
    run_dir.mkdir(parents=True)
    t = np.linspace(0.0, 100.0, 1001)
    v = p["drive_velocity"]
    force = 20.0 + np.sin(t)
    np.savetxt(run_dir / "trace.csv", np.column_stack([t, force, v * t]), delimiter=",",
               header="time,spring_force,wall_position", comments="")
    e = lambda m, s=None: {"mean": m, "stderr": s}  # noqa: E731
    sliding = sliding_section(read_trace(run_dir / "trace.csv", drive_velocity=v))
    doc = {"regime": regime, "slips": {"count": slips, "static_force": e(60.0, 1.0),
                                       "backward_force": e(20.0, 1.0), "period": e(10.0, 0.5),
                                       "slip_distance": e(1.0), "slip_duration": e(2.0)},
           "viscosity": {"steady": {"eta_eff": e(eta, 0.1 * eta), "shear_rate": e(rate)}},
           "sliding": sliding}
    (run_dir / "analysis.json").write_text(json.dumps(doc))


def test_aggregate_of_a_v_by_k_sweep(tmp_path):
    cal = tmp_path / "calibration.json"
    cal.write_text(json.dumps({"schema": "filmfriction.calibration/1", "units": "lj",
                               "runs": [{"static_force": {"value": 60.0},
                                         "kinetic_force": {"value": 20.0},
                                         "film_damping": {"value": 10.0}}]}))
    plan = sweep.plan_sweep("stick-slip", ["drive_velocity=0.01:1:3:log",
                                           "spring_constant=50,200"], calibration=cal)
    sweep.write_plan(plan, tmp_path)
    # K = 50: smooth from V = 1; K = 200: smooth from V = 0.1.  eta = 3 rate^-0.5
    regimes = {(0.01, 50.0): "stick-slip", (0.1, 50.0): "stick-slip", (1.0, 50.0): "smooth",
               (0.01, 200.0): "stick-slip", (0.1, 200.0): "smooth", (1.0, 200.0): "smooth"}
    for point in plan.points:
        v, k = point.values["drive_velocity"], point.values["spring_constant"]
        rate = v / 2.0
        fake_point(tmp_path, plan, point.name, regimes[v, k],
                   5 if regimes[v, k] == "stick-slip" else 0, 3.0 * rate ** -0.5, rate)
    doc = sweep.aggregate(tmp_path)
    crit = {c["group"]["spring_constant"]: c for c in doc["critical_velocity"]}
    assert crit[50.0]["value"] == pytest.approx(math.sqrt(0.1))
    assert crit[200.0]["value"] == pytest.approx(math.sqrt(0.001))
    assert crit[200.0]["factor"] == pytest.approx(math.sqrt(10.0))
    assert doc["power_law"]["exponent"] == pytest.approx(-0.5)
    assert doc["power_law"]["n"] == 6
    assert doc["reduced_model_boundary"]["force_drop"] == pytest.approx(40.0)
    assert len(doc["calibration_runs"]) == 3
    assert doc["outputs"] == ["aggregate.json", "aggregate.csv", "velocity_map.png", "vk_map.png"]
    for name in doc["outputs"]:
        assert (tmp_path / name).stat().st_size > 0
    agg = sweep.load_aggregate(tmp_path)
    assert set(agg.figures) == {"velocity_map", "vk_map"}
    assert [r["sweep_regime"] for r in agg.points].count("unresolved") == 0


def test_a_run_too_short_to_slip_is_unresolved_not_smooth(tmp_path):
    plan = sweep.plan_sweep("stick-slip", ["drive_velocity=0.05,0.5"])
    sweep.write_plan(plan, tmp_path)
    for point in plan.points:
        fake_point(tmp_path, plan, point.name, "smooth", 0, 10.0, 0.1)
    # the slow point's wall never moved: it was stuck, still loading the spring
    slow = tmp_path / "points" / plan.points[0].name / "trace.csv"
    data = np.genfromtxt(slow, delimiter=",", names=True)
    np.savetxt(slow, np.column_stack([data["time"], data["spring_force"], 0 * data["time"]]),
               delimiter=",", header="time,spring_force,wall_position", comments="")
    analysed = slow.parent / "analysis.json"
    doc = json.loads(analysed.read_text())
    v_slow = plan.parameters[plan.points[0].name]["drive_velocity"]
    doc["sliding"] = sliding_section(read_trace(slow, drive_velocity=v_slow))
    analysed.write_text(json.dumps(doc))
    doc = sweep.aggregate(tmp_path, figures=False)
    assert [r["sweep_regime"] for r in doc["points"]] == ["unresolved", "smooth"]
    assert doc["critical_velocity"][0]["status"] == "below_range"
    assert doc["critical_velocity"][0]["high"] == 0.5


def test_launcher_replaces_mpiexec_by_srun():
    from filmfriction.workflows.md import engine

    plain = engine.lmp_command(4, Path("in.lmp"))
    wrapped = engine.lmp_command(4, Path("in.lmp"), launcher=["srun", "--mpi=pmi2"])
    assert wrapped == ["srun", "--mpi=pmi2", *plain[1:]] and wrapped[2:4] == ["-n", "4"]
    assert engine.lmp_command(4, Path("in.lmp")) == plain      # no state left behind
    assert plain[0].endswith("mpiexec")


def test_a_second_sweep_in_the_same_directory_is_refused(tmp_path, cli, small_args):
    out = tmp_path / "sweep"
    with sweep.SweepLock(out):
        r = cli("stick-slip", "--grid", "drive_velocity=0.05,0.5", "--out", str(out), *small_args)
    assert r.returncode == 2 and "another sweep is running" in r.stderr
    assert not (out / "sweep.json").exists()          # it wrote nothing


# ---------------------------------------------------------------- Slurm profile
def test_slurm_profile_dry_run_declares_mpi_on_every_run(tmp_path, cli, small_args):
    pytest.importorskip("snakemake_executor_plugin_slurm",
                        reason="pip install snakemake-executor-plugin-slurm (the sweep extra)")
    out = tmp_path / "sweep"
    ranks = 4 * (os.cpu_count() or 1)       # more than this machine has: fine on Slurm
    r = cli("stick-slip", "--grid", "drive_velocity=0.05,0.5", "--grid", "seed=1,2",
            "--np", str(ranks), "--out", str(out), "--profile", "slurm", "--dry-run",
            *small_args, timeout=120)
    assert r.returncode == 0, r.stderr[-3000:]
    blocks = [b for b in r.stdout.split("rule ")[1:] if b.startswith("point:")]
    assert len(blocks) == 4
    for b in blocks:
        resources = next(line for line in b.splitlines() if "resources:" in line)
        assert "launcher=srun --mpi=pmi2" in resources and f"tasks={ranks}" in resources
        assert "mpi=yes" in resources        # one MPI job of --np tasks for the executor
        assert "cpus_per_task=1" in resources and "runtime=" in resources
    assert "This was a dry-run" in r.stdout
    assert not (out / "points").exists()


# ---------------------------------------------------------------- real sweeps
@pytest.mark.md
def test_tiny_sweep_runs_analyses_aggregates_and_is_incremental(tmp_path, cli, small_args):
    out = tmp_path / "sweep"
    args = ["stick-slip", "--grid", "drive_velocity=0.05,0.5", "--grid", "seed=1,2",
            "--np", "1", "--cores", "2", "--out", str(out), *small_args]
    r = cli(*args, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "sweep directory:" in r.stdout and "critical velocity" in r.stdout
    agg = sweep.load_aggregate(out)
    assert len(agg.points) == 4 and len(agg.run_dirs) == 4
    for run_dir in agg.run_dirs:
        record = json.loads((run_dir / "run.json").read_text())
        assert record["status"] in ("completed", "completed_with_warnings")
        assert record["scene"]["parameters"]["slide_steps"] == 3000
        assert "-n 1" in (run_dir / "command.txt").read_text()
        analysis = json.loads((run_dir / "analysis.json").read_text())
        assert analysis["regime"] in ("stick-slip", "smooth", "irregular", "unresolved")
    by_name = {p["point"]: p for p in agg.points}
    fast = by_name["drive_velocity=0.5__seed=2"]
    assert fast["drive_velocity"] == 0.5 and fast["seed"] == 2
    assert fast["mean_force"] > 0 and fast["mean_force_stderr"] > 0
    assert fast["regime"] in ("stick-slip", "smooth", "irregular")
    # seeds differ: different trajectories
    slow = [by_name[f"drive_velocity=0.05__seed={s}"]["mean_force"] for s in (1, 2)]
    assert slow[0] != slow[1]
    # the aggregate's critical velocity is the one its points' regimes give
    expected = sweep.critical_velocity([p["drive_velocity"] for p in agg.points],
                                       [p["sweep_regime"] for p in agg.points])
    assert len(agg.critical_velocity) == 1
    assert agg.critical_velocity[0]["status"] == expected.status
    assert agg.critical_velocity[0]["value"] == expected.value
    assert set(agg.figures) == {"velocity_map"} and agg.figures["velocity_map"].stat().st_size
    rows = (out / "aggregate.csv").read_text().splitlines()
    assert len(rows) == 5 and rows[0].startswith("point,grid.drive_velocity,grid.seed")
    assert not list(out.glob("points/.*")), "no temporary run directory left behind"
    # the same command again: nothing to redo, nothing touched
    stamps = {p: p.stat().st_mtime_ns for p in out.glob("points/*/*.json")}
    r = cli(*args, timeout=120)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "Nothing to be done" in r.stderr
    assert stamps == {p: p.stat().st_mtime_ns for p in out.glob("points/*/*.json")}


def _start(filmfriction_command, args) -> subprocess.Popen:
    return subprocess.Popen([filmfriction_command, "sweep", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def _stop(proc: subprocess.Popen, until, what: str) -> str:
    """Wait (≤ 120 s) until ``until()`` is true while the sweep runs, then stop it with
    SIGTERM as a user would; return its output (it must exit 130)."""
    deadline = time.time() + 120
    try:
        while not until():
            assert proc.poll() is None, proc.stdout.read()[-3000:]
            assert time.time() < deadline, f"not in 120 s: {what}"
            time.sleep(0.05)
        proc.send_signal(signal.SIGTERM)
        rc = proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    log = proc.stdout.read()
    assert rc == 130, log[-3000:]
    return log


def _newest_restart(run_dir: Path) -> int:
    from filmfriction.workflows.md import restarts

    good = restarts.usable(run_dir)
    return good[-1][0] if good else -1


@pytest.mark.md
def test_killed_sweep_resumes_without_losing_a_point(tmp_path, md, filmfriction_command,
                                                     lock_held, processes_in):
    """Kill a sweep while a point runs, kill its resume, then let it finish: the
    finished point is never redone, the interrupted one keeps its partial run (restart
    files included) and is continued from it, and its trace is whole."""
    out = tmp_path / "sweep"
    # long enough that a restart file is written well before the end, whatever the speed
    steps = {**STEPS, "slide_steps": 10000, "restart_every": 1000}
    args = ["stick-slip", "--grid", "drive_velocity=0.05,0.5", "--np", "1", "--cores", "1",
            "--out", str(out),
            *[arg for k, v in {**md.box, **steps}.items() for arg in ("--set", f"{k}={v}")]]

    def partials():
        return [p for p in out.glob("points/.*.partial")
                if not (out / "points" / p.name[1:-len(".partial")] / "run.json").exists()]

    # 1. one point completed, the next one's run has a restart file: stop the sweep
    log = _stop(_start(filmfriction_command, args),
                lambda: completed(out) and any(_newest_restart(p) > 0 for p in partials()),
                "one point completed and the next one's first restart file")
    done = completed(out)
    assert len(done) == 1
    kept = {p: (p.stat().st_ino, p.stat().st_mtime_ns) for p in done}
    (partial,) = partials()
    name = partial.name[1:-len(".partial")]
    assert not (out / "points" / name / "run.json").exists(), \
        f"the interrupted point {name} was put in place as if it had completed"
    record = json.loads((partial / "run.json").read_text())
    assert record["status"] == "interrupted", record["status"]
    first_stop = _newest_restart(partial)
    assert first_stop > 0, "the partial run and its restart files are kept"
    assert f"partial run kept in points/{partial.name} (newest usable restart " in log, log
    time.sleep(0.5)
    assert processes_in(out) == {}, "an engine was left running"
    assert not lock_held(partial)
    assert not (out / "failed").exists(), "an interrupt is not a failed run"

    # 2. the next sweep resumes it; stop that one too once it has written a newer restart
    _stop(_start(filmfriction_command, args),
          lambda: _newest_restart(partial) > first_stop,
          "the resumed run's next restart file")
    record = json.loads((partial / "run.json").read_text())
    assert record["status"] == "interrupted" and record["resumed_from"] == f"restart.{first_stop}"
    second_stop = _newest_restart(partial)
    assert second_stop > first_stop, "the resume's own progress is kept"
    assert not (out / "points" / name / "run.json").exists() and not (out / "failed").exists()
    time.sleep(0.5)
    assert processes_in(out) == {}, "an engine was left running"

    # 3. the third sweep finishes it from there
    r = subprocess.run([filmfriction_command, "sweep", *args], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    for p, stamp in kept.items():
        assert (p.stat().st_ino, p.stat().st_mtime_ns) == stamp, f"{p} was re-run"
    agg = sweep.load_aggregate(out)
    assert len(agg.points) == 2
    for run_dir in agg.run_dirs:
        assert json.loads((run_dir / "run.json").read_text())["status"] == "completed"
        assert (run_dir / "analysis.json").exists()
    resumed = out / "points" / name
    record = json.loads((resumed / "run.json").read_text())
    assert record["resumed_from"] == f"restart.{second_stop}"
    assert len(record["commands"]) == 3, "started once, resumed twice, never afresh"
    # the same steps as the point that ran in one go, none twice, none missing at a seam
    trace, whole = md.trace(resumed), md.trace(next(iter(kept)).parent)
    assert len(trace) == len(whole) == steps["slide_steps"] // steps["trace_every"] + 1
    assert trace["step"][0] == 0 and trace["step"][-1] == steps["slide_steps"]
    assert np.all(np.diff(trace["step"]) == steps["trace_every"])
    assert md.ledger_closure(trace) < 0.02
    assert not list(out.glob("points/.*")), "no partial run left behind"
    assert not (out / "superseded").exists() and not (out / "failed").exists()


@pytest.mark.parametrize("lo, hi, at_least", [(0.013, 0.062, 2), (8.0, 60.0, 2), (1e-3, 1.0, 4)])
def test_a_log_axis_of_the_sweep_figures_is_labelled_over_any_range(lo, hi, at_least):
    """Under a decade there is no power of ten to label: the axis had no numbers at all."""
    from filmfriction.analysis.files.util import pyplot
    from filmfriction.workflows.sweep.figures import _plain_log_axis

    plt = pyplot()
    fig, ax = plt.subplots()
    ax.plot([lo, hi], [1.0, 2.0])
    ax.set_xscale("log")
    _plain_log_axis(ax.xaxis)
    fig.canvas.draw()
    labels = [t.get_text() for t in ax.get_xticklabels(minor=False) + ax.get_xticklabels(minor=True)
              if t.get_text() and lo * 0.9 <= t.get_position()[0] <= hi * 1.1]
    plt.close(fig)
    assert len(labels) >= at_least, labels
    assert all("10^" not in t and "$" not in t for t in labels), labels
