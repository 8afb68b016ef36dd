"""LAMMPS's own files of a real run: the scene's ``trace.dat`` (``fix print``, ``# step
time ...`` header, a title repeated at each restart segment) and the thermo blocks of
its log give the same slips as the ``trace.csv`` the runner writes from ``trace.dat``.

The run is the default stick-slip scene on the small box (~330 atoms, 5 slips in
60k steps), started here through the engine rather than the runner so that the
thermo interval can equal the trace's (the runner prints thermo more sparsely);
its slide runs in three restart segments, so the log holds four thermo runs (the
equilibration, then the slide's three).
"""
from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.md

SETTINGS = {"equilibrate_steps": 2000, "slide_steps": 60000, "trace_every": 50,
            "restart_every": 20000}


@pytest.fixture(scope="module")
def lammps_run(md, tmp_path_factory):
    from filmfriction import md_inputs
    from filmfriction.md_inputs.contract import DATA_FILE
    from filmfriction.workflows.md import engine, runner

    scene = md.scene("stick-slip", **SETTINGS)
    d = tmp_path_factory.mktemp("lammps-files")
    (d / DATA_FILE).write_text(scene.geometry().lammps_data())
    variables = scene.lammps_variables()
    variables["thermo_every"] = str(SETTINGS["trace_every"])
    cmd = engine.lmp_command(1, md_inputs.script(runner.SCRIPT), variables,
                             log=Path("log.lammps"))
    subprocess.run(cmd, cwd=d, env=engine.engine_env(), stdout=subprocess.DEVNULL,
                   stderr=subprocess.STDOUT, timeout=300, check=True)
    runner.write_trace_csv(runner.read_trace_dat(d / "trace.dat"), d / "trace.csv")
    p = scene.parameters
    parameters = {"spring_constant": p["spring_constant"], "mass": p["wall_mass"],
                  "drive_velocity": p["drive_velocity"], "units": "lj"}
    return d, parameters


def _analysed(path, parameters, **reading):
    from filmfriction.analysis.analyze import analyze
    from filmfriction.analysis.files.trace_reader import read_trace

    trace = read_trace(path, **reading, **parameters)
    doc, per_cycle = analyze(trace, structure=False)
    return trace, doc, per_cycle


SLIP_COLUMNS = ("yield_time", "stick_time", "static_force", "backward_force", "slip_distance",
                "slip_duration")


def test_trace_dat_and_the_log_give_the_slips_of_trace_csv(lammps_run):
    d, parameters = lammps_run
    dat_text = (d / "trace.dat").read_text()
    # the file as LAMMPS wrote it: the title again at each segment, a segment's first
    # step printed twice
    assert dat_text.count("# step time drive_position spring_force") == 3
    csv, csv_doc, csv_cycles = _analysed(d / "trace.csv", parameters)
    assert csv_doc["regime"] in ("stick-slip", "irregular") and csv_doc["slips"]["count"] >= 4
    dat, dat_doc, dat_cycles = _analysed(d / "trace.dat", parameters)
    log, log_doc, log_cycles = _analysed(d / "log.lammps", parameters, log_run="2-4")
    assert len(dat) == len(csv) == len(log)
    assert any("segment boundary" in n for n in dat.notes)
    assert any("thermo runs 2-4 joined of 4" in n for n in log.notes)
    for other, cycles in ((dat, dat_cycles), (log, log_cycles)):
        np.testing.assert_array_equal(other.time, csv.time)
        np.testing.assert_array_equal(other.spring_force, csv.spring_force)
        for name in SLIP_COLUMNS:
            np.testing.assert_array_equal(cycles[name], csv_cycles[name], err_msg=name)
    for name in ("static_force", "backward_force", "slip_distance", "slip_duration", "period"):
        assert dat_doc["slips"][name] == csv_doc["slips"][name]
        assert log_doc["slips"][name] == csv_doc["slips"][name]
    # the units check on an MD trace in its own units: the stick ramps agree with K·V
    check = csv_doc["units_check"]
    print("stick ramps / K V:", check["stick_ramp"])
    assert check["stick_ramp"]["agrees"] and not check["warnings"], check
    assert 0.5 < check["stick_ramp"]["ratio"] <= 1.1


def test_analyze_reads_the_log_and_asks_which_run(lammps_run, run_cli, tmp_path):
    d, parameters = lammps_run
    flags = ["--spring-constant", parameters["spring_constant"], "--drive-velocity",
             parameters["drive_velocity"], "--units", "lj", "--no-figure"]
    r = run_cli("analyze", d / "log.lammps", *flags, "--output", tmp_path / "a.json")
    assert r.code == 2
    assert "holds 4 thermo runs" in r.err and "--log-run 2-4" in r.err
    assert len(r.err.strip().splitlines()) == 1
    r = run_cli("analyze", d / "log.lammps", "--log-run", "2-4", *flags,
                "--output", tmp_path / "analysis.json", "--json")
    assert r.code == 0, r.err
    doc = r.json()
    assert doc["source"]["format"] == "lammps-log" and doc["source"]["log_run"] == "2-4"
    csv = run_cli("analyze", d / "trace.csv", *flags, "--output", tmp_path / "b.json", "--json")
    assert csv.code == 0, csv.err
    assert doc["slips"] == csv.json()["slips"]
    # the analysed log's directory reads the log again, with the runs recorded
    from filmfriction.analysis.files.trace_reader import read_trace

    again = read_trace(tmp_path)
    assert again.layout.kind == "lammps-log" and again.layout.log_run == "2-4"
    assert json.loads((tmp_path / "analysis.json").read_text())["source"]["samples"] == len(again)
    r = run_cli("analyze", d / "log.lammps", "--log-run", "5", *flags,
                "--output", tmp_path / "c.json")
    assert r.code == 2 and "--log-run 5" in r.err and "4 finished thermo runs" in r.err
