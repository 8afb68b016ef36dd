"""The load's work on the gap taken out of the film force, on model releases of known law.

A wall let go from a stretched spring over a film resisted by F_k + B·v + m_c·a whose
gap opens with the velocity, D(v), against a load L = P·A: the film's x-force carries
L·dD/dx = L·D'(v)·a/v beside its dissipative force, and the trace's ``load_work`` is
−L·(D − D0).  Fitted with ``load_work``, the one law is the dissipative one (F_k, B,
m_c of the model); fitted without, a gap opening as v (not a mass) leaves a loop step.
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from filmfriction.analysis.groundtruth.release_control import fit_releases, model_release
from filmfriction.analysis.slip_law.slip_law import fit_film_force

MASS, LOAD = 500.0, 94.3          # the liquid-release scene's M and P·A (ε/σ³ · σ²)
LAW = dict(kinetic_force=0.5, damping=12.0, comoving_mass=70.0)


def dilatant_release(offset: float, gap, gap_slope, dt: float = 0.05, duration: float = 120.0):
    """(M + m_c + L·D'(v)/v)·a = K(x0 − x) − F_k − B·v with K = 1: the law plus the load's
    work on a gap D(v) (``gap``, its derivative ``gap_slope``), sampled every ``dt``."""
    t = np.arange(0.0, duration, dt)

    def rhs(_, y):
        v = max(y[1], 0.0)
        inertia = MASS + LAW["comoving_mass"] + LOAD * gap_slope(v)
        return [y[1], (offset - y[0] - LAW["kinetic_force"] - LAW["damping"] * y[1]) / inertia]

    x, v = solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-10).y
    d = gap(np.maximum(v, 0.0))
    return {"time": t, "spring_force": offset - x, "wall_position": x, "wall_velocity": v,
            "load_work": -LOAD * (d - d[0])}


# a gap that opens as v (κ·v²/(v + v_c): ∝ v above v_c = 0.05 σ/τ, by 0.05 σ at 0.5 σ/τ);
# D'(v)/v = κ(v + 2v_c)/(v + v_c)²
KAPPA, VC = 0.1, 0.05
OPENS_AS_V = (lambda v: KAPPA * v ** 2 / (v + VC),
              lambda v: KAPPA * (v + 2 * VC) / (v + VC) ** 2)


def releases(gap=OPENS_AS_V):
    return [dilatant_release(x0, *gap) for x0 in (18.0, 20.0, 22.0)]


def test_the_corrected_fit_recovers_the_law_and_the_uncorrected_shows_the_loop():
    trs = releases()
    raw = fit_releases(trs, mass=MASS)
    fit = fit_releases(trs, mass=MASS, load_work=True)
    assert fit.load_work_removed and not raw.load_work_removed
    one, fbar = fit.one_law, fit.one_law.mean_force
    assert one.damping == pytest.approx(LAW["damping"], rel=0.01)
    assert one.kinetic_force == pytest.approx(LAW["kinetic_force"], abs=0.01 * fbar)
    assert one.comoving_mass == pytest.approx(LAW["comoving_mass"], abs=3.0)
    assert abs(fit.loop_step) < 0.01 * fbar
    assert fit.verdict_from == "one law" and fit.verdict == "mixed", fit.reason
    # uncorrected: a step beyond the co-moving mass (the gap's extra inertia is largest at
    # low v, so not one constant m_c), resolved, and the verdict left to the decelerating branch
    assert abs(raw.loop_step) > 0.08 * raw.one_law.mean_force
    assert abs(raw.loop_step_sigmas) >= 2
    assert raw.verdict_from == "decelerating", raw.reason
    assert raw.one_law.comoving_mass > LAW["comoving_mass"] + 10


def test_a_gap_opening_as_v_squared_is_a_mass():
    # D = κ₂·v²: L·dD/dx = 2κ₂·L·a, a co-moving mass of 2κ₂·L and no loop
    k2 = 0.2
    trs = releases((lambda v: k2 * v ** 2, lambda v: 2 * k2 + 0.0 * v))
    raw = fit_releases(trs, mass=MASS)
    fit = fit_releases(trs, mass=MASS, load_work=True)
    assert raw.one_law.comoving_mass == pytest.approx(LAW["comoving_mass"] + 2 * k2 * LOAD,
                                                      abs=3.0)
    assert abs(raw.loop_step) < 0.01 * raw.one_law.mean_force
    assert fit.one_law.comoving_mass == pytest.approx(LAW["comoving_mass"], abs=3.0)
    assert fit.one_law.damping == pytest.approx(LAW["damping"], rel=0.01)


def test_a_gap_that_does_not_move_changes_nothing():
    tr = model_release(damping=12.0, comoving_mass=75.0, mass=MASS)
    still = tr | {"load_work": np.zeros(tr["time"].size)}
    a = fit_releases([tr] * 3, mass=MASS)
    b = fit_releases([still] * 3, mass=MASS, load_work=True)
    assert b.one_law.damping == a.one_law.damping
    assert b.one_law.kinetic_force == a.one_law.kinetic_force
    assert b.loop_step == a.loop_step and b.verdict == a.verdict


def test_bad_load_work_is_refused():
    tr = model_release(damping=12.0, mass=MASS)
    with pytest.raises(ValueError, match="no load_work column"):
        fit_releases([tr], mass=MASS, load_work=True)
    from filmfriction.reduced_model.cycles import cycle_table
    t, f = tr["time"], tr["spring_force"]
    table = cycle_table(t, f, np.array([0]), np.array([1000]))
    with pytest.raises(ValueError, match="load_work has shape"):
        fit_film_force(t, f, tr["wall_velocity"], table, mass=MASS, load_work=np.zeros(3))


def test_the_analysis_reports_the_corrected_fit_beside_the_verdict(tmp_path):
    # a synthetic MD run directory: its trace has a load_work column (a still gap: zeros),
    # so analysis.json's slip_law carries load_work_removed, here the same fit as its own
    import json

    from filmfriction.analysis.groundtruth.synthetic import run_directory
    from filmfriction.workflows.cli.main import main

    run = run_directory(tmp_path / "run")
    assert main(["analyze", "-q", "--no-structure", "--no-figure", str(run)]) == 0
    law = json.loads((run / "analysis.json").read_text())["slip_law"]
    beside = law["load_work_removed"]
    # the correction is made on each slip's own fit, which stands beside the verdict's
    # (the slips' mean) as per_slip_fit
    assert law["estimator"] == "cycle ensemble"
    own = law["per_slip_fit"]
    assert beside["verdict"] == own["verdict"]
    assert beside["verdict_from"] == own["verdict_from"]
    assert beside["one_law"]["damping"] == own["one_law"]["damping"]
    assert beside["loop_step"] == own["loop_step"]
