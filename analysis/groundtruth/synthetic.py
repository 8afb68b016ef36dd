"""Synthetic traces with known answers, for tests, benchmarks and examples.

* :func:`sawtooth` — linear stick ramps and instantaneous drops, plus noise;
* :func:`klein_trace` — a driven spring-block whose slips obey Klein's
  equation M x'' + B x' = K(x_d − x), integrated numerically
  (``solve_ivp``, independent of the closed form in :mod:`.viscosity`), and
  which re-sticks when the force has fallen to Fb;
* :func:`smooth_trace` — steady sliding: constant mean force plus
  correlated (AR(1)) noise;
* :func:`block_trace` — a reduced-model spring-block (any friction law) sampled
  at a uniform step, as an MD trace is;
* :func:`with_wall_noise` — an MD wall's noise added to a trace: thermal
  velocity noise on the sampled wall velocity and a correlated random force in
  the film;
* :func:`irregular_coulomb_trace` — an undamped Coulomb block whose static force
  differs from slip to slip (slips of irregular size and timing), in closed form,
  with its slips' yield and re-stick times;
* :func:`ringing_noise` — narrow-band noise, a wall ringing thermally on the film.

All return a dict of columns named as in a trace CSV.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicHermiteSpline
from scipy.signal import lfilter

from filmfriction.md_inputs.contract import AtomType, RUN_FILE, TRACE_FILE
from filmfriction.md_inputs.geometry import fcc111, plane_spacing

__all__ = ["sawtooth", "klein_trace", "smooth_trace", "block_trace", "with_wall_noise",
           "irregular_coulomb_trace", "ringing_noise", "write_csv"]


def _ar1(n: int, sigma: float, rho: float, rng) -> np.ndarray:
    e = rng.normal(0.0, sigma * np.sqrt(1 - rho ** 2), n)
    return lfilter([1.0], [1.0, -rho], e) if rho else rng.normal(0.0, sigma, n)


def sawtooth(*, static_force=3.0, backward_force=1.0, period=2.0, cycles=10,
             dt=0.005, noise=0.0, rho=0.0, seed=0, spring_constant=2.0) -> dict:
    """Force rising linearly from Fb to Fs over one period, then dropping.

    The first drop is at t = period; the trace ends half a period after the
    last drop.  ``wall_position`` jumps by (Fs − Fb)/K at each drop; the
    spring end moves at V = (Fs − Fb)/(K · period).
    """
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, (cycles + 0.5) * period, dt)
    phase = (t % period) / period
    f = backward_force + (static_force - backward_force) * phase
    k = spring_constant
    v = (static_force - backward_force) / (k * period)
    drive = backward_force / k + v * t
    wall = drive - f / k
    f = f + _ar1(t.size, noise, rho, rng)
    return {"time": t, "spring_force": f, "drive_position": drive,
            "wall_position": wall}


def klein_trace(*, spring_constant=97.0, mass=1.47e-3, damping=3.09,
                drive_velocity=100e-9, static_force=9.7e-6, backward_force=3.0e-6,
                cycles=4, dt=2e-4, noise=0.0, seed=0, ringing=0.0,
                ringing_frequency=45.0, ringing_decay=0.02, kinetic_force=0.0,
                restick_velocity=0.0) -> dict:
    """A driven spring-block with Klein-type slips, sampled every ``dt``.

    Stick: wall at rest until K(x_d − x) reaches Fs.  Slip: M x'' + B x' =
    K(x_d − x) − F_k (``kinetic_force``, 0: Klein's Eq. 1) from rest until the
    force falls to Fb or the wall slows to ``restick_velocity`` (0: comes to
    rest); the wall then stops (the film solidifies).  Defaults are Klein's SFB
    numbers (SI).  With
    ``ringing`` > 0 a decaying oscillation of that force amplitude is added
    after each re-stick (energy ringing²/(2K)).

    Returns columns ``time, spring_force, drive_position, wall_position,
    wall_velocity`` (noise only on the force).
    """
    k, m, b, v = spring_constant, mass, damping, drive_velocity
    rng = np.random.default_rng(seed)
    segments = []                # (t0, t1, kind, payload)
    t, x = 0.0, 0.0
    xd0 = backward_force / k     # start just re-stuck
    for _ in range(cycles):
        t_yield = (static_force / k - xd0 - v * t + x) / v + t
        segments.append((t, t_yield, "stick", x))
        t = t_yield

        def rhs(tt, s):
            return [s[1], (k * (xd0 + v * tt - s[0]) - b * s[1] - kinetic_force) / m]

        def stick(tt, s):
            return k * (xd0 + v * tt - s[0]) - backward_force
        stick.terminal, stick.direction = True, -1

        def rest(tt, s):            # v falls through the re-stick velocity (not v = 0 at y)
            return s[1] - restick_velocity if restick_velocity > 0 or tt > t else 1.0
        rest.terminal, rest.direction = True, -1
        horizon = 100.0 * (b / k + np.sqrt(m / k))
        sol = solve_ivp(rhs, (t, t + horizon), [x, 0.0], events=(stick, rest),
                        dense_output=True, rtol=1e-10, atol=1e-16,
                        first_step=1e-6 * horizon, max_step=1e-3 * horizon)
        t_s = float(min(e[0] for e in sol.t_events if e.size))
        segments.append((t, t_s, "slip", sol.sol))
        t, x = t_s, float(sol.sol(t_s)[0])
    t_end = t + 0.5 * (segments[-2][1] - segments[-2][0])
    segments.append((t, t_end, "stick", x))
    time = np.arange(0.0, t_end, dt)
    wall = np.empty_like(time)
    vel = np.zeros_like(time)
    extra = np.zeros_like(time)
    for t0, t1, kind, payload in segments:
        sel = (time >= t0) & (time < t1)
        if kind == "stick":
            wall[sel] = payload
            if ringing and t0 > 0:
                tau = time[sel] - t0
                extra[sel] = (ringing * np.exp(-tau / ringing_decay)
                              * np.sin(2 * np.pi * ringing_frequency * tau))
        else:
            st = payload(time[sel])
            wall[sel], vel[sel] = st[0], st[1]
    drive = xd0 + v * time
    force = k * (drive - wall) + extra + rng.normal(0.0, noise, time.size)
    return {"time": time, "spring_force": force, "drive_position": drive,
            "wall_position": wall, "wall_velocity": vel}


def smooth_trace(*, mean_force=1.0, noise=0.05, rho=0.9, n=20000, dt=0.5,
                 velocity=0.01, gap=4.0, seed=0) -> dict:
    """Steady sliding: constant force plus AR(1) noise of correlation ``rho``."""
    rng = np.random.default_rng(seed)
    t = dt * np.arange(n)
    f = mean_force + _ar1(n, noise, rho, rng)
    return {"time": t, "spring_force": f, "drive_position": velocity * t,
            "wall_velocity": velocity + _ar1(n, 0.1 * velocity, rho, rng),
            "gap": gap + _ar1(n, 0.01 * gap, rho, rng)}


def block_trace(block, duration: float, dt: float, **simulate) -> dict:
    """A :class:`~filmfriction.reduced_model.SpringBlock` run sampled every ``dt``.

    The run is integrated once at its own samples; the position and the velocity
    are carried to the grid by cubic Hermite interpolation with their exact
    derivatives (the velocity, and the acceleration from the equation of motion
    with the block's friction law; 0 while stuck).  ``simulate`` goes to
    :meth:`SpringBlock.simulate`.

    Returns columns ``time, spring_force, drive_position, wall_position,
    wall_velocity``.

    Example
    -------
    >>> from filmfriction.reduced_model import SpringBlock, laws
    >>> b = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.1,
    ...                 law=laws.Coulomb(static=1.0, kinetic=0.5))
    >>> tr = block_trace(b, 30.0, 0.5)
    >>> tr["time"][:3].tolist(), round(float(tr["spring_force"][20]), 12)   # K·V·t in the stick
    ([0.0, 0.5, 1.0], 1.0)
    """
    grid = np.arange(0.0, duration, dt)
    r = block.simulate(duration, samples_per_segment=512, **simulate)
    t, x, v = r.t, r.x, r.v
    keep = np.concatenate(([True], np.diff(t) > 0))      # an event repeats its time
    t, x, v = t[keep], x[keep], v[keep]
    state = r.state[:, keep] if r.state.size else None
    law, load = block.law, block.normal_load
    friction = np.array([float(law.friction(float(vi), state[:, i] if state is not None
                                            else (), load)) for i, vi in enumerate(v)])
    spring = r.spring_force[keep]
    accel = np.where(v == 0.0, 0.0, (spring - friction - block.damping * v) / block.mass)
    wall = CubicHermiteSpline(t, x, v)(grid)
    vel = CubicHermiteSpline(t, v, accel)(grid)
    drive = np.interp(grid, t, r.drive_position[keep])
    force = block.stiffness * (drive - wall)
    return {"time": grid, "spring_force": force, "drive_position": drive,
            "wall_position": wall, "wall_velocity": vel}


def with_wall_noise(columns: dict, *, velocity_noise, velocity_correlation=0.0,
                    rattle: float = 0.0, force_noise: float = 0.0,
                    force_correlation: float = 0.0, seed: int = 0) -> dict:
    """``columns`` with an MD wall's noise added to what is measured, not to the motion.

    * ``wall_velocity`` + AR(1) noise of rms ``velocity_noise`` and lag-one
      correlation ``velocity_correlation`` (or, sequences of both, a sum of such
      independent terms; the wall's bursts and pauses about the
      law's motion) + white noise of rms ``rattle`` (its thermal rattling);
    * ``spring_force`` + AR(1) noise of rms ``force_noise`` and lag-one correlation
      ``force_correlation`` (a random force of the film, carried as it is by the
      film force F_spring − M·a).

    The position and the motion are left as they are: the law sees the true
    velocity, a fit the noisy one.
    """
    rng = np.random.default_rng(seed)
    out = dict(columns)
    n = len(columns["time"])
    # a sum of AR(1) terms when the rms and the correlation are sequences (one each)
    u = sum(_ar1(n, float(s), float(r), rng) for s, r in
            zip(np.atleast_1d(velocity_noise), np.atleast_1d(velocity_correlation)))
    out["wall_velocity"] = (np.asarray(columns["wall_velocity"], float) + u
                            + rng.normal(0.0, rattle, n))
    out["spring_force"] = np.asarray(columns["spring_force"], float) + _ar1(
        n, force_noise, force_correlation, rng)
    return out


def irregular_coulomb_trace(static_forces, *, kinetic_force, stiffness: float,
                            mass: float, drive_velocity: float, dt: float,
                            start_force: float = 0.0, tail: float = 0.5) -> dict:
    """A driven Coulomb block (no damping) whose i-th slip starts at ``static_forces[i]``.

    The block sticks while the spring force F = K(V t − x) rises at K·V; at F_s,i it slips
    under the kinetic force F_k, and F = F_k + (F_s,i − F_k) cos ωt + (K V/ω) sin ωt
    (ω = √(K/M)) until its velocity V − F'/K is zero again, at ωt = 2(π − atan(A ω/(K V))),
    A = F_s,i − F_k: the re-stick.  ``kinetic_force`` is one F_k or one per slip (a slip
    under a lower F_k lands lower: slips that end and start again after a short stick).
    Slips of irregular size and timing, in closed form,
    sampled every ``dt`` (the samples of each slip's end are exact).  The trace ends
    ``tail`` × the last stick's length after the last re-stick.

    Returns the columns ``time, spring_force, drive_position, wall_position,
    wall_velocity`` and ``yield_time, restick_time, static_force, backward_force`` (one
    value per slip: the truth).

    Example
    -------
    >>> tr = irregular_coulomb_trace([3.0, 2.0], kinetic_force=1.0, stiffness=1.0, mass=1.0,
    ...                              drive_velocity=0.01, dt=0.01)
    >>> [round(float(b), 2) for b in tr["backward_force"]]   # about 2 F_k − F_s
    [-1.0, 0.0]
    """
    k, m, v = float(stiffness), float(mass), float(drive_velocity)
    static = np.asarray(static_forces, float)
    kinetic = np.broadcast_to(np.asarray(kinetic_force, float), static.shape)
    w = np.sqrt(k / m)
    # the piecewise solution: (start time, start force, slipping?, slip's amplitude)
    pieces, now, force = [], 0.0, float(start_force)
    yields, resticks, fs_true, fb_true = [], [], [], []
    for fs, fk in zip(static, kinetic):
        if fs <= force:
            raise ValueError(f"static force {fs} is not above the force it is loaded from, {force}")
        if fs <= fk:
            raise ValueError(f"static force {fs} is not above its kinetic force {fk}")
        stick = (fs - force) / (k * v)
        pieces.append((now, force, False, 0.0, 0.0))
        now += stick
        a = fs - fk
        duration = 2.0 * (np.pi - np.arctan(a * w / (k * v))) / w
        pieces.append((now, fs, True, a, fk))
        yields.append(now)
        now += duration
        force = fk + a * np.cos(w * duration) + k * v / w * np.sin(w * duration)
        resticks.append(now)
        fs_true.append(fs)
        fb_true.append(force)
    end = now + tail * max(yields[-1] - (resticks[-2] if len(resticks) > 1 else 0.0), 10 * dt)
    pieces.append((now, force, False, 0.0, 0.0))
    t = np.arange(0.0, end, dt)
    f = np.empty_like(t)
    vel = np.empty_like(t)
    starts = np.array([p[0] for p in pieces])
    which = np.searchsorted(starts, t, side="right") - 1
    for i, (t0, f0, slipping, a, fk) in enumerate(pieces):
        sel = which == i
        u = t[sel] - t0
        if slipping:
            f[sel] = fk + a * np.cos(w * u) + k * v / w * np.sin(w * u)
            vel[sel] = v + a * w / k * np.sin(w * u) - v * np.cos(w * u)
        else:
            f[sel] = f0 + k * v * u
            vel[sel] = 0.0
    drive = v * t + start_force / k
    wall = drive - f / k
    return {"time": t, "spring_force": f, "drive_position": drive, "wall_position": wall,
            "wall_velocity": vel, "yield_time": np.array(yields),
            "restick_time": np.array(resticks), "static_force": np.array(fs_true),
            "backward_force": np.array(fb_true)}


def ringing_noise(n: int, *, rms: float, period: float, decay: float, dt: float,
                  seed: int = 0) -> np.ndarray:
    """Narrow-band noise of standard deviation ``rms``: an oscillator of ``period`` whose
    amplitude decays in ``decay`` (both in the time unit of ``dt``), driven by white noise
    (an AR(2) process).  A wall that rings on the film's stiffness between thermal kicks
    gives its spring force this: smooth at a fine sampling, correlated over ``decay``.

    >>> x = ringing_noise(200_000, rms=2.0, period=50.0, decay=100.0, dt=0.25)
    >>> round(float(np.std(x)), 1)
    2.0
    """
    r = np.exp(-dt / float(decay))
    a1, a2 = 2.0 * r * np.cos(2.0 * np.pi * dt / float(period)), -r * r
    e = np.random.default_rng(seed).normal(0.0, 1.0, int(n) + 2000)
    x = lfilter([1.0], [1.0, -a1, -a2], e)[2000:]
    return x * (float(rms) / np.std(x))


def write_csv(path, columns: dict) -> None:
    """Write columns as a trace CSV (header line, then rows)."""
    names = list(columns)
    data = np.column_stack([np.asarray(columns[n], float) for n in names])
    np.savetxt(path, data, delimiter=",", header=",".join(names), comments="",
               fmt="%.10g")


def layered_film(directory, *, layers=3, nx=12, ny=7, spacing=1.1, wall_planes=2,
                 frames=20, thermal=0.05, melt_frames=(), nsavc=100, seed=0,
                 flexible_walls=False, timestep=0.005, plane_velocity=None):
    """Write ``topology.data`` + ``trajectory.dcd`` of a film of ``layers``
    close-packed (111) planes between two walls, for structure tests.

    The in-plane lattice is triangular (``nx`` × 2``ny`` atoms per plane,
    box ``nx·a`` × ``ny·√3·a``); planes are ``√(2/3)·a`` apart, stacked ABC.
    Each frame adds Gaussian displacements of ``thermal``; frames listed in
    ``melt_frames`` have the film's in-plane positions randomised (a
    shear-melted film keeps its layers but loses in-plane order).  Types as
    the MD script's (:class:`filmfriction.md_inputs.contract.AtomType`): 1
    film, 2 bottom wall, 3 top wall; with ``flexible_walls`` (the script's
    ``wall_model = flexible``) only each wall's outermost plane keeps type 2
    or 3, its planes facing the film are types 4 and 5 and rattle as the
    film does.  The DCD header holds ``nsavc`` and ``timestep`` as LAMMPS
    writes them (its timestep unconverted, as ``delta``).  ``plane_velocity``
    (``layers + 2`` values: the bottom wall, each
    film layer, the top wall) moves each plane along x at that velocity (σ/τ),
    positions unwrapped as the script's DCD has them: a film of known velocity
    profile.

    Returns
    -------
    (Path, Path)
        Topology and trajectory paths.
    """
    import MDAnalysis as mda
    from pathlib import Path

    directory = Path(directory)
    rng = np.random.default_rng(seed)
    n_planes = 2 * wall_planes + layers
    h = plane_spacing(spacing)
    stack = fcc111(spacing, (nx, ny), n_planes, z0=h)
    lx, ly = stack.box
    pos0 = stack.positions
    bottom, top_ = stack.plane < wall_planes, stack.plane >= wall_planes + layers
    types = np.select([bottom, top_], [AtomType.BOTTOM_WALL, AtomType.TOP_WALL], AtomType.FILM)
    if flexible_walls:
        types[bottom & (stack.plane > 0)] = AtomType.BOTTOM_FLEXIBLE
        types[top_ & (stack.plane < n_planes - 1)] = AtomType.TOP_FLEXIBLE
    n_types = int(types.max())
    n = pos0.shape[0]
    lz = (n_planes + 2) * h
    top = directory / "topology.data"
    lines = ["LAMMPS data file (filmfriction synthetic)", "", f"{n} atoms",
             f"{n_types} atom types", "", f"0 {lx} xlo xhi", f"0 {ly} ylo yhi",
             f"0 {lz} zlo zhi", "", "Masses", ""]
    lines += [f"{t} 1.0" for t in range(1, n_types + 1)] + ["", "Atoms # atomic", ""]
    lines += [f"{k + 1} {types[k]} {x:.6f} {y:.6f} {z:.6f}"
              for k, (x, y, z) in enumerate(pos0)]
    top.write_text("\n".join(lines) + "\n")
    film = types == AtomType.FILM
    mobile = film | (types == AtomType.BOTTOM_FLEXIBLE) | (types == AtomType.TOP_FLEXIBLE)
    coords = np.empty((frames, n, 3), np.float32)
    drift = np.zeros(n)
    if plane_velocity is not None:
        pv = np.asarray(plane_velocity, float)
        if pv.shape != (layers + 2,):
            raise ValueError(f"plane_velocity has {pv.size} values, needs layers + 2 = "
                             f"{layers + 2} (bottom wall, each layer, top wall)")
        drift = pv[np.clip(stack.plane - wall_planes + 1, 0, layers + 1)]
    for f in range(frames):
        pos = pos0 + rng.normal(0.0, thermal, pos0.shape) * mobile[:, None]
        pos[:, 0] += drift * f * nsavc * timestep
        if f in melt_frames:
            pos[film, :2] = rng.uniform(0, 1, (film.sum(), 2)) * [lx, ly]
        coords[f] = pos
    u = mda.Universe.empty(n, trajectory=True)
    u.dimensions = [lx, ly, lz, 90, 90, 90]
    traj = directory / "trajectory.dcd"
    # MDAnalysis writes delta = dt (ps, converted to AKMA) / nsavc: ask for the dt that
    # puts the bare timestep there, as LAMMPS does
    from MDAnalysis import units as mda_units

    dt = mda_units.convert(timestep * nsavc, "AKMA", "ps")
    with mda.Writer(str(traj), n, nsavc=nsavc, istart=0, dt=dt) as w:
        for f in range(frames):
            u.atoms.positions = coords[f]
            u.dimensions = [lx, ly, lz, 90, 90, 90]
            w.write(u.atoms)
    return top, traj


def run_directory(directory, *, layers=3, trajectory=True, dt_trace=0.5, seed=0, scale=1.0):
    """A run directory in the MD runner's format (LJ units), from a Klein-type
    spring-block trace: ``trace.csv`` with every contract column (the energy
    ledger closes exactly), ``run.json`` and, optionally, a trajectory whose
    steps match the trace's ``step`` column.  ``scale``: a contact ``scale`` times
    larger of the same film (area, spring, mass, damping and forces times ``scale``:
    the same motion, the same forces per area; the noise stays the trace's).
    Returns the directory."""
    import json
    from pathlib import Path

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    k, m, b, v = 8.0 * scale, 500.0 * scale, 40.0 * scale, 0.01
    tr = klein_trace(spring_constant=k, mass=m, damping=b, drive_velocity=v,
                     static_force=3.0 * scale, backward_force=1.0 * scale, cycles=4, dt=dt_trace,
                     noise=0.01, seed=seed)
    t = tr["time"]
    n = t.size
    f = tr["spring_force"]
    vel = tr["wall_velocity"]
    from scipy.integrate import cumulative_trapezoid
    drive_work = cumulative_trapezoid(f * v, t, initial=0.0)
    spring = f ** 2 / (2 * k)
    kinetic = 0.5 * m * vel ** 2
    heat = drive_work - (spring - spring[0]) - (kinetic - kinetic[0])
    gap = 1.0 + layers * 0.9
    step = np.round(t / 0.005).astype(int)
    cols = {"time": t, "step": step, "drive_position": tr["drive_position"],
            "spring_force": f, "wall_position": tr["wall_position"],
            "wall_velocity": vel, "wall_z": np.full(n, 10.0), "gap": np.full(n, gap),
            "film_temperature": np.full(n, 0.7), "drive_work": drive_work,
            "load_work": np.zeros(n), "thermostat_heat": heat,
            "potential_energy": np.full(n, -100.0), "kinetic_energy": kinetic,
            "spring_energy": spring}
    write_csv(directory / TRACE_FILE, cols)
    area = 12 * 1.1 * 7 * np.sqrt(3) * 1.1 * scale
    # run.json as the runner writes it: the film's thickness comes from the gap column
    run = {"status": "done",
           "scene": {"name": "synthetic", "parameters": {"film_layers": layers,
                                                         "normal_pressure": 1.0}},
           "trace_parameters": {"spring_constant": k, "mass": m, "area": area,
                                "thickness": None, "drive_velocity": v, "units": "lj"}}
    (directory / RUN_FILE).write_text(json.dumps(run, indent=2))
    if trajectory:
        frames = 60
        nsavc = int(step[-1] // (frames - 1))
        layered_film(directory, layers=layers, frames=frames, nsavc=nsavc, seed=seed)
    return directory
