"""Analysis of stick-slip traces and confined-film trajectories.

Modules (one sitting each):

* :mod:`filmfriction.analysis.stickslip` — yield/re-stick detection, cycle table, regime;
* :mod:`filmfriction.analysis.files.trace_reader` — reading run directories and CSV traces;
* :mod:`filmfriction.analysis.energy` — energy partition per slip (Klein), the heat check, MD ledger;
* :mod:`filmfriction.analysis.viscosity` — η_eff from steady sliding, velocity profiles,
  power-law fits across runs, and Klein's slip equation;
* :mod:`filmfriction.analysis.structure` — layers, hexatic order, gap (MDAnalysis);
* :mod:`filmfriction.analysis.analyze` — the ``analysis.json`` document;
* :mod:`filmfriction.analysis.observables` — sections of ``analysis.json`` and of the
  report declared one file each (Klein's slip law ...), with their contract;
* :mod:`filmfriction.analysis.groundtruth` — traces and films with known answers, the
  analysis scored on them, the slip-law verdict's controls;
* :mod:`filmfriction.analysis.calibration.calibrate` — the reduced model calibrated on MD runs
  (:func:`calibrate`), from :mod:`~filmfriction.analysis.calibration.rundata`,
  :mod:`~filmfriction.analysis.calibration.slipfit`, :mod:`~filmfriction.analysis.calibration.estimators`,
  :mod:`~filmfriction.analysis.calibration.replay` and :mod:`~filmfriction.analysis.calibration.md_estimates`.
"""

from .calibration.calibrate import Calibration, calibrate, load_run, write_calibration

if __name__ != "filmfriction.analysis":  # one name only: two would give two copies of every class
    raise ImportError(f"import filmfriction.analysis, not {__name__}")

__all__ = ["calibrate", "Calibration", "load_run", "write_calibration"]
