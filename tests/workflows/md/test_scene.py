"""Scenes and validation: every value is checked before LAMMPS starts."""
import math
import re

import pytest

from filmfriction.workflows.md import scene
from filmfriction.workflows.md.scene import SceneError, load
from filmfriction.workflows.md.scenes.parameters import PARAMETERS, parse_assignment, resolve


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


def test_the_engine_writes_what_the_outputs_ask():
    plain = load("stick-slip")
    assert not plain.writes_trajectory and not plain.writes_profiles
    v = plain.lammps_variables()
    assert v["dump_every"] == "0" and v["profile_every"] == "0"
    rich = load("film-structure")
    assert rich.writes_trajectory and rich.writes_profiles
    assert int(rich.lammps_variables()["dump_every"]) > 0


def test_the_key_observables_is_refused_naming_outputs(tmp_path):
    path = tmp_path / "old.toml"
    path.write_text('name = "old"\ndescription = ""\nmodels = ""\nexpected_cost = ""\n'
                    'observables = ["stick_slip"]\n')
    with pytest.raises(SceneError, match=r"'observables' is not a scene key.*outputs = \[") as exc:
        load(str(path))
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("key,value,fragment", [
    ("film_layers", 9, "film_layers = 9: outside the allowed range [1, 8]"),
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
    bad.write_text('name = "evil"\nlammps_command = "shell ls"\n')
    with pytest.raises(SceneError, match="unknown keys"):
        load(str(bad))
    # a scene's own script is a file named by path, never text run as commands
    bad.write_text('name = "evil"\nscript = "shell ls"\n')
    with pytest.raises(SceneError, match="no such file"):
        load(str(bad))


# what a -var value may look like: a plain decimal number, nothing LAMMPS could expand
NUMBER = re.compile(r"-?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


@pytest.mark.parametrize("name", sorted(scene.available()))
def test_variables_are_plain_numbers(name):
    s = load(name)
    variables = s.lammps_variables()
    for key, text in variables.items():
        assert NUMBER.fullmatch(text), (key, text)     # no spaces, $, quotes, nan or inf
    # and each is the scene's own value (a choice by its index; outputs the scene
    # does not write are switched off)
    off = {"dump_every"} if not s.writes_trajectory else set()
    off |= {"profile_every"} if not s.writes_profiles else set()
    for key, value in s.parameters.items():
        spec = PARAMETERS[key]
        expected = 0 if key in off else spec.choices.index(value) if spec.choices else value
        assert float(variables[key]) == float(expected), (key, variables[key], value)


def test_cli_rejects_bad_value_before_lammps(tmp_path, run_cli):
    out = tmp_path / "run"
    r = run_cli("run", "--set", "timestep=0.02", "--out", out, "--quiet")
    assert r.code == 2
    assert "timestep 0.02 tau is above the stability limit" in r.err
    assert not out.exists()  # nothing was started


def test_cli_scenes_lists_descriptions(run_cli):
    r = run_cli("scenes")
    assert r.code == 0
    for name in scene.available():
        s = load(name)
        assert name in r.out and s.description in r.out and s.expected_cost in r.out, name


def test_version(capsys):
    from filmfriction import __version__
    from filmfriction.workflows.cli.main import main

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"filmfriction {__version__}"
    assert __version__ != "0+unknown"


@pytest.mark.parametrize("text, value", [("slide_steps=1e5", 100000), ("film_layers=3.0", 3),
                                         ("film_layers=3", 3), ("seed=+12", 12)])
def test_set_takes_a_whole_number_written_as_a_float(text, value):
    """--set slide_steps=1e5 was refused as 'not a whole number' (a TOML 3.0 was accepted)."""
    from filmfriction.workflows.md.scenes.parameters import parse_assignment

    key, got = parse_assignment(text)
    assert got == value and isinstance(got, int)


def test_set_refusal_shows_the_parameters_own_range():
    from filmfriction.workflows.md.scenes.parameters import parse_assignment

    with pytest.raises(SceneError, match=r"not a number in \[0, 5\] sigma/tau"):
        parse_assignment("drive_velocity=fast")


def test_a_recording_interval_set_by_the_user_is_recorded():
    # stick-slip records neither a trajectory nor profiles; --set of their interval asks for them
    plain = load("stick-slip")
    assert not plain.writes_profiles and not plain.writes_trajectory
    assert plain.lammps_variables()["profile_every"] == "0"
    asked = load("stick-slip", {"profile_every": 1000, "dump_every": 400})
    assert asked.writes_profiles and asked.writes_trajectory
    var = asked.lammps_variables()
    assert var["profile_every"] == "1000" and var["dump_every"] == "400"
