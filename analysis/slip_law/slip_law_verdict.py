"""The slip law's verdict on one fitted branch: viscous, kinetic, mixed, weakening or inconclusive.

The rule (:mod:`filmfriction.analysis.slip_law.slip_law` tells the physics): a term is
resolved when it exceeds :data:`~filmfriction.analysis.slip_law.slip_law_stats.RESOLVED_SIGMAS`
and carries at least :data:`NUMERICAL_FLOOR` of the film force; a term not resolved is
ruled out as dominant when the run would have resolved it at
:data:`DOMINANT_SHARE` of the mean film force with 95 % power.

>>> branch_verdict(0.1, 0.5, 0.2, 2.0, 10.0, 1.0, 10.0, 3.6, 1.0, 10.1, 8)[0]
'viscous'
"""
from __future__ import annotations

import math

from .slip_law_stats import RESOLVED_SIGMAS, detectable, sigmas

__all__ = ["branch_verdict", "choose_law", "VERDICTS", "DOMINANT_SHARE", "NUMERICAL_FLOOR",
           "ONE_LAW"]

#: The name of the fit of the whole slip with a co-moving mass, the slip's one law.
ONE_LAW = "one law"

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
    :mod:`filmfriction.analysis.slip_law.slip_law`): F_k and B with their standard errors,
    normal-equivalent sigmas and the smallest values the run resolves at 95 % power,
    the mean velocity and film force, and the number of slips."""
    r = RESOLVED_SIGMAS
    nums = (f"F_k = {fk:.4g} ± {se_fk:.2g} ({z_fk:+.1f} σ), B = {b:.4g} ± {se_b:.2g} "
            f"({z_b:+.1f} σ) over {n} slip(s); F̄ = {fbar:.4g} at v̄ = {vbar:.4g}; "
            f"95 % power at {r:.3g} σ for B ≥ {det_b:.3g}, F_k ≥ {det_fk:.3g}")
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
    if z_fk <= -r and fk_big:
        # no friction force pushes: the line misses the law (on the decelerating branch,
        # a mass carried with the wall, m_c·a < 0, reads as a negative intercept)
        return "inconclusive", f"F_k resolved negative, F_k + B·v does not hold: {nums}"
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


def choose_law(decelerating, one_law, loop_step, mass: float,
               film_mass: float | None = None) -> tuple[str, str, str]:
    """Which fit the verdict is — :data:`ONE_LAW` or ``decelerating`` — its verdict and why.

    The whole slip is one law F_k + B·v + m_c·a (the ``one_law`` fit) when no loop is
    left beyond the co-moving mass: the step of the force at the peak velocity
    (``loop_step``: the whole slip fitted with it too) is not resolved and the run
    had 95 % power to resolve it at :data:`DOMINANT_SHARE` of the one law's mean film
    force, m_c is not resolved negative (no mass moves against the wall) and, where the
    film's own mass ``film_mass`` is known, not resolved above it (the film's atoms are
    all the mass that can move with the wall beyond its own: a larger m_c is a yield loop
    the m_c·a term absorbs, since a is positive while the force is higher and negative
    after the peak, not inertia); as in
    :func:`branch_verdict`, a step under :data:`NUMERICAL_FLOOR` of F̄ and an m_c under
    that share of the wall's ``mass`` (and an m_c that much above the film's) count as not
    resolved.  A
    liquid's slip (no yield) is such a slip; a film that yields on the accelerating
    branch is not, and its verdict is the decelerating branch's — except that a
    ``viscous`` decelerating branch fitted without a co-moving mass, while the one law
    resolves a positive one and a positive kinetic force, is ``inconclusive``: m_c·a < 0
    on that branch reads as a negative intercept and can cancel the kinetic force (the
    release's kinetic control, docs/results/slip-law.md).
    """
    if film_mass is not None and not (math.isfinite(film_mass) and film_mass > 0):
        raise ValueError(f"film_mass = {film_mass!r}: a positive mass, or None (not known)")
    r = RESOLVED_SIGMAS
    step, se, dof = loop_step.loop_step, loop_step.loop_step_stderr, loop_step.dof
    z = sigmas(step, se, dof)
    det = detectable(se, dof)
    fbar = one_law.mean_force
    z_mc = sigmas(one_law.comoving_mass, one_law.comoving_mass_stderr, one_law.dof)
    # the film's atoms are the most mass that can move with the wall
    excess = -math.inf if film_mass is None else one_law.comoving_mass - film_mass
    z_above = sigmas(excess, one_law.comoving_mass_stderr, one_law.dof)   # nan: not known
    nums = (f"loop step F_acc − F_dec = {step:.3g} ± {se:.2g} ({z:+.1f} σ), 95 % power at "
            f"{r:.3g} σ for {det:.3g} against F̄/2 = {DOMINANT_SHARE * fbar:.3g}; m_c = "
            f"{one_law.comoving_mass:.3g} ± {one_law.comoving_mass_stderr:.2g} ({z_mc:+.1f} σ)")
    if not all(math.isfinite(q) for q in (z, det, fbar, z_mc)):
        why = "the one law's errors not defined"
    elif abs(z) >= r and abs(step) >= NUMERICAL_FLOOR * abs(fbar):
        why = "a loop resolved beyond the co-moving mass"
    elif not (fbar > 0 and det < DOMINANT_SHARE * fbar):
        why = "a loop of half the film force could go unresolved"
    elif z_mc <= -r and -one_law.comoving_mass >= NUMERICAL_FLOOR * mass:
        why = "the co-moving mass resolved negative"
    elif z_above >= r and excess >= NUMERICAL_FLOOR * mass:
        why = (f"the co-moving mass resolved above the film's own mass {film_mass:.4g} by "
               f"{excess:.3g} ({z_above:+.1f} σ): a loop the m_c·a term absorbs, not inertia")
    else:
        return ONE_LAW, one_law.verdict, (f"the whole slip is one law with a co-moving "
                                          f"mass ({nums}): {one_law.reason}")
    verdict, reason = decelerating.verdict, decelerating.reason
    z_fk = sigmas(one_law.kinetic_force, one_law.kinetic_force_stderr, one_law.dof)
    if (verdict == "viscous" and not math.isfinite(decelerating.comoving_mass)
            and z_mc >= r and one_law.comoving_mass >= NUMERICAL_FLOOR * mass
            and z_fk >= r and one_law.kinetic_force >= NUMERICAL_FLOOR * abs(fbar)):
        # the branch has no co-moving mass term while the one law resolves one and a kinetic
        # force: on the decelerating branch m_c·a < 0 reads as a negative intercept, which
        # can cancel the kinetic force the one law sees
        verdict, reason = "inconclusive", (
            f"{reason}; but the one law resolves a co-moving mass the branch does not fit "
            f"(its m_c·a < 0 biases the branch's F_k low) and a kinetic force, F_k = "
            f"{one_law.kinetic_force:.3g} ± {one_law.kinetic_force_stderr:.2g} ({z_fk:+.1f} σ)")
    return "decelerating", verdict, (
        f"{reason}; the decelerating branch's, the whole slip not one law ({why}: {nums})")
