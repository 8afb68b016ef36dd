"""film_slide.lmp agrees with its contract (md_inputs/contract.py) and with the scene.

The script is parsed as text here: its ``fix print`` line, its atom types and
its ``index`` defaults.  No LAMMPS runs in this file.
"""
import re

import pytest

from filmfriction import md_inputs
from filmfriction.md_inputs import contract
from filmfriction.md_inputs.contract import AtomType
from filmfriction.workflows.md import runner
from filmfriction.workflows.md.scene import Scene
from filmfriction.workflows.md.scenes.parameters import PARAMETERS, resolve

SCRIPT = md_inputs.script("film_slide.lmp")


def commands(text: str) -> list[str]:
    """The script's commands: comments dropped (a # outside quotes), continued
    lines (ending in &) joined, blank lines skipped."""
    out, pending = [], ""
    for raw in text.splitlines():
        line, quoted = [], False
        for ch in raw:
            if ch == '"':
                quoted = not quoted
            if ch == "#" and not quoted:
                break
            line.append(ch)
        line = "".join(line).rstrip()
        if line.endswith("&"):
            pending += line[:-1] + " "
            continue
        line = (pending + line).strip()
        pending = ""
        if line:
            out.append(" ".join(line.split()) if '"' not in line else line)
    return out


def script_commands():
    return commands(SCRIPT.read_text())


def index_defaults() -> dict[str, str]:
    found = {}
    for c in script_commands():
        m = re.fullmatch(r"variable\s+(\w+)\s+index\s+(\S+)", c)
        if m:
            assert m.group(1) not in found, f"{m.group(1)} declared twice"
            found[m.group(1)] = m.group(2)
    return found


# ---------------------------------------------------------------- the trace
def test_fix_print_writes_the_contract_columns():
    prints = [c for c in script_commands() if c.startswith("fix") and " print " in c]
    assert len(prints) == 1, prints
    m = re.fullmatch(r'fix\s+trace\s+all\s+print\s+\$\{trace_every\}\s+"([^"]*)"\s+'
                     r'append\s+trace\.dat\s+screen\s+no\s+title\s+"([^"]*)"', prints[0])
    assert m, prints[0]
    text, title = (" ".join(g.split()) for g in m.groups())
    assert text == contract.fix_print_text()
    assert title == contract.fix_print_title()


def test_every_printed_variable_is_defined_in_the_script():
    defined = {m.group(1) for c in script_commands()
               for m in [re.match(r"variable\s+(\w+)\s+", c)] if m}
    printed = {c.expression[2:] for c in contract.TRACE if c.expression.startswith("v_")}
    assert printed <= defined, printed - defined


def test_the_runner_and_the_analysis_take_the_columns_from_the_contract():
    from filmfriction.analysis.energy.ledger import LEDGER_COLUMNS
    from filmfriction.analysis.files import trace

    assert runner.DAT_COLUMNS == contract.DAT_COLUMNS
    assert runner.TRACE_COLUMNS == contract.TRACE_COLUMNS
    assert runner.TRACE_UNITS == contract.TRACE_UNITS
    # trace.csv: time first, then every trace.dat column once
    assert contract.TRACE_COLUMNS[:2] == ("time", "step")
    assert sorted(contract.TRACE_COLUMNS) == sorted(contract.DAT_COLUMNS)
    assert list(contract.TRACE_UNITS) == list(contract.TRACE_COLUMNS)
    assert set(LEDGER_COLUMNS + ("mount_heat",)) <= set(contract.DAT_COLUMNS)
    # the analysis labels every column: its quantity has a label in both unit systems,
    # and the LJ label is the contract's unit
    ascii_of = {"τ": "tau", "σ": "sigma", "ε": "epsilon", "1": "-"}
    for c in contract.TRACE:
        for system in ("lj", "si"):
            assert c.quantity in trace.UNITS[system], (c.name, c.quantity)
        label = trace.UNITS["lj"][c.quantity]
        assert "".join(ascii_of.get(ch, ch) for ch in label) == c.unit, (c.name, label)


def test_contract_lookup():
    assert contract.column("gap").unit == "sigma"
    with pytest.raises(KeyError, match="no trace column 'gapp'"):
        contract.column("gapp")


# ---------------------------------------------------------------- atom types
def test_the_script_reads_the_contract_types():
    cmds = script_commands()
    assert "read_data ${data_file}" in cmds
    assert "variable data_file index " + contract.DATA_FILE in cmds
    assert len(AtomType) == 5
    groups = {m.group(1): tuple(int(t) for t in m.group(2).split()) for c in cmds
              for m in [re.fullmatch(r"group\s+(\w+)\s+type\s+([\d ]+)", c)] if m}
    assert groups == {"film": contract.FILM_TYPES, "bottom": (AtomType.BOTTOM_WALL,),
                      "top": (AtomType.TOP_WALL,), "bflex": (AtomType.BOTTOM_FLEXIBLE,),
                      "tflex": (AtomType.TOP_FLEXIBLE,),
                      "walls": (AtomType.BOTTOM_FLEXIBLE, AtomType.TOP_FLEXIBLE)}
    unions = {m.group(1): m.group(2).split() for c in cmds
              for m in [re.fullmatch(r"group\s+(\w+)\s+union\s+([\w ]+)", c)] if m}
    assert unions == {"bwall": ["bottom", "bflex"], "twall": ["top", "tflex"]}
    assert contract.BOTTOM_WALL_TYPES == (AtomType.BOTTOM_WALL, AtomType.BOTTOM_FLEXIBLE)
    assert contract.TOP_WALL_TYPES == (AtomType.TOP_WALL, AtomType.TOP_FLEXIBLE)


def test_the_data_file_has_the_contract_types():
    from filmfriction.md_inputs.geometry import TYPE_SYMBOLS

    text = Scene(name="types", description="", models="", outputs=(), expected_cost="",
                 parameters=resolve({"wall_model": "flexible"})).geometry().lammps_data()
    assert f"{len(AtomType)} atom types" in text
    atoms = text[text.index("Atoms # atomic"):].splitlines()[2:]
    assert {int(line.split()[1]) for line in atoms if line.strip()} == set(map(int, AtomType))
    assert len(TYPE_SYMBOLS) == len(AtomType)


# ---------------------------------------------------------------- defaults
# index variables the scene does not set: the runner's progress interval, the data
# file (the runner writes it under the script's default name) and the offsets of a
# resumed run (the runner reads them from the run directory)
SCRIPT_ONLY = {"thermo_every", "data_file", "resume", "restart_file", "drive_origin", "wall_z0",
               "drive_work0", "heat0", "mount_heat0"}
# the scene's default applies only when its observables ask for the output;
# otherwise the runner passes 0, which is the script's default
ASKED_FOR = {"dump_every": 0, "profile_every": 0}


def _default_variables() -> dict[str, str]:
    """What the runner passes to LAMMPS for a scene of default parameters that asks
    for no trajectory and no profiles."""
    scene = Scene(name="defaults", description="", models="", outputs=(),
                  expected_cost="", parameters=resolve({}))
    return scene.lammps_variables()


def test_the_script_defaults_are_the_scene_defaults():
    script, python = index_defaults(), _default_variables()
    assert set(script) == set(python) | SCRIPT_ONLY, (
        "index variables neither passed by the scene nor listed in SCRIPT_ONLY: "
        f"{sorted(set(script) - set(python) - SCRIPT_ONLY)}; passed but not in the script: "
        f"{sorted(set(python) - set(script))}")
    differ = {name: (script[name], value) for name, value in python.items()
              if float(script[name]) != float(value)}
    assert not differ, f"film_slide.lmp default vs workflows/md/scenes/parameters.py: {differ}"
    # each scene parameter's own default, but for the outputs a scene must ask for
    for name, spec in PARAMETERS.items():
        expected = (spec.choices.index(spec.default) if spec.choices
                    else ASKED_FOR.get(name, spec.default))
        assert float(script[name]) == float(expected), name
    assert {n for n, s in PARAMETERS.items() if float(python[n]) != float(
        s.choices.index(s.default) if s.choices else s.default)} == set(ASKED_FOR)


def test_the_defaults_check_sees_a_changed_default():
    # the check above reads the script's text: a drifted value is caught
    text = SCRIPT.read_text().replace("variable trace_every        index 50 ",
                                      "variable trace_every        index 100")
    assert text != SCRIPT.read_text()
    found = {m.group(1): m.group(2) for c in commands(text)
             for m in [re.fullmatch(r"variable\s+(\w+)\s+index\s+(\S+)", c)] if m}
    assert found["trace_every"] == "100" != _default_variables()["trace_every"]
