"""Extremes of the reduced model and the analysis that the other tests leave out.

Already covered elsewhere (not repeated here): Coulomb with a very stiff
spring, a tiny or zero mass, heavy damping, V -> 0 and V -> inf, Fs = Fk,
zero load, the event cap (reduced_model/test_coulomb.py); the massless film
(reduced_model/test_laws.py); constant, NaN, single-slip and unfinished traces
(analysis/test_stickslip.py).  Here: the same limits on the *ODE path* (which
laws without a closed form take), the overdamped limit approaching the
massless formulation, the step cap of a very stiff smooth law, and traces
with too few samples or without any slip going through the whole analysis.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

from filmfriction.analysis.analyze import analyze, to_json
from filmfriction.analysis.files.trace import Trace, TraceParameters
from filmfriction.reduced_model import SimulationLimitError, SpringBlock, laws

FS, FK, K, M, V = 1.0, 0.5, 1.0, 1.0, 0.1


def coulomb(**kw):
    args = dict(mass=M, stiffness=K, drive_velocity=V, law=laws.Coulomb(FS, FK))
    args.update(kw)
    return SpringBlock(**args)


# ------------------------------------------------------------------ reduced model, ODE path
def test_ode_path_equal_static_and_kinetic_does_not_chatter():
    r = coulomb(law=laws.Coulomb(0.5, 0.5)).simulate(200.0, method="ode")
    assert len(r.events) <= 2 * 200 / (2 * math.pi) + 4
    assert r.v.min() >= -1e-9
    assert r.energy.closure < 1e-8


def test_ode_path_overdamped_slide_matches_closed_form():
    # zeta = 25: the ODE path switches to LSODA; one yield, then smooth sliding
    b = coulomb(damping=50.0)
    exact, ode = b.simulate(300.0), b.simulate(300.0, method="ode")
    assert [e.kind for e in ode.events] == [e.kind for e in exact.events] == ["slip"]
    # compare where both have a sample: the end (sample grids differ in between)
    assert ode.x[-1] == pytest.approx(exact.x[-1], rel=1e-7)
    assert ode.v[-1] == pytest.approx(exact.v[-1], rel=1e-7)
    assert ode.energy.closure < 1e-8


def test_ode_path_vanishing_drive_velocity_long_stick():
    r = coulomb(drive_velocity=1e-5).simulate(2e5, method="ode")
    assert r.events[0].time == pytest.approx(FS / (K * 1e-5), rel=1e-9)
    assert r.energy.closure < 1e-8
    # slower still, the ODE path's step cap counts the (exactly solved) sticks too
    # and refuses with a clear message instead of running for hours
    with pytest.raises(SimulationLimitError, match="natural periods"):
        coulomb(drive_velocity=1e-9).simulate(2e9, method="ode")


def test_overdamped_light_block_approaches_the_massless_block():
    # a Newtonian film (B = 1) on a spring K = 2 driven at V = 0.5, from rest: the massless
    # block moves as x0(t) = V t - (V/k)(1 - exp(-k t)), k = K/B.  A light block, M << B/k,
    # lags it by an inertial time eps = M/B: to first order in eps
    #   x(t) - x0(t) = -V eps k t exp(-k t),   at most V eps / e (at t = 1/k).
    K, V, B, M = 2.0, 0.5, 1.0, 1e-4
    film = laws.NewtonianFilm(viscosity=1.0, area=1.0, thickness=1.0)
    massless = SpringBlock(0.0, K, V, law=film).simulate(10.0, initial_extension=0.0)
    light = SpringBlock(M, K, V, law=film).simulate(10.0, initial_extension=0.0,
                                                    initial_velocity=0.0)
    assert massless.energy.closure < 1e-8 and light.energy.closure < 1e-8
    # the two runs sample different times: the massless run's x and v (= x') give a
    # Hermite interpolant accurate to ~1e-7 here, far below the lag compared (~2e-5)
    x0 = CubicHermiteSpline(massless.t, massless.x, massless.v)
    eps, k = M / B, K / B
    lag = light.x - x0(light.t)
    np.testing.assert_allclose(lag, -V * eps * k * light.t * np.exp(-k * light.t),
                               rtol=0, atol=0.02 * V * eps)
    assert np.abs(lag).max() == pytest.approx(V * eps / math.e, rel=0.02)
    # and the velocities agree once the inertial transient (a few eps) has passed
    late = light.t > 10 * eps
    np.testing.assert_allclose(light.v[late], x0.derivative()(light.t[late]), rtol=0,
                               atol=V * eps * k)


def test_very_stiff_smooth_law_hits_the_step_cap_with_advice():
    # no closed form (rate-and-state): 1e9 natural periods cannot be integrated
    law = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-5, v0=1e-6)
    block = SpringBlock(mass=1e-6, stiffness=1e6, drive_velocity=1e-3, law=law)
    with pytest.raises(SimulationLimitError, match="mass = 0"):
        block.simulate(1e6)


# ------------------------------------------------------------------ analysis, degenerate traces
P = TraceParameters(spring_constant=100.0, mass=500.0, area=58.7, drive_velocity=0.02,
                    mount_damping=150.0)


def doc_for(columns):
    trace = Trace({k: np.asarray(v, float) for k, v in columns.items()}, P, Path("x.csv"))
    doc, _ = analyze(trace, structure=False)
    to_json(doc)                               # strict JSON: no NaN leaks out
    return doc


@pytest.mark.parametrize("n", [1, 2, 3])
def test_too_short_trace_gives_no_slip_and_no_crash(n):
    doc = doc_for({"time": np.arange(n, dtype=float), "spring_force": np.arange(n) + 1.0})
    # too short to classify: unresolved, with the reason, and no section computed
    assert doc["regime"] == "unresolved" and "too short to classify" in doc["regime_note"]
    assert "slips" not in doc and "slips" in doc["skipped"]
    assert "viscosity" in doc["skipped"]


def test_single_sample_spike_is_not_a_slip():
    t = np.arange(0.0, 200.0, 0.1)
    f = np.random.default_rng(1).normal(0.0, 1.0, t.size)
    f[700] += 100.0                            # one corrupted sample
    assert doc_for({"time": t, "spring_force": f})["slips"]["count"] == 0


def test_stuck_wall_ramp_gives_no_steady_viscosity():
    t = np.arange(0.0, 100.0, 0.1)
    doc = doc_for({"time": t, "spring_force": 2.0 * t, "wall_position": np.zeros_like(t),
                   "gap": np.full_like(t, 3.7)})
    assert doc["slips"]["count"] == 0
    assert "steady" not in doc["viscosity"]
    assert "viscosity.steady" in doc["skipped"]
