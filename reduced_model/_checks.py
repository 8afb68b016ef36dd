"""Input checks shared by the reduced models.

Every check raises ``ValueError`` *before* any computation, naming the
parameter, the value received, the allowed range and why the range exists,
so that a bad sweep fails at once instead of hanging or returning nonsense.
"""
from __future__ import annotations

import math

__all__ = ["finite", "positive", "non_negative", "at_least", "in_range", "SimulationLimitError"]


class SimulationLimitError(RuntimeError):
    """A run hit a safety cap (event count, step count) instead of finishing.

    Raised rather than hanging: the message says which cap, and what to change.
    """


def finite(name: str, value, why: str = "") -> float:
    """Return ``float(value)`` or raise if it is not a finite real number."""
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r}: must be a real number{_why(why)}") from None
    if not math.isfinite(out):
        raise ValueError(f"{name} = {value!r}: must be finite{_why(why)}")
    return out


def positive(name: str, value, why: str = "") -> float:
    """Return ``float(value)`` or raise unless 0 < value < inf."""
    out = finite(name, value, why)
    if out <= 0.0:
        raise ValueError(f"{name} = {value!r}: allowed range is (0, inf){_why(why)}")
    return out


def non_negative(name: str, value, why: str = "") -> float:
    """Return ``float(value)`` or raise unless 0 <= value < inf."""
    out = finite(name, value, why)
    if out < 0.0:
        raise ValueError(f"{name} = {value!r}: allowed range is [0, inf){_why(why)}")
    return out


def at_least(name: str, value, floor_name: str, floor: float, why: str = "") -> float:
    """Return ``float(value)`` or raise unless ``value >= floor`` (another parameter)."""
    out = finite(name, value, why)
    if out < floor:
        raise ValueError(f"{name} = {value!r}: allowed range is [{floor_name} = {floor}, inf)"
                         f"{_why(why)}")
    return out


def in_range(name: str, value, low: float, high: float, why: str = "",
             low_open: bool = False, high_open: bool = False) -> float:
    """Return ``float(value)`` or raise unless it lies in the given interval."""
    out = finite(name, value, why)
    bad_low = out <= low if low_open else out < low
    bad_high = out >= high if high_open else out > high
    if bad_low or bad_high:
        lb = "(" if low_open else "["
        hb = ")" if high_open else "]"
        raise ValueError(f"{name} = {value!r}: allowed range is {lb}{low}, {high}{hb}{_why(why)}")
    return out


def _why(why: str) -> str:
    return f" ({why})" if why else ""
