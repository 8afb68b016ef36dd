"""The slip analysis scored on reduced-model traces whose answer is known
(``filmfriction.analysis.groundtruth.cases``; the whole table: ``benchmarks/validate.py``).

Targets (docs/results/validation.md): on exact traces with >= 20 samples per slip, F_s and
F_b within 0.5 % of the force drop, slip distance and duration within 2 %; the error bar
is the sampling's resolution, never ~1e-15.
"""
import math
import zlib

import numpy as np
import pytest

from filmfriction.analysis.groundtruth import cases as gt
from filmfriction.analysis.analyze import analyze
from filmfriction.reduced_model import SpringBlock, laws

README_BLOCK = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.1,
                           law=laws.Coulomb(static=1.0, kinetic=0.5))
TARGET = {"static_force": 0.005, "backward_force": 0.005, "slip_distance": 0.02,
          "slip_duration": 0.02}


def _within_targets(score):
    assert score.detected == score.expected, score
    for name, limit in TARGET.items():
        assert abs(score.errors[name]) <= limit, (score.case.label(), name, score.errors[name])


def test_readme_example_recovers_the_force_extrema_with_honest_error_bars():
    case = gt.Case("coulomb", README_BLOCK, sampling="events", samples_per_slip=64)
    truth = gt.truth(case)
    # the force's maximum lies after the breakaway at F_s = 1: M K V^2 / (2 (F_s - F_k))
    assert truth.static_force[1] == pytest.approx(1.0 + 0.01 / (2 * 0.5), abs=2e-4)
    assert truth.slip_duration[1] == pytest.approx(math.pi, rel=1e-6)
    cols, params = gt.sample(case)
    doc, _ = analyze(gt.as_trace(cols, params), structure=False)
    slips = doc["slips"]
    assert doc["regime"] == "stick-slip"
    drop = truth.static_force[1] - truth.backward_force[1]
    for name, true in (("static_force", truth.static_force[1]),
                       ("backward_force", truth.backward_force[1])):
        e = slips[name]
        assert abs(e["mean"] - true) <= 0.005 * drop
        assert e["mean"] <= np.max(cols["spring_force"]) + e["stderr"]
        assert 1e-6 * drop < e["stderr"] < 0.01 * drop, e      # the sampling's, not ~1e-15
        assert abs(e["mean"] - true) <= e["stderr"]
    tau = slips["slip_duration"]
    assert tau["mean"] == pytest.approx(math.pi, rel=0.02)
    assert abs(tau["mean"] - math.pi) <= tau["stderr"]
    # with V the slip distance is the wall's: (F_s - F_b)/K + V tau_s
    assert slips["slip_distance"]["mean"] == pytest.approx(truth.slip_distance[1], rel=0.02)


@pytest.mark.parametrize("family", gt.FAMILIES)
@pytest.mark.parametrize("sampling,n", [("uniform", 20), ("events", 100)])
def test_exact_traces_meet_the_targets(family, sampling, n):
    # a seed of its own per case, the same in every process (hash() of a str is not)
    rng = np.random.default_rng(zlib.crc32(f"{family} {sampling}".encode()))
    _within_targets(gt.score(gt.random_case(family, rng, sampling=sampling, samples_per_slip=n)))


def test_slips_longer_than_the_sticks_are_not_called_smooth():
    # lambda = (F_s - F_k)/(V sqrt(KM)) ~ 1: the slip takes longer than the stick, and the
    # noise estimate must not take the slips' curvature for noise
    block = SpringBlock(mass=3.0, stiffness=0.5, drive_velocity=0.6,
                        law=laws.Coulomb(static=1.5, kinetic=0.9))
    case = gt.Case("coulomb", block, samples_per_slip=40)
    law = gt.simulate(case).cycles()        # the law's own breakaway and re-stick
    assert np.nanmean(law.slip_duration[1:]) > np.nanmean(law.stick_duration[1:])
    score = gt.score(case)
    assert score.regime == "stick-slip"
    _within_targets(score)


def test_the_same_trace_in_lj_and_si_numbers_gives_the_same_relative_errors():
    rng = np.random.default_rng(7)
    case = gt.random_case("klein-eq1", rng, samples_per_slip=30, noise=0.01)
    lj = gt.score(case)
    si = gt.score(gt.Case(**{**case.__dict__, "units": "si"}))
    assert lj.detected == si.detected
    for name, e in lj.errors.items():
        assert si.errors[name] == pytest.approx(e, abs=1e-6 + 1e-6 * abs(e)), name


def test_noisy_traces_are_unbiased_within_their_scatter():
    # 1 % white noise on the drop: over 12 random Coulomb traces the mean error of F_s and F_b
    # is within 0.3 % of the drop and each trace's error within 4 reported standard errors
    rng = np.random.default_rng(11)
    errs = {"static_force": [], "backward_force": []}
    for k in range(12):
        s = gt.score(gt.random_case("coulomb", rng, samples_per_slip=50, noise=0.01, seed=k))
        for name in errs:
            errs[name].append(s.errors[name])
            assert abs(s.errors[name]) <= 4 * s.stderrs[name] + 1e-3, (name, s.case.label())
    for name, e in errs.items():
        assert abs(np.mean(e)) < 0.003, (name, e)
