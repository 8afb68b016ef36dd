"""Flexible thermostatted walls and the thermostat's placement (real, small LAMMPS runs)."""
import json

import MDAnalysis as mda
import numpy as np
import pytest

from filmfriction.workflows.md.scene import SceneError, load
from filmfriction.workflows.md.scenes.parameters import parse_assignment

# on the md fixture's 5 x 3 box
SMALL = {"equilibrate_steps": 2000, "slide_steps": 6000, "trace_every": 20, "wall_mass": 300.0}


def test_choices_are_checked_and_passed_as_indices():
    s = load("stick-slip", {"wall_model": "flexible", "thermostat_placement": "both"})
    v = s.lammps_variables()
    assert v["wall_model"] == "1" and v["thermostat_placement"] == "2"
    assert parse_assignment("wall_model=flexible") == ("wall_model", "flexible")
    for text in ("wall_model=flexible; shell ls", "wall_model=2", "wall_model=Flexible"):
        with pytest.raises(SceneError, match="must be one of rigid, flexible"):
            parse_assignment(text)


def test_walls_thermostat_needs_flexible_walls():
    with pytest.raises(SceneError, match="needs wall_model = 'flexible'"):
        load("stick-slip", {"thermostat_placement": "walls"})


def test_wall_mass_must_exceed_the_flexible_planes():
    # 7 x 4 cells, cutoff 2.5: 3 flexible planes of 56 atoms of mass 2 = 336 m
    with pytest.raises(SceneError, match=r"wall_mass 300 m is not above .* \(336 m"):
        load("stick-slip", {"wall_model": "flexible", "wall_mass": 300.0})


def test_flexible_walls_refuse_a_temperature_that_would_melt_them():
    load("stick-slip", {"wall_model": "flexible", "temperature": 1.0})
    with pytest.raises(SceneError, match="temperature 1.2 .* above 1, the limit for flexible"):
        load("stick-slip", {"wall_model": "flexible", "temperature": 1.2})


def _wall_spread(run_dir):
    """Largest rms in-plane displacement of the top wall's flexible atoms from their
    starting sites, relative to the driven backing, over the trajectory [sigma]."""
    u = mda.Universe(str(run_dir / "topology.data"), str(run_dir / "trajectory.dcd"),
                     format="DCD", topology_format="DATA", atom_style="id type x y z")
    backing, flexible = u.select_atoms("type 3"), u.select_atoms("type 5")
    assert len(flexible) in (2 * len(backing), 3 * len(backing))
    u.trajectory[0]
    rel0 = flexible.positions - backing.center_of_mass()
    spread = []
    for _ in u.trajectory[1:]:
        rel = flexible.positions - backing.center_of_mass()
        spread.append(np.sqrt(((rel - rel0)[:, :2] ** 2).sum(axis=1).mean()))
    return max(spread)


@pytest.fixture(scope="module")
def walls_run(md):
    run = md.shared("film-structure", **SMALL, wall_model="flexible",
                    thermostat_placement="walls", dump_every=200, nprocs=2)
    return run.scene, run.path


@pytest.mark.md
def test_walls_alone_hold_the_film_temperature(walls_run, md):
    scene, run_dir = walls_run
    d = md.trace(run_dir)
    target = scene.parameters["temperature"]
    # the film has no thermostat of its own: it stays at T only through the walls
    assert abs(d["film_temperature"].mean() - target) < 0.1 * target
    # the walls' thermostats exchange heat with the system, and the ledger closes
    # with it.  (Its sign over so short a run is the walls' thermal fluctuation:
    # over seeds it ranged from -78 to +33 epsilon, against 9 epsilon of drive work.)
    assert np.ptp(d["thermostat_heat"]) > 1.0
    assert md.ledger_closure(d) < 0.02


@pytest.mark.md
def test_flexible_walls_stay_crystalline_and_follow_the_backing(walls_run):
    _, run_dir = walls_run
    # thermal rattling on their sites (rms ~0.1 sigma), no melting, no drift
    # away from the driven backing: far below a lattice spacing (1.1 sigma)
    assert _wall_spread(run_dir) < 0.3
    record = json.loads((run_dir / "run.json").read_text())
    assert record["status"] == "completed"
    # the whole top wall: its rigid plane and its flexible planes (5 x 3 cells, 30 per plane)
    assert record["atoms"]["top_wall"] == record["derived"]["wall_layers"] * 30


@pytest.mark.md
def test_flexible_walls_at_their_hottest_allowed_temperature_stay_crystalline(tmp_path, md):
    # the film melts at kT = 1 (it slides smoothly), the walls must not
    scene = md.scene("film-structure", **{**SMALL, "wall_model": "flexible",
                                          "thermostat_placement": "both", "temperature": 1.0,
                                          "slide_steps": 3000, "dump_every": 200})
    run_dir = md.execute(scene, tmp_path / "hot", nprocs=2)
    assert _wall_spread(run_dir) < 0.3


@pytest.mark.md
def test_without_a_mount_dashpot_the_film_takes_the_slip_energy(tmp_path, md):
    # energy-partition: M = 20, no mount dashpot.  The film is then the only sink
    # of the slider's energy: what the spring releases in a slip must show up as
    # the film's dissipation during the slip, with little left ringing at the
    # stick (Klein: >= 90 % viscous).  A check of the partition's bookkeeping on
    # a real run; that the light slider keeps the slips regular needs long runs
    # (README, "energy-partition").
    from filmfriction.analysis.analyze import analyze
    from filmfriction.analysis.files.trace_reader import read_trace

    area = 15 / 28  # the 5 x 3 box against the scene's 7 x 4: same drive per area
    scene = md.scene("energy-partition", spring_constant=100.0 * area, wall_mass=20.0 * area,
                     equilibrate_steps=2000, slide_steps=30000, trace_every=20, restart_every=0)
    run_dir = md.execute(scene, tmp_path / "run", nprocs=2)
    doc, _ = analyze(read_trace(run_dir), structure=False)
    energy = doc["energy"]
    assert doc["slips"]["count"] >= 2
    assert energy["mount_dissipation_slip"]["mean"] == 0.0
    assert energy["viscous_fraction"]["mean"] > 0.8
    released = energy["spring_released_exact"]["mean"] + energy["drive_work_slip"]["mean"]
    assert energy["film_dissipation"]["mean"] > 0.8 * released
