"""``energy``: where the spring's energy goes, per slip and over the whole run.

The physics is :mod:`filmfriction.analysis.energy` (the per-slip energy table,
the heat check and the MD run's ledger); this file writes its summaries into
``analysis.json["energy"]``, the per-slip energies into ``analysis_cycles.csv``
(``energy_*``, one value for every slip, the start-up ones included) and the
whole-run ledger as ``energy.ledger``, and shows in the report the energy
partition as bars and the ledger's terms over time.
"""
from __future__ import annotations

import math

import numpy as np

from ..energy.heat_check import compare_heat
from ..energy.ledger import LEDGER_COLUMNS, ledger
from ..energy.partition import energy_table
from ..stick_ramps import stick_stiffness
from ..files.trace import MissingInput, unit
from ..trace_figure import scaled_unit
from ..files.util import finite_or_none
from .observable import (Context, Observable, entry, format_estimate, format_value, png_bytes,
                         pyplot, shade_slips)

__all__ = ["Energy", "ENERGY_QUANTITIES"]

#: the per-slip summaries of ``analysis.json["energy"]`` and the quantity of each
ENERGY_QUANTITIES = {"spring_released": "energy", "spring_released_exact": "energy",
                     "drive_work_slip": "energy", "film_dissipation": "energy",
                     "wall_ke_change": "energy", "ringing_energy": "energy",
                     "viscous_fraction": "1", "at_stick_fraction": "1",
                     "thermostat_heat_cycle": "energy", "ledger_residual_cycle": "energy",
                     "mount_dissipation_slip": "energy", "film_elastic_released": "energy",
                     "dilation_work": "energy", "quadrature_residual": "1",
                     "thermostat_heat_slip": "energy", "dashpot_static_bias": "force",
                     "film_heat": "energy", "film_heat_cycle": "energy"}

#: energy terms only an MD run has (its thermostat, its mount dashpot, the dilation
#: against the load, the engine's ledger): not drawn for a measured (SI) trace
MD_ONLY_TERMS = ("thermostat", "mount dashpot", "dilation", "ledger", "released: stuck film")

#: the independent checks of the film heat: (key, film heat, the thermostat's, windows)
HEAT_CHECKS = (("slip", "film_heat", "thermostat_heat_slip", "per slip"),
               ("cycle", "film_heat_cycle", "thermostat_heat_cycle", "per cycle"))


#: the rows of the report's table: (section entry, label)
_ROWS = (("spring_released_exact", "spring energy released (Fs² − Fb²)/2K"),
         ("drive_work_slip", "drive's work during the slip"),
         ("film_elastic_released", "stuck film's elastic energy released"),
         ("film_heat", "film heat"),
         ("thermostat_heat_slip", "thermostat's heat over the slip"),
         ("ringing_energy", "ringing energy after s ΔE_osc"),
         ("film_heat_cycle", "film heat over the cycle (y → next y)"),
         ("thermostat_heat_cycle", "thermostat's heat over the cycle"),
         ("viscous_fraction", "viscous fraction E_film/(E_film + ΔE_osc)"),
         ("quadrature_residual", "quadrature residual (engine's work vs the trace's ∫F·v)"))


class Energy(Observable):
    """The energy table's summaries, the stuck film's stiffness and the run's ledger."""

    key = "energy"
    title = "Energy partition"
    order = 20
    per_slip = "all"
    absent = "No energy partition"
    table_header = ("per slip (mean ± stderr)", "value")

    def compute(self, ctx: Context) -> tuple[dict, dict]:
        trace, table, p = ctx.trace, ctx.all_slips, ctx.trace.parameters
        t, f = trace.time, trace.spring_force
        ledger_cols = {c: trace.columns[c] for c in LEDGER_COLUMNS + ("mount_heat",)
                       if trace.has(c)}
        section: dict = {}
        per_slip: dict = {}
        try:
            if len(table) == 0:
                raise MissingInput("slips", "the energy per slip")
            k = p.require("spring_constant", "the spring energy")
            v_drive, _ = trace.drive_velocity()
            stiff = (stick_stiffness(t, f, table, spring_constant=k,
                                               drive_velocity=v_drive) if v_drive else None)
            et = energy_table(
                t, f, table, k, mass=p.mass,
                wall_velocity=trace.columns.get("wall_velocity"),
                wall_position=trace.wall_position(),
                drive_position=trace.columns.get("drive_position"),
                drive_velocity=v_drive, noise=ctx.events.noise, ledger_columns=ledger_cols,
                mount_damping=p.mount_damping or 0.0,
                film_stiffness=None if stiff is None else stiff.film_stiffness)
            if stiff is not None:
                section["film_stiffness"] = ctx.value(
                    stiff.film_stiffness, stiff.film_stiffness_stderr, "stiffness",
                    effective_stiffness=finite_or_none(stiff.effective_stiffness),
                    ramps=stiff.ramps)
            else:
                ctx.skip_part("energy.film_elastic_released",
                              "the stuck film's stiffness k_f is not measurable (fewer than 2 "
                              "stick ramps, or their slope not below K V)")
            summary = et.summary(skip=ctx.skip)
            for name, quantity in ENERGY_QUANTITIES.items():
                section[name] = entry(summary[name], ctx.unit(quantity))
            section["film_dissipation_method"] = et.film_dissipation_method
            section["ringing_method"] = et.ringing_method
            per_slip = {name: values for name, values in et.as_dict().items()
                        if not name.endswith("_method")}
            section["heat_check"] = heat_checks(et, ctx.skip, ctx.unit("energy"))
            if p.mass is None and et.film_dissipation_method != "klein-eq1":
                ctx.skip_part("energy.wall_ke_change", MissingInput("--mass", "ΔKE of the wall"))
        except MissingInput as exc:
            ctx.skip_part("energy", exc)
        if all(c in ledger_cols for c in LEDGER_COLUMNS):
            led = ledger(ledger_cols)
            section["ledger"] = {
                "closure": {"mean": finite_or_none(led["closure"]), "units": "1"},
                "input_work": {"mean": finite_or_none(led["input"]), "units": ctx.unit("energy")},
                "thermostat_heat": {"mean": finite_or_none(led["thermostat_heat"]),
                                    "units": ctx.unit("energy")},
                "mount_heat": {"mean": finite_or_none(led["mount_heat"]),
                               "units": ctx.unit("energy")},
                "residual": {"mean": finite_or_none(led["residual"][-1]),
                             "units": ctx.unit("energy")}}
        else:
            missing = [c for c in LEDGER_COLUMNS if c not in ledger_cols]
            ctx.skip_part("energy.ledger", f"missing column(s) {', '.join(missing)}")
        return section, per_slip

    # -- the report ----------------------------------------------------------
    def shown(self, section: dict) -> bool:
        return bool(section) and "film_dissipation" in section

    def rows(self, section: dict) -> list[tuple[str, str]]:
        rows = [(label, format_estimate(section.get(name))) for name, label in _ROWS
                if (section.get(name) or {}).get("mean") is not None]
        for key, _, _, what in HEAT_CHECKS:
            c = (section.get("heat_check") or {}).get(key)
            if c and c["z"] is not None:
                res = ("" if c["resolution"] is None
                       else f"; resolves a {100 * c['resolution']:.0f} % error")
                rows.append((f"check: film heat vs thermostat's, {what}",
                             f"{c['status']}: {c['z']:.2f} stderr (limit {c['threshold']:.2f}, "
                             f"99 %{res})"))
            elif c:
                rows.append((f"check: film heat vs thermostat's, {what}", c["status"]))
        return rows

    def notes(self, section: dict) -> list[str]:
        e = section
        vf = e.get("viscous_fraction") or {}
        text = (f"Film dissipation method: {e.get('film_dissipation_method', '?')}. Viscous "
                f"fraction film heat/(film heat + ringing) = {format_estimate(vf)}.")
        for check in (e.get("heat_check") or {}).values():
            text += f" Check: {check['message']}."
        quad = e.get("quadrature_residual") or {}
        if quad.get("mean") is not None:
            text += (" Quadrature residual per slip (the engine's integrated work against the "
                     f"trace's sampled ∫F·v, a check of the sampling, not of the film) = "
                     f"{format_estimate(quad)}.")
        text += f" Ringing: {e.get('ringing_method', '?')}."
        if e.get("film_stiffness"):
            text += (f" Stuck film's shear stiffness k_f = {format_estimate(e['film_stiffness'])}"
                     " (from the stick ramps).")
        led = e.get("ledger", {})
        if led:
            eu = led["input_work"]["units"]
            text += (f" Whole-run ledger: input work {format_value(led['input_work']['mean'])} "
                     f"{eu}, thermostat heat {format_value(led['thermostat_heat']['mean'])} {eu}, "
                     f"mount heat {format_value(led['mount_heat']['mean'])} {eu}, closure "
                     f"{format_value(led['closure']['mean'], 2)} (relative).")
        return [text]

    def figures(self, run) -> list[tuple[str, bytes, str]]:
        if run.trace.units == "si":
            # a measured trace: no thermostat, no mount dashpot, no dilation, no ledger
            bars = [b for b in energy_bars(run)
                    if not b[0].strip().startswith(MD_ONLY_TERMS) and math.isfinite(b[1])]
            return [("energy", fig_energy(bars, unit(run.trace.units, "energy")),
                     "Where the spring's energy goes, per slip (its window, from just before "
                     "y to just after s): what is released (the spring, the drive's work "
                     "during the slip) and where it goes (the film's heat, from the "
                     "equation of motion, and the ringing left at s); per cycle (y → next "
                     "y): the film's heat. Mean ± standard error over the analysed slips.")]
        out = [("energy", fig_energy(energy_bars(run), unit(run.trace.units, "energy")),
                "Where the spring's energy goes. Per slip (its window, from just before y to "
                "just after s): what is released (spring, drive, the stuck film's elastic "
                "energy) and where it goes (film heat, which the thermostat measures "
                "independently; the mount dashpot; the ringing left at s; the dilation). "
                "Per cycle (y → next y): the film heat from the mechanics against the "
                "thermostat's, the mount dashpot's heat and the ledger residual. The film heat "
                "and the thermostat's are the independent pair that energy.heat_check tests.")]
        if all(run.trace.has(c) for c in LEDGER_COLUMNS):
            out.append(("ledger", fig_ledger(run),
                        "The run's energy ledger over time, each term from the start: the work "
                        "done on the system (drive and load) against the energy stored "
                        "(potential, kinetic, spring) and the heat the thermostat and the mount "
                        "dashpot removed; the residual is what the engine's integrals leave "
                        "unaccounted (a timestep too long shows here). Shaded: the slips."))
        return out


def heat_checks(et, skip: int, energy_unit: str) -> dict:
    """``energy.heat_check``: the film heat against the thermostat's, per slip and per cycle
    (:func:`filmfriction.analysis.energy.heat_check.compare_heat`), for the windows that have both."""
    out = {}
    for key, film, thermostat, what in HEAT_CHECKS:
        c = compare_heat(et._column(film), et._column(thermostat), skip=skip, what=what)
        if c.n == 0:
            continue
        out[key] = {"status": c.status, "message": c.message, "n": c.n,
                    "film_heat": {"mean": finite_or_none(c.film_heat), "units": energy_unit},
                    "thermostat_heat": {"mean": finite_or_none(c.thermostat_heat),
                                        "units": energy_unit},
                    "difference": {"mean": finite_or_none(c.difference),
                                   "stderr": finite_or_none(c.stderr), "units": energy_unit},
                    "z": finite_or_none(c.z), "threshold": finite_or_none(c.threshold),
                    "resolution": finite_or_none(c.resolution)}
    return out


def _mount_heat_per_cycle(run) -> float:
    tr = run.trace
    yi = np.asarray(run.cycles.get("yield_index", []), int)
    if not tr.has("mount_heat") or yi.size < 2 + run.skip:
        return math.nan
    q = np.diff(tr.columns["mount_heat"][yi])[run.skip:]
    return float(np.mean(q)) if q.size else math.nan


def energy_bars(run) -> list[tuple[str, float, float]]:
    """(label, mean per cycle, stderr) of the energy partition, in the trace's energy unit."""
    e = run.analysis.get("energy", {})

    def get(name):
        d = e.get(name) or {}
        return (d.get("mean") if d.get("mean") is not None else math.nan,
                d.get("stderr") if d.get("stderr") is not None else math.nan)
    bars = [("released: spring (slip)",) + get("spring_released_exact"),
            ("released: drive work (slip)",) + get("drive_work_slip"),
            ("released: stuck film's elastic (slip)",) + get("film_elastic_released"),
            ("film heat (slip)",) + get("film_heat"),
            ("  thermostat's measure of it (slip)",) + get("thermostat_heat_slip"),
            ("mount dashpot (slip)",) + get("mount_dissipation_slip"),
            ("ringing after s",) + get("ringing_energy"),
            ("dilation work P·A·Δz (slip)",) + get("dilation_work"),
            ("film heat (cycle)",) + get("film_heat_cycle"),
            ("  thermostat's measure of it (cycle)",) + get("thermostat_heat_cycle"),
            ("mount dashpot (cycle)", _mount_heat_per_cycle(run), math.nan),
            ("ledger residual (cycle)",) + get("ledger_residual_cycle")]
    return [(a, float(b), float(c)) for a, b, c in bars]


def fig_energy(bars, energy_unit: str) -> bytes:
    """The energy partition as horizontal bars with their standard errors."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8.5, 0.34 * len(bars) + 1.0))
    labels = [b[0] for b in bars]
    vals = np.array([b[1] for b in bars], float)
    errs = np.array([b[2] for b in bars], float)
    if energy_unit == "J":      # an SI prefix for the numbers, not a 1e-13 offset
        factor, energy_unit = scaled_unit(vals[np.isfinite(vals)], "si", "energy")
        vals, errs = vals * factor, errs * factor
    e0 = np.where(np.isfinite(errs), errs, 0.0)
    colors = {"released": "tab:blue", "film": "tab:red", "  the": "tab:pink",
              "ringing": "tab:orange", "mount": "tab:brown", "dilation": "tab:gray",
              "thermostat": "tab:purple", "ledger": "0.5"}
    colour = [next((c for k, c in colors.items() if lab.startswith(k)), "0.5") for lab in labels]
    ax.barh(labels, np.nan_to_num(vals), xerr=e0, color=colour, capsize=3)
    span = float(np.nanmax(np.abs(np.nan_to_num(vals)) + e0)) if len(vals) else 1.0
    for i, v in enumerate(vals):
        # the number goes beyond the end of the error bar, never over it
        end = 0.0 if not np.isfinite(v) else (v + e0[i] if v >= 0 else v - e0[i])
        ax.text(end + (0.01 if v >= 0 or not np.isfinite(v) else -0.01) * span, i,
                "n/a" if not np.isfinite(v) else f"{v:.3g}", va="center", fontsize=8,
                ha="left" if (not np.isfinite(v) or v >= 0) else "right")
    ax.set_xlim(min(0.0, float(np.nanmin(np.nan_to_num(vals) - e0))) - 0.12 * span, 1.15 * span)
    ax.invert_yaxis()
    ax.axvline(0, color="k", lw=0.6)
    ax.set_xlabel(f"energy per slip / per cycle [{energy_unit}] (mean ± stderr over analysed "
                  "cycles)")
    return png_bytes(fig)


def fig_ledger(run) -> bytes:
    """The ledger's terms against time (:func:`filmfriction.analysis.energy.ledger.ledger`)."""
    plt = pyplot()
    tr = run.trace
    lab = lambda q: unit(tr.units, q)  # noqa: E731
    cols = {c: tr.columns[c] for c in LEDGER_COLUMNS + ("mount_heat",) if tr.has(c)}
    led = ledger(cols)

    def since_start(name):
        x = np.asarray(cols[name], float)
        return x - x[0]
    t = tr.time
    work = since_start("drive_work") + since_start("load_work")
    stored = (since_start("potential_energy") + since_start("kinetic_energy")
              + since_start("spring_energy"))
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(9, 5.0), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1]})
    ax.plot(t, work, color="k", lw=1.2, label="work in (drive + load)")
    ax.plot(t, stored, color="tab:blue", lw=0.9, label="Δ stored (potential + kinetic + spring)")
    ax.plot(t, since_start("thermostat_heat"), color="tab:purple", lw=0.9,
            label="thermostat heat")
    if "mount_heat" in cols:
        ax.plot(t, since_start("mount_heat"), color="tab:brown", lw=0.9, label="mount dashpot heat")
    axr.plot(t, led["residual"], color="0.4", lw=0.8, label="residual")
    axr.axhline(0.0, color="k", lw=0.5)
    for a in (ax, axr):
        shade_slips(a, run)
        a.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.set_ylabel(f"energy since the start [{lab('energy')}]")
    axr.set_ylabel(f"residual [{lab('energy')}]")
    axr.set_xlabel(f"time [{lab('time')}]")
    fig.align_ylabels((ax, axr))
    return png_bytes(fig)
