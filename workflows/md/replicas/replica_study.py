"""Replicas of one scene in one study directory, run until their error bars are small enough.

``filmfriction run SCENE --replicas N [--np P] [--target OBS=REL ...] [--budget B]``
creates a study directory::

    scene.toml          the resolved scene every replica starts from
    study.json          the study's record: seeds, the rule, each segment and check, why it stopped
    replica-<i>/        one run directory per replica (the runner's, see runner.py)
    replica-<i>.log     what replica i's runs printed
    ensemble.json       the observables combined over the replicas (combine_replicas)
    ensemble.md         the same as a report: between- and within-run parts, per-replica rows
    segments/           with --profile: each segment's replica jobs and their markers
    superseded/         replica directories that held nothing to resume, kept (afresh.py)
    snakemake.log       with --profile: Snakemake's output (workflows/sweep/replica_jobs.py)

Each replica is a ``filmfriction run`` of its own (a child process with its own seed, lock,
interruption handling, sanity checks and ``run.json``), ``P`` ranks each (1 by default), as
many at once as the usable CPUs hold (:func:`filmfriction.workflows.inputs.cap_workers`).
With targets, every replica slides the scene's ``slide_steps`` (the first segment), then
the slide is extended segment by segment (``run --resume DIR --slide-to STEPS``, from the
newest restart file) until every target is met or the budget is spent
(:mod:`filmfriction.workflows.md.target`).  The study directory is locked while a command
drives it; Ctrl-C, SIGTERM or SIGHUP interrupt every replica (each records its own
interruption) and the study, and ``filmfriction run --resume STUDY`` carries on where it
stopped: each replica from its newest restart file, or, with none (stopped before its
first), from its beginning with its seed, its old directory moved to ``superseded/``
(:mod:`.afresh`).  ``study.json`` keeps each replica's run status.  With ``--profile`` a
segment's replicas are Snakemake jobs instead of this process's children (an ``executor``
the command line gives: one Slurm job per replica with the ``slurm`` profile); everything
else is the same.
"""
from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from filmfriction.analysis.ensemble import check_target, combine_replicas
from filmfriction.analysis.files.util import write_atomic
from filmfriction.md_inputs.contract import (ANALYSIS_FILE, ENSEMBLE_FILE, ENSEMBLE_REPORT_FILE, REPLICA_DIR,
                                             REPLICA_LOG, RUN_FILE, SCENE_FILE, STUDY_FILE)
from ..locks import DirectoryLock
from ..run_record import OWN_SCRIPT, new_run_dir, scene_toml
from ..scene import Scene, SceneError
from .afresh import list_moves, replica_state, start_again, why_not_resumable
from .target import OBSERVABLES, Budget, next_slide, slip_values

__all__ = ["MAX_REPLICAS", "replica_seeds", "replica_dir", "replica_log", "is_study",
           "replica_state", "run_study", "resume_study", "combine_study"]

SCHEMA = "filmfriction.replicas/1"
#: the most replicas one study runs (more is a typo, or a job for the sweep)
MAX_REPLICAS = 256
#: a target without --budget spends at most this many times the first segment
DEFAULT_BUDGET_SEGMENTS = 10
#: seconds a replica has to record its interruption before it is killed
STOP_GRACE = 60.0


#: the largest seed drawn for a replica: LAMMPS's Marsaglia generator (fix langevin, seeded
#: with the seed plus the rank, plus up to 4, plus 104729 per restart segment) refuses
#: seeds above 900 000 000
MAX_DRAWN_SEED = 800_000_000


def replica_seeds(seed: int, count: int) -> list[int]:
    """The seeds of ``count`` replicas: the scene's own first, then distinct ones drawn
    from it in [1, :data:`MAX_DRAWN_SEED`] (reproducible: the same scene seed gives the
    same replicas).

    >>> replica_seeds(4928459, 3)[0], len(set(replica_seeds(4928459, 50)))
    (4928459, 50)
    """
    rng = np.random.default_rng(np.random.SeedSequence(int(seed)))
    seeds = [int(seed)]
    while len(seeds) < count:
        s = int(rng.integers(1, MAX_DRAWN_SEED + 1))
        if s not in seeds:
            seeds.append(s)
    return seeds


def replica_dir(study: Path, index: int) -> Path:
    """Replica ``index``'s run directory (1-based) in the study directory."""
    return Path(study) / REPLICA_DIR.format(index=index)


def replica_log(study: Path, index: int) -> Path:
    """What replica ``index``'s runs printed (every segment appended)."""
    return Path(study) / REPLICA_LOG.format(index=index)


def is_study(path: Path) -> bool:
    """True for a study directory (it holds ``study.json``)."""
    return (Path(path) / STUDY_FILE).is_file()


def _lock(study: Path) -> DirectoryLock:
    return DirectoryLock(study / ".lock", lambda holder: SceneError(
        f"study directory {study} is in use ({holder}: a run or a resume is driving it); "
        "wait for it to finish, or stop that process first"))


def write_json(path: Path, doc: dict) -> None:
    """Strict JSON (NaN → null), written atomically."""
    from filmfriction.analysis.files.util import json_default, json_safe

    write_atomic(path, json.dumps(json_safe(doc), indent=2, default=json_default,
                                  allow_nan=False) + "\n")


def _now() -> str:
    return datetime.now(timezone.utc).isoformat()


def _cli() -> list[str]:
    """The command that starts a ``filmfriction`` of this installation."""
    return [sys.executable, "-c",
            "import sys; from filmfriction.workflows.cli.main import main; sys.exit(main())"]


# ---------------------------------------------------------------- a new study
def run_study(scene: Scene, *, replicas: int, nprocs: int = 1, targets=(),
              budget: Budget | None = None, out: Path | None = None,
              lmp: str | None = None, workers: int = 1, executor=None,
              profile: str | None = None) -> tuple[Path, int]:
    """Run ``replicas`` replicas of ``scene`` in a new study directory, ``workers`` at
    once; return it and the exit code (0 done, 1 a replica failed).  Inputs are the
    caller's to check (the command line does, before this, and caps ``workers`` to the
    usable CPUs).  ``executor(study, record, slide, indices, workers) -> {index: exit
    code}`` runs a segment's replicas instead of this process's own children (the
    Snakemake jobs of :mod:`filmfriction.workflows.sweep.replica_jobs`, recorded as
    ``profile``)."""
    restart_every = int(scene.parameters["restart_every"])
    if targets and restart_every <= 0:
        raise SceneError("--target extends the slide from restart files: the scene has "
                         "restart_every = 0; give --set restart_every=STEPS")
    first = int(scene.parameters["slide_steps"])
    if targets and budget is None:
        budget = Budget(steps=DEFAULT_BUDGET_SEGMENTS * first)
    if budget is not None and budget.steps is not None:
        first = min(first, budget.steps)
    study = new_run_dir(scene.name, out)
    seeds = replica_seeds(scene.parameters["seed"], replicas)
    if scene.script:            # the scene's own script beside its copy (scene.toml names it)
        write_atomic(study / OWN_SCRIPT, Path(scene.script).read_bytes())
    write_atomic(study / SCENE_FILE, scene_toml(scene))
    record = {
        "schema": SCHEMA, "status": "running", "scene": scene.name,
        "command": sys.argv[:], "np": nprocs, "lmp": lmp, "profile": profile,
        "replicas": [{"dir": replica_dir(study, i + 1).name, "seed": s}
                     for i, s in enumerate(seeds)],
        "rule": None if not targets else {
            "targets": [{"observable": t.observable, "relative": t.relative,
                         "min_slips": t.min_slips} for t in targets],
            "budget": budget.as_dict(), "first_segment": first,
            "restart_every": restart_every,
            "start_up_slips_left_out": 1,
            "error": "68 % half-width over |mean| (random effects over the replicas, "
                     "analysis/ensemble)"},
        "segments": [{"slide_steps": first}],
        "started": _now(),
    }
    write_json(study / STUDY_FILE, record)
    return study, _drive(study, record, targets, budget, workers, executor)


def resume_study(study: Path, nprocs: int | None = None, lmp: str | None = None,
                 workers=None, executor=None, profile: str | None = None) -> int:
    """Carry on an interrupted (or failed) study from where each replica stopped (one
    with nothing to resume from its beginning, :mod:`.afresh`);
    ``workers(ranks)`` says how many replicas of ``ranks`` ranks run at once;
    ``executor(profile, ranks)`` gives the runner of a study recorded with a profile, or
    given one (``profile``), as for :func:`run_study`."""
    from filmfriction.analysis.ensemble import TargetError

    study = Path(study)
    path = study / STUDY_FILE
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise SceneError(f"{path}: not a readable study record ({exc})") from None
    if not isinstance(record, dict) or record.get("schema") != SCHEMA:
        raise SceneError(f"{path}: not a study record (schema {SCHEMA})")
    if record.get("status") not in ("interrupted", "failed", "running"):
        raise SceneError(f"{study} already {record.get('status')}; nothing to resume")
    rule = record.get("rule") or {}
    targets = tuple(TargetError(t["observable"], t["relative"], t.get("min_slips", 8))
                    for t in rule.get("targets", []))
    budget = Budget(**rule["budget"]) if rule.get("budget") else None
    if nprocs:
        record["np"] = nprocs
    if lmp:
        record["lmp"] = lmp
    if profile:
        record["profile"] = profile
    record.setdefault("resumed", []).append(_now())
    ranks = int(record.get("np") or 1)
    run = executor(record["profile"], ranks) if executor and record.get("profile") else None
    return _drive(study, record, targets, budget, workers(ranks) if workers else 1, run)


# ---------------------------------------------------------------- the segments
def _statuses(study: Path, record: dict) -> None:
    """Each replica's run status (its ``run.json``; None without one) in ``record``."""
    for i, rep in enumerate(record["replicas"], start=1):
        try:
            rep["status"] = json.loads((replica_dir(study, i) / RUN_FILE).read_text(
                encoding="utf-8")).get("status")
        except (OSError, ValueError, AttributeError):
            rep["status"] = None


def _commands(study: Path, record: dict, slide: int) -> dict[int, list[str]]:
    """The ``filmfriction run`` of each replica not yet at ``slide`` steps."""
    np_, lmp = str(record.get("np") or 1), record.get("lmp")
    extra = ["--lmp", lmp] if lmp else []
    jobs = {}
    for i, rep in enumerate(record["replicas"], start=1):
        run_dir = replica_dir(study, i)
        state = replica_state(run_dir, slide)
        if state == "start":
            jobs[i] = [*_cli(), "run", str(study / SCENE_FILE), "--set", f"seed={rep['seed']}",
                       "--set", f"slide_steps={slide}", "--np", np_, "--out", str(run_dir),
                       "--md-only", *extra]
        elif state == "resume":
            jobs[i] = [*_cli(), "run", "--resume", str(run_dir), "--slide-to", str(slide),
                       "--np", np_, "--md-only", *extra]
        elif state == "restart":        # start_again moves these aside first
            raise SceneError(f"{run_dir}: nothing to resume ({why_not_resumable(run_dir)})")
    return jobs


def _run_jobs(study: Path, jobs: dict[int, list[str]], workers: int) -> dict[int, int]:
    """Run the replicas' commands, ``workers`` at once; their exit codes.  An interruption
    of this process interrupts every replica (SIGINT: each records its own) and waits for
    them, then goes on up."""
    from ...progress import note

    pending, running, codes = sorted(jobs), {}, {}
    try:
        while pending or running:
            while pending and len(running) < workers:
                i = pending.pop(0)
                with open(replica_log(study, i), "a") as log:
                    log.write(f"# {_now()} {' '.join(jobs[i][3:])}\n")
                    log.flush()
                    running[i] = subprocess.Popen(jobs[i], stdout=log, stderr=subprocess.STDOUT,
                                                  stdin=subprocess.DEVNULL,
                                                  start_new_session=True)
            time.sleep(0.2)
            for i, proc in list(running.items()):
                if proc.poll() is not None:
                    codes[i] = proc.returncode
                    del running[i]
                    note(f"replica {i}: {'done' if proc.returncode == 0 else 'exit code %d (see %s)' % (proc.returncode, replica_log(study, i))}")
    except BaseException:
        for proc in running.values():
            try:
                proc.send_signal(signal.SIGINT)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + STOP_GRACE
        for proc in running.values():
            try:
                proc.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                proc.kill()
        raise
    return codes


def _last_line(path: Path) -> str:
    """The last line a replica printed (its error, as a rule)."""
    try:
        lines = [x for x in path.read_text(errors="replace").splitlines() if x.strip()]
    except OSError:
        return "no output"
    return lines[-1].strip() if lines else "no output"


def _values(study: Path, record: dict, observables) -> list[dict[str, list[float]]]:
    return [slip_values(replica_dir(study, i), observables)
            for i in range(1, len(record["replicas"]) + 1)]


def _analysis_digests(study: Path, record: dict) -> dict[str, str]:
    """The SHA-256 of each replica's ``analysis.json`` a check read (which analysis of
    which trace the numbers are)."""
    from filmfriction.analysis.files.provenance import file_sha256

    return {rep["dir"]: file_sha256(replica_dir(study, i) / ANALYSIS_FILE)
            for i, rep in enumerate(record["replicas"], start=1)}


def _warnings(study: Path, record: dict) -> list[str]:
    out = []
    for i in range(1, len(record["replicas"]) + 1):
        try:
            rec = json.loads((replica_dir(study, i) / RUN_FILE).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        out += [f"replica {i}: {w}" for w in rec.get("warnings") or []]
    return out


def _local(study: Path, record: dict, slide: int, indices, workers: int) -> dict[int, int]:
    """This process's own children run the replicas' ``filmfriction run`` commands."""
    jobs = _commands(study, record, slide)
    return _run_jobs(study, {i: jobs[i] for i in indices}, workers)


def _drive(study: Path, record: dict, targets, budget: Budget | None, workers: int,
           executor=None) -> int:
    from ...progress import note
    from ..runner import TerminationAsInterrupt

    path = study / STUDY_FILE
    nprocs = int(record.get("np") or 1)
    workers = max(1, min(int(workers), len(record["replicas"])))
    rule = record.get("rule") or {}
    # wall seconds the study has been driven (this command's and earlier ones'): each
    # check records it as "elapsed" (what `filmfriction tradeoff --targets` reads)
    t_start, before = time.monotonic(), float(record.get("elapsed") or 0.0)

    def elapsed() -> float:
        return before + time.monotonic() - t_start

    with TerminationAsInterrupt():
        lock = _lock(study).acquire()
        try:
            record["status"] = "running"
            write_json(path, record)
            while True:
                seg = record["segments"][-1]
                slide = int(seg["slide_steps"])
                if start_again(study, record, slide):
                    write_json(path, record)
                jobs = _commands(study, record, slide)
                if jobs:
                    how = (f"{workers} at once" if executor is None else
                           f"as Snakemake jobs (profile {record.get('profile')})")
                    note(f"replicas: {len(jobs)} run(s) to slide step {slide}, {how}, "
                         f"{nprocs} rank(s) each (logs: {study}/replica-*.log)")
                seg.setdefault("started", _now())
                seg["at_once"], seg["ranks_each"] = workers, nprocs
                t0 = time.monotonic()
                codes = (executor or _local)(study, record, slide, sorted(jobs), workers) \
                    if jobs else {}
                seg["wall_time"] = seg.get("wall_time", 0.0) + time.monotonic() - t0
                seg["finished"] = _now()
                list_moves(study, record)
                _statuses(study, record)
                failed = {i: c for i, c in codes.items() if c != 0}
                if failed:
                    i, c = sorted(failed.items())[0]
                    why = (f"replica {i} ({replica_dir(study, i).name}) exited with code {c} "
                           f"at slide {slide}: {_last_line(replica_log(study, i))} (see "
                           f"{replica_log(study, i)})")
                    record.update(status="failed", stop={"reason": why, "met": False},
                                  warnings=_warnings(study, record), finished=_now(),
                                  elapsed=elapsed())
                    write_json(path, record)
                    note(f"replicas: failed: {why}; continue with "
                         f"filmfriction run --resume {study}")
                    return 1
                if not targets:
                    record["stop"] = {"reason": "no target: every replica slid "
                                                f"{slide} steps", "met": None}
                    break
                values = _values(study, record, [t.observable for t in targets])
                checks = [check_target([v[t.observable] for v in values], t) for t in targets]
                seg["checks"] = [c.as_dict() for c in checks]
                seg["analyses"] = _analysis_digests(study, record)
                seg["elapsed"] = record["elapsed"] = elapsed()
                met = all(c.met for c in checks)
                spent = sum(s.get("wall_time", 0.0) for s in record["segments"])
                out_of = (budget.steps is not None and slide >= budget.steps) or \
                    (budget.seconds is not None and spent >= budget.seconds)
                for t, c in zip(targets, checks):
                    now = (f"± {100 * c.relative_error:.2f} %" if math.isfinite(
                        c.relative_error) else "no error yet")
                    note(f"replicas: slide {slide}: {t.observable} {now} (target ± "
                         f"{100 * t.relative:.2f} %) over {c.n_slips} slip(s) in "
                         f"{c.estimate.n_replicas} run(s): {'met' if c.met else 'not met'}")
                if met:
                    record["stop"] = {"reason": "every target met: " +
                                      "; ".join(c.reason for c in checks), "met": True}
                    break
                if out_of:
                    spent_what = (f"{budget.steps} slide steps per replica" if budget.steps
                                  is not None and slide >= budget.steps else
                                  f"{budget.seconds:g} s of wall time ({spent:.0f} s spent)")
                    record["stop"] = {"reason": f"budget spent ({spent_what}) with a target "
                                      "not met: " + "; ".join(c.reason for c in checks
                                                              if not c.met), "met": False}
                    break
                nxt = max(next_slide(slide, int(rule["restart_every"]),
                                     relative=c.relative_error, target=t.relative,
                                     budget_steps=budget.steps, first=rule["first_segment"])
                          for t, c in zip(targets, checks) if not c.met)
                seg["next"] = nxt
                record["segments"].append({"slide_steps": nxt})
                write_json(path, record)
            warnings = _warnings(study, record)
            record.update(warnings=warnings, finished=_now(), elapsed=elapsed(),
                          status="completed" if record["stop"]["met"] is not False
                          else "target_not_met")
            write_json(path, record)
            note(f"replicas: stopped: {record['stop']['reason']}")
            return 0
        except KeyboardInterrupt as exc:
            list_moves(study, record)
            _statuses(study, record)
            record.update(status="interrupted", finished=_now(), elapsed=elapsed(),
                          stop={"reason": f"interrupted ({str(exc) or 'SIGINT'}); resume with "
                                          f"filmfriction run --resume {study}", "met": False})
            try:
                write_json(path, record)
            except OSError:
                pass
            exc.run_dir, exc.resume_command = study, f"filmfriction run --resume {study}"
            raise
        except BaseException as exc:
            if record.get("status") == "running":
                record.update(status="failed", finished=_now(),
                              stop={"reason": str(exc) or type(exc).__name__, "met": False})
                try:
                    write_json(path, record)
                except OSError:
                    pass
            raise
        finally:
            lock.release()


# ---------------------------------------------------------------- the combined analysis
def combine_study(study: Path) -> dict:
    """Every per-slip observable combined over the replicas (start-up slip left out of
    each), written to ``ensemble.json`` and ``ensemble.md``; returns the document.  The
    values are each replica's own analysis (:func:`~.target.slip_values`: the one the last
    check read, analysed again only when its run changed since)."""
    from filmfriction.analysis.files.provenance import provenance

    study = Path(study)
    record = json.loads((study / STUDY_FILE).read_text(encoding="utf-8"))
    values = _values(study, record, OBSERVABLES)
    observables = {}
    for name in OBSERVABLES:
        est = combine_replicas([v[name] for v in values])
        observables[name] = est.as_dict()
    doc = {"schema": "filmfriction.ensemble/1", "study": str(study),
           "replicas": [{**rep, "slips": len(v[OBSERVABLES[0]])}
                        for rep, v in zip(record["replicas"], values)],
           "start_up_slips_left_out": 1,
           "error": "stderr: random effects (pooled within-run scatter, DerSimonian-Laird "
                    "between-run variance, the larger of the inverse-weight and "
                    "Hartung-Knapp errors); half_width: 68 % with Student's t",
           "observables": observables, "stop": record.get("stop"),
           "provenance": provenance({f"replica {i + 1}": replica_dir(study, i + 1) / RUN_FILE
                                     for i in range(len(record["replicas"]))})}
    write_json(study / ENSEMBLE_FILE, doc)
    write_atomic(study / ENSEMBLE_REPORT_FILE, ensemble_markdown(doc, record))
    return doc


def _g(x) -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.4g}"


def ensemble_markdown(doc: dict, record: dict) -> str:
    """The combined observables as a Markdown report: one row per observable (mean,
    68 % half-width, within- and between-run parts), then each replica's rows."""
    lines = [f"# {record['scene']}: {len(record['replicas'])} replica(s)", "",
             f"Stopped: {(record.get('stop') or {}).get('reason', '-')}", "",
             "Mean over the replicas (start-up slip of each left out); ± is the 68 % "
             "half-width (t); within: the error of the slips' noise alone; between: τ, "
             "the run-to-run scatter beyond it.", "",
             "| observable | mean | ± (68 %) | stderr | within | between (τ) | runs | slips |",
             "|---|---|---|---|---|---|---|---|"]
    for name, e in doc["observables"].items():
        lines.append(f"| {name} | {_g(e['mean'])} | {_g(e['half_width'])} | {_g(e['stderr'])} "
                     f"| {_g(e['within'])} | {_g(e['between'])} | {e['n_replicas']} | "
                     f"{e['n_slips']} |")
    lines += ["", "Per replica (mean ± standard error with the pooled within-run scatter; "
              "status: its run's, with its sanity checks):",
              "", "| replica | seed | " + " | ".join(doc["observables"]) + " | status |",
              "|---|---|" + "---|" * (len(doc["observables"]) + 1)]
    for i, rep in enumerate(record["replicas"]):
        cells = []
        for e in doc["observables"].values():
            rows = e["replicas"]
            # combine_replicas leaves out replicas without values: match by position only
            # when every replica has some
            r = rows[i] if len(rows) == len(record["replicas"]) else None
            cells.append("-" if r is None else f"{_g(r['mean'])} ± {_g(r['stderr'])} ({r['n']})")
        lines.append(f"| {rep['dir']} | {rep['seed']} | " + " | ".join(cells)
                     + f" | {rep.get('status') or '-'} |")
    if record.get("warnings"):
        lines += ["", "Sanity checks broken (each replica's run.json 'warnings'):", ""]
        lines += [f"- {w}" for w in record["warnings"]]
    moved = [(rep["dir"], e) for rep in record["replicas"] for e in rep.get("superseded", [])]
    if moved:
        lines += ["", "Started again from the beginning (nothing to resume; the old "
                  "directory kept):", ""]
        lines += [f"- {name}: {e['dir']} ({e['why']})" for name, e in moved]
    checks = [(s["slide_steps"], c) for s in record.get("segments", [])
              for c in s.get("checks", [])]
    if checks:
        lines += ["", "Checks of the target after each segment:", "",
                  "| slide steps | check |", "|---|---|"]
        lines += [f"| {steps} | {c['reason']} |" for steps, c in checks]
    return "\n".join(lines) + "\n"
