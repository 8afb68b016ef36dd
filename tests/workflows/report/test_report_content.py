"""What the report says, on a synthetic run with a known answer (no LAMMPS).

The study (analysis, calibration, SFB check, report) runs once on a run
directory made by :func:`filmfriction.analysis.groundtruth.synthetic.run_directory`: four
Klein-type slips from 3 to 1 eps/sigma and a 3-layer trajectory.  The same
content checks run on the real small run in test_report.py (marker md).
"""
import json
from types import SimpleNamespace

import pytest


@pytest.fixture(scope="module")
def synthetic_study(tmp_path_factory, report_study):
    from filmfriction.analysis.groundtruth.synthetic import run_directory

    run_dir = run_directory(tmp_path_factory.mktemp("report-synthetic") / "run", layers=3)
    return SimpleNamespace(path=run_dir, labels=report_study(run_dir))


def test_synthetic_study_writes_every_output(synthetic_study, report_checks):
    report_checks.outputs(synthetic_study.path)


def test_synthetic_report_shows_the_analysis(synthetic_study, report_checks):
    report_checks.content(synthetic_study.path)
    # the synthetic run's known answer
    doc = json.loads((synthetic_study.path / "analysis.json").read_text())
    assert doc["slips"]["static_force"]["mean"] == pytest.approx(3.0, rel=0.1)
    assert doc["structure"]["layers"]["count"] == 3
    # Klein's slips (F_k = 0): the calibration's friction law and the slip law agree
    md = (synthetic_study.path / "report.md").read_text()
    assert "| friction law: calibration vs slip law | agree |" in md


def test_the_zero_error_scan_finds_a_zero_error(report_checks):
    """The scan of the report checks flags "± 0" in every spelling, not "± 0.02"."""
    zero_errors = report_checks.zero_errors
    assert zero_errors("F_k = 3 ± 0 N") and zero_errors("3 ± 0.000 σ") and zero_errors("±0e+00")
    assert not zero_errors("3 ± 0.02 N") and not zero_errors("3 ± 1e-15")


def test_every_figure_has_units_on_its_axes(synthetic_study, report_checks):
    report_checks.axes_units(synthetic_study.labels)


def test_every_figure_loads_in_headless_chromium(synthetic_study, report_checks):
    report = synthetic_study.path / "report.html"
    sizes = report_checks.in_browser(report)
    assert set(sizes) == set(report_checks.images(report.read_text()))
    # the figures of the analysis' observables, each from its own file
    assert {"trace", "energy", "ledger", "eta-per-slip", "film", "structure-time", "layers-top",
            "slip_law"} <= set(sizes), sorted(sizes)


def test_a_run_without_trajectory_says_which_scene_draws_the_film(tmp_path):
    from filmfriction.analysis.observables.structure_section import Structure, fig_film
    from filmfriction.workflows.report import sections

    assert fig_film(tmp_path) == (None, "")
    run = SimpleNamespace(run_dir=tmp_path, analysis={"skipped": {
        "structure": "no trajectory.dcd + topology.data in the run directory"}})
    sec = sections.observable_section(Structure(), run, {})
    assert sec.title == "The film: density profile and picture"
    text = [b for b in sec.blocks if isinstance(b, str)]
    assert any("`film-structure` scene" in b and "no trajectory.dcd" in b for b in text), text


def test_compare_sets_another_run_beside_the_main_one(synthetic_study, tmp_path, report_study,
                                                       run_cli):
    # a second study, compared: its similarity rows and its point appear; it is not calibrated
    from filmfriction.analysis.groundtruth.synthetic import run_directory

    other = run_directory(tmp_path / "other", layers=4)
    report_study(other)
    out = tmp_path / "cmp.html"
    r = run_cli("report", synthetic_study.path, "--compare", other, "--out", out)
    assert r.code == 0, r.err
    md = out.with_suffix(".md").read_text()
    assert "Beside it, `other`" in md
    assert "lambda_zeta" in md and "calibrate" not in r.out
    bad = run_cli("report", synthetic_study.path, "--compare", tmp_path / "nope")
    assert bad.code == 2 and "--compare" in bad.err


def test_markdown_escapes_html_outside_code():
    from filmfriction.workflows.report.render import _inline_md, _md_cell

    assert _inline_md("a <script>x</script> & `<b>`") == "a &lt;script&gt;x&lt;/script&gt; & `<b>`"
    assert _md_cell("<i>|") == "&lt;i&gt;\\|"


def test_a_run_with_warnings_says_so(synthetic_study, tmp_path, report_study):
    import json as _json
    import shutil

    from filmfriction.workflows.report.render import build_report

    run = tmp_path / "warned"
    shutil.copytree(synthetic_study.path, run)
    rj = _json.loads((run / "run.json").read_text())
    rj["status"], rj["warnings"] = "completed_with_warnings", ["film temperature 1.06 vs 0.7"]
    (run / "run.json").write_text(_json.dumps(rj))
    md = build_report(run).with_suffix(".md").read_text()
    assert "completed with warnings" in md and "film temperature 1.06 vs 0.7" in md


def test_a_measured_si_trace_is_reported_in_its_own_units(tmp_path, run_cli, monkeypatch):
    """A measured trace (SFB scale, SI) through analyze, calibrate and report: every number
    and axis in SI, nothing called MD or labelled in LJ units."""
    import re

    from matplotlib.figure import Figure

    from filmfriction.analysis.groundtruth.synthetic import klein_trace, write_csv

    tr = klein_trace(cycles=5, noise=0.005 * 9.7e-6, seed=2)
    write_csv(tmp_path / "trace.csv", {k: tr[k] for k in ("time", "spring_force", "drive_position",
                                                         "wall_position", "wall_velocity")})
    sfb = ["--units", "si", "--spring-constant", "97", "--mass", "1.47e-3", "--area", "4e-10",
           "--thickness", "3.5e-9", "--drive-velocity", "1e-7"]
    assert run_cli("analyze", tmp_path / "trace.csv", *sfb).code == 0
    calibrated = run_cli("calibrate", tmp_path)
    assert calibrated.code == 0, calibrated.err
    cal = json.loads((tmp_path / "calibration.json").read_text())
    assert cal["units"] == "si" and cal["runs"][0]["static_force"]["units"] == "N"
    labels, savefig = [], Figure.savefig

    def capture(fig, *args, **kwargs):
        labels.append([(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes])
        return savefig(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", capture)
    assert run_cli("report", tmp_path).code == 0
    md = (tmp_path / "report.md").read_text()
    assert md.splitlines()[0] == f"# filmfriction report — trace.csv ({tmp_path.name})"
    named = [label for fig in labels for axis in fig for label in axis if label]
    units = {u for label in named for u in re.findall(r"\[([^\]]+)\]", label)}
    # SI units, with a prefix chosen for the numbers: no axis offset (1e-5 ...)
    assert {"µN", "s", "pJ", "Pa·s", "1/s", "µm/s"} <= units, units
    assert not units & {"N", "J", "m/s"}, units       # µN-, pJ-sized numbers in bare units
    # a measured trace: no thermostat or mount dashpot term in the energy figure or its caption
    energy = md.split("## Energy partition", 1)[1].split("\n## ", 1)[0]
    assert "thermostat" not in energy and "dashpot" not in energy
    # the report opens with its summary, then the consistency of its own numbers
    assert re.findall(r"^## (.+)$", md, re.M)[:2] == [
        "Summary: the study's questions and answers", "Consistency of the report's own numbers"]
    assert not units & {"ε/σ", "τ", "σ", "ε", "ετ/σ³", "1/τ", "σ/τ"}, units
    for lj in ("ε/σ", "ετ/σ³", " τ ", "LJ", "MD spring force", "the MD trace"):
        assert lj not in md, lj
    assert re.search(r"^\| static force \| 9\.7\d*e-06 ± \S+ N \|", md, re.M) and "(SI)" in md
    assert all(re.search(r"\[[^\]]+\]", label) for label in named), named


@pytest.mark.parametrize("calibrated_from, reported_from", [("parent", "run"), ("run", "parent")],
                         ids=["calibrate RUN, report .", "calibrate ., report RUN"])
def test_the_calibration_is_found_from_any_working_directory(synthetic_study, tmp_path, run_cli,
                                                             monkeypatch, calibrated_from,
                                                             reported_from):
    import shutil

    run = tmp_path / "myrun"
    shutil.copytree(synthetic_study.path, run)
    where = {"parent": (tmp_path, "myrun"), "run": (run, ".")}
    monkeypatch.chdir(where[calibrated_from][0])
    assert run_cli("calibrate", where[calibrated_from][1]).code == 0
    monkeypatch.chdir(where[reported_from][0])
    r = run_cli("report", where[reported_from][1])
    assert r.code == 0, r.err
    assert "calibration.json across the runs given" not in r.out, r.out
    md = (run / "report.md").read_text()
    assert md.splitlines()[0] == "# filmfriction report — synthetic (myrun)", md.splitlines()[0]


def test_a_run_given_twice_counts_once(synthetic_study, tmp_path, run_cli, monkeypatch):
    """r1 and /abs/r1 (or ./r1/) are one run: calibrating 'both' must not count its slips twice."""
    import shutil

    run = tmp_path / "r1"
    shutil.copytree(synthetic_study.path, run)
    monkeypatch.chdir(tmp_path)
    r = run_cli("calibrate", "r1", run, "./r1/")
    assert r.code == 0, r.err
    assert len(json.loads((run / "calibration.json").read_text())["runs"]) == 1


def test_no_legend_covers_data(synthetic_study, tmp_path, monkeypatch):
    """Every figure's legend sits off its data: no point or line vertex under it; the slip-law
    figure's loops fill its plane, so its legend is above the axes."""
    import shutil

    import numpy as np
    from matplotlib.figure import Figure

    from filmfriction.workflows import study

    covered, outside, savefig = [], {}, Figure.savefig

    def check(fig, *args, **kwargs):
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        for ax in fig.axes:
            legend = ax.get_legend()
            if legend is None:
                continue
            box = legend.get_window_extent(renderer)
            outside[ax.get_ylabel()] = not box.overlaps(ax.get_window_extent(renderer))
            points = [ln.get_transform().transform(np.column_stack(ln.get_data()).astype(float))
                      for ln in ax.get_lines() if len(ln.get_xdata())]
            points += [c.get_offset_transform().transform(np.asarray(c.get_offsets(), float))
                       for c in ax.collections if len(c.get_offsets())]
            p = np.vstack(points) if points else np.empty((0, 2))
            p = p[np.isfinite(p).all(axis=1)]
            if ((p[:, 0] > box.x0) & (p[:, 0] < box.x1) & (p[:, 1] > box.y0)
                    & (p[:, 1] < box.y1)).any():
                covered.append(ax.get_ylabel())
        return savefig(fig, *args, **kwargs)

    run = tmp_path / "run"
    shutil.copytree(synthetic_study.path, run)
    monkeypatch.setattr(Figure, "savefig", check)
    assert study.finish_study(run) == 0
    assert not covered, covered
    slip_law = [ok for label, ok in outside.items() if label.startswith("film force")]
    assert slip_law == [True], outside


def test_the_lambda_zeta_legend_is_off_the_plane(monkeypatch):
    """A contact in the lower right of the plane (a compared run, Klein's) was under the legend."""
    from matplotlib.figure import Figure

    from filmfriction.workflows.report.plots import fig_lambda_zeta

    clear, savefig = [], Figure.savefig

    def check(fig, *args, **kwargs):
        fig.canvas.draw()
        r = fig.canvas.get_renderer()
        clear.extend(not ax.get_legend().get_window_extent(r).overlaps(ax.get_window_extent(r))
                     for ax in fig.axes)
        return savefig(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", check)
    fig_lambda_zeta([("run (MD)", 3.0, 0.2, 0.3, 0.05), ("Klein", 4.1, 0.5, 128.0, 10.0)])
    assert clear == [True]


def test_a_run_without_slips_prints_no_nan(synthetic_study, tmp_path, capsys):
    """A run too short for a slip: the study's summary lines say what is missing, not 'nan'."""
    import shutil

    from filmfriction.workflows import study

    run = tmp_path / "short"
    shutil.copytree(synthetic_study.path, run)
    for name in ("analysis.json", "calibration.json", "sfb.json"):
        (run / name).unlink(missing_ok=True)
    lines = (run / "trace.csv").read_text().splitlines()
    (run / "trace.csv").write_text("\n".join(lines[:40]) + "\n")      # the first stick only
    capsys.readouterr()
    study.finish_study(run)
    out = capsys.readouterr().out
    assert "analysis: unresolved, 0 slips ->" in out, out
    assert "nan" not in out, out


def test_a_moved_run_keeps_its_calibration(synthetic_study, tmp_path, run_cli):
    """calibrate, then move or rename the run directory: its calibration.json is still its own."""
    import shutil

    shutil.copytree(synthetic_study.path, tmp_path / "before")
    assert run_cli("calibrate", tmp_path / "before").code == 0
    (tmp_path / "before").rename(tmp_path / "after")
    r = run_cli("report", tmp_path / "after")
    assert r.code == 0, r.err
    assert "calibration.json across the runs given" not in r.out, r.out


def test_a_compared_run_without_similarity_rows_is_named(synthetic_study, tmp_path, run_cli):
    """--compare OTHER whose sfb.json has no similarity rows (no slips): it was left out
    without a word."""
    import shutil

    other = tmp_path / "other"
    shutil.copytree(synthetic_study.path, other)
    doc = json.loads((other / "sfb.json").read_text())
    doc["rows"] = [r for r in doc["rows"] if r["source"] != "similarity"]
    (other / "sfb.json").write_text(json.dumps(doc))
    out = tmp_path / "cmp.html"
    r = run_cli("report", synthetic_study.path, "--compare", other, "--out", out)
    assert r.code == 0, r.err
    assert "`other` (compared): no similarity rows" in out.with_suffix(".md").read_text()
