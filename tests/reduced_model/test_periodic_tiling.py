"""Periodic stick-slip is computed for one cycle and tiled: the tiled run equals the run
computed cycle by cycle (to round-off) for the closed form and the stateless ODE path."""
import numpy as np
import pytest

from filmfriction.reduced_model import SpringBlock, laws
from filmfriction.reduced_model.integrators import closed_form as coulomb, event_driven as hybrid

CASES = [
    ("closed", SpringBlock(1.0, 1.0, 0.1, damping=0.02, law=laws.Coulomb(1.0, 0.5))),
    ("closed", SpringBlock(1.0, 1.0, 0.1, law=laws.Coulomb(1.0, 0.5, viscous=0.3))),
    ("closed", SpringBlock(1.0, 1.0, 0.1, law=laws.Coulomb(1.0, 0.5, freeze_velocity=0.3))),
    ("closed", SpringBlock(1.0, 1.0, 0.1, law=laws.Coulomb(1.0, 0.5, shear_stiffness=5.0))),
    ("closed", SpringBlock(1.0, 1.0, -0.1, damping=0.1, law=laws.Coulomb(1.0, 0.5))),
    ("closed", SpringBlock(1.0, 1.0, 0.05, damping=0.05, drive="belt", law=laws.Coulomb(1.0, 0.5))),
    ("ode", SpringBlock(1.0, 1.0, 0.1, damping=0.02, law=laws.StribeckExponential(1.0, 0.5, 0.05))),
    ("ode", SpringBlock(1.0, 1.0, 0.1, law=laws.StribeckSchnelle())),
]


def _untiled(rec, cycle, sigma, t, x, xa, T):
    return t, x, xa, None


@pytest.mark.parametrize("path, block", CASES)
def test_tiled_equals_cycle_by_cycle(monkeypatch, path, block):
    method = "ode" if path == "ode" else "auto"
    tiled = block.simulate(700.0, method=method)
    monkeypatch.setattr(coulomb if path == "closed" else hybrid, "tile_cycles", _untiled)
    plain = block.simulate(700.0, method=method)
    assert [e.kind for e in tiled.events] == [e.kind for e in plain.events]
    assert len(tiled.events) > 40
    t_a = np.array([e.time for e in tiled.events])
    t_b = np.array([e.time for e in plain.events])
    np.testing.assert_allclose(t_a, t_b, rtol=0, atol=1e-10)
    # every event sits on its sample, the cycle tables agree
    assert all(tiled.t[e.index] == e.time for e in tiled.events)
    ca, cb = tiled.cycles(), plain.cycles()
    for name in ("static_force", "backward_force", "slip_distance", "period"):
        np.testing.assert_allclose(getattr(ca, name), getattr(cb, name), rtol=0, atol=1e-10)
    assert abs(tiled.x[-1] - plain.x[-1]) < 1e-10
    assert tiled.t[-1] == plain.t[-1] == 700.0
    assert abs(tiled.energy.drive_work - plain.energy.drive_work) < 1e-9
    assert tiled.energy.closure < 1e-10
    assert np.all(np.diff(tiled.t) >= 0)


def test_tiling_respects_max_events():
    from filmfriction.reduced_model._checks import SimulationLimitError
    block = SpringBlock(1.0, 1.0, 0.1, law=laws.Coulomb(1.0, 0.5))
    with pytest.raises(SimulationLimitError, match="max_events"):
        block.simulate(5000.0, max_events=50)


def test_slip_pairs_vectorised_matches_the_rule():
    from types import SimpleNamespace

    from filmfriction.reduced_model.result import Event, SimulationResult

    def rule(events):       # the first yield after the last pairing, with the next re-stick
        ys, ss, pending = [], [], None
        for e in events:
            if e.kind == "slip":
                pending = e.index if pending is None else pending
            elif e.kind == "stick" and pending is not None:
                ys.append(pending)
                ss.append(e.index)
                pending = None
        return ys, ss

    rng = np.random.default_rng(3)
    for _ in range(200):
        kinds = rng.choice(["slip", "stick", "reversal"], size=rng.integers(0, 12))
        events = [Event(time=float(i), kind=str(k), index=i, spring_force=0.0) for i, k in enumerate(kinds)]
        y, s = SimulationResult.slip_pairs(SimpleNamespace(events=events))
        assert (y.tolist(), s.tolist()) == rule(events)
