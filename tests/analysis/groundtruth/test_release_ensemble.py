"""The ensemble release fit on the fluctuating Newtonian film: coverage, verdicts and controls.

Releases of the wall on the film of :mod:`filmfriction.analysis.groundtruth.film_release`
at the ``liquid-release`` scene's scale (67 per replica, the MD's held-gap series; kT 1.5,
sampled every 0.05 τ) are viscous with no loop: the mean release's fit, its errors the
jackknife's over the releases, covers the true loop step (0), F_k (0) and B (η·A/W) at
about the nominal rate and says ``viscous`` (the one law's): 12 replicas here (68 fits
each, the jackknife's); over 100 (the benchmark) ±2 s.e. covers them in 98, 94 and 95 of 100
and the verdict is ``viscous`` in 94 — the rule's own 2 σ tests on F_k (either sign) and on
the loop step each call a true null resolved in ≈ 4.6 % of repeats, which keeps the rate
under 95 %.  The negative controls: a
yield on the accelerating branch is a resolved loop step and the verdict is not the one
law's; a kinetic force of about half the film force is not ``viscous``.  The larger study
is ``benchmarks/slip_law/release_ensemble_coverage.py`` (docs/results/slip-law.md).
"""
import numpy as np
import pytest

from filmfriction.analysis.groundtruth.film_release import (Film, film_release, held_until,
                                                            peak_time, release_traces)
from filmfriction.analysis.groundtruth.release_control import (fit_release_ensemble,
                                                               fit_releases, mean_release)
from filmfriction.analysis.slip_law.slip_law import ONE_LAW

FILM = Film()
RELEASES = 67
NULL_REPLICAS = 12


def _releases(seed, **kw):
    return release_traces(film_release(RELEASES, FILM, seed=seed, **kw))


@pytest.fixture(scope="module")
def null_fits():
    return [fit_release_ensemble(_releases(1000 + k), mass=FILM.mass)
            for k in range(NULL_REPLICAS)]


def test_the_ensemble_fit_covers_the_truth_and_says_viscous(null_fits):
    step = np.array([(f.loop_step, f.loop_step_stderr) for f in null_fits])
    fk = np.array([(f.one_law.kinetic_force, f.one_law.kinetic_force_stderr) for f in null_fits])
    b = np.array([(f.one_law.damping, f.one_law.damping_stderr) for f in null_fits])
    for (est, se), truth in ((step.T, 0.0), (fk.T, 0.0), (b.T, FILM.damping)):
        covered = np.abs(est - truth) <= 2 * se
        assert covered.sum() >= NULL_REPLICAS - 2, (est, se)      # nominal 95.4 %
        # the errors are the estimates' scatter, not far from it either way
        assert 0.6 < se.mean() / est.std(ddof=1) < 1.6
    # no bias of the loop step beyond its scatter over the replicas
    assert abs(step[:, 0].mean()) < 2.5 * step[:, 0].std(ddof=1) / np.sqrt(NULL_REPLICAS)
    verdicts = [(f.verdict, f.verdict_from) for f in null_fits]
    # under 95 % by the rule's false alarms (module text); the per-release fit: 19 % (docs)
    assert verdicts.count(("viscous", ONE_LAW)) >= NULL_REPLICAS - 2, verdicts
    # the errors are the jackknife's over the releases
    assert all(f.one_law.dof == RELEASES - 1 and f.one_law.slips == RELEASES for f in null_fits)


def test_the_per_release_fit_finds_a_loop_the_film_does_not_have():
    # the reason for the ensemble fit: on the same null each release's own noise moves its
    # regressors, and the slips' mean step is biased positive (≈ +1.4 ε/σ, docs)
    steps = [fit_releases(_releases(1000 + k), mass=FILM.mass).loop_step for k in range(3)]
    assert np.mean(steps) > 0.7, steps


def test_a_yield_on_the_accelerating_branch_is_a_loop():
    until = peak_time(FILM)
    for seed in (2001, 2002):
        fit = fit_release_ensemble(held_until(_releases(seed), 3.0, until), mass=FILM.mass)
        assert fit.loop_step_sigmas >= 2, fit.reason
        assert fit.loop_step == pytest.approx(3.0, abs=3 * fit.loop_step_stderr)
        assert fit.verdict_from != ONE_LAW, fit.reason


def test_a_kinetic_force_is_not_viscous():
    for seed in (3001, 3002):
        fit = fit_release_ensemble(_releases(seed, kinetic_force=2.5), mass=FILM.mass)
        assert fit.verdict != "viscous", fit.reason
        assert fit.one_law.kinetic_sigmas >= 2, fit.reason


def test_a_kinetic_force_behind_a_chance_loop_step_is_not_viscous():
    # the benchmark's kinetic-control replicas 23 and 30 (seed 1): a loop step resolved by
    # chance sends the verdict to the decelerating branch, whose intercept (the co-moving
    # mass's m_c·a < 0, not fitted there) cancels the kinetic force of 2.5
    seeds = np.random.SeedSequence(1).spawn(180)
    for k in (23, 30):
        fit = fit_release_ensemble(_releases(seeds[140 + k], kinetic_force=2.5), mass=FILM.mass)
        assert fit.verdict_from == "decelerating" and fit.decelerating.kinetic_sigmas < 2
        assert fit.verdict == "inconclusive", fit.reason


def test_the_mean_release_and_its_checks():
    trs = _releases(5)[:3]
    m = mean_release(trs)
    assert np.allclose(m["wall_position"], np.mean([t["wall_position"] for t in trs], axis=0))
    shifted = trs[:2] + [trs[2] | {"time": trs[2]["time"] * 1.5}]
    with pytest.raises(ValueError, match="sampled at other times"):
        mean_release(shifted)
    with pytest.raises(ValueError, match="3 or more"):
        fit_release_ensemble(trs[:2], mass=FILM.mass)
