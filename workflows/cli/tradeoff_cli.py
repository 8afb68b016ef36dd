"""``filmfriction tradeoff``: the cost and error of each numerical knob
(:mod:`filmfriction.workflows.cost.tradeoff`)."""
from __future__ import annotations

import argparse
import json
import sys
from datetime import datetime
from pathlib import Path

from ..cost.tradeoff import study
from ..cost.tradeoff_table import summary
from ..inputs import check_not_in_run, check_ranks, check_writable, UserError


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "tradeoff", help="cost and error of each numerical knob (timestep, cutoff, box, ...)",
        description="Run the stick-slip scene once per knob setting and tabulate the cost "
                    "and the error of the observables against each knob's reference, "
                    "with the statistical uncertainty of each error.")
    p.add_argument("--quick", action="store_true",
                   help="300 tau runs, few values (a few minutes on 2 cores)")
    p.add_argument("--json", action="store_true", help="print the rows as JSON on stdout")
    p.add_argument("--out", type=Path, default=None,
                   help="directory to create (default runs/tradeoff-<time>)")
    p.add_argument("--np", type=int, default=2, help="MPI ranks per run (default 2)")
    p.add_argument("--seeds", type=int, default=1,
                   help="runs per setting with successive seeds (default 1); with 2 or more "
                        "each error's uncertainty is the scatter over the runs, which one "
                        "run's slips can understate (N times the cost)")
    t = p.add_argument_group(
        "wall time to a target error (--targets)",
        "per scene: 2 replicas x 1 rank against 1 run x 2 ranks, each a study with a target "
        "on F_s, the slip duration and eta_eff at the tightest level, paired (order "
        "alternating); the seconds to each level's first met check, median and min-max "
        "over the pairs; then each fidelity preset's run and the tightest level it meets")
    t.add_argument("--targets", action="store_true",
                   help="time the targets instead of the knobs (writes targets.json, targets.md)")
    t.add_argument("--scene", dest="scenes", action="append", default=None, metavar="SCENE",
                   help="with --targets: a scene (several allowed; default stick-slip and "
                        "sfb-similar)")
    t.add_argument("--pairs", type=int, default=3,
                   help="with --targets: pairs of the two sides per scene (default 3)")
    t.add_argument("--levels", default="0.1,0.05,0.03", metavar="REL,REL,...",
                   help="with --targets: the relative errors (default 0.1,0.05,0.03)")
    t.add_argument("--budget", default=None, metavar="STEPS|DURATION",
                   help="with --targets: each study's budget, as for run --budget (default "
                        "10 times the scene's slide_steps)")
    t.add_argument("--presets", default="preview,standard,reference", metavar="NAME,...",
                   help="with --targets: the fidelity presets to run as targets (default "
                        "preview,standard,reference; 'reference' is 8 times a standard "
                        "run's atom-steps)")
    t.add_argument("--no-presets", dest="presets", action="store_const", const="",
                   help="with --targets: leave out the presets' runs (--presets '')")
    t.add_argument("--collect", type=Path, default=None, metavar="DIR",
                   help="with --targets: no runs; rebuild DIR's targets.json and targets.md "
                        "from the finished studies and preset runs in it (an interrupted "
                        "study; the existing files are kept as *.before)")
    t.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help="with --targets: a scene parameter for every run (e.g. a short "
                        "check of the command); a preset that sets the same key is not run")
    p.set_defaults(func=main)


def main(args: argparse.Namespace) -> int:
    if args.targets:
        return targets_main(args)
    if args.np < 1:
        raise UserError(f"--np {args.np}: need at least 1 MPI rank")
    if not 1 <= args.seeds <= 100:
        raise UserError(f"--seeds {args.seeds}: allowed 1 to 100 runs per setting")
    out = args.out or Path("runs") / f"tradeoff-{datetime.now():%Y%m%d-%H%M%S}"
    if out.exists():
        raise UserError(f"{out} already exists: the study never overwrites; choose a new --out")

    check_ranks(args.np)
    check_writable(out, "--out", directory=True)
    check_not_in_run(out, "--out")
    stream = sys.stderr if args.json else sys.stdout
    # flushed: the progress lines must show while the study runs, even in a log file

    def log(msg):
        if not args.quiet:
            print(msg, file=stream, flush=True)
    try:
        rows = study(args.quick, out, args.np, log, args.seeds)
    except RuntimeError as exc:
        print(f"filmfriction tradeoff: {exc}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(rows, indent=1, allow_nan=False))
    else:
        print(summary(rows))
        print(f"table: {out / 'tradeoff.csv'}; figures: {out}/pareto_*.png")
    return 0


def _levels(text: str) -> tuple[float, ...]:
    try:
        levels = tuple(sorted({float(x) for x in text.split(",") if x.strip()}, reverse=True))
    except ValueError:
        levels = ()
    if not levels or not all(0 < x < 1 for x in levels):
        raise UserError(f"--levels {text!r}: give relative errors between 0 and 1, "
                        "comma-separated, e.g. 0.1,0.05,0.03")
    return levels


def targets_main(args: argparse.Namespace) -> int:
    from ..cost.tradeoff_targets import SCENES, run_targets
    from ..inputs import parse_overrides, usable_cpus
    from ..md.scene import SceneError, load
    from ..md.replicas.target import TargetInputError, parse_budget

    from ..cost.tradeoff_targets import PRESETS

    if args.quick or args.json or args.seeds != 1 or args.np != 2:
        raise UserError("--targets times 2 replicas x 1 rank against 1 run x 2 ranks: "
                        "--quick, --json, --seeds and --np are not accepted with it")
    presets = tuple(x.strip() for x in args.presets.split(",") if x.strip())
    unknown = [x for x in presets if x not in PRESETS]
    if unknown:
        raise UserError(f"--presets {args.presets!r}: {', '.join(unknown)} is no preset; "
                        f"accepted: {', '.join(PRESETS)} (comma-separated) or ''")
    if args.collect is not None:
        return _collect(args.collect, _levels(args.levels), presets)
    if not 1 <= args.pairs <= 50:
        raise UserError(f"--pairs {args.pairs}: allowed 1 to 50 pairs per scene")
    levels = _levels(args.levels)
    if args.budget is not None:
        try:
            parse_budget(args.budget)
        except TargetInputError as exc:
            raise UserError(str(exc)) from None
    scenes = tuple(args.scenes or SCENES)
    overrides = parse_overrides(args.sets)
    for scene in scenes:             # every scene and --set checked before any run
        try:
            p = load(scene, overrides).parameters
        except SceneError as exc:
            raise UserError(str(exc)) from None
        if not p["restart_every"]:
            raise UserError(f"{scene}: restart_every = 0; a target extends the slide from "
                            "restart files (give --set restart_every=STEPS)")
    if usable_cpus() < 2:
        raise UserError(f"--targets compares two ways to use 2 cores; this process may use "
                        f"{usable_cpus()}")
    out = args.out or Path("runs") / f"tradeoff-targets-{datetime.now():%Y%m%d-%H%M%S}"
    if out.exists():
        raise UserError(f"{out} already exists: the study never overwrites; choose a new --out")
    check_writable(out, "--out", directory=True)
    check_not_in_run(out, "--out")

    def log(msg):
        if not args.quiet:
            print(msg, flush=True)
    try:
        run_targets(out, scenes=scenes, pairs=args.pairs, levels=levels, budget=args.budget,
                    sets=tuple(args.sets), presets=presets, log=log)
    except RuntimeError as exc:
        print(f"filmfriction tradeoff: {exc}", file=sys.stderr)
        return 1
    print((out / "targets.md").read_text(), end="")
    print(f"tables: {out / 'targets.md'}; every figure: {out / 'targets.json'}")
    return 0


def _collect(out: Path, levels, presets) -> int:
    """``--collect DIR``: the tables of an interrupted study from what its runs left."""
    from ..cost.tradeoff_targets import collect_targets, write_targets

    if not out.is_dir() or not any(out.glob("*/pair-*")) and not any(out.glob("*/preset-*")):
        raise UserError(f"--collect {out}: not a tradeoff --targets directory (no "
                        "<scene>/pair-<k>/ or <scene>/preset-<name>/ in it)")
    check_writable(out, "--collect", directory=True)
    doc = collect_targets(out, levels, presets=presets)
    stamp = f"{datetime.now():%Y%m%d-%H%M%S}"
    for name in ("targets.json", "targets.md"):      # kept, never overwritten
        if (out / name).exists():
            (out / name).rename(out / f"{name}.before-{stamp}")
    write_targets(out, doc)
    print((out / "targets.md").read_text(), end="")
    print(f"tables: {out / 'targets.md'}; every figure: {out / 'targets.json'}")
    return 0
