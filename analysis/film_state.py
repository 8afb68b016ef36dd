"""A lasting change of the film's state: its gap gains or loses half a layer for good.

A film of n layers between the walls' innermost planes sits at a gap of n + 1 layer
spacings.  Its slips dilate it by a few hundredths of a layer to a quarter of one, and
it closes again at the re-stick; a film that melts and takes (or loses) a layer stays
beyond half a layer from where it started, to the end of the run.  Stick-slip
statistics, the slip law and Eq. (1)'s η_eff are those of the layered film only
before that: :func:`lasting_gap_change` finds the change, and the analysis
(:func:`~filmfriction.analysis.analyze.analyze`) stops there.

Measured on nine MD runs of 2.8–4.6 M steps (four and six layers, kT 0.63–0.71;
docs/analysis.md, "A film that changed state"): the gap smoothed over
:data:`SMOOTHING_SHARE` of the run stays within 0.24 of a layer of its start in the eight
that kept their layers, and the one that took a fifth layer sits at +1.01 layer from
t ≈ 10 440 τ to its end.

Example
-------
>>> import numpy as np
>>> t = np.arange(4000) * 0.25
>>> gap = np.where(t < 600.0, 4.7, 5.7)          # four layers: a layer is 4.7/5 = 0.94
>>> change = lasting_gap_change(t, gap, film_layers=4)
>>> round(change.time, 2), round(change.layers, 2)
(600.0, 1.06)
>>> lasting_gap_change(t, np.full(t.size, 4.7), film_layers=4) is None
True
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import median_filter

__all__ = ["GapChange", "lasting_gap_change", "GAP_LAYER_CHANGE", "ONSET_LAYER",
           "LASTING_SHARE", "SMOOTHING_SHARE", "REFERENCE_SHARE", "FRAMES_NOT_CUT"]

#: A change of the gap by this share of one layer spacing, lasting to the end, is a change of
#: the film's state (a slip dilates it by at most a quarter layer).
GAP_LAYER_CHANGE = 0.5
#: The change starts at the first sample after the last one within this share of a layer of
#: the start.
ONSET_LAYER = 0.25
#: A change lasts: the smoothed gap stays beyond :data:`GAP_LAYER_CHANGE` over at least this
#: share of the samples, to the last one (a slip under way at the run's end dilates it briefly).
LASTING_SHARE = 0.05
#: Why a section that reads a run's frames (trajectory, profiles) and cannot cut them at the
#: change is skipped.
FRAMES_NOT_CUT = ("the film changed state and {what} frames after the change are not "
                  "separated (analyze --whole-trace reads them all)")
#: The gap is smoothed by a running median over this share of the samples (at least 5).
SMOOTHING_SHARE = 0.001
#: The starting gap is the median over this first share of the samples (at least 10).
REFERENCE_SHARE = 0.1


@dataclass(frozen=True)
class GapChange:
    """Where the film changed state: the analysis keeps the samples before ``index``.

    Attributes
    ----------
    index : int
        The first sample of the change: the first after the last sample whose smoothed
        gap was within :data:`ONSET_LAYER` of its start before it left for good.
    time : float
        The time of that sample.
    gap_before, gap_after : float
        The starting gap and the mean gap over the samples beyond the threshold.
    layer_spacing : float
        The starting gap over film_layers + 1.
    layers : float
        (gap_after − gap_before)/layer_spacing.
    """

    index: int
    time: float
    gap_before: float
    gap_after: float
    layer_spacing: float
    layers: float

    def note(self, time_unit: str = "") -> str:
        unit = f" {time_unit}" if time_unit else ""
        return (f"the film changed state at t = {self.time:.6g}{unit}: its gap went from "
                f"{self.gap_before:.3g} to {self.gap_after:.3g} ({self.layers:+.2f} of a "
                f"layer spacing of {self.layer_spacing:.3g}) and stayed beyond "
                f"{GAP_LAYER_CHANGE:g} of a layer to the end; analysed before that time")

    def to_dict(self) -> dict:
        return {"index": self.index, "time": self.time, "gap_before": self.gap_before,
                "gap_after": self.gap_after, "layer_spacing": self.layer_spacing,
                "layers": self.layers, "threshold_layers": GAP_LAYER_CHANGE}


def lasting_gap_change(time, gap, film_layers: int) -> GapChange | None:
    """The film's lasting change of state in a trace's ``gap`` column, or None.

    The gap, smoothed by a running median, must leave its starting value by more than
    :data:`GAP_LAYER_CHANGE` of a layer spacing and stay beyond it to the last sample over
    at least :data:`LASTING_SHARE` of the samples, its mean there too beyond it; the change
    starts at the first sample after the last one within :data:`ONSET_LAYER` of the
    start.  A trace of fewer than 20 samples, or whose gap is not finite, has none.
    """
    t = np.asarray(time, dtype=float)
    g = np.asarray(gap, dtype=float)
    n = g.size
    if n < 20 or t.size != n or film_layers < 1 or not np.all(np.isfinite(g)):
        return None
    g0 = float(np.median(g[:max(10, int(REFERENCE_SHARE * n))]))
    if not g0 > 0:
        return None
    layer = g0 / (film_layers + 1)
    smooth = median_filter(g, size=max(5, int(SMOOTHING_SHARE * n)), mode="nearest")
    away = np.abs(smooth - g0) / layer
    within = np.flatnonzero(away <= GAP_LAYER_CHANGE)
    last_within = int(within[-1]) if within.size else -1
    if n - 1 - last_within < max(1, int(LASTING_SHARE * n)):
        return None                                   # within half a layer at or near the end
    after = float(np.mean(g[last_within + 1:]))
    if abs(after - g0) <= GAP_LAYER_CHANGE * layer:
        return None
    near = np.flatnonzero(away[:last_within + 1] <= ONSET_LAYER)
    onset = int(near[-1]) + 1 if near.size else 0
    if onset < 1:
        return None                                   # changed from the start: nothing before
    return GapChange(index=onset, time=float(t[onset]), gap_before=g0, gap_after=after,
                     layer_spacing=layer, layers=(after - g0) / layer)
