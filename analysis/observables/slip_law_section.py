"""``slip_law``: Klein's slip equation tested on the slips, F_film = F_k + B·v.

The physics is :mod:`filmfriction.analysis.slip_law.slip_law`.  The verdict's fit is the
slips' mean, each slip aligned at its yield and held at its end, with the jackknife's
errors over the slips (:mod:`~filmfriction.analysis.slip_law.slip_law_cycles`,
``estimator`` ``cycle ensemble``): a fit of each slip is biased where the film's random
force moves the wall (docs/results/slip-law.md, "The controls with a random force that
moves the wall"); that per-slip fit stands beside it as ``per_slip_fit``, and is the
verdict's (``estimator`` ``per slip``) only where the mean cannot be fitted (fewer than
three slips, a sampling not uniform).  This file says what the fit needs, what it writes into ``analysis.json["slip_law"]`` and
``analysis_cycles.csv`` (``slip_law_kinetic_force``, ``slip_law_damping`` of
the decelerating branch, ``slip_law_accelerating_kinetic_force``,
``slip_law_accelerating_damping``, ``slip_law_loop_area``), and what the report
shows: the verdict's table and the film force against the wall's velocity with
the two branches' lines.  Where the trace has the load's work (an MD trace's
``load_work`` column), each slip's own fit with that work taken out of the film force
(``fit_film_force(load_work=…)``: the film's dissipative force, the gap's work
against the load removed; to compare with ``per_slip_fit``) is reported beside it as
``load_work_removed`` (its verdict, the one law, the loop step); the section's verdict
stays the film force's
(docs/results/slip-law.md: on the MD liquid the correction carries the gap's thermal
breathing into the fit and more than doubles the errors).  The section's own F_k, B, exponent and power are the
verdict's law's (``verdict_from``: the one law over the whole slip with a co-moving
mass when no loop is left beyond it, else the decelerating branch); every fit is
under ``branches``, the one law as ``one_law``, with the loop step beside it.

Beside B stand the smallest B the run resolves (``detectable_damping``) and, for
an LJ run, the B of a no-slip film of bulk viscosity, η_bulk·A/D
(``bulk_film_damping``), with η_bulk the LJ liquid's measured at the film's
state point (:func:`filmfriction.reduced_model.units.lj_bulk_viscosity`; the Klein-similar
film's, :data:`~filmfriction.reduced_model.units.LJ_ETA_FILM`, with a note where none was measured).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.signal import savgol_filter

from filmfriction.reduced_model.units import lj_bulk_viscosity

from ..slip_law.slip_law import BRANCHES, RESOLVED_SIGMAS, film_force, fit_film_force
from ..slip_law.slip_law_cycles import MD_NOISE_TIME, fit_cycle_ensemble
from ..files.trace import unit
from ..trace_figure import scaled_unit
from ..files.util import finite_or_none
from .observable import (Context, MissingInput, Observable, column, format_estimate, format_value,
                         parameter, png_bytes, pyplot)

__all__ = ["SlipLaw", "BULK_VISCOSITY_SOURCE", "ESTIMATORS"]

#: The fits the verdict can be: the slips' mean (three or more slips, uniform sampling),
#: else each slip's own.
ESTIMATORS = ("cycle ensemble", "per slip")

#: The bulk viscosity taken for a film at a state point where none was measured: the
#: Klein-similar film's (kT 0.71, :data:`~filmfriction.reduced_model.units.LJ_ETA_FILM`).
_KLEIN_SIMILAR_FILM = lj_bulk_viscosity(0.71)


def _source(at) -> dict:
    """Where a bulk viscosity comes from: its state point and the command that measured it."""
    return {"state_point": f"T = {at.temperature:g} ε/k_B, ρ = {at.density:g} σ⁻³ (rc = 2.5 σ)",
            "command": at.command}


#: Where the Klein-similar film's bulk viscosity comes from.
BULK_VISCOSITY_SOURCE = _source(_KLEIN_SIMILAR_FILM)
#: A film whose mean temperature (ε/k_B) is this close to a measured state point's takes
#: its bulk viscosity (:func:`~filmfriction.reduced_model.units.lj_bulk_viscosity`).
_STATE_POINT_TOLERANCE = 0.03


class SlipLaw(Observable):
    """F_film = F_k + B·v fitted on each branch of the analysed slips, and its verdict."""

    key = "slip_law"
    title = "Klein's slip equation on the slips: viscous, kinetic or neither resolved?"
    needs = (column("wall_velocity", "the film force during the slip"),
             parameter("mass", "the film force F_spring − M·a"))
    table_header = ("slip law (mean ± stderr over slips)", "value")
    absent = "No slip-law fit"
    caption = ("The film's own shear force during each slip (the spring's force less "
               "the wall's inertia and the mount dashpot, smoothed over a tenth of a "
               "slip) against the wall's velocity, with the fitted lines F_k + B·v of the "
               "accelerating and the decelerating branch. A line through the origin is "
               "Klein's viscous film (his Eq. 1); a flat line is a kinetic friction force "
               "(Braun & Tosatti).")

    def compute(self, ctx: Context) -> tuple[dict, dict]:
        trace, p = ctx.trace, ctx.trace.parameters
        if len(ctx.table) == 0:
            raise MissingInput("slips", "the slip-law fit")
        v_drive, _ = trace.drive_velocity()
        args = dict(mass=p.mass, drive_velocity=v_drive or 0.0,
                    mount_damping=p.mount_damping or 0.0,
                    wall_position=trace.wall_position(), film_mass=p.film_mass)
        t, f, v = trace.time, trace.spring_force, trace.columns["wall_velocity"]
        per_slip = fit_film_force(t, f, v, ctx.table, **args)
        try:
            # the verdict's fit: the slips' mean, unbiased where the film's random force
            # moves the wall (module text)
            noise_time = MD_NOISE_TIME if ctx.units == "lj" else 0.0
            fit = fit_cycle_ensemble(t, f, v, ctx.table, **args, min_window_time=noise_time,
                                     registry_period=p.registry_period)
            estimator = ESTIMATORS[0]
        except ValueError as err:
            fit, estimator = per_slip, ESTIMATORS[1]
            ctx.skip_part("slip_law.cycle_ensemble", f"the slips' mean not fitted: {err}; "
                          "the verdict is the per-slip fit's")
        law, one = fit.law, fit.one_law          # the verdict's law; the whole slip with m_c
        force_velocity = f"{ctx.unit('force')}·{ctx.unit('velocity')}"
        out = {"verdict": fit.verdict, "reason": fit.reason, "verdict_from": fit.verdict_from,
               "estimator": estimator,
               "kinetic_force": ctx.value(law.kinetic_force, law.kinetic_force_stderr, "force"),
               "damping": ctx.value(law.damping, law.damping_stderr, "damping"),
               "detectable_damping": ctx.value(law.detectable_damping, None, "damping"),
               "mean_slip_velocity": ctx.value(law.mean_velocity, None, "velocity"),
               "viscous_share": law.viscous_share,
               "exponent": ctx.value(law.exponent, law.exponent_stderr, "1"),
               "samples": law.samples, "slips": law.slips,
               "branches": {b.branch: self._branch(ctx, b)
                            for b in (fit.decelerating, fit.accelerating, fit.whole)}
                           | {"one_law": self._branch(ctx, one)},
               "loop_step": ctx.value(fit.loop_step, fit.loop_step_stderr, "force",
                                      sigmas=finite_or_none(fit.loop_step_sigmas),
                                      detectable=finite_or_none(fit.detectable_loop_step)),
               "loop": {"area": {"mean": finite_or_none(fit.loop_area), "stderr": finite_or_none(fit.loop_area_stderr),
                                 "units": force_velocity},
                        "force_gap": ctx.value(fit.loop_force, fit.loop_force_stderr, "force")},
               "comoving_mass": ctx.value(one.comoving_mass, one.comoving_mass_stderr, "mass",
                                          branch="whole slip",
                                          damping=finite_or_none(one.damping),
                                          damping_stderr=finite_or_none(one.damping_stderr),
                                          kinetic_force=finite_or_none(one.kinetic_force)),
               "smoothing_window": fit.smoothing_window,
               # the registry period the slips were fitted with (None: none, or too short)
               "registry_period": ctx.value(fit.registry_period, None, "length")
               if fit.registry_period else None,
               "law": "F_film = kinetic_force + damping * v on each branch (+ comoving_mass "
                      "* a over the whole slip: one_law), F_film = F_spring - M a - "
                      "mount_damping (v - V), fitted in the integrated equation of motion "
                      "(estimator: the slips' mean, each slip held at its end, jackknife "
                      "errors over the slips; or each slip's own); the verdict's law is "
                      "verdict_from's; with registry_period, the slips' mean is fitted with "
                      "a force periodic in the wall's position beside the law (two "
                      "harmonics of that period: commensurate walls)"}
        if estimator == ESTIMATORS[0]:
            out["per_slip_fit"] = self._per_slip_fit(ctx, per_slip)
        if trace.has("load_work"):
            out["load_work_removed"] = self._load_work_removed(
                ctx, fit_film_force(t, f, v, ctx.table, **args,
                                    load_work=trace.columns["load_work"]))
        if p.area is not None and (trace.has("gap") or p.thickness is not None):
            d, d_src = trace.film_thickness()
            if math.isfinite(law.damping):
                out["eta_from_damping"] = ctx.value(law.damping * d / p.area,
                                                    law.damping_stderr * d / p.area,
                                                    "viscosity", thickness=d,
                                                    thickness_source=d_src, form="B·D/A")
            if ctx.units == "lj":
                out.update(self._bulk(ctx, law.damping, law.damping_stderr, d, p.area))
            else:
                ctx.skip_part("slip_law.bulk_film_damping",
                              "no bulk viscosity for a measured (SI) trace")
        # the cycles' table: each slip's own fit (the ensemble's pseudo-values are per slip
        # kept, not per slip of the table)
        cycles = {"kinetic_force": per_slip.decelerating.per_slip_kinetic_force.tolist(),
                  "damping": per_slip.decelerating.per_slip_damping.tolist(),
                  "accelerating_kinetic_force":
                      per_slip.accelerating.per_slip_kinetic_force.tolist(),
                  "accelerating_damping": per_slip.accelerating.per_slip_damping.tolist(),
                  "loop_area": per_slip.per_slip_loop_area.tolist()}
        return out, cycles

    @classmethod
    def _per_slip_fit(cls, ctx, fit) -> dict:
        """The fit slip by slip, beside the ensemble's: biased where the film's random
        force moves the wall (kept as the comparison)."""
        return {"verdict": fit.verdict, "verdict_from": fit.verdict_from, "reason": fit.reason,
                "one_law": cls._branch(ctx, fit.one_law),
                "decelerating": cls._branch(ctx, fit.decelerating),
                "loop_step": ctx.value(fit.loop_step, fit.loop_step_stderr, "force",
                                       sigmas=finite_or_none(fit.loop_step_sigmas),
                                       detectable=finite_or_none(fit.detectable_loop_step)),
                "note": "each slip fitted on its own, the errors the slips' scatter: biased "
                        "where the film's random force moves the wall (its regressors carry "
                        "the response's noise); the verdict is the cycle ensemble's"}

    @classmethod
    def _load_work_removed(cls, ctx, fit) -> dict:
        """The fit of the film force less the load's work on the gap, beside the section's."""
        one = fit.one_law
        return {"verdict": fit.verdict, "verdict_from": fit.verdict_from, "reason": fit.reason,
                "one_law": cls._branch(ctx, one),
                "comoving_mass": ctx.value(one.comoving_mass, one.comoving_mass_stderr, "mass"),
                "decelerating": cls._branch(ctx, fit.decelerating),
                "loop_step": ctx.value(fit.loop_step, fit.loop_step_stderr, "force",
                                       sigmas=finite_or_none(fit.loop_step_sigmas),
                                       detectable=finite_or_none(fit.detectable_loop_step)),
                "law": "F_film + dW_load/dx (W_load the load's work on the wall, "
                       "-P A (D - D0)): the film force less the load's work on the gap"}

    @staticmethod
    def _branch(ctx, b) -> dict:
        return {"kinetic_force": ctx.value(b.kinetic_force, b.kinetic_force_stderr, "force",
                                           sigmas=finite_or_none(b.kinetic_sigmas)),
                "damping": ctx.value(b.damping, b.damping_stderr, "damping",
                                     sigmas=finite_or_none(b.damping_sigmas)),
                "detectable_damping": ctx.value(b.detectable_damping, None, "damping"),
                "detectable_kinetic_force": ctx.value(b.detectable_kinetic_force, None, "force"),
                "mean_velocity": ctx.value(b.mean_velocity, None, "velocity"),
                "mean_force": ctx.value(b.mean_force, None, "force"),
                "viscous_share": finite_or_none(b.viscous_share),
                "exponent": ctx.value(b.exponent, b.exponent_stderr, "1"),
                "velocity_residual": ctx.value(b.velocity_residual, None, "velocity"),
                "dof": b.dof, "samples": b.samples, "slips": b.slips,
                "verdict": b.verdict, "reason": b.reason}

    @staticmethod
    def _bulk(ctx, b, b_err, d, area) -> dict:
        """B of a no-slip film of bulk viscosity beside the fitted B (LJ runs), η_bulk the
        one measured at the film's mean temperature (the Klein-similar film's when none
        was measured there, with a note)."""
        tr = ctx.trace
        temp = (float(np.mean(tr.columns["film_temperature"])) if tr.has("film_temperature")
                else math.nan)
        measured = lj_bulk_viscosity(temp, tolerance=_STATE_POINT_TOLERANCE)
        at = measured or _KLEIN_SIMILAR_FILM
        eta, eta_err = at.viscosity, at.stderr
        bulk = eta * area / d
        out = {"bulk_viscosity": ctx.value(eta, eta_err, "viscosity", **_source(at)),
               "bulk_film_damping": ctx.value(bulk, eta_err * area / d, "damping",
                                              form="eta_bulk·A/D", thickness=d),
               "damping_over_bulk": finite_or_none(b / bulk),
               "damping_over_bulk_stderr": finite_or_none(b_err / bulk)}
        if measured is None and math.isfinite(temp):
            out["bulk_viscosity"]["note"] = (
                f"no bulk viscosity measured at the film's mean temperature {temp:.3g}: the "
                "Klein-similar film's (0.71) is taken; measure eta_bulk at the film's own "
                "state point (filmfriction viscosity)")
        return out

    def rows(self, section: dict) -> list[tuple[str, str]]:
        br = section.get("branches") or {}
        frm = section.get("verdict_from", "decelerating")
        rows = [(f"verdict ({frm})", f"**{section.get('verdict', '?')}**"),
                ("fitted", section.get("estimator", ESTIMATORS[1]))]
        for name in BRANCHES:
            b = br.get(name) or {}
            rows += [(f"{name}: kinetic force F_k", format_estimate(b.get("kinetic_force"))),
                     (f"{name}: damping B", format_estimate(b.get("damping"))),
                     (f"{name}: smallest B resolved ({RESOLVED_SIGMAS:.3g} σ, 95 % power)",
                      format_estimate(b.get("detectable_damping"))),
                     (f"{name}: exponent n = d ln F/d ln v",
                      format_estimate(b.get("exponent"))),
                     (f"{name}: verdict", b.get("verdict", "?"))]
        loop = section.get("loop") or {}
        rows.append(("loop: mean force gap, accelerating − decelerating",
                     format_estimate(loop.get("force_gap"))))
        one = br.get("one_law") or {}
        if one:
            rows += [("one law (whole slip + m_c·a): F_k", format_estimate(one.get("kinetic_force"))),
                     ("one law: B", format_estimate(one.get("damping"))),
                     ("one law: verdict", one.get("verdict", "?")),
                     ("loop step beyond the co-moving mass, F_acc − F_dec",
                      format_estimate(section.get("loop_step")))]
        ps = section.get("per_slip_fit") or {}
        if ps:
            rows += [(f"each slip's own fit (biased by the noise): verdict "
                      f"({ps.get('verdict_from', '?')})", ps.get("verdict", "?")),
                     ("  its loop step", format_estimate(ps.get("loop_step")))]
        lw = section.get("load_work_removed") or {}
        if lw:
            rows += [("with the load's work on the gap taken out: verdict "
                      f"({lw.get('verdict_from', '?')})", lw.get("verdict", "?")),
                     ("  its loop step beyond the co-moving mass",
                      format_estimate(lw.get("loop_step")))]
        if section.get("bulk_film_damping"):
            rows.append(("B of a no-slip film of bulk viscosity, η_bulk·A/D",
                         format_estimate(section["bulk_film_damping"])))
            rows.append(("B / (η_bulk·A/D)", format_value(section.get("damping_over_bulk"), 3)))
        cm = section.get("comoving_mass") or {}
        if cm:
            rows.append(("co-moving mass m_c (fitted with the law over the whole slip)",
                         format_estimate(cm)))
        if section.get("eta_from_damping"):
            rows.append(("η from B (B·D/A)", format_estimate(section["eta_from_damping"])))
        return rows

    def notes(self, section: dict) -> list[str]:
        return [f"Why: {section.get('reason', '')}. Klein himself proposed this test (his note "
                "27: the friction force against the sliding velocity during the slip). "
                "`inconclusive` says that the run's slips are too few or too noisy to tell; "
                "what the test can resolve at the MD's noise is in docs/results/slip-law.md. "
                "Where the film's random force moves the wall a fit of each slip is biased "
                "(on driven slips at the MD's noise Klein's viscous controls come out `mixed`, "
                "with a kinetic force and a loop where there are none): the verdict is the "
                "slips' mean's, each slip aligned at its yield and held at its end, its errors "
                "the jackknife's over the slips (`estimator`), which passes the controls as "
                "docs/results/slip-law.md states them; the per-slip fit stands beside it "
                "(`per_slip_fit`) as the comparison. A verdict is "
                "this film's: it bears on Klein's film, and on Braun & "
                "Tosatti's reading of it, only when the run's Bingham number η_eff/η_bulk "
                "(sfb.json, `bingham_number`) is ≫ 1, as his is (~10⁴)."]

    def figure(self, run) -> bytes | None:
        """The film's force against the wall's velocity during the slips, with the
        branches' fitted lines."""
        tr = run.trace
        p = tr.parameters
        if not (tr.has("wall_velocity") and p.mass):
            return None
        law = run.analysis.get(self.key) or {}
        plt = pyplot()
        t, f, v = tr.time, tr.spring_force, tr.columns["wall_velocity"]
        v_drive, _ = tr.drive_velocity()   # the same V as the fit's (compute)
        w = int(law.get("smoothing_window") or 0)
        if w >= 5 and t.size > w:
            dt = float(t[1] - t[0])
            a = savgol_filter(v, w, 2, deriv=1, delta=dt)
            vs, fs = savgol_filter(v, w, 2), savgol_filter(f, w, 2)
            ff = fs - p.mass * a - (p.mount_damping or 0.0) * (vs - (v_drive or 0.0))
        else:
            vs = v
            ff = film_force(t, f, v, mass=p.mass, drive_velocity=v_drive or 0.0,
                            mount_damping=p.mount_damping or 0.0)
        lab = lambda q: unit(tr.units, q)  # noqa: E731
        yi = np.asarray(run.cycles.get("yield_index", []), int)[run.skip:]
        si = np.asarray(run.cycles.get("stick_index", []), int)[run.skip:]
        # SI: a prefix chosen for the numbers (µN), never an axis offset
        fscale, flab = scaled_unit(f, tr.units, "force")
        ff = ff * fscale
        vscale, vlab = scaled_unit(vs, tr.units, "length")   # m/s as µm/s ...
        vlab = f"{vlab}/s" if tr.units == "si" else lab("velocity")
        vs = vs * vscale
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        cmap = plt.get_cmap("viridis")
        vmax = 0.0
        for i, (y, s_) in enumerate(zip(yi, si)):
            seg = slice(int(y), int(s_) + 1)
            ax.plot(vs[seg], ff[seg], ".-", lw=0.5, ms=2, color=cmap(i / max(len(yi) - 1, 1)),
                    alpha=0.6, label="slips (colour: order)" if i == 0 else None)
            vmax = max(vmax, float(np.max(vs[seg])) if vs[seg].size else 0.0)
        styles = {"decelerating": "k--", "accelerating": "r:"}
        for name, b in (law.get("branches") or {}).items():
            if name not in styles:
                continue
            fk = (b.get("kinetic_force") or {}).get("mean")
            bb = (b.get("damping") or {}).get("mean")
            if fk is None or bb is None or vmax <= 0:
                continue
            vv = np.linspace(0.0, vmax, 50)
            ax.plot(vv, (fk + bb * vv / vscale) * fscale, styles.get(name, "k-"), lw=1.5,
                    label=f"{name}: F_k = {fk:.3g} {lab('force')}, B = {bb:.3g} {lab('damping')}")
        ax.axhline(0, color="0.6", lw=0.5)
        ax.set_xlabel(f"wall velocity during the slip v [{vlab}]")
        ax.set_ylabel(f"film force F_spring − M·a − γM(v − V) [{flab}]")
        # above the axes: inside, it hid slips' points (the loops fill the plane)
        ax.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), fontsize=8, frameon=False)
        return png_bytes(fig)
