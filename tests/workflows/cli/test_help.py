"""Every sub-command's ``--help``: exits 0, says what the command does, in plain text.

The commands are read from the parser itself, so a new sub-command is checked
too.  ``run --help`` lists every scene parameter with its unit, default and
range, the same table ``filmfriction scenes --parameters`` prints with the
meaning of each.
"""
from __future__ import annotations

import re

import pytest

from filmfriction.workflows.cli.main import build_parser
from filmfriction.workflows.md.scenes.parameters import PARAMETERS

COMMANDS = sorted(build_parser()._subparsers._group_actions[0].choices)

# reStructuredText that a terminal shows raw: ``literal``, :role:`x`, `link`_, directives
RST = re.compile(r"``|:[a-z]+:`|`_|^\s*\.\. [a-z-]+::", re.M)


def test_every_command_is_checked():
    assert {"run", "scenes", "map", "bench", "analyze", "sweep"} <= set(COMMANDS)


@pytest.mark.parametrize("command", COMMANDS)
def test_help_has_a_plain_description(command, capsys):
    from filmfriction.workflows.cli.main import main

    with pytest.raises(SystemExit) as exc:
        main([command, "--help"])
    out = capsys.readouterr().out
    assert exc.value.code == 0
    # the description: the paragraph after the usage, before the argument lists
    body = out.split("\n\n", 1)[1]
    description = re.split(r"^(?:positional arguments|options):", body, flags=re.M)[0]
    assert len(description.split()) >= 5, f"{command} --help has no description:\n{out}"
    assert not RST.search(out), f"{command} --help shows reStructuredText:\n{out}"


def test_run_help_lists_every_parameter(capsys):
    from filmfriction.workflows.cli.main import main

    with pytest.raises(SystemExit):
        main(["run", "--help"])
    out = capsys.readouterr().out
    for spec in PARAMETERS.values():
        line = next((ln for ln in out.splitlines() if ln.split()[:1] == [spec.name]), None)
        assert line is not None, f"{spec.name} missing from run --help"
        assert spec.unit in line.split()
        if spec.choices:
            assert all(c in line for c in spec.choices)
        else:
            low = str(spec.low) if spec.kind is int else f"{spec.low:g}"
            assert f"{'(' if spec.low_open else '['}{low}, " in line, line


def test_scenes_parameters_says_what_each_one_is(run_cli):
    r = run_cli("scenes", "--parameters")
    assert r.code == 0
    lines = r.out.splitlines()
    for spec in PARAMETERS.values():
        i = next(i for i, ln in enumerate(lines) if ln.split()[:1] == [spec.name])
        assert spec.help.split()[0] in lines[i + 1], (spec.name, lines[i + 1])


@pytest.mark.parametrize("args", [["sfb"], ["scenes", "--parameters"], ["run", "--help"]],
                         ids=["sfb", "scenes", "run --help"])
def test_output_into_a_closed_pipe_stops_quietly(args, filmfriction_command):
    """`filmfriction sfb | head`: the reader is gone before the output is written; no
    'error: Broken pipe' line, no traceback."""
    import subprocess

    proc = subprocess.Popen([filmfriction_command, *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    proc.stdout.close()                 # as `head` does once it has its lines
    err = proc.stderr.read()
    code = proc.wait(timeout=60)
    assert err == "", err
    assert code in (0, 141), code
