"""Known answers: traces and films built from a model, and the analysis scored on them.

* :mod:`~filmfriction.analysis.groundtruth.synthetic` — sawtooth, Klein-law and spring-block
  traces, layered films and whole run directories whose answers are known;
* :mod:`~filmfriction.analysis.groundtruth.cases` — random spring-block cases, their exact
  truth read off the model, and the analysis' score on them (``benchmarks/validate.py``);
* :mod:`~filmfriction.analysis.groundtruth.calibration_sets` — the calibration's traces with
  known F_k and B, and the slip fit's score on them;
* :mod:`~filmfriction.analysis.groundtruth.slip_law_controls` — the slip-law verdict's
  positive and negative controls and its power;
* :mod:`~filmfriction.analysis.groundtruth.film_noise` — the film's random force of the
  controls, calibrated to the MD at each slider's scale;
* :mod:`~filmfriction.analysis.groundtruth.random_force` — a driven slider whose film's
  random force moves the wall (the controls' noise as an MD wall has it).

Nothing in the analysis imports this folder: it stands beside the estimators it checks.
"""
