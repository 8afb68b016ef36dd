"""A creeping hold of a light, stiff block with rate-and-state: no stall, same end state."""
import numpy as np
from scipy.integrate import solve_ivp

from filmfriction.reduced_model import SpringBlock, laws


def test_creeping_hold_light_block_no_stall():
    # M = 1e-6, K = 1e5: period/16 = 1.2e-5; with that fixed cap 1 s takes ~10^6 steps (30+ s)
    law = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-5, v0=1e-6)
    M, K, ext, v_init = 1e-6, 1e5, 0.6 / 1e5 * 0.98, 1e-7
    psi0 = float(law.steady_state(1e-6)[0])
    block = SpringBlock(mass=M, stiffness=K, drive_velocity=0.0, drive="fixed", law=law)
    r = block.simulate(1.0, initial_extension=ext, initial_velocity=v_init, initial_state=[psi0])
    assert r.success
    assert r.nfev < 20_000                    # the step cap follows the local damping

    # independent reference: Radau on (x, v, psi) with no step cap
    def rhs(t, y):
        f = K * (ext - y[0]) - float(law.friction(y[1], y[2:], 1.0))
        return [y[1], f / M, float(law.state_rate(abs(y[1]), y[2:])[0])]
    ref = solve_ivp(rhs, (0.0, 1.0), [0.0, v_init, psi0], method="Radau", rtol=1e-11,
                    atol=[1e-20, 1e-18, 1e-12])
    assert np.isclose(r.x[-1], ref.y[0, -1], rtol=1e-7, atol=0)
    assert np.isclose(r.v[-1], ref.y[1, -1], rtol=1e-6, atol=0)
    assert np.isclose(r.state[0, -1], ref.y[2, -1], rtol=0, atol=1e-9)
    assert r.energy.closure < 1e-8


def test_light_block_stick_slip_no_stall(monkeypatch):
    # M = 0.1, K = 0.05: between slips the block creeps at ~1e-6, where LSODA alone crawls
    # (1.6e6 evaluations, ~30 s for 80 time units); past STEPS_PER_PERIOD Radau takes over
    from filmfriction.reduced_model.integrators import event_driven as hybrid
    law = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1)
    block = SpringBlock(mass=0.1, stiffness=0.05, drive_velocity=0.1, law=law)
    r = block.simulate(80.0, initial_velocity=0.05)
    assert r.success and r.nfev < 400_000
    monkeypatch.setattr(hybrid, "_WatchedLSODA", hybrid._LocalCapRadau)   # Radau throughout
    with np.errstate(over="ignore"):
        radau = block.simulate(80.0, initial_velocity=0.05)
    assert [e.kind for e in r.events] == [e.kind for e in radau.events] and len(r.events) >= 6
    np.testing.assert_allclose([e.time for e in r.events], [e.time for e in radau.events],
                               rtol=0, atol=1e-6)
    assert np.isclose(r.x[-1], radau.x[-1], rtol=1e-8) and np.isclose(r.psi[-1], radau.psi[-1], atol=1e-7)
