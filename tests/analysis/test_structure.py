"""Film structure analyses on a synthetic layered film (DCD written in tmp_path)."""
import warnings

import MDAnalysis as mda
import numpy as np
import pytest

from filmfriction.analysis.structure import DensityProfile, FilmThickness, HexaticOrder, frame_steps
from filmfriction.analysis.synthetic import layered_film

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
