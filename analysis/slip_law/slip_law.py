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
of the film while it slides and re-solidifies.  The two are fitted separately,
and the loop's area between the two branches' lines (and the mean force gap,
area over the velocity range) says how far from one law F(v) the slip is.
(∮F_film dv over the samples themselves is no measure: the noise of M·a is
correlated with that of dv.)

One law.  A film carried along with the wall also makes a loop: its m_c·a is
positive while the wall accelerates and negative while it slows.  A liquid's
force is F_k + B·v + m_c·a to first order in the frequency (a Couette film adds
a third of its mass without slip), with no yield: its whole slip is one law, and
fitting both branches with m_c (``one_law``) uses every sample (releases of the MD liquid,
fitted as their mean trace, are one law: docs/results/slip-law.md).  A film that
breaks on the accelerating branch is not: m_c·a would take up its yield loop as
a mass.  So the whole slip is fitted once more with a step of the force at the
peak velocity (``loop_step``, F_acc − F_dec at a common law), and the verdict is
the one law's when that step is not resolved, the run had 95 % power to resolve
a step of half the one law's film force, and m_c is not resolved negative; else
it is the decelerating branch's (the sliding law), the accelerating one reported
beside it (:func:`~filmfriction.analysis.slip_law.slip_law_verdict.choose_law`).

Smoothing.  The sampled wall velocity of an MD run carries the wall's thermal
vibration; differentiated for M·a it swamps the film force.  A Savitzky–Golay
filter (order 2, a window of ``smoothing`` × the median slip duration) is
applied to the spring force, the velocity and the acceleration alike; a linear
law F_k + B·v + m_c·a survives any such filter unchanged (the filter is linear
and keeps constants), so the smoothing removes noise, not the law.

Verdict (one of :data:`VERDICTS`).  Each term is *resolved* when it exceeds
:data:`RESOLVED_SIGMAS` = 2.24 σ — a term that is truly absent is resolved, either sign, in
:data:`FALSE_ALARM` = 2.5 % of repeats, at the normal's coverage with the Student t of
the errors' degrees of freedom; the other half of a 5 % budget is left to the power, so
that a pure law keeps its verdict in ≥ 95 % of repeats of a run that resolves its term
with 97.5 % power — and carries at least :data:`NUMERICAL_FLOOR` of
the film force |F_k| + |B·v̄| (on an exact trace the errors vanish and the
quadrature's own error would read as a term), and *ruled out as dominant* when the run had
95 % power to resolve it at half the film force F̄ (the power analysis, on the
run's own errors: :func:`detectable`):

* ``velocity-weakening`` — B resolved negative;
* ``inconclusive`` — F_k resolved negative (no friction force pushes: the line is
  not the branch's law);
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

``detectable_damping`` is the smallest B the run resolves at 2.24 σ in 95 % of
repeats; B, it and the B of a no-slip film of bulk viscosity (η_bulk·A/D,
computed by the caller) belong side by side.  σ_B and σ_Fk are the standard
errors of the per-slip fits' mean over the slips (their scatter, n − 1 degrees
of freedom), never below the pooled least-squares errors widened for the
residuals' correlation.  Only samples faster than ``min_velocity_fraction`` of
the slip's peak are fitted: near v = 0 the film is re-solidifying (or has not
yet shear-melted), which is not the law; nor are the samples whose derivative or
smoothing window reaches across the yield or the re-stick (half a window and one
sample at each end of the slip).

The load's work on the gap.  A wall held at a load P whose film's gap D opens while it
slides pays P·A·dD of its travel to the load, and gets it back as the gap closes: the
film's x-force then carries P·A·dD/dx beside its dissipative force (the energy per unit
slide is F_film·dx = dissipation + P·A·dD + the film's own energy).  Given the trace's
``load_work`` (W_L = −P·A·(D − D0), the work the load did on the wall), the fit takes
it out, F_diss = F_film + dW_L/dx with dW_L/dx = (dW_L/dt)/v, v the guiding
(smoothed) velocity; in the integral form the response gains ∫(dW_L/dt)/v dt, the
rate unsmoothed (the integral takes its noise back to the gap's own: by parts it is
[W_L/v] + ∫W_L·v'/v² dt).  A gap that opens as v² is a mass
(P·A·dD/dx = 2κP·A·a) and moves only m_c; one that opens otherwise can leave a loop,
which the correction removes (``tests/analysis/groundtruth/test_release_dilatancy.py``).
The gap's thermal breathing is exchanged with the film's own energy, not with the
wall's travel, yet the correction carries it into the fit as P·A·δD/v (bounded by the
velocity floor): on the MD liquid released at P = 1 it more than doubles the errors
(docs/results/slip-law.md), so the correction is an option, off by default.

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
from scipy.integrate import cumulative_trapezoid
from scipy.signal import savgol_filter

from filmfriction.reduced_model.cycles import CycleTable

from .slip_law_branches import BranchFit, Segment, fit_branch, jackknife, jackknife_branch
from .slip_law_stats import FALSE_ALARM, POWER, RESOLVED_SIGMAS, detectable, mean_se, sigmas
from .slip_law_verdict import DOMINANT_SHARE, NUMERICAL_FLOOR, ONE_LAW, VERDICTS, choose_law

__all__ = ["FilmForceFit", "BranchFit", "film_force", "fit_film_force", "fit_segments",
           "jackknife_fit", "loop_step_branch", "checked_trace", "checked_fit_inputs", "smoothing_samples",
           "detectable",
           "sigmas", "VERDICTS", "BRANCHES", "RESOLVED_SIGMAS", "FALSE_ALARM", "POWER", "DOMINANT_SHARE",
           "NUMERICAL_FLOOR", "MIN_RELAXATION", "ONE_LAW"]

#: The branches of a slip; without one law, the verdict is the first one's.
BRANCHES = ("decelerating", "accelerating")
#: A window is a slip only when the spring force falls over it by at least this share of
#: its value at the yield (K·(Δx − VΔt) of F_s): a window in which the wall did not move
#: (a film holding the wall, the wall rattling in its well) is refused, not fitted.
MIN_RELAXATION = 0.05
#: Default window of the velocity that picks the fitted samples, as a share of the median
#: slip duration.
SMOOTHING = 0.1


@dataclass(frozen=True)
class FilmForceFit:
    """The slip law on both branches, the one law over the whole slip, the loop, and the verdict.

    Attributes
    ----------
    decelerating, accelerating : BranchFit
        The two branches (see the module text).
    whole : BranchFit
        The whole slip in one fit (both branches: a loop makes it a compromise; with
        the co-moving mass, the term where the acceleration takes both signs).
    one_law : BranchFit
        The whole slip with the co-moving mass, F_k + B·v + m_c·a (whatever
        ``comoving_mass`` says): the law when the slip is one (module text).
    loop_step, loop_step_stderr, loop_step_sigmas, detectable_loop_step : float
        The step of the film force at the peak velocity beyond the one law,
        F_acc − F_dec (positive when the accelerating branch lies above), its
        standard error, its normal-equivalent sigmas and the smallest step the run
        resolves at 2.24 σ (:data:`RESOLVED_SIGMAS`) with 95 % power.
    verdict_from : str
        The fit the verdict is: ``one law`` (:data:`ONE_LAW`) or ``decelerating``.
    verdict, reason : str
        That fit's verdict, and why it is that fit's.
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
        Whether the m_c·a term was fitted on the branches.
    still_windows : int
        Windows of the table left out because the wall did not slip in them (the
        spring relaxed by less than :data:`MIN_RELAXATION` of its force); the
        reasons say by how much it moved.
    load_work_removed : bool
        Whether the load's work on the gap was taken out of the film force (module text).
    registry_period : float or None
        The period of the walls' registry whose force was fitted beside the law (the
        slips' mean: :func:`~filmfriction.analysis.slip_law.slip_law_cycles.fitted_registry_period`);
        None: none fitted.
    viscous_lag : float or None
        The relaxation time of the viscous force the fit lagged (B's regressor ∫v_f dt:
        :func:`~filmfriction.analysis.slip_law.slip_law_cycles.held_slips`); None: B·v.
    """

    decelerating: BranchFit
    accelerating: BranchFit
    whole: BranchFit
    one_law: BranchFit
    loop_step: float
    loop_step_stderr: float
    loop_step_sigmas: float
    detectable_loop_step: float
    verdict_from: str
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
    load_work_removed: bool = False
    registry_period: float | None = None
    viscous_lag: float | None = None

    @property
    def law(self) -> BranchFit:
        """The fit the verdict is (:attr:`verdict_from`): the law the callers quote."""
        return self.one_law if self.verdict_from == ONE_LAW else self.decelerating

    @property
    def kinetic_force(self) -> float:
        return self.law.kinetic_force

    @property
    def kinetic_force_stderr(self) -> float:
        return self.law.kinetic_force_stderr

    @property
    def damping(self) -> float:
        return self.law.damping

    @property
    def damping_stderr(self) -> float:
        return self.law.damping_stderr

    @property
    def detectable_damping(self) -> float:
        return self.law.detectable_damping

    @property
    def mean_slip_velocity(self) -> float:
        return self.law.mean_velocity

    @property
    def viscous_share(self) -> float:
        return self.law.viscous_share

    @property
    def samples(self) -> int:
        return self.law.samples


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
    t, f, v = checked_trace(time, spring_force, wall_velocity, mass)
    return f - mass * np.gradient(v, t) - mount_damping * (v - drive_velocity)


def checked_trace(time, spring_force, wall_velocity, mass):
    """(t, F_spring, v) as float arrays, checked: 1-D, one length, at least 2 samples,
    a positive ``mass`` (ValueError otherwise)."""
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


def checked_fit_inputs(time, spring_force, wall_velocity, wall_position, mass, *,
                       min_velocity_fraction: float, smoothing: float):
    """The slip-law fits' inputs checked (ValueError otherwise): ``min_velocity_fraction``
    and ``smoothing`` in [0, 1), the trace (:func:`checked_trace`), and the wall's
    position of the trace's shape (the integral of its velocity when None).  Returns
    (t, F_spring, v, x) as float arrays."""
    if not 0 <= min_velocity_fraction < 1:
        raise ValueError(f"min_velocity_fraction = {min_velocity_fraction!r}: must be in [0, 1)")
    if not (math.isfinite(smoothing) and 0 <= smoothing < 1):
        raise ValueError(f"smoothing = {smoothing!r}: must be in [0, 1) (share of a slip)")
    t, f, v = checked_trace(time, spring_force, wall_velocity, mass)
    if wall_position is None:
        return t, f, v, cumulative_trapezoid(v, t, initial=0.0)
    x = np.asarray(wall_position, float)
    if x.shape != t.shape:
        raise ValueError(f"wall_position has shape {x.shape}, the trace {t.shape}")
    return t, f, v, x


def smoothing_samples(t: np.ndarray, table: CycleTable, smoothing: float) -> int:
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
                   smoothing: float = SMOOTHING, comoving_mass: bool = False,
                   load_work=None, film_mass: float | None = None) -> FilmForceFit:
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
    load_work : array_like, shape (n,), optional
        The work the load did on the wall (an MD trace's ``load_work`` column,
        −P·A·(D − D0)): taken out of the film force, which is then its dissipative
        part (module text).  None: the film force as the equation of motion gives it.
    film_mass : float, optional
        The film's own mass, the most a co-moving mass can be: a resolved m_c above it is
        a yield loop, not inertia (:func:`~filmfriction.analysis.slip_law.slip_law_verdict.choose_law`).
        None (a measured trace): not known, no such check.

    Returns
    -------
    FilmForceFit
    """
    t, f, v, x = checked_fit_inputs(time, spring_force, wall_velocity, wall_position, mass,
                                    min_velocity_fraction=min_velocity_fraction,
                                    smoothing=smoothing)
    w = smoothing_samples(t, table, smoothing)
    # the velocity that picks the samples: from the position, whose noise is not the
    # response's (selecting on the response's own noise would bias the fit)
    if w and wall_position is not None:
        guide = savgol_filter(x, w, 2, deriv=1, delta=float(t[1] - t[0]))
    else:
        guide = savgol_filter(v, w, 2) if w else v
    impulse = cumulative_trapezoid(f, t, initial=0.0)
    gap_rate = None if load_work is None else _load_work_rate(load_work, t)
    segs = {name: [] for name in BRANCHES + ("whole",)}
    ranges = []
    edge = w // 2 + 1
    still = []                       # (slip, Δx, v̄, relaxation) of windows with no slip
    for j, (y, s) in enumerate(zip(table.yield_index, table.stick_index)):
        y, s = int(y), int(s)
        g = guide[y:s + 1]
        # the spring's relaxation as the slips' table has it (F_s − F_b of F_s)
        f_s, f_b = float(table.static_force[j]), float(table.backward_force[j])
        relaxed = (f_s - f_b) / abs(f_s) if f_s else math.nan
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
            imp = impulse[i] - impulse[i[0]] - mount_damping * (dx - drive_velocity * dt_)
            if gap_rate is not None:
                # + ∫ (dW_L/dt)/v dt: the film force less the load's work on the gap
                # (v bounded below by the floor, or 1 % of the peak with no floor)
                u = np.maximum(guide[i], max(min_velocity_fraction, 0.01) * peak)
                imp = imp + cumulative_trapezoid(gap_rate[i] / u, t[i], initial=0.0)
            segs[name].append(Segment(imp, v[i], dt_, dx, guide[i] - guide[i[0]], mass,
                                      np.maximum(dt_ - (t[y + p] - t[i[0]]), 0.0)))
        ranges.append((min_velocity_fraction * peak, peak))
    return fit_segments(segs, ranges, mass=mass, comoving_mass=comoving_mass,
                        smoothing_window=w, still=still, windows=len(table),
                        load_work_removed=gap_rate is not None, film_mass=film_mass)


def fit_segments(segs: dict, ranges: list, *, mass: float, comoving_mass: bool,
                 smoothing_window: int, still=(), windows: int = 0,
                 load_work_removed: bool = False,
                 film_mass: float | None = None) -> FilmForceFit:
    """The branches, the one law, the loop and the verdict from the slips' segments.

    ``segs`` maps ``decelerating``, ``accelerating`` and ``whole`` to one
    :class:`~filmfriction.analysis.slip_law.slip_law_branches.Segment` (or None) per
    slip, ``ranges`` holds each slip's fitted velocity range (floor, peak); ``still``
    the windows refused (:func:`fit_film_force`), of ``windows`` in all; ``film_mass``
    the most a co-moving mass can be (:func:`~filmfriction.analysis.slip_law.slip_law_verdict.choose_law`)."""
    still = list(still)
    fits = {name: fit_branch(name, segs[name], comoving_mass) for name in segs}
    # one law F_k + B·v + m_c·a over the whole slip, and the step at the peak beyond it
    fits["one_law"] = fit_branch(ONE_LAW, segs["whole"], True)
    fits["loop_step"] = fit_branch(ONE_LAW, segs["whole"], True, loop_step=True)
    if still:
        fits = _refuse_still(fits, still, windows)
    acc, dec = fits["accelerating"], fits["decelerating"]
    lo, hi = np.array(ranges, float).reshape(-1, 2).T
    # the loop between the two branches' lines, over the velocities both cover
    gap_fk = acc.per_slip_kinetic_force - dec.per_slip_kinetic_force
    gap_b = acc.per_slip_damping - dec.per_slip_damping
    area = gap_fk * (hi - lo) + gap_b * (hi ** 2 - lo ** 2) / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        gap = area / (hi - lo)
    la, lf = mean_se(area), mean_se(gap)
    one, st = fits["one_law"], fits["loop_step"]
    frm, verdict, reason = choose_law(dec, one, st, mass, film_mass)
    return FilmForceFit(dec, acc, fits["whole"], one, st.loop_step, st.loop_step_stderr,
                        sigmas(st.loop_step, st.loop_step_stderr, st.dof),
                        detectable(st.loop_step_stderr, st.dof), frm, verdict, reason,
                        la[0], la[1], lf[0], lf[1], area, smoothing_window, comoving_mass,
                        len(still), load_work_removed)


def jackknife_fit(fit: FilmForceFit, leave_one_out, *, mass: float,
                  replicas: str = "releases", film_mass: float | None = None) -> FilmForceFit:
    """The fit of a mean trace with its errors from the jackknife over its replicas.

    ``fit`` is :func:`fit_film_force` on the mean of R replicas of one slip (releases
    of one initial condition, aligned at the release; or the slips of a driven run,
    :func:`~filmfriction.analysis.slip_law.slip_law_cycles.fit_cycle_ensemble`),
    ``leave_one_out`` the R fits of
    the means that leave one replica out.  The law is linear in the trace, so the mean
    trace's fit has the law's expectation whatever the noise (E[ξ] = 0), while a fit
    per replica regresses on the replica's own noisy Δx and Δv, which the film's
    random force has moved (the regressors correlate with the response's noise: a
    bias that does not shrink with more replicas).  Its errors are not the mean
    trace's (its residuals are the law's and the smoothing's, not the replicas'
    scatter) but the jackknife's, R − 1 degrees of freedom
    (:func:`~filmfriction.analysis.slip_law.slip_law_branches.jackknife_branch`); the
    significance, the power, the branches' verdicts and the choice of the law
    (:func:`~filmfriction.analysis.slip_law.slip_law_verdict.choose_law`) follow from
    them as on any fit (``film_mass`` as for :func:`fit_segments`).  ``replicas`` names the
    replicas in the reasons.
    """
    loo = list(leave_one_out)
    if len(loo) < 2:
        raise ValueError(f"{len(loo)} leave-one-out fit(s): the jackknife needs 2 or more")
    br = {name: jackknife_branch(getattr(fit, name), [getattr(f, name) for f in loo],
                                 replicas=replicas)
          for name in ("decelerating", "accelerating", "whole", "one_law")}
    st = jackknife_branch(loop_step_branch(fit), [loop_step_branch(f) for f in loo], replicas=replicas)
    dof = len(loo) - 1
    frm, verdict, reason = choose_law(br["decelerating"], br["one_law"], st, mass, film_mass)
    (la_se, la_ps), (lf_se, _) = (jackknife(getattr(fit, k), [getattr(f, k) for f in loo])
                                  for k in ("loop_area", "loop_force"))
    return replace(fit, **br, loop_step_stderr=st.loop_step_stderr,
                   loop_step_sigmas=sigmas(fit.loop_step, st.loop_step_stderr, dof),
                   detectable_loop_step=detectable(st.loop_step_stderr, dof),
                   verdict_from=frm, verdict=verdict, reason=reason, loop_area_stderr=la_se,
                   loop_force_stderr=lf_se, per_slip_loop_area=la_ps)


def loop_step_branch(fit: FilmForceFit) -> BranchFit:
    """The one law's fit carrying the loop step (what :func:`choose_law` reads)."""
    return replace(fit.one_law, loop_step=fit.loop_step, loop_step_stderr=fit.loop_step_stderr)


def _load_work_rate(load_work, t: np.ndarray) -> np.ndarray:
    """dW_L/dt of the load's work (second-order central differences)."""
    lw = np.asarray(load_work, float)
    if lw.shape != t.shape:
        raise ValueError(f"load_work has shape {lw.shape}, the trace {t.shape}")
    if not np.all(np.isfinite(lw)):
        raise ValueError("load_work has non-finite samples")
    return np.gradient(lw, t)


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
