"""The force at changes of the sliding plane (analysis/structure/plane_hops.py), on slips of
known law: a force that steps at the changes, one that does not, and a registry feature
phase-locked with the changes (which the phase-matched null must catch)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from filmfriction.analysis.structure.plane_hops import hop_force, plane_changes

LAMBDA = 1.1


def _slips(rng, *, step=0.0, registry_spike=0.0, locked=False, n=30, noise=3.0):
    """n slips of 6 σ: F = 20 + 40·v + 8·sin(2πx/λ) + noise, plus ``step`` within 0.1 σ of
    each change of plane, plus ``registry_spike`` within 0.1 σ of a fixed phase of every
    period (a sharp registry force two harmonics do not take); changes about every 1.5 σ,
    at that phase when ``locked``."""
    out = []
    for _ in range(n):
        x = np.linspace(0.0, 6.0, 1200)
        v = 0.3 * np.sin(np.pi * x / 6.0)
        if locked:
            periods = np.sort(rng.choice(np.arange(1, 5), 2, replace=False))
            hops = (periods + 0.3) * LAMBDA
        else:
            hops = np.sort(rng.uniform(0.6, 5.4, 4))
        f = 20 + 40 * v + 8 * np.sin(2 * np.pi * x / LAMBDA) + rng.normal(0, noise, x.size)
        f += step * (np.abs(x[:, None] - hops).min(axis=1) < 0.1)
        phase = (x / LAMBDA - 0.3 + 0.5) % 1.0 - 0.5
        f += registry_spike * (np.abs(phase * LAMBDA) < 0.1)
        out.append((x, f, v, hops))
    return out


def test_a_force_that_steps_at_the_changes_reads_its_step_beyond_both_nulls():
    r = hop_force(_slips(np.random.default_rng(1), step=6.0), registry_period=LAMBDA,
                  draws=100)
    assert r.changes == 120 and r.slips == 30
    assert r.bump == pytest.approx(6.0, abs=3 * r.stderr) and r.stderr < 1.0
    assert r.random.share_at_or_above == 0.0 and r.phase_matched.share_at_or_above == 0.0
    # the smooth law is recovered beside it (F_k, B, the first harmonic's sine)
    assert r.law[0] == pytest.approx(20.0, abs=1.5) and r.law[1] == pytest.approx(40.0, abs=6)
    assert r.law[2] == pytest.approx(8.0, abs=0.5)


def test_no_step_at_the_changes_reads_none():
    r = hop_force(_slips(np.random.default_rng(2)), registry_period=LAMBDA, draws=100)
    assert abs(r.bump) < 3 * r.stderr
    assert r.random.share_at_or_above > 0.02 and r.phase_matched.share_at_or_above > 0.02


def test_a_registry_force_locked_with_the_changes_reads_in_the_phase_matched_null():
    # the changes sit at one phase of the walls' lattice where the registry force has a
    # sharp peak: the changes' bump is that peak, beyond the uniform null, but positions
    # of the same phase without a change read it too (the two harmonics take most of the
    # peak; what they leave is the bump)
    r = hop_force(_slips(np.random.default_rng(3), registry_spike=6.0, locked=True),
                  registry_period=LAMBDA, draws=100)
    assert r.bump > 5 * r.stderr and r.random.share_at_or_above < 0.01
    assert r.phase_matched.mean == pytest.approx(r.bump, abs=3 * r.phase_matched.sd)
    assert r.phase_matched.share_at_or_above > 0.05


def test_refusals_and_plane_changes():
    with pytest.raises(ValueError, match="registry_period"):
        hop_force(_slips(np.random.default_rng(0), n=2), registry_period=0.0)
    with pytest.raises(ValueError, match="near"):
        hop_force(_slips(np.random.default_rng(0), n=2), registry_period=LAMBDA, near=0.4)
    with pytest.raises(ValueError, match="2 or more"):
        hop_force(_slips(np.random.default_rng(0), n=1), registry_period=LAMBDA)
    # plane 1 from frame 3 (held); a one-frame flicker back to 0 at 7 is not a change; plane 2
    # from frame 11
    assert plane_changes([0, 0, 0, 1, 1, 1, 1, 0, 1, 1, 1, 2, 2, 2, 2], 3) == [3, 11]
    assert plane_changes([0, 1, 0, 1, 0, 1], 2) == []


def test_the_bumps_error_covers_the_true_step_at_the_nominal_rate():
    # 150 realisations of 12 slips whose force steps by 4 at each change, the noise
    # correlated within a slip (AR(1), 0.9 a sample) and an offset per slip: the
    # jackknife's ± 1 and ± 1.96 errors cover the step in ≈ 68 % and 95 % of them
    # (binomial sd 3.8 % and 1.8 % at 150); no bias beyond a third of an error
    z = []
    for k in range(150):
        rng = np.random.default_rng(500 + k)
        slips = []
        for _ in range(12):
            x = np.linspace(0.0, 6.0, 400)
            v = 0.3 * np.sin(np.pi * x / 6.0)
            hops = np.sort(rng.uniform(0.6, 5.4, 4))
            e = lfilter([np.sqrt(1 - 0.81)], [1.0, -0.9], rng.normal(0.0, 3.0, x.size))
            f = 20 + 40 * v + 8 * np.sin(2 * np.pi * x / LAMBDA) + e + rng.normal(0.0, 2.0)
            f += 4.0 * (np.abs(x[:, None] - hops).min(axis=1) < 0.1)
            slips.append((x, f, v, hops))
        r = hop_force(slips, registry_period=LAMBDA, draws=2, seed=k)
        z.append((r.bump - 4.0) / r.stderr)
    z = np.asarray(z)
    assert 0.57 <= np.mean(np.abs(z) < 1.0) <= 0.79
    assert 0.90 <= np.mean(np.abs(z) < 1.96) <= 0.99
    assert abs(z.mean()) < 0.3
