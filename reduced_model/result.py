"""What a spring-block (or Prandtl-Tomlinson) run returns.

The result is shaped like scipy's ``solve_ivp`` result (``t``, ``y``,
``t_events``, ``status``, ``message``, ``success``, ``nfev``) with the physics
spelled out: positions, velocities, spring force, the stick/slip events and
the energy ledger.  Every event time is also a sample time, and
``yield_index`` / ``stick_index`` point at those samples, so per-cycle
statistics need no interpolation.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .cycles import cycle_table

__all__ = ["Event", "EnergyLedger", "SimulationResult"]


@dataclass(frozen=True)
class Event:
    """One transition of the contact.

    Attributes
    ----------
    time : float
        When it happened (exactly: root of the closed form or of the dense output).
    kind : str
        ``"slip"`` (breakaway from stick: the yield point y), ``"stick"``
        (re-stick: the solidification point s) or ``"reversal"`` (slip changes
        direction without sticking).  A block that stops for good (fixed spring
        end inside the static threshold) simply has no event after its stick.
        For smooth laws, which never stop exactly, ``"slip"``/``"stick"`` mark
        the maxima/minima of the spring force instead.
    index : int
        Index of the sample at ``time`` in the result arrays.
    spring_force : float
        Spring force at that instant.
    """

    time: float
    kind: str
    index: int
    spring_force: float

    @classmethod
    def many(cls, times, kinds, indices, forces) -> list:
        """Events from parallel sequences, without the frozen dataclass's per-field
        ``object.__setattr__`` (a run of 10^4 cycles builds 2 x 10^4 of them)."""
        new = object.__new__
        out = []
        for t, k, i, f in zip(times, kinds, indices, forces):
            e = new(cls)
            e.__dict__.update(time=t, kind=k, index=i, spring_force=f)
            out.append(e)
        return out


@dataclass(frozen=True)
class EnergyLedger:
    """Energy balance of a run (all in the caller's energy unit).

    ``drive_work = kinetic + spring + substrate + friction_dissipation
    + damper_dissipation - thermal_work``.  ``kinetic``, ``spring`` and
    ``substrate`` are *changes* over the run; the dissipations are totals.
    ``closure`` is the largest imbalance along the run relative to the
    largest energy in play; it should be at round-off level (<= 1e-8).
    """

    drive_work: float
    kinetic: float
    spring: float
    friction_dissipation: float
    damper_dissipation: float
    closure: float
    substrate: float = 0.0
    thermal_work: float = 0.0

    def as_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Trajectory, events and energy ledger of one run.

    Attributes
    ----------
    t, x, v : ndarray
        Sample times, block position and velocity.
    drive_position : ndarray
        Position of the driven spring end (constant for a fixed end or a belt).
    spring_force : ndarray
        ``stiffness * (drive_position - x)``: what an SFB or MD spring records.
    state : ndarray, shape (n_state, n)
        Internal friction state (contact age, log theta, film thickness).
    drive_work, friction_dissipation, damper_dissipation : ndarray
        Cumulative energies at each sample.
    events : tuple of Event
    energy : EnergyLedger
    status, message, nfev : as in solve_ivp (status 0: reached the end).
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    drive_position: np.ndarray
    state: np.ndarray
    drive_work: np.ndarray
    friction_dissipation: np.ndarray
    damper_dissipation: np.ndarray
    events: tuple
    energy: EnergyLedger
    stiffness: float
    mass: float
    state_names: tuple = ()
    status: int = 0
    message: str = "The simulation reached the end of the requested duration."
    nfev: int = 0
    extras: dict = field(default_factory=dict)

    # -- solve_ivp look-alike ----------------------------------------------
    @property
    def y(self) -> np.ndarray:
        """Rows: x, v, then the friction state (like ``solve_ivp``'s ``y``)."""
        return np.vstack([self.x, self.v, self.state]) if self.state.size else np.vstack([self.x, self.v])

    @property
    def success(self) -> bool:
        return self.status >= 0

    @property
    def t_events(self) -> list:
        """Times of ``[slip, stick]`` events (like ``solve_ivp``'s ``t_events``)."""
        return [np.array([e.time for e in self.events if e.kind == k]) for k in ("slip", "stick")]

    # -- drive protocols, exact output times, the state -----------------------
    @property
    def eval_index(self) -> np.ndarray:
        """Indices of the samples at ``simulate(t_eval=...)``'s times (``r.x[r.eval_index]``)."""
        if "eval_index" not in self.extras:
            raise AttributeError("eval_index: this run had no t_eval; pass t_eval to simulate")
        return self.extras["eval_index"]

    @property
    def psi(self) -> np.ndarray:
        """Rate-and-state log state psi = ln(v0 theta / dc) at every sample."""
        if "log_state" not in self.state_names:
            raise AttributeError(f"psi: this law's state is {self.state_names}, not a log state")
        return self.state[self.state_names.index("log_state")]

    @property
    def theta(self) -> np.ndarray:
        """Rate-and-state state theta = (dc / v0) e^psi [time] at every sample."""
        if "theta" not in self.extras:
            raise AttributeError(f"theta: this law's state is {self.state_names}; theta is "
                                 "defined for rate-and-state")
        return self.extras["theta"]

    # -- physics ------------------------------------------------------------
    @property
    def spring_force(self) -> np.ndarray:
        return self.stiffness * (self.drive_position - self.x)

    @property
    def yield_index(self) -> np.ndarray:
        """Sample indices of the yield points that start a complete slip."""
        return self.slip_pairs()[0]

    @property
    def stick_index(self) -> np.ndarray:
        """Sample indices of the re-stick point of each complete slip."""
        return self.slip_pairs()[1]

    def slip_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """Index arrays (yield, stick) of complete slips: each yield with the
        first re-stick after it; an unfinished last slip is left out."""
        kinds = np.array([e.kind for e in self.events], dtype=object)
        index = np.array([e.index for e in self.events], dtype=int)
        slip_at = np.flatnonzero(kinds == "slip")
        stick_at = np.flatnonzero(kinds == "stick")
        # each re-stick pairs with the first yield after the re-stick before it (if any)
        before = np.concatenate(([-1], stick_at[:-1])) if stick_at.size else stick_at
        first = np.searchsorted(slip_at, before, side="right")
        ok = first < slip_at.size
        ok[ok] = slip_at[first[ok]] < stick_at[ok]
        return index[slip_at[first[ok]]], index[stick_at[ok]]

    def cycles(self):
        """Per-cycle table (static force, backward force, slip distance, durations, period).

        Uses :func:`~filmfriction.reduced_model.cycles.cycle_table` -- the same ruler as for MD
        traces -- on the exact event samples of this run; the block position is
        the "wall" whose displacement is the slip distance.

        Example
        -------
        >>> from filmfriction.reduced_model import SpringBlock, laws
        >>> r = SpringBlock(1.0, 1.0, 0.1, law=laws.Coulomb(1.0, 0.5)).simulate(100.0)
        >>> round(float(r.cycles().backward_force[0]), 12)    # 2 Fk - Fs
        0.0
        """
        yields, sticks = self.slip_pairs()
        return cycle_table(self.t, self.spring_force, yields, sticks,
                           spring_constant=self.stiffness, wall_position=self.x)

    def __repr__(self) -> str:
        kinds = {}
        for e in self.events:
            kinds[e.kind] = kinds.get(e.kind, 0) + 1
        return (f"SimulationResult(n={self.t.size}, t=[{self.t[0]:.4g}, {self.t[-1]:.4g}], "
                f"events={kinds}, closure={self.energy.closure:.2e}, status={self.status})")


def ledger_from_series(t, x, v, drive_position, stiffness, mass, drive_work, friction, damper,
                       substrate=None, thermal=None) -> EnergyLedger:
    """Build the ledger, with closure = max |imbalance| over the run / energy scale."""
    kinetic = 0.5 * mass * v ** 2
    spring = 0.5 * stiffness * (drive_position - x) ** 2
    d_kin = kinetic - kinetic[0]
    d_spr = spring - spring[0]
    d_sub = np.zeros_like(t) if substrate is None else substrate - substrate[0]
    therm = np.zeros_like(t) if thermal is None else thermal
    residual = drive_work + therm - (d_kin + d_spr + d_sub + friction + damper)
    scale = max(np.max(np.abs(drive_work)), np.max(kinetic + spring), friction[-1] + damper[-1],
                np.max(np.abs(therm)), np.finfo(float).tiny)
    return EnergyLedger(drive_work=float(drive_work[-1]), kinetic=float(d_kin[-1]),
                        spring=float(d_spr[-1]), friction_dissipation=float(friction[-1]),
                        damper_dissipation=float(damper[-1]),
                        closure=float(np.max(np.abs(residual)) / scale),
                        substrate=float(d_sub[-1]), thermal_work=float(therm[-1]))
