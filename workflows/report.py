"""The study report: one self-contained HTML page and its Markdown twin.

:func:`build_report` reads one or several run directories (the first is the
main run) and renders what the study wrote there (:mod:`filmfriction.workflows.study`):
the analysis (``analysis.json``), the calibration (``calibration.json``) and
the SFB check (``sfb.json``).  It computes none of them: a file that is not
there is said in the report, with the command that makes it
(``filmfriction analyze``, ``filmfriction calibrate``, ``filmfriction sfb
--out``).  It writes ``report.html`` (figures embedded as base64 PNG) and
``report.md`` (figures as ``report-*.png`` next to it) into the first run
directory, atomically.  Every number in the text comes from those files; a
step that failed is reported as failed, with its reason, and the rest of the
report is still written.

The document is built once as a list of sections of blocks (paragraph,
figure, table) and rendered twice, so the two files cannot disagree.  Every
section of the analysis is an observable
(:mod:`filmfriction.analysis.observables`: the slips, the energy, the sliding
state, the viscosity, the structure, the slip law ...) and gets its section
from one function, :func:`_observable_section`, in the observables' order: its
title, its lead paragraphs, its figures with their captions, its table and its
notes, or why it is not there.
"""
from __future__ import annotations

import base64
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from filmfriction.analysis.observables import Observable, registered as registered_observables
from filmfriction.analysis.trace import unit as _unit
from filmfriction.analysis.util import format_estimate as _pm, format_pm as _pm_plain
from filmfriction.analysis.util import format_value as _fmt
from filmfriction.analysis.util import png_bytes as _png, pyplot as _plt
from filmfriction.reduced_model.units import OMCTS

__all__ = ["build_report", "Section", "Figure", "Table", "PARAMETER_QUANTITIES"]

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
# document model
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Figure:
    """A PNG figure with a file stem and a caption."""

    name: str
    png: bytes
    caption: str


@dataclass(frozen=True)
class Table:
    """A table: header and rows of strings."""

    header: tuple
    rows: tuple


@dataclass
class Section:
    """A titled list of blocks (str paragraphs, Figure, Table)."""

    title: str
    blocks: list = field(default_factory=list)

    def p(self, text: str) -> None:
        self.blocks.append(str(text))

    def add(self, block) -> None:
        self.blocks.append(block)


def _source(units: str) -> str:
    """What made the trace, as the report names it: an MD run (LJ) or a measurement (SI)."""
    return "MD" if units == "lj" else "measured"


def _fixed(x, decimals: int) -> str:
    """``x`` with fixed decimals; "–" for a value the document has not (null)."""
    return "–" if x is None else f"{x:.{decimals}f}"


# ---------------------------------------------------------------------------
# figures
# ---------------------------------------------------------------------------
def fig_lambda_zeta(points: list) -> bytes:
    """Nakano–Maegawa's plane: (ζ, λ) of each contact with ±1 σ bars and the boundary λ_c(ζ)."""
    from filmfriction.reduced_model.maps import critical_lambda

    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    zz = np.geomspace(1e-3, 0.999, 200)
    ax.plot(zz, critical_lambda(zz), color="k", lw=1.2, label="λ_c(ζ): stick-slip above (Coulomb)")
    ax.axvline(1.0, color="k", ls=":", lw=1.0, label="ζ = 1: none for a viscous law")
    markers = iter("o^sDvP*X")
    for label, zeta, zeta_err, lam, lam_err in points:
        if not (math.isfinite(zeta) and math.isfinite(lam)) or zeta <= 0 or lam <= 0:
            continue
        ax.errorbar([zeta], [lam], xerr=[[min(zeta_err, 0.999 * zeta)], [zeta_err]]
                    if math.isfinite(zeta_err) else None,
                    yerr=[[min(lam_err, 0.999 * lam)], [lam_err]] if math.isfinite(lam_err) else None,
                    fmt=next(markers, "o"), ms=7, capsize=3, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("damping ratio ζ = (B + γM)/(2√(KM)) [1]")
    ax.set_ylabel("λ = (F_s − F_k)/(V√(KM)) [1]")
    # beside the axes: the contacts' points may fall anywhere in the plane
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, frameon=False)
    return _png(fig)


def fig_viscosity(cal: dict) -> bytes:
    """η_eff against γ̇, one point per run, with the rate law (a ``calibration.json`` document)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    pts = np.array(cal["rate_points"], float).reshape(-1, 3)
    err = np.where(np.isfinite(pts[:, 2]), pts[:, 2], 0.0)
    units = cal.get("units", "lj")
    ax.errorbar(pts[:, 0], pts[:, 1], yerr=err, fmt="o", color="tab:blue", capsize=3,
                label=f"{_source(units)} runs")
    law = cal.get("rate_law")
    if law is not None:
        # the fitted law as written, drawn over the runs' range (rendering, not fitting)
        g = np.geomspace(pts[:, 0].min() / 2, pts[:, 0].max() * 2, 50)
        ax.plot(g, law["prefactor"] * g ** law["exponent"], "-", color="tab:red",
                label=f"η ∝ γ̇^({law['exponent']:.2f} ± {_fixed(law['exponent_stderr'], 2)})")
    if len(pts) > 1:
        ax.set_xscale("log")
        ax.set_yscale("log")
    else:
        # one run: no law to draw; a log-log plane of one point says nothing more
        ax.set_title("one shear rate only: a sweep of drive velocities gives η_eff(γ̇)",
                     fontsize=8, color="0.3")
    ax.set_xlabel(f"shear rate γ̇ [{_unit(units, 'shear_rate')}]")
    ax.set_ylabel(f"η_eff [{_unit(units, 'viscosity')}]")
    ax.legend(fontsize=8)
    return _png(fig)


def fig_replay(run, trace: dict, start_time: float) -> bytes:
    """The run's spring force and the calibrated model's (``trace``: ``t``, ``spring_force``),
    labelled in the units of the analysis."""
    plt = _plt()
    tr = run.trace
    units = run.analysis.get("units", tr.units)
    fig, ax = plt.subplots(figsize=(9, 3.2))
    ax.plot(tr.time, tr.spring_force, lw=0.9, color="0.3", label=_source(units))
    ax.plot(trace["t"], trace["spring_force"], lw=1.2, color="tab:red", alpha=0.85,
            label="calibrated model")
    ax.axvline(start_time, color="tab:red", lw=0.6, ls=":")
    ax.set_xlabel(f"time [{_unit(units, 'time')}]")
    ax.set_ylabel(f"spring force [{_unit(units, 'force')}]")
    # above the axes, right-aligned: never over the traces (nor the offset text)
    ax.legend(fontsize=8, loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=2, frameon=False)
    return _png(fig)


def fig_replay_errors(errors: dict, source: str = "MD") -> bytes:
    """The model's relative error on the peak force, slip distance and period, with the
    ``source``'s (MD or measured) own standard error."""
    plt = _plt()
    names = ["peak_force", "slip_distance", "period"]
    vals = [errors[n]["rel_error"] for n in names]
    md_rel = [errors[n]["md_stderr"] / abs(errors[n]["md"])
              if errors[n]["md"] and math.isfinite(errors[n]["md_stderr"] or math.nan) else 0.0
              for n in names]
    fig, ax = plt.subplots(figsize=(5.5, 2.8))
    v = np.array([x if x is not None and math.isfinite(x) else 0.0 for x in vals]) * 100
    ticks = [n.replace("_", " ") for n in names]
    ax.bar(ticks, v, color=["tab:blue", "tab:orange", "tab:green"])
    ax.errorbar(ticks, np.zeros(3), yerr=np.array(md_rel) * 100, fmt="none", ecolor="k",
                capsize=4, label=f"± {source} standard error")
    bars = np.array(md_rel) * 100
    for i, x in enumerate(vals):
        # beyond the bar and the error bar drawn about zero, never over either
        span = max(float(np.max(np.abs(v))), float(np.max(bars)), 1.0)
        end = (max(v[i], bars[i]) + 0.03 * span if v[i] >= 0
               else min(v[i], -bars[i]) - 0.03 * span)
        ax.text(i, end, "n/a" if x is None or not math.isfinite(x) else f"{x:+.0%}",
                ha="center", va="bottom" if v[i] >= 0 else "top", fontsize=9)
    # room for the numbers over (under) the bars
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo - 0.12 * (hi - lo) * (v.min() < 0), hi + 0.12 * (hi - lo))
    ax.axhline(0, color="k", lw=0.6)
    ax.set_ylabel(f"(model − {source}) / {source} [%]")
    ax.legend(fontsize=7, loc="lower right", bbox_to_anchor=(1.0, 1.0), frameon=False)
    return _png(fig)


def _sfb_reference(check) -> dict:
    """Whose numbers the SFB check sets the model beside: Klein's, or a measured slip on
    one's own set-up (``sfb.json`` with ``setup`` and ``measured``, ``sfb --setup``)."""
    measured = check.doc.get("measured")
    if not measured:
        return {"column": "Klein", "whose": "Klein's", "title": "Klein, OMCTS",
                "curve": "Klein's parameters (η_eff = 27 Pa·s)", "calibrated": "MD-calibrated"}
    name = (check.doc.get("setup") or {}).get("name") or "your set-up"
    eta = measured.get("eta_eff")
    return {"column": "measured", "whose": "the measured value", "title": name,
            "curve": "the set-up's parameters" + (f" (η_eff = {eta:.3g} Pa·s)" if eta else ""),
            "calibrated": "calibrated"}


def fig_sfb(check) -> bytes:
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.5, 3.4))
    ref = _sfb_reference(check)
    labels = {"klein": ref["curve"], "bulk": "bulk viscosity", "md": f"{ref['calibrated']} film"}
    for key, run in check.slips.items():
        if key not in labels or run.t is None:
            continue
        t = np.asarray(run.t)
        end = run.slip_time if math.isfinite(run.slip_time) else t[-1]
        keep = t <= 1.5 * end
        ax.plot(t[keep] * 1e3, np.asarray(run.x)[keep] * 1e9, label=labels[key])
        if math.isfinite(run.slip_time):
            ax.plot(run.slip_time * 1e3, run.slip_distance * 1e9, "o", color="k", ms=4)
    ax.set_xscale("symlog", linthresh=1e-2)
    # slips from tens of nm (Klein) to tens of µm (an MD-calibrated film): a linear axis
    # would flatten the small ones onto zero
    ax.set_yscale("symlog", linthresh=1.0)
    ax.set_ylim(bottom=0)
    ax.set_xlabel("time since yield [ms]")
    ax.set_ylabel("slip x(t) [nm] (log above 1 nm)")
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("SFB-scale slips in the reduced model (● = s)", fontsize=9)
    return _png(fig)


# ---------------------------------------------------------------------------
# sections
# ---------------------------------------------------------------------------
def _attempt(failures: dict, name: str, fn, *args):
    try:
        return fn(*args)
    except Exception as exc:  # noqa: BLE001 -- a report records failures, it does not stop
        failures[name] = f"{type(exc).__name__}: {exc}"
        return None


def _scene_section(run) -> Section:
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


def _viscosity_section(cal, why_none: str, failures) -> Section:
    from filmfriction.reduced_model.klein import KLEIN

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
    png = _attempt(failures, "figure: viscosity", fig_viscosity, cal)
    law = cal.get("rate_law")
    if png:
        sec.add(Figure("viscosity", png, "Film η_eff against shear rate, one point per run"
                       + (" with the power-law fit." if law is not None else ".")))
    if law is not None:
        sec.p(f"Power law over {law['n']} runs: η_eff = {_fmt(law['prefactor'], 3)} · γ̇^({law['exponent']:.3f} ± "
              f"{_fixed(law['exponent_stderr'], 3)}) ({units.upper()} units); a thinning exponent n = {-law['exponent']:.3f}.")
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


def _calibration_section(cal, why_none: str, remarks: list, run, failures) -> Section:
    """The calibrated model from a ``calibration.json`` document (None: ``why_none`` is said)."""
    sec = Section("Calibrated reduced model")
    for r in remarks:
        sec.p(r)
    if cal is None:
        sec.p(why_none)
        return sec
    rc = cal["runs"][0]
    units = cal.get("units", "lj")
    source = _source(units)
    sec.p(f"Model: the {'MD' if units == 'lj' else 'driven'} wall's mass M, spring K, drive V and mount dashpot d in "
          "`filmfriction.reduced_model.SpringBlock`, with a Coulomb film (static F_s, kinetic F_k) plus a viscous "
          "film damping B while it slides, and a freeze force F_f where the film re-solidifies "
          "while the wall still moves. F_k, B and F_f are fitted jointly to the spring force of "
          "every analysed slip (each slip's yield and ramp level free), in the slips' own force "
          "and time scales; standard errors come from the fit's Jacobian and residuals, and a "
          "parameter at the bound of its range says so and has none (see "
          "`analysis/slipfit.py`).")
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
        sec.p(f"Contact ageing: dF_s/d ln(t_stick) = {_pm(ageing)}; "
              + ("more than two standard errors from zero" if sig else "not resolved (within two standard errors of zero)")
              + " (a correlation over the detected slips; small secondary slips with short sticks, if the "
                "detector counts them, push it up too).")
    for k, v in rc.get("failures", {}).items():
        sec.p(f"Not computed — {k}: {v}.")
    replay = rc.get("replay")
    if replay is not None:
        trace = cal.get("replay_trace")
        if trace is not None:
            png = _attempt(failures, "figure: replay", fig_replay, run, trace, replay["start_time"])
            if png:
                sec.add(Figure("replay", png, f"The calibrated model over the {source} trace; it "
                               f"starts at t = {_fmt(replay['start_time'])} {_unit(units, 'time')} "
                               f"(dotted line) from the {source} trace's state there."))
        else:
            sec.p("No replay trace beside `calibration.json` (`calibration_replay.csv`): the figure of the "
                  f"model over the {source} trace is left out; `filmfriction calibrate` writes it.")
        errs = replay["errors"]
        png = _attempt(failures, "figure: replay errors", fig_replay_errors, errs, source)
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


def _sfb_section(check, why_none: str, remarks: list, failures) -> Section:
    """The SFB table from ``sfb.json`` (:class:`~filmfriction.workflows.documents.SFBDocument`)."""
    from filmfriction.reduced_model.klein import BRAUN_TOSATTI_NOTE

    ref = _sfb_reference(check) if check is not None else None
    sec = Section(f"Comparison with the SFB experiment ({ref['title'] if ref else 'Klein, OMCTS'})")
    for r in remarks:
        sec.p(r)
    if check is None:
        sec.p(why_none)
        sec.p(BRAUN_TOSATTI_NOTE)
        return sec
    png = None
    if any(run.t is not None for run in check.slips.values()):
        png = _attempt(failures, "figure: sfb", fig_sfb, check)
    if png:
        sec.add(Figure("sfb", png, f"SFB-scale slips of the reduced model: {ref['curve']}, the same "
                                   f"with bulk viscosity, and (if calibrated) the {ref['calibrated']} "
                                   "film."))
    rows = []
    for r in check.rows:
        if r["source"] == "similarity":   # their own section
            continue
        unc = r.get("uncertainty")
        rows.append((r["name"], r["source"], _fmt(r["klein"], 3), _fmt(r["model"], 3),
                     "–" if r["ratio"] is None else f"{r['ratio']:.3g}",
                     "–" if not unc else f"{_fmt(unc[0], 2)} … {_fmt(unc[1], 2)}", r["units"], r["note"]))
    sec.add(Table(("quantity", "source", ref["column"], "model", "ratio", "model range", "units", "note"),
                  tuple(rows)))
    sec.p(BRAUN_TOSATTI_NOTE)
    sec.p(_sfb_reading(check))
    for n in check.notes:
        if n != BRAUN_TOSATTI_NOTE:
            sec.p(f"Assumption: {n}")
    return sec


def _observable_section(obs: Observable, run, failures) -> Section:
    """The report's section of one observable (``filmfriction.analysis.observables``):
    why it is not there, or its figure, its table and its notes."""
    sec = Section(obs.title)
    section = run.analysis.get(obs.key)
    if not section or not obs.shown(section):
        why = run.analysis.get("skipped", {}).get(obs.key)
        if why is None and obs.key in run.analysis:
            why = "nothing to show for this run"
        elif why is None and not (run.run_dir / "run.json").is_file():
            why = "a trace file has none: it is not an MD run"
        elif why is None:
            why = f"not in this `analysis.json` (rerun `filmfriction analyze {run.run_dir}`)"
        sec.p(f"{obs.absent}: {why}.")
        return sec
    what = obs.key.replace("_", " ")
    for text in _attempt(failures, f"lead: {what}", obs.lead, run) or ():
        sec.p(text)
    for name, png, caption in _attempt(failures, f"figure: {what}", obs.figures, run) or ():
        sec.add(Figure(name, png, caption))
    rows = _attempt(failures, f"table: {what}", obs.rows, section)
    if rows:
        sec.add(Table(tuple(obs.table_header), tuple((str(a), str(b)) for a, b in rows)))
    for text in _attempt(failures, f"notes: {what}", obs.notes, section) or ():
        sec.p(text)
    return sec


def _similarity_rows(run_dir: Path) -> list[dict]:
    """The ``similarity`` rows of ``run_dir/sfb.json`` (what the study wrote)."""
    doc = json.loads((Path(run_dir) / "sfb.json").read_text())
    rows = doc["rows"] if isinstance(doc, dict) else doc
    return [r for r in rows if r["source"] == "similarity"]


def _lambda_zeta_point(label: str, rows: list[dict]) -> tuple:
    """(label, ζ, ζ error, λ, λ error) of a run from its similarity rows: ζ = film + mount
    (an unresolved, non-positive film drag counts as 0), errors the rows' half-ranges."""
    by = {r["name"]: r for r in rows}

    def value(name):
        v = by.get(name, {}).get("model")
        return math.nan if v is None else float(v)

    def half_range(name):
        u = by.get(name, {}).get("uncertainty")
        return math.nan if not u else 0.5 * (u[1] - u[0])
    zf = value("film_damping_ratio")
    zeta = (zf if math.isfinite(zf) and zf > 0 else 0.0) + value("mount_damping_ratio")
    return (label, zeta, half_range("film_damping_ratio"), value("lambda"), half_range("lambda"))


def _similarity_section(check, run_dirs, failures, compare=()) -> Section:
    """Dimensionless numbers beside Klein's, and the λ–ζ map of every run given: the rows
    each run's ``sfb.json`` holds (Klein's point from his printed parameters)."""
    from filmfriction.reduced_model.similarity import klein_contact, similarity_numbers

    sec = Section("Similarity with the SFB experiment: dimensionless numbers")
    rows = [r for r in (check.rows if check is not None else []) if r["source"] == "similarity"]
    if rows:
        sec.p("An MD film slides ~10⁹ times faster than an SFB contact: what carries over is "
              "similarity. Each number of this run beside Klein's (model range: ±1 standard error).")
        sec.add(Table(("number", "Klein", "this run", "ratio", "run's range", "what it is"),
                      tuple((r["name"], _fmt(r["klein"], 3), _fmt(r["model"], 3),
                             "–" if r["ratio"] is None else f"{r['ratio']:.3g}",
                             "–" if not r.get("uncertainty") else
                             f"{_fmt(r['uncertainty'][0], 2)} … {_fmt(r['uncertainty'][1], 2)}",
                             r["note"]) for r in rows)))
    elif (Path(run_dirs[0]) / "run.json").is_file():
        sec.p("No similarity rows in `sfb.json` (make them with `filmfriction sfb --run RUN_DIR "
              "--out RUN_DIR/sfb.json`).")
    else:
        sec.p("Not an MD run: these numbers set an MD film beside Klein's contact. A measured "
              "trace is an experiment of its own: its slip is set beside the model in the SFB "
              "section above.")
    others = {}
    for d in list(run_dirs[1:]) + [Path(c) for c in compare]:
        try:
            others[Path(d)] = _similarity_rows(d)
        except (OSError, ValueError, KeyError, TypeError) as exc:
            failures.setdefault(f"similarity rows of {Path(d).name}", str(exc))
    for d in compare:
        mine = {r["name"]: r for r in others.get(Path(d), [])}
        if not mine:
            sec.p(f"`{Path(d).name}` (compared): no similarity rows in its `sfb.json` (a run "
                  "without slips has none); nothing of it to set beside this run.")
        elif mine and rows:
            sec.p(f"Beside it, `{d.name}` (its own `sfb.json`):")
            sec.add(Table(("number", "Klein", "this run", d.name, f"{d.name}'s range"),
                          tuple((r["name"], _fmt(r["klein"], 3), _fmt(r["model"], 3),
                                 _fmt(mine.get(r["name"], {}).get("model"), 3),
                                 "–" if not mine.get(r["name"], {}).get("uncertainty") else
                                 f"{_fmt(mine[r['name']]['uncertainty'][0], 2)} … "
                                 f"{_fmt(mine[r['name']]['uncertainty'][1], 2)}")
                                for r in rows)))

    def scene_of(d):
        try:
            return json.loads((Path(d) / "run.json").read_text()).get("scene", {}).get("name", "")
        except (OSError, ValueError, AttributeError):
            return ""
    n = similarity_numbers(klein_contact())
    zk = n["film_damping_ratio"].value + n["mount_damping_ratio"].value
    points = [("Klein (SFB, OMCTS)", zk, n["film_damping_ratio"].stderr, n["lambda"].value,
               n["lambda"].stderr)]
    for d, rs in [(Path(run_dirs[0]), rows)] + list(others.items()):
        if rs:
            points.append(_lambda_zeta_point(f"{scene_of(d) or d.name} (MD)", rs))
    png = _attempt(failures, "figure: lambda-zeta", fig_lambda_zeta, points)
    if png:
        sec.add(Figure("lambda_zeta", png,
                       "Nakano–Maegawa's plane for every run given and Klein's contact: λ against "
                       "the total damping ratio (film + mount; an unresolved film drag counts as 0). "
                       "Left of ζ = 1 stick-slip needs λ > λ_c(ζ); right of it, a purely viscous "
                       "film cannot stick again, so a stick-slip there (Klein's) says the film "
                       "re-solidifies. Run the Klein-similar scene with `filmfriction run "
                       "sfb-similar` and give its directory to `filmfriction report` beside this "
                       "one to place it here."))
    return sec


def _sfb_reading(check) -> str:
    """What the comparison supports, from the rows' own ratios."""
    def ratio(name, source):
        try:
            return check.row(name, source)["ratio"]
        except KeyError:
            return None
    ref = _sfb_reference(check)
    parts = []
    r = ratio("slip_time", "sfb-parameters")
    if r is not None and ref["column"] == "Klein":
        parts.append(f"With Klein's own parameters the reduced model gives his slip time to a ratio of "
                     f"{r:.2f} and viscous energy to {ratio('viscous_energy', 'sfb-parameters') or float('nan'):.2f}: "
                     "his Eq. (1) analysis is internally consistent.")
    elif r is not None:
        parts.append(f"With the set-up's parameters and the measured η_eff the reduced model gives the "
                     f"measured slip time to a ratio of {r:.2f}.")
    ri = ratio("inertial_slip_time", "sfb-parameters")
    if ri is not None:
        parts.append(f"With bulk viscosity the same slip would last {ri:.2g} × the observed time.")
    for name in ("yield_stress", "eta_eff", "slip_time"):
        rm = ratio(name, "md-calibrated")
        if rm is not None:
            parts.append(f"{ref['calibrated'][0].upper()}{ref['calibrated'][1:]} "
                         f"{name.replace('_', ' ')}: ratio {rm:.3g} to {ref['whose']}.")
    if ref["column"] != "Klein":
        pass                    # a measured slip: no MD path to read
    elif any(r_["source"] == "md-calibrated" for r_ in check.rows):
        parts.append("Ratios far from 1 on the MD path measure how far a 3-layer LJ film at MD shear rates, "
                     "carried through the unit mapping and the rate law, is from the SFB film; they do not "
                     "by themselves decide between Klein's high effective viscosity and Braun & Tosatti's "
                     "normal-viscosity reading.")
    else:
        parts.append("No MD-calibrated rows: the MD film is not compared with the experiment here.")
    return " ".join(parts)


def _cost_section(run) -> Section:
    sec = Section("Cost and provenance")
    rj = run.trace.run or {}
    if not rj:
        sec.p(f"No `run.json` in `{run.run_dir}`: not a run of `filmfriction run`, so no cost "
              "or provenance to report.")
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
# rendering: Jinja2 templates (workflows/templates/), HTML autoescaped
# ---------------------------------------------------------------------------
#: how a paragraph that says something is missing or failed begins (shown in red)
_FAILURE_OPENINGS = ("Not computed", "Calibration failed", "The SFB check failed", "No `")


def _inline_md(text: str) -> str:
    """Markdown text with its tags escaped outside code spans (a viewer would render them)."""
    import re
    parts = re.split(r"(`[^`]*`)", str(text))
    return "".join(p if p.startswith("`") and p.endswith("`") and len(p) > 1
                   else p.replace("<", "&lt;").replace(">", "&gt;") for p in parts)


def _inline_html(text) -> str:
    """HTML of a paragraph: the text escaped, then its ``**bold**`` and ```code``` marked up."""
    import re

    from markupsafe import Markup, escape
    out = str(escape(str(text)))
    out = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", out)
    out = re.sub(r"`(.+?)`", r"<code>\1</code>", out)
    return Markup(out)


def _md_cell(c: str) -> str:
    return _inline_md(str(c)).replace("|", "\\|").replace("\n", " ")


def _templates(*, html: bool):
    """The report's Jinja2 environment: the package's templates, HTML autoescaped."""
    from jinja2 import Environment, PackageLoader, StrictUndefined

    env = Environment(loader=PackageLoader("filmfriction.workflows", "templates"),
                      autoescape=html, undefined=StrictUndefined, trim_blocks=True,
                      lstrip_blocks=True, keep_trailing_newline=True)
    env.filters.update(inline=_inline_html, md=_inline_md, cell=_md_cell,
                       base64=lambda data: base64.b64encode(data).decode("ascii"))
    env.tests.update(figure=lambda b: isinstance(b, Figure), table=lambda b: isinstance(b, Table),
                     failure=lambda b: isinstance(b, str) and b.startswith(_FAILURE_OPENINGS))
    return env


def _render_html(title: str, intro: list, sections: list) -> str:
    return _templates(html=True).get_template("report.html.j2").render(
        title=title, intro=intro, sections=sections)


def _render_md(title: str, intro: list, sections: list, stem: str) -> tuple[str, dict]:
    """The Markdown twin and its figure files (name -> PNG bytes)."""
    text = _templates(html=False).get_template("report.md.j2").render(
        title=title, intro=intro, sections=sections, stem=stem)
    files = {f"{stem}-{b.name}.png": b.png for sec in sections for b in sec.blocks
             if isinstance(b, Figure)}
    return text, files


from filmfriction.analysis.util import write_atomic as _write_atomic  # noqa: E402


# ---------------------------------------------------------------------------
# entry point
# ---------------------------------------------------------------------------
def _split_sweeps(paths: list) -> tuple[list, list]:
    """Run directories, and sweeps (directories with ``aggregate.json``).

    A sweep contributes its stick-slip runs (its ``calibration_runs``, else all
    its runs) to the calibration, after the run directories given directly.
    """
    from filmfriction.workflows.sweep_aggregate import load_aggregate

    runs, sweeps, seen = [], [], set()

    def add(d):
        # each run once, however it is written (r1, ./r1/, /abs/r1, or within a sweep)
        if Path(d).resolve() not in seen:
            seen.add(Path(d).resolve())
            runs.append(d)
    for p in paths:
        if (p / "aggregate.json").exists():
            agg = load_aggregate(p)
            sweeps.append(agg)
            for d in agg.calibration_runs or agg.run_dirs:
                add(d)
        else:
            add(p)
    return runs, sweeps


def _sweep_section(sweeps) -> Section:
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


def build_report(run_dirs, out=None, *, failures=None, log=None, compare=()) -> Path:
    """Write ``report.html`` and ``report.md`` for one or several runs.

    The report renders what is in the main run's directory: ``analysis.json``
    (with ``analysis_cycles.csv``), ``calibration.json`` (with
    ``calibration_replay.csv``) and ``sfb.json`` (with ``sfb_slips.csv``).
    It computes none of them; a file that is not there is said in the report
    with the command that writes it (and passed to ``log``).

    Parameters
    ----------
    run_dirs : path-like or list of path-like
        Run directories; the first is the main run.  A sweep directory (with
        ``aggregate.json``) adds a sweep section and its stick-slip runs.
    out : path-like, optional
        HTML file to write (default ``<first run>/report.html``); the Markdown
        twin and its PNG figures go next to it (same stem).
    failures : dict, optional
        Step → reason for earlier steps that failed (recorded in the report;
        a failed ``calibration`` or ``sfb`` step is reported as failed, not read).
    log : callable, optional
        Called with one line per input that is missing and the command that makes it.
    compare : list of path-like
        Other analysed runs set beside the main one in the similarity section (their
        ``sfb.json`` similarity rows and their points on the λ–ζ map).

    Returns
    -------
    Path
        The HTML file.

    Raises
    ------
    ValueError
        No run directory, or the main run has no analysis (``filmfriction analyze``).
    """
    from filmfriction.analysis.rundata import load_run
    from filmfriction.workflows.documents import read_report_inputs

    if isinstance(run_dirs, (str, os.PathLike)):
        run_dirs = [run_dirs]
    given = [Path(d) for d in run_dirs]
    run_dirs, sweeps = _split_sweeps(given)
    if out is None and sweeps and given[0] == sweeps[0].sweep_dir:
        out = sweeps[0].sweep_dir / "report.html"   # a sweep's report lives with the sweep
    if not run_dirs:
        raise ValueError("no run directory given (a sweep without completed runs?)")
    failures = dict(failures or {})
    run = load_run(run_dirs[0], analyse=False)
    inputs = read_report_inputs(run.run_dir, run_dirs, given, failures)
    for what, command in inputs.missing:
        if log is not None:
            log(f"missing or out of date: {what}; make it with: {command}")
    out = Path(out) if out is not None else run.run_dir / "report.html"
    name = run.run_dir.resolve().name           # "." has no name of its own
    scene = (run.trace.run or {}).get("scene", {}).get("name", run.trace.path.name)
    title = f"filmfriction report — {scene} ({name})"
    units = run.analysis.get("units", "lj")
    intro = [f"Runs: {', '.join('`' + str(d) + '`' for d in run_dirs)}. " + (
        "MD quantities are in LJ units (σ, ε, m, τ) unless marked SI; SI values go through "
        f"`filmfriction.reduced_model.units` ({OMCTS.name})." if units == "lj" else
        "The trace's quantities are in SI units (N, m, s, J, Pa·s), as its analysis records; "
        "nothing is converted.")]
    observed = [_observable_section(obs, run, failures) for obs in registered_observables()]
    sections = [_scene_section(run), *observed,
                _viscosity_section(inputs.calibration, inputs.why_no_calibration, failures),
                _calibration_section(inputs.calibration, inputs.why_no_calibration,
                                     inputs.calibration_remarks, run, failures),
                _sfb_section(inputs.sfb, inputs.why_no_sfb, inputs.sfb_remarks, failures),
                _similarity_section(inputs.sfb, run_dirs, failures,
                                    compare=[Path(c) for c in compare]),
                _cost_section(run)]
    if sweeps:
        sections.insert(1 + len(observed), _sweep_section(sweeps))
    if inputs.missing:
        sec = Section("Inputs the report did not find")
        sec.p("The report renders the files the study writes and computes none of them. These commands "
              "write what is missing or out of date:")
        sec.add(Table(("file", "command"), tuple((w, f"`{c}`") for w, c in inputs.missing)))
        sections.append(sec)
    if failures:
        sec = Section("Steps that failed")
        sec.add(Table(("step", "reason"), tuple((k, v) for k, v in failures.items())))
        sections.append(sec)
    _write_atomic(out, _render_html(title, intro, sections))
    md_text, files = _render_md(title, intro, sections, out.stem)
    for name, data in files.items():
        _write_atomic(out.parent / name, data)
    _write_atomic(out.with_suffix(".md"), md_text)
    return out
