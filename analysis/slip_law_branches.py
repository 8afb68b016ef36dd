"""One branch of the slips fitted: F_film = F_k + B·v [+ m_c·a] in the integrated equation of motion.

:class:`Segment` holds one branch of one slip in integral form; :func:`fit_branch`
fits each slip, takes the mean over the slips (the errors their scatter, or with
fewer than :data:`MIN_SLIPS_FOR_SCATTER` slips the pooled fit's), the exponent, the
power and the verdict (:func:`~filmfriction.analysis.slip_law_verdict.branch_verdict`).
The physics is :mod:`filmfriction.analysis.slip_law`'s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .slip_law_stats import correlation_time, detectable, ols, sigmas
from .slip_law_verdict import branch_verdict

__all__ = ["BranchFit", "Segment", "fit_branch", "MIN_SLIPS_FOR_SCATTER"]

#: With this many slips or more, the errors are the scatter of the per-slip fits.
MIN_SLIPS_FOR_SCATTER = 3


@dataclass(frozen=True)
class BranchFit:
    """F_film = F_k + B·v [+ m_c·a] fitted on one branch of the slips (see the module text).

    Attributes
    ----------
    branch : str
        ``decelerating``, ``accelerating`` or ``whole``.
    kinetic_force, kinetic_force_stderr : float
        F_k and its standard error (force units).
    damping, damping_stderr : float
        B and its standard error (force per velocity).
    comoving_mass, comoving_mass_stderr : float
        m_c and its standard error (NaN when the term was not fitted).
    mean_velocity, mean_force : float
        v̄ and F̄, the means of the fitted samples.
    viscous_share : float
        B·v̄ / F̄.
    exponent, exponent_stderr : float
        n = d ln F/d ln v of the fitted law at each slip's mean velocity, mean and
        standard error over the slips.
    kinetic_sigmas, damping_sigmas : float
        F_k and B in normal-equivalent standard errors (signed).
    detectable_damping, detectable_kinetic_force : float
        The smallest B and F_k the run resolves at 2 σ with 95 % power.
    dof : int
        Degrees of freedom of the errors.
    verdict, reason : str
        One of :data:`VERDICTS`, and the numbers it rests on.
    per_slip_kinetic_force, per_slip_damping, per_slip_exponent : ndarray
        Per-slip fits (NaN where a slip had too few samples on this branch).
    samples, slips : int
        Samples and slips fitted.
    velocity_residual : float
        Root-mean-square residual of the pooled integral fit over M: how far the
        wall's velocity strays from the law's (velocity units).
    """

    branch: str
    kinetic_force: float
    kinetic_force_stderr: float
    damping: float
    damping_stderr: float
    comoving_mass: float
    comoving_mass_stderr: float
    mean_velocity: float
    mean_force: float
    viscous_share: float
    exponent: float
    exponent_stderr: float
    kinetic_sigmas: float
    damping_sigmas: float
    detectable_damping: float
    detectable_kinetic_force: float
    dof: int
    verdict: str
    reason: str
    per_slip_kinetic_force: np.ndarray
    per_slip_damping: np.ndarray
    per_slip_exponent: np.ndarray
    samples: int
    slips: int
    velocity_residual: float


@dataclass(frozen=True)
class Segment:
    """One branch of one slip in integral form (module text): the response y, the
    regressors Δt, Δx and v − v0, and the branch's mean velocity."""

    y: np.ndarray           # ∫F_spring dt − γM(Δx − VΔt) − M v
    dt: np.ndarray
    dx: np.ndarray
    dv: np.ndarray          # v − v0 of the smoothed velocity (the m_c term)
    mass: float

    @property
    def mean_velocity(self) -> float:
        return float(self.dx[-1] / self.dt[-1]) if self.dt[-1] > 0 else math.nan

    def design(self, comoving: bool, intercepts: int = 1, which: int = 0):
        """Columns [intercepts…, Δt, Δx (, v − v0)] and the response (with m_c, the
        response without the −M·v it would otherwise hold: M·v joins m_c·v)."""
        cols = [np.full(self.y.size, float(k == which)) for k in range(intercepts)]
        cols += [self.dt, self.dx]
        return cols + ([self.dv] if comoving else [])


def fit_branch(branch: str, segments: list[Segment | None], comoving: bool) -> BranchFit:
    """Per-slip fits on one branch, their mean, errors, power and verdict."""
    nterms = 4 if comoving else 3
    per = []                       # (fk, b, mc, vbar) per slip
    used, resids = [], []
    for seg in segments:
        if seg is None or seg.y.size < nterms + 3:
            per.append((math.nan,) * 4)
            continue
        coef, _, res = ols(np.column_stack(seg.design(comoving)), seg.y, errors=False)
        resids.append(res)
        # with m_c, the coefficient of v − v0 is M + m_c
        per.append((float(coef[1]), float(coef[2]),
                    float(coef[3]) - seg.mass if comoving else math.nan, seg.mean_velocity))
        used.append(seg)
    per = np.array(per, float).reshape(-1, 4)
    nan = math.nan
    if not used:
        return BranchFit(branch, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan,
                         nan, nan, nan, 0, "inconclusive",
                         f"no slip with {nterms + 3} or more samples on the {branch} branch "
                         "above the velocity floor", per[:, 0], per[:, 1], per[:, 0] * nan,
                         0, 0, nan)
    m = len(used)
    ok = np.isfinite(per[:, 0]) & np.isfinite(per[:, 1])
    n = int(ok.sum())
    with np.errstate(invalid="ignore", divide="ignore"):
        expo = per[:, 1] * per[:, 3] / (per[:, 0] + per[:, 1] * per[:, 3])
    if n >= MIN_SLIPS_FOR_SCATTER:
        # the slips are the replicas: the standard error of their mean
        est = per[ok, :3].mean(axis=0)
        se = per[ok, :3].std(axis=0, ddof=1) / math.sqrt(n)
        dof = n - 1
    else:
        # too few slips for a scatter: the pooled fit (one intercept per slip, common
        # F_k, B (, m_c)), its errors widened for the residuals' correlation, with the
        # degrees of freedom of its independent samples
        X = np.vstack([np.column_stack(s.design(comoving, m, k)) for k, s in enumerate(used)])
        y = np.concatenate([s.y for s in used])
        coef, pse, resid = ols(X, y)
        est = np.array([coef[m], coef[m + 1], coef[m + 2] - used[0].mass if comoving else nan])
        se = np.array([pse[m], pse[m + 1], pse[m + 2] if comoving else nan])
        dof = max(int(y.size / correlation_time(resid)) - (m + nterms - 1), 1)
    fk, b, mc = (float(x) for x in est)
    se_fk, se_b, se_mc = (float(x) for x in se)
    ex = expo[ok][np.isfinite(expo[ok])]
    n_mean = float(ex.mean()) if ex.size else nan
    n_se = float(ex.std(ddof=1) / math.sqrt(ex.size)) if ex.size >= 2 else nan
    vbar = float(np.nanmean(per[ok, 3])) if n else nan
    fbar = fk + b * vbar
    share = b * vbar / fbar if fbar > 0 else nan
    # the residual as the error of the law's wall velocity: (response residual) / M
    allres = np.concatenate(resids)
    vres = float(np.sqrt(np.mean(allres ** 2))) / used[0].mass
    z_fk, z_b = sigmas(fk, se_fk, dof), sigmas(b, se_b, dof)
    det_b, det_fk = detectable(se_b, dof), detectable(se_fk, dof)
    verdict, reason = branch_verdict(fk, se_fk, z_fk, det_fk, b, se_b, z_b, det_b, vbar, fbar, n)
    return BranchFit(branch, fk, se_fk, b, se_b, mc, se_mc, vbar,
                     fbar, share, n_mean, n_se, z_fk, z_b, det_b, det_fk, dof, verdict, reason,
                     per[:, 0], per[:, 1], expo, int(allres.size), n, vres)
