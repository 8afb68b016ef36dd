"""The fcc(111) geometry that ``film_slide.lmp`` builds, in Python.

The script builds its walls and its film with LAMMPS's own ``lattice custom``
command: a 6-atom orthogonal cell of an ABC-stacked fcc(111) crystal, x along
a close-packed row, y across the rows, z normal to the planes.  The Python
that needs the same geometry (the scene's derived quantities, the synthetic
films of the analysis tests) calls :func:`fcc111`, and
``tests/test_md_contract.py`` checks it against the atoms a tiny LAMMPS run
of the script creates.

A close-packed plane of nearest-neighbour distance ``a`` in a box of
``cells_x`` x ``cells_y`` cells: ``cells_x`` rows along x (Lx = cells_x a),
``2 cells_y`` rows along y (Ly = cells_y sqrt(3) a), so 2 cells_x cells_y
atoms.  Planes are sqrt(2/3) a apart; plane k of the stack is shifted in the
plane by (k mod 3) (a/2, a/(2 sqrt(3))) (A, B, C stacking).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

__all__ = ["Fcc111", "fcc111", "plane_spacing"]

SQRT3 = math.sqrt(3.0)


def plane_spacing(spacing: float) -> float:
    """Distance between neighbouring (111) planes of nearest-neighbour distance ``spacing``."""
    return math.sqrt(2.0 / 3.0) * spacing


@dataclass(frozen=True)
class Fcc111:
    """A stack of close-packed (111) planes in an orthogonal periodic box.

    Build it with :func:`fcc111`.  ``positions`` and ``plane`` are computed
    when first asked for; everything else is a number.
    """

    spacing: float                  # nearest-neighbour distance asked for [length]
    cells: tuple[int, int]          # (rows along x, row pairs along y)
    box: tuple[float, float]        # (Lx, Ly)
    planes: int
    z0: float = 0.0                 # z of the first plane
    stacking: int = 0               # stacking index (mod 3) of the first plane
    origin: tuple[float, float] = (0.0, 0.0)  # in-plane shift, in fractions of a cell

    @property
    def plane_spacing(self) -> float:
        return plane_spacing(self.spacing)

    @property
    def cell(self) -> tuple[float, float]:
        """In-plane cell (one row along x, one row pair along y), stretched to fit the box."""
        return self.box[0] / self.cells[0], self.box[1] / self.cells[1]

    @property
    def strain(self) -> tuple[float, float]:
        """In-plane strain of the rows along x and y against ``spacing`` (0 unless fitted)."""
        return (self.box[0] / self.cells[0] / self.spacing - 1.0,
                self.box[1] / self.cells[1] / (SQRT3 * self.spacing) - 1.0)

    @property
    def atoms_per_plane(self) -> int:
        return 2 * self.cells[0] * self.cells[1]

    @property
    def n_atoms(self) -> int:
        return self.atoms_per_plane * self.planes

    @cached_property
    def plane(self) -> np.ndarray:
        """Index of each atom's plane, 0 for the plane at ``z0``."""
        return np.repeat(np.arange(self.planes), self.atoms_per_plane)

    @cached_property
    def positions(self) -> np.ndarray:
        """(n_atoms, 3) positions, plane by plane from ``z0`` up, wrapped into the box."""
        (cx, cy), (ax, ay) = self.cells, self.cell
        i, j = np.meshgrid(np.arange(cx), np.arange(2 * cy), indexing="ij")
        # row j of a plane: x offset by half a spacing on odd rows, rows ay/2 apart
        base = np.column_stack([(i + 0.5 * (j % 2) + self.origin[0]).ravel() * ax,
                                (0.5 * j + self.origin[1]).ravel() * ay])
        out = []
        for p in range(self.planes):
            k = (self.stacking + p) % 3
            xy = np.mod(base + k * np.array([0.5 * ax, ay / 6.0]), self.box)
            z = np.full((xy.shape[0], 1), self.z0 + p * self.plane_spacing)
            out.append(np.hstack([xy, z]))
        return np.vstack(out) if out else np.empty((0, 3))


def fcc111(spacing: float, cells: tuple[int, int] | None = None, planes: int = 1, *,
           fit: tuple[float, float] | None = None, z0: float = 0.0, stacking: int = 0,
           origin: tuple[float, float] = (0.0, 0.0)) -> Fcc111:
    """``planes`` close-packed fcc(111) planes of nearest-neighbour distance ``spacing``.

    Parameters
    ----------
    spacing : float
        Nearest-neighbour distance in a plane (the planes are
        ``sqrt(2/3) * spacing`` apart).
    cells : (int, int), optional
        Rows along x and row pairs along y: the box is
        ``(cells[0] * spacing, cells[1] * sqrt(3) * spacing)``.
    planes : int
        Number of planes.
    fit : (float, float), optional
        Instead of ``cells``: a box (Lx, Ly) to fill with the nearest whole
        number of rows, the lattice stretched to fit it exactly (as the
        script builds its film).
    z0 : float
        z of the first plane.
    stacking : int
        Stacking index of the first plane: plane p takes the in-plane shift of
        index (stacking + p) mod 3, so a stack continued above another keeps
        one ABC sequence (the script's film starts at index ``wall_layers``).
    origin : (float, float)
        In-plane shift of every plane, in fractions of the cell (the script's
        lattices use (0.25, 0.125), off the periodic boundary).

    Returns
    -------
    Fcc111

    Examples
    --------
    >>> wall = fcc111(1.1, (7, 4), planes=4)
    >>> wall.box, wall.atoms_per_plane, round(wall.plane_spacing, 6)
    ((7.700000000000001, 7.62102355330306), 56, 0.898146)
    >>> fcc111(1.1, planes=3, fit=wall.box).cells
    (7, 4)
    """
    if (cells is None) == (fit is None):
        raise ValueError("give either cells or fit")
    if fit is not None:
        lx, ly = float(fit[0]), float(fit[1])
        cells = (max(1, round(lx / spacing)), max(1, round(ly / (SQRT3 * spacing))))
    else:
        cells = (int(cells[0]), int(cells[1]))
        if min(cells) < 1:
            raise ValueError(f"cells {cells}: need at least one cell along x and y")
        lx, ly = cells[0] * spacing, cells[1] * SQRT3 * spacing
    if planes < 0:
        raise ValueError(f"planes {planes}: need 0 or more")
    return Fcc111(float(spacing), cells, (lx, ly), int(planes), float(z0), int(stacking),
                  (float(origin[0]), float(origin[1])))
