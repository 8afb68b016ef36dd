"""Static friction against load for each wall model: F_s = F_0 + mu * L.

Runs the 4-layer film of the Klein-similar scene (kT = 0.71) with each wall model
at several normal pressures and seeds, one LAMMPS run at a time on one rank, a
stiff spring (short ramps) and a short slide; finds the slips in each trace
(``analysis.stickslip.detect_slips``, for the count) and takes each run's static
force as the largest spring force before the wall has slid one wall lattice
spacing, if the wall was pinned until then (the spring's stretch at least half the
drive's travel).  The film's age at that yield is the same in every run (the
equilibration and one ramp); a film that yields and then slides without
re-sticking counts; a wall that follows the drive slides freely.  Per wall model it fits F_s = F_0 + mu * L over
the runs that pin (``scipy.stats.linregress``: L = P * A, each run one point, so
the errors include the scatter between seeds) and gives the yield stress F_s / A.
For a wall that slides freely the mean and largest spring force are given.

    python benchmarks/wall_load.py --out runs/wall-load [--models rigid,flexible]
        [--pressures 0.01,0.1,0.3,1] [--seeds 1,2] [--report-only]

Existing run directories are read, not re-run (a run directory is never
overwritten), so the study can be resumed and extended.  The table is written to
``<out>/wall_load.json`` and printed.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

#: The film and slider every wall model is measured with (the Klein-similar
#: scene's film; a stiff spring so that each ramp is short).
BASE = {"film_layers": 4, "temperature": 0.71, "spring_constant": 20.0, "wall_mass": 500.0,
        "mount_damping": 0.3, "drive_velocity": 0.08, "equilibrate_steps": 4000,
        "slide_steps": 16000, "trace_every": 20, "restart_every": 0}

#: Wall models: the scene parameters that make each.
MODELS = {
    "rigid": {},
    "flexible": {"wall_model": "flexible", "thermostat_placement": "both"},
    "twisted": {"top_wall_twist": "twisted"},
    "vacancies": {"wall_vacancies": 0.2},
    "flexible-twisted": {"wall_model": "flexible", "thermostat_placement": "both",
                         "top_wall_twist": "twisted"},
    "flexible-vacancies": {"wall_model": "flexible", "thermostat_placement": "both",
                           "wall_vacancies": 0.2},
}


def run_name(model: str, pressure: float, seed: int) -> str:
    return f"{model}_P{pressure:g}_s{seed}"


def command(out: Path, model: str, pressure: float, seed: int) -> list[str]:
    sets = {**BASE, **MODELS[model], "normal_pressure": pressure, "seed": seed}
    cmd = [str(Path(sys.executable).with_name("filmfriction")), "run", "stick-slip",
           "--md-only", "--np", "1", "--quiet", "--out", str(out / run_name(model, pressure, seed))]
    for key, value in sets.items():
        cmd += ["--set", f"{key}={value}"]
    return cmd


def measure(run_dir: Path) -> dict:
    """Slips, static force, kinetic force and the gap of one run."""
    from filmfriction.analysis.stickslip import detect_slips

    data = np.loadtxt(run_dir / "trace.dat", comments="#")
    t, f, gap = data[:, 1], data[:, 3], data[:, 7]
    record = json.loads((run_dir / "run.json").read_text())
    area = record["derived"]["area"]
    events = detect_slips(t, f)
    # the static force: the largest spring force before the wall has slid one wall
    # lattice spacing from where it started (a pinned wall creeps elastically by a
    # fraction of it, then yields; the film's yield may come in small hops)
    spacing = record["scene"]["parameters"]["wall_spacing"]
    beyond = np.flatnonzero(data[:, 4] >= spacing)
    end = beyond[0] + 1 if beyond.size else len(f)
    peak = int(np.argmax(f[:end]))
    # pinned: up to that peak the wall stayed behind the drive, the spring's
    # stretch at least half the drive's travel (a free wall follows the drive, its
    # peak force is a noise excursion)
    pinned = (data[peak, 2] - data[peak, 4]) >= 0.5 * data[peak, 2] and data[peak, 2] > 0
    half = len(f) // 2
    return {"slips": events.count, "yield_forces": f[events.yield_index].tolist(),
            "pinned": bool(pinned), "peak_force": float(f[peak]),
            "peak_time": float(t[peak]), "slid_one_spacing": bool(beyond.size),
            "static_force": float(f[peak]) if pinned else None,
            "mean_force_late": float(f[half:].mean()), "max_force": float(f.max()),
            "noise": float(events.noise), "threshold": float(events.threshold),
            "gap_start": float(gap[:50].mean()), "gap_end": float(gap[-50:].mean()),
            "film_temperature": float(data[:, 8].mean()), "area": area,
            "status": record.get("status")}


def _finished(run_dir: Path) -> bool:
    """The trace reaches the end of the slide (a run still going is left out)."""
    last = (run_dir / "trace.dat").read_text().rstrip().rsplit("\n", 1)[-1].split()
    return bool(last) and last[0].isdigit() and int(last[0]) >= BASE["slide_steps"]


def fit(points: list[tuple[float, float]]) -> dict | None:
    """F_s = F_0 + mu * L by least squares over (L, F_s) points, with standard errors."""
    from scipy.stats import linregress

    if len({L for L, _ in points}) < 2 or len(points) < 3:
        return None
    L, F = np.array(points).T
    r = linregress(L, F)
    return {"F0": r.intercept, "F0_se": r.intercept_stderr, "mu": r.slope, "mu_se": r.stderr,
            "points": len(points)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--models", default="rigid,flexible,twisted,vacancies")
    ap.add_argument("--pressures", default="0.01,0.1,0.3,1")
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--report-only", action="store_true")
    a = ap.parse_args(argv)
    models = a.models.split(",")
    unknown = [m for m in models if m not in MODELS]
    if unknown:
        print(f"error: --models {a.models!r}: unknown {unknown}; known: {', '.join(MODELS)}",
              file=sys.stderr)
        return 2
    pressures = [float(p) for p in a.pressures.split(",")]
    seeds = [int(s) for s in a.seeds.split(",")]
    a.out.mkdir(parents=True, exist_ok=True)
    table = {}
    for model in models:
        rows = []
        for seed in seeds:
            for pressure in pressures:
                run_dir = a.out / run_name(model, pressure, seed)
                if not (run_dir / "trace.dat").is_file():
                    if a.report_only:
                        continue
                    subprocess.run(command(a.out, model, pressure, seed), check=False)
                if not (run_dir / "run.json").is_file() or not _finished(run_dir):
                    continue
                m = measure(run_dir)
                m.update(pressure=pressure, seed=seed, load=pressure * m["area"])
                rows.append(m)
                fs = "free" if m["static_force"] is None else f"{m['static_force']:.2f}"
                print(f"{model:20s} P={pressure:<5g} seed={seed} pinned={m['pinned']} "
                      f"slips={m['slips']} "
                      f"F_s={fs} F_late={m['mean_force_late']:.2f} max={m['max_force']:.2f} "
                      f"gap {m['gap_start']:.2f}->{m['gap_end']:.2f} T={m['film_temperature']:.3f}",
                      flush=True)
        pinned = [(r["load"], r["static_force"]) for r in rows if r["static_force"] is not None]
        result = fit(pinned)
        table[model] = {"parameters": MODELS[model], "runs": rows, "fit": result}
        if result:
            area = rows[0]["area"]
            print(f"{model}: F_s = ({result['F0']:.2f} ± {result['F0_se']:.2f}) + "
                  f"({result['mu']:.3f} ± {result['mu_se']:.3f}) L over {result['points']} runs; "
                  f"F_0/A = {result['F0'] / area:.3f} ± {result['F0_se'] / area:.3f} eps/sigma^3")
    print("\n| wall model | runs (pinned) | seeds | F_0 (ε/σ) | μ | F_0/A (ε/σ³) | F_s/A at P = 0.01 (ε/σ³) |")
    print("|---|---|---|---|---|---|---|")
    for model, entry in table.items():
        rows, result = entry["runs"], entry["fit"]
        if not rows:
            continue
        area = rows[0]["area"]
        low = [r["static_force"] / area for r in rows
               if r["static_force"] is not None and r["pressure"] == min(pressures)]
        seeds_run = sorted({r["seed"] for r in rows})
        n_pinned = sum(r["pinned"] for r in rows)
        if result:
            cells = (f"{result['F0']:.1f} ± {result['F0_se']:.1f} | "
                     f"{result['mu']:.3f} ± {result['mu_se']:.3f} | "
                     f"{result['F0'] / area:.3f} ± {result['F0_se'] / area:.3f}")
        else:
            late = [r["mean_force_late"] for r in rows]
            cells = (f"slides freely (mean force {np.mean(late):.2f}, largest "
                     f"{max(r['max_force'] for r in rows):.2f}) | – | –")
        low_text = (f"{np.mean(low):.3f}" + (f" ± {np.std(low, ddof=1) / np.sqrt(len(low)):.3f}"
                                             if len(low) > 1 else "")) if low else "–"
        print(f"| {model} | {len(rows)} ({n_pinned}) | {','.join(map(str, seeds_run))} | "
              f"{cells} | {low_text} |")
    doc = {"base": BASE, "models": table, "command": "python benchmarks/wall_load.py " +
           " ".join(argv if argv is not None else sys.argv[1:])}
    from filmfriction.analysis.files.util import write_atomic
    write_atomic(a.out / "wall_load.json", json.dumps(doc, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
