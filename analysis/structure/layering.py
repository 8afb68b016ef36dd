"""The film's layers across the gap and the gap itself, from a trajectory (MDAnalysis):
:class:`DensityProfile` (its peaks: :func:`find_layers`) and :class:`FilmThickness`."""
from __future__ import annotations

import math

import numpy as np
from MDAnalysis.analysis.base import AnalysisBase
from scipy.signal import find_peaks

__all__ = ["DensityProfile", "FilmThickness", "find_layers"]


def find_layers(centers, density, *, min_spacing: float = 0.5,
                min_prominence: float = 0.1) -> dict:
    """Layers as peaks of a density profile.

    Parameters
    ----------
    centers, density : array_like
        Bin centres along z and the density there.
    min_spacing : float
        Smallest distance between two layers (length units).
    min_prominence : float
        Smallest peak prominence, as a fraction of the highest density.

    Returns
    -------
    dict
        ``count``, ``positions`` (z of each layer), ``spacing`` (mean
        distance between neighbouring layers, NaN for fewer than 2),
        ``spacing_std`` and ``edges`` (boundaries between layers: midpoints,
        with the outer ones half a spacing beyond the outer layers).
    """
    z = np.asarray(centers, float)
    rho = np.asarray(density, float)
    dz = float(z[1] - z[0]) if z.size > 1 else 1.0
    # pad with zeros so a layer in the first/last bin is still a peak
    padded = np.concatenate([[0.0], rho, [0.0]])
    peaks, _ = find_peaks(padded, prominence=min_prominence * max(rho.max(), 1e-300),
                          distance=max(1, int(round(min_spacing / dz))))
    pos = z[peaks - 1]
    gaps = np.diff(pos)
    spacing = float(gaps.mean()) if gaps.size else math.nan
    half = 0.5 * (spacing if gaps.size else min_spacing)
    edges = np.concatenate([[pos[0] - half] if pos.size else [],
                            0.5 * (pos[1:] + pos[:-1]),
                            [pos[-1] + half] if pos.size else []])
    return {"count": int(pos.size), "positions": pos, "spacing": spacing,
            "spacing_std": float(gaps.std(ddof=1)) if gaps.size > 1 else math.nan,
            "edges": edges}


class DensityProfile(AnalysisBase):
    """Number density of an atom group across the gap (along z).

    Parameters
    ----------
    atomgroup : AtomGroup
        The film atoms.
    bin_width : float
        Bin width along z.
    zrange : (float, float), optional
        Range of the profile; default: the group's z extent in the first
        analysed frame, widened by 1.
    min_spacing, min_prominence : float
        Passed to :func:`find_layers`.

    Attributes
    ----------
    results.bin_centers, results.density : ndarray
        Profile, number per volume averaged over the frames.
    results.layers : dict
        From :func:`find_layers` (count, positions, spacing, edges).

    Examples
    --------
    >>> u = mda.Universe("topology.data", "trajectory.dcd",
    ...                  atom_style="id type x y z")          # doctest: +SKIP
    >>> prof = DensityProfile(u.select_atoms("type 1")).run(step=10)  # doctest: +SKIP
    >>> prof.results.layers["count"]                           # doctest: +SKIP
    3
    """

    def __init__(self, atomgroup, bin_width: float = 0.05, zrange=None,
                 min_spacing: float = 0.5, min_prominence: float = 0.1, **kwargs):
        super().__init__(atomgroup.universe.trajectory, **kwargs)
        self._ag = atomgroup
        self._bin = bin_width
        self._zrange = zrange
        self._spacing = min_spacing
        self._prominence = min_prominence

    def _prepare(self):
        self._area_sum = 0.0
        if self._zrange is None:
            self._ag.universe.trajectory[self.start or 0]
            z = self._ag.positions[:, 2]
            self._zrange = (float(z.min()) - 1.0, float(z.max()) + 1.0)
        lo, hi = self._zrange
        n = max(1, int(math.ceil((hi - lo) / self._bin)))
        self._edges = np.linspace(lo, lo + n * self._bin, n + 1)
        self._counts = np.zeros(n)

    def _single_frame(self):
        z = self._ag.positions[:, 2]
        idx = np.floor((z - self._edges[0]) / self._bin).astype(np.int64)
        idx = idx[(idx >= 0) & (idx < self._counts.size)]
        self._counts += np.bincount(idx, minlength=self._counts.size)
        self._area_sum += float(
            self._ts.dimensions[0] * self._ts.dimensions[1])

    def _conclude(self):
        frames = max(self.n_frames, 1)
        area = self._area_sum / frames
        density = self._counts / frames / (area * self._bin)
        centers = 0.5 * (self._edges[1:] + self._edges[:-1])
        self.results.bin_edges = self._edges
        self.results.bin_centers = centers
        self.results.density = density
        self.results.layers = find_layers(centers, density, min_spacing=self._spacing,
                                          min_prominence=self._prominence)


class FilmThickness(AnalysisBase):
    """Gap between the facing planes of the two walls, per frame.

    The facing plane of each wall is found in the first analysed frame: its
    innermost atom and every atom reached from it in steps along z shorter
    than ``plane`` (atoms sorted by z; the step to the next plane, 0.9 σ in
    the default walls, is longer).  The set is kept for every frame; the gap
    is the difference of the planes' mean z.  Rigid walls' planes are flat;
    a flexible wall's atoms rattle about their plane, which this finds whole
    (the trace's ``gap`` column averages the same atoms).

    Parameters
    ----------
    bottom, top : AtomGroup
        Bottom and top wall atoms: every atom of each wall (for a
        filmfriction run, the types ``BOTTOM_WALL_TYPES`` and
        ``TOP_WALL_TYPES`` of :mod:`filmfriction.md_inputs.contract`).
    plane : float
        Largest z step between neighbouring atoms of one plane.

    Attributes
    ----------
    results.gap : ndarray, shape (n_frames,)
    results.frames : ndarray

    Examples
    --------
    >>> gap = FilmThickness(u.select_atoms("type 2 4"),
    ...                     u.select_atoms("type 3 5")).run()  # doctest: +SKIP
    >>> gap.results.gap.mean()                                # doctest: +SKIP
    """

    def __init__(self, bottom, top, plane: float = 0.3, **kwargs):
        super().__init__(bottom.universe.trajectory, **kwargs)
        self._bottom, self._top, self._plane = bottom, top, plane

    def _prepare(self):
        self._bottom.universe.trajectory[self.start or 0]
        self._bsel = self._bottom[_facing_plane(-self._bottom.positions[:, 2], self._plane)]
        self._tsel = self._top[_facing_plane(self._top.positions[:, 2], self._plane)]
        self._gap = np.full(self.n_frames, np.nan)

    def _single_frame(self):
        self._gap[self._frame_index] = (self._tsel.positions[:, 2].mean()
                                        - self._bsel.positions[:, 2].mean())

    def _conclude(self):
        self.results.gap = self._gap
        self.results.frames = np.asarray(self.frames)


def _facing_plane(depth, step: float) -> np.ndarray:
    """Indices of the plane nearest the film: from the smallest ``depth`` (the
    distance into the wall) up to the first gap between neighbours longer than ``step``."""
    order = np.argsort(depth, kind="stable")
    gaps = np.flatnonzero(np.diff(depth[order]) > step)
    return order[:gaps[0] + 1] if gaps.size else order
