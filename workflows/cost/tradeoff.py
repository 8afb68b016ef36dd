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

from filmfriction.analysis.files.util import json_safe, write_atomic
from filmfriction.md_inputs.contract import LOG_FILE, RUN_FILE

from ..md.scenes.parameters import WCA_CUTOFF as WCA
from .tradeoff_figures import plot
from .tradeoff_reduced import reduced_rows
from .tradeoff_table import (EXTENSIVE, Measurement, combine, compare, drift, value_and_error,
                             write_csv)

SCENE = "stick-slip"


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
    from ..md.scenes.parameters import PARAMETERS

    dt0 = base.get("timestep", PARAMETERS["timestep"].default)
    ratio = dt0 / dt
    out = {"timestep": dt}
    for key in ("equilibrate_steps", "slide_steps", "trace_every"):
        steps = base.get(key, PARAMETERS[key].default)
        out[key] = max(1, int(round(steps * ratio)))
    return out


def box_overrides(base: dict, cells: tuple[int, int]) -> dict:
    """Overrides for a lateral box: K and M scale with the area (same drive per area)."""
    from ..md.scenes.parameters import PARAMETERS

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
    from filmfriction.analysis.energy.ledger import LEDGER_COLUMNS, ledger
    from filmfriction.analysis.analyze import analyze
    from filmfriction.analysis.files.trace_reader import read_trace

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
        "static_force": value_and_error(slips["static_force"]),
        "slip_distance": value_and_error(slips["slip_distance"]),
        "period": value_and_error(slips["period"]),
        "eta_eff": value_and_error(doc["viscosity"].get("from_slip", {}).get("eta_eff")),
    }
    led = ledger({c: trace.columns[c] for c in LEDGER_COLUMNS + ("mount_heat",)
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


def _seeded(params: dict, k: int) -> dict:
    """The scene's parameters for the k-th seed of a setting (k = 0: as they are)."""
    if k == 0:
        return params
    from ..md.scenes.parameters import PARAMETERS

    return {**params, "seed": int(params.get("seed", PARAMETERS["seed"].default)) + k}


def _dirname(label: str) -> str:
    return label.replace("=", "-").replace(" ", "-")


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


