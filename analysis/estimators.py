"""Estimates of the calibration and the ones read off a run's slips directly.

:class:`Estimate` is a value with its one-standard-error uncertainty;
:func:`summary_estimate` takes one from ``analysis.json``; :func:`ageing` is
the contact-ageing slope dF_s/d ln(t_stick); :func:`shear_stiffness` the
stuck film's elastic stiffness from the slopes of the stick ramps.

Example
-------
>>> e = Estimate(2.0, 0.1, "ε/σ", "a fit")
>>> e.rel, e.as_dict()["stderr"]
(0.05, 0.1)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .rundata import RunData
from .trace import UNITS
from .util import finite_or_none as _num

__all__ = ["Estimate", "summary_estimate", "ageing", "shear_stiffness"]


@dataclass(frozen=True)
class Estimate:
    """A fitted value with its one-standard-error uncertainty.

    Attributes
    ----------
    value, stderr : float
        ``stderr`` is NaN when it cannot be computed.
    units : str
        Unit label (LJ: ε/σ, ετ/σ³, …).
    method : str
        How it was obtained (one line, for people).
    """

    value: float
    stderr: float
    units: str
    method: str = ""

    def as_dict(self) -> dict:
        return {"value": _num(self.value), "stderr": _num(self.stderr), "units": self.units,
                "method": self.method}

    @property
    def rel(self) -> float:
        """Relative uncertainty (NaN if undefined)."""
        return abs(self.stderr / self.value) if self.value else math.nan


def summary_estimate(doc: dict, name: str, units: str, method: str) -> Estimate | None:
    """The ``slips`` summary ``name`` of an ``analysis.json`` document as an Estimate (None if absent)."""
    e = doc.get("slips", {}).get(name) or {}
    if e.get("mean") is None:
        return None
    return Estimate(float(e["mean"]), float(e["stderr"]) if e.get("stderr") is not None else math.nan,
                    units, method)


def ageing(run: RunData) -> Estimate | None:
    """Slope of F_s against ln(preceding stick time) over the analysed slips (≥ 4)."""
    from scipy.stats import linregress

    fs = np.asarray(run.cycles.get("static_force", []), float)
    stick = np.asarray(run.cycles.get("stick_duration", []), float)
    if fs.size < 2:
        return None
    # slip i+1 yields after the stick that follows slip i
    x = stick[:-1][run.skip:] if run.skip else stick[:-1]
    y = fs[1:][run.skip:] if run.skip else fs[1:]
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0)
    if ok.sum() < 4 or np.ptp(np.log(x[ok])) == 0:
        return None
    res = linregress(np.log(x[ok]), y[ok])
    return Estimate(float(res.slope), float(res.stderr), UNITS[run.trace.units]["force"],
                    f"linear fit of F_s vs ln(preceding stick time), {int(ok.sum())} slips")


def shear_stiffness(run: RunData) -> Estimate | None:
    """The stuck film's elastic shear stiffness k_f from the slopes of the stick ramps.

    A stuck film strains like a spring in series with the drive spring: the
    force rises at K_eff V with 1/K_eff = 1/K + 1/k_f.  Each ramp (re-stick to
    the next yield, its first quarter and last tenth left out: ringing and
    creep before the yield) gives a slope; k_f = K K_eff/(K − K_eff) from
    their mean, its error propagated from theirs.  None with fewer than 2
    ramps or when K_eff is not below K (no measurable compliance).
    """
    tr = run.trace
    k = tr.parameters.spring_constant
    v = tr.parameters.drive_velocity
    if not (k and v):
        return None
    t, f = tr.time, tr.spring_force
    sticks = np.asarray(run.cycles.get("stick_index", []), int)
    yields = np.asarray(run.cycles.get("yield_index", []), int)
    slopes = []
    for i0, i1 in zip(sticks[:-1], yields[1:]):
        lo, hi = i0 + (i1 - i0) // 4, i1 - (i1 - i0) // 10
        if hi - lo >= 5:
            slopes.append(np.polyfit(t[lo:hi], f[lo:hi], 1)[0] / v)
    if len(slopes) < 2:
        return None
    k_eff = float(np.mean(slopes))
    se = float(np.std(slopes, ddof=1) / math.sqrt(len(slopes)))
    if not 0.0 < k_eff < k - 2.0 * se:
        return None
    k_f = k * k_eff / (k - k_eff)
    dk = se * (k / (k - k_eff)) ** 2          # d k_f / d K_eff
    return Estimate(k_f, dk, UNITS[tr.units]["stiffness"],
                    f"stick ramps' slope K_eff = {k_eff:.4g} (K = {k:g}) from {len(slopes)} "
                    "ramps: 1/k_f = 1/K_eff - 1/K")
