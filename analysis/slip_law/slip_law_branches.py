"""One branch of the slips fitted: F_film = F_k + B·v [+ m_c·a], integrated equation of motion.

:class:`Segment` holds one branch of one slip in integral form; :func:`fit_branch`
fits each slip, takes the mean over the slips (the errors their scatter, or with
fewer than :data:`MIN_SLIPS_FOR_SCATTER` slips the pooled fit's), the exponent, the
power and the verdict (:func:`~filmfriction.analysis.slip_law.slip_law_verdict.branch_verdict`).
The physics is :mod:`filmfriction.analysis.slip_law.slip_law`'s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .slip_law_stats import correlation_time, detectable, ols, sigmas
from .slip_law_verdict import branch_verdict

__all__ = ["BranchFit", "Segment", "fit_branch", "jackknife_branch", "jackknife",
           "MIN_SLIPS_FOR_SCATTER"]

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
        The smallest B and F_k the run resolves at 2.24 σ (``RESOLVED_SIGMAS``) with 95 %
        power.
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
    loop_step, loop_step_stderr : float
        With the loop step fitted: the force's step at the peak velocity,
        F_acc − F_dec (positive when the accelerating branch lies above), else NaN.
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
    loop_step: float = math.nan
    loop_step_stderr: float = math.nan


@dataclass(frozen=True)
class Segment:
    """One branch of one slip in integral form (module text): the impulse y, the
    sampled velocity v, the regressors Δt, Δx and v − v0, and the time past the slip's
    peak velocity (the loop step's regressor)."""

    y: np.ndarray           # ∫F_spring dt − γM(Δx − VΔt)
    v: np.ndarray           # the sampled wall velocity (the wall's own M·v)
    dt: np.ndarray
    dx: np.ndarray
    dv: np.ndarray          # v − v0 of the smoothed velocity (the m_c term)
    mass: float
    after_peak: np.ndarray  # max(Δt − Δt_peak, 0)
    registry: np.ndarray | None = None  # ∫sin, ∫cos(2π·h·x/λ) dt, (samples, 2·harmonics)
    viscous_dx: np.ndarray | None = None  # ∫v_f dt, the lagging film's B regressor (else Δx)

    @property
    def mean_velocity(self) -> float:
        return float(self.dx[-1] / self.dt[-1]) if self.dt[-1] > 0 else math.nan

    @property
    def response(self) -> np.ndarray:
        """The response y − M·v (the wall's own momentum from its sampled velocity, which
        the impulse balances sample by sample; with m_c, its smoothed velocity is the
        film's regressor alone, so a sampled velocity's noise is response noise there,
        not an error in a regressor)."""
        return self.y - self.mass * self.v

    def design(self, comoving: bool, intercepts: int = 1, which: int = 0, step: bool = False):
        """Columns [intercepts…, Δt, Δx (, v − v0) (, the registry's) (, time past the
        peak)]."""
        cols = [np.full(self.y.size, float(k == which)) for k in range(intercepts)]
        cols += [self.dt, self.dx if self.viscous_dx is None else self.viscous_dx]
        reg = list(self.registry.T) if self.registry is not None else []
        return (cols + ([self.dv] if comoving else []) + reg
                + ([self.after_peak] if step else []))


def fit_branch(branch: str, segments: list[Segment | None], comoving: bool,
               loop_step: bool = False) -> BranchFit:
    """Per-slip fits on one branch, their mean, errors, power and verdict; with
    ``loop_step`` (on the whole slip) a step of the force at the peak velocity is
    fitted too, F_acc − F_dec at a common B (and m_c)."""
    nterms = 3 + comoving + loop_step + max(
        (s.registry.shape[1] for s in segments if s is not None and s.registry is not None),
        default=0)
    per = []                       # (fk, b, mc, vbar, step) per slip
    used, resids = [], []
    for seg in segments:
        if seg is None or seg.y.size < nterms + 3:
            per.append((math.nan,) * 5)
            continue
        coef, _, res = ols(np.column_stack(seg.design(comoving, step=loop_step)),
                           seg.response, errors=False)
        resids.append(res)
        # with m_c, the coefficient of v − v0 is m_c; the step's is F_dec − F_acc
        per.append((float(coef[1]), float(coef[2]),
                    float(coef[3]) if comoving else math.nan, seg.mean_velocity,
                    -float(coef[-1]) if loop_step else math.nan))
        used.append(seg)
    per = np.array(per, float).reshape(-1, 5)
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
        cols = [0, 1, 2, 4]
        est = per[np.ix_(ok, cols)].mean(axis=0)
        se = per[np.ix_(ok, cols)].std(axis=0, ddof=1) / math.sqrt(n)
        dof = n - 1
    else:
        # too few slips for a scatter: the pooled fit (one intercept per slip, common
        # F_k, B (, m_c)), its errors widened for the residuals' correlation, with the
        # degrees of freedom of its independent samples
        X = np.vstack([np.column_stack(s.design(comoving, m, k, loop_step))
                       for k, s in enumerate(used)])
        y = np.concatenate([s.response for s in used])
        coef, pse, resid = ols(X, y)
        est = np.array([coef[m], coef[m + 1], coef[m + 2] if comoving else nan,
                        -coef[-1] if loop_step else nan])
        se = np.array([pse[m], pse[m + 1], pse[m + 2] if comoving else nan,
                       pse[-1] if loop_step else nan])
        dof = max(int(y.size / correlation_time(resid)) - (m + nterms - 1), 1)
    fk, b, mc, step = (float(x) for x in est)
    se_fk, se_b, se_mc, se_step = (float(x) for x in se)
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
                     per[:, 0], per[:, 1], expo, int(allres.size), n, vres, step, se_step)


def jackknife(estimate: float, leave_one_out) -> tuple[float, np.ndarray]:
    """The jackknife's standard error of ``estimate`` (a smooth function of the mean of R
    replicas) from its values on the R means that leave one replica out, and the
    pseudo-values R·θ − (R − 1)·θ₍ᵢ₎ (per-replica values whose standard deviation over
    √R is that error: they stand for the replicas in the power of more of them).

    >>> x = np.array([1.0, 2.0, 4.0, 7.0])
    >>> loo = (x.sum() - x) / 3                  # the mean is its own jackknife
    >>> se, pseudo = jackknife(x.mean(), loo)
    >>> bool(np.isclose(se, x.std(ddof=1) / 2)), pseudo.tolist()
    (True, [1.0, 2.0, 4.0, 7.0])
    """
    th = np.asarray(leave_one_out, float)
    r = th.size
    if r < 2 or not (math.isfinite(estimate) and np.all(np.isfinite(th))):
        return math.nan, np.full(r, math.nan)
    se = math.sqrt((r - 1) / r * float(np.sum((th - th.mean()) ** 2)))
    return se, r * estimate - (r - 1) * th


def jackknife_branch(fit: BranchFit, leave_one_out: list[BranchFit], *,
                     replicas: str = "releases") -> BranchFit:
    """``fit`` (of the replicas' mean trace) with its errors from the jackknife over the
    R replicas (:func:`jackknife`, R − 1 degrees of freedom): F_k, B, m_c, the exponent
    and the loop step; the significance, the power and the verdict recomputed from them
    (:func:`~filmfriction.analysis.slip_law.slip_law_verdict.branch_verdict`); the
    per-slip arrays hold the pseudo-values, one per replica; ``replicas`` names them in
    the reason."""
    r = len(leave_one_out)
    err = {name: jackknife(getattr(fit, name), [getattr(b, name) for b in leave_one_out])
           for name in ("kinetic_force", "damping", "comoving_mass", "exponent", "loop_step")}
    dof = r - 1
    (se_fk, fk_ps), (se_b, b_ps) = err["kinetic_force"], err["damping"]
    fk, b, vbar, fbar = fit.kinetic_force, fit.damping, fit.mean_velocity, fit.mean_force
    z_fk, z_b = sigmas(fk, se_fk, dof), sigmas(b, se_b, dof)
    det_b, det_fk = detectable(se_b, dof), detectable(se_fk, dof)
    verdict, reason = branch_verdict(fk, se_fk, z_fk, det_fk, b, se_b, z_b, det_b, vbar, fbar, r)
    reason = reason.replace(f"over {r} slip(s)", f"mean of {r} {replicas}, jackknife errors")
    return replace(fit, kinetic_force_stderr=se_fk, damping_stderr=se_b,
                   comoving_mass_stderr=err["comoving_mass"][0],
                   exponent_stderr=err["exponent"][0], kinetic_sigmas=z_fk, damping_sigmas=z_b,
                   detectable_damping=det_b, detectable_kinetic_force=det_fk, dof=dof,
                   verdict=verdict, reason=reason, per_slip_kinetic_force=fk_ps,
                   per_slip_damping=b_ps, per_slip_exponent=err["exponent"][1], slips=r,
                   loop_step_stderr=err["loop_step"][0])
