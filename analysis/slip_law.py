"""Klein's slip equation tested on the slips themselves: viscous, kinetic, mixed or weakening?

Klein (PRL 98, 056101) writes the slip as ``M x'' + B x' = K(x0 − x)``: the film
resists with a viscous force B·v only.  Braun & Tosatti (EPL 88, 48003, 2009)
read the same slips as a kinetic friction stress with a bulk-like viscosity.
An SFB trace cannot tell the two apart; a trace that has the wall's velocity can
(Klein's note 27): the wall's equation of motion gives the film's own shear force
sample by sample,

    F_film(t) = F_spring − M·a − γM·(v − V)

(spring, minus the wall's inertia, minus the mount dashpot of an MD run, which
acts on the wall's velocity relative to the drive), and the law

    F_film = F_k + B·v  [+ m_c·a]

is fitted to (v, F_film) over each slip by least squares; the optional term m_c·a
is a mass moving with the wall that the equation of motion left out (film
atoms carried along).

Branches.  A slip is a loop in the (v, F_film) plane, not a line: the force on
the *accelerating* branch (yield → peak velocity) is the breaking of the pinned
film, the force on the *decelerating* branch (peak velocity → re-stick) is that
of the film while it slides and re-solidifies.  The two are fitted separately;
the verdict is the decelerating branch's (the sliding law), the accelerating
one is reported beside it, and the loop's area between the two branches'
lines (and the mean force gap, area over the velocity range) says how far from
one law F(v) the slip is.  (∮F_film dv over the samples themselves is no
measure: the noise of M·a is correlated with that of dv.)

Smoothing.  The sampled wall velocity of an MD run carries the wall's thermal
vibration; differentiated for M·a it swamps the film force.  A Savitzky–Golay
filter (order 2, a window of ``smoothing`` × the median slip duration) is
applied to the spring force, the velocity and the acceleration alike; a linear
law F_k + B·v + m_c·a survives any such filter unchanged (the filter is linear
and keeps constants), so the smoothing removes noise, not the law.

Verdict (one of :data:`VERDICTS`).  Each term is *resolved* when it exceeds
2 σ — at the coverage of a normal 2 σ (97.7 % one-sided) with the Student t of
the errors' degrees of freedom — and carries at least :data:`NUMERICAL_FLOOR` of
the film force |F_k| + |B·v̄| (on an exact trace the errors vanish and the
quadrature's own error would read as a term), and *ruled out as dominant* when the run had
95 % power to resolve it at half the film force F̄ (the power analysis, on the
run's own errors: :func:`detectable`):

* ``velocity-weakening`` — B resolved negative;
* ``mixed`` — B and F_k both resolved positive;
* ``viscous`` — B resolved, F_k not, and a kinetic force of F̄/2 would have been
  resolved (Klein's reading);
* ``kinetic`` — F_k resolved, B not, and a viscous force of F̄/2 at v̄ would have
  been resolved (Braun–Tosatti's reading);
* ``inconclusive`` — anything else: nothing resolved, or the missing term could
  carry half the force unseen.

A window of the table in which the wall did not slip — the spring force falls over it
by less than :data:`MIN_RELAXATION` of its value at the yield, as when a solid film
holds the wall and it only rattles in its well — is left out, and the reasons say
how far and how fast the wall moved in it; with no window left every branch is
``inconclusive`` (no slip, no law).

``detectable_damping`` is the smallest B the run resolves at 2 σ in 95 % of
repeats; B, it and the B of a no-slip film of bulk viscosity (η_bulk·A/D,
computed by the caller) belong side by side.  σ_B and σ_Fk are the standard
errors of the per-slip fits' mean over the slips (their scatter, n − 1 degrees
of freedom), never below the pooled least-squares errors widened for the
residuals' correlation.  Only samples faster than ``min_velocity_fraction`` of
the slip's peak are fitted: near v = 0 the film is re-solidifying (or has not
yet shear-melted), which is not the law; nor are the samples whose derivative or
smoothing window reaches across the yield or the re-stick (half a window and one
sample at each end of the slip).

The local exponent n = d ln F/d ln v is fitted per slip as F = c·(v/v̄)^n on the
same branch: 1 for a viscous film, 0 for a kinetic force, < 0 for weakening.

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
from dataclasses import dataclass, replace

import numpy as np
from scipy import stats as sps
from scipy.integrate import cumulative_trapezoid
from scipy.optimize import brentq
from scipy.signal import savgol_filter

from filmfriction.reduced_model.cycles import CycleTable

__all__ = ["FilmForceFit", "BranchFit", "film_force", "fit_film_force", "detectable",
           "sigmas", "VERDICTS", "BRANCHES", "RESOLVED_SIGMAS", "POWER", "DOMINANT_SHARE",
           "NUMERICAL_FLOOR", "MIN_RELAXATION"]

#: The verdicts, in the order the rules are tried.
VERDICTS = ("velocity-weakening", "mixed", "viscous", "kinetic", "inconclusive")
#: The branches of a slip; the verdict is the first one's.
BRANCHES = ("decelerating", "accelerating")
#: A fitted term is resolved when it exceeds this many standard errors (at a normal's coverage).
RESOLVED_SIGMAS = 2.0
#: The power at which a term the run did not resolve is ruled out.
POWER = 0.95
#: A term not resolved is ruled out as dominant when the run would have resolved it (at
#: :data:`POWER`) carrying this share of the mean film force.
DOMINANT_SHARE = 0.5
#: A term is resolved only when it also carries at least this share of the film force
#: (|F_k| + |B·v̄|): the numerical floor of the sampled equation of motion (its
#: trapezoid impulse and the sampling leave terms of 1e-4–1e-3 of the force on exact
#: model traces at the controls' sampling, with standard errors far smaller).
NUMERICAL_FLOOR = 0.01
#: A window is a slip only when the spring force falls over it by at least this share of
#: its value at the yield (K·(Δx − VΔt) of F_s): a window in which the wall did not move
#: (a film holding the wall, the wall rattling in its well) is refused, not fitted.
MIN_RELAXATION = 0.05
#: Default window of the velocity that picks the fitted samples, as a share of the median
#: slip duration.
SMOOTHING = 0.1
#: With this many slips or more, the errors are the scatter of the per-slip fits.
MIN_SLIPS_FOR_SCATTER = 3


@dataclass(frozen=True)
class BranchFit:
    """F_film = F_k + B·v [+ m_c·a] fitted on one branch of the slips (see the module text).

    Attributes
    ----------
    branch : str
        ``decelerating``, ``accelerating`` or ``whole``.
    kinetic_force, kinetic_force_stderr : float
        F_k and its standard error (force units).
    damping, damping_stderr : float
        B and its standard error (force per velocity).
    comoving_mass, comoving_mass_stderr : float
        m_c and its standard error (NaN when the term was not fitted).
    mean_velocity, mean_force : float
        v̄ and F̄, the means of the fitted samples.
    viscous_share : float
        B·v̄ / F̄.
    exponent, exponent_stderr : float
        n = d ln F/d ln v of the fitted law at each slip's mean velocity, mean and
        standard error over the slips.
    kinetic_sigmas, damping_sigmas : float
        F_k and B in normal-equivalent standard errors (signed).
    detectable_damping, detectable_kinetic_force : float
        The smallest B and F_k the run resolves at 2 σ with 95 % power.
    dof : int
        Degrees of freedom of the errors.
    verdict, reason : str
        One of :data:`VERDICTS`, and the numbers it rests on.
    per_slip_kinetic_force, per_slip_damping, per_slip_exponent : ndarray
        Per-slip fits (NaN where a slip had too few samples on this branch).
    samples, slips : int
        Samples and slips fitted.
    velocity_residual : float
        Root-mean-square residual of the pooled integral fit over M: how far the
        wall's velocity strays from the law's (velocity units).
    """

    branch: str
    kinetic_force: float
    kinetic_force_stderr: float
    damping: float
    damping_stderr: float
    comoving_mass: float
    comoving_mass_stderr: float
    mean_velocity: float
    mean_force: float
    viscous_share: float
    exponent: float
    exponent_stderr: float
    kinetic_sigmas: float
    damping_sigmas: float
    detectable_damping: float
    detectable_kinetic_force: float
    dof: int
    verdict: str
    reason: str
    per_slip_kinetic_force: np.ndarray
    per_slip_damping: np.ndarray
    per_slip_exponent: np.ndarray
    samples: int
    slips: int
    velocity_residual: float


@dataclass(frozen=True)
class FilmForceFit:
    """The slip law on both branches, the loop, and the verdict (the decelerating branch's).

    Attributes
    ----------
    decelerating, accelerating : BranchFit
        The two branches (see the module text).
    whole : BranchFit
        The whole slip in one fit (both branches: a loop makes it a compromise; with
        the co-moving mass, the term where the acceleration takes both signs).
    verdict, reason : str
        The decelerating branch's.
    loop_area, loop_area_stderr : float
        The area between the two branches' fitted lines over the velocities both
        cover (the floor to the peak), ∫(F_acc − F_dec) dv (force × velocity;
        positive when the accelerating branch lies above), mean and standard
        error over the slips.
    loop_force, loop_force_stderr : float
        Loop area / that velocity range: the mean force gap between the branches.
    per_slip_loop_area : ndarray
    smoothing_window : int
        Window of the guiding velocity in samples (0: not smoothed).
    comoving_mass : bool
        Whether the m_c·a term was fitted.
    still_windows : int
        Windows of the table left out because the wall did not slip in them (the
        spring relaxed by less than :data:`MIN_RELAXATION` of its force); the
        reasons say by how much it moved.
    """

    decelerating: BranchFit
    accelerating: BranchFit
    whole: BranchFit
    verdict: str
    reason: str
    loop_area: float
    loop_area_stderr: float
    loop_force: float
    loop_force_stderr: float
    per_slip_loop_area: np.ndarray
    smoothing_window: int
    comoving_mass: bool
    still_windows: int = 0

    # the verdict's branch, as the single law the callers quote
    @property
    def kinetic_force(self) -> float:
        return self.decelerating.kinetic_force

    @property
    def kinetic_force_stderr(self) -> float:
        return self.decelerating.kinetic_force_stderr

    @property
    def damping(self) -> float:
        return self.decelerating.damping

    @property
    def damping_stderr(self) -> float:
        return self.decelerating.damping_stderr

    @property
    def detectable_damping(self) -> float:
        return self.decelerating.detectable_damping

    @property
    def mean_slip_velocity(self) -> float:
        return self.decelerating.mean_velocity

    @property
    def viscous_share(self) -> float:
        return self.decelerating.viscous_share

    @property
    def samples(self) -> int:
        return self.decelerating.samples


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
    t, f, v = _checked(time, spring_force, wall_velocity, mass)
    return f - mass * np.gradient(v, t) - mount_damping * (v - drive_velocity)


def _checked(time, spring_force, wall_velocity, mass):
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
    return t, f, v


# ---------------------------------------------------------------------------
# significance and power
# ---------------------------------------------------------------------------
def sigmas(estimate: float, stderr: float, dof: int) -> float:
    """``estimate/stderr`` as normal-equivalent standard errors (signed): the t of ``dof``
    degrees of freedom mapped to the normal quantile of the same tail probability.

    >>> round(sigmas(2.0, 1.0, 10**6), 3), round(sigmas(2.0, 1.0, 4), 2)
    (2.0, 1.57)
    """
    if not (math.isfinite(estimate) and math.isfinite(stderr) and stderr >= 0 and dof >= 1):
        return math.nan
    if stderr == 0:
        return math.copysign(38.0, estimate) if estimate else 0.0
    t = estimate / stderr
    z = float(sps.norm.isf(sps.t.sf(abs(t), dof)))
    return math.copysign(min(z, 38.0), t)


def detectable(stderr: float, dof: int, *, resolved: float = RESOLVED_SIGMAS,
               power: float = POWER) -> float:
    """The smallest true value resolved at ``resolved`` σ (normal-equivalent) in a share
    ``power`` of repeats, for an estimate with standard error ``stderr`` whose own
    error has ``dof`` degrees of freedom: δ·stderr with δ the noncentrality at
    which a noncentral t exceeds the critical t with probability ``power``.

    >>> round(detectable(1.0, 10**6), 2), round(detectable(1.0, 6), 2)   # 2 + 1.645; 6 dof
    (3.64, 4.45)
    """
    if not (math.isfinite(stderr) and stderr >= 0 and dof >= 1):
        return math.nan
    crit = sps.t.isf(sps.norm.sf(resolved), dof)
    if dof > 1000:
        return float((crit + sps.norm.ppf(power)) * stderr)
    delta = brentq(lambda d: sps.nct.sf(crit, dof, d) - power, 0.0, 10 * crit + 50)
    return float(delta * stderr)


# ---------------------------------------------------------------------------
# fitting
# ---------------------------------------------------------------------------
def _ols(X: np.ndarray, y: np.ndarray, errors: bool = True):
    """Least squares y = X·c: (coef, stderr, residuals); the errors widened by the
    residuals' integrated autocorrelation time (NaN with ``errors=False``)."""
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ coef
    dof = y.size - X.shape[1]
    if dof <= 0 or not errors:
        return coef, np.full(X.shape[1], math.nan), resid
    s2 = float(resid @ resid) / dof
    try:
        se = np.sqrt(np.diag(s2 * np.linalg.inv(X.T @ X)) * _correlation_time(resid))
    except np.linalg.LinAlgError:
        se = np.full(X.shape[1], math.nan)
    return coef, se, resid


def _correlation_time(r: np.ndarray) -> float:
    """Integrated autocorrelation time of ``r`` in samples, 1 + 2 Σ ρ_k summed up to
    the first lag where ρ_k ≤ 0 (1 for uncorrelated samples)."""
    r = r - r.mean()
    den = float(r @ r)
    if r.size < 3 or den <= 0:
        return 1.0
    tau = 1.0
    for k in range(1, r.size // 2):
        rho = float(r[k:] @ r[:-k]) / den
        if rho <= 0:
            break
        tau += 2 * rho
    return tau


@dataclass(frozen=True)
class _Segment:
    """One branch of one slip in integral form (module text): the response y, the
    regressors Δt, Δx and v − v0, and the branch's mean velocity."""

    y: np.ndarray           # ∫F_spring dt − γM(Δx − VΔt) − M v
    dt: np.ndarray
    dx: np.ndarray
    dv: np.ndarray          # v − v0 of the smoothed velocity (the m_c term)
    mass: float

    @property
    def mean_velocity(self) -> float:
        return float(self.dx[-1] / self.dt[-1]) if self.dt[-1] > 0 else math.nan

    def design(self, comoving: bool, intercepts: int = 1, which: int = 0):
        """Columns [intercepts…, Δt, Δx (, v − v0)] and the response (with m_c, the
        response without the −M·v it would otherwise hold: M·v joins m_c·v)."""
        cols = [np.full(self.y.size, float(k == which)) for k in range(intercepts)]
        cols += [self.dt, self.dx]
        return cols + ([self.dv] if comoving else [])


def _fit_branch(branch: str, segments: list[_Segment | None], comoving: bool) -> BranchFit:
    """Per-slip fits on one branch, their mean, errors, power and verdict."""
    nterms = 4 if comoving else 3
    per = []                       # (fk, b, mc, vbar) per slip
    used, resids = [], []
    for seg in segments:
        if seg is None or seg.y.size < nterms + 3:
            per.append((math.nan,) * 4)
            continue
        coef, _, res = _ols(np.column_stack(seg.design(comoving)), seg.y, errors=False)
        resids.append(res)
        # with m_c, the coefficient of v − v0 is M + m_c
        per.append((float(coef[1]), float(coef[2]),
                    float(coef[3]) - seg.mass if comoving else math.nan, seg.mean_velocity))
        used.append(seg)
    per = np.array(per, float).reshape(-1, 4)
    nan = math.nan
    if not used:
        return BranchFit(branch, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan,
                         nan, nan, nan, 0, "inconclusive",
                         f"no slip with {nterms + 3} or more samples on the {branch} branch "
                         "above the velocity floor", per[:, 0], per[:, 1], per[:, 0] * nan,
                         0, 0, nan)
    m = len(used)
    ok = np.isfinite(per[:, 0]) & np.isfinite(per[:, 1])
    n = int(ok.sum())
    with np.errstate(invalid="ignore", divide="ignore"):
        expo = per[:, 1] * per[:, 3] / (per[:, 0] + per[:, 1] * per[:, 3])
    if n >= MIN_SLIPS_FOR_SCATTER:
        # the slips are the replicas: the standard error of their mean
        est = per[ok, :3].mean(axis=0)
        se = per[ok, :3].std(axis=0, ddof=1) / math.sqrt(n)
        dof = n - 1
    else:
        # too few slips for a scatter: the pooled fit (one intercept per slip, common
        # F_k, B (, m_c)), its errors widened for the residuals' correlation, with the
        # degrees of freedom of its independent samples
        X = np.vstack([np.column_stack(s.design(comoving, m, k)) for k, s in enumerate(used)])
        y = np.concatenate([s.y for s in used])
        coef, pse, resid = _ols(X, y)
        est = np.array([coef[m], coef[m + 1], coef[m + 2] - used[0].mass if comoving else nan])
        se = np.array([pse[m], pse[m + 1], pse[m + 2] if comoving else nan])
        dof = max(int(y.size / _correlation_time(resid)) - (m + nterms - 1), 1)
    fk, b, mc = (float(x) for x in est)
    se_fk, se_b, se_mc = (float(x) for x in se)
    ex = expo[ok][np.isfinite(expo[ok])]
    n_mean = float(ex.mean()) if ex.size else nan
    n_se = float(ex.std(ddof=1) / math.sqrt(ex.size)) if ex.size >= 2 else nan
    vbar = float(np.nanmean(per[ok, 3])) if n else nan
    fbar = fk + b * vbar
    share = b * vbar / fbar if fbar > 0 else nan
    # the residual as the error of the law's wall velocity: (response residual) / M
    allres = np.concatenate(resids)
    vres = float(np.sqrt(np.mean(allres ** 2))) / used[0].mass
    z_fk, z_b = sigmas(fk, se_fk, dof), sigmas(b, se_b, dof)
    det_b, det_fk = detectable(se_b, dof), detectable(se_fk, dof)
    verdict, reason = _verdict(fk, se_fk, z_fk, det_fk, b, se_b, z_b, det_b, vbar, fbar, n)
    return BranchFit(branch, fk, se_fk, b, se_b, mc, se_mc, vbar,
                     fbar, share, n_mean, n_se, z_fk, z_b, det_b, det_fk, dof, verdict, reason,
                     per[:, 0], per[:, 1], expo, int(allres.size), n, vres)


def _verdict(fk, se_fk, z_fk, det_fk, b, se_b, z_b, det_b, vbar, fbar, n):
    """The verdict of one branch and the numbers it rests on (module text)."""
    r = RESOLVED_SIGMAS
    nums = (f"F_k = {fk:.4g} ± {se_fk:.2g} ({z_fk:+.1f} σ), B = {b:.4g} ± {se_b:.2g} "
            f"({z_b:+.1f} σ) over {n} slip(s); F̄ = {fbar:.4g} at v̄ = {vbar:.4g}; "
            f"95 % power at 2 σ for B ≥ {det_b:.3g}, F_k ≥ {det_fk:.3g}")
    if not all(math.isfinite(x) for x in (z_fk, z_b, fbar, vbar)):
        return "inconclusive", f"errors not defined: {nums}"
    # a term counts only above the numerical floor too: on an exact trace its error is
    # ~0 and the quadrature's own error would otherwise read as a resolved term
    floor = NUMERICAL_FLOOR * (abs(fk) + abs(b * vbar))
    b_big, fk_big = abs(b * vbar) >= floor, abs(fk) >= floor
    small = [f"{name} carries {abs(val) / (abs(fk) + abs(b * vbar)):.1e} of the force, "
             f"under the numerical floor {NUMERICAL_FLOOR:g}"
             for name, val, big, z in (("F_k", fk, fk_big, z_fk), ("B·v̄", b * vbar, b_big, z_b))
             if abs(z) >= r and not big]
    if small:
        nums = f"{nums}; {'; '.join(small)}"
    if z_b <= -r and b_big:
        return "velocity-weakening", f"B resolved negative: {nums}"
    b_res, fk_res = z_b >= r and b_big, z_fk >= r and fk_big
    if b_res and fk_res:
        return "mixed", f"both terms resolved (viscous share {b * vbar / fbar:.2f}): {nums}"
    if fbar <= 0:
        return "inconclusive", f"mean film force not positive: {nums}"
    hidden_visc = det_b * vbar / fbar       # share a viscous term could carry unseen
    hidden_kin = det_fk / fbar
    if b_res:
        if hidden_kin < DOMINANT_SHARE:
            return "viscous", (f"B resolved, F_k not; a kinetic force of {hidden_kin:.2f} F̄ "
                               f"would have been resolved: {nums}")
        return "inconclusive", (f"B resolved, F_k not, but a kinetic force up to "
                                f"{hidden_kin:.2f} F̄ could go unresolved: {nums}")
    if fk_res:
        if hidden_visc < DOMINANT_SHARE:
            return "kinetic", (f"F_k resolved, B not; a viscous force of {hidden_visc:.2f} F̄ "
                               f"would have been resolved: {nums}")
        return "inconclusive", (f"F_k resolved, B not, but a viscous force up to "
                                f"{hidden_visc:.2f} F̄ could go unresolved: {nums}")
    return "inconclusive", f"neither term resolved: {nums}"


def _window(t: np.ndarray, table: CycleTable, smoothing: float) -> int:
    """Savitzky–Golay window (odd, ≥ 5 samples) for ``smoothing`` × median slip duration;
    0 when the sampling is not uniform or the window would be under 5 samples."""
    if smoothing <= 0 or t.size < 7:
        return 0
    dt = np.diff(t)
    if not np.allclose(dt, dt[0], rtol=1e-6, atol=0):
        return 0
    dur = np.asarray(table.slip_duration, float)
    dur = dur[np.isfinite(dur)]
    if dur.size == 0:
        return 0
    w = int(round(smoothing * float(np.median(dur)) / dt[0]))
    w += 1 - w % 2
    return w if 5 <= w < t.size else 0


def fit_film_force(time, spring_force, wall_velocity, table: CycleTable, *, mass: float,
                   drive_velocity: float = 0.0, mount_damping: float = 0.0,
                   wall_position=None, min_velocity_fraction: float = 0.2,
                   smoothing: float = SMOOTHING, comoving_mass: bool = False) -> FilmForceFit:
    """Fit F_film = F_k + B·v [+ m_c·a] on each branch of each slip of ``table``.

    Parameters
    ----------
    time, spring_force, wall_velocity : array_like, shape (n,)
        The trace (the wall velocity as sampled, not differentiated positions).
    table : CycleTable
        The slips (yield → re-stick indices); leave out start-up slips before
        passing it (``table[skip:]``).
    mass, drive_velocity, mount_damping : float
        See :func:`film_force`.
    wall_position : array_like, shape (n,), optional
        The wall's position (else the integrated velocity).
    min_velocity_fraction : float
        Fit only samples with v above this fraction of the slip's peak velocity.
    smoothing : float
        Window of the velocity that picks the peak, the branches and the fitted
        samples, as a share of the median slip duration (0: the samples' own).
    comoving_mass : bool
        Fit the term m_c·a too.

    Returns
    -------
    FilmForceFit
    """
    if not 0 <= min_velocity_fraction < 1:
        raise ValueError(f"min_velocity_fraction = {min_velocity_fraction!r}: must be in [0, 1)")
    if not (math.isfinite(smoothing) and 0 <= smoothing < 1):
        raise ValueError(f"smoothing = {smoothing!r}: must be in [0, 1) (share of a slip)")
    t, f, v = _checked(time, spring_force, wall_velocity, mass)
    if wall_position is None:
        x = cumulative_trapezoid(v, t, initial=0.0)
    else:
        x = np.asarray(wall_position, float)
        if x.shape != t.shape:
            raise ValueError(f"wall_position has shape {x.shape}, the trace {t.shape}")
    w = _window(t, table, smoothing)
    # the velocity that picks the samples: from the position, whose noise is not the
    # response's (selecting on the response's own noise would bias the fit)
    if w and wall_position is not None:
        guide = savgol_filter(x, w, 2, deriv=1, delta=float(t[1] - t[0]))
    else:
        guide = savgol_filter(v, w, 2) if w else v
    impulse = cumulative_trapezoid(f, t, initial=0.0)
    segs = {name: [] for name in BRANCHES + ("whole",)}
    ranges = []
    edge = w // 2 + 1
    still = []                       # (slip, Δx, v̄, relaxation) of windows with no slip
    for j, (y, s) in enumerate(zip(table.yield_index, table.stick_index)):
        y, s = int(y), int(s)
        g = guide[y:s + 1]
        relaxed = (f[y] - f[s]) / abs(f[y]) if f[y] else math.nan
        if not relaxed >= MIN_RELAXATION:
            still.append((j, float(x[s] - x[y]), float((x[s] - x[y]) / (t[s] - t[y]))
                          if t[s] > t[y] else math.nan, float(relaxed)))
            g = g[:0]
        if g.size < 3 or not np.max(g) > 0:
            for name in segs:
                segs[name].append(None)
            ranges.append((math.nan, math.nan))
            continue
        p = int(np.argmax(g))
        peak = float(g[p])
        fast = g > min_velocity_fraction * peak
        fast[:edge] = False
        fast[max(g.size - edge, 0):] = False
        for name, (lo, hi) in (("accelerating", (0, p + 1)), ("decelerating", (p, g.size)),
                               ("whole", (0, g.size))):
            k = np.flatnonzero(fast[lo:hi]) + lo
            if k.size == 0:
                segs[name].append(None)
                continue
            i = np.arange(k[0], k[-1] + 1) + y          # contiguous: the integral needs it
            dt_, dx = t[i] - t[i[0]], x[i] - x[i[0]]
            resp = (impulse[i] - impulse[i[0]] - mount_damping * (dx - drive_velocity * dt_)
                    - (0.0 if comoving_mass else mass) * v[i])
            segs[name].append(_Segment(resp, dt_, dx, guide[i] - guide[i[0]], mass))
        ranges.append((min_velocity_fraction * peak, peak))
    fits = {name: _fit_branch(name, segs[name], comoving_mass) for name in segs}
    if still:
        fits = _refuse_still(fits, still, len(table))
    acc, dec = fits["accelerating"], fits["decelerating"]
    lo, hi = np.array(ranges, float).reshape(-1, 2).T
    # the loop between the two branches' lines, over the velocities both cover
    gap_fk = acc.per_slip_kinetic_force - dec.per_slip_kinetic_force
    gap_b = acc.per_slip_damping - dec.per_slip_damping
    area = gap_fk * (hi - lo) + gap_b * (hi ** 2 - lo ** 2) / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        gap = area / (hi - lo)
    la, lf = _mean_se(area), _mean_se(gap)
    return FilmForceFit(dec, acc, fits["whole"], dec.verdict, dec.reason, la[0], la[1], lf[0],
                        lf[1], area, w, comoving_mass, len(still))


def _refuse_still(fits: dict, still: list, total: int) -> dict:
    """The branches with the windows in which the wall did not move said so: all
    ``inconclusive`` when no window is left, else the fit of the others with a note."""
    j, dx, vbar, relaxed = (np.array(c, float) for c in zip(*still))
    note = (f"{len(still)} of {total} window(s) left out, the wall did not slip in them: "
            f"it moved Δx = {', '.join(f'{d:.3g}' for d in dx[:5])}"
            f"{', …' if dx.size > 5 else ''} at a mean velocity "
            f"{', '.join(f'{u:.3g}' for u in vbar[:5])}{', …' if dx.size > 5 else ''}, "
            f"relaxing the spring by {100 * np.nanmax(relaxed):.2g} % of its force at most "
            f"(a slip relaxes it by {100 * MIN_RELAXATION:g} % or more)")
    if len(still) == total:
        return {k: replace(b, verdict="inconclusive", reason=f"no slip: {note}")
                for k, b in fits.items()}
    return {k: replace(b, reason=f"{b.reason}; {note}") for k, b in fits.items()}


def _mean_se(x: np.ndarray) -> tuple[float, float]:
    x = x[np.isfinite(x)]
    if x.size == 0:
        return math.nan, math.nan
    return float(x.mean()), (float(x.std(ddof=1) / math.sqrt(x.size)) if x.size > 1 else math.nan)
