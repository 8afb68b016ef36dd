"""The calibrated reduced model run over the MD trace, and its cycles beside the MD's.

:func:`replay` runs :class:`filmfriction.reduced_model.SpringBlock` with the
MD's K, M, V and mount dashpot d and the calibrated Coulomb + viscous film
(with the stuck film's shear stiffness, and the freeze velocity
:func:`filmfriction.reduced_model.integrators.closed_form.freeze_velocity_for` that re-sticks
it at the MD's F_b) from the MD's first re-stick, measures its cycles with the
same ruler as the MD's and returns the relative errors.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from filmfriction.reduced_model import SpringBlock, laws
from filmfriction.reduced_model.integrators.closed_form import freeze_velocity_for

from ..files.util import finite_or_none as _num
from .rundata import RunData

__all__ = ["Replay", "replay"]


@dataclass(frozen=True, eq=False)
class Replay:
    """The calibrated model run over the MD trace.

    Attributes
    ----------
    t, spring_force : numpy.ndarray
        The model's trace (MD time axis).
    start_time : float
        MD time at which the model starts (the MD's first re-stick, or 0).
    errors : dict
        ``{quantity: {"md", "md_stderr", "model", "rel_error"}}`` for
        ``peak_force``, ``slip_distance``, ``period`` (and ``backward_force``).
    model : str
        Description of the model run.
    """

    t: np.ndarray
    spring_force: np.ndarray
    start_time: float
    errors: dict
    model: str

    def as_dict(self) -> dict:
        return {"start_time": _num(self.start_time), "model": self.model,
                "errors": {k: {kk: _num(vv) for kk, vv in v.items()} for k, v in self.errors.items()}}


def no_restick_reason(run: RunData, kinetic_force: float, film_damping: float) -> str | None:
    """Why the calibrated block cannot come back to rest, if it cannot.

    With the mount's d, the slip is overdamped when B + d >= 2 sqrt(K M): the
    velocity then relaxes towards V without ever reaching zero, and with no
    kinetic force left to hold it the block slides on for good.  The MD film
    re-solidifies while the wall still moves; the model has no rule for that.
    """
    p = run.trace.parameters
    k, m = p.require("spring_constant"), p.require("mass")
    damping = film_damping + (p.mount_damping or 0.0)
    critical = 2.0 * math.sqrt(k * m)
    if damping < critical:
        return None
    return (f"the calibrated slip is overdamped (B + d = {damping:.3g} >= 2 sqrt(K M) = "
            f"{critical:.3g}, F_k = {kinetic_force:.3g}): the model's block never comes back to "
            "rest, so its replay has no cycles; the MD film re-solidifies while the wall still "
            "moves, and the Coulomb + viscous law has no re-stick rule for that (a freeze "
            "velocity would be the next model)")


def replay(run: RunData, static_force: float, kinetic_force: float, film_damping: float,
           restick_force: float | None = None, shear_stiffness: float = math.inf) -> Replay:
    """Run the calibrated :class:`filmfriction.reduced_model.SpringBlock` over the MD trace and compare cycles.

    With the MD's ``restick_force`` the law gets the freeze velocity that
    re-sticks it there (:func:`freeze_velocity_for`): a fitted, not a predicted,
    re-stick level, which an overdamped slip (:func:`no_restick_reason`) needs to stop
    at all.  ``shear_stiffness`` is the stuck film's k_f (inf: rigid).
    """
    tr = run.trace
    p = tr.parameters
    k, m = p.require("spring_constant"), p.require("mass")
    v = p.drive_velocity or 0.0
    d = p.mount_damping or 0.0
    t, f = tr.time, tr.spring_force
    if run.skip and run.n_slips > run.skip:
        i0 = int(run.cycles["stick_index"][run.skip - 1])
    else:
        i0 = 0
    t0 = float(t[i0])
    duration = float(t[-1] - t0)
    law = laws.Coulomb(static=static_force, kinetic=kinetic_force, viscous=film_damping,
                       shear_stiffness=shear_stiffness)
    block = SpringBlock(mass=m, stiffness=k, drive_velocity=v, damping=d, law=law)
    freeze = 0.0
    if restick_force is not None:
        freeze = freeze_velocity_for(block, static_force, restick_force)
        block = dataclasses.replace(block, law=dataclasses.replace(law, freeze_velocity=freeze))
    ext = min(float(f[i0]) / k, 0.999 * static_force / k)
    r = block.simulate(duration, initial_extension=ext)
    model_t = r.t + t0
    table = r.cycles()
    md = run.cycles
    sk = slice(run.skip, None)

    def stats(arr):
        a = np.asarray(arr, float)
        a = a[np.isfinite(a)]
        if a.size == 0:
            return math.nan, math.nan
        return float(a.mean()), (float(a.std(ddof=1) / math.sqrt(a.size)) if a.size > 1 else math.nan)

    errors = {}
    for name, col in (("peak_force", "static_force"), ("slip_distance", "slip_distance"),
                      ("period", "period"), ("backward_force", "backward_force")):
        md_mean, md_err = stats(np.asarray(md[col], float)[sk])
        model_mean, _ = stats(getattr(table, col))
        rel = (model_mean - md_mean) / abs(md_mean) if md_mean and math.isfinite(model_mean) else math.nan
        errors[name] = {"md": md_mean, "md_stderr": md_err, "model": model_mean, "rel_error": rel,
                        "model_cycles": float(len(table))}
    frz = f", freeze_velocity={freeze:.4g} (fitted to F_b)" if freeze else ""
    if math.isfinite(shear_stiffness):
        frz += f", shear_stiffness={shear_stiffness:.4g}"
    desc = (f"SpringBlock(M={m:g}, K={k:g}, V={v:g}, d={d:g}) with Coulomb(F_s={static_force:.4g}, "
            f"F_k={kinetic_force:.4g}, B={film_damping:.4g}{frz}), from t = {t0:g}")
    return Replay(model_t, r.spring_force, t0, errors, desc)
