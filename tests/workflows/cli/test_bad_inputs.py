"""Bad input, table-driven: every case ends in one line naming the input, exit
code 2, no traceback, and nothing written (the working directory, where
``runs/`` and ``sweeps/`` would go, and every input directory are unchanged).

Each case builds its inputs under ``tmp`` and returns the command line; none
reaches LAMMPS (the checks come first), so the table runs without an engine.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from filmfriction.workflows.inputs import check_writable, UserError


def _csv(path: Path, header: str, rows) -> Path:
    path.write_text(header + "\n" + "".join(",".join(repr(float(v)) for v in r) + "\n"
                                            for r in rows))
    return path


def _trace(tmp: Path, n: int = 400, wall=None, name: str = "trace.csv") -> Path:
    t = np.arange(n) * 0.5
    force = 10 * np.sin(t) + t % 20
    x = np.cumsum(np.abs(force)) * 0.01
    wall = x if wall is None else wall
    return _csv(tmp / name, "time,spring_force,drive_position,wall_position",
                zip(t, force, x, wall))


def _latin1(tmp: Path, name: str, text: str) -> Path:
    (tmp / name).write_bytes(text.encode("latin-1"))
    return tmp / name


def _link(target: Path, link: Path) -> Path:
    link.symlink_to(target)
    return link


def _afile(tmp: Path) -> Path:
    (tmp / "afile").write_text("x")
    return tmp / "afile"


def _run_with(tmp: Path, name: str, run_json: str) -> Path:
    """A directory with a trace and the given run.json text."""
    d = tmp / name
    d.mkdir()
    _trace(d)
    (d / "run.json").write_text(run_json)
    return d


def _list_run(tmp: Path) -> Path:
    return _run_with(tmp, "run-list", "[1, 2]")


def _run_dir(tmp: Path) -> Path:
    return _run_with(tmp, "run", "{}")


def _md_run(tmp: Path) -> Path:
    return _run_with(tmp, "md-run", '{"trace_parameters": {"spring_constant": 100.0, "mass": 500.0, '
                                    '"area": 58.7, "thickness": null, "drive_velocity": 0.02, '
                                    '"units": "lj"}}')


def _with_runs_file(tmp: Path, args: list) -> list:
    """``args``, with a file called runs in the working directory (the cases' cwd is
    tmp/../work), where a run's default directory would go."""
    (tmp.parent / "work" / "runs").write_text("not a directory")
    return args


def _sweep_dir(tmp: Path) -> Path:
    d = tmp / "sweep"
    (d / "points").mkdir(parents=True)
    (d / "sweep.json").write_text("{}")
    return d


def _foreign_rung(tmp: Path) -> Path:
    """A ladder root whose first rung's folder holds someone's file, no sweep.json."""
    (tmp / "ladder" / "M=240000").mkdir(parents=True)
    (tmp / "ladder" / "M=240000" / "notes.txt").write_text("mine")
    return tmp / "ladder"


def _empty_rung(tmp: Path) -> Path:
    """A ladder root with one rung's sweep planned, no point finished."""
    (tmp / "ladder" / "M=30" / "points").mkdir(parents=True)
    (tmp / "ladder" / "M=30" / "sweep.json").write_text('{"fixed": {}}')
    return tmp / "ladder"


def _analysed_file_dir(tmp: Path) -> Path:
    d = tmp / "measured"
    d.mkdir()
    (d / "analysis.json").write_text("{}")
    return d


def _huge(tmp: Path) -> Path:
    t = np.arange(400) * 0.5
    force = (10 * np.sin(t) + t % 20) * 1e306     # finite, but its square is not
    return _csv(tmp / "huge.csv", "time,spring_force", zip(t, force))


def _sparse(tmp: Path) -> Path:
    """A small trace padded to 2 GiB with NUL bytes (sparse: no disk space taken)."""
    path = _trace(tmp, name="big.csv")
    with open(path, "r+b") as fh:
        fh.truncate(2 << 30)
    return path


def _with_nul(tmp: Path) -> Path:
    path = _trace(tmp, name="nul.csv")
    with open(path, "ab") as fh:
        fh.write(b"\0" * 100)
    return path


def _toml(tmp: Path, name: str, text: str) -> Path:
    (tmp / name).write_text(text)
    return tmp / name


def _edited(tmp: Path, name: str, file: str, edit, analysed: bool = False) -> Path:
    """A synthetic run directory (analysed when ``analysed``) whose JSON ``file`` is passed
    through ``edit`` (a hand-edited or foreign document)."""
    import json

    from filmfriction.analysis.analyze import analyse_run
    from filmfriction.analysis.groundtruth.synthetic import run_directory

    d = run_directory(tmp / name, trajectory=False)
    if analysed:
        analyse_run(d)
    doc = json.loads((d / file).read_text())
    edit(doc)
    (d / file).write_text(json.dumps(doc))
    return d


def _set(path: str, value):
    """An edit setting the entry at the dotted ``path``."""
    def edit(doc):
        *head, last = path.split(".")
        for key in head:
            doc = doc[key]
        doc[last] = value
    return edit


def _analysed_file(tmp: Path, edit=None) -> Path:
    """The directory of an analysed trace file (analysis.json beside the trace), its
    analysis.json passed through ``edit``."""
    import json

    from filmfriction.analysis.analyze import analyze, write_outputs
    from filmfriction.analysis.files.trace_reader import read_trace

    d = tmp / "measured"
    d.mkdir()
    trace = _trace(d, name="scan.csv")
    doc, per_cycle = analyze(read_trace(trace, units="si", spring_constant=97.0), structure=False)
    doc["source"]["path"] = "scan.csv"
    if edit is not None:
        edit(doc)
    write_outputs(doc, per_cycle, d / "analysis.json")
    (d / "analysis.json").write_text(json.dumps(doc))
    return d


def _resumable(tmp: Path, edit) -> Path:
    """An interrupted run's record, passed through ``edit``, for --resume."""
    import json

    d = tmp / "stopped"
    d.mkdir()
    doc = {"schema": "filmfriction.run/1", "status": "interrupted", "np": 1,
           "scene": {"name": "stick-slip", "description": "x", "models": [],
                     "expected_cost": "", "parameters": {}}}
    edit(doc)
    (d / "run.json").write_text(json.dumps(doc))
    return d


def _fifo(tmp: Path) -> Path:
    os.mkfifo(tmp / "pipe")
    return tmp / "pipe"


def _user_file(tmp: Path, name: str, text: str = "the user's own notes\n") -> Path:
    (tmp / name).write_text(text)
    return tmp / name


def _setup_file(tmp: Path) -> Path:
    return _toml(tmp, "mine.toml", "name = 'mine'\nspring_constant = 97\nmass = 0.002\n"
                                   "contact_area = 1e-8\nfilm_thickness = 3.6e-9\nload = 1e-3\n"
                                   "drive_velocity = 1e-6\n")


# id: (command line from tmp, message fragment, exit code)
CASES = {
    # -- ended in a traceback
    "run --out under a file": (lambda t: ["run", "--md-only", "--out", _afile(t) / "r"],
                               "is a file, not a directory", 2),
    "run --out in /proc": (lambda t: ["run", "--md-only", "--out", "/proc/ff-run"],
                           "cannot write in /proc", 2),
    "analyze --output a directory": (lambda t: ["analyze", _trace(t), "--output", t],
                                     "is a directory", 2),
    "analyze --output under a file": (lambda t: ["analyze", _trace(t), "--output",
                                                 _afile(t) / "a.json"], "is a file", 2),
    "sweep --out in /proc": (lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run",
                                        "--out", "/proc/ff-sweep"], "cannot write in /proc", 2),
    "scene not UTF-8": (lambda t: ["run", _latin1(t, "s.toml", 'name = "caf\xe9"\n'),
                                   "--out", t / "r"], "not UTF-8", 2),
    "calibration not UTF-8": (lambda t: ["sfb", "--calibration",
                                         _latin1(t, "c.json", '{"a": "caf\xe9"}')],
                              "not UTF-8", 2),
    "trace whose arithmetic overflows": (lambda t: ["analyze", _huge(t)], "beyond ±1e+100", 2),
    "run.json not an object (analyze)": (lambda t: ["analyze", _list_run(t)],
                                         "JSON object", 2),
    "run.json not an object (calibrate)": (lambda t: ["calibrate", _list_run(t)],
                                           "JSON object", 2),
    "run.json not an object (report)": (lambda t: ["report", _list_run(t)], "JSON object", 2),
    "bench --steps 0": (lambda t: ["bench", "--steps", "0"], "--steps 0", 2),
    "bench --repeat 0": (lambda t: ["bench", "--repeat", "0"], "--repeat 0", 2),
    # -- were accepted
    "--skip negative": (lambda t: ["analyze", _trace(t), "--skip", "-1"], "--skip", 2),
    "--skip beyond the slips": (lambda t: ["analyze", _trace(t), "--skip", "100000"],
                                "--skip 100000", 2),
    "--grid int rounded": (lambda t: ["sweep", "stick-slip", "--grid", "film_layers=1.4,2.6",
                                      "--dry-run", "--out", t / "s"], "whole numbers", 2),
    "--grid too large": (lambda t: ["sweep", "stick-slip", "--grid",
                                    "drive_velocity=0.01:1:100000000000", "--dry-run",
                                    "--out", t / "s"], "above the cap", 2),
    "--grid product too large": (lambda t: ["sweep", "stick-slip", "--grid",
                                            "drive_velocity=0.01:1:200", "--grid",
                                            "spring_constant=10:100:200", "--dry-run",
                                            "--out", t / "s"], "above the cap", 2),
    "--np 1000": (lambda t: ["run", "--np", "1000", "--out", t / "r"], "--np 1000", 2),
    "--np 0": (lambda t: ["run", "--np", "0", "--out", t / "r"], "--np 0", 2),
    "bench --np 1000": (lambda t: ["bench", "--np", "1000"], "--np 1000", 2),
    "sweep --np 1000 here": (lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2", "--np",
                                        "1000", "--dry-run", "--out", t / "s"],
                             "Slurm (--profile slurm) may ask for more", 2),
    "sweep --np 0 on Slurm": (lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2", "--np",
                                         "0", "--profile", "slurm", "--dry-run",
                                         "--out", t / "s"], "--np 0", 2),
    "slide_steps beyond LAMMPS": (lambda t: ["run", "--set", "slide_steps=3000000000",
                                             "--out", t / "r"], "2147483647", 2),
    "scene name as a path": (lambda t: ["run", _toml(t, "n.toml", 'name = "../../escape"\n'),
                                        "--md-only"], "scene name", 2),
    "scene name absolute": (lambda t: ["run", _toml(t, "n.toml", 'name = "/tmp/x"\n'),
                                       "--md-only"], "scene name", 2),
    "--calibration not JSON": (lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2",
                                          "--dry-run", "--out", t / "s", "--calibration",
                                          _toml(t, "c.json", "not json")], "not valid JSON", 2),
    "--set integer as 2.5": (lambda t: ["run", "--set", "film_layers=2.5", "--out", t / "r"],
                             "whole number in [1, 8]", 2),
    "TOML integer as 2.5": (lambda t: ["run", _toml(t, "f.toml",
                                                    "[parameters]\nfilm_layers = 2.5\n"),
                                       "--out", t / "r"], "whole number in [1, 8]", 2),
    "--set key twice": (lambda t: ["run", "--set", "seed=1", "--set", "seed=2",
                                   "--out", t / "r"], "given twice", 2),
    "sweep --set key twice": (lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2",
                                         "--set", "cells_x=8", "--set", "cells_x=9",
                                         "--dry-run", "--out", t / "s"], "given twice", 2),
    "--set seed above fix langevin's limit": (lambda t: ["run", "--set", "seed=900000000",
                                                          "--out", t / "r"], "899999990", 2),
    "--resume with --set": (lambda t: ["run", "--resume", t, "--set", "seed=1"],
                            "not accepted with it", 2),
    # -- replicas and a target error (workflows/md/replica_study.py, target.py)
    "--replicas 0": (lambda t: ["run", "--replicas", "0", "--out", t / "r"],
                     "--replicas 0: give between 1 and", 2),
    "--replicas absurd": (lambda t: ["run", "--replicas", "100000", "--out", t / "r"],
                          "--replicas 100000", 2),
    "--target unknown observable": (lambda t: ["run", "--target", "friction=0.05",
                                               "--out", t / "r"], "unknown observable", 2),
    "--target REL 0": (lambda t: ["run", "--target", "static_force=0", "--out", t / "r"],
                       "between 0 and 1", 2),
    "--target REL 1": (lambda t: ["run", "--target", "static_force=1", "--out", t / "r"],
                       "between 0 and 1", 2),
    "--target REL negative": (lambda t: ["run", "--target", "static_force=-0.1",
                                         "--out", t / "r"], "between 0 and 1", 2),
    "--target REL not a number": (lambda t: ["run", "--target", "static_force=five",
                                             "--out", t / "r"], "between 0 and 1", 2),
    "--target without =": (lambda t: ["run", "--target", "static_force", "--out", t / "r"],
                           "OBSERVABLE=REL", 2),
    "--target twice": (lambda t: ["run", "--target", "static_force=0.1", "--target",
                                  "static_force=0.2", "--out", t / "r"], "given twice", 2),
    "--budget nonsense": (lambda t: ["run", "--target", "static_force=0.05", "--budget",
                                     "lots", "--out", t / "r"], "--budget 'lots'", 2),
    "--budget 0 steps": (lambda t: ["run", "--target", "static_force=0.05", "--budget", "0",
                                    "--out", t / "r"], "--budget '0'", 2),
    "--budget negative time": (lambda t: ["run", "--target", "static_force=0.05", "--budget=-5m",
                                          "--out", t / "r"], "wall time", 2),
    "--budget below a restart interval": (lambda t: ["run", "--target", "static_force=0.05",
                                                     "--budget", "100", "--out", t / "r"],
                                          "below one restart interval", 2),
    "--budget without --target": (lambda t: ["run", "--budget", "1h", "--out", t / "r"],
                                  "give --target", 2),
    "--target without restarts": (lambda t: ["run", "--target", "static_force=0.05", "--set",
                                             "restart_every=0", "--out", t / "r"],
                                  "restart_every = 0", 2),
    "--resume with --replicas": (lambda t: ["run", "--resume", t, "--replicas", "2"],
                                 "not accepted with it", 2),
    "--slide-to without --resume": (lambda t: ["run", "--slide-to", "200000", "--out",
                                               t / "r"], "give it with --resume", 2),
    "--slide-to shorter": (lambda t: ["run", "--resume", _resumable(
        t, lambda d: d["scene"]["parameters"].update(slide_steps=100000)), "--slide-to",
        "50000"], "give a longer slide", 2),
    # -- pointed the user at a command that fails in turn
    "analyze a sweep directory": (lambda t: ["analyze", _sweep_dir(t)],
                                  "a sweep directory, not a run", 2),
    "sfb --run a sweep directory": (lambda t: ["sfb", "--run", _sweep_dir(t)],
                                    "a sweep's runs are", 2),
    "sfb --run an analysed trace file's directory": (
        lambda t: ["sfb", "--run", _analysed_file_dir(t)],
        "not a run directory of 'filmfriction run' (no run.json)", 2),
    # -- named a dataclass field, not the option, or gave Python's errno text
    "sfb --sigma-nm negative": (lambda t: ["sfb", "--sigma-nm", "-1"],
                                "argument --sigma-nm: must be a positive number: '-1'", 2),
    "sfb --epsilon-K zero": (lambda t: ["sfb", "--epsilon-K", "0"],
                             "argument --epsilon-K: must be a positive number: '0'", 2),
    "sfb --calibration a directory": (lambda t: ["sfb", "--calibration", _run_dir(t)],
                                      "a directory; give its calibration.json", 2),
    # -- relabelled an MD run (its analysis.json) with another K or in SI
    "analyze a run with another K": (lambda t: ["analyze", _md_run(t), "--spring-constant", "5"],
                                     "ran with spring_constant = 100.0", 2),
    "analyze a run in SI": (lambda t: ["analyze", _md_run(t), "--units", "si"],
                            "ran with units = lj", 2),
    "analyze a run with a set-up": (lambda t: ["analyze", _md_run(t), "--setup",
                                               _toml(t, "s.toml", "name = 'x'\n")],
                                    "--setup is for a trace file", 2),
    # -- accepted, to fail (as a note) only after the whole sweep had run
    "sweep --calibration not a calibration": (
        lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", t / "s",
                   "--calibration", _toml(t, "a.json", '{"schema": "filmfriction.analysis/1"}')],
        "not a calibration.json", 2),
    "sweep --calibration in SI": (
        lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", t / "s",
                   "--calibration", _toml(t, "c.json", '{"schema": "filmfriction.calibration/1",'
                                                       ' "units": "si"}')],
        "needs an MD calibration, in LJ units", 2),
    # -- ended in "runs: File exists"
    "run with runs/ a file": (lambda t: _with_runs_file(t, ["run", "--md-only"]),
                              "the default --out, runs: is a file", 2),
    "viscosity with runs/ a file": (lambda t: _with_runs_file(
        t, ["viscosity", "--temperature", "0.722", "--density", "0.8442"]),
        "the default --out, runs: is a file", 2),
    # -- replaced the user's file
    "geometry --out another file": (lambda t: ["geometry", "--out", _afile(t)],
                                    "is not a data file of 'filmfriction geometry'", 2),
    # -- wrote the HTML under the Markdown twin's name, which then replaced it
    "report --out FILE.md": (lambda t: ["report", _run_dir(t), "--out", t / "rep.md"],
                             "give a .html file name", 2),
    # -- limits that did not hold: a cost check, physical sanity, nesting, big or binary input
    "map --resolution 1000": (lambda t: ["map", "velocity-stiffness", "--resolution", "1000",
                                         "--out", t / "m"],
                              "1,000,000 cells of up to 2 simulations each, 2,000,000 "
                              "simulations, above the limit of 40,000", 2),
    "viscosity --temperature 1e5": (lambda t: ["viscosity", "--temperature", "1e5", "--density",
                                               "0.8442", "--out", t / "v"],
                                    "--temperature 100000: at most 10 epsilon/k_B", 2),
    "viscosity hot for its time step": (lambda t: ["viscosity", "--temperature", "10",
                                                   "--density", "0.8442", "--timestep", "0.01",
                                                   "--out", t / "v"],
                                        "at most 2.5 epsilon/k_B with --timestep 0.01", 2),
    "run --out inside a run": (lambda t: ["run", "--md-only", "--out", _run_dir(t) / "nested"],
                               "is inside the run directory", 2),
    "viscosity --out inside a run": (lambda t: ["viscosity", "--temperature", "0.722",
                                                "--density", "0.8442", "--out",
                                                _run_dir(t) / "a" / "b"],
                                     "is inside the run directory", 2),
    "sweep --out inside a run": (lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2",
                                            "--dry-run", "--out", _run_dir(t) / "s"],
                                 "is inside the run directory", 2),
    "analyze a 2 GiB file": (lambda t: ["analyze", _sparse(t)],
                             "2,147,483,648 bytes, above the limit of 1,073,741,824", 2),
    "analyze a trace with NUL bytes": (lambda t: ["analyze", _with_nul(t)],
                                       "a NUL byte at byte", 2),
    "analyze a device": (lambda t: ["analyze", "/dev/zero"], "/dev/zero: a NUL byte at byte 0", 2),
    # -- wrote a sweep into it (sweep.json, inputs/, .snakemake/)
    "sweep --out a run directory": (lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2",
                                               "--dry-run", "--out", _run_dir(t)],
                                    "is a run directory", 2),
    "sweep --out another folder": (lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2",
                                              "--dry-run", "--out", _afile(t).parent],
                                   "not a sweep directory", 2),
    # -- replaced an input, another run's file, a device or a file not of the project
    "analyze --output the trace itself": (
        lambda t: ["analyze", _trace(t), "--output", t / "trace.csv"], "is the input", 2),
    "analyze --output the trace through a link": (
        lambda t: ["analyze", _trace(t), "--output", _link(t / "trace.csv", t / "alias.csv")],
        "is the input", 2),
    "analyze --output the run's run.json": (
        lambda t: ["analyze", _run_dir(t), "--output", t / "run" / "run.json"],
        "which only 'filmfriction run' writes", 2),
    "analyze --output another run's analysis.json": (
        lambda t: ["analyze", _trace(t), "--output", _run_dir(t) / "analysis.json"],
        "which is not an input of this command", 2),
    "analyze --output /dev/null": (lambda t: ["analyze", _trace(t), "--output", "/dev/null"],
                                   "is a character device, not a regular file", 2),
    "analyze --output a FIFO": (lambda t: ["analyze", _trace(t), "--output", _fifo(t)],
                                "is a FIFO (named pipe), not a regular file", 2),
    "analyze --output a file not of the project": (
        lambda t: ["analyze", _trace(t), "--output", _user_file(t, "notes.json", "{}")],
        "exists and was not written by filmfriction", 2),
    "analyze: its cycles table onto a user's file": (
        lambda t: ["analyze", _trace(t), "--output",
                   (_user_file(t, "a_cycles.csv"), t / "a.json")[1]],
        "(its cycles table): exists and was not written by filmfriction", 2),
    "sfb --out a run's run.json": (lambda t: ["sfb", "--out", _run_dir(t) / "run.json"],
                                   "which only 'filmfriction run' writes", 2),
    "sfb --out a run's trace.csv": (lambda t: ["sfb", "--out", _run_dir(t) / "trace.csv"],
                                    "which only 'filmfriction run' writes", 2),
    "sfb --out its calibration": (
        lambda t: ["sfb", "--calibration", _toml(t, "c.json", '{"yield_stress": 1.0, '
                                                              '"eta_zero": 2.0}'),
                   "--out", t / "c.json"], "is the input", 2),
    "sfb --out a file not of the project": (
        lambda t: ["sfb", "--out", _user_file(t, "sfb.json", "[]")],
        "exists and was not written by filmfriction", 2),
    "report --out beside the user's Markdown": (
        lambda t: ["report", _run_dir(t), "--out",
                   (_user_file(t, "notes.md"), t / "notes.html")[1]],
        "(its Markdown twin): exists and was not written by filmfriction", 2),
    "report --out the user's page": (
        lambda t: ["report", _run_dir(t), "--out", _user_file(t, "page.html", "<html>")],
        "exists and was not written by filmfriction", 2),
    "report --out into another run": (
        lambda t: ["report", _run_dir(t), "--out", _md_run(t) / "report.html"],
        "which is not an input of this command", 2),
    "geometry --out a run's data file": (
        lambda t: ["geometry", "--out", _run_dir(t) / "geometry.data"],
        "which only 'filmfriction run' writes", 2),
    "map --out a run directory": (lambda t: ["map", "lambda-zeta", "--resolution", "2",
                                             "--out", _run_dir(t)],
                                  "which is not an input of this command", 2),
    # -- hand-edited or foreign documents: an internal error (exit 1, no input named)
    "--resume: scene.name missing": (
        lambda t: ["run", "--resume", _resumable(t, lambda d: d["scene"].pop("name"))],
        "stopped/run.json: scene.name missing: expected a string", 2),
    "--resume: np a word": (
        lambda t: ["run", "--resume", _resumable(t, _set("np", "two"))],
        'np = "two": expected a positive whole number', 2),
    "analyze: trace_parameters a string": (
        lambda t: ["analyze", _edited(t, "r", "run.json", _set("trace_parameters", "abc"))],
        'r/run.json: trace_parameters = "abc": expected a JSON object or null', 2),
    "analyze: trace_parameters a list": (
        lambda t: ["analyze", _edited(t, "r", "run.json", _set("trace_parameters", [1]))],
        "trace_parameters = [1]: expected a JSON object or null", 2),
    "analyze: K text": (
        lambda t: ["analyze", _edited(t, "r", "run.json",
                                      _set("trace_parameters.spring_constant", "abc"))],
        'trace_parameters.spring_constant = "abc": expected a positive number', 2),
    "analyze: K true": (
        lambda t: ["analyze", _edited(t, "r", "run.json",
                                      _set("trace_parameters.spring_constant", True))],
        "trace_parameters.spring_constant = true: expected a positive number", 2),
    "analyze: source a string": (
        lambda t: ["analyze", _analysed_file(t, _set("source", "abc"))],
        'measured/analysis.json: source = "abc": expected a JSON object', 2),
    "analyze: source a list": (
        lambda t: ["analyze", _analysed_file(t, _set("source", []))],
        "source = []: expected a JSON object", 2),
    "report: scene a list": (
        lambda t: ["report", _edited(t, "r", "run.json", _set("scene", [1]))],
        "r/run.json: scene = [1]: expected a JSON object", 2),
    "calibrate: slips a list": (
        lambda t: ["calibrate", _edited(t, "r", "analysis.json", _set("slips", [1]),
                                        analysed=True)],
        "r/analysis.json: slips = [1]: expected a JSON object", 2),
    "calibrate: static force true": (
        lambda t: ["calibrate", _edited(t, "r", "analysis.json",
                                        _set("slips.static_force", {"mean": True}),
                                        analysed=True)],
        "slips.static_force.mean = true: expected a number or null", 2),
    "sfb --measured: spring constant text": (
        lambda t: ["sfb", "--setup", _setup_file(t), "--measured",
                   _analysed_file(t, _set("source.parameters.spring_constant", "97"))],
        'source.parameters.spring_constant = "97": expected a positive number', 2),
    # -- filmfriction ladder
    "ladder plan --steps-per-second 0": (lambda t: ["ladder", "plan", "--steps-per-second", "0"],
                                         "--steps-per-second 0: give a positive rate", 2),
    "ladder run --np 0": (lambda t: ["ladder", "run", "--np", "0", "--root", t / "l"],
                          "--np 0", 2),
    "ladder run --np 1000 here": (lambda t: ["ladder", "run", "--np", "1000", "--root", t / "l"],
                                  "--np 1000", 2),
    "ladder run --profile unknown": (lambda t: ["ladder", "run", "--profile", "nowhere",
                                                "--root", t / "l"], "no such profile", 2),
    "ladder run --root a file": (lambda t: ["ladder", "run", "--root", _afile(t)],
                                 "is a file", 2),
    "ladder run --root in a run": (lambda t: ["ladder", "run", "--root",
                                              _run_with(t, "r", "{}") / "ladder"],
                                   "inside the run directory", 2),
    "ladder run: a rung's folder not a sweep": (lambda t: ["ladder", "run", "--root",
                                                           _foreign_rung(t)],
                                                "not a sweep directory", 2),
    "ladder collect --root missing": (lambda t: ["ladder", "collect", "--root", t / "none"],
                                      "no such directory", 2),
    "ladder collect --root without rungs": (lambda t: ["ladder", "collect", "--root", t],
                                            "holds no rung's sweep", 2),
    "ladder collect --out a run's file": (lambda t: ["ladder", "collect", "--root",
                                                     _empty_rung(t), "--out",
                                                     _run_with(t, "r", "{}") / "run.json"],
                                          "of the run directory", 2),
    "sfb --calibration: a stress true": (
        lambda t: ["sfb", "--calibration", _toml(t, "c.json", '{"yield_stress": true, '
                                                              '"eta_zero": 2.0}')],
        "yield_stress = true: expected a number or null", 2),
}


def _snapshot(root: Path) -> dict:
    """Every path under root; files with their size and time (a directory's own
    time changes when the writability probe creates and removes its file)."""
    return {str(p.relative_to(root)): (p.stat().st_size, p.stat().st_mtime_ns)
            if p.is_file() else "dir" for p in root.rglob("*")}


# environment overrides: id -> (variable, value, command line from tmp, message fragment)
ENV_CASES = {
    "FILMFRICTION_MAX_POINTS=abc": (
        "FILMFRICTION_MAX_POINTS", "abc",
        lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", t / "s"],
        "environment variable FILMFRICTION_MAX_POINTS='abc': give a whole number >= 1"),
    "FILMFRICTION_MAX_POINTS=0": (
        "FILMFRICTION_MAX_POINTS", "0",
        lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", t / "s"],
        "FILMFRICTION_MAX_POINTS='0': give a whole number >= 1"),
    "FILMFRICTION_MAX_MAP_SIMULATIONS=1e9": (
        "FILMFRICTION_MAX_MAP_SIMULATIONS", "1e9",
        lambda t: ["map", "lambda-zeta", "--out", t / "m"],
        "FILMFRICTION_MAX_MAP_SIMULATIONS='1e9': give a whole number >= 1"),
    "FILMFRICTION_MAX_MAP_SIMULATIONS lowered": (
        "FILMFRICTION_MAX_MAP_SIMULATIONS", "100",
        lambda t: ["map", "lambda-zeta", "--out", t / "m"],
        "10,000 simulations, above the limit of 100; give a --resolution of at most 10"),
    "FILMFRICTION_MAX_INPUT_BYTES=-1": (
        "FILMFRICTION_MAX_INPUT_BYTES", "-1", lambda t: ["analyze", _trace(t)],
        "FILMFRICTION_MAX_INPUT_BYTES='-1': give a whole number >= 1"),
    "FILMFRICTION_MAX_INPUT_BYTES lowered": (
        "FILMFRICTION_MAX_INPUT_BYTES", "1000", lambda t: ["analyze", _trace(t)],
        "above the limit of 1,000 bytes for a text input"),
}


@pytest.mark.parametrize("case", list(ENV_CASES))
def test_bad_environment(case, tmp_path, monkeypatch, run_cli):
    name, value, build, fragment = ENV_CASES[case]
    monkeypatch.setenv(name, value)
    _refused(build, fragment, 2, tmp_path, monkeypatch, run_cli)


def _refused(build, fragment, code, tmp_path, monkeypatch, run_cli):
    inputs = tmp_path / "in"
    inputs.mkdir()
    work = tmp_path / "work"            # the working directory: runs/, sweeps/ go here
    work.mkdir()
    monkeypatch.chdir(work)
    args = build(inputs)
    before = _snapshot(tmp_path)
    rc, out, err = run_cli(*args)
    assert rc == code, (rc, err)
    assert fragment in err, err
    assert "Traceback" not in err + out
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert lines[-1].startswith("filmfriction ") and "error" in lines[-1], err
    assert _snapshot(tmp_path) == before, "something was written"


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input(case, tmp_path, monkeypatch, run_cli):
    _refused(*CASES[case], tmp_path, monkeypatch, run_cli)



def test_debug_shows_the_traceback(tmp_path, run_cli):
    (tmp_path / "run-list").mkdir()
    _trace(tmp_path / "run-list")
    (tmp_path / "run-list" / "run.json").write_text("[1]")
    r = run_cli("--debug", "calibrate", tmp_path / "run-list")
    assert r.code == 2 and "Traceback" in r.err and "JSON object" in r.err


def test_internal_error_is_one_line_exit_1(monkeypatch, run_cli):
    from filmfriction.workflows.cli import run_cli as run_cli_mod

    def boom(args):
        raise ZeroDivisionError("boom")

    monkeypatch.setattr(run_cli_mod, "list_scenes", boom)
    # the parser holds the function: patch it through the registered default
    from filmfriction.workflows.cli import main as cli

    parser = cli.build_parser
    monkeypatch.setattr(cli, "build_parser", lambda: _patched(parser(), boom))
    r = run_cli("scenes")
    assert r.code == 1 and "ZeroDivisionError: boom" in r.err and "--debug" in r.err
    assert "Traceback" not in r.err


def _patched(parser, func):
    for action in parser._subparsers._group_actions:
        action.choices["scenes"].set_defaults(func=func)
    return parser


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
    lambda ro, t: ["run", "--md-only", "--out", ro / "r"],
    lambda ro, t: ["analyze", _trace(t), "--out", ro / "a.json"],
    lambda ro, t: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", ro / "s"],
    lambda ro, t: ["map", "velocity-stiffness", "--out", ro / "m"],
], ids=["run", "analyze", "sweep", "map"])
def test_read_only_file_system(command, read_only_dir, tmp_path, monkeypatch, capsys, run_cli):
    inputs = tmp_path / "in"
    inputs.mkdir()
    monkeypatch.chdir(inputs)
    args = command(read_only_dir, inputs)
    before = _snapshot(tmp_path)
    rc, out, err = run_cli(*args)
    assert rc == 2 and "Read-only file system" in err and "Traceback" not in err, err
    # refused by the check before any compute, which names the option
    flag = next(a for a in args if str(a).startswith("--o"))
    assert f"error: {flag} {read_only_dir}" in err, err
    assert _snapshot(tmp_path) == before


@pytest.mark.parametrize("command", [
    lambda t: ["bench", "--np", "1", "--steps", "10", "--repeat", "1"],
    lambda t: ["sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run", "--out", t / "s"],
], ids=["bench", "sweep"])
def test_a_bad_filmfriction_lmp_is_refused_before_any_run(command, tmp_path, monkeypatch, capsys,
                                                           run_cli):
    """bench started its first run, a sweep its points, before the executable was looked at."""
    inputs = tmp_path / "in"
    inputs.mkdir()
    monkeypatch.chdir(inputs)
    monkeypatch.setenv("FILMFRICTION_LMP", str(tmp_path / "no-lmp"))
    before = _snapshot(tmp_path)
    rc, out, err = run_cli(*command(inputs))
    assert rc == 2 and f"FILMFRICTION_LMP {tmp_path / 'no-lmp'}: no such file" in err, err
    assert "[1/" not in out and "Traceback" not in err
    assert _snapshot(tmp_path) == before
