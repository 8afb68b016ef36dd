"""Parameter sweeps: one scene fanned out over a grid, scheduled by Snakemake.

``filmfriction sweep SCENE --grid KEY=START:STOP:N[:log] ...`` plans the grid
here (every point is validated through :func:`filmfriction.workflows.md.scene.load` before
anything starts), writes it into the sweep directory, and hands the
scheduling to Snakemake (``workflows/sweep/sweep.smk``): locally on ``--cores``,
or on a Slurm cluster with ``--profile slurm``.  Nothing here schedules jobs.

A sweep directory holds::

    sweep.json                 the plan: scene, grid, fixed overrides, points
    inputs/<point>.json        resolved parameters of one point (rewritten only
                               when they change, so Snakemake re-runs only that point)
    points/<point>/            a complete run directory (run.json, trace.csv,
                               analysis.json, ...), moved into place atomically
    logs/<point>.*.log         the point's engine and analysis output
    aggregate.json, aggregate.csv, velocity_map.png, vk_map.png (when V x K)
    superseded/, failed/       old or failed run directories, never deleted
    .snakemake/                Snakemake's state (incomplete jobs, its lock)

Point names are ``key=value`` pairs of the grid joined by ``__``, e.g.
``drive_velocity=0.05__spring_constant=100``.

Safety: one sweep per directory at a time (an ``flock`` held by the command
and by Snakemake for the whole sweep, on top of Snakemake's own lock); a
point runs in a fresh hidden directory and is renamed into ``points/`` only
when the run completed, so ``points/<point>/run.json`` exists only for a
complete run; an interrupted sweep is resumed by running the same command.

The aggregate (:func:`aggregate`) reads every point's ``analysis.json`` and
trace and gives friction vs V, the regime per point, the critical velocity
with its bracket, η_eff vs γ̇ with the power-law fit, and the (V, K) map,
overlaid with the reduced model's stick-slip boundary when a calibration is
given.  :func:`load_aggregate` is what the report and the calibration read.
"""
from __future__ import annotations

from pathlib import Path

# The sweep is split by purpose; this module is the one place the rest of the
# project imports from.
from .aggregate import (IRREGULAR, SMOOTH, STICK_SLIP, STUCK, Aggregate, CriticalVelocity,
                        build_aggregate, critical_velocity, load_aggregate, reduced_model_boundary,
                        write_aggregate)
from filmfriction.analysis.stickslip import STEADY_VELOCITY_TOLERANCE

from .figures import numeric_axes, fig_velocity_map, fig_vk_map
from .jobs import (PROFILES, SNAKEFILE, analyse_point, profile_path, run_point,
                   run_sweep, snakemake_command)
from .plan import (GridAxis, SweepLock, SweepPlan, SweepPoint, format_value,
                   parse_grid, plan_sweep, write_plan)

__all__ = ["GridAxis", "SweepPoint", "SweepPlan", "CriticalVelocity", "Aggregate",
           "parse_grid", "plan_sweep", "write_plan", "SweepLock", "snakemake_command",
           "run_sweep", "run_point", "analyse_point", "critical_velocity",
           "reduced_model_boundary", "aggregate", "load_aggregate", "summary", "SNAKEFILE",
           "PROFILES", "profile_path", "format_value", "fig_velocity_map", "fig_vk_map", "numeric_axes"]


def aggregate(sweep_dir: Path, *, figures: bool = True) -> dict:
    """Combine every point of a finished sweep; write the aggregate files.

    Writes ``aggregate.json``, ``aggregate.csv``, ``velocity_map.png`` and,
    when both V and K are swept, ``vk_map.png``, each atomically.  Returns the
    ``aggregate.json`` document (see :func:`.sweep_aggregate.build_aggregate`).
    """
    from filmfriction.analysis.files.util import write_atomic

    sweep_dir = Path(sweep_dir)
    doc, rows = build_aggregate(sweep_dir)
    if figures and not numeric_axes(doc):
        doc["notes"].append("no velocity_map.png: every grid axis is a choice (e.g. "
                            "wall_model); the table compares the points")
    elif figures:
        write_atomic(sweep_dir / "velocity_map.png", fig_velocity_map(doc))
        doc["outputs"].append("velocity_map.png")
        keys = {a["key"] for a in doc["grid"]}
        if {"drive_velocity", "spring_constant"} <= keys:
            write_atomic(sweep_dir / "vk_map.png", fig_vk_map(doc))
            doc["outputs"].append("vk_map.png")
    return write_aggregate(sweep_dir, doc, rows)


def summary(agg: Aggregate) -> str:
    """A few lines for the terminal: where the files are, V_c, the power law."""
    lines = [f"sweep directory: {agg.sweep_dir}"]
    regimes = [r["sweep_regime"] for r in agg.points]
    lines.append("regimes: " + ", ".join(f"{regimes.count(r)} {r}" for r in
                                         (STICK_SLIP, IRREGULAR, SMOOTH, STUCK)
                                         if regimes.count(r)))
    if STUCK in regimes:
        lines.append(f"note: {STUCK}: < 2 slips without steady sliding (a stuck wall, one "
                     f"late slip, or a wall off V by more than {STEADY_VELOCITY_TOLERANCE:.0%}): "
                     "the run is too short to tell its regime (raise slide_steps; each "
                     "point's analysis.json has the reason)")
    for cv in agg.critical_velocity:
        group = ", ".join(f"{k}={format_value(v)}" for k, v in cv["group"].items())
        prefix = f"critical velocity{' (' + group + ')' if group else ''}: "
        if cv["status"] == "bracketed":
            lines.append(prefix + f"V_c = {cv['value']:.3g} σ/τ (×/÷ {cv['factor']:.3g}; "
                         f"between {cv['low']:.3g} and {cv['high']:.3g})"
                         + ("" if cv["monotonic"] else " [not monotonic]"))
        else:
            lines.append(prefix + cv["note"])
    law = agg.power_law
    if law:
        lines.append(f"eta_eff ∝ shear_rate^({law['exponent']:.3f} ± "
                     f"{law['exponent_stderr']:.3f}) over {law['n']} runs")
    for note in agg.doc.get("notes", []):
        lines.append(f"note: {note}")
    lines.append("files: " + ", ".join(str(agg.sweep_dir / o) for o in agg.doc["outputs"]))
    return "\n".join(lines)
