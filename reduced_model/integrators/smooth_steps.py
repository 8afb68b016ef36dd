"""Compiled DOP853 steps of an inertial block with rate-and-state friction (numba).

The hot loop of :mod:`.limit_cycle`.  SciPy's DOP853 (Fortran or Python) calls a
Python right-hand side at every evaluation, about a microsecond each, and a
rate-and-state stick-slip cycle takes some 300 evaluations at rtol 1e-7.  Here
the steps, their error control and the right-hand side are one function
compiled by numba, so the Python interpreter is entered once per spring-force
extremum, not once per evaluation.

* **method:** Dormand & Prince's 8(5,3) pair, the coefficients read from
  :class:`scipy.integrate.DOP853` (not copied), with SciPy's error estimate
  (the 5th- and 3rd-order estimates combined, as in Hairer's code) and its
  step-size rule (safety 0.9, factor between 0.2 and 10, no growth right after a
  rejection).  ``atol`` is per component; accepted steps are written to the
  caller's arrays.
* **variables:** (spring extension ``x_a - x``, velocity, drive work, friction
  and damper dissipation, log state psi), the right-hand side being
  :func:`.laws.rate_state.state_rates` compiled from its own source.
* **stop:** at the end time, after the first accepted step across
  ``v = V`` (a spring-force extremum) when ``detect``, when the output arrays
  are full, or when the step underflows (the run is stiff: the caller hands it
  to the stiff-aware path).  With the unregularized law (the log form, defined
  for forward slip only) a step that would end at ``v <= u`` is rejected: a
  block that creeps towards rest is stiff, and an explicit step must not carry
  it across into backward slip, where the log form is no law at all.

Compiled functions are cached on disk (``cache=True``): the first run on a
machine compiles for about 3 s, a new process loads them in about 0.2 s.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.integrate import DOP853

from ..laws.rate_state import state_rates

__all__ = ["advance", "derivatives", "END", "CROSSED", "FULL", "UNDERFLOW"]

#: ``advance`` return codes
END, CROSSED, FULL, UNDERFLOW = 0, 1, 2, 3

_A = np.ascontiguousarray(DOP853.A, dtype=np.float64)
_B = np.ascontiguousarray(DOP853.B, dtype=np.float64)
_C = np.ascontiguousarray(DOP853.C, dtype=np.float64)
_E3 = np.ascontiguousarray(DOP853.E3, dtype=np.float64)
_E5 = np.ascontiguousarray(DOP853.E5, dtype=np.float64)
_STAGES = int(DOP853.n_stages)
_EXPONENT = -1.0 / (DOP853.error_estimator_order + 1)

_rates = njit(cache=True)(state_rates)


@njit(cache=True)
def _flow(y, block, law, out):
    """dy/dt; ``block`` = (K, M, d, u, V), ``law`` = ``RateState.rate_parameters(N)``."""
    K, M, d, u, va = block
    v = y[1]
    spring = K * y[0]
    s = v - u
    friction, rate = _rates(s, y[5], law)
    out[0] = va - v
    out[1] = (spring - d * v - friction) / M
    out[2] = spring * va - friction * u
    out[3] = friction * s
    out[4] = d * v * v
    out[5] = rate


@njit(cache=True)
def derivatives(y, eps, block, law):
    """dy/dt at ``y`` and d2y/dt2 (a central difference along the flow over ``eps``)."""
    n = y.size
    f, ahead, back, probe = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    _flow(y, block, law, f)
    for i in range(n):
        probe[i] = y[i] + eps * f[i]
    _flow(probe, block, law, ahead)
    for i in range(n):
        probe[i] = y[i] - eps * f[i]
    _flow(probe, block, law, back)
    for i in range(n):
        ahead[i] = (ahead[i] - back[i]) / (2.0 * eps)
    return f, ahead


@njit(cache=True)
def advance(t, y0, t_end, h, rtol, atol, max_step, block, law, detect, ts, ys, n, n_max):
    """Step from (t, y0) towards ``t_end``, first trying the step ``h``; accepted steps go
    to ``ts[n:]``, ``ys[n:]`` (up to row ``n_max``).

    Returns (code, rows filled, next step size, evaluations)."""
    dim = y0.size
    k = np.empty((_STAGES + 1, dim))
    y, y_new, probe = y0.copy(), np.empty(dim), np.empty(dim)
    _flow(y, block, law, k[0])
    nfev = 1
    u, va = block[3], block[4]
    log_form = law[7] == 0.0            # RateState(regularized=False)
    g_prev = y[1] - va
    rejected = False
    while t < t_end:
        if n >= n_max:
            return FULL, n, h, nfev
        step, last = min(h, max_step), False
        if t + step >= t_end:
            step, last = t_end - t, True
        for s in range(1, _STAGES):
            for i in range(dim):
                acc = 0.0
                for j in range(s):
                    acc += _A[s, j] * k[j, i]
                probe[i] = y[i] + step * acc
            _flow(probe, block, law, k[s])
        for i in range(dim):
            acc = 0.0
            for j in range(_STAGES):
                acc += _B[j] * k[j, i]
            y_new[i] = y[i] + step * acc
        _flow(y_new, block, law, k[_STAGES])
        nfev += _STAGES
        err5, err3 = 0.0, 0.0
        for i in range(dim):
            scale = atol[i] + rtol * max(abs(y[i]), abs(y_new[i]))
            e5, e3 = 0.0, 0.0
            for j in range(_STAGES + 1):
                e5 += _E5[j] * k[j, i]
                e3 += _E3[j] * k[j, i]
            err5 += (e5 / scale) ** 2
            err3 += (e3 / scale) ** 2
        if err5 == 0.0 and err3 == 0.0:
            error = 0.0
        else:
            error = step * err5 / math.sqrt((err5 + 0.01 * err3) * dim)
        if log_form and not y_new[1] - u > 0.0:
            error = math.inf        # the log form holds for forward slip only: step shorter
        if error < 1.0:                                 # accepted (a NaN error is not)
            factor = 10.0 if error == 0.0 else min(10.0, 0.9 * error ** _EXPONENT)
            if rejected:
                factor = min(1.0, factor)
            rejected = False
            if not last or step * factor < h:           # a step cut to t_end keeps h
                h = step * factor
            t = t_end if last else t + step
            for i in range(dim):
                y[i] = y_new[i]
                k[0, i] = k[_STAGES, i]
                ys[n, i] = y_new[i]
            ts[n] = t
            n += 1
            if detect:
                g = y[1] - va
                if (g > 0.0) != (g_prev > 0.0) and g != 0.0 and g_prev != 0.0:
                    return CROSSED, n, h, nfev
                g_prev = g
        else:
            factor = 0.2
            if error == error:                          # not NaN
                factor = max(0.2, 0.9 * error ** _EXPONENT)
            h = step * factor
            rejected = True
            if h < 1e-14 * max(abs(t), abs(t_end - t)):
                return UNDERFLOW, n, h, nfev
    return END, n, h, nfev
