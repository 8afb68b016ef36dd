"""The MD's noise measured on slips (analysis/groundtruth/md_noise.py) and the controls' process
calibrated to it (film_noise.MD_NOISE).

The MD's numbers are those of ``python benchmarks/slip_law/md_noise_calibration.py`` on the 47 slips of
three ``sfb-similar`` runs of 2.8 M steps (docs/results/slip-law.md, "The MD's noise"); the
runs are not in the repository, so they are written here as measured data.
"""
import math

import numpy as np
import pytest

from filmfriction.analysis.groundtruth.md_noise import (increment_rms, replica_slips,
                                                        residual_statistics, residuals,
                                                        slip_velocities)
from filmfriction.analysis.groundtruth.film_noise import (M1E4_NOISE, M1E4_REGISTRY_NOISE,
                                                       M3E3_NOISE, M3E3_REGISTRY_NOISE,
                                                       K16M3E3_REGISTRY_NOISE,
                                                       K4M3E3_REGISTRY_NOISE,
                                                       M25E3_REGISTRY_NOISE,
                                                       MD_NOISE, RESIDUAL_AS_NOISE,
                                                       STIFF_NOISE, STIFF_REGISTRY_NOISE)

#: The MD's: the wall velocity's change over 0.25, 1, 2 τ (rms, σ/τ), and the residual with
#: Δt², Δt³ fitted besides (rms ± its standard error over the slips).
MD_INCREMENTS = (0.286, 0.330, 0.357)
MD_FAST_RESIDUAL = (0.229, 0.007)
#: The plain residual of F_k + B·v: rms and autocorrelation at 0.25, 1, 2 τ.
MD_RESIDUAL = (0.686, (0.78, 0.57, 0.38))


def _measures(noise, replicas=20):
    slips = replica_slips(noise, replicas=replicas)
    inc = increment_rms([v for s in slips for v in slip_velocities(s["wall_velocity"],
                                                                   s["yields"], s["sticks"])])
    plain, fast = (residual_statistics([r for s in slips for r in residuals(s, trend=k)])
                   for k in (1, 3))
    return inc, plain, fast


def test_a_noise_free_slip_of_the_fitted_law_leaves_no_residual():
    inc, plain, _ = _measures({"velocity_noise": 0.0, "velocity_correlation": 0.0,
                               "rattle": 0.0}, replicas=1)
    assert plain["slips"] >= 5
    assert plain["rms"] < 1e-3            # the quadrature's own error only
    assert max(inc) < 0.05                # the slip's own smooth change over 2 τ


def test_md_noise_reproduces_the_md_jitter_and_fast_residual():
    inc, plain, fast = _measures(MD_NOISE)
    assert inc == pytest.approx(MD_INCREMENTS, rel=0.1)
    assert fast["rms"] == pytest.approx(MD_FAST_RESIDUAL[0], abs=3 * MD_FAST_RESIDUAL[1])
    # what it does not reproduce: the plain residual is half the MD's and faster (the rest of
    # the MD's is a slip-long shape F_k + B·v misses)
    assert plain["rms"] < 0.6 * MD_RESIDUAL[0]
    assert plain["autocorrelation"][2] < MD_RESIDUAL[1][2] - 0.2


def test_the_residual_taken_as_noise_jitters_more_than_the_md():
    inc, _, _ = _measures(RESIDUAL_AS_NOISE)
    assert all(a > 1.4 * b for a, b in zip(inc, MD_INCREMENTS)), inc


def test_residual_statistics_of_a_known_ar1():
    rng = np.random.default_rng(1)
    rho, n = 0.8, 2000
    rs = []
    for _ in range(10):
        e = rng.normal(0, math.sqrt(1 - rho ** 2), n)
        r = np.empty(n)
        r[0] = rng.normal()
        for i in range(1, n):
            r[i] = rho * r[i - 1] + e[i]
        rs.append(r)
    s = residual_statistics(rs, lags=(1, 4))
    assert s["rms"] == pytest.approx(1.0, rel=0.05)
    assert s["autocorrelation"] == pytest.approx([rho, rho ** 4], abs=0.03)
    with pytest.raises(ValueError, match="no slip"):
        residual_statistics([])


def test_a_lag_longer_than_a_slip_leaves_that_slip_out_of_that_lag():
    # a brief slip has no pair at a long lag: it is left out there, kept at the short ones
    rng = np.random.default_rng(2)
    long_, short = rng.normal(size=(3, 400)), rng.normal(size=30)
    s = residual_statistics([*long_, short], lags=(1, 64))
    alone = residual_statistics(list(long_), lags=(64,))
    assert s["slips"] == 4 and s["rms"] == pytest.approx(
        np.mean([r.std() for r in [*long_, short]]))
    assert s["autocorrelation"][1] == pytest.approx(alone["autocorrelation"][0])
    assert s["autocorrelation_stderr"][1] == pytest.approx(alone["autocorrelation_stderr"][0])
    assert math.isnan(residual_statistics([short], lags=(64,))["autocorrelation"][0])


#: The MD's fast residual (with Δt², Δt³) at the heavy slider's scale read with the walls'
#: registry force fitted besides: ten ``sfb-thick-stiff`` runs, 89 slips (``python
#: benchmarks/slip_law/md_noise_calibration.py RUN… --scale stiff --share 0.2 --corrugation 20
#: 1.1 -0.97 --registry-period 1.1``, docs/results/slip-law.md), rms ± its standard error.
MD_STIFF_FAST_RESIDUAL_BESIDE_REGISTRY = (0.00158, 0.00007)
#: The same at M = 10⁴: six runs (seeds 1–6), ``--scale m1e4 --share 0.5``.
MD_M1E4_FAST_RESIDUAL_BESIDE_REGISTRY = (0.00541, 0.00022)
#: The same at M = 3×10³: the mass ladder's eight runs, ``--scale m3e3 --share 0.5``.
MD_M3E3_FAST_RESIDUAL_BESIDE_REGISTRY = (0.0131, 0.0005)
#: The same at M = 3×10³ on K = 16: that rung's eight runs, ``--scale k16m3e3 --share 0.5``.
MD_K16M3E3_FAST_RESIDUAL_BESIDE_REGISTRY = (0.0112, 0.0004)
#: The same at M = 2.5×10³: that rung's sixteen runs, ``--scale m25e3 --share 0.5``.
MD_M25E3_FAST_RESIDUAL_BESIDE_REGISTRY = (0.0139, 0.0003)
#: The same at M = 3×10³ on K = 4: that rung's sixteen runs, ``--scale k4m3e3 --share 0.3``.
MD_K4M3E3_FAST_RESIDUAL_BESIDE_REGISTRY = (0.0140, 0.0004)
CORRUGATION = (20.0, 1.1, -0.97)


def _stiff_fast_rms(noise, replicas, registry_period, scale="stiff", share=0.2):
    slips = replica_slips(noise, scale=scale, share=share, replicas=replicas, slips=10,
                          duration=None, corrugation=CORRUGATION)
    return residual_statistics([r for s in slips for r in residuals(
        s, trend=3, registry_period=registry_period)])["rms"]


def test_the_registry_terms_take_a_corrugated_films_force_out_of_the_residual():
    quiet = {"velocity_noise": 0.0, "velocity_correlation": 0.0, "rattle": 0.0}
    unfitted = _stiff_fast_rms(quiet, 2, None)
    fitted = _stiff_fast_rms(quiet, 2, CORRUGATION[1])
    assert unfitted > 5e-4                # the registry force is in the law's residual
    assert fitted < 0.05 * unfitted       # and the terms take it out


def test_the_stiff_noise_beside_the_registry_is_the_mds_and_the_older_one_too_loud():
    md, err = MD_STIFF_FAST_RESIDUAL_BESIDE_REGISTRY
    assert _stiff_fast_rms(STIFF_REGISTRY_NOISE, 20, 1.1) == pytest.approx(md, abs=3 * err)
    # calibrated without the registry's terms, STIFF_NOISE carries the registry force as noise
    assert _stiff_fast_rms(STIFF_NOISE, 20, 1.1) > md + 6 * err


def test_the_m1e4_noise_beside_the_registry_is_the_mds_and_the_older_one_too_loud():
    md, err = MD_M1E4_FAST_RESIDUAL_BESIDE_REGISTRY
    assert _stiff_fast_rms(M1E4_REGISTRY_NOISE, 20, 1.1, "m1e4", 0.5) == pytest.approx(
        md, abs=3 * err)
    assert _stiff_fast_rms(M1E4_NOISE, 20, 1.1, "m1e4", 0.5) > md + 6 * err


def test_the_m3e3_noise_beside_the_registry_is_the_mds_and_the_plain_one_too_loud():
    md, err = MD_M3E3_FAST_RESIDUAL_BESIDE_REGISTRY
    assert _stiff_fast_rms(M3E3_REGISTRY_NOISE, 20, 1.1, "m3e3", 0.5) == pytest.approx(
        md, abs=3 * err)
    assert _stiff_fast_rms(M3E3_NOISE, 20, 1.1, "m3e3", 0.5) > md + 6 * err


def test_the_k16m3e3_noise_beside_the_registry_is_the_mds():
    # the same film on a spring twice as stiff: its own calibration, which a noise of 0.7
    # times its rms misses by far
    md, err = MD_K16M3E3_FAST_RESIDUAL_BESIDE_REGISTRY
    assert _stiff_fast_rms(K16M3E3_REGISTRY_NOISE, 20, 1.1, "k16m3e3", 0.5) == pytest.approx(
        md, abs=3 * err)
    quiet = {**K16M3E3_REGISTRY_NOISE, "velocity_noise": 0.7 * 0.055}
    assert _stiff_fast_rms(quiet, 20, 1.1, "k16m3e3", 0.5) < md - 6 * err


@pytest.mark.parametrize("scale, share, noise, md", [
    ("m25e3", 0.5, M25E3_REGISTRY_NOISE, MD_M25E3_FAST_RESIDUAL_BESIDE_REGISTRY),
    # the softer spring's rung, against replicas of its own viscous share (0.3)
    ("k4m3e3", 0.3, K4M3E3_REGISTRY_NOISE, MD_K4M3E3_FAST_RESIDUAL_BESIDE_REGISTRY)])
def test_the_noise_beside_the_registry_is_the_mds_and_a_louder_one_misses(scale, share,
                                                                          noise, md):
    # each rung its own calibration, which a noise of 1.4 times its rms misses by far
    md, err = md
    assert _stiff_fast_rms(noise, 20, 1.1, scale, share) == pytest.approx(md, abs=3 * err)
    loud = {**noise, "velocity_noise": 1.4 * noise["velocity_noise"]}
    assert _stiff_fast_rms(loud, 20, 1.1, scale, share) > md + 6 * err
