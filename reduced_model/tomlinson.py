"""The Prandtl-Tomlinson model: an atom dragged by a spring over a corrugated substrate.

``m x'' = -dU/dx + K (V t - x) - gamma x' (+ thermal noise)``, with
``U(x) = -U0 cos(2 pi x / a)``.  In the quasi-static limit the atom sticks and
slips exactly when ``eta = 4 pi^2 U0 / (K a^2) > 1``: only then does the total
energy ``U(x) + K (X - x)^2 / 2`` have more than one minimum for some spring
position X, so that the atom's minimum can vanish under it (a fold) and the
atom jumps.

At zero temperature the motion is integrated with DOP853 (energy integrals in
the state, so the ledger closes to ~1e-10).  With ``temperature > 0`` a
Langevin BAOAB splitting with a fixed step is used; the heat exchanged with the
bath is booked as ``thermal_work`` and the ledger then closes only to the
scheme's O(dt^2) energy error.

Example
-------
>>> pt = PrandtlTomlinson(mass=1.0, stiffness=1.0, drive_velocity=1e-3,
...                       corrugation=0.05, lattice_constant=1.0, damping=2.0)
>>> round(pt.eta, 4), pt.quasistatic_jumps(3.0) > 0
(1.9739, True)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from ._checks import finite, non_negative, positive
from .integrators.event_driven import force_extrema
from .result import SimulationResult, ledger_from_series
from .integrators.trajectory import Recorder

__all__ = ["PrandtlTomlinson"]


@dataclass(frozen=True)
class PrandtlTomlinson:
    """Driven atom in the potential -U0 cos(2 pi x / a).

    Parameters
    ----------
    mass : float
        Atom (tip) mass m, > 0.
    stiffness : float
        Spring constant K, > 0.
    drive_velocity : float
        Velocity V of the spring end.
    corrugation : float
        U0 >= 0 (the peak-to-peak barrier is 2 U0).
    lattice_constant : float
        Substrate period a > 0.
    damping : float
        Viscous damping gamma (force per velocity) of the atom, >= 0; > 0 if
        ``temperature > 0`` (the bath needs a friction to balance its noise).
    temperature : float
        k_B T in energy units (0: deterministic).
    seed : int, optional
        Random seed of the thermal noise.
    """

    mass: float
    stiffness: float
    drive_velocity: float
    corrugation: float
    lattice_constant: float
    damping: float = 1.0
    temperature: float = 0.0
    seed: int | None = None

    def __post_init__(self):
        positive("mass", self.mass, "the atom needs inertia; use large damping for the overdamped limit")
        positive("stiffness", self.stiffness, "a spring with K <= 0 cannot drive the atom")
        finite("drive_velocity", self.drive_velocity)
        non_negative("corrugation", self.corrugation, "barrier height U0 of the substrate")
        positive("lattice_constant", self.lattice_constant, "substrate period a")
        non_negative("damping", self.damping, "a negative damping would feed energy in")
        non_negative("temperature", self.temperature, "k_B T")
        if self.temperature > 0 and self.damping == 0:
            raise ValueError("damping = 0 with temperature > 0: allowed range is (0, inf) -- the "
                             "fluctuation-dissipation theorem ties the noise to the damping")

    @property
    def eta(self) -> float:
        """Tomlinson parameter 4 pi^2 U0 / (K a^2); stick-slip iff > 1 (quasi-static)."""
        return 4.0 * math.pi ** 2 * self.corrugation / (self.stiffness * self.lattice_constant ** 2)

    def substrate_force(self, x):
        q = 2.0 * math.pi / self.lattice_constant
        return -self.corrugation * q * np.sin(q * x)

    def substrate_energy(self, x):
        return -self.corrugation * np.cos(2.0 * math.pi * x / self.lattice_constant)

    # -- quasi-static limit ------------------------------------------------------
    def quasistatic_jumps(self, travel: float, points_per_period: int = 400) -> int:
        """Number of jumps of the atom while the spring end moves by ``travel``
        infinitely slowly (the atom follows its local energy minimum).

        Each X step re-minimises from the previous position by damped Newton.  A
        jump is a move across ground where the total energy is not convex
        (``K + U''(x) <= 0`` somewhere between the old and the new minimum):
        the old minimum has vanished under the atom.  For eta < 1 the energy is
        convex everywhere and there is never a jump, however steep the branch.
        """
        a, K = self.lattice_constant, self.stiffness
        q = 2.0 * math.pi / a
        n = max(int(travel / a * points_per_period), 2)
        X = np.linspace(0.0, travel, n)
        x, jumps = 0.0, 0
        for Xk in X[1:]:
            prev = x
            for _ in range(500):     # gradient flow with Newton acceleration where convex
                grad = self.corrugation * q * math.sin(q * x) - K * (Xk - x)
                curv = self.corrugation * q * q * math.cos(q * x) + K
                step = grad / curv if curv > 0.1 * K else grad / (K + self.corrugation * q * q) * 0.5
                x -= step
                if abs(step) < 1e-13 * a:
                    break
            between = np.linspace(prev, x, 64)
            if np.min(K + self.corrugation * q * q * np.cos(q * between)) <= 0.0:
                jumps += 1
        return jumps

    # -- dynamics ----------------------------------------------------------------
    def simulate(self, duration: float, *, dt: float | None = None, sample_every: int = 10):
        """Run from rest at x = 0 (spring relaxed) for ``duration``.

        ``dt`` and ``sample_every`` only matter for the thermal (Langevin) run;
        the default dt is 1/50 of the shortest oscillation period.
        """
        T = positive("duration", duration, "length of the run")
        if self.temperature > 0:
            return self._langevin(T, dt, sample_every)
        return self._deterministic(T)

    def _omega_max(self):
        q = 2.0 * math.pi / self.lattice_constant
        return math.sqrt((self.stiffness + self.corrugation * q * q) / self.mass)

    def _deterministic(self, T):
        m, K, V, g = self.mass, self.stiffness, self.drive_velocity, self.damping
        period = 2.0 * math.pi / self._omega_max()
        zeta = g / (2.0 * math.sqrt(K * m))
        max_step = period / 16.0 * max(1.0, zeta)
        if T / max_step > 20_000_000:
            raise ValueError(f"duration = {T!r} spans more than 2e7 steps of {max_step:.3g}; shorten it")

        def rhs(t, y):
            f_spring = K * (V * t - y[0])
            f = f_spring + self.substrate_force(y[0]) - g * y[1]
            return [y[1], f / m, f_spring * V, g * y[1] * y[1]]

        energy = max(self.corrugation, K * self.lattice_constant ** 2, 1e-300)
        atol = np.array([1e-12 * self.lattice_constant, 1e-12 * math.sqrt(energy / m),
                         1e-12 * energy, 1e-12 * energy])
        sol = solve_ivp(rhs, (0.0, T), [0.0, 0.0, 0.0, 0.0], method="DOP853", rtol=1e-10,
                        atol=atol, max_step=max_step, dense_output=True)
        ts, ys, marks = force_extrema(sol.t, sol.y, sol.sol, lambda t, y: y[1] - V,
                                       lambda t, y: K * (V * t - y[0]))
        result = self._result(ts, ys[0], ys[1], ys[2], ys[3], np.zeros_like(ts), marks, sol.nfev)
        if sol.status == -1:
            return _with_status(result, -1, f"solve_ivp failed: {sol.message}")
        return result

    def _langevin(self, T, dt, sample_every):
        m, K, V, g, kT = self.mass, self.stiffness, self.drive_velocity, self.damping, self.temperature
        dt = 2.0 * math.pi / self._omega_max() / 50.0 if dt is None else positive("dt", dt, "time step")
        n = int(math.ceil(T / dt))
        if n > 50_000_000:
            raise ValueError(f"duration/dt = {n}: more than 5e7 Langevin steps; shorten the run or raise dt")
        rng = np.random.default_rng(self.seed)
        c1 = math.exp(-g / m * dt)
        c2 = math.sqrt(kT / m * (1.0 - c1 * c1))
        noise = rng.standard_normal(n)
        every = max(int(sample_every), 1)
        out = {k: [0.0] for k in ("t", "x", "v", "drive", "heat")}
        x = v = t = drive = heat = 0.0
        for i in range(n):
            # BAOAB: kick, drift, thermostat, drift, kick
            f_spring = K * (V * t - x)
            v += 0.5 * dt * (f_spring + float(self.substrate_force(x))) / m
            x += 0.5 * dt * v
            v_new = c1 * v + c2 * noise[i]
            heat += 0.5 * m * (v_new * v_new - v * v)
            v = v_new
            x += 0.5 * dt * v
            # drive work: spring force at mid-step times V (midpoint rule)
            drive += K * (V * (t + 0.5 * dt) - x) * V * dt
            t += dt
            v += 0.5 * dt * (K * (V * t - x) + float(self.substrate_force(x))) / m
            if (i + 1) % every == 0 or i == n - 1:
                for k, val in (("t", t), ("x", x), ("v", v), ("drive", drive), ("heat", heat)):
                    out[k].append(val)
        ts = np.array(out["t"])
        zeros = np.zeros_like(ts)
        # thermal: events at samples, with a hysteresis of a quarter of the force range
        force = K * (V * ts - np.array(out["x"]))
        marks = _hysteresis_extrema(ts, force, 0.25 * np.ptp(force))
        return self._result(ts, np.array(out["x"]), np.array(out["v"]), np.array(out["drive"]),
                            zeros, np.array(out["heat"]), marks, n)

    def _result(self, ts, x, v, drive, damp, heat, marks, nfev):
        xa = self.drive_velocity * ts
        rec = Recorder(t0=ts[0], x0=x[0], v0=v[0], xa0=xa[0], state0=np.empty(0), stiffness=self.stiffness,
                       mass=self.mass, state_names=(), max_events=10 ** 9, time_scale=1.0)
        rec.append(ts, x, v, xa, np.empty((0, ts.size)), drive, damp, np.zeros_like(ts))
        rec.insert_events([m_[0] for m_ in marks], [m_[1] for m_ in marks])
        rec.nfev = nfev
        base = rec.finish()
        # the substrate potential and the bath enter the ledger too
        ledger = ledger_from_series(ts, x, v, xa, self.stiffness, self.mass, drive, damp, np.zeros_like(ts),
                                    substrate=self.substrate_energy(x), thermal=heat)
        return SimulationResult(**{**base.__dict__, "energy": ledger,
                                   "extras": {"eta": self.eta,
                                              "max_velocity_ratio": float(np.max(np.abs(v)) /
                                                                          max(abs(self.drive_velocity), 1e-300))}})


def _with_status(result, status, message):
    return SimulationResult(**{**result.__dict__, "status": status, "message": message})


def _hysteresis_extrema(t, f, h):
    """Alternating maxima ("slip") / minima ("stick") of f that differ by more than h."""
    marks = []
    if f.size < 3 or h <= 0:
        return marks
    i_max = i_min = 0
    looking_for = None
    for i in range(1, f.size):
        if f[i] > f[i_max]:
            i_max = i
        if f[i] < f[i_min]:
            i_min = i
        if looking_for != "stick" and f[i_max] - f[i] > h:
            marks.append((t[i_max], "slip"))
            looking_for, i_min = "stick", i
        elif looking_for == "stick" and f[i] - f[i_min] > h:
            marks.append((t[i_min], "stick"))
            looking_for, i_max = "slip", i
    return marks
