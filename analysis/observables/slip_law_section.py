"""``slip_law``: Klein's slip equation tested on the slips, F_film = F_k + B·v.

The physics is :mod:`filmfriction.analysis.slip_law`; this file says what the
fit needs, what it writes into ``analysis.json["slip_law"]`` and
``analysis_cycles.csv`` (``slip_law_kinetic_force``, ``slip_law_damping``), and
what the report shows: the verdict's table and the film force against the
wall's velocity with the fitted line.
"""
from __future__ import annotations

import math

import numpy as np

from ..slip_law import film_force, fit_film_force
from ..trace import unit
from .observable import (Context, MissingInput, Observable, column, format_estimate, format_value,
                         parameter, png_bytes, pyplot)

__all__ = ["SlipLaw"]


class SlipLaw(Observable):
    """F_film = F_k + B·v fitted over the analysed slips, and its verdict."""

    key = "slip_law"
    title = "Klein's slip equation on the slips: viscous or kinetic?"
    needs = (column("wall_velocity", "the film force during the slip"),
             parameter("mass", "the film force F_spring − M·a"))
    table_header = ("slip law (mean ± stderr over slips)", "value")
    absent = "No slip-law fit"
    caption = ("The film's own shear force during each slip (the spring's force less "
               "the wall's inertia and the mount dashpot) against the wall's velocity, "
               "with the fit F_film = F_k + B·v. A line through the origin is Klein's "
               "viscous film (his Eq. 1); a flat line at F_k is a kinetic friction "
               "stress (Braun & Tosatti).")

    def compute(self, ctx: Context) -> tuple[dict, dict]:
        trace, p = ctx.trace, ctx.trace.parameters
        if len(ctx.table) == 0:
            raise MissingInput("slips", "the slip-law fit")
        v_drive, _ = trace.drive_velocity()
        fit = fit_film_force(trace.time, trace.spring_force, trace.columns["wall_velocity"],
                             ctx.table, mass=p.mass, drive_velocity=v_drive or 0.0,
                             mount_damping=p.mount_damping or 0.0)
        out = {"kinetic_force": ctx.value(fit.kinetic_force, fit.kinetic_force_stderr, "force"),
               "damping": ctx.value(fit.damping, fit.damping_stderr, "damping"),
               "mean_slip_velocity": ctx.value(fit.mean_slip_velocity, None, "velocity"),
               "viscous_share": fit.viscous_share, "verdict": fit.verdict,
               "reason": fit.reason, "samples": fit.samples,
               "residual_rms": ctx.value(fit.residual_rms, None, "force"),
               "r_squared": fit.r_squared,
               "law": "F_film = kinetic_force + damping * v, F_film = F_spring - M a - "
                      "mount_damping (v - V)"}
        if p.area is not None and math.isfinite(fit.damping) and (
                trace.has("gap") or p.thickness is not None):
            d, d_src = trace.film_thickness()
            out["eta_from_damping"] = ctx.value(fit.damping * d / p.area,
                                                fit.damping_stderr * d / p.area, "viscosity",
                                                thickness=d, thickness_source=d_src,
                                                form="B·D/A")
        per_slip = {"kinetic_force": fit.per_slip_kinetic_force.tolist(),
                    "damping": fit.per_slip_damping.tolist()}
        return out, per_slip

    def rows(self, section: dict) -> list[tuple[str, str]]:
        rows = [("kinetic force F_k", format_estimate(section.get("kinetic_force"))),
                ("damping B", format_estimate(section.get("damping"))),
                ("mean slip velocity v̄", format_estimate(section.get("mean_slip_velocity"))),
                ("viscous share B·v̄/(F_k + B·v̄)", format_value(section.get("viscous_share"), 3)),
                ("share of F_film's variance the line explains",
                 format_value(section.get("r_squared"), 3)),
                ("verdict", f"**{section.get('verdict', '?')}**")]
        if section.get("eta_from_damping"):
            rows.append(("η from B (B·D/A)", format_estimate(section["eta_from_damping"])))
        return rows

    def notes(self, section: dict) -> list[str]:
        return [f"Why: {section.get('reason', '')}. Klein himself proposed this test (his note "
                "27: the friction force against the sliding velocity during the slip)."]

    def figure(self, run) -> bytes | None:
        """The film's force against the wall's velocity during the slips, with the fitted line."""
        tr = run.trace
        p = tr.parameters
        if not (tr.has("wall_velocity") and p.mass):
            return None
        law = run.analysis.get(self.key) or {}
        plt = pyplot()
        t, f, v = tr.time, tr.spring_force, tr.columns["wall_velocity"]
        v_drive, _ = tr.drive_velocity()   # the same V as the fit's (compute)
        ff = film_force(t, f, v, mass=p.mass, drive_velocity=v_drive or 0.0,
                        mount_damping=p.mount_damping or 0.0)
        lab = lambda q: unit(tr.units, q)  # noqa: E731
        yi = np.asarray(run.cycles.get("yield_index", []), int)[run.skip:]
        si = np.asarray(run.cycles.get("stick_index", []), int)[run.skip:]
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        cmap = plt.get_cmap("viridis")
        vmax = 0.0
        for i, (y, s_) in enumerate(zip(yi, si)):
            seg = slice(int(y), int(s_) + 1)
            ax.plot(v[seg], ff[seg], ".-", lw=0.5, ms=3, color=cmap(i / max(len(yi) - 1, 1)),
                    alpha=0.8, label="slips (colour: order)" if i == 0 else None)
            vmax = max(vmax, float(np.max(v[seg])) if v[seg].size else 0.0)
        fk = (law.get("kinetic_force") or {}).get("mean")
        b = (law.get("damping") or {}).get("mean")
        if fk is not None and b is not None and vmax > 0:
            vv = np.linspace(0.0, vmax, 50)
            ax.plot(vv, fk + b * vv, "k--", lw=1.5,
                    label=f"fit F_k + B·v: F_k = {fk:.3g} {lab('force')}, "
                          f"B = {b:.3g} {lab('damping')}")
        ax.axhline(0, color="0.6", lw=0.5)
        ax.set_xlabel(f"wall velocity during the slip v [{lab('velocity')}]")
        ax.set_ylabel(f"film force F_spring − M·a − γM(v − V) [{lab('force')}]")
        # above the axes: inside, it hid slips' points (the loops fill the plane)
        ax.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
        return png_bytes(fig)
