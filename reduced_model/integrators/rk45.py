"""A Coulomb + viscous spring-block integrated the way a user writes it by hand.

Slips are integrated with a plain ``scipy.integrate.solve_ivp`` RK45 to the
event v = 0, sticks are linear ramps solved in closed form.  Unlike
:meth:`SpringBlock.simulate <filmfriction.reduced_model.SpringBlock.simulate>`
(exact closed form, or an event-driven DOP853 with an exact re-stick), its
error follows its tolerance: the trade study
(``filmfriction tradeoff``) measures that cost and error against the closed
form, which is why it is kept as it is.

Example
-------
>>> from filmfriction.reduced_model import SpringBlock, laws
>>> block = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.1,
...                     law=laws.Coulomb(static=1.0, kinetic=0.5))
>>> t, force, x, kinds = rk45_stick_slip(block, 30.0, rtol=1e-9)
>>> kinds[:3], round(float(t[1]), 9)                # the first stick lasts Fs/(K V)
(['start', 'slip', 'stick'], 10.0)
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from ..laws import Coulomb

__all__ = ["rk45_stick_slip"]


def rk45_stick_slip(block, duration: float, rtol: float, atol: float = 1e-9):
    """Integrate ``block`` (Coulomb + viscous law, spring drive) with RK45 slips and exact sticks.

    Parameters
    ----------
    block : SpringBlock
        ``drive="spring"`` with a :class:`~filmfriction.reduced_model.laws.Coulomb` law
        (static, kinetic and viscous used; no freeze velocity, rigid stick), starting at
        rest on a relaxed spring.
    duration : float
        Length of the run.
    rtol, atol : float
        Tolerances of ``solve_ivp`` (RK45).

    Returns
    -------
    t, spring_force, x : numpy.ndarray
        Sampled at the start and at each event.
    kinds : list of str
        ``"start"``, then ``"slip"`` (a yield) and ``"stick"`` (a re-stick) per event.

    Raises
    ------
    ValueError
        Not a Coulomb law or not a spring drive.
    """
    law = block.law
    if not isinstance(law, Coulomb) or block.drive != "spring":
        raise ValueError(f"rk45_stick_slip: needs a Coulomb law and drive='spring', got "
                         f"{type(law).__name__} and drive={block.drive!r}")
    M, K, V, d = block.mass, block.stiffness, block.drive_velocity, block.damping
    fs, fk, b = law.static * block.normal_load, law.kinetic * block.normal_load, law.viscous
    t, x = 0.0, 0.0
    ts, fs_, xs, kinds = [0.0], [0.0], [0.0], ["start"]
    while t < duration:
        # stick: the force K (V t - x) rises linearly to Fs (SpringBlock's damper acts
        # on the block's own velocity, zero while stuck)
        t = max(t, (fs / K + x) / V)
        if t >= duration:
            break
        ts.append(t), fs_.append(K * (V * t - x)), xs.append(x), kinds.append("slip")
        t0, x0 = t, x

        def rhs(tau, y, t0=t0):
            f = K * (V * (t0 + tau) - y[0]) - d * y[1] - fk - b * y[1]
            return [y[1], f / M]

        def stop(tau, y):
            return y[1]
        stop.terminal, stop.direction = True, -1
        sol = solve_ivp(rhs, (0.0, duration - t0), [x0, 1e-12], method="RK45", rtol=rtol,
                        atol=atol, events=stop)
        x, t = float(sol.y[0, -1]), t0 + float(sol.t[-1])
        ts.append(t), fs_.append(K * (V * t - x)), xs.append(x), kinds.append("stick")
        if sol.status != 1:
            break
    return np.array(ts), np.array(fs_), np.array(xs), kinds
