"""Drive protocols: piecewise-constant spring-end velocities in one run.

A :class:`DriveSchedule` is a list of pieces ``(duration, velocity)``: velocity
steps, holds (velocity 0) and slide-hold-slide, the standard experiments of
rate-and-state friction and contact ageing.  ``SpringBlock.simulate(drive=...)``
runs the pieces one after the other with the block position, the spring
extension, the velocity and the friction state carried across each boundary,
so x is continuous and the spring end moves continuously (its velocity jumps).

Example
-------
>>> from filmfriction.reduced_model import DriveSchedule
>>> s = DriveSchedule.slide_hold_slide(velocity=1.0, slide=10.0, hold=100.0, reslide=10.0)
>>> s.duration, s.velocities
(120.0, (1.0, 0.0, 1.0))
>>> float(s.position(115.0))        # spring-end travel: 10 + 0 + 5
15.0
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["DriveSchedule"]


@dataclass(frozen=True)
class DriveSchedule:
    """Spring-end velocity ``velocities[k]`` for ``durations[k]``, piece after piece."""

    durations: tuple
    velocities: tuple

    def __post_init__(self):
        d = tuple(float(x) for x in self.durations)
        v = tuple(float(x) for x in self.velocities)
        if not d or len(d) != len(v):
            raise ValueError(f"DriveSchedule: {len(d)} durations and {len(v)} velocities; "
                             "need one velocity per piece and at least one piece")
        for k, (dk, vk) in enumerate(zip(d, v)):
            if not (math.isfinite(dk) and dk > 0.0):
                raise ValueError(f"DriveSchedule.durations[{k}] = {dk!r}: allowed range is (0, inf)")
            if not math.isfinite(vk):
                raise ValueError(f"DriveSchedule.velocities[{k}] = {vk!r}: must be finite")
        object.__setattr__(self, "durations", d)
        object.__setattr__(self, "velocities", v)

    # -- constructors ------------------------------------------------------------
    @classmethod
    def pieces(cls, pieces) -> "DriveSchedule":
        """From ``[(duration, velocity), ...]``."""
        pieces = list(pieces)
        return cls(tuple(p[0] for p in pieces), tuple(p[1] for p in pieces))

    @classmethod
    def velocity_step(cls, v_before: float, t_before: float, v_after: float,
                      t_after: float) -> "DriveSchedule":
        """Slide at ``v_before`` for ``t_before``, then at ``v_after`` for ``t_after``."""
        return cls((t_before, t_after), (v_before, v_after))

    @classmethod
    def slide_hold_slide(cls, velocity: float, slide: float, hold: float,
                         reslide: float) -> "DriveSchedule":
        """Slide at ``velocity`` for ``slide``, hold (spring end still) for ``hold``,
        slide again for ``reslide`` (all durations)."""
        return cls((slide, hold, reslide), (velocity, 0.0, velocity))

    @classmethod
    def coerce(cls, drive) -> "DriveSchedule":
        if isinstance(drive, DriveSchedule):
            return drive
        try:
            return cls.pieces(drive)
        except (TypeError, IndexError) as err:
            raise ValueError(f"drive = {drive!r}: expected a DriveSchedule or a list of "
                             "(duration, velocity) pairs") from err

    # -- what it describes -------------------------------------------------------
    @property
    def duration(self) -> float:
        return float(sum(self.durations))

    @property
    def boundaries(self) -> np.ndarray:
        """Start times of the pieces and the end: ``[0, d0, d0 + d1, ..., duration]``."""
        return np.concatenate(([0.0], np.cumsum(self.durations)))

    def velocity(self, t):
        """Spring-end velocity at ``t`` (the later piece at a boundary)."""
        k = np.clip(np.searchsorted(self.boundaries, t, side="right") - 1, 0, len(self.durations) - 1)
        return np.asarray(self.velocities)[k]

    def position(self, t):
        """Spring-end travel since t = 0."""
        b = self.boundaries
        travel = np.concatenate(([0.0], np.cumsum(np.asarray(self.durations) * self.velocities)))
        k = np.clip(np.searchsorted(b, t, side="right") - 1, 0, len(self.durations) - 1)
        return travel[k] + np.asarray(self.velocities)[k] * (np.asarray(t, float) - b[k])
