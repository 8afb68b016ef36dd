"""The report's sections that set the run beside Klein's experiment: the SFB check
(:func:`sfb_section`, from ``sfb.json``) and the similarity numbers with the
Bingham number first (:func:`similarity_section`)."""
from __future__ import annotations

import json
import math
from pathlib import Path

from filmfriction.analysis.files.util import format_value as _fmt
from filmfriction.md_inputs.contract import RUN_FILE, SFB_FILE

from ..rundir import reference
from .document import Figure, Section, Table, link
from .plots import fig_lambda_zeta, fig_sfb, measured_slips, sfb_reference
from .sections import attempt

__all__ = ["sfb_section", "similarity_section"]


def sfb_section(check, why_none: str, remarks: list, failures, run=None) -> Section:
    """The SFB table from ``sfb.json`` (:class:`~filmfriction.workflows.rundir.SFBDocument`)."""
    from filmfriction.reduced_model.sfb.klein import BRAUN_TOSATTI_NOTE

    ref = sfb_reference(check) if check is not None else None
    sec = Section(f"Comparison with the SFB experiment ({ref['title'] if ref else 'Klein, OMCTS'})")
    for r in remarks:
        sec.p(r)
    if check is None:
        sec.p(why_none)
        sec.p(BRAUN_TOSATTI_NOTE)
        return sec
    from .overview import APPENDIX_TITLE, far_extrapolated
    far = far_extrapolated(check)
    png = None
    measured = [] if run is None else attempt(failures, "measured slips", measured_slips, run) or []
    if any(s.t is not None for s in check.slips.values()):
        png = attempt(failures, "figure: sfb", lambda: fig_sfb(check, measured, carried_over=not far))
    if png:
        sec.add(Figure("sfb", png, f"SFB-scale slips of the reduced model: {ref['curve']}, the same "
                                   "with bulk viscosity"
                       + ("" if far else f" and (if calibrated) the {ref['calibrated']} film")
                       + (f", over the {len(measured)} measured slips (grey, wall displacement "
                          "since y, up to s)" if measured else
                          f", and {ref['whose']} slip time and distance (★)")
                       + ". Each model curve ends at its s (●); a dashed one did not reach s "
                         "and stops at the figure's window."))
    rows = []
    for r in check.rows:
        if r["source"] == "similarity":   # their own section
            continue
        if far and r["source"] == "md-calibrated":   # not a prediction: the appendix
            continue
        unc = r.get("uncertainty")
        rows.append((r["name"], r["source"], _fmt(reference(r), 3), _fmt(r["model"], 3),
                     "–" if r["ratio"] is None else f"{r['ratio']:.3g}",
                     "–" if not unc else f"{_fmt(unc[0], 2)} … {_fmt(unc[1], 2)}", r["units"], r["note"]))
    sec.add(Table(("quantity", "source", ref["column"], "model", "ratio", "model range", "units", "note"),
                  tuple(rows)))
    if far:
        sec.p(f"The {ref['calibrated']} rows carry the film's law too many decades of shear "
              f"rate to be predictions: they are in the {link(APPENDIX_TITLE, 'appendix')}, "
              "without ratios or intervals.")
    sec.p(BRAUN_TOSATTI_NOTE)
    sec.p(_sfb_reading(check, far))
    for n in check.notes:
        if n != BRAUN_TOSATTI_NOTE:
            sec.p(f"Assumption: {n}")
    return sec


def _similarity_rows(run_dir: Path) -> list[dict]:
    """The ``similarity`` rows of ``run_dir/sfb.json`` (what the study wrote)."""
    from ..rundir import read_json

    doc = read_json(Path(run_dir) / SFB_FILE, "sfb")
    if doc is None:
        raise ValueError(f"{Path(run_dir) / SFB_FILE}: no such file")
    rows = doc["rows"] if isinstance(doc, dict) else doc
    return [r for r in rows if isinstance(r, dict) and r.get("source") == "similarity"]


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


def _klein_cell(row) -> str:
    """Klein's number, with † and the range of a derived one."""
    cell = _fmt(row["klein"], 3)
    rng = row.get("klein_range")
    if row.get("klein_source") == "derived" and rng:
        cell += f" † ({_fmt(rng[0], 2)} … {_fmt(rng[1], 2)})"
    return cell


def _bingham_reading(rows) -> str:
    """What the Bingham number of the run says about the slip law's reach (no more)."""
    by = {r["name"]: r for r in rows}
    bi = by.get("bingham_number")
    if not bi or bi.get("model") is None or bi.get("klein") is None:
        return ""
    lo, hi = bi.get("uncertainty") or (bi["model"], bi["model"])
    text = (f"The number Klein and Braun & Tosatti disagree on is the Bingham number "
            f"η_eff/η_bulk: Klein's Eq. (1) needs {_fmt(bi['klein'], 3)} × the damping of a "
            f"no-slip film of bulk viscosity, this run's {_fmt(bi['model'], 3)} "
            f"({_fmt(lo, 2)} … {_fmt(hi, 2)}). ")
    if hi < 10:
        text += ("Here Eq. (1) asks for less than ten times the damping a bulk film would "
                 "give, so a fit of Eq. (1) cannot by itself show a viscous film, and the run "
                 "does not reproduce the regime of Klein's film: a verdict on his film needs "
                 "Bi ≫ 1. What the run's slips say of the film's own law is the slip law's "
                 "reading (its own section), with its power: on driven slips at the MD's noise "
                 "that fit (the slips' mean) calls Klein's viscous slips `viscous` in 96 % of "
                 "replicas of 30 slips and no Coulomb, rate-and-state or weakening slips "
                 "`viscous` (docs/results/slip-law.md). How Bi moves with the slider's mass at "
                 "this film, how far 2 cores take it and what Klein's Bi would cost on a cluster "
                 "are measured by the slider-mass ladder (`filmfriction ladder plan`, `run`, "
                 "`collect`; its results page is docs/results/mass-ladder.md).")
    else:
        below = ("though far below Klein's" if bi["model"] < 0.1 * bi["klein"] else
                 "near Klein's")
        text += (f"Bi ≫ 1 here, {below}: the slip law's verdict (its own section) says "
                 "whether the large damping is a viscous film's, within the power its controls "
                 "give it at the run's scale. Measured on the six-layer film at K = 8 "
                 "(docs/results/mass-ladder.md): one run of 7–10 slips has no power to resolve "
                 "a viscous share (its controls: purely viscous slips `viscous` in 11 % of "
                 "replicas), so the verdict is not established by a run. The slips of many "
                 "runs pooled (`filmfriction slip-law`, errors by the jackknife over the "
                 "runs), the walls' registry force (≈ 20 ε/σ at their lattice's period) "
                 "fitted beside the law as that command does: at M = 10³ and 10⁴ (Bi ≈ 10 "
                 "and 18; 16 and 12 runs) the rule reads `mixed`, a kinetic force of two "
                 "thirds to three quarters of the film's mean force beside a viscous term 2.4 "
                 "and 4.1 times a bulk no-slip film's, so Klein's purely viscous film is "
                 "rejected there; at M = 10⁵ (Bi 32–57 over thirty seeds; twenty runs pooled "
                 "with the registry) it reads `mixed` too, "
                 "each term at 3–4 σ (ten runs read `inconclusive`): a "
                 "kinetic force about half the film's mean force beside a viscous term ≈ 14 "
                 "times a bulk film's, and a viscous force that lags the slip by ≈ 26 τ (over "
                 "whole rungs absent at M = 10³ and 2×10³, shorter and indicated at 2.5×10³, "
                 "resolved at 3×10³ and 10⁴ against controls of their scales: no relaxation "
                 "time of the film; at 3×10³, 10⁴ and 10⁵ it reads as one lag in slide of "
                 "≈ 0.25 σ, or one share of the slip's own time; split at each rung's median "
                 "slip velocity, the slower half of the slips lags longer than the faster, "
                 "indicated, not established), with a yield-loop step left (4 σ) that this "
                 "lag and the walls' registry force, weaker while a slip speeds up than "
                 "while it slows, make most of in controls (within the noise, not "
                 "established). Neither reading of the "
                 "dispute is established at the highest Bi reached: the film's force is a kinetic friction beside a viscous term "
                 "two to twenty times a bulk film's, growing with the slider's mass. "
                 "At lighter sliders on the same film (Bi 3–18) the "
                 "film force is sub-linear in the slip velocity (n 0.19–0.37 from 0.34 to "
                 "0.042 σ/τ); the decelerating branch's larger n at the lightest slider is "
                 "partly the inertia of film that moves with the wall (controls with that "
                 "mass), so it is not a trend of the film's friction. What reaching "
                 "Klein's Bi would cost: docs/results/mass-ladder.md "
                 "(\"Going further\").")
    return text


def similarity_section(check, run_dirs, failures, compare=(), user_point=None) -> Section:
    """Dimensionless numbers beside Klein's, and the λ–ζ map of every run given: the rows
    each run's ``sfb.json`` holds (Klein's point from his printed parameters)."""
    from filmfriction.reduced_model.sfb.similarity import klein_contact, similarity_numbers

    sec = Section("Similarity with the SFB experiment: dimensionless numbers")
    rows = [r for r in (check.rows if check is not None else []) if r["source"] == "similarity"]
    if rows:
        sec.p("An MD film slides ~10⁹ times faster than an SFB contact: what carries over is "
              "similarity. Each number of this run beside Klein's (model range: ±1 standard "
              "error; Klein's marked † where it needs an input he did not print, with the range "
              "those inputs allow).")
        sec.add(Table(("number", "Klein", "this run", "ratio", "run's range", "what it is"),
                      tuple((r["name"], _klein_cell(r), _fmt(r["model"], 3),
                             "–" if r["ratio"] is None else f"{r['ratio']:.3g}",
                             "–" if not r.get("uncertainty") else
                             f"{_fmt(r['uncertainty'][0], 2)} … {_fmt(r['uncertainty'][1], 2)}",
                             r["note"]) for r in rows)))
        reading = _bingham_reading(rows)
        if reading:
            sec.p(reading)
    elif (Path(run_dirs[0]) / RUN_FILE).is_file():
        sec.p("No similarity rows in `sfb.json` (make them with `filmfriction sfb --run RUN_DIR "
              "--out RUN_DIR/sfb.json`).")
    else:
        sec.p("Not an MD run: the table of numbers sets an MD film beside Klein's contact. A "
              "measured trace is an experiment of its own: its slip is set beside the model in "
              "the SFB section above"
              + (f", and its contact is placed on the λ–ζ map below beside Klein's: λ = "
                 f"{_fmt(user_point[3], 3)} ± {_fmt(user_point[4], 2)}, ζ = "
                 f"{_fmt(user_point[1], 3)} (film ± {_fmt(user_point[2], 2)}, from the "
                 "set-up's K, M, A, D, V and the measured F_s, F_b and η_eff)."
                 if user_point is not None else "."))
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
            return json.loads((Path(d) / RUN_FILE).read_text()).get("scene", {}).get("name", "")
        except (OSError, ValueError, AttributeError):
            return ""
    n = similarity_numbers(klein_contact())
    zk = n["film_damping_ratio"].value + n["mount_damping_ratio"].value
    points = [("Klein (SFB, OMCTS)", zk, n["film_damping_ratio"].stderr, n["lambda"].value,
               n["lambda"].stderr)]
    if user_point is not None:
        points.append(user_point)
    for d, rs in [(Path(run_dirs[0]), rows)] + list(others.items()):
        if rs:
            points.append(_lambda_zeta_point(f"{scene_of(d) or d.name} (MD)", rs))
    png = attempt(failures, "figure: lambda-zeta", fig_lambda_zeta, points)
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


def _sfb_reading(check, far: bool = False) -> str:
    """What the comparison supports, from the rows' own ratios."""
    def ratio(name, source):
        try:
            return check.row(name, source)["ratio"]
        except KeyError:
            return None
    ref = sfb_reference(check)
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
        rm = None if far else ratio(name, "md-calibrated")
        if rm is not None:
            parts.append(f"{ref['calibrated'][0].upper()}{ref['calibrated'][1:]} "
                         f"{name.replace('_', ' ')}: ratio {rm:.3g} to {ref['whose']}.")
    if ref["column"] != "Klein":
        pass                    # a measured slip: no MD path to read
    elif far:
        parts.append("The MD film's law, carried across many decades of shear rate, gives no "
                     "SFB-scale prediction here (appendix).")
    elif any(r_["source"] == "md-calibrated" for r_ in check.rows):
        parts.append("Ratios far from 1 on the MD path measure how far a 3-layer LJ film at MD shear rates, "
                     "carried through the unit mapping and the rate law, is from the SFB film; they do not "
                     "by themselves decide between Klein's high effective viscosity and Braun & Tosatti's "
                     "normal-viscosity reading.")
    else:
        parts.append("No MD-calibrated rows: the MD film is not compared with the experiment here.")
    return " ".join(parts)
