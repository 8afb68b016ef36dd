"""The cycle table of a stick-slip trace: one row per slip, in Klein's notation.

Static force Fs = K x0 at the yield point y, backward force Fb at the re-stick
point s, spring extension at yield x0, slip distance Δx0, slip duration τ_s
(y → s), stick duration (s → next y) and period τ_ss (y → next y).

One ruler for every trace: MD (LJ units), SFB (SI) and the reduced model's
exact events (:meth:`SimulationResult.cycles`) all tabulate their slips with
:func:`cycle_table`.  Reading and writing the table as CSV is
:mod:`filmfriction.analysis.files.cycles_csv`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

__all__ = ["CycleTable", "cycle_table", "stats", "CYCLE_COLUMNS"]

#: Per-slip columns of a :class:`CycleTable` besides the two index columns.
CYCLE_COLUMNS = ("yield_time", "stick_time", "static_force", "backward_force",
            "spring_extension", "slip_distance", "slip_duration",
            "stick_duration", "period")


def stats(values: np.ndarray) -> dict:
    """Mean, sample standard deviation, standard error and count of the finite values."""
    finite = values[np.isfinite(values)]
    n = int(finite.size)
    mean = float(finite.mean()) if n else math.nan
    std = float(finite.std(ddof=1)) if n > 1 else math.nan
    stderr = std / math.sqrt(n) if n > 1 else math.nan
    return {"mean": mean, "std": std, "stderr": stderr, "n": n}


@dataclass(frozen=True, eq=False)
class CycleTable:
    """Per-slip values of a stick-slip trace (one row per slip y → s).

    Attributes
    ----------
    yield_index, stick_index : ndarray of int
        Indices of the yield point y and re-stick point s in the trace.
    yield_time, stick_time : ndarray
        Times of y and s.
    static_force : ndarray
        Fs, spring force at y.
    backward_force : ndarray
        Fb, spring force at s.
    spring_extension : ndarray
        x0 = Fs / K (NaN without a spring constant).
    slip_distance : ndarray
        Δx0: wall displacement y → s when the wall position is known,
        else (Fs − Fb)/K (exact when the spring end does not move during the
        slip), else NaN.
    slip_duration : ndarray
        τ_s = t(s) − t(y).
    stick_duration : ndarray
        t(next y) − t(s); NaN for the last slip.
    period : ndarray
        τ_ss = t(next y) − t(y); NaN for the last slip.
    uncertainty : dict, optional
        Column name → (noise error, sampling error), per-slip arrays: what each
        slip's value may be off by (:func:`filmfriction.analysis.extrema.refine_extrema`);
        None for exact event samples.
    """

    yield_index: np.ndarray
    stick_index: np.ndarray
    yield_time: np.ndarray
    stick_time: np.ndarray
    static_force: np.ndarray
    backward_force: np.ndarray
    spring_extension: np.ndarray
    slip_distance: np.ndarray
    slip_duration: np.ndarray
    stick_duration: np.ndarray
    period: np.ndarray
    spring_constant: float | None = field(default=None)
    uncertainty: dict | None = field(default=None)

    def __len__(self) -> int:
        return int(self.yield_index.size)

    def __getitem__(self, rows) -> "CycleTable":
        """The table restricted to ``rows`` (a slice or index array); the
        per-slip values (period, stick duration) are kept as computed."""
        if isinstance(rows, (int, np.integer)):
            n = len(self)
            if not -n <= rows < n:  # ends iteration (`for row in table`) like a sequence
                raise IndexError(f"slip {rows} out of range for a table of {n} slips")
            rows = rows % n
            rows = slice(rows, rows + 1)
        names = ("yield_index", "stick_index") + CYCLE_COLUMNS
        unc = None if self.uncertainty is None else {
            n: (np.asarray(a)[rows], np.asarray(b)[rows]) for n, (a, b) in self.uncertainty.items()}
        return replace(self, **{n: np.asarray(getattr(self, n))[rows] for n in names},
                       uncertainty=unc)

    @property
    def count(self) -> int:
        """Number of slips."""
        return len(self)

    def summary(self, skip: int = 0) -> dict:
        """Mean, sample standard deviation, standard error and count of each
        per-cycle quantity, ignoring NaN.

        Parameters
        ----------
        skip : int
            Leave out the first ``skip`` slips (e.g. 1 to drop the start-up
            yield from a relaxed spring, which is larger than the rest).

        With per-slip errors (``uncertainty``) the standard error is the
        scatter's, s/√n, combined in quadrature with the mean sampling error
        (the same for every slip, it does not average out); for a single slip
        it is that slip's own error (noise and sampling).  ``resolution`` is the
        mean sampling error (0 without ``uncertainty``).

        Returns
        -------
        dict
            ``{name: {"mean", "std", "stderr", "n", "resolution"}}``.
        """
        out = {}
        for name in CYCLE_COLUMNS[2:]:
            values = np.asarray(getattr(self, name), float)[skip:]
            st = stats(values)
            st["resolution"] = 0.0
            if self.uncertainty and name in self.uncertainty:
                noise, res = (np.asarray(a, float)[skip:] for a in self.uncertainty[name])
                ok = np.isfinite(values) & np.isfinite(noise) & np.isfinite(res)
                if ok.any():
                    r = float(np.mean(res[ok]))
                    st["resolution"] = r
                    if st["n"] == 1:
                        st["stderr"] = float(math.hypot(noise[ok][0], res[ok][0]))
                    elif st["n"] > 1:
                        st["stderr"] = float(math.hypot(st["stderr"], r))
            out[name] = st
        return out

    def as_dict(self) -> dict:
        """Per-cycle columns as lists (JSON-ready; NaN stays NaN)."""
        out = {"yield_index": self.yield_index.tolist(),
               "stick_index": self.stick_index.tolist()}
        out.update({name: np.asarray(getattr(self, name), float).tolist()
                    for name in CYCLE_COLUMNS})
        return out


def cycle_table(time, spring_force, yield_index, stick_index, *,
                spring_constant=None, wall_position=None) -> CycleTable:
    """Tabulate stick-slip cycles from known yield and re-stick indices.

    Parameters
    ----------
    time, spring_force : array_like, shape (n,)
        The trace.
    yield_index, stick_index : array_like of int, shape (m,)
        Slip ``i`` runs from ``yield_index[i]`` (y) to ``stick_index[i]`` (s);
        both increasing, with ``yield_index[i] <= stick_index[i] <=
        yield_index[i+1]``.
    spring_constant : float, optional
        K; gives x0 = Fs/K and, without ``wall_position``, Δx0 = (Fs − Fb)/K.
    wall_position : array_like, shape (n,), optional
        Wall (slider) position; gives Δx0 = x(s) − x(y).

    Returns
    -------
    CycleTable

    Examples
    --------
    >>> t = np.arange(6.0); f = np.array([0, 1, 2, 0.5, 1.5, 2.5])
    >>> cycle_table(t, f, [2], [3], spring_constant=2.0).slip_distance
    array([0.75])
    """
    t = np.asarray(time, float)
    f = np.asarray(spring_force, float)
    if t.shape != f.shape or t.ndim != 1:
        raise ValueError(f"time and spring_force must be 1-D of equal length, "
                         f"got {t.shape} and {f.shape}")
    yi = np.asarray(yield_index, dtype=np.int64).ravel()
    si = np.asarray(stick_index, dtype=np.int64).ravel()
    if yi.shape != si.shape:
        raise ValueError(f"{yi.size} yield points but {si.size} re-stick points")
    if yi.size:
        if yi.min() < 0 or si.max() >= t.size:
            raise ValueError("yield/stick index outside the trace")
        if np.any(si < yi) or np.any(yi[1:] < si[:-1]):
            raise ValueError("yield and re-stick indices must alternate: "
                             "y[i] <= s[i] <= y[i+1]")
    fs, fb = f[yi], f[si]
    ty, ts = t[yi], t[si]
    nan = np.full(yi.size, math.nan)
    k = None if spring_constant is None else float(spring_constant)
    x0 = fs / k if k else nan.copy()
    if wall_position is not None:
        x = np.asarray(wall_position, float)
        if x.shape != t.shape:
            raise ValueError("wall_position must have the length of time")
        dx0 = x[si] - x[yi]
    elif k:
        dx0 = (fs - fb) / k
    else:
        dx0 = nan.copy()
    period = nan.copy()
    stick = nan.copy()
    if yi.size > 1:
        period[:-1] = np.diff(ty)
        stick[:-1] = ty[1:] - ts[:-1]
    arrays = dict(yield_index=yi, stick_index=si, yield_time=ty, stick_time=ts,
                  static_force=fs, backward_force=fb, spring_extension=x0,
                  slip_distance=dx0, slip_duration=ts - ty,
                  stick_duration=stick, period=period)
    for a in arrays.values():
        a.setflags(write=False)
    return CycleTable(**arrays, spring_constant=k)
