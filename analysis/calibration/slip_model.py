"""The slip of a Coulomb + viscous wall: the spring force of one slip from rest at the
yield point (:func:`coulomb_slip_force`), the model that
:func:`filmfriction.analysis.calibration.slipfit.fit_slips` fits to a run's slips.

It is the damped oscillator of :mod:`filmfriction.reduced_model.integrators.oscillator`
about steady sliding (through :func:`filmfriction.analysis.viscosity.slip_force`), ending
where the wall's velocity returns to zero (its exact root,
:meth:`DampedOscillator.first_crossing <filmfriction.reduced_model.integrators.oscillator.DampedOscillator.first_crossing>`)
or, with a freeze force F_f, where the spring force has fallen to F_f (the film
re-solidifies while the wall still moves, as in Klein's traces and the MD's), then the
stick ramp.

Example
-------
>>> import numpy as np
>>> f = coulomb_slip_force(np.array([-1.0, 0.0, 1.0]), 60.0, 20.0, 80.0, 500.0, 100.0, 0.02)
>>> f[:2].tolist()                              # the stick ramp, then the yield force
[58.0, 60.0]
"""
from __future__ import annotations

import math

import numpy as np

from filmfriction.reduced_model.integrators.oscillator import DampedOscillator

from ..viscosity import slip_force

__all__ = ["coulomb_slip_force"]


def coulomb_slip_force(t, static_force: float, kinetic_force: float, damping: float,
                       mass: float, stiffness: float, drive_velocity: float,
                       freeze_force: float = -math.inf,
                       stick_rate: float | None = None) -> np.ndarray:
    """Spring force of one Coulomb + viscous slip from rest at the yield point.

    Solves ``M x'' + b x' = K(x0 + V t − x) − F_k`` from x = x' = 0 with
    K x0 = F_s (:func:`filmfriction.analysis.viscosity.slip_force` with F_s − F_k) until
    the wall velocity returns to zero or the spring force has fallen to
    ``freeze_force`` (the film re-solidifies while the wall still moves), whichever
    comes first (exact roots), after which the wall sticks and the force ramps
    at K V.  A second yield inside ``t`` is not modelled.

    Parameters
    ----------
    t : array_like
        Times since the yield point (≥ 0 where the slip applies; earlier
        times get the stick ramp F_s + K V t).
    static_force, kinetic_force : float
        F_s and F_k.
    damping : float
        Total damping b = B (film) + d (mount), force per velocity.
    mass, stiffness, drive_velocity : float
        M, K, V.
    freeze_force : float
        F_f: the slip ends where the spring force has fallen to it (default: never;
        the slip ends at rest).
    stick_rate : float, optional
        The stick ramps' slope (default K V; K_eff V on an elastic stuck film).

    Returns
    -------
    numpy.ndarray
        Spring force at ``t``.
    """
    t = np.asarray(t, dtype=float)
    k, v = stiffness, drive_velocity
    rate = k * v if stick_rate is None else stick_rate
    end = float(np.max(t)) if t.size else 0.0
    out = static_force + rate * t
    if end <= 0.0:
        return out
    drop = static_force - kinetic_force
    # about steady sliding the wall is x = x_p + u, M u'' + b u' + K u = 0, u(0) = -drop/K + b V/K,
    # u'(0) = -V: its velocity V + u' returns to zero where u' = -V (the slip starts there)
    osc = DampedOscillator(mass=mass, damping=damping, stiffness=k)
    u0 = -drop / k + damping * v / k
    t_stick = osc.first_crossing(u0, -v, -v, end, skip_start=True)
    if freeze_force < static_force:
        # the spring force is F_k + b V - K u: it falls to F_f where u = level.  u is the
        # derivative of the solution W = -(M u' + b u)/K, so first_crossing finds it
        level = (kinetic_force + damping * v - freeze_force) / k
        t_freeze = osc.first_crossing(-(mass * -v + damping * u0) / k, u0, level,
                                      end if t_stick is None else t_stick)
        if t_freeze is not None:
            t_stick = t_freeze
    if t_stick is None:
        t_stick, f_stick = math.inf, math.nan
    else:
        f_stick = kinetic_force + float(slip_force(t_stick, drop, damping, mass, k, v))
    after = t >= 0.0
    slipping = after & (t < t_stick)
    out[slipping] = kinetic_force + slip_force(t[slipping], drop, damping, mass, k, v)
    stuck = after & (t >= t_stick)
    out[stuck] = f_stick + rate * (t[stuck] - t_stick)
    return out
