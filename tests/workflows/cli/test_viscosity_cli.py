"""filmfriction viscosity without LAMMPS: input checks and the Green-Kubo file readers."""
import math

import numpy as np
import pytest

from filmfriction.analysis import green_kubo as gk
from filmfriction.workflows.cli import viscosity_cli
from filmfriction.workflows.md import viscosity_run
from filmfriction.workflows.cli.main import main

STATE = ["viscosity", "--temperature", "0.722", "--density", "0.8442"]


@pytest.fixture
def no_compute(monkeypatch, tmp_path):
    """Any attempt to start LAMMPS fails the test; the cwd is a scratch directory."""
    def forbidden(*args, **kwargs):
        raise AssertionError("LAMMPS was started for a bad input")

    monkeypatch.setattr(viscosity_cli, "run", forbidden)
    monkeypatch.setattr(viscosity_cli.engine, "lmp_command", forbidden)
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("extra, names, accepted", [
    (["--temperature", "0"], "--temperature 0", "> 0"),
    (["--temperature", "-1"], "--temperature -1", "> 0"),
    (["--temperature", "nan"], "--temperature nan", "> 0"),
    (["--temperature", "inf"], "--temperature inf", "> 0"),
    (["--density", "nan"], "--density nan", "(0, 1.4142)"),
    (["--density", "1.5"], "--density 1.5", "(0, 1.4142)"),
    (["--density", "0"], "--density 0", "(0, 1.4142)"),
    (["--density", "-0.8"], "--density -0.8", "(0, 1.4142)"),
    (["--cutoff", "0.5"], "--cutoff 0.5", "[1, 5.04]"),
    (["--cutoff", "6"], "--cutoff 6", "[1, 5.04]"),
    (["--steps", "100"], "--steps 100", ">= 12000"),
    (["--steps", "-5"], "--steps -5", ">= 12000"),
    (["--blocks", "1"], "--blocks 1", ">= 2"),
    (["--cells", "1"], "--cells 1", "[2, 40]"),
    (["--timestep", "0.1"], "--timestep 0.1", "(0, 0.01]"),
    (["--timestep", "0"], "--timestep 0", "(0, 0.01]"),
    (["--correlation-time", "0"], "--correlation-time 0", ">= 0.05"),
    (["--sample-every", "0"], "--sample-every 0", ">= 1"),
    (["--np", "0"], "--np 0", ">= 1"),
    (["--seed", "0"], "--seed 0", "[1, 2^31)"),
])
def test_bad_input_is_one_line_before_any_compute(no_compute, capsys, extra, names, accepted):
    args = STATE + extra
    # a later option replaces the state's own --temperature / --density
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0, err
    assert err.startswith("filmfriction viscosity: error: ")
    assert names in err and accepted in err, err
    assert not (no_compute / "runs").exists()


def test_existing_output_directory_is_refused(no_compute, capsys):
    out = no_compute / "taken"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    assert main(STATE + ["--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"--out {out}" in err and "already exists" in err
    assert (out / "keep.txt").read_text() == "mine"
    assert sorted(p.name for p in out.iterdir()) == ["keep.txt"]


def test_the_default_relative_run_directory_reaches_lammps(monkeypatch, tmp_path):
    """LAMMPS runs inside the run directory: the log path it is given must name the run
    directory's lammps.log from there, also for the default relative runs/... ."""
    from pathlib import Path

    seen = {}

    class Stop(Exception):
        pass

    def popen(cmd, cwd, **kwargs):
        seen.update(cmd=cmd, cwd=cwd)
        raise Stop

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(viscosity_run.subprocess, "Popen", popen)
    run_dir = Path("runs") / "viscosity-relative"
    run_dir.mkdir(parents=True)
    settings = viscosity_cli.settings_from_args(viscosity_cli.argparse.Namespace(
        **{**viscosity_cli.DEFAULTS, "temperature": 0.722, "density": 0.8442, "np": 1}))
    with pytest.raises(Stop):
        viscosity_cli.run(settings, run_dir, progress=lambda message: None)
    log = Path(seen["cmd"][seen["cmd"].index("-log") + 1])
    assert (tmp_path / seen["cwd"] / log).resolve() == (tmp_path / run_dir / "lammps.log")


def test_missing_state_is_an_argparse_error(no_compute, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["viscosity", "--density", "0.8442"])
    assert exc.value.code == 2
    assert "--temperature" in capsys.readouterr().err


def test_settings_round_to_whole_blocks():
    parser_args = viscosity_cli.argparse.Namespace(
        temperature=0.722, density=0.8442, cutoff=2.5, steps=100_003, blocks=10, cells=6,
        timestep=0.005, correlation_time=2.5, sample_every=5, equilibrate_steps=10_005,
        seed=1, np=1)
    s = viscosity_cli.settings_from_args(parser_args)
    assert s.steps == 100_000 and s.block_steps == 10_000
    assert s.correlation_length == 101            # 2.5 tau / (5 x 0.005 tau) + 1
    assert s.equilibrate_steps % 20 == 0 and s.equilibrate_steps >= 10_005
    assert s.n_atoms == 864
    v = s.lammps_variables()
    assert v["block_steps"] == "10000" and v["blocks"] == "10" and v["cells"] == "6"


# ---------------------------------------------------------------- file readers

def _write_correlate(path, blocks, delays, values, with_start=True, truncated=False):
    """A fix ave/correlate file: an optional step-0 section, then one per block."""
    lines = ["# Time-correlated data for fix gk", "# Timestep Number-of-time-windows",
             "# Index TimeDelta Ncount c_p[4]*c_p[4] c_p[5]*c_p[5] c_p[6]*c_p[6]"]
    n = len(delays)
    if with_start:
        lines.append(f"0 {n}")
        lines += [f"{i + 1} {d} {1 if i == 0 else 0} 0.3 0.2 0.1" if i == 0 else
                  f"{i + 1} {d} 0 0.0 0.0 0.0" for i, d in enumerate(delays)]
    for b, step in enumerate(blocks):
        lines.append(f"{step} {n}")
        for i, d in enumerate(delays):
            lines.append(f"{i + 1} {d} {n + 10 - i} " + " ".join(f"{v:.12g}" for v in values[b, i]))
    if truncated:
        lines.append(f"{blocks[-1] * 2} {n}")
        lines.append("1 0 100 1 1 1")
    path.write_text("\n".join(lines) + "\n")


def test_running_integral_of_an_exponential(tmp_path):
    # C(t) = A exp(-t/tr) in every component: eta(inf) = V/T * A * tr
    dt, every, n = 0.005, 2, 801
    delays = np.arange(n) * every
    t = delays * dt
    a, tr, volume = np.array([1.0, 2.0]), 0.4, 100.0
    temps = np.array([0.5, 0.8])
    values = a[:, None, None] * np.exp(-t / tr)[None, :, None] * np.ones(3)
    path = tmp_path / "gk.correlate"
    _write_correlate(path, [1000, 2000], delays, values, truncated=True)
    corr = gk.read_correlate(path)
    assert list(corr.steps) == [1000, 2000]          # step-0 and cut-short sections dropped
    assert corr.values.shape == (2, n, 3)
    assert corr.names[0] == "c_p[4]*c_p[4]"
    tt, eta, err = gk.running_integral(corr, volume=volume, temperature=temps, timestep=dt)
    exact = volume / temps * a * tr * (1 - np.exp(-tt[-1] / tr))
    assert eta[-1] == pytest.approx(exact.mean(), rel=1e-4)
    assert err[-1] == pytest.approx(exact.std(ddof=1) / math.sqrt(2), rel=1e-4)
    assert eta[0] == 0.0 and tt[1] == pytest.approx(every * dt)


def test_read_correlate_rejects_other_files(tmp_path):
    p = tmp_path / "x"
    p.write_text("# nothing here\n")
    with pytest.raises(ValueError, match="header"):
        gk.read_correlate(p)
    _write_correlate(p, [], np.arange(3), np.zeros((0, 3, 3)))
    with pytest.raises(ValueError, match="no complete"):
        gk.read_correlate(p)


def _write_blocks(path, rows):
    header = "# " + " ".join(gk.BLOCK_COLUMNS)
    path.write_text(header + "\n" + "\n".join(" ".join(map(str, r)) for r in rows) + "\n")


def test_green_kubo_block_statistics(tmp_path):
    etas = np.array([3.0, 3.4, 2.8, 3.2])
    rows = [[10000 * (i + 1), 0.72, 0.9, -5.6, 0.3 * (i + 1) * 50, e - 0.1, e, e + 0.1, e]
            for i, e in enumerate(etas)]
    path = tmp_path / "gk.blocks"
    _write_blocks(path, rows)
    blocks = gk.read_blocks(path)
    r = gk.green_kubo(blocks, timestep=0.005)
    assert r.n_blocks == 4
    assert r.eta == pytest.approx(etas.mean())
    assert r.eta_stderr == pytest.approx(etas.std(ddof=1) / 2)
    assert r.components["xy"] == pytest.approx(etas.mean() - 0.1)
    # msd = 15 per block of 50 tau: D = 15 / 50 / 6
    assert r.diffusion == pytest.approx(15 / 50 / 6)
    assert r.temperature == pytest.approx(0.72)


def test_read_blocks_checks_header_and_rows(tmp_path):
    p = tmp_path / "gk.blocks"
    p.write_text("# step eta\n1 2\n")
    with pytest.raises(ValueError, match="not a gk.blocks"):
        gk.read_blocks(p)
    _write_blocks(p, [[1, 2, 3]])
    with pytest.raises(ValueError, match="columns"):
        gk.read_blocks(p)


def test_sfb_with_the_viscosity_matched_time_unit(run_cli):
    import json

    from filmfriction.reduced_model import MDCalibration
    from filmfriction.reduced_model.units import OMCTS, OMCTS_VISCOSITY_MATCHED

    cal = {"yield_stress": 5.0, "eta_zero": 3.0, "sliding_stress": 1.0, "restick_stress": 2.0}
    rows = {}
    for unit in ("mass", "viscosity"):
        import tempfile
        from pathlib import Path
        path = Path(tempfile.mkdtemp()) / "cal.json"
        path.write_text(json.dumps(cal))
        r = run_cli("sfb", "--json", "--calibration", path, "--time-unit", unit)
        assert r.code == 0, r.err
        rows[unit] = {x["name"]: x for x in r.json() if x["source"] == "md-calibrated"}
    ratio = OMCTS_VISCOSITY_MATCHED.tau / OMCTS.tau
    # eta = eta* eps tau / sigma^3: the matched unit scales it by the ratio of the time units
    assert rows["viscosity"]["eta_eff"]["model"] == pytest.approx(
        rows["mass"]["eta_eff"]["model"] * ratio, rel=1e-6)
    # stresses do not involve time
    assert rows["viscosity"]["yield_stress"]["model"] == pytest.approx(
        rows["mass"]["yield_stress"]["model"])
    assert MDCalibration.from_dict(cal).yield_stress == 5.0
    bad = run_cli("sfb", "--time-unit", "viscosity", "--sigma-nm", "0.9")
    assert bad.code == 2 and "--time-unit viscosity" in bad.err
