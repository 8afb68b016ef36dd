"""When has a run enough slips?  A relative error asked for, checked after each segment.

A run that stops as soon as its error *looks* small enough stops, more often than not,
when its slips happened to agree: the error it reports then is too small (optional
stopping).  On normal slips with a 10 % scatter, stopping at the first n ≥ 3 whose
s.e./mean ≤ 3 % covers the truth with ±1 s.e. 56 % of the time, not 68 %
(``tests/analysis/ensemble/test_ensemble.py`` measures it).  Two things make the rule honest here:

* a pilot of :attr:`TargetError.min_slips` slips (8 by default) before the first check,
  so that the scatter it judges by is not three numbers;
* the error it judges and reports is the 68 % half-width with Student's t (n − 1 degrees
  of freedom in one run, k − 1 over k replicas, :func:`~.replicas.combine_replicas`), not
  the bare standard error.

With both, a single run's reported error covered the truth 65-66 % of the time on normal
slips (10-20 % scatter, targets 3-5 %), against 54-61 % for the naive rule; over 2-4
replicas with a run-to-run scatter, 74-92 %: conservative, since two or three replica means
say little about that scatter (:mod:`.replicas`).  ``tests/analysis/ensemble/test_ensemble.py``
measures both.  The start-up slip is the caller's to leave out.

Examples
--------
>>> rule = TargetError("static_force", 0.05)
>>> check_target([[10.0, 10.4, 9.7]], rule).met       # too few slips to judge
False
>>> slips = [[10.0, 10.4, 9.7, 10.1, 9.9, 10.2, 9.8, 10.0, 10.3]]
>>> check = check_target(slips, rule)
>>> check.met, check.n_slips, round(check.relative_error, 3)
(True, 9, 0.008)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

from .replicas import ReplicaEstimate, combine_replicas

__all__ = ["TargetError", "TargetCheck", "check_target"]


@dataclass(frozen=True)
class TargetError:
    """A relative error asked for one observable.

    Attributes
    ----------
    observable : str
        The per-slip quantity (a column of the cycle table, e.g. ``static_force``).
    relative : float
        The 68 % half-width over |mean| asked for, e.g. 0.03 for ± 3 %; in (0, 1).
    min_slips : int
        Slips (over all replicas) before the first check, at least 3.
    """

    observable: str
    relative: float
    min_slips: int = 8

    def __post_init__(self):
        if not (isinstance(self.relative, (int, float)) and 0 < self.relative < 1):
            raise ValueError(f"target for {self.observable}: relative error {self.relative!r}; "
                             "accepted: a number between 0 and 1 (0.03 = ± 3 %)")
        if not (isinstance(self.min_slips, int) and self.min_slips >= 3):
            raise ValueError(f"target for {self.observable}: min_slips {self.min_slips!r}; "
                             "accepted: an integer >= 3")


@dataclass(frozen=True)
class TargetCheck:
    """One check of a :class:`TargetError` on the slips so far.

    Attributes
    ----------
    met : bool
        True when the relative error is at or below the target (after the pilot).
    relative_error : float
        The current 68 % half-width over |mean| (NaN before two slips).
    n_slips : int
        The slips the check saw, over all replicas.
    estimate : ReplicaEstimate
        The combined estimate it judged.
    reason : str
        Why it is met or not, in one line with the numbers.
    """

    met: bool
    relative_error: float
    n_slips: int
    estimate: ReplicaEstimate
    reason: str

    def as_dict(self) -> dict:
        return {"met": self.met, "relative_error": self.relative_error,
                "n_slips": self.n_slips, "reason": self.reason,
                "estimate": self.estimate.as_dict()}


def check_target(values: Sequence[Sequence[float]], target: TargetError) -> TargetCheck:
    """Check ``target`` on per-slip values (one sequence per replica).

    Parameters
    ----------
    values : sequence of sequences of float
        The observable's per-slip values of each replica, start-up slip left out.
    target : TargetError

    Returns
    -------
    TargetCheck
    """
    est = combine_replicas(values)
    rel = est.relative_error
    name, asked = target.observable, target.relative
    if est.n_slips < target.min_slips:
        return TargetCheck(False, rel, est.n_slips, est,
                           f"{name}: {est.n_slips} slip(s), the first check needs "
                           f"{target.min_slips}")
    if not math.isfinite(rel):
        return TargetCheck(False, rel, est.n_slips, est,
                           f"{name}: no finite relative error yet (mean {est.mean:.4g})")
    met = rel <= asked
    why = (f"{name}: ± {100 * rel:.2f} % over {est.n_slips} slip(s) in {est.n_replicas} "
           f"run(s) {'≤' if met else '>'} the target ± {100 * asked:.2f} %")
    if not met and math.isfinite(est.between) and est.between > est.within:
        why += (f"; the run-to-run scatter ({est.between:.3g}) exceeds the slips' noise "
                f"({est.within:.3g}): more runs, not more slips, lower it")
    return TargetCheck(met, rel, est.n_slips, est, why)
