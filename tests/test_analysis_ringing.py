"""Ringing of the wall after a re-stick is not a slip."""
import numpy as np

from analysis.stickslip import detect_slips


def ringing_sawtooth(n_slips=6, period=50.0, fs=100.0, fb=10.0, slip=3.0, ring=35.0,
                     ring_period=8.0, decay=6.0, dt=0.05, noise=0.3, seed=0):
    """Sawtooth whose every re-stick is followed by a decaying oscillation."""
    t = np.arange(0, n_slips * period + period * 0.8, dt)
    f = np.empty_like(t)
    rng = np.random.default_rng(seed)
    for i, ti in enumerate(t):
        k, u = divmod(ti, period)
        stick = period - slip
        if u < stick:  # loading ramp from fb, ringing after the previous slip
            base = fb + (fs - fb) * u / stick
            ringing = ring * np.exp(-u / decay) * np.sin(2 * np.pi * u / ring_period) if k else 0.0
            f[i] = base + ringing
        else:          # the slip: a fast fall from fs to fb
            f[i] = fs - (fs - fb) * (u - stick) / slip
    return t, f + rng.normal(0, noise, t.size)


def test_ringing_bounces_are_not_counted():
    t, f = ringing_sawtooth()
    events = detect_slips(t, f)
    assert events.count == 6
    without_rule = detect_slips(t, f, ringing_window=0)
    assert without_rule.count > 6  # the rule is what removes the bounces


def test_genuine_short_sticks_of_full_size_are_kept():
    # fast cycles: stick only 2x the slip duration, but full-size drops are slips
    t, f = ringing_sawtooth(period=9.0, slip=3.0, ring=0.0)
    assert detect_slips(t, f).count == 6
