"""Where the shear sits, on a real LAMMPS slide that writes both a trajectory and profiles:
the section from the profiles alone (no trajectory analyses) comes out, its shares add up,
and it agrees with the section from the trajectory over the same intervals."""
import numpy as np
import pytest

from filmfriction.analysis.analyze import analyze
from filmfriction.analysis.files.trace_reader import read_trace

pytestmark = pytest.mark.md

#: The shared film-structure run's settings (tests/conftest.py FILM_RUN: 3 layers, several
#: slips of ~7 τ at 2.5x the default drive), with frames and profile windows of 1 τ.
RUN = {"equilibrate_steps": 2000, "slide_steps": 12000, "trace_every": 20,
       "drive_velocity": 0.05, "dump_every": 200, "profile_every": 200}


@pytest.fixture(scope="module")
def both(md):
    run = md.shared("film-structure", **RUN)
    from_profiles = analyze(read_trace(run.path), structure=False).document["shear_location"]
    from_trajectory = analyze(read_trace(run.path)).document["shear_location"]
    return run, from_profiles, from_trajectory


def test_the_section_comes_from_the_profiles_without_a_trajectory(both):
    run, prof, _ = both
    assert prof["source"] == "profiles" and prof["profile_window_steps"] == 200
    assert len(prof["share"]) == run.parameters["film_layers"]
    assert prof["slips"] >= 1 and prof["profile_windows"] >= 4
    assert sum(prof["jump"]) == pytest.approx(1.0)
    assert prof["location"] in ("bottom interface", "top interface", "inside the film", "spread")
    assert prof["wall_slip_velocity"] > run.parameters["drive_velocity"]


def test_profiles_and_trajectory_agree_on_the_same_intervals(both):
    _, prof, traj = both
    assert traj["source"] == "trajectory"
    # the same 1 τ intervals in the same slips: the same shares, to far less than their
    # errors (the two differ only in the layers' edges, each from its own density profile,
    # and in time-averaged velocities against displacements; 0.01 on this run)
    assert prof["slips"] == traj["slips"] and prof["samples"] == traj["samples"]
    assert abs(prof["profile_windows"] - traj["frame_pairs"]) <= prof["slips"]
    assert np.all(np.abs(np.subtract(prof["jump"], traj["jump"])) < 0.05), (prof, traj)
    assert prof["interval_largest_gap"] == traj["interval_largest_gap"]
    assert prof["location"] == traj["location"]
