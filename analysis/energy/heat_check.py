"""The film's heat from the wall's mechanics against the thermostat's own tally.

Two independent measures of one heat (:mod:`filmfriction.analysis.energy.partition`'s
``film_heat`` and ``thermostat_heat_slip``, or per cycle ``film_heat_cycle`` and
``thermostat_heat_cycle``), tested slip by slip with Student's t: the check of the
energy partition that can fail.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["HeatComparison", "compare_heat"]


@dataclass(frozen=True)
class HeatComparison:
    """The film's heat from the mechanics against the thermostat's, slip by slip.

    Attributes
    ----------
    status : {"agree", "disagree", "undetermined"}
        ``disagree`` when the mean paired difference exceeds ``threshold``
        standard errors; ``undetermined`` with fewer than 3 pairs or no
        scatter to judge by.
    message : str
        One line saying so, with the numbers.
    film_heat, thermostat_heat : float
        Means over the ``n`` pairs (both finite).
    difference, stderr : float
        Mean of film − thermostat heat, pair by pair, and its standard error
        (the pairs' scatter: the film's thermal noise and the slips' spread).
    z : float
        difference / stderr.
    threshold : float
        The two-sided 99 % quantile of Student's t with n − 1 degrees of
        freedom: a correct film heat is flagged in 1 % of runs.
    resolution : float
        threshold × stderr / |film_heat|: the relative error of the film heat
        that the check flags in half of the runs (its power).

    Windows that share their ends (cycles y → next y) share the tally's
    fluctuation there, which cancels in the mean; the pairs' scatter then
    overstates its error, the check flags less often than 1 % and the
    resolution is an upper bound.
    """

    status: str
    message: str
    n: int
    film_heat: float
    thermostat_heat: float
    difference: float
    stderr: float
    z: float
    threshold: float
    resolution: float


def compare_heat(film_heat, thermostat_heat, *, skip: int = 0,
                 what: str = "per slip") -> HeatComparison:
    """Test the film's heat from the mechanics against the thermostat's tally.

    The two are independent measures of the same heat: ``film_heat`` from the
    wall's equation of motion (the trace's force and velocity), the
    thermostat's from the atoms (LAMMPS's ``fix langevin … tally yes``).
    They differ by the film's internal energy still to be removed at the end
    of the window, the engine's ledger residual and the quadrature of the
    sampled trace.

    Parameters
    ----------
    film_heat, thermostat_heat : array_like
        Per slip (or per cycle), the same windows; pairs with a NaN are dropped.
    skip : int
        Leading pairs left out (start-up slips).
    what : str
        Names the windows in the message.

    Returns
    -------
    HeatComparison

    Examples
    --------
    >>> c = compare_heat([10.2, 9.7, 10.4, 9.9], [10.0, 10.1, 10.3, 9.8])
    >>> c.status, abs(c.difference) < 1e-12
    ('agree', True)
    >>> compare_heat([13.0, 12.4, 13.2, 12.9], [10.0, 10.1, 10.3, 9.8]).status
    'disagree'
    """
    from scipy.stats import t as student_t

    a = np.asarray(film_heat, float)[skip:]
    b = np.asarray(thermostat_heat, float)[skip:]
    ok = np.isfinite(a) & np.isfinite(b)
    a, b = a[ok], b[ok]
    n = int(a.size)
    nan = math.nan
    if n < 3:
        return HeatComparison("undetermined", f"film heat vs thermostat heat {what}: {n} pair(s) "
                              "with both values, at least 3 needed", n,
                              float(a.mean()) if n else nan, float(b.mean()) if n else nan,
                              nan, nan, nan, nan, nan)
    d = a - b
    diff = float(d.mean())
    err = float(d.std(ddof=1) / math.sqrt(n))
    q = float(student_t.ppf(0.995, n - 1))
    fh, th = float(a.mean()), float(b.mean())
    if not err > 0:
        return HeatComparison("undetermined", f"film heat vs thermostat heat {what}: the "
                              "differences do not scatter, no error to judge by", n, fh, th,
                              diff, err, nan, q, nan)
    z = diff / err
    res = q * err / abs(fh) if fh else nan
    status = "agree" if abs(z) <= q else "disagree"
    msg = (f"film heat {fh:.4g} vs thermostat heat {th:.4g} {what} ({n} pairs): difference "
           f"{diff:.3g} ± {err:.2g} = {z:.2f} standard errors, limit {q:.2f} (99 %): {status}; "
           f"the check resolves a film-heat error of {100 * res:.0f} %")
    return HeatComparison(status, msg, n, fh, th, diff, err, z, q, res)
