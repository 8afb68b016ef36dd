"""The slider-mass ladder: the Klein-similar film under sliders from M = 30 to 2.4×10⁶ m.

The Bingham number Bi = η_eff/η_bulk of the Klein-similar scene (``sfb-similar``) is about 1
because its slider is light and its slips fast.  The ladder keeps the film, the walls, the load
and the spring of that scene and raises the slider's mass M, lowering the drive velocity V so
that V stays well below the slips' velocity, and the mount's dashpot γ so that its damping
ratio γ/(2√(K/M)) stays the scene's 0.019 (γ = 0.01·√(30/M)).  Each rung is one sweep of the
project's sweep machinery (``filmfriction sweep sfb-similar --grid seed=...``, Snakemake, so it
runs on a cluster unchanged); the rungs differ in their fixed values, which a grid product
cannot express.

    filmfriction ladder plan [--steps-per-second R]
    filmfriction ladder run --root DIR [--profile slurm] [--np N]
    filmfriction ladder collect --root DIR [--out FILE]

(the command line is ``workflows/cli/ladder_cli.py``).  ``plan`` prints the rungs, their
``filmfriction sweep`` commands and the steps each run takes (and its time at R steps per
second, a rate the user measures).  ``run`` runs the sweeps one after another in the order
of :data:`STAGES` (one seed of the Bi ≥ 30 rung, one seed of every other rung, then the other
seeds), each sweep with ``--cores`` = ``--np`` so that one LAMMPS runs at a time; run it
again to resume (finished points are not redone, an interrupted one continues from its
newest restart file).  ``collect`` reads every finished point
(``analysis.json``, and the similarity numbers of :mod:`filmfriction.reduced_model.sfb.similarity`
from :func:`filmfriction.analysis.calibration.contact.contact_from_run`) and gives per rung the
slips, the slip velocity, F_k and B of both branches of the slip law, B/B_bulk, the exponent
n, the Bingham number and the slip heating, each with its standard error, and the slip law
of the rung's slips pooled (the mean of all its seeds' slips, errors and verdict by the
jackknife over the seeds: ``filmfriction slip-law``).

Slide steps per rung: the spring's end must travel the first extension x0 = F_s/K and then one
slip length per further slip, at V, and each slip lasts about slip/v̄; v̄ is taken as the
sfb-similar scene's 0.65 σ/τ scaled by √(30/M) (the slips' shape at fixed film force does not
depend on M, their time scale is √(M/K)); 15 % margin, rounded up to 10⁵ steps.  The heavy
rungs (M ≥ 2.4×10⁵) take :data:`HEAVY_STEP_FACTOR` times that: the first slip of the M = 2.4×10⁵
rung ran 34 σ at 0.031 σ/τ (docs/results/mass-ladder.md), 2.4× longer than the model's slip,
so a cycle takes ≈ 15 000 τ and the model's steps hold one slip fewer than it was sized for.
The M = 2.4×10⁶ rung is sized on its own measured slips (:attr:`Rung.measured_slip_velocity`):
faster than the model's (0.0089 against 0.0023 σ/τ), so it keeps the M = 2.4×10⁵ rung's V and
takes 1.12× the model's steps; it is not in ``run``'s campaign (a run takes about an hour on 2
cores), ``plan`` prints its sweep.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Rung", "RUNGS", "STAGES", "slide_steps", "sweep_command", "collect_rung",
           "combine_seeds", "pooled_law", "campaign_steps", "HEAVY_STEP_FACTOR"]

SCENE = "sfb-similar"
#: The scene's own slider and mount: M = 30 m, γ = 0.01 /τ.
REFERENCE_MASS = 30.0
REFERENCE_MOUNT_DAMPING = 0.01
#: Cost model, from the sfb-similar runs (docs/results/sfb-similar.md): yield force F_s ≈ 50 ε/σ
#: at K = 2 ε/σ² (x0 ≈ 25 σ), slips of ≈ 14 σ at v̄ ≈ 0.65 σ/τ for M = 30 m.
STATIC_FORCE = 50.0
SPRING_CONSTANT = 2.0
SLIP_LENGTH = 14.0
REFERENCE_SLIP_VELOCITY = 0.65
TIMESTEP = 0.005
MARGIN = 1.15
SEEDS = (1, 2, 3)
#: The scene's profile window (steps): a few per slip of M = 30 m (its ``profile_every``).
REFERENCE_PROFILE_EVERY = 500
#: The heavy rungs' steps over the cost model's: the measured first slip of M = 2.4×10⁵
#: (34 σ against the model's 14 σ) makes a cycle ≈ 15 000 τ at V = 0.002.
HEAVY_STEP_FACTOR = 1.4


def slide_steps(mass: float, drive_velocity: float, slips: int, factor: float = 1.0) -> int:
    """Steps for ``slips`` slips (the start-up slip included) under a slider of ``mass``,
    by the cost model, times ``factor``, rounded up to 10⁵ steps.

    >>> slide_steps(240000, 0.002, 4)
    9500000
    >>> slide_steps(240000, 0.002, 4, factor=1.4)
    13300000
    >>> slide_steps(30, 0.02, 8)
    1500000
    """
    x0 = STATIC_FORCE / SPRING_CONSTANT
    v_slip = REFERENCE_SLIP_VELOCITY * math.sqrt(REFERENCE_MASS / mass)
    t = (x0 + (slips - 1) * SLIP_LENGTH) / drive_velocity + slips * SLIP_LENGTH / v_slip
    return int(math.ceil(factor * MARGIN * t / TIMESTEP / 1e5 - 1e-9) * 100000)


@dataclass(frozen=True)
class Rung:
    """One slider mass of the ladder.

    Parameters
    ----------
    mass : float
        The top wall's mass M (m).
    drive_velocity : float
        V (σ/τ).
    slips : int
        Slips the run is sized for, the start-up slip included (≥ 4: ≥ 3 analysed).
    planned : bool
        Not in ``run``'s campaign (longer than 30 min a run on 2 cores); ``plan`` prints its
        sweep command.
    step_factor : float
        The rung's steps over the cost model's (:data:`HEAVY_STEP_FACTOR` for the heavy
        rungs, whose measured slips are longer than the model's).
    measured_slip_velocity : float or None
        v̄_slip of the rung's own runs (σ/τ), where it sets V instead of the model's.
    """

    mass: float
    drive_velocity: float
    slips: int
    planned: bool = False
    step_factor: float = 1.0
    measured_slip_velocity: float | None = None

    @property
    def mount_damping(self) -> float:
        """γ (1/τ) keeping the mount's damping ratio of sfb-similar, 3 significant digits."""
        return float(f"{REFERENCE_MOUNT_DAMPING * math.sqrt(REFERENCE_MASS / self.mass):.3g}")

    @property
    def slip_velocity_estimate(self) -> float:
        """v̄_slip (σ/τ): the rung's measured one, else the cost model's."""
        if self.measured_slip_velocity is not None:
            return self.measured_slip_velocity
        return REFERENCE_SLIP_VELOCITY * math.sqrt(REFERENCE_MASS / self.mass)

    @property
    def slide_steps(self) -> int:
        return slide_steps(self.mass, self.drive_velocity, self.slips, self.step_factor)

    @property
    def profile_every(self) -> int:
        """The profiles' window (steps): the scene's scaled by √(M/30), the slips' time
        scale, so that a slip holds as many windows at every rung and the profile files
        grow with the slips, not with the steps."""
        return REFERENCE_PROFILE_EVERY * round(math.sqrt(self.mass / REFERENCE_MASS))

    @property
    def model_steps(self) -> int:
        """The cost model's steps, before :attr:`step_factor`."""
        return slide_steps(self.mass, self.drive_velocity, self.slips)

    @property
    def run_steps(self) -> int:
        """Every step of one run: the scene's equilibration and the slide."""
        from .md.scene import load

        return load(SCENE).parameters["equilibrate_steps"] + self.slide_steps

    @property
    def name(self) -> str:
        return f"M={self.mass:g}"

    def sets(self) -> list[str]:
        return [f"wall_mass={self.mass:g}", f"drive_velocity={self.drive_velocity:g}",
                f"mount_damping={self.mount_damping:g}", f"slide_steps={self.slide_steps}",
                f"profile_every={self.profile_every}"]


#: The rungs, lightest first.  M = 2.4e5 was planned as the Bi ≥ 30 rung (the ``sfb-heavy``
#: scene is its seed 1); M = 2.4e6, run outside the campaign, keeps its V: its slips (v̄ measured
#: on two seeds, docs/results/mass-ladder.md) run 4× faster than the model's, 27–34 σ long, so
#: that 15.0 M steps (the model's × 1.12) hold 4–5 slips.
RUNGS = (Rung(30, 0.02, 8), Rung(300, 0.02, 8), Rung(3000, 0.01, 6), Rung(30000, 0.005, 5),
         Rung(240000, 0.002, 4, step_factor=HEAVY_STEP_FACTOR),
         Rung(2.4e6, 0.002, 4, planned=True, step_factor=1.12,
              measured_slip_velocity=0.0089))
HEAVY = RUNGS[4]
#: The campaign's order: (rung, seeds); a later stage on a rung adds seeds to its sweep.
STAGES = ((HEAVY, (1,)),) + tuple((r, (1,)) for r in RUNGS[:4]) + tuple(
    (r, SEEDS) for r in RUNGS[:5])


def campaign_steps() -> tuple[int, int]:
    """(runs, steps) of the whole campaign (:data:`STAGES`, every run's equilibration and
    slide): its cost in steps; its wall time is steps over a measured rate.

    A later stage on a rung re-runs no seed an earlier one finished.
    """
    seeds: dict[str, set] = {}
    runs = steps = 0
    for rung, stage_seeds in STAGES:
        new = set(stage_seeds) - seeds.setdefault(rung.name, set())
        seeds[rung.name] |= new
        runs += len(new)
        steps += len(new) * rung.run_steps
    return runs, steps


def sweep_command(rung: Rung, seeds, root: Path, np_: int = 1,
                  profile: str | None = None) -> list[str]:
    """The ``filmfriction sweep`` command of one rung (``--cores`` = ``np_``: one run at a time)."""
    cmd = ["filmfriction", "sweep", SCENE, "--grid", "seed=" + ",".join(map(str, seeds))]
    for s in rung.sets():
        cmd += ["--set", s]
    cmd += ["--np", str(np_), "--cores", str(np_), "--out", str(Path(root) / rung.name)]
    if profile:
        cmd += ["--profile", profile]
    return cmd


# -- collect -------------------------------------------------------------------------------

def _est(entry):
    """(mean, stderr) of an analysis entry ``{"mean", "stderr"}`` or a bare number."""
    if isinstance(entry, dict):
        m, e = entry.get("mean"), entry.get("stderr")
    else:
        m, e = entry, None
    m = math.nan if m is None else float(m)
    e = math.nan if e is None else float(e)
    return m, e


def point_row(run_dir: Path) -> dict:
    """The ladder's quantities of one finished point, each as (value, stderr)."""
    from filmfriction.analysis.calibration.contact import contact_from_run
    from filmfriction.reduced_model.sfb.similarity import similarity_numbers

    analysis = json.loads((run_dir / "analysis.json").read_text())
    slips = analysis.get("slips") or {}
    law = analysis.get("slip_law") or {}
    br = law.get("branches") or {}
    row = {"point": run_dir.name, "regime": (analysis.get("regime")
                                             or (analysis.get("sliding") or {}).get("regime")),
           "slips": slips.get("count") or 0,
           "verdict": law.get("verdict")}
    for b in ("decelerating", "accelerating"):
        x = br.get(b) or {}
        row[f"{b}_kinetic_force"] = _est(x.get("kinetic_force"))
        row[f"{b}_damping"] = _est(x.get("damping"))
        row[f"{b}_exponent"] = _est(x.get("exponent"))
        row[f"{b}_slips"] = x.get("slips")
    row["damping_over_bulk"] = (float(law["damping_over_bulk"]) if law.get("damping_over_bulk")
                                is not None else math.nan,
                                float(law.get("damping_over_bulk_stderr") or math.nan))
    try:
        nums = similarity_numbers(contact_from_run(run_dir))
    except (ValueError, KeyError, TypeError) as exc:
        row["similarity_error"] = str(exc)
        nums = {}
    for k in ("bingham_number", "slip_heating", "film_damping_ratio", "mount_damping_ratio",
              "slip_velocity_over_thermal", "slip_over_extension"):
        n = nums.get(k)
        row[k] = (n.value, n.stderr) if n is not None else (math.nan, math.nan)
    row["slip_temperature_rise"] = slip_temperature_rise(run_dir)
    t = row["slip_velocity_over_thermal"]
    temp = ((json.loads((run_dir / "run.json").read_text()).get("scene") or {})
            .get("parameters") or {}).get("temperature")
    row["slip_velocity"] = ((t[0] * math.sqrt(temp), t[1] * math.sqrt(temp)) if temp
                            else (math.nan, math.nan))
    return row


def slip_temperature_rise(run_dir: Path) -> tuple[float, float]:
    """The film's measured temperature rise during a slip over its temperature, ± s.e. over slips.

    Per analysed cycle (``analysis_cycles.csv``): the film temperature averaged over the slip
    (yield to re-stick) less its average over the stick before the yield, over the stick's
    average.  Unlike the similarity rows' adiabatic ``slip_heating``, this is what the
    thermostatted film shows.
    """
    import numpy as np

    from filmfriction.analysis.files.trace_reader import read_trace

    trace, cycles = run_dir / "trace.csv", run_dir / "analysis_cycles.csv"
    if not (trace.is_file() and cycles.is_file()):
        return math.nan, math.nan
    # the reader's binary copy of a long trace (the pooled law reads the same)
    try:
        tr = read_trace(trace).columns
    except ValueError:                      # a trace the reader refuses: no rise to give
        return math.nan, math.nan
    cy = np.genfromtxt(cycles, delimiter=",", names=True, ndmin=1)
    if "film_temperature" not in tr or cy.size == 0:
        return math.nan, math.nan
    t, temp = tr["time"], tr["film_temperature"]
    rises = []
    previous_stick = float(t[0])
    for y, s in zip(cy["yield_time"], cy["stick_time"]):
        stick = temp[(t >= previous_stick) & (t < y)]
        slip = temp[(t >= y) & (t <= s)]
        previous_stick = float(s)
        if stick.size > 1 and slip.size > 1:
            rises.append((slip.mean() - stick.mean()) / stick.mean())
    if not rises:
        return math.nan, math.nan
    r = np.asarray(rises)
    return float(r.mean()), float(r.std(ddof=1) / math.sqrt(r.size)) if r.size > 1 else math.nan


QUANTITIES = ("slip_velocity", "decelerating_kinetic_force", "decelerating_damping",
              "accelerating_kinetic_force", "accelerating_damping", "damping_over_bulk",
              "decelerating_exponent", "accelerating_exponent", "bingham_number",
              "slip_heating", "slip_temperature_rise", "film_damping_ratio", "mount_damping_ratio")


def combine_seeds(rows: list[dict], key: str) -> tuple[float, float, int]:
    """Mean over seeds and its standard error, with the number of seeds used.

    One seed: its own standard error.  Several: the scatter between seeds, s/√n
    (each seed an independent repeat of the same rung).

    >>> combine_seeds([{"x": (1.0, 0.2)}, {"x": (3.0, 0.2)}], "x")
    (2.0, 1.0, 2)
    >>> combine_seeds([{"x": (1.0, 0.2)}], "x")
    (1.0, 0.2, 1)
    """
    vals = [r[key] for r in rows if key in r and math.isfinite(r[key][0])]
    if not vals:
        return math.nan, math.nan, 0
    if len(vals) == 1:
        return vals[0][0], vals[0][1], 1
    xs = [v[0] for v in vals]
    mean = sum(xs) / len(xs)
    var = sum((x - mean) ** 2 for x in xs) / (len(xs) - 1)
    return mean, math.sqrt(var / len(xs)), len(xs)


def collect_rung(sweep_dir: Path) -> dict:
    """Every finished point of one rung's sweep, and the rung's seed-combined quantities."""
    sweep_dir = Path(sweep_dir)
    plan = json.loads((sweep_dir / "sweep.json").read_text())
    points = [p for p in sorted((sweep_dir / "points").glob("*"))
              if (p / "analysis.json").is_file()]
    rows = [point_row(p) for p in points]
    out = {"sweep": sweep_dir.name, "fixed": plan.get("fixed"), "points": rows,
           "seeds": len(rows), "slips": sum(r["slips"] for r in rows)}
    for k in QUANTITIES:
        m, e, n = combine_seeds(rows, k)
        out[k] = {"mean": m, "stderr": e, "seeds": n}
    out["pooled_slip_law"] = pooled_law(points)
    return out


def pooled_law(points) -> dict:
    """The slip law of the rung's points pooled (the mean of all their slips, the
    jackknife over the points: :mod:`filmfriction.analysis.calibration.slip_law_runs`), or
    ``{"error": why}`` where it cannot be fitted (fewer than three points, a point without
    a slip)."""
    from filmfriction.analysis.calibration.slip_law_runs import pooled_slip_law, to_document

    try:
        return to_document(pooled_slip_law(points, analyse=False))["pooled"]
    except ValueError as exc:
        return {"error": str(exc)}


def _fmt(q: dict) -> str:
    m, e = q["mean"], q["stderr"]
    if not math.isfinite(m):
        return "–"
    return f"{m:.3g} ± {e:.2g}" if math.isfinite(e) else f"{m:.3g}"


def _pooled_cells(law: dict) -> list[str]:
    """The pooled slip law's n and verdict as table cells ("–" where it was not fitted)."""
    if "verdict" not in law:
        return ["–", "–"]
    n = law["exponent"]
    q = {"mean": math.nan if n["mean"] is None else n["mean"],
         "stderr": math.nan if n["stderr"] is None else n["stderr"]}
    return [_fmt(q), f"{law['verdict']} ({law['replicas']} seeds)"]


def table(rungs: list[dict]) -> str:
    """The markdown table of the collected rungs."""
    head = ("| rung | seeds | slips | v̄_slip (σ/τ) | F_k dec (ε/σ) | B dec (m/τ) | F_k acc | B acc "
            "| B_dec/B_bulk | n dec | n acc | Bi (Eq. 1) | ΔT/T adiabatic | ΔT/T measured "
            "| n, slips pooled | verdict, slips pooled |")
    lines = [head, "|" + "---|" * 16]
    for r in rungs:
        lines.append("| " + " | ".join([
            r["sweep"], str(r["seeds"]), str(r["slips"]), _fmt(r["slip_velocity"]),
            _fmt(r["decelerating_kinetic_force"]), _fmt(r["decelerating_damping"]),
            _fmt(r["accelerating_kinetic_force"]), _fmt(r["accelerating_damping"]),
            _fmt(r["damping_over_bulk"]), _fmt(r["decelerating_exponent"]),
            _fmt(r["accelerating_exponent"]), _fmt(r["bingham_number"]),
            _fmt(r["slip_heating"]), _fmt(r["slip_temperature_rise"]),
            *_pooled_cells(r.get("pooled_slip_law") or {})]) + " |")
    return "\n".join(lines)
