"""Dimensionless numbers of a driven stick-slip contact: how MD speaks to an SFB experiment.

An MD film slides 10⁹ times faster than an SFB contact; unit conversion cannot
bridge that, similarity can.  Two stick-slip contacts are alike when these
numbers are alike (K spring, M slider mass, V drive velocity, L normal load,
F_s static force at yield, F_b spring force at re-stick, B the film's viscous
drag, γM the mount's dashpot, k_f the stuck film's shear stiffness, a the
molecular diameter):

``static_friction_coefficient``      μ_s = F_s / L
``kinetic_friction_coefficient``     μ_k = F_k / L with F_k = (F_s + F_b)/2, the
                                     cycle-averaged spring force of a sawtooth
                                     (exact for Coulomb stick-slip: F_b = 2F_k − F_s)
``extension_over_lattice``           x0 / a, x0 = F_s / K
``slip_over_extension``              Δx0 / x0
``film_damping_ratio``               ζ_film = B / (2√(KM))
``mount_damping_ratio``              ζ_mount = γM / (2√(KM))
``compliance_ratio``                 K / k_f (the stuck film's share of the
                                     elastic energy at yield: E_film/E_spring)
``viscous_fraction``                 share of a slip's dissipation that is viscous
                                     heating of the film during the slip
``lambda``                           λ = (F_s − F_k)/(V√(KM)), Nakano–Maegawa
``lambda_critical``                  λ_c(ζ) at ζ = ζ_film + ζ_mount
                                     (:func:`.maps.critical_lambda`; ∞ for ζ ≥ 1)
``reduced_pressure``                 P σ³/ε (needs ε/σ³)
``bingham_number``                   Bi = B/B_bulk = η_eff/η_bulk: the film's damping
                                     (Klein's Eq. 1 fitted to the slips) over that of
                                     a no-slip film of bulk viscosity, B_bulk = η_bulk·A/D
                                     — the number Klein and Braun & Tosatti disagree on
``bulk_film_damping_ratio``          ζ_bulk = B_bulk/(2√(KM))
``slip_heating``                     ΔT/T, the film's temperature rise per slip
                                     (adiabatic) over its temperature
``slip_velocity_over_thermal``       (Δx0/τ_s)/√(kT/m), the mean slip velocity over
                                     the molecules' thermal velocity
``contact_width_over_sigma``         √A/a, the contact's width in molecular diameters
``backward_over_static``             F_b/F_s

Uncertainties are propagated to first order from the inputs' standard errors,
taken independent (each input moved by its error, the changes added in quadrature).

Example
-------
A Coulomb stick-slip of unit mass and spring, V = 0.1, F_s = 1, F_b = 0, load 2:

>>> c = SlidingContact(spring_constant=1.0, mass=1.0, drive_velocity=0.1, static_force=1.0,
...                    restick_force=0.0, normal_load=2.0, slip_distance=1.0)
>>> n = similarity_numbers(c)
>>> n["kinetic_friction_coefficient"].value, n["lambda"].value
(0.25, 5.0)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from itertools import product

from scipy import constants

from .klein import KLEIN, KleinExperiment, klein_slip_geometry, newtonian_damping
from ..maps import critical_lambda
from .rows import table_row, without_unfixed_ratio
from ..units import OMCTS, LJUnits

__all__ = ["SlidingContact", "Number", "similarity_numbers", "NUMBERS", "klein_contact",
           "klein_ranges", "similarity_rows", "KLEIN_RINGDOWN_TIME", "KLEIN_UNPRINTED",
           "KLEIN_ROOM_TEMPERATURE", "SIMILARITY_SOURCE"]

#: ``source`` of the similarity rows of the SFB table.
SIMILARITY_SOURCE = "similarity"
#: Decay time of Klein's ringing after the stick, s ("ca. 80 ms for the trace shown", PRL 98,
#: 056101): the mount's damping ratio is 1/(2π ν_c τ) at ν_c = 45 Hz.
KLEIN_RINGDOWN_TIME = 0.08

#: The numbers :func:`similarity_numbers` returns, in order, with what each needs.
NUMBERS = ("static_friction_coefficient", "kinetic_friction_coefficient",
           "extension_over_lattice", "slip_over_extension", "film_damping_ratio",
           "mount_damping_ratio", "compliance_ratio", "viscous_fraction", "lambda",
           "lambda_critical", "reduced_pressure", "bingham_number", "bulk_film_damping_ratio",
           "slip_heating", "slip_velocity_over_thermal", "contact_width_over_sigma",
           "backward_over_static")

#: Klein's inputs that he did not print, with the range each can take: his ΔE_f ≈ 1×10⁻¹⁴ J
#: is one figure (±10 %), and x0, Δx0 and the drive velocity follow from it; the molecular
#: diameter σ of OMCTS, 0.82 ± 0.02 nm from the force oscillations or 0.875 nm from his
#: 3.5 nm / 4 layers; "room temperature", 293–298 K.
KLEIN_UNPRINTED = {"film_energy": (0.9e-14, 1.1e-14), "sigma": (0.80e-9, 0.875e-9),
                   "temperature": (293.0, 298.0)}
#: The room temperature taken for Klein's film, K (not printed).
KLEIN_ROOM_TEMPERATURE = 295.0


@dataclass(frozen=True)
class Number:
    """A dimensionless number with its standard error (NaN: not available)."""

    value: float
    stderr: float = math.nan
    note: str = ""


@dataclass(frozen=True)
class SlidingContact:
    """A stick-slip contact's measured parameters, in any one consistent unit system.

    Every ``*_err`` is a one-standard-error uncertainty (0: exact or not known).
    ``None`` marks a quantity that was not measured; the numbers that need it are NaN.
    """

    spring_constant: float
    mass: float
    drive_velocity: float
    static_force: float
    restick_force: float
    normal_load: float | None = None
    slip_distance: float | None = None
    film_damping: float | None = None
    mount_damping: float = 0.0
    film_stiffness: float | None = None
    molecular_diameter: float | None = None
    viscous_fraction: float | None = None
    pressure: float | None = None
    stress_unit: float | None = None        # ε/σ³, for the reduced pressure
    bulk_damping: float | None = None       # η_bulk·A/D, a no-slip film of bulk viscosity
    temperature: float | None = None
    temperature_rise: float | None = None   # of the film per slip, adiabatic
    slip_velocity: float | None = None      # mean slip velocity Δx0/τ_s
    thermal_velocity: float | None = None   # √(kT/m) of one molecule
    contact_width: float | None = None      # √A
    static_force_err: float = 0.0
    restick_force_err: float = 0.0
    slip_distance_err: float = 0.0
    film_damping_err: float = 0.0
    film_stiffness_err: float = 0.0
    viscous_fraction_err: float = 0.0
    mass_err: float = 0.0
    spring_constant_err: float = 0.0
    normal_load_err: float = 0.0
    bulk_damping_err: float = 0.0
    temperature_rise_err: float = 0.0
    slip_velocity_err: float = 0.0

    def __post_init__(self):
        for name in ("spring_constant", "mass", "drive_velocity"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} = {v!r}: must be a positive number")
        for f in fields(self):
            v = getattr(self, f.name)
            if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ValueError(f"{f.name} = {v!r}: must be a finite number or None")
            if f.name.endswith("_err") and v < 0:
                raise ValueError(f"{f.name} = {v!r}: an error cannot be negative")


def _values(c: SlidingContact) -> dict:
    nan = math.nan
    opt = lambda v: nan if v is None else float(v)  # noqa: E731
    K, M, V = c.spring_constant, c.mass, c.drive_velocity
    fs, fb = c.static_force, c.restick_force
    fk = 0.5 * (fs + fb)
    root = math.sqrt(K * M)
    x0 = fs / K
    load = opt(c.normal_load)
    zf = opt(c.film_damping) / (2 * root)
    zm = c.mount_damping / (2 * root)
    return {
        "static_friction_coefficient": fs / load,
        "kinetic_friction_coefficient": fk / load,
        "extension_over_lattice": x0 / opt(c.molecular_diameter),
        "slip_over_extension": opt(c.slip_distance) / x0,
        "film_damping_ratio": zf,
        "mount_damping_ratio": zm,
        "compliance_ratio": K / opt(c.film_stiffness),
        "viscous_fraction": opt(c.viscous_fraction),
        "lambda": (fs - fk) / (V * root),
        "lambda_critical": (float(critical_lambda(zf + zm)) if math.isfinite(zf + zm)
                            and zf + zm >= 0 else nan),
        "reduced_pressure": opt(c.pressure) / opt(c.stress_unit),
        "bingham_number": opt(c.film_damping) / opt(c.bulk_damping),
        "bulk_film_damping_ratio": opt(c.bulk_damping) / (2 * root),
        "slip_heating": opt(c.temperature_rise) / opt(c.temperature),
        "slip_velocity_over_thermal": opt(c.slip_velocity) / opt(c.thermal_velocity),
        "contact_width_over_sigma": opt(c.contact_width) / opt(c.molecular_diameter),
        "backward_over_static": fb / fs,
    }


def similarity_numbers(contact: SlidingContact) -> dict[str, Number]:
    """The dimensionless numbers of ``contact`` (see the module text), with errors.

    Returns
    -------
    dict
        ``{name: Number}`` for every name in :data:`NUMBERS`.
    """
    base = _values(contact)
    var = {k: 0.0 for k in base}
    for f in fields(contact):
        if not f.name.endswith("_err"):
            continue
        err = getattr(contact, f.name)
        name = f.name[:-4]
        if not err or getattr(contact, name) is None:
            continue
        moved = _values(replace(contact, **{name: getattr(contact, name) + err}))
        for k, v in moved.items():
            if math.isfinite(v) and math.isfinite(base[k]):
                var[k] += (v - base[k]) ** 2
    out = {}
    for k in NUMBERS:
        v = base[k]
        note = ""
        if k == "lambda_critical" and math.isinf(v):
            note = "total damping ratio >= 1: no stick-slip for a purely viscous law"
        out[k] = Number(v, math.sqrt(var[k]) if math.isfinite(v) else math.nan, note)
    return out


def klein_contact(experiment: KleinExperiment = KLEIN, units: LJUnits = OMCTS,
                  temperature: float = KLEIN_ROOM_TEMPERATURE) -> SlidingContact:
    """Klein's SFB cycle as a :class:`SlidingContact` (SI), from his printed numbers.

    * x0 and Δx0 from his energy statements (:func:`.klein.klein_slip_geometry`);
      F_s = K x0, F_b = K (x0 − Δx0);
    * V = Δx0/τ_ss: in steady stick-slip the spring's end advances one slip per
      cycle (his drive velocity is not printed);
    * B = Aη_eff/D with its ±20 % (his errors of η_eff, A, D);
    * the mount's damping from the ringing's decay (45 Hz, ~80 ms): ζ ≈ 0.044;
    * k_f = F_s/δ with δ ≈ 1 nm, the film's strain before yield in his ΔE_f ≈ K x0 δ,
      so K/k_f = δ/x0;
    * viscous fraction ΔE_spring/(ΔE_spring + ΔE_osc) from his energies (he states
      "of order 90 % or more");
    * the molecular diameter, the molecule's mass and ε/σ³ of the OMCTS unit mapping
      ``units``;
    * B_bulk = A·η_bulk/D with his bulk viscosity (2.5 mPa·s), so that the Bingham
      number is his η_eff/η_bulk;
    * the film's temperature rise per slip, his note [29]'s 0.6 K, over the room
      ``temperature`` (not printed: :data:`KLEIN_UNPRINTED`);
    * the mean slip velocity Δx0/τ_s over √(k_B T/m) of one OMCTS molecule; √A.

    Example
    -------
    >>> n = similarity_numbers(klein_contact())
    >>> round(n["film_damping_ratio"].value, 2), round(n["extension_over_lattice"].value)
    (4.09, 126)
    """
    ex = experiment
    geo = klein_slip_geometry(ex)
    K, M = ex.spring_constant, ex.mass
    fs = K * geo.x0
    fb = K * (geo.x0 - geo.slip_distance)
    zeta_mount = 1.0 / (2 * math.pi * ex.ringing_frequency * KLEIN_RINGDOWN_TIME)
    return SlidingContact(
        spring_constant=K, mass=M, drive_velocity=geo.slip_distance / ex.cycle_time,
        static_force=fs, restick_force=fb, normal_load=ex.load,
        slip_distance=geo.slip_distance, film_damping=ex.damping,
        film_damping_err=ex.damping * ex.damping_rel_err,
        mount_damping=zeta_mount * 2 * math.sqrt(K * M),
        film_stiffness=fs / ex.film_energy_length,
        molecular_diameter=units.sigma,
        viscous_fraction=ex.spring_energy_released / (ex.spring_energy_released
                                                      + ex.ringing_energy),
        pressure=ex.load / ex.contact_area, stress_unit=units.stress,
        bulk_damping=newtonian_damping(ex.contact_area, ex.eta_bulk, ex.film_thickness),
        temperature=temperature, temperature_rise=ex.temperature_rise,
        slip_velocity=geo.slip_distance / ex.slip_time,
        thermal_velocity=math.sqrt(constants.k * temperature / units.mass),
        contact_width=math.sqrt(ex.contact_area))


def klein_ranges(experiment: KleinExperiment = KLEIN, units: LJUnits = OMCTS) -> dict:
    """For each of :data:`NUMBERS`, the range Klein's number takes over what his
    unprinted inputs allow (:data:`KLEIN_UNPRINTED`, every corner), or ``None`` when it
    does not depend on them (computed from printed numbers only).

    Example
    -------
    >>> r = klein_ranges()
    >>> [round(x, 3) for x in r["slip_over_extension"]], r["bingham_number"]
    ([0.401, 0.795], None)
    """
    values = {k: [] for k in NUMBERS}
    fe, sig, temp = (KLEIN_UNPRINTED[k] for k in ("film_energy", "sigma", "temperature"))
    for e, a, t in product(fe, sig, temp):
        n = similarity_numbers(klein_contact(replace(experiment, film_energy=e),
                                             replace(units, sigma=a), temperature=t))
        for k in NUMBERS:
            values[k].append(n[k].value)
    base = similarity_numbers(klein_contact(experiment, units))
    out = {}
    for k, vs in values.items():
        lo, hi = min(vs), max(vs)
        ref = abs(base[k].value)
        moves = math.isfinite(lo) and math.isfinite(hi) and hi - lo > 1e-9 * max(ref, 1e-300)
        out[k] = (lo, hi) if moves else None
    return out


#: What each similarity row compares, for its note.
_ROW_NOTES = {
    "static_friction_coefficient": "F_s/L; at low load adhesion carries much of F_s: see the shear stress",
    "kinetic_friction_coefficient": "(F_s + F_b)/(2L), the cycle-averaged spring force over the load",
    "extension_over_lattice": "x0/a, spring extension at yield in molecular diameters",
    "slip_over_extension": "slip distance over the spring extension at yield",
    "film_damping_ratio": "B/(2 sqrt(KM)), B from Klein's Eq. (1) fitted to the slips, as he "
                          "measured his (A eta_eff/D); the slip law says whether B is viscous",
    "mount_damping_ratio": "gamma M/(2 sqrt(KM)) (Klein: ringing decay ~80 ms at 45 Hz)",
    "compliance_ratio": "K/k_f (Klein: delta/x0 with delta ~ 1 nm; his dE_f/dE_spring reads 0.025)",
    "viscous_fraction": "film heat over film heat + ringing (Klein: from dE_spring and dE_osc)",
    "lambda": "Nakano-Maegawa (F_s - F_k)/(V sqrt(KM)) (Klein: V = slip/cycle time)",
    "lambda_critical": "lambda_c at zeta = film + mount (inf: no stick-slip for a viscous law)",
    "reduced_pressure": "P sigma^3/epsilon",
    "bingham_number": "eta_eff/eta_bulk = B/(eta_bulk A/D), B from Klein's Eq. (1) fitted to the "
                      "slips (less the mount's dashpot); the number Klein (~1e4) and Braun & "
                      "Tosatti (~1) disagree on. Near 1, Eq. (1) needs no more damping than a "
                      "bulk film gives: a fitted eta_eff cannot show a viscous film there",
    "bulk_film_damping_ratio": "eta_bulk A/(D 2 sqrt(KM)): the damping ratio a no-slip film of "
                               "bulk viscosity would give (MD: eta_bulk of the LJ liquid at the "
                               "film's state point)",
    "slip_heating": "temperature rise of the film per slip (adiabatic) over its temperature "
                    "(Klein: his note 29's 0.6 K; MD: film heat / (3 N k_B))",
    "slip_velocity_over_thermal": "mean slip velocity dx0/tau_s over sqrt(kT/m) of one molecule",
    "contact_width_over_sigma": "sqrt(A)/a: contact width in molecular diameters (MD: the "
                                "periodic box; Klein: his JKR area)",
    "backward_over_static": "F_b/F_s, re-stick over yield force",
}


def similarity_rows(model: SlidingContact, klein: SlidingContact | None = None,
                    ranges: dict | None = None) -> list[dict]:
    """Rows of the SFB table (``source = "similarity"``): each number, Klein's beside the model's.

    ``uncertainty`` is the model's ±1 standard error interval; a row whose
    interval spans more than a decade (or reaches zero) has no ratio and says so.
    ``ranges`` (:func:`klein_ranges`; by default those of Klein's own contact when
    ``klein`` is not given, else none) mark his numbers printed or derived.
    """
    mk = similarity_numbers(model)
    kl = similarity_numbers(klein if klein is not None else klein_contact())
    if ranges is None:
        ranges = klein_ranges() if klein is None else {}
    rows = []
    for name in NUMBERS:
        m, k = mk[name], kl[name]
        unc = None
        note = _ROW_NOTES[name]
        if math.isfinite(m.stderr) and math.isfinite(m.value):
            unc = (m.value - m.stderr, m.value + m.stderr)
        for who, n in (("this run", m.note), ("Klein", k.note)):
            if n:
                note += f"; {who}: {n}"
        rng = ranges.get(name)
        if rng is not None:
            note += (f"; Klein's value is derived, not printed: {rng[0]:.3g} to {rng[1]:.3g} "
                     "over his unprinted inputs (dE_f +-10 %, sigma, room temperature)")
        src = (("derived" if rng is not None else "printed") if name in ranges else None)
        # every number here is positive by nature
        rows.append(without_unfixed_ratio(
            table_row(name, k.value, m.value, "1", SIMILARITY_SOURCE, note, unc,
                      klein_source=src, klein_range=rng)))
    return rows
