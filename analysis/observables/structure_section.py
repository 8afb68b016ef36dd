"""``structure``: the film's layers, hexatic order and gap, from the run's trajectory.

The analyses are :mod:`filmfriction.analysis.structure` (MDAnalysis); this file
runs them on a run directory's ``trajectory.dcd`` and ``topology.data`` (when
the trajectory analyses are asked for), writes ``analysis.json["structure"]``
(layers, ψ6 per layer, the gap, and stick against slip), and shows in the
report the density across the gap and a side view of the film.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from filmfriction.md_inputs.contract import BOTTOM_WALL_TYPES, FILM_TYPES, TOP_WALL_TYPES

from ..files.trace import unit
from .observable import Context, Observable, format_value, png_bytes, pyplot, shade_slips
from ..film_state import FRAMES_NOT_CUT

__all__ = ["Structure", "summarize_run", "universe", "fig_film"]

TRAJECTORY, TOPOLOGY = "trajectory.dcd", "topology.data"


def universe(run_dir: Path):
    """The MDAnalysis Universe of a run directory's trajectory, with times in τ."""
    from ..structure.trajectory_reader import open_trajectory

    return open_trajectory(run_dir / TOPOLOGY, run_dir / TRAJECTORY)


def summarize_run(topology, trajectory, *, trace=None, table=None, units="lj",
                  film_types=FILM_TYPES, bottom_types=BOTTOM_WALL_TYPES,
                  top_types=TOP_WALL_TYPES, step: int = 1) -> dict:
    """Structure section of ``analysis.json`` for one run.

    Layers from the mean density profile; ψ6 per layer and the gap per
    frame; with a trace that has a ``step`` column and a slip table, frames
    are split into stick and slip (t(y) <= t <= t(s)) and the means of ψ6
    and gap are reported for each.  The film and each wall are the atoms of
    the given types (default: the script's contract, either wall model).
    """
    from ..structure.hexatic import HexaticOrder
    from ..structure.layering import FilmThickness
    from ..structure.trajectory_reader import film_layers, frame_steps, select_types

    u, film, prof = film_layers(topology, trajectory, film_types, step)
    layers = prof.results.layers
    out = {"frames": int(prof.n_frames), "units": units,
           "layers": {"count": layers["count"],
                      "positions": layers["positions"].tolist(),
                      "spacing": {"mean": layers["spacing"], "std": layers["spacing_std"]}}}
    hex_ = HexaticOrder(film, layers["edges"]).run(step=step) if layers["count"] else None
    bottom = select_types(u, bottom_types)
    top = select_types(u, top_types)
    gap = FilmThickness(bottom, top).run(step=step) if bottom.n_atoms and top.n_atoms else None
    if hex_ is not None:
        out["psi6"] = {"per_layer_mean": np.nanmean(hex_.results.psi6, axis=0).tolist()}
    if gap is not None:
        out["gap"] = {"mean": float(np.mean(gap.results.gap)),
                      "std": float(np.std(gap.results.gap))}
    steps = frame_steps(u)
    if (trace is not None and table is not None and len(table) and steps is not None
            and trace.has("step")):
        frames = np.arange(u.trajectory.n_frames)[slice(None, None, step)]
        t_frame = np.interp(steps[frames], trace.columns["step"], trace.time)
        slipping = np.zeros(frames.size, bool)
        for ty, ts in zip(table.yield_time, table.stick_time):
            slipping |= (t_frame >= ty) & (t_frame <= ts)
        for name, mask in (("stick", ~slipping), ("slip", slipping)):
            sec = {"frames": int(mask.sum())}
            if mask.any() and hex_ is not None:
                sec["psi6_per_layer"] = np.nanmean(hex_.results.psi6[mask], axis=0).tolist()
            if mask.any() and gap is not None:
                sec["gap"] = float(np.mean(gap.results.gap[mask]))
            out[name] = sec
    return out


class Structure(Observable):
    """Layers, ψ6 per layer and the gap, over the frames and at stick and slip."""

    key = "structure"
    title = "The film: density profile and picture"
    order = 50
    absent = "No film structure (the `film-structure` scene writes a trajectory)"

    def applies(self, ctx: Context) -> bool:
        return ctx.trajectory_analyses and ctx.trace.run_dir is not None

    def compute(self, ctx: Context) -> tuple[dict | None, dict]:
        trace = ctx.trace
        traj = trace.optional_path(TRAJECTORY)
        topo = trace.optional_path(TOPOLOGY)
        if not (traj and topo):
            ctx.skip_part(self.key, f"no {TRAJECTORY} + {TOPOLOGY} in the run directory")
            return None, {}
        if ctx.sections.get("film_state_change"):
            ctx.skip_part(self.key, FRAMES_NOT_CUT.format(what="its trajectory's"))
            return None, {}
        try:
            return summarize_run(topo, traj, trace=trace, table=ctx.all_slips,
                                           units=ctx.units), {}
        except (ValueError, OSError) as exc:
            ctx.skip_part(self.key, f"{traj}: {exc}")
            return None, {}

    # -- the report ----------------------------------------------------------
    def rows(self, section: dict) -> list[tuple[str, str]]:
        length = unit(section.get("units", "lj"), "length")
        lay = section.get("layers", {})
        rows = [("film layers", str(lay.get("count"))),
                ("layer spacing", f"{format_value((lay.get('spacing') or {}).get('mean'), 3)} "
                                  f"{length}")]
        if section.get("gap"):
            gap = section["gap"]
            # a gap that does not change (a rigid wall's) has no spread to print
            rows.append(("gap between the walls' inner planes",
                         f"{format_value(gap['mean'], 4)} ± {format_value(gap['std'], 2)} "
                         f"{length} (mean ± std)" if gap.get("std") else
                         f"{format_value(gap['mean'], 4)} {length} (the same in every frame)"))
        per_layer = (section.get("psi6") or {}).get("per_layer_mean")
        if per_layer:
            rows.append(("ψ6 per layer, all frames (bottom → top)", _layers(per_layer)))
        for phase in ("stick", "slip"):
            part = section.get(phase) or {}
            if part.get("psi6_per_layer"):
                rows.append((f"ψ6 per layer at {phase} ({part['frames']} frames)",
                             _layers(part["psi6_per_layer"])))
            if part.get("gap") is not None:
                rows.append((f"gap at {phase}", f"{format_value(part['gap'], 4)} {length}"))
        return rows

    def notes(self, section: dict) -> list[str]:
        lay = section.get("layers", {})
        length = unit(section.get("units", "lj"), "length")
        return [f"Structure analysis: {lay.get('count')} layers, spacing "
                f"{format_value((lay.get('spacing') or {}).get('mean'), 3)} {length} over "
                f"{section.get('frames')} frames."]

    def figures(self, run) -> list[tuple[str, bytes, str]]:
        out = []
        png, note = fig_film(run.run_dir)
        if png is not None:
            out.append(("film", png, note + "."))
        frames = film_frames(run)
        if frames is None:
            return out
        out.append(("structure-time", fig_structure_time(run, frames),
                    "The spring force with the detected yield (y, ▼) and re-stick (s, ▲) points, "
                    "and under it, on the same time axis, the hexatic order |ψ6| of each film "
                    "layer (one point per trajectory frame) and the gap between the walls' "
                    "inner planes; shaded: the slips (y → s)."))
        png, caption = fig_layers_top(run, frames)
        if png is not None:
            out.append(("layers-top", png, caption))
        return out


def slip_windows(run) -> list[tuple[float, float]]:
    """(t at y, t at s) of every detected slip of a run (its ``analysis_cycles.csv``)."""
    t = run.trace.time
    yi = np.asarray(run.cycles.get("yield_index", []), int)
    si = np.asarray(run.cycles.get("stick_index", []), int)
    return [(float(t[y]), float(t[s])) for y, s in zip(yi, si)]


def film_frames(run) -> dict | None:
    """The trajectory's frames on the trace's time axis, with the film's layers
    and their ψ6 per frame (:class:`~filmfriction.analysis.structure.layering.DensityProfile`,
    :class:`~filmfriction.analysis.structure.hexatic.HexaticOrder`); None without a
    trajectory, a ``step`` column or layers."""
    from filmfriction.md_inputs.contract import FILM_TYPES

    from ..structure.hexatic import HexaticOrder
    from ..structure.layering import DensityProfile
    from ..structure.trajectory_reader import frame_steps

    tr = run.trace
    if not ((run.run_dir / TRAJECTORY).exists() and (run.run_dir / TOPOLOGY).exists()
            and tr.has("step")):
        return None
    u = universe(run.run_dir)
    steps = frame_steps(u)
    film = u.select_atoms("type " + " ".join(str(int(t)) for t in FILM_TYPES))
    if steps is None or film.n_atoms == 0:
        return None
    layers = DensityProfile(film).run().results.layers
    if not layers["count"]:
        return None
    psi6 = HexaticOrder(film, layers["edges"]).run().results.psi6
    time = np.interp(steps, tr.columns["step"], tr.time)
    return {"universe": u, "film": film, "time": time, "psi6": psi6,
            "edges": np.asarray(layers["edges"], float)}


def fig_structure_time(run, frames: dict) -> bytes:
    """Force, ψ6 per layer and gap against time, aligned, the slips shaded."""
    plt = pyplot()
    tr = run.trace
    lab = lambda q: unit(tr.units, q)  # noqa: E731
    fig, axes = plt.subplots(3, 1, figsize=(10, 6.8), sharex=True,
                             gridspec_kw={"height_ratios": [2, 1.4, 1]})
    t, f = tr.time, tr.spring_force
    ax = axes[0]
    ax.plot(t, f, lw=0.8, color="0.2", label="spring force")
    yi = np.asarray(run.cycles.get("yield_index", []), int)
    si = np.asarray(run.cycles.get("stick_index", []), int)
    if yi.size:
        ax.plot(t[yi], f[yi], "v", color="tab:red", ms=6, label="y (yield)")
        ax.plot(t[si], f[si], "^", color="tab:green", ms=6, label="s (re-stick)")
    ax.set_ylabel(f"spring force [{lab('force')}]")
    ax = axes[1]
    psi6 = frames["psi6"]
    colours = pyplot().get_cmap("viridis")
    n = psi6.shape[1]
    for i in range(n):
        ax.plot(frames["time"], psi6[:, i], ".-", lw=0.7, ms=4,
                color=colours(i / max(n - 1, 1)), label=f"layer {i + 1}" + (
                    " (bottom)" if i == 0 else " (top)" if i == n - 1 else ""))
    ax.set_ylabel("hexatic order |ψ6| [1]")
    ax.set_ylim(0.0, 1.05)
    ax = axes[2]
    if tr.has("gap"):
        ax.plot(t, tr.columns["gap"], lw=0.7, color="tab:blue", label="gap (trace)")
    else:
        from filmfriction.md_inputs.contract import BOTTOM_WALL_TYPES, TOP_WALL_TYPES

        from ..structure.layering import FilmThickness

        u = frames["universe"]
        pick = lambda types: u.select_atoms(  # noqa: E731
            "type " + " ".join(str(int(x)) for x in types))
        gap = FilmThickness(pick(BOTTOM_WALL_TYPES), pick(TOP_WALL_TYPES)).run()
        ax.plot(frames["time"], gap.results.gap, ".-", lw=0.7, color="tab:blue",
                label="gap (trajectory)")
    ax.set_ylabel(f"gap [{lab('length')}]")
    ax.set_xlabel(f"time [{lab('time')}]")
    for ax in axes:
        shade_slips(ax, run)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    fig.align_ylabels(axes)
    return png_bytes(fig)


def _stick_and_slip_frames(run, frames: dict) -> tuple[int | None, int | None]:
    """A frame deep in a stick (the one between two slips farthest from every slip) and
    one in a slip (the one nearest the middle of a slip), as indices into ``frames["time"]``."""
    windows = slip_windows(run)
    tf = frames["time"]
    if not windows:
        return (int(tf.size // 2) if tf.size else None), None
    inside = np.zeros(tf.size, bool)
    for ty, ts in windows:
        inside |= (tf >= ty) & (tf <= ts)
    mids = np.array([0.5 * (ty + ts) for ty, ts in windows])
    edges = np.array([x for w in windows for x in w])
    stick = None
    # a stick between two slips (not the start-up loading), else any frame out of the slips
    between = ~inside & (tf >= windows[0][1]) & (tf <= windows[-1][0])
    candidates = between if between.any() else ~inside
    if candidates.any():
        distance = np.min(np.abs(tf[:, None] - edges[None, :]), axis=1)
        distance[~candidates] = -1.0
        stick = int(np.argmax(distance))
    slip = None
    if inside.any():
        distance = np.min(np.abs(tf[:, None] - mids[None, :]), axis=1)
        distance[~inside] = np.inf
        slip = int(np.argmin(distance))
    return stick, slip


def fig_layers_top(run, frames: dict) -> tuple[bytes | None, str]:
    """Top views (x, y) of each film layer at a frame in a stick and one in a slip."""
    stick, slip = _stick_and_slip_frames(run, frames)
    columns = [(name, i) for name, i in (("stick", stick), ("slip", slip)) if i is not None]
    if not columns:
        return None, ""
    plt = pyplot()
    lab = unit(run.trace.units, "length")
    tu = unit(run.trace.units, "time")
    u, film, edges = frames["universe"], frames["film"], frames["edges"]
    n = edges.size - 1
    box = u.dimensions[:2].astype(float)
    fig, axes = plt.subplots(n, len(columns), figsize=(3.3 * len(columns) + 0.6, 3.0 * n),
                             squeeze=False, sharex=True, sharey=True)
    for c, (name, i) in enumerate(columns):
        u.trajectory[int(i)]
        pos = film.positions
        layer = np.searchsorted(edges, pos[:, 2]) - 1
        xy = np.mod(pos[:, :2], box)
        for row in range(n):
            ax = axes[n - 1 - row, c]           # the top layer on top
            sel = xy[layer == row]
            ax.scatter(sel[:, 0], sel[:, 1], s=22, color="tab:orange", edgecolor="k", lw=0.3)
            ax.set_xlim(0, box[0])
            ax.set_ylim(0, box[1])
            ax.set_aspect("equal")
            psi = frames["psi6"][int(i), row]
            ax.set_title(f"layer {row + 1}, {name} (t = {frames['time'][int(i)]:.4g} {tu}): "
                         f"|ψ6| = {psi:.2f}", fontsize=8)
            if row == 0:
                ax.set_xlabel(f"x [{lab}] (sliding)")
            if c == 0:
                ax.set_ylabel(f"y [{lab}]")
    fig.tight_layout()
    caption = ("Top views of each film layer (bottom layer at the bottom; atoms assigned to "
               "layers by height, the periodic box shown) at a trajectory frame deep in a stick"
               + (" and at one inside a slip" if slip is not None else
                  "; no trajectory frame falls inside a slip (frames are further apart than "
                  "the slips last)") + ".")
    return png_bytes(fig), caption


def _layers(values) -> str:
    return " / ".join(format_value(v, 3) for v in values)


def fig_film(run_dir: Path) -> tuple[bytes | None, str]:
    """Density across the gap (the profile file, else the trajectory) and a side
    view of the film's last frame; (None, "") without either."""
    from filmfriction.md_inputs import contract

    from .viscosity_section import DENSITY_PROFILE, averaged_profile

    plt = pyplot()
    run_dir = Path(run_dir)
    has_traj = (run_dir / TRAJECTORY).exists() and (run_dir / TOPOLOGY).exists()
    prof = run_dir / DENSITY_PROFILE
    if not has_traj and not prof.exists():
        return None, ""
    ncols = 2 if has_traj else 1
    fig, axes = plt.subplots(1, ncols, figsize=(10 if has_traj else 5, 3.8), squeeze=False)
    note = []
    u = universe(run_dir) if has_traj else None
    ax = axes[0, 0]
    if prof.exists():
        z, rho, col = averaged_profile(prof, ("density",), "ncount")
        src = f"{DENSITY_PROFILE} ({col}, last half of the run)"
        ax.set_xlabel("number density [σ⁻³]" if col.startswith("density") else
                      "atoms per bin [1]")
    else:
        film = u.select_atoms(f"type {int(contract.AtomType.FILM)}")
        zs = np.concatenate([film.positions[:, 2].copy()
                             for _ in u.trajectory[len(u.trajectory) // 2:]])
        hist, edges = np.histogram(zs, bins=max(20, int(np.ptp(zs) / 0.05)))
        z, rho = 0.5 * (edges[1:] + edges[:-1]), hist / hist.max()
        src = "film atoms' z over the last half of the trajectory (normalised)"
        ax.set_xlabel("number density (normalised) [1]")
    ax.plot(rho, z, color="tab:blue")
    ax.set_ylabel("z [σ]")
    ax.set_title("density across the gap", fontsize=9)
    note.append(f"density from {src}")
    if has_traj:
        u.trajectory[-1]
        ax2 = axes[0, 1]
        lx = float(u.dimensions[0])
        for typ, c in ATOM_COLOURS.items():
            g = u.select_atoms(f"type {int(typ)}")
            if g.n_atoms:
                # the trajectory is unwrapped (for the analyses); the picture
                # shows the periodic box
                x = np.mod(g.positions[:, 0], lx) if lx > 0 else g.positions[:, 0]
                ax2.scatter(x, g.positions[:, 2], s=9, color=c, label=contract.ATOM_TYPES[typ])
        ax.set_ylim(ax2.get_ylim())
        ax2.set_aspect("equal")
        ax2.set_xlabel("x [σ] (sliding direction)")
        ax2.set_ylabel("z [σ]")
        ax2.set_title(f"side view, last frame ({len(u.trajectory)} frames)", fontsize=9)
        ax2.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
        note.append("side view: atoms of the last trajectory frame, coloured by type")
    return png_bytes(fig), "; ".join(note)


def _atom_colours() -> dict:
    from filmfriction.md_inputs import contract

    # every atom type of the contract (flexible walls have two per wall)
    return {contract.AtomType.FILM: "tab:orange", contract.AtomType.BOTTOM_WALL: "0.45",
            contract.AtomType.TOP_WALL: "0.65", contract.AtomType.BOTTOM_FLEXIBLE: "tab:green",
            contract.AtomType.TOP_FLEXIBLE: "tab:olive"}


#: the colour of each atom type of the contract in the pictures of the film
ATOM_COLOURS = _atom_colours()
