"""Scenes and validation: every value is checked before LAMMPS starts."""
import math

import pytest

from filmfriction.workflows import cli, scene
from filmfriction.workflows.scene import PARAMETERS, SceneError, load, parse_assignment, resolve


def test_every_shipped_scene_loads_and_is_valid():
    names = scene.available()
    assert {"stick-slip", "smooth-sliding", "film-structure"} <= set(names)
    for name in names:
        s = load(name)
        assert s.description and s.models and s.expected_cost
        assert set(s.parameters) == set(PARAMETERS)


def test_contract_names_exist():
    for name in ("drive_velocity", "spring_constant", "normal_pressure", "temperature",
                 "film_layers", "wall_mass", "wall_fluid_epsilon", "wall_spacing",
                 "timestep", "cutoff", "seed"):
        assert name in PARAMETERS


def test_outputs_follow_observables():
    plain = load("stick-slip")
    assert not plain.writes_trajectory and not plain.writes_profiles
    v = plain.lammps_variables()
    assert v["dump_every"] == "0" and v["profile_every"] == "0"
    rich = load("film-structure")
    assert rich.writes_trajectory and rich.writes_profiles
    assert int(rich.lammps_variables()["dump_every"]) > 0


@pytest.mark.parametrize("key,value,fragment", [
    ("film_layers", 9, "film_layers = 9"),
    ("film_layers", 2.5, "whole number"),
    ("drive_velocity", 0.0, "drive_velocity = 0.0"),
    ("drive_velocity", math.nan, "finite"),
    ("temperature", -0.1, "temperature = -0.1"),
    ("seed", True, "must be a number"),
    ("spring_constant", "100", "must be a number"),
])
def test_bad_values_name_parameter_value_and_range(key, value, fragment):
    with pytest.raises(SceneError) as err:
        resolve({key: value})
    assert fragment in str(err.value)
    assert key in str(err.value)


def test_timestep_against_lj_and_spring_limits():
    with pytest.raises(SceneError, match=r"timestep 0.02 tau is above the stability limit 0.01 tau"):
        resolve({"timestep": 0.02})
    # stiff spring on a light wall: the wall's period sets the limit
    with pytest.raises(SceneError, match=r"spring_constant K=10000 .* wall_mass M=1 m"):
        resolve({"spring_constant": 1e4, "wall_mass": 1.0})
    # stronger wall-film bond shortens the LJ limit
    with pytest.raises(SceneError, match=r"wall_fluid_epsilon = 4"):
        resolve({"wall_fluid_epsilon": 4.0, "timestep": 0.006})


def test_lateral_box_must_exceed_two_cutoffs():
    with pytest.raises(SceneError, match=r"shorter than 2 cutoffs"):
        resolve({"cells_x": 3})


def test_film_must_fit_box():
    with pytest.raises(SceneError, match=r"strained"):
        resolve({"film_spacing": 1.3, "cells_x": 5})


def test_unknown_parameter_is_listed():
    with pytest.raises(SceneError, match=r"unknown parameter 'drive_speed'"):
        resolve({"drive_speed": 1.0})


@pytest.mark.parametrize("text", [
    "drive_velocity=0.1\nshell touch /tmp/pwned",
    "drive_velocity=0.1 ; shell rm -rf /",
    "drive_velocity=${x}",
    "timestep=0.005\n",  # trailing newline is still a number for float(); see below
])
def test_injection_via_set_is_rejected_or_reduced_to_a_number(text):
    try:
        key, value = parse_assignment(text)
    except SceneError:
        return
    # only a pure number may pass; it is re-formatted by us, never pasted
    assert isinstance(value, (int, float))
    s = load("stick-slip", {key: value})
    assert all(c not in s.lammps_variables()[key] for c in " ;\n$\"'")


def test_injection_via_scene_file_is_rejected(tmp_path):
    bad = tmp_path / "evil.toml"
    bad.write_text('name = "evil"\n[parameters]\ndrive_velocity = "0.1\\nshell touch /tmp/x"\n')
    with pytest.raises(SceneError, match="must be a number"):
        load(str(bad))
    bad.write_text('name = "evil"\n[parameters]\nlammps_command = 1\n')
    with pytest.raises(SceneError, match="unknown parameter"):
        load(str(bad))
    bad.write_text('name = "evil"\nscript = "shell ls"\n')
    with pytest.raises(SceneError, match="unknown keys"):
        load(str(bad))


def test_variables_are_plain_numbers():
    for name, value in load("film-structure").lammps_variables().items():
        float(value)  # raises if anything but a number


def test_cli_rejects_bad_value_before_lammps(tmp_path, capsys):
    out = tmp_path / "run"
    code = cli.main(["run", "--set", "timestep=0.02", "--out", str(out), "--quiet"])
    assert code == 2
    err = capsys.readouterr().err
    assert "timestep 0.02 tau is above the stability limit" in err
    assert not out.exists()  # nothing was started


def test_cli_scenes_lists_descriptions(capsys):
    assert cli.main(["scenes"]) == 0
    text = capsys.readouterr().out
    assert "stick-slip" in text and "cost:" in text
