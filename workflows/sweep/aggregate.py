"""Sweep aggregation: per-point summaries, the critical velocity, η_eff vs γ̇, the
(V, K) map, and reading a finished sweep back (report, calibration).

Part of :mod:`filmfriction.workflows.sweep`.
"""
from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from filmfriction.analysis.files.documents import read_document
from filmfriction.analysis.files.provenance import provenance
from filmfriction.analysis.files.util import finite_or_none, json_safe, write_atomic
from filmfriction.analysis.stickslip import Regime, sliding_steadily
from filmfriction.md_inputs.contract import AGGREGATE_FILE, ANALYSIS_FILE, SWEEP_FILE

from .plan import format_value, json_text

AGGREGATE_SCHEMA = "filmfriction.sweep-aggregate/1"
# regimes of the analysis (filmfriction.analysis.stickslip.Regime)
STICK_SLIP, SMOOTH, IRREGULAR = Regime.STICK_SLIP, Regime.SMOOTH, Regime.IRREGULAR
# Unresolved points (fewer than 2 slips without steady sliding) are left out of V_c and of η_eff.
STUCK = Regime.UNRESOLVED


# ---------------------------------------------------------------------------
# aggregation
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class CriticalVelocity:
    """Where stick-slip gives way to smooth sliding along V (one group of points).

    ``status`` is ``bracketed`` (``low`` = last stick-slip V below ``high`` =
    first smooth V; ``value`` = √(low·high), the midpoint in log V, and
    ``log10_halfwidth`` = ½·log10(high/low)), ``below_range`` (all smooth:
    V_c < ``high`` = the lowest V), ``above_range`` (no smooth point: V_c >
    ``low`` = the highest V) or ``undetermined``.
    """

    status: str
    value: float | None
    low: float | None
    high: float | None
    log10_halfwidth: float | None
    monotonic: bool
    regimes: dict = field(hash=False)
    note: str = ""

    def as_dict(self) -> dict:
        return {"status": self.status, "value": self.value, "low": self.low, "high": self.high,
                "log10_halfwidth": self.log10_halfwidth,
                "factor": (10 ** self.log10_halfwidth if self.log10_halfwidth is not None
                           else None),
                "monotonic": self.monotonic,
                "regimes": {format_value(v): r for v, r in self.regimes.items()},
                "note": self.note}


def majority_regime(regimes: list[str]) -> str:
    """A velocity's regime over its points (seeds): the majority, else irregular."""
    for r in (STICK_SLIP, SMOOTH):
        if 2 * regimes.count(r) > len(regimes):
            return r
    return IRREGULAR


def critical_velocity(velocities, regimes) -> CriticalVelocity:
    """Bracket the critical velocity from the regime of each point.

    Parameters
    ----------
    velocities : sequence of float
        Drive velocity of each point (repeats, e.g. seeds, are combined by majority).
    regimes : sequence of str
        ``stick-slip``, ``smooth`` or ``irregular`` per point.

    Returns
    -------
    CriticalVelocity

    Examples
    --------
    >>> cv = critical_velocity([0.01, 0.1, 1.0], ["stick-slip", "stick-slip", "smooth"])
    >>> round(cv.value, 4), round(cv.log10_halfwidth, 3)
    (0.3162, 0.5)
    """
    by_v: dict = {}
    for v, r in zip(velocities, regimes):
        by_v.setdefault(float(v), []).append(r)
    per_v = {v: majority_regime(rs) for v, rs in sorted(by_v.items())}
    vs = list(per_v)
    ss = [v for v in vs if per_v[v] == STICK_SLIP]
    sm = [v for v in vs if per_v[v] == SMOOTH]
    if not ss and not sm:
        return CriticalVelocity("undetermined", None, None, None, None, True, per_v,
                                "no velocity is clearly stick-slip or smooth")
    if not ss:
        return CriticalVelocity("below_range", None, None, min(sm), None, True, per_v,
                                f"smooth at every V: V_c < {format_value(min(sm))}")
    above = [v for v in sm if v > min(ss)]
    if not above:
        return CriticalVelocity("above_range", None, max(ss), None, None, not sm, per_v,
                                f"no smooth sliding above a stick-slip V: V_c > "
                                f"{format_value(max(ss))}")
    high = min(above)
    low = max(v for v in ss if v < high)
    monotonic = all(v < high for v in ss) and all(v > low for v in sm)
    value = math.sqrt(low * high)
    half = 0.5 * math.log10(high / low)
    between = [format_value(v) for v in vs if low < v < high]
    note = f"stick-slip up to V = {format_value(low)}, smooth from {format_value(high)}"
    if between:
        note += f"; irregular in between at V = {', '.join(between)}"
    if not monotonic:
        note += "; not monotonic: stick-slip above or smooth below the bracket"
    return CriticalVelocity("bracketed", value, low, high, half, monotonic, per_v, note)


def _get(doc: dict, *path):
    for key in path:
        if not isinstance(doc, dict):
            return None
        doc = doc.get(key)
    return doc


def point_summary(sweep_dir: Path, point: dict) -> dict:
    """One row of the aggregate: parameters, regime, forces, η_eff for a completed point."""
    sweep_dir = Path(sweep_dir)
    name = point["name"]
    run_dir = sweep_dir / "points" / name
    inputs = json.loads((sweep_dir / "inputs" / f"{name}.json").read_text())
    p = inputs["parameters"]
    doc = read_document(run_dir / ANALYSIS_FILE, "analysis")
    row = {"point": name, **{f"grid.{k}": v for k, v in point["values"].items()},
           "drive_velocity": p["drive_velocity"], "spring_constant": p["spring_constant"],
           "normal_pressure": p["normal_pressure"], "temperature": p["temperature"],
           "film_layers": p["film_layers"], "seed": p["seed"],
           "wall_mass": p["wall_mass"], "mount_damping": p["mount_damping"],
           "regime": doc.get("regime"), "slips": _get(doc, "slips", "count")}
    for q in ("static_force", "backward_force", "period", "slip_distance"):
        row[q] = finite_or_none(_get(doc, "slips", q, "mean"))
        row[f"{q}_stderr"] = finite_or_none(_get(doc, "slips", q, "stderr"))
    # the time-averaged friction: the spring force over the last half of the drive
    # (the start-up ramp from a relaxed spring is in the first half), as analysed
    row["mean_force"] = finite_or_none(_get(doc, "sliding", "mean_force", "mean"))
    row["mean_force_stderr"] = finite_or_none(_get(doc, "sliding", "mean_force", "stderr"))
    # the analysis' own rule (sliding_steadily), applied again to an analysis.json
    # that reads "smooth" for a wall that did not slide steadily
    ratio = finite_or_none(_get(doc, "sliding", "wall_velocity_ratio"))
    row["wall_velocity_ratio"] = ratio
    row["sweep_regime"] = row["regime"]
    if row["regime"] == SMOOTH and ratio is not None and not sliding_steadily(ratio):
        row["sweep_regime"] = STUCK
    # η_eff at its shear rate: steady sliding (V/D), else the slip fits (slip velocity / D)
    eta = rate = eta_err = None
    source = None
    steady = _get(doc, "viscosity", "steady")
    slip = _get(doc, "viscosity", "from_slip")
    if steady:
        eta, eta_err = _get(steady, "eta_eff", "mean"), _get(steady, "eta_eff", "stderr")
        rate, source = _get(steady, "shear_rate", "mean"), "steady"
    elif slip and _get(slip, "eta_eff", "mean") is not None:
        d = _get(slip, "thickness", "mean")
        dx, ts = row["slip_distance"], _get(doc, "slips", "slip_duration", "mean")
        if d and dx and ts:
            eta, eta_err = _get(slip, "eta_eff", "mean"), _get(slip, "eta_eff", "stderr")
            rate, source = dx / ts / d, "from_slip"
    row.update(eta_eff=finite_or_none(eta), eta_eff_stderr=finite_or_none(eta_err), shear_rate=finite_or_none(rate),
               eta_source=source, run_dir=str(run_dir.resolve()))
    return row


def eta_points(rows: list[dict]) -> list[dict]:
    """Points with a positive η_eff and γ̇; a stuck wall has no shear rate to speak of."""
    return [r for r in rows if r["eta_eff"] and r["shear_rate"] and r["eta_eff"] > 0
            and r["shear_rate"] > 0 and r["sweep_regime"] != STUCK]


def group_key(row: dict, keys: list[str]) -> tuple:
    """A point's values of the grid ``keys`` (the group it is compared within)."""
    return tuple(row[f"grid.{k}"] for k in keys)


def reduced_model_boundary(calibration: dict, stiffnesses, mass: float,
                           mount_damping: float) -> dict:
    """The calibrated spring-block model's stick-slip boundary V_c(K).

    The calibrated film is Coulomb (static F_s, kinetic F_k) plus a viscous
    B, on the MD's wall mass M and mount dashpot d = γ·M; its V_c(K) is
    :func:`filmfriction.reduced_model.maps.coulomb_critical_velocity` with
    d + B and F_s − F_k averaged over the runs.

    Parameters
    ----------
    calibration : dict
        A ``calibration.json`` document (``filmfriction.analysis.calibration.calibrate``); the runs
        with F_s, F_k and B are averaged.
    stiffnesses : array_like
        K values (ε/σ²).
    mass, mount_damping : float
        M (m) and d = γ·M (m/τ).

    Returns
    -------
    dict
        ``stiffness``, ``velocity`` lists and the parameters used.
    """
    from filmfriction.reduced_model.maps import coulomb_critical_velocity

    def values(name):
        out = []
        for r in calibration.get("runs", []):
            e = r.get(name) or {}
            if e.get("value") is not None:
                out.append(float(e["value"]))
        return out

    fs, fk, b = values("static_force"), values("kinetic_force"), values("film_damping")
    if not (fs and fk and b):
        raise ValueError("the calibration has no run with static_force, kinetic_force and "
                         "film_damping (a stick-slip run with fitted slips is needed)")
    drop = float(np.mean(fs) - np.mean(fk))
    damping = mount_damping + float(np.mean(b))
    k = np.asarray(stiffnesses, float)
    vc = coulomb_critical_velocity(drop, damping, k, mass)
    return {"stiffness": k.tolist(), "velocity": vc.tolist(), "force_drop": drop,
            "damping": damping, "mass": mass,
            "model": "Coulomb(F_s, F_k) + viscous B + mount dashpot; V_c = (F_s - F_k) / "
                     "(lambda_c(zeta) sqrt(K M)), zeta = (d + B) / (2 sqrt(K M))"}


CSV_COLUMNS = ("point", "drive_velocity", "spring_constant", "normal_pressure", "temperature",
               "film_layers", "seed", "regime", "sweep_regime", "wall_velocity_ratio", "slips",
               "static_force", "static_force_stderr", "backward_force", "backward_force_stderr", "mean_force", "mean_force_stderr",
               "period", "period_stderr", "eta_eff", "eta_eff_stderr", "shear_rate",
               "eta_source", "run_dir")


def build_aggregate(sweep_dir: Path) -> tuple[dict, list[dict]]:
    """Combine every point of a finished sweep (nothing written).

    The figures (:mod:`.sweep_figures`) and :func:`write_aggregate` take the
    result; :func:`filmfriction.workflows.sweep.aggregate` chains the three.

    Returns
    -------
    (dict, list of dict)
        The ``aggregate.json`` document (schema ``filmfriction.sweep-aggregate/1``):
        ``points`` (one row per point: parameters, ``regime`` from the analysis and
        ``sweep_regime`` — ``unresolved`` when the run was too short to tell —, static
        and mean spring force ± standard error, η_eff at its shear rate),
        ``critical_velocity`` (one :class:`CriticalVelocity` per group of the other swept
        keys), ``power_law`` (η_eff = c·γ̇^α, or None with the reason in ``notes``),
        ``reduced_model_boundary`` (or None), ``calibration_runs``, ``run_dirs``,
        and ``notes``; and the per-point rows of ``aggregate.csv``.
    """
    from filmfriction.analysis.viscosity import power_law_fit

    sweep_dir = Path(sweep_dir)
    plan = json.loads((sweep_dir / SWEEP_FILE).read_text())
    rows = [point_summary(sweep_dir, p) for p in plan["points"]]
    keys = [a["key"] for a in plan["grid"]]
    doc: dict = {"schema": AGGREGATE_SCHEMA, "units": "lj", "scene": plan["scene"],
                 "grid": plan["grid"], "fixed": plan["fixed"], "np": plan["np"],
                 "points": rows, "notes": []}
    # critical velocity, per group of the other swept keys (seeds are repeats)
    group_keys = [k for k in keys if k not in ("drive_velocity", "seed")]
    crit = []
    if "drive_velocity" in keys:
        groups: dict = {}
        for r in rows:
            groups.setdefault(group_key(r, group_keys), []).append(r)
        for g, members in groups.items():
            cv = critical_velocity([r["drive_velocity"] for r in members],
                                   [r["sweep_regime"] for r in members])
            crit.append({"group": dict(zip(group_keys, g)), **cv.as_dict()})
    else:
        doc["notes"].append("drive_velocity is not swept: no critical velocity")
    doc["critical_velocity"] = crit
    # η_eff vs γ̇ across runs
    pts = eta_points(rows)
    # one definition at a time: steady sliding, (F/A)/(V/D), when it has enough points;
    # the slip fits measure a different rate (the slip's) and scatter much more
    steady = [r for r in pts if r["eta_source"] == "steady"]
    if len(steady) >= 3:
        pts, used = steady, "steady sliding points only"
    else:
        used = "steady sliding and slip fits"
    law = None
    try:
        errs = [r["eta_eff_stderr"] for r in pts]
        use_err = all(e is not None and e > 0 for e in errs)
        fit = power_law_fit([r["shear_rate"] for r in pts], [r["eta_eff"] for r in pts],
                            errs if use_err else None)
        law = {"exponent": fit.exponent, "exponent_stderr": fit.exponent_stderr,
               "prefactor": fit.prefactor, "prefactor_rel_stderr": fit.prefactor_rel_stderr,
               "n": fit.n, "weighted": use_err, "points": used,
               "form": "eta_eff = prefactor * shear_rate**exponent"}
    except (ValueError, RuntimeError) as exc:
        doc["notes"].append(f"no power-law fit of eta_eff vs shear rate: {exc}")
    doc["power_law"] = law
    # the reduced model's boundary on the (V, K) map
    boundary = None
    vk = "drive_velocity" in keys and "spring_constant" in keys
    if vk and plan.get("calibration"):
        try:
            cal = json.loads(Path(plan["calibration"]).read_text())
            ks = sorted({r["spring_constant"] for r in rows})
            kk = np.geomspace(min(ks), max(ks), 40) if len(ks) > 1 else np.array(ks)
            masses = {r["wall_mass"] for r in rows}
            gammas = {r["mount_damping"] for r in rows}
            if len(masses) > 1 or len(gammas) > 1:
                raise ValueError("wall_mass or mount_damping varies across points")
            m, g = masses.pop(), gammas.pop()
            boundary = {"calibration": plan["calibration"],
                        **reduced_model_boundary(cal, kk, m, g * m)}
        except (OSError, ValueError, KeyError, ImportError) as exc:
            doc["notes"].append(f"no reduced-model boundary: {exc}")
    elif vk:
        doc["notes"].append("no reduced-model boundary on the (V, K) map: no --calibration given")
    doc["reduced_model_boundary"] = boundary
    # what the calibration takes: runs with slips to fit
    doc["calibration_runs"] = [r["run_dir"] for r in rows if r["regime"] == STICK_SLIP]
    doc["run_dirs"] = [r["run_dir"] for r in rows]
    doc["outputs"] = ["aggregate.json", "aggregate.csv"]
    doc["provenance"] = provenance({f"{Path(r['run_dir']).name} {ANALYSIS_FILE}":
                                    Path(r["run_dir"]) / ANALYSIS_FILE for r in rows})
    return doc, rows


def write_aggregate(sweep_dir: Path, doc: dict, rows: list[dict]) -> dict:
    """Write ``aggregate.csv`` and ``aggregate.json`` atomically; returns the document."""
    sweep_dir = Path(sweep_dir)
    write_atomic(sweep_dir / "aggregate.csv", _csv(rows).encode())
    write_atomic(sweep_dir / AGGREGATE_FILE, json_text(json_safe(doc)).encode())
    return doc


def _csv(rows: list[dict]) -> str:
    grid_cols = [k for k in rows[0] if k.startswith("grid.")] if rows else []
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    cols = list(CSV_COLUMNS[:1]) + grid_cols + list(CSV_COLUMNS[1:])
    w.writerow(cols)
    for r in rows:
        w.writerow(["" if r.get(c) is None else r.get(c) for c in cols])
    return buf.getvalue()




# ---------------------------------------------------------------------------
# reading a sweep (report, calibration)
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Aggregate:
    """A finished sweep, as the report and the calibration read it.

    Attributes
    ----------
    sweep_dir : Path
    doc : dict
        ``aggregate.json``.
    run_dirs : tuple of Path
        Every point's run directory, in grid order.
    calibration_runs : tuple of Path
        The stick-slip points (slips to fit), for ``filmfriction.analysis.calibrate``.
    figures : dict
        ``velocity_map`` / ``vk_map`` → Path, for those written.
    """

    sweep_dir: Path
    doc: dict = field(hash=False)
    run_dirs: tuple = ()
    calibration_runs: tuple = ()
    figures: dict = field(default_factory=dict, hash=False)

    @property
    def points(self) -> list:
        return self.doc["points"]

    @property
    def critical_velocity(self) -> list:
        return self.doc["critical_velocity"]

    @property
    def power_law(self) -> dict | None:
        return self.doc["power_law"]


def load_aggregate(sweep_dir) -> Aggregate:
    """Read a finished sweep's ``aggregate.json``.

    Raises
    ------
    FileNotFoundError
        The sweep has not finished (no ``aggregate.json``).
    """
    sweep_dir = Path(sweep_dir)
    path = sweep_dir / AGGREGATE_FILE
    if not path.exists():
        raise FileNotFoundError(f"{path}: no aggregate; run (or resume) the sweep first")
    doc = json.loads(path.read_text())
    figures = {name: sweep_dir / f"{name}.png" for name in ("velocity_map", "vk_map")
               if (sweep_dir / f"{name}.png").exists()}
    return Aggregate(sweep_dir=sweep_dir, doc=doc,
                     run_dirs=tuple(Path(p) for p in doc["run_dirs"]),
                     calibration_runs=tuple(Path(p) for p in doc["calibration_runs"]),
                     figures=figures)


