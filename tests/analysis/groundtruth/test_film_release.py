"""The fluctuating Newtonian film under a released wall: its noise-free limit and its equilibrium.

Noise-free, the film is the memory Couette film: its wall follows the first-order law
B·v + m_c·a (B = η·A/W, m_c = ρ·A·W/3, ``model_release``) to within the film's memory,
and the release fit reads it as one law with no loop.  With noise, the exact steps keep
the equilibrium: the stationary covariance kT/m of the velocities solves the step's
Lyapunov equation, and sampled releases have every node's kinetic temperature at kT.
"""
import numpy as np
import pytest

from filmfriction.analysis.groundtruth.film_release import (Film, film_release, release_traces,
                                                            transition)
from filmfriction.analysis.groundtruth.release_control import fit_releases, model_release


@pytest.mark.parametrize("slabs", [5, 20])
def test_the_noise_free_film_is_the_first_order_law_to_within_its_memory(slabs):
    film = Film(slabs=slabs)
    q = film_release(2, film, kT=0.0)
    law = model_release(damping=film.damping, comoving_mass=film.comoving_mass, mass=film.mass)
    x = q["wall_position"][0]
    assert np.array_equal(x, q["wall_position"][1])
    # through the first swing (the slip: ~70 τ) the wall is within 1 % of x0 of the law's
    first = q["time"] < 70.0
    assert np.max(np.abs(x - law["wall_position"])[first]) < 0.01 * film.offset
    assert q["wall_velocity"][0].max() == pytest.approx(law["wall_velocity"].max(), rel=0.02)
    fit = fit_releases(release_traces(q) * 2, mass=film.mass)
    o = fit.one_law
    assert o.damping == pytest.approx(film.damping, rel=0.04)
    assert o.comoving_mass == pytest.approx(film.comoving_mass, rel=0.06)
    assert abs(o.kinetic_force) < 0.01 * o.mean_force
    assert abs(fit.loop_step) < 0.01 * o.mean_force


def test_the_exact_step_keeps_the_equilibrium_covariance():
    # a free wall (no spring): the velocities' stationary covariance is kT/m on each node
    film = Film(slabs=6, stiffness=1e-12, offset=0.0)
    kT = 1.5
    phi, _, chol = transition(film, 0.05, kT=kT)
    sigma = np.diag(kT / film.node_masses())
    u = slice(1, None)
    after = phi[u, u] @ sigma @ phi[u, u].T + (chol @ chol.T)[u, u]
    assert np.allclose(after, sigma, rtol=0, atol=1e-9 * sigma.max())
    # and a noise of another size does not
    _, _, hot = transition(film, 0.05, kT=2 * kT)
    wrong = phi[u, u] @ sigma @ phi[u, u].T + (hot @ hot.T)[u, u]
    assert not np.allclose(wrong, sigma, rtol=0.01, atol=0)


def test_sampled_releases_are_at_the_film_s_temperature():
    film = Film(slabs=8, stiffness=1e-12, offset=0.0)
    q = film_release(200, film, kT=1.5, duration=40.0, seed=11)
    m = film.node_masses()
    # per release, the time-mean kinetic temperature; the releases are independent
    wall = m[-1] * np.mean(q["wall_velocity"] ** 2, axis=1)
    slabs = m[:-1] * np.mean(q["slab_velocity"] ** 2, axis=1)
    for temps in [wall] + list(slabs.T):
        se = temps.std(ddof=1) / np.sqrt(temps.size)
        assert se < 0.1 * 1.5          # resolved to 10 % of kT
        assert abs(temps.mean() - 1.5) < 3.5 * se


def test_seeded_and_checked():
    a = film_release(3, seed=7, duration=5.0)
    b = film_release(3, seed=7, duration=5.0)
    assert np.array_equal(a["wall_position"], b["wall_position"])
    assert a["slab_velocity"].shape == (3, 100, 19)
    with pytest.raises(ValueError, match="releases"):
        film_release(0)
    with pytest.raises(ValueError, match="viscosity"):
        Film(viscosity=-1.0)
    with pytest.raises(ValueError, match="kT"):
        transition(Film(), 0.05, kT=-1.0)
