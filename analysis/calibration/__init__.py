"""The reduced model calibrated on MD runs (and on measured traces).

* :mod:`~filmfriction.analysis.calibration.calibrate` — :func:`calibrate`, per run and
  across runs, and ``calibration.json``;
* :mod:`~filmfriction.analysis.calibration.rundata` — one run directory, read;
* :mod:`~filmfriction.analysis.calibration.slipfit` — the slip's closed form and its fit;
* :mod:`~filmfriction.analysis.calibration.estimators` — F_s, F_b, ageing, k_f;
* :mod:`~filmfriction.analysis.calibration.replay` — the model over the MD trace;
* :mod:`~filmfriction.analysis.calibration.md_estimates` — the MD film for the SFB check;
* :mod:`~filmfriction.analysis.calibration.contact` — a run's sliding contact;
* :mod:`~filmfriction.analysis.calibration.measured` — a measured trace's slip.
"""
