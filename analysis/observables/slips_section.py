"""``slips``: the stick-slip cycles in Klein's notation, and the trace with its events.

The detection and the cycle table are :mod:`filmfriction.analysis.stickslip`
(the analysis runs them once, before every section: the regime needs them);
this file writes their summary into ``analysis.json["slips"]`` (Fs, Fb, x0,
Δx0, τ_s, the stick duration and τ_ss, mean ± stderr over the analysed slips)
and every cycle-table column into ``analysis_cycles.csv`` (unprefixed:
``yield_index``, ``static_force`` ...), and shows in the report the regime, the
force trace with the y and s points (and the gap under it) and the table.
"""
from __future__ import annotations

import numpy as np

from ..trace_figure import scaled_unit
from ..files.trace import MissingInput, unit
from .observable import Context, Observable, entry, format_estimate, png_bytes, pyplot, shade_slips

__all__ = ["Slips", "SLIP_QUANTITIES"]

#: the per-slip summaries of ``analysis.json["slips"]`` and the quantity of each
SLIP_QUANTITIES = {"static_force": "force", "backward_force": "force",
                   "spring_extension": "length", "slip_distance": "length",
                   "slip_duration": "time", "stick_duration": "time", "period": "time"}
#: the rows of the report's table
_ROWS = ("static_force", "backward_force", "slip_distance", "slip_duration", "stick_duration",
         "period")


def force_label(units: str) -> str:
    """What the spring force of a trace is called on an axis: an MD run's
    spring, or a measured one's (SI)."""
    return "MD spring force" if units == "lj" else "spring force"


class Slips(Observable):
    """Fs, Fb, x0, Δx0, τ_s, stick duration and τ_ss over the analysed slips."""

    key = "slips"
    title = "Stick-slip trace"
    order = 10
    per_slip = "all"
    column_prefix = ""
    table_header = ("per cycle (mean ± stderr)", "value")

    def compute(self, ctx: Context) -> tuple[dict, dict]:
        trace, table = ctx.trace, ctx.all_slips
        summary = table.summary(skip=ctx.skip)
        section = {"count": len(table), "summary_skips_first": ctx.skip}
        for name, quantity in SLIP_QUANTITIES.items():
            section[name] = entry(summary[name], ctx.unit(quantity))
        if not trace.parameters.spring_constant:
            ctx.skip_part("slips.spring_extension",
                          MissingInput("--spring-constant", "x0 = Fs/K"))
            if trace.wall_position() is None:
                ctx.skip_part("slips.slip_distance",
                              "missing column 'wall_position' (or 'drive_position' with "
                              "--spring-constant) or --spring-constant")
        return section, table.as_dict()

    def lead(self, run) -> list[str]:
        out = []
        warnings = (run.trace.run or {}).get("warnings") or []
        if warnings:
            out.append("**The run completed with warnings** (physics checks): "
                       + "; ".join(map(str, warnings))
                       + ". Read the numbers below with them in mind.")
        doc = run.analysis
        s = doc.get(self.key, {})
        out.append(f"Regime: **{doc.get('regime', '?')}** ({doc.get('regime_criterion', '')}). "
                   f"{s.get('count', 0)} slips detected; summaries "
                   f"{'leave out the start-up yield' if s.get('summary_skips_first') else 'use all slips'}.")
        return out

    def rows(self, section: dict) -> list[tuple[str, str]]:
        return [(name.replace("_", " "), format_estimate(section.get(name))) for name in _ROWS
                if section.get(name)]

    def figures(self, run) -> list[tuple[str, bytes, str]]:
        return [("trace", fig_trace(run),
                 f"The {force_label(run.trace.units)} with the detected yield (y, ▼) "
                 "and re-stick (s, ▲) points, the slips shaded"
                 + ("; lower panel: the gap between the walls' inner planes."
                    if run.trace.has("gap") else "."))]


def fig_trace(run) -> bytes:
    """Spring force (and gap) against time with the detected y and s points."""
    plt = pyplot()
    tr = run.trace
    lab = lambda q: unit(tr.units, q)  # noqa: E731
    t, f = tr.time, tr.spring_force
    rows = 2 if tr.has("gap") else 1
    fig, axes = plt.subplots(rows, 1, figsize=(9, 4.2 if rows == 2 else 3), sharex=True,
                             gridspec_kw={"height_ratios": [3, 1][:rows]}, squeeze=False)
    ax = axes[0, 0]
    # an SI prefix chosen for the numbers (µN, nm), never an axis offset (the time axis
    # stays in the trace's unit: the slips' shading is drawn on it)
    ff, lf = scaled_unit(f, tr.units, "force")
    f = f * ff
    ax.plot(t, f, lw=0.9, color="0.2", label=force_label(tr.units))
    yi = np.asarray(run.cycles.get("yield_index", []), int)
    si = np.asarray(run.cycles.get("stick_index", []), int)
    if len(yi):
        ax.plot(t[yi], f[yi], "v", color="tab:red", ms=6, label="y (yield)")
        ax.plot(t[si], f[si], "^", color="tab:green", ms=6, label="s (re-stick)")
    ax.set_ylabel(f"spring force [{lf}]")
    if rows == 2:
        fg, lg = scaled_unit(tr.columns["gap"], tr.units, "length")
        axes[1, 0].plot(t, tr.columns["gap"] * fg, lw=0.7, color="tab:blue", label="gap")
        axes[1, 0].set_ylabel(f"gap [{lg}]")
    for a in axes[:, 0]:
        shade_slips(a, run, label=a is ax)
    # the legend above the axes, right-aligned: never over the trace (nor the offset text)
    ax.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=8, ncol=4, frameon=False)
    axes[-1, 0].set_xlabel(f"time [{lab('time')}]")
    fig.align_ylabels(axes[:, 0])
    return png_bytes(fig)
