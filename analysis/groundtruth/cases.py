"""Traces with known answers from the reduced model, and the analysis scored on them.

A :class:`Case` is a spring-block (:class:`~filmfriction.reduced_model.SpringBlock`)
with one of five friction laws -- Coulomb, Coulomb + viscous, Stribeck,
rate-and-state and Klein's Eq. (1) (a viscous slip that freezes at a set
speed) -- sampled uniformly or at the model's own output times, with white or
correlated (AR(1)) noise on the spring force, in LJ or SI numbers.
:func:`truth` reads the answer off the model's exact trajectory with the
analysis' own definitions (docs/analysis.md, "Definitions"):

* the yield point y is the spring force's maximum at the end of a stick
  (the wall has caught up with the drive, v = V), F_s the force there;
* the re-stick point s is the force's minimum at the end of the slip, F_b the
  force there;
* slip duration t_s − t_y, stick duration t_y(next) − t_s, period
  t_y(next) − t_y; slip distance x(s) − x(y), the wall's displacement
  (= (F_s − F_b)/K + V (t_s − t_y));
* energy per slip: the heat the contact makes from y to s (the law's friction
  and the damper's work, the model's own integrals).

:func:`score` runs the analysis (:func:`filmfriction.analysis.analyze.context`
and, on request, the calibration) on a case's trace and compares each
reported mean ± standard error with the truth: the error in units of the
force drop (forces) or relative (the rest), and whether ±1 s.e. covers it.
``benchmarks/validate.py`` tabulates the scores over random cases.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicHermiteSpline
from scipy.signal import lfilter

from filmfriction.reduced_model import SpringBlock, laws
from filmfriction.reduced_model.integrators.closed_form import freeze_velocity_for

from ..files.trace import Trace, TraceParameters

__all__ = ["FAMILIES", "Case", "Truth", "random_case", "simulate", "truth", "sample",
           "Score", "score", "OBSERVABLES"]

#: the friction laws of the suite
FAMILIES = ("coulomb", "coulomb-viscous", "coulomb-elastic", "stribeck", "rate-state",
            "klein-eq1")

#: SI scales of one model unit (length, time, mass): an SFB-like contact,
#: forces of µN, displacements of 100 nm, slips of ms
SI_SCALE = (1e-7, 1e-3, 1e-3)


@dataclass(frozen=True)
class Case:
    """One ground-truth trace to make.

    Attributes
    ----------
    family : str
        One of :data:`FAMILIES`.
    block : SpringBlock
        The model, in model units (the SI case is scaled after the run).
    cycles : int
        Slips wanted in the trace (the first, from a relaxed spring, included).
    samples_per_slip : float
        Samples over one slip duration (uniform sampling), or the closed form's
        samples per slip segment (``sampling = "events"``).
    sampling : {"uniform", "events"}
        Uniform in time, or the model's own output times (event times included).
    noise : float
        Standard deviation of the force noise, as a fraction of the force drop.
    correlation : float
        AR(1) coefficient of the noise per sample (0: white).
    units : {"lj", "si"}
    seed : int
    initial_velocity : float, optional
        Block velocity at t = 0 (a law without static friction starts from a
        perturbed steady sliding, which grows into stick-slip).
    """

    family: str
    block: SpringBlock
    cycles: int = 8
    samples_per_slip: float = 50.0
    sampling: str = "uniform"
    noise: float = 0.0
    correlation: float = 0.0
    units: str = "lj"
    seed: int = 0
    initial_velocity: float | None = None

    def label(self) -> str:
        return (f"{self.family} {self.units} {self.sampling} n/slip={self.samples_per_slip:g} "
                f"noise={self.noise:g} rho={self.correlation:g} seed={self.seed}")


def _loguniform(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def random_case(family: str, rng, **options) -> Case:
    """A random stick-slip block of ``family`` (model units, forces of order 1): see
    :func:`_draw`; a draw that does not stick-slip (checked by a short run) is
    drawn again."""
    for _ in range(50):
        try:
            case = _draw(family, rng, **options)
            c = _probe(case)
        except ValueError:
            continue
        if len(c) >= 3:
            return case
    raise RuntimeError(f"no stick-slip {family} block in 50 draws")


def _probe(case: Case):
    block = case.block
    return block.simulate(duration=_probe_duration(block), samples_per_segment=64,
                          initial_velocity=case.initial_velocity).cycles()


def _draw(family: str, rng, **options) -> Case:
    """A random stick-slip block of ``family`` (model units, forces of order 1).

    λ = (F_s − F_k)/(V √(KM)), the ratio of the slip's speed to the drive's, is
    drawn in [1, 100]: clean stick-slip whose force extrema sit close to the
    law's breakaway and re-stick (λ large) or well after and before them (λ ≈ 1,
    slips as long as the sticks).
    """
    k = _loguniform(rng, 0.3, 30.0)
    m = _loguniform(rng, 0.3, 300.0)
    fs = _loguniform(rng, 0.5, 5.0)
    lam = _loguniform(rng, 1.0, 100.0)
    root = math.sqrt(k * m)
    if family == "coulomb":
        fk = fs * rng.uniform(0.2, 0.8)
        law = laws.Coulomb(static=fs, kinetic=fk)
    elif family == "coulomb-elastic":
        # a stuck film that strains before it yields: the ramps rise at K k_f/(K + k_f) V
        fk = fs * rng.uniform(0.2, 0.8)
        law = laws.Coulomb(static=fs, kinetic=fk, shear_stiffness=_loguniform(rng, 1.0, 10.0) * k)
    elif family == "coulomb-viscous":
        fk = fs * rng.uniform(0.2, 0.8)
        law = laws.Coulomb(static=fs, kinetic=fk, viscous=rng.uniform(0.05, 0.6) * 2 * root)
    elif family == "stribeck":
        fk = fs * rng.uniform(0.2, 0.7)
        speed = (fs - fk) / root                      # the slip's speed scale
        law = laws.StribeckExponential(static=fs, kinetic=fk,
                                       stribeck_velocity=rng.uniform(0.2, 1.0) * speed)
    elif family == "rate-state":
        # velocity weakening, K well below the critical stiffness: relaxation oscillations
        k, m = 10.0 * rng.uniform(0.5, 1.0), _loguniform(rng, 0.2, 2.0)
        law = laws.RateState(mu0=0.6, a=0.01, b=0.015, dc=1e-2, v0=0.1)
        v = 0.1 * rng.uniform(0.5, 2.0)
        block = SpringBlock(mass=m, stiffness=k, drive_velocity=v, law=law)
        return Case(family, block, initial_velocity=0.5 * v, **options)
    elif family == "klein-eq1":
        # M x'' + B x' = K(x0 - x) overdamped (Klein's SFB: ζ ≈ 4), frozen at F_b
        b = rng.uniform(1.5, 5.0) * 2 * root
        fk = 0.0
        speed = fs / b
        v = speed / _loguniform(rng, 5.0, 50.0)
        block = SpringBlock(mass=m, stiffness=k, drive_velocity=v,
                            law=laws.Coulomb(static=fs, kinetic=0.0, viscous=b))
        fb = fs * rng.uniform(0.15, 0.5)
        vf = freeze_velocity_for(block, fs, fb)
        block = replace(block, law=replace(block.law, freeze_velocity=vf))
        return Case(family, block, **options)
    else:
        raise ValueError(f"family = {family!r}: allowed values are {FAMILIES}")
    v = (fs - fk) / (lam * root)
    return Case(family, SpringBlock(mass=m, stiffness=k, drive_velocity=v, law=law), **options)


# ---------------------------------------------------------------------------
# the truth
# ---------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Truth:
    """Per-slip answers of a model run (model units), by the analysis' definitions.

    ``yield_time``/``stick_time`` are the force's maxima and minima;
    ``period`` and ``stick_duration`` are NaN for the last slip.
    """

    yield_time: np.ndarray
    stick_time: np.ndarray
    static_force: np.ndarray
    backward_force: np.ndarray
    slip_distance: np.ndarray
    slip_duration: np.ndarray
    stick_duration: np.ndarray
    period: np.ndarray
    slip_heat: np.ndarray
    law_static_force: float | None = None
    film_stiffness: float | None = None

    def __len__(self):
        return int(self.yield_time.size)


def simulate(case: Case):
    """The model run of ``case``: ``cycles`` slips and three quarters of a period more
    (model units)."""
    block = case.block
    c = _probe(case)
    if len(c) < 2:
        raise ValueError(f"{case.label()}: the block does not stick-slip ({len(c)} slips)")
    period = float(np.nanmedian(c.period))
    first = float(c.yield_time[0])
    duration = first + (case.cycles - 0.25) * period
    return block.simulate(duration=duration, samples_per_segment=512,
                          initial_velocity=case.initial_velocity)


def _probe_duration(block: SpringBlock) -> float:
    law = block.law
    fs = getattr(law, "static", None)
    if fs is None:          # rate-and-state: the limit cycle needs a few dc/V
        return 400.0 * law.dc / block.drive_velocity
    return 4.0 * fs / (block.stiffness * block.drive_velocity) + 40.0 * math.sqrt(
        block.mass / block.stiffness)


def _spline(r, k, v_drive):
    """Hermite cubic of the spring force on the model's samples (F' = K(V − v) exact there)."""
    t, f = r.t, r.spring_force
    keep = np.concatenate(([True], np.diff(t) > 0))
    return CubicHermiteSpline(t[keep], f[keep], k * (v_drive - r.v[keep]))


def _extremum(spline, lo, hi, largest):
    """(time, value) of the largest (smallest) value of ``spline`` on [lo, hi]."""
    ts = spline.x
    inner = ts[(ts > lo) & (ts < hi)]
    roots = spline.derivative().roots(extrapolate=False)
    roots = roots[(roots > lo) & (roots < hi)]
    cand = np.concatenate(([lo, hi], inner, roots))
    vals = spline(cand)
    i = int(np.argmax(vals) if largest else np.argmin(vals))
    return float(cand[i]), float(vals[i])


def truth(case: Case, result=None) -> Truth:
    """The answers of ``case``'s run (model units) by the analysis' definitions.

    Each slip of the law (breakaway to re-stick, or for a law without a true
    stick the model's own force maximum to minimum) is bracketed; the force's
    maximum and minimum are found on the Hermite cubic through the model's
    samples (error ~1e-8 of the drop at 512 samples per slip), and the heat
    from the model's own dissipation integrals, interpolated the same way."""
    r = simulate(case) if result is None else result
    block = case.block
    k, v_drive = block.stiffness, block.drive_velocity
    spline = _spline(r, k, v_drive)
    yi, si = r.slip_pairs()
    t = r.t
    # a last slip whose re-stick the run does not reach still has its force minimum
    # when the force rises again before the end (the analysis counts it)
    slips = [e.index for e in r.events if e.kind == "slip"]
    last = [i for i in slips if not si.size or i > si[-1]]
    ends = list(si) + ([t.size - 1] if last else [])
    starts = list(yi) + ([last[0]] if last else [])
    ty, fy, ts_, fb = [], [], [], []
    for j, (a, b) in enumerate(zip(starts, ends)):
        prev = t[ends[j - 1]] if j else t[0]
        nxt = t[starts[j + 1]] if j + 1 < len(starts) else t[-1]
        # the maximum lies between the previous re-stick and this slip's re-stick,
        # the minimum between this slip's breakaway and the next breakaway
        tmax, fmax = _extremum(spline, 0.5 * (prev + t[a]), t[b], True)
        tmin, fmin = _extremum(spline, tmax, 0.5 * (t[b] + nxt) if j + 1 < len(starts)
                               else t[-1], False)
        if j == len(yi) and not (tmin < t[-1] and spline(t[-1]) > fmin + 1e-3 * (fmax - fmin)):
            break                       # the last slip's force has not turned up yet
        ty.append(tmax), fy.append(fmax), ts_.append(tmin), fb.append(fmin)
    ty, fy, ts_, fb = map(np.asarray, (ty, fy, ts_, fb))
    nan = np.full(ty.size, math.nan)
    period, stick = nan.copy(), nan.copy()
    period[:-1] = np.diff(ty)
    stick[:-1] = ty[1:] - ts_[:-1]
    dist = (fy - fb) / k + v_drive * (ts_ - ty)
    heat_cum = r.friction_dissipation + r.damper_dissipation
    heat = np.interp(ts_, t, heat_cum) - np.interp(ty, t, heat_cum)
    law = block.law
    kf = getattr(law, "shear_stiffness", None)
    return Truth(ty, ts_, fy, fb, dist, ts_ - ty, stick, period, heat,
                 getattr(law, "static", None),
                 kf if kf is not None and math.isfinite(kf) else None)


# ---------------------------------------------------------------------------
# the trace
# ---------------------------------------------------------------------------

def sample(case: Case, result=None, tr: Truth | None = None) -> tuple[dict, dict]:
    """The trace of ``case`` (columns ``time, spring_force, drive_position``) and
    its parameters, in the case's units.

    Uniform sampling: ``samples_per_slip`` samples per mean slip duration, the
    force from the Hermite cubic through the model's samples.  ``"events"``:
    the model's own output at ``samples_per_slip`` samples per slip segment
    (sticks are straight lines and get few), event times included.
    """
    block = case.block
    k, v_drive = block.stiffness, block.drive_velocity
    rng = np.random.default_rng(case.seed)
    if case.sampling == "events":
        r = block.simulate(duration=float(simulate(case).t[-1]) if result is None
                           else float(result.t[-1]),
                           samples_per_segment=max(int(case.samples_per_slip), 2),
                           initial_velocity=case.initial_velocity)
        keep = np.concatenate(([True], np.diff(r.t) > 0))
        t, f = r.t[keep], r.spring_force[keep]
        tr = truth(case, r) if tr is None else tr
    elif case.sampling == "uniform":
        r = simulate(case) if result is None else result
        tr = truth(case, r) if tr is None else tr
        dt = float(np.mean(tr.slip_duration[1:])) / case.samples_per_slip
        phase = rng.uniform(0.0, dt)
        t = np.arange(phase, r.t[-1], dt)
        f = _spline(r, k, v_drive)(t)
    else:
        raise ValueError(f"sampling = {case.sampling!r}: allowed values are 'uniform', 'events'")
    drop = float(np.mean(tr.static_force[1:] - tr.backward_force[1:]))
    if case.noise:
        rho = case.correlation
        e = rng.normal(0.0, case.noise * drop * math.sqrt(1 - rho ** 2), t.size)
        e[0] = rng.normal(0.0, case.noise * drop)
        f = f + (lfilter([1.0], [1.0, -rho], e) if rho else e)
    xd0 = (r.drive_position[0] if result is None else result.drive_position[0])
    drive = xd0 + v_drive * t
    L, T, M = SI_SCALE if case.units == "si" else (1.0, 1.0, 1.0)
    F = M * L / T ** 2
    cols = {"time": t * T, "spring_force": f * F, "drive_position": drive * L}
    params = {"spring_constant": k * F / L, "mass": block.mass * M,
              "drive_velocity": v_drive * L / T, "units": case.units}
    return cols, params


def as_trace(cols: dict, params: dict) -> Trace:
    """A :class:`Trace` of ``cols`` (in memory, no file)."""
    return Trace(columns={n: np.asarray(c, float) for n, c in cols.items()},
                 parameters=TraceParameters(**params), path=Path("<ground truth>"))


# ---------------------------------------------------------------------------
# scoring
# ---------------------------------------------------------------------------

#: observable -> (truth attribute, how its error is expressed): "drop" = in units of
#: the force drop F_s − F_b, "rel" = relative to the truth
OBSERVABLES = {"static_force": ("static_force", "drop"),
               "backward_force": ("backward_force", "drop"),
               "slip_distance": ("slip_distance", "rel"),
               "slip_duration": ("slip_duration", "rel"),
               "stick_duration": ("stick_duration", "rel"),
               "period": ("period", "rel"),
               "energy_per_slip": ("slip_heat", "rel")}


@dataclass(frozen=True)
class Score:
    """One case's result: per observable the error (value − truth, scaled as in
    :data:`OBSERVABLES`), the reported standard error on the same scale, and
    whether ±1 s.e. covers the truth (None when no error bar was reported)."""

    case: Case
    detected: int
    expected: int
    regime: str
    errors: dict = field(default_factory=dict)
    stderrs: dict = field(default_factory=dict)
    covered: dict = field(default_factory=dict)
    message: str = ""


def _scale(case: Case):
    L, T, M = SI_SCALE if case.units == "si" else (1.0, 1.0, 1.0)
    return {"force": M * L / T ** 2, "length": L, "time": T, "energy": M * L ** 2 / T ** 2}


_QUANTITY = {"static_force": "force", "backward_force": "force", "slip_distance": "length",
             "slip_duration": "time", "stick_duration": "time", "period": "time",
             "energy_per_slip": "energy"}


def score(case: Case) -> Score:
    """Analyse ``case``'s trace and score every observable against :func:`truth`."""
    from ..energy.partition import energy_table
    from ..analyze import context
    from ..stick_ramps import stick_stiffness

    r = simulate(case)
    tr = truth(case, r)
    cols, params = sample(case, r, tr)
    trace = as_trace(cols, params)
    scale = _scale(case)
    expected = len(tr)
    try:
        ctx = context(trace, structure=False)
    except ValueError as exc:
        return Score(case, 0, expected, "error", message=str(exc))
    table = ctx.all_slips
    n = len(table)
    out = Score(case, n, expected, str(ctx.regime))
    if n < 2:
        return replace(out, message="fewer than 2 slips detected")
    # match each detected slip to the true slip whose yield is nearest
    ty = tr.yield_time * scale["time"]
    match = np.abs(np.asarray(table.yield_time)[:, None] - ty[None, :]).argmin(axis=1)
    skip = ctx.skip
    rows = match[skip:]
    drop = float(np.mean(tr.static_force[rows] - tr.backward_force[rows])) * scale["force"]
    summary = table.summary(skip=skip)
    et = energy_table(trace.time, trace.spring_force, table, params["spring_constant"],
                      drive_velocity=params["drive_velocity"],
                      drive_position=cols["drive_position"])
    heat = np.asarray(et.film_dissipation, float)[skip:]
    summary["energy_per_slip"] = _stats(heat)
    errors, ses, cov = {}, {}, {}
    if tr.film_stiffness is not None:
        st = stick_stiffness(trace.time, trace.spring_force, table,
                             spring_constant=params["spring_constant"],
                             drive_velocity=params["drive_velocity"])
        kf = tr.film_stiffness * scale["force"] / scale["length"]
        if st is not None:
            errors["film_stiffness"] = (st.film_stiffness - kf) / kf
            ses["film_stiffness"] = st.film_stiffness_stderr / kf
            cov["film_stiffness"] = (abs(st.film_stiffness - kf) <= st.film_stiffness_stderr
                                     if math.isfinite(st.film_stiffness_stderr) else None)
    for name, (attr, how) in OBSERVABLES.items():
        true_rows = np.asarray(getattr(tr, attr), float)[rows] * scale[_QUANTITY[name]]
        est_rows = heat if name == "energy_per_slip" else np.asarray(getattr(table, name),
                                                                     float)[skip:]
        ok = np.isfinite(true_rows) & np.isfinite(est_rows)
        est = summary[name]
        if not ok.any() or not math.isfinite(est["mean"]):
            continue
        truth_mean = float(np.mean(true_rows[ok]))
        denom = drop if how == "drop" else abs(truth_mean)
        errors[name] = (est["mean"] - truth_mean) / denom
        se = est["stderr"]
        ses[name] = se / denom if math.isfinite(se) else math.nan
        cov[name] = (abs(est["mean"] - truth_mean) <= se) if math.isfinite(se) else None
    return replace(out, errors=errors, stderrs=ses, covered=cov)


def _stats(values):
    from filmfriction.reduced_model.cycles import stats
    return stats(np.asarray(values, float))
