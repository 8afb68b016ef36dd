"""The speed–accuracy trade: what each numerical knob costs and what it changes.

``filmfriction tradeoff [--quick] [--json] [--out DIR]`` runs the stick-slip
scene once per knob setting, one knob at a time around a *base* setting, and
compares the observables with a *reference* value of the same knob (the most
accurate one tried: the smallest timestep, the longest cutoff, the largest
box, the finest trace, the longest run).  Each error carries the statistical
uncertainty of the two runs combined, ``sqrt(se_setting**2 + se_reference**2)``,
so a difference smaller than about twice that is noise, not bias.

Knobs
-----
MD: ``timestep`` (step counts rescaled so the simulated time stays the same),
``cutoff`` (WCA 2^(1/6), 2.5, 3.5 sigma), ``box`` (``cells_x x cells_y``, with
the spring constant and wall mass scaled with the area so that the drive per
area, hence the slip distance and the period, stay the same),
``thermostat_damping``, ``trace_every`` (the output interval), ``run_length``
(prefixes of the base run: the first 1/4, 1/2 of the slide; a shorter run with
the same seed is exactly such a prefix), ``wall_model`` (rigid walls against
flexible walls whose film-facing planes are an LJ crystal; reference:
flexible) and, full study only, ``thermostat_placement`` on flexible walls
(the film along y, the walls, both; reference: the walls, where an
experiment's heat goes).  Reduced model: ``reduced_integrator`` (closed
form, the ODE path at several tolerances, a plain ``solve_ivp`` RK45).

Observables (``error_<name>`` in the rows): ``static_force`` (mean Fs;
extensive, so scaled to the base box's area), ``slip_distance``, ``period``,
``eta_eff`` (from the slip fits), ``ledger_closure`` (|residual|/input work)
and ``energy_drift`` (slope of the energy-ledger residual, the integrator's
non-conservation, ε/τ scaled to the base area).

Cost: wall seconds of the run (``cost_seconds``), per τ simulated and per slip
cycle, atom-steps/s from ``run.json``, the peak resident memory of the LAMMPS
processes (``getrusage(RUSAGE_CHILDREN)`` of a forked child that runs only
that setting) and LAMMPS's own per-rank allocation estimate.

The wall-model and placement rows measure a change of the model, not only of
its numerics: their "errors" are what the cheaper model changes in the answer.
"""
from __future__ import annotations

import csv
import io
import json
import math
import multiprocessing
import re
import resource
import time
import traceback
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from filmfriction.analysis.util import json_safe, write_atomic
from filmfriction.md_inputs.contract import LOG_FILE, RUN_FILE

from ..md.scene import WCA_CUTOFF as WCA

SCENE = "stick-slip"

# name -> unit; the order is the order of the table's columns
OBSERVABLES = {
    "static_force": "epsilon/sigma",
    "slip_distance": "sigma",
    "period": "tau",
    "eta_eff": "epsilon tau/sigma^3",
    "ledger_closure": "1",
    "energy_drift": "epsilon/tau",
}
# observables whose value grows with the contact area: scaled to the base area
EXTENSIVE = {"static_force", "energy_drift"}
COST_FIELDS = ("cost_seconds", "cost_seconds_per_tau", "cost_seconds_per_cycle",
               "atom_steps_per_second", "memory_peak_rss_mb", "memory_lammps_mb_per_rank",
               "atoms", "steps", "simulated_tau", "cycles")


# ----------------------------------------------------------------- the plan
@dataclass(frozen=True)
class Setting:
    """One row of the study: a knob at one value.

    Attributes
    ----------
    knob, value : str
        What is varied and its value as printed (``"0.005"``, ``"7x4"``).
    overrides : dict
        Scene parameters that differ from the base (applied on top of it).
    reference : bool
        This is the knob's reference value: its errors are zero by definition.
    prefix : float
        For ``run_length``: the fraction of the base run's slide analysed.
    """

    knob: str
    value: str
    overrides: dict = field(default_factory=dict, hash=False)
    reference: bool = False
    prefix: float = 1.0


@dataclass(frozen=True)
class Plan:
    """The base setting and the rows of a study."""

    base: dict = field(hash=False)
    settings: tuple
    description: str


# Quick study: the default scene (616 atoms; 8 slips in 500 tau) cut to 300 tau
# of slide (5 slips, the first left out) and a shorter equilibration.  A smaller
# box is not a quicker answer: at 5 x 3 cells the slips turn irregular after
# ~100 tau, with K and M scaled by the area or not, and the analysis then finds
# no periodic slips to average (measured).
QUICK_BASE = {"equilibrate_steps": 5000, "slide_steps": 60000, "restart_every": 0}
# Full study: the default scene as shipped, 400 tau of slide (7 slips).
FULL_BASE = {"slide_steps": 80000, "restart_every": 0}


def timestep_overrides(base: dict, dt: float) -> dict:
    """Overrides for a timestep: step counts rescaled to keep the simulated times."""
    from ..md.scene import PARAMETERS

    dt0 = base.get("timestep", PARAMETERS["timestep"].default)
    ratio = dt0 / dt
    out = {"timestep": dt}
    for key in ("equilibrate_steps", "slide_steps", "trace_every"):
        steps = base.get(key, PARAMETERS[key].default)
        out[key] = max(1, int(round(steps * ratio)))
    return out


def box_overrides(base: dict, cells: tuple[int, int]) -> dict:
    """Overrides for a lateral box: K and M scale with the area (same drive per area)."""
    from ..md.scene import PARAMETERS

    def get(key):
        return base.get(key, PARAMETERS[key].default)

    ratio = cells[0] * cells[1] / (get("cells_x") * get("cells_y"))
    return {"cells_x": cells[0], "cells_y": cells[1],
            "spring_constant": get("spring_constant") * ratio,
            "wall_mass": get("wall_mass") * ratio}


def plan(quick: bool) -> Plan:
    """The settings of the quick or the full study."""
    base = dict(QUICK_BASE if quick else FULL_BASE)
    rows: list[Setting] = []

    def add(knob, value, overrides, reference=False, prefix=1.0):
        rows.append(Setting(knob, value, overrides, reference, prefix))

    # timestep: the reference is the smallest step tried
    dts = (0.004, 0.005, 0.008) if quick else (0.0025, 0.004, 0.005, 0.0075, 0.01)
    for dt in dts:
        add("timestep", f"{dt:g}", timestep_overrides(base, dt), reference=dt == min(dts))
    # cutoff: a 3.5 sigma cutoff needs a box of at least 7 sigma (the default's)
    cuts = (WCA, 2.5) if quick else (WCA, 2.5, 3.5)
    for rc in cuts:
        add("cutoff", "wca" if rc == WCA else f"{rc:g}", {"cutoff": rc},
            reference=rc == max(cuts))
    if not quick:
        for cells in ((5, 3), (7, 4), (10, 6)):
            add("box", f"{cells[0]}x{cells[1]}", box_overrides(base, cells),
                reference=cells == (10, 6))
    # thermostat damping: no 'exact' value exists; the default is the reference
    # and the rows measure the sensitivity of the answer to it
    for tdamp in ((1.0, 0.25) if quick else (0.25, 1.0, 4.0)):
        add("thermostat_damping", f"{tdamp:g}", {"thermostat_damping": tdamp},
            reference=tdamp == 1.0)
    traces = (50, 250) if quick else (10, 50, 250)
    for every in traces:
        add("trace_every", str(every), {"trace_every": every}, reference=every == min(traces))
    for model in ("rigid", "flexible"):
        add("wall_model", model, {"wall_model": model}, reference=model == "flexible")
    if not quick:
        for where in ("film", "walls", "both"):
            add("thermostat_placement", where,
                {"wall_model": "flexible", "thermostat_placement": where},
                reference=where == "walls")
    for frac in (0.25, 0.5, 1.0):
        add("run_length", f"{frac:g}", {}, reference=frac == 1.0, prefix=frac)
    text = ("quick: the default stick-slip scene, 300 tau of slide" if quick else
            "full: the default stick-slip scene, 400 tau of slide")
    return Plan(base=base, settings=tuple(rows), description=text)


def _key(overrides: dict) -> str:
    """Identity of a setting: its resolved parameters (a default given explicitly is no change)."""
    from ..md.scene import load

    return json.dumps(sorted(load(SCENE, overrides).parameters.items()))


# ----------------------------------------------------------------- running
@dataclass(frozen=True)
class RunCost:
    """What one MD run cost."""

    run_dir: Path
    wall_seconds: float
    atom_steps_per_second: float
    atoms: int
    steps: int
    simulated_tau: float
    slide_tau: float
    equilibrate_seconds_fraction: float
    peak_rss_mb: float
    lammps_mb_per_rank: float


_MEMORY = re.compile(r"Per MPI rank memory allocation \(min/avg/max\) = "
                     r"[0-9.eE+-]+ \| [0-9.eE+-]+ \| ([0-9.eE+-]+) Mbytes")


def _child_run(scene_name, overrides, out, nprocs, queue):
    """Body of the forked child: one run, then the children's peak RSS."""
    try:
        from ..md.runner import execute
        from ..md.scene import load

        scene = load(scene_name, overrides)
        run_dir = execute(scene, out=out, nprocs=nprocs, progress=False)
        # ru_maxrss of RUSAGE_CHILDREN: the largest reaped descendant (an lmp
        # rank); the counter starts at zero in a freshly forked process
        rss_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        queue.put(("ok", str(run_dir), rss_kb))
    except BaseException as exc:  # noqa: BLE001 -- reported to the parent
        queue.put(("error", f"{type(exc).__name__}: {exc}", traceback.format_exc()))


def run_setting(overrides: dict, out: Path, nprocs: int = 2,
                scene_name: str = SCENE) -> RunCost:
    """Run one setting in a forked child and measure its cost.

    Raises
    ------
    RuntimeError
        The run failed; the message is the runner's.
    """
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    proc = ctx.Process(target=_child_run, args=(scene_name, overrides, out, nprocs, queue))
    proc.start()
    result = queue.get()
    proc.join()
    if result[0] != "ok":
        raise RuntimeError(f"setting {overrides}: {result[1]}")
    run_dir = Path(result[1])
    record = json.loads((run_dir / RUN_FILE).read_text())
    p = record["scene"]["parameters"]
    steps = p["equilibrate_steps"] + p["slide_steps"]
    memory = [float(m.group(1)) for m in _MEMORY.finditer(
        (run_dir / LOG_FILE).read_text(errors="replace"))]
    wall = float(record["wall_time"])
    rate = float(record.get("atom_steps_per_second") or math.nan)
    atoms = int(record["atoms"]["total"])
    return RunCost(run_dir=run_dir, wall_seconds=wall, atom_steps_per_second=rate, atoms=atoms,
                   steps=steps, simulated_tau=steps * p["timestep"],
                   slide_tau=p["slide_steps"] * p["timestep"],
                   equilibrate_seconds_fraction=p["equilibrate_steps"] / steps,
                   peak_rss_mb=result[2] / 1024.0,
                   lammps_mb_per_rank=max(memory) if memory else math.nan)


# ----------------------------------------------------------------- measuring
@dataclass(frozen=True)
class Measurement:
    """Observables of one setting: name -> (mean, standard error)."""

    values: dict
    cycles: int
    regime: str
    area: float


def _pair(entry) -> tuple[float, float]:
    if not entry:
        return math.nan, math.nan
    mean, se = entry.get("mean"), entry.get("stderr")
    return (math.nan if mean is None else float(mean)), (math.nan if se is None else float(se))


def drift(time_, residual, blocks: int = 5) -> tuple[float, float]:
    """Slope of the ledger residual with its standard error from block slopes.

    Parameters
    ----------
    time_, residual : array
        Time and the cumulative ledger residual (zero at the start).
    blocks : int
        Equal-time blocks; the spread of their mean slopes gives the error.

    Returns
    -------
    (slope, stderr) : tuple of float
    """
    t = np.asarray(time_, float)
    r = np.asarray(residual, float)
    if t.size < 2 or t[-1] <= t[0]:
        return math.nan, math.nan
    slope = (r[-1] - r[0]) / (t[-1] - t[0])
    edges = np.linspace(t[0], t[-1], blocks + 1)
    idx = np.searchsorted(t, edges)
    idx[-1] = t.size - 1
    slopes = [(r[b] - r[a]) / (t[b] - t[a]) for a, b in zip(idx[:-1], idx[1:]) if t[b] > t[a]]
    se = float(np.std(slopes, ddof=1) / math.sqrt(len(slopes))) if len(slopes) > 1 else math.nan
    return float(slope), se


def measure(run_dir: Path, *, area_ref: float | None = None, prefix: float = 1.0,
            trace_stride: int = 1) -> Measurement:
    """Analyse a run (or the first ``prefix`` of it) into the study's observables.

    Parameters
    ----------
    run_dir : Path
    area_ref : float, optional
        Area the extensive observables are scaled to (default: the run's own).
    prefix : float
        Fraction of the slide to analyse (a shorter run with the same seed).
    trace_stride : int
        Keep every n-th trace row (a coarser ``trace_every``).
    """
    from filmfriction.analysis import energy
    from filmfriction.analysis.analyze import analyze
    from filmfriction.analysis.trace import read_trace

    trace = read_trace(run_dir)
    if prefix < 1.0 or trace_stride > 1:
        t = trace.time
        keep = np.flatnonzero(t <= t[0] + prefix * (t[-1] - t[0]))[::trace_stride]
        trace = replace(trace, columns={k: v[keep] for k, v in trace.columns.items()})
    doc, _ = analyze(trace, structure=False)
    area = float(trace.parameters.area)
    scale = (area_ref / area) if area_ref else 1.0
    slips = doc["slips"]
    values = {
        "static_force": _pair(slips["static_force"]),
        "slip_distance": _pair(slips["slip_distance"]),
        "period": _pair(slips["period"]),
        "eta_eff": _pair(doc["viscosity"].get("from_slip", {}).get("eta_eff")),
    }
    led = energy.ledger({c: trace.columns[c] for c in energy.LEDGER_COLUMNS + ("mount_heat",)
                         if trace.has(c)})
    slope, slope_se = drift(trace.time, led["residual"])
    duration = float(trace.time[-1] - trace.time[0])
    values["ledger_closure"] = (led["closure"],
                                abs(slope_se * duration / led["input"]) if led["input"]
                                else math.nan)
    values["energy_drift"] = (slope, slope_se)
    values = {k: ((m * scale, s * scale) if k in EXTENSIVE else (m, s))
              for k, (m, s) in values.items()}
    return Measurement(values=values, cycles=int(slips["count"]), regime=doc["regime"],
                       area=area)


def combine(measurements: list[Measurement]) -> Measurement:
    """One setting's runs with different seeds as one measurement: each observable's mean
    over the runs, with the standard error of that mean over the runs (the runs' own
    standard errors for a single run).  Cycles add up; the regime is the runs' regimes."""
    if len(measurements) == 1:
        return measurements[0]
    values = {}
    for name in measurements[0].values:
        means = np.array([m.values[name][0] for m in measurements], float)
        ok = means[np.isfinite(means)]
        values[name] = ((float(ok.mean()), float(ok.std(ddof=1) / math.sqrt(ok.size)))
                        if ok.size > 1 else
                        (float(ok[0]) if ok.size else math.nan, math.nan))
    regimes = sorted({m.regime for m in measurements})
    return Measurement(values=values, cycles=sum(m.cycles for m in measurements),
                       regime=regimes[0] if len(regimes) == 1 else "mixed: " + ", ".join(regimes),
                       area=measurements[0].area)


def _seeded(params: dict, k: int) -> dict:
    """The scene's parameters for the k-th seed of a setting (k = 0: as they are)."""
    if k == 0:
        return params
    from ..md.scene import PARAMETERS

    return {**params, "seed": int(params.get("seed", PARAMETERS["seed"].default)) + k}


def _dirname(label: str) -> str:
    return label.replace("=", "-").replace(" ", "-")


def compare(setting: Measurement, reference: Measurement, is_reference: bool) -> dict:
    """``error_<obs>`` = setting − reference with ``error_<obs>_uncertainty``.

    The uncertainty combines both standard errors in quadrature; for a run
    compared with itself both are zero.  A missing standard error (fewer
    than two cycles) gives a NaN uncertainty: the error is then not tested.
    """
    row = {}
    for name in OBSERVABLES:
        m, s = setting.values[name]
        mr, sr = reference.values[name]
        row[f"value_{name}"] = m
        if is_reference:
            row[f"error_{name}"], row[f"error_{name}_uncertainty"] = 0.0, 0.0
        else:
            row[f"error_{name}"] = m - mr
            row[f"error_{name}_uncertainty"] = math.hypot(s, sr)
    return row


# ----------------------------------------------------------------- the reduced model
# The reduced model stands in for the default MD run: M, K and V of the default
# scene, Coulomb friction with the measured Fs and a kinetic force (Fs + Fb)/2,
# so that an undamped slip re-sticks at the measured Fb = 2 Fk - Fs; a light
# viscous term (damping ratio 0.045) keeps the slip dynamics non-trivial.  The
# MD mount dashpot acts on v - V and has no counterpart in SpringBlock's
# ground damper, so it is left out.  1100 tau hold 24 cycles.
REDUCED = {"mass": 500.0, "stiffness": 100.0, "drive_velocity": 0.02, "damping": 0.0,
           "static": 98.7, "kinetic": 61.2, "viscous": 20.0, "duration": 1100.0}
#: the knob of the reduced model's rows
REDUCED_KNOB = "reduced_integrator"


def _reduced_block():
    from filmfriction.reduced_model import SpringBlock, laws

    r = REDUCED
    return SpringBlock(mass=r["mass"], stiffness=r["stiffness"],
                       drive_velocity=r["drive_velocity"], damping=r["damping"],
                       law=laws.Coulomb(static=r["static"], kinetic=r["kinetic"],
                                        viscous=r["viscous"]))


def _reduced_measure(t, f, x, yields, sticks) -> dict:
    from filmfriction.analysis.stickslip import cycle_table

    table = cycle_table(t, f, yields, sticks, spring_constant=REDUCED["stiffness"],
                        wall_position=x)
    summ = table.summary(skip=1)
    out = {}
    for name in ("static_force", "slip_distance", "period"):
        s = summ[name]
        out[name] = (float(s["mean"]), 0.0)  # deterministic: no sampling error
    return out


def reduced_rows(repeat: int = 3) -> list[dict]:
    """Cost and error of the reduced model's integrators against the closed form.

    The closed form and the event-driven ODE path at several tolerances
    (:meth:`SpringBlock.simulate <filmfriction.reduced_model.SpringBlock.simulate>`), and a
    plain ``solve_ivp`` RK45 loop as a user writes it
    (:func:`filmfriction.reduced_model.integrators.rk45.rk45_stick_slip`).
    """
    from filmfriction.reduced_model.integrators.rk45 import rk45_stick_slip

    block = _reduced_block()
    T = REDUCED["duration"]
    variants = [("closed_form", {"method": "closed_form"}),
                ("ode_rtol_1e-4", {"method": "ode", "rtol": 1e-4}),
                ("ode_rtol_1e-7", {"method": "ode", "rtol": 1e-7}),
                ("ode_rtol_1e-10", {"method": "ode", "rtol": 1e-10}),
                ("solve_ivp_rk45_rtol_1e-3", {"rk45": 1e-3}),
                ("solve_ivp_rk45_rtol_1e-6", {"rk45": 1e-6}),
                ("solve_ivp_rk45_rtol_1e-9", {"rk45": 1e-9})]
    results = {}
    for label, kw in variants:
        best = math.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            if "rk45" in kw:
                t, f, x, kinds = rk45_stick_slip(block, T, rtol=kw["rk45"])
                yi = np.array([i for i, k in enumerate(kinds) if k == "slip"])
                si = np.array([i for i, k in enumerate(kinds) if k == "stick"])
                n = min(len(yi), len(si))
                values = _reduced_measure(t, f, x, yi[:n], si[:n])
                values["ledger_closure"] = (math.nan, math.nan)
            else:
                res = block.simulate(T, **kw)
                yi, si = res.slip_pairs()
                values = _reduced_measure(res.t, res.spring_force, res.x, yi, si)
                values["ledger_closure"] = (float(res.energy.closure), 0.0)
            best = min(best, time.perf_counter() - t0)
        values["eta_eff"] = (math.nan, math.nan)
        values["energy_drift"] = (math.nan, math.nan)
        results[label] = (Measurement(values, len(yi), "stick-slip", 1.0), best)
    ref = results["closed_form"][0]
    rows = []
    for label, (meas, seconds) in results.items():
        row = {"knob": REDUCED_KNOB, "value": label, "reference": label == "closed_form",
               "cost_seconds": seconds, "cost_seconds_per_tau": seconds / T,
               "cost_seconds_per_cycle": seconds / T * meas.values["period"][0],
               "atom_steps_per_second": math.nan, "memory_peak_rss_mb": math.nan,
               "memory_lammps_mb_per_rank": math.nan, "atoms": 1, "steps": math.nan,
               "simulated_tau": T, "cycles": meas.cycles, "regime": meas.regime}
        row.update(compare(meas, ref, label == "closed_form"))
        # ledger closure is the model's own check, not a difference: report it as is
        row["error_ledger_closure"] = meas.values["ledger_closure"][0]
        row["error_ledger_closure_uncertainty"] = 0.0
        rows.append(row)
    return rows


# ----------------------------------------------------------------- the study
def _atom_steps(overrides: dict) -> float:
    """Atoms times steps of a setting, from the scene alone (for the ETA)."""
    from ..md.scene import load

    scene = load(SCENE, overrides)
    p, q = scene.parameters, scene.derived()
    atoms = q["film_atoms"] + 2 * q["wall_layers"] * q["wall_atoms_per_layer"]
    return float(atoms * (p["equilibrate_steps"] + p["slide_steps"]))


def md_rows(study: Plan, out: Path, nprocs: int = 2, log=print, seeds: int = 1) -> list[dict]:
    """Run every MD setting of ``study`` (each distinct scene once per seed) and tabulate.

    With ``seeds`` > 1 each setting also runs with the seeds following the scene's
    (``seed`` + 1, ...); its observables are then the mean over the runs, with the
    standard error of that mean over the runs (:func:`combine`), so that an error
    includes the run-to-run scatter of a chaotic trajectory."""
    runs: dict[str, RunCost] = {}
    failed: dict[str, str] = {}
    # each setting's runs, one per seed; a scene shared by settings runs once
    keys, todo = {}, {}
    for s in study.settings:
        keys[(s.knob, s.value)] = []
        for k in range(seeds):
            params = _seeded({**study.base, **s.overrides}, k)
            key = _key(params)
            keys[(s.knob, s.value)].append(key)
            todo.setdefault(key, (key, s, k, params))
    todo = list(todo.values())
    work = [_atom_steps(params) for *_, params in todo]
    started, done = time.perf_counter(), 0.0
    for i, (key, s, k, params) in enumerate(todo, 1):
        label = (f"{s.knob}={s.value}" if s.overrides else "base") + (f" seed+{k}" if k else "")
        elapsed = time.perf_counter() - started
        # ETA from the atom-steps done so far: settings differ in atoms and steps
        eta = (f", about {elapsed / done * sum(work[i - 1:]) / 60:.0f} min left" if done
               else "")
        log(f"[{i}/{len(todo)}] {label} ({elapsed / 60:.1f} min elapsed{eta})")
        t0 = time.perf_counter()
        done += work[i - 1]
        try:
            runs[key] = run_setting(params, out / "runs" / f"{i:02d}-{_dirname(label)}", nprocs)
        except RuntimeError as exc:
            # one failed setting is a result (the knob is past its limit), not the end
            failed[key] = str(exc).splitlines()[0]
            log(f"    FAILED: {failed[key]}")
            continue
        log(f"    {time.perf_counter() - t0:.0f} s, "
            f"{runs[key].atom_steps_per_second:.3g} atom-steps/s")
    base_key = _key(study.base)
    if base_key not in runs:
        raise RuntimeError(f"the base run failed: {failed[base_key]}")
    area_ref = measure(runs[base_key].run_dir).area
    measured = {}
    for s in study.settings:
        done_keys = [key for key in keys[(s.knob, s.value)] if key in runs]
        if done_keys:
            measured[(s.knob, s.value)] = combine([measure(runs[key].run_dir, area_ref=area_ref,
                                                           prefix=s.prefix) for key in done_keys])
    rows = []
    for s in study.settings:
        ref = next(r for r in study.settings if r.knob == s.knob and r.reference)
        done_keys = [key for key in keys[(s.knob, s.value)] if key in runs]
        if not done_keys or (ref.knob, ref.value) not in measured:
            why = (next((failed[key] for key in keys[(s.knob, s.value)] if key in failed), None)
                   or f"its reference {ref.value} failed")
            rows.append({"knob": s.knob, "value": s.value, "reference": s.reference,
                         "regime": f"failed: {why}"})
            continue
        meas = measured[(s.knob, s.value)]
        cost = runs[done_keys[0]]
        # the cost of one run: the mean over the seeds (same scene, same work)
        seconds = float(np.mean([runs[key].wall_seconds for key in done_keys]))
        tau = cost.simulated_tau
        if s.prefix < 1.0:
            # a shorter run costs its share of the slide plus the whole equilibration
            f_eq = cost.equilibrate_seconds_fraction
            seconds *= f_eq + (1.0 - f_eq) * s.prefix
            tau = cost.simulated_tau - cost.slide_tau * (1.0 - s.prefix)
        period = meas.values["period"][0]
        row = {"knob": s.knob, "value": s.value, "reference": s.reference,
               "cost_seconds": seconds, "cost_seconds_per_tau": seconds / tau,
               "cost_seconds_per_cycle": seconds / tau * period if math.isfinite(period)
               else math.nan,
               "atom_steps_per_second": cost.atom_steps_per_second,
               "memory_peak_rss_mb": cost.peak_rss_mb,
               "memory_lammps_mb_per_rank": cost.lammps_mb_per_rank,
               "atoms": cost.atoms, "steps": cost.steps, "simulated_tau": tau,
               "cycles": meas.cycles, "regime": meas.regime, "seeds": len(done_keys)}
        row.update(compare(meas, measured[(ref.knob, ref.value)], s.reference))
        row["run_dir"] = str(cost.run_dir)
        rows.append(row)
    return rows


def columns() -> list[str]:
    cols = ["knob", "value", "reference", *COST_FIELDS, "regime", "seeds"]
    for name in OBSERVABLES:
        cols += [f"value_{name}", f"error_{name}", f"error_{name}_uncertainty"]
    return cols + ["run_dir"]


def write_csv(rows: list[dict], path: Path) -> Path:
    cols = columns()
    buf = io.StringIO(newline="")
    w = csv.DictWriter(buf, fieldnames=cols, extrasaction="ignore")
    w.writeheader()
    for row in rows:
        w.writerow({c: _fmt(row.get(c)) for c in cols})
    return write_atomic(path, buf.getvalue())


def _fmt(v):
    if isinstance(v, float):
        return "" if not math.isfinite(v) else f"{v:.6g}"
    return "" if v is None else v


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


def study(quick: bool, out: Path, nprocs: int = 2, log=print, seeds: int = 1) -> list[dict]:
    """Run the study; write ``tradeoff.csv``, ``tradeoff.json`` and the PNGs under ``out``."""
    out.mkdir(parents=True, exist_ok=False)
    p = plan(quick)
    log(f"tradeoff ({p.description}{f', {seeds} seeds per setting' if seeds > 1 else ''}); "
        f"output in {out}")
    rows = md_rows(p, out, nprocs, log, seeds) + reduced_rows()
    rows = json_safe(rows)
    write_csv(rows, out / "tradeoff.csv")
    write_atomic(out / "tradeoff.json", json.dumps(rows, indent=1, allow_nan=False) + "\n")
    plot([{k: (math.nan if v is None else v) for k, v in r.items()} for r in rows], out)
    return rows


def summary(rows: list[dict]) -> str:
    """A text table: cost and the relative error ± uncertainty of Fs, slip, period, eta."""
    head = f"{'knob':20s} {'value':26s} {'s':>7s} {'s/tau':>7s} {'MB':>6s}"
    names = ("static_force", "slip_distance", "period", "eta_eff", "energy_drift")
    head += "".join(f" {n[:12]:>19s}" for n in names)
    lines = [head]
    for r in rows:
        line = (f"{r['knob']:20s} {r['value'] + (' (ref)' if r['reference'] else ''):26s} "
                f"{_g(r.get('cost_seconds'), 7)} {_g(r.get('cost_seconds_per_tau'), 7)} "
                f"{_g(r.get('memory_peak_rss_mb'), 6)}")
        for n in names:
            e, u = r.get(f"error_{n}"), r.get(f"error_{n}_uncertainty")
            line += f" {_g(e, 9)}±{_g(u, 9, left=True)}"
        lines.append(line)
    return "\n".join(lines)


def _g(v, width, left=False):
    text = "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.3g}"
    return f"{text:<{width}s}" if left else f"{text:>{width}s}"
