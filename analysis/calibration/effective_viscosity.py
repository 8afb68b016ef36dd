"""The run's one effective viscosity η_eff, and the other estimates as cross-checks.

A run can give η_eff several ways, each resting on its own assumption:

``calibration``
    B·D/A from the joint Coulomb + viscous fit of the slips' spring force
    (:func:`~filmfriction.analysis.calibration.slipfit.fit_slips`): the film's drag beyond a
    rate-independent part F_k, the viscous term of Klein's Eq. 1 with the
    kinetic force his equation leaves out.  Assumes the slips follow that law.
``slips``
    Klein's Eq. 1 fitted to each slip alone (``analysis.json``
    ``viscosity.from_slip``, mount dashpot removed): all sliding friction viscous
    (F_k = 0).  Where the film has a rate-independent part it is read as
    viscosity, and η_eff comes out higher.
``slip_law``
    B·D/A of F_film = F_k + B·v fitted to the film force against the wall's velocity
    sample by sample (``analysis.json`` ``slip_law``): no slip shape assumed, but
    the film force is the spring's less the wall's inertia from a differentiated
    velocity, which is noisy.
``steady``
    (F/A)/(V/D) of steady sliding (mount dashpot removed), for a ``smooth`` run.
``internal``
    The steady stress over the film's own shear rate from the velocity profile.

:func:`choose` names the primary one: for a ``smooth`` run the steady value; for
stick-slip the calibration's, when its B is resolved (off its bound and more than
2 standard errors from zero, by the fit's error and by the slips' scatter).  Otherwise the primary is "not resolved" and says
why.  Every other available estimate is listed as a cross-check with the assumption
it rests on and its difference from the primary in standard errors.  The
calibration's friction law (F_k, B resolved or not) is set beside the slip law's
verdict, with the evidence each rests on.

Example
-------
>>> doc = {"regime": "smooth", "viscosity": {"steady": {"eta_eff": {"mean": 5.0, "stderr": 0.5,
...        "units": "ετ/σ³"}}}}
>>> c = choose(doc)
>>> c.estimator, c.primary.value, c.status
('steady', 5.0, 'resolved')
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from .estimators import Estimate
from ..files.trace import UNITS
from ..files.util import finite_or_none

__all__ = ["CrossCheck", "ViscosityChoice", "choose", "choice_note", "RESOLVED_SIGMAS", "RESTS_ON"]

#: A damping counts as resolved when it exceeds this many standard errors.
RESOLVED_SIGMAS = 2.0

_TERMS = {"mixed": "both a kinetic part and a film drag", "viscous": "a film drag only",
          "kinetic": "a kinetic part only", "neither": "neither term"}

#: What each estimator assumes (one line, for people).
RESTS_ON = {
    "calibration": "the joint Coulomb + viscous fit of the slips' spring force: B beyond a "
                   "rate-independent F_k",
    "slips": "Klein's Eq. 1 on each slip alone: all sliding friction viscous (F_k = 0)",
    "slip_law": "F_film = F_k + B·v against the wall's velocity sample by sample (the film "
                "force from a differentiated velocity)",
    "steady": "steady sliding: (F − d V)/A over V/D",
    "internal": "the steady stress over the film's own shear rate from the velocity profile",
}


@dataclass(frozen=True)
class CrossCheck:
    """One estimate of η_eff that is not the primary.

    Attributes
    ----------
    estimator : str
        A key of :data:`RESTS_ON`.
    eta_eff : Estimate
    rests_on : str
    difference : str
        How it compares with the primary (in standard errors), and why it may differ.
    unphysical : str
        Non-empty when the estimate or some of its parts are unphysical (a negative
        η_eff), saying which.
    """

    estimator: str
    eta_eff: Estimate
    rests_on: str
    difference: str
    unphysical: str = ""

    def as_dict(self) -> dict:
        return {"estimator": self.estimator, "eta_eff": self.eta_eff.as_dict(),
                "rests_on": self.rests_on, "difference": self.difference,
                "unphysical": self.unphysical}


@dataclass(frozen=True)
class ViscosityChoice:
    """The run's primary η_eff, why, and the cross-checks.

    Attributes
    ----------
    status : str
        ``resolved`` (a primary) or ``not resolved``.
    estimator : str or None
        The primary's key in :data:`RESTS_ON`.
    primary : Estimate or None
    reason : str
        Why this estimator (or why none).
    cross_checks : tuple of CrossCheck
    friction_law : dict
        The calibration's reading of the slips beside the slip law's verdict, each
        with the evidence it rests on, and whether they agree (empty without both).
    """

    status: str
    estimator: str | None
    primary: Estimate | None
    reason: str
    cross_checks: tuple = ()
    friction_law: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {"status": self.status, "estimator": self.estimator,
                "primary": None if self.primary is None else self.primary.as_dict(),
                "reason": self.reason, "cross_checks": [c.as_dict() for c in self.cross_checks],
                "friction_law": dict(self.friction_law)}


def _entry(e: dict | None, method: str) -> Estimate | None:
    """An ``analysis.json`` value ``{"mean", "stderr", "units"}`` as an Estimate."""
    if not e or e.get("mean") is None:
        return None
    err = e.get("stderr")
    return Estimate(float(e["mean"]), math.nan if err is None else float(err), e["units"], method)


def _resolved(e: Estimate | None) -> bool:
    return (e is not None and not e.at_bound and math.isfinite(e.stderr)
            and e.value > RESOLVED_SIGMAS * e.stderr)


def _sigmas(a: Estimate, b: Estimate) -> float:
    err = math.hypot(a.stderr if math.isfinite(a.stderr) else 0.0,
                     b.stderr if math.isfinite(b.stderr) else 0.0)
    return (a.value - b.value) / err if err > 0 else math.nan


def _reading(kinetic: Estimate | None, damping: Estimate | None,
             damping_scatter: float = math.nan, *,
             significance: tuple[float | None, float | None] = (None, None)) -> str:
    """Which terms of F_k + B·v a fit resolves (more than 2 standard errors, off a bound):
    ``mixed``, ``viscous`` (B only), ``kinetic`` (F_k only) or ``neither``.
    ``significance`` gives a fit's own signed significance of F_k and B in standard
    errors where it has one (the slip law's, which allows for the few slips' t
    distribution): it then decides, so that the reading is the one the fit states."""
    k_sig, b_sig = significance
    if k_sig is not None:
        k_ok = kinetic is not None and k_sig > RESOLVED_SIGMAS
    else:
        k_ok = kinetic is not None and not kinetic.at_bound and math.isfinite(kinetic.stderr) \
            and kinetic.value > RESOLVED_SIGMAS * kinetic.stderr
    if b_sig is not None:
        b_ok = damping is not None and b_sig > RESOLVED_SIGMAS
    else:
        b_ok = _resolved(damping) and not (math.isfinite(damping_scatter) and damping is not None
                                           and damping.value <= RESOLVED_SIGMAS * damping_scatter)
    return {(True, True): "mixed", (False, True): "viscous", (True, False): "kinetic",
            (False, False): "neither"}[(k_ok, b_ok)]


def _law_significance(law: dict) -> tuple[float | None, float | None]:
    """The slip law's own significance of F_k and B (``sigmas`` of the branch its verdict
    is from), None where analysis.json does not carry it."""
    branch = (law.get("branches") or {}).get(law.get("verdict_from") or "") or {}

    def sig(key):
        value = (branch.get(key) or {}).get("sigmas")
        return float(value) if isinstance(value, (int, float)) and math.isfinite(value) else None
    return sig("kinetic_force"), sig("damping")


def choose(analysis: dict, *, kinetic_force: Estimate | None = None,
           film_damping: Estimate | None = None, damping_scatter: float = math.nan,
           thickness: float = math.nan,
           area: float = math.nan, mount_damping: float = 0.0,
           units: str = "lj") -> ViscosityChoice:
    """Name the primary η_eff of a run and list the others as cross-checks.

    Parameters
    ----------
    analysis : dict
        The run's ``analysis.json``.
    kinetic_force, film_damping : Estimate, optional
        The calibration's joint slip fit (:class:`~filmfriction.analysis.calibration.slipfit.SlipLawFit`).
    damping_scatter : float
        B's standard error from the slips' scatter (the fit's jackknife); where
        given, B must be resolved by it too.
    thickness, area : float
        D and A for η = B·D/A.
    mount_damping : float
        d, subtracted from a steady run's force (d V).
    units : str
        ``lj`` or ``si``, the run's.
    """
    regime = analysis.get("regime")
    visc = analysis.get("viscosity") or {}
    law = analysis.get("slip_law") or {}
    label = UNITS[units]["viscosity"]
    estimates: dict[str, Estimate] = {}
    unphysical: dict[str, str] = {}
    if film_damping is not None and area and math.isfinite(thickness) and area > 0:
        estimates["calibration"] = Estimate(
            film_damping.value * thickness / area,
            film_damping.stderr * thickness / area if math.isfinite(film_damping.stderr)
            else math.nan, label, "B D / A from the joint slip fit (D = mean gap)",
            at_bound=film_damping.at_bound, limit=film_damping.limit * thickness / area)
    steady = (visc.get("steady") or {}).get("eta_eff")
    if steady and steady.get("mean") is not None:
        gap = ((visc.get("steady") or {}).get("thickness") or {}).get("mean") or thickness
        ok = area and math.isfinite(area) and gap and math.isfinite(gap)
        shift = mount_damping * gap / area if ok else 0.0
        e = _entry(steady, "")
        estimates["steady"] = Estimate(e.value - shift, e.stderr, e.units,
                                       f"steady sliding: ((F - d V)/A)/(V/D), mount d = "
                                       f"{mount_damping:g} subtracted")
    slips = visc.get("from_slip") or {}
    e = _entry(slips.get("eta_eff"), "Klein's Eq. 1 fitted to each slip, mean ± stderr "
                                     "(mount dashpot removed)")
    if e is not None:
        estimates["slips"] = e
        bad = (slips.get("unphysical") or {}).get("slips") or []
        if bad:
            unphysical["slips"] = (f"slip{'s' if len(bad) > 1 else ''} "
                                   f"{', '.join(map(str, bad))}: η_eff < 0 (fitted B below the "
                                   "mount's dashpot), kept in the mean")
    e = _entry(law.get("eta_from_damping"), "B·D/A of the slip law's F_film = F_k + B·v")
    if e is not None:
        estimates["slip_law"] = e
    e = _entry((visc.get("internal") or {}).get("eta_eff"),
               "steady stress over the profile's internal shear rate")
    if e is not None:
        estimates["internal"] = e
    for name, est in estimates.items():
        if est.value < 0 and name not in unphysical:
            unphysical[name] = "η_eff < 0: unphysical, the film's drag is not resolved"

    # the primary
    cal = estimates.get("calibration")
    if regime == "smooth" and "steady" in estimates:
        primary, reason = "steady", "smooth sliding: the steady stress over V/D"
    elif cal is not None and _resolved(film_damping) and (
            not (math.isfinite(damping_scatter) and damping_scatter > 0)
            or film_damping.value > RESOLVED_SIGMAS * damping_scatter):
        primary = "calibration"
        reason = (f"stick-slip with the calibration's film damping resolved: B = "
                  f"{film_damping.value:.4g} ± {film_damping.stderr:.2g} {film_damping.units}, "
                  f"{film_damping.value / film_damping.stderr:.1f} standard errors from 0"
                  + (f" ({film_damping.value / damping_scatter:.1f} over the slips' scatter)"
                     if math.isfinite(damping_scatter) and damping_scatter > 0 else ""))
    else:
        primary = None
        if regime == "smooth":
            reason = "smooth sliding without a steady η_eff (area, drive velocity or gap missing)"
        elif film_damping is None:
            reason = "no calibrated slip fit (run `filmfriction calibrate`)" \
                if regime == "stick-slip" else f"regime {regime}: no slip fit, no steady sliding"
        elif film_damping.at_bound:
            reason = ("the calibration's film damping B is at its bound 0: the slips' shape "
                      "resolves no film drag beyond the mount's dashpot"
                      + (f" (B below {film_damping.limit:.3g} {film_damping.units} at 95 %, "
                         "one-sided)" if math.isfinite(film_damping.limit) else ""))
        elif not _resolved(film_damping):
            reason = (f"the calibration's film damping B = {film_damping.value:.4g} ± "
                      f"{film_damping.stderr:.2g} {film_damping.units} is within "
                      f"{RESOLVED_SIGMAS:g} standard errors of 0")
        else:
            reason = (f"the calibration's film damping B = {film_damping.value:.4g} ± "
                      f"{film_damping.stderr:.2g} {film_damping.units} is "
                      f"{film_damping.value / film_damping.stderr:.1f} standard errors from 0 "
                      f"by the fit's error but {film_damping.value / damping_scatter:.1f} by "
                      f"the slips' scatter (± {damping_scatter:.2g}, leave one slip out)")
    main = estimates.get(primary) if primary else None
    # without a primary the others are set beside the calibration's (else the slips')
    reference = next(((n, estimates[n]) for n in ("calibration", "slips") if n in estimates),
                     None)
    if main is None and len(estimates) > 1:
        finite = [(n, e) for n, e in estimates.items() if math.isfinite(e.stderr)]
        spread = max((abs(_sigmas(a, b)) for i, (_, a) in enumerate(finite)
                      for _, b in finite[i + 1:]), default=math.nan)
        if math.isfinite(spread):
            reason += (f"; the {len(estimates)} estimates differ by at most {spread:.1f} "
                       "standard errors of their difference")
    checks = []
    for name, est in estimates.items():
        if name == primary:
            continue
        if main is not None:
            z = _sigmas(est, main)
            diff = (f"{z:+.1f} standard errors from the primary" if math.isfinite(z)
                    else "no standard error to compare with")
            if name == "slips" and kinetic_force is not None and not kinetic_force.at_bound \
                    and math.isfinite(z) and z > RESOLVED_SIGMAS:
                diff += (f"; higher because Klein's Eq. 1 reads the rate-independent F_k = "
                         f"{kinetic_force.value:.4g} {kinetic_force.units} as viscosity")
            elif math.isfinite(z) and abs(z) > RESOLVED_SIGMAS:
                diff += "; the two assumptions do not both hold for these slips"
            elif math.isfinite(z):
                diff += ": they agree within their errors"
        elif reference is not None and name != reference[0]:
            z = _sigmas(est, reference[1])
            diff = (f"no primary; {z:+.1f} standard errors from the {reference[0]} estimate"
                    if math.isfinite(z) else "no primary to compare with")
        else:
            diff = "no primary to compare with"
        if name == "calibration" and est.at_bound:
            diff = "B at its bound 0: " + diff
        checks.append(CrossCheck(name, est, RESTS_ON[name], diff, unphysical.get(name, "")))

    friction = {}
    verdict = law.get("verdict")
    if film_damping is not None and verdict:
        mine = _reading(kinetic_force, film_damping, damping_scatter)
        theirs = _reading(_entry(law.get("kinetic_force"), ""), _entry(law.get("damping"), ""),
                          significance=_law_significance(law))

        def show(e):
            if e is None:
                return "–"
            if e.at_bound:
                return f"{e.value:.4g} {e.units} (at bound)" + (
                    f"; below {e.limit:.3g} at 95 %" if math.isfinite(e.limit) else "")
            return f"{e.value:.4g} ± {e.stderr:.2g} {e.units}"

        friction = {
            "calibration": mine,
            "calibration_rests_on": (f"the shape of the spring force over the slips (F_k = "
                                     f"{show(kinetic_force)}, B = {show(film_damping)})"),
            "slip_law": theirs, "slip_law_verdict": verdict,
            "slip_law_rests_on": ("the film force against the wall's velocity during the slips"
                                  + (f" ({law['reason']})" if law.get("reason") else "")),
            "agree": mine == theirs,
        }
        if mine != theirs:
            friction["note"] = (
                f"the calibration resolves {_TERMS[mine]}, the slip law {_TERMS[theirs]}: the "
                "calibration sees only the spring force, whose shape a kinetic part and a "
                "viscous drag can trade against each other; the slip law sees the film force "
                "directly but through the wall's differentiated velocity; neither reading is "
                "established until they agree")
        elif mine == "neither":
            friction["note"] = ("neither resolves a kinetic part or a film drag beyond the "
                                "mount's" + (f" (the slip law's verdict '{verdict}' is its rule "
                                             "for a drag it does not resolve)"
                                             if verdict != "none" else ""))
    status = "resolved" if main is not None else "not resolved"
    return ViscosityChoice(status, primary if main is not None else None, main, reason,
                           tuple(checks), friction)


def choice_note(choice: dict) -> str:
    """One sentence for people from a :meth:`ViscosityChoice.as_dict` document."""
    if choice.get("status") != "resolved":
        return f"η_eff not resolved: {choice.get('reason', '')}"
    p = choice["primary"]
    err = finite_or_none(p.get("stderr"))
    return (f"η_eff = {p['value']:.4g}" + (f" ± {err:.2g}" if err else "") + f" {p['units']} "
            f"({choice['estimator']}: {choice['reason']})")
