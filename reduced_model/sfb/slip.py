"""One SFB slip in the reduced model: released at the yield point, followed to re-stick.

The block (M, K) is released from a spring extension x0 with the spring end
held (``drive="fixed"``: the SFB's slip is much shorter than its cycle) and
slides on a friction law from :mod:`filmfriction.reduced_model.laws`;
:func:`run_slip` finds the solidification point s on the model's trace and
reads the slip time, distance and energies there from the model's energy
ledger.

Example
-------
>>> from filmfriction.reduced_model import laws
>>> film = laws.NewtonianFilm(viscosity=27.0, area=4e-10, thickness=3.5e-9)
>>> run = run_slip(1.47e-3, 97.0, 103e-9, film, restick_force=97.0 * 49e-9)
>>> round(run.slip_time * 1e3, 1), round(run.slip_distance * 1e9, 1)     # ms, nm
(23.8, 54.0)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..springblock import SpringBlock

__all__ = ["SlipRun", "run_slip", "time_to_fraction"]


@dataclass(frozen=True, eq=False)
class SlipRun:
    """One slip from the yield point, computed with the reduced model (SI).

    Attributes
    ----------
    label : str
    t, x, v, spring_force : numpy.ndarray
        The model's trace from y (t = 0, x = 0) to the end of the run (past s).
    x0 : float
        Spring extension at y, m.
    slip_time : float
        τ_s: time from y to s, s (``nan`` if s was not reached).
    slip_distance : float
        Slip at s, m.
    spring_energy_released : float
        K x0²/2 − K(x0 − Δx)²/2 from y to s, J.
    viscous_energy : float
        Friction dissipation from the model's energy ledger from y to s, J.
    kinetic_energy_at_stick : float
        M v(s)²/2, J: what Eq. (1) leaves for the ringing.
    peak_velocity : float
        Largest slip velocity before s, m/s.
    ledger_closure : float
        The model's energy-ledger closure (relative).
    end_rule : str
        How s was found.
    """

    label: str
    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    spring_force: np.ndarray
    x0: float
    slip_time: float
    slip_distance: float
    spring_energy_released: float
    viscous_energy: float
    kinetic_energy_at_stick: float
    peak_velocity: float
    ledger_closure: float
    end_rule: str

    @property
    def viscous_fraction(self) -> float:
        """Viscous share of the energy dissipated per cycle (viscous + residual kinetic)."""
        total = self.viscous_energy + self.kinetic_energy_at_stick
        return self.viscous_energy / total if total > 0 else math.nan

    @property
    def mean_shear_rate_factor(self) -> float:
        """Mean slip velocity Δx/τ_s, m/s (divide by D for the shear rate)."""
        return self.slip_distance / self.slip_time if self.slip_time > 0 else math.nan


def _crossing(t, y, level):
    """First time at which the decreasing/increasing series ``y`` reaches ``level``
    (linear interpolation between samples), or ``None``."""
    y = np.asarray(y)
    sign0 = np.sign(y[0] - level)
    if sign0 == 0:
        return float(t[0]), 0
    hit = np.nonzero(np.sign(y - level) != sign0)[0]
    if hit.size == 0:
        return None, None
    i = int(hit[0])
    f = (level - y[i - 1]) / (y[i] - y[i - 1])
    return float(t[i - 1] + f * (t[i] - t[i - 1])), i


def run_slip(mass: float, stiffness: float, x0: float, law, *, restick_force: float | None = None,
             label: str = "", time_scale: float | None = None, samples: int = 4000,
             relaxed_fraction: float = 0.99, model_mass: float | None = None) -> SlipRun:
    """Release the block from a spring extension ``x0`` (spring end fixed) and follow the slip.

    The reduced model (:class:`filmfriction.reduced_model.SpringBlock`, ``drive="fixed"``)
    integrates the slip; this function only finds s and reads the trace and
    the energy ledger there.

    Parameters
    ----------
    mass, stiffness : float
        M (kg) and K (N/m).
    x0 : float
        Spring extension at the yield point, m (spring force K x0).
    law : reduced_model.laws.FrictionLaw
        The film during the slip.  A law with a static threshold must hold less
        than K x0 (the block is released just past yield).
    restick_force : float, optional
        Spring force at which the film re-solidifies (s).  ``None``: s is the
        model's own re-stick event, or if it never sticks (an overdamped slip
        only approaches rest) the time at which ``relaxed_fraction`` of the
        final slip is reached.
    label : str
    time_scale : float, optional
        Expected slip time scale, s (default: from the law's drag and the
        oscillator period); the run is extended until s is reached.
    samples : int
        Samples per run of the closed-form path.
    relaxed_fraction : float
        See ``restick_force``.
    model_mass : float, optional
        Mass given to the integrator instead of ``mass`` (kinetic energies
        still use ``mass``).  Used for strongly overdamped slips, whose
        inertial time 2M/B is many decades below the slip time B/K and would
        make the explicit integrator take ~B²/(MK) steps; a heavier block
        that keeps 4MK/B² ≪ 1 changes the slip by O(MK/B²).

    Returns
    -------
    SlipRun
    """
    if restick_force is not None and not restick_force < stiffness * x0:
        raise ValueError(f"restick_force = {restick_force!r} N: must be below the yield force "
                         f"K x0 = {stiffness * x0:.4g} N (the spring relaxes during the slip)")
    period = 2.0 * math.pi * math.sqrt(mass / stiffness)
    if time_scale is None:
        drag = getattr(law, "drag_coefficient", None)
        time_scale = max(period, drag / stiffness if drag else 0.0)
    block = SpringBlock(mass=mass if model_mass is None else model_mass, stiffness=stiffness,
                        drive_velocity=0.0, drive="fixed", law=law)
    duration = 8.0 * time_scale
    for _attempt in range(12):
        r = block.simulate(duration, initial_extension=x0, samples_per_segment=samples)
        t, x, v, F = r.t, r.x, r.v, r.spring_force
        end, rule = None, ""
        if restick_force is not None:
            end, _ = _crossing(t, F, restick_force)
            rule = f"spring force falls to the re-stick level {restick_force:.4g} N"
        else:
            stops = [e for e in r.events if e.kind in ("stick", "rest")]
            if stops:
                end, rule = float(stops[0].time), f"model's own '{stops[0].kind}' event (v = 0)"
            else:
                # An overdamped slip only approaches rest, at x0 - F_k/K (F_k: the law's
                # rate-independent part).  The end is where it has covered relaxed_fraction of that.
                kinetic = law.sliding_force(0.0, law.steady_state(0.0), 1.0)
                final = x0 - float(kinetic) / stiffness
                end, _ = _crossing(t, x, relaxed_fraction * final)
                rule = (f"overdamped slip never stops: {relaxed_fraction:.0%} of the final slip "
                        f"x0 - F_k/K = {final:.4g} m")
        if end is not None:
            break
        duration *= 4.0
    else:
        end, rule = math.nan, "s not reached"
    if math.isfinite(end):
        xs = float(np.interp(end, t, x))
        vs = float(np.interp(end, t, v))
        wf = float(np.interp(end, t, r.friction_dissipation + r.damper_dissipation))
        vmax = float(np.max(np.abs(v[t <= end]))) if np.any(t <= end) else abs(vs)
    else:
        xs = vs = wf = vmax = math.nan
    released = 0.5 * stiffness * (x0**2 - (x0 - xs) ** 2)
    return SlipRun(label=label, t=t, x=x, v=v, spring_force=F, x0=x0, slip_time=end,
                   slip_distance=xs, spring_energy_released=released, viscous_energy=wf,
                   kinetic_energy_at_stick=0.5 * mass * vs * vs, peak_velocity=vmax,
                   ledger_closure=float(r.energy.closure), end_rule=rule)


def time_to_fraction(run: SlipRun, fraction: float) -> float:
    """Time at which a fully relaxing slip has covered ``fraction`` of x0 (nan: never)."""
    end, _ = _crossing(run.t, run.x, fraction * run.x0)
    return math.nan if end is None else end
