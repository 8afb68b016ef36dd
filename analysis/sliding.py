"""The last half of a trace as a sliding state, and whether it is one.

:func:`sliding_state` measures the last half of a trace: the time-averaged
spring force (block-average error), the wall's mean velocity and its ratio to
the drive's, the force's trend.  :func:`not_sliding` says why such a state is
not steady sliding (the regime rule's last word on a trace with fewer than 2
slips).  The ``sliding`` section of ``analysis.json`` is the observable
:mod:`filmfriction.analysis.observables.sliding_section`.

Example
-------
>>> from filmfriction.analysis.groundtruth.synthetic import smooth_trace
>>> from filmfriction.analysis.files.trace import Trace, TraceParameters
>>> trace = Trace(smooth_trace(n=2000), TraceParameters(), path="smooth.csv")
>>> state = sliding_state(trace)
>>> round(state["mean_force"], 1), not_sliding(state) is None
(1.0, True)
"""
from __future__ import annotations

import math

import numpy as np

from . import stickslip, viscosity
from .files.trace import Trace

__all__ = ["last_half", "sliding_state", "not_sliding"]


def last_half(trace: Trace) -> slice:
    """The samples of the trace's last half."""
    return slice(len(trace) // 2, None)


def sliding_state(trace: Trace, half: slice | None = None) -> dict:
    """The last half of the trace (``half``) as a sliding state.

    Returns
    -------
    dict
        ``mean_force`` and ``mean_force_stderr`` (time-averaged spring force,
        block-average error), ``wall_velocity`` (slope of ``wall_position``,
        else mean of ``wall_velocity``, else None), ``wall_velocity_ratio`` (to
        the drive's, or None) and ``force_trend`` (the fitted line's change of
        the force over the half).
    """
    half = last_half(trace) if half is None else half
    t = np.asarray(trace.columns["time"], float)[half]
    f = np.asarray(trace.columns["spring_force"], float)[half]
    v_drive, _ = trace.drive_velocity()
    wall = None
    if trace.has("wall_position") and t.size > 2:
        wall = float(np.polyfit(t, np.asarray(trace.columns["wall_position"], float)[half], 1)[0])
    elif trace.has("wall_velocity") and t.size:
        wall = float(np.mean(np.asarray(trace.columns["wall_velocity"], float)[half]))
    mean, err = viscosity.block_mean(f)
    trend = float(np.polyfit(t, f, 1)[0]) * float(t[-1] - t[0]) if t.size > 2 else math.nan
    ratio = wall / v_drive if (wall is not None and v_drive) else None
    return {"mean_force": mean, "mean_force_stderr": err, "wall_velocity": wall,
            "wall_velocity_ratio": ratio, "force_trend": trend}


def not_sliding(state: dict) -> str | None:
    """Why a slip-free last half (:func:`sliding_state`) is not steady sliding, or None.

    No slips is not enough: a wall stuck for the whole run (V -> 0, a soft
    spring) has no slip either, and its ramping force over V/D would be a
    meaningless viscosity.  Steady sliding means the wall moves at the drive's
    velocity (within 20 %); without wall columns, the force has no trend
    (its change over the half is below 10 % of its mean).
    """
    if state["wall_velocity_ratio"] is not None:
        if not stickslip.sliding_steadily(state["wall_velocity_ratio"]):
            return (f"the wall moves at {state['wall_velocity_ratio']:.3g} × the drive's "
                    "velocity on average: it is not sliding steadily")
        return None
    if abs(state["force_trend"]) > 0.1 * abs(state["mean_force"]):
        return (f"the force changes by {state['force_trend']:.3g} over the last half (mean "
                f"{state['mean_force']:.3g}): not steady")
    return None
