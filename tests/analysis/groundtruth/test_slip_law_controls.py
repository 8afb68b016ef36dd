"""The slip-law test's controls at the MD's noise (analysis/groundtruth/slip_law_controls.py).

Negative: Coulomb, rate-and-state and velocity-weakening slips are not called
``viscous``; positive: Klein's viscous slips are called ``viscous`` once there are
enough of them, and never ``kinetic``; each law is named by its name where the
noise lets it be resolved.  40 replicas each (the MD wall's noise drawn anew);
≥ 95 % means at most 2 of 40 otherwise.  The rates and the power are in
docs/results/slip-law.md (``python benchmarks/slip_law_power.py``).
"""
import pytest

from filmfriction.analysis.groundtruth.slip_law_controls import (
    _DRIVE, MD_NOISE, control_trace, coulomb_viscous, replica_fits, verdict_rates)

REPLICAS = 40
AT_MOST = 2          # of 40: ≥ 95 % pass

#: A tenth of the MD's noise: where the laws' own small slopes can be resolved.
QUIET = {k: (v if k == "velocity_correlation" else v / 10) for k, v in MD_NOISE.items()}


@pytest.mark.parametrize("law, slips", [("coulomb", 8), ("coulomb", 30), ("rate-state", 8),
                                        ("weakening", 8), ("weakening", 30)])
def test_negative_controls_are_not_viscous_at_the_md_noise(law, slips):
    rates = verdict_rates(law, REPLICAS, slips)
    assert rates["viscous"] <= AT_MOST, rates


def test_viscous_slips_are_viscous_with_enough_slips_at_the_md_noise():
    rates = verdict_rates("viscous", REPLICAS, 30)
    assert rates["viscous"] >= REPLICAS - AT_MOST, rates


def test_few_viscous_slips_are_inconclusive_not_kinetic():
    # the full sfb-similar run has 8 slips: at the MD's noise the test cannot call them
    # viscous, and must not call them kinetic (what the former test did with unresolved B)
    rates = verdict_rates("viscous", REPLICAS, 8)
    assert rates["kinetic"] + rates["velocity-weakening"] <= AT_MOST, rates
    assert rates["inconclusive"] > REPLICAS // 2, rates


def test_coulomb_slips_are_kinetic_where_the_noise_allows():
    # B is truly 0: a 2 σ test resolves it, either sign, in 4.6 % nominally, so `kinetic`
    # can come out at 95.4 % at best (38 of 40 on average): at most 4 of 40 otherwise,
    # and never `viscous`
    rates = verdict_rates("coulomb", REPLICAS, 8, noise=QUIET)
    assert rates["kinetic"] >= REPLICAS - 2 * AT_MOST, rates
    assert rates["viscous"] == 0, rates


def test_weakening_slips_are_velocity_weakening_where_the_noise_allows():
    rates = verdict_rates("weakening", REPLICAS, 30, noise=QUIET)
    assert rates["velocity-weakening"] >= REPLICAS - AT_MOST, rates


def _exact(trace, drive_velocity):
    # noise-free: the replica's noise set to zero
    return replica_fits(trace, 1, drive_velocity=drive_velocity,
                        noise={"velocity_noise": 0.0, "velocity_correlation": 0.9,
                               "rattle": 0.0})[0]


@pytest.mark.parametrize("law, verdict", [("viscous", "viscous"), ("coulomb", "kinetic"),
                                          ("weakening", "velocity-weakening"),
                                          ("rate-state", "velocity-weakening")])
def test_exact_controls_are_named_by_their_law_on_every_branch(law, verdict):
    # on a noise-free trace the errors are ~0: a negligible term (the quadrature's own
    # error, 1e-4 of the force) must not read as resolved (Coulomb's B, the viscous F_k)
    fit = _exact(control_trace(law, 8), _DRIVE[law])
    for br in (fit.decelerating, fit.whole):
        assert br.verdict == verdict, (br.branch, br.reason)


@pytest.mark.parametrize("share, verdict", [(0.0, "kinetic"), (0.5, "mixed"), (1.0, "viscous")])
def test_exact_coulomb_viscous_slips_by_their_share(share, verdict):
    fit = _exact(coulomb_viscous(share), 0.1)
    for br in (fit.decelerating, fit.accelerating, fit.whole):
        assert br.verdict == verdict, (br.branch, br.reason)
