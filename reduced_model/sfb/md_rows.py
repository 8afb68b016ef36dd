"""The md-calibrated rows of the SFB check: the MD film carried to Klein's contact.

The MD film's yield, re-stick and sliding stresses (LJ) are converted to SI
through :mod:`filmfriction.reduced_model.units` and scaled to Klein's contact
area; its η_eff(γ̇) law is carried to the SFB slip's shear rate; the
SFB-scale slip of the reduced model with those parameters
(:func:`~filmfriction.reduced_model.sfb.slip.run_slip`) is set beside Klein's
numbers, with uncertainties propagated from the calibration's (one-at-a-time
±1σ perturbations, combined in quadrature), however large the disagreement.

Example
-------
>>> from filmfriction.reduced_model.units import OMCTS
>>> from filmfriction.reduced_model.sfb.klein import KLEIN, klein_slip_geometry
>>> from filmfriction.reduced_model.sfb.heating import OMCTS_LIQUID
>>> cal = MDCalibration(yield_stress=0.5, restick_stress=0.25, eta_zero=50.0)
>>> rows, run, notes = md_rows(cal, OMCTS, KLEIN, klein_slip_geometry(), OMCTS_LIQUID)
>>> rows[0]["name"], rows[0]["source"]
('yield_stress', 'md-calibrated')
"""
from __future__ import annotations

import math
from dataclasses import replace

from .heating import LiquidProperties, temperature_rise
from .klein import KleinExperiment, SlipGeometry
from .md_calibration import MDCalibration, film_law, slip_drag
from .rows import table_row as _row
from .slip import SlipRun, run_slip
from ..units import SI_IDENTITY, LJUnits

__all__ = ["md_rows", "md_quantities"]

#: Below this 4MK/B² a slip is integrated with a heavier block (see run_slip's model_mass).
_STIFF_OVERDAMPING = 1e-3


def md_quantities(cal: MDCalibration, units: LJUnits, ex: KleinExperiment, shear_rate_si: float,
                  liquid: LiquidProperties) -> tuple[dict, SlipRun]:
    """SI quantities of the MD-calibrated SFB slip (one evaluation; used for the errors too).

    Parameters
    ----------
    cal : MDCalibration
    units : LJUnits
    ex : KleinExperiment
        K, M, A, D of the SFB.
    shear_rate_si : float
        Shear rate at which η_eff is reported, 1/s.
    liquid : LiquidProperties
        For the temperature rise.

    Returns
    -------
    (dict, SlipRun)
        The quantities by row name, and the slip.
    """
    K, M, A, D = ex.spring_constant, ex.mass, ex.contact_area, ex.film_thickness
    tau_y = units.to_si(cal.yield_stress, "stress")
    x0 = tau_y * A / K
    restick = None if cal.restick_stress is None else units.to_si(cal.restick_stress, "stress") * A
    law = film_law(cal, units, A, D)
    eta_rate = units.to_si(cal.eta(units.from_si(shear_rate_si, "shear_rate")), "viscosity")
    # Drag of the slip at its start: the overdamped speed at which the film carries K x0.
    drag = slip_drag(cal, units, A, D, K * x0)
    scale = max(2 * math.pi * math.sqrt(M / K), drag / K)
    model_mass = None
    if 4.0 * M * K / drag**2 < _STIFF_OVERDAMPING:
        model_mass = 0.25 * _STIFF_OVERDAMPING * drag**2 / K
    run = run_slip(M, K, x0 * (1 + 1e-9), law, restick_force=restick, label="MD-calibrated",
                   time_scale=scale, model_mass=model_mass)
    if model_mass is not None:
        run = replace(run, end_rule=run.end_rule + f"; strongly overdamped (4MK/B^2 = "
                      f"{4 * M * K / drag**2:.1e}): integrated with mass {model_mass:.3g} kg, "
                      f"error O({_STIFF_OVERDAMPING:g})")
    q = {
        "yield_stress": tau_y,
        "static_force": tau_y * A,
        "restick_stress": None if restick is None else restick / A,
        "sliding_stress": units.to_si(cal.sliding_stress, "stress"),
        "eta_eff": eta_rate,
        "slip_time": run.slip_time,
        "slip_distance": run.slip_distance,
        "spring_energy_released": run.spring_energy_released,
        "viscous_energy": run.viscous_energy,
        "viscous_fraction": run.viscous_fraction,
        "temperature_rise": temperature_rise(run.viscous_energy, A, D, liquid),
    }
    return q, run


def md_rows(cal: MDCalibration, units: LJUnits, ex: KleinExperiment, geo: SlipGeometry,
            liquid: LiquidProperties, setup: str | None = None) -> tuple[list, SlipRun, list]:
    """The ``md-calibrated`` rows of the SFB table.

    Parameters
    ----------
    cal : MDCalibration
        The MD film (LJ units).
    units : LJUnits
        LJ ↔ SI.
    ex : KleinExperiment
    geo : SlipGeometry
        Klein's x0 and Δx0 (his slip's shear rate, his re-stick stress).
    liquid : LiquidProperties
    setup : str, optional
        The name of the SFB set-up whose measured slip ``ex`` and ``geo`` hold: the
        notes then speak of it instead of Klein (:func:`~filmfriction.reduced_model.sfb.check.sfb_check`).

    Returns
    -------
    (list of dict, SlipRun, list of str)
        Rows (:func:`~filmfriction.reduced_model.sfb.rows.table_row`), the MD-calibrated
        slip, and the notes on units and extrapolation.
    """
    K, A, D = ex.spring_constant, ex.contact_area, ex.film_thickness
    src = "md-calibrated"
    # Klein's slip shear rate: mean slip velocity dx0/tau_s over the gap (~6e2 1/s)
    rate = geo.slip_distance / ex.slip_time / D
    rate_lj = units.from_si(rate, "shear_rate")
    q, run = md_quantities(cal, units, ex, rate, liquid)

    # One-at-a-time +/-1 sigma perturbations, combined in quadrature (log space for positive values).
    perturbed = []
    for name in ("yield_stress", "eta_zero", "thinning_exponent", "onset_rate", "restick_stress",
                 "sliding_stress"):
        err = getattr(cal, name + "_err")
        value = getattr(cal, name)
        if not err or value is None:
            continue
        pair = []
        for sign in (-1.0, 1.0):
            new = value + sign * err
            try:
                c = replace(cal, **{name: new})
                pair.append(md_quantities(c, units, ex, rate, liquid)[0])
            except ValueError:
                continue  # the perturbed value leaves the allowed range: skip that side
        perturbed.append(pair)

    def interval(key):
        base = q[key]
        if base is None or not math.isfinite(base):
            return None
        up2 = dn2 = 0.0
        log = base > 0
        for pair in perturbed:
            devs = []
            for p in pair:
                val = p[key]
                if val is None or not math.isfinite(val) or (log and val <= 0):
                    continue
                devs.append(math.log(val / base) if log else val - base)
            up2 += max([d for d in devs if d > 0], default=0.0) ** 2
            dn2 += max([-d for d in devs if d < 0], default=0.0) ** 2
        if log:
            return (base * math.exp(-math.sqrt(dn2)), base * math.exp(math.sqrt(up2)))
        return (base - math.sqrt(dn2), base + math.sqrt(up2))

    decades = None
    if cal.shear_rate_range is not None:
        decades = math.log10(cal.shear_rate_range[0] / rate_lj)
    # a measured trace's calibration is SI already (units = SI_IDENTITY): said in SI words
    si = units == SI_IDENTITY
    md, rate_unit = ("calibrated", "1/s") if si else ("MD", "/tau")
    is_klein = setup is None
    whose = "Klein's" if is_klein else "the measured"
    area = "Klein's contact area" if is_klein else f"the contact area of {setup}"
    extrap = (f"{md} law evaluated at {whose} mean slip rate dx0/(tau_s D) = {rate:.3g} 1/s"
              + ("" if si else f" = {rate_lj:.3g} /tau")
              + (f", {decades:.1f} decades below the lowest {md} rate"
                 if decades is not None else ""))
    stress_text = (f"calibrated yield stress {cal.yield_stress:g} Pa" if si else
                   f"MD yield stress {cal.yield_stress:g} eps/sigma^3 x {units.stress:.3g} Pa")
    klein_restick = geo.restick_force(K) / A
    rows = [
        _row("yield_stress", geo.x0 * K / A, q["yield_stress"], "Pa", src,
             f"{stress_text}; "
             + ("Klein: K x0/A with x0 from dE_f (not printed in the paper)" if is_klein else
                f"{setup}: F_s/A with the measured static force F_s"), interval("yield_stress")),
        _row("static_force", geo.x0 * K, q["static_force"], "N", src,
             f"{md} yield stress x {area} {A:.2g} m2 vs "
             + ("Klein's K x0" if is_klein else "the measured F_s"), interval("static_force")),
    ]
    if q["restick_stress"] is not None:
        rows.append(_row("restick_stress", klein_restick, q["restick_stress"], "Pa", src,
                         "stress at which the film re-solidifies (s); "
                         f"{'Klein' if is_klein else setup}: K(x0 - dx0)/A",
                         interval("restick_stress")))
    rows.append(_row("sliding_stress", None, q["sliding_stress"], "Pa", src,
                     "rate-independent stress while sliding; Klein's Eq. (1) has none (purely viscous)",
                     interval("sliding_stress")))
    rows.append(_row("eta_eff", ex.eta_eff, q["eta_eff"], "Pa s", src,
                     extrap + f"; Carreau eta0 = {cal.eta_zero:g}, n = {cal.thinning_exponent:g}, "
                     f"onset {cal.onset_rate:g} {rate_unit}", interval("eta_eff")))
    if cal.shear_rate_range is not None and cal.thinning_exponent > 0:
        g_lo = cal.shear_rate_range[0]
        eta_pl = units.to_si(cal.eta(g_lo) * (rate_lj / g_lo) ** (-cal.thinning_exponent), "viscosity")
        rows.append(_row("eta_eff_power_law", ex.eta_eff, eta_pl, "Pa s", src,
                         "pure power law eta ~ rate^-n extrapolated from the lowest MD rate (no "
                         "Newtonian plateau): upper bracket of eta_eff"))
    for key, klein, unit, note in (
            ("slip_time", ex.slip_time, "s", f"SFB-scale slip of the calibrated model; end: {run.end_rule}"),
            ("slip_distance", geo.slip_distance, "m", "slip from y to s; " + (
                "Klein's dx0 derived from dE_spring" if is_klein else "the measured dx0")),
            ("spring_energy_released", ex.spring_energy_released, "J", "K x0^2/2 - K (x0 - dx)^2/2"),
            ("viscous_energy", ex.spring_energy_released, "J", "friction dissipation y -> s (model ledger)"),
            ("viscous_fraction", ex.viscous_fraction, "1", "viscous / (viscous + kinetic energy at s)"),
            ("temperature_rise", ex.temperature_rise, "K", "viscous energy / (rho c_p A D)")):
        rows.append(_row(key, klein, q[key], unit, src, note, interval(key)))
    mapping = ("a measured trace's calibration, SI already (no LJ mapping)" if si else
               f"units {units.name} (sigma = {units.sigma * 1e9:.3g} nm, eps/kB = "
               f"{units.temperature:.0f} K, tau = {units.tau * 1e12:.2f} ps)")
    scaled_by = "Klein's area" if is_klein else area
    notes = [f"md-calibrated: {mapping}; stresses x {scaled_by}; "
             f"{extrap}." + (f" Calibration source: {cal.source}" if cal.source else "")]
    return rows, run, notes
