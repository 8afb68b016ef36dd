# Over 500 lines as one module: the film's structure from a trajectory, MDAnalysis-style
# analyses that share the layers (found once, here) and the trajectory's opening.
"""Structure of the confined film from a trajectory (MDAnalysis).

* :class:`DensityProfile` — number density across the gap, layer count and
  spacing (peaks of the profile);
* :class:`HexaticOrder` — in-plane bond-orientational order ψ6 of each layer
  per frame, to contrast stick (crystalline, |ψ6| high) with slip (shear
  melted, |ψ6| low);
* :class:`FilmThickness` — the gap between the walls' facing planes per
  frame (dilation at slip).

All follow MDAnalysis conventions: ``AnalysisBase`` subclasses, results in
``.results``, ``run(start, stop, step, verbose=True)`` with a progress bar.
Velocity profiles come from ``fix ave/chunk`` files (see
:mod:`filmfriction.analysis.analyze`), not from trajectories (DCD holds positions only).
Lengths are in the trajectory's units (σ for an LJ run).

Atom types of a filmfriction run are the script's contract
(:mod:`filmfriction.md_inputs.contract`): the film, and each wall as all of
its types (its rigid part and, with ``wall_model = flexible``, its mobile
planes facing the film).  The structure section of ``analysis.json`` is built
from these by :mod:`filmfriction.analysis.observables.structure_section`.
"""
from __future__ import annotations

import math

import numpy as np
from MDAnalysis.analysis.base import AnalysisBase
from scipy.signal import find_peaks
from scipy.spatial import cKDTree

__all__ = ["DensityProfile", "HexaticOrder", "LayerNeighbours", "psi6_per_layer",
           "FilmThickness", "find_layers",
           "frame_steps", "lammps_frame_interval", "open_trajectory", "select_types"]


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


class HexaticOrder(AnalysisBase):
    """In-plane hexatic order ψ6 of each film layer, per frame.

    Atoms are assigned to layers by z (``layer_edges``, e.g. from
    :class:`DensityProfile`).  In each layer, neighbours are the atoms closer
    in-plane than ``cutoff`` (periodic in x and y), and
    ψ6_j = (1/n_j) Σ_k exp(6iθ_jk).  The default cutoff, 1.37 a with
    a = (2/(√3 ρ₂))^½ the triangular-lattice spacing of the layer's areal
    density ρ₂, lies between the first (a) and second (√3 a) shells.  Per
    layer and frame: ``psi6`` = |⟨ψ6_j⟩| (orientational order of the layer as
    a whole: ≈ 1 crystal, ≈ 0 liquid) and ``psi6_local`` = ⟨|ψ6_j|⟩ over atoms
    with neighbours.  The same ψ6_j as ``freud.order.Hexatic(k=6)`` with
    ``neighbors={"r_max": cutoff}`` (tested).

    Neighbours come from a Verlet list (:class:`LayerNeighbours`): pairs
    within the cutoff plus a skin, found with ``scipy.spatial.cKDTree``
    (``boxsize``, periodic) and kept while no atom has moved half the skin
    and no atom has changed layer, so a film that holds its structure
    between frames (stick) is searched once, not every frame.  Exact either
    way: every pair within the cutoff is found in every frame.

    Parameters
    ----------
    atomgroup : AtomGroup
        The film atoms.
    layer_edges : array_like
        Boundaries along z; layer i is between edges[i] and edges[i+1].
    cutoff : float, optional
        In-plane neighbour distance (default: from each layer's density).

    Attributes
    ----------
    results.psi6, results.psi6_local : ndarray, shape (n_frames, n_layers)
    results.frames : ndarray
        Frame indices analysed.
    results.neighbour_searches : int
        Frames in which the neighbours were searched afresh (the rest reused
        the Verlet list).

    Examples
    --------
    >>> layers = DensityProfile(film).run().results.layers   # doctest: +SKIP
    >>> psi = HexaticOrder(film, layers["edges"]).run(verbose=True)  # doctest: +SKIP
    >>> psi.results.psi6.mean(axis=0)                         # doctest: +SKIP

    Frames are independent, so MDAnalysis's parallel backends split them
    between processes (each keeps its own Verlet list; the results are the
    same as a serial run's):

    >>> HexaticOrder(film, layers["edges"]).run(backend="multiprocessing",
    ...                                          n_workers=2, n_parts=8)  # doctest: +SKIP

    (several parts per process balance the load: a melted frame costs about
    four crystalline ones.)
    """

    _analysis_algorithm_is_parallelizable = True

    @classmethod
    def get_supported_backends(cls):
        return ("serial", "multiprocessing", "dask")

    def _get_aggregator(self):
        from MDAnalysis.analysis.results import ResultsGroup

        return ResultsGroup(lookup={"psi6": ResultsGroup.ndarray_vstack,
                                    "psi6_local": ResultsGroup.ndarray_vstack,
                                    "neighbour_searches": sum})

    def __init__(self, atomgroup, layer_edges, cutoff: float | None = None, **kwargs):
        super().__init__(atomgroup.universe.trajectory, **kwargs)
        self._ag = atomgroup
        self._edges = np.asarray(layer_edges, float)
        self._cutoff = cutoff

    def _prepare(self):
        n_layers = self._edges.size - 1
        # filled frame by frame in results: a parallel run merges the workers' results
        self.results.psi6 = np.full((self.n_frames, n_layers), np.nan)
        self.results.psi6_local = np.full((self.n_frames, n_layers), np.nan)
        self.results.neighbour_searches = 0
        self._neighbours = LayerNeighbours(n_layers, self._cutoff)

    def _single_frame(self):
        pos = self._ag.positions
        box = self._ts.dimensions[:2].astype(float)
        layer = np.searchsorted(self._edges, pos[:, 2]) - 1
        xy = np.mod(pos[:, :2].astype(float), box)
        xy[xy >= box] = 0.0           # guard the upper edge after rounding
        i, j, dx, dy = self._neighbours.pairs(xy, layer, box)
        psi, local = psi6_per_layer(i, j, dx, dy, layer, self._edges.size - 1)
        self.results.psi6[self._frame_index] = psi
        self.results.psi6_local[self._frame_index] = local
        self.results.neighbour_searches = self._neighbours.searches

    def _conclude(self):
        self.results.frames = np.asarray(self.frames)


def psi6_per_layer(i, j, dx, dy, layer, n_layers: int) -> tuple[np.ndarray, np.ndarray]:
    """|⟨ψ6_j⟩| and ⟨|ψ6_j|⟩ of each layer from its neighbour pairs.

    ``i``, ``j``: the atoms of each pair (each pair once), ``dx``, ``dy``: the
    in-plane vector from i to j, ``layer``: each atom's layer (pairs join atoms
    of one layer).  exp(6iθ) = (z/|z|)⁶ with z = dx + i dy, here as ((dx² − dy²) +
    i 2 dx dy)³ / r⁶, the same for both atoms of a pair (θ + π).  A layer
    with no pairs is NaN.
    """
    n = layer.size
    a, b = dx * dx - dy * dy, 2.0 * dx * dy       # z² = a + ib, |z²| = r²
    a2, b2 = a * a, b * b
    r6 = a2 + b2
    r6 *= np.sqrt(r6)
    re, im = a * (a2 - 3.0 * b2) / r6, b * (3.0 * a2 - b2) / r6
    ends = np.concatenate([i, j])
    count = np.bincount(ends, minlength=n)
    has = count > 0
    c = count[has]
    pre = np.bincount(ends, np.concatenate([re, re]), n)[has] / c
    pim = np.bincount(ends, np.concatenate([im, im]), n)[has] / c
    lh = layer[has]
    atoms = np.bincount(lh, minlength=n_layers)[:n_layers]
    with np.errstate(invalid="ignore", divide="ignore"):     # a layer without pairs: NaN
        mean_re = np.bincount(lh, pre, n_layers)[:n_layers] / atoms
        mean_im = np.bincount(lh, pim, n_layers)[:n_layers] / atoms
        local = np.bincount(lh, np.hypot(pre, pim), n_layers)[:n_layers] / atoms
    return np.hypot(mean_re, mean_im), local


class LayerNeighbours:
    """In-plane neighbour pairs within each layer, frame after frame (a Verlet list).

    The pairs within each layer's cutoff plus a skin (:attr:`SKIN` of the
    cutoff) are searched with ``scipy.spatial.cKDTree`` (periodic
    ``boxsize``), one tree per layer.  In a later frame the list is complete
    as long as the box and every atom's layer are unchanged and no atom has
    moved more than half the skin (minimum image), so only its pairs' lengths
    are checked (each pair's vector is its vector at the search plus the two
    atoms' moves since).  When a list is discarded without ever having been reused
    (the film moves fast: slip, a liquid), the next :attr:`PLAIN_FRAMES`
    searches use no skin, which finds fewer pairs.

    Parameters
    ----------
    n_layers : int
        Layers 0 … n_layers − 1 (atoms of any other index are outside the film).
    cutoff : float, optional
        The neighbour distance; default 1.37 a from each layer's areal density.
    """

    SKIN = 0.5
    PLAIN_FRAMES = 10

    def __init__(self, n_layers: int, cutoff: float | None = None):
        self.n_layers = n_layers
        self.cutoff = cutoff
        self.searches = 0
        # at the search: i, j, dx, dy, cutoff² of each pair, skin, xy, layer, box
        self._list = None
        self._reused = 0
        self._plain = 0

    def cutoffs(self, layer, box) -> np.ndarray:
        """The neighbour distance of each layer (inf for a layer of fewer than 3 atoms)."""
        n = np.bincount(layer[(layer >= 0) & (layer < self.n_layers)],
                        minlength=self.n_layers)
        if self.cutoff is not None:
            rc = np.full(self.n_layers, float(self.cutoff))
        else:
            with np.errstate(divide="ignore"):
                rc = 1.37 * np.sqrt(2.0 * box[0] * box[1] / (math.sqrt(3.0) * n))
        rc[n < 3] = np.inf                   # too few atoms for an order: no pairs
        return rc

    def pairs(self, xy, layer, box):
        """``(i, j, dx, dy)``: every pair of atoms of one layer closer than its cutoff
        (each pair once), with the minimum-image vector (dx, dy) from i to j."""
        box = np.asarray(box, float)
        moved = self._moved(xy, layer, box)
        if moved is None:
            self._search(xy, layer, box)
        i, j, dx, dy, rc2, skin = self._list[:6]
        if moved is None and skin == 0:
            return i, j, dx, dy                   # searched at the cutoff itself
        if moved is not None:                     # each atom's move since the search
            mx, my = moved[:, 0], moved[:, 1]
            dx = dx + (mx.take(j) - mx.take(i))
            dy = dy + (my.take(j) - my.take(i))
        near = np.flatnonzero(dx * dx + dy * dy < rc2)
        return i.take(near), j.take(near), dx.take(near), dy.take(near)

    def _moved(self, xy, layer, box):
        """Each atom's move (minimum image) since the list's search if the list still
        holds every pair within the cutoff, else None."""
        if self._list is None:
            return None
        skin, xy0, layer0, box0 = self._list[5:]
        if skin > 0 and np.array_equal(box, box0) and np.array_equal(layer, layer0):
            moved = xy - xy0
            moved -= box * np.round(moved / box)
            if np.einsum("ij,ij->i", moved, moved).max(initial=0.0) < (0.5 * skin) ** 2:
                self._reused += 1
                return moved
        if skin > 0 and self._reused == 0:
            self._plain = self.PLAIN_FRAMES          # a list that was never reused
        return None

    def _search(self, xy, layer, box):
        rc = self.cutoffs(layer, box)
        finite = rc[np.isfinite(rc)]
        skin = self.SKIN * finite.min() if finite.size and self._plain == 0 else 0.0
        self._plain = max(0, self._plain - 1)
        order = np.argsort(layer, kind="stable")
        bounds = np.searchsorted(layer[order], np.arange(self.n_layers + 1))
        found_i, found_j = [np.empty(0, np.intp)], [np.empty(0, np.intp)]
        for k in range(self.n_layers):
            members = order[bounds[k]:bounds[k + 1]]
            if not np.isfinite(rc[k]):
                continue
            # leaves of 8 points: ~7 % more frames/s than scipy's 16 on a 2288-atom film
            tree = cKDTree(xy[members], boxsize=box, balanced_tree=False, compact_nodes=False,
                           leafsize=8)
            pairs = tree.query_pairs(rc[k] + skin, output_type="ndarray")
            found_i.append(members.take(pairs[:, 0]))
            found_j.append(members.take(pairs[:, 1]))
        i, j = np.concatenate(found_i), np.concatenate(found_j)
        x, y = xy[:, 0].copy(), xy[:, 1].copy()
        dx, dy = x.take(j) - x.take(i), y.take(j) - y.take(i)
        dx -= box[0] * np.round(dx / box[0])        # minimum image
        dy -= box[1] * np.round(dy / box[1])
        self._list = (i, j, dx, dy, rc.take(layer.take(i)) ** 2, skin,
                      xy.copy(), layer.copy(), box.copy())
        self._reused = 0
        self.searches += 1


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


def select_types(universe, types):
    return universe.select_atoms("type " + " ".join(str(int(t)) for t in types))


def frame_steps(universe) -> np.ndarray | None:
    """MD step of each frame of a DCD trajectory (istart + i·nsavc), or None."""
    header = getattr(getattr(universe.trajectory, "_file", None), "header", None)
    if not header or not header.get("nsavc"):
        return None
    n = universe.trajectory.n_frames
    return header["istart"] + header["nsavc"] * np.arange(n)


def lammps_frame_interval(trajectory) -> float | None:
    """Time between frames of a DCD that LAMMPS wrote, in the run's units (τ in LJ), or None.

    LAMMPS writes its own timestep, unconverted, as the DCD header's float32
    ``delta`` and the dump interval as ``nsavc``; MDAnalysis reads ``delta`` as
    CHARMM's AKMA time unit (48.9 fs) and so reports a wrong time.  The
    interval is nsavc × the timestep, the timestep being the shortest
    decimal that rounds to ``delta`` in float32 (0.005, not 0.004999999888).
    """
    import struct

    with open(trajectory, "rb") as f:
        head = f.read(100)
    if len(head) < 48 or head[4:8] != b"CORD":
        return None
    order = "<" if struct.unpack("<i", head[:4])[0] == 84 else ">"
    nsavc = struct.unpack(order + "i", head[16:20])[0]      # CORD, NSET, ISTART, NSAVC
    delta = struct.unpack(order + "f", head[44:48])[0]
    if nsavc <= 0 or not delta > 0:
        return None
    return nsavc * float(str(np.float32(delta)))


def open_trajectory(topology, trajectory, dt: float | None = None):
    """A filmfriction run's trajectory as an MDAnalysis ``Universe``, with times in τ.

    ``dt``: the time between frames (dump_every × timestep); default from
    the DCD header (:func:`lammps_frame_interval`).  ``u.trajectory.time`` is
    then step × timestep, the trace's ``time``; lengths are in σ (MDAnalysis
    labels them Å and times ps, but converts neither).

    For a user's own script the same is::

        mda.Universe("topology.data", "trajectory.dcd", atom_style="id type x y z",
                     dt=dump_every * timestep)
    """
    import warnings

    import MDAnalysis as mda

    if dt is None:
        dt = lammps_frame_interval(trajectory)
    with warnings.catch_warnings():      # DCDReader's 3.0 deprecation notice
        warnings.simplefilter("ignore", DeprecationWarning)
        return mda.Universe(str(topology), str(trajectory), format="DCD",
                            topology_format="DATA", atom_style="id type x y z",
                            **({"dt": dt} if dt else {}))


def film_layers(topology, trajectory, film_types, step: int = 1):
    """A run's trajectory opened (:func:`open_trajectory`), its film atoms (``film_types``)
    and their :class:`DensityProfile` over every ``step``-th frame: ``(universe, film,
    profile)``; ``profile.results.layers`` holds the layers and their ``edges``.

    Raises
    ------
    ValueError
        No atom of ``film_types`` in ``topology``.
    """
    u = open_trajectory(topology, trajectory)
    film = select_types(u, film_types)
    if film.n_atoms == 0:
        raise ValueError(f"no film atoms (type {' '.join(map(str, map(int, film_types)))}) "
                         f"in {topology}")
    return u, film, DensityProfile(film).run(step=step)
