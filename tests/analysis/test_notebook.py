"""The example notebook ``docs/examples/analyse_a_trace.ipynb`` runs: its code cells are
executed in order in one namespace, from the repository root, as a kernel would run
them (the notebook has no magics or shell escapes, which this runner refuses), and its
own assertions check the numbers against those the trace was made with.

The runner reads the notebook as the JSON it is (nbformat 4) and needs no Jupyter
kernel: what it cannot catch is a notebook that only runs under IPython, which the
refusal of ``%``/``!`` lines rules out.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from filmfriction.analysis.results import AnalysisResult

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK = ROOT / "docs" / "examples" / "analyse_a_trace.ipynb"


def code_cells(path: Path) -> list[str]:
    nb = json.loads(path.read_text())
    assert nb["nbformat"] == 4
    cells = ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"]
    for source in cells:
        for line in source.splitlines():
            assert not line.lstrip().startswith(("%", "!")), f"IPython-only line: {line}"
    return cells


def run_notebook(path: Path) -> dict:
    """Execute the code cells of ``path`` in one namespace; returns the namespace."""
    import matplotlib

    matplotlib.use("Agg")
    namespace: dict = {"__name__": "__notebook__"}
    for i, source in enumerate(code_cells(path)):
        try:
            exec(compile(source, f"{path.name}[cell {i}]", "exec"), namespace)
        except Exception as exc:  # noqa: BLE001 -- say which cell failed
            raise AssertionError(f"{path.name}: code cell {i} failed: {exc!r}") from exc
    return namespace


def test_the_example_notebook_runs(monkeypatch):
    pytest.importorskip("pandas")
    monkeypatch.chdir(ROOT)
    ns = run_notebook(NOTEBOOK)
    result = ns["result"]
    assert isinstance(result, AnalysisResult) and result.status == "stick-slip"
    assert len(ns["slips"]) == result.slips["count"] == 5
    assert ns["fig"].axes and ns["ax"].get_ylabel() == "F_s [µN]"
    assert "slips" in ns["doc"] and os.path.basename(str(result.trace.path)) == "<arrays>"


def test_the_runner_fails_on_a_failing_cell(tmp_path, monkeypatch):
    """Negative control: a notebook whose cell raises does not pass."""
    nb = json.loads(NOTEBOOK.read_text())
    nb["cells"].append({"cell_type": "code", "metadata": {}, "execution_count": None,
                        "outputs": [], "id": "bad", "source": ["assert result.status == 'smooth'"]})
    bad = tmp_path / "bad.ipynb"
    bad.write_text(json.dumps(nb))
    monkeypatch.chdir(ROOT)
    with pytest.raises(AssertionError, match="code cell"):
        run_notebook(bad)
