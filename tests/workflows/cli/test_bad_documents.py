"""Hand-edited or foreign documents (run.json, analysis.json, a calibration, a set-up):
refused naming the file, the key and what is expected; an internal error is one line
(exit 1), ``--debug`` shows the traceback.
Table-driven, as every bad-input table: each case ends in one line naming the input,
exit code 2 (1 for an internal error), no traceback, and nothing written (see
conftest.py's ``refused``)."""
from __future__ import annotations

import pytest

# id: (command line from tmp and the input builders, message fragment, exit code)
CASES = {
    # -- hand-edited or foreign documents: an internal error (exit 1, no input named)
    "--resume: scene.name missing": (
        lambda t, b: ["run", "--resume", b.resumable(t, lambda d: d["scene"].pop("name"))],
        "stopped/run.json: scene.name missing: expected a string", 2),
    "--resume: np a word": (
        lambda t, b: ["run", "--resume", b.resumable(t, b.set("np", "two"))],
        'np = "two": expected a positive whole number', 2),
    "analyze: trace_parameters a string": (
        lambda t, b: ["analyze", b.edited(t, "r", "run.json", b.set("trace_parameters", "abc"))],
        'r/run.json: trace_parameters = "abc": expected a JSON object or null', 2),
    "analyze: trace_parameters a list": (
        lambda t, b: ["analyze", b.edited(t, "r", "run.json", b.set("trace_parameters", [1]))],
        "trace_parameters = [1]: expected a JSON object or null", 2),
    "analyze: K text": (
        lambda t, b: ["analyze", b.edited(t, "r", "run.json",
                                      b.set("trace_parameters.spring_constant", "abc"))],
        'trace_parameters.spring_constant = "abc": expected a positive number', 2),
    "analyze: K true": (
        lambda t, b: ["analyze", b.edited(t, "r", "run.json",
                                      b.set("trace_parameters.spring_constant", True))],
        "trace_parameters.spring_constant = true: expected a positive number", 2),
    "analyze: source a string": (
        lambda t, b: ["analyze", b.analysed_file(t, b.set("source", "abc"))],
        'measured/analysis.json: source = "abc": expected a JSON object', 2),
    "analyze: source a list": (
        lambda t, b: ["analyze", b.analysed_file(t, b.set("source", []))],
        "source = []: expected a JSON object", 2),
    "report: scene a list": (
        lambda t, b: ["report", b.edited(t, "r", "run.json", b.set("scene", [1]))],
        "r/run.json: scene = [1]: expected a JSON object", 2),
    "calibrate: slips a list": (
        lambda t, b: ["calibrate", b.edited(t, "r", "analysis.json", b.set("slips", [1]),
                                        analysed=True)],
        "r/analysis.json: slips = [1]: expected a JSON object", 2),
    "calibrate: static force true": (
        lambda t, b: ["calibrate", b.edited(t, "r", "analysis.json",
                                        b.set("slips.static_force", {"mean": True}),
                                        analysed=True)],
        "slips.static_force.mean = true: expected a number or null", 2),
    "sfb --measured: spring constant text": (
        lambda t, b: ["sfb", "--setup", b.setup_file(t), "--measured",
                   b.analysed_file(t, b.set("source.parameters.spring_constant", "97"))],
        'source.parameters.spring_constant = "97": expected a positive number', 2),
    "sfb --calibration: a stress true": (
        lambda t, b: ["sfb", "--calibration", b.toml(t, "c.json", '{"yield_stress": true, '
                                                              '"eta_zero": 2.0}')],
        "yield_stress = true: expected a number or null", 2),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_document(case, refused):
    refused(*CASES[case])


def test_debug_shows_the_traceback(tmp_path, run_cli, input_files):
    (tmp_path / "run-list").mkdir()
    input_files.trace(tmp_path / "run-list")
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

