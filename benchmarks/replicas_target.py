"""Replicas and the target rule on the default scene: the two checks that need an idle machine.

``coverage``: the stopping rule's reported error is honest on the real scene.  It runs
``filmfriction run SCENE --replicas 2 --target static_force=REL`` for ``--seeds`` scene
seeds (each study's replicas: the seed and seeds drawn from it), then asks of each study
whether its final mean ± its 68 % half-width holds the many-seed mean, the mean of every
*other* study's slips combined (leave-one-out, so a study is never judged against itself).
It prints the count, the coverage with its Clopper-Pearson 68 % interval, the nominal
68 %, the slips and segments each study spent, and writes every figure to
``OUT/coverage.json``.  20 seeds say coverage to about ± 10 %: enough to catch a rule
that covers half the time (the naive rule on one run), not to tell 68 % from 75 %.

``paired``: slips per wall-second of 2 replicas x 1 rank against 1 run x 2 ranks, the
same scene and slide, run one after the other in each pair (the order alternates), so
the pairs see the same machine.  Each side's figure is the whole command's wall time
(set-up and equilibration included: each replica pays its own); the slips are every
slip after the start-up one.  Prints each side's median and spread, the ratio's median
and min-max over the pairs, and the CPU seconds other processes used meanwhile (from
``/proc/stat``): figures taken while other work ran are lower bounds, and the script
says so.

Run on an idle machine (both take long: the coverage part ~20 studies of several
minutes each on 2 cores)::

    .venv/bin/python benchmarks/replicas_target.py paired --pairs 5 --out /tmp/rt-paired
    .venv/bin/python benchmarks/replicas_target.py coverage --seeds 20 --out /tmp/rt-cov

Nothing here is timed in the test suite; no figure of it is in the docs until measured.
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

from filmfriction.workflows.cost.bench import cpu_snapshot, other_cpu_seconds

CLI = [sys.executable, "-c",
       "import sys; from filmfriction.workflows.cli.main import main; sys.exit(main())"]


def _run(args: list[str]) -> float:
    """Run ``filmfriction run ARGS``; its wall time (SystemExit on failure)."""
    t0 = time.perf_counter()
    done = subprocess.run([*CLI, "run", *args], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        sys.exit(f"filmfriction run {' '.join(args)} failed ({done.returncode}):\n"
                 f"{done.stderr[-2000:]}")
    return wall


def _slips(run_dir: Path) -> int:
    from filmfriction.workflows.md.replicas.target import slip_values

    return len(slip_values(run_dir, ["static_force"])["static_force"])


def paired(args) -> dict:
    out = Path(args.out)
    rows = []
    before, t0 = cpu_snapshot(), time.perf_counter()
    for k in range(args.pairs):
        sides = ["replicas", "ranks"] if k % 2 == 0 else ["ranks", "replicas"]
        row = {}
        for side in sides:
            d = out / f"pair-{k + 1}" / side
            common = [args.scene, "--md-only", "--quiet", "--out", str(d), *args.set]
            if side == "replicas":
                wall = _run([*common, "--replicas", "2", "--np", "1"])
                slips = sum(_slips(d / f"replica-{i}") for i in (1, 2))
            else:
                wall = _run([*common, "--np", "2"])
                slips = _slips(d)
            row[side] = {"wall": wall, "slips": slips, "rate": slips / wall}
        # no slip on the 2-rank side: no ratio (a slide too short for the scene)
        row["ratio"] = (row["replicas"]["rate"] / row["ranks"]["rate"]
                        if row["ranks"]["slips"] else float("nan"))
        rows.append(row)
        print(f"pair {k + 1}: 2 replicas x 1 rank {row['replicas']['slips']} slips in "
              f"{row['replicas']['wall']:.1f} s; 1 run x 2 ranks {row['ranks']['slips']} "
              f"slips in {row['ranks']['wall']:.1f} s; ratio {row['ratio']:.2f}", flush=True)
    elapsed = time.perf_counter() - t0
    other = other_cpu_seconds(before, cpu_snapshot())

    def spread(values):
        return {"median": statistics.median(values), "min": min(values), "max": max(values)}
    result = {"scene": args.scene, "set": args.set, "pairs": rows,
              "replicas_rate": spread([r["replicas"]["rate"] for r in rows]),
              "ranks_rate": spread([r["ranks"]["rate"] for r in rows]),
              "ratio": spread([r["ratio"] for r in rows]),
              "elapsed": elapsed, "other_cpu_seconds": other, "cpus": _cpus()}
    q = result["ratio"]
    print(f"slips per wall-second: 2 replicas x 1 rank {result['replicas_rate']['median']:.3f} "
          f"({result['replicas_rate']['min']:.3f}-{result['replicas_rate']['max']:.3f}), "
          f"1 run x 2 ranks {result['ranks_rate']['median']:.3f} "
          f"({result['ranks_rate']['min']:.3f}-{result['ranks_rate']['max']:.3f})")
    print(f"ratio (replicas / ranks) over {len(rows)} pairs: median {q['median']:.2f} "
          f"(min {q['min']:.2f}, max {q['max']:.2f}); target >= 1.1")
    _say_other(other, elapsed, result["cpus"])
    return result


def _cpus() -> int:
    from filmfriction.workflows.inputs import usable_cpus

    return usable_cpus()


def _say_other(other, elapsed, cpus) -> None:
    if other is None:
        print(f"{elapsed:.0f} s; other work: unknown (no /proc/stat)")
        return
    share = other / (elapsed * cpus)
    print(f"{elapsed:.0f} s on {cpus} cores; other processes used {other:.0f} CPU-s meanwhile "
          f"({100 * share:.0f} % of the machine)"
          + ("; OTHER WORK RAN BESIDE IT: the figures are not an idle machine's" if share > 0.02
             else ""))


def coverage(args) -> dict:
    from scipy import stats

    from filmfriction.analysis.ensemble import combine_replicas
    from filmfriction.analysis.ensemble.replicas import ONE_SIGMA
    from filmfriction.workflows.md.replicas.replica_study import replica_seeds
    from filmfriction.workflows.md.scene import load
    from filmfriction.workflows.md.replicas.target import slip_values

    out = Path(args.out)
    base = load(args.scene).parameters["seed"]
    seeds = replica_seeds(base + 1, args.seeds)     # study seeds, apart from the scene's own
    studies = []
    before, t0 = cpu_snapshot(), time.perf_counter()
    for k, seed in enumerate(seeds, start=1):
        d = out / f"study-{k}"
        if not (d / "study.json").exists():
            _run([args.scene, "--replicas", str(args.replicas), "--target",
                  f"{args.observable}={args.target}", "--set", f"seed={seed}", "--md-only",
                  "--quiet", "--out", str(d), *args.set])
        record = json.loads((d / "study.json").read_text())
        values = [slip_values(d / r["dir"], [args.observable])[args.observable]
                  for r in record["replicas"]]
        last = record["segments"][-1]["checks"][0]
        studies.append({"seed": seed, "status": record["status"], "met": record["stop"]["met"],
                        "segments": len(record["segments"]),
                        "slide_steps": record["segments"][-1]["slide_steps"],
                        "mean": last["estimate"]["mean"],
                        "half_width": last["estimate"]["half_width"],
                        "relative_error": last["relative_error"], "n_slips": last["n_slips"],
                        "values": values})
        print(f"study {k} (seed {seed}): {record['status']}, {len(record['segments'])} "
              f"segment(s), {last['n_slips']} slips, {args.observable} {last['estimate']['mean']:.4g}"
              f" ± {last['estimate']['half_width']:.3g}", flush=True)
    covered = []
    for i, s in enumerate(studies):
        others = [v for j, o in enumerate(studies) if j != i for v in o["values"]]
        truth = combine_replicas(others).mean
        s["many_seed_mean"] = truth
        s["covered"] = abs(s["mean"] - truth) <= s["half_width"]
        covered.append(s["covered"])
    n, c = len(covered), sum(covered)
    lo = stats.beta.ppf((1 - ONE_SIGMA) / 2, c, n - c + 1) if c else 0.0
    hi = stats.beta.ppf(1 - (1 - ONE_SIGMA) / 2, c + 1, n - c) if c < n else 1.0
    allmean = combine_replicas([v for s in studies for v in s["values"]])
    elapsed = time.perf_counter() - t0
    other = other_cpu_seconds(before, cpu_snapshot())
    print(f"{args.observable} over every study: {allmean.mean:.4g} ± {allmean.half_width:.2g} "
          f"(68 %, {allmean.n_replicas} runs, {allmean.n_slips} slips)")
    print(f"coverage of the many-seed mean (leave-one-out) by the final ± 68 %: {c}/{n} = "
          f"{c / n:.2f} (Clopper-Pearson 68 %: {lo:.2f}-{hi:.2f}); nominal {ONE_SIGMA:.2f}")
    print(f"targets met: {sum(bool(s['met']) for s in studies)}/{n}; slips per study: median "
          f"{statistics.median(s['n_slips'] for s in studies)}; segments: median "
          f"{statistics.median(s['segments'] for s in studies)}")
    _say_other(other, elapsed, _cpus())
    return {"scene": args.scene, "set": args.set, "observable": args.observable,
            "target": args.target, "replicas": args.replicas, "studies": studies,
            "covered": c, "n": n, "coverage": c / n, "interval_68": [lo, hi],
            "nominal": ONE_SIGMA, "elapsed": elapsed, "other_cpu_seconds": other}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("part", choices=["coverage", "paired"])
    p.add_argument("--scene", default="stick-slip")
    p.add_argument("--set", action="append", default=[], type=lambda s: f"--set={s}",
                   metavar="KEY=VALUE", help="scene parameter for every run")
    p.add_argument("--out", required=True, help="a new directory for the runs and the JSON")
    p.add_argument("--pairs", type=int, default=5)
    p.add_argument("--seeds", type=int, default=20)
    p.add_argument("--replicas", type=int, default=2)
    p.add_argument("--observable", default="static_force")
    p.add_argument("--target", type=float, default=0.05)
    args = p.parse_args(argv)
    Path(args.out).mkdir(parents=True, exist_ok=True)
    result = paired(args) if args.part == "paired" else coverage(args)

    from filmfriction.workflows.md.replicas.replica_study import write_json

    write_json(Path(args.out) / f"{args.part}.json", result)
    print(f"-> {Path(args.out) / f'{args.part}.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
