"""The contract every observable keeps (``filmfriction.analysis.observables``).

Each registered observable (the built-in sections -- slips, energy, sliding,
viscosity, structure -- are observables too), and one defined in this file (the
mean film temperature of each slip: what a user would drop into
``analysis/observables/`` as a file of its own), on a synthetic run directory
with a trajectory (:func:`filmfriction.analysis.groundtruth.synthetic.run_directory`):

* its section is JSON data and lands in ``analysis.json``, its per-slip columns
  (``<key>_<name>`` unless it names them otherwise, one value per slip) in
  ``analysis_cycles.csv``; sections and columns come in the observables' order;
* with any one of its ``needs`` taken from the run, it is skipped with a reason
  naming that need, and the analysis and the report still go through;
* on a trace of nothing but ``time``, ``spring_force`` and its needs it gives
  its section or a reason, never an error (no need left undeclared);
* ``rows()`` gives (label, value) strings, ``figure()`` PNG bytes or None, and
  the report shows its title, table and figures.
"""
from __future__ import annotations

import base64
import csv
import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from markupsafe import escape

from filmfriction.analysis import observables
from filmfriction.analysis.observables import REGISTRY, Observable

PNG = b"\x89PNG\r\n\x1a\n"
HERE = "slip_temperature"      # the key of the observable defined in this file


def define_slip_temperature() -> type[Observable]:
    """The whole of what ``analysis/observables/slip_temperature.py`` would hold
    (defined here in a function, so that it registers for this module's tests only)."""
    from filmfriction.analysis.observables.observable import (Observable, column, format_estimate,
                                                              png_bytes, pyplot)

    class SlipTemperature(Observable):
        """The film's mean temperature during each slip (y → s)."""

        key = "slip_temperature"
        title = "Film temperature during the slips"
        needs = (column("film_temperature", "the film's temperature during each slip"),)
        table_header = ("film temperature (mean ± stderr over slips)", "value")
        caption = "The film's mean temperature during each analysed slip."

        def compute(self, ctx):
            temp = ctx.trace.columns["film_temperature"]
            per_slip = [float(np.mean(temp[y:s + 1]))
                        for y, s in zip(ctx.table.yield_index, ctx.table.stick_index)]
            return {"mean": ctx.statistic(per_slip, "temperature")}, {"mean": per_slip}

        def rows(self, section):
            return [("mean film temperature of a slip", format_estimate(section["mean"]))]

        def figure(self, run):
            temp = run.cycles.get("slip_temperature_mean", np.empty(0))[run.skip:]
            if not temp.size:
                return None
            plt = pyplot()
            fig, ax = plt.subplots(figsize=(5, 3))
            ax.plot(np.arange(1, temp.size + 1), temp, "o-")
            ax.set_xlabel("analysed slip [1]")
            ax.set_ylabel(f"film temperature [{run.analysis[self.key]['mean']['units']}]")
            return png_bytes(fig)

    return SlipTemperature


@pytest.fixture(scope="module")
def slip_temperature():
    """The observable of this file, registered while this module's tests run."""
    cls = define_slip_temperature()
    assert REGISTRY[HERE] is cls, "a class statement registers the observable"
    yield cls
    del REGISTRY[HERE]


#: every observable of the package, and the one of this file
KEYS = sorted(set(REGISTRY) | {HERE})


@pytest.fixture(params=KEYS)
def observable(request, slip_temperature) -> Observable:
    return REGISTRY[request.param]()


def _needs(key: str) -> tuple:
    """The needs of the observable ``key`` (that of this file: its one column)."""
    return (REGISTRY[key].needs if key in REGISTRY else
            (observables.column("film_temperature", "the film's temperature during each slip"),))


#: (key, index of one of its needs) for every need of every observable
NEEDS = [(key, i) for key in KEYS for i in range(len(_needs(key)))]


def analyse_and_report(run_dir: Path) -> tuple[dict, dict, str, str]:
    """``analyze`` (written out) and ``build_report`` on ``run_dir``: the document,
    the per-slip CSV's columns, report.html and report.md."""
    from filmfriction.analysis.analyze import analyze, write_outputs
    from filmfriction.analysis.files.trace_reader import read_trace
    from filmfriction.workflows.report.render import build_report

    doc, per_cycle = analyze(read_trace(run_dir))
    write_outputs(doc, per_cycle, run_dir / "analysis.json")
    out = build_report(run_dir)
    with open(run_dir / "analysis_cycles.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    columns = {name: [row[i] for row in rows[1:]] for i, name in enumerate(rows[0])}
    return (json.loads((run_dir / "analysis.json").read_text()), columns, out.read_text(),
            out.with_suffix(".md").read_text())


@pytest.fixture(scope="module")
def study(tmp_path_factory, slip_temperature):
    """The synthetic run analysed and reported with every observable registered."""
    from filmfriction.analysis.calibration.rundata import load_run
    from filmfriction.analysis.groundtruth.synthetic import run_directory

    run_dir = run_directory(tmp_path_factory.mktemp("observables") / "run")
    doc, columns, html, md = analyse_and_report(run_dir)
    return dict(dir=run_dir, doc=doc, columns=columns, html=html, md=md,
                run=load_run(run_dir, analyse=False))


def images(html: str) -> dict[str, bytes]:
    return {name: base64.b64decode(data) for name, data in
            re.findall(r"<img alt='([^']+)' src='data:image/png;base64,([A-Za-z0-9+/=]+)'", html)}


# ---------------------------------------------------------------------------- registration
def test_every_module_of_the_folder_is_imported_and_registers():
    folder = Path(observables.__file__).parent
    files = {p.stem for p in folder.glob("*.py")} - {"__init__", "observable"}
    assert files, "no observable in the package"
    modules = {cls.__module__.rsplit(".", 1)[1] for cls in REGISTRY.values()
               if cls.__module__.startswith(observables.__name__ + ".")}
    assert files <= modules, f"modules that register no observable: {files - modules}"


def test_the_class_statement_registers_and_refuses_a_taken_key(slip_temperature):
    from filmfriction.analysis.observables.observable import BUILT_IN

    assert REGISTRY[HERE] is slip_temperature and HERE in {o.key for o in observables.registered()}
    before = dict(REGISTRY)
    try:
        for key in (HERE, *sorted(BUILT_IN), "Not A Key"):
            with pytest.raises(TypeError, match="key"):
                type("Again", (Observable,), {"key": key, "title": "t"})
        with pytest.raises(TypeError, match="title"):
            type("Untitled", (Observable,), {"key": "untitled"})
        with pytest.raises(TypeError, match="needs"):
            type("Bare", (Observable,), {"key": "bare", "title": "t", "needs": "mass"})
        with pytest.raises(TypeError, match="order"):
            type("Late", (Observable,), {"key": "late", "title": "t", "order": "last"})
        with pytest.raises(TypeError, match="per_slip"):
            type("Each", (Observable,), {"key": "each", "title": "t", "per_slip": "every"})
        type("Helper", (Observable,), {"key": "helper", "title": "t"}, register=False)
        assert REGISTRY == before
    finally:                        # whatever a failure registered goes again
        REGISTRY.clear()
        REGISTRY.update(before)


# ---------------------------------------------------------------------------- the analysis
def test_its_section_is_json_and_lands_in_analysis_json(observable, study):
    key, doc = observable.key, study["doc"]
    assert key in doc, (f"{key} not in analysis.json of the synthetic run "
                        f"(skipped: {doc['skipped'].get(key)}); give the synthetic run what it needs")
    assert key not in doc["skipped"]
    section = doc[key]
    assert isinstance(section, dict) and section
    assert json.loads(json.dumps(section, allow_nan=False)) == section
    # its per-slip columns, one value a slip (the start-up slips empty unless it covers all)
    from filmfriction.analysis.analyze import context, run_observable

    _, columns = run_observable(observable, context(study["run"].trace))
    n, skip = doc["slips"]["count"], doc["slips"]["summary_skips_first"]
    for name in columns:
        cells = study["columns"][observable.column_name(name)]
        assert len(cells) == n, name
        if observable.per_slip == "analysed":
            assert all(c == "" for c in cells[:skip]), name
            cells = cells[skip:]
        assert cells == ["" if not np.isfinite(float(v)) else repr(v) for v in columns[name]], name


def test_sections_and_columns_come_in_the_observables_order(study):
    doc, order = study["doc"], [o.key for o in observables.registered()]
    assert order[:5] == ["slips", "energy", "sliding", "viscosity", "structure"]
    written = [k for k in doc if k in REGISTRY]
    assert written == [k for k in order if k in doc]
    # the CSV: the slips' own columns first, the slip law's after the viscosity's
    header = list(study["columns"])
    assert header[:2] == ["yield_index", "stick_index"]
    assert header.index("energy_film_heat") < header.index("eta_eff") \
        < header.index("slip_law_damping")


def _without(run_dir: Path, need, dest: Path) -> Path:
    """A copy of ``run_dir`` without the column or parameter ``need``."""
    shutil.copytree(run_dir, dest)
    for stale in ("analysis.json", "analysis_cycles.csv"):
        (dest / stale).unlink()
    if need.kind == "column":
        with open(dest / "trace.csv", newline="") as fh:
            rows = list(csv.reader(fh))
        assert need.name in rows[0], f"the synthetic run has no column {need.name!r} to take away"
        i = rows[0].index(need.name)
        with open(dest / "trace.csv", "w", newline="") as fh:
            csv.writer(fh).writerows([row[:i] + row[i + 1:] for row in rows])
    else:
        run = json.loads((dest / "run.json").read_text())
        assert run["trace_parameters"].get(need.name) is not None, need.name
        run["trace_parameters"][need.name] = None
        (dest / "run.json").write_text(json.dumps(run))
    return dest


@pytest.mark.parametrize("key, i", NEEDS, ids=[f"{k}-{i}" for k, i in NEEDS])
def test_without_any_one_need_it_is_skipped_naming_it(key, i, slip_temperature, study,
                                                      tmp_path):
    observable = REGISTRY[key]()
    need = observable.needs[i]
    doc, columns, html, md = analyse_and_report(_without(study["dir"], need, tmp_path / "run"))
    assert observable.key not in doc, need
    reason = doc["skipped"].get(observable.key, "")
    assert need.label in reason, (need, reason)
    assert not [c for c in columns if c.startswith(observable.column_name(""))]
    # the report says why, under the observable's title
    assert observable.title in md and f"{observable.absent}: {reason}." in md


def test_a_trace_of_its_needs_alone_gives_its_section_or_a_reason(observable, study):
    """No column or parameter read that ``needs`` does not declare: on ``time``,
    ``spring_force`` and the needs, the observable computes or says what is missing."""
    from filmfriction.analysis.analyze import analyze
    from filmfriction.analysis.files.trace import Trace, TraceParameters

    full = study["run"].trace
    cols = {c: full.columns[c] for c in ("time", "spring_force")}
    params = {}
    for need in observable.needs:
        if need.kind == "column":
            cols[need.name] = full.columns[need.name]
        else:
            params[need.name] = getattr(full.parameters, need.name)
    # the run directory's files (trajectory, profiles) stay: they are no column or parameter
    doc, _ = analyze(Trace(cols, TraceParameters(**params), study["dir"] / "trace.csv",
                           run_dir=study["dir"]))
    assert observable.key in doc or doc["skipped"].get(observable.key)


# ---------------------------------------------------------------------------- the report
def test_rows_and_notes_are_strings(observable, study):
    section = study["doc"][observable.key]
    rows = observable.rows(section)
    assert rows and all(len(r) == 2 and all(isinstance(c, str) and c for c in r) for r in rows)
    assert len(observable.table_header) == 2 and all(isinstance(h, str) for h in observable.table_header)
    assert all(isinstance(p, str) for p in observable.notes(section))


def test_its_figures_are_pngs_and_the_report_shows_them(observable, study):
    figures = observable.figures(study["run"])
    html, md = study["html"], study["md"]
    assert f">{escape(observable.title)}</h2>" in html and f"## {observable.title}" in md
    for label, value in observable.rows(study["doc"][observable.key]):
        assert f"| {label} | {value} |" in md
    assert not re.search(rf"\| (lead|figure|table|notes): {observable.key.replace('_', ' ')} \|",
                         md), "the report recorded a failure of the observable"
    for name, png, caption in figures:
        assert isinstance(png, bytes) and png.startswith(PNG) and len(png) > 2000, name
        assert images(html).get(name, b"").startswith(PNG), name
        assert f"![{name}](report-{name}.png)" in md and f"*{caption}*" in md


def test_one_file_is_enough(slip_temperature, study):
    """The observable of this file: computed, in the CSV and in the report, with no other change."""
    doc = study["doc"]
    assert doc[HERE]["mean"]["mean"] == pytest.approx(0.7)       # the synthetic film is at 0.7
    assert doc[HERE]["mean"]["units"] == "ε/k_B"
    assert doc[HERE]["mean"]["n"] == doc["slips"]["count"] - doc["slips"]["summary_skips_first"]
    assert "slip_temperature_mean" in study["columns"]
    assert "## Film temperature during the slips" in study["md"]
    assert HERE in images(study["html"])
