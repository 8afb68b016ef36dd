"""The SFB check on one's own surface force balance: its set-up and its measured slip.

:func:`~filmfriction.reduced_model.sfb.check.sfb_check` compares the reduced model with
Klein's cycle; the same check runs on any SFB whose set-up (:class:`SFBSetup`:
spring constant K, mass M, contact area A or radius a, film thickness D, load L,
drive velocity V, each with its one-sigma error, SI) and measured slip
(:class:`MeasuredSlip`: the static force, slip distance, slip time, period and the
η_eff of Klein's Eq. 1 fitted to the slips, e.g. from ``analysis.json``) are given.
:func:`setup_experiment` puts them where Klein's numbers were, and
:func:`sfb_check_setup` runs the check and propagates every input's error to each
model number: one input at a time moved by +1σ, the changes added in quadrature
(linear propagation), which replaces the η, A, D interval of Klein's check.

What Klein read off his trace and a trace alone does not give (the ringing's
frequency, amplitude and mass, the temperature rise, the viscous fraction) is
left out: those rows have no measured value.

Example
-------
>>> setup = SFBSetup.from_dict({"spring_constant": {"value": 97.0, "error": 5.0},
...     "mass": 1.47e-3, "contact_radius": {"value": 11.3e-6, "error": 0.5e-6},
...     "film_thickness": {"value": 3.5e-9, "error": 0.3e-9}, "load": 42e-6,
...     "drive_velocity": 1e-7})
>>> round(setup.contact_area * 1e10, 2), round(setup.contact_area_err / setup.contact_area, 3)
(4.01, 0.088)
>>> slip = MeasuredSlip(static_force=9.7e-6, slip_distance=7.25e-8, slip_time=0.03,
...                     cycle_time=0.73, eta_eff=27.0, eta_eff_err=1.0)
>>> check = sfb_check_setup(setup, slip)
>>> row = check.row("slip_time")
>>> row["klein"], row["uncertainty"][0] < row["model"] < row["uncertainty"][1]
(0.03, True)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from pathlib import Path

from .klein import KleinExperiment
from .check import SFBCheck, sfb_check
from ..units import OMCTS, LJUnits

__all__ = ["SFBSetup", "MeasuredSlip", "setup_experiment", "sfb_check_setup", "SETUP_KEYS",
           "load_setup", "read_setup_file"]

#: The set-up's quantities: name -> (SI unit, meaning).
SETUP_KEYS = {
    "spring_constant": ("N/m", "shear spring constant K"),
    "mass": ("kg", "mass M of the moving surface and its mount"),
    "contact_area": ("m²", "contact area A (or give contact_radius a: A = π a²)"),
    "contact_radius": ("m", "contact radius a, instead of contact_area"),
    "film_thickness": ("m", "film thickness D"),
    "load": ("N", "normal load L"),
    "drive_velocity": ("m/s", "drive velocity V of the spring's end"),
    "bulk_viscosity": ("Pa·s", "the liquid's bulk viscosity (default OMCTS's 2.5 mPa·s)"),
}


def _number(name: str, value, *, error: bool = False) -> float:
    what = f"{name} error" if error else name
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{what} = {value!r}: give a number (SI units, "
                         f"{SETUP_KEYS.get(name, ('',))[0]})")
    value = float(value)
    if not math.isfinite(value) or (value < 0 if error else value <= 0):
        raise ValueError(f"{what} = {value!r}: must be {'0 or more' if error else 'positive'} "
                         "and finite")
    return value


def _check_numbers(record, *, text_field: str) -> None:
    """Every field of the dataclass ``record`` but ``text_field`` a positive finite
    number, each ``*_err`` field one of 0 or more (:func:`_number`)."""
    for f in fields(record):
        if f.name != text_field:
            _number(f.name.removesuffix("_err"), getattr(record, f.name),
                    error=f.name.endswith("_err"))


@dataclass(frozen=True)
class SFBSetup:
    """An SFB's set-up in SI units, each quantity with its one-sigma error (0: exact).

    Attributes
    ----------
    spring_constant, mass, contact_area, film_thickness, load, drive_velocity : float
        K (N/m), M (kg), A (m²), D (m), L (N), V (m/s).
    *_err : float
        Their one-sigma errors, same units.
    bulk_viscosity : float
        The liquid's bulk viscosity (Pa·s) for the inertial rows.
    name : str
        A label for the outputs.
    """

    spring_constant: float
    mass: float
    contact_area: float
    film_thickness: float
    load: float
    drive_velocity: float
    spring_constant_err: float = 0.0
    mass_err: float = 0.0
    contact_area_err: float = 0.0
    film_thickness_err: float = 0.0
    load_err: float = 0.0
    drive_velocity_err: float = 0.0
    bulk_viscosity: float = 2.5e-3
    name: str = "SFB set-up"

    def __post_init__(self):
        _check_numbers(self, text_field="name")

    @classmethod
    def from_dict(cls, data: dict, name: str = "SFB set-up") -> "SFBSetup":
        """A set-up from a mapping (a TOML file's tables): each key of :data:`SETUP_KEYS`
        a number or ``{value = ..., error = ...}``; ``name`` optional.

        Raises
        ------
        ValueError
            An unknown key, a missing quantity, a value that is not a positive
            number, an error that is negative, or both contact_area and contact_radius.
        """
        data = dict(data)
        name = str(data.pop("name", name))
        unknown = sorted(set(data) - set(SETUP_KEYS))
        if unknown:
            raise ValueError(f"unknown set-up key(s) {', '.join(unknown)}; accepted: "
                             f"{', '.join(SETUP_KEYS)}, name")
        values = {}
        for key, given in data.items():
            if isinstance(given, dict):
                extra = sorted(set(given) - {"value", "error"})
                if extra or "value" not in given:
                    raise ValueError(f"{key} = {given!r}: give a number or "
                                     "{value = ..., error = ...}")
                values[key] = (_number(key, given["value"]),
                               _number(key, given.get("error", 0.0), error=True))
            else:
                values[key] = (_number(key, given), 0.0)
        if "contact_area" in values and "contact_radius" in values:
            raise ValueError("give contact_area or contact_radius, not both")
        if "contact_radius" in values:
            a, da = values.pop("contact_radius")
            values["contact_area"] = (math.pi * a * a, 2.0 * math.pi * a * da)
        missing = [k for k in ("spring_constant", "mass", "contact_area", "film_thickness",
                               "load", "drive_velocity") if k not in values]
        if missing:
            raise ValueError(f"the set-up lacks {', '.join(missing)} (SI units: "
                             + ", ".join(f"{k} in {SETUP_KEYS[k][0]}" for k in missing) + ")")
        kw = {"name": name}
        for key, (value, error) in values.items():
            kw[key] = value
            if key != "bulk_viscosity":
                kw[key + "_err"] = error
        return cls(**kw)

    def as_dict(self) -> dict:
        """The set-up as ``{key: {"value", "error", "units"}}`` plus ``name``."""
        out = {"name": self.name}
        for key, (units_, _) in SETUP_KEYS.items():
            if key == "contact_radius":
                continue
            out[key] = {"value": getattr(self, key),
                        "error": getattr(self, key + "_err", 0.0), "units": units_}
        return out


def read_setup_file(path) -> dict:
    """The set-up file ``path`` as a TOML table; ValueError naming the file when it is
    missing or not UTF-8 TOML (the one reader of set-up files: :func:`load_setup` and the
    trace's ``[trace]`` table both use it)."""
    import tomllib

    path = Path(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8-sig"))  # a BOM is accepted
    except FileNotFoundError:
        raise ValueError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise ValueError(f"{path}: cannot read it as TOML: {exc}") from None


def load_setup(path) -> SFBSetup:
    """The :class:`SFBSetup` in the TOML file ``path`` (named after the file unless it
    says ``name``).  A ``[trace]`` table, how the instrument writes its traces, is not
    part of the set-up: ``filmfriction analyze`` reads it
    (:func:`filmfriction.analysis.files.column_spec.trace_table`).

    Raises
    ------
    ValueError
        A file that is missing, not UTF-8 TOML, or not a valid set-up; the message
        names the file.
    """
    path = Path(path)
    data = read_setup_file(path)
    data.pop("trace", None)
    try:
        return SFBSetup.from_dict(data, name=path.stem)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


@dataclass(frozen=True)
class MeasuredSlip:
    """The slip measured on the SFB's trace (SI), each with its one-sigma error.

    Attributes
    ----------
    static_force : float
        F_s, the spring force at the yield point y, N (x0 = F_s/K).
    slip_distance : float
        Δx0, the slip from y to the re-stick s, m.
    slip_time : float
        τ_s, from y to s, s.
    cycle_time : float
        The stick-slip period, s.
    eta_eff : float
        η_eff of Klein's Eq. 1 fitted to the slips, Pa·s.
    source : str
        Where the numbers come from.
    """

    static_force: float
    slip_distance: float
    slip_time: float
    cycle_time: float
    eta_eff: float
    static_force_err: float = 0.0
    slip_distance_err: float = 0.0
    slip_time_err: float = 0.0
    eta_eff_err: float = 0.0
    source: str = ""

    def __post_init__(self):
        _check_numbers(self, text_field="source")


# the scale of Klein's film energy dE_f ~ K x0 delta; any delta gives the same x0
_DELTA = 1e-9


def setup_experiment(setup: SFBSetup, slip: MeasuredSlip) -> KleinExperiment:
    """The set-up and its slip in the place of Klein's numbers.

    x0 = F_s/K and Δx0 are written as the energies that
    :func:`~filmfriction.reduced_model.sfb.klein.klein_slip_geometry` reads back
    (ΔE_f = K x0 δ, ΔE_spring = K (x0 − Δx0/2) Δx0); the ringing, the
    temperature rise and the viscous fraction are NaN (not measured).

    Raises
    ------
    ValueError
        A slip longer than the spring's extension at yield (Δx0 > x0).
    """
    K = setup.spring_constant
    x0 = slip.static_force / K
    dx = slip.slip_distance
    if dx > x0:
        raise ValueError(f"slip distance {dx:.3g} m exceeds the spring's extension at yield "
                         f"F_s/K = {x0:.3g} m: the spring would push back at the re-stick")
    nan = math.nan
    return KleinExperiment(
        spring_constant=K, mass=setup.mass,
        contact_area=setup.contact_area, contact_area_err=setup.contact_area_err,
        film_thickness=setup.film_thickness, film_thickness_err=setup.film_thickness_err,
        eta_eff=slip.eta_eff, eta_eff_err=slip.eta_eff_err, eta_bulk=setup.bulk_viscosity,
        load=setup.load, slip_time=slip.slip_time, cycle_time=slip.cycle_time,
        spring_energy_released=K * (x0 - dx / 2.0) * dx,
        film_energy=K * x0 * _DELTA, film_energy_length=_DELTA,
        ringing_frequency=nan, ringing_amplitude=nan, ringing_mass=nan, ringing_energy=nan,
        viscous_fraction=nan, temperature_rise=nan)


def _perturbed(setup: SFBSetup, slip: MeasuredSlip):
    """(input name, set-up, slip) with one input moved by +1σ, for each input with an error."""
    for f in fields(setup):
        if f.name.endswith("_err") and getattr(setup, f.name) > 0:
            key = f.name.removesuffix("_err")
            yield key, replace(setup, **{key: getattr(setup, key) + getattr(setup, f.name)}), slip
    for f in fields(slip):
        if f.name.endswith("_err") and getattr(slip, f.name) > 0:
            key = f.name.removesuffix("_err")
            yield key, setup, replace(slip, **{key: getattr(slip, key) + getattr(slip, f.name)})


def sfb_check_setup(setup: SFBSetup, slip: MeasuredSlip, calibration=None,
                    units: LJUnits = OMCTS) -> SFBCheck:
    """:func:`~filmfriction.reduced_model.sfb.check.sfb_check` on ``setup`` and ``slip``, each
    model number's interval propagated from every input's error (linear, one input at a
    time by +1σ, in quadrature).  The ``klein`` column holds the measured numbers; the
    notes speak of the set-up (by its ``name``) and its trace, first the propagation.

    Raises
    ------
    ValueError
        The slip does not fit the set-up (:func:`setup_experiment`).
    """
    base = sfb_check(calibration=calibration, units=units,
                     experiment=setup_experiment(setup, slip), setup=setup.name)
    shifts: dict[tuple, float] = {}
    inputs = []
    for key, s, m in _perturbed(setup, slip):
        inputs.append(key)
        try:
            other = sfb_check(calibration=calibration, units=units,
                              experiment=setup_experiment(s, m), setup=setup.name)
        except ValueError as exc:
            raise ValueError(f"{key} + 1 sigma: {exc}") from None
        for r0, r1 in zip(base.rows, other.rows):
            if r0["model"] is not None and r1["model"] is not None:
                k = (r0["name"], r0["source"])
                shifts[k] = shifts.get(k, 0.0) + (r1["model"] - r0["model"]) ** 2
    rows = []
    for r in base.rows:
        r = dict(r)
        k = (r["name"], r["source"])
        if r["model"] is not None and inputs:
            sigma = math.sqrt(shifts.get(k, 0.0))
            r["uncertainty"] = [r["model"] - sigma, r["model"] + sigma]
        rows.append(r)
    note = (f"{setup.name}: the measured slip ({slip.source or 'given'}) in place of Klein's "
            f"numbers; intervals: +/-1 sigma propagated linearly from "
            f"{', '.join(inputs) if inputs else 'no input (no errors given)'}; no measured "
            "ringing, temperature rise or viscous fraction")
    return replace(base, rows=rows, notes=(note,) + base.notes)
