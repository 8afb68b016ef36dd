"""The trade study's pieces, the fidelity presets, and one tiny end-to-end study."""
from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from filmfriction.workflows.md import fidelity
from filmfriction.workflows.cost import tradeoff, tradeoff_figures, tradeoff_reduced, tradeoff_table
from filmfriction.workflows.md.scene import SceneError, load


def test_pareto_front_keeps_only_undominated_points():
    cost = [1.0, 2.0, 3.0, 4.0, 0.5, math.nan]
    error = [5.0, -1.0, 2.0, 0.5, 9.0, 0.0]      # |error| counts; NaN cost is left out
    front = tradeoff_figures.pareto_front(cost, error)
    assert [int(i) for i in front] == [4, 0, 1, 3]


def test_drift_recovers_a_slope_and_its_noise():
    t = np.linspace(0.0, 100.0, 5001)
    rng = np.random.default_rng(3)
    r = 0.02 * t + np.cumsum(rng.normal(0.0, 0.05, t.size))
    slope, se = tradeoff_table.drift(t, r)
    assert slope == pytest.approx((r[-1] - r[0]) / 100.0)
    assert 0 < se < 0.05
    assert abs(slope - 0.02) < 4 * se + 0.01


def test_compare_combines_standard_errors_and_zeroes_the_reference():
    names = list(tradeoff_table.OBSERVABLES)
    a = tradeoff_table.Measurement({n: (10.0, 3.0) for n in names}, 5, "stick-slip", 1.0)
    b = tradeoff_table.Measurement({n: (7.0, 4.0) for n in names}, 5, "stick-slip", 1.0)
    row = tradeoff_table.compare(a, b, is_reference=False)
    assert row["error_static_force"] == 3.0
    assert row["error_static_force_uncertainty"] == 5.0
    ref = tradeoff_table.compare(b, b, is_reference=True)
    assert ref["error_period"] == 0.0 and ref["error_period_uncertainty"] == 0.0


def test_knob_overrides_keep_simulated_time_and_drive_per_area():
    base = {"slide_steps": 60000, "trace_every": 50}
    o = tradeoff.timestep_overrides(base, 0.0025)
    assert o["slide_steps"] * 0.0025 == pytest.approx(base["slide_steps"] * 0.005)
    assert o["trace_every"] * 0.0025 == pytest.approx(base["trace_every"] * 0.005)
    b = tradeoff.box_overrides({}, (10, 6))
    assert b["spring_constant"] / 100.0 == pytest.approx(60 / 28)
    assert b["wall_mass"] / 500.0 == pytest.approx(60 / 28)


@pytest.mark.parametrize("quick", [True, False])
def test_every_planned_setting_is_a_valid_scene_with_one_reference_per_knob(quick):
    p = tradeoff.plan(quick)
    for s in p.settings:
        load(tradeoff.SCENE, {**p.base, **s.overrides})
    knobs = {s.knob for s in p.settings}
    for knob in knobs:
        assert sum(s.reference for s in p.settings if s.knob == knob) == 1, knob
    assert {"timestep", "cutoff", "thermostat_damping", "trace_every", "run_length",
            "wall_model"} <= knobs
    if not quick:
        assert {"box", "thermostat_placement"} <= knobs


def test_reduced_integrators_agree_with_the_closed_form():
    rows = {r["value"]: r for r in tradeoff_reduced.reduced_rows(repeat=1)}
    assert rows["closed_form"]["reference"]
    assert rows["closed_form"]["cycles"] >= 20
    for label, r in rows.items():
        for name in ("static_force", "slip_distance", "period"):
            assert abs(r[f"error_{name}"]) < 1e-2 * abs(r[f"value_{name}"]), (label, name)
    # the event-driven ODE path is exact to round-off whatever its rtol; a hand-written
    # RK45 loop is not: its error follows its tolerance
    assert abs(rows["solve_ivp_rk45_rtol_1e-3"]["error_period"]) > \
        abs(rows["solve_ivp_rk45_rtol_1e-9"]["error_period"])


@pytest.mark.parametrize("name", fidelity.names())
def test_presets_are_valid_for_every_scene(name):
    for scene in ("stick-slip", "smooth-sliding", "film-structure"):
        base = load(scene).parameters
        resolved = load(scene, fidelity.preset(name, base)).parameters
        # a preset never changes the physics, only numerics
        for key in ("drive_velocity", "normal_pressure", "temperature", "film_layers",
                    "cutoff", "mount_damping"):
            assert resolved[key] == base[key]
        # and keeps simulated times (up to its own factor)
        f = fidelity.PRESETS[name]
        assert resolved["slide_steps"] * resolved["timestep"] == pytest.approx(
            f.slide_factor * base["slide_steps"] * base["timestep"], rel=1e-4)


def test_reference_preset_keeps_the_drive_per_area_of_a_preloaded_scene():
    # sfb-thick-stiff loads its spring by a ramp at start-up: on 4x the area the ramp's
    # force per area, like K and M per area, must stay the scene's, and its time too
    base = load("sfb-thick-stiff").parameters
    resolved = load("sfb-thick-stiff", fidelity.preset("reference", base)).parameters
    area = resolved["cells_x"] * resolved["cells_y"] / (base["cells_x"] * base["cells_y"])
    assert area == 4
    for key in ("spring_constant", "wall_mass", "preload_force"):
        assert resolved[key] == pytest.approx(area * base[key])
    assert resolved["preload_steps"] * resolved["timestep"] == pytest.approx(
        base["preload_steps"] * base["timestep"])


def test_standard_preset_is_the_default_scene():
    assert fidelity.preset("standard") == {}
    assert fidelity.preset("standard", load("stick-slip").parameters) == {}


def test_unknown_preset_is_a_clear_error():
    with pytest.raises(SceneError, match="unknown fidelity 'fast'.*preview"):
        fidelity.preset("fast")


def test_cli_refuses_bad_input(tmp_path, run_cli):
    taken = tmp_path / "taken"
    taken.mkdir()
    r = run_cli("tradeoff", "--quick", "--out", taken)
    assert r.code == 2 and "already exists" in r.err
    r = run_cli("tradeoff", "--np", "0", "--out", tmp_path / "x")
    assert r.code == 2 and "--np 0" in r.err
    assert not (tmp_path / "x").exists() and list(taken.iterdir()) == []


@pytest.mark.md
def test_tiny_study_writes_table_json_and_figures(tmp_path, monkeypatch, run_cli, md):
    # two short MD settings and a run-length prefix: the whole pipeline in seconds
    base = {**md.box, "equilibrate_steps": 500, "slide_steps": 4000, "trace_every": 20,
            "restart_every": 0}
    settings = (tradeoff.Setting("trace_every", "20", {}, reference=True),
                tradeoff.Setting("trace_every", "40", {"trace_every": 40}),
                tradeoff.Setting("run_length", "0.5", {}, prefix=0.5),
                tradeoff.Setting("run_length", "1", {}, reference=True))
    monkeypatch.setattr(tradeoff, "plan", lambda quick: tradeoff.Plan(base, settings, "tiny"))
    monkeypatch.setattr(tradeoff, "reduced_rows", lambda repeat=2: [])
    out = tmp_path / "study"
    result = run_cli("tradeoff", "--quick", "--json", "--np", "1", "--out", out)
    assert result.code == 0, result.err
    rows = result.json()
    assert [(r["knob"], r["value"]) for r in rows] == [(s.knob, s.value) for s in settings]
    for r in rows:
        assert r["cost_seconds"] > 0 and r["cost_seconds_per_tau"] > 0
        assert r["atom_steps_per_second"] > 0 and r["memory_peak_rss_mb"] > 1
        for name in tradeoff_table.OBSERVABLES:
            assert f"error_{name}" in r and f"error_{name}_uncertainty" in r
    assert rows[0]["error_static_force"] == 0.0
    # the same trajectory traced every 40 steps instead of 20: identical dynamics (20 tau,
    # the first stick: no slip yet), so the same energy turnover, seen at half the sampling
    coarse, reference = rows[1], rows[0]
    for name in ("ledger_closure", "energy_drift"):
        assert coarse[f"value_{name}"] == pytest.approx(reference[f"value_{name}"], rel=1e-3,
                                                       abs=1e-9), (name, coarse)
        assert abs(coarse[f"error_{name}"]) <= 1e-3 * abs(reference[f"value_{name}"]) + 1e-9
    # half the run costs less than the whole
    assert rows[2]["cost_seconds"] < rows[3]["cost_seconds"]
    with open(out / "tradeoff.csv") as fh:
        table = list(csv.DictReader(fh))
    assert len(table) == len(rows) and "error_period_uncertainty" in table[0]
    for name in tradeoff_table.OBSERVABLES:
        assert (out / f"pareto_{name}.png").stat().st_size > 1000


def test_figures_are_written_atomically(tmp_path, monkeypatch):
    written, write_atomic = [], tradeoff_figures.write_atomic

    def record(path, data):
        written.append(path.name)
        return write_atomic(path, data)

    monkeypatch.setattr(tradeoff_figures, "write_atomic", record)
    row = {"knob": "timestep", "value": "0.01", "reference": False, "cost_seconds": 2.0,
           **{f"error_{n}": 0.1 for n in tradeoff_table.OBSERVABLES},
           **{f"error_{n}_uncertainty": 0.01 for n in tradeoff_table.OBSERVABLES}}
    paths = tradeoff_figures.plot([row, {**row, "value": "0.005", "reference": True}], tmp_path)
    assert sorted(written) == sorted(p.name for p in paths) == sorted(
        f"pareto_{n}.png" for n in tradeoff_table.OBSERVABLES)


def test_point_labels_do_not_overlap_each_other_or_the_markers():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # the study's crowded corner: four settings that cost the same as the default run
    points = [("0.005", 18.2, 1.0), ("7x4", 18.2, 2.0), ("0.25", 18.2, 0.4), ("50", 18.2, 0.1),
              ("250", 21.1, 0.9), ("both", 29.7, 2.6), ("film", 30.0, 3.7), ("0.5", 10.1, 2.6)]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot([p[1] for p in points], [p[2] for p in points], "o")
    ax.set_xscale("log")
    ax.set_ylim(0, 25)
    fig.tight_layout()
    anns = tradeoff_figures.place_labels(ax, points)
    renderer = fig.canvas.get_renderer()
    boxes = [a.get_window_extent(renderer) for a in anns]
    assert [a.get_text() for a in anns] == [p[0] for p in points]
    for k, box in enumerate(boxes):
        assert all(not box.overlaps(other) for other in boxes[k + 1:]), anns[k].get_text()
        for _, x, y in points:
            mx, my = ax.transData.transform((x, y))
            assert not (box.x0 < mx < box.x1 and box.y0 < my < box.y1), (anns[k].get_text(), x, y)
        assert ax.get_window_extent(renderer).contains(box.x0, box.y0)
    plt.close(fig)


def test_seeds_combine_into_the_mean_and_its_scatter():
    runs = [tradeoff_table.Measurement(values={"static_force": (m, 0.1)}, cycles=6, regime=r, area=58.7)
            for m, r in ((90.0, "stick-slip"), (96.0, "stick-slip"), (99.0, "irregular"))]
    both = tradeoff_table.combine(runs)
    mean, se = both.values["static_force"]
    assert mean == pytest.approx(95.0)
    # the scatter over the runs (std 4.58), not the runs' own 0.1
    assert se == pytest.approx(np.std([90.0, 96.0, 99.0], ddof=1) / np.sqrt(3))
    assert both.cycles == 18 and both.regime == "mixed: irregular, stick-slip"
    assert tradeoff_table.combine(runs[:1]) is runs[0]


@pytest.mark.parametrize("value", ["0", "101", "-2"])
def test_seeds_out_of_range_are_refused(run_cli, tmp_path, value):
    result = run_cli("tradeoff", "--seeds", value, "--out", tmp_path / "s")
    assert result.code == 2 and f"--seeds {value}: allowed 1 to 100" in result.err
    assert not (tmp_path / "s").exists()


@pytest.mark.md
def test_a_study_with_two_seeds_runs_each_setting_twice(tmp_path, monkeypatch, run_cli, md):
    base = {**md.box, "equilibrate_steps": 500, "slide_steps": 4000, "trace_every": 20,
            "restart_every": 0}
    settings = (tradeoff.Setting("trace_every", "20", {}, reference=True),
                tradeoff.Setting("trace_every", "40", {"trace_every": 40}))
    monkeypatch.setattr(tradeoff, "plan", lambda quick: tradeoff.Plan(base, settings, "tiny"))
    monkeypatch.setattr(tradeoff, "reduced_rows", lambda repeat=2: [])
    out = tmp_path / "study"
    result = run_cli("tradeoff", "--quick", "--json", "--np", "1", "--seeds", "2", "--out", out)
    assert result.code == 0, result.err
    rows = result.json()
    assert [r["seeds"] for r in rows] == [2, 2]
    dirs = sorted(d.name for d in (out / "runs").iterdir())
    assert len(dirs) == 4 and sum("seed+1" in d for d in dirs) == 2, dirs
    seeded = [json.loads((out / "runs" / d / "run.json").read_text())["scene"]["parameters"]["seed"]
              for d in dirs]
    assert len(set(seeded)) == 2
    # the coarse trace's ledger closure: the mean over its two runs, measured one by one
    one = [tradeoff.measure(out / "runs" / d).values["ledger_closure"][0]
           for d in dirs if "trace_every-40" in d]
    assert rows[1]["value_ledger_closure"] == pytest.approx(np.mean(one), rel=1e-9)
    assert rows[0]["error_static_force"] == 0.0
