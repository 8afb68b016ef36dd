"""The slider-mass ladder's plan: every rung is a valid sweep, and the Bi >= 30 scene is its rung."""
import math

import pytest

from filmfriction.workflows import ladder
from filmfriction.workflows.md.scene import load
from filmfriction.workflows.sweep import plan_sweep


@pytest.mark.parametrize("rung", ladder.RUNGS, ids=lambda r: r.name)
def test_every_rung_is_a_valid_sweep(rung):
    plan = plan_sweep(ladder.SCENE, ["seed=" + ",".join(map(str, ladder.SEEDS))], rung.sets(), 1)
    assert len(plan.points) == len(ladder.SEEDS)
    assert plan.fixed["wall_mass"] == rung.mass


def test_rungs_keep_the_mount_damping_ratio_and_stay_below_the_slips():
    ref = load(ladder.SCENE).parameters
    for r in ladder.RUNGS:
        ratio = r.mount_damping * r.mass / (2 * math.sqrt(ref["spring_constant"] * r.mass))
        assert ratio == pytest.approx(0.019, rel=0.03), r.name
        assert r.drive_velocity < 0.4 * r.slip_velocity_estimate, r.name
    masses = [r.mass for r in ladder.RUNGS]
    assert masses == sorted(masses) and masses[0] == ref["wall_mass"] and masses[-1] >= 2.4e6


def test_slide_steps_cover_the_first_loading_and_the_slips():
    for r in ladder.RUNGS:
        t = r.slide_steps * ladder.TIMESTEP
        loading = ladder.STATIC_FORCE / ladder.SPRING_CONSTANT / r.drive_velocity
        assert t > loading + (r.slips - 1) * ladder.SLIP_LENGTH / r.drive_velocity, r.name
    assert ladder.slide_steps(30, 0.02, 9) > ladder.slide_steps(30, 0.02, 8)


def test_the_heavy_scene_is_the_heavy_rungs_seed_one():
    r = ladder.HEAVY
    plan = plan_sweep(ladder.SCENE, ["seed=1"], r.sets(), 1)
    heavy = load("sfb-heavy")
    resolved = load(ladder.SCENE, {**plan.fixed, "seed": 1}).parameters
    assert resolved == heavy.parameters


def test_stages_put_one_heavy_seed_first_and_run_no_planned_rung():
    first, seeds = ladder.STAGES[0]
    assert first is ladder.HEAVY and seeds == (1,)
    assert not any(r.planned for r, _ in ladder.STAGES)


def test_combine_seeds_uses_the_scatter_between_seeds():
    rows = [{"x": (v, 0.01)} for v in (1.0, 2.0, 3.0)]
    m, e, n = ladder.combine_seeds(rows, "x")
    assert (m, n) == (2.0, 3) and e == pytest.approx(1 / math.sqrt(3))
    assert ladder.combine_seeds([{"x": (math.nan, 1.0)}], "x")[2] == 0


def test_slip_temperature_rise_recovers_a_known_rise(tmp_path):
    import numpy as np

    rng = np.random.default_rng(3)
    t = np.arange(0.0, 400.0, 0.25)
    slips = [(100.0, 120.0, 0.07), (200.0, 230.0, 0.14), (300.0, 310.0, 0.07)]
    temp = 0.71 + 0.005 * rng.standard_normal(t.size)
    for y, s, dt in slips:
        temp[(t >= y) & (t <= s)] += dt
    (tmp_path / "trace.csv").write_text("time,film_temperature\n" + "".join(
        f"{a},{b}\n" for a, b in zip(t, temp)))
    (tmp_path / "analysis_cycles.csv").write_text("yield_time,stick_time\n" + "".join(
        f"{y},{s}\n" for y, s, _ in slips))
    rise, err = ladder.slip_temperature_rise(tmp_path)
    truth = np.mean([dt for *_, dt in slips]) / 0.71
    assert abs(rise - truth) < 3 * err + 1e-3
    assert err == pytest.approx(np.std([0.07, 0.14, 0.07], ddof=1) / 0.71 / np.sqrt(3), rel=0.1)
