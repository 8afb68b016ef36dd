"""Shear viscosity of a bulk liquid from LAMMPS's Green-Kubo output.

The MD side is ``md_inputs/viscosity_gk.lmp``: its production is cut into
blocks, each with its own autocorrelation of the off-diagonal pressure tensor
(``fix ave/correlate ... ave one``) and its own Green-Kubo integral
(LAMMPS's ``trap()``).  This module reads its two files and turns them into
η with a statistical error:

* ``gk.blocks`` (:func:`read_blocks`): one row per block; the block values
  of η are nearly independent samples, so η is their mean and the error is
  the standard error of that mean (:func:`green_kubo`);
* ``gk.correlate`` (:func:`read_correlate`): the autocorrelations
  themselves, from which :func:`running_integral` rebuilds η(t_c), the
  integral as a function of its upper limit, to show where it levels off.

Everything is in LJ units (η in ετ/σ³); nothing here converts.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.integrate import cumulative_trapezoid

__all__ = ["BLOCK_COLUMNS", "read_blocks", "CorrelationData", "read_correlate",
           "running_integral", "GreenKubo", "green_kubo"]

#: Columns of ``gk.blocks``, in order (see viscosity_gk.lmp).
BLOCK_COLUMNS = ("step", "temperature", "pressure", "potential_energy", "msd",
                 "eta_xy", "eta_xz", "eta_yz", "eta")


def read_blocks(path) -> dict[str, np.ndarray]:
    """The block table of ``gk.blocks`` as a dict of column arrays.

    Raises
    ------
    ValueError
        If the header does not name :data:`BLOCK_COLUMNS` or a row is short.
    """
    path = Path(path)
    lines = path.read_text().splitlines()
    if not lines or lines[0].lstrip("# ").split() != list(BLOCK_COLUMNS):
        raise ValueError(f"{path}: not a gk.blocks file (header should be "
                         f"'# {' '.join(BLOCK_COLUMNS)}')")
    rows = [l.split() for l in lines[1:] if l.strip() and not l.startswith("#")]
    if any(len(r) != len(BLOCK_COLUMNS) for r in rows):
        raise ValueError(f"{path}: a row does not have {len(BLOCK_COLUMNS)} columns")
    data = np.array(rows, dtype=float).reshape(len(rows), len(BLOCK_COLUMNS))
    return {name: data[:, i] for i, name in enumerate(BLOCK_COLUMNS)}


@dataclass(frozen=True, eq=False)
class CorrelationData:
    """The autocorrelations of ``gk.correlate``, one section per block.

    ``steps[b]`` is the step at which block b was written; ``delay`` the
    time delay of each row in steps; ``count[b, i]`` the number of pairs
    averaged into row i; ``values[b, i, k]`` the correlation of pair k
    (named in ``names``).
    """

    steps: np.ndarray
    delay: np.ndarray
    count: np.ndarray
    values: np.ndarray
    names: tuple[str, ...]


def read_correlate(path) -> CorrelationData:
    """Read a ``fix ave/correlate`` file.

    Sections whose longest delay has no samples (the one LAMMPS writes when
    the fix starts, at the production's step 0) are dropped: they are not
    blocks.
    """
    path = Path(path)
    names: tuple[str, ...] = ()
    sections: list[tuple[int, int, list[list[float]]]] = []   # step, rows declared, rows
    current: list[list[float]] | None = None
    for number, line in enumerate(path.read_text().splitlines(), 1):
        fields = line.split()
        if not fields:
            continue
        if fields[0] == "#":
            if len(fields) > 3 and fields[1] == "Index":
                names = tuple(fields[4:])
            continue
        if len(fields) == 2:                # a section header: step, rows
            current = []
            sections.append((int(fields[0]), int(fields[1]), current))
        elif current is None or len(fields) != 3 + len(names):
            raise ValueError(f"{path}:{number}: not a correlation row: {line!r}")
        else:
            current.append([float(x) for x in fields])
    if not names:
        raise ValueError(f"{path}: no '# Index TimeDelta Ncount ...' header")
    # a section cut short (a run stopped while writing) is not a block either
    complete = [(s, np.array(rows)) for s, n, rows in sections
                if rows and len(rows) == n and rows[-1][2] > 0]
    if not complete:
        raise ValueError(f"{path}: no complete correlation block")
    arr = np.stack([rows for _, rows in complete])
    return CorrelationData(steps=np.array([s for s, _ in complete]), delay=arr[0, :, 1],
                           count=arr[:, :, 2], values=arr[:, :, 3:], names=names)


def running_integral(corr: CorrelationData, *, volume: float, temperature,
                     timestep: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """η(t_c) = V/(k_B T) ∫_0^t_c ⟨P_ab(0) P_ab(t)⟩ dt, block by block.

    The components are averaged, each block is integrated with the
    trapezoidal rule (LAMMPS's ``trap()``, so the last point equals the
    block's value in ``gk.blocks``) and scaled by its own temperature.

    Parameters
    ----------
    corr : CorrelationData
        From :func:`read_correlate`.
    volume : float
        Box volume V.
    temperature : float or array_like
        k_B T, one value or one per block.
    timestep : float
        MD time step (the delays are in steps).

    Returns
    -------
    t, eta, eta_stderr : numpy.ndarray
        The delays in time units, the mean over blocks of η(t_c) and its
        standard error (NaN with one block).
    """
    temps = np.broadcast_to(np.asarray(temperature, float), (corr.values.shape[0],))
    t = corr.delay * timestep
    acf = corr.values.mean(axis=2)                       # (blocks, delays)
    per_block = cumulative_trapezoid(acf, t, axis=1, initial=0.0) * (volume / temps)[:, None]
    n = per_block.shape[0]
    err = per_block.std(axis=0, ddof=1) / math.sqrt(n) if n > 1 else np.full(t.shape, math.nan)
    return t, per_block.mean(axis=0), err


@dataclass(frozen=True, eq=False)
class GreenKubo:
    """η from independent blocks: the mean and its standard error.

    ``eta_blocks`` are the blocks' own values (the mean of the three
    components); ``components`` the mean of each component over blocks;
    ``diffusion`` D = slope(MSD)/6 over the production (NaN with fewer than
    two blocks), a check that the sample stayed liquid.
    """

    eta: float
    eta_stderr: float
    n_blocks: int
    eta_blocks: np.ndarray
    components: dict = field(default_factory=dict)
    temperature: float = math.nan
    temperature_stderr: float = math.nan
    pressure: float = math.nan
    pressure_stderr: float = math.nan
    diffusion: float = math.nan


def _mean_stderr(x: np.ndarray) -> tuple[float, float]:
    x = np.asarray(x, float)
    if x.size == 0:
        return math.nan, math.nan
    err = float(x.std(ddof=1) / math.sqrt(x.size)) if x.size > 1 else math.nan
    return float(x.mean()), err


def green_kubo(blocks: dict[str, np.ndarray], *, timestep: float) -> GreenKubo:
    """Combine the blocks of :func:`read_blocks` into η ± standard error.

    Each block's η is an independent estimate (the correlation restarts in
    every block and a block is many stress-relaxation times long), so the
    error is the standard error of their mean, std/√n.

    Parameters
    ----------
    blocks : dict
        Column arrays as returned by :func:`read_blocks`.
    timestep : float
        MD time step, for the diffusion coefficient (the steps are counted
        from the start of the production).
    """
    eta = np.asarray(blocks["eta"], float)
    if eta.size == 0:
        raise ValueError("no Green-Kubo block finished")
    mean, err = _mean_stderr(eta)
    comps = {name: _mean_stderr(blocks[f"eta_{name}"])[0] for name in ("xy", "xz", "yz")}
    t_mean, t_err = _mean_stderr(blocks["temperature"])
    p_mean, p_err = _mean_stderr(blocks["pressure"])
    diffusion = math.nan
    if eta.size > 1:
        time = np.asarray(blocks["step"], float) * timestep
        slope = np.polyfit(time, np.asarray(blocks["msd"], float), 1)[0]
        diffusion = float(slope / 6.0)
    return GreenKubo(eta=mean, eta_stderr=err, n_blocks=int(eta.size), eta_blocks=eta,
                     components=comps, temperature=t_mean, temperature_stderr=t_err,
                     pressure=p_mean, pressure_stderr=p_err, diffusion=diffusion)
