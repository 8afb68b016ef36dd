"""How the sliding stress depends on the shear rate: Eyring-like or power law, chosen by residuals.

Two two-parameter laws for the steady sliding stress τ at shear rate γ̇:

* Eyring-like (thermally activated sliding, logarithmic in the rate):
  τ = τ0 + τ1·ln(γ̇/γ̇_ref);
* power law (shear thinning, η_eff = τ/γ̇ ∝ γ̇^α):
  τ = c·γ̇^n, fitted as ln τ = ln c + n·ln γ̇ (n = 1 + α).

Both are fitted by (weighted) least squares, each in its own linear form; the
choice compares their residual sums of squares in the same variable, the stress
itself (weighted by its errors when given).  Carried to a rate far outside the
measured range (an SFB slip rate is ~10⁷ times an MD one), each law gives a value
and a 68 % interval from its parameters' covariance; an interval wider than a
decade says so (:attr:`Extrapolation.spans_decade`) rather than being read as a
prediction.

Example
-------
>>> import numpy as np
>>> rate = np.geomspace(1e-3, 1e-1, 6)
>>> stress = 2.0 + 0.3 * np.log(rate / 1e-2)
>>> best = choose_rate_law(rate, stress)
>>> best.form, round(best.parameters["tau1"], 6)
('eyring', 0.3)
>>> e = best.extrapolate(1e-9)
>>> round(e.value, 4), e.spans_decade   # 2 + 0.3 ln(1e-7): negative, meaningless
(-2.8354, True)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from filmfriction.reduced_model.sfb.rows import spans_decade

__all__ = ["RateLaw", "Extrapolation", "eyring_fit", "power_fit", "choose_rate_law"]


@dataclass(frozen=True)
class Extrapolation:
    """A law's stress at one rate with a 68 % interval (parameters' covariance).

    ``spans_decade`` is True when the interval reaches zero or below, or its ends
    differ by more than a factor of 10: the extrapolation does not fix the value.
    """

    rate: float
    value: float
    low: float
    high: float

    @property
    def spans_decade(self) -> bool:
        return self.value <= 0 or spans_decade(self.low, self.high)

    def as_dict(self) -> dict:
        return {"rate": self.rate, "value": self.value, "low": self.low, "high": self.high,
                "spans_decade": self.spans_decade}


@dataclass(frozen=True)
class RateLaw:
    """A fitted rate law (see the module text).

    Attributes
    ----------
    form : {"eyring", "power"}
    parameters : dict
        Eyring: ``tau0``, ``tau1``, ``rate_ref``; power: ``prefactor``, ``exponent``.
    covariance : ndarray, shape (2, 2)
        Of the linear-form coefficients (Eyring: τ0, τ1; power: ln c, n).
    residual : float
        Residual sum of squares in stress, weighted by 1/σ² when errors were given.
    n : int
        Points fitted.
    """

    form: str
    parameters: dict
    covariance: np.ndarray = field(repr=False)
    residual: float
    n: int

    def _design(self, rate) -> np.ndarray:
        r = np.atleast_1d(np.asarray(rate, float))
        if self.form == "eyring":
            return np.column_stack([np.ones_like(r), np.log(r / self.parameters["rate_ref"])])
        return np.column_stack([np.ones_like(r), np.log(r)])

    def _coef(self) -> np.ndarray:
        p = self.parameters
        if self.form == "eyring":
            return np.array([p["tau0"], p["tau1"]])
        return np.array([math.log(p["prefactor"]), p["exponent"]])

    def stress(self, rate):
        """τ at ``rate`` (array or scalar)."""
        lin = self._design(rate) @ self._coef()
        out = lin if self.form == "eyring" else np.exp(lin)
        return out if np.ndim(rate) else float(out[0])

    def extrapolate(self, rate: float) -> Extrapolation:
        """τ at ``rate`` with its 68 % interval."""
        x = self._design(rate)[0]
        lin = float(x @ self._coef())
        se = float(math.sqrt(max(x @ self.covariance @ x, 0.0)))
        if self.form == "eyring":
            return Extrapolation(float(rate), lin, lin - se, lin + se)
        return Extrapolation(float(rate), math.exp(lin), math.exp(lin - se), math.exp(lin + se))

    def as_dict(self) -> dict:
        return {"form": self.form, "parameters": dict(self.parameters),
                "covariance": self.covariance.tolist(), "residual": self.residual, "n": self.n,
                "law": ("stress = tau0 + tau1 * ln(rate / rate_ref)" if self.form == "eyring"
                        else "stress = prefactor * rate**exponent")}


def _check(rate, stress, stress_err, positive_stress):
    r = np.asarray(rate, float).ravel()
    s = np.asarray(stress, float).ravel()
    if r.shape != s.shape:
        raise ValueError(f"rate and stress differ in length ({r.size} vs {s.size})")
    if r.size < 3:
        raise ValueError(f"{r.size} points: a two-parameter law needs at least 3 to have a residual")
    if not np.all(np.isfinite(r) & (r > 0)):
        raise ValueError("every rate must be positive and finite")
    if not np.all(np.isfinite(s)):
        raise ValueError("every stress must be finite")
    if positive_stress and not np.all(s > 0):
        raise ValueError("a power law needs positive stresses")
    if np.unique(r).size < 2:
        raise ValueError("the rates must not all be equal")
    e = None
    if stress_err is not None:
        e = np.asarray(stress_err, float).ravel()
        if e.shape != s.shape or not np.all(np.isfinite(e) & (e > 0)):
            raise ValueError("stress_err must be positive and finite, one per point")
    return r, s, e


def _wls(x: np.ndarray, y: np.ndarray, w: np.ndarray | None):
    A = np.column_stack([np.ones_like(x), x])
    W = np.ones_like(y) if w is None else w
    Aw = A * np.sqrt(W)[:, None]
    yw = y * np.sqrt(W)
    coef, *_ = np.linalg.lstsq(Aw, yw, rcond=None)
    resid = yw - Aw @ coef
    dof = y.size - 2
    s2 = float(resid @ resid) / dof
    cov = np.linalg.inv(Aw.T @ Aw)
    # without given errors the scatter sets the scale; with errors, the larger of the two
    cov = cov * (s2 if w is None else max(s2, 1.0))
    return coef, cov


def eyring_fit(rate, stress, stress_err=None) -> RateLaw:
    """τ = τ0 + τ1·ln(γ̇/γ̇_ref), γ̇_ref the geometric mean of the rates (least squares)."""
    r, s, e = _check(rate, stress, stress_err, False)
    ref = float(np.exp(np.mean(np.log(r))))
    coef, cov = _wls(np.log(r / ref), s, None if e is None else 1.0 / e ** 2)
    law = RateLaw("eyring", {"tau0": float(coef[0]), "tau1": float(coef[1]), "rate_ref": ref},
                  cov, 0.0, int(r.size))
    return _with_residual(law, r, s, e)


def power_fit(rate, stress, stress_err=None) -> RateLaw:
    """τ = c·γ̇^n, fitted as ln τ = ln c + n ln γ̇ (weights (τ/σ_τ)² when errors are given)."""
    r, s, e = _check(rate, stress, stress_err, True)
    coef, cov = _wls(np.log(r), np.log(s), None if e is None else (s / e) ** 2)
    law = RateLaw("power", {"prefactor": float(math.exp(coef[0])), "exponent": float(coef[1])},
                  cov, 0.0, int(r.size))
    return _with_residual(law, r, s, e)


def _with_residual(law: RateLaw, r, s, e) -> RateLaw:
    d = s - law.stress(r)
    if e is not None:
        d = d / e
    return RateLaw(law.form, law.parameters, law.covariance, float(d @ d), law.n)


def choose_rate_law(rate, stress, stress_err=None) -> RateLaw:
    """The law (Eyring or power) with the smaller residual in stress.

    A power law cannot fit non-positive stresses; then the Eyring law is returned.
    """
    eyring = eyring_fit(rate, stress, stress_err)
    try:
        power = power_fit(rate, stress, stress_err)
    except ValueError:
        return eyring
    return eyring if eyring.residual <= power.residual else power
