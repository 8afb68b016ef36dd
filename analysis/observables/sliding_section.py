"""``sliding``: the last half of the trace as a sliding state.

The measurement is :mod:`filmfriction.analysis.sliding` (the analysis makes it
once, before every section: the regime rule needs it); this file writes it into
``analysis.json["sliding"]``: the time-averaged spring force over the last half
(block-average error), the wall's mean velocity there and its ratio to the
drive's.  A sweep reads friction against velocity from it.
"""
from __future__ import annotations

from ..sliding import sliding_state
from ..files.trace import Trace, unit
from ..files.util import finite_or_none
from .observable import Context, Observable, format_estimate, format_value, value

__all__ = ["Sliding", "sliding_section"]


def sliding_section(trace: Trace, state: dict | None = None) -> dict:
    """``analysis.json``'s ``sliding`` section for ``trace`` (``state``: its
    :func:`~filmfriction.analysis.sliding.sliding_state`, measured when not given)."""
    s = sliding_state(trace) if state is None else state
    lab = lambda q: unit(trace.units, q)  # noqa: E731
    return {"samples": "last half of the trace",
            "mean_force": value(s["mean_force"], s["mean_force_stderr"], lab("force")),
            "wall_velocity": value(s["wall_velocity"], None, lab("velocity")),
            "wall_velocity_ratio": finite_or_none(s["wall_velocity_ratio"])}


class Sliding(Observable):
    """The time-averaged friction and the wall's speed over the last half."""

    key = "sliding"
    title = "Time-averaged friction over the last half"
    order = 30
    table_header = ("last half of the trace", "value")

    def compute(self, ctx: Context) -> tuple[dict, dict]:
        return sliding_section(ctx.trace, ctx.sliding), {}

    def rows(self, section: dict) -> list[tuple[str, str]]:
        rows = [("time-averaged spring force", format_estimate(section.get("mean_force")))]
        if (section.get("wall_velocity") or {}).get("mean") is not None:
            rows.append(("wall's mean velocity", format_estimate(section["wall_velocity"])))
        if section.get("wall_velocity_ratio") is not None:
            rows.append(("wall's velocity / drive's",
                         format_value(section["wall_velocity_ratio"], 3)))
        return rows

    def notes(self, section: dict) -> list[str]:
        text = ("The spring force averaged over the last half of the run, stick and slip "
                "alike, is the friction a sweep plots against the drive velocity; it says "
                "nothing by itself of whether the wall slides steadily.")
        if section.get("wall_velocity_ratio") is not None:
            text += (" The wall's mean velocity over the drive's (above) tells: a ratio of 1 "
                     "within 20 % is steady sliding.")
        return [text]
