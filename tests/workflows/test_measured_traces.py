"""A user's own SFB trace end to end, through the command line: the documented example
(docs/examples/: tab-separated, its own column names, SI) goes through analyze →
calibrate → report → sfb with SI units in every output, and the outputs validate
against the shipped JSON Schemas."""
from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import jsonschema
import pytest

from filmfriction.analysis.files.util import json_schema
from filmfriction.workflows.cli.main import main

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"
COLUMNS = ["--column", "time=t_s", "--column", "spring_force=shear_force_N",
           "--column", "drive_position=drive_x_m"]
LJ_LABELS = ("ε", "σ", "τ")


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    """The guide's commands on a copy of the example; the printed text of each."""
    d = tmp_path_factory.mktemp("measured")
    for name in ("sfb_trace.tsv", "my_sfb.toml"):
        shutil.copy(EXAMPLES / name, d / name)
    printed = {}
    commands = {
        "analyze": ["analyze", str(d / "sfb_trace.tsv"), "--setup", str(d / "my_sfb.toml")]
                   + COLUMNS,
        "calibrate": ["calibrate", str(d)],
        "sfb": ["sfb", "--setup", str(d / "my_sfb.toml"), "--measured", str(d),
                "--calibration", str(d / "calibration.json"), "--out", str(d / "sfb.json")],
        "report": ["report", str(d)],
    }
    import contextlib
    import io

    for step, argv in commands.items():
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            assert main(argv) == 0, step
        printed[step] = buf.getvalue()
    return d, printed


def _labels(doc) -> set:
    """Every ``units`` label in a document."""
    out = set()
    if isinstance(doc, dict):
        for k, v in doc.items():
            if k == "units" and isinstance(v, str):
                out.add(v)
            else:
                out |= _labels(v)
    elif isinstance(doc, list):
        for v in doc:
            out |= _labels(v)
    return out


def test_analyze_reads_the_users_columns_and_labels_si(chain):
    d, printed = chain
    doc = json.loads((d / "analysis.json").read_text())
    jsonschema.validate(doc, json_schema("analysis"))
    assert doc["units"] == "si"
    assert doc["source"]["delimiter"] == "tab"
    assert doc["source"]["columns"] == {"time": "t_s", "spring_force": "shear_force_N",
                                        "drive_position": "drive_x_m"}
    # the set-up's values, read from my_sfb.toml (contact_radius 11.3 um -> A = pi a^2)
    assert doc["source"]["parameters"]["spring_constant"] == 97.0
    assert doc["source"]["parameters"]["area"] == pytest.approx(3.14159265 * 11.3e-6 ** 2)
    assert doc["slips"]["static_force"]["units"] == "N"
    assert doc["viscosity"]["from_slip"]["eta_eff"]["units"] == "Pa·s"
    labels = _labels(doc)
    assert labels and not any(c in "".join(labels) for c in LJ_LABELS), labels
    # the synthetic trace's slips: Klein's Fs and eta_eff come back
    assert doc["slips"]["count"] >= 4 and "stick-slip" in printed["analyze"]
    assert doc["slips"]["static_force"]["mean"] == pytest.approx(9.7e-6, rel=0.01)
    assert (d / doc["figure"]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_calibrate_works_in_si(chain):
    d, printed = chain
    cal = json.loads((d / "calibration.json").read_text())
    assert cal["units"] == "si"
    labels = _labels(cal)
    assert {"N", "Pa·s"} <= labels and not any(c in "".join(labels) for c in LJ_LABELS)
    text = printed["calibrate"]
    fs = re.search(r"static_force\s+([0-9.eE+-]+) ± [0-9.eE+-]+ N\n", text)
    assert fs and float(fs.group(1)) == pytest.approx(9.7e-6, rel=0.01), text
    assert not any(c in text for c in LJ_LABELS) and "MD" not in text, text


#: the generator of the example (docs/examples/make_measured_trace.py: synthetic.klein_trace's
#: defaults): Klein's slip, all friction viscous, the film freezing at F_b
GENERATOR = {"kinetic_force": 0.0, "film_damping": 3.09, "freeze_force": 3.0e-6}


def test_calibrate_recovers_the_generators_film(chain):
    """F_k = 0 is the bound of its range: the fit ends there and says so; B and the freeze
    force come back within their standard errors (2 of them), none printed as "± 0"."""
    d, printed = chain
    run = json.loads((d / "calibration.json").read_text())["runs"][0]
    fk, b = run["kinetic_force"], run["film_damping"]
    assert fk["at_bound"] and fk["value"] == 0.0 and fk["stderr"] is None, fk
    assert abs(b["value"] - GENERATOR["film_damping"]) < 2 * b["stderr"], b
    ff = run["slip_fit"]["freeze_force"]
    assert abs(ff["value"] - GENERATOR["freeze_force"]) < 2 * ff["stderr"], ff
    assert "kinetic_force      0 N (at bound; below 2.1e-07 N at 95 %)" in printed["calibrate"]
    assert "± 0 " not in printed["calibrate"] and "± 0\n" not in printed["calibrate"]
    # one effective viscosity: the calibration's B·D/A, Klein's per-slip fit a cross-check
    choice = run["eta_eff_choice"]
    assert choice["status"] == "resolved" and choice["estimator"] == "calibration", choice
    assert run["eta_eff"] == choice["primary"]
    assert [c["estimator"] for c in choice["cross_checks"]] == ["slips"]


def test_calibrate_gives_the_same_film_in_micronewtons_nanometres_and_milliseconds(
        tmp_path, chain):
    """The example written in µN, nm and ms (a consistent set, read as such with
    --units si and the set-up in those units): the same physical parameters."""
    import numpy as np

    d, _ = chain
    rows = np.loadtxt(EXAMPLES / "sfb_trace.tsv", skiprows=2)
    lines = ["t_ms\tF_uN\tx_nm"] + [f"{t * 1e3!r}\t{f * 1e6!r}\t{x * 1e9!r}"
                                      for t, f, x in rows.tolist()]
    (tmp_path / "trace.tsv").write_text("\n".join(lines) + "\n")
    si = json.loads((d / "analysis.json").read_text())["source"]["parameters"]
    # µN/nm = 1e3 N/m; µN ms²/nm = 1e-3 kg; µN ms/nm = 1 kg/s
    scaled = {"--spring-constant": si["spring_constant"] / 1e3, "--mass": si["mass"] / 1e-3,
              "--area": si["area"] / 1e-18, "--thickness": si["thickness"] / 1e-9,
              "--drive-velocity": si["drive_velocity"] / 1e-6}
    argv = ["analyze", str(tmp_path / "trace.tsv"), "--units", "si", "--column", "time=t_ms",
            "--column", "spring_force=F_uN", "--column", "drive_position=x_nm"]
    for flag, value in scaled.items():
        argv += [flag, repr(value)]
    assert main(argv) == 0
    assert main(["calibrate", str(tmp_path)]) == 0
    mine = json.loads((tmp_path / "calibration.json").read_text())["runs"][0]
    ref = json.loads((d / "calibration.json").read_text())["runs"][0]
    for name, scale in (("static_force", 1e-6), ("film_damping", 1.0), ("eta_eff", 1e9),
                        ("restick_force", 1e-6)):
        for key in ("value", "stderr"):
            assert mine[name][key] * scale == pytest.approx(ref[name][key], rel=1e-6), (name, key)
    assert mine["kinetic_force"]["at_bound"] and mine["kinetic_force"]["value"] == 0.0
    assert mine["slip_fit"]["freeze_force"]["value"] * 1e-6 == pytest.approx(
        ref["slip_fit"]["freeze_force"]["value"], rel=1e-6)


def test_sfb_runs_on_the_users_setup_and_slip(chain):
    d, printed = chain
    doc = json.loads((d / "sfb.json").read_text())
    jsonschema.validate(doc, json_schema("sfb"))
    analysis = json.loads((d / "analysis.json").read_text())
    assert doc["setup"]["spring_constant"] == {"value": 97.0, "error": 3.0, "units": "N/m"}
    assert doc["experiment"]["spring_constant"] == 97.0
    row = next(r for r in doc["rows"] if r["name"] == "slip_time"
               and r["source"] == "sfb-parameters")
    # the measured slip time is the trace's, not Klein's 25 ms
    assert row["measured"] == pytest.approx(analysis["slips"]["slip_duration"]["mean"])
    assert "klein" not in row and "setup" in doc["slips"] and "klein" not in doc["slips"]
    assert row["uncertainty"][0] < row["model"] < row["uncertainty"][1]
    assert doc["units"]["name"] == "SI (identity)"      # an SI calibration is not re-mapped
    assert "measured" in printed["sfb"].splitlines()[2]
    assert not any(c in "".join(r["units"] for r in doc["rows"]) for c in LJ_LABELS)
    # the calibrated rows speak SI too: no LJ mapping in their notes
    calibrated = [r["note"] for r in doc["rows"] if r["source"] == "md-calibrated"]
    assert calibrated and not any("eps/sigma" in n or "/tau" in n for n in calibrated)
    # what the set-up does not give (the ringing, Klein's heating) is said, not printed as nan
    import re
    assert not [r["note"] for r in doc["rows"] if re.search(r"\bnan\b", r["note"])]


def test_report_is_written(chain):
    d, printed = chain
    assert (d / "report.html").stat().st_size > 10_000 and "report:" in printed["report"]


def test_report_labels_a_measured_trace_in_si(chain):
    d, _ = chain
    text = (d / "report.md").read_text()
    assert "ε/σ" not in text and "LJ unit" not in text


def test_report_sets_the_model_beside_the_measured_slip_not_klein(chain):
    d, _ = chain
    text = (d / "report.md").read_text()
    sfb = text[text.index("## Comparison with the SFB experiment"):]
    sfb = sfb[:sfb.index("\n## ")]
    assert sfb.startswith("## Comparison with the SFB experiment (example SFB")
    assert "| quantity | source | measured | model |" in sfb
    assert "Klein's parameters" not in sfb and "to Klein's" not in sfb, sfb
    # the similarity numbers are an MD run's: no command that cannot apply here
    assert "filmfriction sfb --run" not in text and "Not an MD run" in text
    assert "rerun `filmfriction analyze" not in text      # it cannot make a film structure


def test_sfb_notes_speak_of_the_setup_not_of_kleins_text(chain):
    """The printed notes, sfb.json's and the report's: x0 from the trace, the set-up by its
    name; none of Klein's dE_f reading, his area or his slip rate."""
    from filmfriction.reduced_model.sfb.user_setup import load_setup

    d, printed = chain
    name = load_setup(d / "my_sfb.toml").name
    notes = json.loads((d / "sfb.json").read_text())["notes"]
    report = (d / "report.md").read_text()
    report = report[report.index("## Comparison with the SFB experiment"):]
    report = report[:report.index("\n## ")]
    for where, text in (("printed", printed["sfb"]), ("sfb.json", "\n".join(notes)),
                        ("report", report)):
        for phrase in ("dE_f", "Klein's area", "Klein's contact area", "Klein's mean slip rate",
                       "Klein:", "sensitivity to x0"):
            assert phrase not in text, (where, phrase)
        assert f"{name}: the measured slip" in text and "x0 = F_s/K" in text, where
    assert any(f"the contact area of {name}" in n for n in notes)


@pytest.mark.parametrize("argv,message", [
    (["--column", "time=t"], "no column 't' in the header (columns: t_s, shear_force_N, drive_x_m)"),
    (["--column", "tim=t_s"], "unknown name 'tim'"),
    ([], "required column 'time' missing (header: t_s, shear_force_N, drive_x_m)"),
])
def test_bad_mappings_are_one_line_errors(tmp_path, capsys, argv, message):
    shutil.copy(EXAMPLES / "sfb_trace.tsv", tmp_path / "t.tsv")
    assert main(["analyze", str(tmp_path / "t.tsv"), "--units", "si"] + argv) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "analysis.json").exists()


def test_a_mapping_without_equals_sign_is_refused(capsys):
    assert main(["analyze", str(EXAMPLES / "sfb_trace.tsv"), "--column", "time"]) == 2
    err = capsys.readouterr().err
    assert "--column time: give NAME=COLUMN" in err and len(err.strip().splitlines()) == 1


def test_bad_setups_are_one_line_errors(tmp_path, capsys, chain):
    d, _ = chain
    cases = {"spring_constant = -1\n": "spring_constant = -1.0: must be positive",
             "spring_constant = {value = 97, error = -1}\n": "spring_constant error = -1.0",
             "spring_constant = 97\nfoo = 1\n": "unknown set-up key(s) foo",
             "contact_area = 4e-10\ncontact_radius = 1e-5\n": "not both",
             "spring_constant = 97\n": "the set-up lacks mass"}
    for text, message in cases.items():
        (tmp_path / "s.toml").write_text(text)
        assert main(["sfb", "--setup", str(tmp_path / "s.toml"), "--measured", str(d)]) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1, err
    # a set-up that is not the instrument the analysis used
    (tmp_path / "s.toml").write_text((d / "my_sfb.toml").read_text().replace(
        "value = 97.0", "value = 90.0"))
    assert main(["sfb", "--setup", str(tmp_path / "s.toml"), "--measured", str(d)]) == 2
    assert "differs from the 97" in capsys.readouterr().err



def test_an_analysis_written_elsewhere_finds_its_trace_from_any_directory(tmp_path, run_cli,
                                                                         monkeypatch):
    """analyze data/trace --output results/analysis.json, then calibrate results from
    another working directory: the trace is found from the analysis' own directory."""
    (tmp_path / "data").mkdir()
    for name in ("sfb_trace.tsv", "my_sfb.toml"):
        shutil.copy(EXAMPLES / name, tmp_path / "data" / name)
    monkeypatch.chdir(tmp_path)
    r = run_cli("analyze", "data/sfb_trace.tsv", "--setup", "data/my_sfb.toml", *COLUMNS,
                "--output", "results/analysis.json")
    assert r.code == 0, r.err
    monkeypatch.chdir(tmp_path / "results")
    r = run_cli("calibrate", ".")
    assert r.code == 0, r.err
    assert (tmp_path / "results" / "calibration.json").is_file()


def test_the_suggested_sfb_command_names_the_users_setup_file(chain):
    """sfb.json records the set-up file in its provenance; the command the report suggests
    to remake it keeps that file, --measured and the calibration (never Klein's set-up)."""
    from filmfriction.workflows.rundir import SETUP_PLACEHOLDER, sfb_command

    d, _ = chain
    cmd = sfb_command(d, d / "calibration.json", d / "sfb.json")
    assert f"--setup {d / 'my_sfb.toml'} --measured {d}" in cmd, cmd
    assert SETUP_PLACEHOLDER not in cmd
