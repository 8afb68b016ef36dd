"""The slip law's verdict on one fitted branch: viscous, kinetic, mixed, weakening or inconclusive.

The rule (:mod:`filmfriction.analysis.slip_law` tells the physics): a term is
resolved when it exceeds :data:`~filmfriction.analysis.slip_law_stats.RESOLVED_SIGMAS`
and carries at least :data:`NUMERICAL_FLOOR` of the film force; a term not resolved is
ruled out as dominant when the run would have resolved it at
:data:`DOMINANT_SHARE` of the mean film force with 95 % power.

>>> branch_verdict(0.1, 0.5, 0.2, 2.0, 10.0, 1.0, 10.0, 3.6, 1.0, 10.1, 8)[0]
'viscous'
"""
from __future__ import annotations

import math

from .slip_law_stats import RESOLVED_SIGMAS

__all__ = ["branch_verdict", "VERDICTS", "DOMINANT_SHARE", "NUMERICAL_FLOOR"]

#: The verdicts, in the order the rules are tried.
VERDICTS = ("velocity-weakening", "mixed", "viscous", "kinetic", "inconclusive")
#: A term not resolved is ruled out as dominant when the run would have resolved it (at 95 %
#: power) carrying this share of the mean film force.
DOMINANT_SHARE = 0.5
#: A term is resolved only when it also carries at least this share of the film force
#: (|F_k| + |B·v̄|): the numerical floor of the sampled equation of motion (its
#: trapezoid impulse and the sampling leave terms of 1e-4–1e-3 of the force on exact
#: model traces at the controls' sampling, with standard errors far smaller).
NUMERICAL_FLOOR = 0.01


def branch_verdict(fk, se_fk, z_fk, det_fk, b, se_b, z_b, det_b, vbar, fbar, n):
    """The verdict of one branch and the numbers it rests on (the rule of
    :mod:`filmfriction.analysis.slip_law`): F_k and B with their standard errors,
    normal-equivalent sigmas and the smallest values the run resolves at 95 % power,
    the mean velocity and film force, and the number of slips."""
    r = RESOLVED_SIGMAS
    nums = (f"F_k = {fk:.4g} ± {se_fk:.2g} ({z_fk:+.1f} σ), B = {b:.4g} ± {se_b:.2g} "
            f"({z_b:+.1f} σ) over {n} slip(s); F̄ = {fbar:.4g} at v̄ = {vbar:.4g}; "
            f"95 % power at 2 σ for B ≥ {det_b:.3g}, F_k ≥ {det_fk:.3g}")
    if not all(math.isfinite(x) for x in (z_fk, z_b, fbar, vbar)):
        return "inconclusive", f"errors not defined: {nums}"
    # a term counts only above the numerical floor too: on an exact trace its error is
    # ~0 and the quadrature's own error would otherwise read as a resolved term
    floor = NUMERICAL_FLOOR * (abs(fk) + abs(b * vbar))
    b_big, fk_big = abs(b * vbar) >= floor, abs(fk) >= floor
    small = [f"{name} carries {abs(val) / (abs(fk) + abs(b * vbar)):.1e} of the force, "
             f"under the numerical floor {NUMERICAL_FLOOR:g}"
             for name, val, big, z in (("F_k", fk, fk_big, z_fk), ("B·v̄", b * vbar, b_big, z_b))
             if abs(z) >= r and not big]
    if small:
        nums = f"{nums}; {'; '.join(small)}"
    if z_b <= -r and b_big:
        return "velocity-weakening", f"B resolved negative: {nums}"
    b_res, fk_res = z_b >= r and b_big, z_fk >= r and fk_big
    if b_res and fk_res:
        return "mixed", f"both terms resolved (viscous share {b * vbar / fbar:.2f}): {nums}"
    if fbar <= 0:
        return "inconclusive", f"mean film force not positive: {nums}"
    hidden_visc = det_b * vbar / fbar       # share a viscous term could carry unseen
    hidden_kin = det_fk / fbar
    if b_res:
        if hidden_kin < DOMINANT_SHARE:
            return "viscous", (f"B resolved, F_k not; a kinetic force of {hidden_kin:.2f} F̄ "
                               f"would have been resolved: {nums}")
        return "inconclusive", (f"B resolved, F_k not, but a kinetic force up to "
                                f"{hidden_kin:.2f} F̄ could go unresolved: {nums}")
    if fk_res:
        if hidden_visc < DOMINANT_SHARE:
            return "kinetic", (f"F_k resolved, B not; a viscous force of {hidden_visc:.2f} F̄ "
                               f"would have been resolved: {nums}")
        return "inconclusive", (f"F_k resolved, B not, but a viscous force up to "
                                f"{hidden_visc:.2f} F̄ could go unresolved: {nums}")
    return "inconclusive", f"neither term resolved: {nums}"
