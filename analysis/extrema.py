"""The yield and re-stick points between the samples: each slip's force maximum (y, F_s)
and minimum (s, F_b), refined from the detector's extreme samples, with their errors
(:func:`refine_extrema`; the definitions are in docs/analysis.md, "Definitions")."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from filmfriction.reduced_model.cycles import CycleTable

from .noise import cycle_noise, noise_correlation
from .noisy_extremum import noisy_extremum

__all__ = ["refine_extrema", "EXTREMUM_WINDOW_SIGMAS", "PLATEAU_SIGMAS"]


#: an extreme sample that stands this many noise standard deviations above the chord
#: of its neighbours is refined as on a noise-free trace (see :func:`refine_extrema`)
EXTREMUM_WINDOW_SIGMAS = 4.0
#: a flat extremum's samples lie within this many noise standard deviations of the
#: extreme sample (see :func:`refine_extrema`)
PLATEAU_SIGMAS = 2.0


def _quadratic(t, g, lo, hi, centre):
    """Least-squares parabola through g[lo:hi+1] (times relative to ``centre``):
    coefficients (a, b, c) of a u² + b u + c and their covariance (unscaled)."""
    u = t[lo:hi + 1] - centre
    # solved in times scaled to the window (u/h): in raw units u² and 1 can differ by
    # more than float64 resolves (LJ times of 1e11), and the fit would depend on the unit
    h = float(np.max(np.abs(u))) or 1.0
    us = u / h
    xs = np.column_stack([us * us, us, np.ones_like(us)])
    coef_s, *_ = np.linalg.lstsq(xs, g[lo:hi + 1], rcond=None)
    d = np.array([1.0 / (h * h), 1.0 / h, 1.0])
    cov = np.linalg.pinv(xs.T @ xs) * np.outer(d, d)
    return coef_s * d, cov, xs / d


def _secant_bound(t, g, i, lo, hi):
    """Highest value a concave curve through the samples can reach next to sample i,
    and where: the meeting point of the neighbouring pairs' secants, extended
    ((t[i], g[i]) when none meet above it)."""
    best = (t[i], g[i])
    for a, b, c, d in ((i - 2, i - 1, i, i + 1), (i - 1, i, i + 1, i + 2)):
        if a < lo or d > hi:
            continue
        s1 = (g[b] - g[a]) / (t[b] - t[a])
        s2 = (g[d] - g[c]) / (t[d] - t[c])
        if s1 <= s2:
            continue
        tx = (g[c] - g[b] + s1 * t[b] - s2 * t[c]) / (s1 - s2)
        if not t[b] <= tx <= t[c]:
            continue
        value = g[b] + s1 * (tx - t[b])
        if value > best[1]:
            best = (tx, value)
    return best


def _ramp_side(t, g, i, lo, hi, step, tol):
    """Indices of the straight (stick-ramp) samples next to the extremum i on the
    side ``step`` (−1: before, +1: after), nearest first (i itself when it lies on
    the ramp), or [] when that side is curved.  Three samples must be collinear;
    a stick sampled by fewer (the model's own output: a stick is one straight
    segment between its events) is taken as straight."""
    pts = [j for j in (i + step * k for k in (1, 2, 3)) if lo <= j <= hi]
    if not pts:
        return []
    near, far = pts[0], pts[-1]

    def off(j):
        w = (t[j] - t[far]) / (t[near] - t[far])
        return abs(g[j] - (1 - w) * g[far] - w * g[near])
    if len(pts) == 3:
        if off(pts[1]) > tol:
            return []
        return [i] + pts if off(i) <= tol else pts
    if len(pts) == 2:
        # the stick's two events: the steeper rise towards i is the ramp (the other pair
        # reaches into the previous slip)
        def rise(a, b):
            return (g[a] - g[b]) / abs(t[a] - t[b])
        return [i, near] if rise(i, near) >= rise(near, far) else [near, far]
    return [i, near]


def _kink_extremum(t, g, i, lo, hi, tol):
    """The extremum next to a stick ramp: (time, value) or None.

    At a yield the force leaves its straight stick ramp L(t) and bends over (at a
    re-stick it joins the next ramp): f = L + q with q = 0 on the ramp side and
    smooth on the slip side (−K times the wall's displacement since it left the
    ramp).  q is the parabola through the first three slip-side samples; the
    extremum is where f' = L' + q' = 0, or the joint itself (q = 0) when f has
    no turning point on the slip side (a slip that ends by freezing)."""
    for step in (-1, 1):
        ramp = _ramp_side(t, g, i, lo, hi, step, tol)
        if ramp:
            break
    else:
        return None
    a, b = ramp[-1], ramp[-2]
    slope = (g[b] - g[a]) / (t[b] - t[a])
    if not slope * step < 0:             # the ramp rises towards the extremum
        return None
    line = lambda x: g[a] + slope * (x - t[a])  # noqa: E731
    first = ramp[0] - step                     # first slip-side sample
    curved = [first - step * k for k in range(3)]
    if min(curved) < lo or max(curved) > hi:
        return None
    tc = t[curved]
    q = g[curved] - line(tc)
    if not np.all(q < 0):
        return None
    q2, q1, q0 = np.polyfit(tc - t[ramp[0]], q, 2)
    edge = t[ramp[0]]
    # the joint: where q returns to 0 between the last ramp sample and the first slip one
    lo_t, hi_t = sorted((0.0, t[first] - edge))
    roots = np.roots([q2, q1, q0]) if q2 else (np.array([-q0 / q1]) if q1 else np.array([]))
    roots = roots[np.isreal(roots)].real
    roots = roots[(roots >= lo_t) & (roots <= hi_t)]
    joint = float(roots[np.argmin(np.abs(roots))]) if roots.size else (
        float(np.clip(-q1 / (2 * q2), lo_t, hi_t)) if q2 else 0.0)
    if q2 < 0:
        turn = (-slope - q1) / (2 * q2)
        # the turning point lies on the slip side of the joint
        if (turn - joint) * (-step) > 0:
            if abs(turn) > abs(t[curved[-1]] - edge):
                return None
            return edge + turn, float(line(edge + turn) + q2 * turn * turn + q1 * turn + q0)
    return edge + joint, float(line(edge + joint))


def _extremum(t, g, i, lo, hi, sigma, lag, rho):
    """Refined maximum of g about sample i (the highest in [lo, hi]).

    Returns (time, value, noise error of value, noise error of time, systematic
    error of value, systematic error of time).  The systematic error is the one the
    same on every slip, which does not average out: on a noise-free trace the
    sampling's (the range the samples leave open), on a noisy one half the bias the
    bootstrap corrected (:mod:`filmfriction.analysis.noisy_extremum`: the correction
    rests on the fitted shape, which the true one may differ from) and, for the time,
    the fit's resolution of one sample spacing (uniform: spacing/√12)."""
    n_lo, n_hi = i - lo, hi - i
    if n_lo < 1 or n_hi < 1:              # at the end of its range: the sample itself
        dt = t[min(i + 1, hi)] - t[max(i - 1, lo)]
        return t[i], g[i], 0.0, 0.0, 0.0, dt / math.sqrt(12.0)
    a_, b_ = i - 1, i + 1
    coef, cov, _ = _quadratic(t, g, a_, b_, t[i])
    a = coef[0]
    # how far the extreme sample stands above the chord of its neighbours, in σ
    x = (t[i] - t[a_]) / (t[b_] - t[a_])
    bump = g[i] - (1.0 - x) * g[a_] - x * g[b_]
    # unevenly spaced samples (a model's output: long sticks, dense slips) are a
    # noise-free trace's; the noisy fit assumes an even sampling
    gaps = (t[i] - t[a_], t[b_] - t[i])
    uneven = max(gaps) > 3.0 * min(gaps)
    w = 1 if sigma == 0.0 or uneven or bump >= EXTREMUM_WINDOW_SIGMAS * sigma else 2
    if w > 1:      # the noise is comparable to the turn over three samples
        e = noisy_extremum(t, g, i, lo, hi, sigma, lag=lag, correlation=rho)
        # the fit's time resolution: its knots sit on the samples, and where the true
        # turn is sharper than the fitted shape its time is off by up to a sample
        # spacing, the same on every slip (a uniform spread over one spacing)
        resolution = 0.5 * (t[b_] - t[a_]) / math.sqrt(12.0)
        return (e.time, e.value, e.value_error, e.time_error, 0.5 * abs(e.value_bias),
                math.hypot(0.5 * abs(e.time_bias), resolution))
    a, b, c = coef
    u_lo, u_hi = t[a_] - t[i], t[b_] - t[i]
    if a < 0 and u_lo <= -b / (2 * a) <= u_hi:
        tv = -b / (2 * a)
        value = c - b * b / (4 * a)
        grad_v = np.array([b * b / (4 * a * a), -b / (2 * a), 1.0])
        grad_t = np.array([b / (2 * a * a), -1.0 / (2 * a), 0.0])
    else:                                 # no interior vertex: the highest sample
        tv, value = 0.0, g[i]
        grad_v = grad_t = None
    t_peak = t[i] + tv
    if w == 1:
        # noise-free regime: the sampling bounds the peak between the highest
        # sample and where the neighbouring secants meet
        t_bound, bound = _secant_bound(t, g, i, lo, hi)
        value = min(max(value, g[i]), bound)
        if not t[i - 1] <= t_peak <= t[i + 1]:
            t_peak = t[i]
        dt = 0.5 * (t[min(i + 1, hi)] - t[max(i - 1, lo)])
        scale = float(np.ptp(g[lo:hi + 1])) if hi > lo else 0.0
        kink = _kink_extremum(t, g, i, lo, hi, 1e-9 * scale + 4.0 * sigma)
        if kink is not None:
            if not g[i] <= kink[1] <= bound:
                # a sharp corner the slip-side parabola overshoots: where the secants meet
                kink = (t_bound, bound)
            dv, dtk = abs(kink[1] - value), abs(kink[0] - t_peak)
            return kink[0], kink[1], 0.0, 0.0, dv / 2.0, dtk / 2.0
        ev = et = 0.0
        if sigma and grad_v is not None:
            var = sigma * sigma * max(lag, 1)
            ev = math.sqrt(max(float(grad_v @ cov @ grad_v) * var, 0.0))
            et = math.sqrt(max(float(grad_t @ cov @ grad_t) * var, 0.0))
        return t_peak, value, ev, et, (bound - g[i]) / math.sqrt(12.0), dt / math.sqrt(12.0)
    if grad_v is None:
        return t_peak, value, sigma, 0.0, 0.0, 0.0
    var = sigma * sigma * max(lag, 1)
    ev = math.sqrt(max(float(grad_v @ cov @ grad_v) * var, 0.0))
    et = math.sqrt(max(float(grad_t @ cov @ grad_t) * var, 0.0))
    return t_peak, value, ev, et, 0.0, 0.0


def refine_extrema(time, spring_force, table: CycleTable, *, noise: float = 0.0, lag: int = 1,
                   spring_constant: float | None = None, drive_velocity: float | None = None,
                   wall_position=None) -> CycleTable:
    """The yield and re-stick points between the samples: each slip's force maximum
    (y, F_s) and minimum (s, F_b), with their errors.

    The detector's y and s are the highest and lowest samples.  On a noise-free
    trace (the extreme sample stands more than :data:`EXTREMUM_WINDOW_SIGMAS` noise
    standard deviations above the chord of its neighbours) the extremum is the
    parabola's through it and its two neighbours, or, next to a straight stick
    ramp, where the ramp's line and the slip's parabola meet or turn (the value kept
    between the highest sample and the bound of the neighbouring secants, which a
    concave peak cannot exceed); its errors are the sampling's (the range the
    samples leave open, as a uniform distribution).  On a noisy trace it is a
    least-squares fit of the turn's shape, its bias corrected and its errors of
    value and time from a parametric bootstrap with the trace's own noise
    (:func:`filmfriction.analysis.noisy_extremum.noisy_extremum`; half the corrected
    bias is kept as a systematic error, with a sample spacing's resolution for a time).  The noise is the smaller of ``noise``
    (the local estimate, which overstates noise correlated over many samples) and
    the cycle-to-cycle one (:func:`filmfriction.analysis.noise.cycle_noise`, which
    overstates it on a trace whose cycles differ), its correlation from sample to
    sample :func:`filmfriction.analysis.noise.noise_correlation`.

    The times' errors enter the durations (slip, stick, period) and, with the
    forces', the slip distance.

    Slip distance: the wall's displacement x(s) − x(y) = (F_s − F_b)/K + V τ_s
    with K and V; else from ``wall_position`` interpolated at the refined times;
    else (F_s − F_b)/K (the spring's relaxation, short of the slip by V τ_s).

    Returns
    -------
    CycleTable
        With the refined times and forces, the durations between the refined
        times, and ``uncertainty``: per column, the per-slip noise error and
        systematic error (the sampling's, or the noisy fit's; see
        :meth:`CycleTable.summary`).
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    yi, si = table.yield_index, table.stick_index
    m = len(table)
    sigma = float(noise)
    rho = 0.0
    if sigma > 0.0:
        # the local estimate overstates noise correlated over many samples (its longer
        # lags straddle the slips), the cycle-to-cycle one a trace whose cycles differ:
        # the noise is at most either
        cyc = cycle_noise(t, f, yi) if m >= 2 else 0.0
        sigma = min(sigma, cyc) if cyc > 0.0 else sigma
        rho = noise_correlation(f, sigma, time=t)
        lag = min(max(int(lag), 1), math.ceil((1.0 + rho) / (1.0 - rho)))
    cols = {n: np.full(m, math.nan) for n in ("ty", "fy", "ts", "fs")}
    errs = {n: np.zeros(m) for n in ("ty_n", "fy_n", "ts_n", "fs_n",
                                     "ty_r", "fy_r", "ts_r", "fs_r")}
    for j in range(m):
        lo_y = si[j - 1] if j else 0
        hi_s = yi[j + 1] if j + 1 < m else t.size - 1
        y, s = yi[j], si[j]
        if sigma > 0.0:
            # a flat top (the wall creeping with the drive before it slips) or a flat
            # bottom: y is its end, s its start -- the samples within the noise's
            # reach of the extreme one nearest the fall
            band = PLATEAU_SIGMAS * sigma
            y = y + int(np.flatnonzero(f[y:s + 1] >= f[y] - band)[-1])
            s = y + int(np.flatnonzero(f[y:s + 1] <= f[s] + band)[0])
        ty, vy, evy, ety, rvy, rty = _extremum(t, f, y, lo_y, s, sigma, lag, rho)
        ts, vs, evs, ets, rvs, rts = _extremum(t, -f, s, y, hi_s, sigma, lag, rho)
        cols["ty"][j], cols["fy"][j], cols["ts"][j], cols["fs"][j] = ty, vy, ts, -vs
        for key, val in (("ty_n", ety), ("fy_n", evy), ("ts_n", ets), ("fs_n", evs),
                         ("ty_r", rty), ("fy_r", rvy), ("ts_r", rts), ("fs_r", rvs)):
            errs[key][j] = val
    ty, ts = cols["ty"], cols["ts"]
    fs, fb = cols["fy"], cols["fs"]
    nan = np.full(m, math.nan)
    period, stick = nan.copy(), nan.copy()
    if m > 1:
        period[:-1] = np.diff(ty)
        stick[:-1] = ty[1:] - ts[:-1]
    k = None if spring_constant is None else float(spring_constant)
    x0 = fs / k if k else nan.copy()
    tau = ts - ty
    unc = {}
    for kind in ("n", "r"):
        e = {name: errs[f"{name}_{kind}"] for name in ("ty", "fy", "ts", "fs")}
        nxt = np.append(e["ty"][1:], math.nan)
        unc[kind] = {"static_force": e["fy"], "backward_force": e["fs"],
                     "spring_extension": e["fy"] / k if k else nan.copy(),
                     "slip_duration": np.hypot(e["ty"], e["ts"]),
                     "stick_duration": np.hypot(e["ts"], nxt),
                     "period": np.hypot(e["ty"], nxt),
                     "yield_time": e["ty"], "stick_time": e["ts"]}
    if k and drive_velocity:
        dist = (fs - fb) / k + float(drive_velocity) * tau
        for kind in ("n", "r"):
            u = unc[kind]
            u["slip_distance"] = np.hypot(np.hypot(u["static_force"], u["backward_force"]) / k,
                                          float(drive_velocity) * u["slip_duration"])
    elif wall_position is not None:
        x = np.asarray(wall_position, float)
        dist = np.interp(ts, t, x) - np.interp(ty, t, x)
        for kind in ("n", "r"):
            unc[kind]["slip_distance"] = np.zeros(m)
    elif k:
        dist = (fs - fb) / k
        for kind in ("n", "r"):
            u = unc[kind]
            u["slip_distance"] = np.hypot(u["static_force"], u["backward_force"]) / k
    else:
        dist = nan.copy()
    # the samples nearest the refined points (the energy windows, the figures)
    near = lambda x: np.clip(np.searchsorted(t, x), 1, t.size - 1) - (  # noqa: E731
        np.abs(x - t[np.clip(np.searchsorted(t, x), 1, t.size - 1) - 1])
        <= np.abs(t[np.clip(np.searchsorted(t, x), 1, t.size - 1)] - x))
    new_y, new_s = near(ty).astype(np.int64), near(ts).astype(np.int64)
    new_s = np.maximum(new_s, new_y)
    if m > 1:
        new_y[1:] = np.maximum(new_y[1:], new_s[:-1])
    arrays = dict(yield_index=new_y, stick_index=new_s,
                  yield_time=ty, stick_time=ts, static_force=fs, backward_force=fb,
                  spring_extension=x0, slip_distance=dist, slip_duration=tau,
                  stick_duration=stick, period=period)
    for a in arrays.values():
        a.setflags(write=False)
    uncertainty = {name: (unc["n"][name], unc["r"][name]) for name in unc["n"]}
    return replace(table, **arrays, uncertainty=uncertainty)
