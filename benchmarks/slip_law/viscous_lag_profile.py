"""The slip law pooled over runs with the film's viscous force lagging by τ_r: a profile over τ_r,
on MD runs or on controls of a known lag.

    python benchmarks/slip_law/viscous_lag_profile.py RUN… [--lags 0 5 10 …] [--no-registry]
    python benchmarks/slip_law/viscous_lag_profile.py --control SHARE TAU [--replicas 40]
        [--runs 10] [--slips 9] [--noise-scale 1.0] [--corrugation 20 1.1 -0.97]
        [--stop-velocity -0.0025] [--lags …] [--scale m1e4 --noise U RHO]
        [--loop LAW W D] [--slip-end force-minimum] [--registry-lag TAU_G]
        [--branching DF2 PHI2 W1 W2 DPHI] [--lag-distance D] [--lag-yield-exponent A]
    (either form) [--split velocity]

A film whose viscous force relaxes to B·v over τ_r (dψ/dt = (B·v − ψ)/τ_r, ψ = 0 at the
yield: the ``maxwell`` film of :mod:`filmfriction.analysis.groundtruth.random_force`) is
read by the plain pooled fit (B·v, τ_r = 0) with a negative co-moving mass, m_c ≈ −B·τ_r,
and its decelerating branch low.  With B's regressor ∫v_f dt at the film's own τ_r
(:func:`~filmfriction.analysis.slip_law.slip_law_pooled.fit_pooled_ensemble`,
``viscous_lag``) the one law carries no co-moving mass beyond the film's own: the τ_r where
the one law's m_c crosses zero estimates the lag (linear between the grid's points; its
error m_c's jackknife error over the slope dm_c/dτ_r there).  Per τ_r of ``--lags`` (τ):
the one law's F_k, B and m_c, the loop step, the rule's reading; then τ̂.

RUN…: the MD runs' directories (their slips analysed), pooled as ``filmfriction
slip-law RUN…`` pools them (the walls' registry force fitted where the runs record its
period; ``--no-registry``: the law alone).  ``--control SHARE TAU``: ``--replicas`` pools
of ``--runs`` runs of the heavy slider's Coulomb + viscous mix of viscous share SHARE whose
viscous force lags by TAU (0: no lag, the negative control) (``SCALES["stiff"]``, each run its own yield force and film as in
:mod:`~filmfriction.analysis.groundtruth.pooled_controls`), with the walls' registry force
of ``--corrugation`` (fitted at its period) and the noise beside it
(the scale's ``registry_noise``, :mod:`~filmfriction.analysis.groundtruth.film_noise`, times ``--noise-scale``), re-sticking at
``--stop-velocity`` (negative: once the wall recoils that fast, the MD-like end); printed:
``--scale m1e4`` (``m3e3``, ``m1e3``, ``m1e2``): the M = 10⁴ (3×10³, 10³, 10²) slider's scale
instead (``m25e3``: M = 2.5×10³; ``k16m3e3``, ``k4m3e3``: M = 3×10³ on K = 16, 4);
``--noise U RHO`` (u's rms and its correlation per sample) overrides the scale's noise;
``--registry-lag TAU_G``: the registry force
trailing the wall's position, relaxing over TAU_G (``lagged-registry``; TAU 0, no loop);
``--branching DF2 PHI2 W1 W2 DPHI``: the registry force with a second harmonic
DF2·sin(4π·x/L + PHI2), the first's amplitude times 1 − W1·r and phase plus DPHI·r, the
second's times 1 + W2·r, r = |v|/(the slip's fastest |v| so far), 1 while the slip speeds up
(``branching-registry``; TAU 0, no loop, no registry lag); ``--lag-distance D``: the viscous
force lagging by the slip distance D (σ), not a time (``distance-lag``; TAU 0; with
``--branching``, ``distance-lag-branching``); ``--lag-yield-exponent A``: each run's lag
TAU·(F̄_s/F_s)^A, F_s its yield force (± 30 % about the scale's F̄_s): longer in the runs
that yield weaker and slip slower, the split's positive control (TAU > 0, no loop);
``--loop LAW W D``: the film with a yield loop besides (``melting``, D a velocity, or
``slip-weakening``, D a distance; ΔF = W·(F_s − F_k) of each run's yield force, fading over D:
``corrugated-loop`` of :mod:`filmfriction.analysis.groundtruth.random_force`), whether it lags
or not (a melting film's viscous force cannot lag: TAU 0); besides τ̂, the loop step at the
grid point nearest it; ``--slip-end force-minimum``: each slip ends at its lowest spring
force, where the MD's detector ends one, not where the slider re-sticks
(:data:`~filmfriction.analysis.groundtruth.pooled_controls.SLIP_ENDS`); for the pools whose m_c does not cross, m_c at τ_r = 0 in its
errors, and over all pools the one law's m_c and the loop step at the grid's first τ_r; the noise-free profile of the first pool's runs (re-sticking at the scale's own stop
velocity: noise-free the wall does not recoil; or, where a strong loop keeps a noise-free
run sliding, why there is none), then over the pools τ̂'s mean, its scatter
and how many pools' τ̂ ± 2 errors cover TAU, and the one law's B at the grid point nearest
τ̂ (mean ± its standard error) against the law's.  ``--split velocity``: the slips split
at the pool's median slip velocity (slide over duration), each half profiled on its own: on
MD runs each half's table, τ̂ and τ̂·v̄ and the difference slow − fast; on controls, over the
pools, each half's m_c and τ̂, how often τ̂ ± 2 errors covers a known lag in time, and the
difference (a lag fixed in time or in slide leaves it within about one sd of 0 at the
M = 3×10³ scale: docs/results/slip-law.md); with ``--lag-yield-exponent``, each half's lag
at its slips' mean yield force instead of the coverage.  Seeds fixed: counts deterministic.
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from filmfriction.analysis.groundtruth.pooled_controls import (SLIP_ENDS, branch_weights,
                                                                pooled_runs, yield_loop)
from filmfriction.analysis.groundtruth.random_force import NOISE_FREE
from filmfriction.analysis.groundtruth.film_noise import scaled
from filmfriction.analysis.groundtruth.slip_law_controls import SCALES
from filmfriction.analysis.slip_law.slip_law_cycles import MD_NOISE_TIME
from filmfriction.analysis.slip_law.slip_law_pooled import fit_pooled_ensemble

LAGS = (0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 50.0, 60.0)


def profile(runs, lags, **kw) -> list:
    """The pooled fit at each τ_r of ``lags`` (0: B·v)."""
    return [fit_pooled_ensemble(runs, **kw, viscous_lag=lag or None) for lag in lags]


def crossing(lags, fits) -> tuple[float, float]:
    """τ̂, where the one law's m_c crosses zero downwards-to-upwards (the first crossing),
    and its error; (nan, nan) where it does not cross on the grid."""
    mc = np.array([f.one_law.comoving_mass for f in fits])
    se = np.array([f.one_law.comoving_mass_stderr for f in fits])
    for k in range(len(lags) - 1):
        if mc[k] < 0 <= mc[k + 1]:
            slope = (mc[k + 1] - mc[k]) / (lags[k + 1] - lags[k])
            tau = lags[k] - mc[k] / slope
            w = (tau - lags[k]) / (lags[k + 1] - lags[k])
            return float(tau), float(((1 - w) * se[k] + w * se[k + 1]) / slope)
    return math.nan, math.nan


def table(lags, fits) -> str:
    rows = ["| τ_r (τ) | one law F_k (ε/σ) | one law B (m/τ) | one law m_c (m) | loop step "
            "(ε/σ) | the rule |", "|---|---|---|---|---|---|"]
    for lag, f in zip(lags, fits):
        o = f.one_law
        rows.append(f"| {lag:g} | {o.kinetic_force:.1f} ± {o.kinetic_force_stderr:.1f} | "
                    f"{o.damping:.0f} ± {o.damping_stderr:.0f} | {o.comoving_mass:.0f} ± "
                    f"{o.comoving_mass_stderr:.0f} | {f.loop_step:+.1f} ± "
                    f"{f.loop_step_stderr:.1f} | `{f.verdict}` ({f.verdict_from}) |")
    tau, err = crossing(lags, fits)
    rows.append(f"\nτ̂ (the one law's m_c crossing zero): {tau:.1f} ± {err:.1f} τ"
                if math.isfinite(tau) else "\nthe one law's m_c does not cross zero on the grid")
    return "\n".join(rows)


def split_by_velocity(runs) -> list:
    """The runs' slips split at the pool's median slip velocity (each slip's slide over its
    duration): [(slow half's runs, its mean slip velocity), (fast half's …)], each run with
    its own slips of that half (a run left without one dropped)."""
    speeds = [r.table.slip_distance / r.table.slip_duration for r in runs]
    cut = float(np.median(np.concatenate(speeds)))
    halves = []
    for slow in (True, False):
        masks = [(v <= cut) == slow for v in speeds]
        kept = [(replace(r, table=r.table[np.flatnonzero(m)]), v[m])
                for r, v, m in zip(runs, speeds, masks) if m.any()]
        halves.append(([r for r, _ in kept], float(np.mean(np.concatenate([v for _, v in kept])))))
    return halves


def split_md(args, runs, fit_kw) -> int:
    """The profile of each half of ``split_by_velocity``, τ̂ and τ̂·v̄ of each."""
    out = []
    for label, (rs, v) in zip(("slow", "fast"), split_by_velocity(runs)):
        try:
            fits = profile(rs, args.lags, **fit_kw)
        except ValueError as exc:      # too few runs or slips left in the half
            print(f"the {label} half: {len(rs)} runs, mean slip velocity {v:.4f} σ/τ: not "
                  f"fitted ({exc})\n")
            return 0
        tau, err = crossing(args.lags, fits)
        out.append((tau, err))
        print(f"the {label} half: {len(rs)} runs, {sum(len(r.table) for r in rs)} slips, "
              f"mean slip velocity {v:.4f} σ/τ\n{table(args.lags, fits)}"
              + (f"; τ̂·v̄ {tau * v:.2f} σ\n" if math.isfinite(tau) else "\n"))
    (ts, es), (tf, ef) = out
    if math.isfinite(ts - tf):
        print(f"τ̂ slow − fast: {ts - tf:+.1f} ± {math.hypot(es, ef):.1f} τ")
    return 0


def md(args) -> int:
    from filmfriction.analysis.calibration.slip_law_runs import fit_arguments, read_runs

    try:
        runs, shared, _ = read_runs(args.runs_dirs, analyse=False)
        if args.no_registry:
            shared = {**shared, "registry_period": None}
        if args.split:
            return split_md(args, runs, fit_arguments(shared))
        fits = profile(runs, args.lags, **fit_arguments(shared))
    except ValueError as exc:
        print(f"viscous_lag_profile: {exc}", file=sys.stderr)
        return 1
    print(f"{len(runs)} runs, {sum(len(r.table) for r in runs)} slips; the walls' registry "
          f"force fitted at period {fits[0].registry_period}\n")
    print(table(args.lags, fits))
    return 0


def control(args) -> int:
    share, tau = args.control
    base = SCALES[args.scale]
    sc = replace(base, mix={**base.mix, "stop_velocity": args.stop_velocity})
    loop_law, loop = "melting", None
    if args.loop is not None:
        loop_law, *loop = yield_loop(*args.loop, laws=("melting", "slip-weakening"))
        loop = tuple(loop)
    law = sc.law("x", share, loop, loop_law, tau or None)
    fk, b = law["parameters"][:2]
    period = args.corrugation[1]
    kw = dict(mass=sc.mass, film_mass=sc.film_mass, mount_damping=sc.mount_damping,
              min_window_time=MD_NOISE_TIME, registry_period=period)
    noise = scaled(sc.registry_noise if args.noise is None else
                   {"velocity_noise": args.noise[0], "velocity_correlation": args.noise[1],
                    "rattle": 0.0}, args.noise_scale)
    print(f"controls at the {args.scale} scale: share {share:g} (F_k {fk:.2f}, B {b:.1f}) "
          f"lagging by {tau:g} τ, "
          + ("" if loop is None else f"a {loop_law} loop {loop[0]:g} over {loop[1]:g}, ")
          + ("" if args.registry_lag is None else
             f"the registry trailing the wall over {args.registry_lag:g} τ, ")
          + ("" if args.branching is None else
             f"branching (ΔF₂, φ₂, w₁, w₂, δφ) = {tuple(args.branching)}, ")
          + ("" if args.lag_distance is None else
             f"the viscous force lagging by {args.lag_distance:g} σ of slide, ")
          + ("" if not args.lag_yield_exponent else
             f"each run's lag × (F̄_s/F_s)^{args.lag_yield_exponent:g}, F̄_s "
             f"{law['static_force']:.1f} ε/σ, ")
          + f"registry force {args.corrugation}, noise {noise}, {args.runs} runs x {args.slips} "
          f"slips, stop velocity {args.stop_velocity:g}, law spread {args.law_spread:g}, "
          f"slip ends: {args.slip_end}\n")

    def runs_of(k, noise_, scale=sc):
        return pooled_runs("x", args.runs, args.slips, share=share, scale=scale, noise=noise_,
                           law_spread=args.law_spread, lag=tau or None,
                           weakening=loop, loop_law=loop_law, slip_end=args.slip_end,
                           corrugation=tuple(args.corrugation), seed=(0, k),
                           registry_lag=args.registry_lag,
                           branching=(None if args.branching is None
                                      else branch_weights(args.branching)),
                           lag_distance=args.lag_distance,
                           lag_yield_exponent=args.lag_yield_exponent)

    def pool(k, noise_, scale=sc):
        rs, vd = runs_of(k, noise_, scale)
        return profile(rs, args.lags, drive_velocity=vd, **kw)

    if args.split:
        return split_control(args, lambda k: runs_of(k, noise), kw, law["static_force"])

    # noise-free the wall does not recoil: it re-sticks once slowed to the scale's own stop
    # (a strong loop can keep a noise-free run sliding: then that run's message instead)
    try:
        quiet = table(args.lags, pool(0, NOISE_FREE, base))
    except ValueError as exc:
        if args.loop is None:
            raise
        quiet = f"(none: {exc})\n"
    print("noise-free (re-sticking at the scale's stop velocity), the first pool's runs:\n"
          + quiet, flush=True)
    taus, errs, bs, steps, first = [], [], [], [], []
    for k in range(args.replicas):
        fits = pool(k, noise)
        o = fits[0].one_law
        first.append((o.comoving_mass / o.comoving_mass_stderr, fits[0].loop_step,
                      fits[0].loop_step / fits[0].loop_step_stderr))
        t, e = crossing(args.lags, fits)
        taus.append(t)
        errs.append(e)
        if math.isfinite(t):
            near = fits[int(np.argmin(np.abs(np.asarray(args.lags) - t)))]
            bs.append(near.one_law.damping)
            steps.append((near.loop_step, near.loop_step_stderr))
    taus, errs, first = np.array(taus), np.array(errs), np.array(first)
    ok = np.isfinite(taus)
    print(f"\nat τ_r = {args.lags[0]:g}, over the {args.replicas} pools: the one law's m_c "
          f"{first[:, 0].mean():+.1f} errors (sd {first[:, 0].std():.1f}; ≤ −2 in "
          f"{int((first[:, 0] <= -2).sum())}), the loop step {first[:, 1].mean():+.2f} ε/σ "
          f"(sd {first[:, 1].std():.2f}; ≥ +2 errors in {int((first[:, 2] >= 2).sum())})")
    mc0 = first[~ok, 0]             # the pools whose m_c does not cross
    if mc0.size:
        print(f"{mc0.size} pools whose m_c does not cross zero on the grid: m_c at τ_r = "
              f"{args.lags[0]:g} {np.mean(mc0):+.1f} errors (sd {np.std(mc0):.1f})")
    if not ok.any():
        print(f"{args.replicas} pools: m_c crosses zero on the grid in none")
        return 0
    st = np.array(steps)
    print(f"the loop step at the grid point nearest τ̂: {st[:, 0].mean():+.2f} ε/σ (sd "
          f"{st[:, 0].std():.2f}; ≥ +2 errors in {int((st[:, 0] >= 2 * st[:, 1]).sum())} of "
          f"{len(st)})")
    sd = taus[ok].std(ddof=1) if ok.sum() > 1 else math.nan
    bse = np.std(bs, ddof=1) / math.sqrt(len(bs)) if len(bs) > 1 else math.nan
    print(f"\n{args.replicas} pools: m_c crosses zero in {ok.sum()}; τ̂ {taus[ok].mean():.1f} "
          f"(sd {sd:.1f}, median error {np.median(errs[ok]):.1f}) τ for "
          f"{tau:g}; τ̂ ± 2 errors covers it in {int((np.abs(taus[ok] - tau) <= 2 * errs[ok]).sum())}"
          f"; the one law's B at the grid point nearest τ̂ {np.mean(bs):.0f} ± "
          f"{bse:.0f} m/τ (law {b:.0f})")
    return 0


def split_control(args, runs_of, kw, static_force) -> int:
    """Over the pools: each half of ``split_by_velocity``'s m_c at the grid's first τ_r (in
    its errors), where each crosses zero, τ̂ of each, how often τ̂ ± 2 errors covers the
    control's own lag (a lag in time only; with ``--lag-yield-exponent`` each half's lag at
    its mean yield force instead, ``static_force`` the scale's F̄_s) and the halves'
    difference."""
    tau, alpha = args.control[1], args.lag_yield_exponent
    halves = ([], [])         # per half, per pool: τ̂, its error, v̄, m_c / error, its lag
    for k in range(args.replicas):
        rs, vd = runs_of(k)
        for rows, (half, v) in zip(halves, split_by_velocity(rs)):
            fits = profile(half, args.lags, drive_velocity=vd, **kw)
            o = fits[0].one_law
            fs = np.mean(np.concatenate([r.table.static_force for r in half]))
            rows.append((*crossing(args.lags, fits), v, o.comoving_mass / o.comoving_mass_stderr,
                         tau * (static_force / fs) ** alpha))
    slow, fast = (np.array(h) for h in halves)
    cross = np.isfinite(np.column_stack([slow[:, 0], fast[:, 0]]))
    both = cross.all(axis=1)

    def m_c(h):
        low = int((h[:, 3] <= -2).sum())
        return f"{h[:, 3].mean():+.1f} (sd {h[:, 3].std():.1f}; ≤ −2 in {low})"

    print(f"split at each pool's median slip velocity, over the {args.replicas} pools: mean "
          f"slip velocity {slow[:, 2].mean():.4f} (slow half) and {fast[:, 2].mean():.4f} σ/τ "
          f"(fast); the one law's m_c at τ_r = {args.lags[0]:g} {m_c(slow)} and {m_c(fast)} "
          f"errors; m_c crosses zero in {int(cross[:, 0].sum())} and {int(cross[:, 1].sum())}, "
          f"in both in {int(both.sum())}, in the slow half alone in "
          f"{int((cross[:, 0] & ~cross[:, 1]).sum())}")
    if alpha:
        print(f"the law's lag at each half's mean yield force: {slow[:, 4].mean():.1f} (slow) "
              f"and {fast[:, 4].mean():.1f} τ (fast), slow − fast "
              f"{(slow[:, 4] - fast[:, 4]).mean():+.1f} τ (means over the pools)")
    elif tau > 0 and args.lag_distance is None:
        cover = [int((np.abs(h[c, 0] - tau) <= 2 * h[c, 1]).sum())
                 for h, c in ((slow, cross[:, 0]), (fast, cross[:, 1]))]
        print(f"τ̂ ± 2 errors covers the lag of {tau:g} τ in {cover[0]} of "
              f"{int(cross[:, 0].sum())} (slow half) and {cover[1]} of {int(cross[:, 1].sum())} "
              f"(fast)")
    if both.sum() > 1:
        d = slow[both, 0] - fast[both, 0]
        print(f"where both cross: τ̂ {slow[both, 0].mean():.1f} (sd "
              f"{slow[both, 0].std(ddof=1):.1f}) and {fast[both, 0].mean():.1f} (sd "
              f"{fast[both, 0].std(ddof=1):.1f}) τ; slow − fast "
              f"{d.mean():+.1f} (sd {d.std(ddof=1):.1f}; median error "
              f"{np.median(np.hypot(slow[both, 1], fast[both, 1])):.1f}) τ; > 0 in "
              f"{int((d > 0).sum())} of {int(both.sum())}")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs_dirs", nargs="*", type=Path, metavar="RUN")
    ap.add_argument("--lags", nargs="+", type=float, default=list(LAGS), metavar="TAU")
    ap.add_argument("--no-registry", action="store_true")
    ap.add_argument("--control", nargs=2, type=float, default=None, metavar=("SHARE", "TAU"))
    ap.add_argument("--replicas", type=int, default=40)
    ap.add_argument("--runs", type=int, default=10)
    ap.add_argument("--slips", type=int, default=9)
    ap.add_argument("--noise-scale", type=float, default=1.0)
    ap.add_argument("--law-spread", type=float, default=0.15)
    ap.add_argument("--corrugation", nargs=3, type=float, default=[20.0, 1.1, -0.97],
                    metavar=("DF", "L", "PHI"))
    ap.add_argument("--stop-velocity", type=float, default=-0.0025)
    ap.add_argument("--scale", choices=[s for s in SCALES if s != "klein"], default="stiff")
    ap.add_argument("--noise", nargs=2, type=float, default=None, metavar=("U", "RHO"))
    ap.add_argument("--loop", nargs=3, default=None, metavar=("LAW", "W", "D"))
    ap.add_argument("--slip-end", choices=SLIP_ENDS, default="slider")
    ap.add_argument("--registry-lag", type=float, default=None, metavar="TAU_G")
    ap.add_argument("--branching", nargs=5, type=float, default=None,
                    metavar=("DF2", "PHI2", "W1", "W2", "DPHI"))
    ap.add_argument("--lag-distance", type=float, default=None, metavar="D")
    ap.add_argument("--lag-yield-exponent", type=float, default=0.0, metavar="A")
    ap.add_argument("--split", choices=("velocity",), default=None)
    a = ap.parse_args(argv)
    if sorted(a.lags) != a.lags or any(not (math.isfinite(x) and x >= 0) for x in a.lags):
        ap.error(f"--lags {a.lags}: increasing, each >= 0 (τ)")
    if (a.control is None) == (not a.runs_dirs):
        ap.error("RUN… or --control SHARE TAU (one of them)")
    if a.control is not None:
        share, tau = a.control
        if not (0 < share <= 1 and math.isfinite(tau) and tau >= 0):
            ap.error(f"--control {a.control}: SHARE in (0, 1], TAU >= 0 (0: no lag)")
        if a.replicas < 1 or a.runs < 3 or a.slips < 1 or not a.noise_scale >= 0:
            ap.error("--replicas >= 1, --runs >= 3, --slips >= 1, --noise-scale >= 0")
        if not (all(map(math.isfinite, a.corrugation)) and a.corrugation[1] > 0):
            ap.error(f"--corrugation {a.corrugation}: finite, L > 0")
        if a.noise is not None and not (a.noise[0] >= 0 and 0 <= a.noise[1] < 1):
            ap.error(f"--noise {a.noise}: U >= 0, RHO in [0, 1)")
        if a.noise is None and SCALES[a.scale].registry_noise is None:
            ap.error(f"--scale {a.scale}: its noise beside the registry is not calibrated; "
                     "give --noise U RHO")
        if a.loop is not None:
            try:
                yield_loop(*a.loop, laws=("melting", "slip-weakening"))
            except ValueError as exc:
                ap.error(f"--loop {' '.join(a.loop)}: {exc}")
            if a.loop[0] == "melting" and tau > 0:
                ap.error(f"--loop {' '.join(a.loop)}: melting with TAU 0 only")
        if a.registry_lag is not None and (not (math.isfinite(a.registry_lag)
                                                and a.registry_lag > 0) or tau > 0 or a.loop):
            ap.error(f"--registry-lag {a.registry_lag}: a time > 0 (τ), with TAU 0 and no "
                     "--loop")
        if a.branching is not None:
            try:
                branch_weights(a.branching)
            except ValueError as exc:
                ap.error(f"--branching {' '.join(map(str, a.branching))}: {exc}")
            if tau > 0 or a.loop or a.registry_lag is not None:
                ap.error("--branching: with TAU 0, no --loop, no --registry-lag")
        d = a.lag_distance
        if d is not None and not (math.isfinite(d) and d > 0 and tau == 0 and not a.loop
                                  and a.registry_lag is None):
            ap.error(f"--lag-distance {d}: a distance > 0 (σ); with TAU 0, no --loop or "
                     "--registry-lag")
        y = a.lag_yield_exponent
        if y and not (math.isfinite(y) and tau > 0 and not a.loop and a.registry_lag is None
                      and a.branching is None and d is None):
            ap.error(f"--lag-yield-exponent {y}: finite, with TAU > 0, no --loop, "
                     "--registry-lag, --branching or --lag-distance")
        if not (0 <= a.law_spread < 1 and math.isfinite(a.stop_velocity)):
            ap.error(f"--law-spread {a.law_spread} in [0, 1), --stop-velocity "
                     f"{a.stop_velocity} finite")
        try:
            return control(a)
        except ValueError as exc:      # a law the spread made impossible (D or τ_r <= 0)
            print(f"viscous_lag_profile: {exc}", file=sys.stderr)
            return 1
    if (a.registry_lag is not None or a.branching is not None or a.lag_distance is not None
            or a.lag_yield_exponent):
        ap.error("--registry-lag, --branching, --lag-distance and --lag-yield-exponent are "
                 "the controls' (with --control)")
    missing = [str(r) for r in a.runs_dirs if not (r / "trace.csv").is_file()]
    if missing:
        ap.error(f"RUN without trace.csv: {', '.join(missing)}")
    return md(a)


if __name__ == "__main__":
    sys.exit(main())
