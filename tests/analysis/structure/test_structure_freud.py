"""ψ6 per layer (analysis/structure/hexatic.py) against the field's tool, freud's ``order.Hexatic``,
and the Verlet list it uses against a fresh neighbour search in every frame."""
import warnings

import MDAnalysis as mda
import numpy as np
import pytest
from scipy.spatial import cKDTree

from filmfriction.analysis.structure.hexatic import HexaticOrder, LayerNeighbours, psi6_per_layer
from filmfriction.analysis.structure.layering import DensityProfile
from filmfriction.analysis.groundtruth.synthetic import layered_film

freud = pytest.importorskip("freud")
warnings.filterwarnings("ignore", category=DeprecationWarning)


@pytest.fixture(scope="module")
def film(tmp_path_factory):
    """3 layers of 2 x 10 x 6 atoms, thermal frames then shear-melted ones."""
    top, traj = layered_film(tmp_path_factory.mktemp("freud"), layers=3, nx=10, ny=6,
                             frames=16, thermal=0.12, melt_frames=range(10, 16), seed=3)
    u = mda.Universe(str(top), str(traj), format="DCD", topology_format="DATA",
                     atom_style="id type x y z")
    film = u.select_atoms("type 1")
    edges = DensityProfile(film).run(stop=1).results.layers["edges"]
    return u, film, edges


def _freud_psi6(u, film, edges, k=6):
    """|<psi_j>| and <|psi_j|> per layer and frame from freud (2D box per layer, the
    neighbour distance of analysis.structure's default)."""
    n_layers = len(edges) - 1
    neighbours = LayerNeighbours(n_layers)
    out, local = [], []
    for _ in u.trajectory:
        lx, ly = u.dimensions[:2]
        box = freud.box.Box(lx, ly, is2D=True)
        layer = np.searchsorted(edges, film.positions[:, 2]) - 1
        rc = neighbours.cutoffs(layer, (lx, ly))
        row, row_local = [], []
        for i in range(n_layers):
            pts = np.zeros((np.sum(layer == i), 3), np.float32)
            pts[:, :2] = film.positions[layer == i, :2]
            pts = box.wrap(pts)
            hexatic = freud.order.Hexatic(k=k)
            hexatic.compute((box, pts), neighbors={"r_max": float(rc[i])})
            nlist = freud.locality.AABBQuery(box, pts).query(
                pts, {"r_max": float(rc[i]), "exclude_ii": True}).toNeighborList()
            has = np.bincount(nlist.query_point_indices, minlength=len(pts)) > 0
            psi = hexatic.particle_order[has]
            row.append(abs(psi.mean()))
            row_local.append(np.abs(psi).mean())
        out.append(row)
        local.append(row_local)
    return np.array(out), np.array(local)


def test_psi6_per_layer_is_freuds(film):
    u, atoms, edges = film
    ours = HexaticOrder(atoms, edges).run()
    psi6, local = _freud_psi6(u, atoms, edges)
    assert psi6.shape == ours.results.psi6.shape == (16, 3)
    # both ordered and melted frames are compared
    assert psi6[:10].min() > 0.5 and psi6[10:].max() < 0.3
    np.testing.assert_allclose(ours.results.psi6, psi6, rtol=0.01)
    np.testing.assert_allclose(ours.results.psi6_local, local, rtol=0.01)
    # the comparison can fail: freud's fourfold order is another number
    psi4, _ = _freud_psi6(u, atoms, edges, k=4)
    assert not np.allclose(ours.results.psi6, psi4, rtol=0.01)


def _fresh_pairs(xy, layer, box, rc):
    """Every in-layer pair within rc from a new search (the reference)."""
    found = set()
    for k, r in enumerate(rc):
        members = np.flatnonzero(layer == k)
        if not np.isfinite(r):
            continue
        for a, b in cKDTree(xy[members], boxsize=box).query_pairs(r):
            found.add((min(members[a], members[b]), max(members[a], members[b])))
    return found


def test_the_verlet_list_finds_every_pair_in_every_frame():
    """Atoms drifting and rattling: the list is reused while it holds, searched anew when
    an atom has moved half the skin or changed layer, and every frame's pairs are those of
    a fresh search."""
    rng = np.random.default_rng(1)
    box = np.array([12.0, 10.0])
    n = 240
    xy0 = rng.uniform(0, 1, (n, 2)) * box
    layer = np.repeat([0, 1], n // 2)
    neighbours = LayerNeighbours(2)
    drift = rng.normal(0, 1, (n, 2))
    for frame in range(40):
        xy = np.mod(xy0 + 0.02 * frame * drift + rng.normal(0, 0.03, (n, 2)), box)
        if frame == 30:
            layer = layer.copy()
            layer[0] = 1                          # an atom changes layer
        i, j, dx, dy = neighbours.pairs(xy, layer, box)
        rc = neighbours.cutoffs(layer, box)
        assert {(min(a, b), max(a, b)) for a, b in zip(i, j)} == _fresh_pairs(xy, layer, box, rc)
        d = xy[j] - xy[i]
        d -= box * np.round(d / box)
        np.testing.assert_allclose(np.column_stack([dx, dy]), d, atol=1e-12)
    assert 2 < neighbours.searches < 40           # reused, and searched anew


def test_psi6_of_a_perfect_triangular_lattice_is_one():
    from filmfriction.md_inputs.geometry import fcc111

    plane = fcc111(1.0, (6, 4), 1)
    xy = plane.positions[:, :2]
    layer = np.zeros(len(xy), int)
    i, j, dx, dy = LayerNeighbours(1).pairs(xy, layer, plane.box)
    assert len(i) == 3 * len(xy)                  # six neighbours each
    psi, local = psi6_per_layer(i, j, dx, dy, layer, 1)
    np.testing.assert_allclose([psi[0], local[0]], 1.0, rtol=1e-12)
