"""Nothing lost, nothing stale: the binary trace copy lives under a name the project
owns and is keyed by the text's content; a copied or moved run keeps its calibration;
a calibration made from other data is said to be out of date; every JSON written
carries its provenance; a document read back that is not of the project's form is
refused naming the file and the key.  (The refusals of the command line are cases of
the bad-input table, tests/workflows/cli/test_bad_paths.py and test_bad_documents.py.)"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from filmfriction.analysis.groundtruth.synthetic import run_directory
from filmfriction.analysis.files.trace_reader import read_trace
from filmfriction.analysis.files.trace_cache import (BINARY_MIN_ROWS, CACHE_DIR, binary_copy_path,
                                                    write_binary_copy)


def _sha(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _long_trace(path: Path, n: int = BINARY_MIN_ROWS, scale: float = 1.0) -> Path:
    t = np.arange(n) * 0.01
    force = scale * (10 * np.sin(t) + t % 20)
    lines = ["time,spring_force\n"] + [f"{a:.6f},{b:.9f}\n" for a, b in zip(t, force)]
    path.write_text("".join(lines))
    return path


# ------------------------------------------------------------------ the binary copy
def test_the_binary_copy_never_takes_a_users_name(tmp_path, run_cli):
    """analyze run7.csv of 10^5 rows kept its binary copy at run7.npy, over the user's
    own file; a text trace named scan.npy was replaced by its copy."""
    trace = _long_trace(tmp_path / "run7.csv")
    (tmp_path / "run7.npy").write_bytes(b"the user's own array")
    r = run_cli("analyze", trace, "--no-structure", "--no-figure")
    assert r.code == 0, r.err
    assert (tmp_path / "run7.npy").read_bytes() == b"the user's own array"
    copies = list((tmp_path / CACHE_DIR).glob("run7.csv.*.npy"))
    assert copies == [binary_copy_path(trace)]
    assert copies[0].name == f"run7.csv.{_sha(trace)}.npy"
    # read again: from the copy, the same columns
    again = read_trace(trace)
    assert again.layout.binary
    np.testing.assert_array_equal(again.spring_force, read_trace(trace).spring_force)

    text = _long_trace(tmp_path / "scan.npy")
    before = text.read_bytes()
    r = run_cli("analyze", text, "--output", tmp_path / "scan.json", "--no-structure",
                "--no-figure")
    assert r.code == 0, r.err
    assert text.read_bytes() == before


def test_a_replaced_trace_is_read_again_whatever_its_date(tmp_path):
    """The copy was trusted while newer than the text: a text replaced by an older-dated
    file (a restore, cp -p) was read from the stale copy."""
    path = _long_trace(tmp_path / "trace.csv")
    first = read_trace(path)
    copy = write_binary_copy(first)
    assert read_trace(path).layout.binary
    _long_trace(path, scale=2.0)                       # other content ...
    os.utime(path, ns=(1, 1))                          # ... dated 1970
    again = read_trace(path)
    assert not again.layout.binary
    np.testing.assert_allclose(again.spring_force, 2.0 * first.spring_force, atol=1e-8)
    # its own copy replaces the old one
    new = write_binary_copy(again)
    assert new != copy and not copy.exists() and new.exists()


def test_no_copy_under_a_cache_name_that_is_not_a_folder(tmp_path):
    path = _long_trace(tmp_path / "trace.csv")
    (tmp_path / CACHE_DIR).write_text("a file of the user")
    with pytest.raises(ValueError, match="not the project's cache folder"):
        write_binary_copy(read_trace(path))
    assert (tmp_path / CACHE_DIR).read_text() == "a file of the user"


# ------------------------------------------------------- calibration: moved, copied, stale
@pytest.fixture
def calibrated_run(tmp_path, run_cli) -> Path:
    d = run_directory(tmp_path / "r", trajectory=False)
    assert run_cli("analyze", d, "--no-figure").code == 0
    r = run_cli("calibrate", d)
    assert r.code == 0, r.err
    return d


def test_the_calibration_records_its_runs_relative_to_itself(calibrated_run):
    doc = json.loads((calibrated_run / "calibration.json").read_text())
    assert doc["runs"][0]["run_dir"] == "."
    assert doc["run_dirs_relative_to"] == "calibration.json"
    inputs = doc["provenance"]["inputs"]
    assert inputs["runs[0] analysis.json"]["sha256"] == _sha(calibrated_run / "analysis.json")
    assert inputs["runs[0] trace"]["sha256"] == _sha(calibrated_run / "trace.csv")


@pytest.mark.parametrize("how", ["copy", "move"])
def test_a_copied_or_moved_run_keeps_its_calibration(calibrated_run, run_cli, how):
    other = calibrated_run.with_name("elsewhere")
    (shutil.copytree if how == "copy" else shutil.move)(calibrated_run, other)
    r = run_cli("report", other)
    assert r.code == 0, r.err
    assert f"out of date: {other / 'calibration.json'}" not in r.out, r.out
    md = (other / "report.md").read_text()
    assert "covers the runs" not in md and "No `calibration.json`" not in md


def test_a_calibration_of_other_data_is_out_of_date(calibrated_run, run_cli):
    assert run_cli("analyze", calibrated_run, "--skip", "0", "--no-figure").code == 0
    r = run_cli("report", calibrated_run)
    assert r.code == 0, r.err
    assert "calibration.json (out of date); make it with: filmfriction calibrate" in r.out
    assert "their SHA-256 differ" in (calibrated_run / "report.md").read_text()


def test_writing_again_over_the_projects_own_files_is_accepted(calibrated_run, run_cli):
    """The guard refuses files not of the project, not the project's own outputs."""
    for _ in range(2):
        assert run_cli("analyze", calibrated_run).code == 0
        assert run_cli("calibrate", calibrated_run).code == 0
        assert run_cli("sfb", "--calibration", calibrated_run / "calibration.json",
                       "--out", calibrated_run / "sfb.json").code == 0
        r = run_cli("report", calibrated_run)
        assert r.code == 0, r.err


# ------------------------------------------------------------------------ provenance
def test_every_document_carries_its_provenance(calibrated_run, run_cli):
    from filmfriction import __version__
    from filmfriction.analysis.files.provenance import git_state

    cal = calibrated_run / "calibration.json"
    assert run_cli("sfb", "--calibration", cal, "--out", calibrated_run / "sfb.json").code == 0
    commit, _ = git_state()
    for name in ("analysis.json", "calibration.json", "sfb.json"):
        prov = json.loads((calibrated_run / name).read_text())["provenance"]
        assert prov["package"] == "filmfriction" and prov["version"] == __version__
        assert prov["git_commit"] == commit
    analysis = json.loads((calibrated_run / "analysis.json").read_text())["provenance"]
    assert analysis["inputs"]["trace"]["sha256"] == _sha(calibrated_run / "trace.csv")
    assert analysis["inputs"]["run.json"]["sha256"] == _sha(calibrated_run / "run.json")
    sfb = json.loads((calibrated_run / "sfb.json").read_text())["provenance"]
    assert sfb["inputs"]["calibration"]["sha256"] == _sha(cal)


def test_the_documents_with_provenance_match_their_schemas(calibrated_run, run_cli):
    jsonschema = pytest.importorskip("jsonschema")
    from filmfriction.analysis.files.util import json_schema

    assert run_cli("sfb", "--calibration", calibrated_run / "calibration.json",
                   "--out", calibrated_run / "sfb.json").code == 0
    for name in ("analysis", "sfb"):
        doc = json.loads((calibrated_run / f"{name}.json").read_text())
        jsonschema.validate(doc, json_schema(name))


def test_the_git_commit_is_the_checkouts_and_none_outside_one(tmp_path):
    from filmfriction.analysis.files.provenance import checkout_state, git_state

    assert checkout_state(tmp_path) == (None, None)
    root = Path(__file__).resolve().parents[2]
    if not (root / ".git").exists() or shutil.which("git") is None:
        pytest.skip("the tests do not run from a git checkout")
    head = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True,
                          text=True).stdout.strip()
    assert checkout_state(root)[0] == head
    (tmp_path / ".git").mkdir()                       # looks like one, is not: no failure
    assert checkout_state(tmp_path) == (None, None)
    assert git_state()[0] in (head, None)


# -------------------------------------------------------------- documents read back
def test_slide_origin_not_numbers(tmp_path):
    from filmfriction.workflows.md.scene import SceneError
    from filmfriction.workflows.md.output.trace_dat import slide_origin

    (tmp_path / "slide_origin.txt").write_text("abc def\n")
    with pytest.raises(SceneError, match=r"slide_origin.txt: 'abc def': expected two finite "
                                         r"numbers"):
        slide_origin(tmp_path)
    (tmp_path / "slide_origin.txt").write_text("1.5 -2.0\n")
    assert slide_origin(tmp_path) == ("1.5", "-2.0")


def test_a_quote_in_the_launcher_is_refused(monkeypatch, tmp_path):
    from filmfriction.workflows.md import lammps_build
    from filmfriction.workflows.md.scene import SceneError

    monkeypatch.setenv(lammps_build.LAUNCHER_ENV, 'mpiexec "-n')
    with pytest.raises(SceneError, match="FILMFRICTION_MPIEXEC 'mpiexec \"-n': No closing "
                                         "quotation"):
        lammps_build.launcher()
    # a quoted program path with a space is one word (the program must exist)
    launcher = tmp_path / "my mpi" / "mpiexec"
    launcher.parent.mkdir()
    launcher.write_text("#!/bin/sh\n")
    launcher.chmod(0o755)
    monkeypatch.setenv(lammps_build.LAUNCHER_ENV, f"'{launcher}' -bind-to none")
    assert lammps_build.launcher() == [str(launcher), "-bind-to", "none"]


def test_a_path_the_terminal_cannot_show(tmp_path, filmfriction_command):
    """A non-ASCII path with an ASCII stdout ended in an internal error after the
    outputs were written."""
    d = tmp_path / "données"
    d.mkdir()
    t = np.arange(400) * 0.5
    force = 10 * np.sin(t) + t % 20
    (d / "trace.csv").write_text("time,spring_force\n" + "".join(
        f"{a:.6f},{b:.6f}\n" for a, b in zip(t, force)))
    env = dict(os.environ, PYTHONIOENCODING="ascii", LC_ALL="C", LANG="C")
    r = subprocess.run([filmfriction_command, "analyze", str(d / "trace.csv"), "--no-structure",
                        "--no-figure"], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "donn\\xe9es" in r.stdout and (d / "analysis.json").is_file()


def test_the_reports_figures_never_replace_a_users_file(calibrated_run, run_cli, tmp_path):
    """The Markdown twin's figures (<stem>-<name>.png) go beside --out: a file of that
    name the twin there does not name is the user's, and nothing is written."""
    out = tmp_path / "notes"
    out.mkdir()
    (out / "page-trace.png").write_bytes(b"the user's own picture")
    r = run_cli("report", calibrated_run, "--out", out / "page.html")
    assert r.code == 2 and "(a figure of its Markdown twin): exists and was not written" in r.err
    assert sorted(p.name for p in out.iterdir()) == ["page-trace.png"]
    assert (out / "page-trace.png").read_bytes() == b"the user's own picture"
