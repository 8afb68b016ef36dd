"""The command line's habits, walked over every sub-command read from the parser:
``filmfriction`` alone prints a short help naming ``run`` (and runs nothing);
every command takes ``--quiet``/``--verbose`` and says so in its ``--help``;
every command that writes takes ``--out``; a command with required arguments
given none prints its usage, exit 2; progress is one line per stage when
stderr is not a terminal, nothing with ``--quiet``.
"""
from __future__ import annotations

import argparse
import os
import sys
import threading
from pathlib import Path

import pytest

from filmfriction.workflows.cli.main import build_parser

PARSERS = build_parser()._subparsers._group_actions[0].choices
COMMANDS = sorted(PARSERS)


def _options(parser: argparse.ArgumentParser) -> set:
    return set(parser._option_string_actions)


def _needs_arguments(parser: argparse.ArgumentParser) -> bool:
    return any(a.required or (not a.option_strings and a.nargs not in ("?", "*"))
               for a in parser._actions)


def test_the_walk_sees_every_command():
    assert {"run", "scenes", "geometry", "bench", "analyze", "map", "calibrate", "sfb",
            "report", "tradeoff", "sweep", "viscosity"} <= set(COMMANDS)


def test_filmfriction_alone_prints_a_short_help(tmp_path, monkeypatch, capsys, run_cli):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli()
    assert code == 2
    assert "filmfriction run" in out and "usage:" in out and "--help" in out
    assert len(out.splitlines()) <= 15, out
    assert os.listdir(tmp_path) == [], "filmfriction alone started something"


@pytest.mark.parametrize("command", COMMANDS)
def test_quiet_and_verbose_everywhere(command, capsys, run_cli):
    parser = PARSERS[command]
    assert {"-q", "--quiet", "-v", "--verbose"} <= _options(parser)
    # both accepted, and not together (argparse refuses the pair as it reads it)
    code, out, err = run_cli(command, "--quiet", "--verbose")
    assert code == 2 and "not allowed with argument -q/--quiet" in err, err
    code, out, err = run_cli(command, "--help")
    assert code == 0 and "--quiet" in out and "--verbose" in out


@pytest.mark.parametrize("command", COMMANDS)
def test_out_where_the_command_writes(command, capsys, run_cli):
    parser = PARSERS[command]
    writes = parser.get_default("writes") is not False
    assert ("--out" in _options(parser)) == writes, command
    if writes:
        code, out, err = run_cli(command, "--help")
        assert "--out" in out


@pytest.mark.parametrize("command", [c for c in COMMANDS if _needs_arguments(PARSERS[c])])
def test_bare_command_prints_its_usage(command, tmp_path, monkeypatch, capsys, run_cli):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(command)
    assert code == 2 and f"usage: filmfriction {command}" in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []


def test_commands_without_arguments_are_few():
    """The commands that do something when given nothing: run (the default study, as
    `make run`) and the ones that print or draw a default; the walk above covers the rest."""
    assert {c for c in COMMANDS if not _needs_arguments(PARSERS[c])} <= {
        "run", "scenes", "geometry", "bench", "sfb", "tradeoff"}


# ------------------------------------------------------------------- quiet, verbose, progress
def _fake_engine(tmp_path: Path) -> list:
    """A command that prints what LAMMPS prints for the runner: two stages, thermo lines."""
    lines = ["FILMFRICTION stage equilibrate 0"] + [f"{s} 1.0 2.0" for s in range(0, 101, 10)]
    lines += ["FILMFRICTION stage slide 0"] + [f"{s} 1.0 2.0" for s in range(0, 401, 10)]
    script = tmp_path / "engine.py"
    script.write_text("print(" + repr("\n".join(lines)) + ")\n")
    return [sys.executable, str(script)]


@pytest.mark.parametrize("level, shown", [("NORMAL", "stages"), ("VERBOSE", "tenths"),
                                          ("QUIET", "nothing")])
def test_progress_without_a_terminal_is_lines(level, shown, tmp_path, capsys):
    from filmfriction.workflows import progress
    from filmfriction.workflows.md.output.lammps_output import run_engine

    progress.set_level(getattr(progress, level))
    try:
        outcome = run_engine(_fake_engine(tmp_path), tmp_path, total_steps=500,
                             progress=True, label="test")
    finally:
        progress.set_level(progress.NORMAL)
    assert outcome.returncode == 0
    err = capsys.readouterr().err
    assert "\r" not in err
    lines = err.splitlines()
    if shown == "nothing":
        assert lines == []
        return
    stage_lines = [ln for ln in lines if "started" in ln or "steps in" in ln]
    # setup, equilibrate, slide: each starts and ends once
    assert [ln.split(":")[0] for ln in stage_lines if "started" in ln] == [
        "test setup", "test equilibrate", "test slide"]
    assert stage_lines[-1].startswith("test slide: at step 500 of 500")
    tenths = [ln for ln in lines if ln.endswith("%)")]
    if shown == "tenths":
        assert [ln.rsplit("(", 1)[1] for ln in tenths] == [f"{10 * k} %)" for k in range(1, 11)]
        assert any("engine.py" in ln for ln in lines)      # the command, with --verbose
    else:
        assert tenths == [] and len(lines) == 6


def test_quiet_drops_notes_not_results(tmp_path, capsys, run_cli):
    code, out, err = run_cli("map", "lambda-zeta", "--resolution", "4", "--processes",
                          "100000", "--quiet", "--out", tmp_path)
    assert code == 0 and err == "" and "lambda_zeta.csv" in out


# ------------------------------------------------------------------------------------ --out
def _trace(folder: Path) -> Path:
    """A 400-row trace with slips (time, spring_force)."""
    import numpy as np

    t = np.arange(400) * 0.5
    force = 10 * np.sin(t) + t % 20
    path = folder / "t.csv"
    path.write_text("time,spring_force\n" + "".join(f"{a!r},{b!r}\n" for a, b in
                                                   zip(t.tolist(), force.tolist())))
    return path


def test_report_out_creates_its_folder(synthetic_run, tmp_path, capsys, run_cli):
    assert run_cli("analyze", synthetic_run, "--no-structure", "--no-figure")[0] == 0
    out = tmp_path / "new" / "deeper" / "x.html"
    code, stdout, err = run_cli("report", synthetic_run, "--out", out)
    assert code == 0, err
    assert out.is_file() and out.with_suffix(".md").is_file()


def test_analyze_output_is_an_alias_of_out(tmp_path, capsys, run_cli):
    trace = _trace(tmp_path)
    for flag in ("--out", "--output"):
        target = tmp_path / flag.strip("-") / "a.json"
        code, out, err = run_cli("analyze", trace, flag, target, "--no-figure")
        assert code == 0 and target.is_file(), err


def test_calibrate_out(synthetic_run, tmp_path, capsys, run_cli):
    assert run_cli("analyze", synthetic_run, "--no-structure", "--no-figure")[0] == 0
    target = tmp_path / "cal" / "c.json"
    code, out, err = run_cli("calibrate", synthetic_run, "--out", target)
    assert code == 0, err
    assert target.is_file() and not (synthetic_run / "calibration.json").exists()


# ------------------------------------------------------------------- worker counts, streams
def test_map_processes_capped_to_the_cpus(tmp_path, capsys, run_cli):
    from filmfriction.workflows.inputs import usable_cpus

    cpus = usable_cpus()
    code, out, err = run_cli("map", "lambda-zeta", "--resolution", "4", "--processes",
                          "100000", "--out", tmp_path)
    assert code == 0, err
    assert f"--processes 100000: capped to {cpus}" in err
    assert f"on {cpus} process(es)" in out and "100000" not in out


def test_sweep_cores_capped_to_the_cpus(tmp_path, monkeypatch, capsys, run_cli):
    from filmfriction.workflows.cli import sweep_cli
    from filmfriction.workflows.inputs import usable_cpus

    given = {}
    monkeypatch.setattr(sweep_cli, "run_sweep",
                        lambda plan, out, cores, **kw: given.setdefault("cores", cores) and 0)
    code, out, err = run_cli("sweep", "stick-slip", "--grid", "seed=1,2", "--dry-run",
                          "--cores", "100000", "--out", tmp_path / "s")
    assert code == 0, err
    assert f"--cores 100000: capped to {usable_cpus()}" in err
    assert given["cores"] == usable_cpus()


def test_a_stream_is_read_once(tmp_path, capsys, run_cli):
    """`analyze <(cat t.csv)`: a pipe, read once; the same analysis as of the file."""
    import json

    trace = _trace(tmp_path)
    assert run_cli("analyze", trace, "--out", tmp_path / "file.json",
                "--no-figure")[0] == 0
    read, write = os.pipe()

    def feed():
        with os.fdopen(write, "wb") as fh:
            fh.write(trace.read_bytes())

    feeder = threading.Thread(target=feed)
    feeder.start()
    try:
        code, out, err = run_cli("analyze", f"/dev/fd/{read}", "--out",
                              tmp_path / "stream.json", "--no-figure")
    finally:
        feeder.join()
        os.close(read)
    assert code == 0, err
    a = json.loads((tmp_path / "file.json").read_text())
    b = json.loads((tmp_path / "stream.json").read_text())
    assert b["source"]["path"] == f"/dev/fd/{read}"
    assert a["slips"] == b["slips"] and a["source"]["samples"] == b["source"]["samples"] == 400
