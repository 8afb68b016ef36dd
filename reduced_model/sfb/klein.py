"""Klein's SFB stick-slip cycle on OMCTS: his measured numbers and his slip equation.

Klein (PRL 98, 056101 (2007); seed 004) measured one stick-slip cycle of mica
sliding across a 4-layer OMCTS film in the surface force balance (SFB) and
analysed the slip with the equation of motion (his Eq. 1)::

    M x'' + B x' = K (x0 - x),    B = A eta_eff / D,    x(0) = x'(0) = 0,

where ``x`` is the slip since the yield point y and ``x0`` the spring extension
at y (the spring end is taken fixed during the slip because τ_s ≪ τ_ss).  The
slip ends at the solidification point s after a slip Δx0.  Its solution (his
Eq. 2) is the damped oscillator released from rest,
:func:`klein_closed_form`.

x0 and Δx0 are not printed in the text; :func:`klein_slip_geometry` derives
them from two of his energy statements (see its docstring and
:mod:`filmfriction.reduced_model.sfb.check` for what that assumes).

Example
-------
>>> geo = klein_slip_geometry()
>>> round(geo.x0 * 1e9, 1), round(geo.slip_distance * 1e9, 1)      # nm
(103.1, 54.3)
>>> round(KLEIN.damping, 3)                                         # B = A eta_eff / D, N s/m
3.086
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..laws import newtonian_damping
from ..integrators.oscillator import DampedOscillator

__all__ = ["KleinExperiment", "KLEIN", "SlipGeometry", "klein_slip_geometry",
           "newtonian_damping", "klein_closed_form", "ringing_energy", "BRAUN_TOSATTI_NOTE"]

BRAUN_TOSATTI_NOTE = (
    "Braun & Tosatti (EPL 88, 48003 (2009), 'Kinetics of stick-slip friction in boundary "
    "lubrication') simulate an earthquake-like model of the boundary film -- many contacts "
    "with a distribution of static thresholds, a delay before broken contacts re-form, "
    "elastic slider and contacts -- with parameters chosen for this SFB experiment, and "
    "explain Klein's stick-slip with a totally normal (bulk-like) lubricant viscosity. "
    "Klein's eta_eff = 27 Pa s (~1e4 x bulk) is the damping his Eq. (1) needs if all "
    "dissipation is Newtonian shear of the film; it is not a direct measurement of the "
    "film's viscosity. The sfb-parameters rows test the internal consistency of "
    "Klein's analysis with the reduced model; they cannot decide between the two readings.")


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

    Example
    -------
    >>> round(KleinExperiment().damping_rel_err, 3)        # B = A eta/D: +/- 20 %
    0.198
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

    Example
    -------
    >>> full = klein_slip_geometry(assumption="full-relaxation")
    >>> round(full.x0 * 1e9, 1) == round(full.slip_distance * 1e9, 1) == 90.8
    True
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


def klein_closed_form(t, x0: float, mass: float, stiffness: float, damping: float) -> np.ndarray:
    """Klein's Eq. (2): x(t) = x0[1 − e^(−t/τ0){cosh(ωt/τ0) + sinh(ωt/τ0)/ω}].

    τ0 = 2M/B, ω = (1 − 4MK/B²)^½.  This is the damped oscillator
    M e'' + B e' + K e = 0 of e = x − x0 released from rest at e(0) = −x0, and
    is evaluated by :class:`~filmfriction.reduced_model.integrators.oscillator.DampedOscillator`
    (overdamped: the slow and fast exponentials, which do not overflow for
    t ≫ τ0 as the printed cosh/sinh form does; underdamped, e.g. the bulk
    viscosity: the damped cosine; critical: the limit).

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

    Example
    -------
    >>> x = klein_closed_form([0.0, 1.0], 1e-7, KLEIN.mass, KLEIN.spring_constant, KLEIN.damping)
    >>> float(x[0]), round(float(x[1]) / 1e-7, 9)          # from rest to the relaxed spring
    (0.0, 1.0)
    """
    osc = DampedOscillator(mass=mass, damping=damping, stiffness=stiffness)
    return x0 + osc.value(np.asarray(t, dtype=float), -x0, 0.0)


def ringing_energy(mass: float, amplitude: float, frequency: float, convention: str = "klein") -> float:
    """Energy of the ringing after s, ΔE_osc = M_eff v0²/2.

    Parameters
    ----------
    mass, amplitude, frequency : float
        M_eff (kg), a0 (m), ν_c (Hz).
    convention : {"klein", "harmonic"}
        ``"klein"``: v0 = 2 a0 ν_c as in the paper; ``"harmonic"``: v0 = 2π a0 ν_c.

    Returns
    -------
    float
        J.

    Example
    -------
    >>> round(ringing_energy(KLEIN.ringing_mass, KLEIN.ringing_amplitude, KLEIN.ringing_frequency), 17)
    8.75e-15
    """
    factor = {"klein": 2.0, "harmonic": 2.0 * math.pi}.get(convention)
    if factor is None:
        raise ValueError(f"convention = {convention!r}: allowed values are 'klein', 'harmonic'")
    v0 = factor * amplitude * frequency
    return 0.5 * mass * v0 * v0
