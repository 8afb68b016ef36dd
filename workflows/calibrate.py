"""Calibrate the reduced spring-block model on MD runs and replay the MD trace with it.

The model
---------
The MD top wall (mass M) is pulled through a spring K whose end moves at V,
and its mount has a dashpot d = γ·M to ground (``trace_parameters``).  The
reduced model is the same block, spring, drive and dashpot
(:class:`filmfriction.reduced_model.SpringBlock` with ``damping = d``) on a film described by
:class:`filmfriction.reduced_model.laws.Coulomb` with a viscous term::

    stick:  wall at rest until the spring force reaches F_s
    slip:   M x'' = K (x_d - x) - d x' - F_k - B x'   until x' = 0 (re-stick)

Why this law: the MD film is a solid that shear-melts at a threshold and
re-crystallises when the wall stops (Thompson & Robbins 1990).  A static
threshold F_s with an exact stick phase is the minimal description of the
first; while the film is molten it carries a rate-independent part F_k (the
wall still drags over the walls' corrugation through a disordered layer) and a
viscous part B·x' (Klein's Eq. 1, B = A η_eff / D).  Klein's purely viscous
film (F_k = 0, no threshold) cannot stick at all; a rate-and-state or
contact-age law needs ageing data that one MD run at one velocity does not
constrain.  Coulomb + viscous has a closed form (fast, exact), and each of
its three parameters is measured by a distinct feature of the trace: F_s by
the peak force, F_k by the level the force swings about during the slip,
B by how fast that swing decays and how long the slip lasts.  Its known
limitation: the model sticks at the first velocity zero, so it has no ringing
after the stick (the MD wall rings on the elastic, re-solidified film).

Fits (all in the run's LJ units)
--------------------------------
``static_force``
    Mean spring force at the fitted yield instants of the analysed slips
    (see below; the start-up yield from a relaxed spring is left out when
    ≥ 3 slips exist, as in ``analysis.json``), ± its standard error; the
    analysis's mean F_s when no slip could be fitted.  The start-up yield is
    reported apart (``first_yield_force``).
``kinetic_force`` and ``film_damping``
    One joint least-squares fit of the slip equation above (closed form,
    d fixed to the mount's value, each slip started at rest from its own
    stick ramp, its yield instant free within a few samples of the detected
    y) to the spring force over every slip window (y to s plus as long again
    after s, so the re-stick level is constrained).  Uncertainty:
    jackknife over slips (leave one slip out, refit), which carries the
    slip-to-slip scatter; with fewer than 3 slips, the fit's covariance.
``eta_eff``
    B·D/A with D the mean gap, at the slips' shear rate γ̇ = (Δx0/τ_s)/D.
    With a smooth-sliding run the steady η_eff = (F̄/A)/(V/D) is used instead.
``rate_law``
    With ≥ 3 runs at different shear rates, η_eff = c·γ̇^α fitted with
    :func:`filmfriction.analysis.viscosity.power_law_fit` (α ± its standard error).
``ageing``
    With ≥ 4 slips, the slope of F_s against ln(preceding stick time), ± its
    standard error (contact ageing: positive and significant if the film
    strengthens while stuck).

The :class:`filmfriction.workflows.sfb.MDCalibration` for the SFB check takes the stresses
F/A, η_eff and the rate law; the thinning law is Carreau with its onset at
the lowest MD rate, matched to the fit there (the pure power law from that
rate is the SFB check's upper bracket).

``shear_stiffness``
    The stuck film's elastic shear stiffness k_f, from the slopes of the stick
    ramps (K_eff = slope / V, 1/k_f = 1/K_eff − 1/K); none when the ramps rise
    at K within their errors.

Replay
------
The calibrated law carries k_f (the block creeps on the elastic film while
stuck) and a freeze velocity fitted to the MD's mean re-stick force F_b (the
MD film re-solidifies while the wall still moves; an overdamped slip would
otherwise never stop, and an underdamped one would overshoot below F_b).
F_s and F_b are therefore inputs of the replay; slip distance and period are
its predictions.  The calibrated model is run with the MD's K, M, V and d from
the MD's first re-stick point (the start-up yield, whose larger threshold reflects the
contact's age after equilibration, is not part of the steady cycle), and its
cycles are measured with the same ruler as the MD's
(:func:`filmfriction.analysis.stickslip.cycle_table` via ``SimulationResult.cycles``).
Errors are (model − MD)/MD of the mean peak force, slip distance and period.
The peak and re-stick forces are inputs of the model (their errors check the
replay, they predict nothing); slip distance and period are predictions.
"""
from __future__ import annotations

import json
import math
import os
import dataclasses
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["Estimate", "RunData", "SlipLawFit", "Replay", "RunCalibration", "Calibration",
           "load_run", "coulomb_slip_force", "fit_slip_law", "replay", "calibrate_run",
           "calibrate", "write_calibration", "SCHEMA"]

SCHEMA = "filmfriction.calibration/1"


# ---------------------------------------------------------------------------
# small containers
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Estimate:
    """A fitted value with its one-standard-error uncertainty.

    Attributes
    ----------
    value, stderr : float
        ``stderr`` is NaN when it cannot be computed.
    units : str
        Unit label (LJ: ε/σ, ετ/σ³, …).
    method : str
        How it was obtained (one line, for people).
    """

    value: float
    stderr: float
    units: str
    method: str = ""

    def as_dict(self) -> dict:
        return {"value": _num(self.value), "stderr": _num(self.stderr), "units": self.units,
                "method": self.method}

    @property
    def rel(self) -> float:
        """Relative uncertainty (NaN if undefined)."""
        return abs(self.stderr / self.value) if self.value else math.nan


@dataclass(frozen=True, eq=False)
class RunData:
    """One run directory's trace, analysis and per-cycle table.

    Attributes
    ----------
    run_dir : Path
    trace : analysis.trace.Trace
    analysis : dict
        ``analysis.json`` content.
    cycles : dict of str -> ndarray
        Per-cycle columns (``yield_index``, ``stick_index``, ``static_force`` …).
    skip : int
        Slips left out of the summaries (the analysis's choice).
    """

    run_dir: Path
    trace: object
    analysis: dict
    cycles: dict
    skip: int

    @property
    def n_slips(self) -> int:
        return int(len(self.cycles.get("yield_index", ())))

    @property
    def thickness(self) -> float:
        tr = self.trace
        if tr.has("gap"):
            return float(np.mean(tr.columns["gap"]))
        return float(tr.parameters.require("thickness", "eta_eff = B D / A"))


def _num(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def load_run(run_dir) -> RunData:
    """Read a run directory; run the analysis (and write it) if ``analysis.json`` is missing.

    Raises
    ------
    ValueError
        No run directory, no trace, or an unreadable analysis.
    """
    from filmfriction.analysis.cycles_csv import read_cycles_csv
    from filmfriction.analysis.report import analyze, write_outputs
    from filmfriction.analysis.trace import read_trace

    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise ValueError(f"{run_dir}: not a run directory")
    trace = read_trace(run_dir)
    apath = run_dir / "analysis.json"
    cpath = run_dir / "analysis_cycles.csv"
    if apath.exists() and cpath.exists():
        try:
            doc = json.loads(apath.read_text())
        except json.JSONDecodeError as exc:
            raise ValueError(f"{apath}: not valid JSON: {exc}") from None
        cycles = read_cycles_csv(cpath)
    else:
        doc, per_cycle = analyze(trace)
        try:
            write_outputs(doc, per_cycle, apath)
        except OSError:
            pass  # read-only run directory: the analysis stays in memory
        cycles = {k: np.asarray(v, dtype=float) for k, v in per_cycle.items()
                  if not isinstance(v, str)}
    for key in ("yield_index", "stick_index"):
        cycles[key] = np.asarray(cycles.get(key, []), dtype=float).astype(int)
    skip = int(doc.get("slips", {}).get("summary_skips_first", 0) or 0)
    return RunData(run_dir, trace, doc, cycles, skip)


# ---------------------------------------------------------------------------
# the slip of a Coulomb + viscous block (closed form)
# ---------------------------------------------------------------------------
def coulomb_slip_force(t, static_force: float, kinetic_force: float, damping: float,
                       mass: float, stiffness: float, drive_velocity: float) -> np.ndarray:
    """Spring force of one Coulomb + viscous slip from rest at the yield point.

    Solves ``M x'' + b x' = K(x0 + V t − x) − F_k`` from x = x' = 0 with
    K x0 = F_s (:func:`filmfriction.analysis.viscosity.slip_force` with F_s − F_k) until
    the wall velocity returns to zero, after which the wall sticks and the
    force ramps at K V.  A second yield inside ``t`` is not modelled.

    Parameters
    ----------
    t : array_like
        Times since the yield point (≥ 0 where the slip applies; earlier
        times get the stick ramp F_s + K V t).
    static_force, kinetic_force : float
        F_s and F_k.
    damping : float
        Total damping b = B (film) + d (mount), force per velocity.
    mass, stiffness, drive_velocity : float
        M, K, V.

    Returns
    -------
    numpy.ndarray
        Spring force at ``t``.
    """
    from filmfriction.analysis.viscosity import slip_force

    t = np.asarray(t, dtype=float)
    k, v = stiffness, drive_velocity
    end = float(np.max(t)) if t.size else 0.0
    out = static_force + k * v * t
    if end <= 0.0:
        return out
    grid = np.linspace(0.0, end, 801)
    fg = kinetic_force + slip_force(grid, static_force - kinetic_force, damping, mass, k, v)
    vel = v - np.gradient(fg, grid) / k          # wall velocity: x = x_d − F/K
    neg = np.flatnonzero(vel[2:] <= 0.0)
    if neg.size:
        i = int(neg[0]) + 2
        # linear interpolation of the velocity zero
        f0 = vel[i - 1] / (vel[i - 1] - vel[i]) if vel[i - 1] != vel[i] else 0.0
        t_stick = grid[i - 1] + f0 * (grid[i] - grid[i - 1])
        f_stick = float(np.interp(t_stick, grid, fg))
    else:
        t_stick, f_stick = math.inf, math.nan
    after = t >= 0.0
    slipping = after & (t < t_stick)
    out[slipping] = kinetic_force + slip_force(t[slipping], static_force - kinetic_force,
                                               damping, mass, k, v)
    stuck = after & (t >= t_stick)
    out[stuck] = f_stick + k * v * (t[stuck] - t_stick)
    return out


@dataclass(frozen=True, eq=False)
class SlipLawFit:
    """Joint fit of F_k and B over the slips of one run.

    Attributes
    ----------
    kinetic_force, film_damping : Estimate
    static_force : Estimate
        Spring force at the fitted yield instants (mean ± standard error).
    mount_damping : float
        d, fixed (not fitted).
    rms_residual : float
        RMS force residual of the joint fit.
    n_slips : int
    jackknife : list of (float, float)
        (F_k, B) with each slip left out.
    windows : list of (int, int)
        Sample index windows fitted.
    yield_shifts : tuple of float
        Fitted yield instant minus the detected one, per slip (time units).
    damping_at_bound : bool
        B ended at the fit's lower bound: no film drag beyond the mount's is resolved.
    """

    kinetic_force: Estimate
    film_damping: Estimate
    static_force: Estimate
    mount_damping: float
    rms_residual: float
    n_slips: int
    jackknife: list = field(default_factory=list)
    windows: list = field(default_factory=list)
    yield_shifts: tuple = ()
    damping_at_bound: bool = False


def _windows(t, yi, si) -> list[tuple[int, int]]:
    out = []
    for j, (y, s) in enumerate(zip(yi, si)):
        nxt = yi[j + 1] if j + 1 < len(yi) else t.size - 1
        hi = min(int(s + max(s - y, 2)), int(nxt), t.size - 1)
        if hi - y >= 4:
            out.append((int(y), int(hi)))
    return out


def fit_slip_law(run: RunData) -> SlipLawFit:
    """Fit F_k, the film's damping B and each slip's yield instant to the analysed slips.

    Each slip window starts a few samples before the detected yield y; the
    model there is the stick ramp F_s,i + K V (t − t_y,i) (F_s,i: the
    analysis's ramp-line value at y) until the yield instant t_y,i + δ_i, then
    :func:`coulomb_slip_force`.  δ_i is free within (−4, +2) samples: with a
    sampled, noisy trace the detected y lags or leads the true yield by up to
    a sample or two, and a slip started at the wrong instant biases F_k.

    Raises
    ------
    ValueError
        No slips to fit, or missing K / M.
    """
    from scipy.optimize import least_squares

    tr = run.trace
    p = tr.parameters
    k = p.require("spring_constant", "the slip fit")
    m = p.require("mass", "the slip fit")
    v = p.drive_velocity or 0.0
    d = p.mount_damping or 0.0
    t, f = tr.time, tr.spring_force
    yi = run.cycles["yield_index"][run.skip:]
    si = run.cycles["stick_index"][run.skip:]
    fs_all = np.asarray(run.cycles["static_force"], float)[run.skip:]
    fs_by_start = {int(y): float(fs) for y, fs in zip(yi, fs_all)}
    wins = _windows(t, yi, si)
    if not wins:
        raise ValueError(f"{run.run_dir}: no slip with enough samples to fit "
                         f"({run.n_slips} slips detected, regime {run.analysis.get('regime')})")
    dt = float(np.median(np.diff(t)))
    lead = 4
    data = []
    for a, b in wins:
        lo = max(a - lead, 0)
        data.append((t[lo:b + 1] - t[a], f[lo:b + 1], fs_by_start[a]))
    n = len(data)
    fs_min = min(fs for _, _, fs in data)
    b_crit = 2.0 * math.sqrt(m * k)
    upper_fk = max(0.999 * fs_min, 1e-12)

    def one(i, fk, b, delta):
        tt, ff, fs = data[i]
        return coulomb_slip_force(tt - delta, fs + k * v * delta, fk, b, m, k, v) - ff

    def resid(params, subset):
        fk, logb = params[:2]
        b = math.exp(logb) + d
        return np.concatenate([one(i, fk, b, params[2 + j]) for j, i in enumerate(subset)])

    lo_d, hi_d = -lead * dt, 2.0 * dt

    def solve(subset, start, tol=1e-8):
        x0 = np.concatenate([start[:2], [min(max(start[2 + i], lo_d * 0.999), hi_d * 0.999)
                                         for i in subset]])
        lower = [0.0, math.log(1e-6 * b_crit)] + [lo_d] * len(subset)
        upper = [upper_fk, math.log(1e4 * b_crit)] + [hi_d] * len(subset)
        return least_squares(resid, x0=x0, args=(subset,), bounds=(lower, upper),
                             x_scale=[max(fs_min, 1.0), 1.0] + [dt] * len(subset),
                             ftol=tol, xtol=tol)

    every = list(range(n))
    # coarse grid over (F_k, B) as a start, yield instants at the detected y
    best = None
    for fk in np.linspace(0.0, 0.95 * fs_min, 7) if fs_min > 0 else [0.0]:
        for lb in np.log(np.geomspace(1e-3 * b_crit, 1e2 * b_crit, 11)):
            cost = float(np.sum(resid(np.concatenate([[fk, lb], np.zeros(n)]), every) ** 2))
            if best is None or cost < best[0]:
                best = (cost, fk, lb)
    full0 = np.concatenate([[min(best[1], 0.99 * upper_fk), best[2]], np.zeros(n)])
    sol = solve(every, full0)
    fk, logb = sol.x[:2]
    deltas = sol.x[2:]
    yield_forces = np.array([data[i][2] + k * v * deltas[i] for i in every])
    rms = float(np.sqrt(np.mean(sol.fun ** 2)))
    jack = []
    if n >= 3:
        for i in every:
            sub = [j for j in every if j != i]
            s_ = solve(sub, np.concatenate([[min(fk, 0.99 * upper_fk), logb], deltas]), tol=1e-5)
            jack.append((float(s_.x[0]), float(math.exp(s_.x[1]))))
        arr = np.array(jack)
        err = np.sqrt((n - 1) / n * np.sum((arr - arr.mean(axis=0)) ** 2, axis=0))
        fk_err, b_err = float(err[0]), float(err[1])
        how = f"jackknife over {n} slips"
    else:
        J = sol.jac
        dof = max(sol.fun.size - J.shape[1], 1)
        try:
            cov = np.linalg.pinv(J.T @ J) * float(np.sum(sol.fun ** 2)) / dof
            fk_err = float(math.sqrt(cov[0, 0]))
            b_err = float(math.exp(logb) * math.sqrt(cov[1, 1]))
        except (np.linalg.LinAlgError, ValueError):
            fk_err = b_err = math.nan
        how = f"fit covariance ({n} slip{'s' if n != 1 else ''}; jackknife needs 3)"
    u = _labels(tr.units)
    fs_err = float(yield_forces.std(ddof=1) / math.sqrt(n)) if n > 1 else math.nan
    # a parameter pinned at a bound has no sampling spread to report: the
    # jackknife's zero would read as an exact value
    fk_how = b_how = how
    if fk <= 1e-9 * max(fs_min, 1.0):
        fk_err, fk_how = math.nan, how + "; at the fit's lower bound 0: no rate-independent part"
    damping_at_bound = bool(logb <= math.log(1e-6 * b_crit) + 1e-6)
    if damping_at_bound:
        b_err, b_how = math.nan, (how + "; at the fit's lower bound: no film drag beyond the "
                                  "mount's dashpot is resolved")
    return SlipLawFit(
        kinetic_force=Estimate(float(fk), fk_err, u["force"],
                               f"joint fit of the Coulomb+viscous slip to {n} slips; {fk_how}"),
        film_damping=Estimate(float(math.exp(logb)), b_err, u["damping"],
                              f"same fit, mount dashpot d = {d:g} fixed; {b_how}"),
        static_force=Estimate(float(yield_forces.mean()), fs_err, u["force"],
                              f"spring force at the fitted yield instants of {n} slips, mean ± stderr"),
        mount_damping=d, rms_residual=rms, n_slips=n, jackknife=jack, windows=wins,
        yield_shifts=tuple(float(x) for x in deltas), damping_at_bound=damping_at_bound)


def _labels(units: str) -> dict:
    from filmfriction.analysis.trace import UNITS
    return UNITS[units]


# ---------------------------------------------------------------------------
# replay
# ---------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Replay:
    """The calibrated model run over the MD trace.

    Attributes
    ----------
    t, spring_force : numpy.ndarray
        The model's trace (MD time axis).
    start_time : float
        MD time at which the model starts (the MD's first re-stick, or 0).
    errors : dict
        ``{quantity: {"md", "md_stderr", "model", "rel_error"}}`` for
        ``peak_force``, ``slip_distance``, ``period`` (and ``backward_force``).
    model : str
        Description of the model run.
    """

    t: np.ndarray
    spring_force: np.ndarray
    start_time: float
    errors: dict
    model: str

    def as_dict(self) -> dict:
        return {"start_time": _num(self.start_time), "model": self.model,
                "errors": {k: {kk: _num(vv) for kk, vv in v.items()} for k, v in self.errors.items()}}


def _no_restick(run: RunData, kinetic_force: float, film_damping: float) -> str | None:
    """Why the calibrated block cannot come back to rest, if it cannot.

    With the mount's d, the slip is overdamped when B + d >= 2 sqrt(K M): the
    velocity then relaxes towards V without ever reaching zero, and with no
    kinetic force left to hold it the block slides on for good.  The MD film
    re-solidifies while the wall still moves; the model has no rule for that.
    """
    p = run.trace.parameters
    k, m = p.require("spring_constant"), p.require("mass")
    damping = film_damping + (p.mount_damping or 0.0)
    critical = 2.0 * math.sqrt(k * m)
    if damping < critical:
        return None
    return (f"the calibrated slip is overdamped (B + d = {damping:.3g} >= 2 sqrt(K M) = "
            f"{critical:.3g}, F_k = {kinetic_force:.3g}): the model's block never comes back to "
            "rest, so its replay has no cycles; the MD film re-solidifies while the wall still "
            "moves, and the Coulomb + viscous law has no re-stick rule for that (a freeze "
            "velocity would be the next model)")


def freeze_velocity_for(block, static_force: float, restick_force: float) -> float:
    """Slip speed at which the film must freeze for ``block`` to re-stick at ``restick_force``.

    The re-stick force of the model's steady cycle rises monotonically with the
    freeze velocity, up to ``static_force``; brentq finds it.  An overdamped
    slip (see :func:`_no_restick`) needs one above V to re-stick at all; an
    underdamped one that already re-sticks at or above ``restick_force`` gets 0.

    Raises
    ------
    ValueError
        ``restick_force`` is not reachable (not between those ends).
    """
    from scipy.optimize import brentq

    k, v = block.stiffness, abs(block.drive_velocity)
    law = block.law
    # one cycle's stick and a slip: (Fs - Fb)/(K V) plus margin; two cycles give a steady one
    horizon = 3.0 * static_force / (k * max(v, 1e-300))

    def last_restick(result):
        fb = np.asarray(result.cycles().backward_force, float)
        return float(fb[-1]) if fb.size else -math.inf

    def run(vf):
        return dataclasses.replace(block, law=dataclasses.replace(law, freeze_velocity=vf)
                                   ).simulate(horizon)

    def restick(vf):
        return last_restick(run(vf))

    # the film can only freeze below the slip's peak speed, and an overdamped
    # slip only above the steady sliding speed V, which it approaches from above
    free = run(0.0)
    peak = float(np.max(np.abs(free.v)))
    lo, hi = (v * (1.0 + 1e-3) if len(free.cycles()) == 0 else 0.0), 0.999 * peak
    # at lo = 0 the film never freezes early: that is the free run itself
    f_lo = (last_restick(free) if lo == 0.0 else restick(lo)) - restick_force
    f_hi = restick(hi) - restick_force
    if f_lo >= 0.0 and lo == 0.0:
        return 0.0      # it already re-sticks at or above F_b: freezing could only raise it
    if not (f_lo < 0.0 < f_hi):
        raise ValueError(f"re-stick force {restick_force:.4g} is outside what a freeze velocity "
                         f"in [{lo:.3g}, {hi:.3g}] gives ({f_lo + restick_force:.4g} .. "
                         f"{f_hi + restick_force:.4g})")
    return float(brentq(lambda vf: restick(vf) - restick_force, lo, hi, xtol=1e-9 * peak))


def replay(run: RunData, static_force: float, kinetic_force: float, film_damping: float,
           restick_force: float | None = None, shear_stiffness: float = math.inf) -> Replay:
    """Run the calibrated :class:`filmfriction.reduced_model.SpringBlock` over the MD trace and compare cycles.

    With the MD's ``restick_force`` the law gets the freeze velocity that
    re-sticks it there (:func:`freeze_velocity_for`): a fitted, not a predicted,
    re-stick level, which an overdamped slip (:func:`_no_restick`) needs to stop
    at all.  ``shear_stiffness`` is the stuck film's k_f (inf: rigid).
    """
    from filmfriction.reduced_model import SpringBlock, laws

    tr = run.trace
    p = tr.parameters
    k, m = p.require("spring_constant"), p.require("mass")
    v = p.drive_velocity or 0.0
    d = p.mount_damping or 0.0
    t, f = tr.time, tr.spring_force
    if run.skip and run.n_slips > run.skip:
        i0 = int(run.cycles["stick_index"][run.skip - 1])
    else:
        i0 = 0
    t0 = float(t[i0])
    duration = float(t[-1] - t0)
    law = laws.Coulomb(static=static_force, kinetic=kinetic_force, viscous=film_damping,
                       shear_stiffness=shear_stiffness)
    block = SpringBlock(mass=m, stiffness=k, drive_velocity=v, damping=d, law=law)
    freeze = 0.0
    if restick_force is not None:
        freeze = freeze_velocity_for(block, static_force, restick_force)
        block = dataclasses.replace(block, law=dataclasses.replace(law, freeze_velocity=freeze))
    ext = min(float(f[i0]) / k, 0.999 * static_force / k)
    r = block.simulate(duration, initial_extension=ext)
    model_t = r.t + t0
    table = r.cycles()
    md = run.cycles
    sk = slice(run.skip, None)

    def stats(arr):
        a = np.asarray(arr, float)
        a = a[np.isfinite(a)]
        if a.size == 0:
            return math.nan, math.nan
        return float(a.mean()), (float(a.std(ddof=1) / math.sqrt(a.size)) if a.size > 1 else math.nan)

    errors = {}
    for name, col in (("peak_force", "static_force"), ("slip_distance", "slip_distance"),
                      ("period", "period"), ("backward_force", "backward_force")):
        md_mean, md_err = stats(np.asarray(md[col], float)[sk])
        model_mean, _ = stats(getattr(table, col))
        rel = (model_mean - md_mean) / abs(md_mean) if md_mean and math.isfinite(model_mean) else math.nan
        errors[name] = {"md": md_mean, "md_stderr": md_err, "model": model_mean, "rel_error": rel,
                        "model_cycles": float(len(table))}
    frz = f", freeze_velocity={freeze:.4g} (fitted to F_b)" if freeze else ""
    if math.isfinite(shear_stiffness):
        frz += f", shear_stiffness={shear_stiffness:.4g}"
    desc = (f"SpringBlock(M={m:g}, K={k:g}, V={v:g}, d={d:g}) with Coulomb(F_s={static_force:.4g}, "
            f"F_k={kinetic_force:.4g}, B={film_damping:.4g}{frz}), from t = {t0:g}")
    return Replay(model_t, r.spring_force, t0, errors, desc)


# ---------------------------------------------------------------------------
# per run and across runs
# ---------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class RunCalibration:
    """What one run gives.

    Attributes
    ----------
    run : RunData
    regime : str
    static_force, restick_force, first_yield_force : Estimate or None
    kinetic_force, film_damping : Estimate or None
    eta_eff, shear_rate : Estimate or None
        The film's η_eff and the shear rate it belongs to.
    ageing : Estimate or None
        dF_s / d ln(t_stick).
    slip_fit : SlipLawFit or None
    replay : Replay or None
    area, thickness : float
    failures : dict
        Step name → reason, for what could not be computed.
    """

    run: RunData
    regime: str
    area: float
    thickness: float
    static_force: Estimate | None = None
    restick_force: Estimate | None = None
    first_yield_force: Estimate | None = None
    kinetic_force: Estimate | None = None
    film_damping: Estimate | None = None
    eta_eff: Estimate | None = None
    shear_rate: Estimate | None = None
    ageing: Estimate | None = None
    shear_stiffness: Estimate | None = None
    slip_fit: SlipLawFit | None = None
    replay: Replay | None = None
    failures: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        out = {"run_dir": str(self.run.run_dir), "regime": self.regime,
               "area": _num(self.area), "thickness": _num(self.thickness),
               "slips": self.run.n_slips, "skipped_first": self.run.skip}
        for name in ("static_force", "restick_force", "first_yield_force", "kinetic_force",
                     "film_damping", "eta_eff", "shear_rate", "ageing", "shear_stiffness"):
            e = getattr(self, name)
            out[name] = None if e is None else e.as_dict()
        if self.slip_fit is not None:
            out["slip_fit"] = {"rms_residual": _num(self.slip_fit.rms_residual),
                               "n_slips": self.slip_fit.n_slips,
                               "mount_damping": _num(self.slip_fit.mount_damping)}
        out["replay"] = None if self.replay is None else self.replay.as_dict()
        out["failures"] = dict(self.failures)
        return out


def _summary(doc: dict, name: str, units: str, method: str) -> Estimate | None:
    e = doc.get("slips", {}).get(name) or {}
    if e.get("mean") is None:
        return None
    return Estimate(float(e["mean"]), float(e["stderr"]) if e.get("stderr") is not None else math.nan,
                    units, method)


def _ageing(run: RunData) -> Estimate | None:
    """Slope of F_s against ln(preceding stick time) over the analysed slips (≥ 4)."""
    from scipy.stats import linregress

    fs = np.asarray(run.cycles.get("static_force", []), float)
    stick = np.asarray(run.cycles.get("stick_duration", []), float)
    if fs.size < 2:
        return None
    # slip i+1 yields after the stick that follows slip i
    x = stick[:-1][run.skip:] if run.skip else stick[:-1]
    y = fs[1:][run.skip:] if run.skip else fs[1:]
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0)
    if ok.sum() < 4 or np.ptp(np.log(x[ok])) == 0:
        return None
    res = linregress(np.log(x[ok]), y[ok])
    return Estimate(float(res.slope), float(res.stderr), _labels(run.trace.units)["force"],
                    f"linear fit of F_s vs ln(preceding stick time), {int(ok.sum())} slips")


def _shear_stiffness(run: RunData) -> Estimate | None:
    """The stuck film's elastic shear stiffness k_f from the slopes of the stick ramps.

    A stuck film strains like a spring in series with the drive spring: the
    force rises at K_eff V with 1/K_eff = 1/K + 1/k_f.  Each ramp (re-stick to
    the next yield, its first quarter and last tenth left out: ringing and
    creep before the yield) gives a slope; k_f = K K_eff/(K − K_eff) from
    their mean, its error propagated from theirs.  None with fewer than 2
    ramps or when K_eff is not below K (no measurable compliance).
    """
    tr = run.trace
    k = tr.parameters.spring_constant
    v = tr.parameters.drive_velocity
    if not (k and v):
        return None
    t, f = tr.time, tr.spring_force
    sticks = np.asarray(run.cycles.get("stick_index", []), int)
    yields = np.asarray(run.cycles.get("yield_index", []), int)
    slopes = []
    for i0, i1 in zip(sticks[:-1], yields[1:]):
        lo, hi = i0 + (i1 - i0) // 4, i1 - (i1 - i0) // 10
        if hi - lo >= 5:
            slopes.append(np.polyfit(t[lo:hi], f[lo:hi], 1)[0] / v)
    if len(slopes) < 2:
        return None
    k_eff = float(np.mean(slopes))
    se = float(np.std(slopes, ddof=1) / math.sqrt(len(slopes)))
    if not 0.0 < k_eff < k - 2.0 * se:
        return None
    k_f = k * k_eff / (k - k_eff)
    dk = se * (k / (k - k_eff)) ** 2          # d k_f / d K_eff
    return Estimate(k_f, dk, _labels(tr.units)["stiffness"],
                    f"stick ramps' slope K_eff = {k_eff:.4g} (K = {k:g}) from {len(slopes)} "
                    "ramps: 1/k_f = 1/K_eff - 1/K")


def calibrate_run(run: RunData) -> RunCalibration:
    """Calibrate the model on one run (see the module docstring for each parameter)."""
    tr = run.trace
    u = _labels(tr.units)
    doc = run.analysis
    regime = doc.get("regime", "?")
    area = tr.parameters.area
    failures: dict = {}
    try:
        thickness = run.thickness
    except LookupError as exc:
        thickness = math.nan
        failures["thickness"] = str(exc)
    kw: dict = {}
    skipnote = "start-up yield left out" if run.skip else "all slips"
    kw["static_force"] = _summary(doc, "static_force", u["force"], f"mean F_s at y, {skipnote}")
    kw["restick_force"] = _summary(doc, "backward_force", u["force"], f"mean F_b at s, {skipnote}")
    if run.skip and run.n_slips:
        kw["first_yield_force"] = Estimate(float(run.cycles["static_force"][0]), math.nan, u["force"],
                                           "start-up yield from a relaxed spring (one value)")
    kw["ageing"] = _ageing(run)
    kw["shear_stiffness"] = _shear_stiffness(run)
    if kw["static_force"] is None:
        failures["slip_fit"] = f"no slips to fit (regime {regime})"
    else:
        try:
            fit = fit_slip_law(run)
            kw.update(slip_fit=fit, kinetic_force=fit.kinetic_force, film_damping=fit.film_damping,
                      static_force=fit.static_force)
        except (ValueError, LookupError, RuntimeError) as exc:
            failures["slip_fit"] = str(exc)
    # eta_eff: from the slip fit, else steady sliding
    fit = kw.get("slip_fit")
    if fit is not None and area and math.isfinite(thickness):
        b = fit.film_damping
        eta = b.value * thickness / area
        slips = doc.get("slips", {})
        dx = (slips.get("slip_distance") or {}).get("mean")
        ts = (slips.get("slip_duration") or {}).get("mean")
        rate = dx / ts / thickness if dx and ts else math.nan
        kw["eta_eff"] = Estimate(eta, b.stderr * thickness / area, u["viscosity"],
                                 "B D / A from the slip fit (D = mean gap)")
        klein = (doc.get("viscosity", {}).get("from_slip") or {}).get("eta_eff") or {}
        if fit.damping_at_bound and klein.get("mean"):
            # F_k carries all of the sliding friction and B is unresolved: the film's
            # viscosity is then Klein's own reading of the slips (all friction viscous)
            kw["eta_eff"] = Estimate(float(klein["mean"]), float(klein.get("stderr") or math.nan),
                                     u["viscosity"],
                                     "Klein's purely viscous fit of the slips (analysis, mount "
                                     "removed): the calibration's B is at its lower bound")
        kw["shear_rate"] = Estimate(rate, math.nan, u["shear_rate"],
                                    "mean slip velocity (dx0 / tau_s) over the gap")
    else:
        steady = doc.get("viscosity", {}).get("steady")
        if steady:
            e = steady["eta_eff"]
            # the spring also pulls the mount dashpot (d V): not the film's
            d = tr.parameters.mount_damping or 0.0
            gap = steady.get("thickness", {}).get("mean") or thickness
            kw["eta_eff"] = Estimate(e["mean"] - d * gap / area, e.get("stderr") or math.nan,
                                     u["viscosity"],
                                     f"steady sliding: ((F - d V)/A)/(V/D), block-averaged (mount d = {d:g} "
                                     "subtracted)")
            kw["shear_rate"] = Estimate(steady["shear_rate"]["mean"], math.nan, u["shear_rate"],
                                        "V / D")
        else:
            failures["eta_eff"] = "neither a slip fit nor steady sliding in this run"
    if fit is not None:
        try:
            restick = kw["restick_force"].value if kw.get("restick_force") else None
            shear = kw["shear_stiffness"].value if kw.get("shear_stiffness") else math.inf
            kw["replay"] = replay(run, kw["static_force"].value, fit.kinetic_force.value,
                                  fit.film_damping.value, restick_force=restick,
                                  shear_stiffness=shear)
            why = _no_restick(run, fit.kinetic_force.value, fit.film_damping.value)
            if why and not kw["replay"].errors["period"]["model_cycles"]:
                failures["replay"] = why
        except (ValueError, LookupError, RuntimeError) as exc:
            failures["replay"] = str(exc)
    else:
        failures.setdefault("replay", "no calibrated slip law")
    return RunCalibration(run=run, regime=regime, area=float(area or math.nan),
                          thickness=thickness, failures=failures, **kw)


@dataclass(frozen=True, eq=False)
class Calibration:
    """The calibration over one or several runs.

    Attributes
    ----------
    runs : list of RunCalibration
        In the order given (the first is the "main" run: replay, report).
    rate_law : analysis.viscosity.PowerLaw or None
        η_eff = c γ̇^α across runs (≥ 3 distinct rates).
    rate_points : list of (float, float, float)
        (γ̇, η_eff, stderr) per run that has both.
    md_calibration : workflows.sfb.MDCalibration or None
    notes : list of str
    failures : dict
    units : str
    """

    runs: list
    rate_law: object = None
    rate_points: list = field(default_factory=list)
    md_calibration: object = None
    notes: list = field(default_factory=list)
    failures: dict = field(default_factory=dict)
    units: str = "lj"

    @property
    def main(self) -> RunCalibration:
        return self.runs[0]

    def as_dict(self) -> dict:
        law = None
        if self.rate_law is not None:
            law = {"exponent": _num(self.rate_law.exponent),
                   "exponent_stderr": _num(self.rate_law.exponent_stderr),
                   "prefactor": _num(self.rate_law.prefactor),
                   "prefactor_rel_stderr": _num(self.rate_law.prefactor_rel_stderr),
                   "n": self.rate_law.n, "form": "eta_eff = prefactor * shear_rate**exponent"}
        md = None
        if self.md_calibration is not None:
            md = asdict(self.md_calibration)
            md["shear_rate_range"] = (list(md["shear_rate_range"])
                                      if md["shear_rate_range"] is not None else None)
        return {"schema": SCHEMA, "units": self.units,
                "model": "SpringBlock + Coulomb(static F_s, kinetic F_k, viscous B) + mount dashpot d",
                "runs": [r.as_dict() for r in self.runs],
                "rate_points": [[_num(a), _num(b), _num(c)] for a, b, c in self.rate_points],
                "rate_law": law, "md_calibration": md,
                "notes": list(self.notes), "failures": dict(self.failures)}


def _combine(values: list[Estimate]) -> tuple[float, float]:
    """Inverse-variance mean (plain mean when an error is missing) and its error."""
    v = np.array([e.value for e in values], float)
    s = np.array([e.stderr for e in values], float)
    if v.size == 1:
        return float(v[0]), float(s[0]) if np.isfinite(s[0]) else 0.0
    if np.all(np.isfinite(s) & (s > 0)):
        w = 1.0 / s ** 2
        return float(np.sum(w * v) / np.sum(w)), float(1.0 / math.sqrt(np.sum(w)))
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(v.size))


def _stress(e: Estimate | None, area: float) -> Estimate | None:
    if e is None or not area or not math.isfinite(area):
        return None
    return Estimate(e.value / area, e.stderr / area, "stress", e.method)


def _md_calibration(runs: list[RunCalibration], law, points, notes: list):
    """Build the MDCalibration (LJ stresses) or explain why not."""
    from filmfriction.workflows.sfb import MDCalibration

    ss = [r for r in runs if r.static_force is not None and r.kinetic_force is not None
          and r.eta_eff is not None]
    if not ss:
        raise ValueError("no run with a calibrated slip law (stick-slip with fitted slips) "
                         "to give the yield stress")
    ys, ys_err = _combine([_stress(r.static_force, r.area) for r in ss])
    ks, ks_err = _combine([_stress(r.kinetic_force, r.area) for r in ss])
    rs_list = [_stress(r.restick_force, r.area) for r in ss if r.restick_force is not None]
    restick, restick_err = (None, 0.0)
    if rs_list:
        rs, rs_err = _combine(rs_list)
        if 0.0 <= rs < ys:
            restick, restick_err = rs, rs_err if math.isfinite(rs_err) else 0.0
        else:
            notes.append(f"re-stick stress {rs:.3g} outside [0, yield stress): the SFB slip ends "
                         "where the model stops instead")
    ks = min(max(ks, 0.0), 0.999 * ys)
    rates = [p[0] for p in points if math.isfinite(p[0])]
    kwargs = {}
    if law is not None:
        n = -law.exponent
        n_err = law.exponent_stderr
        if not 0.0 <= n < 1.0:
            notes.append(f"fitted thinning exponent n = {n:.3g} outside [0, 1): clipped for the SFB law")
            n = min(max(n, 0.0), 0.99)
        g_lo = min(rates)
        eta_lo = law.prefactor * g_lo ** law.exponent
        eta0 = eta_lo * 2.0 ** (n / 2.0)      # Carreau at its onset = the fit there
        kwargs = dict(eta_zero=eta0, eta_zero_err=eta0 * law.prefactor_rel_stderr,
                      thinning_exponent=n, thinning_exponent_err=n_err, onset_rate=g_lo)
    else:
        e, e_err = _combine([r.eta_eff for r in ss])
        if not e > 0:
            raise ValueError(f"film eta_eff = {e:.3g} is not positive: no viscous film to carry to the SFB")
        kwargs = dict(eta_zero=e, eta_zero_err=e_err if math.isfinite(e_err) else 0.0)
        notes.append("one shear rate only: Newtonian eta_eff carried to the SFB rate (a sweep of "
                     "drive velocities is needed for the shear-rate law)")
    return MDCalibration(
        yield_stress=ys, yield_stress_err=ys_err if math.isfinite(ys_err) else 0.0,
        sliding_stress=ks, sliding_stress_err=ks_err if math.isfinite(ks_err) else 0.0,
        restick_stress=restick, restick_stress_err=restick_err,
        shear_rate_range=(min(rates), max(rates)) if rates else None,
        film_thickness=float(np.mean([r.thickness for r in ss])),
        source="; ".join(str(r.run.run_dir) for r in runs), **kwargs)


def calibrate(run_dirs) -> Calibration:
    """Calibrate the reduced model on one or several run directories.

    Parameters
    ----------
    run_dirs : path-like or list of path-like

    Returns
    -------
    Calibration

    Raises
    ------
    ValueError
        A directory cannot be read.
    """
    from filmfriction.analysis.viscosity import power_law_fit

    if isinstance(run_dirs, (str, os.PathLike)):
        run_dirs = [run_dirs]
    runs = [calibrate_run(load_run(d)) for d in run_dirs]
    if not runs:
        raise ValueError("no run directory given")
    units = {r.run.trace.units for r in runs}
    if len(units) != 1:
        raise ValueError(f"runs in different unit systems: {sorted(units)}")
    notes, failures = [], {}
    points = [(r.shear_rate.value, r.eta_eff.value, r.eta_eff.stderr) for r in runs
              if r.eta_eff is not None and r.shear_rate is not None
              and math.isfinite(r.shear_rate.value) and r.eta_eff.value > 0]
    law = None
    distinct = len({round(math.log10(p[0]), 3) for p in points if p[0] > 0})
    if distinct >= 3:
        errs = np.array([p[2] for p in points], float)
        use_err = bool(np.all(np.isfinite(errs) & (errs > 0)))
        try:
            law = power_law_fit([p[0] for p in points], [p[1] for p in points],
                                errs if use_err else None)
        except (ValueError, RuntimeError) as exc:
            failures["rate_law"] = str(exc)
    else:
        failures["rate_law"] = (f"{distinct} distinct shear rate(s): the power law needs runs at >= 3 "
                                "(e.g. a drive-velocity sweep)")
    md = None
    try:
        md = _md_calibration(runs, law, points, notes)
    except ValueError as exc:
        failures["md_calibration"] = str(exc)
    return Calibration(runs=runs, rate_law=law, rate_points=points, md_calibration=md,
                       notes=notes, failures=failures, units=units.pop())


def write_calibration(cal: Calibration, path=None) -> Path:
    """Write ``calibration.json`` atomically (default: in the first run directory)."""
    from filmfriction.analysis.report import to_json

    path = Path(path) if path is not None else cal.main.run.run_dir / "calibration.json"
    from filmfriction.analysis.atomic import write_atomic

    return write_atomic(path, to_json(cal.as_dict()) + "\n")
