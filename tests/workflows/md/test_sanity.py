"""Physics sanity of a finished run (sanity.sanity_warnings) and the lost-atoms
hint, on synthetic traces and parameters: fast, no LAMMPS."""
from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from filmfriction.workflows.md import finish, runner
from filmfriction.workflows.md.output import lammps_output, sanity, trace_dat
from filmfriction.workflows.md.scene import load


def _scene(**p):
    return load("stick-slip", p)


def _dat(scene, n=400, **change):
    """A steady-sliding trace that passes every check; ``change``: column -> array."""
    p = scene.parameters
    V, T = p["drive_velocity"], p["temperature"]
    t = np.arange(n) * p["trace_every"] * p["timestep"]
    cols = {c: np.zeros(n) for c in runner.DAT_COLUMNS}
    cols.update(step=np.arange(n) * p["trace_every"], time=t, drive_position=V * t,
                wall_position=V * t - 0.1, wall_velocity=np.full(n, V),
                film_temperature=np.full(n, T), gap=np.full(n, 3.7))
    cols.update(change)
    return np.column_stack([cols[c] for c in runner.DAT_COLUMNS])


def test_a_sane_run_has_no_warnings():
    s = _scene()
    assert sanity.sanity_warnings(_dat(s), s) == []


@pytest.mark.parametrize("column, values, check", [
    ("film_temperature", lambda n, s: np.full(n, 2 * s.parameters["temperature"]),
     "film temperature: mean 1.4"),
    ("gap", lambda n, s: np.linspace(3.7, 6.6, n), "gap drift: the gap went from"),
    ("wall_velocity", lambda n, s: np.full(n, 0.5 * s.parameters["drive_velocity"]),
     None),  # the speed check reads the wall's displacement, below
    ("drive_work", lambda n, s: np.linspace(0, 10, n), "energy ledger: residual"),
])
def test_each_check_names_itself_and_the_values(column, values, check):
    s = _scene()
    n = 400
    if check is None:
        V = s.parameters["drive_velocity"]
        t = np.arange(n) * s.parameters["trace_every"] * s.parameters["timestep"]
        dat = _dat(s, n, wall_position=0.5 * V * t, wall_velocity=np.full(n, 0.5 * V))
        check = "wall speed: 0.01 sigma/tau in steady sliding against the drive V = 0.02"
    else:
        dat = _dat(s, n, **{column: values(n, s)})
    warnings = sanity.sanity_warnings(dat, s)
    assert len(warnings) == 1 and check in warnings[0], warnings


def test_stick_slip_is_not_taken_for_a_slow_wall():
    s = _scene()
    n = 400
    v = np.where(np.arange(n) % 50 < 40, 0.0, 5 * s.parameters["drive_velocity"])
    assert sanity.sanity_warnings(_dat(s, n, wall_velocity=v), s) == []


def test_finish_records_completed_with_warnings(tmp_path):
    s = _scene()
    dat = _dat(s, 400, film_temperature=np.full(400, 1.4))
    trace_dat.rewrite_trace_dat(tmp_path / "trace.dat", dat)
    record = {"segments": [], "trace_parameters": {}}
    finish.finish(tmp_path, record, replace(s, parameters={**s.parameters,
                                                              "slide_steps": 399 * 50}),
                   lammps_output.EngineOutcome(returncode=0, error=None), None)
    saved = json.loads((tmp_path / "run.json").read_text())
    assert saved["status"] == "completed_with_warnings"
    assert saved["warnings"][0].startswith("film temperature")
    assert (tmp_path / "trace.csv").exists()


@pytest.mark.parametrize("params, cause", [
    ({"temperature": 5.0}, "above the LJ critical temperature"),
    ({"film_spacing": 0.9, "cells_x": 8, "cells_y": 5}, "film_spacing 0.9 sigma against"),
    ({"timestep": 0.009}, "close to the stability limit"),
    ({"normal_pressure": 0.1}, "normal_pressure 0.1 is low for temperature 0.7"),
    ({"cutoff": 2 ** (1 / 6)}, "cutoff 1.122 sigma is purely repulsive (WCA)"),
])
def test_lost_atoms_hint_names_the_cause_from_the_parameters(params, cause):
    s = _scene()
    s = replace(s, parameters={**s.parameters, **params})
    hint = sanity.lost_atoms_hint(s)
    # the named cause comes first: the most likely one
    assert hint.startswith(" (atoms left the box; likely cause: ") and cause in hint, hint
    assert hint.index(cause) < 80, hint


def test_lost_atoms_hint_for_default_parameters_blames_nothing_in_particular():
    assert "none of" in sanity.lost_atoms_hint(_scene())


def test_a_thick_film_that_gains_a_layer_is_flagged_below_the_share():
    # six layers (gap 6.6 sigma) dilating by a layer's worth to 7.45 (+13 %, under the 15 %
    # share): the film melted and slid as a liquid; a few % of breathing at slips is not flagged
    s = load("sfb-thick-heavy", {})
    n = 400
    grown = np.concatenate([np.full(n // 2, 6.6), np.full(n - n // 2, 7.45)])
    warnings = sanity.sanity_warnings(_dat(s, n, gap=grown, wall_velocity=np.zeros(n)), s)
    assert len(warnings) == 1 and "+0.90 of a layer's 0.943 sigma" in warnings[0], warnings
    breathing = 6.6 + 0.15 * (np.arange(n) % 40 < 8)
    assert sanity.sanity_warnings(_dat(s, n, gap=breathing, wall_velocity=np.zeros(n)), s) == []
