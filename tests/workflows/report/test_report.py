"""The report builds from a small real MD run and renders in headless Chromium.

The session's small real run (``film_run`` in conftest.py: a 5x3-cell
film-structure film, 14k steps) is copied once for the module; the post-MD study
(analysis, calibration, SFB check, report) runs on the copy, and its report is
checked as the synthetic one is (test_report_content.py).  The Chromium test
skips when no chromium binary is found (install: ``apt-get install -y chromium``).
"""
import shutil

import pytest

from filmfriction.workflows.cli import main as cli

SECTIONS = ("Scene and parameters", "Stick-slip trace", "Energy partition",
            "Effective viscosity", "The film: density profile and picture",
            "Calibrated reduced model", "Comparison with the SFB experiment", "Cost and provenance")


@pytest.fixture(scope="module")
def study(film_run, tmp_path_factory, report_study):
    """A copy of the session's small real run (the study writes into it), then the
    post-MD study on it."""
    run_dir = tmp_path_factory.mktemp("report") / "run"
    shutil.copytree(film_run.path, run_dir)
    report_study(run_dir)
    return run_dir


@pytest.mark.md
def test_study_writes_every_output(study, report_checks):
    report_checks.outputs(study)


@pytest.mark.md
def test_report_sections_and_figures(study, report_checks):
    # sections, figures as images (the film's too: the run wrote a trajectory), the
    # analysis' numbers with their units, Braun & Tosatti and the provenance
    report_checks.content(study)
    html = (study / "report.html").read_text()
    assert report_checks.sections == SECTIONS
    assert "film" in report_checks.images(html)


@pytest.mark.md
def test_report_cli_with_out(study, tmp_path, report_checks):
    out = tmp_path / "r.html"
    assert cli.main(["report", str(study), "--out", str(out)]) == 0
    # the same report, written elsewhere under the name asked for
    report_checks.content(study, out)
    assert (tmp_path / "r-trace.png").stat().st_size > 5000
    assert cli.main(["report", str(tmp_path / "nothing")]) == 2


def test_film_figure_from_a_trajectory(synthetic_run):
    """The film picture and density profile from a (synthetic) trajectory."""
    from filmfriction.analysis.observables.structure_section import fig_film

    png, note = fig_film(synthetic_run)
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 5000
    assert "side view" in note


def _analysed_synthetic_run(directory):
    """A synthetic run directory (no LAMMPS) with its analysis written, as `filmfriction analyze` does."""
    from filmfriction.analysis.analyze import analyze, write_outputs
    from filmfriction.analysis.groundtruth.synthetic import run_directory
    from filmfriction.analysis.files.trace_reader import read_trace

    d = run_directory(directory, trajectory=False)
    doc, per_cycle = analyze(read_trace(d))
    write_outputs(doc, per_cycle, d / "analysis.json")
    return d


def test_report_without_calibration_says_so_and_does_not_calibrate(tmp_path, monkeypatch, capsys):
    from filmfriction.analysis.calibration import calibrate as calibration
    from filmfriction.reduced_model import SpringBlock
    from filmfriction.reduced_model.sfb import check as sfb

    d = _analysed_synthetic_run(tmp_path / "run")

    def refuse(*args, **kwargs):
        raise AssertionError("the report computed a calibration or a model run")

    # the report must neither calibrate nor run the reduced model (replay, SFB slips)
    monkeypatch.setattr(calibration, "calibrate", refuse)
    monkeypatch.setattr(calibration, "calibrate_run", refuse)
    monkeypatch.setattr(sfb, "sfb_check", refuse)
    monkeypatch.setattr(SpringBlock, "simulate", refuse)
    assert cli.main(["report", str(d)]) == 0
    out = capsys.readouterr().out
    # the CLI prints what is missing and the command that makes it
    assert f"{d / 'calibration.json'}; make it with: filmfriction calibrate {d}" in out
    assert f"filmfriction sfb --calibration {d / 'calibration.json'} --out {d / 'sfb.json'}" in out
    md = (d / "report.md").read_text()
    assert "No `calibration.json` in" in md and "does not calibrate" in md
    assert f"`filmfriction calibrate {d}`" in md
    assert "No `sfb.json` in" in md and "Braun & Tosatti" in md
    assert "## Inputs the report did not find" in md
    assert not (d / "calibration.json").exists() and not (d / "sfb.json").exists()
    # without an analysis it renders nothing and says which command makes it
    (d / "analysis.json").unlink()
    assert cli.main(["report", str(d)]) == 2
    assert f"filmfriction analyze {d}" in capsys.readouterr().err


def test_the_study_writes_what_the_report_renders(tmp_path):
    """The post-MD study on a synthetic run (no LAMMPS): files first, then the report reads them."""
    from filmfriction.analysis.groundtruth.synthetic import run_directory
    from filmfriction.workflows.rundir import read_calibration, read_sfb
    from filmfriction.workflows.study import finish_study

    d = run_directory(tmp_path / "run", trajectory=False)
    assert finish_study(d) == 0
    cal, check = read_calibration(d / "calibration.json"), read_sfb(d / "sfb.json")
    assert cal["replay_trace"] is not None and len(cal["replay_trace"]["t"]) > 10
    assert check.calibration == cal["md_calibration"] is not None
    assert {"klein", "bulk", "md"} <= set(check.slips) and check.slips["md"].t is not None
    md = (d / "report.md").read_text()
    for title in SECTIONS:
        assert title in md, title
    assert "Inputs the report did not find" not in md and "Steps that failed" not in md
    for name in ("trace", "viscosity", "replay", "replay-errors", "sfb"):
        assert (d / f"report-{name}.png").exists(), name
    # the SFB table of the report is the one in sfb.json; the md-calibrated rows carry the
    # law many decades of shear rate: they are in the appendix, without ratio or interval
    from filmfriction.workflows.report.summary import MAX_DECADES, extrapolated_decades

    assert extrapolated_decades(check.rows) > MAX_DECADES
    main, appendix = md.split("## Appendix: SFB-scale carry-over")
    row = check.row("slip_time", "sfb-parameters")
    assert f"| slip_time | sfb-parameters | {row['klein']:.3g} |" in main
    assert "| md-calibrated |" not in main
    assert f"| slip_time | {check.row('slip_time', 'md-calibrated')['klein']:.2g} | ~" in appendix
    assert md.index("## Summary: the study's questions and answers") < md.index("## Scene")


@pytest.mark.md
def test_report_renders_in_headless_chromium(study, report_checks):
    sizes = report_checks.in_browser(study / "report.html")
    # every figure of the report, the film's own included (the run wrote a trajectory)
    assert set(sizes) == set(report_checks.images((study / "report.html").read_text()))
    assert {"trace", "structure-time", "layers-top", "velocity-profile", "ledger"} <= set(sizes)


@pytest.mark.md
def test_report_of_a_sweep_has_a_sweep_section(study, tmp_path, report_checks):
    """A finished sweep directory given to the report adds its section and its runs."""
    import json

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sweep = tmp_path / "sweep"
    sweep.mkdir()
    fig, ax = plt.subplots()
    ax.plot([1, 2], [1, 2])
    fig.savefig(sweep / "velocity_map.png")
    plt.close(fig)
    (sweep / "aggregate.json").write_text(json.dumps({
        "scene": "stick-slip", "grid": [{"key": "drive_velocity", "spec": "drive_velocity=0.1,0.5",
                                          "values": [0.1, 0.5]}],
        "points": [{}, {}], "run_dirs": [str(study)], "calibration_runs": [str(study)],
        "critical_velocity": [{"group": {}, "status": "bracketed", "value": 0.22, "factor": 2.2,
                               "note": "stick-slip up to V = 0.1, smooth from 0.5"}],
        "power_law": {"exponent": -0.7, "exponent_stderr": 0.1, "n": 3, "points": "steady"}}))
    from filmfriction.workflows.cli import main as cli

    assert cli.main(["report", str(sweep)]) == 0
    text = (sweep / "report.md").read_text()
    assert "## Sweeps" in text and "0.22" in text and "−2/3" in text
    # the sweep's figure, as the sweep drew it, in both twins
    drawn = (sweep / "velocity_map.png").read_bytes()
    assert (sweep / "report-sweep-velocity_map.png").read_bytes() == drawn
    assert report_checks.images((sweep / "report.html").read_text())["sweep-velocity_map"] == drawn
    assert str(study) in text  # the sweep's run is the report's main run
