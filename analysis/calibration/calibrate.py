"""Calibrate the reduced spring-block model on MD runs and replay the MD trace with it.

The pieces: :mod:`~filmfriction.analysis.calibration.rundata` (reading a run),
:mod:`~filmfriction.analysis.calibration.slipfit` (the slip's closed form and its fit),
:mod:`~filmfriction.analysis.calibration.estimators` (F_s, F_b, ageing, k_f),
:mod:`~filmfriction.analysis.calibration.replay` (the model over the MD trace); this module
puts them together per run (:func:`calibrate_run`) and across runs
(:func:`calibrate`), and writes ``calibration.json`` (:func:`write_calibration`).

The model
---------
The MD top wall (mass M) is pulled through a spring K whose end moves at V,
and its mount has a dashpot d = γ·M to ground (``trace_parameters``).  The
reduced model is the same block, spring, drive and dashpot
(:class:`filmfriction.reduced_model.SpringBlock` with ``damping = d``) on a film described by
:class:`filmfriction.reduced_model.laws.Coulomb` with a viscous term::

    stick:  wall at rest until the spring force reaches F_s
    slip:   M x'' = K (x_d - x) - d x' - F_k - B x'   until x' = 0 (re-stick)

Why this law: the MD film is a solid that shear-melts at a threshold and
re-crystallises when the wall stops (Thompson & Robbins 1990).  A static
threshold F_s with an exact stick phase is the minimal description of the
first; while the film is molten it carries a rate-independent part F_k (the
wall still drags over the walls' corrugation through a disordered layer) and a
viscous part B·x' (Klein's Eq. 1, B = A η_eff / D).  Klein's purely viscous
film (F_k = 0, no threshold) cannot stick at all; a rate-and-state or
contact-age law needs ageing data that one MD run at one velocity does not
constrain.  Coulomb + viscous has a closed form (fast, exact), and each of
its three parameters is measured by a distinct feature of the trace: F_s by
the peak force, F_k by the level the force swings about during the slip,
B by how fast that swing decays and how long the slip lasts.  Its known
limitation: the model sticks at the first velocity zero, so it has no ringing
after the stick (the MD wall rings on the elastic, re-solidified film).

Fits (all in the run's LJ units)
--------------------------------
``static_force``
    Mean spring force at the fitted yield instants of the analysed slips
    (see below; the start-up yield from a relaxed spring is left out when
    ≥ 3 slips exist, as in ``analysis.json``), ± its standard error; the
    analysis's mean F_s when no slip could be fitted.  The start-up yield is
    reported apart (``first_yield_force``).
``kinetic_force`` and ``film_damping``
    One joint least-squares fit of the slip equation above
    (:func:`~filmfriction.analysis.calibration.slipfit.fit_slips`: closed form, d fixed to the
    mount's value, each slip started at rest from its own stick ramp, its yield
    instant and ramp level free, the film's freeze force F_f free where it
    improves the fit by 5 σ) to the spring force over every slip window (the
    ramp before y, the slip, and as long again after s, so the re-stick is
    constrained).  The fit runs in the slips' own force and time scales, so the
    result does not depend on the units of the trace.  Uncertainty: from the
    Jacobian at the solution and the residual variance (with the residuals'
    serial correlation); a parameter at the bound of its range (F_k = 0, B = 0)
    says so and has none.  The jackknife over slips (leave one slip out, refit)
    is written beside it as a cross-check.
``eta_eff``
    The run's one η_eff, named by
    :func:`~filmfriction.analysis.calibration.effective_viscosity.choose` (``eta_eff_choice``
    in ``calibration.json``): B·D/A with D the mean gap, at the slips' shear rate
    γ̇ = (Δx0/τ_s)/D, where the fit resolves B; the steady η_eff = ((F̄ − d V)/A)/(V/D)
    of a smooth-sliding run; else none ("not resolved", with the reason).  The
    other estimates (Klein's Eq. 1 per slip, the slip law's B, the profile's) are
    listed as cross-checks with the assumption each rests on.
``rate_law``
    With ≥ 3 runs at different shear rates, η_eff = c·γ̇^α fitted with
    :func:`filmfriction.analysis.viscosity.power_law_fit` (α ± its standard error).
``ageing``
    With ≥ 4 slips, the slope of F_s against ln(preceding stick time), ± its
    standard error (contact ageing: positive and significant if the film
    strengthens while stuck).

The :class:`filmfriction.reduced_model.MDCalibration` for the SFB check takes the stresses
F/A, η_eff and the rate law; the thinning law is Carreau with its onset at
the lowest MD rate, matched to the fit there (the pure power law from that
rate is the SFB check's upper bracket).

``shear_stiffness``
    The stuck film's elastic shear stiffness k_f, from the slopes of the stick
    ramps (K_eff = slope / V, 1/k_f = 1/K_eff − 1/K); none when the ramps rise
    at K within their errors.

Replay
------
The calibrated law carries k_f (the block creeps on the elastic film while
stuck) and a freeze velocity fitted to the MD's mean re-stick force F_b (the
MD film re-solidifies while the wall still moves; an overdamped slip would
otherwise never stop, and an underdamped one would overshoot below F_b).
F_s and F_b are therefore inputs of the replay; slip distance and period are
its predictions.  The calibrated model is run with the MD's K, M, V and d from
the MD's first re-stick point (the start-up yield, whose larger threshold reflects the
contact's age after equilibration, is not part of the steady cycle), and its
cycles are measured with the same ruler as the MD's
(:func:`filmfriction.reduced_model.cycles.cycle_table` via ``SimulationResult.cycles``).
Errors are (model − MD)/MD of the mean peak force, slip distance and period.
The peak and re-stick forces are inputs of the model (their errors check the
replay, they predict nothing); slip distance and period are predictions.

Example
-------
>>> import tempfile, pathlib
>>> from filmfriction.analysis.groundtruth.synthetic import run_directory
>>> cal = calibrate(run_directory(pathlib.Path(tempfile.mkdtemp()) / "run", trajectory=False))
>>> rc = cal.main
>>> rc.regime == "stick-slip", round(rc.static_force.value, 2), round(rc.film_damping.value, 1)
(True, 3.0, 39.6)
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .effective_viscosity import ViscosityChoice, choose
from .estimators import Estimate, ageing, shear_stiffness, summary_estimate
from ..files.util import finite_or_none as _num
from .md_estimates import md_calibration
from .replay import Replay, no_restick_reason, replay
from .rundata import RunData, load_run
from .slipfit import SlipLawFit, coulomb_slip_force, fit_slip_law
from ..files.trace import UNITS

__all__ = ["Estimate", "RunData", "SlipLawFit", "Replay", "RunCalibration", "Calibration",
           "load_run", "coulomb_slip_force", "fit_slip_law", "replay", "calibrate_run",
           "calibrate", "write_calibration", "SCHEMA", "REPLAY_TRACE_SUFFIX"]

SCHEMA = "filmfriction.calibration/1"

#: ``write_calibration`` writes the main run's replay trace to ``<stem><suffix>`` beside the JSON.
REPLAY_TRACE_SUFFIX = "_replay.csv"


@dataclass(frozen=True, eq=False)
class RunCalibration:
    """What one run gives.

    Attributes
    ----------
    run : RunData
    regime : str
    static_force, restick_force, first_yield_force : Estimate or None
    kinetic_force, film_damping : Estimate or None
    eta_eff, shear_rate : Estimate or None
        The film's η_eff (the primary of ``eta_eff_choice``; None where it is not
        resolved) and the shear rate it belongs to.
    eta_eff_choice : ViscosityChoice or None
        Which estimate of η_eff is the primary and why, and the others as cross-checks
        (:func:`filmfriction.analysis.calibration.effective_viscosity.choose`).
    ageing : Estimate or None
        dF_s / d ln(t_stick).
    slip_fit : SlipLawFit or None
    replay : Replay or None
    area, thickness : float
    failures : dict
        Step name → reason, for what could not be computed.
    """

    run: RunData
    regime: str
    area: float
    thickness: float
    static_force: Estimate | None = None
    restick_force: Estimate | None = None
    first_yield_force: Estimate | None = None
    kinetic_force: Estimate | None = None
    film_damping: Estimate | None = None
    eta_eff: Estimate | None = None
    shear_rate: Estimate | None = None
    eta_eff_choice: ViscosityChoice | None = None
    ageing: Estimate | None = None
    shear_stiffness: Estimate | None = None
    slip_fit: SlipLawFit | None = None
    replay: Replay | None = None
    failures: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        out = {"run_dir": str(Path(self.run.run_dir).resolve()), "regime": self.regime,
               "area": _num(self.area), "thickness": _num(self.thickness),
               "slips": self.run.n_slips, "skipped_first": self.run.skip}
        for name in ("static_force", "restick_force", "first_yield_force", "kinetic_force",
                     "film_damping", "eta_eff", "shear_rate", "ageing", "shear_stiffness"):
            e = getattr(self, name)
            out[name] = None if e is None else e.as_dict()
        if self.slip_fit is not None:
            out["slip_fit"] = self.slip_fit.as_dict()
        out["eta_eff_choice"] = (None if self.eta_eff_choice is None
                                 else self.eta_eff_choice.as_dict())
        out["replay"] = None if self.replay is None else self.replay.as_dict()
        out["failures"] = dict(self.failures)
        return out


def calibrate_run(run: RunData) -> RunCalibration:
    """Calibrate the model on one run (see the module docstring for each parameter)."""
    tr = run.trace
    u = UNITS[tr.units]
    doc = run.analysis
    regime = doc.get("regime", "?")
    area = tr.parameters.area
    failures: dict = {}
    try:
        thickness = run.thickness
    except LookupError as exc:
        thickness = math.nan
        failures["thickness"] = str(exc)
    kw: dict = {}
    skipnote = "start-up yield left out" if run.skip else "all slips"
    kw["static_force"] = summary_estimate(doc, "static_force", u["force"], f"mean F_s at y, {skipnote}")
    kw["restick_force"] = summary_estimate(doc, "backward_force", u["force"], f"mean F_b at s, {skipnote}")
    if run.skip and run.n_slips:
        kw["first_yield_force"] = Estimate(float(run.cycles["static_force"][0]), math.nan, u["force"],
                                           "start-up yield from a relaxed spring (one value)")
    kw["ageing"] = ageing(run)
    kw["shear_stiffness"] = shear_stiffness(run)
    if kw["static_force"] is None:
        failures["slip_fit"] = f"no slips to fit (regime {regime})"
    else:
        try:
            k_f = kw["shear_stiffness"].value if kw.get("shear_stiffness") else math.inf
            k = tr.parameters.spring_constant
            fit = fit_slip_law(run, stick_stiffness=k * k_f / (k + k_f) if k else None)
            kw.update(slip_fit=fit, kinetic_force=fit.kinetic_force, film_damping=fit.film_damping,
                      static_force=fit.static_force)
        except (ValueError, LookupError, RuntimeError) as exc:
            failures["slip_fit"] = str(exc)
    # eta_eff: the one the run's estimators agree to name (effective_viscosity.choose)
    fit = kw.get("slip_fit")
    d = tr.parameters.mount_damping or 0.0
    choice = choose(doc, kinetic_force=kw.get("kinetic_force"),
                    film_damping=kw.get("film_damping"),
                    damping_scatter=fit.jackknife_stderr[1] if fit is not None else math.nan,
                    thickness=thickness,
                    area=float(area) if area else math.nan, mount_damping=d, units=tr.units)
    kw["eta_eff_choice"] = choice
    if choice.primary is not None:
        kw["eta_eff"] = choice.primary
    else:
        failures["eta_eff"] = f"not resolved: {choice.reason}"
    steady = (doc.get("viscosity") or {}).get("steady")
    if choice.estimator in ("steady", "internal") and steady:
        kw["shear_rate"] = Estimate(steady["shear_rate"]["mean"], math.nan, u["shear_rate"],
                                    "V / D")
    elif fit is not None and math.isfinite(thickness):
        slips = doc.get("slips", {})
        dx = (slips.get("slip_distance") or {}).get("mean")
        ts = (slips.get("slip_duration") or {}).get("mean")
        kw["shear_rate"] = Estimate(dx / ts / thickness if dx and ts else math.nan, math.nan,
                                    u["shear_rate"], "mean slip velocity (dx0 / tau_s) over the gap")
    if fit is not None:
        try:
            restick = kw["restick_force"].value if kw.get("restick_force") else None
            shear = kw["shear_stiffness"].value if kw.get("shear_stiffness") else math.inf
            kw["replay"] = replay(run, kw["static_force"].value, fit.kinetic_force.value,
                                  fit.film_damping.value, restick_force=restick,
                                  shear_stiffness=shear)
            why = no_restick_reason(run, fit.kinetic_force.value, fit.film_damping.value)
            if why and not kw["replay"].errors["period"]["model_cycles"]:
                failures["replay"] = why
        except (ValueError, LookupError, RuntimeError) as exc:
            failures["replay"] = str(exc)
    else:
        failures.setdefault("replay", "no calibrated slip law")
    return RunCalibration(run=run, regime=regime, area=float(area or math.nan),
                          thickness=thickness, failures=failures, **kw)


@dataclass(frozen=True, eq=False)
class Calibration:
    """The calibration over one or several runs.

    Attributes
    ----------
    runs : list of RunCalibration
        In the order given (the first is the "main" run: replay, report).
    rate_law : analysis.viscosity.PowerLaw or None
        η_eff = c γ̇^α across runs (≥ 3 distinct rates).
    rate_points : list of (float, float, float)
        (γ̇, η_eff, stderr) per run that has both.
    rate_dependence : dict or None
        The sliding stress τ = η_eff γ̇ against γ̇, Eyring-like and power law, the
        one with the smaller residual chosen, carried to the mean shear rate of
        Klein's slip with its 68 % interval (:func:`rate_dependence`).
    md_calibration : filmfriction.reduced_model.MDCalibration or None
    notes : list of str
    failures : dict
    units : str
    """

    runs: list
    rate_law: object = None
    rate_points: list = field(default_factory=list)
    md_calibration: object = None
    rate_dependence: dict | None = None
    notes: list = field(default_factory=list)
    failures: dict = field(default_factory=dict)
    units: str = "lj"

    @property
    def main(self) -> RunCalibration:
        return self.runs[0]

    def as_dict(self) -> dict:
        law = None
        if self.rate_law is not None:
            law = {"exponent": _num(self.rate_law.exponent),
                   "exponent_stderr": _num(self.rate_law.exponent_stderr),
                   "prefactor": _num(self.rate_law.prefactor),
                   "prefactor_rel_stderr": _num(self.rate_law.prefactor_rel_stderr),
                   "n": self.rate_law.n, "form": "eta_eff = prefactor * shear_rate**exponent"}
        md = None if self.md_calibration is None else self.md_calibration.as_dict()
        return {"schema": SCHEMA, "units": self.units,
                "model": "SpringBlock + Coulomb(static F_s, kinetic F_k, viscous B) + mount dashpot d",
                "runs": [r.as_dict() for r in self.runs],
                "rate_points": [[_num(a), _num(b), _num(c)] for a, b, c in self.rate_points],
                "rate_law": law, "rate_dependence": self.rate_dependence, "md_calibration": md,
                "notes": list(self.notes), "failures": dict(self.failures)}


def calibrate(run_dirs) -> Calibration:
    """Calibrate the reduced model on one or several run directories.

    Parameters
    ----------
    run_dirs : path-like or list of path-like

    Returns
    -------
    Calibration

    Raises
    ------
    ValueError
        A directory cannot be read.
    """
    from filmfriction.analysis.viscosity import power_law_fit

    if isinstance(run_dirs, (str, os.PathLike)):
        run_dirs = [run_dirs]
    runs = [calibrate_run(load_run(d)) for d in run_dirs]
    if not runs:
        raise ValueError("no run directory given")
    units = {r.run.trace.units for r in runs}
    if len(units) != 1:
        raise ValueError(f"runs in different unit systems: {sorted(units)}")
    notes, failures = [], {}
    points = [(r.shear_rate.value, r.eta_eff.value, r.eta_eff.stderr) for r in runs
              if r.eta_eff is not None and r.shear_rate is not None
              and math.isfinite(r.shear_rate.value) and r.eta_eff.value > 0]
    law = None
    distinct = len({round(math.log10(p[0]), 3) for p in points if p[0] > 0})
    if distinct >= 3:
        errs = np.array([p[2] for p in points], float)
        use_err = bool(np.all(np.isfinite(errs) & (errs > 0)))
        try:
            law = power_law_fit([p[0] for p in points], [p[1] for p in points],
                                errs if use_err else None)
        except (ValueError, RuntimeError) as exc:
            failures["rate_law"] = str(exc)
    else:
        failures["rate_law"] = (f"{distinct} distinct shear rate(s): the power law needs runs at >= 3 "
                                "(e.g. a drive-velocity sweep)")
    md = None
    try:
        md = md_calibration(runs, law, points, notes)
    except ValueError as exc:
        failures["md_calibration"] = str(exc)
    dependence = None
    if distinct >= 3:
        from filmfriction.reduced_model.units import SI_IDENTITY
        try:
            # an SI trace's rates are SI already: the identity mapping carries them
            dependence = rate_dependence(points, SI_IDENTITY if units == {"si"} else None)
        except ValueError as exc:
            failures["rate_dependence"] = str(exc)
    return Calibration(runs=runs, rate_law=law, rate_points=points, md_calibration=md,
                       notes=notes, failures=failures, units=units.pop(),
                       rate_dependence=dependence)


def rate_dependence(points, units=None) -> dict:
    """The sliding stress's rate law across runs, carried to Klein's slip rate.

    ``points`` are (γ̇, η_eff, stderr) in LJ units (SI with ``units`` =
    :data:`~filmfriction.reduced_model.units.SI_IDENTITY`, a measured trace's); the stress is τ = η_eff·γ̇ (error
    stderr·γ̇).  Both an Eyring-like τ0 + τ1 ln(γ̇/γ̇_ref) and a power law c γ̇^n are
    fitted (:mod:`.ratelaw`); the one with the smaller residual in stress is chosen
    and both are evaluated at the mean shear rate of Klein's slip, Δx0/(τ_s D)
    (≈ 6×10² s⁻¹), converted to LJ with ``units`` (default OMCTS), each with its 68 %
    interval and whether that interval spans more than a decade.
    """
    from filmfriction.reduced_model.sfb.klein import KLEIN, klein_slip_geometry
    from filmfriction.reduced_model.units import OMCTS, SI_IDENTITY

    from ..rate_law import choose_rate_law, eyring_fit, power_fit

    units = units or OMCTS
    stress_units = "Pa, a measured trace's" if units == SI_IDENTITY else "LJ stress units"
    rate = np.array([p[0] for p in points], float)
    stress = np.array([p[1] * p[0] for p in points], float)
    err = np.array([p[2] * p[0] for p in points], float)
    err = err if np.all(np.isfinite(err) & (err > 0)) else None
    geo = klein_slip_geometry(KLEIN)
    sfb_rate_si = geo.slip_distance / (KLEIN.slip_time * KLEIN.film_thickness)
    sfb_rate = float(units.from_si(sfb_rate_si, "shear_rate"))
    out = {"stress": f"eta_eff * shear_rate ({stress_units})", "weighted": err is not None,
           "sfb_shear_rate": sfb_rate, "sfb_shear_rate_si": sfb_rate_si,
           "decades_extrapolated": float(np.log10(rate.min() / sfb_rate))}
    fits = {"eyring": eyring_fit(rate, stress, err)}
    try:
        fits["power"] = power_fit(rate, stress, err)
    except ValueError as exc:
        out["power_failure"] = str(exc)
    chosen = choose_rate_law(rate, stress, err)
    out["chosen"] = chosen.form
    for name, law in fits.items():
        e = law.extrapolate(sfb_rate)
        out[name] = {**law.as_dict(), "stress_at_sfb_rate": e.as_dict(),
                     "stress_at_sfb_rate_si": {
                         k: float(units.to_si(getattr(e, k), "stress")) for k in ("value", "low", "high")}}
    return out


#: ``calibration.json``'s ``run_dirs_relative_to``: its runs' ``run_dir`` are relative to
#: the folder of the file itself (older files hold absolute paths).
RUN_DIRS_RELATIVE_TO = "calibration.json"


def write_calibration(cal: Calibration, path=None) -> Path:
    """Write ``calibration.json`` atomically (default: in the first run directory).

    The main run's replay trace (the model's spring force on the MD's time
    axis, columns ``time,spring_force``) goes beside it, to
    ``calibration_replay.csv`` (:data:`REPLAY_TRACE_SUFFIX`), when there is a
    replay; the document's ``replay_trace`` names that file (or is null).

    Returns
    -------
    Path
        The JSON file.
    """
    from filmfriction.analysis.files.util import write_atomic
    from filmfriction.analysis.analyze import to_json

    from filmfriction.analysis.files.provenance import provenance
    from filmfriction.md_inputs.contract import ANALYSIS_FILE, TRACE_FILE

    path = Path(path) if path is not None else cal.main.run.run_dir / "calibration.json"
    doc = cal.as_dict()
    # the runs as seen from this file's folder: a run directory moved or copied with its
    # calibration.json keeps it (RUN_DIRS_RELATIVE_TO says how to read them)
    base = path.parent.resolve()
    for entry in doc["runs"]:
        entry["run_dir"] = os.path.relpath(Path(entry["run_dir"]).resolve(), base)
    doc["run_dirs_relative_to"] = RUN_DIRS_RELATIVE_TO
    inputs = {}
    for i, r in enumerate(cal.runs):
        d = Path(r.run.run_dir)
        inputs[f"runs[{i}] {ANALYSIS_FILE}"] = d / ANALYSIS_FILE
        inputs[f"runs[{i}] trace"] = r.run.trace.path if Path(r.run.trace.path).is_file() \
            else d / TRACE_FILE
    doc["provenance"] = provenance(inputs)
    doc["replay_trace"] = None
    rp = cal.main.replay
    if rp is not None:
        trace = path.with_name(path.stem + REPLAY_TRACE_SUFFIX)
        rows = "".join(f"{t!r},{f!r}\n" for t, f in zip(rp.t.tolist(), rp.spring_force.tolist()))
        write_atomic(trace, "time,spring_force\n" + rows)
        doc["replay_trace"] = trace.name
    return write_atomic(path, to_json(doc) + "\n")
