"""Effective viscosity of the confined film.

Three routes:

* steady sliding — η_eff = (F/A)/γ̇ with γ̇ = V/D (:func:`steady_viscosity`);
  with a velocity profile, the shear rate inside the film and the slip at
  each wall (:func:`profile_shear`);
* across runs — η_eff ∝ γ̇^α, a power law fitted in log–log with the
  exponent's uncertainty (:func:`power_law_fit`);
* slip dynamics — Klein's slip equation M x'' + B x' = K(x_d(t) − x), with
  the spring end x_d = x0 + V t moving during the slip, fitted to the spring
  force of each slip → B → η_eff = B·D/A (:func:`fit_slip`,
  :func:`slip_viscosity`).

Nothing here converts units: inputs and outputs are in the caller's system.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import curve_fit

from filmfriction.reduced_model.cycles import CycleTable
from filmfriction.reduced_model.integrators.oscillator import DampedOscillator

__all__ = ["SteadyViscosity", "steady_viscosity", "ProfileShear", "profile_shear",
           "PowerLaw", "power_law_fit", "slip_force", "SlipFit", "fit_slip",
           "SlipViscosity", "slip_viscosity"]


# ------------------------------------------------------------------ steady

@dataclass(frozen=True)
class SteadyViscosity:
    """η_eff = (F̄/A)/(V/D) with its standard error (block averages of F)."""

    eta_eff: float
    eta_eff_stderr: float
    shear_stress: float
    shear_rate: float
    mean_force: float
    thickness: float


def block_mean(x, blocks: int = 10) -> tuple[float, float]:
    """Mean of correlated samples and its standard error from block averages.

    NaN samples are ignored; the error is NaN when there are fewer samples
    than blocks.
    """
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return math.nan, math.nan
    n = x.size // blocks
    if n < 1 or blocks < 2:
        return float(x.mean()), math.nan
    means = x[: n * blocks].reshape(blocks, n).mean(axis=1)
    return float(x.mean()), float(means.std(ddof=1) / math.sqrt(blocks))


def _block_stderr(x: np.ndarray, blocks: int = 10) -> float:
    return block_mean(x, blocks)[1]


def steady_viscosity(spring_force, area: float, velocity: float,
                     thickness, mount_damping: float = 0.0) -> SteadyViscosity:
    """Effective viscosity of steady sliding.

    In steady sliding the spring force balances the film's friction plus any
    damping of the wall that is not the film's (``mount_damping``, force per
    velocity, e.g. an MD run's mount dashpot): the film's share is
    ``F - mount_damping * V``.

    Parameters
    ----------
    spring_force : array_like
        Force samples of the steady part of the trace.
    area : float
        Contact area A.
    velocity : float
        Sliding velocity V.
    thickness : float or array_like
        Film thickness D (the mean of an array, e.g. the gap column, is used).
    mount_damping : float
        Damping of the wall outside the film (force per velocity).

    Examples
    --------
    >>> steady_viscosity(np.full(100, 2.0), area=4.0, velocity=0.5,
    ...                  thickness=1.0).eta_eff
    1.0
    """
    f = np.asarray(spring_force, float)
    d = float(np.mean(thickness))
    rate = velocity / d
    fbar = float(f.mean()) - mount_damping * velocity
    err = _block_stderr(f)
    eta = fbar / area / rate
    return SteadyViscosity(eta, err / area / rate, fbar / area, rate, fbar, d)


@dataclass(frozen=True)
class ProfileShear:
    """Shear inside the film from a time-averaged velocity profile v_x(z).

    ``shear_rate`` is the slope of a straight line fitted to v_x(z) over the
    film; ``slip_bottom`` = v_film(z_bottom) − v_bottom_wall and
    ``slip_top`` = v_top_wall − v_film(z_top), z_bottom/z_top being the
    film's outermost occupied bins.
    """

    shear_rate: float
    shear_rate_stderr: float
    slip_bottom: float
    slip_top: float
    z_bottom: float
    z_top: float


def profile_shear(z, vx, density, *, wall_velocity_bottom: float = 0.0,
                  wall_velocity_top: float, min_density: float = 0.1) -> ProfileShear:
    """Shear rate in the film and slip at each wall from v_x(z).

    Bins whose density is below ``min_density`` × max are outside the film.
    """
    z, vx, rho = (np.asarray(a, float) for a in (z, vx, density))
    inside = np.flatnonzero(rho >= min_density * rho.max())
    if inside.size < 3:
        raise ValueError("velocity profile: fewer than 3 occupied bins")
    zi, vi, wi = z[inside], vx[inside], rho[inside]
    coef, cov = np.polyfit(zi, vi, 1, w=np.sqrt(wi), cov="unscaled") if inside.size > 3 \
        else (np.polyfit(zi, vi, 1, w=np.sqrt(wi)), np.full((2, 2), np.nan))
    if inside.size > 3:
        resid = vi - np.polyval(coef, zi)
        s2 = float(np.sum(wi * resid ** 2) / (inside.size - 2))
        cov = cov * s2
    zb, zt = float(zi[0]), float(zi[-1])
    return ProfileShear(float(coef[0]), float(np.sqrt(cov[0, 0])),
                        float(np.polyval(coef, zb)) - wall_velocity_bottom,
                        wall_velocity_top - float(np.polyval(coef, zt)), zb, zt)


# ------------------------------------------------------------------ power law

@dataclass(frozen=True)
class PowerLaw:
    """η_eff = prefactor · γ̇^exponent (fitted in log–log)."""

    exponent: float
    exponent_stderr: float
    prefactor: float
    prefactor_rel_stderr: float
    n: int


def power_law_fit(shear_rate, eta, eta_stderr=None) -> PowerLaw:
    """Fit η = c·γ̇^α by weighted least squares on log η vs log γ̇.

    With ``eta_stderr`` the weights are the log-errors σ/η and the
    covariance is absolute; without, it is scaled by the residual scatter.
    Needs three or more points (two fit the line exactly: no uncertainty).

    Examples
    --------
    >>> g = np.array([1e-3, 1e-2, 1e-1, 1.0])
    >>> round(power_law_fit(g, 5 * g ** (-2 / 3)).exponent, 6)
    -0.666667
    """
    g = np.asarray(shear_rate, float)
    e = np.asarray(eta, float)
    ok = np.isfinite(g) & np.isfinite(e) & (g > 0) & (e > 0)
    if ok.sum() < 3:
        raise ValueError(f"power-law fit needs >= 3 positive points, got {int(ok.sum())}")
    lx, ly = np.log(g[ok]), np.log(e[ok])
    sigma = None
    if eta_stderr is not None:
        sigma = np.asarray(eta_stderr, float)[ok] / e[ok]
    popt, pcov = curve_fit(lambda x, a, b: a * x + b, lx, ly, sigma=sigma,
                           absolute_sigma=sigma is not None)
    perr = np.sqrt(np.diag(pcov))
    return PowerLaw(float(popt[0]), float(perr[0]), float(math.exp(popt[1])),
                    float(perr[1]), int(ok.sum()))


# ------------------------------------------------------------------ slip dynamics

def slip_force(t, spring_force_at_yield: float, damping: float, mass: float,
               spring_constant: float, drive_velocity: float = 0.0,
               wall_velocity0: float = 0.0) -> np.ndarray:
    """Spring force during a slip from Klein's equation with a moving drive.

    Solves M x'' + B x' = K(x0 + V t − x), x(0) = 0, x'(0) = v0 (x measured
    from the yield point, x0 = Fs/K) in closed form and returns
    F(t) = K(x0 + V t − x(t)).  With V = v0 = 0 this is Klein's Eq. (2).
    About the steady sliding x_p = x0 + V t − B V/K the slip is the damped
    oscillator M u'' + B u' + K u = 0
    (:class:`filmfriction.reduced_model.integrators.oscillator.DampedOscillator`).

    Examples
    --------
    >>> float(slip_force(0.0, 2.0, damping=1.0, mass=1.0, spring_constant=1.0))
    2.0
    """
    t = np.asarray(t, float)
    m, b, k, v = mass, damping, spring_constant, drive_velocity
    x0 = spring_force_at_yield / k
    # x = x_p + u,  x_p = x0 + V t − B V / K,  M u'' + B u' + K u = 0
    u0 = -x0 + b * v / k
    du0 = wall_velocity0 - v
    u = DampedOscillator(mass=m, damping=b, stiffness=k).value(t, u0, du0)
    x = x0 + v * t - b * v / k + u
    return k * (x0 + v * t - x)


@dataclass(frozen=True)
class SlipFit:
    """Klein's slip equation fitted to one slip."""

    damping: float
    damping_stderr: float
    static_force: float
    yield_time: float
    rms_residual: float
    n_points: int


def fit_slip(time, spring_force, yield_index: int, stick_index: int, *,
             mass: float, spring_constant: float, drive_velocity: float = 0.0,
             lead: int = 3) -> SlipFit:
    """Fit B (and Fs, the yield instant) of one slip to the spring force.

    The model is the stick ramp F = Fs + K V (t − t_y) before t_y and
    :func:`slip_force` after it; the data are the samples from ``lead``
    samples before the detected yield up to the detected re-stick.  The
    yield instant t_y is free within that window (with a heavy wall the
    force keeps rising after the yield while the wall accelerates, so the
    force maximum lags the yield).  B gets a
    log-spaced grid search as a start, then ``scipy.optimize.curve_fit``;
    the standard error comes from its covariance (scaled by the residuals).
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    lo = max(yield_index - lead, 0)
    hi = stick_index + 1
    tt, ff = t[lo:hi], f[lo:hi]
    if tt.size < 5:
        raise ValueError(f"slip at index {yield_index}: only {tt.size} samples")
    m, k, v = mass, spring_constant, drive_velocity
    t_ref = t[yield_index]

    def model(x, log_b, fs, ty):
        dt = x - (t_ref + ty)
        out = fs + k * v * dt
        after = dt > 0
        out[after] = slip_force(dt[after], fs, math.exp(log_b), m, k, v)
        return out

    fs0 = float(f[yield_index])
    span = t[stick_index] - t_ref
    b_crit = 2 * math.sqrt(m * k)
    grid = np.log(np.geomspace(1e-2 * b_crit, 1e4 * max(b_crit, k * span), 49))
    errs = [np.sum((model(tt, g, fs0, 0.0) - ff) ** 2) for g in grid]
    g0 = grid[int(np.argmin(errs))]
    dt_s = t[min(yield_index + 1, t.size - 1)] - t[yield_index] or span
    popt, pcov = curve_fit(model, tt, ff, p0=(g0, fs0, 0.0),
                           bounds=([grid[0] - 5, -np.inf, t[lo] - t_ref],
                                   [grid[-1] + 5, np.inf, 3 * dt_s]))
    b = math.exp(popt[0])
    rms = float(np.sqrt(np.mean((model(tt, *popt) - ff) ** 2)))
    return SlipFit(b, b * float(np.sqrt(pcov[0, 0])), float(popt[1]),
                   float(t_ref + popt[2]), rms, int(tt.size))


@dataclass(frozen=True, eq=False)
class SlipViscosity:
    """η_eff = B·D/A from each slip and their combination.

    ``eta_eff`` is the mean over slips; ``eta_eff_stderr`` the larger of the
    spread-based standard error (std/√n) and the propagated fit error
    (√Σσ_i²/n); ``eta_eff_fit_stderr`` the latter alone.
    """

    damping: np.ndarray
    damping_stderr: np.ndarray
    eta_eff_per_slip: np.ndarray
    eta_eff: float
    eta_eff_stderr: float
    eta_eff_fit_stderr: float
    n: int
    failures: tuple


def slip_viscosity(time, spring_force, table: CycleTable, *, mass: float,
                   spring_constant: float, area: float, thickness: float,
                   drive_velocity: float = 0.0,
                   mount_damping: float = 0.0) -> SlipViscosity:
    """Fit every slip of ``table`` (see :func:`fit_slip`) and convert B to η.

    ``mount_damping`` (force per velocity) is damping acting on the wall that
    is not the film's (an MD run's mount dashpot); the film's share of the
    fitted B is ``B - mount_damping``.
    """
    bs, errs, failures = [], [], []
    for y, s in zip(table.yield_index, table.stick_index):
        prev = table.stick_index[table.stick_index < y]
        lead = max(3, min(int((y - (prev[-1] if prev.size else 0)) // 5), int(s - y)))
        try:
            fit = fit_slip(time, spring_force, int(y), int(s), mass=mass,
                           spring_constant=spring_constant,
                           drive_velocity=drive_velocity, lead=lead)
            bs.append(fit.damping)
            errs.append(fit.damping_stderr)
        except (ValueError, RuntimeError) as exc:
            failures.append(f"slip at index {int(y)}: {exc}")
            bs.append(math.nan)
            errs.append(math.nan)
    b, e = np.array(bs), np.array(errs)
    eta = (b - mount_damping) * thickness / area
    eta_err = e * thickness / area
    ok = np.isfinite(eta)
    n = int(ok.sum())
    mean = float(eta[ok].mean()) if n else math.nan
    spread = float(eta[ok].std(ddof=1) / math.sqrt(n)) if n > 1 else math.nan
    fit_err = float(np.sqrt(np.nansum(eta_err[ok] ** 2)) / n) if n else math.nan
    stderr = float(np.nanmax([spread, fit_err])) if n else math.nan
    return SlipViscosity(b, e, eta, mean, stderr, fit_err, n, tuple(failures))
