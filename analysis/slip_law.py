"""Klein's slip equation tested on the slips themselves: viscous flow or kinetic friction?

Klein (PRL 98, 056101) writes the slip as ``M x'' + B x' = K(x0 − x)``: the film
resists with a viscous force B·v only.  Braun & Tosatti (EPL 88, 48003, 2009)
read the same slips as a kinetic friction stress F_k with a bulk-like viscosity.
The slip alone cannot tell the two apart in an SFB trace, but a trace that has
the wall's velocity can: during a slip, the wall's equation of motion gives the
film's own shear force sample by sample,

    F_film(t) = F_spring − M·a − γM·(v − V),

(spring, minus the wall's inertia, minus the mount dashpot of an MD run, which
acts on the wall's velocity relative to the drive), and the law

    F_film = F_k + B·v

is fitted to (v, F_film) over each slip, by least squares, and over all slips.

The verdict compares the two terms at the mean slip velocity v̄ of the fitted
samples, with the viscous share s = B·v̄ / (F_k + B·v̄):

* ``viscous`` — B is resolved (B > 2 σ_B) and s ≥ 0.8 (Klein's reading);
* ``kinetic`` — B is not resolved, or s ≤ 0.2 (Braun–Tosatti's reading);
* ``mixed`` — both terms resolved and each carries more than a fifth.

σ_B and σ_Fk are the standard errors over the slips (their scatter) when there
are 2 or more, never below the pooled least-squares fit's own (which carries the
error of differentiating the sampled velocity).  Only samples where the wall moves faster than
``min_velocity_fraction`` of the slip's peak velocity are fitted: near v = 0 the
film is re-solidifying (or has not yet shear-melted), which is not the law.

Example
-------
A reduced-model trace with known F_k and B (a Coulomb + viscous block) gives them back:

>>> from filmfriction.reduced_model import SpringBlock, laws
>>> r = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.01, damping=0.5,
...                 law=laws.Coulomb(static=1.0, kinetic=0.4)).simulate(600.0)
>>> fit = fit_film_force(r.t, r.spring_force, r.v, r.cycles(), mass=1.0, drive_velocity=0.01)
>>> round(fit.kinetic_force, 3), round(fit.damping, 3), fit.verdict
(0.4, 0.5, 'mixed')
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from filmfriction.reduced_model.cycles import CycleTable

__all__ = ["FilmForceFit", "film_force", "fit_film_force", "VISCOUS_SHARE", "RESOLVED_SIGMAS"]

#: Viscous share s = B·v̄/(F_k + B·v̄) at or above which a slip is ``viscous`` (and at or
#: below 1 − VISCOUS_SHARE, ``kinetic``).
VISCOUS_SHARE = 0.8
#: A fitted term counts as resolved when it exceeds this many standard errors.
RESOLVED_SIGMAS = 2.0


@dataclass(frozen=True)
class FilmForceFit:
    """F_film = F_k + B·v fitted over the slips (see the module text).

    Attributes
    ----------
    kinetic_force, kinetic_force_stderr : float
        F_k and its standard error (force units).
    damping, damping_stderr : float
        B and its standard error (force per velocity).
    mean_slip_velocity : float
        v̄, mean wall velocity of the fitted samples.
    viscous_share : float
        B·v̄ / (F_k + B·v̄).
    verdict : str
        ``viscous``, ``kinetic``, ``mixed``, or ``none`` (nothing to fit).
    reason : str
        Why the verdict (the numbers it rests on).
    per_slip_kinetic_force, per_slip_damping : ndarray
        The per-slip fits (NaN where a slip had fewer than 4 samples to fit).
    samples : int
        Samples fitted over all slips.
    residual_rms : float
        Root-mean-square residual of the pooled fit (force units).
    r_squared : float
        Share of the variance of F_film that the pooled line explains: how well
        a straight line in v describes the film force at all (a wall hopping
        one registry site feels the film's corrugation, not F_k + B·v).
    """

    kinetic_force: float
    kinetic_force_stderr: float
    damping: float
    damping_stderr: float
    mean_slip_velocity: float
    viscous_share: float
    verdict: str
    reason: str
    per_slip_kinetic_force: np.ndarray
    per_slip_damping: np.ndarray
    samples: int
    residual_rms: float
    r_squared: float = float("nan")


def film_force(time, spring_force, wall_velocity, *, mass: float, drive_velocity: float = 0.0,
               mount_damping: float = 0.0) -> np.ndarray:
    """The film's shear force on the wall from its equation of motion.

    ``F_film = F_spring − M·dv/dt − mount_damping·(v − V)``, the acceleration by
    second-order central differences (:func:`numpy.gradient`) on the samples.

    Parameters
    ----------
    time, spring_force, wall_velocity : array_like, shape (n,)
    mass : float
        M of the wall (> 0).
    drive_velocity : float
        V of the spring end (the mount dashpot acts on v − V).
    mount_damping : float
        γM of an MD run's mount dashpot (force per velocity), 0 for none.

    Examples
    --------
    >>> t = np.linspace(0, 1, 5); v = 2 * t
    >>> film_force(t, np.full(5, 3.0), v, mass=0.5).tolist()   # 3 − 0.5·2
    [2.0, 2.0, 2.0, 2.0, 2.0]
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    v = np.asarray(wall_velocity, float)
    if not (t.shape == f.shape == v.shape) or t.ndim != 1:
        raise ValueError(f"time, spring_force and wall_velocity must be 1-D of one length, "
                         f"got {t.shape}, {f.shape}, {v.shape}")
    if not mass > 0:
        raise ValueError(f"mass = {mass!r}: must be positive")
    if t.size < 2:
        raise ValueError("need at least 2 samples")
    accel = np.gradient(v, t)
    return f - mass * accel - mount_damping * (v - drive_velocity)


def _line_fit(v: np.ndarray, f: np.ndarray):
    """Least-squares f = a + b v: (a, b, se_a, se_b, rms)."""
    n = v.size
    A = np.column_stack([np.ones(n), v])
    coef, *_ = np.linalg.lstsq(A, f, rcond=None)
    resid = f - A @ coef
    dof = n - 2
    s2 = float(resid @ resid) / dof if dof > 0 else math.nan
    try:
        cov = s2 * np.linalg.inv(A.T @ A)
        se = np.sqrt(np.diag(cov))
    except np.linalg.LinAlgError:
        se = np.array([math.nan, math.nan])
    rms = float(np.sqrt(np.mean(resid ** 2)))
    return float(coef[0]), float(coef[1]), float(se[0]), float(se[1]), rms


def _verdict(fk, se_fk, b, se_b, vbar):
    if not (math.isfinite(b) and math.isfinite(fk)):
        return "none", math.nan, "no slip could be fitted"
    total = fk + b * vbar
    share = b * vbar / total if total != 0 else math.nan
    b_ok = math.isfinite(se_b) and b > RESOLVED_SIGMAS * se_b
    fk_ok = math.isfinite(se_fk) and abs(fk) > RESOLVED_SIGMAS * se_fk
    nums = (f"F_k = {fk:.4g} ± {se_fk:.2g}, B = {b:.4g} ± {se_b:.2g}, "
            f"B·v̄ = {b * vbar:.4g} at v̄ = {vbar:.4g} (viscous share {share:.2f})")
    if not b_ok:
        return "kinetic", share, f"B not resolved (< {RESOLVED_SIGMAS:g} σ): {nums}"
    if share >= VISCOUS_SHARE or not fk_ok:
        why = "F_k not resolved" if not fk_ok else f"share ≥ {VISCOUS_SHARE:g}"
        return "viscous", share, f"{why}: {nums}"
    if share <= 1 - VISCOUS_SHARE:
        return "kinetic", share, f"share ≤ {1 - VISCOUS_SHARE:.1f}: {nums}"
    return "mixed", share, f"both terms resolved: {nums}"


def fit_film_force(time, spring_force, wall_velocity, table: CycleTable, *, mass: float,
                 drive_velocity: float = 0.0, mount_damping: float = 0.0,
                 min_velocity_fraction: float = 0.2) -> FilmForceFit:
    """Fit F_film = F_k + B·v over each slip of ``table`` and over all of them.

    Parameters
    ----------
    time, spring_force, wall_velocity : array_like, shape (n,)
        The trace (the wall velocity as sampled, not differentiated positions).
    table : CycleTable
        The slips (yield → re-stick indices); leave out start-up slips before
        passing it (``table[skip:]``).
    mass, drive_velocity, mount_damping : float
        See :func:`film_force`.
    min_velocity_fraction : float
        Fit only samples with v above this fraction of the slip's peak velocity.

    Returns
    -------
    FilmForceFit
        The pooled F_k and B are the means of the per-slip fits, with the
        standard error of their scatter (2 or more slips, floored at the pooled
        least-squares errors); with one slip, that slip's fit and its errors.
    """
    if not 0 <= min_velocity_fraction < 1:
        raise ValueError(f"min_velocity_fraction = {min_velocity_fraction!r}: must be in [0, 1)")
    t = np.asarray(time, float)
    v = np.asarray(wall_velocity, float)
    ff = film_force(t, spring_force, v, mass=mass, drive_velocity=drive_velocity,
                    mount_damping=mount_damping)
    fks, bs, vs, fs, ses = [], [], [], [], []
    for y, s in zip(table.yield_index, table.stick_index):
        seg = slice(int(y), int(s) + 1)
        vv, fff = v[seg], ff[seg]
        peak = float(np.max(vv)) if vv.size else 0.0
        keep = (vv > min_velocity_fraction * peak) & np.isfinite(fff) if peak > 0 else \
            np.zeros(vv.size, bool)
        if keep.sum() < 4:
            fks.append(math.nan), bs.append(math.nan), ses.append((math.nan, math.nan))
            continue
        a, b, se_a, se_b, _ = _line_fit(vv[keep], fff[keep])
        fks.append(a), bs.append(b), ses.append((se_a, se_b))
        vs.append(vv[keep]), fs.append(fff[keep])
    fks, bs = np.array(fks, float), np.array(bs, float)
    ok = np.isfinite(fks) & np.isfinite(bs)
    nan = math.nan
    if not ok.any():
        return FilmForceFit(nan, nan, nan, nan, nan, nan, "none",
                          "no slip with 4 or more samples above the velocity floor",
                          fks, bs, 0, nan)
    vall, fall = np.concatenate(vs), np.concatenate(fs)
    _, _, pooled_se_fk, pooled_se_b, rms = _line_fit(vall, fall)
    if ok.sum() >= 2:
        fk, b = float(fks[ok].mean()), float(bs[ok].mean())
        se_fk = max(float(fks[ok].std(ddof=1) / math.sqrt(ok.sum())), pooled_se_fk)
        se_b = max(float(bs[ok].std(ddof=1) / math.sqrt(ok.sum())), pooled_se_b)
    else:
        i = int(np.flatnonzero(ok)[0])
        fk, b = float(fks[i]), float(bs[i])
        se_fk, se_b = ses[i]
    vbar = float(vall.mean())
    var = float(np.var(fall))
    r2 = 1.0 - rms ** 2 / var if var > 0 else math.nan
    verdict, share, reason = _verdict(fk, se_fk, b, se_b, vbar)
    reason += f"; the line explains {r2:.0%} of the film force's variance"
    return FilmForceFit(fk, se_fk, b, se_b, vbar, share, verdict, reason, fks, bs,
                      int(vall.size), rms, r2)
