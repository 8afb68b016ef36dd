"""``filmfriction map``: its figures name the unit of every axis, its files are written
atomically (an existing map in --out is replaced whole, never half-written)."""
from __future__ import annotations

import re

import pytest


@pytest.mark.parametrize("kind, resolution", [("lambda-zeta", "4"), ("velocity-stiffness", "2")])
def test_map_axes_have_units_and_outputs_are_atomic(kind, resolution, tmp_path, run_cli,
                                                    monkeypatch):
    from matplotlib.figure import Figure

    from filmfriction.analysis.files import util

    labels, savefig = [], Figure.savefig

    def capture(fig, *args, **kwargs):
        labels.extend(label for ax in fig.axes for label in (ax.get_xlabel(), ax.get_ylabel()))
        return savefig(fig, *args, **kwargs)

    written, write_atomic = [], util.write_atomic

    def record(path, data):
        written.append(path.name)
        return write_atomic(path, data)

    monkeypatch.setattr(Figure, "savefig", capture)
    monkeypatch.setattr(util, "write_atomic", record)
    r = run_cli("map", kind, "--out", tmp_path, "--resolution", resolution, "--processes", "1")
    assert r.code == 0, r.err
    assert len(labels) == 2 and all(re.search(r"\[[^\]]+\]$", label) for label in labels), labels
    stem = kind.replace("-", "_")
    assert sorted(written) == [f"{stem}.csv", f"{stem}.png"]
