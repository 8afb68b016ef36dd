"""A slide extended segment by segment until its error bar is small enough.

``filmfriction run SCENE --target static_force=0.05`` asks for the mean static force to
± 5 % (the 68 % half-width over |mean|, :class:`~filmfriction.analysis.ensemble.TargetError`).
The run slides ``slide_steps`` (the first segment), then, while a target is not met and
the budget allows, continues from its newest restart file to a longer slide (the runner's
resume, :func:`filmfriction.workflows.md.runner.resume` with ``slide_steps``).  After each
segment every target is checked on the per-slip values of every replica's own analysis
(``analysis.json`` and ``analysis_cycles.csv``, made once per segment and read again by the
combined analysis), the start-up slip of each left out (:func:`slip_values`,
:func:`~filmfriction.analysis.ensemble.check_target`).

This module holds what the rule needs apart from running LAMMPS: the parsing of
``--target`` and ``--budget`` (each refused with one line before any compute), the per-slip
values of a run directory's analysis, the length of the next segment, and the change to a run
record that lets a run (completed too) slide further (:func:`extend_record`).

Examples
--------
>>> parse_target("static_force=0.05")
TargetError(observable='static_force', relative=0.05, min_slips=8)
>>> parse_budget("200000"), parse_budget("90m")
(Budget(steps=200000, seconds=None), Budget(steps=None, seconds=5400.0))
>>> next_slide(100000, 20000, relative=0.08, target=0.05, budget_steps=400000)
160000
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, fields
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from filmfriction.analysis.ensemble import TargetError
from filmfriction.md_inputs.contract import ANALYSIS_FILE
from filmfriction.reduced_model.cycles import CycleTable

from ..scene import SceneError

__all__ = ["OBSERVABLES", "Budget", "parse_target", "parse_budget", "replica_analysis",
           "slip_values",
           "next_slide", "extend_record"]

#: the per-slip observables a target may name: the cycle table's columns of values and
#: the effective viscosity of each slip, as ``analysis_cycles.csv`` names them
OBSERVABLES = tuple(f.name for f in fields(CycleTable)
                    if f.name not in ("yield_index", "stick_index", "yield_time",
                                      "stick_time", "uncertainty", "spring_constant")) \
    + ("eta_eff",)

#: a budget in wall time: a number and its unit
_DURATION = re.compile(r"^\s*([0-9]+(?:\.[0-9]*)?)\s*(s|m|min|h|d)\s*$")
_SECONDS = {"s": 1.0, "m": 60.0, "min": 60.0, "h": 3600.0, "d": 86400.0}


class TargetInputError(ValueError):
    """A ``--target`` or ``--budget`` the rule cannot take (one line: the value and what
    is accepted)."""


@dataclass(frozen=True)
class Budget:
    """What a target may spend: ``steps`` of slide per replica, or ``seconds`` of wall
    time (checked between segments: a segment under way is finished)."""

    steps: int | None = None
    seconds: float | None = None

    def as_dict(self) -> dict:
        return {"steps": self.steps, "seconds": self.seconds}


def parse_target(text: str) -> TargetError:
    """``OBSERVABLE=REL`` → :class:`TargetError`; :class:`TargetInputError` otherwise."""
    name, sep, value = str(text).partition("=")
    name = name.strip()
    accepted = f"OBSERVABLE=REL with OBSERVABLE one of {', '.join(OBSERVABLES)}"
    if not sep:
        raise TargetInputError(f"--target {text!r}: give {accepted} and REL in (0, 1), "
                               "e.g. static_force=0.05")
    if name not in OBSERVABLES:
        raise TargetInputError(f"--target {text!r}: unknown observable {name!r}; accepted: "
                               f"{', '.join(OBSERVABLES)}")
    try:
        rel = float(value)
    except ValueError:
        rel = math.nan
    if not (math.isfinite(rel) and 0 < rel < 1):
        raise TargetInputError(f"--target {text!r}: relative error {value.strip()!r}; "
                               "accepted: a number between 0 and 1, e.g. 0.05 for ± 5 %")
    return TargetError(name, rel)


def parse_targets(texts) -> tuple[TargetError, ...]:
    """Every ``--target``, each observable once."""
    targets = tuple(parse_target(t) for t in texts)
    names = [t.observable for t in targets]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise TargetInputError(f"--target {twice[0]} given twice: give each observable once")
    return targets


def parse_budget(text: str) -> Budget:
    """``STEPS`` (slide steps per replica, a whole number ≥ 1, ``_`` allowed) or a
    ``DURATION`` (``45s``, ``90m``, ``2h``, ``1d``) → :class:`Budget`."""
    raw = str(text).strip()
    digits = raw.replace("_", "")
    if digits.isdigit():
        steps = int(digits)
        if 1 <= steps <= 2**31 - 1:
            return Budget(steps=steps)
    else:
        m = _DURATION.match(raw)
        if m and float(m.group(1)) > 0:
            return Budget(seconds=float(m.group(1)) * _SECONDS[m.group(2)])
    raise TargetInputError(f"--budget {text!r}: give slide steps per replica (a whole number "
                           f"in [1, {2**31 - 1}]) or a wall time (e.g. 45s, 90m, 2h, 1d)")


def replica_analysis(run_dir: Path) -> Path:
    """``run_dir``'s own ``analysis.json`` (the project's analysis,
    :func:`filmfriction.analysis.analyze.analyse_run`), made when it is missing or was made
    from other inputs than the run's files now (its trace and ``run.json``, compared by
    SHA-256: a slide extended since is analysed again); returns its path."""
    from filmfriction.analysis.analyze import analyse_run

    path = Path(run_dir) / ANALYSIS_FILE
    if not _analysis_current(path):
        analyse_run(run_dir)
    return path


def _analysis_current(path: Path) -> bool:
    from filmfriction.analysis.files.provenance import file_sha256

    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        inputs = doc["provenance"]["inputs"]
        if "trace" not in inputs or not (path.parent / doc["cycles_csv"]).is_file():
            return False
        return all(file_sha256(path.parent / Path(e["path"]).name) == e["sha256"]
                   for e in inputs.values())
    except (OSError, ValueError, KeyError, TypeError):
        return False


def slip_values(run_dir: Path, observables) -> dict[str, list[float]]:
    """Each observable's per-slip values in ``run_dir``'s own analysis
    (``analysis_cycles.csv`` beside :func:`replica_analysis`'s ``analysis.json``), the
    start-up slip (the first row) left out; empty lists for a trace too short to
    analyse."""
    from filmfriction.analysis.files.cycles_csv import read_cycles_csv

    path = replica_analysis(run_dir)
    doc = json.loads(path.read_text(encoding="utf-8"))
    columns = read_cycles_csv(path.parent / doc["cycles_csv"])
    return {name: [float(v) for v in np.asarray(columns.get(name, []), float)[1:]]
            for name in observables}


def next_slide(slide: int, restart_every: int, *, relative: float, target: float,
               budget_steps: int | None, first: int | None = None) -> int:
    """The slide (in steps, in all) the next segment runs to.

    The error falls as 1/√slips: ``(relative/target)²`` times the slide so far would meet
    the target; the next segment goes a third of the way there beyond ``slide`` (an
    estimate from few slips overshoots as easily as it falls short), at least
    ``restart_every`` steps and at most ``first`` (the first segment's length, default
    ``slide``), in whole restart intervals, and never past ``budget_steps``.
    """
    first = first or slide
    if math.isfinite(relative) and relative > 0:
        want = slide * ((relative / target) ** 2 - 1) / 3
    else:
        want = first
    more = min(max(want, restart_every), first)
    more = int(math.ceil(more / restart_every)) * restart_every
    nxt = slide + more
    if budget_steps is not None:
        nxt = min(nxt, budget_steps)
    return nxt


def extend_record(run_dir: Path, record: dict, slide_steps: int) -> None:
    """Let the run of ``record`` (``run.json`` of ``run_dir``, in memory) slide to
    ``slide_steps`` in all: :class:`SceneError` when it is not longer than the run's
    slide (a run that has not reached its slide is resumed as it is), or the run has no
    restart files (``restart_every`` 0).  The record keeps each extension."""
    params = record["scene"]["parameters"]
    old = int(params.get("slide_steps", 0))
    done = record.get("status") in ("completed", "completed_with_warnings")
    if not isinstance(slide_steps, int) or isinstance(slide_steps, bool) or slide_steps < old:
        raise SceneError(f"--slide-to {slide_steps!r}: the run {run_dir} slides {old} steps; "
                         f"give a longer slide (an integer > {old})")
    if slide_steps == old:
        if done:
            raise SceneError(f"{run_dir} already completed its {old} steps; nothing to "
                             f"resume (give --slide-to above {old} to slide further)")
        return
    if not int(params.get("restart_every", 0)):
        raise SceneError(f"{run_dir}: restart_every = 0, no restart file to continue from; "
                         "a slide extended by segments needs restart files")
    params["slide_steps"] = slide_steps
    record.setdefault("extensions", []).append(
        {"from": old, "to": slide_steps, "status_before": record.get("status"),
         "at": datetime.now(timezone.utc).isoformat()})
