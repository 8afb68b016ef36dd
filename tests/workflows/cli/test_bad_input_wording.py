"""Bad input that was refused in the wrong words, or wrongly refused (a table as in
test_bad_options.py and the other test_bad_*.py tables): each refusal is one line naming the user's input (the file and
its line, the options as given, the set-up's quantities) and its remedy, exit 2, no
traceback, nothing written; the accepted cases run.
"""
from __future__ import annotations

import errno
import json
import math
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[3] / "docs" / "examples"


def _two_columns(tmp: Path) -> Path:
    t = [i * 0.5 for i in range(400)]
    (tmp / "tf.csv").write_text("t,F\n" + "".join(f"{a!r},{10 * math.sin(a) + a % 20!r}\n"
                                                  for a in t))
    return tmp / "tf.csv"


def _wide(tmp: Path) -> Path:
    """A header of 100 kB (12000 extra columns) before the usual columns' rows."""
    t = [i * 0.5 for i in range(200)]
    extra = 12000
    header = "time,spring_force," + ",".join(f"x{i}" for i in range(extra))
    zeros = ",0" * extra
    (tmp / "wide.csv").write_text(header + "\n" + "".join(
        f"{a!r},{10 * math.sin(a) + a % 20!r}{zeros}\n" for a in t))
    assert len(header) > 65536
    return tmp / "wide.csv"


def _setup_with_big_errors(tmp: Path) -> list:
    """A measured analysis (the docs' example) and a set-up whose film thickness error
    exceeds the thickness: B - 1 sigma is negative."""
    import shutil
    from filmfriction.workflows.cli.main import main

    for name in ("sfb_trace.tsv", "my_sfb.toml"):
        shutil.copy(DOCS / name, tmp / name)
    assert main(["analyze", str(tmp / "sfb_trace.tsv"), "--setup", str(tmp / "my_sfb.toml"),
                 "--column", "time=t_s", "--column", "spring_force=shear_force_N",
                 "--column", "drive_position=drive_x_m"]) == 0
    text = (tmp / "my_sfb.toml").read_text()
    old = "film_thickness = {value = 3.5e-9, error = 0.3e-9}"
    assert old in text
    (tmp / "big.toml").write_text(text.replace(old, old.replace("0.3e-9", "5e-9")))
    return ["sfb", "--setup", tmp / "big.toml", "--measured", tmp]


def _resume_of_a_bad_trace_dat(tmp: Path, interrupted_run) -> list:
    """An interrupted run whose trace.dat has a byte that is not UTF-8 on line 6."""
    run_dir = interrupted_run(tmp / "run")
    lines = (run_dir / "trace.dat").read_bytes().split(b"\n")
    lines[5] = b"\xff" + lines[5]
    (run_dir / "trace.dat").write_bytes(b"\n".join(lines))
    return ["run", "--resume", run_dir, "--md-only"]


CASES = {
    "one column for two names": (
        lambda t, _: ["analyze", _two_columns(t), "--column", "time=t", "--column",
                      "spring_force=t"],
        "--column time=t and --column spring_force=t: one column given for two names"),
    "set-up errors of 100 % and more": (
        lambda t, _: _setup_with_big_errors(t),
        "relative error of 143% (eta_eff 27.49 +- 0.48 Pa s, contact area 4.011e-10 +- "
        "3.5e-11 m2, film thickness 3.5e-09 +- 5e-09 m)"),
    "a run's trace.dat not UTF-8": (
        _resume_of_a_bad_trace_dat, "trace.dat, line 6: not UTF-8 text (invalid start byte: "
                                    "byte b'\\xff')"),
}


def _snapshot(root: Path) -> dict:
    """Every path under root, but a run directory's lock file (a resume takes the lock
    before it reads the directory)."""
    return {str(p.relative_to(root)): (p.stat().st_size, p.stat().st_mtime_ns)
            if p.is_file() else "dir" for p in root.rglob("*") if p.name != ".lock"}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_is_worded_by_the_input(case, tmp_path, monkeypatch, run_cli,
                                          interrupted_run):
    build, fragment = CASES[case]
    monkeypatch.chdir(tmp_path)
    args = build(tmp_path, interrupted_run)
    before = _snapshot(tmp_path)
    r = run_cli(*args)
    assert r.code == 2, r.err
    lines = [ln for ln in r.err.splitlines() if ln.strip()]
    assert fragment in lines[-1] and "error" in lines[-1], r.err
    assert "Traceback" not in r.err and "internal error" not in r.err
    assert "NewtonianFilm" not in r.err
    assert _snapshot(tmp_path) == before, "something was written"


# ---------------------------------------------------------------- wrongly refused
def test_a_header_wider_than_64_kb_is_read(tmp_path, run_cli):
    r = run_cli("analyze", _wide(tmp_path), "--output", tmp_path / "a.json")
    assert r.code == 0, r.err
    assert json.loads((tmp_path / "a.json").read_text())["source"]["samples"] == 200


def test_a_scene_with_a_byte_order_mark_is_read(tmp_path):
    from filmfriction.workflows.md.scene import load

    text = 'name = "bom"\n[parameters]\nslide_steps = 400\n'
    (tmp_path / "bom.toml").write_bytes(b"\xef\xbb\xbf" + text.encode())
    assert load(str(tmp_path / "bom.toml")).parameters["slide_steps"] == 400


def test_a_setup_with_a_byte_order_mark_is_read(tmp_path):
    from filmfriction.reduced_model.sfb.user_setup import load_setup

    text = (DOCS / "my_sfb.toml").read_bytes()
    (tmp_path / "bom.toml").write_bytes(b"\xef\xbb\xbf" + text)
    assert load_setup(tmp_path / "bom.toml") == load_setup(DOCS / "my_sfb.toml")


# ---------------------------------------------------------------- the remedy of a full disk
@pytest.mark.parametrize("command, remedy", [
    ("report", "free space, then run filmfriction report again"),
    ("analyze", "free space, then run filmfriction analyze again"),
    ("run", "free space, then resume the run (--resume DIR) or run it again"),
])
def test_a_full_disk_names_the_commands_own_remedy(command, remedy):
    from filmfriction.workflows.cli.main import _one_line

    exc = OSError(errno.ENOSPC, "No space left on device", "out/report.html")
    message, code = _one_line(exc, command)
    assert code == 1 and message.startswith("out/report.html: No space left on device")
    assert message.endswith(remedy), message
    assert ("--resume" in message) == (command == "run")


def test_a_full_disk_during_report_does_not_advise_resume(synthetic_run, tmpfs, run_cli):
    """The report of a run written into a 32 kB tmpfs (root only): one line naming the
    file, exit 1, and the remedy of the report, not --resume."""
    tiny = tmpfs("tiny", "size=32k", "the full-disk test needs root")
    assert run_cli("analyze", synthetic_run).code == 0
    r = run_cli("report", synthetic_run, "--out", tiny / "report.html")
    assert r.code == 1, r.err
    lines = [ln for ln in r.err.splitlines() if ln.strip()]
    assert f"{tiny}/" in lines[-1] and "No space left on device" in lines[-1], r.err
    assert "Traceback" not in r.err
    assert "free space, then run filmfriction report again" in lines[-1], r.err
    assert "--resume" not in r.err
