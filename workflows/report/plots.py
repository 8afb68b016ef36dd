"""The report's own figures (PNG bytes) of what the study wrote: λ-ζ, viscosity,
the replay and its errors, the SFB table."""
from __future__ import annotations

import math

import numpy as np

from filmfriction.analysis.files.trace import unit as _unit
from filmfriction.analysis.trace_figure import scaled_unit
from filmfriction.analysis.files.util import png_bytes as _png, pyplot as _plt

from ..rundir import reference
from .document import fixed_decimals, trace_source


# ---------------------------------------------------------------------------
# figures
# ---------------------------------------------------------------------------
def fig_lambda_zeta(points: list) -> bytes:
    """Nakano–Maegawa's plane: (ζ, λ) of each contact with ±1 σ bars and the boundary λ_c(ζ)."""
    from filmfriction.reduced_model.maps import critical_lambda

    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    zz = np.geomspace(1e-3, 0.999, 200)
    ax.plot(zz, critical_lambda(zz), color="k", lw=1.2, label="λ_c(ζ): stick-slip above (Coulomb)")
    ax.axvline(1.0, color="k", ls=":", lw=1.0, label="ζ = 1: none for a viscous law")
    markers = iter("o^sDvP*X")
    for label, zeta, zeta_err, lam, lam_err in points:
        if not (math.isfinite(zeta) and math.isfinite(lam)) or zeta <= 0 or lam <= 0:
            continue
        ax.errorbar([zeta], [lam], xerr=[[min(zeta_err, 0.999 * zeta)], [zeta_err]]
                    if math.isfinite(zeta_err) else None,
                    yerr=[[min(lam_err, 0.999 * lam)], [lam_err]] if math.isfinite(lam_err) else None,
                    fmt=next(markers, "o"), ms=7, capsize=3, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("damping ratio ζ = (B + γM)/(2√(KM)) [1]")
    ax.set_ylabel("λ = (F_s − F_k)/(V√(KM)) [1]")
    # beside the axes: the contacts' points may fall anywhere in the plane
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, frameon=False)
    return _png(fig)


def fig_viscosity(cal: dict) -> bytes:
    """η_eff against γ̇, one point per run, with the rate law (a ``calibration.json`` document)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    pts = np.array(cal["rate_points"], float).reshape(-1, 3)
    err = np.where(np.isfinite(pts[:, 2]), pts[:, 2], 0.0)
    units = cal.get("units", "lj")
    ax.errorbar(pts[:, 0], pts[:, 1], yerr=err, fmt="o", color="tab:blue", capsize=3,
                label=f"{trace_source(units)} runs")
    law = cal.get("rate_law")
    if law is not None:
        # the fitted law as written, drawn over the runs' range (rendering, not fitting)
        g = np.geomspace(pts[:, 0].min() / 2, pts[:, 0].max() * 2, 50)
        ax.plot(g, law["prefactor"] * g ** law["exponent"], "-", color="tab:red",
                label=f"η ∝ γ̇^({law['exponent']:.2f} ± {fixed_decimals(law['exponent_stderr'], 2)})")
    if len(pts) > 1:
        ax.set_xscale("log")
        ax.set_yscale("log")
    else:
        # one run: no law to draw; a log-log plane of one point says nothing more
        ax.set_title("one shear rate only: a sweep of drive velocities gives η_eff(γ̇)",
                     fontsize=8, color="0.3")
    ax.set_xlabel(f"shear rate γ̇ [{_unit(units, 'shear_rate')}]")
    ax.set_ylabel(f"η_eff [{_unit(units, 'viscosity')}]")
    ax.legend(fontsize=8)
    return _png(fig)


def fig_replay(run, trace: dict, start_time: float) -> bytes:
    """The run's spring force and the calibrated model's (``trace``: ``t``, ``spring_force``),
    labelled in the units of the analysis."""
    plt = _plt()
    tr = run.trace
    units = run.analysis.get("units", tr.units)
    fig, ax = plt.subplots(figsize=(9, 3.2))
    # SI prefixes chosen for the numbers (µN, ms ...), never an axis offset
    ft, lt = scaled_unit(tr.time, units, "time")
    ff, lf = scaled_unit(tr.spring_force, units, "force")
    ax.plot(tr.time * ft, tr.spring_force * ff, lw=0.9, color="0.3", label=trace_source(units))
    ax.plot(np.asarray(trace["t"]) * ft, np.asarray(trace["spring_force"]) * ff, lw=1.2,
            color="tab:red", alpha=0.85, label="calibrated model")
    ax.axvline(start_time * ft, color="tab:red", lw=0.6, ls=":")
    ax.set_xlabel(f"time [{lt}]")
    ax.set_ylabel(f"spring force [{lf}]")
    # above the axes, right-aligned: never over the traces (nor the offset text)
    ax.legend(fontsize=8, loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=2, frameon=False)
    return _png(fig)


def fig_replay_errors(errors: dict, source: str = "MD") -> bytes:
    """The model's relative error on the peak force, slip distance and period, with the
    ``source``'s (MD or measured) own standard error."""
    plt = _plt()
    names = ["peak_force", "slip_distance", "period"]
    vals = [errors[n]["rel_error"] for n in names]
    md_rel = [errors[n]["md_stderr"] / abs(errors[n]["md"])
              if errors[n]["md"] and math.isfinite(errors[n]["md_stderr"] or math.nan) else 0.0
              for n in names]
    fig, ax = plt.subplots(figsize=(5.5, 2.8))
    v = np.array([x if x is not None and math.isfinite(x) else 0.0 for x in vals]) * 100
    ticks = [n.replace("_", " ") for n in names]
    ax.bar(ticks, v, color=["tab:blue", "tab:orange", "tab:green"])
    ax.errorbar(ticks, np.zeros(3), yerr=np.array(md_rel) * 100, fmt="none", ecolor="k",
                capsize=4, label=f"± {source} standard error")
    bars = np.array(md_rel) * 100
    for i, x in enumerate(vals):
        # beyond the bar and the error bar drawn about zero, never over either
        span = max(float(np.max(np.abs(v))), float(np.max(bars)), 1.0)
        end = (max(v[i], bars[i]) + 0.03 * span if v[i] >= 0
               else min(v[i], -bars[i]) - 0.03 * span)
        ax.text(i, end, "n/a" if x is None or not math.isfinite(x) else f"{x:+.0%}",
                ha="center", va="bottom" if v[i] >= 0 else "top", fontsize=9)
    # room for the numbers over (under) the bars
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo - 0.12 * (hi - lo) * (v.min() < 0), hi + 0.12 * (hi - lo))
    ax.axhline(0, color="k", lw=0.6)
    ax.set_ylabel(f"(model − {source}) / {source} [%]")
    ax.legend(fontsize=7, loc="lower right", bbox_to_anchor=(1.0, 1.0), frameon=False)
    return _png(fig)


def sfb_reference(check) -> dict:
    """Whose numbers the SFB check sets the model beside: Klein's, or a measured slip on
    one's own set-up (``sfb.json`` with ``setup`` and ``measured``, ``sfb --setup``)."""
    measured = check.doc.get("measured")
    if not measured:
        return {"column": "Klein", "whose": "Klein's", "title": "Klein, OMCTS",
                "curve": "Klein's parameters (η_eff = 27 Pa·s)", "calibrated": "MD-calibrated"}
    name = (check.doc.get("setup") or {}).get("name") or "your set-up"
    eta = measured.get("eta_eff")
    return {"column": "measured", "whose": "the measured value", "title": name,
            "curve": "the set-up's parameters" + (f" (η_eff = {eta:.3g} Pa·s)" if eta else ""),
            "calibrated": "calibrated"}


def measured_slips(run) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each analysed slip of a measured (SI) trace as (time since y, wall displacement
    since y), from y to its re-stick s; [] for an MD run or without a wall position."""
    tr = run.trace
    if run.analysis.get("units", tr.units) != "si":
        return []
    x = tr.wall_position()
    yi = np.asarray(run.cycles.get("yield_index", []), int)
    si = np.asarray(run.cycles.get("stick_index", []), int)
    if x is None or yi.size == 0 or si.size != yi.size:
        return []
    out = []
    for a, b in list(zip(yi, si))[run.skip:]:
        if b > a:
            out.append((tr.time[a:b + 1] - tr.time[a], x[a:b + 1] - x[a]))
    return out


def sfb_curves(check, *, carried_over: bool = True) -> list[tuple[str, np.ndarray, np.ndarray, bool]]:
    """The SFB figure's model curves: (label, t [s], x [m], whether s was reached), each cut
    at its s, or, where s was not reached, at the figure's time window (1.5 × the longest
    slip time reached): a curve never runs beyond what the table says. ``carried_over``
    False leaves the calibrated film out (a law carried too many decades: appendix)."""
    ref = sfb_reference(check)
    labels = {"klein": ref["curve"], "setup": ref["curve"], "bulk": "bulk viscosity", "md": f"{ref['calibrated']} film"}
    if not carried_over:
        labels.pop("md")
    ends = [r.slip_time for k, r in check.slips.items()
            if k in labels and r.t is not None and math.isfinite(r.slip_time)]
    window = 1.5 * max(ends) if ends else None
    out = []
    for key, run in check.slips.items():
        if key not in labels or run.t is None:
            continue
        t, x = np.asarray(run.t, float), np.asarray(run.x, float)
        reached = math.isfinite(run.slip_time)
        end = run.slip_time if reached else (window if window is not None else t[-1])
        keep = t <= end
        out.append((labels[key] + ("" if reached else " (s not reached)"), t[keep], x[keep],
                    reached))
    return out


def fig_sfb(check, measured=(), *, carried_over: bool = True, axes_out: list | None = None
            ) -> bytes:
    """The SFB-scale slips of the reduced model on linear axes with SI prefixes, each up
    to its s (●), the measured slips (``measured``: (t, x) pairs, SI) in grey beneath, and
    the legend beside the axes.  ``axes_out`` receives the Axes (for the layout's test)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8.2, 3.6))
    curves = sfb_curves(check, carried_over=carried_over)
    t_all = [c[1] for c in curves] + [m[0] for m in measured]
    x_all = [c[2] for c in curves] + [m[1] for m in measured]
    ft, lt = scaled_unit(np.concatenate(t_all) if t_all else [1.0], "si", "time")
    fx, lx = scaled_unit(np.concatenate(x_all) if x_all else [1.0], "si", "length")
    for i, (t, x) in enumerate(measured):
        ax.plot(t * ft, x * fx, color="0.55", lw=0.9, alpha=0.8,
                label="measured slips (y → s)" if i == 0 else None)
    for label, t, x, reached in curves:
        (line,) = ax.plot(t * ft, x * fx, lw=1.6, label=label, ls="-" if reached else "--")
        if reached:
            ax.plot(t[-1] * ft, x[-1] * fx, "o", color=line.get_color(), ms=5, mec="k")
    ref = sfb_reference(check)
    try:
        row = check.row("slip_time")
        tau, dx = reference(row), check.doc.get("geometry", {}).get("slip_distance")
    except KeyError:
        tau = dx = None
    if tau and dx and not measured:
        ax.plot(tau * ft, dx * fx, "*", color="k", ms=11,
                label=f"{ref['whose']} τ_s and Δx0")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.set_xlabel(f"time since yield [{lt}]")
    ax.set_ylabel(f"slip x(t) [{lx}]")
    # beside the axes: never over a curve
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.set_title("SFB-scale slips in the reduced model (● = s, where the slip ends)",
                 fontsize=9)
    if axes_out is not None:
        axes_out.append(ax)
    return _png(fig)
