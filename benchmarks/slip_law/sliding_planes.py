"""Where MD runs' films slide during their slips, plane by plane, grouped by the slider's mass.

    python benchmarks/slip_law/sliding_planes.py RUN… [--window 2] [--psi6] [--hop-force]

Each RUN is an analysed run directory with a trajectory (``dump_every`` set: its
``trajectory.dcd`` and ``topology.data``, its ``analysis_cycles.csv``).  The film's layers
come from its density profile; each frame's layer positions along the slide and the walls'
(:class:`~filmfriction.analysis.structure.slip_planes.LayerDisplacement`) give each plane's
share of the wall's slide, and the plane carrying most of it at each frame
(:func:`~filmfriction.analysis.structure.slip_planes.active_plane`, velocities over
``--window`` τ).  Per analysed slip, from the frame at its yield to the frame after its
re-stick: each plane's share of the slip's distance (the planes numbered from the bottom
wall | first layer, 0, to the last layer | top wall); the largest share (1: the slip is one
plane's); the accelerating and decelerating parts apart (split at the peak of the top wall's
velocity smoothed over five windows) and whether their largest shares sit on different
planes; and the changes of the active plane while the wall moves faster than a fifth of its
peak (a change counted once the new plane has held for a window).  Printed per slider mass M
(the runs' ``source.parameters.mass``): runs, slips, their median duration and distance, the
planes' shares averaged over the slips, the mean largest share (its standard error over the
slips), the share of slips whose two parts slide on different planes, and the changes per
slip and per σ slid, and the median distance the wall slides between two changes (one plane
sliding; λ = 1.1 σ is the walls' registry period along the slide).  ``--psi6``: besides, each layer's in-plane order ψ6
(:class:`~filmfriction.analysis.structure.hexatic.HexaticOrder`) averaged over the 20 frames
before each slip and over its accelerating and decelerating parts, per mass its lowest and
highest layer (a film that shear-melts in its slips loses it there).  ``--hop-force``: the
film's force on the wall (its equation of motion, the force and the wall's motion smoothed
over the window) at the changes of plane, per mass
(:func:`~filmfriction.analysis.structure.plane_hops.hop_force`: the bump within 0.1 σ of a
change less its level 0.3–0.55 σ away, after a smooth law and the walls' registry fitted on
all slipping samples; its error by the bootstrap over the slips; the same at uniformly drawn
positions and at the changes moved by whole registry periods).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
from scipy.signal import savgol_filter

from filmfriction.analysis.slip_law.slip_law import film_force
from filmfriction.analysis.structure.plane_hops import hop_force, plane_changes
from filmfriction.analysis.structure.slip_planes import LayerDisplacement, active_plane
from filmfriction.analysis.structure.trajectory_reader import (film_layers, frame_steps,
                                                               select_types)
from filmfriction.md_inputs.contract import BOTTOM_WALL_TYPES, FILM_TYPES, TOP_WALL_TYPES


def run_planes(run: Path, window: float, psi6: bool = False, force: bool = False) -> dict:
    """One run's slips: each one's plane shares (whole, accelerating, decelerating part),
    its active-plane changes, duration and distance, and its slipping samples for the force
    at the changes (with ``force``: wall position, film force and velocity smoothed over the
    window, the changes' wall positions); the run's mass and registry period."""
    analysis = json.loads((run / "analysis.json").read_text())
    params = json.loads((run / "run.json").read_text())["trace_parameters"] if force else {}
    u, film, prof = film_layers(run / "topology.data", run / "trajectory.dcd", FILM_TYPES,
                                step=10)
    disp = LayerDisplacement(film, select_types(u, BOTTOM_WALL_TYPES),
                             select_types(u, TOP_WALL_TYPES),
                             prof.results.layers["edges"]).run()
    order = None
    if psi6:
        from filmfriction.analysis.structure.hexatic import HexaticOrder
        order = HexaticOrder(film, prof.results.layers["edges"]).run().results.psi6
    walls = disp.results.wall_x
    x = np.column_stack([walls[:, 0], disp.results.layer_x, walls[:, 1]])
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{run}: a layer is empty in some frame (the film left its layers)")
    steps = frame_steps(u)
    trace = np.genfromtxt(run / "trace.csv", delimiter=",", names=True)
    cycles = np.genfromtxt(run / "analysis_cycles.csv", delimiter=",", names=True)
    if steps is None or steps.size < 3:
        raise ValueError(f"{run}: the trajectory carries no frame steps, or fewer than 3")
    dt = float(np.interp(steps[1], trace["step"], trace["time"])
               - np.interp(steps[0], trace["step"], trace["time"]))
    plane, _ = active_plane(x, dt, window)
    w = max(3, int(round(window / dt)) | 1)
    t = trace["time"]
    wt = max(5, int(round(window / (t[1] - t[0]))) | 1)     # the window in trace samples
    if force:
        xw = trace["wall_position"]
        vw = savgol_filter(xw, wt, 2, deriv=1, delta=t[1] - t[0])
        fw = film_force(t, savgol_filter(trace["spring_force"], wt, 2), vw,
                        mass=params["mass"], drive_velocity=params["drive_velocity"],
                        mount_damping=params.get("mount_damping") or 0.0)
    slow = savgol_filter(walls[:, 1], min(5 * w | 1, x.shape[0] - (1 - x.shape[0] % 2)), 2,
                         deriv=1, delta=dt)
    out = []
    for y, s in zip(np.atleast_1d(cycles["yield_index"]).astype(int),
                    np.atleast_1d(cycles["stick_index"]).astype(int)):
        a = int(np.searchsorted(steps, trace["step"][y]))
        b = int(np.searchsorted(steps, trace["step"][s])) + 1
        if b >= x.shape[0] or b - a < 4:
            continue
        k = a + int(np.argmax(slow[a:b]))
        parts = {}
        for name, (i, j) in (("whole", (a, b)), ("accelerating", (a, k)),
                             ("decelerating", (k, b))):
            dx = np.diff(x[j] - x[i])
            parts[name] = dx / dx.sum() if j > i and dx.sum() > 0 else None
        if order is not None:
            for name, (i, j) in (("before", (max(0, a - 20), a)), ("acc_psi6", (a, k + 1)),
                                 ("dec_psi6", (k, b + 1))):
                parts[name] = order[i:j].mean(axis=0) if j > i else None
        moving = a + np.flatnonzero(slow[a:b] > 0.2 * slow[a:b].max())
        hops = moving[plane_changes(plane[moving], w)] if moving.size else np.array([], int)
        k_in = np.arange(y + wt // 2, s - wt // 2)
        samples = (xw[k_in], fw[k_in], vw[k_in], np.interp(steps[hops], trace["step"], xw)) \
            if force and k_in.size >= 5 else None
        out.append({**parts, "changes": len(hops), "force": samples,
                    "between": np.diff(x[hops, -1]).tolist(),
                    "distance": float(x[b, -1] - x[a, -1]), "duration": float((b - a) * dt)})
    return {"mass": float(analysis["source"]["parameters"]["mass"]), "slips": out,
            "registry_period": params.get("registry_period")}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", type=Path, metavar="RUN")
    ap.add_argument("--window", type=float, default=2.0,
                    help="the window of the planes' velocities (τ)")
    ap.add_argument("--psi6", action="store_true", help="each layer's ψ6 before and in the slips")
    ap.add_argument("--hop-force", action="store_true",
                    help="the film force's bump at the changes of plane, against nulls")
    args = ap.parse_args(argv)
    if not (math.isfinite(args.window) and args.window > 0):
        ap.error(f"--window {args.window!r}: > 0, finite (τ)")
    missing = [str(r) for r in args.runs if not all(
        (r / f).is_file() for f in ("analysis.json", "analysis_cycles.csv", "trace.csv",
                                    "trajectory.dcd", "topology.data"))]
    if missing:
        ap.error("RUN without an analysis, a trace or a trajectory (run with dump_every "
                 f"set): {', '.join(missing)}")
    by_mass, period = defaultdict(list), {}
    try:
        for run in args.runs:
            r = run_planes(run, args.window, args.psi6, args.hop_force)
            by_mass[r["mass"]].append(r["slips"])
            period[r["mass"]] = r["registry_period"]
    except ValueError as exc:
        print(f"sliding_planes: {exc}", file=sys.stderr)
        return 1
    print("| M (m) | runs | slips | median slip (τ; σ) | planes' shares of the slip, bottom wall "
          "→ top wall | largest share | two parts on different planes | active-plane changes "
          "per slip; per σ | slide between changes: median (quartiles) σ |\n"
          "|---|---|---|---|---|---|---|---|---|")
    for mass in sorted(by_mass):
        slips = [s for run in by_mass[mass] for s in run]
        if not slips:
            continue
        share = np.array([s["whole"] for s in slips])
        top = share.max(axis=1)
        both = [s for s in slips if s["accelerating"] is not None
                and s["decelerating"] is not None]
        differ = sum(int(np.argmax(s["accelerating"]) != np.argmax(s["decelerating"]))
                     for s in both)
        ch = np.array([s["changes"] for s in slips], float)
        dist = np.array([s["distance"] for s in slips])
        between = np.array([d for s in slips for d in s["between"]])
        print(f"| {mass:g} | {len(by_mass[mass])} | {len(slips)} | "
              f"{np.median([s['duration'] for s in slips]):.0f}; {np.median(dist):.2f} | "
              f"{' '.join(f'{q:.2f}' for q in share.mean(axis=0))} | {top.mean():.2f} ± "
              f"{top.std(ddof=1) / math.sqrt(top.size) if top.size > 1 else math.nan:.2f} | "
              f"{differ} of {len(both)} | {ch.mean():.2f}; {ch.sum() / dist.sum():.2f} | "
              + (f"{np.median(between):.2f} ({np.percentile(between, 25):.2f}–"
                 f"{np.percentile(between, 75):.2f})" if between.size else "–") + " |")
    if args.psi6:
        print("\n| M (m) | ψ6 before the slips: lowest, highest layer | accelerating part | "
              "decelerating part |\n|---|---|---|---|")
        for mass in sorted(by_mass):
            slips = [s for run in by_mass[mass] for s in run]
            cells = []
            for key in ("before", "acc_psi6", "dec_psi6"):
                q = np.array([s[key] for s in slips if s.get(key) is not None])
                cells.append(f"{q.mean(axis=0).min():.3f}, {q.mean(axis=0).max():.3f}"
                             if q.size else "–")
            print(f"| {mass:g} | " + " | ".join(cells) + " |")
    if args.hop_force:
        print("\n| M (m) | slips, changes | bump at the changes (ε/σ) | random positions: mean "
              "(sd); share ≥ | phase-matched positions: mean (sd); share ≥ |\n|---|---|---|---|---|")
        for mass in sorted(by_mass):
            slips = [s["force"] for run in by_mass[mass] for s in run if s["force"] is not None]
            if len(slips) < 2 or not any(len(s[3]) for s in slips):
                print(f"| {mass:g} | {len(slips)}, {sum(len(s[3]) for s in slips)} | – | – | – |")
                continue
            h = hop_force(slips, registry_period=period[mass])
            nulls = [f"{n.mean:+.2f} ({n.sd:.2f}); {n.share_at_or_above:.3f}" if n else "–"
                     for n in (h.random, h.phase_matched)]
            print(f"| {mass:g} | {h.slips}, {h.changes} | {h.bump:+.2f} ± {h.stderr:.2f} | "
                  + " | ".join(nulls) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
