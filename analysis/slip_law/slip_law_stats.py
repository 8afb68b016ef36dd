"""The slip-law fit's statistics: significance, power, least squares with correlated residuals.

:func:`sigmas` and :func:`detectable` are the verdict's significance and power
(:mod:`filmfriction.analysis.slip_law.slip_law`); :func:`ols` is the least squares of the
integrated equation of motion, its errors widened by the residuals' integrated
autocorrelation time (:func:`correlation_time`).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy import special
from scipy import stats as sps
from scipy.optimize import brentq

__all__ = ["sigmas", "detectable", "ols", "correlation_time", "mean_se", "RESOLVED_SIGMAS",
           "FALSE_ALARM", "POWER"]

#: The share of repeats in which a term that is truly absent is resolved, either sign.  A
#: verdict is lost to the absent term's false alarm or to the present term's lack of
#: power; this half of a 5 % budget leaves the other half to the power (a pure law keeps
#: its verdict in >= 95 % of repeats when the run resolves its term with 97.5 % power).
FALSE_ALARM = 0.025
#: A fitted term is resolved when it exceeds this many standard errors (normal-equivalent):
#: the two-sided quantile of :data:`FALSE_ALARM`, 2.24.
RESOLVED_SIGMAS = float(sps.norm.isf(FALSE_ALARM / 2))
#: The power at which a term the run did not resolve is ruled out.
POWER = 0.95


def sigmas(estimate: float, stderr: float, dof: int) -> float:
    """``estimate/stderr`` as normal-equivalent standard errors (signed): the t of ``dof``
    degrees of freedom mapped to the normal quantile of the same tail probability.

    >>> round(sigmas(2.0, 1.0, 10**6), 3), round(sigmas(2.0, 1.0, 4), 2)
    (2.0, 1.57)
    """
    if not (math.isfinite(estimate) and math.isfinite(stderr) and stderr >= 0 and dof >= 1):
        return math.nan
    if stderr == 0:
        return math.copysign(38.0, estimate) if estimate else 0.0
    t = estimate / stderr
    # the normal quantile of the t's upper tail: norm.isf(t.sf(|t|, dof)), by the special
    # functions themselves (the distributions' wrappers cost a millisecond a call)
    z = -float(special.ndtri(special.stdtr(dof, -abs(t))))
    return math.copysign(min(z, 38.0), t)


def detectable(stderr: float, dof: int, *, resolved: float = RESOLVED_SIGMAS,
               power: float = POWER) -> float:
    """The smallest true value resolved at ``resolved`` σ (normal-equivalent) in a share
    ``power`` of repeats, for an estimate with standard error ``stderr`` whose own
    error has ``dof`` degrees of freedom: δ·stderr with δ the noncentrality at
    which a noncentral t exceeds the critical t with probability ``power``.

    >>> round(detectable(1.0, 10**6, resolved=2.0), 2)   # 2 + 1.645
    3.64
    >>> round(detectable(1.0, 10**6), 2), round(detectable(1.0, 6), 2)   # 2.24 + 1.645; 6 dof
    (3.89, 5.03)
    """
    if not (math.isfinite(stderr) and stderr >= 0 and dof >= 1):
        return math.nan
    return float(_noncentrality(int(dof), float(resolved), float(power)) * stderr)


@lru_cache(maxsize=4096)
def _noncentrality(dof: int, resolved: float, power: float) -> float:
    """δ of :func:`detectable` for ``dof`` degrees of freedom (a root of the noncentral t's
    tail: computed once per dof)."""
    crit = sps.t.isf(sps.norm.sf(resolved), dof)
    if dof > 1000:
        return float(crit + sps.norm.ppf(power))
    return float(brentq(lambda d: sps.nct.sf(crit, dof, d) - power, 0.0, 10 * crit + 50))


def ols(X: np.ndarray, y: np.ndarray, errors: bool = True):
    """Least squares y = X·c: (coef, stderr, residuals); the errors widened by the
    residuals' integrated autocorrelation time (NaN with ``errors=False``, and where the
    design is singular to working precision).

    >>> import warnings
    >>> x = np.linspace(0.0, 1.0, 50)
    >>> X = np.column_stack([np.ones(50), x, x])                 # two equal columns
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error")                          # no RuntimeWarning
    ...     _, se, _ = ols(X, 1.0 + 2.0 * x)
    >>> np.isnan(se).tolist()
    [True, True, True]
    """
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ coef
    dof = y.size - X.shape[1]
    if dof <= 0 or not errors:
        return coef, np.full(X.shape[1], math.nan), resid
    s2 = float(resid @ resid) / dof
    try:
        var = np.diag(s2 * np.linalg.inv(X.T @ X)) * correlation_time(resid)
    except np.linalg.LinAlgError:
        var = np.full(X.shape[1], math.nan)
    # a design singular to working precision inverts to negative or infinite variances:
    # its coefficients have no error bar (NaN), not a warning
    with np.errstate(invalid="ignore"):
        se = np.where(np.isfinite(var) & (var >= 0.0), np.sqrt(np.abs(var)), math.nan)
    return coef, se, resid


def correlation_time(r: np.ndarray) -> float:
    """Integrated autocorrelation time of ``r`` in samples, 1 + 2 Σ ρ_k summed up to
    the first lag where ρ_k ≤ 0 (1 for uncorrelated samples)."""
    r = r - r.mean()
    den = float(r @ r)
    if r.size < 3 or den <= 0:
        return 1.0
    # the autocovariance at every lag at once (zero-padded FFT), lags 1 … n//2 − 1
    f = np.fft.rfft(r, 2 * r.size)
    rho = np.fft.irfft(f * np.conj(f))[1:r.size // 2] / den
    stop = np.flatnonzero(rho <= 0)
    return 1.0 + 2.0 * float(rho[:stop[0] if stop.size else rho.size].sum())


def mean_se(x: np.ndarray) -> tuple[float, float]:
    """Mean and standard error of the finite values of ``x`` (NaN for none; the error NaN
    for one)."""
    x = x[np.isfinite(x)]
    if x.size == 0:
        return math.nan, math.nan
    return float(x.mean()), (float(x.std(ddof=1) / math.sqrt(x.size)) if x.size > 1 else math.nan)
