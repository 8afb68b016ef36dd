"""The fast path of smooth laws with a state (``reduced_model/integrators/limit_cycle.py``): it agrees
with the general LSODA path, its tiled limit cycle agrees with integrating every cycle,
and a run that turns stiff falls back to the general path."""
import warnings

import numpy as np
import pytest

from filmfriction.reduced_model import SpringBlock, laws
from filmfriction.reduced_model.integrators import limit_cycle

LAW = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1)
BLOCK = SpringBlock(mass=1.0, stiffness=10.0, drive_velocity=0.1, law=LAW)   # K < k_c: stick-slip


def _events(r):
    return (np.array([e.time for e in r.events]), np.array([e.spring_force for e in r.events]),
            [e.kind for e in r.events])


def _general_path(monkeypatch):
    monkeypatch.setattr(limit_cycle, "run_smooth", lambda *args, **kwargs: None)


def _spy(monkeypatch):
    used = []
    run = limit_cycle.run_smooth

    def spy(*args, **kwargs):
        out = run(*args, **kwargs)
        used.append(out is not None)
        return out
    monkeypatch.setattr(limit_cycle, "run_smooth", spy)
    return used


def test_tiled_limit_cycle_equals_every_cycle_integrated(monkeypatch):
    rtol, T = 1e-8, 300.0
    tiled = BLOCK.simulate(T, initial_velocity=0.05, rtol=rtol)
    monkeypatch.setattr(limit_cycle._SmoothRun, "_converged", lambda self: False)
    full = BLOCK.simulate(T, initial_velocity=0.05, rtol=rtol)
    assert tiled.nfev < 0.7 * full.nfev, "the limit cycle was not tiled"
    (ta, fa, ka), (tb, fb, kb) = _events(tiled), _events(full)
    assert ka == kb and ka.count("slip") > 140
    # a tiled cycle's period is within rtol of the limit cycle's: rtol x T at most in all
    np.testing.assert_allclose(ta, tb, rtol=0, atol=rtol * T)
    np.testing.assert_allclose(fa, fb, rtol=0, atol=10 * rtol * np.abs(fb).max())
    assert tiled.x[-1] == pytest.approx(full.x[-1], rel=10 * rtol)
    # the state where the phase is pinned (the last maximum), not at a time a phase error shifts
    last = [[e.index for e in r.events if e.kind == "slip"][-1] for r in (tiled, full)]
    assert tiled.psi[last[0]] == pytest.approx(full.psi[last[1]], abs=10 * rtol)
    assert tiled.energy.drive_work == pytest.approx(full.energy.drive_work, rel=10 * rtol)
    assert tiled.energy.closure < 1e-8
    assert tiled.t[-1] == full.t[-1] == T and np.all(np.diff(tiled.t) > 0)
    assert all(tiled.t[e.index] == e.time for e in tiled.events)
    np.testing.assert_allclose(tiled.cycles().period[-40:-1], full.cycles().period[-40:-1],
                               rtol=10 * rtol)


def _same_events_on_the_general_path(monkeypatch, block, duration, fast, more_than):
    """Run ``block`` on the general path; its events equal the fast path's (kind, time to
    1e-7, force to 1e-8), and there are more than ``more_than`` of them."""
    _general_path(monkeypatch)
    general = block.simulate(duration, initial_velocity=0.05)
    (ta, fa, ka), (tb, fb, kb) = _events(fast), _events(general)
    assert ka == kb and len(ka) > more_than
    np.testing.assert_allclose(ta, tb, rtol=0, atol=1e-7)
    np.testing.assert_allclose(fa, fb, rtol=0, atol=1e-8)
    return general


def test_fast_path_agrees_with_the_general_path(monkeypatch):
    used = _spy(monkeypatch)
    fast = BLOCK.simulate(100.0, initial_velocity=0.05)
    assert used == [True]
    general = _same_events_on_the_general_path(monkeypatch, BLOCK, 100.0, fast, more_than=90)
    for name in ("x", "v", "psi", "theta"):
        assert getattr(fast, name)[-1] == pytest.approx(getattr(general, name)[-1], rel=1e-6)
    assert fast.energy.friction_dissipation == pytest.approx(general.energy.friction_dissipation, rel=1e-8)
    assert fast.energy.closure < 1e-10
    # the extrema are samples of their own, with v at the drive speed
    assert np.max(np.abs(fast.v[[e.index for e in fast.events]] - 0.1)) < 1e-9


@pytest.mark.parametrize("evolution, regularized", [("aging", False), ("slip", True)])
def test_fast_path_for_the_other_variants(monkeypatch, evolution, regularized):
    law = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1, evolution=evolution,
                         regularized=regularized)
    block = SpringBlock(mass=1.0, stiffness=10.0, drive_velocity=0.1, law=law)
    used = _spy(monkeypatch)
    fast = block.simulate(40.0, initial_velocity=0.05)
    assert used == [True]
    _same_events_on_the_general_path(monkeypatch, block, 40.0, fast, more_than=10)


def test_steady_sliding_has_no_events(monkeypatch):
    law = laws.RateState(mu0=0.6, a=0.015, b=0.01, dc=1e-2, v0=0.1)     # velocity strengthening
    used = _spy(monkeypatch)
    r = SpringBlock(mass=1.0, stiffness=10.0, drive_velocity=0.1, law=law).simulate(50.0)
    assert used == [True] and r.events == ()
    assert r.v[-1] == pytest.approx(0.1, rel=1e-9)


def test_a_run_that_turns_stiff_falls_back(monkeypatch):
    # K far below k_c: the block nearly stops between slips and DOP853 gives up
    block = SpringBlock(mass=1.0, stiffness=0.05, drive_velocity=0.1, law=LAW)
    used = _spy(monkeypatch)
    r = block.simulate(300.0, initial_velocity=0.05)
    assert used == [False]
    _general_path(monkeypatch)
    general = block.simulate(300.0, initial_velocity=0.05)
    assert r.nfev == general.nfev and [e.time for e in r.events] == [e.time for e in general.events]
    np.testing.assert_array_equal(r.x, general.x)


@pytest.mark.parametrize("options", [{"damping": 0.05}, {"drive": "belt"}], ids=["damper", "belt"])
def test_fast_path_with_a_damper_or_a_belt(monkeypatch, options):
    block = SpringBlock(mass=1.0, stiffness=10.0, drive_velocity=0.1, law=LAW, **options)
    used = _spy(monkeypatch)
    fast = block.simulate(40.0, initial_velocity=0.05)
    assert used == [True]
    _general_path(monkeypatch)
    general = block.simulate(40.0, initial_velocity=0.05)
    (ta, _, ka), (tb, _, kb) = _events(fast), _events(general)
    assert ka == kb and len(ka) > 30
    np.testing.assert_allclose(ta, tb, rtol=0, atol=1e-7)
    assert fast.x[-1] == pytest.approx(general.x[-1], abs=1e-8)
    assert fast.energy.damper_dissipation == pytest.approx(general.energy.damper_dissipation, rel=1e-8)
    assert fast.energy.closure < 1e-10


def test_without_numba_the_general_path_runs(monkeypatch):
    import sys

    from filmfriction.reduced_model import integrators
    monkeypatch.setitem(sys.modules, "filmfriction.reduced_model.integrators.smooth_steps", None)   # import fails
    monkeypatch.delattr(integrators, "smooth_steps", raising=False)
    used = _spy(monkeypatch)
    with pytest.warns(RuntimeWarning, match="compiled rate-and-state path is unavailable"):
        r = BLOCK.simulate(20.0, initial_velocity=0.05)
    assert used == [False] and len(r.events) > 10


def test_the_log_form_never_slips_backwards(monkeypatch):
    # the unregularized law holds for forward slip only; this block creeps towards rest
    # between slips (v ~ 1e-11), stiff: explicit steps once carried it into backward slip
    # (v down to -0.06), where the log form is no law.  The fast path hands it over instead.
    law = laws.RateState(mu0=0.6, a=0.005858, b=0.014064, dc=0.0019423, v0=0.7894, regularized=False)
    block = SpringBlock(mass=3.0416, stiffness=3.6167, drive_velocity=0.065826, damping=0.05, law=law)
    used = _spy(monkeypatch)
    r = block.simulate(117.0, initial_velocity=0.015524)
    assert used == [False]
    assert r.v.min() > 0.0 and len(r.events) >= 30


def test_a_log_form_run_that_steps_into_backward_slip_is_flagged():
    # the same law creeping below what the steps resolve: v crosses 0 (the general path's
    # LSODA steps over the singular creep); the result says so rather than passing quietly
    law = laws.RateState(mu0=0.6, a=0.0078217, b=0.0194656, dc=0.019228, v0=0.0601096,
                         evolution="slip", regularized=False)
    block = SpringBlock(mass=6.7985, stiffness=0.38849, drive_velocity=0.320095, law=law)
    with pytest.warns(RuntimeWarning, match=r"regularized=False.*fell to 0 at t = "):
        r = block.simulate(529.3, initial_velocity=0.428138)
    assert r.v.min() <= 0.0
    forward = SpringBlock(mass=1.0, stiffness=10.0, drive_velocity=0.1,
                          law=laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1,
                                             regularized=False))
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # a run that stays forward is not flagged
        r = forward.simulate(40.0, initial_velocity=0.05)
    assert r.v.min() > 0.0
