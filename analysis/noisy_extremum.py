"""The extremum of a noisy force: a least-squares fit of the turn's shape, with its bias
and errors from a parametric bootstrap (:func:`noisy_extremum`).

The highest point of a curve fitted to noisy samples leans towards the noise: the
fitted turn is sharper or higher than the true one as often as the noise makes it so,
and the highest point of the fit picks those cases (a parabola's vertex value
c − b²/4a grows with the noise in b; a knot scanned over the window settles where the
noise peaks).  The same fit, repeated on the fitted curve plus noise of the trace's
own standard deviation and correlation, shows how far its extremum lies from the
curve's, on average (the bias, subtracted) and from replicate to replicate (the
errors of the value and of the time).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["NoisyExtremum", "noisy_extremum", "NOISY_WINDOW_SIGMAS", "NOISY_WINDOW_MAX",
           "NOISY_WINDOW_SMOOTHING_MAX", "BOOTSTRAP_REPLICATES"]

#: the window of a noisy extremum's fit reaches where the (lightly smoothed) force
#: has fallen this many noise standard deviations below it, at most
#: ``NOISY_WINDOW_MAX`` samples on each side
NOISY_WINDOW_SIGMAS = 6.0
NOISY_WINDOW_MAX = 120
#: the force that bounds the window is smoothed over the noise's decorrelation lag, at
#: most this many samples each side: a longer average (AR(1) noise of ρ = 0.9 has a lag
#: of ~19 samples) blurs the turn it bounds, on a slip of a few tens of samples
NOISY_WINDOW_SMOOTHING_MAX = 4
#: replicates of the parametric bootstrap (the bias' own error is 1/√R of the spread)
BOOTSTRAP_REPLICATES = 64


@dataclass(frozen=True)
class NoisyExtremum:
    """The maximum of a noisy force about one sample (:func:`noisy_extremum`).

    Attributes
    ----------
    time, value : float
        Where the fitted curve is highest and its value there, less the fit's bias.
    time_error, value_error : float
        Their standard errors from the noise (the half-width of the bootstrap's
        central 68 %, with the bias' own error).
    time_bias, value_bias : float
        The bias subtracted (the bootstrap's mean extremum less the curve's).
    shape : str
        The fitted shape: ``"turn"`` (a parabola), ``"slip-after"`` (a stick ramp
        the slip leaves at a knot) or ``"slip-before"`` (a ramp the slip joins).
    """

    time: float
    value: float
    time_error: float
    value_error: float
    time_bias: float
    value_bias: float
    shape: str


def _window(t, g, i, lo, hi, sigma, lag):
    """The fit's samples about i: where the force, smoothed over ``lag`` samples, has
    fallen :data:`NOISY_WINDOW_SIGMAS` σ below its top, at most :data:`NOISY_WINDOW_MAX`
    samples each side, at least 2 (the smoothing at most
    :data:`NOISY_WINDOW_SMOOTHING_MAX` samples each side)."""
    from scipy.ndimage import uniform_filter1d

    m = min(max(1, int(lag)), NOISY_WINDOW_SMOOTHING_MAX)
    seg = g[lo:hi + 1]
    sm = uniform_filter1d(seg, size=2 * m + 1, mode="nearest") if m > 1 or seg.size > 4 else seg
    k = i - lo
    top = sm[max(k - m, 0):k + m + 1].max()
    floor = top - NOISY_WINDOW_SIGMAS * sigma
    left = np.flatnonzero(sm[:k] < floor)
    right = np.flatnonzero(sm[k + 1:] < floor)
    a = max(k - NOISY_WINDOW_MAX, (int(left[-1]) if left.size else 0), k - seg.size)
    b = min(k + NOISY_WINDOW_MAX, (k + 1 + int(right[0])) if right.size else seg.size - 1)
    a, b = max(0, min(a, k - 2)), min(seg.size - 1, max(b, k + 2))
    return lo + a, lo + b


def _shapes(u):
    """Design matrices of every candidate shape on the times u (scaled to [−1, 1]):
    (X of shape (C, n, 4), parameters per shape, kind per shape (0: parabola, 1: slip
    after the knot, −1: slip before it), knot per shape).

    A knot shape is f = c0 + c1 u + c2 d + c3 d², d the time since the ramp was left
    (after the knot) or until it is joined (before it), 0 on the ramp: smooth at the
    knot (c2 = 0, the force's slope K(V − v) is continuous while the wall's velocity
    is) or a corner (c2 free: a film that freezes at a speed, the velocity jumping to
    0)."""
    n = u.size
    one = np.ones_like(u)
    quad = np.column_stack([one, u, u * u, np.zeros_like(u)])[None]
    if n < 6:
        return quad, np.array([3]), np.array([0]), np.array([0.0])
    knots = u[1:-1]
    after = np.clip(u[None, :] - knots[:, None], 0.0, None)
    before = np.clip(knots[:, None] - u[None, :], 0.0, None)
    d = np.concatenate([after, before, after, before])
    c = d.shape[0]
    x = np.empty((c, n, 4))
    x[:, :, 0], x[:, :, 1], x[:, :, 2], x[:, :, 3] = 1.0, u, d, d * d
    x[c // 2:, :, 2] = 0.0                      # the smooth knots
    side = np.concatenate([np.ones(knots.size, int), -np.ones(knots.size, int)])
    kinds = np.concatenate([[0], side, side])
    params = np.concatenate([[3], np.full(c // 2, 5), np.full(c // 2, 4)])
    return (np.concatenate([quad, x]), params, kinds,
            np.concatenate([[0.0], knots, knots, knots, knots]))


def _highest(coef, kind, knot, u0, u1):
    """Where each fitted curve (rows of ``coef``, shapes ``kind`` with ``knot``) is
    highest on [u0, u1], and its value there."""
    c0, c1, c2, c3 = coef.T
    cand = [np.full(c0.shape, u0), np.full(c0.shape, u1), knot.copy()]
    with np.errstate(divide="ignore", invalid="ignore"):
        # the parabola's vertex; the slip side's turn (d = u − knot after, knot − u before)
        vertex = np.where(kind == 0, -c1 / (2 * c2),
                          np.where(kind > 0, knot - (c1 + c2) / (2 * c3),
                                   knot - (c1 - c2) / (2 * c3)))
    cand.append(vertex)
    cand = np.stack(cand, axis=1)                              # (R, 4)
    inside = np.isfinite(cand) & (cand >= u0) & (cand <= u1)
    cand = np.where(inside, cand, u0)
    d = np.where(kind[:, None] > 0, np.clip(cand - knot[:, None], 0.0, None),
                 np.clip(knot[:, None] - cand, 0.0, None))
    curve = np.where(kind[:, None] == 0,
                     c0[:, None] + c1[:, None] * cand + c2[:, None] * cand * cand,
                     c0[:, None] + c1[:, None] * cand + c2[:, None] * d + c3[:, None] * d * d)
    j = np.argmax(curve, axis=1)
    rows = np.arange(cand.shape[0])
    return cand[rows, j], curve[rows, j]


def _fit(x, pinv, params, kinds, knots, y, u0, u1):
    """The lowest-BIC shape for each column of y: (its index, its coefficients, the
    curve's highest point (u, value))."""
    n = y.shape[0]
    coef = pinv @ y                                            # (C, 4, R)
    xty = np.swapaxes(x, 1, 2) @ y                             # (C, 4, R)
    rss = np.sum(y * y, axis=0)[None, :] - np.einsum("ckr,ckr->cr", coef, xty)
    bic = n * np.log(np.maximum(rss, 1e-300 * n) / n) + params[:, None] * math.log(n)
    best = np.argmin(bic, axis=0)                              # (R,)
    cols = np.arange(y.shape[1])
    b = coef[best, :, cols]                                    # (R, 4)
    top_u, top_v = _highest(b, kinds[best], knots[best], u0, u1)
    return best, b, top_u, top_v


def noisy_extremum(t, g, i, lo, hi, sigma, *, lag=1, correlation=0.0,
                   replicates=BOOTSTRAP_REPLICATES) -> NoisyExtremum:
    """Maximum of g about sample i (within [lo, hi]) on a noisy trace.

    The fit: over the samples within :data:`NOISY_WINDOW_SIGMAS` σ of the top (the
    force smoothed over ``lag`` samples), a parabola (a smooth turn) and a stick ramp
    that the slip leaves (or joins) at a knot -- a line on one side, a line plus a
    parabola on the other, the knot scanned over the window's samples -- whichever has
    the lowest Bayesian information criterion; the extremum is the fitted curve's
    highest point.

    The bootstrap: the fitted curve plus ``replicates`` draws of AR(1) noise of
    standard deviation ``sigma`` and coefficient ``correlation`` per sample (the
    trace's own, :func:`filmfriction.analysis.noise.noise_correlation`), each fitted
    the same way.  The mean of their extrema less the curve's own is the fit's bias
    (subtracted from value and time), the half-width of their central 68 % the noise
    error (with the bias' own error, 1/√R of it).  The draws are seeded by ``i``: the same
    trace gives the same answer.

    Parameters
    ----------
    t, g : ndarray
        Sample times and the force (negated for a minimum).
    i, lo, hi : int
        The extreme sample and the range the window may span.
    sigma : float
        The noise's standard deviation (> 0).
    lag : int
        The noise's decorrelation lag in samples (the window's smoothing).
    correlation : float
        AR(1) coefficient of the noise per sample, in [0, 1).
    replicates : int

    Returns
    -------
    NoisyExtremum

    Examples
    --------
    A parabola's top under white noise of 0.05: the estimate is within its errors.

    >>> t = np.linspace(-1.0, 1.0, 81)
    >>> g = 1.0 - 4.0 * (t - 0.1) ** 2 + np.random.default_rng(3).normal(0, 0.05, t.size)
    >>> e = noisy_extremum(t, g, int(np.argmax(g)), 0, t.size - 1, 0.05)
    >>> bool(abs(e.value - 1.0) < 3 * e.value_error), bool(abs(e.time - 0.1) < 3 * e.time_error)
    (True, True)
    """
    from scipy.signal import lfilter

    a, b = _window(t, g, i, lo, hi, sigma, lag)
    u = t[a:b + 1] - t[i]
    step = float(np.median(np.diff(u)))
    if np.all(np.abs(np.diff(u) - step) <= 1e-4 * step):
        # uniform sampling: the ideal grid, whatever the last digits of the times (a
        # unit's rounding in a file must not move 64 replicates' knots)
        u = (np.arange(a, b + 1) - i) * step
    h = float(np.max(np.abs(u))) or 1.0
    u = u / h               # the window's own time scale: the fit is the same in any unit
    y0 = float(g[i])
    y = (g[a:b + 1] - y0) / sigma     # and the noise's force scale
    x, params, kinds, knots = _shapes(u)
    pinv = np.linalg.pinv(x)
    u0, u1 = float(u[0]), float(u[-1])
    best, coef, top_u, top_v = _fit(x, pinv, params, kinds, knots, y[:, None], u0, u1)
    curve = x[best[0]] @ coef[0]
    rho = min(max(float(correlation), 0.0), 0.99)
    rng = np.random.default_rng(int(i))
    e = rng.standard_normal((u.size, replicates))
    e[1:] *= math.sqrt(1.0 - rho * rho)
    if rho:
        e = lfilter([1.0], [1.0, -rho], e, axis=0)
    _, _, boot_u, boot_v = _fit(x, pinv, params, kinds, knots, curve[:, None] + e, u0, u1)
    bias_u, bias_v = float(np.mean(boot_u) - top_u[0]), float(np.mean(boot_v) - top_v[0])
    # the half-width of the replicates' central 68 % (a spread that heavy tails -- a
    # replicate whose knot jumps -- do not inflate), with the bias' own error
    inflate = math.sqrt(1.0 + 1.0 / replicates)
    err_u = 0.5 * float(np.subtract(*np.percentile(boot_u, [84.13, 15.87]))) * inflate
    err_v = 0.5 * float(np.subtract(*np.percentile(boot_v, [84.13, 15.87]))) * inflate
    shape = ("turn", "slip-after", "slip-before")[int(kinds[best[0]])]
    return NoisyExtremum(time=t[i] + (float(top_u[0]) - bias_u) * h,
                         value=y0 + (float(top_v[0]) - bias_v) * sigma,
                         time_error=err_u * h, value_error=err_v * sigma,
                         time_bias=bias_u * h, value_bias=bias_v * sigma, shape=shape)
