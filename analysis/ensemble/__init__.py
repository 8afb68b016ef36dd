"""Many slips from many runs: replicas combined, and the rule that stops a run on a target error.

* :mod:`~filmfriction.analysis.ensemble.replicas` — per-slip values of independent runs
  (replicas, seeds) combined into one mean whose error includes the run-to-run scatter,
  with the within-run and between-run parts shown (:func:`combine_replicas`);
* :mod:`~filmfriction.analysis.ensemble.stopping` — when a run (or a set of replicas) has
  enough slips for a relative error asked for (:class:`TargetError`, :func:`check_target`),
  a sequential rule whose reported error covers the truth at its nominal rate.

Pure functions of numbers: nothing here reads a run directory.
"""
from .replicas import ReplicaEstimate, combine_replicas
from .stopping import TargetCheck, TargetError, check_target

__all__ = ["ReplicaEstimate", "combine_replicas", "TargetError", "TargetCheck", "check_target"]
