"""Real (small) LAMMPS runs through the runner: the MD scene does what it claims.

Most checks read the session's shared ``film_run`` (conftest.py): film-structure
on the 5 x 3 box, 2000 + 12000 steps at V = 0.05, with trajectory and profiles.
"""
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import find_peaks

from filmfriction.analysis.files.trace_reader import read_trace
from filmfriction.workflows.md import runner
from filmfriction.workflows.md.scene import SceneError

pytestmark = pytest.mark.md

# the settings of the runs made here (the box comes from the md fixture)
SMALL = {"equilibrate_steps": 2000, "slide_steps": 6000, "trace_every": 20}


@pytest.fixture(scope="module")
def short_run(film_run):
    return film_run.scene, film_run.path


def test_record_and_outputs(short_run):
    scene, run_dir = short_run
    record = json.loads((run_dir / "run.json").read_text())
    assert record["status"] == "completed" and record["error"] is None
    assert record["atoms"]["film"] == 3 * 2 * 5 * 3
    # the film's mass, what the slip law's rule takes for the most a co-moving mass can be
    assert record["trace_parameters"]["film_mass"] == 3 * 2 * 5 * 3
    assert read_trace(run_dir).parameters.film_mass == 3 * 2 * 5 * 3
    # the walls' registry period along the slide (aligned walls: their spacing), which the
    # slip law fits a periodic force of
    spacing = scene.parameters["wall_spacing"]
    assert record["trace_parameters"]["registry_period"] == spacing
    assert read_trace(run_dir).parameters.registry_period == spacing
    assert record["outputs"]["trajectory"] and record["outputs"]["profiles"]
    assert (run_dir / "trajectory.dcd").stat().st_size > 0
    assert (run_dir / "topology.data").stat().st_size > 0
    assert record["atom_steps_per_second"] > 0
    header = (run_dir / "trace.csv").read_text().splitlines()[0].split(",")
    assert tuple(header) == runner.TRACE_COLUMNS
    assert "lmp" in (run_dir / "command.txt").read_text()


def test_spring_force_is_k_times_extension(short_run, md):
    scene, run_dir = short_run
    d = md.trace(run_dir)
    k = scene.parameters["spring_constant"]
    expected = k * (d["drive_position"] - d["wall_position"])
    assert np.allclose(d["spring_force"], expected, rtol=1e-6, atol=1e-5 * k)
    # the drive moves at V
    v = scene.parameters["drive_velocity"]
    assert np.allclose(d["drive_position"], v * d["time"], atol=1e-9 + 1e-7 * v * d["time"][-1])


def test_thermostat_holds_temperature(short_run, md):
    scene, run_dir = short_run
    d = md.trace(run_dir)
    t_target = scene.parameters["temperature"]
    mean = d["film_temperature"].mean()
    assert abs(mean - t_target) < 0.08 * t_target, mean


def test_energy_ledger_closes(short_run, md):
    _, run_dir = short_run
    closure = md.ledger_closure(md.trace(run_dir))
    assert closure < 0.02, closure


def test_film_has_n_layers(short_run):
    scene, run_dir = short_run
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
def test_layer_count_follows_scene(layered_run, layers):
    run = layered_run(layers)
    n, z = _profile_layers(run.path / "profiles" / "density.profile")
    assert n == layers, z


def test_never_overwrites(tmp_path, md):
    out = tmp_path / "taken"
    out.mkdir()
    (out / "precious.txt").write_text("keep me")
    with pytest.raises(SceneError, match="already exists"):
        runner.execute(md.scene("stick-slip", **SMALL), out=out, progress=False)
    assert (out / "precious.txt").read_text() == "keep me"


def test_engine_failure_is_a_clear_error(tmp_path, md):
    # bypass the validator on purpose: a time step far past stability
    scene = md.scene("stick-slip", **SMALL)
    scene = replace(scene, parameters={**scene.parameters, "timestep": 0.05,
                                       "wall_fluid_epsilon": 8.0, "normal_pressure": 40.0})
    with pytest.raises(runner.RunFailed) as err:
        md.execute(scene, tmp_path / "boom", nprocs=2)
    record = json.loads((tmp_path / "boom" / "run.json").read_text())
    assert record["status"] == "failed"
    assert record["error"] and ("ERROR" in record["error"] or "blew up" in record["error"]
                                or "NaN" in record["error"])
    assert record["error"] in str(err.value)
    # partial results kept: the trace starts with the contract's header
    header = (tmp_path / "boom" / "trace.csv").read_text().splitlines()[0]
    assert tuple(header.split(",")) == runner.TRACE_COLUMNS


def test_interrupted_run_resumes(tmp_path, md, filmfriction_command):
    out = tmp_path / "interrupted"
    cmd = [filmfriction_command, "run", "stick-slip", "--md-only", "--quiet", "--out", str(out)]
    cmd += [f"--set={k}={v}" for k, v in
            {**md.box, **SMALL, "slide_steps": 20000, "restart_every": 2000}.items()]
    md.killed_at(cmd, out)
    assert list(out.glob("restart.*")), "no restart file was written before the kill"
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "running"  # killed hard: the record says so

    runner.resume(out, progress=False)
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "completed"
    d = md.trace(out)
    assert d["step"][-1] == 20000
    assert np.all(np.diff(d["step"]) > 0)  # no duplicated or missing order
    assert np.allclose(np.diff(d["step"]), SMALL["trace_every"])
    assert md.ledger_closure(d) < 0.02


def test_analysis_of_a_real_run(film_run):
    """The analysis on a real small run: slips found, ledger closed, n layers in the DCD."""
    from filmfriction.analysis.analyze import analyze
    from filmfriction.analysis.files.trace_reader import read_trace

    doc, per_cycle = analyze(read_trace(film_run.path))
    assert doc["slips"]["count"] >= 2
    assert doc["energy"]["ledger"]["closure"]["mean"] < 0.02
    assert doc["structure"]["layers"]["count"] == film_run.parameters["film_layers"]
    fs = np.asarray(per_cycle["static_force"], float)
    assert np.all(fs > 0)
