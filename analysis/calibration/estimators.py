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

from filmfriction.reduced_model.cycles import cycle_table

from .rundata import RunData
from ..files.trace import UNITS
from ..files.util import finite_or_none as _num

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
    at_bound : bool
        The fit ended at the bound of the parameter's range: ``value`` is that bound
        and there is no standard error (``stderr`` NaN, written null).
    limit : float
        For a parameter at its lower bound, the one-sided 95 % upper limit the data
        allow (a profile of the fit's χ²; NaN where not computed, written null).
    """

    value: float
    stderr: float
    units: str
    method: str = ""
    at_bound: bool = False
    limit: float = math.nan

    def as_dict(self) -> dict:
        return {"value": _num(self.value), "stderr": _num(self.stderr), "units": self.units,
                "method": self.method, "at_bound": self.at_bound,
                "upper_limit_95": _num(self.limit)}

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
    """The stuck film's elastic shear stiffness k_f from the slopes of the stick ramps
    (:func:`filmfriction.analysis.stick_ramps.stick_stiffness`); None when not measurable."""
    from ..stick_ramps import stick_stiffness

    tr = run.trace
    k = tr.parameters.spring_constant
    v = tr.parameters.drive_velocity
    if not (k and v):
        return None
    sticks = np.asarray(run.cycles.get("stick_index", []), int)
    yields = np.asarray(run.cycles.get("yield_index", []), int)
    table = cycle_table(tr.time, tr.spring_force, yields, sticks)
    st = stick_stiffness(tr.time, tr.spring_force, table, spring_constant=k, drive_velocity=v)
    if st is None:
        return None
    return Estimate(st.film_stiffness, st.film_stiffness_stderr, UNITS[tr.units]["stiffness"],
                    f"stick ramps' slope K_eff = {st.effective_stiffness:.4g} (K = {k:g}) from "
                    f"{st.ramps} ramps: 1/k_f = 1/K_eff - 1/K")
