"""Where the shear sits, from the slab profiles (no trajectory): synthetic ``fix ave/chunk``
files of known layer velocities give the known shares."""
import numpy as np
import pytest

from filmfriction.analysis.observables.shear_location_section import (
    _from_profiles, profile_layer_velocities, read_profile_frames)
from filmfriction.analysis.results import trace_from_columns
from filmfriction.analysis.structure.layering import find_layers

LAYERS = 4
LAYER_Z = 1.0 + 0.95 * np.arange(LAYERS)    # the film's layers, σ
BIN = 0.1
WINDOW = 500                                # steps per profile frame
DT = 0.005
V = 0.6                                     # the top wall's velocity in a slip, σ/τ
# four slips of 12 windows each, 8 windows of stick between them (steps)
SLIPS = [(s, s + 12 * WINDOW) for s in (4000, 14000, 24000, 34000)]
END = 44000


def _write(path, steps, z, count, values, column, resumed_at=None):
    """A ``fix ave/chunk`` file; with ``resumed_at``, a second part (as a resumed run appends
    it, after a header of its own) begins after the frame of that step."""
    header = [f"# Chunk-averaged data for fix {column.split('/')[0]} and group film",
              "# Timestep Number-of-chunks Total-count",
              f"# Chunk Coord1 Ncount {column}"]
    lines = list(header)
    for i, (s, c, v) in enumerate(zip(steps, count, values)):
        if resumed_at is not None and i and steps[i - 1] > s:
            lines += header
        lines.append(f"{s} {z.size} {c.sum()}")
        lines += [f"  {i + 1} {zi:g} {ci:g} {vi:g}" for i, (zi, ci, vi) in enumerate(zip(z, c, v))]
    path.write_text("\n".join(lines) + "\n")


def _run(tmp_path, layer_velocity, noise=0.01, seed=1, resumed_at=None):
    """A run directory's trace and profiles: the top wall at rest in the stick, at V in
    the slips; layer k at ``layer_velocity[k]`` (σ/τ) in the slips, at rest in the stick;
    each layer's velocity in each window with Gaussian noise ``noise``."""
    rng = np.random.default_rng(seed)
    step = np.arange(0, END + 1, 50)
    in_slip = np.zeros(step.size, bool)
    for a, b in SLIPS:
        in_slip |= (step > a) & (step <= b)
    wall = np.concatenate([[0.0], np.cumsum(np.where(in_slip[1:], V * 50 * DT, 0.0))])
    trace = trace_from_columns({"time": step * DT, "step": step, "wall_position": wall,
                                "spring_force": np.ones(step.size)}, units="lj")
    z = np.arange(0.0, 5.0, BIN) + BIN / 2
    shape = np.exp(-0.5 * ((z[:, None] - LAYER_Z[None, :]) / 0.08) ** 2)   # bins × layers
    count = 40 * shape.sum(axis=1) / shape.sum(axis=0).max()
    frames = np.arange(WINDOW, END + 1, WINDOW)
    vx, cnt = [], []
    for s in frames:
        slipping = any(a <= s - WINDOW and s <= b for a, b in SLIPS)
        v_layer = (np.asarray(layer_velocity) if slipping else np.zeros(LAYERS)) \
            + noise * rng.standard_normal(LAYERS)
        # each bin's velocity: its layers' velocities weighted by their share of its atoms
        w = shape / np.maximum(shape.sum(axis=1, keepdims=True), 1e-300)
        vx.append(w @ v_layer)
        cnt.append(count)
    steps = frames
    if resumed_at is not None:
        # a resumed run wrote the frames after the restart step again: stale ones first
        redo = frames > resumed_at
        steps = np.concatenate([frames, frames[redo]])
        vx = [np.full(z.size, 99.0) if r else v for v, r in zip(vx, redo)] + \
             [v for v, r in zip(vx, redo) if r]
        cnt = cnt + [c for c, r in zip(cnt, redo) if r]
    (tmp_path / "profiles").mkdir()
    _write(tmp_path / "profiles" / "velocity.profile", steps, z, np.array(cnt), np.array(vx), "vx",
           resumed_at)
    dens = np.array(cnt) / (7.7 * 7.6 * BIN)
    _write(tmp_path / "profiles" / "density.profile", steps, z, np.array(cnt), dens,
           "density/number", resumed_at)
    windows = [(a * DT, b * DT) for a, b in SLIPS]
    return trace, windows


def _located(tmp_path, layer_velocity, **kw):
    trace, windows = _run(tmp_path, layer_velocity, **kw)
    return _from_profiles(trace, tmp_path / "profiles" / "velocity.profile",
                          tmp_path / "profiles" / "density.profile", windows)


def test_the_profiles_give_the_layers_and_their_velocities(tmp_path):
    trace, windows = _run(tmp_path, V * np.arange(1, LAYERS + 1) / (LAYERS + 1), noise=0.0)
    fr = read_profile_frames(tmp_path / "profiles" / "velocity.profile",
                             tmp_path / "profiles" / "density.profile")
    assert fr["window"] == WINDOW and fr["vx"].shape == (END // WINDOW, 50)
    layers = find_layers(fr["z"], fr["density"])
    assert layers["count"] == LAYERS
    assert np.allclose(layers["positions"], LAYER_Z, atol=BIN)
    lv = profile_layer_velocities(fr, layers["edges"], windows, trace_step=trace.columns["step"],
                                  trace_time=trace.time, wall_position=trace.wall_position())
    # 12 windows per slip, all inside it; none of the stick's
    assert np.bincount(lv["slip"]).tolist() == [12] * 4
    assert np.allclose(lv["top"], V) and np.allclose(lv["bottom"], 0.0)
    assert np.allclose(lv["layer"], V * np.arange(1, LAYERS + 1) / (LAYERS + 1), atol=1e-4)


def test_plug_flow_slips_at_the_top_interface(tmp_path):
    # the film moves with the (fixed) bottom wall: the whole slip at the top plane
    out = _located(tmp_path, np.zeros(LAYERS))
    assert out["source"] == "profiles" and out["samples"] == "slip"
    assert out["slips"] == 4 and out["profile_windows"] == 48
    assert out["location"] == "top interface"
    assert out["jump"][-1] == pytest.approx(1.0, abs=4 * out["jump_stderr"][-1] + 0.02)
    assert sum(out["jump"]) == pytest.approx(1.0)
    assert out["wall_slip_velocity"] == pytest.approx(V)
    # per slip and one window at a time: the whole slip at the top plane
    assert len(out["jump_per_sample"]) == 4
    assert np.allclose(np.sum(out["jump_per_sample"], axis=1), 1.0)
    assert out["interval_largest_gap"] == [0, 0, 0, 0, 48]
    assert out["interval_largest_jump_median"] == pytest.approx(1.0, abs=0.05)


def test_linear_couette_is_spread_with_a_linear_profile(tmp_path):
    # no slip at either wall: each of the 5 gaps takes 1/5
    out = _located(tmp_path, V * np.arange(1, LAYERS + 1) / (LAYERS + 1))
    assert out["location"] == "spread"
    truth = np.arange(1, LAYERS + 1) / (LAYERS + 1)
    err = np.asarray(out["share_stderr"])
    assert np.all(np.abs(np.asarray(out["share"]) - truth) < 4 * err + 1e-3), (out["share"], err)
    assert np.allclose(out["jump"], 0.2, atol=0.02)
    # one window at a time as well: no plane takes much more than its fifth
    assert out["interval_largest_jump_median"] < 0.3


def test_plug_flow_with_the_top_wall_slips_at_the_bottom_interface(tmp_path):
    out = _located(tmp_path, np.full(LAYERS, V))
    assert out["location"] == "bottom interface" and out["largest"] == 0


def test_a_resumed_run_keeps_the_last_frame_of_each_step(tmp_path):
    # the resumed run's part follows a header of its own; the frames the interrupted run
    # wrote after the restart step (velocity 99) are replaced by the resumed run's
    out = _located(tmp_path, np.zeros(LAYERS), resumed_at=20000)
    text = (tmp_path / "profiles" / "velocity.profile").read_text()
    assert text.count("# Chunk-averaged data") == 2
    assert out["profile_windows"] == 48 and out["location"] == "top interface"
    assert max(abs(s) for s in out["share"]) < 0.05


def test_a_frame_cut_short_is_left_out_and_a_broken_line_is_a_value_error(tmp_path):
    # a run killed while writing its last frame: that frame is left out, the rest counts
    trace, windows = _run(tmp_path, np.zeros(LAYERS))
    path = tmp_path / "profiles" / "velocity.profile"
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[:-3]))
    frames = read_profile_frames(path)
    assert frames["steps"][-1] == END - WINDOW and frames["vx"].shape[0] == END // WINDOW - 1
    out = _from_profiles(trace, path, None, windows)
    assert out["profile_windows"] == 48 and out["location"] == "top interface"
    # a line cut in the middle of its fields: one clear error
    path.write_text("".join(lines[:-3]) + "  1 0.05\n")
    with pytest.raises(ValueError, match="not a complete fix ave/chunk file"):
        _from_profiles(trace, path, None, windows)


def test_the_viscosity_profile_reads_a_resumed_runs_appended_profile(tmp_path):
    # the time-averaged profile (viscosity, structure) reads a file a resumed run appended to
    # with the same reader as the shear location: its parts joined, the mean of all frames'
    # last half (steps 3000, 4000: vx 3 and 4 in every bin)
    from filmfriction.analysis.files.chunk_file import read_chunk_file
    from filmfriction.analysis.observables.viscosity_section import averaged_profile

    z, count = np.array([1.0, 2.0]), np.ones(2)
    path = tmp_path / "velocity.profile"
    _write(tmp_path / "first.profile", [1000, 2000], z, [count] * 2,
           [np.full(2, k) for k in (1.0, 2.0)], "vx")
    second = tmp_path / "second.profile"
    _write(second, [3000, 4000], z, [count] * 2, [np.full(2, k) for k in (3.0, 4.0)], "vx")
    path.write_text((tmp_path / "first.profile").read_text() + second.read_text())
    assert read_chunk_file(path).timesteps == [1000, 2000, 3000, 4000]
    zz, vx, name = averaged_profile(path, ("vx",))
    assert name == "vx" and np.allclose(zz, z) and np.allclose(vx, 3.5)
