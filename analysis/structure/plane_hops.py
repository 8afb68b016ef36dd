"""Where a sliding film changes the plane it slides on, and what that costs in force.

A solid-like film slides on one interlayer plane at a time
(:func:`~filmfriction.analysis.structure.slip_planes.active_plane`); :func:`plane_changes`
finds where the sliding plane changes (a new plane that holds), and :func:`hop_force` asks
whether the film's force on the wall carries a feature there: the force less a smooth law
fitted on every slipping sample (F_k + B·v and, for aligned walls, two harmonics of their
registry period λ in the wall's position), averaged against the slide from the nearest
change, within ``near`` of it less its level ``wing`` away.  Two nulls draw the same number
of positions per slip: uniformly in the slip's slide (``random``), and each change moved by a
whole number of registry periods to where no change is near (``phase_matched``: the same
phase of the walls' lattice, no change of plane), so that a force of the registry that the
two harmonics leave, phase-locked with the changes, reads in that null as well.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["plane_changes", "NullBump", "HopForce", "hop_force"]


def plane_changes(plane, hold: int) -> list[int]:
    """Where ``plane`` (the sliding plane per frame) changes: the first frame of each new
    plane that then holds for ``hold`` frames in a row.

    Examples
    --------
    >>> plane_changes([1, 1, 2, 1, 1, 2, 2, 2, 0, 0, 0], hold=3)
    [5, 8]
    """
    hops, current, run_of, last = [], int(plane[0]), 0, None
    for i, p in enumerate(plane[1:], 1):
        if p == current:
            run_of, last = 0, None
            continue
        run_of = run_of + 1 if p == last else 1
        last = p
        if run_of >= hold:
            hops.append(i - hold + 1)
            current, run_of, last = int(p), 0, None
    return hops


@dataclass(frozen=True)
class NullBump:
    """The bump at positions drawn without regard to the changes: its mean and standard
    deviation over ``draws`` draws, and the share of draws at or above the changes' bump
    (the one-sided p-value of the changes' bump against this null)."""

    mean: float
    sd: float
    share_at_or_above: float
    draws: int


@dataclass(frozen=True)
class HopForce:
    """:func:`hop_force`'s result: the force bump at the changes of plane (force units),
    its standard error (jackknife over the slips, the smooth law refitted without each), the
    changes and slips it rests on, the smooth law's coefficients (F_k, B, then the
    harmonics' sin, cos pairs) and the nulls."""

    bump: float
    stderr: float
    changes: int
    slips: int
    law: tuple
    random: NullBump
    phase_matched: NullBump | None


def _basis(x, v, period):
    cols = [np.ones_like(v), v]
    if period:
        cols += [fn(2 * np.pi * h * x / period) for h in (1, 2) for fn in (np.sin, np.cos)]
    return np.column_stack(cols)


def _offsets(x, positions):
    """Each sample's slide from the nearest position (inf where there is none)."""
    if len(positions) == 0:
        return np.full(x.size, np.inf)
    d = x[:, None] - np.asarray(positions, float)[None, :]
    return d[np.arange(x.size), np.argmin(np.abs(d), axis=1)]


def _fit_law(bases, forces, normal, moment):
    """The smooth law least-squares fitted from the summed normal equations (``normal``,
    ``moment``): its coefficients and each slip's residual."""
    coef = np.linalg.lstsq(normal, moment, rcond=None)[0]
    return coef, [f - a @ coef for a, f in zip(bases, forces)]


def _bump(data, residual, positions, near, wing):
    """The residual within ``near`` of ``positions`` (per slip) less its mean in the wing."""
    centre, side = [], []
    for (x, *_), res, pos in zip(data, residual, positions):
        d = np.abs(_offsets(x, pos))
        centre.append(res[d < near])
        side.append(res[(d > wing[0]) & (d < wing[1])])
    centre, side = np.concatenate(centre), np.concatenate(side)
    return float(centre.mean() - side.mean()) if centre.size and side.size else np.nan


def hop_force(slips, *, registry_period: float | None, near: float = 0.1,
              wing: tuple = (0.3, 0.55), draws: int = 200, seed: int = 0) -> HopForce:
    """The film force's bump at the changes of its sliding plane, against two nulls.

    Parameters
    ----------
    slips : sequence of (x, force, velocity, changes)
        Per slip, the slipping samples' wall position, film force and wall velocity (1-D
        arrays of one length) and the wall positions of its changes of plane.
    registry_period : float or None
        λ of aligned walls (the law's two harmonics and the phase-matched null); None for
        walls out of registry (no harmonics, no phase-matched null).
    near, wing : float, (float, float)
        The bump is the residual within ``near`` of a change less its mean at
        ``wing[0]`` to ``wing[1]`` from it (lengths of the slide).
    draws, seed
        Null draws and the generator's seed.

    The standard error is the jackknife's over the slips (each left out in turn, the law
    refitted): on slips of known step with noise correlated within a slip it covers the
    step at the nominal rate (tests/analysis/structure/test_plane_hops.py).

    Examples
    --------
    A force that steps up by 5 within 0.1 σ of each change, on a linear law:

    >>> x = np.linspace(0, 6, 600); v = np.full(600, 0.2)
    >>> hops = [np.array([0.7, 2.2, 3.1, 4.9])] * 20
    >>> f = 10 + 5 * (np.abs(x[:, None] - hops[0]).min(axis=1) < 0.1)
    >>> r = hop_force([(x, f, v, h) for h in hops], registry_period=None, draws=20)
    >>> round(r.bump, 1), r.random.share_at_or_above
    (5.0, 0.0)
    """
    if registry_period is not None and not registry_period > 0:
        raise ValueError(f"registry_period = {registry_period!r}: > 0 or None")
    if not 0 < near < wing[0] < wing[1]:
        raise ValueError(f"near = {near!r}, wing = {wing!r}: 0 < near < wing[0] < wing[1]")
    data = []
    for x, f, v, h in slips:
        x, f, v = (np.asarray(a, float) for a in (x, f, v))
        if not (x.shape == f.shape == v.shape and x.ndim == 1):
            raise ValueError("each slip's x, force and velocity: 1-D arrays of one length")
        if x.size:
            data.append((x, f, v, np.asarray(h, float)))
    if len(data) < 2:
        raise ValueError(f"{len(data)} slips with samples: needs 2 or more")
    bases = [_basis(x, v, registry_period) for x, _, v, _ in data]
    forces = [d[1] for d in data]
    normals = np.array([a.T @ a for a in bases])
    moments = np.array([a.T @ f for a, f in zip(bases, forces)])
    normal, moment = normals.sum(0), moments.sum(0)
    coef, residual = _fit_law(bases, forces, normal, moment)

    def bump(positions):
        return _bump(data, residual, positions, near, wing)

    hops = [d[3] for d in data]
    observed = bump(hops)
    loo = []
    for i in range(len(data)):
        keep = [j for j in range(len(data)) if j != i]
        _, res = _fit_law([bases[j] for j in keep], [forces[j] for j in keep],
                          normal - normals[i], moment - moments[i])
        loo.append(_bump([data[j] for j in keep], res, [data[j][3] for j in keep], near, wing))
    # a slip whose removal leaves no sample near a change (or none in the wing) leaves the
    # jackknife undefined: no error then, rather than one over fewer slips
    loo = np.asarray(loo)
    stderr = (float(np.sqrt((loo.size - 1) / loo.size * np.sum((loo - loo.mean()) ** 2)))
              if np.all(np.isfinite(loo)) else np.nan)
    rng = np.random.default_rng(seed)

    def null(draw) -> NullBump:
        b = np.array([bump(draw()) for _ in range(draws)])
        b = b[np.isfinite(b)]
        return NullBump(float(b.mean()) if b.size else np.nan,
                        float(b.std(ddof=1)) if b.size > 1 else np.nan,
                        float(np.mean(b >= observed)) if b.size else np.nan, int(b.size))

    def uniform():
        return [rng.uniform(x.min(), x.max(), h.size) for x, _, _, h in data]

    def shifted():
        out = []
        for x, _, _, h in data:
            moved = []
            for c in h:
                for k in rng.permutation([-3, -2, -1, 1, 2, 3]):
                    p = c + k * registry_period
                    if x.min() < p < x.max() and np.all(np.abs(p - h) > wing[0]):
                        moved.append(p)
                        break
            out.append(np.array(moved))
        return out

    return HopForce(observed, stderr, int(sum(h.size for h in hops)),
                    len(data), tuple(float(c) for c in coef), null(uniform),
                    null(shifted) if registry_period else None)
