"""Bad places to read from or write to: an output under a file or in /proc, a run
directory or a user's file that would be replaced, a sweep or an input written into,
a read-only file system, an input not UTF-8, too big or not a trace.
Table-driven, as every bad-input table: each case ends in one line naming the input,
exit code 2 (1 for an internal error), no traceback, and nothing written (see
conftest.py's ``refused``)."""
from __future__ import annotations

import os

import pytest

from filmfriction.workflows.inputs import check_writable, UserError

# id: (command line from tmp and the input builders, message fragment, exit code)
CASES = {
    # -- ended in a traceback
    "run --out under a file": (lambda t, b: ["run", "--md-only", "--out", b.afile(t) / "r"],
                               "is a file, not a directory", 2),
    "run --out in /proc": (lambda t, b: ["run", "--md-only", "--out", "/proc/ff-run"],
                           "cannot write in /proc", 2),
    "analyze --output a directory": (lambda t, b: ["analyze", b.trace(t), "--output", t],
                                     "is a directory", 2),
    "analyze --output under a file": (lambda t, b: ["analyze", b.trace(t), "--output",
                                                 b.afile(t) / "a.json"], "is a file", 2),
    "sweep --out in /proc": (lambda t, b: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run",
                                        "--out", "/proc/ff-sweep"], "cannot write in /proc", 2),
    "scene not UTF-8": (lambda t, b: ["run", b.latin1(t, "s.toml", 'name = "caf\xe9"\n'),
                                   "--out", t / "r"], "not UTF-8", 2),
    "calibration not UTF-8": (lambda t, b: ["sfb", "--calibration",
                                         b.latin1(t, "c.json", '{"a": "caf\xe9"}')],
                              "not UTF-8", 2),
    "trace whose arithmetic overflows": (lambda t, b: ["analyze", b.huge(t)], "beyond ±1e+100", 2),
    "run.json not an object (analyze)": (lambda t, b: ["analyze", b.list_run(t)],
                                         "JSON object", 2),
    "run.json not an object (calibrate)": (lambda t, b: ["calibrate", b.list_run(t)],
                                           "JSON object", 2),
    "run.json not an object (report)": (lambda t, b: ["report", b.list_run(t)], "JSON object", 2),
    "bench --steps 0": (lambda t, b: ["bench", "--steps", "0"], "--steps 0", 2),
    "bench --repeat 0": (lambda t, b: ["bench", "--repeat", "0"], "--repeat 0", 2),
    # -- ended in "runs: File exists"
    "run with runs/ a file": (lambda t, b: b.with_runs_file(t, ["run", "--md-only"]),
                              "the default --out, runs: is a file", 2),
    "viscosity with runs/ a file": (lambda t, b: b.with_runs_file(
        t, ["viscosity", "--temperature", "0.722", "--density", "0.8442"]),
        "the default --out, runs: is a file", 2),
    # -- replaced the user's file
    "geometry --out another file": (lambda t, b: ["geometry", "--out", b.afile(t)],
                                    "is not a data file of 'filmfriction geometry'", 2),
    # -- wrote the HTML under the Markdown twin's name, which then replaced it
    "report --out FILE.md": (lambda t, b: ["report", b.run_dir(t), "--out", t / "rep.md"],
                             "give a .html file name", 2),
    # -- wrote a sweep into it (sweep.json, inputs/, .snakemake/)
    "sweep --out a run directory": (lambda t, b: ["sweep", "stick-slip", "--grid", "seed=1,2",
                                               "--dry-run", "--out", b.run_dir(t)],
                                    "is a run directory", 2),
    "sweep --out another folder": (lambda t, b: ["sweep", "stick-slip", "--grid", "seed=1,2",
                                              "--dry-run", "--out", b.afile(t).parent],
                                   "not a sweep directory", 2),
    # -- replaced an input, another run's file, a device or a file not of the project
    "analyze --output the trace itself": (
        lambda t, b: ["analyze", b.trace(t), "--output", t / "trace.csv"], "is the input", 2),
    "analyze --output the trace through a link": (
        lambda t, b: ["analyze", b.trace(t), "--output", b.link(t / "trace.csv", t / "alias.csv")],
        "is the input", 2),
    "analyze --output the run's run.json": (
        lambda t, b: ["analyze", b.run_dir(t), "--output", t / "run" / "run.json"],
        "which only 'filmfriction run' writes", 2),
    "analyze --output another run's analysis.json": (
        lambda t, b: ["analyze", b.trace(t), "--output", b.run_dir(t) / "analysis.json"],
        "which is not an input of this command", 2),
    "analyze --output /dev/null": (lambda t, b: ["analyze", b.trace(t), "--output", "/dev/null"],
                                   "is a character device, not a regular file", 2),
    "analyze --output a FIFO": (lambda t, b: ["analyze", b.trace(t), "--output", b.fifo(t)],
                                "is a FIFO (named pipe), not a regular file", 2),
    "analyze --output a file not of the project": (
        lambda t, b: ["analyze", b.trace(t), "--output", b.user_file(t, "notes.json", "{}")],
        "exists and was not written by filmfriction", 2),
    "analyze: its cycles table onto a user's file": (
        lambda t, b: ["analyze", b.trace(t), "--output",
                   (b.user_file(t, "a_cycles.csv"), t / "a.json")[1]],
        "(its cycles table): exists and was not written by filmfriction", 2),
    "sfb --out a run's run.json": (lambda t, b: ["sfb", "--out", b.run_dir(t) / "run.json"],
                                   "which only 'filmfriction run' writes", 2),
    "sfb --out a run's trace.csv": (lambda t, b: ["sfb", "--out", b.run_dir(t) / "trace.csv"],
                                    "which only 'filmfriction run' writes", 2),
    "sfb --out its calibration": (
        lambda t, b: ["sfb", "--calibration", b.toml(t, "c.json", '{"yield_stress": 1.0, '
                                                              '"eta_zero": 2.0}'),
                   "--out", t / "c.json"], "is the input", 2),
    "sfb --out a file not of the project": (
        lambda t, b: ["sfb", "--out", b.user_file(t, "sfb.json", "[]")],
        "exists and was not written by filmfriction", 2),
    "report --out beside the user's Markdown": (
        lambda t, b: ["report", b.run_dir(t), "--out",
                   (b.user_file(t, "notes.md"), t / "notes.html")[1]],
        "(its Markdown twin): exists and was not written by filmfriction", 2),
    "report --out the user's page": (
        lambda t, b: ["report", b.run_dir(t), "--out", b.user_file(t, "page.html", "<html>")],
        "exists and was not written by filmfriction", 2),
    "report --out into another run": (
        lambda t, b: ["report", b.run_dir(t), "--out", b.md_run(t) / "report.html"],
        "which is not an input of this command", 2),
    "geometry --out a run's data file": (
        lambda t, b: ["geometry", "--out", b.run_dir(t) / "geometry.data"],
        "which only 'filmfriction run' writes", 2),
    "map --out a run directory": (lambda t, b: ["map", "lambda-zeta", "--resolution", "2",
                                             "--out", b.run_dir(t)],
                                  "which is not an input of this command", 2),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_path(case, refused):
    refused(*CASES[case])


def test_umask_is_not_the_check(tmp_path):
    """check_writable probes with a real file (root passes os.access everywhere)."""
    check_writable(tmp_path / "new" / "x.json", "--out")
    assert not (tmp_path / "new").exists() and os.listdir(tmp_path) == []
    with pytest.raises(UserError, match="cannot write in /proc"):
        check_writable("/proc/x", "--out")


@pytest.fixture
def read_only_dir(tmpfs):
    """A read-only tmpfs (root only); skipped with the reason where it cannot be made."""
    return tmpfs("ro", "ro,size=64k", "the read-only file-system test needs root")


@pytest.mark.parametrize("command", [
    lambda ro, t, b: ["run", "--md-only", "--out", ro / "r"],
    lambda ro, t, b: ["analyze", b.trace(t), "--out", ro / "a.json"],
    lambda ro, t, b: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", ro / "s"],
    lambda ro, t, b: ["map", "velocity-stiffness", "--out", ro / "m"],
], ids=["run", "analyze", "sweep", "map"])
def test_read_only_file_system(command, read_only_dir, tmp_path, monkeypatch, capsys, run_cli,
                               input_files):
    inputs = tmp_path / "in"
    inputs.mkdir()
    monkeypatch.chdir(inputs)
    args = command(read_only_dir, inputs, input_files)
    before = input_files.snapshot(tmp_path)
    rc, out, err = run_cli(*args)
    assert rc == 2 and "Read-only file system" in err and "Traceback" not in err, err
    # refused by the check before any compute, which names the option
    flag = next(a for a in args if str(a).startswith("--o"))
    assert f"error: {flag} {read_only_dir}" in err, err
    assert input_files.snapshot(tmp_path) == before

