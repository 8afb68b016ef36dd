"""Where the spring's energy goes in each stick-slip cycle (Klein, seed 004).

Per slip y → s:

``spring_released``
    ΔE_spring = K(x0 − Δx0/2)Δx0, Klein's estimate (spring end fixed).
``spring_released_exact``
    ½K(e_y² − e_s²) = (Fs² − Fb²)/(2K) from the trace's own forces.
``drive_work_slip``
    Work done by the moving spring end during the slip, ∫F dx_d (zero in
    Klein's approximation; counted here when the drive is known).
``film_dissipation``
    Work the film absorbs during the slip, from the wall's equation of motion
    M v' = F_spring − F_film − γM(v − V): ∫F_film v dt = ∫F_spring v dt − ΔKE_wall
    − ∫γM(v − V) v dt, the last term the work of an MD run's mount dashpot on
    the wall (γM = ``mount_damping``; it acts on the wall's velocity relative to
    the drive, so its work on the wall is not its heat ∫γM(v − V)² dt).
    Needs the wall velocity (column, else derivative of the wall position).
    The integral runs from 10 % of the preceding stick before y to 10 % of
    the following stick after s (the wall is at rest there, so the margin
    adds nothing but makes the result insensitive to where exactly y and s
    fall between samples).
    Without wall kinematics Klein's Eq. (1) identity is used: everything the
    spring delivers, ``spring_released_exact + drive_work_slip``, is
    dissipated viscously (``film_dissipation_method = "klein-eq1"``).
``ringing_energy``
    ΔE_osc, the oscillator energy left at re-stick.  With the wall's velocity
    and mass: Klein's M v0²/2 with v0 the largest velocity of the wall's
    oscillation after s, i.e. the largest ½M(v − v̄)² over the first quarter of
    the next stick from the wall's first reversal on (v̄ its mean: the stuck
    wall's creep), less the largest that the wall's thermal motion alone
    reaches over as many samples: the energy of the oscillation on K + k_f
    whatever its stiffness, and 0 for an overdamped approach that never
    reverses (``ringing_method = "wall-kinetic"``).  Without them, Klein's estimate from the largest ringing
    amplitude of the force, A²/(2K) (``"force-amplitude"``: it misses the
    film's share k_f of the ringing stiffness); 0 when the ringing is within
    4 σ of the noise.
``film_elastic_released``
    The stuck film's elastic energy released by the slip, (Fs² − Fb²)/(2k_f),
    with k_f its shear stiffness (from the stick ramps): the spring is not the
    only store a slip empties.
``mount_dissipation_slip``
    Heat of an MD run's mount dashpot over the slip window, ∫γM(v − V)² dt along
    x (plus ∫γM v_z² dt along z when the trace has the engine's ``mount_heat``).
``dilation_work``
    Work against the normal load, P·A·Δz of the top wall over the slip window
    (from the ``load_work`` column).
``quadrature_residual``
    Per slip: (released − accounted)/released over the slip window, with
    released = spring energy released + drive work (both ends of the drive:
    spring and mount, from the engine's columns) + ``film_elastic_released``
    and accounted = ``film_heat`` + the dashpot's heat along x + ΔKE_wall +
    ``dilation_work``.  ``film_dissipation`` is itself ∫F v − ΔKE_wall − the
    dashpot's work, so this is no physics check: it reduces to the engine's
    integrated power (``drive_work`` − ``spring_energy``) against the trace's
    sampled ∫F v dt, less V∫γM(v − V) dt.  It tests the sampling and the
    quadrature (a trace too coarse for its slips shows here), not the film.
``film_heat``
    What the film turns into heat in a slip: ``film_dissipation`` +
    ``film_elastic_released`` − ``dilation_work``.
``thermostat_heat_slip``
    Heat the thermostat removed over the slip window (MD, ``fix langevin``'s
    own tally): an independent measure of ``film_heat``, noisy by the film's
    thermal fluctuations (and short of it when the window ends before the
    film has cooled).  :func:`~filmfriction.analysis.energy.heat_check.compare_heat` tests the two against each other.
``film_heat_cycle``
    The film's heat from the mechanics over a whole cycle (y → next y, the
    window of ``thermostat_heat_cycle``): ∫F v dt − ΔKE_wall − the mount
    dashpot's work along x, less its heat along z (the engine's
    ``mount_heat`` less its x part) and the dilation work.  The film starts
    and ends the cycle stuck and cool, so no k_f is needed and no heat is
    still on its way out: :func:`~filmfriction.analysis.energy.heat_check.compare_heat` against
    ``thermostat_heat_cycle`` is the check that does not depend on the window.
``dashpot_static_bias``
    γM (V − v̄) at the end of each stick: the mount dashpot's force that the
    film carries at yield besides the spring's (the film's static force is
    Fs + this).
``thermostat_heat_cycle`` / ``ledger_residual_cycle``
    From the MD ledger columns (y → next y), when present.

Fractions as Klein reports them: ``viscous_fraction`` = E_film /
(E_film + ΔE_osc) (viscous, during the slip) and ``at_stick_fraction`` =
ΔE_osc / (E_film + ΔE_osc) (lost at the stick), with E_film = ``film_heat``
(which is ``film_dissipation`` when k_f and the dilation are not known).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import trapezoid

from filmfriction.reduced_model.cycles import CycleTable, stats as _stats

from .ledger import LEDGER_COLUMNS, ledger

__all__ = ["EnergyTable", "energy_table"]

@dataclass(frozen=True, eq=False)
class EnergyTable:
    """Per-slip energies (see the module docstring for each column)."""

    spring_released: np.ndarray
    spring_released_exact: np.ndarray
    drive_work_slip: np.ndarray
    film_dissipation: np.ndarray
    wall_ke_change: np.ndarray
    ringing_energy: np.ndarray
    viscous_fraction: np.ndarray
    at_stick_fraction: np.ndarray
    thermostat_heat_cycle: np.ndarray
    ledger_residual_cycle: np.ndarray
    film_dissipation_method: str
    # heat of an MD run's mount dashpot over the same slip window (NaN when
    # the trace has no mount_heat): the share of the released energy that is
    # neither the film's nor the ringing's
    mount_dissipation_slip: np.ndarray | None = None
    film_elastic_released: np.ndarray | None = None
    dilation_work: np.ndarray | None = None
    quadrature_residual: np.ndarray | None = None
    thermostat_heat_slip: np.ndarray | None = None
    dashpot_static_bias: np.ndarray | None = None
    film_heat: np.ndarray | None = None
    ringing_method: str = "force-amplitude"
    film_heat_cycle: np.ndarray | None = None

    _NAMES = ("spring_released", "spring_released_exact", "drive_work_slip",
              "film_dissipation", "wall_ke_change", "ringing_energy",
              "viscous_fraction", "at_stick_fraction", "thermostat_heat_cycle",
              "ledger_residual_cycle", "mount_dissipation_slip", "film_elastic_released",
              "dilation_work", "quadrature_residual", "thermostat_heat_slip",
              "dashpot_static_bias", "film_heat", "film_heat_cycle")

    def _column(self, name):
        value = getattr(self, name)
        if value is None:
            return np.full(len(self.spring_released), math.nan)
        return np.asarray(value, float)

    def summary(self, skip: int = 0) -> dict:
        """``{name: {"mean", "std", "stderr", "n"}}``, NaN ignored."""
        return {n: _stats(self._column(n)[skip:]) for n in self._NAMES}

    def as_dict(self) -> dict:
        out = {n: self._column(n).tolist() for n in self._NAMES}
        out["film_dissipation_method"] = self.film_dissipation_method
        out["ringing_method"] = self.ringing_method
        return out


def _ringing(t, f, s, stop, k, noise, fraction=0.25):
    """Oscillator energy A²/(2K), A the largest force excursion about the
    early stick ramp; 0 when A is within 4 σ of the noise."""
    hi = s + max(int(fraction * (stop - s)), 0)
    if hi - s < 4:
        return math.nan
    tt = t[s:hi] - t[s]
    coef = np.polyfit(tt, f[s:hi], 1)
    amp = float(np.max(np.abs(f[s:hi] - np.polyval(coef, tt))))
    return amp ** 2 / (2 * k) if amp > 4 * noise else 0.0


def _wall_ringing(t, v, s, stop, mass, fraction=0.25):
    """Kinetic energy of the wall's oscillation after s (see ``ringing_energy``).

    The largest ½M(v − v̄)² over the first ``fraction`` of the stick, from the
    wall's first reversal on (v̄ the stick's mean creep), less what the wall's
    thermal motion alone would reach there: ½M σ_v² · 2 ln n, the expected
    largest square of n Gaussian samples, with σ_v the velocity's scatter over
    the stick's second half.  0 when the wall never reverses (an overdamped
    approach does not ring) or rings within its thermal motion.
    """
    hi = s + max(int(fraction * (stop - s)), 0)
    if hi - s < 4:
        return math.nan
    dv = v[s:hi] - v[s:hi].mean()
    flips = np.flatnonzero(np.sign(dv[1:]) != np.sign(dv[:-1]))
    if flips.size == 0:
        return 0.0
    tail = dv[flips[0] + 1:]
    late = v[s + (stop - s) // 2:stop - (stop - s) // 10]
    thermal = float(np.var(late)) * 2.0 * math.log(max(tail.size, 2)) if late.size > 3 else 0.0
    return float(0.5 * mass * max(float(np.max(tail ** 2)) - thermal, 0.0))


def energy_table(time, spring_force, table: CycleTable, spring_constant: float, *,
                 mass: float | None = None, wall_velocity=None,
                 wall_position=None, drive_position=None,
                 drive_velocity: float | None = None, noise: float = 0.0,
                 ledger_columns: dict | None = None, mount_damping: float = 0.0,
                 film_stiffness: float | None = None, ringing: str = "auto") -> EnergyTable:
    """Energy partition of each slip in ``table``.

    Parameters
    ----------
    time, spring_force : ndarray
        The trace.
    table : CycleTable
        Slips (y, s indices, Fs, Fb, Δx0).
    spring_constant : float
        K.
    mass : float, optional
        Wall mass M (needed for the kinetic-energy term).
    wall_velocity, wall_position : ndarray, optional
        Wall kinematics; velocity preferred, else the position is
        differentiated.
    drive_position : ndarray, optional
        Spring-end position (drive work during the slip); else
        ``drive_velocity`` × time is used, else the drive is taken fixed.
    noise : float
        Noise standard deviation of the force (subtracted from the ringing).
    ledger_columns : dict, optional
        MD ledger columns (``thermostat_heat``, ``mount_heat``, ``load_work`` …) by name.
    mount_damping : float
        γM of an MD run's mount dashpot on v − V (force per velocity), 0 for none.
    film_stiffness : float, optional
        k_f of the stuck film (:func:`filmfriction.analysis.stick_ramps.stick_stiffness`).
    ringing : {"auto", "wall-kinetic", "force-amplitude"}
        How the ringing energy is measured (module text); ``auto`` takes the
        wall's kinetic energy when the wall velocity and mass are known.

    Returns
    -------
    EnergyTable
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    k = float(spring_constant)
    yi, si = table.yield_index, table.stick_index
    m = len(table)
    nan = lambda: np.full(m, math.nan)   # noqa: E731
    x0 = table.static_force / k
    dx0 = np.asarray(table.slip_distance, float)
    released = k * (x0 - dx0 / 2) * dx0
    exact = (table.static_force ** 2 - table.backward_force ** 2) / (2 * k)

    if drive_position is not None:
        xd = np.asarray(drive_position, float)
    elif drive_velocity is not None:
        xd = drive_velocity * t
    else:
        xd = None
    drive = np.zeros(m)
    if xd is not None:
        drive = np.array([trapezoid(f[y:s + 1], xd[y:s + 1]) for y, s in zip(yi, si)])

    v = None
    if wall_velocity is not None:
        v = np.asarray(wall_velocity, float)
    elif wall_position is not None:
        v = np.gradient(np.asarray(wall_position, float), t)
    film, dke, mount = nan(), nan(), nan()
    mount_x = np.zeros(m)
    cols = ledger_columns or {}
    v_drive = 0.0 if drive_velocity is None else float(drive_velocity)
    starts = np.concatenate([[0], si[:-1]])
    stops = np.concatenate([yi[1:], [t.size - 1]])
    lo = yi - ((yi - starts) // 10)
    hi = si + ((stops - si) // 10)
    if v is not None:
        method = "equation-of-motion"
        work = np.array([trapezoid(f[a:b + 1] * v[a:b + 1], t[a:b + 1])
                         for a, b in zip(lo, hi)])
        dke = 0.5 * mass * (v[hi] ** 2 - v[lo] ** 2) if mass else np.zeros(m)
        if not mass:
            method += " (no mass: ΔKE neglected)"
        film = work - dke
        if mount_damping:
            # the dashpot acts on v − V: its work on the wall, ∫γM(v − V)v, is taken off
            mount_work = np.array([trapezoid(mount_damping * (v[a:b + 1] - v_drive) * v[a:b + 1],
                                             t[a:b + 1]) for a, b in zip(lo, hi)])
            film = film - mount_work
            # heat of the dashpot along x; an MD run's mount_heat column also has the
            # dashpot along z, whose energy comes from the film's work in z (as the dilation)
            mount_x = np.array([trapezoid(mount_damping * (v[a:b + 1] - v_drive) ** 2,
                                          t[a:b + 1]) for a, b in zip(lo, hi)])
            method += " (mount dashpot's work on the wall subtracted)"
        mount = mount_x
        if "mount_heat" in cols:   # the engine's own integral, x and z
            mh = np.asarray(cols["mount_heat"], float)
            mount = mh[hi] - mh[lo]
            if not mount_damping and np.any(mount != 0):
                # a dashpot whose γM was not given: its heat stands in for its work
                film = film - mount
                method += " (mount dashpot heat subtracted: its damping was not given)"
    else:
        method = "klein-eq1"
        film = exact + drive
    ring = nan()
    if ringing not in ("auto", "wall-kinetic", "force-amplitude"):
        raise ValueError(f"ringing = {ringing!r}: allowed values are 'auto', 'wall-kinetic', "
                         "'force-amplitude'")
    kinetic_ok = v is not None and bool(mass)
    if ringing == "wall-kinetic" and not kinetic_ok:
        raise ValueError("ringing = 'wall-kinetic' needs the wall velocity (or position) and mass")
    ring_method = ("wall-kinetic" if kinetic_ok and ringing != "force-amplitude"
                   else "force-amplitude")
    for i in range(m):
        stop = yi[i + 1] if i + 1 < m else t.size
        ring[i] = (_wall_ringing(t, v, si[i], stop, mass) if ring_method == "wall-kinetic"
                   else _ringing(t, f, si[i], stop, k, noise))

    elastic = nan()
    if film_stiffness is not None and film_stiffness > 0:
        elastic = (table.static_force ** 2 - table.backward_force ** 2) / (2 * film_stiffness)
    dilation = nan()
    if "load_work" in cols:
        lw = np.asarray(cols["load_work"], float)     # −P A (z − z0)
        dilation = -(lw[hi] - lw[lo])
    bias = nan()
    if v is not None and mount_damping:
        bias = np.array([mount_damping * (v_drive - np.mean(v[max(y - (y - a) // 10, a):y + 1]))
                         for a, y in zip(starts, yi)])
    quadrature, q_slip = nan(), nan()
    film_heat = film + np.where(np.isfinite(elastic), elastic, 0.0) \
        - np.where(np.isfinite(dilation), dilation, 0.0)
    # Klein's fractions, with everything the film turns into heat in the slip
    total = film_heat + ring
    with np.errstate(invalid="ignore", divide="ignore"):
        visc_frac = film_heat / total
        stick_frac = ring / total
    if v is not None and mass and all(c in cols for c in ("spring_energy", "drive_work")):
        es = np.asarray(cols["spring_energy"], float)
        wd = np.asarray(cols["drive_work"], float)
        el = np.nan_to_num(elastic) if np.all(np.isfinite(elastic)) else np.zeros(m)
        dil = dilation if np.all(np.isfinite(dilation)) else np.zeros(m)
        mnt = mount_x
        into = (es[lo] - es[hi]) + (wd[hi] - wd[lo]) + el
        accounted = (film + el - dil) + mnt + dke + dil
        with np.errstate(invalid="ignore", divide="ignore"):
            quadrature = (into - accounted) / into
    if "thermostat_heat" in cols:
        q = np.asarray(cols["thermostat_heat"], float)
        q_slip = q[hi] - q[lo]

    heat, resid, film_cycle = nan(), nan(), nan()
    if v is not None and m > 1:
        film_cycle[:-1] = _film_heat_cycle(t, f, v, yi, mass, mount_damping, v_drive, cols)
    if m > 1 and "thermostat_heat" in cols:
        q = np.asarray(cols["thermostat_heat"], float)
        heat[:-1] = np.diff(q[yi])
    if m > 1 and all(c in cols for c in LEDGER_COLUMNS):
        r = ledger(cols)["residual"]
        resid[:-1] = np.diff(r[yi])
    return EnergyTable(released, exact, drive, film, dke, ring, visc_frac,
                       stick_frac, heat, resid, method, mount, elastic, dilation, quadrature,
                       q_slip, bias, film_heat, ring_method, film_cycle)


def _film_heat_cycle(t, f, v, yi, mass, mount_damping, v_drive, cols):
    """``film_heat_cycle`` of the cycles yi[i] → yi[i + 1] (module text)."""
    def integral(y, a, b):
        return trapezoid(y[a:b + 1], t[a:b + 1])
    out = []
    for a, b in zip(yi[:-1], yi[1:]):
        heat = integral(f * v, a, b)
        if mass:
            heat -= 0.5 * mass * (v[b] ** 2 - v[a] ** 2)
        x_heat = 0.0
        if mount_damping:
            heat -= integral(mount_damping * (v - v_drive) * v, a, b)
            x_heat = integral(mount_damping * (v - v_drive) ** 2, a, b)
        if "mount_heat" in cols:
            mh = np.asarray(cols["mount_heat"], float)
            # the engine's dashpot heat beyond its x part is the z dashpot's, fed by the film
            heat -= (mh[b] - mh[a]) - x_heat if mount_damping else mh[b] - mh[a]
        if "load_work" in cols:
            lw = np.asarray(cols["load_work"], float)
            heat += lw[b] - lw[a]          # the film's work lifting the wall: −ΔW_load
        out.append(heat)
    return np.asarray(out, float)
