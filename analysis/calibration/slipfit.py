"""The slip of a Coulomb + viscous wall, and its joint fit to the slips of an MD run.

:func:`coulomb_slip_force` is the spring force of one slip from rest at the
yield point (the damped oscillator of
:mod:`filmfriction.reduced_model.integrators.oscillator` about steady sliding, through
:func:`filmfriction.analysis.viscosity.slip_force`), ending where the wall's
velocity returns to zero (its exact root,
:meth:`DampedOscillator.first_crossing <filmfriction.reduced_model.integrators.oscillator.DampedOscillator.first_crossing>`),
then the stick ramp.  :func:`fit_slip_law` fits F_k and the film's damping B
(and each slip's yield instant) to every analysed slip of a run at once.

Example
-------
>>> import numpy as np
>>> f = coulomb_slip_force(np.array([-1.0, 0.0, 1.0]), 60.0, 20.0, 80.0, 500.0, 100.0, 0.02)
>>> f[:2].tolist()                              # the stick ramp, then the yield force
[58.0, 60.0]
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from filmfriction.reduced_model.integrators.oscillator import DampedOscillator

from .estimators import Estimate
from .rundata import RunData
from ..trace import UNITS
from ..viscosity import slip_force

__all__ = ["coulomb_slip_force", "SlipLawFit", "fit_slip_law"]


def coulomb_slip_force(t, static_force: float, kinetic_force: float, damping: float,
                       mass: float, stiffness: float, drive_velocity: float) -> np.ndarray:
    """Spring force of one Coulomb + viscous slip from rest at the yield point.

    Solves ``M x'' + b x' = K(x0 + V t − x) − F_k`` from x = x' = 0 with
    K x0 = F_s (:func:`filmfriction.analysis.viscosity.slip_force` with F_s − F_k) until
    the wall velocity returns to zero (the exact root), after which the wall
    sticks and the force ramps at K V.  A second yield inside ``t`` is not modelled.

    Parameters
    ----------
    t : array_like
        Times since the yield point (≥ 0 where the slip applies; earlier
        times get the stick ramp F_s + K V t).
    static_force, kinetic_force : float
        F_s and F_k.
    damping : float
        Total damping b = B (film) + d (mount), force per velocity.
    mass, stiffness, drive_velocity : float
        M, K, V.

    Returns
    -------
    numpy.ndarray
        Spring force at ``t``.
    """
    t = np.asarray(t, dtype=float)
    k, v = stiffness, drive_velocity
    end = float(np.max(t)) if t.size else 0.0
    out = static_force + k * v * t
    if end <= 0.0:
        return out
    drop = static_force - kinetic_force
    # about steady sliding the wall is x = x_p + u, M u'' + b u' + K u = 0, u(0) = -drop/K + b V/K,
    # u'(0) = -V: its velocity V + u' returns to zero where u' = -V (the slip starts there)
    osc = DampedOscillator(mass=mass, damping=damping, stiffness=k)
    t_stick = osc.first_crossing(-drop / k + damping * v / k, -v, -v, end, skip_start=True)
    if t_stick is None:
        t_stick, f_stick = math.inf, math.nan
    else:
        f_stick = kinetic_force + float(slip_force(t_stick, drop, damping, mass, k, v))
    after = t >= 0.0
    slipping = after & (t < t_stick)
    out[slipping] = kinetic_force + slip_force(t[slipping], static_force - kinetic_force,
                                               damping, mass, k, v)
    stuck = after & (t >= t_stick)
    out[stuck] = f_stick + k * v * (t[stuck] - t_stick)
    return out


@dataclass(frozen=True, eq=False)
class SlipLawFit:
    """Joint fit of F_k and B over the slips of one run.

    Attributes
    ----------
    kinetic_force, film_damping : Estimate
    static_force : Estimate
        Spring force at the fitted yield instants (mean ± standard error).
    mount_damping : float
        d, fixed (not fitted).
    rms_residual : float
        RMS force residual of the joint fit.
    n_slips : int
    jackknife : list of (float, float)
        (F_k, B) with each slip left out.
    windows : list of (int, int)
        Sample index windows fitted.
    yield_shifts : tuple of float
        Fitted yield instant minus the detected one, per slip (time units).
    damping_at_bound : bool
        B ended at the fit's lower bound: no film drag beyond the mount's is resolved.
    """

    kinetic_force: Estimate
    film_damping: Estimate
    static_force: Estimate
    mount_damping: float
    rms_residual: float
    n_slips: int
    jackknife: list = field(default_factory=list)
    windows: list = field(default_factory=list)
    yield_shifts: tuple = ()
    damping_at_bound: bool = False


def _windows(t, yi, si) -> list[tuple[int, int]]:
    out = []
    for j, (y, s) in enumerate(zip(yi, si)):
        nxt = yi[j + 1] if j + 1 < len(yi) else t.size - 1
        hi = min(int(s + max(s - y, 2)), int(nxt), t.size - 1)
        if hi - y >= 4:
            out.append((int(y), int(hi)))
    return out


def fit_slip_law(run: RunData) -> SlipLawFit:
    """Fit F_k, the film's damping B and each slip's yield instant to the analysed slips.

    Each slip window starts a few samples before the detected yield y; the
    model there is the stick ramp F_s,i + K V (t − t_y,i) (F_s,i: the
    analysis's ramp-line value at y) until the yield instant t_y,i + δ_i, then
    :func:`coulomb_slip_force`.  δ_i is free within (−4, +2) samples: with a
    sampled, noisy trace the detected y lags or leads the true yield by up to
    a sample or two, and a slip started at the wrong instant biases F_k.

    Raises
    ------
    ValueError
        No slips to fit, or missing K / M.
    """
    from scipy.optimize import least_squares

    tr = run.trace
    p = tr.parameters
    k = p.require("spring_constant", "the slip fit")
    m = p.require("mass", "the slip fit")
    v = p.drive_velocity or 0.0
    d = p.mount_damping or 0.0
    t, f = tr.time, tr.spring_force
    yi = run.cycles["yield_index"][run.skip:]
    si = run.cycles["stick_index"][run.skip:]
    fs_all = np.asarray(run.cycles["static_force"], float)[run.skip:]
    fs_by_start = {int(y): float(fs) for y, fs in zip(yi, fs_all)}
    wins = _windows(t, yi, si)
    if not wins:
        raise ValueError(f"{run.run_dir}: no slip with enough samples to fit "
                         f"({run.n_slips} slips detected, regime {run.analysis.get('regime')})")
    dt = float(np.median(np.diff(t)))
    lead = 4
    data = []
    for a, b in wins:
        lo = max(a - lead, 0)
        data.append((t[lo:b + 1] - t[a], f[lo:b + 1], fs_by_start[a]))
    n = len(data)
    fs_min = min(fs for _, _, fs in data)
    b_crit = 2.0 * math.sqrt(m * k)
    upper_fk = max(0.999 * fs_min, 1e-12)

    def one(i, fk, b, delta):
        tt, ff, fs = data[i]
        return coulomb_slip_force(tt - delta, fs + k * v * delta, fk, b, m, k, v) - ff

    def resid(params, subset):
        fk, logb = params[:2]
        b = math.exp(logb) + d
        return np.concatenate([one(i, fk, b, params[2 + j]) for j, i in enumerate(subset)])

    lo_d, hi_d = -lead * dt, 2.0 * dt

    def solve(subset, start, tol=1e-8):
        x0 = np.concatenate([start[:2], [min(max(start[2 + i], lo_d * 0.999), hi_d * 0.999)
                                         for i in subset]])
        lower = [0.0, math.log(1e-6 * b_crit)] + [lo_d] * len(subset)
        upper = [upper_fk, math.log(1e4 * b_crit)] + [hi_d] * len(subset)
        return least_squares(resid, x0=x0, args=(subset,), bounds=(lower, upper),
                             x_scale=[max(fs_min, 1.0), 1.0] + [dt] * len(subset),
                             ftol=tol, xtol=tol)

    every = list(range(n))
    # coarse grid over (F_k, B) as a start, yield instants at the detected y
    best = None
    for fk in np.linspace(0.0, 0.95 * fs_min, 7) if fs_min > 0 else [0.0]:
        for lb in np.log(np.geomspace(1e-3 * b_crit, 1e2 * b_crit, 11)):
            cost = float(np.sum(resid(np.concatenate([[fk, lb], np.zeros(n)]), every) ** 2))
            if best is None or cost < best[0]:
                best = (cost, fk, lb)
    full0 = np.concatenate([[min(best[1], 0.99 * upper_fk), best[2]], np.zeros(n)])
    sol = solve(every, full0)
    fk, logb = sol.x[:2]
    deltas = sol.x[2:]
    yield_forces = np.array([data[i][2] + k * v * deltas[i] for i in every])
    rms = float(np.sqrt(np.mean(sol.fun ** 2)))
    jack = []
    if n >= 3:
        for i in every:
            sub = [j for j in every if j != i]
            s_ = solve(sub, np.concatenate([[min(fk, 0.99 * upper_fk), logb], deltas]), tol=1e-5)
            jack.append((float(s_.x[0]), float(math.exp(s_.x[1]))))
        arr = np.array(jack)
        err = np.sqrt((n - 1) / n * np.sum((arr - arr.mean(axis=0)) ** 2, axis=0))
        fk_err, b_err = float(err[0]), float(err[1])
        how = f"jackknife over {n} slips"
    else:
        J = sol.jac
        dof = max(sol.fun.size - J.shape[1], 1)
        try:
            cov = np.linalg.pinv(J.T @ J) * float(np.sum(sol.fun ** 2)) / dof
            fk_err = float(math.sqrt(cov[0, 0]))
            b_err = float(math.exp(logb) * math.sqrt(cov[1, 1]))
        except (np.linalg.LinAlgError, ValueError):
            fk_err = b_err = math.nan
        how = f"fit covariance ({n} slip{'s' if n != 1 else ''}; jackknife needs 3)"
    u = UNITS[tr.units]
    fs_err = float(yield_forces.std(ddof=1) / math.sqrt(n)) if n > 1 else math.nan
    # a parameter pinned at a bound has no sampling spread to report: the
    # jackknife's zero would read as an exact value
    fk_how = b_how = how
    if fk <= 1e-9 * max(fs_min, 1.0):
        fk_err, fk_how = math.nan, how + "; at the fit's lower bound 0: no rate-independent part"
    damping_at_bound = bool(logb <= math.log(1e-6 * b_crit) + 1e-6)
    if damping_at_bound:
        b_err, b_how = math.nan, (how + "; at the fit's lower bound: no film drag beyond the "
                                  "mount's dashpot is resolved")
    return SlipLawFit(
        kinetic_force=Estimate(float(fk), fk_err, u["force"],
                               f"joint fit of the Coulomb+viscous slip to {n} slips; {fk_how}"),
        film_damping=Estimate(float(math.exp(logb)), b_err, u["damping"],
                              f"same fit, mount dashpot d = {d:g} fixed; {b_how}"),
        static_force=Estimate(float(yield_forces.mean()), fs_err, u["force"],
                              f"spring force at the fitted yield instants of {n} slips, mean ± stderr"),
        mount_damping=d, rms_residual=rms, n_slips=n, jackknife=jack, windows=wins,
        yield_shifts=tuple(float(x) for x in deltas), damping_at_bound=damping_at_bound)
