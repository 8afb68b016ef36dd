"""Klein's slip equation tested on slips: F_film = F_k + B·v recovered from known models."""
import math

import numpy as np
import pytest

from filmfriction.analysis.slip_law import film_force, fit_film_force
from filmfriction.reduced_model import SpringBlock, laws


def _run(kinetic, damping, *, static=1.0, mass=1.0, k=1.0, v=0.01, duration=800.0):
    r = SpringBlock(mass=mass, stiffness=k, drive_velocity=v, damping=damping,
                    law=laws.Coulomb(static=static, kinetic=kinetic)).simulate(duration)
    return r, r.cycles()


@pytest.mark.parametrize("kinetic, damping, verdict", [
    (0.4, 0.5, "mixed"),      # both terms carry a share
    (0.5, 0.02, "kinetic"),   # a tiny B: share well below 0.2
    (0.02, 1.2, "viscous"),   # nearly all the film force is B·v
])
def test_recovers_known_kinetic_force_and_damping(kinetic, damping, verdict):
    r, tab = _run(kinetic, damping)
    assert len(tab) >= 3
    fit = fit_film_force(r.t, r.spring_force, r.v, tab[1:], mass=1.0, drive_velocity=0.01)
    assert fit.kinetic_force == pytest.approx(kinetic, abs=2e-3)
    assert fit.damping == pytest.approx(damping, rel=5e-3, abs=1e-3)
    assert fit.verdict == verdict, fit.reason
    assert np.all(np.isfinite(fit.per_slip_damping))


def test_mount_dashpot_is_taken_off_the_film():
    # the block's damper D = B + d acts on v; a mount dashpot d acts on v − V, so the
    # film's law is F_k + d·V + B·v
    b, d, v = 0.3, 0.2, 0.01
    r, tab = _run(0.4, b + d, v=v)
    fit = fit_film_force(r.t, r.spring_force, r.v, tab[1:], mass=1.0, drive_velocity=v,
                       mount_damping=d)
    assert fit.damping == pytest.approx(b, rel=1e-2)
    assert fit.kinetic_force == pytest.approx(0.4 + d * v, abs=2e-3)


def test_noise_gives_errors_that_cover_the_truth():
    rng = np.random.default_rng(7)
    r, tab = _run(0.4, 0.5, duration=2000.0)
    f = r.spring_force + rng.normal(0, 0.01, r.spring_force.size)
    fit = fit_film_force(r.t, f, r.v, tab[1:], mass=1.0, drive_velocity=0.01)
    assert fit.damping_stderr > 0 and fit.kinetic_force_stderr > 0
    assert abs(fit.damping - 0.5) < 4 * fit.damping_stderr + 1e-3
    assert abs(fit.kinetic_force - 0.4) < 4 * fit.kinetic_force_stderr + 1e-3


def test_inertia_matters():
    # leaving the wall's inertia in the film force (mass → tiny) biases B: the fit uses M
    r, tab = _run(0.4, 0.5, mass=5.0)
    good = fit_film_force(r.t, r.spring_force, r.v, tab[1:], mass=5.0, drive_velocity=0.01)
    bad = fit_film_force(r.t, r.spring_force, r.v, tab[1:], mass=1e-6, drive_velocity=0.01)
    assert good.damping == pytest.approx(0.5, rel=1e-2)
    assert abs(bad.damping - 0.5) > 0.05


def test_no_slips_and_bad_input():
    r, tab = _run(0.4, 0.5)
    fit = fit_film_force(r.t, r.spring_force, r.v, tab[0:0], mass=1.0)
    assert fit.verdict == "none" and math.isnan(fit.damping)
    with pytest.raises(ValueError, match="mass"):
        film_force([0, 1], [0, 0], [0, 0], mass=0.0)
    with pytest.raises(ValueError, match="min_velocity_fraction"):
        fit_film_force(r.t, r.spring_force, r.v, tab, mass=1.0, min_velocity_fraction=1.5)
