"""The held gap (``hold_gap = 1``) on real LAMMPS: the top wall free along x only in the slide.

A short ``liquid-release`` run in the small test box, killed after its second restart file (4000 steps)
and resumed: through both parts the gap keeps the value it had when the wall was let go (to
round-off), the load does no work, and the wall still slides towards the spring's end.
"""
import json

import numpy as np
import pytest

from filmfriction.workflows.md import runner

pytestmark = pytest.mark.md

# the film melted and thermalised before the release (a crystal still melting takes heat
# from the thermostat, and with no work done the net heat is all the ledger has to close on)
HELD = {"hold_gap": 1, "equilibrate_steps": 8000, "slide_steps": 8000, "trace_every": 20,
        "restart_every": 2000}


def test_held_gap_stays_constant_through_a_resumed_release(tmp_path, md, filmfriction_command):
    out = tmp_path / "held"
    cmd = [filmfriction_command, "run", "liquid-release", "--md-only", "--quiet",
           "--np", "1", "--out", str(out)]
    cmd += [f"--set={k}={v}" for k, v in {**md.box, **HELD}.items()]
    md.killed_at(cmd, out)
    assert list(out.glob("restart.*")), "no restart file was written before the kill"
    runner.resume(out, progress=False)
    assert json.loads((out / "run.json").read_text())["status"] == "completed"
    d = md.trace(out)
    assert d["step"][-1] == HELD["slide_steps"]
    gap, z = d["gap"], d["wall_z"]
    # the liquid film's gap (about 5 sigma), held to round-off of the %.8g trace
    assert 4.0 < gap[0] < 7.0, gap[0]
    assert np.ptp(gap) < 1e-6 * gap[0], np.ptp(gap)
    assert np.ptp(z) < 1e-6 * abs(z[0]), np.ptp(z)
    assert np.max(np.abs(d["load_work"])) < 1e-6, np.max(np.abs(d["load_work"]))
    # the x-dynamics: let go from 20 sigma, the wall moves most of the way to the spring's end
    assert d["spring_force"][0] == pytest.approx(20.0, rel=1e-3)
    assert d["wall_position"].max() > 10.0, d["wall_position"].max()
    assert md.ledger_closure(d) < 0.02


def test_free_gap_breathes(md):
    """The negative: with hold_gap = 0 (the default) the same release's gap moves."""
    run = md.shared("liquid-release", **{**HELD, "hold_gap": 0, "restart_every": 0})
    d = md.trace(run.path)
    assert np.ptp(d["gap"]) > 1e-3, np.ptp(d["gap"])
