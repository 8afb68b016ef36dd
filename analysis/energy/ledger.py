"""The energy ledger of an MD run: the work done on the film's box against what it
stores and the heat the thermostat and the mount's dashpot take out.

The one ledger of an MD run: the analysis reports it
(:mod:`filmfriction.analysis.observables.energy_section`), the energy partition
takes its residual cycle by cycle (:mod:`filmfriction.analysis.energy.partition`),
and the runner's sanity check fails a run whose residual is too large.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["LEDGER_COLUMNS", "ledger"]

# trace columns (md_inputs/contract.py) the ledger needs; mount_heat is optional
# (traces written before the mount dashpot lack it)
LEDGER_COLUMNS = ("drive_work", "load_work", "potential_energy",
                  "kinetic_energy", "spring_energy", "thermostat_heat")


def ledger(columns: dict) -> dict:
    """Energy ledger of an MD run.

    drive_work + load_work = Δ(potential + kinetic + spring) + thermostat_heat
    + mount_heat + residual  (``mount_heat``, the mount dashpot's heat, when the
    trace has it).

    The one ledger of an MD run: the analysis reports it, and the runner
    (``filmfriction.workflows.md.runner.ledger_problem``) fails a run whose
    residual exceeds a share of ``turnover``.

    Returns
    -------
    dict
        ``residual`` (array, cumulative, zero at the first sample),
        ``input`` (drive_work + load_work at the end, relative to the start),
        ``closure`` (|final residual| / |input|; NaN when no work was done),
        ``thermostat_heat`` and ``mount_heat`` (at the end, relative to the
        start), ``turnover`` (the energy turned over: the largest of |input|,
        |thermostat_heat + mount_heat| and the spring energy released, the most the
        spring's energy fell below its start: a wall let go from a stretched spring
        turns that over before any heat leaves).
    """
    c = {n: np.asarray(columns[n], float) for n in LEDGER_COLUMNS}
    work = c["drive_work"] + c["load_work"]
    stored = c["potential_energy"] + c["kinetic_energy"] + c["spring_energy"]
    heat = c["thermostat_heat"] - c["thermostat_heat"][0]
    mount = np.zeros_like(heat)
    if "mount_heat" in columns:
        mount = np.asarray(columns["mount_heat"], float)
        mount = mount - mount[0]
    residual = (work - work[0]) - (stored - stored[0]) - heat - mount
    total = float(work[-1] - work[0])
    closure = abs(float(residual[-1])) / abs(total) if total else math.nan
    spring = c["spring_energy"]
    released = float(np.max(spring[0] - spring))
    turnover = max(abs(total), abs(float(heat[-1] + mount[-1])), released)
    return {"residual": residual, "input": total, "closure": closure,
            "thermostat_heat": float(heat[-1]), "mount_heat": float(mount[-1]),
            "turnover": turnover}
