"""Fast path for smooth laws with a state (rate-and-state): compiled steps, exact
extrema, and the converged limit cycle tiled.

A smooth law (no static threshold) with one state variable makes the block an autonomous
system in (spring extension, velocity, state).  Where the slip is not
overdamped it is not stiff, and the run goes through here:

* **steps:** Hairer's Fortran DOP853 (``scipy.integrate.ode``), the step loop
  compiled, the right-hand side a closure on Python floats built from
  ``law.scalar_state_rates`` (no NumPy per evaluation).  The extension
  ``x_a - x`` is integrated, not the position, so rtol applies to the spring
  force rather than to a growing x; the three energy integrals ride along.
* **extrema of the spring force** (the ``slip``/``stick`` events: ``v`` crosses
  the drive speed): the step loop stops at the step that crosses (DOP853 is not
  re-entrant) and goes on from there.  The time is the
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

:func:`run_smooth` returns ``None`` where this path does not apply, or when
DOP853 finds the run stiff after all (a slip slowing to a creep): the caller
then integrates with its stiff-aware LSODA path from the start.
"""
from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.integrate import ode

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
    rates = law.scalar_state_rates(N)
    if rates is None or M <= 0.0 or len(law.state_names) != 1:
        return None
    if law.static_force(p.state0, N) is not None:
        return None
    state0 = [float(c) for c in p.state0]
    for s_ref in {abs(va - u), abs(p.v0 - u)}:
        if s_ref > 0.0 and not _local_zeta(rates, s_ref, state0, d, K, M) < EXPLICIT_ZETA:
            return None
    run = _SmoothRun(p, rates, rtol, atol, max_step)
    return run.result() if run.integrate() else None


class _SmoothRun:
    """The integration of :func:`run_smooth`; the ODE's variables are (extension, v, drive
    work, friction and damper dissipation, the law's one state variable)."""

    def __init__(self, p, rates, rtol, atol, max_step):
        self.p, self.rtol, self.max_step = p, float(rtol), float(max_step)
        M, K, d, u, va = (float(c) for c in (p.mass, p.stiffness, p.damping, p.u, p.va))
        self.K, self.va = K, va
        # DOP853 takes one atol: integrate z = y / scale, the tolerances folded into the scale
        self.scale = scale = np.asarray(atol, dtype=float) / 1e-12
        s0, s1, s2, s3, s4 = (float(c) for c in scale[:5])
        st_scale = [float(c) for c in scale[5:]]
        i0, i1, i2, i3, i4 = 1.0 / s0, 1.0 / s1, 1.0 / s2, 1.0 / s3, 1.0 / s4
        st_inv = [1.0 / c for c in st_scale]
        a1, ks0, dv_i4 = i1 / M, K * s0, d * i4
        self.nfev = 0

        (ss0,), (si0,) = st_scale, st_inv        # one state variable (run_smooth checks)

        def f(tau, z):                          # the hot loop: plain floats only
            z0, z1, _, _, _, z5 = z.tolist()
            vb = z1 * s1
            f_spring = ks0 * z0
            s = vb - u
            fr, r = rates(s, (z5 * ss0,))
            return [(va - vb) * i0, (f_spring - d * vb - fr) * a1, (f_spring * va - fr * u) * i2,
                    fr * s * i3, dv_i4 * vb * vb, r[0] * si0]
        self.f = f
        self.rec = p.recorder()
        self.events = []          # kept extrema: [time, kind, force, sample list index]
        self.slips = []           # sample indices of the kept maxima
        self.cycles = {}          # (start, end sample of a cycle) -> (its quantities, tolerances)

    # -- one stretch of integration ----------------------------------------------------
    def integrate(self):
        """Integrate to the end (tiling once converged); False if DOP853 gave up (stiff)."""
        p = self.p
        t0, xa0 = 0.0, p.xa0
        z0 = np.concatenate(([p.xa0 - p.x0, p.v0, 0.0, 0.0, 0.0], p.state0)) / self.scale
        self.f_min = self.f_max = self.K * (p.xa0 - p.x0)
        while True:
            ok, tiled = self._stretch(t0, xa0, z0)
            if not ok:
                return False
            if tiled is None:
                return True
            t0, xa0, z0 = tiled

    def _stretch(self, t0, xa0, z0):
        p, K, va, scale = self.p, self.K, self.va, self.scale
        T = p.duration
        self.t0, self.xa0 = t0, xa0
        ts, zs = [0.0], [z0]
        self.ts, self.zs = ts, zs
        self.events, self.slips, self.flushed, self.cycles = [], [], 0, {}
        self.e_ref = K * float(z0[0] * scale[0])
        s1, k0 = float(scale[1]), K * float(scale[0])
        g_prev = [float(z0[1]) * s1 - va]
        budget = 1000 + 400.0 * (T - t0) / p.period     # steps; more is a stiff run
        stop = {}

        def solout(tau, z):
            if not tau > ts[-1]:
                return 0
            ts.append(tau)
            zs.append(z.copy())
            if len(ts) > budget:
                stop["stiff"] = True
                return -1
            z0, z1 = z[:2].tolist()
            f_spring = k0 * z0
            if f_spring < self.f_min:
                self.f_min = f_spring
            elif f_spring > self.f_max:
                self.f_max = f_spring
            g = z1 * s1 - va
            crossed = (g > 0.0) != (g_prev[0] > 0.0) and g != 0.0 and g_prev[0] != 0.0
            rising = g_prev[0] < 0.0
            g_prev[0] = g
            if crossed:
                stop["extremum"] = rising
                return -1                       # handled out here: DOP853 is not re-entrant
            return 0

        solver = ode(self.f).set_integrator("dop853", rtol=self.rtol, atol=1e-12, nsteps=10 ** 9,
                                            max_step=self.max_step)
        solver.set_solout(solout)
        self.sub = ode(self.f).set_integrator("dop853", rtol=self.rtol, atol=1e-12, nsteps=10 ** 6)
        self.sub.set_initial_value(z0, 0.0)
        while True:
            # go on from the last accepted step (DOP853 picks its first step anew)
            solver.set_initial_value(zs[-1], ts[-1])
            stop.clear()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")     # "probably stiff": the caller takes over
                solver.integrate(T - t0)
            self.nfev += int(getattr(solver._integrator, "iwork", [0] * 17)[16])  # its NFCN
            if stop.get("stiff") or (not solver.successful() and not stop):
                return False, None
            if "extremum" in stop:
                if self._extremum(stop["extremum"]):
                    return True, self._tile()
                continue
            self._flush(len(ts) - 1)
            return True, None

    # -- extrema -----------------------------------------------------------------------
    def _derivatives(self, z, h):
        """dz/dt and d2z/dt2 (a central difference along the flow, over 1e-3 of the step)."""
        fz = np.array(self.f(0.0, z))
        eps = 1e-3 * h
        self.nfev += 3
        return fz, (np.array(self.f(0.0, z + eps * fz)) - np.array(self.f(0.0, z - eps * fz))) / (2.0 * eps)

    def _extremum(self, is_max):
        """Locate the extremum in the last step, insert it as a sample, keep it or not;
        True when the run has converged to its limit cycle and should be tiled."""
        ts, zs, va, s1 = self.ts, self.zs, self.va, float(self.scale[1])
        t_a, t_b, z_a, z_b = ts[-2], ts[-1], zs[-2], zs[-1]
        h = t_b - t_a
        (da, ca), (db, cb) = self._derivatives(z_a, h), self._derivatives(z_b, h)
        g_a, g_b = float(z_a[1]) * s1 - va, float(z_b[1]) * s1 - va
        frac, lo, hi = g_a / (g_a - g_b), 0.0, 1.0
        for _ in range(12):
            val, slope = _hermite5(h, z_a[1], da[1], ca[1], z_b[1], db[1], cb[1], frac)
            g = float(val) * s1 - va
            if (g > 0.0) == (g_a > 0.0):
                lo = frac
            else:
                hi = frac
            step = g / (float(slope) * s1) if slope != 0.0 else math.inf
            new = frac - step
            if not lo <= new <= hi:
                new = 0.5 * (lo + hi)
            if abs(new - frac) <= 1e-15:
                frac = new
                break
            frac = new
        t_e = t_a + frac * h
        z_e = self._step(z_a, t_a, t_e)
        if z_e is None:
            z_e, _ = _hermite5(h, z_a, da, ca, z_b, db, cb, frac)
        if t_a < t_e < t_b:
            ts.insert(-1, t_e)
            zs.insert(-1, z_e)
            j = len(ts) - 2
        else:
            j = len(ts) - 2 if t_e <= t_a else len(ts) - 1
            z_e = zs[j]
        force = self.K * float(z_e[0]) * float(self.scale[0])
        return self._keep(t_e, "slip" if is_max else "stick", force, j)

    def _step(self, z_a, t_a, t_e):
        """The state at ``t_e`` by one DOP853 step from the accepted step at ``t_a`` (as
        accurate as the steps themselves; an interpolant is not, for a fast state)."""
        if not t_e > t_a:
            return None
        try:    # scipy's DOP853 wrapper called directly: no new solver object per event
            integ = self.sub._integrator
            integ.work[6] = t_e - t_a           # the first (and only) step
            _, z, istate = integ.runner(self.f, t_a, np.array(z_a), t_e, *integ.call_args, ())
            self.nfev += int(integ.iwork[16])
            return z if istate > 0 else None
        except (AttributeError, IndexError, TypeError, ValueError):     # other scipy internals
            sub = ode(self.f).set_integrator("dop853", rtol=self.rtol, atol=1e-12, first_step=t_e - t_a)
            sub.set_initial_value(z_a, t_a)
            z = sub.integrate(t_e)
            return z if sub.successful() else None

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
        za, zb = self.zs[ja] * self.scale, self.zs[jb] * self.scale
        q = np.concatenate(([self.ts[jb] - self.ts[ja], zb[0]], zb[5:], zb[2:5] - za[2:5]))
        tol = self.rtol * np.abs(q) + np.concatenate(([0.0, self.scale[0] * 1e-12],
                                                      np.full(zb.size - 5, self.rtol),
                                                      self.scale[2:5] * 1e-12))
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
        z = self.zs[jb].copy()
        z[2:5] = 0.0
        tau = self.ts[jb]
        return self.t0 + tau + dt, self.xa0 + self.va * tau + dxa, z

    # -- recording -----------------------------------------------------------------------
    def _flush(self, j_end):
        """Hand samples flushed+1 .. j_end (and the kept extrema among them) to the recorder."""
        j0 = self.flushed
        if j_end <= j0:
            return
        ts = np.array(self.ts[j0:j_end + 1])
        ys = (np.array(self.zs[j0:j_end + 1]) * self.scale).T
        xa = self.xa0 + self.va * ts
        e0 = ys[2:5, 0:1]
        self.rec.append(self.t0 + ts, xa - ys[0], ys[1], xa, ys[5:], *(ys[2:5] - e0))
        self.rec.nfev = self.nfev
        kept = [e for e in self.events if j0 < e[3] <= j_end]
        self.rec.insert_events([self.t0 + self.ts[e[3]] for e in kept], [e[1] for e in kept])
        self.flushed = j_end

    def result(self):
        return self.rec.finish()
