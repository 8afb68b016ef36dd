"""Real (small) LAMMPS runs through the runner: the MD scene does what it claims."""
import json
import os
import signal
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import find_peaks

from filmfriction.workflows import runner
from filmfriction.workflows.scene import SceneError, load

pytestmark = pytest.mark.md

# a small box: 5 x 3 cells (Lx 5.5, Ly 5.7 sigma), about 330 atoms
SMALL = {"cells_x": 5, "cells_y": 3, "equilibrate_steps": 2000, "slide_steps": 6000,
         "trace_every": 20}


def small(scene="film-structure", **extra):
    return load(scene, {**SMALL, **extra})


def read_csv(run_dir):
    return np.genfromtxt(run_dir / "trace.csv", delimiter=",", names=True)


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("md") / "run"
    scene = small(profile_every=1000)
    return scene, runner.execute(scene, out=out, nprocs=2, progress=False)


def test_record_and_outputs(short_run):
    scene, run_dir = short_run
    record = json.loads((run_dir / "run.json").read_text())
    assert record["status"] == "completed" and record["error"] is None
    assert record["atoms"]["film"] == 3 * 2 * 5 * 3
    assert record["outputs"]["trajectory"] and record["outputs"]["profiles"]
    assert (run_dir / "trajectory.dcd").stat().st_size > 0
    assert (run_dir / "topology.data").exists()
    assert record["atom_steps_per_second"] > 0
    header = (run_dir / "trace.csv").read_text().splitlines()[0].split(",")
    assert tuple(header) == runner.TRACE_COLUMNS
    assert "lmp" in (run_dir / "command.txt").read_text()


def test_spring_force_is_k_times_extension(short_run):
    scene, run_dir = short_run
    d = read_csv(run_dir)
    k = scene.parameters["spring_constant"]
    expected = k * (d["drive_position"] - d["wall_position"])
    assert np.allclose(d["spring_force"], expected, rtol=1e-6, atol=1e-5 * k)
    # the drive moves at V
    v = scene.parameters["drive_velocity"]
    assert np.allclose(d["drive_position"], v * d["time"], atol=1e-9 + 1e-7 * v * d["time"][-1])


def test_thermostat_holds_temperature(short_run):
    scene, run_dir = short_run
    d = read_csv(run_dir)
    t_target = scene.parameters["temperature"]
    mean = d["film_temperature"].mean()
    assert abs(mean - t_target) < 0.08 * t_target, mean


def test_energy_ledger_closes(short_run):
    _, run_dir = short_run
    d = read_csv(run_dir)
    work = d["drive_work"] + d["load_work"]
    stored = d["potential_energy"] + d["kinetic_energy"] + d["spring_energy"]
    heat = d["thermostat_heat"] + d["mount_heat"]
    residual = (work - work[0]) - (stored - stored[0]) - (heat - heat[0])
    scale = max(abs(d["drive_work"][-1]), np.abs(heat - heat[0]).max())
    assert scale > 0
    assert abs(residual[-1]) < 0.02 * scale, (residual[-1], scale)


def test_film_has_n_layers(short_run):
    scene, run_dir = short_run
    from filmfriction.analysis.structure import DensityProfile  # noqa: F401  (trajectory analysis exists)
    n, _ = _profile_layers(run_dir / "profiles" / "density.profile")
    assert n == scene.parameters["film_layers"]


def _profile_layers(path: Path):
    """Peaks of the film's number density across the gap (fix ave/chunk output)."""
    rows, blocks = [], []
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            continue
        parts = line.split()
        if len(parts) == 3:       # block header: step nchunks total
            if rows:
                blocks.append(rows)
            rows = []
        elif len(parts) >= 4:
            rows.append([float(x) for x in parts])
    if rows:
        blocks.append(rows)
    data = np.array(blocks)                  # (blocks, chunks, columns)
    z, rho = data[0, :, 1], data[:, :, 3].mean(axis=0)
    peaks, _ = find_peaks(rho, prominence=0.2 * rho.max())
    return len(peaks), z[peaks]


@pytest.mark.parametrize("layers", [1, 5])
def test_layer_count_follows_scene(tmp_path, layers):
    scene = small("film-structure", film_layers=layers, slide_steps=1000, profile_every=500,
                  equilibrate_steps=2000)
    run_dir = runner.execute(scene, out=tmp_path / "run", nprocs=2, progress=False)
    n, z = _profile_layers(run_dir / "profiles" / "density.profile")
    assert n == layers, z


def test_never_overwrites(tmp_path):
    out = tmp_path / "taken"
    out.mkdir()
    (out / "precious.txt").write_text("keep me")
    with pytest.raises(SceneError, match="already exists"):
        runner.execute(small("stick-slip"), out=out, progress=False)
    assert (out / "precious.txt").read_text() == "keep me"


def test_engine_failure_is_a_clear_error(tmp_path):
    # bypass the validator on purpose: a time step far past stability
    scene = small("stick-slip")
    scene = replace(scene, parameters={**scene.parameters, "timestep": 0.05,
                                       "wall_fluid_epsilon": 8.0, "normal_pressure": 40.0})
    with pytest.raises(runner.RunFailed) as err:
        runner.execute(scene, out=tmp_path / "boom", progress=False)
    record = json.loads((tmp_path / "boom" / "run.json").read_text())
    assert record["status"] == "failed"
    assert record["error"] and ("ERROR" in record["error"] or "blew up" in record["error"]
                                or "NaN" in record["error"])
    assert record["error"] in str(err.value)
    assert (tmp_path / "boom" / "trace.csv").exists()  # partial results kept


def test_interrupted_run_resumes(tmp_path):
    out = tmp_path / "interrupted"
    cmd = [sys.executable, "-m", "filmfriction.workflows.cli", "run", "stick-slip", "--md-only", "--quiet",
           "--out", str(out)] + [f"--set={k}={v}" for k, v in
                                 {**SMALL, "slide_steps": 20000, "restart_every": 2000}.items()]
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while time.time() < deadline and not list(out.glob("restart.4000")):
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    assert list(out.glob("restart.*")), "no restart file was written before the kill"
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "running"  # killed hard: the record says so

    runner.resume(out, progress=False)
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "completed"
    d = read_csv(out)
    assert d["step"][-1] == 20000
    assert np.all(np.diff(d["step"]) > 0)  # no duplicated or missing order
    assert np.allclose(np.diff(d["step"]), SMALL["trace_every"])
    work = d["drive_work"] + d["load_work"]
    stored = d["potential_energy"] + d["kinetic_energy"] + d["spring_energy"]
    heat = d["thermostat_heat"] + d["mount_heat"]
    residual = (work - work[0]) - (stored - stored[0]) - (heat - heat[0])
    assert abs(residual[-1]) < 0.02 * max(abs(work[-1]), abs(heat[-1]))


def test_analysis_of_a_real_run(tmp_path):
    """The analysis on a real small run: slips found, ledger closed, n layers in the DCD."""
    from filmfriction.analysis.report import analyze
    from filmfriction.analysis.trace import read_trace

    scene = small("film-structure", drive_velocity=0.05, slide_steps=12000, dump_every=500)
    run_dir = runner.execute(scene, out=tmp_path / "run", nprocs=2, progress=False)
    doc, per_cycle = analyze(read_trace(run_dir))
    assert doc["slips"]["count"] >= 2
    assert doc["energy"]["ledger"]["closure"]["mean"] < 0.02
    assert doc["structure"]["layers"]["count"] == scene.parameters["film_layers"]
    fs = np.asarray(per_cycle["static_force"], float)
    assert np.all(fs > 0)
