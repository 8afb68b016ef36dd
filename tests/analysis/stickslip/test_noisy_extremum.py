"""The extremum of a noisy force (``filmfriction.analysis.noisy_extremum``): the bootstrap
removes the fit's lean towards the noise, and the errors of value and time cover the
truth at their nominal rate, for the shapes a slip makes (a smooth turn, a stick ramp
that bends into the slip) under white and correlated noise."""
import math

import numpy as np
import pytest
from scipy.signal import lfilter

from filmfriction.analysis.noise import noise_correlation
from filmfriction.analysis.noisy_extremum import noisy_extremum

T = np.linspace(-1.0, 1.0, 121)
DT = T[1] - T[0]


def turn(t):
    """A smooth turn: top 1.0 at t = 0.1."""
    return 1.0 - 3.0 * (t - 0.1) ** 2


def yield_shape(t):
    """A stick ramp (slope 0.5) that bends into a slip at t = 0 (smooth: the slope is
    continuous); top at t = 0.5/(2·4) = 0.0625, value 0.5·0.0625 − 4·0.0625²."""
    d = np.clip(t, 0.0, None)
    return 0.5 * t - 4.0 * d * d


YIELD_TOP = (0.0625, 0.5 * 0.0625 - 4.0 * 0.0625 ** 2)


def _draws(shape, top, sigma, rho, n):
    rows = []
    for seed in range(n):
        e = np.random.default_rng(seed).normal(0.0, sigma * math.sqrt(1 - rho ** 2), T.size)
        e = lfilter([1.0], [1.0, -rho], e) if rho else e
        g = shape(T) + e
        i = int(np.argmax(g))
        x = noisy_extremum(T, g, i, 0, T.size - 1, sigma, correlation=rho)
        rows.append((x.value - top[1], x.time - top[0], x.value_error, x.time_error,
                     x.value + x.value_bias - top[1]))
    return np.array(rows)


@pytest.mark.parametrize("shape,top", [(turn, (0.1, 1.0)), (yield_shape, YIELD_TOP)],
                         ids=["turn", "ramp-into-slip"])
def test_white_noise_bias_removed_and_errors_cover(shape, top):
    sigma = 0.03
    r = _draws(shape, top, sigma, 0.0, 160)
    n = len(r)
    # the fitted curve's highest point leans towards the noise (upward) ...
    assert r[:, 4].mean() > 0.0
    # ... the corrected value does not, to within 3 standard errors of the mean
    assert abs(r[:, 0].mean()) < 3 * r[:, 0].std() / math.sqrt(n)
    assert abs(r[:, 1].mean()) < 3 * r[:, 1].std() / math.sqrt(n)
    # ±1 error covers at its nominal 68 %, within the binomial scatter of 160 draws
    for err, se in ((0, 2), (1, 3)):
        cover = np.mean(np.abs(r[:, err]) <= r[:, se])
        assert 0.55 <= cover <= 0.82, (err, cover)


def test_correlated_noise_errors_cover():
    # AR(1) with rho = 0.8 per sample: the bootstrap draws noise of the same correlation
    r = _draws(turn, (0.1, 1.0), 0.03, 0.8, 120)
    for err, se in ((0, 2), (1, 3)):
        cover = np.mean(np.abs(r[:, err]) <= r[:, se])
        assert 0.52 <= cover <= 0.85, (err, cover)


def test_the_time_has_an_error_of_its_own():
    g = turn(T) + np.random.default_rng(1).normal(0.0, 0.03, T.size)
    x = noisy_extremum(T, g, int(np.argmax(g)), 0, T.size - 1, 0.03)
    assert 0.2 * DT < x.time_error < 20 * DT
    assert x.shape in ("turn", "slip-after", "slip-before")


def test_the_same_in_any_units_and_the_same_every_time():
    g = yield_shape(T) + np.random.default_rng(4).normal(0.0, 0.02, T.size)
    i = int(np.argmax(g))
    a = noisy_extremum(T, g, i, 0, T.size - 1, 0.02)
    b = noisy_extremum(T * 1e-3 + 5.0, g * 1e-6, i, 0, T.size - 1, 0.02e-6)
    assert noisy_extremum(T, g, i, 0, T.size - 1, 0.02) == a
    assert b.value == pytest.approx(a.value * 1e-6, rel=1e-9)
    assert b.time == pytest.approx(a.time * 1e-3 + 5.0, rel=1e-12)
    assert b.value_error == pytest.approx(a.value_error * 1e-6, rel=1e-6)
    assert b.time_error == pytest.approx(a.time_error * 1e-3, rel=1e-6)


@pytest.mark.parametrize("rho", [0.0, 0.5, 0.9])
def test_noise_correlation_of_ar1_noise(rho):
    e = np.random.default_rng(3).normal(0.0, 1.0, 20000)
    ar = lfilter([1.0], [1.0, -rho], e) * math.sqrt(1 - rho ** 2) if rho else e
    # on a sawtooth (ramps and drops): the ramps' residuals carry the noise's correlation
    t = np.arange(ar.size, dtype=float)
    saw = 50.0 * ((t / 400.0) % 1.0)
    assert noise_correlation(saw + ar, 1.0) == pytest.approx(rho, abs=0.05)
