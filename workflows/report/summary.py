"""The report's opening: the study's questions, each answered from the numbers the study
already wrote (``analysis.json``, ``calibration.json``, ``sfb.json``), with its
uncertainty, a one-word status and the section it comes from; and the consistency check
of those numbers against each other.

Nothing here computes physics. Every status follows from a rule stated beside it:

* **established**: the number is resolved by the rule given (an interval that excludes
  a value, a verdict with its power, a prediction within its tolerance);
* **inconclusive**: the inputs are there, the rule is not met;
* **not comparable**: the numbers exist but do not describe the same regime or scale
  as what they are set beside (a film far from Klein's Bingham number, a law carried
  many decades beyond the rates it was calibrated on).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

from filmfriction.analysis.trace_figure import scaled_unit
from filmfriction.analysis.files.util import format_value as _fmt

from ..rundir import reference

__all__ = ["Answer", "Check", "answers", "consistency_checks", "extrapolated_decades",
           "STATUSES", "MAX_DECADES", "REPLAY_TOLERANCE", "BINGHAM_REGIME"]

#: the one-word statuses of an answer
STATUSES = ("established", "inconclusive", "not comparable")
#: a law carried more decades of shear rate than this beyond its calibrated rates is
#: not a prediction: its rows leave the main SFB table (appendix)
MAX_DECADES = 1.0
#: a replayed quantity agrees when |model − trace| ≤ max(2 standard errors, this share)
REPLAY_TOLERANCE = 0.05
#: Klein's reading needs Bi = η_eff/η_bulk ≫ 1: a run's Bi interval wholly below this is
#: not in his regime; wholly above it, it is
BINGHAM_REGIME = 10.0


@dataclass(frozen=True)
class Answer:
    """One question of the study and its answer for one run."""

    question: str
    answer: str
    status: str
    rule: str
    section: str        # title of the report's section the answer comes from


@dataclass(frozen=True)
class Check:
    """One consistency check of the report's numbers: ``agree`` or ``disagree``."""

    name: str
    status: str
    detail: str
    reading: str = ""   # what a disagreement means, and which number to trust


# ---------------------------------------------------------------------------
# formatting: SI prefixes for SI numbers, LJ as written
# ---------------------------------------------------------------------------
def estimate(mean, stderr, units: str, quantity: str, digits: int = 3) -> str:
    """'value ± stderr unit' with an SI prefix for SI force, length, time and energy."""
    if mean is None or not math.isfinite(float(mean)):
        return "–"
    factor, label = scaled_unit([mean], units, quantity)
    label = label if label != "1" else ""
    v = f"{float(mean) * factor:.{digits}g}"
    if stderr is None or not math.isfinite(float(stderr)) or stderr == 0:
        return f"{v} {label}".strip()
    return f"{v} ± {float(stderr) * factor:.2g} {label}".strip()


def _entry(d, units, quantity, digits=3) -> str:
    d = d or {}
    return estimate(d.get("mean", d.get("value")), d.get("stderr"), units, quantity, digits)


def _cv(d) -> float:
    d = d or {}
    m, s = d.get("mean"), d.get("std")
    return math.nan if not m or s is None else abs(float(s) / float(m))


def _num(x) -> float:
    return math.nan if x is None else float(x)


# ---------------------------------------------------------------------------
# the questions
# ---------------------------------------------------------------------------
SECTIONS = {"slips": "Stick-slip trace", "energy": "Energy partition",
            "eta": "Effective viscosity η_eff(γ̇)", "calibration": "Calibrated reduced model",
            "sfb": "Comparison with the SFB experiment",
            "similarity": "Similarity with the SFB experiment: dimensionless numbers",
            "slip_law": "Klein's slip equation on the slips: viscous, kinetic or neither resolved?"}


def _stick_slip(a: dict) -> Answer:
    units = a.get("units", "lj")
    regime = a.get("regime") or "not classified"
    s = a.get("slips") or {}
    n = (s.get("static_force") or {}).get("n") or 0
    q = "Does the film stick-slip, and how regularly?"
    rule = ("established: the regime's criterion (analysis.json regime_criterion) met over "
            "≥ 3 analysed slips, or a smooth slide; inconclusive: fewer slips or regime "
            "unresolved")
    if regime == "smooth":
        return Answer(q, "smooth sliding: fewer than 2 slips", "established", rule,
                      SECTIONS["slips"])
    text = (f"{regime}: {s.get('count', 0)} slips ({n} analysed); F_s = "
            f"{_entry(s.get('static_force'), units, 'force')}, period "
            f"{_entry(s.get('period'), units, 'time')}; CV(F_s) = {_fmt(_cv(s.get('static_force')), 2)}, "
            f"CV(period) = {_fmt(_cv(s.get('period')), 2)}")
    change = a.get("film_state_change")
    if change:
        text += f"; {change.get('note', 'analysed up to a change of the film state')}"
    ok = regime in ("stick-slip", "irregular") and n >= 3
    return Answer(q, text, "established" if ok else "inconclusive", rule, SECTIONS["slips"])


def _energy(a: dict) -> Answer:
    units = a.get("units", "lj")
    e = a.get("energy") or {}
    q = "Where does a slip's energy go?"
    rule = ("established: the viscous fraction's standard error is known over ≥ 3 slips"
            + (" and every independent heat check (film heat vs the thermostat's) agrees at 99 %"
               if units == "lj" else " (a measured trace has no independent heat measurement: "
               "the film heat is the equation of motion's)"))
    vf = e.get("viscous_fraction") or {}
    if vf.get("mean") is None:
        return Answer(q, "not measured: " + str((a.get("skipped") or {}).get("energy",
                      "no energy partition")), "inconclusive", rule, SECTIONS["energy"])
    checks = e.get("heat_check") or {}
    text = (f"film heat {_entry(e.get('film_heat'), units, 'energy')} per slip; viscous "
            f"fraction film heat/(film heat + ringing) = {_fmt(vf['mean'], 3)} ± "
            f"{_fmt(vf.get('stderr'), 2)}")
    if checks:
        text += "; heat check " + ", ".join(f"{k}: {c['status']}" for k, c in checks.items())
    ok = (vf.get("stderr") is not None and (vf.get("n") or 0) >= 3
          and all(c.get("status") == "agree" for c in checks.values()))
    return Answer(q, text, "established" if ok else "inconclusive", rule, SECTIONS["energy"])


_ESTIMATOR = {"calibration": "the calibration's joint slip fit (B·D/A)",
              "slips": "Klein's Eq. 1 per slip", "slip_law": "the slip law",
              "steady": "steady sliding", "internal": "the velocity profile"}


def _viscosity(a: dict, cal: dict | None, checks: list) -> Answer:
    units = a.get("units", "lj")
    q = "What is the film's effective viscosity, and by which estimator?"
    rule = ("established: the calibration resolves its film damping (B more than 2 standard "
            "errors above 0) and no two η_eff estimators disagree by more than 2 standard "
            "errors (consistency section)")
    choice = ((cal or {}).get("runs") or [{}])[0].get("eta_eff_choice") if cal else None
    if not choice:
        fs = ((a.get("viscosity") or {}).get("from_slip") or {}).get("eta_eff")
        text = ("no calibration to choose one; Klein's Eq. 1 per slip gives "
                + _entry(fs, units, "viscosity") if fs else "not measured")
        return Answer(q, text, "inconclusive", rule, SECTIONS["eta"])
    eta_disagree = any(c.status == "disagree" and c.name.startswith("η_eff") for c in checks)
    if choice.get("status") == "resolved":
        p = choice["primary"]
        text = (f"{estimate(p['value'], p.get('stderr'), units, 'viscosity')} from "
                f"{_ESTIMATOR.get(choice.get('estimator'), choice.get('estimator'))}")
        if units == "lj":
            from filmfriction.reduced_model.units import OMCTS
            text += f" (= {OMCTS.to_si(p['value'], 'viscosity'):.3g} Pa·s with OMCTS' units)"
        if eta_disagree:
            text += "; other estimators disagree with it by more than 2 σ (consistency)"
        return Answer(q, text, "inconclusive" if eta_disagree else "established", rule,
                      SECTIONS["eta"])
    vals = [c["eta_eff"] for c in choice.get("cross_checks") or [] if c.get("eta_eff")]
    spread = ", ".join(f"{estimate(v['value'], v.get('stderr'), units, 'viscosity')}"
                       for v in vals)
    return Answer(q, f"not resolved: {choice.get('reason')}" + (f"; estimates {spread}"
                  if spread else ""), "inconclusive", rule, SECTIONS["eta"])


def _replay(cal: dict | None, units: str) -> Answer:
    q = "How well does the calibrated model replay the trace?"
    rule = (f"established: the two predictions (slip distance, period) within max(2 standard "
            f"errors of the trace, {REPLAY_TOLERANCE:.0%}); the peak force is an input")
    rc = ((cal or {}).get("runs") or [{}])[0]
    replay = rc.get("replay") if cal else None
    if not replay:
        return Answer(q, "no replay (no calibration)" if cal is None else "no replay: "
                      + str((rc.get("failures") or {}).get("replay", "not computed")),
                      "inconclusive", rule, SECTIONS["calibration"])
    errs = replay["errors"]
    parts, ok = [], True
    for name in ("slip_distance", "period"):
        e = errs.get(name) or {}
        rel, md, se = _num(e.get("rel_error")), _num(e.get("md")), _num(e.get("md_stderr"))
        tol = max(2 * abs(se / md) if md and math.isfinite(se) else 0.0, REPLAY_TOLERANCE)
        good = math.isfinite(rel) and abs(rel) <= tol
        ok &= good
        parts.append(f"{name.replace('_', ' ')} {rel:+.1%} (tolerance ±{tol:.1%})"
                     if math.isfinite(rel) else f"{name.replace('_', ' ')} –")
    return Answer(q, "; ".join(parts), "established" if ok else "inconclusive", rule,
                  SECTIONS["calibration"])


def extrapolated_decades(rows: list) -> float | None:
    """How many decades of shear rate the calibrated law is carried beyond its rates for
    the SFB rows (the ``md-calibrated`` ``eta_eff`` row's note, which
    :mod:`filmfriction.reduced_model.sfb.md_rows` writes); None when there is none."""
    for r in rows:
        if r.get("source") == "md-calibrated" and r.get("name") == "eta_eff":
            m = re.search(r"(-?\d+(?:\.\d+)?) decades below", r.get("note", ""))
            return abs(float(m.group(1))) if m else math.inf
    return None


def _sfb_prediction(cal: dict | None, sfb, measured: bool) -> Answer:
    q = "What does the calibrated model predict at the SFB scale?"
    whose = "the measured" if measured else "Klein's"
    rule = (f"established: {whose} slip time inside the calibrated model's ±1 σ range, with the "
            f"law used within {MAX_DECADES:g} decade of its calibrated rates; not comparable: "
            "carried farther (appendix)")
    rows = [] if sfb is None else sfb.rows
    decades = extrapolated_decades(rows)
    if sfb is None:
        return Answer(q, "no SFB check", "inconclusive", rule, SECTIONS["sfb"])
    if decades is None:
        why = ("calibration.json hands no calibration to the SFB check"
               + (": " + "; ".join(f"{k}: {v}" for k, v in (cal.get("failures") or {}).items())
                  if cal and cal.get("failures") else ""))
        return Answer(q, why, "inconclusive", rule, SECTIONS["sfb"])
    row = next((r for r in rows if r["source"] == "md-calibrated" and r["name"] == "slip_time"),
               None)
    if decades > MAX_DECADES:
        return Answer(q, f"the law is carried {decades:.1f} decades of shear rate beyond its "
                      "calibrated rates: no prediction (the run's report lists them in an appendix)",
                      "not comparable", rule, "Appendix: SFB-scale carry-over")
    if row is None or row.get("model") is None:
        return Answer(q, "no calibrated slip time", "inconclusive", rule, SECTIONS["sfb"])
    unc = row.get("uncertainty")
    ref = reference(row)
    inside = bool(unc and ref is not None and unc[0] <= ref <= unc[1])
    text = (f"slip time {estimate(row['model'], None, 'si', 'time')} "
            + (f"({estimate(unc[0], None, 'si', 'time')} … {estimate(unc[1], None, 'si', 'time')})"
               if unc else "") + f" beside {whose} {estimate(ref, None, 'si', 'time')}; "
            f"{decades:.1f} decades of extrapolation")
    return Answer(q, text, "established" if inside else "inconclusive", rule, SECTIONS["sfb"])


def _beside_klein(sfb, measured: bool, user_point=None) -> Answer:
    rule = (f"Bingham number Bi = η_eff/η_bulk first: established when the run's ±1 σ range of "
            f"Bi lies above {BINGHAM_REGIME:g} (Klein's regime, Bi ≫ 1); not comparable when it "
            f"lies below; inconclusive when it straddles {BINGHAM_REGIME:g}")
    q = "Where does the run stand beside Klein's contact (Bi first)?"
    if measured:
        q = "Does the reduced model with the set-up's own parameters give the measured slip?"
        rule = ("established: the measured slip time inside the ±1 σ range of the model with "
                "the set-up's K, M, A, D and the measured η_eff")
        if sfb is None:
            return Answer(q, "no SFB check", "inconclusive", rule, SECTIONS["sfb"])
        try:
            row = sfb.row("slip_time", "sfb-parameters")
        except KeyError:
            return Answer(q, "no slip-time row", "inconclusive", rule, SECTIONS["sfb"])
        unc, ref = row.get("uncertainty"), reference(row)
        inside = bool(unc and ref is not None and unc[0] <= ref <= unc[1])
        text = (f"slip time {estimate(row['model'], None, 'si', 'time')} "
                + (f"({estimate(unc[0], None, 'si', 'time')} … "
                   f"{estimate(unc[1], None, 'si', 'time')})" if unc else "")
                + f" beside the measured {estimate(ref, None, 'si', 'time')}")
        if user_point is not None:
            text += (f"; on the λ–ζ map the contact sits at λ = {_fmt(user_point[3], 3)}, "
                     f"ζ = {_fmt(user_point[1], 3)}")
        return Answer(q, text, "established" if inside else "inconclusive", rule,
                      SECTIONS["sfb"])
    rows = {r["name"]: r for r in ([] if sfb is None else sfb.rows)
            if r["source"] == "similarity"}
    bi = rows.get("bingham_number")
    if not bi or bi.get("model") is None:
        return Answer(q, "no similarity rows (sfb.json)", "inconclusive", rule,
                      SECTIONS["similarity"])
    lo, hi = bi.get("uncertainty") or (bi["model"], bi["model"])
    text = (f"Bi = {_fmt(bi['model'], 3)} ({_fmt(lo, 2)} … {_fmt(hi, 2)}) beside Klein's "
            f"{_fmt(bi['klein'], 3)}")
    for name, label in (("lambda", "λ"), ("film_damping_ratio", "ζ_film")):
        r = rows.get(name)
        if r and r.get("model") is not None:
            text += f"; {label} = {_fmt(r['model'], 3)} (Klein {_fmt(r['klein'], 3)})"
    status = ("established" if lo > BINGHAM_REGIME else
              "not comparable" if hi < BINGHAM_REGIME else "inconclusive")
    return Answer(q, text, status, rule, SECTIONS["similarity"])


def _slip_law(a: dict, checks: list, sfb=None) -> Answer:
    units = a.get("units", "lj")
    q = "Is this film's sliding friction viscous (Klein's Eq. 1) or kinetic (Braun & Tosatti)?"
    rule = ("the slip law's own verdict, reported as a reading: never established, because the "
            "driven fit (the slips' mean) does not reach its positive control's 95 % where the "
            "film's random force moves the wall (Klein's viscous slips `viscous` in 36 of 40 at the "
            "MD's noise, the rest `mixed`: docs/results/slip-law.md); "
            "with the smallest B the run resolves at 95 % power and the calibration's friction "
            "law beside it")
    law = a.get("slip_law")
    if not law:
        why = (a.get("skipped") or {}).get("slip_law", "not in analysis.json")
        return Answer(q, f"not tested: {why}", "inconclusive", rule, SECTIONS["slip_law"])
    verdict = law.get("verdict", "?")
    text = (f"verdict **{verdict}**: F_k = {_entry(law.get('kinetic_force'), units, 'force')}, "
            f"B = {_entry(law.get('damping'), units, 'damping')}; power: B ≥ "
            f"{_entry(law.get('detectable_damping'), units, 'damping')} resolved at 95 %")
    clash = any(c.status == "disagree" and c.name.startswith("friction law") for c in checks)
    if clash:
        text += "; the calibration's friction law disagrees (consistency)"
    text += _reach(sfb)
    text += ("; the per-slip fit is biased where the film's random force moves the wall: on "
             "driven slips at the MD's noise Klein's viscous controls come out `mixed`, with a "
             "loop (docs/results/slip-law.md), so a loop or a `mixed` verdict on a driven run "
             "is no evidence of a yield or of a kinetic term")
    return Answer(q, text, "inconclusive", rule, SECTIONS["slip_law"])


def _reach(sfb) -> str:
    """What the slip law's verdict says about Klein's film: nothing unless Bi ≫ 1."""
    bi = next((r for r in ([] if sfb is None else sfb.rows)
               if r["name"] == "bingham_number" and r["source"] == "similarity"), None)
    if not bi or bi.get("model") is None:
        return ("; about this film only: its Bingham number is not computed, so whether it "
                "bears on Klein's film (which needs Bi ≫ 1) is not known")
    lo, _ = bi.get("uncertainty") or (bi["model"], bi["model"])
    if lo > BINGHAM_REGIME:
        return ""
    return (f"; about this film only: at Bi = {_fmt(bi['model'], 3)} (Klein's "
            f"{_fmt(bi['klein'], 3)}) it does not decide between Klein's reading and Braun & "
            f"Tosatti's, which needs Bi ≫ 1")


def answers(analysis: dict, calibration: dict | None, sfb, checks=(), user_point=None
            ) -> list[Answer]:
    """The study's answers for one run, from its documents (``sfb``: an
    :class:`~filmfriction.workflows.rundir.SFBDocument` or None)."""
    units = analysis.get("units", "lj")
    measured = bool(sfb is not None and sfb.doc.get("measured"))
    out = [_stick_slip(analysis), _energy(analysis), _viscosity(analysis, calibration, list(checks)),
           _replay(calibration, units), _sfb_prediction(calibration, sfb, measured),
           _beside_klein(sfb, measured, user_point), _slip_law(analysis, list(checks), sfb)]
    return out


# ---------------------------------------------------------------------------
# consistency: the report's numbers against each other
# ---------------------------------------------------------------------------
def _z(a, b) -> float:
    """Difference of two estimates (value, stderr) in standard errors of the difference."""
    (va, sa), (vb, sb) = a, b
    s = math.hypot(sa if sa and math.isfinite(sa) else 0.0, sb if sb and math.isfinite(sb) else 0.0)
    return math.nan if s == 0 else (va - vb) / s


def consistency_checks(analysis: dict, calibration: dict | None) -> list[Check]:
    """Checks of the report's numbers against each other; each says ``agree`` or
    ``disagree`` and, for a disagreement, what it means."""
    units = analysis.get("units", "lj")
    out: list[Check] = []
    rc = ((calibration or {}).get("runs") or [{}])[0] if calibration else {}
    law = analysis.get("slip_law") or {}
    # 1. calibration's friction law against the slip law's
    fl = (rc.get("eta_eff_choice") or {}).get("friction_law") or {}
    if fl:
        fk = rc.get("kinetic_force") or {}
        detail = (f"calibration: {fl.get('calibration')} (F_k = "
                  f"{estimate(fk.get('value'), fk.get('stderr'), units, 'force')}"
                  f"{' at its bound' if fk.get('at_bound') else ''}); slip law: "
                  f"{fl.get('slip_law')} (verdict {fl.get('slip_law_verdict', law.get('verdict'))})")
        out.append(Check("friction law: calibration vs slip law",
                         "agree" if fl.get("agree") else "disagree", detail,
                         "" if fl.get("agree") else (fl.get("note") or "")))
    # 2. the η_eff estimators, pairwise, and any negative one
    choice = rc.get("eta_eff_choice") or {}
    ests = {}
    if choice.get("primary"):
        ests[choice.get("estimator") or "primary"] = choice["primary"]
    for c in choice.get("cross_checks") or []:
        if c.get("eta_eff"):
            ests.setdefault(c["estimator"], c["eta_eff"])
    names = list(ests)
    for i, a_ in enumerate(names):
        for b_ in names[i + 1:]:
            ea, eb = ests[a_], ests[b_]
            if ea.get("at_bound") or eb.get("at_bound"):
                continue
            z = _z((ea["value"], ea.get("stderr")), (eb["value"], eb.get("stderr")))
            if not math.isfinite(z):
                continue
            out.append(Check(f"η_eff: {a_} vs {b_}", "agree" if abs(z) <= 2 else "disagree",
                             f"{estimate(ea['value'], ea.get('stderr'), units, 'viscosity')} vs "
                             f"{estimate(eb['value'], eb.get('stderr'), units, 'viscosity')}: "
                             f"{z:+.1f} standard errors (limit 2)",
                             "" if abs(z) <= 2 else
                             "the estimators rest on different assumptions (see the η_eff "
                             "section): at most one of them describes the film"))
    for name, e in ests.items():
        if e.get("value") is not None and e["value"] < 0:
            se = _num(e.get("stderr"))
            beyond = math.isfinite(se) and e["value"] + 2 * se < 0
            out.append(Check(f"η_eff ({name}) is positive", "disagree",
                             estimate(e["value"], e.get("stderr"), units, "viscosity"),
                             "negative beyond 2 standard errors: unphysical, the estimator's "
                             "assumptions fail for this film" if beyond else
                             "negative but within 2 standard errors of 0: the estimator "
                             "resolves no drag; its value is not a viscosity"))
    unph = ((analysis.get("viscosity") or {}).get("from_slip") or {}).get("unphysical")
    out.append(Check("per-slip η_eff (Klein's Eq. 1) all positive",
                     "disagree" if unph else "agree",
                     (unph or {}).get("note", "every analysed slip gives η_eff > 0")
                     if unph else "every analysed slip gives η_eff ≥ 0",
                     "a slip with η_eff < 0 has a fitted B below the mount's dashpot: the film's "
                     "drag is not resolved slip by slip, only (if at all) in the mean"
                     if unph else ""))
    # 3. a fitted effect larger than the quantity it modifies
    fs = (analysis.get("slips") or {}).get("static_force") or {}
    fs_mean = _num(fs.get("mean"))
    ageing = rc.get("ageing") or {}
    if ageing.get("value") is not None and math.isfinite(fs_mean):
        big = abs(ageing["value"]) > abs(fs_mean)
        out.append(Check("ageing dF_s/d ln t_stick below F_s", "disagree" if big else "agree",
                         f"{estimate(ageing['value'], ageing.get('stderr'), units, 'force')} per "
                         f"e-fold of stick time vs F_s = {estimate(fs_mean, fs.get('stderr'), units, 'force')}",
                         "one e-fold of stick time would change F_s by more than F_s itself: "
                         "an artefact of the correlation over few slips (or of small secondary "
                         "slips counted by the detector), not contact ageing" if big else ""))
    for label, e in (("calibration's F_k", rc.get("kinetic_force")),
                     ("slip law's F_k", law.get("kinetic_force"))):
        e = e or {}
        v = _num(e.get("value", e.get("mean")))
        if math.isfinite(v) and math.isfinite(fs_mean):
            big = v > fs_mean
            out.append(Check(f"{label} below F_s", "disagree" if big else "agree",
                             f"{estimate(v, e.get('stderr'), units, 'force')} vs F_s = "
                             f"{estimate(fs_mean, fs.get('stderr'), units, 'force')}",
                             "a kinetic friction above the static one cannot give stick-slip "
                             "in the model: the fit trades F_k against B" if big else ""))
    cm = law.get("comoving_mass") or {}
    if cm.get("mean") is not None:
        neg = cm["mean"] < 0
        out.append(Check("slip law's co-moving mass not negative", "disagree" if neg else "agree",
                         estimate(cm["mean"], cm.get("stderr"), units, "mass"),
                         "a negative mass is unphysical: the whole-slip fit trades the co-moving "
                         "mass against the damping, and neither is resolved" if neg else ""))
    # 4. the independent heat checks
    for key, c in ((analysis.get("energy") or {}).get("heat_check") or {}).items():
        out.append(Check(f"film heat vs thermostat's ({key})",
                         "agree" if c.get("status") == "agree" else "disagree",
                         c.get("message", ""),
                         "" if c.get("status") == "agree" else
                         "the mechanics' film heat and the thermostat's disagree: one of the "
                         "two misses a term"))
    return out
