"""The structure analysis finds the walls by the contract's atom types, so the gap is the
distance between the innermost wall planes for rigid and flexible walls alike."""
import warnings

import MDAnalysis as mda
import numpy as np
import pytest

from filmfriction.analysis.observables.structure_section import summarize_run
from filmfriction.analysis.structure.layering import FilmThickness
from filmfriction.analysis.structure.trajectory_reader import frame_steps
from filmfriction.analysis.groundtruth.synthetic import layered_film
from filmfriction.md_inputs.contract import BOTTOM_WALL_TYPES, TOP_WALL_TYPES
from filmfriction.md_inputs.geometry import plane_spacing

warnings.filterwarnings("ignore", category=DeprecationWarning)


@pytest.mark.parametrize("flexible", [False, True])
def test_gap_between_the_innermost_planes_on_a_synthetic_film(tmp_path, flexible):
    # 3 wall planes each side, 4 film planes: the innermost wall planes are 5 h apart;
    # flexible walls' inner planes rattle like the film (0.05 sigma)
    top, traj = layered_film(tmp_path, layers=4, wall_planes=3, frames=6,
                             flexible_walls=flexible)
    doc = summarize_run(top, traj)
    h = plane_spacing(1.1)
    assert doc["layers"]["count"] == 4
    assert doc["gap"]["mean"] == pytest.approx(5 * h, abs=0.03)


def _types(u):
    return {int(t) for t in np.unique(u.atoms.types.astype(int))}


@pytest.mark.md
def test_flexible_walls_gap_is_the_trace_gap(tmp_path):
    """A real small run with flexible walls (the small settings of tests/test_md_walls.py):
    the gap measured from the trajectory is the gap LAMMPS traces, the distance between
    the innermost wall planes (types 4 and 5 here, not the rigid backing planes 2 and 3)."""
    from filmfriction.analysis.files.trace_reader import read_trace
    from filmfriction.workflows.md import runner
    from filmfriction.workflows.md.scene import load

    scene = load("film-structure", {"cells_x": 5, "cells_y": 3, "equilibrate_steps": 2000,
                                    "slide_steps": 2000, "trace_every": 20,
                                    "wall_mass": 300.0, "wall_model": "flexible",
                                    "dump_every": 200})
    run_dir = runner.execute(scene, out=tmp_path / "run", nprocs=2, progress=False)
    trace = read_trace(run_dir)
    u = mda.Universe(str(run_dir / "topology.data"), str(run_dir / "trajectory.dcd"),
                     format="DCD", topology_format="DATA", atom_style="id type x y z")
    assert _types(u) == {1, 2, 3, 4, 5}

    steps = frame_steps(u)
    rows = np.isin(trace.columns["step"], steps)
    traced = trace.columns["gap"][rows]
    assert traced.size == steps.size >= 10

    gap = FilmThickness(u.select_atoms("type " + " ".join(map(str, BOTTOM_WALL_TYPES))),
                        u.select_atoms("type " + " ".join(map(str, TOP_WALL_TYPES)))).run()
    np.testing.assert_allclose(gap.results.gap, traced, atol=1e-3)

    doc = summarize_run(run_dir / "topology.data", run_dir / "trajectory.dcd", trace=trace)
    assert doc["gap"]["mean"] == pytest.approx(float(np.mean(traced)), abs=1e-3)
    # the film's three layers lie between the planes that bound the gap
    n = scene.parameters["film_layers"]
    assert doc["layers"]["count"] == n
    assert 0.5 * (n + 1) * plane_spacing(1.1) < doc["gap"]["mean"] < 1.5 * (n + 1) * 1.1
