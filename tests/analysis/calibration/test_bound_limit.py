"""A calibration parameter pinned at its bound: its one-sided 95 % upper limit.

Klein's slip (F_k = 0, a viscous film freezing at F_b) fitted as ``filmfriction calibrate``
does: F_k ends at its bound 0 with no standard error, and the fit's χ² profile gives the
largest F_k the slips allow.  Its coverage over many traces (the limit at or above the
truth, also where the truth is off the bound and the fit pinned it):
``benchmarks/calibration_errors.py`` (docs/results/validation.md).
"""
import math

import numpy as np
import pytest

from filmfriction.analysis.calibration.rundata import load_run
from filmfriction.analysis.calibration.slipfit import fit_slip_law
from filmfriction.analysis.groundtruth.calibration_sets import WALLS, klein_slip, write_run
from filmfriction.analysis.groundtruth.synthetic import klein_trace


def _fit(tmp_path, name, noise):
    w = WALLS["si"]
    kw = klein_slip(np.random.default_rng(0), w["k"], w["m"], w["fs"])
    drop = kw["static_force"] - kw["backward_force"]
    tr = klein_trace(noise=noise * drop, seed=5, **kw)
    write_run(tmp_path / name, w, tr["time"], tr["spring_force"], tr["drive_position"],
              kw["drive_velocity"])
    return fit_slip_law(load_run(tmp_path / name), jackknife=False), drop


def test_a_kinetic_force_at_its_bound_has_an_upper_limit_that_scales_with_the_noise(tmp_path):
    quiet, drop = _fit(tmp_path, "quiet", 0.005)
    loud, _ = _fit(tmp_path, "loud", 0.02)
    for fit in (quiet, loud):
        fk = fit.kinetic_force
        assert fk.at_bound and fk.value == 0.0 and math.isnan(fk.stderr)
        assert 0 < fk.limit < 0.05 * drop, (fk.limit, drop)
        assert "95 %, one-sided" in fk.method
        assert fk.as_dict()["upper_limit_95"] == pytest.approx(fk.limit)
    # Δχ² in units of the residual variance: a limit that scales as the noise does (the same
    # noise pattern four times larger), not one fixed by the fit's tolerance
    assert 2.5 < loud.kinetic_force.limit / quiet.kinetic_force.limit < 6.0
    # a parameter off its bound has no limit
    assert not quiet.film_damping.at_bound and math.isnan(quiet.film_damping.limit)
