"""The MD film as the SFB check takes it: :class:`MDCalibration` and its friction law in SI.

The calibration of the reduced model on MD runs
(:func:`filmfriction.analysis.calibrate`) ends in an :class:`MDCalibration`:
the film's yield, re-stick and sliding stresses and its η(γ̇) law, in LJ
units.  :func:`film_law` carries it to SI through
:mod:`filmfriction.reduced_model.units` at a given contact (area A, gap D) as
one of the reduced model's friction laws; :func:`slip_drag` is the film's
effective drag when it carries a given force in steady sliding.

Example
-------
>>> from filmfriction.reduced_model.units import OMCTS
>>> cal = MDCalibration(yield_stress=0.5, restick_stress=0.25, eta_zero=50.0)
>>> law = film_law(cal, OMCTS, area=4e-10, thickness=3.5e-9)
>>> type(law).__name__, law.closed_form(1.0)[:2]        # Newtonian, no sliding stress
('Coulomb', (0.0, 0.0))
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from .. import laws
from ..units import LJUnits

__all__ = ["MDCalibration", "film_law", "slip_drag"]


@dataclass(frozen=True)
class MDCalibration:
    """What the MD film contributes to the SFB check, in LJ units.

    Stresses are in ε/σ³, viscosities in ετ/σ³, shear rates in 1/τ; each
    ``*_err`` is a one-standard-error uncertainty in the same unit (0: not
    known).  Converted to SI with the :class:`~filmfriction.reduced_model.units.LJUnits`
    passed to :func:`~filmfriction.reduced_model.sfb.check.sfb_check`.

    Attributes
    ----------
    yield_stress : float
        Shear stress at the yield point y (film shear-melts), ε/σ³.
    eta_zero : float
        Film viscosity at low shear rate (plateau of the Carreau law), ετ/σ³.
    thinning_exponent : float
        n in η ∝ γ̇⁻ⁿ above the onset rate; 0 is Newtonian, 0 ≤ n < 1.
    onset_rate : float
        Shear rate where thinning starts, 1/τ.  The law is the reduced model's
        :class:`~filmfriction.reduced_model.laws.ShearThinningFilm`:
        η(γ̇) = η0 (1 + (γ̇/γ̇_c)²)^(−n/2).
    restick_stress : float or None
        Shear stress at the re-stick point s (film re-solidifies), ε/σ³.
        ``None``: the slip ends when the model's block stops.
    sliding_stress : float
        Rate-independent (Coulomb-like) stress carried while the film slides,
        *in addition to* the viscous stress η γ̇, ε/σ³.  0: a purely viscous
        melted film, as in Klein's Eq. (1).
    shear_rate_range : tuple of float, optional
        (lowest, highest) MD shear rate the η law was fitted on, 1/τ: used to
        state how far the law is extrapolated and to give the pure power-law
        extrapolation from the lowest MD rate as an upper bracket.
    film_thickness : float, optional
        The MD film's thickness, σ (for the report; the SFB slip uses Klein's D).
    source : str
        Where the numbers come from (run directories, fit).

    Example
    -------
    >>> MDCalibration(yield_stress=0.5, eta_zero=8.0, thinning_exponent=0.5, onset_rate=1.0).eta(1.0)
    6.727171322029716
    """

    yield_stress: float
    eta_zero: float
    thinning_exponent: float = 0.0
    onset_rate: float = 1.0
    restick_stress: float | None = None
    sliding_stress: float = 0.0
    yield_stress_err: float = 0.0
    eta_zero_err: float = 0.0
    thinning_exponent_err: float = 0.0
    onset_rate_err: float = 0.0
    restick_stress_err: float = 0.0
    sliding_stress_err: float = 0.0
    shear_rate_range: tuple | None = None
    film_thickness: float | None = None
    source: str = ""

    def __post_init__(self):
        def check(name, value, low=0.0, strict=True):
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) \
                    or (value <= low if strict else value < low):
                raise ValueError(f"MDCalibration.{name} = {value!r}: must be a finite number "
                                 f"{'>' if strict else '>='} {low}")
        check("yield_stress", self.yield_stress)
        check("eta_zero", self.eta_zero)
        check("onset_rate", self.onset_rate)
        check("sliding_stress", self.sliding_stress, strict=False)
        if not 0.0 <= self.thinning_exponent < 1.0:
            raise ValueError(f"MDCalibration.thinning_exponent = {self.thinning_exponent!r}: allowed "
                             "range is [0, 1) (0 Newtonian; 1 would make the film's stress rate-independent)")
        for f in fields(self):
            if f.name.endswith("_err"):
                check(f.name, getattr(self, f.name), strict=False)
        if self.restick_stress is not None:
            check("restick_stress", self.restick_stress, strict=False)
            if self.restick_stress >= self.yield_stress:
                raise ValueError(f"MDCalibration.restick_stress = {self.restick_stress!r}: must be below "
                                 f"yield_stress = {self.yield_stress!r} (the film re-solidifies after "
                                 "the spring has relaxed)")
        if self.sliding_stress >= self.yield_stress:
            raise ValueError(f"MDCalibration.sliding_stress = {self.sliding_stress!r}: must be below "
                             f"yield_stress = {self.yield_stress!r} (otherwise there is no slip)")
        if self.shear_rate_range is not None:
            lo, hi = (float(v) for v in self.shear_rate_range)
            if not (0.0 < lo <= hi and math.isfinite(hi)):
                raise ValueError(f"MDCalibration.shear_rate_range = {self.shear_rate_range!r}: "
                                 "expected (lowest, highest) positive rates")
            object.__setattr__(self, "shear_rate_range", (lo, hi))

    def eta(self, shear_rate):
        """η(γ̇) in LJ units for γ̇ in 1/τ (:func:`~filmfriction.reduced_model.laws.carreau_viscosity`,
        the law of ShearThinningFilm)."""
        g = np.asarray(shear_rate, dtype=float)
        out = laws.carreau_viscosity(self.eta_zero, g, self.onset_rate, self.thinning_exponent)
        return float(out) if out.ndim == 0 else out

    @classmethod
    def from_dict(cls, data: dict) -> "MDCalibration":
        """Build from a JSON-like dict with the field names; unknown keys are an error."""
        if not isinstance(data, dict):
            raise ValueError(f"calibration must be a JSON object, got {type(data).__name__}")
        names = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise ValueError(f"unknown calibration field(s) {unknown}; allowed: {sorted(names)}")
        missing = [n for n in ("yield_stress", "eta_zero") if n not in data]
        if missing:
            raise ValueError(f"calibration is missing required field(s) {missing}")
        kwargs = dict(data)
        if kwargs.get("shear_rate_range") is not None:
            kwargs["shear_rate_range"] = tuple(kwargs["shear_rate_range"])
        return cls(**kwargs)

    @classmethod
    def coerce(cls, obj) -> "MDCalibration":
        """Accept an MDCalibration, a dict, or any object with the same attribute names."""
        if isinstance(obj, cls):
            return obj
        if isinstance(obj, dict):
            return cls.from_dict(obj)
        data = {f.name: getattr(obj, f.name) for f in fields(cls) if hasattr(obj, f.name)}
        return cls.from_dict(data)

    def as_dict(self) -> dict:
        """The fields as a JSON-ready dict (``shear_rate_range`` as a list); :meth:`from_dict` reads it."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        if out["shear_rate_range"] is not None:
            out["shear_rate_range"] = list(out["shear_rate_range"])
        return out


def film_law(calibration: MDCalibration, units: LJUnits, area: float, thickness: float):
    """The MD film as a reduced-model friction law in SI at the SFB contact.

    Newtonian (n = 0): Coulomb with the sliding force as both thresholds plus
    the viscous B = A η0 / D; shear-thinning:
    :class:`~filmfriction.reduced_model.laws.ShearThinningFilm`, or
    :class:`~filmfriction.reduced_model.laws.ThinningFilmWithSliding` when the
    film also carries a sliding stress.
    """
    eta0 = units.to_si(calibration.eta_zero, "viscosity")
    kinetic = units.to_si(calibration.sliding_stress, "stress") * area
    if calibration.thinning_exponent == 0.0:
        return laws.Coulomb(static=kinetic, kinetic=kinetic,
                            viscous=laws.newtonian_damping(area, eta0, thickness))
    onset = units.to_si(calibration.onset_rate, "shear_rate")
    if kinetic == 0.0:
        return laws.ShearThinningFilm(viscosity=eta0, area=area, thickness=thickness,
                                      exponent=calibration.thinning_exponent, onset_rate=onset)
    return laws.ThinningFilmWithSliding(viscosity=eta0, area=area, thickness=thickness,
                                        exponent=calibration.thinning_exponent, onset_rate=onset,
                                        kinetic=kinetic)


def slip_drag(cal: MDCalibration, units: LJUnits, area: float, thickness: float, force: float) -> float:
    """Effective drag force/velocity of the film when it carries ``force`` in steady sliding (SI).

    The viscous part ``force − F_k`` is carried by A η(γ̇) γ̇; the shear rate is
    found by bisection in log γ̇ (η γ̇ rises with γ̇ for n < 1), the sliding
    speed is γ̇ D, and the drag is ``force`` over that speed (inf when the
    sliding force alone carries ``force``).
    """
    kinetic = units.to_si(cal.sliding_stress, "stress") * area
    viscous = force - kinetic
    if viscous <= 0.0:
        return math.inf

    def film_force(log_rate):
        rate_lj = units.from_si(math.exp(log_rate), "shear_rate")
        return area * units.to_si(cal.eta(rate_lj), "viscosity") * math.exp(log_rate)

    # eta * rate grows monotonically with rate for n < 1: bisect in log rate
    lo, hi = math.log(1e-30), math.log(1e30)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if film_force(mid) < viscous else (lo, mid)
    speed = math.exp(0.5 * (lo + hi)) * thickness
    return force / speed
