"""The MD scene at the edges of its parameter ranges, with real (small) LAMMPS runs.

Each extreme either reaches the physically right limit, checked here, or
stops with a clear error before LAMMPS starts (validator) or at the failure
(runner).  Runs use the ``md`` fixture's 5 x 3 box (330 atoms for 3 layers), 500
equilibration and 1500-3000 slide steps, one MPI rank (no busy-waiting MPI
ranks fighting for shared cores), and its watchdog that ends the run's own
engine processes if it hangs.
"""
from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from filmfriction.analysis.stickslip import detect_slips
from filmfriction.workflows.md import runner
from filmfriction.workflows.md.scene import SceneError
from filmfriction.workflows.md.scenes.parameters import resolve

pytestmark = pytest.mark.md

TINY = {"equilibrate_steps": 500, "slide_steps": 1500, "trace_every": 10, "restart_every": 0}
H_FILM = math.sqrt(2.0 / 3.0) * 1.1   # (111) plane spacing of the film as built


@pytest.fixture
def run(md, tmp_path):
    """``run(**overrides)``: a tiny stick-slip run (one rank, under the md fixture's
    watchdog) -> (scene, trace); ``bypass`` sets values without the validator."""
    def run_(name="run", bypass=None, **overrides):
        scene = md.scene("stick-slip", **{**TINY, **overrides})
        if bypass:
            scene = replace(scene, parameters={**scene.parameters, **bypass})
        run_dir = md.execute(scene, tmp_path / name)
        return scene, md.trace(run_dir)
    return run_


@pytest.fixture
def closure(md):
    return md.ledger_closure


def late(d, column):
    return d[column][len(d) // 2:]


# ------------------------------------------------------------------ timestep
def test_timestep_at_the_lj_limit_runs_and_conserves_energy(run, closure):
    _, d = run(timestep=0.01, slide_steps=1000, trace_every=5)
    assert closure(d) < 0.03
    assert abs(d["film_temperature"].mean() - 0.7) < 0.1


def test_timestep_just_past_the_limit_is_refused_before_lammps():
    with pytest.raises(SceneError, match=r"timestep 0.0101 tau is above the stability limit"):
        resolve({"timestep": 0.0101})


@pytest.mark.parametrize("dt, message", [
    # 2.5x the limit: the thermostat keeps T looking normal, only the ledger shows
    # it (61 % of the energy turned over is unaccounted for)
    (0.025, "energy ledger does not close"),
    # 5x: atoms fly out of the box (at 4x they take some 100 s of exploding steps to leave
    # it before the thermo check reports them; at 5x under a second)
    (0.05, r"Lost atoms.*likely cause: timestep 0.05 tau is above the stability limit"),
])
def test_timestep_past_the_limit_behind_the_validators_back_fails_clearly(run, tmp_path, dt, message):
    with pytest.raises(runner.RunFailed, match=message):
        run(bypass={"timestep": dt}, slide_steps=3000)
    record = json.loads((tmp_path / "run" / "run.json").read_text())
    assert record["status"] == "failed"
    assert (tmp_path / "run" / "trace.csv").exists()      # partial results kept


# ------------------------------------------------------------------ spring
def test_very_stiff_spring_drags_the_wall_with_the_drive(run, closure):
    scene, d = run(spring_constant=1.0e5)
    lag = d["drive_position"] - d["wall_position"]
    # the lag is F/K: at most a few hundred epsilon/sigma over 1e5
    assert np.abs(lag).max() < 5e-3
    assert closure(d) < 0.05


@pytest.mark.parametrize("overrides", [
    {"spring_constant": 0.01},
    # the wall vibrates thermally, smooth at its sampling (trace every 10 steps): the
    # detector must not count the vibration's dips as slips
    {"drive_velocity": 1e-4},
], ids=["soft-spring", "slowest-drive"])
def test_weak_drive_leaves_the_wall_stuck_in_registry(run, overrides):
    scene, d = run(**overrides)
    # the spring force stays far below the yield force: the wall only vibrates
    # about its registry site (thermal amplitude ~ 0.05 sigma), nothing slips
    assert np.abs(d["spring_force"]).max() < 5.0
    assert np.abs(d["wall_position"]).max() < 0.1
    assert detect_slips(d["time"], d["spring_force"]).count == 0


def test_fastest_drive_slides_the_wall_at_the_drive_velocity(run):
    # 40 tau: the wall's ringing (period 14 tau) decays with the mount's 1/gamma = 3 tau
    scene, d = run(drive_velocity=1.0, slide_steps=8000)
    half = len(d) // 2
    v = (d["wall_position"][-1] - d["wall_position"][half]) / (d["time"][-1] - d["time"][half])
    assert v == pytest.approx(1.0, rel=0.05)
    assert late(d, "film_temperature").mean() < 2.0  # sheared, heated, not blown up


# ------------------------------------------------------------------ load
def test_zero_load_with_adhesion_keeps_a_finite_gap(run):
    # the top wall is held by the wall-film attraction alone: it must not drift off
    _, d = run(normal_pressure=0.0)
    assert d["gap"].max() < 4 * H_FILM + 0.3
    assert abs(d["gap"][-1] - d["gap"][0]) < 0.2


def test_zero_load_without_adhesion_is_refused_before_lammps():
    # WCA walls and no load: nothing holds the top wall; LAMMPS would lose atoms
    with pytest.raises(SceneError, match="nothing holds the top wall"):
        resolve({"normal_pressure": 0.0, "cutoff": 2.0 ** (1.0 / 6.0)})


def test_highest_load_compresses_the_film_without_squeezing_it_out(run, closure):
    # the periodic film has no reservoir to be squeezed into: at the highest
    # allowed load it compresses, keeps its 3 layers, and nothing blows up
    _, d = run(normal_pressure=100.0)
    gap = late(d, "gap").mean()
    assert 2.0 * H_FILM < gap < 4 * H_FILM - 0.2
    assert closure(d) < 0.05


# ------------------------------------------------------------------ temperature
def test_temperature_zero_stays_cold_and_sticks(run, closure):
    _, d = run(temperature=0.0)
    # frictional heat only, drained by the thermostat along y
    assert d["film_temperature"].mean() < 0.05
    assert np.abs(d["wall_position"]).max() < 0.2
    assert closure(d) < 0.05


def test_film_above_melting_slides_without_stick_slip(run):
    # at kT = 1.2 (above the film's melting, below the LJ critical point) the
    # film is liquid: the wall slides at V after the spring's transient
    # 40 tau at V = 0.2: a solid film would slip every 1.1 sigma, 7 times
    _, d = run(temperature=1.2, drive_velocity=0.2, slide_steps=8000)
    # no periodic slips: the start-up yield of the film (still crystalline after
    # 2.5 tau at kT 1.2), and at most one more event from the liquid's force
    # fluctuations (0-2 events over 48 seeds; a solid film would slip 7 times)
    assert detect_slips(d["time"], d["spring_force"]).count <= 2
    half = len(d) // 2
    v = (d["wall_position"][-1] - d["wall_position"][half]) / (d["time"][-1] - d["time"][half])
    assert v == pytest.approx(0.2, rel=0.1)
    # a liquid is less dense than the solid film, but the load holds it
    assert 4 * H_FILM - 0.5 < late(d, "gap").mean() < 1.6 * 4 * H_FILM


def test_film_far_above_melting_pushes_the_wall_off_with_a_clear_error(run):
    # kT = 5 at P = 1: the film is a supercritical gas whose pressure exceeds the
    # load; the top wall is pushed out of the box and LAMMPS loses atoms.  The
    # runner says why instead of only "Lost atoms".
    with pytest.raises(runner.RunFailed, match=r"Lost atoms.*temperature 5 epsilon/k_B is "
                                               r"above the LJ critical temperature.*"
                                               r"normal_pressure 1 is low for temperature 5"):
        run(temperature=5.0, slide_steps=8000)


# ------------------------------------------------------------------ layers and wall mass
@pytest.mark.parametrize("layers", [1, 8])
def test_one_and_eight_layers_fill_the_gap(layered_run, closure, layers):
    # the session's layered run (film-structure, 1000 slide steps), shared with the
    # runner's layer-count test
    d = layered_run(layers).trace()
    # n layers fill n + 1 plane spacings between the walls' inner planes
    ratio = d["gap"].mean() / ((layers + 1) * H_FILM)
    assert 0.9 < ratio < 1.15, ratio
    assert closure(d) < 0.05


def test_wall_lighter_than_one_film_atom_runs_and_conserves_energy(run, closure):
    # the whole top wall (120 atoms) weighs as much as one film atom
    _, d = run(wall_mass=1.0)
    assert np.all(np.isfinite(d["wall_velocity"]))
    assert closure(d) < 0.05


def test_wall_far_heavier_than_the_film_follows_the_mount(run):
    # M = 1e7 m: film and spring forces are negligible beside the mount dashpot
    # gamma M (v - V), so the wall relaxes to V with the time constant 1/gamma:
    # x(t) = V (t - (1 - exp(-gamma t)) / gamma)
    scene, d = run(wall_mass=1.0e7)
    p = scene.parameters
    v, gamma, t = p["drive_velocity"], p["mount_damping"], d["time"]
    expected = v * (t - (1.0 - np.exp(-gamma * t)) / gamma)
    assert np.abs(d["wall_position"] - expected).max() < 0.01 * v * t[-1] + 1e-3
