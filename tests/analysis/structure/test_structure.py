"""Film structure analyses on a synthetic layered film (DCD written in tmp_path)."""
import warnings

import MDAnalysis as mda
import numpy as np
import pytest

from filmfriction.analysis.structure.hexatic import HexaticOrder
from filmfriction.analysis.structure.layering import DensityProfile, FilmThickness
from filmfriction.analysis.structure.trajectory_reader import frame_steps
from filmfriction.analysis.groundtruth.synthetic import layered_film

warnings.filterwarnings("ignore", category=DeprecationWarning)


def _universe(tmp_path, **kw):
    top, traj = layered_film(tmp_path, **kw)
    return mda.Universe(str(top), str(traj), format="DCD", topology_format="DATA",
                        atom_style="id type x y z")


@pytest.mark.parametrize("layers", [2, 3, 5])
def test_layer_count_and_spacing(tmp_path, layers):
    u = _universe(tmp_path, layers=layers, frames=5)
    prof = DensityProfile(u.select_atoms("type 1")).run()
    lay = prof.results.layers
    assert lay["count"] == layers
    assert lay["spacing"] == pytest.approx(np.sqrt(2 / 3) * 1.1, rel=0.05)
    # density integrates to the number of film atoms per area
    n_per_area = u.select_atoms("type 1").n_atoms / (u.dimensions[0] * u.dimensions[1])
    assert np.sum(prof.results.density) * 0.05 == pytest.approx(n_per_area, rel=1e-3)


def test_hexatic_order_stick_vs_melt(tmp_path):
    u = _universe(tmp_path, layers=3, frames=12, melt_frames=range(6, 12))
    film = u.select_atoms("type 1")
    edges = DensityProfile(film).run(stop=1).results.layers["edges"]
    psi = HexaticOrder(film, edges).run()
    assert psi.results.psi6.shape == (12, 3)
    assert np.all(psi.results.psi6[:6] > 0.8)          # crystalline
    assert np.all(psi.results.psi6[6:] < 0.2)          # in-plane disorder
    sub = HexaticOrder(film, edges).run(start=2, stop=10, step=4)
    np.testing.assert_array_equal(sub.results.frames, [2, 6])


def test_film_thickness_and_steps(tmp_path):
    u = _universe(tmp_path, layers=4, frames=3, nsavc=50)
    gap = FilmThickness(u.select_atoms("type 2"), u.select_atoms("type 3")).run()
    h = np.sqrt(2 / 3) * 1.1
    np.testing.assert_allclose(gap.results.gap, 5 * h, rtol=1e-5)   # 4 film planes between
    np.testing.assert_array_equal(frame_steps(u), [0, 50, 100])


def test_trajectory_time_is_in_tau(tmp_path):
    """MDAnalysis would read the DCD's delta (the LAMMPS timestep) as AKMA time; the
    project's opener gives time = step x timestep."""
    from filmfriction.analysis.structure.trajectory_reader import lammps_frame_interval, open_trajectory

    top, traj = layered_film(tmp_path, layers=2, frames=4, nsavc=500, timestep=0.005)
    plain = mda.Universe(str(top), str(traj), format="DCD", topology_format="DATA",
                         atom_style="id type x y z")
    assert plain.trajectory.dt == pytest.approx(500 * 0.005 * 0.04888821, rel=1e-5)  # AKMA
    assert lammps_frame_interval(traj) == 2.5
    u = open_trajectory(top, traj)
    assert u.trajectory.dt == 2.5
    np.testing.assert_allclose([ts.time for ts in u.trajectory], 2.5 * np.arange(4))
    np.testing.assert_allclose(frame_steps(u) * 0.005, [ts.time for ts in u.trajectory])
    assert open_trajectory(top, traj, dt=1.0).trajectory.dt == 1.0
    assert lammps_frame_interval(top) is None         # not a DCD


@pytest.mark.md
def test_a_lammps_trajectory_time_is_the_trace_time(tmp_path):
    """film_slide.lmp's own DCD: times and dt are dump_every x timestep, and each frame's
    time is the trace's time at its step."""
    import subprocess

    from filmfriction import md_inputs
    from filmfriction.analysis.structure.trajectory_reader import open_trajectory
    from filmfriction.md_inputs.contract import DATA_FILE
    from filmfriction.workflows.md import engine
    from filmfriction.workflows.md.scene import Scene
    from filmfriction.workflows.md.scenes.parameters import resolve

    p = resolve({"timestep": 0.004, "equilibrate_steps": 0, "slide_steps": 60,
                 "dump_every": 20, "trace_every": 10, "restart_every": 0})
    scene = Scene(name="time", description="", models="", outputs=("structure",),
                  expected_cost="", parameters=p)
    (tmp_path / DATA_FILE).write_text(scene.geometry().lammps_data())
    cmd = engine.lmp_command(1, md_inputs.script("film_slide.lmp"), scene.lammps_variables())
    out = subprocess.run(cmd, cwd=tmp_path, env=engine.engine_env(), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stdout[-3000:]
    u = open_trajectory(tmp_path / "topology.data", tmp_path / "trajectory.dcd")
    assert u.trajectory.dt == pytest.approx(20 * 0.004, rel=1e-12)
    times = np.array([ts.time for ts in u.trajectory])
    np.testing.assert_allclose(times, 0.08 * np.arange(len(times)), rtol=1e-12, atol=1e-12)
    trace = np.loadtxt(tmp_path / "trace.dat")
    at = {int(s): t for s, t in trace[:, :2]}
    steps = frame_steps(u)
    assert len(steps) == len(times) >= 3
    np.testing.assert_allclose(times, [at[int(s)] for s in steps], rtol=1e-7)
