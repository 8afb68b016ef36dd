"""Ground truth for the slip detector on slips of irregular size under an MD wall's noise.

Exact traces of a driven Coulomb block whose static force differs from slip to slip
(``synthetic.irregular_coulomb_trace``: K = 8, M = 1e5, V = 0.0025, F_k = 25, F_s drawn
from 32-55, so drops of 14-60 at irregular times, the sfb-thick-stiff scene's scale) plus
the noise of a wall ringing on the film (``synthetic.ringing_noise``: rms 1.5, period
200 τ, decaying in 400 τ, the wiggles of that scene's traces), sampled every 0.25 τ as
the MD writes them: smooth at its sampling, so the detector's local noise estimate is
blind and the threshold comes from the noise at its own time scale.  Measured at the
time of writing: 273 of the 280 slips of 20 traces found, none extra; none in 40 traces
of the noise alone (flat or loading).  The earlier rule (k times the cycle-to-cycle
noise, re-estimated from the slips it kept) found 220 of the 280: each missed slip raised
the next estimate.

Slips inside slips (``merged``): pairs of slips with a stick between them that reloads the
spring by 6-10 ε/σ, below h (17-22 here): of 140 true slips in 10 traces the scan alone
finds 59, with the split at re-sticks inside its slips (the loading rate K·V given, as the
analysis gives it) 117, none extra, their re-stick forces within the noise (measured at the
time of writing); a bump rising at 5x the reload rate (a wall ringing back) is not split;
white noise on model slips is never split.
"""
import numpy as np
import pytest

from filmfriction.analysis.groundtruth import synthetic
from filmfriction.analysis.stickslip import detect_slips

DT = 0.25
KV = 8.0 * 0.0025      # the drive's loading rate K·V of these traces (ε/σ per τ)
NOISE = {"rms": 1.5, "period": 200.0, "decay": 400.0, "dt": DT}


def irregular(seed):
    rng = np.random.default_rng(seed)
    tr = synthetic.irregular_coulomb_trace(rng.uniform(32.0, 55.0, 14), kinetic_force=25.0,
                                           stiffness=8.0, mass=1.0e5, drive_velocity=0.0025,
                                           dt=DT)
    noise = synthetic.ringing_noise(tr["time"].size, seed=seed + 100, **NOISE)
    return tr, tr["spring_force"] + noise


def test_the_exact_trace_is_the_closed_form():
    tr = synthetic.irregular_coulomb_trace([40.0, 30.0, 45.0], kinetic_force=25.0,
                                           stiffness=8.0, mass=1.0e5, drive_velocity=0.0025,
                                           dt=DT)
    t, f = tr["time"], tr["spring_force"]
    # the force at each yield is its static force; each re-stick is about 2 F_k − F_s
    for ty, fs in zip(tr["yield_time"], tr["static_force"]):
        assert f[np.searchsorted(t, ty) - 1] == pytest.approx(fs, abs=8.0 * 0.0025 * DT * 2)
    np.testing.assert_allclose(tr["backward_force"], 50.0 - tr["static_force"], atol=0.5)
    # the wall is at rest between slips and never moves backwards
    assert np.all(tr["wall_velocity"] >= -1e-9)
    ev = detect_slips(t, f)
    assert ev.count == 3


def test_slips_of_irregular_size_are_all_found_under_ringing_noise():
    found = made = extra = 0
    for seed in range(20):
        tr, f = irregular(seed)
        t = tr["time"]
        ev = detect_slips(t, f)
        # a true yield is found when a detected one lies within 300 τ of it (a slip lasts
        # π √(M/K) ≈ 350 τ)
        hit = sum(bool(np.any(np.abs(t[ev.yield_index] - y) < 300.0)) for y in tr["yield_time"])
        found += hit
        made += tr["yield_time"].size
        extra += ev.count - hit
    assert extra == 0
    assert found >= 0.95 * made, (found, made)        # 273 of 280 measured


@pytest.mark.parametrize("loading", [0.0, 0.02], ids=["flat", "loading"])
def test_the_noise_alone_gives_no_slip(loading):
    t = np.arange(0.0, 23000.0, DT)
    counts = [detect_slips(t, 30.0 + loading * t
                           + synthetic.ringing_noise(t.size, seed=s, **NOISE)).count
              for s in range(20)]
    assert sum(counts) == 0, counts


def test_a_small_slip_soon_after_a_slow_one_is_a_slip_not_ringing():
    # a slow slip (≈ 370 τ) from 50 to 14, then after 1 000 τ of stick (< 3 slip durations)
    # a slip of less than half its drop: the drive reloads it at K·V, so it is kept
    tr = synthetic.irregular_coulomb_trace([50.0, 34.0, 45.0], kinetic_force=32.0,
                                           stiffness=8.0, mass=1.0e5, drive_velocity=0.0025,
                                           dt=DT)
    drops = tr["static_force"] - tr["backward_force"]
    stick = tr["yield_time"][1] - tr["restick_time"][0]
    slip = tr["restick_time"][0] - tr["yield_time"][0]
    assert stick < 3.0 * slip and drops[1] < 0.5 * drops[0]
    assert detect_slips(tr["time"], tr["spring_force"]).count == 3


# ---- slips inside slips: a short stick that reloads the spring by less than h -------------

#: The heavy slider's pairs (K = 8, M = 1e5, V = 0.0025): yields, re-sticks, the second
#: slip's depth below the re-stick, and the ringing noise; :data:`M1E4_PAIRS` the M = 1e4
#: scale's (below).
PAIRS = {"pairs": 7, "static": (40.0, 55.0), "restick": (20.0, 30.0), "below": (5.0, 15.0),
         "mass": 1.0e5, "drive_velocity": 0.0025}


def merged(seed, rises=(6.0, 10.0), scale=None):
    """Pairs of slips: a slip from F_s (``static``) re-sticks at m (``restick``), sticks
    while the drive reloads the spring by r (drawn from ``rises``, below the detector's h of
    about 17-20 here), then slips on from m + r to ``below`` under m (its own kinetic force),
    and sticks until the next pair.  Exact (per-slip kinetic forces) plus the ringing noise
    (``NOISE``; ``scale``: the keys of :data:`PAIRS` and the noise of another scale)."""
    sc = scale or dict(PAIRS, noise=NOISE)
    rng = np.random.default_rng(seed)
    static, kinetic = [], []
    for _ in range(sc["pairs"]):
        fs, m = rng.uniform(*sc["static"]), rng.uniform(*sc["restick"])
        r, below = rng.uniform(*rises), rng.uniform(*sc["below"])
        static += [fs, m + r]
        kinetic += [(fs + m) / 2.0, (2.0 * m + r - below) / 2.0]
    tr = synthetic.irregular_coulomb_trace(static, kinetic_force=kinetic, stiffness=8.0,
                                           mass=sc["mass"], drive_velocity=sc["drive_velocity"],
                                           dt=DT)
    return tr, tr["spring_force"] + synthetic.ringing_noise(tr["time"].size, seed=seed + 100,
                                                            **sc["noise"])


def found_yields(t, yields, truth, within=150.0):
    """How many true yields have a detected one within ``within`` (a slip lasts ≈ 350 τ)."""
    return sum(bool(np.any(np.abs(t[yields] - y) < within)) for y in truth)


def test_slips_merged_by_the_threshold_are_split_where_the_wall_stopped():
    found = found_unsplit = made = extra = 0
    restick_errors = []
    for seed in range(10):
        tr, f = merged(seed)
        t = tr["time"]
        ev = detect_slips(t, f, loading_rate=KV)        # as the analysis calls it: K·V known
        hit = found_yields(t, ev.yield_index, tr["yield_time"])
        found += hit
        extra += ev.count - hit
        assert ev.inner_resticks >= 4, (seed, ev.inner_resticks)     # 5-6 measured, of 7
        found_unsplit += found_yields(t, detect_slips(t, f, restick_fraction=0).yield_index,
                                      tr["yield_time"])
        made += tr["yield_time"].size
        assert ev.threshold > 10.0                     # every inner rise is below h
        # each re-stick found: its force is the true F_b within the noise (rms 1.5)
        for ts, fb in zip(tr["restick_time"], tr["backward_force"]):
            near = np.abs(t[ev.stick_index] - ts)
            if near.min() < 150.0:
                restick_errors.append(f[ev.stick_index[np.argmin(near)]] - fb)
    assert extra == 0
    assert found_unsplit <= 0.5 * made, (found_unsplit, made)
    assert found >= 0.8 * made, (found, made)              # 117 of 140 measured
    e = np.abs(restick_errors)
    assert len(e) >= found - 5 and np.median(e) < 2.5 and e.max() < 6.0, (len(e), np.median(e), e.max())


def test_the_split_is_the_same_in_other_units():
    # seconds and newtons (an SFB trace's numbers): the same slips, split at the same samples
    tr, f = merged(3)
    t = tr["time"]
    lj = detect_slips(t, f, loading_rate=KV)
    si = detect_slips(t * 2.0e-12, f * 3.0e-11, loading_rate=KV * 3.0e-11 / 2.0e-12)
    assert lj.inner_resticks >= 4 and si.inner_resticks == lj.inner_resticks
    np.testing.assert_array_equal(si.yield_index, lj.yield_index)
    np.testing.assert_array_equal(si.stick_index, lj.stick_index)


def test_white_noise_on_model_slips_is_never_split():
    # 1 % white noise on random Coulomb blocks: a spike of 3 σ just after a rounded yield
    # rises at the loading rate over one sample; the noise floor of the rise (k σ over the
    # slips' samples, about h on white noise) keeps it from splitting the slip
    from filmfriction.analysis.groundtruth import cases as gt

    rng = np.random.default_rng(11)
    for k in range(12):
        case = gt.random_case("coulomb", rng, samples_per_slip=50, noise=0.01, seed=k)
        cols, params = gt.sample(case)
        ev = detect_slips(cols["time"], cols["spring_force"])
        assert ev.inner_resticks == 0, case.label()


def test_a_bounce_inside_a_slip_is_not_a_restick():
    # a slip (F_s 50, F_k 32) whose wall rings back near its end: a bump of 10 ε/σ rising in
    # ≈ 40 τ, five times the drive's reload rate.  Under the ringing noise h is above 10, so
    # the bump is inside the slip the scan finds; the wall did not stop, so it stays whole.
    # Without the rate test the same bump is taken for a re-stick (each seed).

    def bumped(seed):
        tr = synthetic.irregular_coulomb_trace([50.0, 45.0, 52.0], kinetic_force=32.0,
                                               stiffness=8.0, mass=1.0e5,
                                               drive_velocity=0.0025, dt=DT)
        t = tr["time"]
        slip = (t > tr["yield_time"][0]) & (t < tr["restick_time"][0])
        lowest = t[slip][np.argmin(tr["spring_force"][slip])]     # the slip's force minimum
        bump = 10.0 * np.exp(-0.5 * ((t - lowest + 60.0) / 15.0) ** 2)
        return tr, t, tr["spring_force"] + bump + synthetic.ringing_noise(t.size, seed=seed,
                                                                          **NOISE)
    for seed in range(5):
        tr, t, f = bumped(seed)
        ev = detect_slips(t, f, loading_rate=KV)
        assert ev.threshold > 10.0
        assert ev.inner_resticks == 0
        assert found_yields(t, ev.yield_index, tr["yield_time"]) == ev.count == 3
    for seed in range(5):
        tr, t, f = bumped(seed)
        assert detect_slips(t, f, loading_rate=KV, restick_rate=1e9).inner_resticks >= 1, seed


def test_a_restick_rate_that_is_not_positive_is_refused():
    tr, f = merged(0)
    with pytest.raises(ValueError, match="restick_rate"):
        detect_slips(tr["time"], f, loading_rate=KV, restick_rate=0.0)


# ---- the same at the M = 1e4 scale of the K = 8 film, under that scale's noise -------------
# K = 8, M = 1e4, V = 0.0079 (slips of π √(M/K) ≈ 111 τ).  The noise: the wall ringing at
# 50 τ, decaying in 110 τ (the autocorrelation of the M = 1e4 runs' sticks about their
# ramps: lowest at 25 τ, back to 0.66 at 50 τ, 0.37 at 100 τ), rms 1.4, which gives the
# detector the readings it takes from those runs (increment noise 1.9, cycle noise 2.0, h
# 15-17; on the runs 1.3-2.0, 1.2-2.7, 10-16).  Measured at the time of writing: of the 74
# reloads of h/3-h/2 in the 10 traces below 61 found (the scan alone: none; with the rise
# at h/2, 54), none extra; 1 split among the 320 plain slips.  The M = 1e4 runs' own splits
# reload at 0.9-1.9 K·V, 10 of their 29 by h/3-h/2 (docs/results/mass-ladder.md).
KV4 = 8.0 * 0.0079
NOISE4 = {"rms": 1.4, "period": 50.0, "decay": 110.0, "dt": DT}


#: The M = 1e4 scale's pairs: the runs' F_s and F_b, eight pairs.
M1E4_PAIRS = {"pairs": 8, "static": (37.0, 59.0), "restick": (13.0, 24.0), "below": (2.0, 8.0),
              "mass": 1.0e4, "drive_velocity": 0.0079, "noise": NOISE4}


def merged4(seed, rises):
    return merged(seed, rises, scale=M1E4_PAIRS)


def test_reloads_of_a_third_to_half_of_h_are_found_at_the_m1e4_scale():
    found = made = extra = unsplit = 0
    for seed in range(10):
        tr, f = merged4(seed, (5.5, 8.5))
        t = tr["time"]
        ev = detect_slips(t, f, loading_rate=KV4)
        assert 14.0 < ev.threshold < 20.0, ev.threshold          # the runs' h is 10-16
        inner = tr["yield_time"][1::2]
        rise = tr["static_force"][1::2] - tr["backward_force"][0::2]
        band = (rise > ev.threshold / 3.0) & (rise < ev.threshold / 2.0)
        found += found_yields(t, ev.yield_index, inner[band], within=60.0)
        unsplit += found_yields(t, detect_slips(t, f, restick_fraction=0).yield_index,
                                inner[band], within=60.0)
        made += int(band.sum())
        extra += ev.count - found_yields(t, ev.yield_index, tr["yield_time"], within=60.0)
    assert made >= 60, made
    assert unsplit == 0
    assert found >= 0.75 * made, (found, made)        # 61 of 74 measured
    assert extra <= 1


def test_plain_slips_are_hardly_ever_split_at_the_m1e4_scale():
    splits = extra = 0
    for seed in range(20):
        rng = np.random.default_rng(seed)
        static, backward = rng.uniform(37.0, 59.0, 16), rng.uniform(8.0, 24.0, 16)
        tr = synthetic.irregular_coulomb_trace(static, kinetic_force=(static + backward) / 2.0,
                                               stiffness=8.0, mass=1.0e4,
                                               drive_velocity=0.0079, dt=DT)
        t = tr["time"]
        f = tr["spring_force"] + synthetic.ringing_noise(t.size, seed=seed + 100, **NOISE4)
        ev = detect_slips(t, f, loading_rate=KV4)
        splits += ev.inner_resticks
        extra += ev.count - found_yields(t, ev.yield_index, tr["yield_time"], within=60.0)
    assert extra == 0
    assert splits <= 3, splits          # of 320 slips; 1 measured
