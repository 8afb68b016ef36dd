"""The report builds from a small real MD run and renders in headless Chromium.

One real LAMMPS run (a 5x3-cell stick-slip film, 10k steps, ~10-30 s on 2
cores) is made once for the module; the post-MD study (analysis, calibration,
SFB check, report) runs on it.  The Chromium test skips when no chromium
binary is found (install: ``apt-get install -y chromium``).
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
def study(tmp_path_factory):
    """A small real run, then the post-MD study on it."""
    from filmfriction.workflows import runner, scene, study as study_mod

    out = tmp_path_factory.mktemp("report") / "run"
    # drive_velocity 0.1 (5x the default) so that the short run reaches its first yield
    sc = scene.load("stick-slip", {"cells_x": 5, "cells_y": 3, "equilibrate_steps": 2000,
                                   "slide_steps": 8000, "trace_every": 20, "drive_velocity": 0.1})
    try:
        run_dir = runner.execute(sc, out=out, nprocs=2, progress=False)
    except runner.RunFailed as exc:
        pytest.fail(f"the small LAMMPS run failed: {exc}")
    assert study_mod.finish_study(run_dir) == 0
    return run_dir


@pytest.mark.md
def test_study_writes_every_output(study):
    for name in ("analysis.json", "calibration.json", "sfb.json", "report.html", "report.md"):
        assert (study / name).exists(), name


@pytest.mark.md
def test_report_sections_and_figures(study):
    html = (study / "report.html").read_text()
    md = (study / "report.md").read_text()
    for title in SECTIONS:
        assert title in html and title in md, title
    imgs = re.findall(r"<img alt='([^']+)' src='data:image/png;base64,([A-Za-z0-9+/=]+)'", html)
    names = {n for n, _ in imgs}
    assert {"trace", "energy", "sfb"} <= names or {"trace", "sfb"} <= names, names
    assert all(len(data) > 1000 for _, data in imgs)
    # the markdown twin links PNG files that exist next to it
    links = re.findall(r"!\[[^\]]*\]\(([^)]+\.png)\)", md)
    assert links and all((study / link).stat().st_size > 1000 for link in links)
    assert len(links) == len(imgs)
    # no trajectory in this scene: the report says which scene gives the film picture
    assert "film-structure" in md
    # the Braun & Tosatti statement and provenance are there
    assert "Braun & Tosatti" in md
    assert "atom-steps per second" in md and "versions" in md


@pytest.mark.md
def test_report_cli_with_out(study, tmp_path):
    out = tmp_path / "r.html"
    assert cli.main(["report", str(study), "--out", str(out)]) == 0
    assert out.exists() and (tmp_path / "r.md").exists()
    assert cli.main(["report", str(tmp_path / "nothing")]) == 2


def test_film_figure_from_a_trajectory(tmp_path):
    """The film picture and density profile from a (synthetic) trajectory."""
    from filmfriction.analysis.synthetic import run_directory
    from filmfriction.workflows.report import fig_film

    d = run_directory(tmp_path / "synth", trajectory=True)
    png, note = fig_film(d)
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
def test_report_of_a_sweep_has_a_sweep_section(study, tmp_path):
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
    assert (sweep / "report-sweep-velocity_map.png").exists()
    assert str(study) in text  # the sweep's run is the report's main run
