"""The study report: one self-contained HTML page and its Markdown twin.

:func:`build_report` reads one or several run directories (the first is the
main run) and renders what the study wrote there (:mod:`filmfriction.workflows.study`):
the analysis (``analysis.json``), the calibration (``calibration.json``) and
the SFB check (``sfb.json``).  It computes none of them: a file that is not
there is said in the report, with the command that makes it
(``filmfriction analyze``, ``filmfriction calibrate``, ``filmfriction sfb
--out``).  It writes ``report.html`` (figures embedded as base64 PNG) and
``report.md`` (figures as ``report-*.png`` next to it) into the first run
directory, atomically.  Every number in the text comes from those files; a
step that failed is reported as failed, with its reason, and the rest of the
report is still written.

The document is built once as a list of sections of blocks (paragraph,
figure, table) and rendered twice, so the two files cannot disagree.  Every
section of the analysis is an observable
(:mod:`filmfriction.analysis.observables`: the slips, the energy, the sliding
state, the viscosity, the structure, the slip law ...) and gets its section
from one function, :func:`observable_section`, in the observables' order: its
title, its lead paragraphs, its figures with their captions, its table and its
notes, or why it is not there.
"""
from __future__ import annotations

import base64
import os
from pathlib import Path

from filmfriction.analysis.observables import registered as registered_observables
from filmfriction.analysis.files.util import write_atomic as _write_atomic
from filmfriction.reduced_model.units import OMCTS

from ..rundir import read_report_inputs, split_sweeps
from .document import Figure, Section, Table
from .summary import consistency_checks
from .overview import (appendix_section, consistency_section, summary_section,
                       user_contact_point)
from .sections import (PARAMETER_QUANTITIES, attempt, calibration_section, cost_section,
                       observable_section, scene_section, sweep_section, viscosity_section)
from .sfb_sections import sfb_section, similarity_section

__all__ = ["build_report", "Section", "Figure", "Table", "PARAMETER_QUANTITIES"]


# ---------------------------------------------------------------------------
# rendering: Jinja2 templates (workflows/report/templates/), HTML autoescaped
# ---------------------------------------------------------------------------
#: how a paragraph that says something is missing or failed begins (shown in red)
_FAILURE_OPENINGS = ("Not computed", "Calibration failed", "The SFB check failed", "No `")


def _inline_md(text: str) -> str:
    """Markdown text with its tags escaped outside code spans (a viewer would render them)."""
    import re
    parts = re.split(r"(`[^`]*`)", str(text))
    return "".join(p if p.startswith("`") and p.endswith("`") and len(p) > 1
                   else p.replace("<", "&lt;").replace(">", "&gt;") for p in parts)


def _inline_html(text) -> str:
    """HTML of a paragraph: the text escaped, then its ``**bold**`` and ```code``` marked up."""
    import re

    from markupsafe import Markup, escape
    out = str(escape(str(text)))
    out = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", out)
    out = re.sub(r"`(.+?)`", r"<code>\1</code>", out)
    out = re.sub(r"\[([^\]]+)\]\(#([^)\s]+)\)", r"<a href='#\2'>\1</a>", out)
    return Markup(out)


def _md_cell(c: str) -> str:
    return _inline_md(str(c)).replace("|", "\\|").replace("\n", " ")


def _templates(*, html: bool):
    """The report's Jinja2 environment: the package's templates, HTML autoescaped."""
    from jinja2 import Environment, PackageLoader, StrictUndefined

    env = Environment(loader=PackageLoader("filmfriction.workflows.report", "templates"),
                      autoescape=html, undefined=StrictUndefined, trim_blocks=True,
                      lstrip_blocks=True, keep_trailing_newline=True)
    env.filters.update(inline=_inline_html, md=_inline_md, cell=_md_cell,
                       base64=lambda data: base64.b64encode(data).decode("ascii"))
    env.tests.update(figure=lambda b: isinstance(b, Figure), table=lambda b: isinstance(b, Table),
                     failure=lambda b: isinstance(b, str) and b.startswith(_FAILURE_OPENINGS))
    return env


#: How the report's HTML page and its Markdown twin begin (what tells them from a user's
#: file of the same name, which the report never replaces).
REPORT_HTML_MARK = b"<title>filmfriction report"
REPORT_MD_MARK = b"# filmfriction report"


def _render_html(title: str, intro: list, sections: list) -> str:
    return _templates(html=True).get_template("report.html.j2").render(
        title=title, intro=intro, sections=sections)


def _render_md(title: str, intro: list, sections: list, stem: str) -> tuple[str, dict]:
    """The Markdown twin and its figure files (name -> PNG bytes)."""
    text = _templates(html=False).get_template("report.md.j2").render(
        title=title, intro=intro, sections=sections, stem=stem)
    files = {f"{stem}-{b.name}.png": b.png for sec in sections for b in sec.blocks
             if isinstance(b, Figure)}
    return text, files


def build_report(run_dirs, out=None, *, failures=None, log=None, compare=()) -> Path:
    """Write ``report.html`` and ``report.md`` for one or several runs.

    The report renders what is in the main run's directory: ``analysis.json``
    (with ``analysis_cycles.csv``), ``calibration.json`` (with
    ``calibration_replay.csv``) and ``sfb.json`` (with ``sfb_slips.csv``).
    It computes none of them; a file that is not there is said in the report
    with the command that writes it (and passed to ``log``).

    Parameters
    ----------
    run_dirs : path-like or list of path-like
        Run directories; the first is the main run.  A sweep directory (with
        ``aggregate.json``) adds a sweep section and its stick-slip runs.
    out : path-like, optional
        HTML file to write (default ``<first run>/report.html``); the Markdown
        twin and its PNG figures go next to it (same stem).
    failures : dict, optional
        Step → reason for earlier steps that failed (recorded in the report;
        a failed ``calibration`` or ``sfb`` step is reported as failed, not read).
    log : callable, optional
        Called with one line per input that is missing and the command that makes it.
    compare : list of path-like
        Other analysed runs set beside the main one in the similarity section (their
        ``sfb.json`` similarity rows and their points on the λ–ζ map).

    Returns
    -------
    Path
        The HTML file.

    Raises
    ------
    ValueError
        No run directory, or the main run has no analysis (``filmfriction analyze``).
    """
    from filmfriction.analysis.calibration.rundata import load_run

    if isinstance(run_dirs, (str, os.PathLike)):
        run_dirs = [run_dirs]
    given = [Path(d) for d in run_dirs]
    run_dirs, sweeps = split_sweeps(given)
    if out is None and sweeps and given[0] == sweeps[0].sweep_dir:
        out = sweeps[0].sweep_dir / "report.html"   # a sweep's report lives with the sweep
    if not run_dirs:
        raise ValueError("no run directory given (a sweep without completed runs?)")
    failures = dict(failures or {})
    run = load_run(run_dirs[0], analyse=False)
    inputs = read_report_inputs(run.run_dir, run_dirs, given, failures)
    for what, command in inputs.missing:
        if log is not None:
            log(f"missing or out of date: {what}; make it with: {command}")
    out = Path(out) if out is not None else run.run_dir / "report.html"
    name = run.run_dir.resolve().name           # "." has no name of its own
    scene = (run.trace.run or {}).get("scene", {}).get("name", run.trace.path.name)
    title = f"filmfriction report — {scene} ({name})"
    units = run.analysis.get("units", "lj")
    intro = [f"Runs: {', '.join('`' + str(d) + '`' for d in run_dirs)}. " + (
        "MD quantities are in LJ units (σ, ε, m, τ) unless marked SI; SI values go through "
        f"`filmfriction.reduced_model.units` ({OMCTS.name})." if units == "lj" else
        "The trace's quantities are in SI units (N, m, s, J, Pa·s), as its analysis records; "
        "nothing is converted.")]
    observed = [observable_section(obs, run, failures) for obs in registered_observables()]
    checks = consistency_checks(run.analysis, inputs.calibration)
    sections = [scene_section(run), *observed,
                viscosity_section(inputs.calibration, inputs.why_no_calibration, failures),
                calibration_section(inputs.calibration, inputs.why_no_calibration,
                                     inputs.calibration_remarks, run, failures),
                sfb_section(inputs.sfb, inputs.why_no_sfb, inputs.sfb_remarks, failures, run),
                similarity_section(inputs.sfb, run_dirs, failures,
                                    compare=[Path(c) for c in compare],
                                    user_point=attempt(failures, "the set-up on the λ–ζ map",
                                                       user_contact_point, inputs.sfb,
                                                       run.analysis)),
                cost_section(run)]
    if sweeps:
        sections.insert(1 + len(observed), sweep_section(sweeps))
    appendix = appendix_section(inputs.sfb)
    if appendix is not None:
        sections.append(appendix)
    # a section whose inputs are absent is left out, with one line in the summary
    left_out = [(sec.title, next((b for b in sec.blocks if isinstance(b, str)), sec.absent))
                for sec in sections if sec.absent]
    sections = [sec for sec in sections if not sec.absent]
    compared = [Path(c) for c in compare] + list(run_dirs[1:])
    sections = [summary_section(run, inputs, checks, compared, left_out, failures,
                                [sec.title for sec in sections]),
                consistency_section(checks), *sections]
    if inputs.missing:
        sec = Section("Inputs the report did not find")
        sec.p("The report renders the files the study writes and computes none of them. These commands "
              "write what is missing or out of date:")
        sec.add(Table(("file", "command"), tuple((w, f"`{c}`") for w, c in inputs.missing)))
        sections.append(sec)
    if failures:
        sec = Section("Steps that failed")
        sec.add(Table(("step", "reason"), tuple((k, v) for k, v in failures.items())))
        sections.append(sec)
    html = _render_html(title, intro, sections)
    md_text, files = _render_md(title, intro, sections, out.stem)
    # nothing replaces a file the report did not write: its page, its Markdown twin, and
    # the twin's figures (those the twin there names)
    from ..outputs import check_output, head_has, names_in

    sources = [*given, *compare]
    check_output(out, "--out", inputs=sources, ours=head_has(REPORT_HTML_MARK))
    check_output(out.with_suffix(".md"), "--out", inputs=sources, ours=head_has(REPORT_MD_MARK),
                 what="its Markdown twin")
    for name in files:
        check_output(out.parent / name, "--out", inputs=sources,
                     ours=names_in(out.with_suffix(".md")), what="a figure of its Markdown twin")
    _write_atomic(out, html)
    for name, data in files.items():
        _write_atomic(out.parent / name, data)
    _write_atomic(out.with_suffix(".md"), md_text)
    return out
