"""Fast path for rate-and-state (a smooth law with one state variable): compiled
steps, exact extrema, and the converged limit cycle tiled.

A smooth law (no static threshold) with one state variable makes the block an autonomous
system in (spring extension, velocity, state).  Where the slip is not
overdamped it is not stiff, and the run goes through here:

* **steps:** DOP853 compiled with its right-hand side (:mod:`.smooth_steps`,
  numba): Python is entered once per spring-force extremum, not once per
  evaluation.  The extension ``x_a - x`` is integrated, not the position, so
  rtol applies to the spring force rather than to a growing x; the three
  energy integrals ride along.
* **extrema of the spring force** (the ``slip``/``stick`` events: ``v`` crosses
  the drive speed): the steps stop after the step that crosses and go on from
  there with the step size they had.  The time is the
  root of a quintic Hermite interpolant of ``v`` over the step (values, first and
  second derivatives at both ends; the second from a central difference along
  the flow), the state there one more DOP853 step from the step's start, inserted
  as a sample.  Wiggles smaller than 10^-6 of the force level are dropped, as on
  the general path.
* **limit cycle:** at every force maximum the cycle just finished (period,
  extension and state at the maximum, energy gained per cycle) is compared with
  the one before.  Once the change per cycle shrinks geometrically with ratio
  rho < 1 and its geometric tail ``change * rho / (1 - rho)`` -- the distance
  left to the limit cycle -- is within ``rtol`` of every quantity (and of the
  period), the run is periodic to the accuracy of the integration itself: the
  last cycle is tiled to the end of the run (``Recorder.repeat``) and the
  final part integrated.  Event times of the tiled cycles are then off by at
  most ``rtol`` x period per cycle, what the integrator's own phase error
  accumulates at that tolerance anyway.

:func:`run_smooth` returns ``None`` where this path does not apply, when the
steps find the run stiff after all (a slip slowing to a creep: the step size
underflows or the step budget is spent), or when numba cannot be imported: the
caller then integrates with its stiff-aware LSODA path from the start.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from ..laws.rate_state import RateState

__all__ = ["run_smooth"]

#: local damping ratio (d + dF/dv) / (2 sqrt(K M)) above which this explicit path is not tried
EXPLICIT_ZETA = 1.0
#: extrema of the spring force smaller than this fraction of the force level are round-off
WIGGLE = 1e-6


def _hermite5(h, ya, da, ca, yb, db, cb, s):
    """Quintic Hermite interpolant on [0, h] at the fraction ``s``: value and d/ds."""
    s2 = s * s
    s3, s4, s5 = s2 * s, s2 * s2, s2 * s2 * s
    h0, h1 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5, s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5
    h2 = 0.5 * (s2 - 3.0 * s3 + 3.0 * s4 - s5)
    g0, g1, g2 = 10.0 * s3 - 15.0 * s4 + 6.0 * s5, -4.0 * s3 + 7.0 * s4 - 3.0 * s5, 0.5 * (s3 - 2.0 * s4 + s5)
    dh0, dh1 = -30.0 * s2 + 60.0 * s3 - 30.0 * s4, 1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4
    dh2 = 0.5 * (2.0 * s - 9.0 * s2 + 12.0 * s3 - 5.0 * s4)
    dg0, dg1 = -dh0, -12.0 * s2 + 28.0 * s3 - 15.0 * s4
    dg2 = 0.5 * (3.0 * s2 - 8.0 * s3 + 5.0 * s4)
    hh = h * h
    value = ya * h0 + h * da * h1 + hh * ca * h2 + yb * g0 + h * db * g1 + hh * cb * g2
    slope = ya * dh0 + h * da * dh1 + hh * ca * dh2 + yb * dg0 + h * db * dg1 + hh * cb * dg2
    return value, slope


def _local_zeta(rates, s, state, d, K, M):
    h = max(1e-6 * abs(s), 1e-300)
    try:
        drag = (rates(s + h, state)[0] - rates(s - h, state)[0]) / (2.0 * h)
    except (ValueError, OverflowError, ZeroDivisionError):
        return math.inf
    return (d + drag) / (2.0 * math.sqrt(K * M))


def run_smooth(p, rtol, atol, max_step):
    """Run a smooth law with a state (mass > 0) on the fast path; ``None`` if it does not apply.

    ``atol`` are the absolute tolerances of (position, velocity, the three
    energies, the state) as the general path uses them."""
    law, N, M, K, d, u, va = p.law, p.normal_load, p.mass, p.stiffness, p.damping, p.u, p.va
    if not isinstance(law, RateState) or M <= 0.0:
        return None
    rates = law.scalar_state_rates(N)
    state0 = [float(c) for c in p.state0]
    for s_ref in {abs(va - u), abs(p.v0 - u)}:
        if s_ref > 0.0 and not _local_zeta(rates, s_ref, state0, d, K, M) < EXPLICIT_ZETA:
            return None
    try:
        from . import smooth_steps
    except (ImportError, RuntimeError, OSError) as err:  # numba missing, or no cache dir to write
        warnings.warn(f"the compiled rate-and-state path is unavailable ({err}); "
                      "integrating with LSODA instead (slower)", RuntimeWarning, stacklevel=3)
        return None
    run = _SmoothRun(p, smooth_steps, law.rate_parameters(N), rtol, atol, max_step)
    return run.result() if run.integrate() else None


class _SmoothRun:
    """The integration of :func:`run_smooth`; the ODE's variables are (extension, v, drive
    work, friction and damper dissipation, the law's one state variable)."""

    def __init__(self, p, steps, law_params, rtol, atol, max_step):
        self.p, self.steps, self.law = p, steps, law_params
        self.rtol, self.max_step = float(rtol), float(max_step)
        self.atol = np.asarray(atol, dtype=float)
        M, K, d, u, va = (float(c) for c in (p.mass, p.stiffness, p.damping, p.u, p.va))
        self.K, self.va, self.block = K, va, (K, M, d, u, va)
        self.nfev = 0
        self.rec = p.recorder()
        self.events = []          # kept extrema: [time, kind, force, sample index]
        self.slips = []           # sample indices of the kept maxima
        self.cycles = {}          # (start, end sample of a cycle) -> (its quantities, tolerances)

    # -- one stretch of integration ----------------------------------------------------
    def integrate(self):
        """Integrate to the end (tiling once converged); False if the run turned stiff."""
        p = self.p
        t0, xa0 = 0.0, p.xa0
        y0 = np.concatenate(([p.xa0 - p.x0, p.v0, 0.0, 0.0, 0.0], p.state0)).astype(float)
        self.f_min = self.f_max = self.K * (p.xa0 - p.x0)
        self.h = min(1e-3 * p.period, self.max_step)    # the first step; then the steps' own
        while True:
            ok, tiled = self._stretch(t0, xa0, y0)
            if not ok:
                return False
            if tiled is None:
                return True
            t0, xa0, y0 = tiled

    def _stretch(self, t0, xa0, y0):
        p, steps = self.p, self.steps
        T = p.duration - t0
        self.t0, self.xa0 = t0, xa0
        budget = int(1000 + 400.0 * T / p.period)       # steps; more is a stiff run
        rows = min(budget, 4096) + 2
        self.ts, self.ys = np.empty(rows), np.empty((rows, y0.size))
        self.ts[0], self.ys[0] = 0.0, y0
        self.n = 1
        self.events, self.slips, self.flushed, self.cycles = [], [], 0, {}
        self.e_ref = self.K * float(y0[0])
        while True:
            if self.n + 2 > self.ts.size:               # room for the step and an extremum
                self._grow(min(budget + 2, 2 * self.ts.size))
            n0 = self.n - 1
            code, n, self.h, nfev = steps.advance(
                float(self.ts[n0]), self.ys[n0], T, self.h, self.rtol, self.atol, self.max_step,
                self.block, self.law, True, self.ts, self.ys, self.n, self.ts.size - 1)
            self.nfev += nfev
            self.n = n
            if n > n0 + 1:
                spring = self.K * self.ys[n0 + 1:n, 0]
                self.f_min, self.f_max = min(self.f_min, spring.min()), max(self.f_max, spring.max())
            if code == steps.UNDERFLOW or (code == steps.FULL and n >= budget):
                return False, None
            if code == steps.CROSSED:
                if self._extremum(self.ys[n - 2, 1] < self.va):
                    return True, self._tile()
            elif code == steps.END:
                self._flush(self.n - 1)
                return True, None

    def _grow(self, rows):
        ts, ys = np.empty(rows), np.empty((rows, self.ys.shape[1]))
        ts[:self.n], ys[:self.n] = self.ts[:self.n], self.ys[:self.n]
        self.ts, self.ys = ts, ys

    # -- extrema -----------------------------------------------------------------------
    def _extremum(self, is_max):
        """Locate the extremum in the last step, insert it as a sample, keep it or not;
        True when the run has converged to its limit cycle and should be tiled."""
        ts, ys, va, n = self.ts, self.ys, self.va, self.n
        t_a, t_b, y_a, y_b = float(ts[n - 2]), float(ts[n - 1]), ys[n - 2], ys[n - 1]
        h = t_b - t_a
        eps = 1e-3 * h
        (da, ca), (db, cb) = (self.steps.derivatives(y, eps, self.block, self.law) for y in (y_a, y_b))
        self.nfev += 6
        g_a, g_b = float(y_a[1]) - va, float(y_b[1]) - va
        frac, lo, hi = g_a / (g_a - g_b), 0.0, 1.0
        for _ in range(12):
            val, slope = _hermite5(h, float(y_a[1]), float(da[1]), float(ca[1]),
                                   float(y_b[1]), float(db[1]), float(cb[1]), frac)
            g = val - va
            if (g > 0.0) == (g_a > 0.0):
                lo = frac
            else:
                hi = frac
            step = g / slope if slope != 0.0 else math.inf
            new = frac - step
            if not lo <= new <= hi:
                new = 0.5 * (lo + hi)
            if abs(new - frac) <= 1e-15:
                frac = new
                break
            frac = new
        t_e = t_a + frac * h
        if t_a < t_e < t_b:
            y_e = self._step(y_a, t_a, t_e)
            if y_e is None:
                y_e, _ = _hermite5(h, y_a, da, ca, y_b, db, cb, frac)
            ts[n], ys[n] = t_b, y_b                 # the step's end moves one row on
            ts[n - 1], ys[n - 1] = t_e, y_e
            self.n = n + 1
            j = n - 1
        else:
            j = n - 2 if t_e <= t_a else n - 1
        force = self.K * float(ys[j, 0])
        return self._keep(float(ts[j]), "slip" if is_max else "stick", force, j)

    def _step(self, y_a, t_a, t_e):
        """The state at ``t_e`` by one DOP853 step from the accepted step at ``t_a`` (as
        accurate as the steps themselves; an interpolant is not, for a fast state)."""
        ts, ys = np.empty(9), np.empty((9, y_a.size))
        code, n, _, nfev = self.steps.advance(t_a, y_a, t_e, t_e - t_a, self.rtol, self.atol,
                                              self.max_step, self.block, self.law, False, ts, ys, 0, 8)
        self.nfev += nfev
        return ys[n - 1].copy() if code == self.steps.END and n > 0 else None

    def _keep(self, t_e, kind, force, j):
        events = self.events
        threshold = WIGGLE * max(self.f_max - self.f_min, abs(self.f_max), abs(self.f_min), 1e-300)
        if events and events[-1][1] == kind:
            if (kind == "slip") == (force > events[-1][2]):
                events[-1] = [t_e, kind, force, j]
                if kind == "slip":
                    self.slips[-1] = j
            return False
        if abs(force - (events[-1][2] if events else self.e_ref)) < threshold:
            if events:
                gone = events.pop()
                if gone[1] == "slip":
                    self.slips.pop()
            return False
        events.append([t_e, kind, force, j])
        if kind != "slip":
            return False
        self.slips.append(j)
        return self._converged()

    # -- the limit cycle -----------------------------------------------------------------
    def _cycle(self, k):
        """(period, extension and state at the k-th kept maximum, energies gained since the one before)."""
        ja, jb = self.slips[k - 1], self.slips[k]
        if (ja, jb) in self.cycles:
            return self.cycles[ja, jb]
        ya, yb = self.ys[ja], self.ys[jb]
        q = np.concatenate(([self.ts[jb] - self.ts[ja], yb[0]], yb[5:], yb[2:5] - ya[2:5]))
        tol = self.rtol * np.abs(q) + np.concatenate(([0.0, self.atol[0]], np.full(yb.size - 5, self.rtol),
                                                      self.atol[2:5]))
        self.cycles[ja, jb] = q, tol
        return q, tol

    def _converged(self):
        slips = self.slips
        if len(slips) < 5:
            return False
        # each of the last four cycles: one minimum, then the maximum that ends it
        kinds = [e[1] for e in self.events]
        if kinds[-8:] != ["stick", "slip"] * 4:
            return False
        cycles = [self._cycle(k) for k in range(len(slips) - 4, len(slips))]
        tol = cycles[-1][1]
        change = [float(np.max(np.abs(b[0] - a[0]) / tol)) for a, b in zip(cycles[:-1], cycles[1:])]
        if change[-1] == 0.0:
            return self._copies() >= 1
        if not (0.0 < change[0] and change[1] < change[0] and change[2] < change[1]):
            return False
        rho = max(change[1] / change[0], change[2] / change[1])
        return change[2] * rho / (1.0 - rho) <= 1.0 and self._copies() >= 1

    def _copies(self):
        t_end = self.t0 + self.ts[self.slips[-1]]
        period = self.ts[self.slips[-1]] - self.ts[self.slips[-2]]
        copies = int((self.p.duration - t_end) / period)
        if t_end + copies * period > self.p.duration - 1e-9 * period:
            copies -= 1                         # the last part is integrated
        return copies

    def _tile(self):
        """Record up to the last maximum, tile the last cycle; return where to go on from."""
        ja, jb = self.slips[-2], self.slips[-1]
        copies = self._copies()
        self._flush(ja)
        mark = self.rec.mark()
        self._flush(jb)
        dt, dx, dxa = self.rec.repeat(mark, copies)
        y = self.ys[jb].copy()
        y[2:5] = 0.0
        tau = float(self.ts[jb])
        return self.t0 + tau + dt, self.xa0 + self.va * tau + dxa, y

    # -- recording -----------------------------------------------------------------------
    def _flush(self, j_end):
        """Hand samples flushed+1 .. j_end (and the kept extrema among them) to the recorder."""
        j0 = self.flushed
        if j_end <= j0:
            return
        ts = self.ts[j0:j_end + 1].copy()
        ys = self.ys[j0:j_end + 1].T.copy()
        xa = self.xa0 + self.va * ts
        e0 = ys[2:5, 0:1]
        self.rec.append(self.t0 + ts, xa - ys[0], ys[1], xa, ys[5:], *(ys[2:5] - e0))
        self.rec.nfev = self.nfev
        kept = [e for e in self.events if j0 < e[3] <= j_end]
        self.rec.insert_events([self.t0 + float(self.ts[e[3]]) for e in kept], [e[1] for e in kept])
        self.flushed = j_end

    def result(self):
        return self.rec.finish()
