"""The slip-law test's controls at the MD's noise (analysis/groundtruth/slip_law_controls.py).

The noise is the film's random force, which moves the wall (its position and velocity
respond, as an MD wall's do: analysis/groundtruth/random_force.py), and the slips are
fitted as the driven analysis fits them: their mean, each slip aligned at its yield and
held at its end, with the jackknife's errors over the slips
(analysis/slip_law/slip_law_cycles.py).  Negative: Coulomb, rate-and-state and
velocity-weakening slips are not called ``viscous``; positive: Klein's viscous slips are
``viscous`` with 30 slips and never ``kinetic``; a Coulomb slip has no loop step.  The
measured rates, bias and coverage: docs/results/slip-law.md, "The controls with a random
force that moves the wall" (``python benchmarks/slip_law/slip_law_random_force.py --ensemble``).
40 replicas each; ≥ 95 % means at most 2 of 40 otherwise.  The noise added to the law's
trace (the position and the velocity the law's) is kept as the comparison, fitted slip
by slip.
"""
from collections import Counter
from functools import lru_cache

import numpy as np
import pytest
from scipy import stats

from filmfriction.analysis.groundtruth.film_noise import MD_NOISE, scaled
from filmfriction.analysis.groundtruth.slip_law_controls import (
    control_fits, coulomb_viscous, dynamical_fits, replica_fits)
from filmfriction.analysis.slip_law.slip_law import RESOLVED_SIGMAS, VERDICTS

REPLICAS = 40
AT_MOST = 2          # of 40: ≥ 95 % pass

#: A tenth of the MD's noise: where the laws' own small slopes can be resolved.
QUIET = scaled(MD_NOISE, 0.1)
NOISE_FREE = {"velocity_noise": 0.0, "velocity_correlation": 0.9, "rattle": 0.0}

@lru_cache(maxsize=None)
def _fits(law, slips, quiet=False, injected=False, replicas=REPLICAS):
    # one set of replicas per control, shared by the tests that read it
    return control_fits(law, replicas, slips, noise=QUIET if quiet else None, injected=injected)


def verdict_rates(law, replicas, slips, **kw):
    counts = Counter(f.verdict for f in _fits(law, slips, replicas=replicas, **kw))
    return {v: counts.get(v, 0) for v in VERDICTS}


@pytest.mark.parametrize("law, slips", [("coulomb", 8), ("coulomb", 30), ("rate-state", 8),
                                        ("weakening", 8)])
def test_negative_controls_are_not_viscous_at_the_md_noise(law, slips):
    rates = verdict_rates(law, REPLICAS, slips)
    assert rates["viscous"] <= AT_MOST, rates


#: The positive control's replicas: enough to tell a bias of a quarter of the fit's error.
POSITIVE_REPLICAS = 200
#: The most replicas of 200 that may fall short of `viscous` when the verdict keeps the rule's
#: ≥ 95 %: the 99th percentile of a binomial at 5 %, so that a rate of 95 % fails in 1 % of
#: draws (the rule's own false alarms on F_k, either sign, are 2.5 % nominally).
FALSE_ALARMS_99 = int(stats.binom.ppf(0.99, 200, 0.05))


def test_klein_slips_decelerating_branch_is_unbiased_and_covered_at_the_md_noise():
    # the slips' mean, each held at its re-stick (the last sample on which the wall slid), on
    # 30 slips: the decelerating branch's F_k and B recover the law (mean within 3 s.e. of the
    # noise-free fit's) and their 2 σ bars cover it at the nominal rate (95 %: 91 % is its 1st
    # percentile at 200).  With the slider's re-stick marked after the wall stopped (v = 0:
    # the static friction's impulse taken for the law's) the branch's F_k was +0.61 ± 0.04 ε/σ
    # over 1000 replicas: this fails there
    from filmfriction.analysis.slip_law.slip_law_stats import sigmas
    fits = _fits("viscous", 30, replicas=POSITIVE_REPLICAS)
    exact = dynamical_fits("viscous", 1, 30, noise=NOISE_FREE)[0].decelerating
    for attr in ("kinetic_force", "damping"):
        est = np.array([getattr(f.decelerating, attr) for f in fits])
        se = np.array([getattr(f.decelerating, f"{attr}_stderr") for f in fits])
        truth = getattr(exact, attr)
        bias, se_mean = est.mean() - truth, est.std(ddof=1) / np.sqrt(est.size)
        assert abs(bias) < 3 * se_mean, (attr, bias, se_mean)
        z = [sigmas(e - truth, s, f.decelerating.dof) for e, s, f in zip(est, se, fits)]
        assert np.mean(np.abs(z) < 2) >= 0.90, (attr, np.mean(np.abs(z) < 2))


def test_viscous_slips_are_viscous_with_enough_slips_at_the_md_noise():
    # Klein's slips, 30 of them, at the calibrated noise: `viscous` in >= 95 % (the rule's own
    # false alarms on F_k are `mixed` or `inconclusive`), never a negative law.  Measured
    # (docs/results/slip-law.md, 1000 replicas): see the page's cycle-ensemble table
    rates = verdict_rates("viscous", POSITIVE_REPLICAS, 30)
    assert rates["viscous"] >= POSITIVE_REPLICAS - FALSE_ALARMS_99, rates
    assert rates["kinetic"] + rates["velocity-weakening"] == 0, rates


def test_few_viscous_slips_are_never_kinetic():
    # the full sfb-similar run has 8 slips: whatever the test cannot resolve there, it must
    # not call Klein's slips kinetic or weakening
    rates = verdict_rates("viscous", REPLICAS, 8)
    assert rates["kinetic"] + rates["velocity-weakening"] <= AT_MOST, rates


def test_a_coulomb_slip_has_no_loop_step_at_the_md_noise():
    # F_k + 0·v on every sample: one law, no step at the peak velocity; the rule's test resolves
    # a step of 0 in 2.5 % nominally
    fits = _fits("coulomb", 8)
    assert sum(abs(f.loop_step_sigmas) >= RESOLVED_SIGMAS for f in fits) <= 2 * AT_MOST


def test_coulomb_slips_are_kinetic_where_the_noise_allows():
    # B is truly 0: the rule's test resolves it, either sign, in 2.5 % nominally, so `kinetic`
    # can come out at 97.5 % at best (39 of 40 on average): at most 4 of 40 otherwise,
    # and never `viscous`
    rates = verdict_rates("coulomb", REPLICAS, 8, quiet=True)
    assert rates["kinetic"] >= REPLICAS - 2 * AT_MOST, rates
    assert rates["viscous"] == 0, rates


def test_weakening_slips_are_velocity_weakening_where_the_noise_allows():
    rates = verdict_rates("weakening", REPLICAS, 8, quiet=True)
    assert rates["velocity-weakening"] >= REPLICAS - AT_MOST, rates


def test_with_the_noise_added_to_the_trace_viscous_slips_are_viscous():
    # the comparison: the same noise on the law's own motion passes the positive control
    rates = verdict_rates("viscous", REPLICAS, 30, injected=True)
    assert rates["viscous"] >= REPLICAS - AT_MOST, rates


def _exact(trace, drive_velocity):
    # noise-free: the replica's noise set to zero
    return replica_fits(trace, 1, drive_velocity=drive_velocity, noise=NOISE_FREE)[0]


@pytest.mark.parametrize("injected", [True, False])
@pytest.mark.parametrize("law, verdict", [("viscous", "viscous"), ("coulomb", "kinetic"),
                                          ("weakening", "velocity-weakening"),
                                          ("rate-state", "velocity-weakening")])
def test_exact_controls_are_named_by_their_law_on_every_branch(law, verdict, injected):
    # on a noise-free trace (the reduced model's, or the random-force slider's with no
    # force) the errors are ~0: a negligible term (the quadrature's own error, 1e-4 of the
    # force) must not read as resolved (Coulomb's B, the viscous F_k)
    fits = [control_fits(law, 1, 8 if injected else 3, noise=NOISE_FREE, injected=injected,
                         **({} if injected else {"ensemble": False}))[0]]
    if not injected:
        # the cycle ensemble of the same slips (the driven analysis's fit)
        fits.append(control_fits(law, 1, 3, noise=NOISE_FREE)[0])
    for fit in fits:
        for br in (fit.decelerating, fit.whole):
            assert br.verdict == verdict, (br.branch, br.reason)


@pytest.mark.parametrize("share, verdict", [(0.0, "kinetic"), (0.5, "mixed"), (1.0, "viscous")])
def test_exact_coulomb_viscous_slips_by_their_share(share, verdict):
    # the slider's slips fitted slip by slip and as the cycle ensemble; noise-free, the
    # ensemble's velocity needs no smoothing over the noise's correlation time (3 τ would
    # leave the short decelerating branch of the share-0 slips no sample)
    for fit in (_exact(coulomb_viscous(share), 0.1),
                dynamical_fits("", 1, 3, noise=NOISE_FREE, share=share, ensemble=False)[0],
                dynamical_fits("", 1, 3, noise=NOISE_FREE, share=share, min_window_time=0.0)[0]):
        for br in (fit.decelerating, fit.accelerating, fit.whole):
            assert br.verdict == verdict, (br.branch, br.reason)


def test_the_cycle_ensemble_refuses_too_few_slips():
    with pytest.raises(ValueError, match="needs 3 or more"):
        dynamical_fits("viscous", 1, 2, noise=NOISE_FREE)


# --- the heavy slider's scales: SCALES["stiff"] (K = 8, M = 1e5, the mount dashpot 34 m/τ)
# and the K = 8 film's slider at M = 1e4 (SCALES["m1e4"]: V 0.0079, the mount dashpot 10.7 m/τ)

@pytest.mark.parametrize("scale, name, share, verdict, kinetic, damping", [
    ("stiff", "coulomb", None, "kinetic", 25.0, 0.0),
    ("stiff", "viscous", None, "viscous", 0.0, 1788.9),
    ("stiff", "", 0.6, "mixed", 10.8, 952.9),
    ("m1e4", "coulomb", None, "kinetic", 27.0, 0.0),
    ("m1e4", "viscous", None, "viscous", 0.0, 565.7),
    ("m1e4", "", 0.3, "mixed", 22.4, 213.3),
    ("m3e3", "coulomb", None, "kinetic", 25.5, 0.0),
    ("m3e3", "viscous", None, "viscous", 0.0, 309.8),
    ("m3e3", "", 0.5, "mixed", 16.75, 274.6),
    ("k16m3e3", "coulomb", None, "kinetic", 25.3, 0.0),
    ("k16m3e3", "viscous", None, "viscous", 0.0, 438.2),
    ("k16m3e3", "", 0.5, "mixed", 16.65, 287.1),
    ("k4m3e3", "coulomb", None, "kinetic", 25.4, 0.0),
    ("k4m3e3", "viscous", None, "viscous", 0.0, 219.1),
    ("k4m3e3", "", 0.3, "mixed", 23.38, 126.8),
    ("m25e3", "viscous", None, "viscous", 0.0, 282.8),
    ("m25e3", "", 0.5, "mixed", 16.1, 211.8)])
def test_heavy_scale_noise_free_controls_give_their_law_back(scale, name, share, verdict,
                                                             kinetic, damping):
    # the slider's mount dashpot is the fit's: the law comes back exactly
    fit = dynamical_fits(name, 1, 8, noise=NOISE_FREE, share=share, scale=scale)[0]
    assert fit.verdict == verdict
    assert fit.decelerating.kinetic_force == pytest.approx(kinetic, abs=0.05)
    assert fit.decelerating.damping == pytest.approx(damping, abs=1.0)


@pytest.mark.parametrize("scale, below", [("stiff", -300.0), ("m1e4", -100.0)])
def test_heavy_weakening_slips_are_weakening_noise_free(scale, below):
    # the force falls with the velocity on the slowing branch: B resolved negative
    fit = dynamical_fits("weakening", 1, 8, noise=NOISE_FREE, scale=scale)[0]
    assert fit.verdict == "velocity-weakening", fit.reason
    assert fit.decelerating.damping < below


def test_stiff_coulomb_slips_are_never_viscous_at_the_stiff_noise():
    # 0 of 200 at 8 and 30 slips (docs/results/slip-law.md, "Controls at the heavy
    # slider's scale"); 20 replicas of 8 slips here
    fits = dynamical_fits("coulomb", 20, 8, scale="stiff")
    assert not any(f.verdict == "viscous" for f in fits), Counter(f.verdict for f in fits)


# --- the M = 1e4, 3e3 (K = 8, 16 and 4) and 2.5e3 scales' periods

@pytest.mark.parametrize("scale, name, share", [
    *(("m1e4", n, s) for n, s in (("coulomb", None), ("weakening", None), ("viscous", None),
                                  ("", 0.0), ("", 0.3), ("", 1.0))),
    *((sc, n, s) for sc in ("m3e3", "k16m3e3", "k4m3e3", "m25e3")
      for n, s in (("coulomb", None), ("viscous", None), ("", 0.0), ("", 0.5), ("", 1.0)))])
def test_periods_hold_a_noise_free_cycle(scale, name, share):
    # ``period`` is a slip cycle's length or a little more (the mixes' one period, the
    # longest of their shares'; at M = 3×10³ one period for every law, the Coulomb
    # control's the longest): the runs' durations rest on it
    from filmfriction.analysis.groundtruth.slip_law_controls import SCALES, random_force_runs

    run = random_force_runs(name, 1, slips=4, noise=NOISE_FREE, share=share, scale=scale)[0][0]
    cycle = np.diff(run["time"][run["yield_index"]])
    assert cycle.size >= 5
    period = SCALES[scale].law(name or "coulomb", share)["period"]
    assert cycle[1:].max() <= period
    if share is None and (scale == "m1e4" or name == "coulomb"):
        assert period < 1.3 * cycle[1:].max()


def test_a_rattle_on_the_sampled_velocity_does_not_bias_the_one_law():
    # white noise on the sampled velocity only (the wall's thermal rattle; the random
    # force off, so the slides are the noise-free one): the one law's co-moving-mass
    # regressor is each slip's held velocity from its own positions, which the rattle does
    # not reach, and the rattle is noise in the response y − M·v alone (the sampled
    # velocity as the regressor froze it into the held lags: a loop step of +2.1 ε/σ)
    rattle = {"velocity_noise": 0.0, "velocity_correlation": 0.0, "rattle": 0.15}
    exact = dynamical_fits("coulomb-viscous", 1, 8, noise=NOISE_FREE, share=0.3)[0]
    fits = dynamical_fits("coulomb-viscous", REPLICAS, 8, noise=rattle, share=0.3)
    for get in (lambda f: f.one_law.kinetic_force, lambda f: f.one_law.damping,
                lambda f: f.one_law.comoving_mass, lambda f: f.loop_step):
        err = np.array([get(f) - get(exact) for f in fits])
        assert abs(err.mean()) < 3 * err.std(ddof=1) / np.sqrt(err.size) + 0.05
