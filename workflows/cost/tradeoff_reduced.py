"""The reduced model's rows of the trade study: the same stick-slip block integrated
by each route (closed form, event-driven ODE, fixed-step RK45), cost and error against
the closed form."""
from __future__ import annotations

import math
import time

import numpy as np

from .tradeoff_table import Measurement, compare


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
    from filmfriction.reduced_model.cycles import cycle_table

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
