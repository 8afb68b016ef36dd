"""The spring-block model: a block of mass M on a spring K, a damper d, a
normal load N and a friction law.

Drive modes
-----------
``"spring"``  the far end of the spring moves at ``drive_velocity`` (SFB, MD wall,
              Braun's picture).
``"fixed"``   the far end is held: a free oscillator released from an initial
              spring extension or velocity (Perret-Liaudet & Majdoub, seed 001).
``"belt"``    the spring end is fixed and the surface under the block moves at
              ``drive_velocity`` (Schnelle's model 2, seed 003).

Equation of motion (x: block position, x_a: spring end, u: surface velocity)::

    M x'' = K (x_a - x) - d x' - F_friction(x' - u, state)

Units are any consistent set: SI (kg, N/m, m/s, N s/m, N) or LJ.

Example
-------
>>> from filmfriction.reduced_model import SpringBlock, laws
>>> block = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.1,
...                     law=laws.Coulomb(static=1.0, kinetic=0.5))
>>> r = block.simulate(duration=200.0)
>>> round(float(r.events[0].time), 12)           # first stick lasts Fs/(K V)
10.0
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ._checks import finite, non_negative, positive
from .laws import Coulomb, FrictionLaw
from .result import Event
from .integrators.trajectory import Problem

__all__ = ["SpringBlock"]

DRIVES = ("spring", "fixed", "belt")


@dataclass(frozen=True)
class SpringBlock:
    """Spring-block slider with a friction law.

    Parameters
    ----------
    mass : float
        Block mass M [kg or m]; 0 selects the massless (quasi-static) block,
        available for smooth laws that can be inverted (rate-and-state, films).
    stiffness : float
        Spring constant K [N/m or eps/sigma^2], > 0.
    drive_velocity : float
        Velocity V of the spring end ("spring") or of the belt ("belt") [m/s or
        sigma/tau]; must be 0 for ``drive="fixed"``.
    damping : float
        Viscous damper d between block and ground [N s/m], >= 0.
    law : FrictionLaw
        One of :mod:`filmfriction.reduced_model.laws`; default Coulomb(static=1, kinetic=0.5).
    normal_load : float
        Normal load N [N]; dry-friction coefficients of the law are multiplied by it.
    drive : {"spring", "fixed", "belt"}
    """

    mass: float
    stiffness: float
    drive_velocity: float
    damping: float = 0.0
    law: FrictionLaw = Coulomb(static=1.0, kinetic=0.5)
    normal_load: float = 1.0
    drive: str = "spring"

    def __post_init__(self):
        non_negative("mass", self.mass, "block mass; 0 means the massless quasi-static block")
        positive("stiffness", self.stiffness, "a spring with K <= 0 cannot drive the block")
        finite("drive_velocity", self.drive_velocity)
        non_negative("damping", self.damping, "a negative damper would feed energy in")
        non_negative("normal_load", self.normal_load, "the load presses the surfaces together")
        if not isinstance(self.law, FrictionLaw):
            raise ValueError(f"law = {self.law!r}: must be a friction law from filmfriction.reduced_model.laws")
        if self.drive not in DRIVES:
            raise ValueError(f"drive = {self.drive!r}: allowed values are {DRIVES}")
        if self.drive == "fixed" and self.drive_velocity != 0.0:
            raise ValueError(f"drive_velocity = {self.drive_velocity!r}: must be 0 with drive='fixed' "
                             "(the spring end is held still; release the block with initial_extension "
                             "or initial_velocity instead)")
        if self.mass == 0.0:
            self._check_massless()

    def _check_massless(self):
        law = self.law
        if law.static_force(law.steady_state(0.0), self.normal_load) is not None:
            raise ValueError(
                f"mass = 0 with {type(law).__name__}: allowed range is (0, inf) for laws with static "
                "friction -- a massless block would jump instantly at breakaway, with no defined "
                "slip. Use a small positive mass (the closed form stays exact for stiff, light blocks).")
        if law.quasi_static_speed(1.0, law.steady_state(1.0), max(self.normal_load, 1.0)) is None:
            raise ValueError(f"mass = 0 with {type(law).__name__}: this law has no massless formulation; "
                             "use a positive mass")
        if self.damping != 0.0 or self.drive != "spring":
            raise ValueError("mass = 0: the massless formulation supports drive='spring' with damping = 0 "
                             f"only (got drive={self.drive!r}, damping={self.damping!r})")
        if self.normal_load == 0.0 and not hasattr(law, "drag_coefficient"):
            raise ValueError("normal_load = 0 with mass = 0: a massless block with no friction has no "
                             "defined motion; use normal_load > 0")

    # -- derived numbers -------------------------------------------------------
    @property
    def natural_period(self) -> float:
        """2 pi sqrt(M/K)."""
        return 2.0 * math.pi * math.sqrt(self.mass / self.stiffness)

    @property
    def damping_ratio(self) -> float:
        """Nakano-Maegawa zeta = d / (2 sqrt(K M))."""
        return self.damping / (2.0 * math.sqrt(self.stiffness * self.mass)) if self.mass > 0 else math.inf

    def _default_start(self, va, u):
        """(extension, velocity) to start from: rest, or steady sliding for smooth laws."""
        law, N = self.law, self.normal_load
        state = law.steady_state(abs(self.drive_velocity))
        if self.drive == "fixed" or law.static_force(state, N) is not None:
            return 0.0, 0.0
        slip = va - u
        friction = float(law.friction(slip, state, N)) if slip else 0.0
        # spring balances friction (and the damper) in steady sliding
        return (friction + self.damping * va) / self.stiffness, (va if self.mass > 0 else 0.0)

    # -- running -----------------------------------------------------------------
    def simulate(self, duration: float | None = None, *, drive=None, t_eval=None,
                 initial_extension: float | None = None,
                 initial_velocity: float | None = None,
                 initial_state=None, samples_per_segment: int = 64, max_events: int = 100_000,
                 method: str = "auto", rtol: float = 1e-10):
        """Run the model from t = 0 to ``duration``.

        Parameters
        ----------
        duration : float
            Length of the run (> 0); optional with ``drive`` (its length), and must
            equal it if given.
        drive : DriveSchedule or list of (duration, velocity), optional
            A drive protocol: the spring-end velocity piece by piece (velocity
            steps, holds, slide-hold-slide), in place of ``drive_velocity``, in one
            run with x, the extension, v and the state continuous across the
            pieces.  Needs the block's ``drive="spring"``; works with mass = 0.
        t_eval : array-like, optional
            Times in [0, duration] at which the result holds an exact sample (the
            run is integrated to each of them, not interpolated); their indices are
            ``result.eval_index``.
        initial_extension : float, optional
            Spring extension at t = 0 (spring force K * extension).
        initial_velocity : float, optional
            Block velocity at t = 0 (lab frame; on a belt, 0 means slipping).
            Defaults: at rest on a relaxed spring for laws with static friction
            and for a fixed spring end; steady sliding at the drive speed for
            smooth laws (which have no state of rest to start from).
        initial_state : array-like, optional
            Friction state (default: steady state at the drive speed, or at the
            initial slip speed for a fixed spring end).
        samples_per_segment : int
            Samples per slip segment of the closed form (sticks are linear and get
            fewer).  The ODE path samples at its own steps (at least 16 per period).
        max_events : int
            Safety cap on stick/slip events; exceeding it raises SimulationLimitError.
        method : {"auto", "closed_form", "ode"}
            "auto" takes the closed form for Coulomb(+viscous) and Newtonian films.
        rtol : float
            Relative tolerance of the ODE path (DOP853).

        Returns
        -------
        SimulationResult
        """
        if drive is not None or t_eval is not None:
            return self._simulate_pieces(duration, drive, t_eval, initial_extension,
                                         initial_velocity, initial_state,
                                         dict(samples_per_segment=samples_per_segment,
                                              max_events=max_events, method=method, rtol=rtol))
        if duration is None:
            raise ValueError("duration = None: give the length of the run (or a drive schedule)")
        T = positive("duration", duration, "length of the run")
        law = self.law
        V = self.drive_velocity
        va, u = {"spring": (V, 0.0), "fixed": (0.0, 0.0), "belt": (0.0, V)}[self.drive]
        if initial_extension is None or initial_velocity is None:
            ext_default, v_default = self._default_start(va, u)
            initial_extension = ext_default if initial_extension is None else initial_extension
            initial_velocity = v_default if initial_velocity is None else initial_velocity
        ext = finite("initial_extension", initial_extension)
        v0 = finite("initial_velocity", initial_velocity)
        if int(samples_per_segment) < 2:
            raise ValueError(f"samples_per_segment = {samples_per_segment!r}: allowed range is [2, inf)")
        if int(max_events) < 1:
            raise ValueError(f"max_events = {max_events!r}: allowed range is [1, inf)")
        if method not in ("auto", "closed_form", "ode"):
            raise ValueError(f"method = {method!r}: allowed values are 'auto', 'closed_form', 'ode'")
        if self.mass == 0.0 and v0 != 0.0:
            raise ValueError(f"initial_velocity = {v0!r}: a massless block has no velocity of its own; "
                             "must be 0 with mass = 0")
        speed_ref = abs(V) if self.drive != "fixed" else abs(v0 - u)
        if initial_state is None:
            state0 = law.steady_state(speed_ref)
        else:
            state0 = np.atleast_1d(np.asarray(initial_state, dtype=float))
            if state0.shape != (len(law.state_names),) or not np.all(np.isfinite(state0)):
                raise ValueError(f"initial_state = {initial_state!r}: expected {len(law.state_names)} "
                                 f"finite value(s) for {law.state_names}")
        problem = Problem(mass=self.mass, stiffness=self.stiffness, damping=self.damping,
                          normal_load=self.normal_load, law=law, spring_end_velocity=va,
                          surface_velocity=u, xa0=ext, x0=0.0, v0=v0, state0=state0, duration=T,
                          samples_per_segment=int(samples_per_segment), max_events=int(max_events))
        closed = law.closed_form(self.normal_load) if self.mass > 0 else None
        if method == "closed_form" and closed is None:
            raise ValueError(f"method = 'closed_form': {type(law).__name__} has no closed form "
                             "(only Coulomb(+viscous) and Newtonian films, with mass > 0)")
        freeze = getattr(law, "freeze_velocity", 0.0)
        shear = getattr(law, "shear_stiffness", math.inf)
        for name, value, on in (("freeze_velocity", freeze, freeze > 0.0),
                                ("shear_stiffness", shear, not math.isinf(shear))):
            if on and (closed is None or method == "ode"):
                raise ValueError(f"{type(law).__name__}.{name} = {value!r}: solved in closed "
                                 "form only (mass > 0, method 'auto' or 'closed_form')")
        if closed is not None and method != "ode":
            from .integrators.closed_form import run_closed_form
            return run_closed_form(problem, *closed, freeze_velocity=freeze,
                                   shear_stiffness=shear)
        from .integrators.event_driven import run_ode
        result = run_ode(problem, rtol=rtol)
        leaving = law.outside_domain(result.t, result.v - u)
        if leaving:
            warnings.warn(leaving, RuntimeWarning, stacklevel=2)
        theta = getattr(law, "theta", None)
        if theta is not None and result.state.size:
            result.extras["theta"] = theta(result.state)
        return result

    # -- drive protocols and exact output times ---------------------------------
    def _simulate_pieces(self, duration, drive, t_eval, ext, v0, state0, options):
        """Run a drive schedule (and/or stop at ``t_eval``) as consecutive pieces."""
        from dataclasses import replace

        from .drive import DriveSchedule
        from .result import SimulationResult, ledger_from_series

        if drive is None:
            T = positive("duration", duration, "length of the run")
            schedule = DriveSchedule((T,), (self.drive_velocity,))
        else:
            if self.drive != "spring":
                raise ValueError(f"drive schedule with drive = {self.drive!r}: a schedule sets the "
                                 "spring-end velocity; use drive='spring'")
            schedule = DriveSchedule.coerce(drive)
            T = schedule.duration
            if duration is not None and not math.isclose(float(duration), T, rel_tol=1e-12):
                raise ValueError(f"duration = {duration!r}: the drive schedule lasts {T!r}; "
                                 "give one or the other")
        cuts = list(schedule.boundaries)
        if t_eval is not None:
            te = np.atleast_1d(np.asarray(t_eval, dtype=float))
            if te.ndim != 1 or not np.all(np.isfinite(te)) or np.any(te < 0) or np.any(te > T):
                raise ValueError(f"t_eval: must be finite times within [0, {T!r}]")
            if np.any(np.diff(te) <= 0):
                raise ValueError("t_eval: times must be strictly increasing")
            cuts = sorted(set(cuts) | set(te.tolist()))
        cuts = np.array(cuts)
        cuts = cuts[np.concatenate(([True], np.diff(cuts) > 1e-12 * T))]
        cuts[-1] = T
        parts = []
        x_off, energy = 0.0, np.zeros(3)
        for a, b in zip(cuts[:-1], cuts[1:]):
            velocity = float(schedule.velocity(0.5 * (a + b)))
            block = replace(self, drive_velocity=velocity) if self.drive == "spring" else self
            kwargs = dict(options)
            if parts:
                last = parts[-1]
                kwargs.update(initial_extension=float(last.drive_position[-1] - last.x[-1]),
                              initial_velocity=0.0 if self.mass == 0.0 else float(last.v[-1]),
                              initial_state=last.state[:, -1] if last.state.size else None)
            else:
                kwargs.update(initial_extension=ext, initial_velocity=v0, initial_state=state0)
            r = block.simulate(b - a, **kwargs)
            parts.append(r)
            if not r.success:
                break
        # stitch: time, positions and cumulative energies continue; the repeated first
        # sample of each later piece is dropped (an event there maps to the previous end)
        ts, xs, vs, xas, sts, wds, wfs, wdms, events = [], [], [], [], [], [], [], [], []
        n, nfev = 0, 0
        for k, (a, r) in enumerate(zip(cuts, parts)):
            lo = 0 if k == 0 else 1
            base = n - lo
            ts.append(r.t[lo:] + a)
            xs.append(r.x[lo:] + x_off)
            xas.append(r.drive_position[lo:] + x_off)
            vs.append(r.v[lo:])
            sts.append(r.state[:, lo:])
            wds.append(r.drive_work[lo:] + energy[0])
            wfs.append(r.friction_dissipation[lo:] + energy[1])
            wdms.append(r.damper_dissipation[lo:] + energy[2])
            events.extend(Event(time=e.time + a, kind=e.kind, index=e.index + base,
                                spring_force=e.spring_force) for e in r.events)
            n += r.t.size - lo
            nfev += r.nfev
            x_off += r.x[-1]
            energy += (r.drive_work[-1], r.friction_dissipation[-1], r.damper_dissipation[-1])
        t, x, v, xa = (np.concatenate(z) for z in (ts, xs, vs, xas))
        state = np.concatenate(sts, axis=1)
        wd, wf, wdm = (np.concatenate(z) for z in (wds, wfs, wdms))
        last = parts[-1]
        ledger = ledger_from_series(t, x, v, xa, self.stiffness, self.mass, wd, wf, wdm)
        extras = {"drive_schedule": schedule}
        theta = getattr(self.law, "theta", None)
        if theta is not None and state.size:
            extras["theta"] = theta(state)
        if t_eval is not None:
            extras["eval_index"] = np.searchsorted(t, te - 1e-13 * T).clip(0, t.size - 1)
        return SimulationResult(t=t, x=x, v=v, drive_position=xa, state=state, drive_work=wd,
                                friction_dissipation=wf, damper_dissipation=wdm,
                                events=tuple(events), energy=ledger, stiffness=self.stiffness,
                                mass=self.mass, state_names=last.state_names,
                                status=last.status, message=last.message, nfev=nfev,
                                extras=extras)
