"""``filmfriction analyze``'s options for reading a file: ``--column NAME=COLUMN[:UNIT]``,
``--skip-rows``, ``--comment``, ``--log-run`` and a set-up's ``[trace]`` table; every bad
value is a one-line error (exit 2) naming the option, the value and what is accepted,
before anything is read or written."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "docs" / "examples"
LOG = ROOT / "tests" / "analysis" / "data" / "lammps" / "log.lammps"


@pytest.fixture
def example(tmp_path):
    """The documented SFB example, its numbers rewritten in ms, µN and nm."""
    rows = [line.split("\t") for line in
            (EXAMPLES / "sfb_trace.tsv").read_text().splitlines()[2:]]
    lines = ["t\tF\tx"] + [f"{float(t) * 1e3:.6g}\t{float(f) * 1e6:.5g}\t{float(x) * 1e9:.6g}"
                           for t, f, x in rows]
    (tmp_path / "trace.tsv").write_text("\n".join(lines) + "\n")
    shutil.copy(EXAMPLES / "my_sfb.toml", tmp_path / "my_sfb.toml")
    return tmp_path


UNITS = ["--column", "time=t:ms", "--column", "spring_force=F:uN",
         "--column", "drive_position=x:nm"]


def test_units_on_the_command_line_and_in_the_setup_agree(example, run_cli):
    d = example
    flags = run_cli("analyze", d / "trace.tsv", "--setup", d / "my_sfb.toml", *UNITS,
                    "--json", "--no-figure")
    assert flags.code == 0, flags.err
    assert "warning" not in flags.err
    doc = flags.json()
    assert doc["source"]["column_units"] == {"time": "ms", "spring_force": "uN",
                                             "drive_position": "nm"}
    # the slips of the SI example in SI: its generator's F_s = 9.7 µN within 3 standard
    # errors (read as N it would be 9.7, as in µN 9.7e-12), the period 0.7300 s
    # (docs/measured-traces.md)
    fs = doc["slips"]["static_force"]
    assert abs(fs["mean"] - 9.7e-6) < 3 * fs["stderr"] and fs["stderr"] < 1e-8
    assert doc["slips"]["period"]["mean"] == pytest.approx(0.7300, rel=1e-3)
    assert doc["units_check"]["stick_ramp"]["agrees"]
    setup = (d / "my_sfb.toml").read_text() + (
        '\n[trace]\n[trace.columns]\ntime = "t:ms"\nspring_force = "F:uN"\n'
        'drive_position = "x:nm"\n')
    (d / "with_trace.toml").write_text(setup)
    (d / "analysis.json").unlink()
    table = run_cli("analyze", d / "trace.tsv", "--setup", d / "with_trace.toml", "--json",
                    "--no-figure")
    assert table.code == 0, table.err
    assert table.json()["slips"] == doc["slips"]
    # the sfb check reads the same set-up file, its [trace] table left to the analysis
    from filmfriction.reduced_model.sfb.user_setup import load_setup

    assert load_setup(d / "with_trace.toml").spring_constant == 97.0
    # calibrate and report read the file again the recorded way
    from filmfriction.analysis.files.trace_reader import read_trace

    again = read_trace(d)
    assert again.layout.column_units == doc["source"]["column_units"]
    assert again.spring_force.max() < 1e-4            # in N, not in µN


def test_the_unit_error_of_the_issue_is_warned(example, run_cli):
    """µN, nm and ms read as N, m and s: analysed (the numbers may be what the user
    means) but warned, naming the units that would agree."""
    d = example
    r = run_cli("analyze", d / "trace.tsv", "--setup", d / "my_sfb.toml", "--column", "time=t",
                "--column", "spring_force=F", "--column", "drive_position=x", "--no-figure")
    assert r.code == 0
    (warning,) = [line for line in r.err.splitlines() if line.startswith("warning:")]
    assert "the stick ramps rise at 1e3 × K·V" in warning
    assert "the drive column moves at 1e6 × V" in warning
    assert "spring_force (F) in uN, time (t) in ms and drive_position (x) in nm" in warning


def test_instrument_header_skipped_from_the_setup(example, run_cli):
    d = example
    text = (d / "trace.tsv").read_text()
    (d / "trace.tsv").write_text("SFB-3 export\nOperator: A. B.\n% calibrated 2007-02-02\n"
                                 + text)
    setup = (d / "my_sfb.toml").read_text() + (
        '\n[trace]\nskip_rows = 2\ncomments = ["%"]\n'
        'columns = {time = "t:ms", spring_force = "F:uN", drive_position = "x:nm"}\n')
    (d / "s.toml").write_text(setup)
    r = run_cli("analyze", d / "trace.tsv", "--setup", d / "s.toml", "--json", "--no-figure")
    assert r.code == 0, r.err
    source = r.json()["source"]
    assert source["skip_rows"] == 2 and source["comments"] == ["%"]
    assert source["samples"] == 3998


@pytest.mark.parametrize("argv, message", [
    (["--column", "spring_force=F:um"],
     "--column spring_force=F:um: unit 'um' is not a force unit (e.g. N, mN, uN"),
    (["--column", "time=t:"], "--column time=t:: give NAME=COLUMN:UNIT with both"),
    (["--column", "time=t:xyz"], "--column time=t:xyz: unit 'xyz': unknown symbol 'xyz'"),
    (["--column", "step=t:s"], "--column step=t:s: step is a count, it has no unit"),
    (["--column", "time"], "--column time: give NAME=COLUMN or NAME=COLUMN:UNIT"),
    (["--skip-rows", "-1"], "--skip-rows -1: give a whole number, 0 or more"),
    (["--skip-rows", "two"], "--skip-rows two: give a whole number, 0 or more"),
    (["--skip-rows", "99999"], "--skip-rows 99999:"),
    (["--comment", ""], "--comment '': give the text a comment line starts with"),
    (["--log-run", "0"], "--log-run 0: give a run number N, or N-M"),
    (["--log-run", "3-2"], "--log-run 3-2: the range runs backwards"),
    (["--log-run", "last"], "--log-run last: give a run number N, or N-M"),
])
def test_bad_reading_options_are_one_line_errors(example, run_cli, argv, message):
    r = run_cli("analyze", example / "trace.tsv", "--units", "si", *argv)
    assert r.code == 2 and message in r.err, r.err
    assert len(r.err.strip().splitlines()) == 1 and "Traceback" not in r.err
    assert not (example / "analysis.json").exists()


def test_units_of_both_systems_need_units_said(example, run_cli):
    argv = ["--column", "time=t:tau", "--column", "spring_force=F:uN", "--no-figure"]
    r = run_cli("analyze", example / "trace.tsv", *argv)
    assert r.code == 2 and len(r.err.strip().splitlines()) == 1
    assert "units of SI and of LJ mixed (time:tau, spring_force:uN); say which system" in r.err
    # said: the LJ column is converted with the OMCTS mapping, and the note says so
    r = run_cli("analyze", example / "trace.tsv", *argv, "--units", "si", "--json")
    assert r.code == 0, r.err
    assert any("time read in tau" in n and "OMCTS" in n for n in r.json()["source"]["notes"])


@pytest.mark.parametrize("table, message", [
    ("[trace]\nfoo = 1\n", "unknown key(s) foo in [trace]; accepted: columns, skip_rows, comments"),
    ("[trace]\nskip_rows = -2\n", "[trace] skip_rows = -2: give a whole number, 0 or more"),
    ("[trace]\ncomments = [1]\n", "[trace] comments = [1]: give a prefix or a list"),
    ("[trace.columns]\ntime = 3\n", "[trace.columns] time = 3: give \"COLUMN\" or"),
    ("[trace.columns]\nspring_force = \"F:ms\"\n", "unit 'ms' is not a force unit"),
])
def test_bad_trace_tables_are_one_line_errors(example, run_cli, table, message):
    (example / "s.toml").write_text((example / "my_sfb.toml").read_text() + "\n" + table)
    r = run_cli("analyze", example / "trace.tsv", "--setup", example / "s.toml")
    assert r.code == 2 and message in r.err, r.err
    assert len(r.err.strip().splitlines()) == 1


def test_log_options_where_they_do_not_belong(tmp_path, run_cli, synthetic_run):
    r = run_cli("analyze", LOG, "--skip-rows", "3", "--output", tmp_path / "a.json")
    assert r.code == 2 and "--skip-rows 3:" in r.err and "is a LAMMPS log" in r.err
    r = run_cli("analyze", synthetic_run, "--log-run", "2")
    assert r.code == 2 and "--log-run 2:" in r.err and "is a run directory" in r.err
    # a LAMMPS file of a run directory is analysed elsewhere than the run's analysis.json
    r = run_cli("analyze", synthetic_run / "trace.csv", "--output", tmp_path / "b.json")
    assert r.code == 0, r.err
    shutil.copy(LOG, synthetic_run / "log.lammps")
    r = run_cli("analyze", synthetic_run / "log.lammps", "--log-run", "2-3")
    assert r.code == 2 and "give --out FILE.json" in r.err


def test_nan_and_overflowing_cells_are_dropped_not_refused(tmp_path, run_cli):
    """A value beyond a double (1e400 reads as inf) and a column with gaps (every third
    wall position NaN): the rows go, the note says which, the rest is analysed."""
    t = [0.1 * i for i in range(400)]
    lines = ["time,spring_force,wall_position"]
    for i, ti in enumerate(t):
        force = "1e400" if i == 4 else f"{(ti % 5.0) * 2:.6g}"
        wall = "nan" if i % 3 == 0 else f"{ti * 0.1:.6g}"
        lines.append(f"{ti:.6g},{force},{wall}")
    path = tmp_path / "gaps.csv"
    path.write_text("\n".join(lines) + "\n")
    r = run_cli("analyze", path, "--json", "--no-figure")
    assert r.code == 0, r.err
    source = r.json()["source"]
    assert source["samples"] == 400 - 134 - 1
    assert source["dropped_rows"]["count"] == 135
    assert source["dropped_rows"]["columns"] == {"spring_force": 1, "wall_position": 134}
    assert source["dropped_rows"]["lines"][:3] == [2, 5, 6]


def test_analysing_the_directory_again_keeps_the_recorded_reading(example, run_cli):
    d = example
    (d / "trace.tsv").write_text("exported by SFB-3\n" + (d / "trace.tsv").read_text())
    first = run_cli("analyze", d / "trace.tsv", "--setup", d / "my_sfb.toml", "--skip-rows", "1",
                    *UNITS, "--json", "--no-figure")
    assert first.code == 0, first.err
    again = run_cli("analyze", d, "--json", "--no-figure")
    assert again.code == 0, again.err
    assert again.json()["slips"] == first.json()["slips"]
    for key in ("column_units", "skip_rows", "columns"):
        assert again.json()["source"][key] == first.json()["source"][key]
