"""The files the study writes into a run directory for the report to read.

``calibration.json`` (+ ``calibration_replay.csv``) is written by
:func:`filmfriction.analysis.write_calibration` (``filmfriction calibrate``
and the study); ``sfb.json`` (+ ``sfb_slips.csv``, the slips' traces) by
:func:`write_sfb` (``filmfriction sfb --out`` and the study).  The readers
here only read: a file that is not there is ``None``, never recomputed;
:func:`read_report_inputs` says, for the report, what is missing or out of date
and the command that makes it.
"""
from __future__ import annotations

import csv
import json
import os
import shlex
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from filmfriction.analysis.files.documents import check_document
from filmfriction.analysis.files.provenance import provenance
from filmfriction.analysis.files.util import write_atomic
from filmfriction.analysis.analyze import to_json
from filmfriction.md_inputs.contract import (AGGREGATE_FILE, ANALYSIS_FILE, CALIBRATION_FILE,
                                             ENSEMBLE_FILE, ENSEMBLE_REPORT_FILE, REPLICA_DIR,
                                             REPLICA_LOG, SFB_FILE, STUDY_FILE)
from filmfriction.reduced_model.sfb.rows import find_row

from .sweep.aggregate import load_aggregate

__all__ = ["STUDY_FILE", "ENSEMBLE_FILE", "ENSEMBLE_REPORT_FILE", "REPLICA_DIR",
           "REPLICA_LOG", "STUDY_FILES", "CALIBRATION_FILE", "SFB_FILE", "SFB_TRACES_SUFFIX", "write_sfb", "read_json",
           "read_calibration", "read_sfb", "SFBDocument", "SlipTrace", "ReportInputs",
           "read_report_inputs", "split_sweeps", "checked_runs"]

#: A study of replicas (``filmfriction run --replicas N``): its record, the combined
#: analysis and its report in the study directory, one run directory per replica
#: (REPLICA_DIR) and each replica's output (REPLICA_LOG): the contract's names
#: (md_inputs/contract.py), shared with the runner's modules (workflows/md/replicas/replica_study.py).
STUDY_FILES = (STUDY_FILE, ENSEMBLE_FILE, ENSEMBLE_REPORT_FILE, REPLICA_DIR, REPLICA_LOG)


#: The slips' traces go to ``<stem><suffix>`` beside ``sfb.json``.
SFB_TRACES_SUFFIX = "_slips.csv"
#: The traces kept run from y to this many slip times.
TRACE_SPAN = 2.0


def write_sfb(check, path, extra: dict | None = None, inputs: dict | None = None) -> Path:
    """Write an SFB check (:class:`filmfriction.reduced_model.SFBCheck`) as ``sfb.json``.

    The document is ``check.as_dict()`` plus ``traces``, the name of the CSV
    (``slip,time,x``, SI) with every slip's trace from the yield point y to
    twice its slip time (the whole run when s was not reached), written
    beside it.  ``extra`` adds top-level entries (the user's ``setup`` and
    ``measured`` slip of ``filmfriction sfb --setup``); ``inputs`` (role -> file: the
    calibration, the set-up, the measured analysis) go into its ``provenance``.

    Returns
    -------
    Path
        The JSON file.
    """
    path = Path(path)
    traces = path.with_name(path.stem + SFB_TRACES_SUFFIX)
    lines = ["slip,time,x\n"]
    for key, run in check.slips.items():
        t, x = np.asarray(run.t, float), np.asarray(run.x, float)
        if np.isfinite(run.slip_time):
            keep = t <= TRACE_SPAN * run.slip_time
            t, x = t[keep], x[keep]
        lines += [f"{key},{a!r},{b!r}\n" for a, b in zip(t.tolist(), x.tolist())]
    doc = check.as_dict()
    doc["traces"] = traces.name
    doc.update(extra or {})
    if doc.get("measured"):
        doc = measured_keys(doc)
        lines = [line.replace("klein,", "setup,", 1) if line.startswith("klein,") else line
                 for line in lines]
    write_atomic(traces, "".join(lines))
    doc["provenance"] = provenance(inputs)
    return write_atomic(path, to_json(doc) + "\n")


def measured_keys(doc: dict) -> dict:
    """An SFB document of a measured slip (``sfb --setup --measured``) keyed by what its
    numbers are: each row's experiment value under ``measured`` (not ``klein``; no
    ``klein_source``/``klein_range``, which describe Klein's derivations) and the slip of
    the set-up's parameters under ``slips.setup`` (not ``slips.klein``)."""
    out = dict(doc)
    rows = []
    for r in doc["rows"]:
        r = {("measured" if k == "klein" else k): v for k, v in r.items()
             if k not in ("klein_source", "klein_range")}
        rows.append(r)
    out["rows"] = rows
    out["slips"] = {("setup" if k == "klein" else k): v for k, v in doc["slips"].items()}
    return out


def reference(row: dict):
    """The experiment's number of an SFB row: the measured one (``measured``) or Klein's."""
    return row["measured"] if "measured" in row else row.get("klein")


def read_json(path, kind: str | None = None):
    """The JSON document at ``path``, or ``None`` if there is no such file; checked as a
    document of ``kind`` (:func:`filmfriction.analysis.files.documents.check_document`) when given.

    Raises
    ------
    ValueError
        The file is not valid JSON.
    """
    path = Path(path)
    if not path.is_file():
        return None
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path}: cannot read: {exc}") from None
    if kind is not None and not (kind == "sfb" and isinstance(doc, list)):
        check_document(doc, kind, path)
    return doc


def _columns(path: Path) -> dict:
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], rows[1:]
    return {name: [row[i] for row in body] for i, name in enumerate(header)}


def read_calibration(path):
    """``calibration.json`` with its replay trace, or ``None`` if the file is not there.

    Returns
    -------
    dict or None
        The document; ``replay_trace`` is replaced by ``{"t", "spring_force"}``
        arrays when its CSV exists (else ``None``).
    """
    path = Path(path)
    doc = read_json(path, "calibration")
    if doc is None:
        return None
    if doc.get("run_dirs_relative_to") == "calibration.json":
        # the runs as written relative to the file's folder: as paths from here
        for entry in doc.get("runs") or []:
            if isinstance(entry, dict) and isinstance(entry.get("run_dir"), str):
                entry["run_dir"] = os.path.normpath(path.parent.absolute() / entry["run_dir"])
    name = doc.get("replay_trace")
    trace = path.with_name(name) if name else None
    if trace is not None and trace.is_file():
        cols = _columns(trace)
        doc["replay_trace"] = {"t": np.array(cols["time"], float),
                               "spring_force": np.array(cols["spring_force"], float)}
    else:
        doc["replay_trace"] = None
    return doc


@dataclass(frozen=True)
class SlipTrace:
    """One slip of ``sfb.json``: its scalars and, when written, its trace (SI)."""

    slip_time: float
    slip_distance: float
    t: np.ndarray | None = None
    x: np.ndarray | None = None


@dataclass(frozen=True)
class SFBDocument:
    """``sfb.json`` as read back: the table, the notes, the slips, the calibration used."""

    rows: list
    notes: tuple = ()
    slips: dict = field(default_factory=dict)
    calibration: dict | None = None
    doc: dict = field(default_factory=dict)

    def row(self, name: str, source: str = "sfb-parameters") -> dict:
        """The row called ``name`` from ``source``."""
        return find_row(self.rows, name, source)


def _nan(x) -> float:
    return float("nan") if x is None else float(x)


def read_sfb(path):
    """``sfb.json`` (and its traces), or ``None`` if the file is not there.

    An ``sfb.json`` of an older version (a bare list of rows) gives the rows
    only (no notes, no slips).
    """
    path = Path(path)
    doc = read_json(path, "sfb")
    if doc is None:
        return None
    if isinstance(doc, list):
        return SFBDocument(rows=doc, doc={"rows": doc})
    traces = {}
    name = doc.get("traces")
    if name and path.with_name(name).is_file():
        cols = _columns(path.with_name(name))
        keys = np.array(cols["slip"])
        t, x = np.array(cols["time"], float), np.array(cols["x"], float)
        traces = {k: (t[keys == k], x[keys == k]) for k in dict.fromkeys(cols["slip"])}
    slips = {k: SlipTrace(_nan(s.get("slip_time")), _nan(s.get("slip_distance")),
                          *traces.get(k, (None, None)))
             for k, s in (doc.get("slips") or {}).items()}
    return SFBDocument(rows=doc.get("rows", []), notes=tuple(doc.get("notes", ())), slips=slips,
                       calibration=doc.get("calibration"), doc=doc)


def changed_inputs(doc: dict) -> list[str]:
    """The inputs of a document (its ``provenance.inputs``) whose content is not the one
    it was made from any more: the ``analysis.json`` of each run of a ``calibration.json``
    (read back by :func:`read_calibration`: its runs' paths as from here), compared by
    SHA-256.  File times are not looked at: a copied or moved run is not out of date."""
    from filmfriction.analysis.files.provenance import file_sha256

    recorded = ((doc.get("provenance") or {}).get("inputs") or {})
    out = []
    for i, entry in enumerate(doc.get("runs") or []):
        want = (recorded.get(f"runs[{i}] {ANALYSIS_FILE}") or {}).get("sha256")
        if not want or not isinstance(entry, dict) or not entry.get("run_dir"):
            continue
        now = Path(entry["run_dir"]) / ANALYSIS_FILE
        try:
            same = file_sha256(now) == want
        except OSError:
            same = False
        if not same:
            out.append(str(now))
    return out


def _failed(failures: dict, step: str) -> str | None:
    """The reason ``step`` (or its write) failed in the study, if it did."""
    for key, why in failures.items():
        if key == step or key.startswith(step + " "):
            return f"{key}: {why}" if key != step else why
    return None


def _same_runs(recorded, given) -> bool:
    """Whether ``calibration.json``'s runs are the report's (paths as written may be relative)."""
    def same(a, b):
        # a relative recorded path is relative to where calibrate ran: only its name is known
        a, b = Path(a), Path(b)
        if a.is_absolute() and a.exists() and b.exists():
            return a.resolve() == b.resolve()
        return a.name == b.resolve().name
    if recorded and given and recorded[0] and Path(recorded[0]).is_absolute() \
            and not Path(recorded[0]).exists():
        # calibrate writes into its first run, and the file was read from the report's first
        # run: that run was moved or renamed since
        recorded = [given[0], *recorded[1:]]
    return (len(recorded) == len(given) and all(any(same(r, g) for g in given) for r in recorded)
            and all(any(same(r, g) for r in recorded) for g in given))


@dataclass
class ReportInputs:
    """What the report reads besides the main run: documents, or why they are not used."""

    calibration: dict | None = None
    sfb: object = None
    why_no_calibration: str = ""
    why_no_sfb: str = ""
    calibration_remarks: list = field(default_factory=list)
    sfb_remarks: list = field(default_factory=list)
    missing: list = field(default_factory=list)       # (what, command that makes it)


def _command(*words) -> str:
    return " ".join(shlex.quote(str(w)) for w in words)


#: what a suggested command writes in the place of the user's set-up file when no output
#: records its path (an ``sfb.json`` records it in its provenance)
SETUP_PLACEHOLDER = "YOUR_SETUP.toml"


def sfb_command(run_dir: Path, cal_path: Path, sfb_path: Path, *, with_calibration=True) -> str:
    """The ``filmfriction sfb`` command that (re)writes ``sfb_path`` for this run as it was
    made: a measured trace (SI ``analysis.json``) or an ``sfb.json`` made with ``--setup``
    keeps ``--setup`` and ``--measured`` (the set-up file as ``sfb.json``'s provenance
    records it, else a placeholder), never falling back to Klein's set-up."""
    measured, setup_file = False, SETUP_PLACEHOLDER
    try:
        doc = read_json(sfb_path)
        measured = isinstance(doc, dict) and bool(doc.get("setup"))
        recorded = (((doc or {}).get("provenance") or {}).get("inputs") or {}).get("setup")
        if isinstance(recorded, dict) and isinstance(recorded.get("path"), str):
            setup_file = recorded["path"]
    except (ValueError, AttributeError):
        pass
    try:
        analysis = read_json(Path(run_dir) / "analysis.json")
        measured = measured or (isinstance(analysis, dict) and analysis.get("units") == "si")
    except ValueError:
        pass
    words = ["filmfriction", "sfb"]
    if measured:
        words += ["--setup", setup_file, "--measured", run_dir]
    if with_calibration:
        words += ["--calibration", cal_path]
    return _command(*words, "--out", sfb_path)


def read_report_inputs(run_dir: Path, run_dirs: list, given: list, failures: dict) -> ReportInputs:
    """Read ``calibration.json`` and ``sfb.json`` of the main run for the report; never compute them.

    Parameters
    ----------
    run_dir : Path
        The main run's directory.
    run_dirs : list of Path
        The report's runs (a sweep's runs included).
    given : list of Path
        What the user named (run or sweep directories): the commands printed use them.
    failures : dict
        Steps that failed in the study: a failed ``calibration`` or ``sfb`` is not read.

    Returns
    -------
    ReportInputs
    """
    got = ReportInputs()
    cal_path, sfb_path = run_dir / CALIBRATION_FILE, run_dir / SFB_FILE
    cal_cmd = _command("filmfriction", "calibrate", *given)
    failed = _failed(failures, "calibration")
    if failed:
        got.why_no_calibration = f"Calibration failed: {failed}."
    else:
        try:
            got.calibration = read_calibration(cal_path)
        except ValueError as exc:
            got.why_no_calibration = f"Not computed — calibration: {exc}; `{cal_cmd}` rewrites it."
            got.missing.append((f"{cal_path} (unreadable)", cal_cmd))
        else:
            if got.calibration is None:
                got.why_no_calibration = (f"No `calibration.json` in `{run_dir}`: the report renders what the "
                                          f"study wrote and does not calibrate. `{cal_cmd}` writes it.")
                got.missing.append((str(cal_path), cal_cmd))
    cal = got.calibration
    if cal is not None:
        covered = [r.get("run_dir") for r in cal.get("runs", [])]
        if not _same_runs(covered, run_dirs):
            got.calibration_remarks.append(
                f"`calibration.json` covers the runs {', '.join('`' + str(c) + '`' for c in covered)}, "
                f"not the {len(run_dirs)} of this report; `{cal_cmd}` writes the calibration across them.")
            got.missing.append((f"{cal_path} across the runs given", cal_cmd))
        else:
            changed = changed_inputs(cal)
            if changed:
                got.calibration_remarks.append(
                    f"`calibration.json` was computed from other contents of "
                    f"{', '.join('`' + c + '`' for c in changed)} (their SHA-256 differ from the "
                    f"ones it records); `{cal_cmd}` recomputes it.")
                got.missing.append((f"{cal_path} (out of date)", cal_cmd))
    # as the study runs it: with the MD calibration, unless calibration.json has none
    no_md = cal is not None and cal.get("md_calibration") is None
    sfb_cmd = sfb_command(run_dir, cal_path, sfb_path, with_calibration=not no_md)
    failed = _failed(failures, "sfb")
    if failed:
        got.why_no_sfb = f"The SFB check failed: {failed}."
        return got
    try:
        got.sfb = read_sfb(sfb_path)
    except ValueError as exc:
        got.why_no_sfb = f"Not computed — SFB check: {exc}; `{sfb_cmd}` rewrites it."
        got.missing.append((f"{sfb_path} (unreadable)", sfb_cmd))
        return got
    if got.sfb is None:
        got.why_no_sfb = (f"No `sfb.json` in `{run_dir}`: the report does not run the SFB check. "
                          f"`{sfb_cmd}` writes it.")
        got.missing.append((str(sfb_path), sfb_cmd))
    elif "calibration" not in got.sfb.doc:
        got.sfb_remarks.append(f"`sfb.json` is of an older version (the table only, no figure); "
                               f"`{sfb_cmd}` rewrites it.")
        got.missing.append((f"{sfb_path} (older version)", sfb_cmd))
    elif cal is not None and got.sfb.calibration != cal.get("md_calibration"):
        got.sfb_remarks.append(f"`sfb.json` was computed with another MD calibration than the one in "
                               f"`calibration.json`; `{sfb_cmd}` recomputes it.")
        got.missing.append((f"{sfb_path} for this calibration.json", sfb_cmd))
    return got


def checked_runs(paths, out=None) -> list:
    """The run directories ``paths`` give (a sweep its runs: :func:`split_sweeps`), each
    path checked as one (:func:`filmfriction.workflows.inputs.check_run_source`) and ``out``,
    a file the command will write, checked writable (``--out``), before any compute
    (UserError otherwise)."""
    from .inputs import UserError, check_run_source, check_writable

    for d in paths:
        if not Path(d).is_dir():
            raise UserError(f"{d}: not a directory")
        check_run_source(d)
    if out is not None:
        check_writable(out, "--out")
    return split_sweeps([Path(p) for p in paths])[0]


def split_sweeps(paths: list) -> tuple[list, list]:
    """Run directories, and sweeps (directories with ``aggregate.json``).

    A sweep contributes its stick-slip runs (its ``calibration_runs``, else all
    its runs) to the calibration, after the run directories given directly.
    """
    runs, sweeps, seen = [], [], set()

    def add(d):
        # each run once, however it is written (r1, ./r1/, /abs/r1, or within a sweep)
        if Path(d).resolve() not in seen:
            seen.add(Path(d).resolve())
            runs.append(d)
    for p in paths:
        if (p / AGGREGATE_FILE).exists():
            agg = load_aggregate(p)
            sweeps.append(agg)
            for d in agg.calibration_runs or agg.run_dirs:
                add(d)
        else:
            add(p)
    return runs, sweeps
