"""Checks of a run's output: the script's contract, lost atoms, NaN, the energy
ledger (a run fails), and the physical sanity of the trace (warnings)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from filmfriction.analysis.energy import ledger
from filmfriction.analysis.film_state import GAP_LAYER_CHANGE
from filmfriction.md_inputs import contract
from filmfriction.md_inputs.contract import DAT_COLUMNS, TRACE_DAT_FILE

from ..scene import Scene


# Largest energy-ledger residual accepted, as a fraction of the energy turned
# over (work in or heat out).  Validated runs stay below 1 % (the default run
# 0.2 %; the LJ-limit step, the highest load, the lightest wall 0.5-1 %); a
# timestep twice the LJ limit (validator bypassed) leaves 8-16 % while the
# thermostat keeps the temperature looking normal, so only the ledger shows it.
LEDGER_LIMIT = 0.05


def contract_problem(run_dir: Path, scene: Scene, rows: int = 4) -> tuple[str | None, int]:
    """The first break of the trace contract in ``trace.dat``'s first ``rows`` rows
    (None: none) and how many rows were there to check."""
    from itertools import islice

    path = run_dir / TRACE_DAT_FILE
    if not path.exists():
        return None, 0
    with open(path, encoding="utf-8", errors="replace") as fh:
        head = [ln for ln in islice(fh, 4 * rows + 8) if ln.strip()][:rows + 1]
    # a last line without its newline may still be being written
    complete = [ln for ln in head if ln.endswith("\n")]
    p = scene.parameters
    problem = contract.check_head(
        "".join(complete), timestep=p["timestep"], trace_every=p["trace_every"],
        drive_velocity=p["drive_velocity"], spring_constant=p["spring_constant"],
        temperature=p["temperature"], rows=rows)
    return problem, max(0, len(complete) - 1)


def contract_message(problem: str) -> str:
    return (f"the LAMMPS script's trace breaks the trace contract (md_inputs/contract.py: "
            f"columns and LJ units): {problem}")


def trace_problem(dat: np.ndarray, scene: Scene) -> str | None:
    """A blow-up the engine did not flag itself: NaN, runaway temperature, broken ledger."""
    if not len(dat):
        return None
    if not np.all(np.isfinite(dat)):
        row = int(np.argmax(~np.all(np.isfinite(dat), axis=1)))
        return f"NaN or infinite value in the trace at step {int(dat[row, 0])}"
    T = dat[:, DAT_COLUMNS.index("film_temperature")]
    limit = max(20.0 * scene.parameters["temperature"], 5.0)
    if np.any(T > limit):
        row = int(np.argmax(T > limit))
        return (f"film temperature {T[row]:.3g} epsilon/k_B at step {int(dat[row, 0])} exceeds "
                f"{limit:.3g}: the integration blew up (timestep too large for the forces?)")
    return ledger_problem(dat, scene)


def lost_atoms_hint(scene: Scene) -> str:
    """Why atoms leave the box, for the engine's bare "Lost atoms" message: the
    likely causes found in the actual parameters, most likely first."""
    from ..scenes.parameters import FLEXIBLE_WALL_MAX_TEMPERATURE, WCA_CUTOFF, derived_quantities

    p = scene.parameters
    d = derived_quantities(p)
    causes = []
    if p["cutoff"] <= WCA_CUTOFF * (1 + 1e-6):
        causes.append(f"cutoff {p['cutoff']:.4g} sigma is purely repulsive (WCA): with no "
                      f"wall-film attraction, normal_pressure {p['normal_pressure']:g} does not "
                      "hold the top wall")
    limit = d["timestep_limit"]
    if p["timestep"] > limit:
        causes.append(f"timestep {p['timestep']:g} tau is above the stability limit "
                      f"{limit:.3g} tau")
    elif p["timestep"] > 0.7 * limit:
        causes.append(f"timestep {p['timestep']:g} tau is close to the stability limit "
                      f"{limit:.3g} tau")
    mismatch = p["film_spacing"] / p["wall_spacing"] - 1.0
    strain = max(abs(d["film_strain_x"]), abs(d["film_strain_y"]))
    if p["film_spacing"] < 1.0 or abs(mismatch) > 0.1 or strain > 0.05:
        causes.append(f"film_spacing {p['film_spacing']:g} sigma against wall_spacing "
                      f"{p['wall_spacing']:g} sigma (mismatch {100 * mismatch:+.0f} %, film "
                      f"strained {100 * strain:.0f} %): overlapping atoms start with huge "
                      f"forces")
    if p["temperature"] > 1.3:
        causes.append(f"temperature {p['temperature']:g} epsilon/k_B is above the LJ "
                      f"critical temperature 1.3: the film boils and pushes the wall off")
    elif p["wall_model"] == "flexible" and p["temperature"] > 0.8 * FLEXIBLE_WALL_MAX_TEMPERATURE:
        causes.append(f"temperature {p['temperature']:g} epsilon/k_B is near the flexible "
                      f"walls' limit {FLEXIBLE_WALL_MAX_TEMPERATURE:g}")
    if p["normal_pressure"] < 0.5 * max(p["temperature"], 0.1):
        causes.append(f"normal_pressure {p['normal_pressure']:g} is low for temperature "
                      f"{p['temperature']:g}: the film can push the top wall off")
    if p["drive_velocity"] > 1.0:
        causes.append(f"drive_velocity {p['drive_velocity']:g} sigma/tau is fast: the film "
                      f"heats faster than the thermostat cools it")
    if not causes:
        return (" (atoms left the box: none of timestep, spacing, temperature, pressure or "
                "velocity looks extreme; see lammps.screen)")
    return " (atoms left the box; likely cause: " + "; ".join(causes) + ")"


# Physics sanity of a finished run: a run outside one of these is
# "completed_with_warnings" (it still counts, but read it with care).
# Validated runs: the thermostat holds the film within ~10 % of its set point,
# the gap moves by a few % (dilation at slips), the ledger closes below 1 %.
TEMPERATURE_TOLERANCE = 0.3     # |<T_film> - T| / T over the slide's second half


GAP_DRIFT_TOLERANCE = 0.15      # |gap(end) - gap(start)| / gap(start), 10 % windows
# ... or more than this share of one film layer's spacing: a thick film that gains or loses a
# layer's worth of gap has changed state (a six-layer film melted at +13 %); the analysis stops
# at such a change (analysis/film_state.py)
GAP_LAYER_TOLERANCE = GAP_LAYER_CHANGE


WALL_SPEED_TOLERANCE = 0.2      # |<v_wall> - V| / V in steady sliding (never stuck)


LEDGER_WARNING = 0.02           # residual / turnover (a run fails at LEDGER_LIMIT)


def sanity_warnings(dat: np.ndarray, scene: Scene) -> list[str]:
    """The physics checks of a run that completed: each broken one as a line
    naming the check and the values (empty: all passed)."""
    if len(dat) < 10:
        return []
    p = scene.parameters
    col = {c: dat[:, i] for i, c in enumerate(DAT_COLUMNS)}
    n = len(dat)
    half = slice(n // 2, None)
    out = []
    T = float(np.mean(col["film_temperature"][half]))
    tol = TEMPERATURE_TOLERANCE * (1.5 if p["thermostat_placement"] == "walls" else 1.0)
    ref = max(p["temperature"], 0.05)
    if abs(T - p["temperature"]) > tol * ref:
        out.append(f"film temperature: mean {T:.3g} epsilon/k_B over the slide's second half "
                   f"against the set point {p['temperature']:g} (tolerance "
                   f"{100 * tol:.0f} %): the thermostat does not hold the film (drive_velocity "
                   f"{p['drive_velocity']:g}, thermostat_damping {p['thermostat_damping']:g})")
    w = max(1, n // 10)
    g0, g1 = float(np.mean(col["gap"][:w])), float(np.mean(col["gap"][-w:]))
    # the gap between the walls' innermost planes holds film_layers + 1 layer spacings
    layer = g0 / (int(p["film_layers"]) + 1)
    tolerance = min(GAP_DRIFT_TOLERANCE * g0, GAP_LAYER_TOLERANCE * layer)
    if g0 > 0 and abs(g1 - g0) > tolerance:
        out.append(f"gap drift: the gap went from {g0:.3g} to {g1:.3g} sigma over the slide "
                   f"({100 * (g1 / g0 - 1):+.0f} %, {(g1 - g0) / layer:+.2f} of a layer's "
                   f"{layer:.3g} sigma; tolerance {100 * GAP_DRIFT_TOLERANCE:.0f} % or "
                   f"{GAP_LAYER_TOLERANCE:g} layer): the film is expanding or squeezed out, "
                   f"it may have melted; its slips and Bingham number are not those of the "
                   f"layered film (a change lasting to the end: the analysis stops where it "
                   f"began, analysis.json film_state_change)")
    V = p["drive_velocity"]
    v = col["wall_velocity"][half]
    if V > 0 and np.min(v) > 0.2 * V:       # steady sliding: the wall never sticks
        t, x = col["time"][half], col["wall_position"][half]
        mean_v = float((x[-1] - x[0]) / (t[-1] - t[0])) if t[-1] > t[0] else float(np.mean(v))
        if abs(mean_v - V) > WALL_SPEED_TOLERANCE * V:
            out.append(f"wall speed: {mean_v:.3g} sigma/tau in steady sliding against the drive "
                       f"V = {V:g} (tolerance {100 * WALL_SPEED_TOLERANCE:.0f} %): not yet "
                       f"steady, or the wall slips past the drive")
    led = ledger.ledger({c: col[c] for c in ledger.LEDGER_COLUMNS + ("mount_heat",)})
    residual, turnover = float(led["residual"][-1]), led["turnover"]
    if turnover > 0 and abs(residual) > LEDGER_WARNING * turnover:
        out.append(f"energy ledger: residual {residual:.3g} epsilon is "
                   f"{100 * abs(residual) / turnover:.1f} % of the turnover {turnover:.3g} "
                   f"epsilon (warning above {100 * LEDGER_WARNING:.0f} %, failure above "
                   f"{100 * LEDGER_LIMIT:.0f} %)")
    return out


def ledger_problem(dat: np.ndarray, scene: Scene) -> str | None:
    """The integrator created or destroyed energy beyond LEDGER_LIMIT of the turnover."""
    led = ledger.ledger({n: dat[:, DAT_COLUMNS.index(n)]
                                for n in ledger.LEDGER_COLUMNS + ("mount_heat",)})
    residual, turnover = float(led["residual"][-1]), led["turnover"]
    if turnover > 0 and abs(residual) > LEDGER_LIMIT * turnover:
        return (f"energy ledger does not close: residual {residual:.3g} epsilon is "
                f"{100 * abs(residual) / turnover:.0f} % of the energy turned over "
                f"({turnover:.3g} epsilon; limit {100 * LEDGER_LIMIT:.0f} %): the integration "
                f"is inaccurate (timestep {scene.parameters['timestep']:g} tau too large for "
                f"the forces?)")
    return None


def rows_problem(run_dir: Path, dat, scene: Scene, returncode: int) -> str | None:
    """Why a trace that LAMMPS ended without an error is short (None: it is whole):
    fewer rows than ``slide_steps // trace_every + 1``, or a last step short of the
    slide's end.  An engine that exits 0 having printed nothing, or a script that
    writes no trace, ends here."""
    # fix print writes on multiples of trace_every from step 0: the last row is the
    # last such multiple, which is below slide_steps when trace_every does not divide it
    steps, every = scene.parameters["slide_steps"], scene.parameters["trace_every"]
    last_row = steps // every * every
    expected = last_row // every + 1
    rows = (f"{len(dat)} trace rows where slide_steps {steps} / trace_every {every} "
            f"implies {expected}")
    if len(dat) and dat[-1, 0] < last_row:
        return (f"LAMMPS stopped at step {int(dat[-1, 0])} of {steps} without an error "
                f"message ({rows})")
    if len(dat) < expected:
        what = ("wrote no trace.dat" if not (run_dir / TRACE_DAT_FILE).exists() else
                "left rows out of trace.dat" if len(dat) else "wrote no row into trace.dat")
        return (f"the engine exited with code {returncode} but {what}: {rows} "
                "(see lammps.screen)")
    return None
