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

from ..trace import unit
from .base import Context, Observable, format_value, png_bytes, pyplot

__all__ = ["Structure", "universe", "fig_film"]

TRAJECTORY, TOPOLOGY = "trajectory.dcd", "topology.data"


def universe(run_dir: Path):
    """The MDAnalysis Universe of a run directory's trajectory."""
    import warnings

    import MDAnalysis as mda

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return mda.Universe(str(run_dir / TOPOLOGY), str(run_dir / TRAJECTORY),
                            format="DCD", topology_format="DATA", atom_style="id type x y z")


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
        from .. import structure

        try:
            return structure.summarize_run(topo, traj, trace=trace, table=ctx.all_slips,
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
            rows.append(("gap between the walls' inner planes",
                         f"{format_value(section['gap']['mean'], 4)} ± "
                         f"{format_value(section['gap']['std'], 2)} {length} (mean ± std)"))
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
        png, note = fig_film(run.run_dir)
        return [] if png is None else [("film", png, note + ".")]


def _layers(values) -> str:
    return " / ".join(format_value(v, 3) for v in values)


def fig_film(run_dir: Path) -> tuple[bytes | None, str]:
    """Density across the gap (the profile file, else the trajectory) and a side
    view of the film's last frame; (None, "") without either."""
    from filmfriction.md_inputs import contract

    from .viscosity import DENSITY_PROFILE, averaged_profile

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
        ax2.legend(fontsize=7, loc="upper right")
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
