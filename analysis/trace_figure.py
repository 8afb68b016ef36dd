"""A figure of a trace with its events: the spring force over time, each slip's
yield point y and re-stick point s marked, and (when the trace has it) the wall's
position below, axes labelled in the trace's units.

SI traces are drawn with an SI prefix chosen for the numbers (µN, ms, nm ...);
LJ traces in σ, ε/σ, τ.  Long traces are drawn from their envelope (the minimum
and maximum of each of a few thousand bins), which keeps every peak and drop.

Example
-------
>>> import numpy as np
>>> from filmfriction.analysis.files.trace import Trace, TraceParameters
>>> t = np.linspace(0.0, 1.0, 200)
>>> tr = Trace({"time": t, "spring_force": 1e-5 * (t % 0.25)}, TraceParameters(units="si"), None)
>>> fig = trace_figure(tr, [49, 99], [50, 100])
>>> [ax.get_ylabel() for ax in fig.axes], fig.axes[-1].get_xlabel()
(['spring force [µN]'], 'time [s]')
"""
from __future__ import annotations

import math

import numpy as np

from .files.trace import Trace, unit
from .files.util import png_bytes, pyplot, write_atomic

__all__ = ["trace_figure", "write_trace_figure", "scaled_unit"]

_PREFIXES = {-12: "p", -9: "n", -6: "µ", -3: "m", 0: "", 3: "k", 6: "M", 9: "G"}

# most bins drawn per curve: the envelope of a longer trace
_BINS = 4000


def scaled_unit(values, units: str, quantity: str) -> tuple[float, str]:
    """The factor to multiply ``values`` by and the label of the result: an SI prefix
    that brings the largest magnitude into [1, 1000) for SI units, none for LJ.

    >>> scaled_unit([2e-5, 9.7e-6], "si", "force")
    (1000000.0, 'µN')
    >>> scaled_unit([3.0], "lj", "force")
    (1.0, 'ε/σ')
    """
    label = unit(units, quantity)
    if units != "si" or label not in ("N", "m", "s", "J"):
        return 1.0, label
    big = float(np.nanmax(np.abs(np.asarray(values, dtype=float)))) if np.size(values) else 0.0
    if not math.isfinite(big) or big == 0.0:
        return 1.0, label
    power = int(min(max(3 * math.floor(math.log10(big) / 3), -12), 9))
    if label == "s" and power > 0:
        power = 0
    return 10.0 ** -power, _PREFIXES[power] + label


def _envelope(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At most 2 × ``_BINS`` points tracing the minimum and maximum of ``y`` per bin."""
    n = t.size
    if n <= 2 * _BINS:
        return t, y
    per = n // _BINS
    m = per * _BINS
    yb = y[:m].reshape(_BINS, per)
    tb = t[:m].reshape(_BINS, per)
    lo, hi = yb.argmin(axis=1), yb.argmax(axis=1)
    rows = np.arange(_BINS)
    first = np.minimum(lo, hi)
    second = np.maximum(lo, hi)
    tt = np.column_stack([tb[rows, first], tb[rows, second]]).ravel()
    yy = np.column_stack([yb[rows, first], yb[rows, second]]).ravel()
    return np.append(tt, t[m:]), np.append(yy, y[m:])


def trace_figure(trace: Trace, yield_index, stick_index):
    """The trace's spring force with its slips' yield (▼) and re-stick (▲) points, and the
    wall's position below when the trace has it (or drive position and K to derive it).

    Parameters
    ----------
    trace : Trace
    yield_index, stick_index : sequence of int
        Sample indices of each slip's y and s (``analysis_cycles.csv``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    u = trace.units
    t, f = np.asarray(trace.time, float), np.asarray(trace.spring_force, float)
    yi = np.asarray(yield_index, dtype=int)
    si = np.asarray(stick_index, dtype=int)
    wall = trace.wall_position()
    panels = 2 if wall is not None else 1
    fig, axes = plt.subplots(panels, 1, figsize=(8.0, 3.2 + 2.0 * (panels - 1)), sharex=True,
                             squeeze=False, constrained_layout=True)
    axes = axes[:, 0]
    ts, t_label = scaled_unit(t, u, "time")
    fs, f_label = scaled_unit(f, u, "force")
    ax = axes[0]
    ax.plot(*_envelope(t * ts, f * fs), lw=0.8, color="0.25", label="spring force")
    if yi.size:
        ax.plot(t[yi] * ts, f[yi] * fs, "v", color="tab:red", ms=6, label=f"yield y ({yi.size})")
    if si.size:
        ax.plot(t[si] * ts, f[si] * fs, "^", color="tab:blue", ms=6, label=f"re-stick s ({si.size})")
    ax.set_ylabel(f"spring force [{f_label}]")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False, fontsize=8)
    if wall is not None:
        ws, w_label = scaled_unit(wall, u, "length")
        axw = axes[1]
        axw.plot(*_envelope(t * ts, np.asarray(wall, float) * ws), lw=0.8, color="tab:green")
        for idx, marker, color in ((yi, "v", "tab:red"), (si, "^", "tab:blue")):
            if idx.size:
                axw.plot(t[idx] * ts, wall[idx] * ws, marker, color=color, ms=5)
        derived = "" if trace.has("wall_position") else "\n(drive − F/K)"
        axw.set_ylabel(f"wall position [{w_label}]{derived}")
    axes[-1].set_xlabel(f"time [{t_label}]")
    return fig


def write_trace_figure(trace: Trace, yield_index, stick_index, path):
    """Draw :func:`trace_figure` and write it as PNG to ``path`` (atomically)."""
    return write_atomic(path, png_bytes(trace_figure(trace, yield_index, stick_index)))
