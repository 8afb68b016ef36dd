"""One fcc(111) geometry (md_inputs/geometry.py): the scene's derived quantities and the
synthetic films use it, ase builds the same crystal, and so does film_slide.lmp (a tiny
real LAMMPS run, marker md)."""
import math
import subprocess

import numpy as np
import pytest
from ase.build import fcc111 as ase_fcc111

from filmfriction import md_inputs
from filmfriction.md_inputs.contract import AtomType
from filmfriction.md_inputs.geometry import fcc111, plane_spacing
from filmfriction.workflows import engine
from filmfriction.workflows.scene import Scene, derived_quantities, resolve


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


@pytest.mark.parametrize("planes", [3, 4])
def test_the_same_crystal_as_ase(planes):
    # ase's orthogonal fcc111 (cubic constant a*sqrt(2), 2 rows per cell along y)
    # ends every slab on an A plane: its first plane has stacking index 1 - planes
    a = 1.1
    ref = ase_fcc111("Cu", size=(5, 6, planes), a=a * math.sqrt(2), orthogonal=True,
                     periodic=True)
    ours = fcc111(a, (5, 3), planes=planes, stacking=1 - planes)
    np.testing.assert_allclose(ours.box, ref.cell.lengths()[:2], rtol=1e-12)
    assert ref.positions[:, 2].min() == 0.0
    _same_sites(ours.positions, ref.positions, ours.box)
    # and not another stacking
    with pytest.raises(AssertionError):
        _same_sites(fcc111(a, (5, 3), planes=planes, stacking=2 - planes).positions,
                    ref.positions, ours.box)


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

    from filmfriction.analysis.synthetic import layered_film

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
    np.testing.assert_allclose(lat.positions, old, rtol=0, atol=1e-12)
    assert list(np.unique(u.atoms.types.astype(int))) == [1, 2, 3]


def _atoms(data_file):
    """Box (Lx, Ly) and (type, x, y, z) rows of a LAMMPS data file (atom_style atomic)."""
    lines = data_file.read_text().splitlines()
    box = {}
    for line in lines:
        parts = line.split()
        if len(parts) == 4 and parts[2:] in (["xlo", "xhi"], ["ylo", "yhi"]):
            box[parts[2][0]] = float(parts[1]) - float(parts[0])
    start = next(i for i, line in enumerate(lines) if line.startswith("Atoms")) + 2
    rows = []
    for line in lines[start:]:
        if not line.strip():
            break
        f = line.split()
        rows.append([int(f[1]), float(f[2]), float(f[3]), float(f[4])])
    return (box["x"], box["y"]), np.array(rows)


@pytest.mark.md
@pytest.mark.parametrize("wall_model", ["rigid", "flexible"])
def test_the_script_builds_the_python_geometry(tmp_path, wall_model):
    """film_slide.lmp's lattice commands, run for 0 steps with the default scene, place
    every atom where md_inputs.geometry.fcc111 does (the script's z layout: the film one
    film plane above the bottom wall, the top wall 0.3 sigma of room above the film)."""
    p = resolve({"wall_model": wall_model})
    scene = Scene(name="geometry", description="", models="", observables=(),
                  expected_cost="", parameters=p)
    variables = {**scene.lammps_variables(), "equilibrate_steps": "0", "slide_steps": "0",
                 "dump_every": "1000", "thermo_every": "1000"}
    cmd = engine.lmp_command(1, md_inputs.script("film_slide.lmp"), variables)
    out = subprocess.run(cmd, cwd=tmp_path, env=engine.engine_env(), capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stdout[-3000:]
    box, atoms = _atoms(tmp_path / "topology.data")   # written before any step is taken

    q = derived_quantities(p)
    d, n, nw = p["wall_spacing"], p["film_layers"], q["wall_layers"]
    origin = (0.25, 0.125)            # the script's lattice origin, off the boundary
    bottom = fcc111(d, (p["cells_x"], p["cells_y"]), nw, origin=origin)
    assert box == pytest.approx(bottom.box, rel=1e-12)
    hw, hf = bottom.plane_spacing, plane_spacing(p["film_spacing"])
    zf0 = (nw - 1) * hw + hf
    film = fcc111(p["film_spacing"], planes=n, fit=bottom.box, z0=zf0, stacking=nw,
                  origin=origin)
    top = fcc111(d, (p["cells_x"], p["cells_y"]), nw, z0=zf0 + n * hf + 0.3, stacking=nw + n,
                 origin=origin)

    def sites(types):
        return atoms[np.isin(atoms[:, 0], [int(t) for t in types]), 1:]

    flexible = wall_model == "flexible"
    _same_sites(sites([AtomType.FILM]), film.positions, box)
    _same_sites(sites([AtomType.BOTTOM_WALL, AtomType.BOTTOM_FLEXIBLE]), bottom.positions, box)
    _same_sites(sites([AtomType.TOP_WALL, AtomType.TOP_FLEXIBLE]), top.positions, box)
    # flexible walls: every plane but the outermost one of each wall is mobile
    _same_sites(sites([AtomType.BOTTOM_WALL]),
                bottom.positions[bottom.plane == 0] if flexible else bottom.positions, box)
    _same_sites(sites([AtomType.TOP_WALL]),
                top.positions[top.plane == nw - 1] if flexible else top.positions, box)
    assert len(sites([AtomType.BOTTOM_FLEXIBLE])) == (nw - 1) * bottom.atoms_per_plane * flexible
    assert len(sites([AtomType.TOP_FLEXIBLE])) == (nw - 1) * top.atoms_per_plane * flexible
    assert len(sites([AtomType.FILM])) == q["film_atoms"]
