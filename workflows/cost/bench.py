"""``filmfriction bench``: the scene's throughput as ``filmfriction run`` runs it, beside bulk LJ.

The film is run exactly as ``filmfriction run --md-only`` runs it (the runner,
the scene's trace, restart files and outputs, equilibration included), on 1
core and on ``--np`` cores; beside each, a bulk LJ liquid
(``md_inputs/bulk_lj.lmp``) with the same atom count (to within one fcc cell
layer), cutoff, step count and ranks.  The runs alternate (film, bulk, film,
bulk ...), so that a change of the machine's load hits both sides alike.

The figure of merit is atom-steps per second over the whole LAMMPS process
(start-up, set-up and output included: what a user waits for); LAMMPS's own
loop-only figure is printed beside it.  Each configuration reports the median
over the repeats, the spread (min-max) and the best; the ratios (film / bulk,
the scaling from 1 core) are medians of the ratios of runs made side by side.
The CPU time that other processes used meanwhile is printed (from
``/proc/stat``, less the bench's own): figures taken while other work ran are
lower bounds.
"""
from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from filmfriction import md_inputs
from filmfriction.md_inputs.contract import LOG_FILE, RUN_FILE
from ..md import engine
from ..md.output.lammps_output import loop_totals


def bulk_cells(n_atoms: int) -> tuple[int, int, int]:
    """fcc cells (4 atoms each) of the most nearly cubic box within 5 % of ``n_atoms``.

    A thin box would cost the bulk side extra ghost atoms: the reference is
    the liquid as LAMMPS's own benchmark runs it, a near-cubic box.

    >>> bulk_cells(616)
    (5, 5, 6)
    """
    best = None
    for nx in range(1, 60):
        for ny in range(nx, 60):
            nz = max(1, round(n_atoms / (4 * nx * ny)))
            n = 4 * nx * ny * nz
            if abs(n - n_atoms) > 0.05 * n_atoms and best is not None:
                continue
            score = (abs(n - n_atoms) > 0.05 * n_atoms, max(nx, ny, nz) - min(nx, ny, nz),
                     abs(n - n_atoms))
            if best is None or score < best[0]:
                best = (score, (nx, ny, nz))
    return best[1]


def time_film(scene, cores: int, threads: int, where: Path) -> dict:
    """The scene as ``filmfriction run --md-only`` runs it; throughput from its wall time."""
    from ..md.runner import RunFailed, execute

    try:
        run_dir = execute(scene, out=where, nprocs=cores // threads, progress=False,
                          threads=threads)
    except RunFailed as exc:
        raise RuntimeError(f"the film run failed: {exc}") from None
    record = json.loads((run_dir / RUN_FILE).read_text())
    atoms, steps, loop = loop_totals((run_dir / LOG_FILE).read_text())
    return {"atoms": atoms, "steps": steps, "wall": record["wall_time"],
            "rate": atoms * steps / record["wall_time"], "loop_rate": atoms * steps / loop}


def time_bulk(atoms: int, steps: int, cores: int, cutoff: float, timestep: float,
              where: Path) -> dict:
    """The bulk LJ liquid of about ``atoms`` atoms for ``steps`` steps on ``cores`` ranks."""
    nx, ny, nz = bulk_cells(atoms)
    where.mkdir()
    cmd = engine.lmp_command(cores, md_inputs.script("bulk_lj.lmp"), {
        "cells_x": str(nx), "cells_y": str(ny), "cells_z": str(nz), "cutoff": repr(cutoff),
        "steps": str(steps), "timestep": repr(timestep)}, log=Path(LOG_FILE))
    t0 = time.perf_counter()
    out = subprocess.run(cmd, cwd=where, env=engine.engine_env(), capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if out.returncode != 0 or "ERROR" in out.stdout:
        err = [l for l in out.stdout.splitlines() if "ERROR" in l] or [out.stderr.strip()]
        raise RuntimeError(f"the bulk LJ run failed: {err[0]}")
    n, s, loop = loop_totals((where / LOG_FILE).read_text())
    return {"atoms": n, "steps": s, "wall": wall, "rate": n * s / wall,
            "loop_rate": n * s / loop}


def busy_cpu_seconds() -> float | None:
    """CPU seconds the whole machine has spent busy since boot (None off Linux)."""
    try:
        fields = Path("/proc/stat").read_text().splitlines()[0].split()[1:]
    except (OSError, IndexError):
        return None
    ticks = [int(x) for x in fields]
    idle = ticks[3] + (ticks[4] if len(ticks) > 4 else 0)
    return (sum(ticks[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def own_cpu_seconds() -> float:
    """CPU seconds of this process and its finished children."""
    me, kids = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def cpu_snapshot() -> tuple:
    """(machine busy CPU seconds, this process's and its finished children's), for
    :func:`other_cpu_seconds`."""
    return busy_cpu_seconds(), own_cpu_seconds()


def other_cpu_seconds(before: tuple, after: tuple) -> float | None:
    """CPU seconds the machine spent busy between two :func:`cpu_snapshot` beyond this
    process and its finished children: other work beside a measurement (None off Linux)."""
    (busy0, own0), (busy1, own1) = before, after
    if busy0 is None or busy1 is None:
        return None
    return max(0.0, (busy1 - busy0) - (own1 - own0))


def summary(values: list[float]) -> dict:
    """Median, spread and best of a list of throughputs."""
    return {"median": statistics.median(values), "min": min(values), "max": max(values),
            "best": max(values), "n": len(values)}


def run_bench(scene, nprocs: int, repeat: int, omp: bool = False, progress=None) -> dict:
    """Time ``scene`` on 1 core and on ``nprocs`` cores beside bulk LJ, ``repeat`` times,
    alternating; ``progress(text)`` is told of each run.  Returns the figures (:func:`_report`);
    RuntimeError when a run fails."""
    cutoff, timestep = scene.parameters["cutoff"], scene.parameters["timestep"]
    layouts = [("film", 1, 1), ("bulk", 1, 1)]
    if nprocs > 1:
        layouts += [("film", nprocs, 1), ("bulk", nprocs, 1)]
        if omp:
            layouts.append(("film", nprocs, nprocs))
    runs: dict[str, list[dict]] = {}
    before, t0 = cpu_snapshot(), time.perf_counter()
    total = len(layouts) * repeat
    with tempfile.TemporaryDirectory(prefix="filmfriction-bench-") as tmp:
        tmp = Path(tmp)
        done = 0
        for i in range(repeat):
            film_atoms = film_steps = None
            for kind, cores, threads in layouts:
                key = _key(kind, cores, threads)
                where = tmp / f"{key.replace(' ', '_')}-{i}"
                done += 1
                if progress is not None:
                    progress(f"[{done}/{total}] {key} ...")
                if kind == "film":
                    res = time_film(scene, cores, threads, where)
                    film_atoms, film_steps = res["atoms"], res["steps"]
                else:
                    res = time_bulk(film_atoms, film_steps, cores, cutoff, timestep, where)
                runs.setdefault(key, []).append(res)
    other, elapsed = other_cpu_seconds(before, cpu_snapshot()), time.perf_counter() - t0
    return _report(scene.name, nprocs, repeat, runs, other, elapsed)


def _key(kind: str, cores: int, threads: int) -> str:
    layout = f"{cores // threads} rank{'s' if cores // threads > 1 else ''}"
    if threads > 1:
        layout += f" x {threads} threads"
    return f"{kind} {cores} core{'s' if cores > 1 else ''} ({layout})"


def _paired(runs, a: str, b: str) -> dict | None:
    if a not in runs or b not in runs:
        return None
    ratios = [x["rate"] / y["rate"] for x, y in zip(runs[a], runs[b])]
    return {"median": statistics.median(ratios), "min": min(ratios), "max": max(ratios)}


def _report(name, nprocs, repeat, runs, other_cpu, elapsed) -> dict:
    film1, bulk1 = _key("film", 1, 1), _key("bulk", 1, 1)
    filmn, bulkn = _key("film", nprocs, 1), _key("bulk", nprocs, 1)
    first = runs[film1][0]
    out = {
        "scene": name, "cores": nprocs, "repeat": repeat,
        "film_atoms": first["atoms"], "steps": first["steps"],
        "bulk_atoms": runs[bulk1][0]["atoms"],
        "elapsed_seconds": elapsed, "other_cpu_seconds": other_cpu, "cpus": os.cpu_count(),
        "atom_steps_per_second": {k: summary([r["rate"] for r in v]) for k, v in runs.items()},
        "loop_atom_steps_per_second": {k: summary([r["loop_rate"] for r in v])
                                       for k, v in runs.items()},
        "wall_time": {k: summary([r["wall"] for r in v]) for k, v in runs.items()},
        "ratios": {},
    }
    if nprocs > 1:
        out["ratios"][f"film / bulk, {nprocs} cores"] = _paired(runs, filmn, bulkn)
        out["ratios"][f"film {nprocs} cores / film 1 core"] = _paired(runs, filmn, film1)
        out["ratios"][f"bulk {nprocs} cores / bulk 1 core"] = _paired(runs, bulkn, bulk1)
        omp = _key("film", nprocs, nprocs)
        if omp in runs:
            out["ratios"][f"film {nprocs} threads / film {nprocs} ranks"] = _paired(runs, omp, filmn)
    out["ratios"]["film / bulk, 1 core"] = _paired(runs, film1, bulk1)
    return out


def as_text(r: dict) -> str:
    cores = os.cpu_count() or 1
    lines = [
        f"scene '{r['scene']}' as 'filmfriction run --md-only' runs it: {r['film_atoms']} atoms, "
        f"{r['steps']} steps (equilibration + slide); bulk LJ liquid: {r['bulk_atoms']} atoms, "
        f"the same steps and cutoff",
        f"{r['repeat']} repeat(s), alternating; Matom-step/s over the whole LAMMPS process "
        f"(loop-only in brackets)",
        f"{'':38s} {'median':>8s} {'spread':>15s} {'best':>7s} {'wall s':>8s}",
    ]
    for key, s in r["atom_steps_per_second"].items():
        loop = r["loop_atom_steps_per_second"][key]["median"]
        wall = r["wall_time"][key]["median"]
        lines.append(f"{key:38s} {s['median'] / 1e6:8.2f} {s['min'] / 1e6:7.2f}-"
                     f"{s['max'] / 1e6:<7.2f} {s['best'] / 1e6:7.2f} {wall:8.1f}"
                     f"   [{loop / 1e6:.2f}]")
    lines.append("ratios of runs side by side (median, min-max):")
    for key, q in r["ratios"].items():
        if q:
            lines.append(f"  {key:36s} {q['median']:.2f} ({q['min']:.2f}-{q['max']:.2f})")
    other, elapsed = r["other_cpu_seconds"], r["elapsed_seconds"]
    if other is None:
        lines.append(f"{elapsed:.0f} s on {cores} cores; other work: unknown (no /proc/stat)")
    else:
        share = other / (elapsed * cores)
        lines.append(f"{elapsed:.0f} s on {cores} cores; other processes used {other:.0f} CPU-s "
                     f"meanwhile ({100 * share:.0f} % of the machine)"
                     + ("; the figures are lower bounds" if share > 0.02 else ""))
    return "\n".join(lines)
