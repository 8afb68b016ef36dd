"""The report's opening and closing sections over what the others show: the summary
(the study's questions and answers, :mod:`.summary`), the consistency of the report's
own numbers, and the appendix of the SFB-scale carry-over that is too far extrapolated
for the main table."""
from __future__ import annotations

import json
import math
from pathlib import Path

from filmfriction.analysis.files.util import format_value as _fmt
from filmfriction.md_inputs.contract import RUN_FILE

from ..rundir import reference
from .document import Section, Table, link
from .summary import (MAX_DECADES, STATUSES, answers, consistency_checks,
                      extrapolated_decades)

__all__ = ["summary_section", "consistency_section", "appendix_section", "far_extrapolated",
           "user_contact_point", "CONSISTENCY_TITLE", "APPENDIX_TITLE"]

SUMMARY_TITLE = "Summary: the study's questions and answers"
CONSISTENCY_TITLE = "Consistency of the report's own numbers"
APPENDIX_TITLE = "Appendix: SFB-scale carry-over"


def far_extrapolated(sfb) -> bool:
    """Whether the SFB check's calibrated rows carry the law farther than
    :data:`~.summary.MAX_DECADES` beyond its calibrated rates."""
    d = None if sfb is None else extrapolated_decades(sfb.rows)
    return d is not None and d > MAX_DECADES


def user_contact_point(sfb, analysis: dict) -> tuple | None:
    """(label, ζ, ζ error, λ, λ error) of the user's own contact (``sfb --setup
    --measured``) on Nakano–Maegawa's plane, from the set-up and the measured slip that
    ``sfb.json`` records and the analysis' F_b; None for Klein's check."""
    from filmfriction.reduced_model.sfb.similarity import SlidingContact, similarity_numbers

    if sfb is None or not sfb.doc.get("measured") or not sfb.doc.get("setup"):
        return None
    setup, m = sfb.doc["setup"], sfb.doc["measured"]
    fb = ((analysis.get("slips") or {}).get("backward_force") or {})
    if fb.get("mean") is None:
        return None

    def val(k):
        return float(setup[k]["value"])

    def err(k):
        return float(setup[k].get("error") or 0.0)
    area, d = val("contact_area"), val("film_thickness")
    damping = m["eta_eff"] * area / d
    damping_err = damping * math.sqrt((m.get("eta_eff_err", 0.0) / m["eta_eff"]) ** 2
                                      + (err("contact_area") / area) ** 2
                                      + (err("film_thickness") / d) ** 2)
    c = SlidingContact(spring_constant=val("spring_constant"), mass=val("mass"),
                       drive_velocity=val("drive_velocity"), static_force=m["static_force"],
                       restick_force=float(fb["mean"]), slip_distance=m["slip_distance"],
                       film_damping=damping, film_damping_err=damping_err,
                       static_force_err=m.get("static_force_err", 0.0),
                       restick_force_err=float(fb.get("stderr") or 0.0),
                       mass_err=err("mass"), spring_constant_err=err("spring_constant"))
    n = similarity_numbers(c)
    zeta = n["film_damping_ratio"].value + n["mount_damping_ratio"].value
    return (f"{setup.get('name') or 'your set-up'} (measured)", zeta,
            n["film_damping_ratio"].stderr, n["lambda"].value, n["lambda"].stderr)


def _label(run_dir: Path) -> str:
    try:
        scene = json.loads((Path(run_dir) / RUN_FILE).read_text()).get("scene", {}).get("name")
    except (OSError, ValueError, AttributeError):
        scene = None
    name = Path(run_dir).resolve().name
    return f"{scene} (`{name}`)" if scene else f"`{name}`"


def _documents(run_dir: Path):
    """(analysis, calibration, sfb) of a compared run as its directory holds them."""
    from filmfriction.workflows.rundir import read_calibration, read_json, read_sfb
    from filmfriction.md_inputs.contract import SFB_FILE

    analysis = read_json(Path(run_dir) / "analysis.json")
    try:
        cal = read_calibration(Path(run_dir) / "calibration.json")
    except ValueError:
        cal = None
    try:
        sfb = read_sfb(Path(run_dir) / SFB_FILE)
    except ValueError:
        sfb = None
    return analysis, cal, sfb


def summary_section(run, inputs, checks, compared, left_out, failures, titles=()) -> Section:
    """The opening section: each question answered for the main run (and beside it every
    compared run), with its status, the rule of that status and a link to its section."""
    sec = Section(SUMMARY_TITLE)
    point = user_contact_point(inputs.sfb, run.analysis)
    main = answers(run.analysis, inputs.calibration, inputs.sfb, checks, point)
    columns = [(_label(run.run_dir), main)]
    for d in compared:
        try:
            a, cal, sfb = _documents(d)
        except (OSError, ValueError) as exc:
            failures.setdefault(f"summary of {Path(d).name}", str(exc))
            continue
        if a is None:
            sec.p(f"{_label(d)}: no `analysis.json`, not in the summary "
                  f"(`filmfriction analyze {d}`).")
            continue
        columns.append((_label(d), answers(a, cal, sfb, consistency_checks(a, cal),
                                           user_contact_point(sfb, a))))
    gone = {t for t, _ in left_out}

    def where(a):
        # the section's title as the report writes it (the SFB one names the set-up)
        title = next((t for t in titles if t.startswith(a.section)), None)
        if title is None:
            return "left out (inputs absent)" if a.section in gone else "–"
        return link(title, "→")
    counts = {s: sum(x.status == s for x in main) for s in STATUSES}
    bad = [c for c in checks if c.status == "disagree"]
    sec.p("What this study found, each answer with its uncertainty (± one standard error "
          "unless a range is given), from the numbers the sections below show; nothing here "
          "is computed anew. " + ", ".join(f"{n} {s}" for s, n in counts.items() if n)
          + f" for {columns[0][0]}. The report's numbers checked against each other: "
          + (f"**{len(bad)} of {len(checks)} disagree**" if bad else
             f"all {len(checks)} agree" if checks else "nothing to check")
          + f" ({link(CONSISTENCY_TITLE, 'consistency')}).")
    if len(columns) == 1:
        sec.add(Table(("question", "answer", "status", "section"),
                      tuple((a.question, a.answer, f"**{a.status}**", where(a))
                            for a in main)))
    else:
        header = ["question"]
        for label, _ in columns:
            header += [f"{label}", "status"]
        rows = []
        for i, a in enumerate(main):
            row = [a.question]
            for _, ans in columns:
                row += [ans[i].answer, f"**{ans[i].status}**"]
            rows.append(tuple(row) + (where(a),))
        sec.add(Table(tuple(header) + ("section",), tuple(rows)))
    sec.p("How a status is decided (established / inconclusive / not comparable):")
    sec.add(Table(("question", "rule"), tuple((a.question, a.rule) for a in main)))
    if left_out:
        sec.p("Left out, their inputs absent: " + " ".join(
            f"**{t}**: {why}" for t, why in left_out))
    return sec


def consistency_section(checks) -> Section:
    """The report's numbers against each other: what disagrees and what it means."""
    sec = Section(CONSISTENCY_TITLE)
    if not checks:
        sec.p("No numbers to set against each other: the run has no calibration and no "
              "slip law.")
        return sec
    bad = [c for c in checks if c.status == "disagree"]
    sec.p("Each check sets two numbers of this report against each other: the calibration's "
          "friction law against the slip law's, the η_eff estimators pairwise (more than 2 "
          "standard errors of their difference apart, or negative), a fitted effect against "
          "the quantity it modifies (ageing per e-fold of stick time and F_k against F_s; a "
          "co-moving mass that must not be negative), and the film heat against the "
          "thermostat's. "
          + (f"**{len(bad)} of {len(checks)} disagree**; each says what it means. A summary "
             "answer that rests on a disagreeing pair (η_eff, the friction law, the heat) is "
             "not marked established."
             if bad else f"All {len(checks)} agree."))
    rows = sorted(checks, key=lambda c: c.status != "disagree")
    sec.add(Table(("check", "outcome", "numbers", "what a disagreement means"),
                  tuple((c.name, f"**{c.status}**" if c.status == "disagree" else c.status,
                         c.detail, c.reading or "–") for c in rows)))
    return sec


def appendix_section(sfb) -> Section | None:
    """The calibrated SFB rows carried farther than MAX_DECADES: no ratio, no interval."""
    if not far_extrapolated(sfb):
        return None
    decades = extrapolated_decades(sfb.rows)
    sec = Section(APPENDIX_TITLE)
    sec.p(f"The calibrated film's law is carried {decades:.1f} decades of shear rate below "
          "the rates it was calibrated on to reach the SFB's slip rate. The ±1 σ intervals "
          "of the SFB check propagate the calibration's statistical errors only, not the "
          "extrapolation's own uncertainty (the law's form over those decades), which nothing "
          "in the study measures. These numbers are therefore not predictions: they are "
          "listed here to one significant figure, with no ratio and no interval, and left out "
          f"of the main SFB table (rule: at most {MAX_DECADES:g} decade of extrapolation).")
    rows = [(r["name"], _fmt(reference(r), 2), "–" if r["model"] is None else f"~{r['model']:.0e}",
             r["units"], r["note"]) for r in sfb.rows if r["source"] == "md-calibrated"]
    sec.add(Table(("quantity", "SFB", "carried-over model (order of magnitude)", "units",
                   "note"), tuple(rows)))
    return sec

