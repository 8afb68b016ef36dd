"""The report's SFB figure, without a browser: its legend covers no curve (matplotlib's
legend box against every line's data in display coordinates), no curve runs beyond the
slip time the table gives, and its axes carry SI prefixes, not an offset."""
from __future__ import annotations

import math

import numpy as np
import pytest

from filmfriction.reduced_model.sfb.check import sfb_check
from filmfriction.workflows.report.plots import fig_sfb, sfb_curves
from filmfriction.workflows.rundir import SFBDocument, SlipTrace


def _document(check) -> SFBDocument:
    """The check as the report reads it back (rows, slips with their traces)."""
    slips = {k: SlipTrace(r.slip_time, r.slip_distance, np.asarray(r.t), np.asarray(r.x))
             for k, r in check.slips.items()}
    doc = check.as_dict()
    return SFBDocument(rows=doc["rows"], notes=tuple(doc["notes"]), slips=slips, doc=doc)


def covered_points(ax) -> int:
    """How many data points of the axes' lines fall inside its legend's box (display
    coordinates, after drawing)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(ax.figure)     # the figure is closed once saved as PNG
    canvas.draw()
    box = ax.get_legend().get_window_extent(canvas.get_renderer())
    n = 0
    for line in ax.get_lines():
        xy = ax.transData.transform(np.column_stack(line.get_data()).astype(float))
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        n += int(np.sum((xy[:, 0] >= box.x0) & (xy[:, 0] <= box.x1)
                        & (xy[:, 1] >= box.y0) & (xy[:, 1] <= box.y1)))
    return n


@pytest.fixture(scope="module")
def klein():
    return _document(sfb_check())


def measured_slips(check, n=3, seed=1):
    """Slips like the model's set-up curve with 1 nm noise: what a measured trace gives."""
    rng = np.random.default_rng(seed)
    s = check.slips["klein"]
    keep = np.asarray(s.t) <= s.slip_time
    t, x = np.asarray(s.t)[keep], np.asarray(s.x)[keep]
    return [(t, x + rng.normal(0, 1e-9, t.size)) for _ in range(n)]


@pytest.mark.parametrize("with_measured", [False, True])
def test_the_sfb_legend_covers_no_curve(klein, with_measured):
    axes = []
    fig_sfb(klein, measured_slips(klein) if with_measured else (), axes_out=axes)
    (ax,) = axes
    assert len(ax.get_lines()) >= 3
    assert covered_points(ax) == 0


def test_the_overlap_check_sees_a_legend_over_the_curves(klein):
    """Negative control: the same figure with its legend moved onto the curves fails."""
    axes = []
    fig_sfb(klein, measured_slips(klein), axes_out=axes)
    (ax,) = axes
    ax.legend(loc="center")
    assert covered_points(ax) > 0


def test_no_curve_runs_beyond_its_slip_time(klein):
    reached = [c for c in sfb_curves(klein) if c[3]]
    assert reached
    for label, t, _, _ in reached:
        key = next(k for k, s in klein.slips.items() if math.isfinite(s.slip_time)
                   and abs(t[-1] - s.slip_time) <= 1e-12 + 0.02 * s.slip_time)
        assert t[-1] <= klein.slips[key].slip_time * (1 + 1e-9), label
    # a slip that does not reach s stops at the figure's window, never far beyond
    window = 1.5 * max(s.slip_time for s in klein.slips.values() if math.isfinite(s.slip_time))
    for _, t, _, _ in sfb_curves(klein):
        assert t[-1] <= window * (1 + 1e-9)


def test_the_sfb_axes_have_si_prefixes_and_no_offset(klein):
    axes = []
    fig_sfb(klein, axes_out=axes)
    (ax,) = axes
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(ax.figure).draw()
    assert ax.get_xlabel().endswith("[ms]") and ax.get_ylabel().endswith("[nm]")
    assert ax.get_xscale() == ax.get_yscale() == "linear"
    assert ax.xaxis.get_offset_text().get_text() == ""
    assert ax.yaxis.get_offset_text().get_text() == ""
