"""filmfriction viscosity end to end with real LAMMPS (256 atoms, a few seconds)."""
import contextlib
import io
import json
import math

import numpy as np
import pytest

from filmfriction.analysis import green_kubo as gk
from filmfriction.workflows.cli.main import main

pytestmark = pytest.mark.md

SMALL = ["viscosity", "--temperature", "0.722", "--density", "0.8442", "--cells", "4",
         "--steps", "8000", "--blocks", "4", "--correlation-time", "1",
         "--equilibrate-steps", "2000", "--np", "1"]
KEYS = {"eta", "eta_stderr", "units", "temperature", "density", "cutoff", "n_atoms", "steps",
        "method"}


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("visc") / "run"
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = main(SMALL + ["--json", "--out", str(out)])
    return code, stdout.getvalue(), stderr.getvalue(), out


def test_runs_end_to_end_with_json(small_run):
    code, stdout, stderr, out = small_run
    assert code == 0, stderr
    result = json.loads(stdout)                      # stdout is the JSON object alone
    assert KEYS <= set(result)
    assert result["units"] == "epsilon*tau/sigma^3"
    assert result["eta"] > 0 and math.isfinite(result["eta"])
    assert result["eta_stderr"] > 0 and math.isfinite(result["eta_stderr"])
    assert result["n_atoms"] == 256 and result["steps"] == 8000
    assert (result["temperature"], result["density"], result["cutoff"]) == (0.722, 0.8442, 2.5)
    assert "Green-Kubo" in result["method"] and "4 independent blocks" in result["method"]
    # a liquid at the right temperature
    assert result["measured_temperature"] == pytest.approx(0.722, abs=0.02)
    assert result["diffusion"] > 0.01
    # progress went to stderr, one line per block
    assert stderr.count("block ") == 4
    # the OMCTS time units
    assert result["omcts"]["tau_s"] == pytest.approx(7.55e-12, rel=0.01)
    assert result["omcts"]["tau_eta_s"] > result["omcts"]["tau_s"]


def test_run_directory_and_lammps_integral(small_run):
    code, stdout, _, out = small_run
    result = json.loads(stdout)
    for name in ("command.txt", "lammps.log", "gk.blocks", "gk.correlate", "viscosity.json",
                 "gk_integral.csv"):
        assert (out / name).is_file(), name
    assert json.loads((out / "viscosity.json").read_text())["eta"] == result["eta"]
    # our trapezoid over gk.correlate ends where LAMMPS's trap() did
    blocks = gk.read_blocks(out / "gk.blocks")
    corr = gk.read_correlate(out / "gk.correlate")
    assert len(corr.steps) == 4 and corr.values.shape[2] == 3
    t, eta, _ = gk.running_integral(corr, volume=256 / 0.8442,
                                    temperature=blocks["temperature"], timestep=0.005)
    assert t[-1] == pytest.approx(1.0)
    assert eta[-1] == pytest.approx(result["eta"], rel=1e-5)
    table = np.genfromtxt(out / "gk_integral.csv", delimiter=",", names=True)
    assert table["eta"][-1] == pytest.approx(result["eta"], rel=1e-5)


def test_second_run_into_the_same_directory_is_refused(small_run, capsys):
    *_, out = small_run
    before = sorted(p.name for p in out.iterdir())
    assert main(SMALL + ["--out", str(out)]) == 2
    assert "already exists" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == before
