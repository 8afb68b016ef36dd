"""The report's sections, one function each, from the files the study wrote: the
scene, every observable of the analysis, the viscosity, the calibration, the cost and
a sweep (the SFB check and the similarity with Klein's experiment:
:mod:`~filmfriction.workflows.report.sfb_sections`)."""
from __future__ import annotations

import json
import math
from pathlib import Path

from filmfriction.analysis.observables import Observable
from filmfriction.analysis.files.trace import unit as _unit
from filmfriction.analysis.files.util import format_estimate as _pm, format_pm as _pm_plain
from filmfriction.analysis.files.util import format_value as _fmt
from filmfriction.md_inputs.contract import RUN_FILE
from filmfriction.reduced_model.units import OMCTS

from .document import Figure, Section, Table, fixed_decimals, trace_source
from .plots import fig_replay, fig_replay_errors, fig_viscosity


#: Scene parameter → (quantity for reduced_model.units, LJ unit label).
PARAMETER_QUANTITIES = {
    "drive_velocity": ("velocity", "σ/τ"), "spring_constant": ("spring_constant", "ε/σ²"),
    "normal_pressure": ("pressure", "ε/σ³"), "temperature": ("temperature", "ε/k_B"),
    "wall_mass": ("mass", "m"), "mount_damping": ("frequency", "1/τ"),
    "wall_fluid_epsilon": ("energy", "ε"), "wall_spacing": ("length", "σ"),
    "film_spacing": ("length", "σ"), "timestep": ("time", "τ"), "cutoff": ("length", "σ"),
    "thermostat_damping": ("time", "τ"), "profile_bin": ("length", "σ"),
}


_SI_LABEL = {"velocity": "m/s", "spring_constant": "N/m", "pressure": "Pa", "temperature": "K",
             "mass": "kg", "frequency": "1/s", "energy": "J", "length": "m", "time": "s"}


# ---------------------------------------------------------------------------
# sections
# ---------------------------------------------------------------------------
def attempt(failures: dict, name: str, fn, *args):
    try:
        return fn(*args)
    except Exception as exc:  # noqa: BLE001 -- a report records failures, it does not stop
        failures[name] = f"{type(exc).__name__}: {exc}"
        return None


def scene_section(run) -> Section:
    sec = Section("Scene and parameters")
    rj = run.trace.run or {}
    scene = rj.get("scene", {})
    if not scene:
        units = run.analysis.get("units", "lj")
        sec.p(f"No MD scene: a trace read as it is (`{run.trace.path.name}`), in "
              f"{'SI' if units == 'si' else 'LJ'} units as its analysis records; the parameters "
              "the analysis used: " + (", ".join(
                  f"{k} = {_fmt(v)}" for k, v in
                  ((run.analysis.get("source") or {}).get("parameters") or {}).items()
                  if v is not None) or "none") + ".")
        return sec
    sec.p(f"Scene **{scene.get('name', '?')}**: {scene.get('description', '')}")
    if scene.get("models"):
        sec.p(" ".join(scene["models"].split()))
    rows = []
    for k, v in (scene.get("parameters") or {}).items():
        q = PARAMETER_QUANTITIES.get(k)
        if q and isinstance(v, (int, float)):
            si = OMCTS.to_si(float(v), q[0])
            rows.append((k, _fmt(v), q[1], f"{si:.3g} {_SI_LABEL[q[0]]}"))
        else:
            rows.append((k, _fmt(v) if isinstance(v, (int, float)) else str(v), "–", "–"))
    tp = rj.get("trace_parameters") or {}
    for k, q, lab in (("area", "area", "σ²"), ("mass", "mass", "m"),
                      ("mount_damping", "damping", "m/τ")):
        if tp.get(k) is not None:
            si = OMCTS.to_si(float(tp[k]), q)
            rows.append((f"{k} (trace)", _fmt(tp[k]), lab, f"{si:.3g} " + {"area": "m²", "mass": "kg",
                                                                            "damping": "N·s/m"}[q]))
    sec.add(Table(("parameter", "value", "LJ unit", f"SI ({OMCTS.name})"), tuple(rows)))
    sec.p(f"SI equivalents use the {OMCTS.name} mapping of `filmfriction.reduced_model.units`: σ = "
          f"{OMCTS.sigma * 1e9:.3g} nm, ε/k_B = {OMCTS.temperature:.0f} K, m = {OMCTS.molar_mass_g:.2f} g/mol, "
          f"τ = {OMCTS.tau * 1e12:.2f} ps ({OMCTS.source}).")
    return sec


def viscosity_section(cal, why_none: str, failures) -> Section:
    from filmfriction.reduced_model.sfb.klein import KLEIN

    sec = Section("Effective viscosity η_eff(γ̇)")
    said = cal is not None and _eta_choice_blocks(sec, cal)
    if cal is None or not cal.get("rate_points"):
        main_failures = cal["runs"][0].get("failures", {}) if cal else {}
        if not said:
            sec.p("No η_eff: " + ("it comes from the calibration, which is not available (see "
                                  "“Calibrated reduced model”)" if cal is None else
                                  main_failures.get("eta_eff") or "no run with η_eff") + ".")
        return sec
    units = cal.get("units", "lj")
    png = attempt(failures, "figure: viscosity", fig_viscosity, cal)
    law = cal.get("rate_law")
    if png:
        sec.add(Figure("viscosity", png, "Film η_eff against shear rate, one point per run"
                       + (" with the power-law fit." if law is not None else ".")))
    if law is not None:
        sec.p(f"Power law over {law['n']} runs: η_eff = {_fmt(law['prefactor'], 3)} · γ̇^({law['exponent']:.3f} ± "
              f"{fixed_decimals(law['exponent_stderr'], 3)}) ({units.upper()} units); a thinning exponent n = {-law['exponent']:.3f}.")
    else:
        g, eta, err = cal["rate_points"][0]
        in_si = ("" if units == "si" else
                 f" (= {OMCTS.to_si(eta, 'viscosity'):.3g} Pa·s)")
        rate_si = "" if units == "si" else f" (= {OMCTS.to_si(g, 'shear_rate'):.3g} 1/s)"
        sec.p(f"One shear rate only: η_eff = {_pm_plain(eta, err, 3)} "
              f"{_unit(units, 'viscosity')}{in_si} at γ̇ = {_fmt(g, 3)} "
              f"{_unit(units, 'shear_rate')}{rate_si}. "
              "A sweep of drive velocities (several runs) is needed for the shear-rate law.")
    dep = cal.get("rate_dependence")
    if dep:
        parts = []
        for form in ("eyring", "power"):
            law_ = dep.get(form)
            if not law_:
                continue
            e, si = law_["stress_at_sfb_rate"], law_["stress_at_sfb_rate_si"]
            where = ("spans more than a decade: not a prediction" if e["spans_decade"] else
                     f"{_fmt(si['low'], 2)} … {_fmt(si['high'], 2)} Pa")
            parts.append(f"{form} (residual {_fmt(law_['residual'], 3)}): τ = {_fmt(e['value'], 3)} "
                         f"ε/σ³ = {_fmt(si['value'], 3)} Pa, 68 % interval {where}")
        sec.p(f"Sliding stress τ = η_eff·γ̇ against the rate, carried "
              f"{dep['decades_extrapolated']:.1f} decades down to the mean shear rate of Klein's "
              f"slip ({_fmt(dep['sfb_shear_rate_si'], 3)} 1/s): " + "; ".join(parts)
              + f". Chosen by residual: **{dep['chosen']}**. Klein's viscous stress η_eff·γ̇ is "
              f"{_fmt(KLEIN.eta_eff * dep['sfb_shear_rate_si'] / 1e3, 3)} kPa at that rate.")
    if len(cal["runs"]) > 1:
        for r in cal["runs"]:
            if r.get("eta_eff") is not None:
                sec.p(f"`{Path(r['run_dir']).resolve().name}`: {r['eta_eff']['method']}.")
    return sec


def _eta_choice_blocks(sec: Section, cal: dict) -> bool:
    """The main run's one η_eff (``eta_eff_choice`` of ``calibration.json``), the other
    estimates as cross-checks, and the calibration's friction law beside the slip law's;
    False where the calibration has no choice to show."""
    choice = cal["runs"][0].get("eta_eff_choice")
    if not choice:
        return False
    names = {"calibration": "calibration (joint slip fit, B·D/A)",
             "slips": "slips (Klein's Eq. 1 per slip)", "slip_law": "slip law (F_film = F_k + B·v)",
             "steady": "steady sliding", "internal": "velocity profile"}
    if choice["status"] == "resolved":
        p = choice["primary"]
        sec.p(f"**The run's η_eff: {_pm(p)}**, from the {names.get(choice['estimator'])}: "
              f"{choice['reason']}.")
    else:
        sec.p(f"**The run's η_eff: not resolved**: {choice['reason']}. The estimates below rest "
              "on other assumptions; none is the run's η_eff.")
    checks = choice.get("cross_checks") or []
    if checks:
        sec.add(Table(("cross-check", "η_eff", "rests on", "against the primary"),
                      tuple((names.get(c["estimator"], c["estimator"]), _pm(c["eta_eff"]),
                             c["rests_on"], c["difference"]
                             + (f"; **unphysical**: {c['unphysical']}" if c.get("unphysical")
                                else "")) for c in checks)))
    law = choice.get("friction_law") or {}
    if law:
        terms = {"mixed": "a kinetic part and a film drag", "viscous": "a film drag only",
                 "kinetic": "a kinetic part only", "neither": "neither term"}
        text = (f"Friction law, F_k + B·v: the calibration resolves "
                f"**{terms.get(law['calibration'], law['calibration'])}** (from "
                f"{law['calibration_rests_on']}), the slip law "
                f"**{terms.get(law['slip_law'], law['slip_law'])}** (from "
                f"{law['slip_law_rests_on']})")
        agree = "they agree" + (f": {law['note']}" if law.get("note") else "")
        sec.p(text + (f"; {agree}." if law.get("agree") else f"; {law.get('note', '')}."))
    return True


def calibration_section(cal, why_none: str, remarks: list, run, failures) -> Section:
    """The calibrated model from a ``calibration.json`` document (None: ``why_none`` is said)."""
    sec = Section("Calibrated reduced model")
    for r in remarks:
        sec.p(r)
    if cal is None:
        sec.p(why_none)
        return sec
    rc = cal["runs"][0]
    units = cal.get("units", "lj")
    source = trace_source(units)
    sec.p(f"Model: the {'MD' if units == 'lj' else 'driven'} wall's mass M, spring K, drive V and mount dashpot d in "
          "`filmfriction.reduced_model.SpringBlock`, with a Coulomb film (static F_s, kinetic F_k) plus a viscous "
          "film damping B while it slides, and a freeze force F_f where the film re-solidifies "
          "while the wall still moves. F_k, B and F_f are fitted jointly to the spring force of "
          "every analysed slip (each slip's yield and ramp level free), in the slips' own force "
          "and time scales; standard errors come from the fit's Jacobian and residuals, and a "
          "parameter at the bound of its range says so and has none (see "
          "`analysis/calibration/slipfit.py`).")
    rows = []
    for name in ("static_force", "kinetic_force", "restick_force", "first_yield_force", "film_damping",
                 "eta_eff", "shear_rate", "ageing"):
        e = rc.get(name)
        if e is not None:
            rows.append((name.replace("_", " "), _pm(e), e["method"]))
    sec.add(Table(("parameter", f"value ({units.upper()})", "how"), tuple(rows)))
    ageing = rc.get("ageing")
    if ageing is not None:
        stderr = math.nan if ageing["stderr"] is None else ageing["stderr"]
        sig = abs(ageing["value"]) > 2 * stderr
        fs = (rc.get("static_force") or {}).get("value")
        too_big = fs is not None and abs(ageing["value"]) > abs(fs)
        sec.p(f"Contact ageing: dF_s/d ln(t_stick) = {_pm(ageing)}; "
              + ("larger than F_s itself, so not read as contact ageing (see the consistency "
                 "section)" if too_big else
                 "more than two standard errors from zero" if sig else
                 "not resolved (within two standard errors of zero)")
              + " (a correlation over the detected slips; small secondary slips with short sticks, if the "
                "detector counts them, push it up too).")
    for k, v in rc.get("failures", {}).items():
        sec.p(f"Not computed — {k}: {v}.")
    replay = rc.get("replay")
    if replay is not None:
        trace = cal.get("replay_trace")
        if trace is not None:
            png = attempt(failures, "figure: replay", fig_replay, run, trace, replay["start_time"])
            if png:
                sec.add(Figure("replay", png, f"The calibrated model over the {source} trace; it "
                               f"starts at t = {_fmt(replay['start_time'])} {_unit(units, 'time')} "
                               f"(dotted line) from the {source} trace's state there."))
        else:
            sec.p("No replay trace beside `calibration.json` (`calibration_replay.csv`): the figure of the "
                  f"model over the {source} trace is left out; `filmfriction calibrate` writes it.")
        errs = replay["errors"]
        png = attempt(failures, "figure: replay errors", fig_replay_errors, errs, source)
        if png:
            sec.add(Figure("replay-errors", png, "Relative error of the model's mean peak force, slip "
                           f"distance and period against the {source} trace's; black bars: its own "
                           "standard error."))
        rows = [(q.replace("_", " "), _fmt(e["md"]), _fmt(e["md_stderr"], 2), _fmt(e["model"]),
                 "–" if e["rel_error"] is None or not math.isfinite(e["rel_error"]) else f"{e['rel_error']:+.1%}")
                for q, e in errs.items()]
        sec.add(Table(("quantity", source, f"{source} stderr", "model", "error"), tuple(rows)))
        sec.p("The peak force is an input of the model (F_s), so its error checks the replay rather than "
              "predicting anything; slip distance and period are predictions. The model re-sticks "
              f"where its wall velocity falls to a freeze velocity fitted to the {source}'s F_b (or "
              f"at rest) and has no ringing after s, which the {source} wall shows.")
    md = cal.get("md_calibration")
    if md is not None:
        sec.p(f"Handed to the SFB check ({units.upper()}): yield stress "
              f"{_pm_plain(md['yield_stress'], md['yield_stress_err'])}, sliding stress "
              f"{_pm_plain(md['sliding_stress'], md['sliding_stress_err'])}, re-stick stress "
              f"{_fmt(md['restick_stress'])}, η0 {_pm_plain(md['eta_zero'], md['eta_zero_err'])}, "
              f"thinning exponent {_pm_plain(md['thinning_exponent'], md['thinning_exponent_err'], 3)}.")
    for k, v in cal.get("failures", {}).items():
        sec.p(f"Not computed — {k}: {v}.")
    for n in cal.get("notes", []):
        sec.p(f"Note: {n}.")
    return sec


def observable_section(obs: Observable, run, failures) -> Section:
    """The report's section of one observable (``filmfriction.analysis.observables``):
    why it is not there, or its figure, its table and its notes."""
    sec = Section(obs.title)
    section = run.analysis.get(obs.key)
    if not section or not obs.shown(section):
        why = run.analysis.get("skipped", {}).get(obs.key)
        if why is None and obs.key in run.analysis:
            why = "nothing to show for this run"
        elif why is None and not (run.run_dir / RUN_FILE).is_file():
            why = "a trace file has none: it is not an MD run"
        elif why is None:
            why = f"not in this `analysis.json` (rerun `filmfriction analyze {run.run_dir}`)"
        sec.p(f"{obs.absent}: {why}.")
        sec.absent = why
        return sec
    what = obs.key.replace("_", " ")
    for text in attempt(failures, f"lead: {what}", obs.lead, run) or ():
        sec.p(text)
    for name, png, caption in attempt(failures, f"figure: {what}", obs.figures, run) or ():
        sec.add(Figure(name, png, caption))
    rows = attempt(failures, f"table: {what}", obs.rows, section)
    if rows:
        sec.add(Table(tuple(obs.table_header), tuple((str(a), str(b)) for a, b in rows)))
    for text in attempt(failures, f"notes: {what}", obs.notes, section) or ():
        sec.p(text)
    return sec


def cost_section(run) -> Section:
    sec = Section("Cost and provenance")
    rj = run.trace.run or {}
    if not rj:
        sec.p(f"No `run.json` in `{run.run_dir}`: not a run of `filmfriction run`, so no cost "
              "or provenance to report.")
        sec.absent = "a trace, not a run of `filmfriction run`: no `run.json`"
        return sec
    rows = [("status", str(rj.get("status"))),
            ("wall time", f"{_fmt(rj.get('wall_time'))} s"),
            ("atom-steps per second", _fmt(rj.get("atom_steps_per_second"))),
            ("atoms", json.dumps(rj.get("atoms"))),
            ("MPI ranks", str(rj.get("np"))),
            ("seeds", json.dumps(rj.get("seeds"))),
            ("versions", ", ".join(f"{k} {v}" for k, v in (rj.get("versions") or {}).items())),
            ("started / finished", f"{rj.get('started')} / {rj.get('finished')}"),
            ("run directory", str(run.run_dir))]
    for w in rj.get("warnings") or []:
        rows.insert(1, ("warning", str(w)))
    sec.add(Table(("item", "value"), tuple(rows)))
    cmd = rj.get("command")
    if cmd:
        sec.p("Command: `" + " ".join(str(c) for c in cmd) + "`")
    return sec


# ---------------------------------------------------------------------------
# entry point
# ---------------------------------------------------------------------------
def sweep_section(sweeps) -> Section:
    sec = Section("Sweeps")
    for agg in sweeps:
        doc = agg.doc
        grid = ", ".join(f"`{g.get('spec', g.get('key'))}`" for g in doc.get("grid") or [])
        sec.p(f"Sweep `{agg.sweep_dir}` of scene `{doc.get('scene')}` over {grid}: "
              f"{len(doc.get('points', []))} points.")
        rows = []
        for cv in doc.get("critical_velocity") or []:
            group = ", ".join(f"{k}={v}" for k, v in (cv.get("group") or {}).items()) or "all"
            rows.append((group, cv.get("status", ""), _fmt(cv.get("value")),
                         f"×/÷ {_fmt(cv.get('factor'), 3)}", cv.get("note", "")))
        if rows:
            sec.add(Table(("points", "status", "critical velocity V_c [σ/τ]", "uncertainty",
                           "bracket"), tuple(rows)))
        law = doc.get("power_law") or {}
        if law.get("exponent") is not None:
            sec.p(f"η_eff ∝ γ̇^α with α = {_fmt(law['exponent'], 3)} ± "
                  f"{_fmt(law.get('exponent_stderr'), 2)} over {law.get('n')} runs "
                  f"({law.get('points', '')}); Thompson, Grest & Robbins report about −2/3 for "
                  "glassy films.")
        for name, path in agg.figures.items():
            sec.add(Figure(f"sweep-{name}", Path(path).read_bytes(),
                           "Friction and regime against the drive velocity, with the critical "
                           "velocity bracket; η_eff against shear rate with the power law."
                           if name == "velocity_map" else
                           "Regime over (V, K), with the calibrated reduced model's boundary "
                           "when a calibration was given."))
    return sec
