"""From the calibrated runs to the MD film the SFB check takes (:class:`MDCalibration`, LJ units).

The yield, sliding and re-stick stresses are the runs' forces over their
contact areas (inverse-variance means); the film's η(γ̇) is the rate law
across runs as a Carreau law
(:func:`filmfriction.reduced_model.laws.carreau_viscosity`) with its onset at
the lowest MD rate and matched to the fit there, or with one rate a Newtonian
η_eff.

Example
-------
>>> from filmfriction.analysis.calibration.estimators import Estimate
>>> mean, err = _combine([Estimate(1.0, 0.1, "ε/σ"), Estimate(3.0, 0.1, "ε/σ")])
>>> mean, round(err, 6)                  # inverse-variance mean and its error
(2.0, 0.070711)
"""
from __future__ import annotations

import math

import numpy as np

from filmfriction.reduced_model.sfb.md_calibration import MDCalibration

from .estimators import Estimate

__all__ = ["md_calibration"]


def _combine(values: list[Estimate]) -> tuple[float, float]:
    """Inverse-variance mean (plain mean when an error is missing) and its error."""
    v = np.array([e.value for e in values], float)
    s = np.array([e.stderr for e in values], float)
    if v.size == 1:
        return float(v[0]), float(s[0]) if np.isfinite(s[0]) else 0.0
    if np.all(np.isfinite(s) & (s > 0)):
        w = 1.0 / s ** 2
        return float(np.sum(w * v) / np.sum(w)), float(1.0 / math.sqrt(np.sum(w)))
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(v.size))


def _stress(e: Estimate | None, area: float) -> Estimate | None:
    if e is None or not area or not math.isfinite(area):
        return None
    return Estimate(e.value / area, e.stderr / area, "stress", e.method)


def md_calibration(runs: list, law, points, notes: list) -> MDCalibration:
    """Build the MDCalibration (LJ stresses) from the runs' calibrations, or explain why not.

    Parameters
    ----------
    runs : list of RunCalibration
    law : analysis.viscosity.PowerLaw or None
        η_eff = c γ̇^α across runs; None: one rate, a Newtonian film.
    points : list of (float, float, float)
        (γ̇, η_eff, stderr) per run.
    notes : list of str
        Appended to (clipped values, one rate only).

    Raises
    ------
    ValueError
        No run with a calibrated slip law, or a non-positive η_eff.
    """
    fitted = [r for r in runs if r.static_force is not None and r.kinetic_force is not None]
    ss = [r for r in fitted if r.eta_eff is not None]
    if not ss:
        if fitted:
            raise ValueError("no run with a resolved η_eff to carry to the SFB (see eta_eff)")
        raise ValueError("no run with a calibrated slip law (stick-slip with fitted slips) "
                         "to give the yield stress")
    ys, ys_err = _combine([_stress(r.static_force, r.area) for r in ss])
    ks, ks_err = _combine([_stress(r.kinetic_force, r.area) for r in ss])
    rs_list = [_stress(r.restick_force, r.area) for r in ss if r.restick_force is not None]
    restick, restick_err = (None, 0.0)
    if rs_list:
        rs, rs_err = _combine(rs_list)
        if 0.0 <= rs < ys:
            restick, restick_err = rs, rs_err if math.isfinite(rs_err) else 0.0
        else:
            notes.append(f"re-stick stress {rs:.3g} outside [0, yield stress): the SFB slip ends "
                         "where the model stops instead")
    ks = min(max(ks, 0.0), 0.999 * ys)
    rates = [p[0] for p in points if math.isfinite(p[0])]
    kwargs = {}
    if law is not None:
        n = -law.exponent
        n_err = law.exponent_stderr
        if not 0.0 <= n < 1.0:
            notes.append(f"fitted thinning exponent n = {n:.3g} outside [0, 1): clipped for the SFB law")
            n = min(max(n, 0.0), 0.99)
        g_lo = min(rates)
        eta_lo = law.prefactor * g_lo ** law.exponent
        eta0 = eta_lo * 2.0 ** (n / 2.0)      # laws.carreau_viscosity at its onset = the fit there
        kwargs = dict(eta_zero=eta0, eta_zero_err=eta0 * law.prefactor_rel_stderr,
                      thinning_exponent=n, thinning_exponent_err=n_err, onset_rate=g_lo)
    else:
        e, e_err = _combine([r.eta_eff for r in ss])
        if not e > 0:
            raise ValueError(f"film eta_eff = {e:.3g} is not positive: no viscous film to carry to the SFB")
        kwargs = dict(eta_zero=e, eta_zero_err=e_err if math.isfinite(e_err) else 0.0)
        notes.append("one shear rate only: Newtonian eta_eff carried to the SFB rate (a sweep of "
                     "drive velocities is needed for the shear-rate law)")
    return MDCalibration(
        yield_stress=ys, yield_stress_err=ys_err if math.isfinite(ys_err) else 0.0,
        sliding_stress=ks, sliding_stress_err=ks_err if math.isfinite(ks_err) else 0.0,
        restick_stress=restick, restick_stress_err=restick_err,
        shear_rate_range=(min(rates), max(rates)) if rates else None,
        film_thickness=float(np.mean([r.thickness for r in ss])),
        source="; ".join(str(r.run.run_dir) for r in runs), **kwargs)
