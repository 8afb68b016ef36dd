"""The damped harmonic oscillator M e'' + D e' + K e = 0 in closed form.

Every slip of a Coulomb (+ viscous) block is this oscillator about a moving
equilibrium, so the slip is known exactly and its end (the slip velocity
returning to zero) is the root of a known function.  The root is found on
intervals where that function is monotone -- between consecutive extrema,
themselves known in closed form -- so no sign change can be missed, unlike a
time-stepping event detector.

The solution is written as ``f(t) = exp(-g t) [f0 C(t) + (f0' + g f0) S(t)]``
with ``g = D/2M`` and (q = K/M - g^2)::

    q > 0:  C = cos(w t),   S = sin(w t)/w,     w = sqrt(q)
    q < 0:  C = cosh(k t),  S = sinh(k t)/k,    k = sqrt(-q)
    q = 0:  C = 1,          S = t

which is continuous through critical damping; the overdamped products are
evaluated with the slow rate ``-K/M / (g + k)`` so that heavy damping
(zeta >> 1) neither overflows nor cancels.  Any derivative of a solution is
again a solution, so the same formula gives e, e', e''.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

__all__ = ["DampedOscillator"]


class DampedOscillator:
    """Closed-form homogeneous solutions of ``M e'' + D e' + K e = 0``.

    Example
    -------
    >>> osc = DampedOscillator(mass=1.0, damping=0.0, stiffness=1.0)
    >>> round(float(osc.value(np.pi, 1.0, 0.0)), 12)     # cos(pi)
    -1.0
    """

    def __init__(self, mass: float, damping: float, stiffness: float):
        self.mass, self.damping, self.stiffness = mass, damping, stiffness
        self.w0sq = stiffness / mass
        self.gamma = 0.5 * damping / mass
        self.q = self.w0sq - self.gamma ** 2
        # treat |q| at round-off level as critical, where both branches agree anyway
        if abs(self.q) <= 1e-14 * self.w0sq:
            self.regime = "critical"
        elif self.q > 0:
            self.regime = "under"
            self.w = math.sqrt(self.q)
        else:
            self.regime = "over"
            self.k = math.sqrt(-self.q)
            self.r_slow = -self.w0sq / (self.gamma + self.k)
            self.r_fast = -self.gamma - self.k

    # -- basis ---------------------------------------------------------------
    def basis(self, t):
        """Return ``(exp(-g t) C(t), exp(-g t) S(t))``."""
        t = np.asarray(t, dtype=float)
        if self.regime == "under":
            decay = np.exp(-self.gamma * t)
            return decay * np.cos(self.w * t), decay * np.sin(self.w * t) / self.w
        if self.regime == "critical":
            decay = np.exp(-self.gamma * t)
            return decay, decay * t
        slow, fast = np.exp(self.r_slow * t), np.exp(self.r_fast * t)
        two_k_t = 2.0 * self.k * t
        # sinh(k t)/k e^{-g t}: expm1 form where the difference would cancel
        es = np.where(two_k_t < 1.0,
                      fast * np.expm1(np.minimum(two_k_t, 1.0)) / (2.0 * self.k),
                      (slow - fast) / (2.0 * self.k))
        return 0.5 * (slow + fast), es

    def value(self, t, f0, f0dot):
        """Solution with ``f(0) = f0``, ``f'(0) = f0dot``."""
        ec, es = self.basis(t)
        return f0 * ec + (f0dot + self.gamma * f0) * es

    def scalar_value(self, t: float, f0: float, f0dot: float) -> float:
        """:meth:`value` at one time, on Python floats (the root finders' inner loop)."""
        if self.regime == "under":
            decay = math.exp(-self.gamma * t)
            ec, es = decay * math.cos(self.w * t), decay * math.sin(self.w * t) / self.w
        elif self.regime == "critical":
            ec = math.exp(-self.gamma * t)
            es = ec * t
        else:
            slow, fast = math.exp(self.r_slow * t), math.exp(self.r_fast * t)
            two_k_t = 2.0 * self.k * t
            es = (fast * math.expm1(two_k_t) if two_k_t < 1.0 else slow - fast) / (2.0 * self.k)
            ec = 0.5 * (slow + fast)
        return f0 * ec + (f0dot + self.gamma * f0) * es

    def second_derivative_at_zero(self, f0, f0dot):
        """``f''(0)`` from the equation of motion."""
        return -2.0 * self.gamma * f0dot - self.w0sq * f0

    # -- zeros of a solution ------------------------------------------------
    def zeros(self, f0, f0dot, t_end):
        """Increasing zeros in (0, t_end] of the solution, as a generator."""
        w_ = f0dot + self.gamma * f0
        if self.regime == "under":
            if f0 == 0.0 and w_ == 0.0:
                return
            # f0 cos + (w_/w) sin = R cos(w t - phi): zeros at w t = phi + pi/2 + n pi
            phi = math.atan2(w_ / self.w, f0)
            first = (phi + 0.5 * math.pi) % math.pi
            n = 0
            while True:
                t = (first + n * math.pi) / self.w
                if t > t_end:
                    return
                if t > 0.0:
                    yield t
                n += 1
        elif self.regime == "critical":
            if w_ != 0.0:
                t = -f0 / w_
                if 0.0 < t <= t_end:
                    yield t
        else:
            if w_ != 0.0:
                ratio = -f0 * self.k / w_
                if 0.0 < ratio < 1.0:
                    t = math.atanh(ratio) / self.k
                    if t <= t_end:
                        yield t

    def envelope(self, t, f0, f0dot):
        """An upper bound of |f| from time t on (None if not cheaply known)."""
        if self.regime != "under":
            return None
        amplitude = math.hypot(f0, (f0dot + self.gamma * f0) / self.w)
        return amplitude * math.exp(-self.gamma * t)

    def first_crossing(self, e0, edot0, level, t_end, skip_start=False):
        """First t in (0, t_end] where ``e'(t) = level``; None if there is none.

        ``e'`` is monotone between the zeros of ``e''``, so each interval holds at
        most one crossing and brentq brackets it exactly.  ``skip_start`` is set
        when ``e'(0) = level`` holds exactly (slip starting from stick): that
        root at t = 0 is not an end of slip.
        """
        a0 = -2.0 * self.gamma * edot0 - self.w0sq * e0          # e''(0)
        j0 = -2.0 * self.gamma * a0 - self.w0sq * edot0          # e'''(0)

        def g(t):
            return self.scalar_value(t, edot0, a0) - level

        left, g_left = 0.0, edot0 - level
        first_piece = True
        for right in self._piece_ends(a0, j0, t_end, edot0, level):  # lazy: stop at the first root
            g_right = g(right)
            skip = first_piece and skip_start
            first_piece = False
            if not skip and ((g_left < 0.0 < g_right) or (g_left > 0.0 > g_right)):
                return brentq(g, left, right, xtol=max(1e-16 * right, 1e-300), rtol=8.9e-16, maxiter=200)
            if g_right == 0.0 and right > 0.0:
                return right  # lands exactly on the level at a piece end (tangency)
            left, g_left = right, g_right
        return None

    def _piece_ends(self, a0, j0, t_end, edot0, level):
        """Ends of the monotone pieces of e' in (0, t_end], stopping once e'
        provably cannot reach ``level`` any more."""
        for tz in self.zeros(a0, j0, t_end):
            yield tz
            env = self.envelope(tz, edot0, a0)
            if env is not None and env < abs(level) * (1.0 - 1e-12):
                return
        yield t_end
