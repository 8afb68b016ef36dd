"""The geometry of ``film_slide.lmp``: fcc(111) walls and a close-packed film, built with ASE.

:class:`ConfinedFilm` builds the whole system with ``ase.build.fcc111``: a
bottom wall, the film and a top wall, one ABC stacking running through all
three, and writes it as the LAMMPS data file the script reads
(``read_data``; ``ase.io``'s ``lammps-data`` writer, ``atom_style atomic``,
the five atom types of :mod:`filmfriction.md_inputs.contract`).  The runner
writes that file into each run directory; ``filmfriction geometry --out
geometry.data`` writes it for a run by hand.  :func:`fcc111` is one stack of
planes (the scene's atom counts, the synthetic films of the analysis tests).

Conventions (those of ``ase.build.fcc111(orthogonal=True)``): x along a
close-packed row, y across the rows, z normal to the planes.  A close-packed
plane of nearest-neighbour distance ``a`` in a box of ``cells_x`` x ``cells_y``
cells holds ``cells_x`` rows along x (Lx = cells_x a) and ``2 cells_y`` rows
along y (Ly = cells_y sqrt(3) a), so 2 cells_x cells_y atoms.  Planes are
sqrt(2/3) a apart; plane k of the stack is shifted in the plane by
(k mod 3) (a/2, a/(2 sqrt(3))) (A, B, C stacking).  Lengths are in σ: ASE's
length unit is read as σ, and the data file is written with ASE's ``metal``
units, which write lengths unconverted.

ASE is imported when atoms are first built, not with this module: the
counts and the box need no ASE.
"""
from __future__ import annotations

import io
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .contract import AtomType

__all__ = ["Fcc111", "fcc111", "plane_spacing", "fewest_wall_planes", "ConfinedFilm",
           "TYPE_SYMBOLS"]

SQRT3 = math.sqrt(3.0)
#: In-plane shift of every stack, in fractions of its cell: off the periodic
#: boundary, so that no row sits on it (a row there could be written on either side).
ORIGIN = (0.25, 0.125)
#: Chemical symbol standing for each atom type in the ASE atoms: atomic number = type,
#: which is also how ``ase.io.read(..., format="lammps-data")`` maps types back.
TYPE_SYMBOLS = ("H", "He", "Li", "Be", "B")
#: Room left between the film's top plane and the top wall's first plane beyond one
#: film plane spacing: the load settles the gap in the first steps [σ].
TOP_WALL_ROOM = 0.3


def plane_spacing(spacing: float) -> float:
    """Distance between neighbouring (111) planes of nearest-neighbour distance ``spacing``."""
    return math.sqrt(2.0 / 3.0) * spacing


def fewest_wall_planes(cutoff: float, spacing: float) -> int:
    """(111) planes a wall needs so that a film atom sees none of the wall's far side:
    enough to span the cutoff, plus one."""
    return math.ceil(cutoff / plane_spacing(spacing)) + 1


@dataclass(frozen=True)
class Fcc111:
    """A stack of close-packed (111) planes in an orthogonal periodic box.

    Build it with :func:`fcc111`.  :meth:`atoms` (an ``ase.Atoms``),
    ``positions`` and ``plane`` are built when first asked for; everything
    else is a number.
    """

    spacing: float                  # nearest-neighbour distance asked for [length]
    cells: tuple[int, int]          # (rows along x, row pairs along y)
    box: tuple[float, float]        # (Lx, Ly)
    planes: int
    z0: float = 0.0                 # z of the first plane
    stacking: int = 0               # stacking index (mod 3) of the first plane
    origin: tuple[float, float] = (0.0, 0.0)  # in-plane shift, in fractions of a cell
    turned: bool = False            # rows along y (a 90 degree turn, a 30 degree twist)

    @property
    def plane_spacing(self) -> float:
        return plane_spacing(self.spacing)

    @property
    def cell(self) -> tuple[float, float]:
        """In-plane cell (one row along x, one row pair along y), stretched to fit the box."""
        return self.box[0] / self.cells[0], self.box[1] / self.cells[1]

    @property
    def strain(self) -> tuple[float, float]:
        """In-plane strain of the lattice along x and y against ``spacing`` (0 unless fitted)."""
        if self.turned:
            return (self.box[0] / self.cells[1] / (SQRT3 * self.spacing) - 1.0,
                    self.box[1] / self.cells[0] / self.spacing - 1.0)
        return (self.box[0] / self.cells[0] / self.spacing - 1.0,
                self.box[1] / self.cells[1] / (SQRT3 * self.spacing) - 1.0)

    @property
    def atoms_per_plane(self) -> int:
        return 2 * self.cells[0] * self.cells[1]

    @property
    def n_atoms(self) -> int:
        return self.atoms_per_plane * self.planes

    @property
    def top(self) -> float:
        """z of the last plane."""
        return self.z0 + (self.planes - 1) * self.plane_spacing

    def atoms(self, symbol: str = "H"):
        """The stack as ``ase.Atoms`` (periodic in x and y), plane by plane from ``z0`` up.

        ``ase.build.fcc111`` builds the planes at the asked spacing; they are
        then shifted in the plane (``stacking``, ``origin``), stretched to the
        box and wrapped into it.
        """
        from ase import Atoms
        from ase.build import fcc111 as ase_fcc111

        cx, cy = self.cells
        if self.planes == 0:
            return Atoms(cell=[*self.box, 0.0], pbc=(True, True, False))
        a = self.spacing
        slab = ase_fcc111(symbol, size=(cx, 2 * cy, self.planes), a=a * math.sqrt(2.0),
                          orthogonal=True, periodic=True)
        # ase ends its slab on an A plane (its last plane has index 0), so its
        # first plane has index 1 - planes: move that to the asked stacking index
        k = (self.stacking - (1 - self.planes)) % 3
        slab.translate([(k * 0.5 + self.origin[0]) * a,
                        (k / 6.0 + self.origin[1]) * SQRT3 * a, self.z0])
        if self.turned:
            # x <-> y: a mirror through the diagonal, which for a close-packed
            # plane is its 90 degree turn (the plane is symmetric about its rows)
            slab.positions = slab.positions[:, [1, 0, 2]]
            slab.set_cell([slab.cell[1, 1], slab.cell[0, 0], slab.cell[2, 2]])
        # stretch the planes to the box (the film fits the walls' box)
        slab.set_cell([self.box[0], self.box[1], slab.cell[2, 2]], scale_atoms=True)
        slab.pbc = (True, True, False)
        slab.wrap()
        order = np.argsort(np.round((slab.positions[:, 2] - self.z0) / self.plane_spacing),
                           kind="stable")
        return slab[order]

    @cached_property
    def plane(self) -> np.ndarray:
        """Index of each atom's plane, 0 for the plane at ``z0``."""
        return np.repeat(np.arange(self.planes), self.atoms_per_plane)

    @cached_property
    def positions(self) -> np.ndarray:
        """(n_atoms, 3) positions, plane by plane from ``z0`` up, wrapped into the box."""
        pos = self.atoms().positions
        return pos if len(pos) else np.empty((0, 3))


def fcc111(spacing: float, cells: tuple[int, int] | None = None, planes: int = 1, *,
           fit: tuple[float, float] | None = None, z0: float = 0.0, stacking: int = 0,
           origin: tuple[float, float] = (0.0, 0.0), turned: bool = False) -> Fcc111:
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
        film is built).
    z0 : float
        z of the first plane.
    stacking : int
        Stacking index of the first plane: plane p takes the in-plane shift of
        index (stacking + p) mod 3, so a stack continued above another keeps
        one ABC sequence (the film starts at index ``wall_layers``).
    origin : (float, float)
        In-plane shift of every plane, in fractions of the cell
        (:class:`ConfinedFilm` uses :data:`ORIGIN`, off the periodic boundary).
    turned : bool
        The planes turned by 90 degrees about z, their close-packed rows along
        y (for a close-packed plane, whose rows repeat every 60 degrees, a
        30 degree twist: the farthest from alignment).  ``cells`` then counts
        atoms along a row (now along y) and row pairs along x: the box is
        ``(cells[1] * sqrt(3) * spacing, cells[0] * spacing)``.

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
    >>> turned = fcc111(1.1, planes=3, fit=wall.box, turned=True)
    >>> turned.cells, [round(e, 4) for e in turned.strain]
    ((7, 4), [0.0104, -0.0103])
    """
    if (cells is None) == (fit is None):
        raise ValueError("give either cells or fit")
    along, across = (1, 0) if turned else (0, 1)    # the box axes of rows and row pairs
    if fit is not None:
        lx, ly = float(fit[0]), float(fit[1])
        size = (lx, ly)
        cells = (max(1, round(size[along] / spacing)),
                 max(1, round(size[across] / (SQRT3 * spacing))))
    else:
        cells = (int(cells[0]), int(cells[1]))
        if min(cells) < 1:
            raise ValueError(f"cells {cells}: need at least one cell along x and y")
        size = [0.0, 0.0]
        size[along], size[across] = cells[0] * spacing, cells[1] * SQRT3 * spacing
        lx, ly = size
    if planes < 0:
        raise ValueError(f"planes {planes}: need 0 or more")
    return Fcc111(float(spacing), cells, (lx, ly), int(planes), float(z0), int(stacking),
                  (float(origin[0]), float(origin[1])), bool(turned))


@dataclass(frozen=True)
class ConfinedFilm:
    """The film between its two walls, as ``film_slide.lmp`` simulates it.

    Parameters
    ----------
    wall_spacing, film_spacing : float
        Nearest-neighbour distance in the walls' and the film's planes [σ].
    cells : (int, int)
        Wall rows along x and row pairs along y (the box).
    film_layers : int
        Close-packed film planes.
    wall_planes : int
        (111) planes per wall (:func:`fewest_wall_planes` for the fewest that
        span the cutoff).
    cutoff : float
        LJ cutoff [σ]: the room above the top wall.
    flexible_walls : bool
        Every wall plane but the outermost one of each wall is mobile (types
        ``BOTTOM_FLEXIBLE`` and ``TOP_FLEXIBLE``).
    top_wall_twisted : bool
        The top wall turned by 90 degrees about z (a 30 degree twist of its
        close-packed rows against the bottom wall's and the film's), its
        lattice stretched to the box (``fcc111(turned=True)``): the film is in
        registry with the bottom wall only.
    vacancy_fraction : float
        Fraction of the atoms of each wall's plane facing the film removed,
        at sites drawn at random (``fraction * atoms per plane`` to the
        nearest whole number, halves up, from each wall, without replacement).
    vacancy_seed : int
        Seed of the vacancies' draw (``numpy.random.default_rng``).

    Layout along z: the bottom wall's planes from z = 0 up; the film's first
    plane one film plane spacing above the bottom wall's last; the top wall's
    first plane one film plane spacing plus :data:`TOP_WALL_ROOM` above the
    film's last.  The box runs from half a wall plane spacing below the bottom
    wall to three wall plane spacings plus a cutoff above the top wall.

    Examples
    --------
    >>> g = ConfinedFilm(1.1, 1.1, (7, 4), film_layers=3, wall_planes=4, cutoff=2.5,
    ...                  flexible_walls=False)
    >>> g.film.n_atoms, g.bottom.n_atoms + g.top.n_atoms, len(g.atoms())
    (168, 448, 616)
    """

    wall_spacing: float
    film_spacing: float
    cells: tuple[int, int]
    film_layers: int
    wall_planes: int
    cutoff: float
    flexible_walls: bool
    top_wall_twisted: bool = False
    vacancy_fraction: float = 0.0
    vacancy_seed: int = 0

    @cached_property
    def bottom(self) -> Fcc111:
        return fcc111(self.wall_spacing, self.cells, self.wall_planes, origin=ORIGIN)

    @cached_property
    def film(self) -> Fcc111:
        # continues the stacking above the bottom wall, stretched to fit its box
        return fcc111(self.film_spacing, planes=self.film_layers, fit=self.bottom.box,
                      z0=self.bottom.top + plane_spacing(self.film_spacing),
                      stacking=self.wall_planes, origin=ORIGIN)

    @cached_property
    def top(self) -> Fcc111:
        z0 = self.film.top + self.film.plane_spacing + TOP_WALL_ROOM
        if self.top_wall_twisted:
            return fcc111(self.wall_spacing, planes=self.wall_planes, fit=self.bottom.box,
                          z0=z0, stacking=self.wall_planes + self.film_layers,
                          origin=ORIGIN, turned=True)
        return fcc111(self.wall_spacing, self.cells, self.wall_planes, z0=z0,
                      stacking=self.wall_planes + self.film_layers, origin=ORIGIN)

    @property
    def registry_period(self) -> float | None:
        """The period of the walls' registry along the slide (x) [σ]: the top wall's rows
        along x, in registry with the bottom wall's, repeat every ``wall_spacing``, and so
        does the force the film passes between them; None with the top wall twisted (its
        rows are not the bottom wall's)."""
        return None if self.top_wall_twisted else self.wall_spacing

    @property
    def vacancies_per_wall(self) -> tuple[int, int]:
        """Atoms taken out of the (bottom, top) wall's plane facing the film."""
        # the nearest whole number, halves up (as film_slide.lmp checks it)
        return (math.floor(self.vacancy_fraction * self.bottom.atoms_per_plane + 0.5),
                math.floor(self.vacancy_fraction * self.top.atoms_per_plane + 0.5))

    @property
    def box(self) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float]]:
        """((xlo, xhi), (ylo, yhi), (zlo, zhi))."""
        hw = self.bottom.plane_spacing
        return ((0.0, self.bottom.box[0]), (0.0, self.bottom.box[1]),
                (-0.5 * hw, self.top.top + 3.0 * hw + self.cutoff))

    def atoms(self):
        """Every atom as ``ase.Atoms``: bottom wall, film, top wall; atomic number = type.

        The cell has the box's lengths; positions are the simulation's, the
        bottom wall's first plane at z = 0, half a plane spacing above the
        box's ``zlo`` (an ``ase.Atoms`` cell starts at 0: :meth:`lammps_data`
        writes the box's own z bounds).
        """
        out = []
        rng = np.random.default_rng(self.vacancy_seed) if self.vacancy_fraction > 0 else None
        removed = dict(zip((0, 2), self.vacancies_per_wall))
        for i, (stack, rigid, mobile, outer, inner) in enumerate((
                (self.bottom, AtomType.BOTTOM_WALL, AtomType.BOTTOM_FLEXIBLE, 0,
                 self.wall_planes - 1),
                (self.film, AtomType.FILM, AtomType.FILM, None, None),
                (self.top, AtomType.TOP_WALL, AtomType.TOP_FLEXIBLE, self.wall_planes - 1,
                 0))):
            part = stack.atoms()
            kind = np.full(len(part), int(rigid))
            if self.flexible_walls and outer is not None:
                kind[stack.plane != outer] = int(mobile)
            part.numbers = kind
            if rng is not None and removed.get(i, 0) > 0:
                # vacancies in the plane facing the film
                sites = np.flatnonzero(stack.plane == inner)
                del part[rng.choice(sites, removed[i], replace=False)]
            out.append(part)
        system = out[0] + out[1] + out[2]
        (_, lx), (_, ly), (zlo, zhi) = self.box
        system.set_cell([lx, ly, zhi - zlo])
        system.pbc = (True, True, False)
        return system

    def lammps_data(self, title: str = "") -> str:
        """The LAMMPS data file (``atom_style atomic``, 5 atom types), as text.

        Written by ``ase.io`` (``lammps-data``); ASE puts every box's lower
        corner at 0, so the z bounds line is set to the box's own, and the
        first line (a comment for LAMMPS) says what the file holds.
        """
        from ase.io import write

        buf = io.StringIO()
        write(buf, self.atoms(), format="lammps-data", specorder=list(TYPE_SYMBOLS),
              atom_style="atomic", units="metal")
        lines = buf.getvalue().splitlines()
        (zlo, zhi) = self.box[2]
        for i, line in enumerate(lines):
            if line.endswith("zlo zhi"):
                lines[i] = f"{zlo!r} {zhi!r}  zlo zhi"
                break
        else:                                       # pragma: no cover - ase's format
            raise RuntimeError("ase wrote no 'zlo zhi' line")
        lines[0] = "# filmfriction " + (title or self.describe()) + " (written by ASE)"
        return "\n".join(lines) + "\n"

    def describe(self) -> str:
        """The parameters in one line (the data file's first line)."""
        return (f"film_slide geometry: wall_spacing={self.wall_spacing!r} "
                f"film_spacing={self.film_spacing!r} cells={self.cells[0]}x{self.cells[1]} "
                f"film_layers={self.film_layers} wall_planes={self.wall_planes} "
                f"cutoff={self.cutoff!r} walls={'flexible' if self.flexible_walls else 'rigid'}"
                + (" top_wall=twisted" if self.top_wall_twisted else "")
                + (f" vacancy_fraction={self.vacancy_fraction!r} vacancy_seed={self.vacancy_seed}"
                   if self.vacancy_fraction > 0 else ""))
