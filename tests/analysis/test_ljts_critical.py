"""benchmarks/ljts_critical.py's estimator on coexistence densities with known answers: T_c and
ρ_c come back within their error bars, with and without noise, and too few temperatures are
refused (its measurement: docs/results/wall-load.md, "The state point")."""
import numpy as np
import pytest

TRUE = {"T_c": 1.08, "rho_c": 0.32, "A": 0.75, "B": 0.20}
TEMPS = np.array([0.70, 0.75, 0.80, 0.85, 0.90, 0.95, 1.00])


def _densities(T, beta=0.325):
    dt = TRUE["T_c"] - T
    mid = TRUE["rho_c"] + TRUE["B"] * dt
    half = 0.5 * TRUE["A"] * dt ** beta
    return mid + half, mid - half


def test_noise_free_densities_give_back_tc_and_rhoc(benchmark_module):
    m = benchmark_module("ljts_critical")
    rl, rv = _densities(TEMPS)
    err = np.full(TEMPS.size, 1e-3)
    f = m.fit_critical(TEMPS, rl, rv, err, err)
    for key in TRUE:
        assert f[key] == pytest.approx(TRUE[key], abs=1e-5), key
    assert f["dT_c"] > 0 and f["drho_c"] > 0 and f["chi2"] < 1e-6


def test_noisy_densities_give_back_tc_and_rhoc_within_their_errors(benchmark_module):
    m = benchmark_module("ljts_critical")
    rng = np.random.default_rng(7)
    T = np.repeat(TEMPS, 2)                                  # two seeds a temperature
    rl, rv = _densities(T)
    dl, dv = np.full(T.size, 0.003), np.full(T.size, 0.001)
    hits = {"T_c": 0, "rho_c": 0}
    trials = 40
    for _ in range(trials):
        f = m.fit_critical(T, rl + dl * rng.standard_normal(T.size),
                           rv + dv * rng.standard_normal(T.size), dl, dv)
        for key in hits:
            assert abs(f[key] - TRUE[key]) < 4 * f["d" + key], (key, f)
            hits[key] += abs(f[key] - TRUE[key]) < f["d" + key]
        assert 0.0005 < f["dT_c"] < 0.02                    # an error bar of the noise's size
    # the one-sigma bars cover the truth about 68 % of the time, not all or none of it
    for key, n in hits.items():
        assert 0.45 * trials <= n <= 0.95 * trials, (key, n)


def test_fewer_than_three_temperatures_are_refused(benchmark_module):
    m = benchmark_module("ljts_critical")
    rl, rv = _densities(TEMPS[:2])
    with pytest.raises(ValueError, match="at least 3"):
        m.fit_critical(TEMPS[:2], rl, rv, [0.01, 0.01], [0.01, 0.01])
    # two seeds at each of two temperatures are still two temperatures
    T = np.repeat(TEMPS[:2], 2)
    rl, rv = _densities(T)
    with pytest.raises(ValueError, match="at least 3"):
        m.fit_critical(T, rl, rv, np.full(4, 0.01), np.full(4, 0.01))


def test_bad_errors_and_swapped_phases_are_refused(benchmark_module):
    m = benchmark_module("ljts_critical")
    rl, rv = _densities(TEMPS)
    ok = np.full(TEMPS.size, 0.01)
    with pytest.raises(ValueError, match="> 0"):
        m.fit_critical(TEMPS, rl, rv, ok, np.zeros(TEMPS.size))
    with pytest.raises(ValueError, match="not a coexistence"):
        m.fit_critical(TEMPS, rv, rl, ok, ok)
