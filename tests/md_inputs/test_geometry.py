"""One geometry (md_inputs/geometry.py, built with ASE): the scene's derived quantities, the
synthetic films and film_slide.lmp's data file.  Checked against the crystal's own
properties, against LAMMPS's lattice commands (tests/md_inputs/lattice_reference.lmp, a tiny
real LAMMPS run, marker md), and run by the script (marker md)."""
import math
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from filmfriction import md_inputs
from filmfriction.md_inputs.contract import DATA_FILE, AtomType
from filmfriction.md_inputs.geometry import fcc111, plane_spacing
from filmfriction.workflows.md import engine
from filmfriction.workflows.md.scene import Scene
from filmfriction.workflows.md.scenes.parameters import derived_quantities, geometry, resolve


def _same_sites(a, b, box, atol=1e-9):
    """Equal sets of positions (any order), periodic in x and y."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, (a.shape, b.shape)
    d = a[:, None, :] - b[None, :, :]
    d[..., :2] -= np.asarray(box) * np.round(d[..., :2] / np.asarray(box))
    dist = np.sqrt((d ** 2).sum(axis=-1))
    nearest = dist.min(axis=1)
    assert nearest.max() < atol, nearest.max()
    assert len(set(dist.argmin(axis=1))) == len(a)      # one to one


def test_spacings_counts_and_stacking():
    a = 1.1
    lat = fcc111(a, (7, 4), planes=4)
    assert lat.box == (7 * a, 4 * math.sqrt(3) * a)
    assert lat.n_atoms == 4 * 56 and lat.positions.shape == (224, 3)
    h = math.sqrt(2 / 3) * a
    assert lat.plane_spacing == plane_spacing(a) == pytest.approx(h)
    np.testing.assert_allclose(np.unique(lat.positions[:, 2]), h * np.arange(4), atol=1e-12)
    plane0 = lat.positions[lat.plane == 0, :2]
    # in a plane every atom has six neighbours at a
    d = plane0[:, None] - plane0[None]
    d -= lat.box * np.round(d / lat.box)
    r = np.sort(np.hypot(d[..., 0], d[..., 1]), axis=1)
    np.testing.assert_allclose(r[:, 1:7], a, rtol=1e-12)
    assert np.all(r[:, 7] > 1.7 * a)
    # ABC: plane 3 sits over plane 0, planes 1 and 2 over neither; each atom has
    # three neighbours at a in the next plane (fcc, not hcp)
    for p, q, over in ((0, 3, True), (0, 1, False), (0, 2, False), (1, 2, False)):
        same = np.allclose(np.sort(lat.positions[lat.plane == p, :2], axis=0),
                           np.sort(lat.positions[lat.plane == q, :2], axis=0))
        assert same is over, (p, q)
    nxt = lat.positions[lat.plane == 1]
    d = lat.positions[lat.plane == 0][:, None] - nxt[None]
    d[..., :2] -= np.asarray(lat.box) * np.round(d[..., :2] / np.asarray(lat.box))
    assert np.all(np.sum(np.isclose(np.sqrt((d ** 2).sum(-1)), a), axis=1) == 3)


def test_a_fitted_film_is_stretched_to_the_box():
    film = fcc111(1.0, planes=2, fit=(7.7, 4 * math.sqrt(3) * 1.1))
    assert film.cells == (8, 4)
    assert film.box == (7.7, 4 * math.sqrt(3) * 1.1)
    np.testing.assert_allclose(film.strain, (7.7 / 8 - 1, 4.4 / 4 - 1), rtol=1e-12)
    assert film.plane_spacing == plane_spacing(1.0)   # the planes keep the film's own spacing
    with pytest.raises(ValueError, match="either cells or fit"):
        fcc111(1.0, (2, 2), fit=(3.0, 3.0))


def test_the_scene_counts_from_the_geometry():
    p = resolve({})
    q = derived_quantities(p)
    wall = fcc111(p["wall_spacing"], (p["cells_x"], p["cells_y"]), q["wall_layers"])
    film = fcc111(p["film_spacing"], planes=p["film_layers"], fit=wall.box)
    assert (q["box_x"], q["box_y"]) == wall.box
    assert q["wall_atoms_per_layer"] == wall.atoms_per_plane == 56
    assert q["film_atoms"] == film.n_atoms == 168
    assert q["wall_layers"] == math.ceil(p["cutoff"] / wall.plane_spacing) + 1 == 4
    # numbers the scene had before it used the geometry (7 x 4 cells, 1.1 sigma)
    assert q["area"] == pytest.approx(7.7 * 4 * math.sqrt(3) * 1.1, rel=1e-15)
    strained = resolve({"film_spacing": 1.05, "cells_x": 9})
    s = derived_quantities(strained)
    assert s["film_atoms_per_layer"] == 2 * round(9.9 / 1.05) * round(4 * math.sqrt(3) * 1.1
                                                                        / (math.sqrt(3) * 1.05))
    assert s["film_strain_x"] == pytest.approx(9.9 / round(9.9 / 1.05) / 1.05 - 1, rel=1e-12)


def test_the_synthetic_film_is_the_geometry(tmp_path):
    import MDAnalysis as mda

    from filmfriction.analysis.groundtruth.synthetic import layered_film

    a, nx, ny = 1.1, 6, 4
    top, _ = layered_film(tmp_path, layers=3, nx=nx, ny=ny, spacing=a, wall_planes=2, frames=1)
    u = mda.Universe(str(top), atom_style="id type x y z")
    h = plane_spacing(a)
    lat = fcc111(a, (nx, ny), 7, z0=h)
    np.testing.assert_allclose(u.atoms.positions, lat.positions, atol=2e-6)
    # the numbers the synthetic film had before it used the geometry
    i, j = np.meshgrid(np.arange(nx), np.arange(2 * ny), indexing="ij")
    base = np.column_stack([(i + 0.5 * (j % 2)).ravel() * a, (j * np.sqrt(3.0) / 2).ravel() * a])
    shifts = [(0.0, 0.0), (0.5 * a, a / (2 * np.sqrt(3))), (a, a / np.sqrt(3))]
    old = np.vstack([np.column_stack([np.mod(base + shifts[p % 3], [nx * a, ny * np.sqrt(3) * a]),
                                      np.full(len(base), (p + 1) * h)]) for p in range(7)])
    _same_sites(lat.positions, old, lat.box, atol=1e-12)
    assert list(np.unique(u.atoms.types.astype(int))) == [1, 2, 3]


def _atoms(data_file):
    """Box ((lo, hi) along x, y, z) and (type, x, y, z) rows of a LAMMPS data file
    (atom_style atomic)."""
    lines = data_file.read_text().splitlines()
    box = {}
    for line in lines:
        parts = line.split()
        if len(parts) >= 4 and parts[2:4] in (["xlo", "xhi"], ["ylo", "yhi"], ["zlo", "zhi"]):
            box[parts[2][0]] = (float(parts[0]), float(parts[1]))
    start = next(i for i, line in enumerate(lines) if line.startswith("Atoms")) + 2
    rows = []
    for line in lines[start:]:
        if not line.strip():
            break
        f = line.split()
        rows.append([int(f[1]), float(f[2]), float(f[3]), float(f[4])])
    return (box["x"], box["y"], box["z"]), np.array(rows)


def _sorted_rows(rows, box):
    """Rows wrapped into the box in x and y (a site on the boundary at 0) and sorted."""
    rows = rows.copy()
    lengths = np.array([box[0][1] - box[0][0], box[1][1] - box[1][0]])
    rows[:, 1:3] = np.mod(rows[:, 1:3] + 1e-9, lengths) - 1e-9
    key = np.round(rows, 6)
    return rows[np.lexsort((key[:, 2], key[:, 1], key[:, 3], key[:, 0]))]


def _geometry(wall_model="rigid", **overrides):
    return geometry(resolve({"wall_model": wall_model, **overrides}))


def test_the_data_file_holds_the_geometry(tmp_path):
    g = _geometry("flexible")
    path = tmp_path / "geometry.data"
    path.write_text(g.lammps_data())
    box, rows = _atoms(path)
    assert "5 atom types" in path.read_text()
    assert box[0] == (0.0, g.bottom.box[0]) and box[1] == (0.0, g.bottom.box[1])
    assert box[2] == pytest.approx(g.box[2], rel=1e-15)
    # every atom inside the box, the bottom wall's first plane half a plane above zlo
    assert rows[:, 3].min() == 0.0 == box[2][0] + 0.5 * g.bottom.plane_spacing
    assert rows[:, 3].max() < box[2][1] - g.cutoff
    types, counts = np.unique(rows[:, 0].astype(int), return_counts=True)
    nw, per_plane = g.wall_planes, g.bottom.atoms_per_plane
    assert dict(zip(types.tolist(), counts.tolist())) == {
        AtomType.FILM: g.film.n_atoms, AtomType.BOTTOM_WALL: per_plane,
        AtomType.TOP_WALL: per_plane, AtomType.BOTTOM_FLEXIBLE: (nw - 1) * per_plane,
        AtomType.TOP_FLEXIBLE: (nw - 1) * per_plane}
    # the outermost plane of each wall is the rigid one
    z = {t: rows[rows[:, 0] == t, 3] for t in types}
    assert z[AtomType.BOTTOM_WALL].max() < z[AtomType.BOTTOM_FLEXIBLE].min()
    assert z[AtomType.TOP_WALL].min() > z[AtomType.TOP_FLEXIBLE].max()
    # the layout: the film one film plane above the bottom wall, the top wall one film
    # plane and 0.3 sigma of room above the film
    hf = plane_spacing(g.film_spacing)
    assert z[AtomType.FILM].min() == pytest.approx(z[AtomType.BOTTOM_FLEXIBLE].max() + hf)
    assert z[AtomType.TOP_FLEXIBLE].min() == pytest.approx(z[AtomType.FILM].max() + hf + 0.3)
    # rigid walls: no flexible types, and ase reads the file back type for type
    from ase.io import read

    rigid = _geometry()
    path.write_text(rigid.lammps_data())
    back = read(path, format="lammps-data", atom_style="atomic", units="metal")
    assert "5 atom types" in path.read_text()
    assert sorted(set(back.numbers)) == [AtomType.FILM, AtomType.BOTTOM_WALL, AtomType.TOP_WALL]
    assert len(back) == rigid.film.n_atoms + 2 * rigid.bottom.n_atoms


def test_one_abc_stacking_through_wall_film_and_wall():
    g = _geometry()
    atoms = g.atoms()
    z = np.round(atoms.positions[:, 2], 9)
    planes = np.unique(z)
    assert planes.size == 2 * g.wall_planes + g.film_layers
    # consecutive planes never sit over each other; planes three apart do (the film
    # has the walls' spacing in the default scene)
    xy = [np.sort(atoms.positions[z == p, :2].round(6), axis=0) for p in planes]
    for i in range(planes.size - 1):
        assert not np.array_equal(xy[i], xy[i + 1]), i
    for i in range(planes.size - 3):
        assert np.array_equal(xy[i], xy[i + 3]), i


@pytest.mark.md
@pytest.mark.parametrize("wall_model,overrides", [
    ("rigid", {}), ("flexible", {}),
    ("rigid", {"film_spacing": 1.05, "cells_x": 9, "cells_y": 5, "film_layers": 4,
               "wall_spacing": 1.0})])
def test_ase_builds_what_the_lattice_commands_built(tmp_path, wall_model, overrides):
    """ASE's data file against the atoms LAMMPS's lattice commands create (the geometry
    section film_slide.lmp had, tests/md_inputs/lattice_reference.lmp): same box, same
    types, same positions (1e-6 sigma) after sorting."""
    p = resolve({"wall_model": wall_model, **overrides})
    names = ("wall_spacing", "film_spacing", "wall_layers", "cells_x", "cells_y", "film_layers",
             "cutoff")
    variables = {n: repr(p[n]) if isinstance(p[n], float) else str(p[n]) for n in names}
    variables["wall_model"] = str(int(wall_model == "flexible"))
    reference = Path(__file__).with_name("lattice_reference.lmp")
    cmd = engine.lmp_command(1, reference, variables)
    out = subprocess.run(cmd, cwd=tmp_path, env=engine.engine_env(), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stdout[-3000:]
    box_ref, ref = _atoms(tmp_path / "lattice.data")
    (tmp_path / "geometry.data").write_text(geometry(p).lammps_data())
    box, ours = _atoms(tmp_path / "geometry.data")
    np.testing.assert_allclose(np.array(box), np.array(box_ref), rtol=0, atol=1e-9)
    assert ours.shape == ref.shape
    ref, ours = _sorted_rows(ref, box), _sorted_rows(ours, box)
    np.testing.assert_array_equal(ours[:, 0], ref[:, 0])
    np.testing.assert_allclose(ours[:, 1:], ref[:, 1:], rtol=0, atol=1e-6)
    # and the test can fail: one plane of the film moved by 1e-5 sigma is seen
    moved = ours.copy()
    moved[moved[:, 0] == AtomType.FILM, 3] += 1e-5
    with pytest.raises(AssertionError):
        np.testing.assert_allclose(moved[:, 1:], ref[:, 1:], rtol=0, atol=1e-6)


@pytest.mark.md
@pytest.mark.parametrize("wall_model", ["rigid", "flexible"])
def test_the_script_reads_the_geometry(tmp_path, wall_model):
    """film_slide.lmp, run for 0 steps with the default scene, starts from the data file:
    its topology.data (written before any step) holds the same atoms, and the gap is
    measured between the walls' facing planes."""
    p = resolve({"wall_model": wall_model})
    scene = Scene(name="geometry", description="", models="", outputs=(),
                  expected_cost="", parameters=p)
    g = scene.geometry()
    (tmp_path / DATA_FILE).write_text(g.lammps_data())
    variables = {**scene.lammps_variables(), "equilibrate_steps": "0", "slide_steps": "0",
                 "dump_every": "1000", "thermo_every": "1000"}
    cmd = engine.lmp_command(1, md_inputs.script("film_slide.lmp"), variables)
    out = subprocess.run(cmd, cwd=tmp_path, env=engine.engine_env(), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stdout[-3000:]
    box, atoms = _atoms(tmp_path / "topology.data")
    box0, atoms0 = _atoms(tmp_path / DATA_FILE)
    np.testing.assert_allclose(np.array(box), np.array(box0), rtol=0, atol=1e-9)
    np.testing.assert_allclose(_sorted_rows(atoms, box), _sorted_rows(atoms0, box), atol=1e-9)
    # the gap: the top wall's first plane above the bottom wall's last
    gap = re.search(r"^\s*0\s+0\s+\S+\s+\S+\s+\S+\s+(\S+)", out.stdout, re.M)
    assert gap, out.stdout[-2000:]
    assert float(gap.group(1)) == pytest.approx(g.top.z0 - g.bottom.top, rel=1e-6)  # thermo: 7 digits


@pytest.mark.md
def test_the_script_refuses_a_data_file_of_other_parameters(tmp_path):
    p = resolve({})
    scene = Scene(name="geometry", description="", models="", outputs=(),
                  expected_cost="", parameters=p)
    (tmp_path / DATA_FILE).write_text(_geometry(film_layers=4).lammps_data())
    variables = {**scene.lammps_variables(), "equilibrate_steps": "0", "slide_steps": "0"}
    cmd = engine.lmp_command(1, md_inputs.script("film_slide.lmp"), variables)
    out = subprocess.run(cmd, cwd=tmp_path, env=engine.engine_env(), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode != 0
    assert "was not built for these parameters" in out.stdout
    assert "4 film planes" in out.stdout and "film_layers 3" in out.stdout
    (tmp_path / DATA_FILE).unlink()
    out = subprocess.run(cmd, cwd=tmp_path, env=engine.engine_env(), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode != 0 and f"no data file {DATA_FILE}" in out.stdout
