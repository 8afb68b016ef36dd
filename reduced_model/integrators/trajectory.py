"""Assembles a run from its stick and slip segments.

Both integrators (closed form and ODE) hand over one segment at a time, each
starting where the previous one ended; the recorder concatenates them, turns
per-segment energies into running totals, stamps events on the exact samples
and enforces the safety caps (event count, runs of zero-length segments).
"""
from __future__ import annotations

import numpy as np

from .._checks import SimulationLimitError
from ..result import Event, SimulationResult, ledger_from_series

__all__ = ["Recorder"]


class Recorder:
    """Collects segments; see :meth:`append` and :meth:`event`."""

    def __init__(self, *, t0, x0, v0, xa0, state0, stiffness, mass, state_names,
                 max_events, time_scale):
        self.stiffness, self.mass, self.state_names = stiffness, mass, state_names
        self.max_events = max_events
        self.time_scale = time_scale
        self._t, self._x, self._v, self._xa = [np.array([t0])], [np.array([x0])], [np.array([v0])], [np.array([xa0])]
        state0 = np.asarray(state0, dtype=float)
        self._state = [state0.reshape(-1, 1) if state0.size else np.empty((0, 1))]
        self._wd, self._wf, self._wdamp = [np.zeros(1)], [np.zeros(1)], [np.zeros(1)]
        self.totals = np.zeros(3)
        self.n = 1
        self.events: list[tuple] = []      # (time, kind, sample index); Events built in finish
        self.nfev = 0
        self._short_run = 0

    def append(self, t, x, v, xa, state, drive_work, friction, damper):
        """Add a segment; arrays start at the segment's first sample (dropped,
        as it repeats the previous end) and energies count from zero."""
        t = np.asarray(t, dtype=float)
        if t.size < 2:
            return
        if t[-1] - t[0] <= 1e-12 * self.time_scale:
            # a run of vanishing segments is chattering: refuse instead of hanging
            self._short_run += 1
            if self._short_run > 1000:
                raise SimulationLimitError(
                    "more than 1000 consecutive stick/slip segments of zero length at "
                    f"t = {t[0]:.6g}: the contact is chattering between stick and slip. "
                    "This happens when the spring force sits exactly at the static threshold "
                    "with nothing driving it on; check the drive velocity and the friction law.")
        else:
            self._short_run = 0
        self._t.append(t[1:])
        self._x.append(np.asarray(x, dtype=float)[1:])
        self._v.append(np.asarray(v, dtype=float)[1:])
        self._xa.append(np.broadcast_to(np.asarray(xa, dtype=float), t.shape)[1:])
        st = np.asarray(state, dtype=float)
        st = st.reshape(len(self.state_names), -1) if st.size else np.empty((0, t.size))
        if st.shape[1] == 1:
            st = np.repeat(st, t.size, axis=1)
        self._state.append(st[:, 1:])
        for store, k, arr in ((self._wd, 0, drive_work), (self._wf, 1, friction), (self._wdamp, 2, damper)):
            arr = np.broadcast_to(np.asarray(arr, dtype=float), t.shape)
            store.append(self.totals[k] + arr[1:])
        self.totals += [np.asarray(drive_work, dtype=float).reshape(-1)[-1],
                        np.asarray(friction, dtype=float).reshape(-1)[-1],
                        np.asarray(damper, dtype=float).reshape(-1)[-1]]
        self.n += t.size - 1

    # -- periodic runs: one cycle recorded, the rest tiled -----------------------
    def mark(self):
        """Where the recorder stands now (segments, events, totals, samples, end sample)."""
        return (len(self._t), len(self.events), self.totals.copy(), self.n,
                float(self._t[-1][-1]), float(self._x[-1][-1]), float(self._xa[-1][-1]))

    def period_since(self, mark):
        """(duration, displacement, spring-end displacement, event kinds) since ``mark``."""
        n_seg, n_ev, _, _, t0, x0, xa0 = mark
        return (float(self._t[-1][-1]) - t0, float(self._x[-1][-1]) - x0,
                float(self._xa[-1][-1]) - xa0, [e[1] for e in self.events[n_ev:]])

    def repeat(self, mark, copies: int):
        """Append ``copies`` more copies of everything recorded since ``mark``.

        For a periodic solution: every quantity of the cycle is shifted by what
        it gained over the cycle (time by the period, positions by the slip of
        the cycle, cumulative energies by the cycle's totals); velocities and the
        state repeat as they are.  One NumPy broadcast per array, no per-sample
        or per-cycle Python.  Returns the (t, x, xa) shift of all copies."""
        n_seg, n_ev, totals0, n0, t0, x0, xa0 = mark
        dt, dx, dxa, _ = self.period_since(mark)
        if copies < 1:
            return 0.0, 0.0, 0.0
        m = self.n - n0                         # samples per cycle
        if len(self.events) + copies * (len(self.events) - n_ev) > self.max_events:
            raise SimulationLimitError(
                f"more than max_events = {self.max_events} stick/slip events by t = "
                f"{t0 + (copies + 1) * dt:.6g}: shorten the duration or raise max_events (each "
                "event costs memory and time).")
        k = np.arange(1, copies + 1, dtype=float)[:, None]
        d_energy = self.totals - totals0

        def cycle(store):
            return np.concatenate(store[n_seg:], axis=-1)

        self._t.append((cycle(self._t) + k * dt).ravel())
        self._x.append((cycle(self._x) + k * dx).ravel())
        self._xa.append((cycle(self._xa) + k * dxa).ravel())
        self._v.append(np.tile(cycle(self._v), copies))
        self._state.append(np.tile(cycle(self._state), (1, copies)))
        for store, j in ((self._wd, 0), (self._wf, 1), (self._wdamp, 2)):
            store.append((cycle(store) + k * d_energy[j]).ravel())
        template = self.events[n_ev:]
        if template:
            c = np.arange(1, copies + 1)[:, None]
            times = (np.array([e[0] for e in template]) + c * dt).ravel().tolist()
            index = (np.array([e[2] for e in template]) + c * m).ravel().tolist()
            self.events.extend(zip(times, [e[1] for e in template] * copies, index))
        self.totals = self.totals + copies * d_energy
        self.n += copies * m
        return copies * dt, copies * dx, copies * dxa

    def insert_events(self, times, kinds):
        """Events at samples already recorded (times must be sample times)."""
        t = np.concatenate(self._t)
        for time, kind in zip(times, kinds):
            i = int(np.searchsorted(t, time))
            i = min(max(i, 0), t.size - 1)
            self._add((float(t[i]), kind, i))

    def event(self, kind: str, time: float, spring_force: float):
        """Record an event at the last sample (which must be at ``time``)."""
        self._add((float(time), kind, self.n - 1))

    def _add(self, ev: tuple):
        self.events.append(ev)
        if len(self.events) > self.max_events:
            raise SimulationLimitError(
                f"more than max_events = {self.max_events} stick/slip events by t = {ev[0]:.6g}: "
                "shorten the duration or raise max_events (each event costs memory and time).")

    def finish(self, status=0, message=None, extras=None) -> SimulationResult:
        t = np.concatenate(self._t)
        x = np.concatenate(self._x)
        v = np.concatenate(self._v)
        xa = np.concatenate(self._xa)
        state = np.concatenate(self._state, axis=1)
        wd, wf, wdamp = (np.concatenate(s) for s in (self._wd, self._wf, self._wdamp))
        ledger = ledger_from_series(t, x, v, xa, self.stiffness, self.mass, wd, wf, wdamp)
        idx = np.array([e[2] for e in self.events], dtype=int)
        forces = (self.stiffness * (xa[idx] - x[idx])).tolist()
        events = Event.many([e[0] for e in self.events], [e[1] for e in self.events],
                            idx.tolist(), forces)
        kwargs = {} if message is None else {"message": message}
        return SimulationResult(t=t, x=x, v=v, drive_position=xa, state=state, drive_work=wd,
                                friction_dissipation=wf, damper_dissipation=wdamp,
                                events=tuple(events), energy=ledger, stiffness=self.stiffness,
                                mass=self.mass, state_names=self.state_names, status=status,
                                nfev=self.nfev, extras=extras or {}, **kwargs)


class Problem:
    """Everything an integrator needs, in plain numbers (built by SpringBlock).

    ``spring_end_velocity`` is the velocity of the driven spring end (V for the
    spring drive, 0 otherwise); ``surface_velocity`` that of the surface under
    the block (V for the belt, 0 otherwise).  The slip velocity is
    ``v - surface_velocity``.
    """

    def __init__(self, *, mass, stiffness, damping, normal_load, law, spring_end_velocity,
                 surface_velocity, xa0, x0, v0, state0, duration, samples_per_segment, max_events):
        self.mass, self.stiffness, self.damping = mass, stiffness, damping
        self.normal_load, self.law = normal_load, law
        self.va, self.u = spring_end_velocity, surface_velocity
        self.xa0, self.x0, self.v0 = xa0, x0, v0
        self.state0 = np.asarray(state0, dtype=float)
        self.duration = duration
        self.samples = samples_per_segment
        self.max_events = max_events

    @property
    def period(self) -> float:
        """Natural period 2 pi sqrt(M/K) (inf for the massless block)."""
        return 2.0 * np.pi * np.sqrt(self.mass / self.stiffness) if self.mass > 0 else np.inf

    def recorder(self) -> Recorder:
        scale = self.period if np.isfinite(self.period) else self.duration
        return Recorder(t0=0.0, x0=self.x0, v0=self.v0, xa0=self.xa0, state0=self.state0,
                        stiffness=self.stiffness, mass=self.mass,
                        state_names=tuple(self.law.state_names), max_events=self.max_events,
                        time_scale=scale)
