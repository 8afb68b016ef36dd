"""The release test's scene parameters: drive_velocity 0 only with a release_offset."""
import pytest

from filmfriction.workflows.md.scene import SceneError, load
from filmfriction.workflows.md.scenes.parameters import resolve


def test_zero_drive_needs_a_release_offset():
    with pytest.raises(SceneError, match=r"drive_velocity = 0.0 .*release_offset > 0"):
        resolve({"drive_velocity": 0.0})
    p = resolve({"drive_velocity": 0.0, "release_offset": 20.0})
    assert p["release_offset"] == 20.0


def test_release_offset_range_and_its_lammps_variable():
    with pytest.raises(SceneError, match=r"release_offset = -1.0"):
        resolve({"release_offset": -1.0})
    scene = load("liquid-release")
    assert scene.lammps_variables()["release_offset"] == "20.0"
    assert scene.lammps_variables()["drive_velocity"] == "0.0"


def test_hold_gap_is_0_or_1_and_its_lammps_variable():
    with pytest.raises(SceneError, match=r"hold_gap = 2: outside the allowed range"):
        resolve({"hold_gap": 2})
    assert resolve({})["hold_gap"] == 0
    scene = load("liquid-release", {"hold_gap": 1})
    assert scene.lammps_variables()["hold_gap"] == "1"
