# Over 500 lines as one module by the project's rule: every LJ <-> SI conversion lives
# here (the mapping, its presets, the unit parser, the column factors), and nowhere else.
"""Lennard-Jones <-> SI conversions: the one place in filmfriction where they happen.

MD runs in reduced Lennard-Jones units (σ, ε, m); experiments (the surface
force balance, SFB) are quoted in SI.  Every conversion between the two goes
through a :class:`LJUnits` instance, so that the choice of σ, ε and m is made
once, documented once, and can be overridden once (every function that
converts takes ``units=`` defaulting to :data:`OMCTS`).

The OMCTS mapping
-----------------
OMCTS (octamethylcyclotetrasiloxane, D4) is the liquid of Klein's SFB
experiment (PRL 98, 056101 (2007); seed 004).  One LJ sphere stands for one
OMCTS molecule.

σ = 0.82 nm
    The period of the oscillatory solvation force of OMCTS between mica,
    0.82 ± 0.02 nm (Attard & Parker 1992, as quoted in the project's
    reference notes, /work/shared/reference/README.md).  That period *is* the layer spacing of the confined liquid in
    the same mica–OMCTS–mica geometry, and the layer spacing of a confined
    LJ film is ≈ 1 σ, so it is the length that maps the MD film's layering
    onto the SFB film's.  Klein's own film, 3.5 ± 0.3 nm for 4 layers, gives
    0.875 ± 0.075 nm per layer: consistent, but ~4× less precise, so it is
    not preferred.  Use ``LJUnits.from_molecule(sigma_nm=0.875, ...)`` to
    see the sensitivity.
ε/k_B = T_triple / T*_triple = 290.25 K / 0.69 ≈ 421 K
    OMCTS's triple point is 290.25 K (Colonna et al., Fluid Phase Equilib.
    244, 193 (2006), as tabulated in CoolProp's D4 fluid file); the triple
    point of the full LJ fluid is at k_B T/ε ≈ 0.69 (reference notes;
    recalled literature values lie within ~0.68–0.70, not re-checked here).  A potential truncated at 2.5 σ melts lower, which would
    push ε/k_B toward ~450 K: the range 420–450 K is the honest uncertainty
    (≈ 7 %).  Room temperature (298 K) is then k_B T/ε ≈ 0.71.
m = 296.62 g/mol
    The molar mass of C8H24O4Si4 (296.616 g/mol, Colonna et al. 2006).

Derived values for this default: τ = σ√(m/ε) ≈ 7.6 ps, σ/τ ≈ 109 m/s,
ε/σ³ ≈ 10.5 MPa, ετ/σ³ ≈ 0.080 mPa·s, ε/σ ≈ 7.1 pN, ε/σ² ≈ 8.6 mN/m.  (With σ = 0.8 nm and
ε/k_B = 450 K, the reference-note values — τ ≈ 7.1 ps, σ/τ ≈ 112 m/s,
ε/σ³ ≈ 12 MPa, ετ/σ³ ≈ 0.086 mPa·s, ε/σ ≈ 7.8 pN — are recovered; the
tests check both.)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import constants

__all__ = ["LJUnits", "OMCTS", "SI_IDENTITY", "QUANTITIES", "to_si", "from_si",
           "OMCTS_SIGMA_NM", "OMCTS_EPSILON_OVER_KB", "OMCTS_MOLAR_MASS_G",
           "OMCTS_T_TRIPLE", "LJ_T_TRIPLE_REDUCED"]

#: Force-oscillation period of OMCTS between mica (Attard & Parker 1992), nm.
OMCTS_SIGMA_NM = 0.82
#: Triple point of OMCTS, K (Colonna et al. 2006 / CoolProp D4).
OMCTS_T_TRIPLE = 290.25
#: Triple-point temperature of the LJ fluid in units of ε/k_B (full potential).
LJ_T_TRIPLE_REDUCED = 0.69
#: ε/k_B for OMCTS from matching triple points, K.
OMCTS_EPSILON_OVER_KB = OMCTS_T_TRIPLE / LJ_T_TRIPLE_REDUCED
#: Molar mass of OMCTS (C8H24O4Si4), g/mol.
OMCTS_MOLAR_MASS_G = 296.62

# Each quantity's dimension as exponents of (σ, ε, m): LJ value × σ^a ε^b m^c
# is the SI value.  τ = σ m^½ ε^-½ is built in, e.g. velocity σ/τ = σ^0 ε^½ m^-½.
# Written as exponents rather than one property per name so that to_si and
# from_si can never disagree with each other.
_DIMENSIONS: dict[str, tuple[float, float, float]] = {
    "dimensionless": (0.0, 0.0, 0.0),
    "length": (1.0, 0.0, 0.0),
    "area": (2.0, 0.0, 0.0),
    "volume": (3.0, 0.0, 0.0),
    "mass": (0.0, 0.0, 1.0),
    "energy": (0.0, 1.0, 0.0),
    "time": (1.0, -0.5, 0.5),                 # τ = σ √(m/ε)
    "frequency": (-1.0, 0.5, -0.5),           # 1/τ
    "shear_rate": (-1.0, 0.5, -0.5),          # 1/τ
    "velocity": (0.0, 0.5, -0.5),             # σ/τ
    "acceleration": (-1.0, 1.0, -1.0),        # σ/τ²
    "force": (-1.0, 1.0, 0.0),                # ε/σ
    "stress": (-3.0, 1.0, 0.0),               # ε/σ³
    "pressure": (-3.0, 1.0, 0.0),             # ε/σ³
    "viscosity": (-2.0, 0.5, 0.5),            # ετ/σ³
    "spring_constant": (-2.0, 1.0, 0.0),      # ε/σ²
    "damping": (-1.0, 0.5, 0.5),              # force/velocity = m/τ
    "momentum": (0.0, 0.5, 0.5),              # m σ/τ
    "power": (-1.0, 1.5, -0.5),               # ε/τ
    "number_density": (-3.0, 0.0, 0.0),       # 1/σ³
    "mass_density": (-3.0, 0.0, 1.0),         # m/σ³
    "diffusion": (1.0, 0.5, -0.5),            # σ²/τ
    "temperature": (0.0, 1.0, 0.0),           # handled apart: ε/k_B, not ε
}

#: The quantity names accepted by :meth:`LJUnits.to_si` / :meth:`LJUnits.from_si`.
QUANTITIES: tuple[str, ...] = tuple(sorted(_DIMENSIONS))


@dataclass(frozen=True)
class LJUnits:
    """A Lennard-Jones unit system expressed in SI.

    Parameters
    ----------
    sigma : float
        Length unit σ, m.
    epsilon : float
        Energy unit ε, J.
    mass : float
        Mass unit m (mass of one particle), kg.
    name : str, optional
        Label used in reports.
    source : str, optional
        Where the numbers come from (free text, carried into reports).

    Notes
    -----
    The derived scales are attributes (``tau``, ``velocity``, ``force``, …),
    each the SI value of one LJ unit of that quantity.  Convert arrays with
    :meth:`to_si` and :meth:`from_si` and a quantity name from
    :data:`QUANTITIES`.
    """

    sigma: float
    epsilon: float
    mass: float
    name: str = "custom"
    source: str = ""

    def __post_init__(self):
        for field in ("sigma", "epsilon", "mass"):
            value = getattr(self, field)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"LJUnits.{field} must be a positive finite number, got {value!r}")

    # -- construction ------------------------------------------------------------
    @classmethod
    def from_molecule(cls, sigma_nm: float = OMCTS_SIGMA_NM,
                      epsilon_over_kB: float = OMCTS_EPSILON_OVER_KB,
                      molar_mass_g: float = OMCTS_MOLAR_MASS_G,
                      name: str = "custom", source: str = "") -> "LJUnits":
        """Build units from chemist's numbers.

        Parameters
        ----------
        sigma_nm : float
            σ in nanometres.
        epsilon_over_kB : float
            ε/k_B in kelvin.
        molar_mass_g : float
            Molar mass of one LJ particle in g/mol.
        name, source : str
            Labels carried into reports.
        """
        return cls(sigma=sigma_nm * 1e-9,
                   epsilon=epsilon_over_kB * constants.k,
                   mass=molar_mass_g * 1e-3 / constants.N_A,
                   name=name, source=source)

    # -- derived scales (SI value of one LJ unit) -----------------------------------
    @property
    def length(self) -> float:
        """σ, m."""
        return self.sigma

    @property
    def tau(self) -> float:
        """τ = σ √(m/ε), s."""
        return self.sigma * math.sqrt(self.mass / self.epsilon)

    @property
    def time(self) -> float:
        """Same as :attr:`tau`, s."""
        return self.tau

    @property
    def velocity(self) -> float:
        """σ/τ, m/s."""
        return self.sigma / self.tau

    @property
    def force(self) -> float:
        """ε/σ, N."""
        return self.epsilon / self.sigma

    @property
    def energy(self) -> float:
        """ε, J."""
        return self.epsilon

    @property
    def stress(self) -> float:
        """ε/σ³, Pa."""
        return self.epsilon / self.sigma**3

    @property
    def pressure(self) -> float:
        """ε/σ³, Pa (same as :attr:`stress`)."""
        return self.stress

    @property
    def viscosity(self) -> float:
        """ετ/σ³, Pa·s."""
        return self.epsilon * self.tau / self.sigma**3

    @property
    def shear_rate(self) -> float:
        """1/τ, s⁻¹."""
        return 1.0 / self.tau

    @property
    def temperature(self) -> float:
        """ε/k_B, K."""
        return self.epsilon / constants.k

    @property
    def spring_constant(self) -> float:
        """ε/σ², N/m."""
        return self.epsilon / self.sigma**2

    @property
    def area(self) -> float:
        """σ², m²."""
        return self.sigma**2

    @property
    def damping(self) -> float:
        """Force per velocity, m/τ, N·s/m."""
        return self.mass / self.tau

    @property
    def molar_mass_g(self) -> float:
        """Mass unit as g/mol."""
        return self.mass * constants.N_A * 1e3

    # -- conversion -------------------------------------------------------------------
    def scale(self, quantity: str) -> float:
        """SI value of one LJ unit of ``quantity``.

        Raises
        ------
        ValueError
            If ``quantity`` is not one of :data:`QUANTITIES`.
        """
        try:
            a, b, c = _DIMENSIONS[quantity]
        except (KeyError, TypeError):
            raise ValueError(
                f"unknown quantity {quantity!r}; allowed: {', '.join(QUANTITIES)}") from None
        if quantity == "temperature":
            return self.temperature
        return self.sigma**a * self.epsilon**b * self.mass**c

    def to_si(self, value, quantity: str):
        """Convert ``value`` in LJ units of ``quantity`` to SI.

        Parameters
        ----------
        value : float or array_like
            Value(s) in LJ units.
        quantity : str
            One of :data:`QUANTITIES`.

        Returns
        -------
        float or numpy.ndarray
            The SI value(s): m, s, m/s, N, J, Pa, Pa·s, s⁻¹, K, N/m, kg, m²,
            N·s/m, … according to ``quantity``.
        """
        return _scaled(value, self.scale(quantity))

    def from_si(self, value, quantity: str):
        """Convert ``value`` in SI to LJ units of ``quantity`` (inverse of :meth:`to_si`)."""
        return _scaled(value, 1.0 / self.scale(quantity))

    def summary(self) -> dict:
        """The unit system as a flat dict of SI scales (for reports and JSON)."""
        return {
            "name": self.name,
            "sigma_m": self.sigma,
            "epsilon_J": self.epsilon,
            "epsilon_over_kB_K": self.temperature,
            "mass_kg": self.mass,
            "molar_mass_g_per_mol": self.molar_mass_g,
            "tau_s": self.tau,
            "velocity_m_per_s": self.velocity,
            "force_N": self.force,
            "stress_Pa": self.stress,
            "viscosity_Pa_s": self.viscosity,
            "spring_constant_N_per_m": self.spring_constant,
            "source": self.source,
        }


def _scaled(value, factor: float):
    # Keep Python floats as floats (JSON-friendly); arrays stay arrays.
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value) * factor
    return np.asarray(value, dtype=float) * factor


#: The identity mapping (σ = 1 m, ε = 1 J, m = 1 kg, so τ = 1 s): numbers that are
#: already SI, such as a measured trace's calibration, pass through unchanged
#: (temperatures excepted: ε/k_B is not a temperature scale here).
SI_IDENTITY = LJUnits(sigma=1.0, epsilon=1.0, mass=1.0, name="SI (identity)",
                      source="a measured trace: its numbers are already SI")


#: The project's default unit system: one LJ particle = one OMCTS molecule.
OMCTS = LJUnits.from_molecule(
    sigma_nm=OMCTS_SIGMA_NM,
    epsilon_over_kB=OMCTS_EPSILON_OVER_KB,
    molar_mass_g=OMCTS_MOLAR_MASS_G,
    name="OMCTS",
    source=("σ = 0.82 nm: OMCTS force-oscillation period between mica (Attard & Parker 1992); "
            "ε/k_B = 290.25 K / 0.69: OMCTS triple point over the LJ triple point; "
            "m = 296.62 g/mol"),
)


def to_si(value, quantity: str, units: LJUnits = OMCTS):
    """Convert LJ ``value`` of ``quantity`` to SI with ``units`` (default :data:`OMCTS`)."""
    return units.to_si(value, quantity)


def from_si(value, quantity: str, units: LJUnits = OMCTS):
    """Convert SI ``value`` of ``quantity`` to LJ with ``units`` (default :data:`OMCTS`)."""
    return units.from_si(value, quantity)


# ---------------------------------------------------------------------------
# Viscosity-matched time unit
# ---------------------------------------------------------------------------
# The mapping above fixes τ = σ√(m/ε) by OMCTS's molecular mass.  With it the
# bulk LJ liquid is about ten times less viscous than OMCTS (η* ≈ 3 ετ/σ³ is
# ≈ 0.25 mPa·s, OMCTS 2.5 mPa·s): one sphere does not carry the friction of a
# floppy ring molecule.  A second, equally defensible choice keeps σ and ε and
# sets the time unit so that the MD liquid's viscosity *is* OMCTS's:
#
#     η_SI = η* · ε τ_η / σ³   ⇒   τ_η = η_SI σ³ / (η* ε).
#
# Keeping σ and ε while changing τ is the same as changing the mass unit to
# m_η = ε τ_η² / σ² (τ = σ√(m/ε) must hold for the conversions to stay
# consistent), so the viscosity-matched system is an ordinary LJUnits with
# that effective mass: lengths, energies, forces and stresses convert as
# before, times, rates, velocities, viscosities and damping by τ_η.

#: Bulk viscosity of OMCTS at room temperature, Pa·s (Klein's η_bulk, seed 004).
OMCTS_BULK_VISCOSITY = 2.5e-3


def viscosity_time_unit(eta_lj: float, eta_si: float = OMCTS_BULK_VISCOSITY,
                        units: LJUnits = OMCTS) -> float:
    """Time unit τ_η (s) that maps the LJ viscosity ``eta_lj`` onto ``eta_si``.

    τ_η = η_SI σ³ / (η* ε), with σ and ε of ``units``.

    Parameters
    ----------
    eta_lj : float
        Bulk shear viscosity of the LJ liquid, ετ/σ³ (e.g. from
        ``filmfriction viscosity``).
    eta_si : float
        The real liquid's viscosity, Pa·s (default OMCTS, 2.5 mPa·s).
    units : LJUnits
        Supplies σ and ε (default :data:`OMCTS`).

    Examples
    --------
    >>> tau = viscosity_time_unit(3.0)
    >>> round(3.0 * OMCTS.epsilon * tau / OMCTS.sigma**3 * 1e3, 9)   # back to mPa·s
    2.5
    """
    for name, value in (("eta_lj", eta_lj), ("eta_si", eta_si)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive finite viscosity, got {value!r}")
    return eta_si * units.sigma**3 / (eta_lj * units.epsilon)


def viscosity_matched(eta_lj: float, eta_si: float = OMCTS_BULK_VISCOSITY,
                      units: LJUnits = OMCTS, name: str | None = None,
                      source: str = "") -> LJUnits:
    """``units`` with the time unit τ_η of :func:`viscosity_time_unit`.

    σ and ε are kept; the mass unit becomes m_η = ε τ_η²/σ², the mass for
    which σ√(m/ε) = τ_η.  Note that ``to_si(x, "mass")`` then converts with
    that effective mass, not with the molecule's.
    """
    tau = viscosity_time_unit(eta_lj, eta_si, units)
    mass = units.epsilon * tau**2 / units.sigma**2
    note = (f"viscosity-matched: tau = eta_SI sigma^3/(eta* epsilon) with eta* = {eta_lj:g} "
            f"epsilon tau/sigma^3 -> {eta_si:g} Pa s; effective mass {mass / units.mass:.4g} "
            f"x that of '{units.name}'")
    return LJUnits(sigma=units.sigma, epsilon=units.epsilon, mass=mass,
                   name=name or f"{units.name} (viscosity-matched)",
                   source="; ".join(s for s in (note, source or units.source) if s))


#: Bulk shear viscosity of the LJ liquid (rc = 2.5 σ, truncated) at the film's
#: state point, T = 0.71 ε/k_B and ρ = 0.85 σ⁻³, in ετ/σ³: 3.55 ± 0.10 (standard
#: error over 20 blocks), measured with
#: ``filmfriction viscosity --temperature 0.71 --density 0.85 --steps 800000
#: --blocks 20 --seed 4928459`` (864 atoms; measured T 0.708, P 0.92 ε/σ³ ≈ the
#: film's load of 1 ε/σ³, D 0.029 σ²/τ: a liquid).  See docs/viscosity.md.
LJ_ETA_FILM = 3.55
#: Its standard error, ετ/σ³.
LJ_ETA_FILM_STDERR = 0.10

#: The OMCTS mapping with the viscosity-matched time unit: τ_η ≈ 67 ps
#: (≈ 8.8 × the mapping's τ = σ√(m/ε) ≈ 7.6 ps), so that the MD liquid's
#: η* = :data:`LJ_ETA_FILM` is OMCTS's 2.5 mPa·s.  Convert SFB numbers with
#: ``units=OMCTS`` or ``units=OMCTS_VISCOSITY_MATCHED`` to see both.
OMCTS_VISCOSITY_MATCHED = viscosity_matched(
    LJ_ETA_FILM, name="OMCTS (viscosity-matched)",
    source=f"eta* = {LJ_ETA_FILM} +- {LJ_ETA_FILM_STDERR} at T = 0.71, rho = 0.85, rc = 2.5 "
           "(filmfriction viscosity); " + OMCTS.source)



@dataclass(frozen=True)
class BulkViscosity:
    """The LJ liquid's (rc = 2.5 σ, truncated) shear viscosity measured at one state point.

    Attributes
    ----------
    temperature, density : float
        The state point, ε/k_B and σ⁻³.
    viscosity, stderr : float
        η and its standard error over the Green–Kubo blocks, ετ/σ³.
    command : str
        The command that measured it (docs/viscosity.md).
    """

    temperature: float
    density: float
    viscosity: float
    stderr: float
    command: str


#: The bulk viscosities measured at the state points of the project's films: the
#: Klein-similar film (kT 0.71), the colder films of the mass ladder (kT 0.63, the density
#: the four-layer film's gap gives) and the liquid of the slip law's positive control
#: (kT 1.5, film atoms over A·(gap − σ)); docs/results/mass-ladder.md, slip-law.md.
LJ_BULK_VISCOSITIES = (
    BulkViscosity(0.71, 0.85, LJ_ETA_FILM, LJ_ETA_FILM_STDERR,
                  "filmfriction viscosity --temperature 0.71 --density 0.85 --steps 800000 "
                  "--blocks 20 --seed 4928459"),
    BulkViscosity(0.63, 0.86, 4.25, 0.18,
                  "filmfriction viscosity --temperature 0.63 --density 0.86 --steps 400000 "
                  "--blocks 10 --seed 4928459 --np 1"),
    BulkViscosity(1.5, 0.585, 0.783, 0.079,
                  "filmfriction viscosity --temperature 1.5 --density 0.585 --cells 5 "
                  "--steps 60000 --blocks 6 --equilibrate-steps 5000"),
)


def lj_bulk_viscosity(temperature: float, *, tolerance: float = 0.03) -> BulkViscosity | None:
    """The measured bulk viscosity (:data:`LJ_BULK_VISCOSITIES`) whose temperature is the
    nearest to ``temperature`` (ε/k_B) within ``tolerance``, or ``None``: a film at a
    state point not measured needs ``filmfriction viscosity`` there.

    >>> lj_bulk_viscosity(0.645).viscosity, lj_bulk_viscosity(0.72).viscosity
    (4.25, 3.55)
    >>> lj_bulk_viscosity(1.0) is None
    True
    """
    if not math.isfinite(temperature):
        return None
    best = min(LJ_BULK_VISCOSITIES, key=lambda b: abs(b.temperature - temperature))
    return best if abs(best.temperature - temperature) <= tolerance else None


__all__ += ["OMCTS_BULK_VISCOSITY", "viscosity_time_unit", "viscosity_matched",
            "LJ_ETA_FILM", "LJ_ETA_FILM_STDERR", "OMCTS_VISCOSITY_MATCHED", "BulkViscosity",
            "LJ_BULK_VISCOSITIES", "lj_bulk_viscosity"]


# ---------------------------------------------------------------------------
# Units of a measured column
# ---------------------------------------------------------------------------
# A trace file's column may be in any unit: µN, nm, ms (an SFB), Å and fs (LAMMPS
# metal units), ε/σ and τ (LJ).  :func:`column_factor` turns a unit's text into
# the factor that brings the column's numbers into the trace's unit system (SI
# base units, or LJ units): SI to SI is the prefixes' arithmetic; LJ to SI and SI
# to LJ go through an :class:`LJUnits` mapping (default :data:`OMCTS`).
#
# A unit's text is a product of symbols, each with an optional SI prefix and
# power, divided by more: ``uN``, ``µm/s``, ``N/m``, ``kcal/mol/Å``,
# ``epsilon/sigma``, ``ε/k_B``.  SI symbols carry dimensions as exponents of
# (kg, m, s, K, mol); LJ symbols as exponents of (σ, ε, m) as in _DIMENSIONS, plus
# one of k_B for ε/k_B (a temperature).

#: The SI prefixes accepted before a symbol (``u`` and ``µ``/``μ`` are micro).
SI_PREFIXES: dict[str, float] = {
    "G": 1e9, "M": 1e6, "k": 1e3, "c": 1e-2, "m": 1e-3, "u": 1e-6, "µ": 1e-6, "μ": 1e-6,
    "n": 1e-9, "p": 1e-12, "f": 1e-15, "a": 1e-18}

# symbol -> (SI factor, exponents of kg, m, s, K, mol, prefix allowed)
_SI_SYMBOLS: dict[str, tuple[float, tuple[int, ...], bool]] = {
    "m": (1.0, (0, 1, 0, 0, 0), True),
    "s": (1.0, (0, 0, 1, 0, 0), True),
    "g": (1e-3, (1, 0, 0, 0, 0), True),
    "N": (1.0, (1, 1, -2, 0, 0), True),
    "J": (1.0, (1, 2, -2, 0, 0), True),
    "Pa": (1.0, (1, -1, -2, 0, 0), True),
    "K": (1.0, (0, 0, 0, 1, 0), False),
    "eV": (constants.eV, (1, 2, -2, 0, 0), True),
    "cal": (constants.calorie, (1, 2, -2, 0, 0), True),
    "mol": (1.0, (0, 0, 0, 0, 1), False),
    "Å": (1e-10, (0, 1, 0, 0, 0), False),
    "angstrom": (1e-10, (0, 1, 0, 0, 0), False),
    "min": (60.0, (0, 0, 1, 0, 0), False),
    "h": (3600.0, (0, 0, 1, 0, 0), False),
}
# symbol -> exponents of sigma, epsilon, m, k_B (LJ units take no prefix)
_LJ_SYMBOLS: dict[str, tuple[float, ...]] = {
    "σ": (1, 0, 0, 0), "sigma": (1, 0, 0, 0),
    "ε": (0, 1, 0, 0), "epsilon": (0, 1, 0, 0),
    "τ": (1, -0.5, 0.5, 0), "tau": (1, -0.5, 0.5, 0),
    "k_B": (0, 0, 0, 1), "kB": (0, 0, 0, 1),
}

#: Example units of each quantity a trace column has, for messages.
UNIT_EXAMPLES: dict[str, tuple[str, ...]] = {
    "time": ("s", "ms", "us", "ns", "ps", "fs", "min", "tau"),
    "length": ("m", "mm", "um", "nm", "Å", "sigma"),
    "force": ("N", "mN", "uN", "nN", "pN", "eV/Å", "kcal/mol/Å", "epsilon/sigma"),
    "velocity": ("m/s", "um/s", "nm/s", "Å/fs", "sigma/tau"),
    "energy": ("J", "nJ", "eV", "kcal/mol", "epsilon"),
    "temperature": ("K", "epsilon/k_B"),
}


@dataclass(frozen=True)
class Unit:
    """A parsed unit: its system (``si`` or ``lj``), its SI factor (SI units: the SI
    value of 1 of it; LJ units: 1) and its dimensions (SI: exponents of kg, m, s, K,
    mol; LJ: of σ, ε, m, k_B)."""

    text: str
    system: str
    factor: float
    dimensions: tuple

    def dimension_of(self, quantity: str) -> bool:
        """Whether this unit measures ``quantity`` (a key of :data:`QUANTITIES`)."""
        return self.dimensions == _quantity_dimensions(quantity, self.system)


def _quantity_dimensions(quantity: str, system: str) -> tuple:
    if quantity not in _DIMENSIONS:
        raise ValueError(f"unknown quantity {quantity!r}; allowed: {', '.join(QUANTITIES)}")
    if quantity == "temperature":
        return (0, 0, 0, 1, 0) if system == "si" else (0, 1, 0, -1)
    a, b, c = _DIMENSIONS[quantity]
    if system == "lj":
        return (a, b, c, 0)
    # sigma -> m, epsilon -> kg m^2 s^-2, mass -> kg
    return (b + c, a + 2 * b, -2 * b, 0, 0)


def _symbol(token: str, text: str):
    """(system, factor, dimensions) of one symbol with its prefix and power."""
    power = 1
    for sup, p in (("²", 2), ("³", 3)):
        if token.endswith(sup):
            token, power = token[:-1], p
    if "^" in token:
        token, _, exp = token.partition("^")
        try:
            power = int(exp)
        except ValueError:
            raise ValueError(f"unit {text!r}: bad power {exp!r} (give e.g. m^2)") from None
    if token in _LJ_SYMBOLS:
        return "lj", 1.0, tuple(power * e for e in _LJ_SYMBOLS[token])
    if token in _SI_SYMBOLS:
        factor, dims, _ = _SI_SYMBOLS[token]
        return "si", factor ** power, tuple(power * e for e in dims)
    for symbol, (factor, dims, prefixable) in _SI_SYMBOLS.items():
        prefix = token[:-len(symbol)]
        if prefixable and token.endswith(symbol) and prefix in SI_PREFIXES:
            return "si", (SI_PREFIXES[prefix] * factor) ** power, tuple(power * e for e in dims)
    raise ValueError(f"unit {text!r}: unknown symbol {token!r} (SI symbols m, s, g, N, J, Pa, "
                     f"K, eV, cal, mol, Å, min, h with a prefix {', '.join(SI_PREFIXES)}; "
                     "LJ: sigma σ, epsilon ε, tau τ, k_B)")


def parse_unit(text: str) -> Unit:
    """The :class:`Unit` of ``text``: symbols with optional SI prefix and power, joined
    by ``*`` or ``·`` and divided by ``/``.

    Raises
    ------
    ValueError
        An empty unit, an unknown symbol, or SI and LJ symbols mixed.

    Examples
    --------
    >>> parse_unit("uN").factor, parse_unit("kcal/mol").dimensions
    (1e-06, (1.0, 2.0, -2.0, 0.0, 0.0))
    >>> parse_unit("epsilon/sigma").system, parse_unit("µN").dimension_of("force")
    ('lj', True)
    """
    raw = str(text).strip()
    if not raw:
        raise ValueError("empty unit")
    symbols = []
    for i, part in enumerate(raw.split("/")):
        tokens = part.replace("·", "*").split("*")
        if any(not t.strip() for t in tokens):
            raise ValueError(f"unit {raw!r}: an empty symbol (write e.g. N/m, kcal/mol/Å)")
        symbols += [(1 if i == 0 else -1, *_symbol(t.strip(), raw)) for t in tokens]
    systems = {system for _, system, _, _ in symbols}
    if len(systems) > 1:
        raise ValueError(f"unit {raw!r}: mixes SI and LJ symbols")
    system = systems.pop()
    factor, dims = 1.0, [0.0] * len(symbols[0][3])
    for sign, _, f, d in symbols:
        factor *= f ** sign
        dims = [x + sign * e for x, e in zip(dims, d)]
    if system == "si":
        # a mole counts particles: per mole is per N_A of them (kcal/mol is an energy)
        factor *= constants.N_A ** dims[4]
        dims[4] = 0.0
    return Unit(raw, system, factor, tuple(float(e) for e in dims))


def column_factor(text: str, quantity: str, system: str,
                  units: LJUnits = OMCTS) -> float:
    """The factor that turns numbers in unit ``text`` of ``quantity`` into the unit
    system ``system`` (``"si"``: SI base units; ``"lj"``: LJ units), through
    ``units`` when the unit is of the other system.

    Raises
    ------
    ValueError
        An unreadable unit, or one that does not measure ``quantity``; the message
        lists units that do.

    Examples
    --------
    >>> column_factor("uN", "force", "si"), column_factor("ms", "time", "si")
    (1e-06, 0.001)
    >>> column_factor("tau", "time", "lj"), round(column_factor("ps", "time", "lj", OMCTS), 4)
    (1.0, 0.1324)
    """
    if system not in ("si", "lj"):
        raise ValueError(f"unit system {system!r}: 'si' or 'lj'")
    unit_ = parse_unit(text)
    if not unit_.dimension_of(quantity):
        examples = ", ".join(UNIT_EXAMPLES.get(quantity, ()))
        raise ValueError(f"unit {text!r} is not a {quantity.replace('_', ' ')} unit"
                         + (f" (e.g. {examples})" if examples else ""))
    if unit_.system == system:
        return unit_.factor
    if unit_.system == "lj":                      # LJ -> SI
        return units.scale(quantity)
    return unit_.factor / units.scale(quantity)   # SI -> LJ


__all__ += ["SI_PREFIXES", "UNIT_EXAMPLES", "Unit", "parse_unit", "column_factor"]
