"""Restart files that look whole but are not: resume falls back to the previous good one.

The run directories are built without LAMMPS (``interrupted_run``): the
restart files carry LAMMPS's start and end markers around arbitrary bytes, and
the resume stops where it would start LAMMPS, so the test reads which restart
it chose and what it recorded.
"""
from __future__ import annotations

import json
import os

import pytest

from filmfriction.workflows.md import finish, restarts, runner
from filmfriction.workflows.md.scene import SceneError


def _zero_tail(path, keep: int) -> None:
    """Bytes after ``keep`` become zeros, the size unchanged: a tail that never
    reached the disk."""
    size = path.stat().st_size
    with open(path, "r+b") as fh:
        fh.seek(keep)
        fh.write(bytes(size - keep))


def _resume_choice(run_dir, monkeypatch) -> tuple[list, dict]:
    """Resume ``run_dir`` up to the engine's start: its command and run.json."""
    seen = []

    def drive(scene, run_dir, record, cmd, total, start_step, progress):
        seen.append(cmd)
        return run_dir

    monkeypatch.setattr(finish, "drive", drive)
    runner.resume(run_dir, progress=False)
    return seen[0], json.loads((run_dir / "run.json").read_text())


def _restart_file(cmd) -> str:
    return cmd[cmd.index("restart_file") + 1]


def test_intact_restarts_resume_from_the_newest(tmp_path, interrupted_run, monkeypatch):
    run_dir = interrupted_run(tmp_path / "run")
    cmd, record = _resume_choice(run_dir, monkeypatch)
    assert _restart_file(cmd) == "restart.4000" and "unusable_restarts" not in record


@pytest.mark.parametrize("damage", ["zero tail", "zero middle", "one byte"])
def test_damaged_restart_of_full_size_falls_back(tmp_path, interrupted_run, monkeypatch,
                                                 damage):
    run_dir = interrupted_run(tmp_path / "run")
    newest = run_dir / "restart.4000"
    size = newest.stat().st_size
    if damage == "zero tail":
        _zero_tail(newest, size // 2)
    elif damage == "zero middle":          # the end marker intact: only the checksum sees it
        with open(newest, "r+b") as fh:
            fh.seek(size // 3)
            fh.write(bytes(64))
    else:
        with open(newest, "r+b") as fh:
            fh.seek(size // 2)
            byte = fh.read(1)
            fh.seek(size // 2)
            fh.write(bytes([byte[0] ^ 1]))
    assert newest.stat().st_size == size
    cmd, record = _resume_choice(run_dir, monkeypatch)
    assert _restart_file(cmd) == "restart.2000"
    assert record["resumed_from"] == "restart.2000"
    assert list(record["unusable_restarts"]) == ["restart.4000"]
    # the trace is cut back to the restart it resumes from
    steps = [float(line.split()[0]) for line in
             (run_dir / "trace.dat").read_text().splitlines()[1:]]
    assert max(steps) < 2000


def test_unrecorded_restart_cut_at_full_size_is_refused(tmp_path, interrupted_run, monkeypatch):
    """LAMMPS outlived the runner (SIGKILL): restart.4000 was never recorded; its
    tail never reached the disk.  The missing end marker gives it away."""
    run_dir = interrupted_run(tmp_path / "run")
    (run_dir / restarts.LEDGER).write_text(json.dumps(
        {k: v for k, v in json.loads((run_dir / restarts.LEDGER).read_text()).items()
         if k != "restart.4000"}))
    _zero_tail(run_dir / "restart.4000", 100)
    cmd, record = _resume_choice(run_dir, monkeypatch)
    assert _restart_file(cmd) == "restart.2000"
    assert "end" in record["unusable_restarts"]["restart.4000"]


def test_unrecorded_whole_restart_is_used(tmp_path, interrupted_run, monkeypatch):
    run_dir = interrupted_run(tmp_path / "run")
    os.remove(run_dir / restarts.LEDGER)          # a run from before the ledger
    cmd, _ = _resume_choice(run_dir, monkeypatch)
    assert _restart_file(cmd) == "restart.4000"


def test_shorter_restart_is_refused(tmp_path, interrupted_run, monkeypatch):
    run_dir = interrupted_run(tmp_path / "run")
    newest = run_dir / "restart.4000"
    newest.write_bytes(newest.read_bytes()[:-300] + restarts.MAGIC)
    cmd, record = _resume_choice(run_dir, monkeypatch)
    assert _restart_file(cmd) == "restart.2000"
    assert "cut off" in record["unusable_restarts"]["restart.4000"]


def test_no_usable_restart_names_each_reason(tmp_path, interrupted_run):
    run_dir = interrupted_run(tmp_path / "run")
    for name in ("restart.2000", "restart.4000"):
        _zero_tail(run_dir / name, 0)
    with pytest.raises(SceneError, match=r"no usable restart file.*restart\.2000: .*"
                                         r"restart\.4000: "):
        runner.resume(run_dir, progress=False)


def test_ledger_records_only_restarts_behind_the_engine(tmp_path):
    for step in (2000, 4000):
        (tmp_path / f"restart.{step}").write_bytes(restarts.MAGIC * 3)
    ledger = restarts.RestartLedger(tmp_path)
    assert ledger.record_below(4000) == ["restart.2000"]     # 4000 may still be written
    assert ledger.record_below(4000) == []
    assert ledger.record_below(None) == ["restart.4000"]      # LAMMPS exited cleanly
    restarts.prune(tmp_path)
    assert [p.name for _, p in restarts.restart_files(tmp_path)] == ["restart.4000"]
    assert list(json.loads((tmp_path / restarts.LEDGER).read_text())) == ["restart.4000"]
