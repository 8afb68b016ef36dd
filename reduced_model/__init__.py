"""Reduced spring-block models of stick-slip friction.

A block on a spring with a friction law from the literature, integrated with
an exact stick phase (no regularisation), closed forms where they exist, an
energy ledger on every run, the Prandtl-Tomlinson model and stability maps;
and the SFB check, the model at the scale of Klein's surface-force-balance
experiment (:func:`sfb_check`, :mod:`filmfriction.reduced_model.sfb.check`).

Example
-------
>>> from filmfriction.reduced_model import SpringBlock, laws
>>> block = SpringBlock(mass=1.0, stiffness=1.0, drive_velocity=0.1, damping=0.0,
...                     law=laws.Coulomb(static=1.0, kinetic=0.5))
>>> result = block.simulate(duration=200.0)
>>> result.energy.closure < 1e-8
True
"""

if __name__ != "filmfriction.reduced_model":  # one name only: two would give two copies of every class
    raise ImportError(f"import filmfriction.reduced_model, not {__name__}")
from . import laws
from ._checks import SimulationLimitError
from .drive import DriveSchedule
from .sfb.klein import KLEIN, KleinExperiment
from .sfb.md_calibration import MDCalibration
from .result import EnergyLedger, Event, SimulationResult
from .sfb.check import SFBCheck, sfb_check, sfb_table
from .springblock import SpringBlock
from .tomlinson import PrandtlTomlinson

__all__ = ["SpringBlock", "DriveSchedule", "laws", "PrandtlTomlinson", "SimulationResult", "Event",
           "EnergyLedger", "SimulationLimitError", "sfb_check", "sfb_table", "SFBCheck",
           "MDCalibration", "KleinExperiment", "KLEIN"]
