"""Sweep figures: friction vs V with η_eff vs γ̇, and the (V, K) regime map.

Part of :mod:`filmfriction.workflows.sweep`.
"""
from __future__ import annotations

import numpy as np

from filmfriction.analysis.files.util import png_bytes, pyplot

from .aggregate import (IRREGULAR, SMOOTH, STICK_SLIP, STUCK, eta_points, group_key,
                        majority_regime)
from .plan import format_value


# ---------------------------------------------------------------------------
# figures
# ---------------------------------------------------------------------------
REGIME_MARKER = {STICK_SLIP: "o", SMOOTH: "s", IRREGULAR: "^", STUCK: "x"}
REGIME_COLOUR = {STICK_SLIP: "tab:red", SMOOTH: "tab:blue", IRREGULAR: "tab:orange",
                 STUCK: "0.6"}


_plt = pyplot
_png = png_bytes


def _err(x):
    return 0.0 if x is None else x


def numeric_axes(doc: dict) -> list[str]:
    """Grid keys with numbers for values (a choice such as wall_model cannot be an x axis)."""
    return [a["key"] for a in doc["grid"]
            if all(isinstance(v, (int, float)) for v in a["values"])]


def _plain_log_axis(axis) -> None:
    """Log axis labelled 0.01, 0.1, 1 rather than 10^-2; the minor ticks are labelled too
    when the axis spans about a decade or less (else it may have no label at all), and
    left bare over wider ranges, where they would crowd."""
    from matplotlib.ticker import FuncFormatter, LogFormatter

    plain = FuncFormatter(lambda x, _: f"{x:g}")
    minor = LogFormatter(labelOnlyBase=False, minor_thresholds=(1, 0.4))

    def minor_label(x, pos=None):
        # LogFormatter decides which minor ticks to label (all, a few, none) by the range
        return plain(x) if minor(x, pos) else ""
    axis.set_major_formatter(plain)
    axis.set_minor_formatter(FuncFormatter(minor_label))
    minor.set_axis(axis)


def _group_label(group: dict) -> str:
    return ", ".join(f"{k}={format_value(v)}" for k, v in group.items())


def fig_velocity_map(doc: dict) -> bytes:
    """Friction vs V (static force filled, mean spring force open; marker = regime, colour =
    group of the other swept keys; V_c bracket shaded) above η_eff vs γ̇ with the power law."""
    plt = _plt()
    rows = doc["points"]
    keys = [a["key"] for a in doc["grid"]]
    xkey = "drive_velocity" if "drive_velocity" in keys else numeric_axes(doc)[0]
    group_keys = [k for k in keys if k not in (xkey, "seed")]
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    groups: dict = {}
    for r in rows:
        groups.setdefault(group_key(r, group_keys), []).append(r)
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7, 9))
    handles = []
    for i, (g, members) in enumerate(groups.items()):
        colour = colours[i % len(colours)]
        members = sorted(members, key=lambda r: r[f"grid.{xkey}"])
        for r in members:
            marker = REGIME_MARKER.get(r["sweep_regime"], "x")
            x = r[f"grid.{xkey}"]
            if r["static_force"] is not None:
                ax.errorbar(x, r["static_force"], yerr=_err(r["static_force_stderr"]),
                            color=colour, marker=marker, ms=7, capsize=3, ls="none")
            if r["mean_force"] is not None:
                ax.errorbar(x, r["mean_force"], yerr=_err(r["mean_force_stderr"]), color=colour,
                            marker=marker, mfc="white", ms=7, capsize=3, ls="none")
        # a guide to the eye through the mean over repeats (seeds) at each x
        by_x: dict = {}
        for r in members:
            if r["mean_force"] is not None:
                by_x.setdefault(r[f"grid.{xkey}"], []).append(r["mean_force"])
        ax.plot(list(by_x), [np.mean(v) for v in by_x.values()], color=colour, lw=0.8,
                alpha=0.6)
        if group_keys:
            handles.append(plt.Line2D([], [], color=colour, lw=2,
                                      label=_group_label(dict(zip(group_keys, g)))))
    crit = [cv for cv in doc.get("critical_velocity", []) if cv["status"] == "bracketed"]
    for i, cv in enumerate(crit):
        gi = list(groups).index(tuple(cv["group"][k] for k in group_keys)) if group_keys else 0
        colour = colours[gi % len(colours)]
        ax.axvspan(cv["low"], cv["high"], color=colour, alpha=0.12, zorder=0)
        ax.axvline(cv["value"], color=colour, ls="--", lw=1)
        ax.text(0.99, 0.97 - 0.06 * i,
                f"$V_c$ = {cv['value']:.3g} ×/÷ {cv['factor']:.2g} σ/τ"
                + (f" ({_group_label(cv['group'])})" if cv["group"] else ""),
                transform=ax.transAxes, ha="right", va="top", fontsize=8, color=colour)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.08 * (1 + len(crit)) * (hi - lo))     # room for the V_c lines
    xs = [r[f"grid.{xkey}"] for r in rows]
    if min(xs) > 0 and max(xs) / min(xs) > 5:
        ax.set_xscale("log")
        _plain_log_axis(ax.xaxis)
    handles += [plt.Line2D([], [], color="k", marker=m, ls="none", label=reg)
                for reg, m in REGIME_MARKER.items()]
    handles += [plt.Line2D([], [], color="k", marker="o", ls="none", label="static force $F_s$"),
                plt.Line2D([], [], color="k", marker="o", mfc="white", ls="none",
                           label="mean spring force (last half)")]
    ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12),
              ncol=3, frameon=False)
    unit = {"drive_velocity": " (σ/τ)"}.get(xkey, "")
    ax.set_xlabel(f"{xkey}{unit}")
    ax.set_ylabel("friction force (ε/σ)")
    ax.set_title(f"{doc['scene']}: friction vs {xkey} ({len(rows)} runs, ± standard error; "
                 "shaded: stick-slip → smooth)", fontsize=9)
    pts = eta_points(rows)
    for r in pts:
        steady = r["eta_source"] == "steady"
        bx.errorbar(r["shear_rate"], r["eta_eff"], yerr=_err(r["eta_eff_stderr"]),
                    color="k" if steady else "tab:purple",
                    marker=REGIME_MARKER.get(r["sweep_regime"], "x"), mfc="white", capsize=3,
                    ls="none")
    law = doc.get("power_law")
    if law:
        fitted = [r for r in pts if r["eta_source"] == "steady"] \
            if law["points"].endswith("only") else pts
        g = np.geomspace(min(r["shear_rate"] for r in fitted),
                         max(r["shear_rate"] for r in fitted), 50)
        bx.plot(g, law["prefactor"] * g ** law["exponent"], "k-", lw=1,
                label=f"η_eff ∝ γ̇^({law['exponent']:.2f} ± {law['exponent_stderr']:.2f}), "
                      f"{law['n']} runs ({law['points']})")
    if any(r["eta_source"] != "steady" for r in pts):
        bx.plot([], [], "o", color="tab:purple", mfc="white", label="from the slip fits")
    if pts:
        bx.legend(fontsize=8)
    if pts:
        bx.set_xscale("log")
        bx.set_yscale("log")
        _plain_log_axis(bx.xaxis)
        _plain_log_axis(bx.yaxis)
    else:
        bx.text(0.5, 0.5, "no η_eff in these runs", transform=bx.transAxes, ha="center")
    bx.set_xlabel("shear rate γ̇ (1/τ): V/D when smooth, slip velocity/D when stick-slip")
    bx.set_ylabel("η_eff (ετ/σ³)")
    fig.tight_layout()
    return _png(fig)


def fig_vk_map(doc: dict) -> bytes:
    """The (V, K) plane: regime per point (majority over other keys), MD's V_c per K,
    and the reduced model's boundary when calibrated."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.5, 5.5))
    cells: dict = {}
    for r in doc["points"]:
        cells.setdefault((r["drive_velocity"], r["spring_constant"]), []).append(
            r["sweep_regime"])
    for (v, k), regs in cells.items():
        regime = majority_regime(regs) if STUCK not in regs else STUCK
        ax.plot(v, k, marker=REGIME_MARKER.get(regime, "x"), color=REGIME_COLOUR.get(regime),
                ms=10, ls="none")
    for cv in doc.get("critical_velocity", []):
        k = cv["group"].get("spring_constant")
        if cv["status"] == "bracketed" and k is not None:
            ax.errorbar(cv["value"], k, xerr=[[cv["value"] - cv["low"]],
                                              [cv["high"] - cv["value"]]],
                        color="k", marker="|", ms=14, capsize=4, ls="none")
    handles = [plt.Line2D([], [], color=REGIME_COLOUR[reg], marker=m, ls="none", label=reg)
               for reg, m in REGIME_MARKER.items()]
    handles.append(plt.Line2D([], [], color="k", marker="|", ls="none",
                              label="MD $V_c$ (bracket)"))
    b = doc.get("reduced_model_boundary")
    if b:
        ax.plot(b["velocity"], b["stiffness"], "k--", lw=1.2)
        handles.append(plt.Line2D([], [], color="k", ls="--",
                                  label="calibrated reduced model: stick-slip left of it"))
    ax.legend(handles=handles, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.13),
              ncol=3, frameon=False)
    ax.set_xscale("log")
    ax.set_yscale("log")
    _plain_log_axis(ax.xaxis)
    _plain_log_axis(ax.yaxis)
    ks = sorted({k for _, k in cells})
    if len(ks) <= 12:
        ax.set_yticks(ks)         # label every swept K
    ax.set_xlabel("drive velocity V (σ/τ)")
    ax.set_ylabel("spring constant K (ε/σ²)")
    title = f"{doc['scene']}: regime map"
    if not b:
        title += " (no calibration given: no reduced-model boundary)"
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    return _png(fig)


