"""The SFB check: the reduced model against Klein's OMCTS stick-slip numbers.

Klein (PRL 98, 056101 (2007); seed 004) measured one stick-slip cycle of mica
sliding across a 4-layer OMCTS film in the surface force balance (SFB) and
analysed the slip with the equation of motion (his Eq. 1)::

    M x'' + B x' = K (x0 - x),    B = A eta_eff / D,    x(0) = x'(0) = 0,

where ``x`` is the slip since the yield point y and ``x0`` the spring extension
at y (the spring end is taken fixed during the slip because τ_s ≪ τ_ss).  The
slip ends at the solidification point s after a slip Δx0.

This module does two things, each as rows of one table
(:func:`sfb_table`, ``filmfriction sfb``):

``source = "sfb-parameters"``
    Klein's own parameters (K, M, A, D, η_eff) in the reduced model
    (:class:`filmfriction.reduced_model.SpringBlock` with :class:`filmfriction.reduced_model.laws.NewtonianFilm`,
    spring end fixed, released from the extension x0): the slip time τ_s,
    the spring energy released, the viscous energy from the model's energy
    ledger, the viscous fraction, the residual kinetic energy at s, the ringing
    energy, the temperature rise of the film, the same slip with the bulk
    viscosity — each beside Klein's number.  The model's trace is
    cross-checked against Klein's closed form (his Eq. 2).
``source = "md-calibrated"`` (only with an :class:`MDCalibration`)
    The MD film's yield, re-stick and sliding stresses (LJ) converted to SI
    through :mod:`filmfriction.reduced_model.units` and scaled to Klein's contact area; its
    η_eff(γ̇) law carried to the SFB slip's shear rate; the SFB-scale slip
    of the reduced model with those parameters — beside Klein's numbers, with
    uncertainties propagated from the calibration's, however large the
    disagreement.

What is assumed (all in :data:`ASSUMPTIONS`, printed by the CLI)
------------------------------------------------------------------
* **x0 and Δx0** are not printed in Klein's text.  Two of his statements fix
  them: the film energy ΔE_f ≈ K x0 δ ≈ 1×10⁻¹⁴ J with δ ≈ 1 nm gives
  x0 = ΔE_f/(K δ) ≈ 103 nm (yield force K x0 ≈ 10 µN, yield stress
  ≈ 25 kPa), and ΔE_spring = K(x0 − Δx0/2)Δx0 ≈ 4×10⁻¹³ J then gives
  Δx0 = x0 − √(x0² − 2ΔE_spring/K) ≈ 54 nm.  Both statements are
  one-significant-figure estimates; τ_s is sensitive to x0 (ΔE_f = 0.95 or
  1.1 ×10⁻¹⁴ J give τ_s ≈ 31 or 17 ms), which is stated, not hidden.  The
  alternative reading "the overdamped slip relaxes fully, Δx0 = x0 ≈ 91 nm"
  is evaluated too (rows ``slip_time_full_relaxation_*``): it gives slip
  times of 32 ms (1 − 1/e of the slip) to 94 ms (95 %), and cannot produce
  the abrupt stick with ringing that Klein's trace shows.
* **τ_s** is Klein's definition, the time from y to s: here the time at which
  the model's slip reaches Δx0, i.e. at which the spring force has fallen
  to the re-stick level K(x0 − Δx0).  Eq. 1 has no solidification of its
  own, so s is imposed from the data; the MD path imposes it from the MD
  film's re-stick stress in the same way.
* **Temperature rise**: the viscous energy heats the film volume A·D with the
  heat capacity of bulk liquid OMCTS (Klein's note [29] makes the same
  assumption): ρ = 956 kg/m³ (25 °C supplier value; the Colonna et al. 2006
  equation of state gives 941) and c_p = 1.49 kJ/(kg·K) (441 J/(mol·K),
  the temperature derivative of the saturated-liquid enthalpy of the
  Colonna et al., Fluid Phase Equilib. 244, 193 (2006) equation of state as
  tabulated in CoolProp's D4 file, at 298 K).  No heat leaves the film during
  the slip — an upper bound.
* **Ringing energy** uses Klein's own estimate ΔE_osc ≈ M_eff v0²/2 with his
  v0 ≈ 2 a0 ν_c (a harmonic oscillation would have v0 = 2π a0 ν_c, ~10×
  more energy; noted on the row).
* **Uncertainties** of the ``sfb-parameters`` rows propagate Klein's quoted
  errors of η_eff (±4 Pa·s), A (±10 %) and D (±0.3 nm) through B = Aη/D
  (±20 %); the undetermined x0 is not in them (see above).

Braun & Tosatti's reading
--------------------------
:data:`BRAUN_TOSATTI_NOTE` — any comparison with Klein should carry it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from filmfriction.reduced_model.units import OMCTS, LJUnits

__all__ = [
    "KleinExperiment", "KLEIN", "LiquidProperties", "OMCTS_LIQUID", "SlipGeometry",
    "klein_slip_geometry", "newtonian_damping", "klein_closed_form", "SlipRun", "run_slip",
    "ringing_energy", "temperature_rise", "MDCalibration", "SFBCheck", "sfb_check",
    "sfb_table", "BRAUN_TOSATTI_NOTE", "ASSUMPTIONS", "SOURCES", "ROW_KEYS",
]

#: Keys of every table row (``note`` and ``uncertainty`` are extras to the issue's six).
ROW_KEYS = ("name", "klein", "model", "ratio", "units", "source", "uncertainty", "note")

#: The two values of a row's ``source``.
SOURCES = ("sfb-parameters", "md-calibrated")

BRAUN_TOSATTI_NOTE = (
    "Braun & Tosatti (EPL 88, 48003 (2009), 'Kinetics of stick-slip friction in boundary "
    "lubrication') simulate an earthquake-like model of the boundary film -- many contacts "
    "with a distribution of static thresholds, a delay before broken contacts re-form, "
    "elastic slider and contacts -- with parameters chosen for this SFB experiment, and "
    "explain Klein's stick-slip with a totally normal (bulk-like) lubricant viscosity. "
    "Klein's eta_eff = 27 Pa s (~1e4 x bulk) is the damping his Eq. (1) needs if all "
    "dissipation is Newtonian shear of the film; it is not a direct measurement of the "
    "film's viscosity. The sfb-parameters rows below test the internal consistency of "
    "Klein's analysis with the reduced model; they cannot decide between the two readings.")


# ---------------------------------------------------------------------------
# The experiment and the liquid
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class KleinExperiment:
    """Klein's SFB cycle on OMCTS (PRL 98, 056101 (2007), Fig. 2 and text), SI units.

    Attributes
    ----------
    spring_constant : float
        Shear-spring constant K, N/m.
    mass : float
        Mass M of the moving surface and its mount, kg.
    contact_area, contact_area_err : float
        Contact area A (JKR at 42 µN) and its error, m².
    film_thickness, film_thickness_err : float
        Film thickness D (n = 4 layers) and its error, m.
    eta_eff, eta_eff_err : float
        Effective viscosity fitted to the slip with Eq. (2), Pa·s.
    eta_bulk : float
        Bulk OMCTS viscosity at room temperature, Pa·s.
    load : float
        Normal load, N.
    slip_time : float
        τ_s, time from yield y to solidification s, s.
    cycle_time : float
        τ_ss, time per stick-slip cycle, s.
    spring_energy_released : float
        ΔE_spring = K(x0 − Δx0/2)Δx0, J.
    film_energy, film_energy_length : float
        ΔE_f ≈ K x0 δ (J) with δ (m): energy stored in the film before yield.
    ringing_frequency, ringing_amplitude, ringing_mass : float
        ν_c (Hz), a0 (m) and M_eff (kg) of the ringing after s.
    ringing_energy : float
        ΔE_osc, J.
    viscous_fraction : float
        Share of the dissipation that is viscous heating during slip ("of
        order 90 % or more": a lower bound).
    temperature_rise : float
        Film temperature rise per cycle (note [29]), K.
    """

    spring_constant: float = 97.0
    mass: float = 1.47e-3
    contact_area: float = 4.0e-10
    contact_area_err: float = 0.4e-10
    film_thickness: float = 3.5e-9
    film_thickness_err: float = 0.3e-9
    eta_eff: float = 27.0
    eta_eff_err: float = 4.0
    eta_bulk: float = 2.5e-3
    load: float = 42e-6
    slip_time: float = 25e-3
    cycle_time: float = 1.0
    spring_energy_released: float = 4e-13
    film_energy: float = 1e-14
    film_energy_length: float = 1e-9
    ringing_frequency: float = 45.0
    ringing_amplitude: float = 12e-9
    ringing_mass: float = 15e-3
    ringing_energy: float = 1e-14
    viscous_fraction: float = 0.9
    temperature_rise: float = 0.6

    @property
    def damping(self) -> float:
        """B = A η_eff / D, N·s/m."""
        return newtonian_damping(self.contact_area, self.eta_eff, self.film_thickness)

    @property
    def damping_rel_err(self) -> float:
        """Relative error of B from those of η_eff, A and D (independent, in quadrature)."""
        return math.sqrt((self.eta_eff_err / self.eta_eff) ** 2
                         + (self.contact_area_err / self.contact_area) ** 2
                         + (self.film_thickness_err / self.film_thickness) ** 2)


#: Klein's numbers as printed.
KLEIN = KleinExperiment()


@dataclass(frozen=True)
class LiquidProperties:
    """Bulk liquid properties used for the film's heat capacity (SI).

    Attributes
    ----------
    density : float
        kg/m³.
    heat_capacity : float
        Specific isobaric heat capacity, J/(kg·K).
    source : str
    """

    density: float
    heat_capacity: float
    source: str = ""

    @property
    def volumetric_heat_capacity(self) -> float:
        """ρ c_p, J/(m³·K)."""
        return self.density * self.heat_capacity


#: Bulk liquid OMCTS near 25 °C (see the module docstring for the sources).
OMCTS_LIQUID = LiquidProperties(
    density=956.0, heat_capacity=1490.0,
    source=("rho = 956 kg/m3 (25 C, supplier value; Colonna et al. 2006 EOS: 941); "
            "c_p = 1.49 kJ/(kg K) = 441 J/(mol K), d h_sat,liq/dT at 298 K from the "
            "Colonna et al. (Fluid Phase Equilib. 244, 193 (2006)) EOS, CoolProp D4"))


@dataclass(frozen=True)
class SlipGeometry:
    """Spring extension at yield and slip distance of the SFB cycle (SI).

    Attributes
    ----------
    x0 : float
        Spring extension at the yield point y, m.
    slip_distance : float
        Δx0, slip from y to s, m.
    assumption : str
        ``"film-energy"`` or ``"full-relaxation"``.
    derivation : str
        How the numbers follow from Klein's text.
    """

    x0: float
    slip_distance: float
    assumption: str
    derivation: str

    def restick_force(self, stiffness: float) -> float:
        """Spring force at s, K(x0 − Δx0), N."""
        return stiffness * (self.x0 - self.slip_distance)


def klein_slip_geometry(experiment: KleinExperiment = KLEIN,
                        assumption: str = "film-energy") -> SlipGeometry:
    """Derive x0 and Δx0 from Klein's energy statements.

    Parameters
    ----------
    experiment : KleinExperiment
    assumption : {"film-energy", "full-relaxation"}
        ``"film-energy"``: x0 = ΔE_f/(K δ) from Klein's ΔE_f ≈ K x0 δ, then Δx0
        from ΔE_spring = K(x0 − Δx0/2)Δx0 (the smaller root: the slip stops
        before the spring is relaxed).  ``"full-relaxation"``: the overdamped
        slip relaxes fully, Δx0 = x0 = √(2ΔE_spring/K).

    Returns
    -------
    SlipGeometry

    Raises
    ------
    ValueError
        For an unknown assumption, or if ΔE_f is too small for x0 to store
        ΔE_spring (K x0²/2 < ΔE_spring).
    """
    K = experiment.spring_constant
    E = experiment.spring_energy_released
    if assumption == "film-energy":
        x0 = experiment.film_energy / (K * experiment.film_energy_length)
        disc = x0 * x0 - 2.0 * E / K
        if disc < 0.0:
            raise ValueError(
                f"film-energy assumption: x0 = dE_f/(K delta) = {x0:.3g} m stores only "
                f"{0.5 * K * x0 * x0:.3g} J < dE_spring = {E:.3g} J; no slip distance fits")
        dx = x0 - math.sqrt(disc)
        how = (f"x0 = dE_f/(K delta) = {experiment.film_energy:.2g} J / ({K:g} N/m x "
               f"{experiment.film_energy_length:.2g} m) = {x0 * 1e9:.1f} nm; "
               f"dx0 = x0 - sqrt(x0^2 - 2 dE_spring/K) = {dx * 1e9:.1f} nm "
               f"(dE_spring = {E:.2g} J)")
    elif assumption == "full-relaxation":
        x0 = dx = math.sqrt(2.0 * E / K)
        how = (f"dx0 = x0 = sqrt(2 dE_spring/K) = {x0 * 1e9:.1f} nm "
               "(the overdamped slip relaxes the spring fully)")
    else:
        raise ValueError(f"assumption = {assumption!r}: allowed values are "
                         "'film-energy', 'full-relaxation'")
    return SlipGeometry(x0=x0, slip_distance=dx, assumption=assumption, derivation=how)


def newtonian_damping(area: float, viscosity: float, thickness: float) -> float:
    """B = A η / D of a Newtonian film with no-slip walls (Klein's damping), N·s/m."""
    return area * viscosity / thickness


def klein_closed_form(t, x0: float, mass: float, stiffness: float, damping: float) -> np.ndarray:
    """Klein's Eq. (2): x(t) = x0[1 − e^(−t/τ0){cosh(ωt/τ0) + sinh(ωt/τ0)/ω}].

    τ0 = 2M/B, ω = (1 − 4MK/B²)^½.  Evaluated as two decaying exponentials
    (the printed cosh/sinh form overflows for t ≫ τ0 in the overdamped case);
    complex ω covers the underdamped case (bulk viscosity), where the
    same expression is the damped cosine.

    Parameters
    ----------
    t : array_like
        Time since the yield point, s.
    x0, mass, stiffness, damping : float
        Spring extension at yield (m), M (kg), K (N/m), B (N·s/m).

    Returns
    -------
    numpy.ndarray
        Slip x(t), m.
    """
    t = np.asarray(t, dtype=float)
    tau0 = 2.0 * mass / damping
    w = np.sqrt(complex(1.0 - 4.0 * mass * stiffness / damping**2))
    if abs(w) < 1e-12:          # critical damping: the limit of the expression
        return x0 * (1.0 - np.exp(-t / tau0) * (1.0 + t / tau0))
    slow = 0.5 * (1.0 + 1.0 / w) * np.exp(-(1.0 - w) * t / tau0)
    fast = 0.5 * (1.0 - 1.0 / w) * np.exp(-(1.0 + w) * t / tau0)
    return x0 * (1.0 - (slow + fast).real)


# ---------------------------------------------------------------------------
# One slip in the reduced model
# ---------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SlipRun:
    """One slip from the yield point, computed with the reduced model (SI).

    Attributes
    ----------
    label : str
    t, x, v, spring_force : numpy.ndarray
        The model's trace from y (t = 0, x = 0) to the end of the run (past s).
    x0 : float
        Spring extension at y, m.
    slip_time : float
        τ_s: time from y to s, s (``nan`` if s was not reached).
    slip_distance : float
        Slip at s, m.
    spring_energy_released : float
        K x0²/2 − K(x0 − Δx)²/2 from y to s, J.
    viscous_energy : float
        Friction dissipation from the model's energy ledger from y to s, J.
    kinetic_energy_at_stick : float
        M v(s)²/2, J: what Eq. (1) leaves for the ringing.
    peak_velocity : float
        Largest slip velocity before s, m/s.
    ledger_closure : float
        The model's energy-ledger closure (relative).
    end_rule : str
        How s was found.
    """

    label: str
    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    spring_force: np.ndarray
    x0: float
    slip_time: float
    slip_distance: float
    spring_energy_released: float
    viscous_energy: float
    kinetic_energy_at_stick: float
    peak_velocity: float
    ledger_closure: float
    end_rule: str

    @property
    def viscous_fraction(self) -> float:
        """Viscous share of the energy dissipated per cycle (viscous + residual kinetic)."""
        total = self.viscous_energy + self.kinetic_energy_at_stick
        return self.viscous_energy / total if total > 0 else math.nan

    @property
    def mean_shear_rate_factor(self) -> float:
        """Mean slip velocity Δx/τ_s, m/s (divide by D for the shear rate)."""
        return self.slip_distance / self.slip_time if self.slip_time > 0 else math.nan


def _crossing(t, y, level):
    """First time at which the decreasing/increasing series ``y`` reaches ``level``
    (linear interpolation between samples), or ``None``."""
    y = np.asarray(y)
    sign0 = np.sign(y[0] - level)
    if sign0 == 0:
        return float(t[0]), 0
    hit = np.nonzero(np.sign(y - level) != sign0)[0]
    if hit.size == 0:
        return None, None
    i = int(hit[0])
    f = (level - y[i - 1]) / (y[i] - y[i - 1])
    return float(t[i - 1] + f * (t[i] - t[i - 1])), i


def run_slip(mass: float, stiffness: float, x0: float, law, *, restick_force: float | None = None,
             label: str = "", time_scale: float | None = None, samples: int = 4000,
             relaxed_fraction: float = 0.99, model_mass: float | None = None) -> SlipRun:
    """Release the block from a spring extension ``x0`` (spring end fixed) and follow the slip.

    The reduced model (:class:`filmfriction.reduced_model.SpringBlock`, ``drive="fixed"``)
    integrates the slip; this function only finds s and reads the trace and
    the energy ledger there.

    Parameters
    ----------
    mass, stiffness : float
        M (kg) and K (N/m).
    x0 : float
        Spring extension at the yield point, m (spring force K x0).
    law : reduced_model.laws.FrictionLaw
        The film during the slip.  A law with a static threshold must hold less
        than K x0 (the block is released just past yield).
    restick_force : float, optional
        Spring force at which the film re-solidifies (s).  ``None``: s is the
        model's own re-stick event, or if it never sticks (an overdamped slip
        only approaches rest) the time at which ``relaxed_fraction`` of the
        final slip is reached.
    label : str
    time_scale : float, optional
        Expected slip time scale, s (default: from the law's drag and the
        oscillator period); the run is extended until s is reached.
    samples : int
        Samples per run of the closed-form path.
    relaxed_fraction : float
        See ``restick_force``.
    model_mass : float, optional
        Mass given to the integrator instead of ``mass`` (kinetic energies
        still use ``mass``).  Used for strongly overdamped slips, whose
        inertial time 2M/B is many decades below the slip time B/K and would
        make the explicit integrator take ~B²/(MK) steps; a heavier block
        that keeps 4MK/B² ≪ 1 changes the slip by O(MK/B²).

    Returns
    -------
    SlipRun
    """
    from filmfriction.reduced_model import SpringBlock

    if restick_force is not None and not restick_force < stiffness * x0:
        raise ValueError(f"restick_force = {restick_force!r} N: must be below the yield force "
                         f"K x0 = {stiffness * x0:.4g} N (the spring relaxes during the slip)")
    period = 2.0 * math.pi * math.sqrt(mass / stiffness)
    if time_scale is None:
        drag = getattr(law, "drag_coefficient", None)
        time_scale = max(period, drag / stiffness if drag else 0.0)
    block = SpringBlock(mass=mass if model_mass is None else model_mass, stiffness=stiffness,
                        drive_velocity=0.0, drive="fixed", law=law)
    duration = 8.0 * time_scale
    for _attempt in range(12):
        r = block.simulate(duration, initial_extension=x0, samples_per_segment=samples)
        t, x, v, F = r.t, r.x, r.v, r.spring_force
        end, rule = None, ""
        if restick_force is not None:
            end, _ = _crossing(t, F, restick_force)
            rule = f"spring force falls to the re-stick level {restick_force:.4g} N"
        else:
            stops = [e for e in r.events if e.kind in ("stick", "rest")]
            if stops:
                end, rule = float(stops[0].time), f"model's own '{stops[0].kind}' event (v = 0)"
            else:
                # An overdamped slip only approaches rest, at x0 - F_k/K (F_k: the law's
                # rate-independent part).  The end is where it has covered relaxed_fraction of that.
                kinetic = law.sliding_force(0.0, law.steady_state(0.0), 1.0)
                final = x0 - float(kinetic) / stiffness
                end, _ = _crossing(t, x, relaxed_fraction * final)
                rule = (f"overdamped slip never stops: {relaxed_fraction:.0%} of the final slip "
                        f"x0 - F_k/K = {final:.4g} m")
        if end is not None:
            break
        duration *= 4.0
    else:
        end, rule = math.nan, "s not reached"
    if math.isfinite(end):
        xs = float(np.interp(end, t, x))
        vs = float(np.interp(end, t, v))
        wf = float(np.interp(end, t, r.friction_dissipation + r.damper_dissipation))
        vmax = float(np.max(np.abs(v[t <= end]))) if np.any(t <= end) else abs(vs)
    else:
        xs = vs = wf = vmax = math.nan
    released = 0.5 * stiffness * (x0**2 - (x0 - xs) ** 2)
    return SlipRun(label=label, t=t, x=x, v=v, spring_force=F, x0=x0, slip_time=end,
                   slip_distance=xs, spring_energy_released=released, viscous_energy=wf,
                   kinetic_energy_at_stick=0.5 * mass * vs * vs, peak_velocity=vmax,
                   ledger_closure=float(r.energy.closure), end_rule=rule)


def _time_to_fraction(run: SlipRun, fraction: float) -> float:
    """Time at which a fully relaxing slip has covered ``fraction`` of x0."""
    end, _ = _crossing(run.t, run.x, fraction * run.x0)
    return math.nan if end is None else end


def ringing_energy(mass: float, amplitude: float, frequency: float, convention: str = "klein") -> float:
    """Energy of the ringing after s, ΔE_osc = M_eff v0²/2.

    Parameters
    ----------
    mass, amplitude, frequency : float
        M_eff (kg), a0 (m), ν_c (Hz).
    convention : {"klein", "harmonic"}
        ``"klein"``: v0 = 2 a0 ν_c as in the paper; ``"harmonic"``: v0 = 2π a0 ν_c.
    """
    factor = {"klein": 2.0, "harmonic": 2.0 * math.pi}.get(convention)
    if factor is None:
        raise ValueError(f"convention = {convention!r}: allowed values are 'klein', 'harmonic'")
    v0 = factor * amplitude * frequency
    return 0.5 * mass * v0 * v0


def temperature_rise(energy: float, area: float, thickness: float,
                     liquid: LiquidProperties = OMCTS_LIQUID) -> float:
    """Adiabatic temperature rise of the film volume A·D heated by ``energy`` (K)."""
    return energy / (liquid.volumetric_heat_capacity * area * thickness)


# ---------------------------------------------------------------------------
# MD calibration input
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class MDCalibration:
    """What the MD film contributes to the SFB check, in LJ units.

    Stresses are in ε/σ³, viscosities in ετ/σ³, shear rates in 1/τ; each
    ``*_err`` is a one-standard-error uncertainty in the same unit (0: not
    known).  Converted to SI with the :class:`~filmfriction.reduced_model.units.LJUnits`
    passed to :func:`sfb_check`.

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
        """η(γ̇) in LJ units for γ̇ in 1/τ (the Carreau form of ShearThinningFilm)."""
        g = np.asarray(shear_rate, dtype=float)
        out = self.eta_zero * (1.0 + (g / self.onset_rate) ** 2) ** (-0.5 * self.thinning_exponent)
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


def _film_law(calibration: MDCalibration, units: LJUnits, area: float, thickness: float):
    """The MD film as a reduced-model friction law in SI at the SFB contact."""
    from filmfriction.reduced_model import laws

    eta0 = units.to_si(calibration.eta_zero, "viscosity")
    kinetic = units.to_si(calibration.sliding_stress, "stress") * area
    if calibration.thinning_exponent == 0.0:
        return laws.Coulomb(static=kinetic, kinetic=kinetic,
                            viscous=newtonian_damping(area, eta0, thickness))
    onset = units.to_si(calibration.onset_rate, "shear_rate")
    if kinetic == 0.0:
        return laws.ShearThinningFilm(viscosity=eta0, area=area, thickness=thickness,
                                      exponent=calibration.thinning_exponent, onset_rate=onset)
    return _ThinningFilmWithSliding(viscosity=eta0, area=area, thickness=thickness,
                                    exponent=calibration.thinning_exponent, onset_rate=onset,
                                    kinetic=kinetic)


def _thinning_film_with_sliding_class():
    # Defined lazily so that importing this module does not import the model.
    from filmfriction.reduced_model import laws

    @dataclass(frozen=True)
    class ThinningFilmWithSliding(laws.ShearThinningFilm):
        """ShearThinningFilm plus a constant sliding force (holds it at rest)."""

        kinetic: float = 0.0

        def sliding_force(self, speed, state, normal_load):
            return self.kinetic + super().sliding_force(speed, state, normal_load)

        def friction(self, s, state, normal_load):
            return (math.copysign(self.kinetic, s) if s else 0.0) + super().friction(s, state, normal_load)

        def static_force(self, state, normal_load):
            return self.kinetic

    return ThinningFilmWithSliding


def _ThinningFilmWithSliding(**kwargs):
    return _thinning_film_with_sliding_class()(**kwargs)


# ---------------------------------------------------------------------------
# The table
# ---------------------------------------------------------------------------
def _row(name, klein, model, units_, source, note="", uncertainty=None) -> dict:
    def clean(v):
        if v is None:
            return None
        v = float(v)
        return v if math.isfinite(v) else None
    klein, model = clean(klein), clean(model)
    ratio = model / klein if (klein not in (None, 0.0) and model is not None) else None
    if uncertainty is not None:
        lo, hi = (clean(u) for u in uncertainty)
        uncertainty = None if lo is None or hi is None else [min(lo, hi), max(lo, hi)]
    return {"name": name, "klein": klein, "model": model, "ratio": ratio, "units": units_,
            "source": source, "uncertainty": uncertainty, "note": note}


@dataclass(frozen=True, eq=False)
class SFBCheck:
    """Everything :func:`sfb_check` computed: rows, slips, assumptions.

    Attributes
    ----------
    rows : list of dict
        The table (keys :data:`ROW_KEYS`).
    geometry : SlipGeometry
        x0 and Δx0 used for Klein's slip.
    slips : dict of str -> SlipRun
        ``"klein"`` (η_eff), ``"bulk"`` (η_bulk), ``"full_relaxation"``, and
        ``"md"`` when calibrated: traces for the report's figure.
    closed_form_deviation, ode_deviation : float
        Largest |model − Eq. (2)| over Klein's slip, relative to x0, for the
        model's closed-form path and for its ODE path.
    notes : tuple of str
        Assumptions and readings (Braun & Tosatti last).
    units : LJUnits
    """

    rows: list
    geometry: SlipGeometry
    slips: dict
    closed_form_deviation: float
    ode_deviation: float
    notes: tuple
    units: LJUnits = OMCTS
    experiment: KleinExperiment = KLEIN

    def row(self, name: str, source: str = "sfb-parameters") -> dict:
        """The row called ``name`` from ``source``."""
        for r in self.rows:
            if r["name"] == name and r["source"] == source:
                return r
        raise KeyError(f"no row {name!r} with source {source!r}")


ASSUMPTIONS = (
    "x0 (spring extension at yield) from Klein's dE_f ~ K x0 delta ~ 1e-14 J with delta ~ 1 nm; "
    "slip distance dx0 from dE_spring = K(x0 - dx0/2) dx0 ~ 4e-13 J. Both are one-figure "
    "estimates in the paper; slip_time is sensitive to x0 (see slip_time's note).",
    "tau_s is Klein's definition, the time from yield y to solidification s; in the model s is "
    "where the slip reaches dx0 (spring force back down to K(x0 - dx0)). Eq. (1) has no "
    "solidification of its own, so s is imposed from the data (md path: from the MD re-stick stress).",
    "Spring end fixed during the slip (tau_s << tau_ss), as in Klein's Eq. (1).",
    "Temperature rise: viscous energy into the film volume A D, bulk-liquid OMCTS heat capacity "
    "(rho c_p = 956 kg/m3 x 1.49 kJ/(kg K)), no heat loss during the slip (upper bound).",
    "Ringing energy with Klein's v0 = 2 a0 nu_c (a harmonic v0 = 2 pi a0 nu_c gives ~10x more).",
    "Uncertainty intervals of sfb-parameters rows: B = A eta/D at +/-1 sigma from Klein's errors "
    "(eta +/-4 Pa s, A +/-10 %, D +/-0.3 nm -> +/-20 %); the x0 ambiguity is not included.",
)


def sfb_check(calibration=None, units: LJUnits = OMCTS, experiment: KleinExperiment = KLEIN,
              liquid: LiquidProperties = OMCTS_LIQUID) -> SFBCheck:
    """Run the SFB check.

    Parameters
    ----------
    calibration : MDCalibration, dict or object with its fields, optional
        The MD film in LJ units; adds the ``md-calibrated`` rows.
    units : LJUnits
        LJ ↔ SI conversion for the calibration (default OMCTS).
    experiment : KleinExperiment
        Klein's numbers (override to test sensitivity).
    liquid : LiquidProperties
        Heat capacity for the temperature rise.

    Returns
    -------
    SFBCheck
    """
    from filmfriction.reduced_model import SpringBlock, laws

    ex = experiment
    K, M, A, D = ex.spring_constant, ex.mass, ex.contact_area, ex.film_thickness
    geo = klein_slip_geometry(ex, "film-energy")
    F_s = geo.restick_force(K)
    src = "sfb-parameters"

    def klein_run(eta, label, restick=F_s, x0=geo.x0):
        law = laws.NewtonianFilm(viscosity=eta, area=A, thickness=D)
        return run_slip(M, K, x0, law, restick_force=restick, label=label)

    main = klein_run(ex.eta_eff, "Klein parameters, eta_eff")
    dB = ex.damping_rel_err
    lo = klein_run(ex.eta_eff * (1 - dB), "B - 1 sigma")
    hi = klein_run(ex.eta_eff * (1 + dB), "B + 1 sigma")
    bulk = klein_run(ex.eta_bulk, "bulk viscosity")
    full_geo = klein_slip_geometry(ex, "full-relaxation")
    full = klein_run(ex.eta_eff, "full relaxation", restick=None, x0=full_geo.x0)

    # Cross-check of the model's slip against Klein's Eq. (2) over the slip (and beyond).
    # The model solves a Newtonian film in closed form; its ODE path (DOP853, event-driven
    # stick) is an independent integrator of the same equation: compare both with Eq. (2).
    closed = klein_closed_form(main.t, main.x0, M, K, ex.damping)
    deviation = float(np.max(np.abs(main.x - closed)) / main.x0)
    ode = SpringBlock(mass=M, stiffness=K, drive_velocity=0.0, drive="fixed",
                      law=laws.NewtonianFilm(viscosity=ex.eta_eff, area=A, thickness=D)).simulate(
        float(main.t[-1]), initial_extension=geo.x0, method="ode")
    ode_deviation = float(np.max(np.abs(ode.x - klein_closed_form(ode.t, geo.x0, M, K, ex.damping)))
                          / geo.x0)

    def unc(attr):
        return (getattr(lo, attr), getattr(hi, attr))

    heat = lambda run: temperature_rise(run.viscous_energy, A, D, liquid)  # noqa: E731
    sens = []
    for e_f in (0.95e-14, 1.1e-14):
        g = klein_slip_geometry(replace(ex, film_energy=e_f))
        r = klein_run(ex.eta_eff, "sensitivity", restick=g.restick_force(K), x0=g.x0)
        sens.append(f"dE_f = {e_f:.3g} J -> x0 = {g.x0 * 1e9:.0f} nm, tau_s = {r.slip_time * 1e3:.1f} ms")
    ring = ringing_energy(ex.ringing_mass, ex.ringing_amplitude, ex.ringing_frequency)
    ring_h = ringing_energy(ex.ringing_mass, ex.ringing_amplitude, ex.ringing_frequency, "harmonic")

    rows = [
        _row("slip_time", ex.slip_time, main.slip_time, "s", src,
             f"time for the model's slip (eta_eff = {ex.eta_eff:g} Pa s, B = {ex.damping:.3g} N s/m) "
             f"to reach dx0 = {geo.slip_distance * 1e9:.1f} nm from x0 = {geo.x0 * 1e9:.1f} nm; "
             f"sensitivity to x0: {'; '.join(sens)}", unc("slip_time")),
        _row("spring_energy_released", ex.spring_energy_released, main.spring_energy_released, "J", src,
             "K x0^2/2 - K (x0 - x(tau_s))^2/2 in the model; equals Klein's value by construction "
             "(dx0 was derived from it), a check of the slip end only"),
        _row("viscous_energy", ex.spring_energy_released, main.viscous_energy, "J", src,
             "friction dissipation from y to s in the model's energy ledger; Klein: "
             "dE_viscous ~ dE_spring ~ 4e-13 J", unc("viscous_energy")),
        _row("viscous_fraction", ex.viscous_fraction, main.viscous_fraction, "1", src,
             "viscous / (viscous + kinetic energy left at s) in the model; Klein: 'of order 90 % "
             "or more' (a lower bound)", unc("viscous_fraction")),
        _row("residual_kinetic_energy", ex.ringing_energy, main.kinetic_energy_at_stick, "J", src,
             f"M v(s)^2/2, the only source of ringing Eq. (1) has (v(s) = "
             f"{math.sqrt(2 * main.kinetic_energy_at_stick / M) * 1e6:.2f} um/s); Klein: the observed "
             "ringing dE_osc ~ 1e-14 J, which he attributes to the film energy dE_f, not to Eq. (1)",
             unc("kinetic_energy_at_stick")),
        _row("ringing_energy", ex.ringing_energy, ring, "J", src,
             f"M_eff (2 a0 nu_c)^2 / 2 with a0 = {ex.ringing_amplitude * 1e9:g} nm, nu_c = "
             f"{ex.ringing_frequency:g} Hz, M_eff = {ex.ringing_mass * 1e3:g} g (Klein's v0 = 2 a0 nu); "
             f"with v0 = 2 pi a0 nu: {ring_h:.2g} J"),
        _row("temperature_rise", ex.temperature_rise, heat(main), "K", src,
             f"viscous energy / (rho c_p A D), film volume {A * D:.2g} m3, bulk liquid OMCTS "
             f"rho c_p = {liquid.volumetric_heat_capacity:.3g} J/(m3 K) ({liquid.source}); "
             f"Klein's 0.6 C implies rho c_p ~ {ex.spring_energy_released / (ex.temperature_rise * A * D):.2g}",
             (heat(lo), heat(hi))),
        _row("inertial_slip_time", ex.slip_time, bulk.slip_time, "s", src,
             f"same slip with the bulk viscosity {ex.eta_bulk:g} Pa s (B = "
             f"{newtonian_damping(A, ex.eta_bulk, D):.3g} N s/m, underdamped): time to cover dx0, "
             "beside the observed tau_s; Klein's dotted curve in Fig. 2(c), no number in the text"),
        _row("inertial_peak_slip", None, float(np.max(bulk.x)), "m", src,
             f"largest slip of the bulk-viscosity run if nothing stopped it (~2 x0 = "
             f"{2 * geo.x0 * 1e9:.0f} nm: inertial overshoot); no Klein number"),
        _row("inertial_residual_kinetic_energy", ex.ringing_energy, bulk.kinetic_energy_at_stick, "J", src,
             "kinetic energy at s with bulk viscosity: what a bulk-viscosity slip would hand to the "
             "ringing; beside Klein's observed dE_osc"),
        _row("slip_time_full_relaxation_63", ex.slip_time, _time_to_fraction(full, 1 - math.exp(-1)), "s", src,
             f"alternative reading: dx0 = x0 = {full_geo.x0 * 1e9:.1f} nm (full relaxation); time to "
             "1 - 1/e of the slip (~ B/K)"),
        _row("slip_time_full_relaxation_95", ex.slip_time, _time_to_fraction(full, 0.95), "s", src,
             "alternative reading, time to 95 % of the fully relaxed slip"),
    ]

    slips = {"klein": main, "bulk": bulk, "full_relaxation": full}
    notes = list(ASSUMPTIONS) + [f"slip geometry: {geo.derivation}",
                                 f"model vs Klein's Eq. (2): max |dx|/x0 = {deviation:.1e} (closed-form "
                                 f"path), {ode_deviation:.1e} (ODE path)"]

    if calibration is not None:
        md_rows, md_run, md_notes = _md_rows(MDCalibration.coerce(calibration), units, ex, geo, liquid)
        rows += md_rows
        slips["md"] = md_run
        notes += md_notes
    notes.append(BRAUN_TOSATTI_NOTE)
    return SFBCheck(rows=rows, geometry=geo, slips=slips, closed_form_deviation=deviation,
                    ode_deviation=ode_deviation, notes=tuple(notes), units=units, experiment=ex)


def _md_quantities(cal: MDCalibration, units: LJUnits, ex: KleinExperiment, shear_rate_si: float,
                   liquid: LiquidProperties) -> tuple[dict, SlipRun]:
    """SI quantities of the MD-calibrated SFB slip (one evaluation; used for the errors too)."""
    K, M, A, D = ex.spring_constant, ex.mass, ex.contact_area, ex.film_thickness
    tau_y = units.to_si(cal.yield_stress, "stress")
    x0 = tau_y * A / K
    restick = None if cal.restick_stress is None else units.to_si(cal.restick_stress, "stress") * A
    law = _film_law(cal, units, A, D)
    eta_rate = units.to_si(cal.eta(units.from_si(shear_rate_si, "shear_rate")), "viscosity")
    # Drag of the slip at its start: the overdamped speed at which the film carries K x0.
    drag = _slip_drag(cal, units, A, D, K * x0)
    scale = max(2 * math.pi * math.sqrt(M / K), drag / K)
    model_mass = None
    if 4.0 * M * K / drag**2 < _STIFF_OVERDAMPING:
        model_mass = 0.25 * _STIFF_OVERDAMPING * drag**2 / K
    run = run_slip(M, K, x0 * (1 + 1e-9), law, restick_force=restick, label="MD-calibrated",
                   time_scale=scale, model_mass=model_mass)
    if model_mass is not None:
        run = replace(run, end_rule=run.end_rule + f"; strongly overdamped (4MK/B^2 = "
                      f"{4 * M * K / drag**2:.1e}): integrated with mass {model_mass:.3g} kg, "
                      f"error O({_STIFF_OVERDAMPING:g})")
    q = {
        "yield_stress": tau_y,
        "static_force": tau_y * A,
        "restick_stress": None if restick is None else restick / A,
        "sliding_stress": units.to_si(cal.sliding_stress, "stress"),
        "eta_eff": eta_rate,
        "slip_time": run.slip_time,
        "slip_distance": run.slip_distance,
        "spring_energy_released": run.spring_energy_released,
        "viscous_energy": run.viscous_energy,
        "viscous_fraction": run.viscous_fraction,
        "temperature_rise": temperature_rise(run.viscous_energy, A, D, liquid),
    }
    return q, run


#: Below this 4MK/B² a slip is integrated with a heavier block (see run_slip's model_mass).
_STIFF_OVERDAMPING = 1e-3


def _slip_drag(cal: MDCalibration, units: LJUnits, area: float, thickness: float, force: float) -> float:
    """Effective drag force/velocity of the film when it carries ``force`` in steady sliding (SI)."""
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


def _md_rows(cal: MDCalibration, units: LJUnits, ex: KleinExperiment, geo: SlipGeometry,
             liquid: LiquidProperties):
    K, A, D = ex.spring_constant, ex.contact_area, ex.film_thickness
    src = "md-calibrated"
    # Klein's slip shear rate: mean slip velocity dx0/tau_s over the gap (~6e2 1/s)
    rate = geo.slip_distance / ex.slip_time / D
    rate_lj = units.from_si(rate, "shear_rate")
    q, run = _md_quantities(cal, units, ex, rate, liquid)

    # One-at-a-time +/-1 sigma perturbations, combined in quadrature (log space for positive values).
    perturbed = []
    for name in ("yield_stress", "eta_zero", "thinning_exponent", "onset_rate", "restick_stress",
                 "sliding_stress"):
        err = getattr(cal, name + "_err")
        value = getattr(cal, name)
        if not err or value is None:
            continue
        pair = []
        for sign in (-1.0, 1.0):
            new = value + sign * err
            try:
                c = replace(cal, **{name: new})
                pair.append(_md_quantities(c, units, ex, rate, liquid)[0])
            except ValueError:
                continue  # the perturbed value leaves the allowed range: skip that side
        perturbed.append(pair)

    def interval(key):
        base = q[key]
        if base is None or not math.isfinite(base):
            return None
        up2 = dn2 = 0.0
        log = base > 0
        for pair in perturbed:
            devs = []
            for p in pair:
                val = p[key]
                if val is None or not math.isfinite(val) or (log and val <= 0):
                    continue
                devs.append(math.log(val / base) if log else val - base)
            up2 += max([d for d in devs if d > 0], default=0.0) ** 2
            dn2 += max([-d for d in devs if d < 0], default=0.0) ** 2
        if log:
            return (base * math.exp(-math.sqrt(dn2)), base * math.exp(math.sqrt(up2)))
        return (base - math.sqrt(dn2), base + math.sqrt(up2))

    decades = None
    if cal.shear_rate_range is not None:
        decades = math.log10(cal.shear_rate_range[0] / rate_lj)
    extrap = (f"MD law evaluated at Klein's mean slip rate dx0/(tau_s D) = {rate:.3g} 1/s = "
              f"{rate_lj:.3g} /tau" + (f", {decades:.1f} decades below the lowest MD rate"
                                       if decades is not None else ""))
    klein_restick = geo.restick_force(K) / A
    rows = [
        _row("yield_stress", geo.x0 * K / A, q["yield_stress"], "Pa", src,
             f"MD yield stress {cal.yield_stress:g} eps/sigma^3 x {units.stress:.3g} Pa; Klein: K x0/A with "
             "x0 from dE_f (not printed in the paper)", interval("yield_stress")),
        _row("static_force", geo.x0 * K, q["static_force"], "N", src,
             f"MD yield stress x Klein's contact area {A:.2g} m2 vs Klein's K x0", interval("static_force")),
    ]
    if q["restick_stress"] is not None:
        rows.append(_row("restick_stress", klein_restick, q["restick_stress"], "Pa", src,
                         "stress at which the film re-solidifies (s); Klein: K(x0 - dx0)/A",
                         interval("restick_stress")))
    rows.append(_row("sliding_stress", None, q["sliding_stress"], "Pa", src,
                     "rate-independent stress while sliding; Klein's Eq. (1) has none (purely viscous)",
                     interval("sliding_stress")))
    rows.append(_row("eta_eff", ex.eta_eff, q["eta_eff"], "Pa s", src,
                     extrap + f"; Carreau eta0 = {cal.eta_zero:g}, n = {cal.thinning_exponent:g}, "
                     f"onset {cal.onset_rate:g} /tau", interval("eta_eff")))
    if cal.shear_rate_range is not None and cal.thinning_exponent > 0:
        g_lo = cal.shear_rate_range[0]
        eta_pl = units.to_si(cal.eta(g_lo) * (rate_lj / g_lo) ** (-cal.thinning_exponent), "viscosity")
        rows.append(_row("eta_eff_power_law", ex.eta_eff, eta_pl, "Pa s", src,
                         "pure power law eta ~ rate^-n extrapolated from the lowest MD rate (no "
                         "Newtonian plateau): upper bracket of eta_eff"))
    for key, klein, unit, note in (
            ("slip_time", ex.slip_time, "s", f"SFB-scale slip of the calibrated model; end: {run.end_rule}"),
            ("slip_distance", geo.slip_distance, "m", "slip from y to s; Klein's dx0 derived from dE_spring"),
            ("spring_energy_released", ex.spring_energy_released, "J", "K x0^2/2 - K (x0 - dx)^2/2"),
            ("viscous_energy", ex.spring_energy_released, "J", "friction dissipation y -> s (model ledger)"),
            ("viscous_fraction", ex.viscous_fraction, "1", "viscous / (viscous + kinetic energy at s)"),
            ("temperature_rise", ex.temperature_rise, "K", "viscous energy / (rho c_p A D)")):
        rows.append(_row(key, klein, q[key], unit, src, note, interval(key)))
    notes = [f"md-calibrated: units {units.name} (sigma = {units.sigma * 1e9:.3g} nm, eps/kB = "
             f"{units.temperature:.0f} K, tau = {units.tau * 1e12:.2f} ps); stresses x Klein's area; "
             f"{extrap}." + (f" Calibration source: {cal.source}" if cal.source else "")]
    return rows, run, notes


def sfb_table(calibration=None, units: LJUnits = OMCTS) -> list[dict]:
    """The SFB comparison as a list of rows (dicts with keys :data:`ROW_KEYS`).

    Parameters
    ----------
    calibration : MDCalibration, dict or compatible object, optional
        Adds the ``md-calibrated`` rows.
    units : LJUnits
        LJ ↔ SI units for the calibration (default :data:`filmfriction.reduced_model.units.OMCTS`).

    Returns
    -------
    list of dict
        ``name, klein, model, ratio, units, source`` (+ ``uncertainty``, a
        [low, high] interval of ``model`` or None, and ``note``).
    """
    return sfb_check(calibration=calibration, units=units).rows
