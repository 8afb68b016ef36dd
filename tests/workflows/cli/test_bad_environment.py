"""Bad environment variables: the limits' overrides (FILMFRICTION_MAX_*) and
FILMFRICTION_LMP, refused before anything runs.
Table-driven, as every bad-input table: each case ends in one line naming the input,
exit code 2 (1 for an internal error), no traceback, and nothing written (see
conftest.py's ``refused``)."""
from __future__ import annotations

import pytest

# id: (variable, value, command line from tmp and the input builders, message fragment)
ENV_CASES = {
    "FILMFRICTION_MAX_POINTS=abc": (
        "FILMFRICTION_MAX_POINTS", "abc",
        lambda t, b: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", t / "s"],
        "environment variable FILMFRICTION_MAX_POINTS='abc': give a whole number >= 1"),
    "FILMFRICTION_MAX_POINTS=0": (
        "FILMFRICTION_MAX_POINTS", "0",
        lambda t, b: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", t / "s"],
        "FILMFRICTION_MAX_POINTS='0': give a whole number >= 1"),
    "FILMFRICTION_MAX_MAP_SIMULATIONS=1e9": (
        "FILMFRICTION_MAX_MAP_SIMULATIONS", "1e9",
        lambda t, b: ["map", "lambda-zeta", "--out", t / "m"],
        "FILMFRICTION_MAX_MAP_SIMULATIONS='1e9': give a whole number >= 1"),
    "FILMFRICTION_MAX_MAP_SIMULATIONS lowered": (
        "FILMFRICTION_MAX_MAP_SIMULATIONS", "100",
        lambda t, b: ["map", "lambda-zeta", "--out", t / "m"],
        "10,000 simulations, above the limit of 100; give a --resolution of at most 10"),
    "FILMFRICTION_MAX_INPUT_BYTES=-1": (
        "FILMFRICTION_MAX_INPUT_BYTES", "-1", lambda t, b: ["analyze", b.trace(t)],
        "FILMFRICTION_MAX_INPUT_BYTES='-1': give a whole number >= 1"),
    "FILMFRICTION_MAX_INPUT_BYTES lowered": (
        "FILMFRICTION_MAX_INPUT_BYTES", "1000", lambda t, b: ["analyze", b.trace(t)],
        "above the limit of 1,000 bytes for a text input"),
}


@pytest.mark.parametrize("case", list(ENV_CASES))
def test_bad_environment(case, monkeypatch, refused):
    name, value, build, fragment = ENV_CASES[case]
    monkeypatch.setenv(name, value)
    refused(build, fragment, 2)


@pytest.mark.parametrize("command", [
    lambda t, b: ["bench", "--np", "1", "--steps", "10", "--repeat", "1"],
    lambda t, b: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", t / "s"],
], ids=["bench", "sweep"])
def test_a_bad_filmfriction_lmp_is_refused_before_any_run(command, tmp_path, monkeypatch, capsys,
                                                           run_cli, input_files):
    """bench started its first run, a sweep its points, before the executable was looked at."""
    inputs = tmp_path / "in"
    inputs.mkdir()
    monkeypatch.chdir(inputs)
    monkeypatch.setenv("FILMFRICTION_LMP", str(tmp_path / "no-lmp"))
    before = input_files.snapshot(tmp_path)
    rc, out, err = run_cli(*command(inputs, input_files))
    assert rc == 2 and f"FILMFRICTION_LMP {tmp_path / 'no-lmp'}: no such file" in err, err
    assert "[1/" not in out and "Traceback" not in err
    assert input_files.snapshot(tmp_path) == before
