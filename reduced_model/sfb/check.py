"""The SFB check: the reduced model against Klein's OMCTS stick-slip numbers.

Klein (PRL 98, 056101 (2007); seed 004) measured one stick-slip cycle of mica
sliding across a 4-layer OMCTS film in the surface force balance (SFB) and
analysed the slip from the yield point y to the solidification point s with
his Eq. 1, M x'' + B x' = K (x0 − x), B = A η_eff / D
(:mod:`~filmfriction.reduced_model.sfb.klein`).

This module does two things, each as rows of one table
(:func:`sfb_table`, ``filmfriction sfb``); the pieces live beside it
(:mod:`~filmfriction.reduced_model.sfb.klein`: Klein's numbers, his slip geometry
and Eq. 2; :mod:`~filmfriction.reduced_model.sfb.slip`: one slip in the model;
:mod:`~filmfriction.reduced_model.sfb.heating`: the temperature rise;
:mod:`~filmfriction.reduced_model.sfb.md_calibration` and
:mod:`~filmfriction.reduced_model.sfb.md_rows`: the MD film at the SFB's scale):

``source = "sfb-parameters"``
    Klein's own parameters (K, M, A, D, η_eff) in the reduced model
    (:class:`filmfriction.reduced_model.SpringBlock` with :class:`filmfriction.reduced_model.laws.NewtonianFilm`,
    spring end fixed, released from the extension x0): the slip time τ_s,
    the spring energy released, the viscous energy from the model's energy
    ledger, the viscous fraction, the residual kinetic energy at s, the ringing
    energy, the temperature rise of the film, the same slip with the bulk
    viscosity — each beside Klein's number.  The model's trace is
    cross-checked against Klein's closed form (his Eq. 2) on both of the
    model's paths (closed form and ODE integrator).
``source = "md-calibrated"`` (only with an :class:`~filmfriction.reduced_model.sfb.md_calibration.MDCalibration`)
    The MD film's yield, re-stick and sliding stresses (LJ) converted to SI
    through :mod:`filmfriction.reduced_model.units` and scaled to Klein's contact area; its
    η_eff(γ̇) law carried to the SFB slip's shear rate; the SFB-scale slip
    of the reduced model with those parameters — beside Klein's numbers, with
    uncertainties propagated from the calibration's, however large the
    disagreement.

What is assumed (all in :data:`ASSUMPTIONS`, printed by the CLI)
------------------------------------------------------------------
* **x0 and Δx0** are not printed in Klein's text.  Two of his statements fix
  them: the film energy ΔE_f ≈ K x0 δ ≈ 1×10⁻¹⁴ J with δ ≈ 1 nm gives
  x0 = ΔE_f/(K δ) ≈ 103 nm (yield force K x0 ≈ 10 µN, yield stress
  ≈ 25 kPa), and ΔE_spring = K(x0 − Δx0/2)Δx0 ≈ 4×10⁻¹³ J then gives
  Δx0 = x0 − √(x0² − 2ΔE_spring/K) ≈ 54 nm.  Both statements are
  one-significant-figure estimates; τ_s is sensitive to x0 (ΔE_f = 0.95 or
  1.1 ×10⁻¹⁴ J give τ_s ≈ 31 or 17 ms), which is stated, not hidden.  The
  alternative reading "the overdamped slip relaxes fully, Δx0 = x0 ≈ 91 nm"
  is evaluated too (rows ``slip_time_full_relaxation_*``): it gives slip
  times of 32 ms (1 − 1/e of the slip) to 94 ms (95 %), and cannot produce
  the abrupt stick with ringing that Klein's trace shows.
* **τ_s** is Klein's definition, the time from y to s: here the time at which
  the model's slip reaches Δx0, i.e. at which the spring force has fallen
  to the re-stick level K(x0 − Δx0).  Eq. 1 has no solidification of its
  own, so s is imposed from the data; the MD path imposes it from the MD
  film's re-stick stress in the same way.
* **Temperature rise**: the viscous energy heats the film volume A·D with the
  heat capacity of bulk liquid OMCTS (Klein's note [29] makes the same
  assumption): ρ = 956 kg/m³ (25 °C supplier value; the Colonna et al. 2006
  equation of state gives 941) and c_p = 1.49 kJ/(kg·K) (441 J/(mol·K),
  the temperature derivative of the saturated-liquid enthalpy of the
  Colonna et al., Fluid Phase Equilib. 244, 193 (2006) equation of state as
  tabulated in CoolProp's D4 file, at 298 K).  No heat leaves the film during
  the slip — an upper bound.
* **Ringing energy** uses Klein's own estimate ΔE_osc ≈ M_eff v0²/2 with his
  v0 ≈ 2 a0 ν_c (a harmonic oscillation would have v0 = 2π a0 ν_c, ~10×
  more energy; noted on the row).
* **Uncertainties** of the ``sfb-parameters`` rows propagate Klein's quoted
  errors of η_eff (±4 Pa·s), A (±10 %) and D (±0.3 nm) through B = Aη/D
  (±20 %); the undetermined x0 is not in them (see above).

With a set-up's measured slip in Klein's place (``setup=``,
:func:`~filmfriction.reduced_model.sfb.user_setup.sfb_check_setup`) x0 = F_s/K and Δx0
come from the trace, so the notes name the set-up and its measured numbers and
leave out what only Klein's text has: the x0 reading and its ΔE_f sensitivity,
his error bars, his ringing convention (no ringing is measured).

Braun & Tosatti's reading
--------------------------
:data:`~filmfriction.reduced_model.sfb.klein.BRAUN_TOSATTI_NOTE` — any comparison with
Klein should carry it.

Example
-------
>>> check = sfb_check()
>>> row = check.row("slip_time")
>>> row["klein"], round(row["model"] * 1e3, 1)          # s, ms
(0.025, 23.9)
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

from .heating import OMCTS_LIQUID, LiquidProperties, temperature_rise
from .klein import (BRAUN_TOSATTI_NOTE, KLEIN, KleinExperiment, SlipGeometry,
                    klein_closed_form, klein_slip_geometry, newtonian_damping, ringing_energy)
from ..laws import NewtonianFilm
from .md_calibration import MDCalibration
from .md_rows import md_rows
from .rows import ROW_KEYS, SOURCES, find_row, table_row as _row, without_unfixed_ratio
from .slip import run_slip, time_to_fraction
from ..springblock import SpringBlock
from ..units import OMCTS, LJUnits

__all__ = ["SFBCheck", "sfb_check", "sfb_table", "ASSUMPTIONS", "ROW_KEYS", "SOURCES",
           "BRAUN_TOSATTI_NOTE", "SFB_SCHEMA"]

#: ``schema`` of :meth:`SFBCheck.as_dict` (the study's ``sfb.json``).
SFB_SCHEMA = "filmfriction.sfb/1"


@dataclass(frozen=True, eq=False)
class SFBCheck:
    """Everything :func:`sfb_check` computed: rows, slips, assumptions.

    Attributes
    ----------
    rows : list of dict
        The table (keys :data:`ROW_KEYS`).
    geometry : SlipGeometry
        x0 and Δx0 used for Klein's slip.
    slips : dict of str -> SlipRun
        ``"klein"`` (η_eff), ``"bulk"`` (η_bulk), ``"full_relaxation"``, and
        ``"md"`` when calibrated: traces for the report's figure.
    closed_form_deviation, ode_deviation : float
        Largest |model − Eq. (2)| over Klein's slip, relative to x0, for the
        model's closed-form path and for its ODE path.
    notes : tuple of str
        Assumptions and readings (Braun & Tosatti last).
    units : LJUnits
    experiment : KleinExperiment
    calibration : MDCalibration or None
        The MD film of the ``md-calibrated`` rows.
    """

    rows: list
    geometry: SlipGeometry
    slips: dict
    closed_form_deviation: float
    ode_deviation: float
    notes: tuple
    units: LJUnits = OMCTS
    experiment: KleinExperiment = KLEIN
    calibration: MDCalibration | None = None

    def row(self, name: str, source: str = "sfb-parameters") -> dict:
        """The row called ``name`` from ``source``."""
        return find_row(self.rows, name, source)

    def as_dict(self) -> dict:
        """The check as a JSON-ready document (schema :data:`SFB_SCHEMA`; NaN stays NaN).

        Everything but the slips' traces: rows, notes, the geometry, Klein's
        numbers, the unit mapping, the calibration used (or None) and each
        slip's scalars (``slips[key]``: label, x0, slip_time, slip_distance,
        energies, end_rule).
        """
        scalars = ("label", "x0", "slip_time", "slip_distance", "spring_energy_released",
                   "viscous_energy", "kinetic_energy_at_stick", "peak_velocity",
                   "ledger_closure", "end_rule")
        return {"schema": SFB_SCHEMA, "rows": [dict(r) for r in self.rows], "notes": list(self.notes),
                "geometry": asdict(self.geometry), "experiment": asdict(self.experiment),
                "units": self.units.summary(),
                "calibration": None if self.calibration is None else self.calibration.as_dict(),
                "closed_form_deviation": self.closed_form_deviation,
                "ode_deviation": self.ode_deviation,
                "slips": {k: {name: getattr(run, name) for name in scalars}
                          for k, run in self.slips.items()}}


#: How x0 and dx0 are read off Klein's text (not said of a measured slip).
_X0_FROM_KLEINS_TEXT = (
    "x0 (spring extension at yield) from Klein's dE_f ~ K x0 delta ~ 1e-14 J with delta ~ 1 nm; "
    "slip distance dx0 from dE_spring = K(x0 - dx0/2) dx0 ~ 4e-13 J. Both are one-figure "
    "estimates in the paper; slip_time is sensitive to x0 (see slip_time's note).")
#: Klein's convention for the ringing (said only when a ringing is given).
_RINGING = "Ringing energy with Klein's v0 = 2 a0 nu_c (a harmonic v0 = 2 pi a0 nu_c gives ~10x more)."
#: The intervals from Klein's error bars (a set-up propagates its own errors instead).
_KLEINS_ERRORS = (
    "Uncertainty intervals of sfb-parameters rows: B = A eta/D at +/-1 sigma from Klein's errors "
    "(eta +/-4 Pa s, A +/-10 %, D +/-0.3 nm -> +/-20 %); the x0 ambiguity is not included.")

ASSUMPTIONS = (
    _X0_FROM_KLEINS_TEXT,
    "tau_s is Klein's definition, the time from yield y to solidification s; in the model s is "
    "where the slip reaches dx0 (spring force back down to K(x0 - dx0)). Eq. (1) has no "
    "solidification of its own, so s is imposed from the data (md path: from the MD re-stick stress).",
    "Spring end fixed during the slip (tau_s << tau_ss), as in Klein's Eq. (1).",
    "Temperature rise: viscous energy into the film volume A D, bulk-liquid OMCTS heat capacity "
    "(rho c_p = 956 kg/m3 x 1.49 kJ/(kg K)), no heat loss during the slip (upper bound).",
    _RINGING,
    _KLEINS_ERRORS,
)


def sfb_check(calibration=None, units: LJUnits = OMCTS, experiment: KleinExperiment = KLEIN,
              liquid: LiquidProperties = OMCTS_LIQUID, contact=None,
              setup: str | None = None) -> SFBCheck:
    """Run the SFB check.

    Parameters
    ----------
    calibration : MDCalibration, dict or object with its fields, optional
        The MD film in LJ units; adds the ``md-calibrated`` rows.
    units : LJUnits
        LJ ↔ SI conversion for the calibration (default OMCTS).
    experiment : KleinExperiment
        Klein's numbers (override to test sensitivity).
    liquid : LiquidProperties
        Heat capacity for the temperature rise.
    contact : SlidingContact, optional
        An MD run's measured contact (:func:`filmfriction.analysis.calibration.contact.contact_from_run`):
        adds the ``similarity`` rows, its dimensionless numbers beside Klein's
        (:func:`.similarity.similarity_rows`).
    setup : str, optional
        The name of the SFB set-up whose measured slip ``experiment`` holds
        (:func:`.sfb_setup.setup_experiment`): the notes then speak of that set-up
        and its trace (x0 = F_s/K and Δx0 measured) instead of Klein's text, and
        leave out what only Klein's text has (his ΔE_f, his error bars, his ringing).

    Returns
    -------
    SFBCheck
    """
    ex = experiment
    K, M, A, D = ex.spring_constant, ex.mass, ex.contact_area, ex.film_thickness
    geo = klein_slip_geometry(ex, "film-energy")
    F_s = geo.restick_force(K)
    src = "sfb-parameters"

    def klein_run(eta, label, restick=F_s, x0=geo.x0):
        law = NewtonianFilm(viscosity=eta, area=A, thickness=D)
        return run_slip(M, K, x0, law, restick_force=restick, label=label)

    dB = ex.damping_rel_err
    if not dB < 1.0:
        raise ValueError(
            f"the film's damping B = A eta_eff / D has a relative error of {dB:.0%} (eta_eff "
            f"{ex.eta_eff:.4g} +- {ex.eta_eff_err:.2g} Pa s, contact area {A:.4g} +- "
            f"{ex.contact_area_err:.2g} m2, film thickness {D:.4g} +- "
            f"{ex.film_thickness_err:.2g} m): B - 1 sigma is not positive; the check needs "
            "errors that add up (in quadrature) to less than 100 %")
    main = klein_run(ex.eta_eff, "Klein parameters, eta_eff")
    lo = klein_run(ex.eta_eff * (1 - dB), "B - 1 sigma")
    hi = klein_run(ex.eta_eff * (1 + dB), "B + 1 sigma")
    bulk = klein_run(ex.eta_bulk, "bulk viscosity")
    full_geo = klein_slip_geometry(ex, "full-relaxation")
    full = klein_run(ex.eta_eff, "full relaxation", restick=None, x0=full_geo.x0)

    # Cross-check of the model's slip against Klein's Eq. (2) over the slip (and beyond).
    # The model solves a Newtonian film in closed form with the same DampedOscillator that
    # evaluates Eq. (2), so that comparison checks the model's bookkeeping (release, sampling)
    # to round-off; its ODE path (DOP853, event-driven stick) is an independent integrator of
    # the same equation.
    closed = klein_closed_form(main.t, main.x0, M, K, ex.damping)
    deviation = float(np.max(np.abs(main.x - closed)) / main.x0)
    ode = SpringBlock(mass=M, stiffness=K, drive_velocity=0.0, drive="fixed",
                      law=NewtonianFilm(viscosity=ex.eta_eff, area=A, thickness=D)).simulate(
        float(main.t[-1]), initial_extension=geo.x0, method="ode")
    ode_deviation = float(np.max(np.abs(ode.x - klein_closed_form(ode.t, geo.x0, M, K, ex.damping)))
                          / geo.x0)

    def unc(attr):
        return (getattr(lo, attr), getattr(hi, attr))

    heat = lambda run: temperature_rise(run.viscous_energy, A, D, liquid)  # noqa: E731
    is_klein = setup is None      # Klein's printed numbers, not a measured slip
    sens = []
    for e_f in (0.95e-14, 1.1e-14) if is_klein else ():
        g = klein_slip_geometry(replace(ex, film_energy=e_f))
        r = klein_run(ex.eta_eff, "sensitivity", restick=g.restick_force(K), x0=g.x0)
        sens.append(f"dE_f = {e_f:.3g} J -> x0 = {g.x0 * 1e9:.0f} nm, tau_s = {r.slip_time * 1e3:.1f} ms")
    ring = ringing_energy(ex.ringing_mass, ex.ringing_amplitude, ex.ringing_frequency)
    ring_h = ringing_energy(ex.ringing_mass, ex.ringing_amplitude, ex.ringing_frequency, "harmonic")

    rows = [
        _row("slip_time", ex.slip_time, main.slip_time, "s", src,
             f"time for the model's slip (eta_eff = {ex.eta_eff:g} Pa s, B = {ex.damping:.3g} N s/m) "
             f"to reach dx0 = {geo.slip_distance * 1e9:.1f} nm from x0 = {geo.x0 * 1e9:.1f} nm"
             + (f"; sensitivity to x0: {'; '.join(sens)}" if is_klein else " (both measured)"),
             unc("slip_time")),
        _row("spring_energy_released", ex.spring_energy_released, main.spring_energy_released, "J", src,
             "K x0^2/2 - K (x0 - x(tau_s))^2/2 in the model; equals "
             + ("Klein's value by construction (dx0 was derived from it)" if is_klein else
                "the measured K (x0 - dx0/2) dx0 by construction (the slip ends at the measured dx0)")
             + ", a check of the slip end only"),
        _row("viscous_energy", ex.spring_energy_released, main.viscous_energy, "J", src,
             "friction dissipation from y to s in the model's energy ledger; "
             + ("Klein: dE_viscous ~ dE_spring ~ 4e-13 J" if is_klein else
                "beside the measured slip's spring energy released (dE_viscous ~ dE_spring)"),
             unc("viscous_energy")),
        _row("viscous_fraction", ex.viscous_fraction, main.viscous_fraction, "1", src,
             "viscous / (viscous + kinetic energy left at s) in the model"
             + ("; Klein: 'of order 90 % or more' (a lower bound)" if is_klein else ""),
             unc("viscous_fraction")),
        _row("residual_kinetic_energy", ex.ringing_energy, main.kinetic_energy_at_stick, "J", src,
             f"M v(s)^2/2, the only source of ringing Eq. (1) has (v(s) = "
             f"{math.sqrt(2 * main.kinetic_energy_at_stick / M) * 1e6:.2f} um/s)"
             + ("; Klein: the observed ringing dE_osc ~ 1e-14 J, which he attributes to the film "
                "energy dE_f, not to Eq. (1)" if is_klein else ""),
             unc("kinetic_energy_at_stick")),
        _row("ringing_energy", ex.ringing_energy, ring, "J", src,
             f"M_eff (2 a0 nu_c)^2 / 2 with a0 = {ex.ringing_amplitude * 1e9:g} nm, nu_c = "
             f"{ex.ringing_frequency:g} Hz, M_eff = {ex.ringing_mass * 1e3:g} g (Klein's v0 = 2 a0 nu); "
             f"with v0 = 2 pi a0 nu: {ring_h:.2g} J" if math.isfinite(ring_h) else
             "M_eff (2 a0 nu_c)^2 / 2: no ringing amplitude, frequency or mass given"),
        _row("temperature_rise", ex.temperature_rise, heat(main), "K", src,
             f"viscous energy / (rho c_p A D), film volume {A * D:.2g} m3, bulk liquid OMCTS "
             f"rho c_p = {liquid.volumetric_heat_capacity:.3g} J/(m3 K) ({liquid.source})"
             + (f"; Klein's 0.6 C implies rho c_p ~ "
                f"{ex.spring_energy_released / (ex.temperature_rise * A * D):.2g}"
                if math.isfinite(ex.temperature_rise) and ex.temperature_rise > 0 else ""),
             (heat(lo), heat(hi))),
        _row("inertial_slip_time", ex.slip_time, bulk.slip_time, "s", src,
             f"same slip with the bulk viscosity {ex.eta_bulk:g} Pa s (B = "
             f"{newtonian_damping(A, ex.eta_bulk, D):.3g} N s/m, underdamped): time to cover dx0, "
             "beside the observed tau_s"
             + ("; Klein's dotted curve in Fig. 2(c), no number in the text" if is_klein else "")),
        _row("inertial_peak_slip", None, float(np.max(bulk.x)), "m", src,
             f"largest slip of the bulk-viscosity run if nothing stopped it (~2 x0 = "
             f"{2 * geo.x0 * 1e9:.0f} nm: inertial overshoot); "
             + ("no Klein number" if is_klein else "nothing measured")),
        _row("inertial_residual_kinetic_energy", ex.ringing_energy, bulk.kinetic_energy_at_stick, "J", src,
             "kinetic energy at s with bulk viscosity: what a bulk-viscosity slip would hand to the "
             "ringing" + ("; beside Klein's observed dE_osc" if is_klein else "")),
        _row("slip_time_full_relaxation_63", ex.slip_time, time_to_fraction(full, 1 - math.exp(-1)), "s", src,
             (f"alternative reading: dx0 = x0 = {full_geo.x0 * 1e9:.1f} nm (full relaxation)" if is_klein
              else f"what if the measured slip's spring energy came from a full relaxation, dx0 = x0 = "
                   f"{full_geo.x0 * 1e9:.1f} nm (not the measured x0 and dx0)")
             + "; time to 1 - 1/e of the slip (~ B/K)"),
        _row("slip_time_full_relaxation_95", ex.slip_time, time_to_fraction(full, 0.95), "s", src,
             ("alternative reading" if is_klein else "the same full relaxation")
             + ", time to 95 % of the fully relaxed slip"),
    ]

    slips = {"klein": main, "bulk": bulk, "full_relaxation": full}
    # Klein's text alone gives x0 from dE_f and his error bars; a ringing convention needs a ringing
    said = [n for n in ASSUMPTIONS if (is_klein or n not in (_X0_FROM_KLEINS_TEXT, _KLEINS_ERRORS))
            and (n != _RINGING or math.isfinite(ring))]
    geometry = (geo.derivation if is_klein else
                f"x0 = F_s/K = {geo.x0 * 1e9:.1f} nm and dx0 = {geo.slip_distance * 1e9:.1f} nm, "
                "both from the measured trace")
    notes = said + [f"slip geometry: {geometry}",
                    f"model vs Klein's Eq. (2): max |dx|/x0 = {deviation:.1e} (closed-form "
                    f"path), {ode_deviation:.1e} (ODE path)"]

    if calibration is not None:
        calibration = MDCalibration.coerce(calibration)
        extra_rows, md_run, md_notes = md_rows(calibration, units, ex, geo, liquid, setup)
        rows += [without_unfixed_ratio(r) for r in extra_rows]
        slips["md"] = md_run
        notes += md_notes
    if contact is not None:
        from .similarity import klein_contact, klein_ranges, similarity_rows
        rows += similarity_rows(contact, klein_contact(ex, units),
                                klein_ranges(ex, units) if is_klein else {})
        notes.append("similarity rows: dimensionless numbers of the MD run (its own units) beside "
                     "Klein's; his drive velocity is taken as slip distance / cycle time, his "
                     "film compliance as delta/x0, his mount damping from the ringing's decay")
    notes.append(BRAUN_TOSATTI_NOTE)
    return SFBCheck(rows=rows, geometry=geo, slips=slips, closed_form_deviation=deviation,
                    ode_deviation=ode_deviation, notes=tuple(notes), units=units, experiment=ex,
                    calibration=calibration)


def sfb_table(calibration=None, units: LJUnits = OMCTS) -> list[dict]:
    """The SFB comparison as a list of rows (dicts with keys :data:`ROW_KEYS`).

    Parameters
    ----------
    calibration : MDCalibration, dict or compatible object, optional
        Adds the ``md-calibrated`` rows.
    units : LJUnits
        LJ ↔ SI units for the calibration (default :data:`filmfriction.reduced_model.units.OMCTS`).

    Returns
    -------
    list of dict
        ``name, klein, model, ratio, units, source`` (+ ``uncertainty``, a
        [low, high] interval of ``model`` or None, and ``note``).
    """
    return sfb_check(calibration=calibration, units=units).rows
