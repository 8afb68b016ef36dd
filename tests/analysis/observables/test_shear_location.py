"""Where the shear sits: per-layer velocities from a trajectory, on films of known profile."""
import warnings

import numpy as np
import pytest

from filmfriction.analysis.structure.layering import DensityProfile
from filmfriction.analysis.structure.trajectory_reader import open_trajectory, select_types
from filmfriction.analysis.groundtruth.synthetic import layered_film
from filmfriction.analysis.observables.shear_location_section import locate, shear_shares

LAYERS = 4
V = 0.5     # the top wall's slip velocity, σ/τ


def _located(tmp_path, plane_velocity, windows=None, frames=30, thermal=0.05):
    top, traj = layered_film(tmp_path, layers=LAYERS, frames=frames, nsavc=100,
                             thermal=thermal, plane_velocity=plane_velocity, seed=3)
    u = open_trajectory(top, traj)
    film = select_types(u, [1])
    edges = DensityProfile(film).run().results.layers["edges"]
    t_end = u.trajectory[-1].time
    windows = windows or [(k * t_end / 4, (k + 1) * t_end / 4) for k in range(4)]
    return locate(u, edges, windows)


def test_plug_slip_at_the_top_wall_is_found_there(tmp_path):
    # positive control: the film moves with the bottom wall, the jump is at the top plane
    out = _located(tmp_path, [0.0] * (LAYERS + 1) + [V])
    assert out["location"] == "top interface"
    assert out["slips"] == 4 and out["samples"] == "slip"
    assert abs(out["jump"][-1] - 1.0) < 3 * out["jump_stderr"][-1] + 0.02
    assert np.allclose(out["share"], 0.0, atol=0.05)
    assert out["wall_slip_velocity"] == pytest.approx(V, rel=1e-3)


def test_plug_slip_at_the_bottom_wall_is_found_there(tmp_path):
    out = _located(tmp_path, [0.0] + [V] * (LAYERS + 1))
    assert out["location"] == "bottom interface"
    assert np.allclose(out["share"], 1.0, atol=0.05)


def test_uniform_shear_is_spread_with_the_shares_of_a_linear_profile(tmp_path):
    # negative control: Couette flow with no slip; each of the 5 gaps takes 1/5
    pv = V * np.arange(LAYERS + 2) / (LAYERS + 1)
    out = _located(tmp_path, pv)
    assert out["location"] == "spread"
    truth = np.arange(1, LAYERS + 1) / (LAYERS + 1)
    err = np.asarray(out["share_stderr"])
    assert np.all(np.abs(np.asarray(out["share"]) - truth) < 4 * err + 1e-3), (out["share"], err)
    assert max(out["jump"]) < 0.3


def test_slip_inside_the_film(tmp_path):
    # the lower two layers with the bottom wall, the upper two with the top: a mid-film plane
    out = _located(tmp_path, [0.0, 0.0, 0.0, V, V, V])
    assert out["location"] == "inside the film" and out["largest"] == 2


def test_frames_outside_the_slips_do_not_count(tmp_path):
    # a single window: blocks of frame pairs are the samples (fewer than 3 slips)
    out = _located(tmp_path, [0.0] * (LAYERS + 1) + [V], windows=[(0.0, 5.0)])
    assert out["samples"] == "block" and out["frame_pairs"] == 10 and out["n"] == 4
    assert out["location"] == "top interface"


def test_no_samples_is_inconclusive():
    assert shear_shares(np.empty((0, 3)))["location"] == "inconclusive"


def test_a_slip_whose_layer_emptied_is_left_out_quietly():
    # a film that melted loses a layer: no atom there in one slip's intervals gives NaN
    # for that layer, and the slip is left out of the shares without a RuntimeWarning
    from filmfriction.analysis.observables.shear_location_section import located
    rng = np.random.default_rng(1)
    slips = np.repeat(np.arange(4), 5)
    layer = rng.normal(0, 0.01, (slips.size, 3))      # the film moves with the bottom wall
    layer[slips == 2, 1] = np.nan
    lv = {"slip": slips, "bottom": np.zeros(slips.size), "top": np.full(slips.size, V),
          "layer": layer}
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        out = located(lv)
    assert out["n"] == 3 and out["location"] == "top interface"
