"""An analysed run as a sliding contact, for the similarity comparison with an SFB experiment.

:func:`contact_from_analysis` reads what the analysis measured (``analysis.json``)
and the run's own parameters (``run.json``'s ``trace_parameters`` and scene) into a
:class:`filmfriction.reduced_model.sfb.similarity.SlidingContact` in the run's units:

* F_s, F_b, Δx0 — the slips' means and standard errors (start-up slip left out);
* B — the film's drag measured as Klein measured his: his Eq. (1) fitted to the slips
  (``viscosity.from_slip.damping``), less the mount's dashpot γM; without that fit, the
  slip law's B (``slip_law.damping``).  Whether a viscous B describes the film at all
  is the slip law's verdict, reported beside it;
* γM — the mount dashpot; k_f — the stick ramps' film stiffness;
* the viscous fraction — film heat over film heat + ringing, per slip;
* L = P·A with P the scene's normal pressure and A the wall area; the molecular
  diameter is the film atom's σ = 1 and ε/σ³ = 1 (LJ units);
* B_bulk = η_bulk·A/D, the slip law's ``bulk_film_damping`` (η_bulk of the LJ liquid
  at the film's state point);
* the film's temperature rise per slip, adiabatic: the film heat over 3 N k_B
  (Dulong–Petit for N film atoms; k_B = 1), beside the scene's temperature;
* the mean slip velocity, mean slip distance over mean slip duration, beside the
  thermal velocity √(kT/m) (m = 1); the contact width √A.
"""
from __future__ import annotations

import math
from pathlib import Path

from filmfriction.reduced_model.sfb.similarity import SlidingContact
from filmfriction.md_inputs.contract import ANALYSIS_FILE, RUN_FILE

from ..files.util import read_json_object

__all__ = ["contact_from_analysis", "contact_from_run"]


def _mean(entry, default=None):
    if not isinstance(entry, dict) or entry.get("mean") is None:
        return default
    return float(entry["mean"])


def _err(entry):
    if not isinstance(entry, dict) or entry.get("stderr") is None:
        return 0.0
    e = float(entry["stderr"])
    return e if math.isfinite(e) else 0.0


def contact_from_analysis(analysis: dict, run: dict) -> SlidingContact:
    """The run's :class:`SlidingContact` (LJ units) from its analysis and run record.

    Raises
    ------
    ValueError
        When the run has no slips to measure, or lacks K, M, V or the area.
    """
    tp = run.get("trace_parameters") or {}
    scene = (run.get("scene") or {}).get("parameters") or {}
    k, m, v, area = (tp.get(n) for n in ("spring_constant", "mass", "drive_velocity", "area"))
    missing = [n for n, x in (("spring_constant", k), ("mass", m), ("drive_velocity", v),
                              ("area", area)) if not x]
    if missing:
        raise ValueError(f"run.json trace_parameters lack {', '.join(missing)}")
    slips = analysis.get("slips") or {}
    if not slips.get("count"):
        raise ValueError("the analysis found no slips: no static force to compare")
    fs, fb = _mean(slips.get("static_force")), _mean(slips.get("backward_force"))
    if fs is None or fb is None:
        raise ValueError("the analysis has no static or backward force")
    gm = float(tp.get("mount_damping") or 0.0)
    fit = (analysis.get("viscosity") or {}).get("from_slip") or {}
    b, b_err = _mean(fit.get("damping")), _err(fit.get("damping"))
    if b is not None:
        b -= gm
    else:
        law = analysis.get("slip_law") or {}
        b, b_err = _mean(law.get("damping")), _err(law.get("damping"))
    energy = analysis.get("energy") or {}
    pressure = scene.get("normal_pressure")
    law = analysis.get("slip_law") or {}
    bulk, bulk_err = _mean(law.get("bulk_film_damping")), _err(law.get("bulk_film_damping"))
    temp = scene.get("temperature")
    atoms = (run.get("derived") or {}).get("film_atoms")
    heat, heat_err = _mean(energy.get("film_heat")), _err(energy.get("film_heat"))
    rise = rise_err = None
    if heat is not None and atoms:
        rise, rise_err = heat / (3.0 * atoms), heat_err / (3.0 * atoms)
    dist, dur = _mean(slips.get("slip_distance")), _mean(slips.get("slip_duration"))
    speed = speed_err = None
    if dist is not None and dur:
        speed = dist / dur
        speed_err = speed * math.hypot(_err(slips.get("slip_distance")) / dist if dist else 0.0,
                                       _err(slips.get("slip_duration")) / dur)
    return SlidingContact(
        spring_constant=float(k), mass=float(m), drive_velocity=float(v),
        static_force=fs, restick_force=fb,
        static_force_err=_err(slips.get("static_force")),
        restick_force_err=_err(slips.get("backward_force")),
        normal_load=None if pressure is None else float(pressure) * float(area),
        slip_distance=_mean(slips.get("slip_distance")),
        slip_distance_err=_err(slips.get("slip_distance")),
        film_damping=b, film_damping_err=b_err, mount_damping=gm,
        film_stiffness=_mean(energy.get("film_stiffness")),
        film_stiffness_err=_err(energy.get("film_stiffness")),
        molecular_diameter=1.0,
        viscous_fraction=_mean(energy.get("viscous_fraction")),
        viscous_fraction_err=_err(energy.get("viscous_fraction")),
        pressure=None if pressure is None else float(pressure), stress_unit=1.0,
        bulk_damping=bulk, bulk_damping_err=bulk_err,
        temperature=None if temp is None else float(temp),
        temperature_rise=rise, temperature_rise_err=rise_err or 0.0,
        slip_velocity=speed, slip_velocity_err=speed_err or 0.0,
        thermal_velocity=None if temp is None else math.sqrt(float(temp)),
        contact_width=math.sqrt(float(area)))


def contact_from_run(run_dir) -> SlidingContact:
    """:func:`contact_from_analysis` of ``run_dir/analysis.json`` and ``run_dir/run.json``."""
    run_dir = Path(run_dir)
    return contact_from_analysis(read_json_object(run_dir / ANALYSIS_FILE),
                                 read_json_object(run_dir / RUN_FILE))
