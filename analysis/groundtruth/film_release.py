"""A wall released on a fluctuating Newtonian film: the slip law's null with the MD's own noise.

The film between a still bottom wall (z = 0) and the released top wall (z = W) is cut
into n slabs of thickness h = W/n.  Node k = 1 … n sits at z = k·h and carries the film
between (k − ½)h and (k + ½)h, mass m = ρ·A·h; node n is the wall, mass M + ρ·A·h/2
(the half slab below the bottom wall's node moves with it).  Neighbouring nodes are
joined by the film's shear between them, a dashpot of

    c = η·A/h

(the Couette stress η·∂u/∂z over the area A), and each dashpot carries the
fluctuation–dissipation partner of its drag, a random force ζ with
⟨ζ(t)ζ(t')⟩ = 2·c·kT·δ(t − t'), equal and opposite on its two nodes.  The wall feels
the spring K(x0 − x) and, optionally, a constant kinetic force −F_k.  This is
ρ·∂u/∂t = η·∂²u/∂z² (momentum diffusion) discretised, with Landau–Lifshitz's random
stress: the thermal Navier–Stokes film in one dimension.

Its force on a wall that moves slowly is, to first order in the frequency,
B·v + m_c·a with

    B = η·A/W,        m_c = ρ·A·W/3

(the Couette damping, and a third of the film carried along: the slowest of the
film's modes relaxes in W²/(π²ν), ν = η/ρ; see
:func:`~filmfriction.analysis.groundtruth.release_control.couette_comoving_mass`), and no
loop: a Newtonian film has no yield.  Released replicas (independent seeds, the
velocities drawn from the equilibrium, the wall at x = 0) are the liquid-release scene's
MD releases with the law known; the noise-free limit (kT = 0) is the film's memory alone.

The state y = (x, u_1 … u_n) obeys the linear equation dy = (A·y + b) dt + G·dW, which
is stepped exactly over each sampling interval (:func:`transition`: y ← Φ·y + φ + ξ,
Φ = exp(A·Δt), ξ Gaussian with the covariance ∫₀^Δt e^{As} G·Gᵀ e^{Aᵀs} ds, by Van
Loan's block exponential): the equilibrium is kept exactly (each node's kinetic
temperature is kT) and no time step enters but the sampling's.

Example
-------
Two noise-free releases are one and the same; with noise they differ by the film's
thermal force:

>>> q = film_release(2, kT=0.0, duration=20.0)
>>> q["wall_position"].shape, bool(np.allclose(*q["wall_position"]))
((2, 400), True)
>>> q = film_release(2, seed=3, duration=20.0)
>>> bool(np.allclose(*q["wall_position"]))
False
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

__all__ = ["Film", "transition", "film_release", "release_traces", "peak_time", "held_until"]


@dataclass(frozen=True)
class Film:
    """A Newtonian film under a wall on a spring (LJ units by default: the
    ``liquid-release`` scene's film, η from ``filmfriction viscosity`` at its state point).

    Attributes
    ----------
    viscosity, density : float
        η and ρ (mass per volume).
    area, width : float
        A and W = D + 2b, the width of the velocity profile.
    mass, stiffness, offset : float
        The wall's M, the spring's K and its stretch x0 at the release.
    slabs : int
        n, the film's slabs (the wall the top node).
    """

    viscosity: float = 0.783
    density: float = 0.485
    area: float = 94.3
    width: float = 6.1
    mass: float = 500.0
    stiffness: float = 1.0
    offset: float = 20.0
    slabs: int = 20

    def __post_init__(self):
        for name in ("viscosity", "density", "area", "width", "mass", "stiffness"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} = {getattr(self, name)!r}: must be positive")
        if not (isinstance(self.slabs, int) and self.slabs >= 1):
            raise ValueError(f"slabs = {self.slabs!r}: must be an integer >= 1")

    @property
    def damping(self) -> float:
        """B = η·A/W, the Couette damping."""
        return self.viscosity * self.area / self.width

    @property
    def comoving_mass(self) -> float:
        """m_c = ρ·A·W/3, the film's mass carried with a slowly moving wall."""
        return self.density * self.area * self.width / 3

    def node_masses(self) -> np.ndarray:
        """Masses of the nodes 1 … n (the last the wall with its half slab)."""
        h = self.width / self.slabs
        m = np.full(self.slabs, self.density * self.area * h)
        m[-1] = self.mass + self.density * self.area * h / 2
        return m


def _generator(film: Film, kT: float, kinetic_force: float):
    """A, b, G of dy = (A·y + b) dt + G·dW for y = (x, u_1 … u_n)."""
    n, m = film.slabs, film.node_masses()
    c = film.viscosity * film.area / (film.width / n)
    a = np.zeros((n + 1, n + 1))
    a[0, n] = 1.0                                   # dx/dt = u_n, the wall's velocity
    g = np.zeros((n + 1, n))                        # column k: the dashpot below node k + 1
    for k in range(n):                              # node k + 1 (row k + 1), below it node k
        a[k + 1, k + 1] -= c / m[k]
        g[k + 1, k] = 1.0 / m[k]
        if k > 0:
            a[k + 1, k] += c / m[k]
            a[k, k + 1] += c / m[k - 1]
            a[k, k] -= c / m[k - 1]
            g[k, k] = -1.0 / m[k - 1]
    a[n, 0] = -film.stiffness / m[-1]
    b = np.zeros(n + 1)
    b[n] = (film.stiffness * film.offset - kinetic_force) / m[-1]
    return a, b, g * math.sqrt(2 * c * kT)


def transition(film: Film, dt: float, *, kT: float = 1.5, kinetic_force: float = 0.0):
    """The exact step of the film and wall over ``dt``: (Φ, φ, L) with
    y(t + dt) = Φ·y(t) + φ + L·N(0, 1), y = (x, u_1 … u_n).

    Φ = exp(A·dt) and φ = ∫₀^dt e^{As} b ds from the exponential of the system with b
    appended; L·Lᵀ = ∫₀^dt e^{As} G·Gᵀ e^{Aᵀs} ds (Van Loan, IEEE TAC 23, 395 (1978)):
    exp([[−A, G·Gᵀ], [0, Aᵀ]]·dt) = [[·, Φ⁻¹·Q], [0, Φᵀ]].  The noise's variance per
    dashpot is 2·c·kT per unit time, c = η·A·n/W, the fluctuation–dissipation
    partner of its drag.

    >>> phi, shift, l = transition(Film(slabs=3), 0.05, kT=0.0)
    >>> phi.shape, float(abs(l).max())
    ((4, 4), 0.0)
    """
    if not (dt > 0 and kT >= 0 and math.isfinite(kinetic_force)):
        raise ValueError(f"dt = {dt!r}, kT = {kT!r}, kinetic_force = {kinetic_force!r}: "
                         "need dt > 0, kT >= 0 and a finite force")
    a, b, g = _generator(film, kT, kinetic_force)
    n = a.shape[0]
    aug = np.zeros((n + 1, n + 1))
    aug[:n, :n], aug[:n, n] = a, b
    e = expm(aug * dt)
    phi, shift = e[:n, :n], e[:n, n]
    vl = np.zeros((2 * n, 2 * n))
    vl[:n, :n], vl[:n, n:], vl[n:, n:] = -a, g @ g.T, a.T
    ev = expm(vl * dt)
    q = phi @ ev[:n, n:]
    q = (q + q.T) / 2
    w, v = np.linalg.eigh(q)
    return phi, shift, v * np.sqrt(np.clip(w, 0.0, None))


def film_release(releases: int, film: Film = Film(), *, kT: float = 1.5,
                 kinetic_force: float = 0.0, dt: float = 0.05, duration: float = 120.0,
                 seed=None) -> dict:
    """``releases`` independent releases of the wall on the fluctuating film, sampled
    every ``dt`` from the release (t = 0) for ``duration``.

    Each starts with the wall at x = 0 and every node's velocity drawn from the
    equilibrium, u_k ~ N(0, kT/m_k) (the film's stationary state when the wall is held:
    the drag and its noise obey fluctuation–dissipation), and is stepped exactly
    (:func:`transition`).  ``kinetic_force``: a constant force −F_k on the wall besides
    the film's (the first swing moves forward, so it resists all of it).  ``seed``:
    of :func:`numpy.random.default_rng`.

    Returns
    -------
    dict
        ``time`` (n_t,), ``wall_position``, ``wall_velocity``, ``spring_force``
        (releases, n_t), and ``slab_velocity`` (releases, n_t, n − 1) of the film's
        nodes below the wall.
    """
    if not (isinstance(releases, int) and releases >= 1):
        raise ValueError(f"releases = {releases!r}: must be an integer >= 1")
    if not duration > dt:
        raise ValueError(f"duration = {duration!r}: must exceed dt = {dt!r}")
    rng = np.random.default_rng(seed)
    phi, shift, chol = transition(film, dt, kT=kT, kinetic_force=kinetic_force)
    steps = int(round(duration / dt))
    y = np.zeros((releases, film.slabs + 1))
    y[:, 1:] = rng.standard_normal((releases, film.slabs)) * np.sqrt(kT / film.node_masses())
    out = np.empty((steps, releases, film.slabs + 1))
    for i in range(steps):
        out[i] = y
        y = y @ phi.T + shift + rng.standard_normal(y.shape) @ chol.T
    out = out.transpose(1, 0, 2)
    x = out[..., 0]
    return {"time": np.arange(steps) * dt, "wall_position": x, "wall_velocity": out[..., -1],
            "spring_force": film.stiffness * (film.offset - x), "slab_velocity": out[..., 1:-1]}


def release_traces(q: dict) -> list[dict]:
    """The releases of :func:`film_release` as one trace dict each (the columns a
    release run's trace.csv has), for
    :func:`~filmfriction.analysis.groundtruth.release_control.fit_releases`."""
    names = ("wall_position", "wall_velocity", "spring_force")
    return [{"time": q["time"]} | {k: q[k][r] for k in names} for r in range(len(q[names[0]]))]


def peak_time(film: Film = Film(), *, kinetic_force: float = 0.0, dt: float = 0.05,
              duration: float = 120.0) -> float:
    """The time of the noise-free release's peak wall velocity (kT = 0)."""
    q = film_release(1, film, kT=0.0, kinetic_force=kinetic_force, dt=dt, duration=duration)
    return float(q["time"][int(np.argmax(q["wall_velocity"][0]))])


def held_until(traces: list[dict], force: float, until: float) -> list[dict]:
    """``traces`` with a yield on their accelerating branch: the film holds ``force``
    more up to the time ``until`` (e.g. :func:`peak_time`), carried by the spring — its
    force reads that much more there, the wall's trajectory unchanged (the film force
    F_spring − M·a then steps down by ``force`` at ``until``: a loop of that size, as on
    the model releases of ``tests/analysis/groundtruth/test_release_model.py``)."""
    return [tr | {"spring_force": tr["spring_force"] + np.where(tr["time"] < until, force, 0.0)}
            for tr in traces]
