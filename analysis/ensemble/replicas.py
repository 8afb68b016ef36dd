"""Independent runs of one scene (replicas, seeds) combined into one mean with an honest error.

One run's standard error, the scatter of its slips over √n, leaves out what differs from
run to run: the film's structure after equilibration, the registry it locks into, slips
that are correlated within a run.  Over six seeds of the default scene the run means of F_s
scatter by several times one run's standard error (docs/results/tradeoff.md).  Replicas
measure that scatter; :func:`combine_replicas` puts it in the error.

The model (random effects, the meta-analysis of independent studies): replica i's mean is
m_i = μ + b_i + e_i, with b_i the run's own offset (variance τ², *between* runs) and e_i its
slips' noise (variance σ²/n_i, *within* a run).  σ² is pooled over the replicas (the same
scene, the same per-slip noise; a run of 3 slips alone says little about it); τ² is the
DerSimonian-Laird moment estimate, never below zero.  The mean weights each replica by
1/(σ²/n_i + τ²).  Its standard error is the larger of two: the inverse total weight, and
Hartung and Knapp's weighted scatter of the replica means about the mean; the interval takes
Student's t with k − 1 degrees of freedom.  Hartung-Knapp alone is exact at a fixed number of
slips, but over 1 degree of freedom (two replicas) it is so noisy that a run stopped when it
dips (:mod:`.stopping`) covers the truth only half of the time.  The larger of the two
covered at least its nominal 68 % in every case measured, fixed or stopped, and more with
2-3 replicas (tests/analysis/ensemble/test_ensemble.py).  With one replica there is no between-run
part; the error is the within-run one and says so.

Examples
--------
>>> est = combine_replicas([[10.2, 9.8, 10.1, 9.9], [11.0, 11.2, 10.9, 11.1]])
>>> round(est.mean, 2), est.n_replicas, est.n_slips
(10.52, 2, 8)
>>> est.between > est.within          # the two runs differ by more than their slips' noise
True
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy import stats

__all__ = ["ReplicaEstimate", "combine_replicas", "ONE_SIGMA"]

#: the probability inside ±1 standard deviation of a normal variable
ONE_SIGMA = 0.6826894921370859


@dataclass(frozen=True)
class ReplicaEstimate:
    """One observable over independent runs.

    Attributes
    ----------
    mean : float
        The combined mean (random-effects weights).
    stderr : float
        Its standard error, within- and between-run scatter included.
    half_width : float
        Half the interval that holds the true mean with probability :data:`ONE_SIGMA`
        (``t_{dof} · stderr``); the honest "±" of a report.
    dof : int
        Degrees of freedom of that interval: k − 1 for k ≥ 2 replicas, n − 1 for one.
    within : float
        The error the slips' noise alone would give (√(1/Σ n_i/σ²)): what one pooled run
        would claim.
    between : float
        τ, the run-to-run standard deviation of the replica means beyond their slips'
        noise (NaN with one replica: not measured).
    n_replicas, n_slips : int
        Replicas with at least one finite value, and their values in all.
    replicas : tuple of (mean, stderr, n)
        Each replica's own mean, standard error (pooled σ over its √n) and count.
    note : str
        What the error includes, in words.
    """

    mean: float
    stderr: float
    half_width: float
    dof: int
    within: float
    between: float
    n_replicas: int
    n_slips: int
    replicas: tuple
    note: str

    @property
    def relative_error(self) -> float:
        """``half_width / |mean|`` (inf for a zero mean, NaN when undetermined)."""
        if not math.isfinite(self.half_width) or not math.isfinite(self.mean):
            return math.nan
        return self.half_width / abs(self.mean) if self.mean else math.inf

    def as_dict(self) -> dict:
        """JSON-ready (NaN stays NaN; the writer turns it into null)."""
        return {"mean": self.mean, "stderr": self.stderr, "half_width": self.half_width,
                "dof": self.dof, "within": self.within, "between": self.between,
                "n_replicas": self.n_replicas, "n_slips": self.n_slips,
                "replicas": [{"mean": m, "stderr": s, "n": n} for m, s, n in self.replicas],
                "note": self.note}


def _t(dof: int) -> float:
    return float(stats.t.ppf(0.5 + ONE_SIGMA / 2, dof)) if dof >= 1 else math.nan


def combine_replicas(values: Sequence[Sequence[float]]) -> ReplicaEstimate:
    """Combine per-slip values of independent runs (one sequence per run).

    Parameters
    ----------
    values : sequence of sequences of float
        Per-slip values of each replica (NaN and inf are left out; a replica with none
        is left out).

    Returns
    -------
    ReplicaEstimate
        NaN mean and errors when fewer than two values in all.
    """
    runs = [a[np.isfinite(a)] for a in (np.asarray(v, dtype=float).ravel() for v in values)]
    runs = [a for a in runs if a.size]
    n = np.array([a.size for a in runs], dtype=float)
    k, total = len(runs), int(n.sum())
    means = np.array([a.mean() for a in runs]) if k else np.array([])
    dof_within = int(np.sum(n - 1))
    if total < 2 or dof_within < 1 and k < 2:
        return ReplicaEstimate(float(means[0]) if k else math.nan, math.nan, math.nan, 0,
                               math.nan, math.nan, k, total,
                               tuple((float(m), math.nan, int(c)) for m, c in zip(means, n)),
                               "fewer than two values: no error")
    # σ² pooled over the replicas' own scatter (runs of one slip add no degree of freedom)
    sigma2 = (sum(float(((a - a.mean()) ** 2).sum()) for a in runs) / dof_within
              if dof_within else math.nan)
    if k == 1:
        se = math.sqrt(sigma2 / total)
        return ReplicaEstimate(float(means[0]), se, _t(total - 1) * se, total - 1, se,
                               math.nan, 1, total, ((float(means[0]), se, total),),
                               "one run: the error is its slips' scatter only; the "
                               "run-to-run scatter is not measured (use replicas)")
    v = sigma2 / n if math.isfinite(sigma2) else np.zeros(k)
    if not np.all(v > 0):          # runs of one slip each, or identical values: no σ²
        v = np.zeros(k)
    if np.all(v > 0):
        w = 1.0 / v
        fixed = float(np.sum(w * means) / w.sum())
        q = float(np.sum(w * (means - fixed) ** 2))
        tau2 = max(0.0, (q - (k - 1)) / float(w.sum() - np.sum(w ** 2) / w.sum()))
        within = math.sqrt(1.0 / float(w.sum()))
    else:
        tau2, within = float(np.var(means, ddof=1)), 0.0
    w_star = 1.0 / (v + tau2)
    mean = float(np.sum(w_star * means) / w_star.sum())
    se_spread = math.sqrt(float(np.sum(w_star * (means - mean) ** 2)) / ((k - 1) * w_star.sum()))
    se = max(math.sqrt(1.0 / float(w_star.sum())), se_spread)
    per_run = tuple((float(m), math.sqrt(vi), int(c)) for m, vi, c in zip(means, v, n))
    return ReplicaEstimate(mean, se, _t(k - 1) * se, k - 1, within, math.sqrt(tau2), k, total,
                           per_run, f"{k} runs: the error includes the run-to-run scatter "
                           f"(t with {k - 1} degree(s) of freedom)")
