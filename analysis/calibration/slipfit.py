"""The slip of a Coulomb + viscous wall, and its joint fit to the slips of a run.

:func:`coulomb_slip_force` is the spring force of one slip from rest at the
yield point (the damped oscillator of
:mod:`filmfriction.reduced_model.integrators.oscillator` about steady sliding, through
:func:`filmfriction.analysis.viscosity.slip_force`), ending where the wall's
velocity returns to zero (its exact root,
:meth:`DampedOscillator.first_crossing <filmfriction.reduced_model.integrators.oscillator.DampedOscillator.first_crossing>`)
or, with a freeze force F_f, where the spring force has fallen to F_f (the film
re-solidifies while the wall still moves, as in Klein's traces and the MD's),
then the stick ramp.  :func:`fit_slips` fits F_k, the film's damping B, F_f and
each slip's yield to every analysed slip of a run at once; :func:`fit_slip_law`
does so for a :class:`~filmfriction.analysis.calibration.rundata.RunData`.

The fit works on dimensionless numbers: forces in units of the slips' own force
drop F0 (the median peak-to-trough of the fitted windows), times in units of
T0 = sqrt(M/K), so B in units of sqrt(K M).  The same trace in N, m, s or in
µN, nm, ms or in LJ units is the same problem to the optimiser, and its
parameters scale back to the same physical values.

The slip's model is in :mod:`~filmfriction.analysis.calibration.slip_model`, the fit's
result in :mod:`~filmfriction.analysis.calibration.slip_result` (both named here too).
"""
from __future__ import annotations

import math

import numpy as np

from .estimators import Estimate
from .rundata import RunData
from .slip_model import coulomb_slip_force
from .slip_result import SlipLawFit
from ..files.trace import UNITS

__all__ = ["coulomb_slip_force", "SlipLawFit", "fit_slips", "fit_slip_law", "LEAD_SAMPLES"]

#: Samples before each detected yield point that the fit's window starts with.
LEAD_SAMPLES = 4


def _windows(n_samples: int, yi, si) -> list[tuple[int, int]]:
    """(yield, end) per slip: from y to s plus as long again after s (the re-stick and the
    start of the next ramp), not past the next yield."""
    out = []
    for j, (y, s) in enumerate(zip(yi, si)):
        nxt = yi[j + 1] if j + 1 < len(yi) else n_samples - 1
        hi = min(int(s + max(s - y, 2)), int(nxt), n_samples - 1)
        if hi - y >= 4:
            out.append((int(y), int(hi)))
    return out


def _stick_noise(f: np.ndarray, spans) -> float:
    """Variance of the force's noise on the stick ramps between the fitted windows: the
    scatter about a straight line fitted to each ramp, the median over the ramps (a
    stretch that holds an unfitted slip does not count; NaN without ramps of more
    than 8 samples)."""
    edges = [0] + [x for lo, hi in spans for x in (lo, hi)] + [f.size - 1]
    out = []
    for a, b in zip(edges[::2], edges[1::2]):
        seg = f[a + 1:b]
        if seg.size > 8:
            x = np.arange(seg.size, dtype=float)
            out.append(float(np.sum((seg - np.polyval(np.polyfit(x, seg, 1), x)) ** 2))
                       / (seg.size - 2))
    return float(np.median(out)) if out else math.nan


def _serial_correlation(r: np.ndarray, sizes) -> float:
    """The variance factor of the residuals' serial correlation, (1 + rho)/(1 - rho) with
    rho their lag-one autocorrelation pooled within the windows of ``sizes`` (an AR(1)
    noise's ratio of long-run to plain variance: about 1 for white noise, 19 for
    rho = 0.9)."""
    rows = np.cumsum([0] + list(sizes))
    segs = [r[a:b] - np.mean(r[a:b]) for a, b in zip(rows[:-1], rows[1:]) if b - a > 2]
    var = sum(float(np.dot(x, x)) for x in segs)
    if var <= 0.0:
        return 1.0
    rho = min(sum(float(np.dot(x[:-1], x[1:])) for x in segs) / var, 0.99)
    return (1.0 + rho) / (1.0 - rho)


def fit_slips(time, spring_force, slips, *, spring_constant: float, mass: float,
              drive_velocity: float = 0.0, mount_damping: float = 0.0,
              stick_stiffness: float | None = None, units: str = "lj",
              jackknife: bool = True, start=None) -> SlipLawFit:
    """Fit F_k, the film's damping B, the freeze force F_f and each slip's yield.

    Each slip's window starts on the stick ramp before the detected yield y (as
    many samples as the slip lasts, at least :data:`LEAD_SAMPLES`, at most half
    the preceding stick) and ends as long after the re-stick s as the slip
    lasted.  The model there is the stick ramp c_i + K_eff V t until the yield
    instant t_y,i + δ_i, then :func:`coulomb_slip_force` with F_k, B + d and F_f,
    then the stick ramp from where the slip ends.  Per slip, the ramp's level c_i
    and δ_i (anywhere on the window's ramp, or up to a quarter of the slip after y)
    are free: the peak of a sampled, noisy trace is flat, its detected yield point
    lags the true one by several samples and its force is known to the noise,
    and a slip started from the wrong force or instant biases F_k and B.

    The fit runs in the dimensionless variables of the module docstring with
    :func:`scipy.optimize.least_squares` (trust-region reflective, ``x_scale="jac"``;
    bounds F_k ∈ [0, min F_s,i), B ≥ 0, F_f between the windows' lowest force and
    min F_s,i), from the best point of a coarse grid over (F_k, B): once without a
    freeze, and with F_f starting at the slips' re-stick level and a little above
    it.  The freeze is kept where it lowers χ² by at least 25 (5 σ for one
    parameter more), else the slips end at rest.

    Standard errors: the diagonal of (JᵀJ)⁻¹ s² c at the solution, J the Jacobian
    of every varied parameter, s² the residual variance per degree of freedom and
    c = (1 + ρ)/(1 − ρ) from the residuals' lag-one autocorrelation ρ (1 for white
    noise).  A parameter at its bound gets none (``at_bound``); J still holds its
    column, so that the others' errors carry the freedom the data leave it (where
    that makes JᵀJ singular, the parameters off their bounds alone).  That is the
    conservative choice: where the truth sits at the bound (Klein's F_k = 0) the errors
    are too wide (B's about nine times its scatter), but the constrained model's errors,
    right there, are far too narrow where the fit pinned a parameter whose truth is off
    the bound (B = 0 for a B > 0: F_k off by 4–55 of its errors; docs/results/validation.md).

    Parameters
    ----------
    time, spring_force : array_like
    slips : sequence of (int, int, float)
        (yield index y, re-stick index s, F_s at y) per slip, in time order.
    spring_constant, mass, drive_velocity, mount_damping : float
        K, M, V and the mount's dashpot d (fixed).
    stick_stiffness : float, optional
        K_eff, the stick ramps' slope over V (an elastic stuck film's, below K);
        default K.
    units : str
        ``lj`` or ``si``: the labels of the estimates.
    jackknife : bool
        Also refit with each slip left out (≥ 3 slips; the ``jackknife`` cross-check).
    start : (float, float, float or None), optional
        (F_k, B, F_f) to start from instead of the grid's best point (F_f None: the
        fit with a freeze starts from the grid's).

    Raises
    ------
    ValueError
        No slip window with enough samples, or K, M not positive.
    """
    from scipy.optimize import least_squares

    k, m = float(spring_constant), float(mass)
    if not (k > 0 and m > 0):
        raise ValueError(f"the slip fit needs K > 0 and M > 0 (K = {k:g}, M = {m:g})")
    v, d = float(drive_velocity or 0.0), float(mount_damping or 0.0)
    k_eff = k if stick_stiffness is None or not math.isfinite(stick_stiffness) else \
        float(stick_stiffness)
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    slips = [(int(y), int(s), float(fs)) for y, s, fs in slips]
    wins = _windows(t.size, [y for y, _, _ in slips], [s for _, s, _ in slips])
    if not wins:
        raise ValueError(f"no slip with enough samples to fit ({len(slips)} slips)")
    dt = float(np.median(np.diff(t)))

    # the problem's own scales
    f0 = float(np.median([np.ptp(f[a:b + 1]) for a, b in wins]))
    if not f0 > 0:
        raise ValueError("the slip windows' force does not vary: nothing to fit")
    t0 = math.sqrt(m / k)
    b0 = math.sqrt(k * m)                      # damping unit; critical damping is 2 b0
    vv, dd, h = v * t0 * k / f0, d / b0, dt / t0
    rr = vv * k_eff / k                        # the stick ramps' slope
    by_yield = {y: (s, fs) for y, s, fs in slips}
    previous_stick = {y: (slips[j - 1][1] if j else 0) for j, (y, _, _) in enumerate(slips)}
    data, spans, shift_range = [], [], []
    for a, b in wins:
        s, fs = by_yield[a]
        lead = max(LEAD_SAMPLES, min(s - a, (a - previous_stick[a]) // 2))
        lo = max(a - lead, 0)
        data.append(((t[lo:b + 1] - t[a]) / t0, f[lo:b + 1] / f0, fs / f0))
        spans.append((lo, b))
        # a noisy peak is flat: the detected y may lag the yield by several samples
        shift_range.append((-float(a - lo - 1), float(max(2, (s - a) // 4))))
    n = len(data)
    npts = sum(x[0].size for x in data)
    fs_min = min(fs for _, _, fs in data)
    upper_fk = max(0.999 * fs_min, 1e-9)
    level_span = 0.5
    # a freeze force below the lowest force of the windows cannot act
    ff_low = min(float(np.min(x[1])) for x in data) - 0.05

    def one(i, fk, b, ff, delta, level):
        tt, fi, fs = data[i]
        tau = delta * h
        return coulomb_slip_force(tt - tau, fs + level + rr * tau, fk, b + dd, 1.0, 1.0, vv,
                                  freeze_force=-math.inf if math.isnan(ff) else ff,
                                  stick_rate=rr) - fi

    def pieces(p, subset):
        m_ = len(subset)
        return [one(i, p[0], p[1], p[2], p[3 + j], p[3 + m_ + j]) for j, i in enumerate(subset)]

    def resid(p, subset):
        return np.concatenate(pieces(p, subset))

    def bounds(subset):
        m_ = len(subset)
        lower = [0.0, 0.0, ff_low] + [shift_range[i][0] for i in subset] + [-level_span] * m_
        upper = [upper_fk, 1e4, upper_fk] + [shift_range[i][1] for i in subset] + [level_span] * m_
        return np.array(lower), np.array(upper)

    def jac(p, subset, vary):
        """Forward differences of the varied parameters; a slip's yield shift and ramp
        level act on that slip only, so one evaluation with all shifts (all levels)
        stepped gives their columns."""
        _, upper = bounds(subset)
        m_ = len(subset)
        base = pieces(p, subset)
        flat = np.concatenate(base)
        rows = np.cumsum([0] + [x.size for x in base])
        out = np.zeros((flat.size, p.size))
        step = 1e-7 * np.maximum(np.abs(np.nan_to_num(p)), 1e-2)
        step = np.where(p + step > upper, -step, step)
        for c in range(3):
            if vary[c]:
                q = p.copy()
                q[c] += step[c]
                out[:, c] = (resid(q, subset) - flat) / step[c]
        for first in (3, 3 + m_):
            q = p.copy()
            q[first:first + m_] += step[first:first + m_]
            for j, piece in enumerate(pieces(q, subset)):
                out[rows[j]:rows[j + 1], first + j] = (piece - base[j]) / step[first + j]
        return out[:, vary]

    def solve(subset, start, *, freeze=True, tol=1e-8, fixed=None):
        """least_squares over the parameters (no freeze, F_f = NaN, unless ``freeze``;
        the parameter ``fixed`` indexes held at its start's value); returns the full
        parameter vector, the residuals, the Jacobian of the varied ones, which were
        varied, and scipy's result."""
        lower, upper = bounds(subset)
        vary = np.ones(lower.size, bool)
        vary[2] = freeze
        if fixed is not None:
            vary[fixed] = False
        full = np.asarray(start, float).copy()
        full[vary] = np.clip(full[vary], lower[vary], upper[vary])
        if not freeze:
            full[2] = math.nan

        def expand(x):
            q = full.copy()
            q[vary] = x
            return q

        sol = least_squares(lambda x: resid(expand(x), subset), x0=full[vary],
                            jac=lambda x: jac(expand(x), subset, vary),
                            bounds=(lower[vary], upper[vary]), x_scale="jac",
                            ftol=tol, xtol=tol, gtol=tol)
        return expand(sol.x), sol.fun, sol.jac, vary, sol

    every = list(range(n))
    some = every[:: max(1, n // 3)][:3]
    # where the slips re-stick: the line through the ramp after each detected s, at s (the
    # force at s itself, a minimum of noisy samples, lies below it by about the noise)
    after = []
    for a, b in wins:
        s_ = by_yield[a][0]
        if b - s_ >= 3:
            after.append(float(np.polyval(np.polyfit(t[s_:b + 1] - t[s_], f[s_:b + 1], 1), 0.0)))
        else:
            after.append(float(f[s_]))
    restick = min(max(float(np.median(after)) / f0, ff_low), upper_fk)

    def grid_start(freeze_force):
        """The best point of a coarse grid over (F_k, B) on up to three slips, each slip
        at its detected yield, F_f fixed (NaN: no freeze; else F_k below it, where an
        overdamped slip reaches the freeze)."""
        best = None
        top = 0.95 * (fs_min if math.isnan(freeze_force) else min(fs_min, freeze_force))
        for fk in np.linspace(0.0, top, 7) if top > 0 else [0.0]:
            for b in np.geomspace(2e-3, 2e2, 11):
                q = np.concatenate([[fk, b, freeze_force], np.zeros(2 * len(some))])
                rq = resid(q, some)
                if not math.isnan(freeze_force):
                    # a start where the freeze never acts leaves the fit nothing to vary
                    q0 = q.copy()
                    q0[2] = math.nan
                    if np.array_equal(rq, resid(q0, some)):
                        continue
                cost = float(np.sum(rq ** 2))
                if best is None or cost < best[0]:
                    best = (cost, q[:3])
        if best is None:
            return None
        return np.concatenate([best[1], np.zeros(2 * n)])

    # starts: the grid's best without a freeze, and with F_f at the slips' re-stick level
    # and a little above it (where the grid's best at that level leaves a freeze that never
    # acts, the fit cannot find one)
    freeze_levels = [min(restick + step, upper_fk) for step in (0.0, 0.03, 0.1)]
    if start is not None:
        ff0 = math.nan if start[2] is None else start[2] / f0
        p0 = np.concatenate([[start[0] / f0, start[1] / b0, ff0], np.zeros(2 * n)])
        starts = (p0, [p0] if not math.isnan(ff0) else [grid_start(x) for x in freeze_levels])
    else:
        starts = (grid_start(math.nan), [grid_start(x) for x in freeze_levels])
    starts = (starts[0], [q for q in starts[1] if q is not None])
    # the slips ending at rest, and the film freezing at F_f, each fitted from its own
    # start; the freeze is kept only where it lowers chi^2 by 25 or more (5 sigma for one
    # parameter more; a freeze near the force's minimum, where a slip ending at rest has
    # its turning point, fits noise more often than one parameter would): a freeze kept
    # by chance moves F_k and B
    p, r, jmat, vary, sol = solve(every, starts[0], freeze=False)
    sizes = [x[0].size for x in data]
    gain = 0.0
    if starts[1]:
        pf, rf, jf, varyf, solf = min((solve(every, q, freeze=True) for q in starts[1]),
                                      key=lambda x: float(np.sum(x[1] ** 2)))
        # chi^2 in independent samples: the residual variance times their serial correlation
        s2_free = (float(np.sum(rf ** 2)) / max(rf.size - pf.size, 1)
                   * _serial_correlation(rf, sizes))
        gain = (float(np.sum(r ** 2)) - float(np.sum(rf ** 2))) / s2_free
    if gain >= 25.0:
        p, r, jmat, vary, sol = pf, rf, jf, varyf, solf
        freeze_note = f"the freeze lowers chi^2 by {gain:.3g}"
    else:
        freeze_note = (f"none: the slips end with the wall at rest (a freeze lowers chi^2 by "
                       f"{max(gain, 0.0):.2g} < 25 only)")
    lower, upper = bounds(every)
    span = upper - lower
    at_lower = vary & (p - lower <= 1e-6 * span)
    at_upper = vary & (upper - p <= 1e-6 * span)
    at_bound = at_lower | at_upper
    p = np.where(at_lower, lower, np.where(at_upper, upper, p))
    free = vary & ~at_bound
    # standard errors: (J^T J)^-1 s^2 c over the parameters off their bounds, s^2 the
    # residual variance per degree of freedom, c the residuals' serial correlation
    dof = max(r.size - int(free.sum()), 1)
    s2 = float(np.sum(r ** 2)) / dof
    corr = _serial_correlation(r, sizes)
    # the covariance is over every varied parameter, those at a bound too: the others'
    # errors then include the freedom of a parameter that the data only bound (F_k = 0 is
    # as consistent with the slips as a small F_k > 0); without that (a singular matrix)
    # over the ones off their bounds
    err = np.full(p.size, math.nan)
    for use in (vary, free):
        cols = jmat[:, use[vary]]
        try:
            cov = np.linalg.inv(cols.T @ cols)
        except np.linalg.LinAlgError:
            continue
        diag = np.diag(cov)
        if np.all(np.isfinite(diag)) and np.all(diag > 0):
            e_all = np.full(p.size, math.nan)
            e_all[use] = np.sqrt(diag * s2 * corr)
            err[free] = e_all[free]
            break
    # a parameter pinned at its lower bound (F_k = 0, B = 0) has no standard error; what the
    # data allow is its one-sided 95 % upper limit: where the fit with it held there (the
    # others refitted) has χ² higher by 2.71 in units of the residual variance times the
    # serial correlation
    limits = [math.nan, math.nan]
    unit = s2 * corr
    for j in (0, 1):
        if at_lower[j] and unit > 0:
            limits[j] = _upper_limit(
                lambda q, j=j: (float(np.sum(solve(every, np.where(np.arange(p.size) == j, q, p),
                                                   freeze=bool(vary[2]), fixed=j)[1] ** 2))
                                - float(np.sum(r ** 2))) / unit,
                float(upper[j]))
    shifts = p[3:3 + n] * dt
    yield_forces = np.array([(data[i][2] + p[3 + n + i] + rr * p[3 + i] * h) * f0 for i in every])
    noise = _stick_noise(f / f0, spans)
    jack = []
    if jackknife and n >= 3:
        for i in every:
            sub = [j for j in every if j != i]
            start_i = np.concatenate([p[:3], p[3:3 + n][sub], p[3 + n:][sub]])
            x_i = solve(sub, start_i, freeze=bool(vary[2]))[0]
            jack.append((float(x_i[0] * f0), float(x_i[1] * b0)))
    u = UNITS[units]
    how = (f"least squares over {n} slip{'s' if n != 1 else ''} ({npts} samples) in units of "
           f"the slips' force drop {f0:.4g} {u['force']} and sqrt(M/K) = {t0:.4g} "
           f"{u['time']}; standard error from the Jacobian at the solution, the residual "
           f"variance and the residuals' serial correlation (factor {corr:.3g})")
    law = "joint slip fit (Coulomb + viscous" + (", freeze force)" if vary[2] else ")")
    names = (("kinetic_force", f0, u["force"], "F_k = 0: no rate-independent part resolved"),
             ("film_damping", b0, u["damping"],
              f"B = 0: no film drag beyond the mount's dashpot (d = {d:.4g}) resolved"),
             ("freeze_force", f0, u["force"], "the freeze force at its bound"))
    est = {}
    for j, (name, scale, label, bound_note) in enumerate(names):
        if not vary[j]:
            est[name] = None
        elif at_bound[j]:
            lim = limits[j] * scale if j < 2 else math.nan
            est[name] = Estimate(float(p[j] * scale), math.nan, label,
                                 f"{law}, at the bound of its range ({bound_note})"
                                 + (f"; below {lim:.3g} {label} (95 %, one-sided: the fit's "
                                    "χ² profile)" if math.isfinite(lim) else ""),
                                 at_bound=True, limit=lim)
        else:
            est[name] = Estimate(float(p[j] * scale), float(err[j] * scale), label, law)
    fs_err = float(yield_forces.std(ddof=1) / math.sqrt(n)) if n > 1 else math.nan
    return SlipLawFit(
        kinetic_force=est["kinetic_force"], film_damping=est["film_damping"],
        freeze_force=est["freeze_force"], freeze_note=freeze_note,
        static_force=Estimate(float(yield_forces.mean()), fs_err, u["force"],
                              f"spring force at the fitted yield points of {n} slips, "
                              "mean ± stderr"),
        mount_damping=d, rms_residual=float(np.sqrt(np.mean(r ** 2)) * f0),
        reduced_chi2=float(s2 / noise) if noise > 1e-20 else math.nan,
        n_slips=n, jackknife=jack, windows=wins, yield_shifts=tuple(float(x) for x in shifts),
        scales={"force": f0, "time": t0, "damping": b0},
        error_method=how, success=bool(sol.success), message=str(sol.message))



#: Δχ² (in noise units) of a one-sided 95 % limit on one parameter: the χ²₁ quantile 0.90.
ONE_SIDED_95 = 2.7055


def _upper_limit(excess, upper: float) -> float:
    """The q > 0 where ``excess(q)`` (the fit's χ² with the parameter held at q, less its
    minimum, in noise units) reaches :data:`ONE_SIDED_95`, by doubling from a small q and
    then bisection (brentq); ``upper`` if even the parameter's upper bound is allowed, NaN
    if no bracket is found."""
    from scipy.optimize import brentq

    g = lambda q: excess(q) - ONE_SIDED_95            # noqa: E731
    lo, q = 0.0, min(1e-3, upper)
    for _ in range(40):
        if g(q) >= 0:
            return float(brentq(g, lo, q, xtol=1e-4 * q, rtol=1e-3, maxiter=30))
        if q >= upper:
            return float(upper)
        lo, q = q, min(2.0 * q, upper)
    return math.nan


def fit_slip_law(run: RunData, *, stick_stiffness: float | None = None,
                 jackknife: bool = True) -> SlipLawFit:
    """:func:`fit_slips` on the analysed slips of a run (the start-up yield left out as in
    the analysis' summaries), with the stick ramps' K_eff ``stick_stiffness`` if given.

    Raises
    ------
    ValueError
        No slips to fit, or missing K / M.
    """
    tr = run.trace
    p = tr.parameters
    k = p.require("spring_constant", "the slip fit")
    m = p.require("mass", "the slip fit")
    yi = run.cycles["yield_index"][run.skip:]
    si = run.cycles["stick_index"][run.skip:]
    fs = np.asarray(run.cycles["static_force"], float)[run.skip:]
    try:
        return fit_slips(tr.time, tr.spring_force, list(zip(yi, si, fs)), spring_constant=k,
                         mass=m, drive_velocity=p.drive_velocity or 0.0,
                         mount_damping=p.mount_damping or 0.0,
                         stick_stiffness=stick_stiffness, units=tr.units, jackknife=jackknife)
    except ValueError as exc:
        raise ValueError(f"{run.run_dir}: {exc} ({run.n_slips} slips detected, regime "
                         f"{run.analysis.get('regime')})") from None
