"""Klein's slip equation tested on slips: F_film = F_k + B·v recovered from known models,
the branches, the loop, the co-moving mass, the errors and the power."""
import math

import numpy as np
import pytest

from filmfriction.analysis.slip_law.slip_law import (ONE_LAW, RESOLVED_SIGMAS, VERDICTS, detectable,
                                            film_force, fit_film_force, sigmas)
from filmfriction.analysis.groundtruth.synthetic import block_trace, klein_trace, with_wall_noise
from filmfriction.analysis.stickslip import detect_slips
from filmfriction.reduced_model.cycles import cycle_table
from filmfriction.reduced_model import SpringBlock, laws


def _run(kinetic, damping, *, static=1.0, mass=1.0, k=1.0, v=0.01, duration=800.0):
    r = SpringBlock(mass=mass, stiffness=k, drive_velocity=v, damping=damping,
                    law=laws.Coulomb(static=static, kinetic=kinetic)).simulate(duration)
    return r, r.cycles()


def _fit(r, tab, **kw):
    kw.setdefault("mass", 1.0)
    kw.setdefault("drive_velocity", 0.01)
    return fit_film_force(r.t, r.spring_force, r.v, tab, wall_position=r.x, **kw)


@pytest.mark.parametrize("kinetic, damping", [(0.4, 0.5), (0.5, 0.02), (0.02, 1.2)])
def test_recovers_known_kinetic_force_and_damping_on_both_branches(kinetic, damping):
    r, tab = _run(kinetic, damping)
    assert len(tab) >= 3
    fit = _fit(r, tab[1:])
    for br in (fit.decelerating, fit.accelerating):
        assert br.kinetic_force == pytest.approx(kinetic, abs=2e-3)
        assert br.damping == pytest.approx(damping, rel=5e-3, abs=1e-3)
        assert np.all(np.isfinite(br.per_slip_damping))
    # one law on both branches: no loop
    assert abs(fit.loop_force) < 2e-3
    # the exponent is the law's d ln F/d ln v at the mean slip velocity
    vbar = fit.decelerating.mean_velocity
    assert fit.decelerating.exponent == pytest.approx(
        damping * vbar / (kinetic + damping * vbar), abs=5e-3)
    # noise-free, both terms are resolved
    assert fit.verdict == "mixed", fit.reason


def test_without_the_wall_position_the_integrated_velocity_does():
    r, tab = _run(0.4, 0.5)
    fit = fit_film_force(r.t, r.spring_force, r.v, tab[1:], mass=1.0, drive_velocity=0.01)
    assert fit.damping == pytest.approx(0.5, rel=2e-2)
    assert fit.kinetic_force == pytest.approx(0.4, abs=5e-3)


def _fit_noisy(tr):
    """The film-force fit of a model trace's slips (the start-up slip left out), the wall's
    velocity and the spring force with a small measurement noise."""
    noisy = with_wall_noise(tr, velocity_noise=0.02, seed=1)
    t, f = tr["time"], tr["spring_force"]
    ev = detect_slips(t, f)
    tab = cycle_table(t, f, ev.yield_index, ev.stick_index, spring_constant=2.0)[1:]
    return fit_film_force(t, noisy["spring_force"], noisy["wall_velocity"], tab, mass=30.0,
                          drive_velocity=0.1, wall_position=tr["wall_position"])


def test_a_pure_law_is_called_by_its_name_when_the_other_term_is_absent():
    # Klein's slip (F_k = 0) at a small noise: viscous; a Coulomb slip (B = 0): kinetic
    fit = _fit_noisy(klein_trace(spring_constant=2.0, mass=30.0, damping=62.0,
                                 drive_velocity=0.1, static_force=48.0, backward_force=24.0,
                                 cycles=8, dt=0.25))
    assert fit.verdict == "viscous", fit.reason
    assert fit.damping == pytest.approx(62.0, rel=0.03)
    assert fit.decelerating.exponent == pytest.approx(1.0, abs=0.05)
    block = SpringBlock(mass=30.0, stiffness=2.0, drive_velocity=0.1,
                        law=laws.Coulomb(static=48.0, kinetic=36.0))
    fit = _fit_noisy(block_trace(block, 1200.0, 0.25))
    assert fit.verdict == "kinetic", fit.reason
    assert abs(fit.decelerating.exponent) < 0.05


def test_mount_dashpot_is_taken_off_the_film():
    # the block's damper D = B + d acts on v; a mount dashpot d acts on v − V, so the
    # film's law is F_k + d·V + B·v
    b, d, v = 0.3, 0.2, 0.01
    r, tab = _run(0.4, b + d, v=v)
    fit = _fit(r, tab[1:], drive_velocity=v, mount_damping=d)
    assert fit.damping == pytest.approx(b, rel=1e-2)
    assert fit.kinetic_force == pytest.approx(0.4 + d * v, abs=2e-3)


def test_a_loop_is_measured_between_the_branches():
    # a film force higher while the wall accelerates: add F_extra on the accelerating half
    r, tab = _run(0.4, 0.5)
    tab = tab[1:]
    a = np.gradient(r.v, r.t)
    extra = np.where(a > 0, 0.1, 0.0)         # the film holds 0.1 more while it breaks
    # the wall's motion is the model's; the measured spring force carries the extra hold
    fit = fit_film_force(r.t, r.spring_force + extra, r.v, tab, mass=1.0, drive_velocity=0.01,
                         wall_position=r.x)
    assert fit.accelerating.kinetic_force == pytest.approx(0.5, abs=0.02)
    assert fit.decelerating.kinetic_force == pytest.approx(0.4, abs=0.02)
    assert fit.loop_force == pytest.approx(0.1, abs=0.02)
    assert fit.loop_area > 0
    # a co-moving mass alone would take the loop up (m_c ≈ 0.18, a mass that is not
    # there); the step at the peak finds it, so the slip is not one law and the verdict
    # is the decelerating branch's
    assert fit.loop_step == pytest.approx(0.1, abs=0.005)
    assert fit.loop_step_sigmas >= 2
    assert fit.verdict_from == "decelerating", fit.reason
    assert fit.damping == fit.decelerating.damping


def test_comoving_mass_is_found():
    # a wall of mass 1.5 analysed as if it were 1: 0.5 moves with it unaccounted
    r, tab = _run(0.4, 0.5, mass=1.5)
    plain = _fit(r, tab[1:], mass=1.0)
    with_mass = _fit(r, tab[1:], mass=1.0, comoving_mass=True)
    # the missing inertia biases the branches' law fitted without m_c
    assert abs(plain.decelerating.damping - 0.5) > 0.02
    assert math.isnan(plain.decelerating.comoving_mass)
    assert with_mass.decelerating.comoving_mass == pytest.approx(0.5, abs=0.02)
    assert with_mass.decelerating.damping == pytest.approx(0.5, rel=2e-2)
    # the one law over the whole slip fits m_c whatever was asked, finds no loop beyond
    # it (the slip is F_k + B·v throughout) and is the verdict's law: unbiased
    for fit in (plain, with_mass):
        assert fit.one_law.comoving_mass == pytest.approx(0.5, abs=0.02)
        assert fit.verdict_from == ONE_LAW, fit.reason
        assert fit.damping == pytest.approx(0.5, rel=2e-2)
        assert fit.kinetic_force == pytest.approx(0.4, rel=2e-2)
        assert fit.verdict == "mixed", fit.reason


def test_noise_gives_errors_that_cover_the_truth_at_the_nominal_rate():
    # 40 noisy replicas of Klein's slip (a Coulomb+viscous in general): |est − truth| < 2 σ
    # in about 95 % of them (the errors are the scatter over 7 slips, t with 6 dof)
    tr = klein_trace(spring_constant=2.0, mass=30.0, damping=62.0, drive_velocity=0.1,
                     static_force=48.0, backward_force=24.0, cycles=8, dt=0.25)
    t, f = tr["time"], tr["spring_force"]
    ev = detect_slips(t, f)
    tab = cycle_table(t, f, ev.yield_index, ev.stick_index, spring_constant=2.0)[1:]
    inside_b = inside_fk = 0
    for seed in range(40):
        noisy = with_wall_noise(tr, velocity_noise=0.75, velocity_correlation=0.9,
                                rattle=0.25, seed=seed)
        fit = fit_film_force(t, noisy["spring_force"], noisy["wall_velocity"], tab, mass=30.0,
                             drive_velocity=0.1, wall_position=tr["wall_position"])
        d = fit.decelerating
        inside_b += abs(sigmas(d.damping - 62.0, d.damping_stderr, d.dof)) < 2
        inside_fk += abs(sigmas(d.kinetic_force, d.kinetic_force_stderr, d.dof)) < 2
    assert inside_b >= 34 and inside_fk >= 34       # ≥ 85 % of 40 (nominal 95.4 %)


def test_significance_and_power_helpers():
    assert sigmas(3.0, 1.0, 10 ** 7) == pytest.approx(3.0, abs=1e-3)
    assert sigmas(-3.0, 1.0, 5) < 0 and abs(sigmas(-3.0, 1.0, 5)) < 3
    assert sigmas(1.0, 0.0, 5) > 30 and math.isnan(sigmas(1.0, math.nan, 5))
    # 95 % power at the rule's 2.24 σ: with many dof, 2.24 + 1.645 standard errors
    assert RESOLVED_SIGMAS == pytest.approx(2.2414, abs=1e-4)   # 2.5 % two-sided
    assert detectable(2.0, 10 ** 7) == pytest.approx(2 * (2.2414 + 1.6449), rel=1e-3)
    assert detectable(2.0, 10 ** 7, resolved=2.0) == pytest.approx(2 * 3.645, rel=1e-3)
    assert detectable(1.0, 3) > detectable(1.0, 30)


def test_the_power_statement_holds():
    # a true B equal to the detectable damping of the run is resolved in ~95 % of repeats
    rng = np.random.default_rng(3)
    se, dof = 1.0, 6
    b = detectable(se, dof)
    n = 4000
    est = b + se * rng.standard_normal(n)
    # the scatter over 7 slips estimates se with 6 dof: resolve est/(se·s) against the rule's σ
    s = np.sqrt(rng.chisquare(dof, n) / dof)
    hits = np.mean([sigmas(e, se * k, dof) >= RESOLVED_SIGMAS for e, k in zip(est, s)])
    assert 0.94 < hits < 0.96


def test_no_slips_and_bad_input():
    r, tab = _run(0.4, 0.5)
    fit = _fit(r, tab[0:0])
    assert fit.verdict == "inconclusive" and math.isnan(fit.damping)
    assert fit.verdict in VERDICTS
    with pytest.raises(ValueError, match="mass"):
        film_force([0, 1], [0, 0], [0, 0], mass=0.0)
    with pytest.raises(ValueError, match="min_velocity_fraction"):
        _fit(r, tab, min_velocity_fraction=1.5)
    with pytest.raises(ValueError, match="smoothing"):
        _fit(r, tab, smoothing=2.0)
    with pytest.raises(ValueError, match="wall_position"):
        fit_film_force(r.t, r.spring_force, r.v, tab, mass=1.0, wall_position=r.x[:-1])


def _pinned_wall(amplitudes, *, mass=500.0, k=1.0, held=20.0, period=15.0, dt=0.05):
    # a wall held by a solid film at the spring force `held`, rattling in its well:
    # x = a(1 − cos ωt), one amplitude per period; the windows are its forward swings
    w = 2 * np.pi / period
    t = np.arange(0, period * len(amplitudes), dt)
    a = np.asarray(amplitudes)[np.minimum((t / period).astype(int), len(amplitudes) - 1)]
    x, v = a * (1 - np.cos(w * t)), a * w * np.sin(w * t)
    n = int(round(period / dt))
    ys = np.arange(0, t.size - n, n)
    return t, held - k * x, v, x, cycle_table(t, held - k * x, ys, ys + n // 2)


def test_a_wall_that_did_not_move_is_no_slip():
    # swings of 0.1–0.14 σ against a spring stretched by 20 σ: fitted, they read as a
    # resolved kinetic force (or weakening, or mixed, by branch); they are no slip
    t, f, v, x, tab = _pinned_wall(0.05 + 0.02 * np.sin(0.37 * np.arange(20)))
    fit = fit_film_force(t, f, v, tab, mass=500.0, wall_position=x)
    assert fit.still_windows == len(tab)
    for br in (fit.decelerating, fit.accelerating, fit.whole):
        assert br.verdict == "inconclusive", br.reason
        assert br.reason.startswith("no slip") and "moved Δx = 0.1" in br.reason, br.reason


def test_a_real_stuck_md_wall_is_no_slip():
    # a solid film (wall–film bond 2 ε) holding the liquid-release wall at 20 ε/σ for the
    # whole run; the windows are the wall's forward swings in its well (0.05–0.17 σ)
    from pathlib import Path
    from scipy.signal import argrelextrema, savgol_filter
    from filmfriction.analysis.groundtruth.release_control import fit_releases
    path = Path(__file__).resolve().parents[1] / "data" / "stuck_wall_trace.csv"
    tr = np.genfromtxt(path, delimiter=",", names=True, skip_header=2)
    t, f, x, v = tr["time"], tr["spring_force"], tr["wall_position"], tr["wall_velocity"]
    xs = savgol_filter(x, 101, 2)
    lo, hi = argrelextrema(xs, np.less, order=20)[0], argrelextrema(xs, np.greater, order=20)[0]
    ys = np.array([a for a in lo if np.any(hi > a)])
    ss = np.array([hi[hi > a][0] for a in ys])
    assert ys.size >= 5 and np.all(x[ss] - x[ys] < 0.2)
    fit = fit_film_force(t, f, v, cycle_table(t, f, ys, ss), mass=500.0, wall_position=x)
    assert fit.still_windows == ys.size
    for br in (fit.decelerating, fit.accelerating, fit.whole):
        assert br.verdict == "inconclusive" and br.reason.startswith("no slip"), br.reason
    # the release control's own window (from the start to the wall's first stop)
    fit = fit_releases([{k: tr[k] for k in tr.dtype.names}], mass=500.0)
    assert fit.verdict == "inconclusive" and fit.reason.startswith("no slip"), fit.reason
    assert "mean velocity" in fit.reason


def test_slips_among_still_windows_are_fitted_and_the_still_ones_named():
    r, tab = _run(0.4, 0.5)
    t, f, v, x = r.t, r.spring_force, r.v, r.x
    # a window inside a stick (the force rising: the spring not relaxed) joins the slips
    y, s = int(tab.stick_index[1]), int(tab.yield_index[2])
    assert s - y >= 3 and f[s] > f[y]
    mixed = cycle_table(t, f, np.insert(tab.yield_index[1:], 1, y),
                        np.insert(tab.stick_index[1:], 1, s))
    fit = fit_film_force(t, f, v, mixed, mass=1.0, drive_velocity=0.01, wall_position=x)
    assert fit.still_windows == 1
    assert fit.kinetic_force == pytest.approx(0.4, abs=2e-3)
    assert fit.damping == pytest.approx(0.5, rel=5e-3)
    assert f"1 of {len(mixed)} window(s) left out" in fit.reason
