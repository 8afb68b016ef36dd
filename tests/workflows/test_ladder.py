"""The slider-mass ladder's plan: every rung is a valid sweep, and the Bi >= 30 scene is its rung."""
import math
from pathlib import Path

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
    (tmp_path / "trace.csv").write_text("time,spring_force,film_temperature\n" + "".join(
        f"{a},1.0,{b}\n" for a, b in zip(t, temp)))
    (tmp_path / "analysis_cycles.csv").write_text("yield_time,stick_time\n" + "".join(
        f"{y},{s}\n" for y, s, _ in slips))
    rise, err = ladder.slip_temperature_rise(tmp_path)
    truth = np.mean([dt for *_, dt in slips]) / 0.71
    assert abs(rise - truth) < 3 * err + 1e-3
    assert err == pytest.approx(np.std([0.07, 0.14, 0.07], ddof=1) / 0.71 / np.sqrt(3), rel=0.1)


def test_the_heavy_rungs_take_more_steps_than_the_cost_model_the_others_its_own():
    for r in ladder.RUNGS:
        if r.mass == 2.4e5:
            assert r.step_factor == ladder.HEAVY_STEP_FACTOR == 1.4
            assert r.slide_steps == pytest.approx(1.4 * r.model_steps, rel=0.01), r.name
        elif r.mass > 2.4e5:
            assert r.measured_slip_velocity is not None and r.step_factor > 1, r.name
        else:
            assert r.slide_steps == r.model_steps, r.name
    # the measured cycle of M = 2.4e5 (first yield after 13 840 tau, then about 15 300 tau a
    # cycle: 28.4 sigma of loading at V = 0.002, 1 070 tau of slip) fits 4 slips in its slide
    t = ladder.HEAVY.slide_steps * ladder.TIMESTEP
    assert 4 <= 1 + (t - 13840) // 15300 < 5
    # and that of M = 2.4e6 (first yield after 10 800-13 800 tau, then 12 500-16 500 tau a
    # cycle, two seeds) fits 4 slips in its own at the slowest cycle, 6 at the fastest
    t = ladder.RUNGS[-1].slide_steps * ladder.TIMESTEP
    assert 1 + (t - 13800) // 16500 == 4
    assert 1 + (t - 10800) // 12500 == 6


def _plan_lines(capsys, *args):
    from filmfriction.workflows.cli.main import main

    capsys.readouterr()
    assert main(["ladder", "plan", *args]) == 0
    return capsys.readouterr().out.splitlines()


def test_plan_states_each_rungs_steps_and_the_campaigns(capsys):
    lines = _plan_lines(capsys)
    for r in ladder.RUNGS:
        (line,) = [ln for ln in lines if ln.startswith(f"{r.name}:")]
        assert f"{r.slide_steps} slide steps" in line and f"{r.run_steps} steps a run" in line
        assert (f"× {r.step_factor:g})" in line) == (r.step_factor != 1)
        assert ("(not in the campaign" in line) == r.planned
        assert ("(measured)" in line) == (r.measured_slip_velocity is not None)
        assert "min at" not in line                # no time without a measured rate
    # the campaign: every seed of every rung that is run, each run once
    runs = [(r, s) for r in ladder.RUNGS if not r.planned for s in ladder.SEEDS]
    total = sum(r.run_steps for r, _ in runs)
    assert lines[-1].startswith(f"campaign ('filmfriction ladder run'): {len(runs)} runs, "
                                f"{total} steps")
    # with a rate the user measured: the time is steps over it
    lines = _plan_lines(capsys, "--steps-per-second", "10000")
    heavy = [ln for ln in lines if ln.startswith(f"{ladder.HEAVY.name}:")][0]
    assert f", {ladder.HEAVY.run_steps / 10000 / 60:.0f} min at 10000 steps/s" in heavy
    assert f"{total / 10000 / 3600:.1f} h at 10000 steps/s" in lines[-1]


def test_plan_prints_the_sweep_commands_that_run_runs(capsys):
    lines = _plan_lines(capsys, "--root", "L")
    for r in ladder.RUNGS:
        assert "    " + " ".join(ladder.sweep_command(r, ladder.SEEDS, "L")) in lines


def test_run_runs_the_stages_through_the_sweep_and_stops_on_an_interrupt(tmp_path, monkeypatch,
                                                                        capsys):
    from filmfriction.workflows.cli import ladder_cli
    from filmfriction.workflows.cli.main import main

    calls, codes = [], {ladder.RUNGS[1].name: 1, ladder.RUNGS[3].name: 130}

    def fake_sweep(args):
        calls.append(args)
        return codes.get(Path(args.out).name, 0)

    monkeypatch.setattr(ladder_cli, "main_sweep", fake_sweep)
    assert main(["ladder", "run", "--root", str(tmp_path / "L"), "--np", "1"]) == 130
    err = capsys.readouterr()
    expected = [(r.name, seeds) for r, seeds in ladder.STAGES]
    got = [(Path(a.out).name, tuple(int(s) for s in a.grid[0][5:].split(","))) for a in calls]
    # a failed rung does not stop the ladder; an interrupted one does, and says how to resume
    assert got == expected[:expected.index((ladder.RUNGS[3].name, (1,))) + 1]
    assert f"{ladder.RUNGS[1].name} seeds (1,): exit 1 (going on)" in err.out
    assert "run the same command again to resume" in err.err
    for a in calls:
        rung = next(r for r in ladder.RUNGS if r.name == Path(a.out).name)
        assert a.scene == ladder.SCENE and a.overrides == rung.sets()
        assert a.np == a.cores == 1 and Path(a.out).parent == tmp_path / "L"
    assert not (tmp_path / "L").exists(), "the fake sweep wrote nothing; nor did the ladder"


def test_collect_writes_the_rungs_it_finds(tmp_path, capsys):
    from filmfriction.workflows.cli.main import main

    rung = tmp_path / "L" / ladder.HEAVY.name
    (rung / "points").mkdir(parents=True)
    (rung / "sweep.json").write_text('{"fixed": {"wall_mass": 240000}}')
    out = tmp_path / "ladder.json"
    capsys.readouterr()
    assert main(["ladder", "collect", "--root", str(tmp_path / "L"), "--out", str(out)]) == 0
    table = capsys.readouterr().out.splitlines()
    assert len(table) == 3 and table[2].startswith(f"| {ladder.HEAVY.name} | 0 | 0 |")
    import json

    doc = json.loads(out.read_text())
    assert doc["schema"] == "filmfriction.mass-ladder/1"
    assert [r["mass"] for r in doc["rungs"]] == [ladder.HEAVY.mass]
    assert doc["rungs"][0]["slide_steps"] == ladder.HEAVY.slide_steps


def test_collect_pools_the_rungs_slips_over_its_seeds(tmp_path):
    # three seeds of Klein's viscous slips (B = 40 m/τ): the rung's pooled law is viscous,
    # its errors the jackknife's over the three seeds
    from filmfriction.analysis.analyze import analyse_run
    from filmfriction.analysis.groundtruth.synthetic import run_directory

    rung = tmp_path / "rung"
    for i in range(3):
        analyse_run(run_directory(rung / "points" / f"seed={i}", trajectory=False, seed=i))
    (rung / "sweep.json").write_text('{"fixed": {"wall_mass": 500}}')
    got = ladder.collect_rung(rung)
    law = got["pooled_slip_law"]
    assert law["verdict"] == "viscous" and law["replicas"] == 3 and law["dof"] == 2
    assert law["damping"]["mean"] == pytest.approx(40.0, rel=0.05)
    assert ladder.table([got]).splitlines()[2].endswith("| viscous (3 seeds) |")
    (rung / "points" / "seed=2" / "analysis.json").unlink()
    assert "pooling needs 3 or more" in ladder.collect_rung(rung)["pooled_slip_law"]["error"]
