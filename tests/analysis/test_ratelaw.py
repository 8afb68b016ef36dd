"""Rate dependence of the sliding stress: Eyring vs power law, chosen by residuals."""
import numpy as np
import pytest

from filmfriction.analysis.rate_law import choose_rate_law, eyring_fit, power_fit


def test_each_law_recovers_its_own_data_and_is_chosen():
    rate = np.geomspace(1e-3, 1.0, 8)
    ey = 1.5 + 0.2 * np.log(rate / 0.03)
    pw = 4.0 * rate ** 0.35
    f = eyring_fit(rate, ey)
    assert f.parameters["tau1"] == pytest.approx(0.2, rel=1e-10)
    assert f.stress(0.03) == pytest.approx(1.5, rel=1e-10)
    p = power_fit(rate, pw)
    assert p.parameters["exponent"] == pytest.approx(0.35, rel=1e-10)
    assert p.parameters["prefactor"] == pytest.approx(4.0, rel=1e-10)
    assert choose_rate_law(rate, ey).form == "eyring"
    assert choose_rate_law(rate, pw).form == "power"


def test_interval_covers_truth_with_noise_and_widens_far_away():
    rng = np.random.default_rng(3)
    rate = np.geomspace(1e-3, 1e-1, 10)
    err = np.full(rate.size, 0.02)
    hits = 0
    for _ in range(200):
        s = 1.0 + 0.1 * np.log(rate / 1e-2) + rng.normal(0, 0.02, rate.size)
        e = eyring_fit(rate, s, err).extrapolate(1e-4)
        truth = 1.0 + 0.1 * np.log(1e-2)
        hits += e.low <= truth <= e.high
    assert 0.55 < hits / 200 < 0.8          # a 68 % interval
    law = eyring_fit(rate, 1.0 + 0.1 * np.log(rate / 1e-2) + rng.normal(0, 0.02, rate.size), err)
    near, far = law.extrapolate(1e-2), law.extrapolate(1e-9)
    assert (far.high - far.low) > 5 * (near.high - near.low)


def test_spans_decade_flag():
    rate = np.geomspace(1e-3, 1e-1, 5)
    law = power_fit(rate, 2.0 * rate ** 0.5 * (1 + 0.3 * np.array([1, -1, 1, -1, 1])))
    e = law.extrapolate(1e-10)
    assert e.spans_decade and e.high / e.low > 10
    ok = power_fit(rate, 2.0 * rate ** 0.5 * (1 + 0.01 * np.array([1, -1, 1, -1, 1])))
    assert not ok.extrapolate(1e-2).spans_decade


def test_negative_stress_falls_back_to_eyring_and_bad_input():
    rate = np.geomspace(1e-3, 1e-1, 5)
    s = 0.1 * np.log(rate / 1e-2)        # negative at low rate
    assert choose_rate_law(rate, s).form == "eyring"
    with pytest.raises(ValueError, match="at least 3"):
        eyring_fit([1, 2], [1, 2])
    with pytest.raises(ValueError, match="positive"):
        eyring_fit([1, -2, 3], [1, 2, 3])
    with pytest.raises(ValueError, match="equal"):
        eyring_fit([1, 1, 1], [1, 2, 3])


def test_rate_dependence_carries_both_laws_to_klein_rate():
    from filmfriction.analysis.calibration.calibrate import rate_dependence
    from filmfriction.reduced_model.units import OMCTS

    # an Eyring-like film: tau = 1 + 0.2 ln(rate/0.01), eta = tau/rate
    rates = [0.003, 0.01, 0.03, 0.1]
    pts = [(g, (1 + 0.2 * np.log(g / 0.01)) / g, 0.01 / g) for g in rates]
    d = rate_dependence(pts)
    assert d["chosen"] == "eyring"
    assert d["sfb_shear_rate_si"] == pytest.approx(620, rel=0.05)    # Klein: dx0/(tau_s D)
    g = d["sfb_shear_rate"]
    assert g == pytest.approx(OMCTS.from_si(d["sfb_shear_rate_si"], "shear_rate"))
    e = d["eyring"]["stress_at_sfb_rate"]
    assert e["value"] == pytest.approx(1 + 0.2 * np.log(g / 0.01), rel=1e-6)
    assert e["spans_decade"]          # negative: the log law does not reach 6 decades down
    assert d["decades_extrapolated"] > 5
