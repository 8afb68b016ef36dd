"""The one law (whole slip + co-moving mass) on model releases of known law.

A wall let go from a stretched spring and resisted by B·v + m_c·a (a liquid carried
along: no yield) is one law: the fit recovers B and m_c, finds no kinetic force and no
loop step, and its verdict is the one law's.  With a yield on the accelerating branch
(the film holds more while the wall speeds up) the step finds the loop and the verdict
is the decelerating branch's.
"""
import numpy as np
import pytest

from filmfriction.analysis.groundtruth.release_control import fit_releases, model_release
from filmfriction.analysis.slip_law.slip_law import ONE_LAW

MASS = 500.0


def test_a_liquid_release_is_one_law_and_viscous():
    tr = model_release(damping=12.0, comoving_mass=75.0, mass=MASS)
    fit = fit_releases([tr] * 3, mass=MASS)
    assert fit.verdict_from == ONE_LAW, fit.reason
    assert fit.verdict == "viscous", fit.reason
    assert fit.one_law.damping == pytest.approx(12.0, rel=0.01)
    assert fit.one_law.comoving_mass == pytest.approx(75.0, abs=3.0)
    assert abs(fit.one_law.kinetic_force) < 0.01 * fit.one_law.mean_force
    assert abs(fit.loop_step) < 0.01 * fit.one_law.mean_force
    # without m_c the decelerating branch reads the film's inertia as a negative intercept
    assert fit.decelerating.kinetic_force < -0.5


def test_a_yield_on_the_accelerating_branch_is_not_one_law():
    tr = model_release(damping=12.0, comoving_mass=75.0, mass=MASS)
    t, v = tr["time"], tr["wall_velocity"]
    a = np.gradient(v, t)
    # the film holds 1.5 ε/σ more while the wall speeds up: the spring's force carries it
    held = dict(tr) | {"spring_force": tr["spring_force"] + np.where(a > 0, 1.5, 0.0)}
    fit = fit_releases([held] * 3, mass=MASS)
    assert fit.loop_step == pytest.approx(1.5, abs=0.2)
    assert fit.loop_step_sigmas >= 2
    assert fit.verdict_from == "decelerating", fit.reason


def test_the_load_s_work_on_a_gap_opening_with_the_travel():
    from filmfriction.analysis.groundtruth.release_control import release_gap, release_slip
    tr = model_release(damping=12.0, comoving_mass=75.0, mass=MASS)
    x = tr["wall_position"]
    # a gap opening by 0.02 σ per σ of travel: P·A·0.02 on both branches, exactly
    g = release_gap(tr | {"gap": 5.6 + 0.02 * x}, pressure=2.0, area=100.0)
    assert g["dilation_force"] == pytest.approx((4.0, 4.0), rel=1e-9)
    assert g["at_release"] == pytest.approx(5.6)
    # opening on the accelerating branch only (by 0.25 σ up to the peak velocity's place)
    _, stop = release_slip(tr["time"], x)
    peak = int(np.argmax(tr["wall_velocity"][:stop]))
    gap = 5.65 + 0.25 * np.minimum(x, x[peak]) / x[peak]
    g = release_gap(tr | {"gap": gap}, pressure=1.0, area=94.3)
    assert g["dilation_force"][0] == pytest.approx(94.3 * 0.25 / x[peak], rel=0.05)
    assert abs(g["dilation_force"][1]) < 0.05 * g["dilation_force"][0]
    by = g["by_part"]
    assert len(by) == 5 and by[0] < by[1] < by[2] and by[-1] == pytest.approx(5.9)
