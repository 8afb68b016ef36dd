"""``shear_location``: where the shear sits during the slips — at a wall–film plane or inside.

From the run's trajectory (MDAnalysis, unwrapped positions as the script writes them),
each film atom is assigned to a layer by z (the layers of
:class:`~filmfriction.analysis.structure.layering.DensityProfile`, as the ``structure``
section has them) and each layer's mean x-velocity is the mean displacement of its
atoms between consecutive frames over the frames' interval; the walls' velocities
likewise.  Only frame pairs inside a slip (yield → re-stick) count.  Each layer's
velocity as a share of the wall's slip velocity,

    f_k = (v_k − v_bottom) / (v_top − v_bottom),

is taken per slip from the slip's mean velocities, then averaged over the slips
(standard error: their scatter; with fewer than 3 slips, over blocks of consecutive
frame pairs, which is optimistic when a block is shorter than the film's velocity
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

import numpy as np

from filmfriction.md_inputs.contract import BOTTOM_WALL_TYPES, FILM_TYPES, TOP_WALL_TYPES

from .observable import Context, Observable, format_value

__all__ = ["ShearLocation", "layer_velocities", "shear_shares", "MIN_SLIPS_FOR_SCATTER"]

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
    """:func:`layer_velocities` in the slip windows, the shares per slip (with fewer than
    :data:`MIN_SLIPS_FOR_SCATTER` slips, per block: each slip's frame pairs cut into
    ``blocks`` consecutive blocks), and :func:`shear_shares`.  A sample's share is the
    ratio of its mean velocities, (⟨v_k⟩ − ⟨v_bottom⟩)/(⟨v_top⟩ − ⟨v_bottom⟩): a ratio
    of frame-pair velocities would blow up where the wall has nearly stopped."""
    lv = layer_velocities(universe, edges, windows, **types)
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
        rows.append((np.nanmean(lv["layer"][g], axis=0) - b) / (w - b) if w != b
                    else np.full(lv["layer"].shape[1], np.nan))
    nl = lv["layer"].shape[1]
    out = shear_shares(np.asarray(rows, float).reshape(-1, nl))
    slip_v = lv["top"] - lv["bottom"]
    out.update({"samples": unit, "frame_pairs": int(lv["slip"].size),
                "slips": int(slips.size),
                "wall_slip_velocity": float(np.mean(slip_v)) if slip_v.size else None})
    return out


class ShearLocation(Observable):
    """The share of the wall's slip taken up at each wall–film plane and inside the film."""

    key = "shear_location"
    title = "Where the shear sits during the slips"
    order = 55
    absent = "No shear location (needs a trajectory: a scene with the `structure` output)"

    def applies(self, ctx: Context) -> bool:
        return ctx.trajectory_analyses and ctx.trace.run_dir is not None

    def compute(self, ctx: Context) -> tuple[dict | None, dict]:
        from ..structure.trajectory_reader import film_layers
        from .structure_section import TOPOLOGY, TRAJECTORY

        trace = ctx.trace
        traj, topo = trace.optional_path(TRAJECTORY), trace.optional_path(TOPOLOGY)
        table = ctx.all_slips
        if not (traj and topo) or table is None or not len(table):
            ctx.skip_part(self.key, f"no {TRAJECTORY} + {TOPOLOGY} or no slips")
            return None, {}
        try:
            u, _, profile = film_layers(topo, traj, FILM_TYPES)
            layers = profile.results.layers
            if not layers["count"]:
                raise ValueError("no film layers found")
            windows = list(zip(np.asarray(table.yield_time, float),
                               np.asarray(table.stick_time, float)))
            out = locate(u, layers["edges"], windows)
        except (ValueError, OSError) as exc:
            ctx.skip_part(self.key, f"{traj}: {exc}")
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
        rows.append(("samples", f"{section.get('n')} ({section.get('samples')}s; "
                                f"{section.get('frame_pairs')} frame pairs in "
                                f"{section.get('slips')} slips)"))
        return rows
