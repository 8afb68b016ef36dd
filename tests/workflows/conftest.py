"""Fixtures of the workflows tests: the post-MD study and the checks of its report.

``report_study(run_dir)`` runs the study (analysis, calibration, SFB check,
report) on a run directory and returns the axis labels of every figure it drew;
``report_checks`` holds the checks that the report tests apply to the synthetic
run (test_report_content.py) and to the real one (test_report.py), among them the
headless-Chromium check that every figure loads at a non-trivial size.
"""
from __future__ import annotations

import base64
import json
import re
from pathlib import Path
from types import SimpleNamespace

import pytest

SECTIONS = ("Scene and parameters", "Stick-slip trace", "Energy partition",
            "Effective viscosity", "The film: density profile and picture",
            "Calibrated reduced model", "Comparison with the SFB experiment", "Cost and provenance")
PNG = b"\x89PNG\r\n\x1a\n"
#: per-cycle rows of the report's trace table, as named in analysis.json
CYCLE_ROWS = ("static_force", "backward_force", "slip_distance", "slip_duration",
              "stick_duration", "period")
#: units that the figures' axes show between them
AXIS_UNITS = {"τ", "ε/σ", "σ", "ε", "1/τ", "ετ/σ³", "ms", "nm", "%", "σ/τ"}


def _study(run_dir: Path) -> list:
    from matplotlib.figure import Figure

    from filmfriction.workflows import study as study_mod

    # every figure the study draws is saved through Figure.savefig, wherever its
    # code lives (the report's own figures, an observable's in the analysis layer)
    labels, savefig = [], Figure.savefig

    def capture(fig, *args, **kwargs):
        labels.append([(ax.get_xlabel(), ax.get_ylabel()) for ax in fig.axes])
        return savefig(fig, *args, **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Figure, "savefig", capture)
        assert study_mod.finish_study(run_dir) == 0
    return labels


@pytest.fixture(scope="session")
def report_study():
    """``report_study(run_dir)``: the post-MD study on ``run_dir`` (it writes there);
    returns the (xlabel, ylabel) of every axis of every figure drawn."""
    return _study


def images(html: str) -> dict[str, bytes]:
    """name -> PNG bytes of every <img> of an HTML report."""
    imgs = re.findall(r"<img alt='([^']+)' src='data:image/png;base64,([A-Za-z0-9+/=]+)'", html)
    assert html.count("<img") == len(imgs), "an image that is not an inline PNG"
    return {name: base64.b64decode(data) for name, data in imgs}


def check_outputs(run_dir: Path) -> None:
    """Every file of the study is there and well formed."""
    from filmfriction.analysis.calibration.calibrate import SCHEMA

    doc = json.loads((run_dir / "analysis.json").read_text())
    assert doc["slips"]["count"] >= 2 and doc["regime"] in ("stick-slip", "irregular")
    cal = json.loads((run_dir / "calibration.json").read_text())
    assert cal["schema"] == SCHEMA and len(cal["runs"]) == 1
    sfb = json.loads((run_dir / "sfb.json").read_text())
    assert sfb["schema"] == "filmfriction.sfb/1"
    rows = sfb["rows"]
    assert rows and {"name", "source", "klein", "model", "ratio", "units"} <= set(rows[0])
    assert "slip_time" in {r["name"] for r in rows}


#: "± value" in a text: the value is an error or a spread, never exactly 0
_PLUS_MINUS = re.compile(r"±\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


def zero_errors(text: str) -> list[str]:
    """The "± 0"-style zero errors of ``text`` (± followed by a number equal to 0), each
    with the 40 characters before it."""
    return [text[max(m.start() - 40, 0):m.end()] for m in _PLUS_MINUS.finditer(text)
            if float(m.group(1)) == 0.0]


def check_content(run_dir: Path, out: Path | None = None) -> None:
    """The report ``out`` (default ``run_dir/report.html``) and its Markdown twin:
    sections, figures as images, the numbers of the run's analysis.json; one η_eff
    named the run's; no "± 0" in any text the study wrote."""
    out = out or run_dir / "report.html"
    html = out.read_text()
    md = out.with_suffix(".md").read_text()
    for path in [out, out.with_suffix(".md"), *run_dir.glob("*.json"), *run_dir.glob("*.txt")]:
        assert not zero_errors(path.read_text()), (path.name, zero_errors(path.read_text()))
    assert len(re.findall(r"The run's η_eff: ", md)) == 1, re.findall(r".*The run's η_eff.*", md)
    for title in SECTIONS:
        assert title in html and title in md, title
    # the report opens with its summary, then the consistency of its own numbers
    assert re.findall(r"^## (.+)$", md, re.M)[:2] == [
        "Summary: the study's questions and answers", "Consistency of the report's own numbers"]
    assert re.findall(r"<h2 id='([^']+)'>", html)[:1] == ["summary-the-studys-questions-and-answers"]
    # every link of the summary leads to a section of the page
    ids = set(re.findall(r"<h2 id='([^']+)'>", html))
    assert set(re.findall(r"<a href='#([^']+)'>", html)) <= ids
    figures = images(html)
    assert {"trace", "energy", "film", "sfb"} <= set(figures), set(figures)
    for name, data in figures.items():
        assert data.startswith(PNG) and len(data) > 5000, (name, len(data))
    # the markdown twin links PNG files next to it: the same figures, byte for byte
    links = re.findall(r"!\[([^\]]*)\]\(([^)]+\.png)\)", md)
    assert {name for name, _ in links} == set(figures)
    for name, link in links:
        assert (out.parent / link).read_bytes() == figures[name], link
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


def check_axes_units(labels: list) -> None:
    """Every axis label of every figure names its unit in brackets."""
    assert len(labels) >= 5
    named = [label for fig in labels for axis in fig for label in axis if label]
    missing = [label for label in named
               if not re.search(r"\[[^\]]+\]", label)]
    assert not missing, f"axis labels without a unit: {missing}"
    units = {u for label in named for u in re.findall(r"\[([^\]]+)\]", label)}
    assert AXIS_UNITS <= units, units


CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync")
#: the least size (width, height in pixels) a figure of the report may have in the browser
MIN_FIGURE = (300, 150)


def chromium() -> str | None:
    """A Chromium binary on PATH, or None."""
    import shutil

    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def check_in_browser(report: Path) -> dict[str, tuple[int, int]]:
    """Open ``report`` in headless Chromium: every figure loads, with a size of at
    least :data:`MIN_FIGURE`; returns name -> (width, height) as the browser decoded it.
    Skips the test when no Chromium is installed."""
    import os
    import subprocess
    import tempfile

    browser = chromium()
    if browser is None:
        pytest.skip("no chromium binary on PATH (install with: apt-get install -y chromium)")
    with tempfile.TemporaryDirectory() as profile:
        cmd = [browser, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "--virtual-time-budget=10000",
               "--dump-dom", Path(report).resolve().as_uri()]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120,
                              env={**os.environ, "HOME": profile})
    body = re.search(r"<body[^>]*>", proc.stdout)
    assert body, f"no DOM from chromium (rc {proc.returncode}): {proc.stderr[-2000:]}"
    total = re.search(r'data-images-total="(\d+)"', body.group(0))
    loaded = re.search(r'data-images-loaded="(\d+)"', body.group(0))
    assert total and loaded, body.group(0)
    imgs = re.findall(r"<img [^>]*>", proc.stdout)
    assert int(total.group(1)) == len(imgs) >= 2
    assert int(loaded.group(1)) == int(total.group(1)), "some figures did not load"
    sizes = {}
    for tag in imgs:
        name = re.search(r'alt="([^"]*)"', tag).group(1)
        natural = re.search(r'data-natural-size="(\d+)x(\d+)"', tag)
        shown = re.search(r'data-shown-size="(\d+)x(\d+)"', tag)
        assert natural and shown, tag[:200]
        w, h = int(natural.group(1)), int(natural.group(2))
        assert w >= MIN_FIGURE[0] and h >= MIN_FIGURE[1], (name, w, h)
        assert int(shown.group(1)) > 0 and int(shown.group(2)) > 0, (name, shown.group(0))
        sizes[name] = (w, h)
    return sizes


@pytest.fixture(scope="session")
def report_checks():
    """The report checks: ``outputs(run_dir)``, ``content(run_dir, out=None)``,
    ``axes_units(labels)``, ``images(html)``, ``in_browser(report_html)``."""
    return SimpleNamespace(outputs=check_outputs, content=check_content, zero_errors=zero_errors,
                           axes_units=check_axes_units, images=images, sections=SECTIONS, png=PNG,
                           in_browser=check_in_browser)


@pytest.fixture
def interrupted_run():
    """``interrupted_run(run_dir)``: a run directory as an interrupted run leaves it,
    without LAMMPS: restarts at 2000 and 4000 (made of LAMMPS's markers around
    arbitrary bytes, each recorded as if LAMMPS had finished it), trace rows every
    200 steps up to 4400, the slide origin; returns ``run_dir``."""
    def make(run_dir: Path) -> Path:
        import numpy as np

        from filmfriction.md_inputs.contract import DAT_COLUMNS
        from filmfriction.workflows.md import restarts
        from filmfriction.workflows.md.scene import load

        scene = load("stick-slip", {"slide_steps": 8000, "restart_every": 2000,
                                    "equilibrate_steps": 100, "trace_every": 200})
        run_dir.mkdir()
        for step in (2000, 4000):
            (run_dir / f"restart.{step}").write_bytes(
                restarts.MAGIC + bytes(range(256)) * 8 + restarts.MAGIC)
        restarts.RestartLedger(run_dir).record_below(4400)
        steps = np.arange(0, 4401, 200)
        rows = np.column_stack([steps] + [steps * 0.001 + i for i in range(1, len(DAT_COLUMNS))])
        (run_dir / "trace.dat").write_text(
            "# " + " ".join(DAT_COLUMNS) + "\n"
            + "".join(" ".join(f"{v:.10g}" for v in r) + "\n" for r in rows))
        (run_dir / "slide_origin.txt").write_text("0.0 0.0\n")
        (run_dir / "lammps.screen").write_text("")
        (run_dir / "run.json").write_text(json.dumps({
            "schema": "filmfriction.run/1", "status": "interrupted", "error": "interrupted",
            "scene": scene.as_dict(), "np": 1, "command": ["mpiexec", "-n", "1", "lmp"],
            "segments": [], "trace_parameters": {}}))
        return run_dir
    return make


def _lock_held(run_dir: Path) -> bool:
    """Whether some process still holds the run directory's lock."""
    import fcntl

    with open(run_dir / ".lock") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return True
        fcntl.flock(fh, fcntl.LOCK_UN)
    return False


@pytest.fixture
def lock_held():
    """``lock_held(run_dir)``: whether some process still holds the run directory's lock."""
    return _lock_held


def _processes_in(directory: Path, *, kill: bool = False) -> dict[int, str]:
    """Live processes whose working directory is ``directory`` or inside it (a run's
    launcher, proxy and ranks; the runs of a sweep's points): pid -> command line.
    ``kill``: each one found is sent SIGKILL (a test's leftovers)."""
    import os
    import signal

    target = str(Path(directory).resolve())
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cwd = os.readlink(entry / "cwd")
            if cwd != target and not cwd.startswith(target + os.sep):
                continue
            # the command name may hold spaces: the state is the field after the last ')'
            if (entry / "stat").read_text().rsplit(")", 1)[1].split()[0] in ("Z", "X"):
                continue
            found[int(entry.name)] = (entry / "cmdline").read_bytes().decode(
                errors="replace").replace("\0", " ")
            if kill:
                os.kill(int(entry.name), signal.SIGKILL)
        except OSError:
            continue
    return found


@pytest.fixture
def processes_in():
    """``processes_in(directory, kill=False)``: the live processes working in
    ``directory`` or below it, pid -> command line; with ``kill=True`` each is killed."""
    return _processes_in
