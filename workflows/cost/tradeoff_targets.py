"""The wall time an error bar costs: replicas against MPI ranks, and the presets as targets.

``filmfriction tradeoff --targets`` answers, for each scene (the default ``stick-slip`` and
the Klein-similar ``sfb-similar``), how long it takes to know F_s, the slip duration τ_s and
η_eff to ± 10 %, ± 5 % and ± 3 % (68 % half-width over |mean|, the rule of
:mod:`filmfriction.analysis.ensemble.stopping`) on two cores, spent two ways:

* ``replicas``: 2 replicas × 1 rank (``run SCENE --replicas 2 --np 1``);
* ``ranks``: 1 run × 2 ranks (``run SCENE --replicas 1 --np 2``).

Each side is one study with a target on every observable at the tightest level (one
``filmfriction run --target OBS=REL ...`` per side, ``--md-only``), slid segment by segment
until every target is met or the budget is spent.  Each check of a study records its
wall time since the study started (``elapsed``) and each observable's error: the time to
± L on an observable is the ``elapsed`` of the first check at which that observable's
error met L (:func:`times_to_target`; the rule's test, :func:`check_met`).  The checks are
the tightest study's, so a looser level is read at those checks: a study asked only for
± L checks at its own, shorter segments, and may stop a segment earlier.  Both sides are
read the same way.

The two sides run one after the other in each pair, the order alternating between pairs;
each pair repeats the same seeds (the scene's own first, :func:`~filmfriction.workflows.md.replicas.replica_study.replica_seeds`),
so the pairs differ in their timing only.  The table gives each time's median and
min–max over the pairs, and the ratio ranks/replicas per pair (above 1: the replicas
were faster).  The CPU time other processes used meanwhile is measured: a figure taken
while other work ran is not an idle machine's, and the summary says so.

The presets as targets (:func:`preset_errors`): a run of each fidelity preset on 2 ranks
(the ranks side's first segment is ``standard``: the scene's own seed and slide), its
error on each observable (one run: within-run scatter only, start-up slip left out),
and the tightest level it meets; a preset that sets a key ``--set`` gives is not run
(:func:`preset_clash`).
"""
from __future__ import annotations

import json
import math
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from filmfriction.analysis.files.util import json_safe, write_atomic
from filmfriction.md_inputs.contract import STUDY_FILE

from .bench import cpu_snapshot, other_cpu_seconds

__all__ = ["LEVELS", "OBSERVABLES", "SIDES", "PRESETS", "Side", "side_command",
           "check_met", "times_to_target", "summarize", "preset_errors", "preset_clash",
           "run_targets", "collect_targets", "write_targets", "markdown"]

#: the relative errors asked (68 % half-width over |mean|)
LEVELS = (0.10, 0.05, 0.03)
#: the observables timed (per-slip columns of each replica's analysis)
OBSERVABLES = ("static_force", "slip_duration", "eta_eff")
#: the scenes of the study by default
SCENES = ("stick-slip", "sfb-similar")
#: the fidelity presets re-expressed as targets
PRESETS = ("preview", "standard", "reference")
#: the fewest slips a check judges (the rule's pilot, TargetError.min_slips)
MIN_SLIPS = 8


@dataclass(frozen=True)
class Side:
    """One way to spend two cores: ``replicas`` runs of ``ranks`` MPI ranks each."""

    name: str
    replicas: int
    ranks: int

    @property
    def label(self) -> str:
        return f"{self.replicas} {'replica' if self.replicas == 1 else 'replicas'} × " \
               f"{self.ranks} {'rank' if self.ranks == 1 else 'ranks'}"


SIDES = (Side("replicas", 2, 1), Side("ranks", 1, 2))

CLI = [sys.executable, "-c",
       "import sys; from filmfriction.workflows.cli.main import main; sys.exit(main())"]


def side_command(scene: str, side: Side, out: Path, *, levels=LEVELS,
                 observables=OBSERVABLES, budget: str | None = None,
                 sets=()) -> list[str]:
    """The ``filmfriction run`` arguments of one side's study: a target on every observable
    at the tightest level.

    >>> side_command("stick-slip", SIDES[0], Path("d"), budget="400000")[:8]
    ['run', 'stick-slip', '--replicas', '2', '--np', '1', '--md-only', '--quiet']
    """
    args = ["run", scene, "--replicas", str(side.replicas), "--np", str(side.ranks),
            "--md-only", "--quiet", "--out", str(out)]
    for s in sets:
        args += ["--set", s]
    tight = min(levels)
    for name in observables:
        args += ["--target", f"{name}={tight:g}"]
    if budget is not None:
        args += ["--budget", str(budget)]
    return args


def check_met(check: dict, level: float, min_slips: int = MIN_SLIPS) -> bool:
    """Whether a recorded check (``study.json``) meets ``level``: the rule's own test
    (:func:`~filmfriction.analysis.ensemble.check_target`: the pilot of slips, a finite
    error at or below the level).

    >>> check_met({"relative_error": 0.04, "n_slips": 9}, 0.05)
    True
    >>> check_met({"relative_error": 0.04, "n_slips": 7}, 0.05)
    False
    """
    rel = check.get("relative_error")
    return (int(check.get("n_slips") or 0) >= min_slips and rel is not None
            and math.isfinite(rel) and rel <= level)


def times_to_target(record: dict, levels=LEVELS, observables=OBSERVABLES) -> dict:
    """``{observable: {level: first check meeting it, or None}}`` of a study record; each
    check as ``{"seconds", "slide_steps", "n_slips", "relative_error"}`` (``seconds``: the
    check's ``elapsed``, wall time since the study started)."""
    targets = [t["observable"] for t in (record.get("rule") or {}).get("targets", [])]
    out = {}
    for name in observables:
        out[name] = {}
        for level in levels:
            hit = None
            if name in targets:
                k = targets.index(name)
                for seg in record.get("segments", []):
                    checks = seg.get("checks") or []
                    if len(checks) > k and check_met(checks[k], level):
                        hit = {"seconds": seg.get("elapsed"), "slide_steps": seg["slide_steps"],
                               "n_slips": checks[k]["n_slips"],
                               "relative_error": checks[k]["relative_error"]}
                        break
            out[name][f"{level:g}"] = hit
    return out


def _spread(values: list[float]) -> dict | None:
    values = [v for v in values if v is not None and math.isfinite(v)]
    if not values:
        return None
    return {"median": statistics.median(values), "min": min(values), "max": max(values),
            "n": len(values)}


def summarize(pairs: list[dict], levels=LEVELS, observables=OBSERVABLES) -> dict:
    """Over the pairs of one scene: each side's time to each (observable, level) (median,
    min–max, how many pairs reached it) and the ratio ranks/replicas of the pairs where
    both reached it."""
    out = {}
    for name in observables:
        out[name] = {}
        for level in levels:
            key = f"{level:g}"
            row = {}
            for side in SIDES:
                hits = [p[side.name]["to_target"][name][key] for p in pairs]
                row[side.name] = {"seconds": _spread([h["seconds"] for h in hits if h]),
                                  "reached": sum(h is not None for h in hits),
                                  "pairs": len(hits)}
            ratios = []
            for p in pairs:
                a = p["replicas"]["to_target"][name][key]
                b = p["ranks"]["to_target"][name][key]
                if a and b and a["seconds"]:
                    ratios.append(b["seconds"] / a["seconds"])
            row["ratio"] = _spread(ratios)
            out[name][key] = row
    return out


def _read_record(study: Path) -> dict:
    return json.loads((Path(study) / STUDY_FILE).read_text(encoding="utf-8"))


def preset_errors(run_dir: Path, levels=LEVELS, observables=OBSERVABLES) -> dict:
    """One run's error on each observable (the rule's check over its slips, start-up slip
    left out) and the tightest level it meets (None: none)."""
    from filmfriction.analysis.ensemble import TargetError, check_target

    from ..md.replicas.target import slip_values

    values = slip_values(Path(run_dir), observables)
    out = {}
    for name in observables:
        check = check_target([values[name]], TargetError(name, max(levels), MIN_SLIPS))
        met = [lv for lv in sorted(levels) if check_met(
            {"relative_error": check.relative_error, "n_slips": check.n_slips}, lv)]
        out[name] = {"relative_error": check.relative_error, "n_slips": check.n_slips,
                     "meets": met[0] if met else None}
    return out


def _run(args: list[str]) -> tuple[float, float | None]:
    """``filmfriction ARGS``; its wall time and the CPU seconds other processes used
    meanwhile (None off Linux; RuntimeError with its last lines on failure)."""
    before, t0 = cpu_snapshot(), time.perf_counter()
    done = subprocess.run([*CLI, *args], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        raise RuntimeError(f"filmfriction {' '.join(args)} failed ({done.returncode}): "
                           f"{done.stderr.strip()[-1500:]}")
    return wall, other_cpu_seconds(before, cpu_snapshot())


def run_targets(out: Path, *, scenes=SCENES, pairs: int = 3, levels=LEVELS,
                observables=OBSERVABLES, budget: str | None = None, sets=(),
                presets=PRESETS, log=print) -> dict:
    """Run the study into ``out`` (a new directory): per scene, ``pairs`` pairs of the two
    sides (order alternating), then one run per preset besides ``standard``; write
    ``targets.json`` and ``targets.md``; return the document."""
    from ..inputs import usable_cpus

    out = Path(out)
    out.mkdir(parents=True)
    doc = {"schema": "filmfriction.tradeoff-targets/1", "levels": list(levels),
           "observables": list(observables), "budget": budget, "set": list(sets),
           "cpus": usable_cpus(), "complete": False, "scenes": {}}
    before, t0 = cpu_snapshot(), time.perf_counter()

    def write(missing: str | None) -> None:
        # after every measurement: an interrupted study keeps what it measured
        doc["elapsed"] = time.perf_counter() - t0
        doc["other_cpu_seconds"] = other_cpu_seconds(before, cpu_snapshot())
        doc["complete"], doc["missing"] = missing is None, missing
        write_targets(out, doc)

    for scene in scenes:
        rows = []
        entry = doc["scenes"][scene] = {"pairs": rows,
                                        "summary": summarize(rows, levels, observables)}
        for k in range(pairs):
            order = SIDES if k % 2 == 0 else SIDES[::-1]
            pair = {"order": [s.name for s in order]}
            for side in order:
                d = out / scene / f"pair-{k + 1}" / side.name
                write(f"{scene}: pair {k + 1} of {pairs}, {side.label}, and what follows it")
                wall, other = _run(side_command(scene, side, d, levels=levels,
                                                observables=observables, budget=budget,
                                                sets=sets))
                pair[side.name] = _side_entry(d, wall, other, levels, observables)
                log(f"{scene} pair {k + 1} {side.label}: {pair[side.name]['status']} after "
                    f"{wall:.0f} s ({pair[side.name]['segments']} segment(s))")
            rows.append(pair)
            entry["summary"] = summarize(rows, levels, observables)
        if presets:
            entry["presets"] = {}
            _presets(out, scene, presets, rows, levels, observables, sets, log,
                     entry["presets"], lambda name: write(f"{scene}: preset {name} and what "
                                                          "follows it"))
    write(None)
    return doc


def _side_entry(study: Path, wall: float | None, other: float | None, levels,
                observables) -> dict:
    record = _read_record(study)
    return {"study": str(study), "wall": wall, "other_cpu_seconds": other,
            "status": record["status"], "slide_steps": record["segments"][-1]["slide_steps"],
            "segments": len(record["segments"]),
            "to_target": times_to_target(record, levels, observables)}


def write_targets(out: Path, doc: dict) -> None:
    """``targets.json`` and ``targets.md`` of ``doc`` (atomically)."""
    write_atomic(out / "targets.json", json.dumps(json_safe(doc), indent=1,
                                                  allow_nan=False) + "\n")
    write_atomic(out / "targets.md", markdown(doc))


def collect_targets(out: Path, levels=LEVELS, observables=OBSERVABLES,
                    presets=PRESETS) -> dict:
    """The document of a study directory ``out`` rebuilt from what its runs left: every
    side whose ``study.json`` is finished and every finished preset run (an interrupted
    study's, or one whose ``targets.json`` was lost).  Wall times are the records' own
    (a side: its study's ``elapsed``; a preset: its run's ``wall_time``); the CPU other
    processes used is not known afterwards (None)."""
    out = Path(out)
    doc = {"schema": "filmfriction.tradeoff-targets/1", "levels": list(levels),
           "observables": list(observables), "budget": None, "set": [],
           "cpus": None, "complete": True, "missing": None, "collected": True,
           "elapsed": None, "other_cpu_seconds": None, "scenes": {}}
    missing = []
    for scene_dir in sorted(p for p in out.iterdir() if p.is_dir()):
        rows = []
        for pair_dir in sorted(scene_dir.glob("pair-*"), key=lambda p: int(p.name[5:])):
            pair = {"order": []}
            for side in SIDES:
                d = pair_dir / side.name
                try:
                    record = _read_record(d)
                except (OSError, ValueError):
                    record = {}
                if not record.get("finished"):
                    missing.append(f"{scene_dir.name} {pair_dir.name} {side.label}")
                    continue
                pair["order"].append(side.name)
                pair[side.name] = _side_entry(d, record.get("elapsed"), None, levels,
                                              observables)
            if all(s.name in pair for s in SIDES):
                rows.append(pair)
        entry = {"pairs": rows, "summary": summarize(rows, levels, observables)}
        found = {}
        for name in presets:
            d = scene_dir / f"preset-{name}"
            if name == "standard" and rows:
                found[name] = _standard(rows, levels, observables)
                continue
            try:
                run = json.loads((d / "run.json").read_text(encoding="utf-8"))
            except (OSError, ValueError):
                run = {}
            if run.get("status") not in ("completed", "completed_with_warnings"):
                if d.exists():
                    missing.append(f"{scene_dir.name} preset {name} ({run.get('status') or 'no run.json'})")
                continue
            found[name] = {"run": str(d), "seconds": run.get("wall_time"),
                           "other_cpu_seconds": None,
                           "slide_steps": run["scene"]["parameters"]["slide_steps"],
                           "errors": preset_errors(d, levels, observables), "from": "its own run"}
        if found:
            entry["presets"] = found
        doc["scenes"][scene_dir.name] = entry
    if missing:
        doc["complete"], doc["missing"] = False, "; ".join(missing)
    return doc


def preset_clash(scene: str, name: str, sets=()) -> list[str]:
    """The ``--set`` keys that a preset's run of ``scene`` would refuse (the preset sets
    them itself: ``run --fidelity`` refuses a ``--set`` of the same key)."""
    from ..inputs import parse_overrides
    from ..md.fidelity import preset
    from ..md.scene import load

    user = parse_overrides(list(sets))
    return sorted(set(preset(name, load(scene, user).parameters)) & set(user))


def _standard(rows, levels, observables) -> dict:
    """The ``standard`` preset: the ranks side's first segment of the first pair."""
    record = _read_record(Path(rows[0]["ranks"]["study"]))
    run_dir = Path(rows[0]["ranks"]["study"]) / "replica-1"
    first = record["segments"][0]
    checks = dict(zip([t["observable"] for t in record["rule"]["targets"]],
                      first.get("checks") or []))
    errs = {}
    for obs in observables:
        c = checks.get(obs)
        met = [lv for lv in sorted(levels) if c and check_met(c, lv)]
        errs[obs] = {"relative_error": c["relative_error"] if c else None,
                     "n_slips": c["n_slips"] if c else 0,
                     "meets": met[0] if met else None}
    return {"run": str(run_dir), "seconds": first.get("elapsed"),
            "other_cpu_seconds": rows[0]["ranks"].get("other_cpu_seconds"),
            "slide_steps": first["slide_steps"], "errors": errs,
            "from": "the ranks side's first segment (pair 1)"}


def _presets(out, scene, presets, rows, levels, observables, sets, log, result,
             starting) -> None:
    """Each preset's run on 2 ranks and its errors into ``result`` (``starting(name)``
    before each run); ``standard`` (the scene as it is) is the ranks side's first
    segment of the first pair: no run of its own.  A preset whose keys a ``--set``
    gives is not run (the reason recorded)."""
    for name in presets:
        clash = preset_clash(scene, name, sets)
        if clash and name != "standard":
            result[name] = {"skipped": f"--set {', '.join(clash)} is a key of the preset"}
            log(f"{scene} preset {name}: not run ({result[name]['skipped']})")
            continue
        if name == "standard" and rows:
            result[name] = _standard(rows, levels, observables)
            continue
        d = out / scene / f"preset-{name}"
        args = ["run", scene, "--fidelity", name, "--np", "2", "--md-only", "--quiet",
                "--out", str(d)]
        for s in sets:
            args += ["--set", s]
        starting(name)
        wall, other = _run(args)
        run = json.loads((d / "run.json").read_text(encoding="utf-8"))
        result[name] = {"run": str(d), "seconds": wall, "other_cpu_seconds": other,
                        "slide_steps": run["scene"]["parameters"]["slide_steps"],
                        "errors": preset_errors(d, levels, observables), "from": "its own run"}
        log(f"{scene} preset {name}: {wall:.0f} s")


def _busy_measurements(doc: dict, threshold: float = 0.02) -> list[str]:
    """Each side's study and preset run during which other processes used more than
    ``threshold`` of the machine, as text."""
    cpus = doc.get("cpus") or 2
    out = []

    def share(item):
        other, wall = item.get("other_cpu_seconds"), item.get("wall", item.get("seconds"))
        if other is None or not wall:
            return None
        return other / (wall * cpus)

    for scene, entry in doc["scenes"].items():
        for k, pair in enumerate(entry["pairs"], start=1):
            for side in SIDES:
                x = share(pair.get(side.name, {}))
                if x is not None and x > threshold:
                    out.append(f"{scene} pair {k} {side.label} {100 * x:.0f} %")
        for name, p in (entry.get("presets") or {}).items():
            x = None if p.get("from", "").startswith("the ranks") else share(p)
            if x is not None and x > threshold:
                out.append(f"{scene} preset {name} {100 * x:.0f} %")
    return out


def _pct(level) -> str:
    return f"± {100 * float(level):g} %"


def _secs(s: dict | None) -> str:
    if not s:
        return "-"
    return f"{s['median']:.0f} s ({s['min']:.0f}–{s['max']:.0f})"


def markdown(doc: dict) -> str:
    """The tables: per scene, each (observable, level) on both sides with the ratio; then
    the presets as targets."""
    lines = ["# Wall time to a target error: 2 replicas × 1 rank against 1 run × 2 ranks", ""]
    if not doc.get("complete", True):
        lines += [f"INCOMPLETE: the study stopped before {doc.get('missing')}; the tables "
                  "hold what it measured.", ""]
    other = doc.get("other_cpu_seconds")
    if other is not None:
        share = other / max(1e-9, doc["elapsed"] * doc["cpus"])
        lines += [f"{doc['elapsed']:.0f} s on {doc['cpus']} cores; other processes used "
                  f"{other:.0f} CPU-s meanwhile ({100 * share:.0f} % of the machine)"
                  + ("; OTHER WORK RAN BESIDE IT: these are not an idle machine's figures."
                     if share > 0.02 else "."), ""]
    elif doc.get("collected"):
        lines += ["Collected from the runs' own records: the CPU time other processes used "
                  "while they ran is not known.", ""]
    busy = _busy_measurements(doc)
    if busy:
        lines += ["Measurements beside other work (other processes' CPU over the "
                  "measurement's wall time × cores; above 2 %): " + "; ".join(busy) + ".", ""]
    for scene, entry in doc["scenes"].items():
        n = len(entry["pairs"])
        lines += [f"## {scene}", "",
                  f"Seconds from the study's start to the first check meeting the target: "
                  f"median (min–max) over {n} pair(s); `k/n`: pairs that reached it within "
                  f"the budget; ratio: ranks / replicas per pair (> 1: replicas faster).", "",
                  "| observable | target | 2 replicas × 1 rank | 1 run × 2 ranks | ratio |",
                  "|---|---|---|---|---|"]
        for name, by_level in entry["summary"].items():
            for level, row in by_level.items():
                a, b = row["replicas"], row["ranks"]
                ratio = row["ratio"]
                lines.append(
                    f"| {name} | {_pct(level)} | {_secs(a['seconds'])} {a['reached']}/{a['pairs']}"
                    f" | {_secs(b['seconds'])} {b['reached']}/{b['pairs']} | "
                    + (f"{ratio['median']:.2f} ({ratio['min']:.2f}–{ratio['max']:.2f})"
                       if ratio else "-") + " |")
        if entry.get("presets"):
            obs = list(entry["summary"])
            lines += ["", "Presets as targets (one run on 2 ranks; its error is the slips' "
                      "scatter within that run; the tightest target met):", "",
                      "| preset | slide steps | seconds | " + " | ".join(obs) + " |",
                      "|---|---|---|" + "---|" * len(obs)]
            for name, p in entry["presets"].items():
                if p.get("skipped"):
                    lines.append(f"| {name} | not run: {p['skipped']} |" + " |" * (len(obs) + 1))
                    continue
                cells = []
                for o in obs:
                    e = p["errors"][o]
                    rel = e["relative_error"]
                    cells.append(("-" if rel is None or not math.isfinite(rel) else
                                  f"± {100 * rel:.1f} %") + f" ({e['n_slips']} slips) → "
                                 + (_pct(e["meets"]) if e["meets"] else "none"))
                sec = p.get("seconds")
                lines.append(f"| {name} | {p['slide_steps']} | "
                             f"{'-' if sec is None else f'{sec:.0f}'} | " + " | ".join(cells) + " |")
        lines.append("")
    return "\n".join(lines)
