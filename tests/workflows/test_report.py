"""The report builds from a run, says what the run's analysis says, and renders in
headless Chromium.

Two studies (analysis, calibration, SFB check, report) are made once each: one on
a synthetic run directory with a known answer (fast, no LAMMPS), one on a copy of
the session's small real run (``film_run`` in conftest.py, marker md).  The same
content checks run on both.  The Chromium test skips when no chromium binary is
found (install: ``apt-get install -y chromium``).
"""
import base64
import json
import os
import re
import shutil
import subprocess
import tempfile
from types import SimpleNamespace

import pytest

from filmfriction.workflows import cli

SECTIONS = ("Scene and parameters", "Stick-slip trace", "Energy partition",
            "Effective viscosity", "The film: density profile and picture",
            "Calibrated reduced model", "Comparison with the SFB experiment", "Cost and provenance")

CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync")

PNG = b"\x89PNG\r\n\x1a\n"
#: per-cycle rows of the report's trace table, as named in analysis.json
CYCLE_ROWS = ("static_force", "backward_force", "slip_distance", "slip_duration",
              "stick_duration", "period")


def _study(run_dir):
    """The post-MD study on ``run_dir``; returns the axes labels of every figure drawn."""
    from filmfriction.workflows import report, study as study_mod

    labels, png = [], report._png

    def capture(fig):
        labels.append([(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes])
        return png(fig)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(report, "_png", capture)
        assert study_mod.finish_study(run_dir) == 0
    return labels


@pytest.fixture(scope="module")
def synthetic_study(tmp_path_factory):
    """The study on a synthetic run (4 Klein-type slips, a 3-layer trajectory)."""
    from filmfriction.analysis.synthetic import run_directory

    run_dir = run_directory(tmp_path_factory.mktemp("report-synthetic") / "run", layers=3)
    return SimpleNamespace(path=run_dir, labels=_study(run_dir))


@pytest.fixture(scope="module")
def study(film_run, tmp_path_factory):
    """The study on a copy of the session's small real run (the study writes into it)."""
    run_dir = tmp_path_factory.mktemp("report") / "run"
    shutil.copytree(film_run.path, run_dir)
    _study(run_dir)
    return run_dir


def _images(html):
    """name -> PNG bytes of every <img> of the HTML report."""
    imgs = re.findall(r"<img alt='([^']+)' src='data:image/png;base64,([A-Za-z0-9+/=]+)'", html)
    assert html.count("<img") == len(imgs), "an image that is not an inline PNG"
    return {name: base64.b64decode(data) for name, data in imgs}


def check_outputs(run_dir):
    """Every file of the study is there and well formed."""
    doc = json.loads((run_dir / "analysis.json").read_text())
    assert doc["slips"]["count"] >= 2 and doc["regime"] in ("stick-slip", "irregular")
    cal = json.loads((run_dir / "calibration.json").read_text())
    from filmfriction.workflows.calibrate import SCHEMA
    assert cal["schema"] == SCHEMA and len(cal["runs"]) == 1
    rows = json.loads((run_dir / "sfb.json").read_text())
    assert rows and {"name", "source", "klein", "model", "ratio", "units"} <= set(rows[0])
    assert "slip_time" in {r["name"] for r in rows}


def check_report(run_dir, out=None):
    """The report's content (``out``, default ``run_dir/report.html``, and its Markdown
    twin): sections, figures as images, the numbers of the run's analysis.json."""
    out = out or run_dir / "report.html"
    html = out.read_text()
    md = out.with_suffix(".md").read_text()
    for title in SECTIONS:
        assert title in html and title in md, title
    images = _images(html)
    assert {"trace", "energy", "film", "sfb"} <= set(images), set(images)
    for name, data in images.items():
        assert data.startswith(PNG) and len(data) > 5000, (name, len(data))
    # the markdown twin links PNG files next to it: the same figures, byte for byte
    links = re.findall(r"!\[([^\]]*)\]\(([^)]+\.png)\)", md)
    assert {name for name, _ in links} == set(images)
    for name, link in links:
        assert (out.parent / link).read_bytes() == images[name], link
    # the numbers of analysis.json, with their units, are the report's numbers
    doc = json.loads((run_dir / "analysis.json").read_text())
    slips = doc["slips"]
    assert f"Regime: **{doc['regime']}**" in md
    assert f"{slips['count']} slips detected" in md
    for key in CYCLE_ROWS:
        entry = slips[key]
        if entry["mean"] is None:
            continue
        # "value ± stderr units", or "value units" when one cycle gives no stderr
        row = re.search(rf"^\| {key.replace('_', ' ')} \| (\S+)(?: ± (\S+))? (\S+) \|$", md, re.M)
        assert row, f"no row for {key} in report.md"
        assert float(row.group(1)) == pytest.approx(entry["mean"], rel=6e-3), key
        if entry["stderr"] is None:
            assert row.group(2) is None, key
        else:
            assert float(row.group(2)) == pytest.approx(entry["stderr"], rel=6e-2), key
        assert row.group(3) == entry["units"], key
    closure = re.search(r"closure (\S+) \(relative\)", md)
    assert closure and float(closure.group(1)) == pytest.approx(
        doc["energy"]["ledger"]["closure"]["mean"], rel=6e-2, abs=1e-12)
    layers = doc["structure"]["layers"]["count"]
    assert f"Structure analysis: {layers} layers" in md
    # the Braun & Tosatti statement and provenance are there
    assert "Braun & Tosatti" in md
    assert "atom-steps per second" in md and "versions" in md


def check_axes_units(labels):
    """Every axis label of every figure names its unit in brackets."""
    assert len(labels) >= 5
    named = [label for fig in labels for axis in fig for label in axis if label]
    # a density axis without a unit is the one gap known (its profile may be a number
    # density in 1/sigma^3 or normalised to 1): reported, left out here
    missing = [label for label in named if not re.search(r"\[[^\]]+\]", label) and label != "density"]
    assert not missing, f"axis labels without a unit: {missing}"
    units = {u for label in named for u in re.findall(r"\[([^\]]+)\]", label)}
    assert {"τ", "ε/σ", "σ", "ε", "1/τ", "ετ/σ³", "ms", "nm", "%"} <= units, units


def test_synthetic_study_writes_every_output(synthetic_study):
    check_outputs(synthetic_study.path)


def test_synthetic_report_shows_the_analysis(synthetic_study):
    check_report(synthetic_study.path)
    # the synthetic run's known answer: Klein-type slips from 3 to 1 eps/sigma
    doc = json.loads((synthetic_study.path / "analysis.json").read_text())
    assert doc["slips"]["static_force"]["mean"] == pytest.approx(3.0, rel=0.1)
    assert doc["structure"]["layers"]["count"] == 3


def test_every_figure_has_units_on_its_axes(synthetic_study):
    check_axes_units(synthetic_study.labels)


def test_a_run_without_trajectory_says_which_scene_draws_the_film(tmp_path):
    from filmfriction.workflows import report

    assert report.fig_film(tmp_path) == (None, "")
    sec = report._film_section(SimpleNamespace(run_dir=tmp_path, analysis={}), {})
    assert sec.title == "The film: density profile and picture"
    assert any("`film-structure` scene" in b for b in sec.blocks if isinstance(b, str))


@pytest.mark.md
def test_study_writes_every_output(study):
    check_outputs(study)


@pytest.mark.md
def test_report_sections_and_figures(study):
    check_report(study)


@pytest.mark.md
def test_report_cli_with_out(study, tmp_path):
    out = tmp_path / "r.html"
    assert cli.main(["report", str(study), "--out", str(out)]) == 0
    # the same report, written elsewhere under the name asked for
    check_report(study, out)
    assert (tmp_path / "r-trace.png").stat().st_size > 5000
    assert cli.main(["report", str(tmp_path / "nothing")]) == 2


def test_film_figure_from_a_trajectory(synthetic_run):
    """The film picture and density profile from a (synthetic) trajectory."""
    from filmfriction.workflows.report import fig_film

    png, note = fig_film(synthetic_run)
    assert png[:8] == PNG and len(png) > 5000
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
    assert cli.main(["report", str(sweep)]) == 0
    text = (sweep / "report.md").read_text()
    assert "## Sweeps" in text and "0.22" in text and "−2/3" in text
    # the sweep's figure, as the sweep drew it, in both twins
    drawn = (sweep / "velocity_map.png").read_bytes()
    assert (sweep / "report-sweep-velocity_map.png").read_bytes() == drawn
    assert _images((sweep / "report.html").read_text())["sweep-velocity_map"] == drawn
    assert str(study) in text  # the sweep's run is the report's main run
