"""The result of the calibration's joint slip fit (:class:`SlipLawFit`, made by
:func:`filmfriction.analysis.calibration.slipfit.fit_slips`): F_k, B and the freeze force with
their errors, the fit's quality and its leave-one-slip-out cross-check."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .estimators import Estimate

__all__ = ["SlipLawFit"]


@dataclass(frozen=True, eq=False)
class SlipLawFit:
    """Joint fit of F_k, B and the freeze force F_f over the slips of one run.

    Attributes
    ----------
    kinetic_force, film_damping : Estimate
        Each with ``at_bound`` set (and no standard error) when the fit ended at
        the bound of its range: F_k = 0 (no rate-independent part), B = 0 (no film
        drag beyond the mount's dashpot).
    freeze_force : Estimate or None
        F_f; None where the slips end with the wall at rest (a freeze does not lower
        χ² by 25, i.e. 5 σ).
    freeze_note : str
        Why there is a freeze force or none.
    static_force : Estimate
        Spring force at the fitted yield instants (mean ± standard error).
    mount_damping : float
        d, fixed (not fitted).
    rms_residual : float
        RMS force residual of the joint fit.
    reduced_chi2 : float
        Residual variance per degree of freedom over the noise variance of the
        stick ramps between the windows (the trace's own noise): about 1 when the
        law describes the slips to the noise.
    n_slips : int
    jackknife : list of (float, float)
        (F_k, B) with each slip left out (≥ 3 slips), a cross-check of the error.
    windows : list of (int, int)
        (yield index, last index) of each slip fitted (its window starts on the
        ramp before the yield, see :func:`fit_slips`).
    yield_shifts : tuple of float
        Fitted yield instant minus the detected one, per slip (time units).
    scales : dict
        The force, time and damping units the fit ran in.
    error_method : str
        How the standard errors were obtained.
    success : bool
    message : str
        The optimiser's.
    """

    kinetic_force: Estimate
    film_damping: Estimate
    static_force: Estimate
    freeze_force: Estimate | None
    freeze_note: str
    mount_damping: float
    rms_residual: float
    reduced_chi2: float
    n_slips: int
    jackknife: list = field(default_factory=list)
    windows: list = field(default_factory=list)
    yield_shifts: tuple = ()
    scales: dict = field(default_factory=dict)
    error_method: str = ""
    success: bool = True
    message: str = ""

    @property
    def damping_at_bound(self) -> bool:
        """B ended at 0: no film drag beyond the mount's is resolved."""
        return self.film_damping.at_bound

    @property
    def jackknife_stderr(self) -> tuple[float, float]:
        """(F_k, B) standard errors from the leave-one-slip-out refits (NaN with fewer
        than 3): the slip-to-slip scatter, beside the fit's own errors."""
        arr = np.asarray(self.jackknife, float)
        if arr.ndim != 2 or arr.shape[0] < 3:
            return math.nan, math.nan
        n = arr.shape[0]
        err = np.sqrt((n - 1) / n * np.sum((arr - arr.mean(axis=0)) ** 2, axis=0))
        return float(err[0]), float(err[1])

    def as_dict(self) -> dict:
        from ..files.util import finite_or_none as num
        return {"kinetic_force": self.kinetic_force.as_dict(),
                "film_damping": self.film_damping.as_dict(),
                "freeze_force": None if self.freeze_force is None else self.freeze_force.as_dict(),
                "freeze_note": self.freeze_note,
                "rms_residual": num(self.rms_residual), "reduced_chi2": num(self.reduced_chi2),
                "n_slips": self.n_slips, "mount_damping": num(self.mount_damping),
                "error_method": self.error_method,
                "jackknife": [[num(a), num(b)] for a, b in self.jackknife],
                "jackknife_stderr": [num(x) for x in self.jackknife_stderr],
                "scales": {k: num(v) for k, v in self.scales.items()},
                "success": self.success, "message": self.message}
