"""The preload ramp (``preload_force``, ``preload_steps``) on real LAMMPS.

A short ``stick-slip`` run in the small test box with the spring loaded by 8 epsilon/sigma over
its first 3000 steps, killed after the restart file inside the ramp (2000 steps) and resumed:
the spring's end follows the ramp and then the drive exactly (also across the resume), and the
energy ledger closes, so the drive's work counts the ramp's extra motion of the spring's end.
"""
import json

import numpy as np
import pytest

from filmfriction.workflows.md import runner

pytestmark = pytest.mark.md

V, K, F, N, DT = 0.02, 2.0, 8.0, 3000, 0.005
RAMP = {"drive_velocity": V, "spring_constant": K, "wall_mass": 30.0, "mount_damping": 0.05,
        "preload_force": F, "preload_steps": N, "equilibrate_steps": 2000, "slide_steps": 5000,
        "trace_every": 20, "restart_every": 2000}


def test_preload_ramp_loads_the_spring_and_the_ledger_closes(tmp_path, md, filmfriction_command):
    out = tmp_path / "ramp"
    cmd = [filmfriction_command, "run", "stick-slip", "--md-only", "--quiet",
           "--np", "1", "--out", str(out)]
    cmd += [f"--set={k}={v}" for k, v in {**md.box, **RAMP}.items()]
    md.killed_at(cmd, out, marker="restart.2000")
    assert list(out.glob("restart.*")), "no restart file was written before the kill"
    runner.resume(out, progress=False)
    assert json.loads((out / "run.json").read_text())["status"] in ("completed",
                                                                    "completed_with_warnings")
    d = md.trace(out)
    assert d["step"][-1] == RAMP["slide_steps"]
    step, xd = d["step"], d["drive_position"]
    # the spring's end: V t plus the ramp's F/K, reached at step N and then held
    expected = V * DT * step + F / K * np.minimum(step, N) / N
    assert np.max(np.abs(xd - expected)) < 1e-5, np.max(np.abs(xd - expected))
    # work went in through the ramp: the ledger would miss about F^2/2K without it
    assert md.ledger_closure(d) < 0.02


def test_a_preload_needs_its_steps():
    from filmfriction.workflows.md.scenes.parameters import SceneError, resolve

    with pytest.raises(SceneError, match=r"preload_force = 8 .* preload_steps = 0"):
        resolve({"preload_force": 8.0})
    with pytest.raises(SceneError, match=r"preload_steps = 200 is longer than slide_steps = 100"):
        resolve({"preload_force": 8.0, "preload_steps": 200, "slide_steps": 100})
    p = resolve({"preload_force": 8.0, "preload_steps": 50, "slide_steps": 100})
    assert (p["preload_force"], p["preload_steps"]) == (8.0, 50)
