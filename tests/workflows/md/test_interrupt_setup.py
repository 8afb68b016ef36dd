"""SIGTERM / SIGHUP / Ctrl-C (SIGINT) while a run or a resume sets up, before LAMMPS starts.

Each test starts ``filmfriction run`` in a child process in which one step of
the set-up is replaced by a pause (it writes a "ready" file, then sleeps): the
runner's own preparation up to that point is real, no LAMMPS runs.  A real
signal is then sent to the child.  What is checked is what a user (or a batch
scheduler) sees: exit 130, no traceback, one line saying what to do, and a
``run.json`` that says ``interrupted`` -- never ``running`` -- with the resume
command when a usable restart exists, and "nothing to resume" otherwise.
"""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

# the child: pause at one step of the set-up, then the real command line
CHILD = """
import importlib, signal, sys, time, pathlib
signal.signal(signal.SIGINT, signal.default_int_handler)   # Ctrl-C even if the parent ignores it
from filmfriction.workflows.cli.main import main

ready, where, *argv = sys.argv[1:]

def pause(*args, **kwargs):
    pathlib.Path(ready).write_text("ready")
    time.sleep(120)
    raise SystemExit("the signal never came")

module, name = where.split(".")       # a module of workflows/md and its function
setattr(importlib.import_module(f"filmfriction.workflows.md.{module}"), name, pause)
sys.exit(main(argv))
"""


def _interrupt(tmp_path: Path, where: str, args: list[str], sig: signal.Signals):
    ready = tmp_path / "ready"
    proc = subprocess.Popen([sys.executable, "-c", CHILD, str(ready), where, *args],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        deadline = time.time() + 60
        while not ready.exists() and time.time() < deadline and proc.poll() is None:
            time.sleep(0.05)
        assert ready.exists(), proc.communicate()[1]
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    return proc.returncode, out, err


SMALL = ["--set", "slide_steps=4000", "--set", "restart_every=2000",
         "--set", "equilibrate_steps=100"]


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT],
                         ids=["SIGTERM", "SIGHUP", "SIGINT"])
@pytest.mark.parametrize("where", ["runner._record", "finish.run_engine"],
                         ids=["before run.json", "run.json written, engine not started"])
def test_signal_during_setup_of_a_run(tmp_path, where, sig, lock_held):
    out = tmp_path / "run"
    code, _, err = _interrupt(tmp_path, where, ["run", "--md-only", "--quiet", "--np", "1",
                                                "--out", str(out), *SMALL], sig)
    assert code == 130, err
    assert "Traceback" not in err
    assert "nothing to resume" in err and sig.name in err, err
    # what to do instead: run it again from its beginning (its resolved scene, once written)
    again = (f"start it again from the beginning with filmfriction run {out}/scene.toml --np 1"
             if where == "finish.run_engine" else
             "start the run again with the command that started it")
    assert again in err, err
    record = json.loads((out / "run.json").read_text())
    assert record["status"] == "interrupted", record
    assert sig.name in record["error"] and "before LAMMPS started" in record["error"]
    assert again in record["error"]
    assert "resume_command" not in record
    assert record["scene"]["name"] == "stick-slip"
    assert not (out / ".lock").exists() or not lock_held(out)



@pytest.mark.parametrize("where", ["resume.rewrite_trace_dat", "finish.run_engine"],
                         ids=["run.json set to running", "engine not started"])
def test_signal_during_setup_of_a_resume(tmp_path, where, interrupted_run):
    run_dir = interrupted_run(tmp_path / "run")
    code, _, err = _interrupt(tmp_path, where, ["run", "--resume", str(run_dir), "--md-only",
                                                "--quiet"], signal.SIGTERM)
    assert code == 130, err
    assert "Traceback" not in err
    assert f"resume with filmfriction run --resume {run_dir}" in err, err
    record = json.loads((run_dir / "run.json").read_text())
    assert record["status"] == "interrupted", record["status"]
    assert record["resume_command"] == f"filmfriction run --resume {run_dir}"
    assert record["resumed_from"] == "restart.4000"
    # the rows before the restart it would resume from are all kept
    kept = [int(float(line.split()[0])) for line in
            (run_dir / "trace.dat").read_text().splitlines()[1:]]
    assert kept[:20] == list(range(0, 4000, 200))
