"""Which plane of the film slides: each layer's displacement along the slide, per frame
(:class:`LayerDisplacement`), and the plane that carries the wall's velocity
(:func:`active_plane`).

A solid-like film sheared between walls slides where its layers part: the planes are the
bottom wall | layer 1, layer 1 | layer 2, …, last layer | top wall.  A plane's velocity is
the difference of the mean x-velocities of the two sides (a wall's from its atoms, a layer's
from its atoms at that frame); the planes' velocities add up to the top wall's less the
bottom wall's.  Lengths in the trajectory's units (σ for an LJ run).
"""
from __future__ import annotations

import numpy as np
from MDAnalysis.analysis.base import AnalysisBase
from scipy.signal import savgol_filter

__all__ = ["LayerDisplacement", "active_plane"]


class LayerDisplacement(AnalysisBase):
    """Mean position along the slide (x) of each film layer and of both walls, per frame.

    Atoms are assigned to layers by their z in each frame (``layer_edges``, e.g. from
    :class:`~.layering.DensityProfile`); the trajectory must be unwrapped in x (a LAMMPS
    DCD written with ``dump_modify unwrap yes``, as filmfriction's runs write it), so that
    a layer's mean x follows its slide across the periodic box.

    Parameters
    ----------
    film, bottom, top : AtomGroup
        The film atoms and each wall's atoms.
    layer_edges : array_like
        Boundaries along z; layer i is between edges[i] and edges[i+1].

    Attributes
    ----------
    results.layer_x : ndarray, shape (n_frames, n_layers)
        Each layer's mean x (NaN in a frame with no atom in the layer).
    results.wall_x : ndarray, shape (n_frames, 2)
        The bottom and the top wall's mean x.
    results.frames : ndarray

    Examples
    --------
    >>> disp = LayerDisplacement(film, bottom, top, edges).run()   # doctest: +SKIP
    >>> x = np.column_stack([disp.results.wall_x[:, 0], disp.results.layer_x,
    ...                      disp.results.wall_x[:, 1]])           # doctest: +SKIP
    >>> plane, share = active_plane(x, dt=0.5, window=2.0)         # doctest: +SKIP
    """

    def __init__(self, film, bottom, top, layer_edges, **kwargs):
        super().__init__(film.universe.trajectory, **kwargs)
        self._film, self._bottom, self._top = film, bottom, top
        self._edges = np.asarray(layer_edges, float)
        if self._edges.ndim != 1 or self._edges.size < 2 or np.any(np.diff(self._edges) <= 0):
            raise ValueError(f"layer_edges = {layer_edges!r}: at least two increasing values")

    def _prepare(self):
        n = self._edges.size - 1
        self._x = np.full((self.n_frames, n), np.nan)
        self._walls = np.empty((self.n_frames, 2))

    def _single_frame(self):
        p = self._film.positions
        layer = np.searchsorted(self._edges, p[:, 2]) - 1
        n = self._edges.size - 1
        inside = (layer >= 0) & (layer < n)
        count = np.bincount(layer[inside], minlength=n)
        total = np.bincount(layer[inside], weights=p[inside, 0], minlength=n)
        with np.errstate(invalid="ignore", divide="ignore"):
            self._x[self._frame_index] = np.where(count > 0, total / count, np.nan)
        self._walls[self._frame_index] = (self._bottom.positions[:, 0].mean(),
                                          self._top.positions[:, 0].mean())

    def _conclude(self):
        self.results.layer_x = self._x
        self.results.wall_x = self._walls
        self.results.frames = np.asarray(self.frames)


def active_plane(x, dt: float, window: float) -> tuple[np.ndarray, np.ndarray]:
    """The plane that carries most of the slide at each frame, and its share.

    Parameters
    ----------
    x : array_like, shape (n_frames, n_bodies)
        Mean x of the bodies from the bottom wall to the top wall (the bottom wall, the
        layers in order, the top wall).
    dt : float
        Time between frames.
    window : float
        Savitzky–Golay window (order 2) over which the velocities are taken (time units):
        a plane's thermal rattle averages out over it.

    Returns
    -------
    plane : ndarray of int, shape (n_frames,)
        Index of the plane with the largest velocity (0: bottom wall | first layer).
    share : ndarray, shape (n_frames,)
        That plane's velocity over the sum of the planes' (the top wall's relative to the
        bottom's); NaN where that sum is 0.

    Examples
    --------
    Three bodies, the middle one moving with the bottom wall until t = 5, with the top
    wall after: the upper plane slides first, the lower one after.

    >>> t = np.arange(0, 10, 0.5)
    >>> mid = np.where(t < 5, 0.0, t - 5)
    >>> plane, share = active_plane(np.column_stack([0 * t, mid, t]), dt=0.5, window=1.5)
    >>> plane[:4].tolist(), plane[-4:].tolist(), float(share[0])
    ([1, 1, 1, 1], [0, 0, 0, 0], 1.0)
    """
    x = np.asarray(x, float)
    if x.ndim != 2 or x.shape[1] < 2 or x.shape[0] < 3:
        raise ValueError(f"x of shape {x.shape}: (frames >= 3, bodies >= 2)")
    if not (dt > 0 and window > 0):
        raise ValueError(f"dt = {dt!r}, window = {window!r}: each > 0")
    w = max(3, int(round(window / dt)) | 1)
    w = min(w, x.shape[0] - (1 - x.shape[0] % 2))
    v = savgol_filter(np.diff(x, axis=1), w, min(2, w - 1), deriv=1, delta=dt, axis=0)
    total = v.sum(axis=1)
    plane = np.argmax(v * np.sign(total)[:, None], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(total != 0, v[np.arange(v.shape[0]), plane] / total, np.nan)
    return plane, share
