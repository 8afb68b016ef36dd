"""The slip law's MD positive control: a liquid film resisting a wall let go from a stretched spring.

The ``liquid-release`` scene lets the top wall go from a spring stretched by x0 = 20 σ,
with no drive (``drive_velocity = 0``, ``release_offset = 20``), on a film that is a
liquid (kT = 1.5 ε).  A liquid has no yield stress, so the slip is Klein's Eq. 1 with
nothing else: M x'' + B x' = K(x0 − x), and B is the Couette damping of the film,

    B = η A / (D + 2b) = η A / W,

η the liquid's viscosity, A the area, D the film's thickness and b the slip length at
each wall; W = D + 2b is the width over which the film's velocity profile, extended
linearly, goes from the bottom wall's velocity to the top wall's, i.e. 1/(d f/dz) with f
the layers' velocity shares (:mod:`~filmfriction.analysis.observables.shear_location_section`).

:func:`release_slip` finds the release's slip in a trace (the first swing: from the
release to the first stop of the wall).  :func:`fit_release_ensemble` fits the slip law
(:func:`~filmfriction.analysis.slip_law.slip_law.fit_film_force`) to the mean trace of
several releases (independent seeds: replicas of one initial condition), its errors the
jackknife's over the releases; :func:`fit_releases` fits each release's slip and takes
the slips' scatter.  The first is the control's fit: the film's random force moves the
wall, so each release's regressors (its Δx, Δv) carry the noise of its response and the
per-release fit is biased (on the fluctuating Newtonian film of
:mod:`~filmfriction.analysis.groundtruth.film_release`, a loop step of ≈ +1.4 ε/σ where
there is none, docs/results/slip-law.md); the law is linear in the trace, so the mean
trace's fit is not.

Example
-------
A Klein block released from x0 = 20 (M = 500, K = 1, B = 20), sampled as the MD is:

>>> import numpy as np
>>> from scipy.integrate import solve_ivp
>>> t = np.arange(0, 120, 0.05)
>>> sol = solve_ivp(lambda _, y: [y[1], (20 - y[0] - 20 * y[1]) / 500], (0, 120), [0, 0],
...                 t_eval=t, rtol=1e-10, atol=1e-10)
>>> x, v = sol.y
>>> y, s = release_slip(t, x)
>>> fit = fit_releases([{"time": t, "wall_position": x, "wall_velocity": v,
...                      "spring_force": 20 - x}] * 3, mass=500.0)
>>> round(fit.decelerating.damping, 2), abs(fit.decelerating.kinetic_force) < 1e-3
(20.0, True)
"""
from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter

from filmfriction.reduced_model.cycles import cycle_table

from ..slip_law.slip_law import FilmForceFit, fit_film_force, jackknife_fit

__all__ = ["release_slip", "release_gap", "fit_releases", "fit_release_ensemble", "mean_release",
           "profile_width", "release_profile",
           "couette_comoving_mass", "model_release"]


def release_slip(time, wall_position, *, smoothing: float = 5.0) -> tuple[int, int]:
    """(0, stick index) of a release: the slip runs from the first sample to the first
    stop of the wall after its peak velocity (the wall's velocity smoothed over
    ``smoothing`` time units, Savitzky–Golay of order 2, crossing zero)."""
    _, peak, stop = _release_turns(time, wall_position, smoothing)
    return 0, stop


def _release_turns(time, wall_position, smoothing: float) -> tuple[int, int, int]:
    """(release, peak velocity, stop) indices of a release, as :func:`release_slip`."""
    t, x = np.asarray(time, float), np.asarray(wall_position, float)
    dt = float(t[1] - t[0])
    w = max(5, int(round(smoothing / dt)) | 1)
    if w >= t.size:
        raise ValueError(f"trace of {t.size} samples is shorter than the smoothing window {w}")
    v = savgol_filter(x, w, 2, deriv=1, delta=dt)
    peak = int(np.argmax(v))
    stops = np.flatnonzero(v[peak:] <= 0)
    if not v[peak] > 0 or stops.size == 0:
        raise ValueError("the wall does not stop within the trace: run the release longer")
    return 0, peak, peak + int(stops[0])


def release_gap(trace, *, pressure: float, area: float, parts: int = 5,
                smoothing: float = 5.0) -> dict:
    """How the film's gap moves during a release's slip, and the load's share of the film
    force it implies.

    ``trace``: dict of trace columns ``time``, ``wall_position``, ``gap``.  Returns
    ``at_release`` (the gap at the first sample: the film as the equilibration left it),
    ``by_part`` (the mean gap in each of ``parts`` equal-time parts of the slip) and
    ``dilation_force``, a pair (accelerating, decelerating branch): P·A·ΔD/Δx, the gap's
    change from the branch's start to its end (means over ``smoothing`` time units around
    each: the release's first ``smoothing``, the peak velocity, the stop) over the wall's
    travel.  A gap opened against the load P by the shear takes P·A·ΔD of work from the
    wall's travel Δx: a force the film exerts beyond its viscous one, on the branch where
    the gap opens.

    >>> t = np.arange(0, 120, 0.05)
    >>> tr = model_release(damping=12.0, dt=0.05) | {"gap": np.full(t.size, 5.9)}
    >>> g = release_gap(tr, pressure=1.0, area=94.3)
    >>> g["at_release"], [round(f, 6) for f in g["dilation_force"]]
    (5.9, [0.0, 0.0])
    """
    t, x, gap = (np.asarray(trace[k], float) for k in ("time", "wall_position", "gap"))
    y, peak, stop = _release_turns(t, x, smoothing)
    half = max(1, int(round(smoothing / 2 / float(t[1] - t[0]))))

    def around(i, lo=None):
        sl = slice(max(y, i - half) if lo is None else lo, min(t.size, i + half + 1))
        return float(gap[sl].mean()), float(x[sl].mean())

    ends = [around(y + half, lo=y), around(peak), around(stop)]
    force = tuple(pressure * area * (d1 - d0) / (x1 - x0)
                  for (d0, x0), (d1, x1) in zip(ends[:-1], ends[1:]))
    bounds = np.linspace(y, stop + 1, parts + 1).round().astype(int)
    return {"at_release": float(gap[y]),
            "by_part": [float(gap[a:b].mean()) for a, b in zip(bounds[:-1], bounds[1:])],
            "dilation_force": force}


def fit_releases(traces, *, mass: float, mount_damping: float = 0.0,
                 comoving_mass: bool = False, load_work: bool = False, **fit) -> FilmForceFit:
    """The slip law fitted to the release slips of ``traces`` (dicts of trace columns
    ``time``, ``spring_force``, ``wall_position``, ``wall_velocity``, one per release,
    uniformly sampled at one interval), each slip from :func:`release_slip`; ``fit``
    goes to :func:`~filmfriction.analysis.slip_law.slip_law.fit_film_force` (e.g.
    ``min_velocity_fraction``).  ``load_work``: take the load's work on the gap out of
    the film force (each trace's ``load_work`` column, each release's from its own start)."""
    parts, yi, si, offset, t0 = [], [], [], 0, 0.0
    names = ("spring_force", "wall_position", "wall_velocity") + (("load_work",) if load_work
                                                                   else ())
    for tr in traces:
        t = np.asarray(tr["time"], float)
        y, s = release_slip(t, tr["wall_position"])
        dt = float(t[1] - t[0])
        if load_work and "load_work" not in tr:
            raise ValueError("load_work=True: a trace has no load_work column")
        parts.append({k: np.asarray(tr[k], float)[:s + 1] for k in names}
                     | {"time": t[:s + 1] - t[0] + t0})
        yi.append(offset + y)
        si.append(offset + s)
        offset += s + 1
        t0 = parts[-1]["time"][-1] + dt
    cols = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    # each release's positions from its own origin, continued: the integral form uses Δx only
    table = cycle_table(cols["time"], cols["spring_force"], np.array(yi), np.array(si))
    return fit_film_force(cols["time"], cols["spring_force"], cols["wall_velocity"], table,
                          mass=mass, mount_damping=mount_damping,
                          wall_position=cols["wall_position"], comoving_mass=comoving_mass,
                          load_work=cols.get("load_work"), **fit)


def mean_release(traces, *, columns=("spring_force", "wall_position", "wall_velocity")) -> dict:
    """The mean trace of releases aligned at the release (each trace's first sample, its
    time from there), over the samples all of them have; ``load_work`` (each from its
    own start) is averaged too when every trace has it.

    >>> a = {"time": np.arange(4.0), "spring_force": np.ones(4), "wall_position": np.zeros(4),
    ...      "wall_velocity": np.zeros(4)}
    >>> b = a | {"time": np.arange(3.0) + 7, "spring_force": np.full(3, 3.0)}
    >>> m = mean_release([a, b])
    >>> m["time"].tolist(), m["spring_force"].tolist()
    ([0.0, 1.0, 2.0], [2.0, 2.0, 2.0])
    """
    traces = list(traces)
    if not traces:
        raise ValueError("no release traces to average")
    n = min(len(tr["time"]) for tr in traces)
    times = [np.asarray(tr["time"], float)[:n] for tr in traces]
    rel = times[0] - times[0][0]
    for j, t in enumerate(times[1:], 1):
        if not np.allclose(t - t[0], rel, rtol=1e-6, atol=1e-9 * max(1.0, rel[-1])):
            raise ValueError(f"release trace {j} is sampled at other times than trace 0: "
                             "the mean needs one sampling interval")
    names = list(columns) + (["load_work"] if all("load_work" in tr for tr in traces) else [])
    out = {"time": rel}
    for k in names:
        cols = [np.asarray(tr[k], float)[:n] for tr in traces]
        if k == "load_work":
            cols = [c - c[0] for c in cols]
        out[k] = np.mean(cols, axis=0)
    return out


def fit_release_ensemble(traces, *, mass: float, mount_damping: float = 0.0,
                         comoving_mass: bool = False, load_work: bool = False,
                         **fit) -> FilmForceFit:
    """The slip law fitted to the mean release (:func:`mean_release` of ``traces``), its
    errors from the jackknife over the releases (the fits of the R means that leave one
    release out: R − 1 degrees of freedom;
    :func:`~filmfriction.analysis.slip_law.slip_law.jackknife_fit`), the verdict by the
    same rule on those errors.  Arguments as :func:`fit_releases`; the per-slip arrays
    of the result hold the jackknife's pseudo-values, one per release.

    The releases must be replicas of one release (one wall, spring and film; the same
    sampling), which a seed series of one scene is.  ``load_work``: the mean load's
    work taken out of the mean film force.
    """
    traces = list(traces)
    if len(traces) < 3:
        raise ValueError(f"{len(traces)} release trace(s): the ensemble fit needs 3 or more")
    if load_work and not all("load_work" in tr for tr in traces):
        raise ValueError("load_work=True: a trace has no load_work column")
    mean = mean_release(traces)
    n, r = mean["time"].size, len(traces)
    keys = [k for k in mean if k != "time"]
    total = {k: mean[k] * r for k in keys}

    def one(tr):
        return fit_releases([tr], mass=mass, mount_damping=mount_damping,
                            comoving_mass=comoving_mass, load_work=load_work, **fit)

    loo = []
    for tr in traces:
        own = {k: np.asarray(tr[k], float)[:n] for k in keys}
        if "load_work" in own:
            own["load_work"] = own["load_work"] - own["load_work"][0]
        loo.append(one({"time": mean["time"]} | {k: (total[k] - own[k]) / (r - 1)
                                                  for k in keys}))
    return jackknife_fit(one(mean), loo, mass=mass)


def profile_width(layer_z, share, share_stderr=None) -> tuple[float, float]:
    """W = D + 2b and its standard error from the layers' velocity shares f(z): the
    inverse slope of a straight line through (z_k, f_k) (weighted by 1/σ² when the
    errors are given)."""
    z, f = np.asarray(layer_z, float), np.asarray(share, float)
    w = None if share_stderr is None else 1.0 / np.asarray(share_stderr, float)
    coef, cov = np.polyfit(z, f, 1, w=w, cov="unscaled" if w is not None else True)
    slope, se = float(coef[0]), float(np.sqrt(cov[0, 0]))
    return 1.0 / slope, se / slope ** 2


def couette_comoving_mass(film_mass: float, thickness: float, width: float) -> float:
    """The mass a Couette film adds to the wall's inertia: the first correction in the
    frequency to its force on a wall moving slowly, F = η·A/W·v + m_c·a.

    For a film of mass ``film_mass`` and thickness D between a still wall and the
    moving one, with a Navier slip length b at each wall (``width`` W = D + 2b),
    ρ u_t = η u_zz solved to first order in ∂/∂t gives
    m_c = (m_f/D)·(s³ − b³)/(3 W²), s = D + b: m_f/3 without slip (b = 0), more
    of the film moving with the wall as b grows.

    >>> round(couette_comoving_mass(270.0, 5.9, 5.9), 6)   # no slip: a third of the film
    90.0
    """
    if not (film_mass > 0 and thickness > 0 and width >= thickness):
        raise ValueError(f"film_mass {film_mass!r}, thickness {thickness!r}, width {width!r}: "
                         "need positive mass and thickness and width >= thickness")
    b = (width - thickness) / 2
    s = thickness + b
    return film_mass / thickness * (s ** 3 - b ** 3) / (3 * width ** 2)


def model_release(*, damping: float, comoving_mass: float = 0.0, kinetic_force: float = 0.0,
                  mass: float = 500.0, stiffness: float = 1.0, offset: float = 20.0,
                  dt: float = 0.05, duration: float = 120.0) -> dict:
    """A wall of ``mass`` let go from a spring stretched by ``offset`` and resisted by
    F_k + B·v + m_c·a while it moves forward: (M + m_c)·x'' = K(x0 − x) − B·x' − F_k,
    sampled every ``dt`` (the ``liquid-release`` scene's scale by default).  Columns
    ``time, spring_force, wall_position, wall_velocity`` (the trace a release run
    writes); only the first swing is the law's (the slip :func:`release_slip` finds)."""
    from scipy.integrate import solve_ivp

    t = np.arange(0.0, duration, dt)
    inertia = mass + comoving_mass

    def rhs(_, y):
        return [y[1], (stiffness * (offset - y[0]) - damping * y[1] - kinetic_force) / inertia]

    sol = solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-10)
    x, v = sol.y
    return {"time": t, "spring_force": stiffness * (offset - x), "wall_position": x,
            "wall_velocity": v}


def release_profile(run_dir, *, blocks: int = 4) -> dict:
    """Where the shear sits in a release run's slip (its trajectory; the slip cut into
    ``blocks``) and the profile's width W = D + 2b: the ``shear_location`` numbers
    plus ``width``, ``width_stderr``, ``area`` and ``layer_z``."""
    import json
    from pathlib import Path

    from ..structure.layering import DensityProfile
    from ..structure.trajectory_reader import open_trajectory, select_types
    from ..observables.shear_location_section import locate

    run_dir = Path(run_dir)
    tr = np.genfromtxt(run_dir / "trace.csv", delimiter=",", names=True)
    y, s = release_slip(tr["time"], tr["wall_position"])
    t0, t1 = float(tr["time"][y]), float(tr["time"][s])
    u = open_trajectory(run_dir / "topology.data", run_dir / "trajectory.dcd")
    layers = DensityProfile(select_types(u, [1])).run().results.layers
    out = locate(u, layers["edges"], [(t0, t1)], blocks=blocks)
    out["width"], out["width_stderr"] = profile_width(layers["positions"], out["share"],
                                                      out["share_stderr"])
    out["area"] = json.loads((run_dir / "run.json").read_text())["trace_parameters"]["area"]
    out["layer_z"] = [float(z) for z in layers["positions"]]
    return out
