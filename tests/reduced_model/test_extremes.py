"""Extremes of the reduced model and the analysis that the other tests leave out.

Already covered elsewhere (not repeated here): Coulomb with a very stiff
spring, a tiny or zero mass, heavy damping, V -> 0 and V -> inf, Fs = Fk,
zero load, the event cap (test_reduced_coulomb.py); the massless film
(test_reduced_laws.py); constant, NaN, single-slip and unfinished traces
(test_analysis_stickslip.py).  Here: the same limits on the *ODE path* (which
laws without a closed form take), the overdamped limit approaching the
massless formulation, the step cap of a very stiff smooth law, and traces
with too few samples or without any slip going through the whole analysis.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from filmfriction.analysis.report import analyze, to_json
from filmfriction.analysis.trace import Trace, TraceParameters
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
    # a Newtonian film: as M -> 0 at fixed B the motion tends to the massless
    # solution v = V (1 - exp(-K t / B)); the difference is of order M/B
    film = laws.NewtonianFilm(viscosity=1.0, area=1.0, thickness=1.0)
    massless = SpringBlock(0.0, 2.0, 0.5, law=film).simulate(10.0, initial_extension=0.0)
    light = SpringBlock(1e-4, 2.0, 0.5, law=film).simulate(10.0, initial_extension=0.0,
                                                            initial_velocity=0.0)
    late = light.t > 0.01                     # after the inertial transient M/B
    np.testing.assert_allclose(light.v[late], 0.5 * (1 - np.exp(-2.0 * light.t[late])),
                               atol=1e-3)
    assert massless.energy.closure < 1e-8 and light.energy.closure < 1e-8


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
    assert doc["slips"]["count"] == 0
    assert doc["slips"]["static_force"]["mean"] is None
    assert "viscosity.from_slip" in doc["skipped"]


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
