"""Fidelity presets: how much accuracy a run buys, chosen from the measured trade.

``preview``, ``standard`` and ``reference`` change only numerical knobs (time
step, run length, trace interval, lateral box) and never the physics of the
scene: when the box grows, the spring constant, the wall mass and the
start-up preload grow with the area so that the drive per area, hence the slip
distance and the period, stay the same; when the time step changes, step counts are rescaled so that
the simulated times stay the same.  The cutoff is part of the model (the film
yields at a different stress without the LJ attraction), so no preset
changes it.

The measured cost and error of each preset are in the README ("Fidelity
presets"), from ``filmfriction tradeoff`` (see ``workflows/cost/tradeoff.py``).

Example
-------
>>> from filmfriction.workflows.md.fidelity import preset
>>> preset("standard")
{}
>>> preset("preview")
{'slide_steps': 50000, 'equilibrate_steps': 5000}
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .scene import SceneError
from .scenes.parameters import PARAMETERS


@dataclass(frozen=True)
class Fidelity:
    """A preset, relative to the scene it is applied to.

    Attributes
    ----------
    name, summary : str
    timestep : float or None
        Time step [tau]; None keeps the scene's.  Step counts follow it.
    slide_factor : float
        Multiplies the simulated slide time (the number of slip cycles averaged).
    equilibrate_factor : float
        Multiplies the simulated equilibration time.
    trace_every_tau : float or None
        Trace interval [tau]; None keeps the scene's.
    area_factor : tuple of int
        Multiplies cells_x and cells_y; K, M and the preload force scale with
        the area.
    """

    name: str
    summary: str
    timestep: float | None = None
    slide_factor: float = 1.0
    equilibrate_factor: float = 1.0
    trace_every_tau: float | None = None
    area_factor: tuple = field(default=(1, 1))


# Chosen from the full study (README, "Speed and accuracy"): at the default
# step nothing measurable changed against half the step, while 0.0075 tau
# biased Fs (-5.3 +- 2.8) for only 20 % less cost, so no preset changes the
# step.  The run length sets the statistical error and the cost; the box is
# the one knob with a systematic trend at the default (slip, eta_eff).
PRESETS = {f.name: f for f in [
    Fidelity("preview", "a look in half the time: half the slide (about 4 slips) and half the "
             "equilibration at the default step; Fs, slip and period within their errors",
             slide_factor=0.5, equilibrate_factor=0.5),
    Fidelity("standard", "the shipped defaults: 500 tau of slide (8 cycles) at 0.005 tau"),
    Fidelity("reference", "convergence check: a box of 4 times the area (K and M scaled with "
             "it) and twice the slide, at the default step",
             slide_factor=2.0, area_factor=(2, 2)),
]}


def names() -> list[str]:
    return list(PRESETS)


def preset(name: str, base: dict | None = None) -> dict:
    """Scene overrides for the preset ``name``.

    Parameters
    ----------
    name : {"preview", "standard", "reference"}
    base : dict, optional
        The scene's resolved parameters (``Scene.parameters``) the preset is
        applied to; default: the parameter defaults (the ``stick-slip`` scene).

    Returns
    -------
    dict
        Overrides; apply them *under* the user's own ``--set`` values.

    Raises
    ------
    SceneError
        Unknown preset name.
    """
    if name not in PRESETS:
        raise SceneError(f"unknown fidelity {name!r}; known: {', '.join(PRESETS)}")
    f = PRESETS[name]
    p = {k: spec.default for k, spec in PARAMETERS.items()}
    p.update(base or {})
    out: dict = {}
    dt = f.timestep or p["timestep"]
    if f.timestep is not None and f.timestep != p["timestep"]:
        out["timestep"] = f.timestep
    ratio = p["timestep"] / dt

    def steps(key, factor):
        value = max(1, int(round(p[key] * ratio * factor)))
        if value != p[key]:
            out[key] = value

    steps("slide_steps", f.slide_factor)
    steps("equilibrate_steps", f.equilibrate_factor)
    if p["preload_steps"]:
        steps("preload_steps", 1.0)   # the ramp's time, not its steps, is the scene's
    if f.trace_every_tau is not None:
        every = max(1, int(round(f.trace_every_tau / dt)))
        if every != p["trace_every"]:
            out["trace_every"] = every
    elif ratio != 1.0:
        steps("trace_every", 1.0)
    if p["restart_every"] and ratio != 1.0:
        steps("restart_every", 1.0)
    if f.area_factor != (1, 1):
        ax, ay = f.area_factor
        out["cells_x"], out["cells_y"] = p["cells_x"] * ax, p["cells_y"] * ay
        out["spring_constant"] = p["spring_constant"] * ax * ay
        out["wall_mass"] = p["wall_mass"] * ax * ay
        if p["preload_force"] > 0.0:   # a force on the whole wall: per area it is the scene's
            out["preload_force"] = p["preload_force"] * ax * ay
    return out
