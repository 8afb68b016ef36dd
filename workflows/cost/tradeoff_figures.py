"""The trade study's figures: error against cost per observable, the Pareto front
labelled (``pareto_*.png``)."""
from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from filmfriction.analysis.files.util import write_atomic

from .tradeoff_reduced import REDUCED_KNOB
from .tradeoff_table import OBSERVABLES


def pareto_front(cost, error) -> np.ndarray:
    """Indices of the points no other point beats in both cost and |error|, by cost."""
    cost, error = np.asarray(cost, float), np.abs(np.asarray(error, float))
    ok = np.flatnonzero(np.isfinite(cost) & np.isfinite(error))
    order = ok[np.lexsort((error[ok], cost[ok]))]
    front, best = [], math.inf
    for i in order:
        if error[i] < best:
            front.append(i)
            best = error[i]
    return np.array(front, dtype=int)


#: where a point's label may go, in points from the point (tried in this order)
LABEL_OFFSETS = ((4, 3), (4, -9), (-4, 3), (-4, -9), (6, -3), (-6, -3), (0, 6), (0, -12),
                 (10, 8), (10, -14), (-10, 8), (-10, -14), (14, -3), (-14, -3))


def place_labels(ax, labels) -> list:
    """Annotate each (text, x, y) next to its point where it covers no other label, no
    marker and stays inside the axes: the first free offset of :data:`LABEL_OFFSETS`,
    else the one that overlaps least.  Returns the annotations."""
    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    to_display = ax.transData.transform
    frame = ax.get_window_extent(renderer)
    pad = 3.5 * fig.dpi / 72.0                                  # a marker's radius, in pixels
    markers = [to_display((x, y)) for _, x, y in labels]
    placed, out = [], []
    for text, x, y in labels:
        best = None
        for dx, dy in LABEL_OFFSETS:
            ann = ax.annotate(text, (x, y), fontsize=7, xytext=(dx, dy), textcoords="offset points",
                              ha="left" if dx >= 0 else "right")
            box = ann.get_window_extent(renderer)
            cost = sum(_area(box, other) for other in placed)
            cost += sum(_area(box, (mx - pad, my - pad, mx + pad, my + pad)) for mx, my in markers)
            cost += box.width * box.height - _area(box, frame)    # the part outside the axes
            if best is None or cost < best[0]:
                if best is not None:
                    best[1].remove()
                best = (cost, ann, box)
            else:
                ann.remove()
            if cost == 0.0:
                break
        placed.append(best[2])
        out.append(best[1])
    return out


def _area(box, other) -> float:
    """Area of the intersection of a display-space bbox with a bbox or (x0, y0, x1, y1)."""
    x0, y0, x1, y1 = other.extents if hasattr(other, "extents") else other
    w = min(box.x1, x1) - max(box.x0, x0)
    h = min(box.y1, y1) - max(box.y0, y0)
    return w * h if w > 0 and h > 0 else 0.0


def plot(rows: list[dict], out: Path) -> list[Path]:
    """One cost–error PNG per observable: the MD settings, and beside them on their own
    cost axis the reduced model's integrators (milliseconds against the MD's seconds)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, MaxNLocator

    paths = []
    knobs = sorted({r["knob"] for r in rows})
    colors = dict(zip(knobs, plt.cm.tab10.colors))
    for name, unit in OBSERVABLES.items():
        # references are the zero of their knob's errors: shown, not part of the front
        pts = [r for r in rows if not r["reference"]
               and r.get(f"error_{name}") is not None and math.isfinite(r[f"error_{name}"])]
        reduced = any(r["knob"] == REDUCED_KNOB for r in pts)
        fig, axes = plt.subplots(1, 2 if reduced else 1, figsize=(9, 4.5) if reduced else (7.5, 4.5),
                                 sharey=True, squeeze=False,
                                 gridspec_kw={"width_ratios": [3, 1]} if reduced else None)
        ax, ax_reduced = axes[0, 0], (axes[0, 1] if reduced else None)
        labels = []
        for knob in knobs:
            sel = [r for r in pts if r["knob"] == knob]
            if not sel:
                continue
            x = [r["cost_seconds"] for r in sel]
            y = [abs(r[f"error_{name}"]) for r in sel]
            e = [r[f"error_{name}_uncertainty"] for r in sel]
            known = [v is not None and math.isfinite(v) for v in e]
            e = [v if k else 0.0 for v, k in zip(e, known)]
            target = ax_reduced if knob == REDUCED_KNOB else ax
            if knob == REDUCED_KNOB:
                x = [1e3 * xi for xi in x]                   # milliseconds
            target.errorbar(x, y, yerr=e, fmt="o", color=colors[knob], label=knob, capsize=3)
            # hollow: no uncertainty (a single cycle), so no measured error
            target.scatter([xi for xi, k in zip(x, known) if not k],
                           [yi for yi, k in zip(y, known) if not k], s=60, color="white",
                           edgecolors=colors[knob], zorder=3)
            if knob != REDUCED_KNOB:      # the integrators sit on one spot; the table names them
                labels += [(r["value"], xi, yi) for xi, yi, r in zip(x, y, sel)]
        # the front is over the MD settings with a measured error: the reduced model
        # answers another question (the spring-block ODE) and would dominate any MD
        # setting trivially
        md = [r for r in pts if r["knob"] != REDUCED_KNOB
              and r.get(f"error_{name}_uncertainty") is not None
              and math.isfinite(r[f"error_{name}_uncertainty"])]
        if md:
            idx = pareto_front([r["cost_seconds"] for r in md],
                               [r[f"error_{name}"] for r in md])
            if idx.size:
                ax.step([md[i]["cost_seconds"] for i in idx],
                        [abs(md[i][f"error_{name}"]) for i in idx], where="post",
                        color="k", lw=1, alpha=0.6, label="Pareto front (MD)")
        ax.set_xscale("log")
        # plain numbers at 1, 2, 3, 5 x 10^k: the MD costs span about one decade
        plain = FuncFormatter(lambda v, _: f"{v:g}" if f"{v:.0e}"[0] in "1235" else "")
        ax.xaxis.set_major_formatter(plain)
        ax.xaxis.set_minor_formatter(plain)
        ax.set_ylim(bottom=0.0)
        ax.set_xlabel("cost: wall seconds of the MD run (--np ranks)")
        ax.set_ylabel(f"|error of {name}| [{unit}]")
        if reduced:
            ax_reduced.set_xlim(left=0.0)
            ax_reduced.xaxis.set_major_locator(MaxNLocator(4))
            ax_reduced.set_xlabel("cost: ms, reduced model (1 core)")
        fig.suptitle(f"{name}: error against each knob's reference (bars: 1 s.e.)", fontsize=11)
        handles = [h for a in axes[0] for h in zip(*a.get_legend_handles_labels())]
        if handles:
            # beside the axes: inside, it would sit on points or their labels
            axes[0, -1].legend(*zip(*handles), fontsize=7, loc="upper left",
                               bbox_to_anchor=(1.03, 1.0), borderaxespad=0.0)
        fig.tight_layout()
        place_labels(ax, labels)
        path = out / f"pareto_{name}.png"
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110)
        plt.close(fig)
        write_atomic(path, buf.getvalue())
        paths.append(path)
    return paths
