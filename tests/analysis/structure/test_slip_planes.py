"""Which plane of the film slides (analysis/structure/slip_planes.py) and the slips' planes by
slider mass (benchmarks/slip_law/sliding_planes.py), on films of known plane velocities."""
from __future__ import annotations

import json

import numpy as np
import pytest

from filmfriction.analysis.groundtruth.synthetic import layered_film
from filmfriction.analysis.structure.slip_planes import LayerDisplacement, active_plane
from filmfriction.analysis.structure.trajectory_reader import film_layers, select_types

#: bottom wall, three layers, top wall (σ/τ): the middle layer | the top layer slides most
VELOCITY = (0.0, 0.0, 0.2, 1.0, 1.0)


def test_each_layers_displacement_follows_its_velocity(tmp_path):
    top, traj = layered_film(tmp_path, layers=3, frames=20, nsavc=100, thermal=0.02,
                             plane_velocity=VELOCITY)
    u, film, prof = film_layers(top, traj, (1,))
    disp = LayerDisplacement(film, select_types(u, (2,)), select_types(u, (3,)),
                             prof.results.layers["edges"]).run()
    t = 0.5 * np.arange(20)                        # 100 steps of 0.005 τ per frame
    x = np.column_stack([disp.results.wall_x[:, 0], disp.results.layer_x,
                         disp.results.wall_x[:, 1]])
    slopes = np.polyfit(t, x - x[0], 1)[0]
    np.testing.assert_allclose(slopes, VELOCITY, atol=5e-3)
    plane, share = active_plane(x, dt=0.5, window=2.0)
    assert set(plane.tolist()) == {2}               # the second layer | the third
    np.testing.assert_allclose(share, 0.8, atol=0.02)
    with pytest.raises(ValueError, match="layer_edges"):
        LayerDisplacement(film, film, film, [1.0])
    with pytest.raises(ValueError, match="bodies"):
        active_plane(np.zeros((10, 1)), 0.5, 2.0)


def _run(tmp_path, mass, melt_frames=()):
    """A run directory of that film: one slip over the whole trajectory."""
    tmp_path.mkdir()
    layered_film(tmp_path, layers=3, frames=40, nsavc=100, thermal=0.02,
                 plane_velocity=VELOCITY, melt_frames=melt_frames)
    steps = 50 * np.arange(79)
    (tmp_path / "trace.csv").write_text("time,step,wall_position,spring_force\n" + "\n".join(
        f"{0.005 * s:g},{s},{0.005 * s:g},1.0" for s in steps) + "\n")
    (tmp_path / "run.json").write_text(json.dumps({"trace_parameters": {
        "mass": mass, "drive_velocity": 1.0, "mount_damping": 0.0, "registry_period": 1.1}}))
    (tmp_path / "analysis_cycles.csv").write_text("yield_index,stick_index\n2,70\n")
    (tmp_path / "analysis.json").write_text(json.dumps(
        {"source": {"parameters": {"mass": mass}}}))
    return tmp_path


def test_the_slips_planes_grouped_by_mass(tmp_path, benchmark_module, capsys):
    main = benchmark_module("slip_law/sliding_planes").main
    a, b = _run(tmp_path / "a", 1000.0), _run(tmp_path / "b", 3000.0)
    assert main([str(a), str(b)]) == 0
    rows = [r for r in capsys.readouterr().out.splitlines() if r.startswith("| 1000 |")
            or r.startswith("| 3000 |")]
    assert len(rows) == 2
    for row in rows:
        cells = [c.strip() for c in row.split("|")[1:-1]]
        assert cells[1:3] == ["1", "1"]
        assert [float(q) for q in cells[4].split()] == pytest.approx([0, 0.2, 0.8, 0],
                                                                       abs=0.02)
        assert float(cells[5].split(" ± ")[0]) == pytest.approx(0.8, abs=0.02)
        assert cells[7].startswith("0.00;")        # one plane throughout: no change
        assert cells[8] == "–"                     # and no slide between changes
    # the force at the changes: one plane throughout, no change to read it at
    assert main([str(a), str(b), "--hop-force"]) == 0
    out = capsys.readouterr().out.splitlines()
    rows = out[out.index(next(r for r in out if "bump at the changes" in r)) + 2:]
    assert [r.split("|")[2].strip() for r in rows] == ["1, 0", "1, 0"]
    with pytest.raises(SystemExit):
        main([str(tmp_path)])
    assert "without an analysis" in capsys.readouterr().err


def test_the_slips_in_plane_order_by_mass(tmp_path, benchmark_module, capsys):
    # ``--psi6``: a crystalline film keeps ψ6 ≈ 1 before and in its slip; one whose layers
    # are randomised in plane from the slip's yield on (shear-melted) loses it in the slip
    main = benchmark_module("slip_law/sliding_planes").main
    a = _run(tmp_path / "a", 1000.0)
    b = _run(tmp_path / "b", 3000.0, melt_frames=range(1, 40))
    assert main([str(a), str(b), "--psi6"]) == 0
    out = capsys.readouterr().out.split("ψ6 before the slips")[1]
    rows = {r.split("|")[1].strip(): [c.strip() for c in r.split("|")[2:-1]]
            for r in out.splitlines() if r.startswith("| 1000 |") or r.startswith("| 3000 |")}
    crystal, melted = rows["1000"], rows["3000"]
    for cell in crystal + melted[:1]:
        assert min(map(float, cell.split(", "))) > 0.9, (crystal, melted)
    for cell in melted[1:]:
        assert max(map(float, cell.split(", "))) < 0.5, melted

