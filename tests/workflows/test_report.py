"""The report builds from a small real MD run and renders in headless Chromium.

The session's small real run (``film_run`` in conftest.py: a 5x3-cell
film-structure film, 14k steps) is copied once for the module; the post-MD study
(analysis, calibration, SFB check, report) runs on the copy, and its report is
checked as the synthetic one is (test_report_content.py).  The Chromium test
skips when no chromium binary is found (install: ``apt-get install -y chromium``).
"""
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

from filmfriction.workflows import cli

SECTIONS = ("Scene and parameters", "Stick-slip trace", "Energy partition",
            "Effective viscosity", "The film: density profile and picture",
            "Calibrated reduced model", "Comparison with the SFB experiment", "Cost and provenance")

CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync")


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
    from filmfriction.workflows.report import fig_film

    png, note = fig_film(synthetic_run)
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 5000
    assert "side view" in note


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


@pytest.mark.md
def test_report_renders_in_headless_chromium(study):
    browser = _chromium()
    if browser is None:
        pytest.skip("no chromium binary on PATH (install with: apt-get install -y chromium)")
    with tempfile.TemporaryDirectory() as profile:
        cmd = [browser, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "--virtual-time-budget=10000",
               "--dump-dom", (study / "report.html").resolve().as_uri()]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120,
                              env={**os.environ, "HOME": profile})
    body = re.search(r"<body[^>]*>", proc.stdout)
    assert body, f"no DOM from chromium (rc {proc.returncode}): {proc.stderr[-2000:]}"
    total = re.search(r'data-images-total="(\d+)"', body.group(0))
    loaded = re.search(r'data-images-loaded="(\d+)"', body.group(0))
    assert total and loaded, body.group(0)
    n_img = proc.stdout.count("<img")
    assert int(total.group(1)) == n_img >= 2
    assert int(loaded.group(1)) == int(total.group(1)), "some figures did not load"


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
    from filmfriction.workflows import cli

    assert cli.main(["report", str(sweep)]) == 0
    text = (sweep / "report.md").read_text()
    assert "## Sweeps" in text and "0.22" in text and "−2/3" in text
    # the sweep's figure, as the sweep drew it, in both twins
    drawn = (sweep / "velocity_map.png").read_bytes()
    assert (sweep / "report-sweep-velocity_map.png").read_bytes() == drawn
    assert report_checks.images((sweep / "report.html").read_text())["sweep-velocity_map"] == drawn
    assert str(study) in text  # the sweep's run is the report's main run
