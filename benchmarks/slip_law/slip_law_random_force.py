"""The slip-law controls with the MD's noise as a random force that moves the wall, against
the noise added to the law's trace (docs/results/slip-law.md, "The controls with a random force").

    python benchmarks/slip_law/slip_law_random_force.py [--replicas 40] [--laws coulomb viscous ...]
                                               [--slips 8 30] [--residual]
    python benchmarks/slip_law/slip_law_random_force.py --ensemble [--noises md md-1.5x md-2tau residual ...]
    python benchmarks/slip_law/slip_law_random_force.py --ensemble --scale stiff [--laws coulomb viscous]

With ``--ensemble``: the driven analysis's fit, the slips' mean
(:func:`~filmfriction.analysis.slip_law.slip_law_cycles.fit_cycle_ensemble`), on the
controls and on Coulomb + viscous slips of viscous share 0.3 and 0.6, at the MD's noise, 1.5
times its amplitude and twice its correlation time: the verdict counts, and the bias
(mean − truth ± its standard error over the replicas) and coverage (how many replicas'
2 σ cover the truth) of F_k and B (decelerating branch, one law) and of the loop step, the
truth being the same fit of the noise-free slider.  Without it, each slip is fitted on its
own:

For each control law and slip count: the verdicts of the replicas and the estimates' means
with their standard errors over the replicas (F_k, B and the exponent n on the decelerating
and the accelerating branch and the one law; the loop step), with the noise as the film's
random force (:func:`~filmfriction.analysis.groundtruth.slip_law_controls.dynamical_fits`)
and added to the noise-free law's trace (``replica_fits``), and noise-free.  With
``--residual``: the integral-form residual of the random-force replicas measured as
``benchmarks/slip_law/slip_law_power.py --measure`` measures an MD run's (the whole slip, 2.5 τ off
its ends, F_k + B·v fitted; :mod:`~filmfriction.analysis.groundtruth.md_noise`), to compare
with the MD's (``benchmarks/slip_law/md_noise_calibration.py``).  With ``--cycle-mean``: a
prototype of the remedy, the slips of each replica aligned at the yield and averaged
before the fit (the noise of the regressors averages down as 1/√slips).  With ``--scale
stiff`` (``--ensemble`` only): the heavy slider's controls
(:data:`~filmfriction.analysis.groundtruth.slip_law_controls.SCALES`), ``md`` its calibrated
noise (``STIFF_NOISE``) and ``md-1.5x``, ``md-2tau`` its variants.
"""
from __future__ import annotations

import argparse
import math
import sys
from collections import Counter

import numpy as np
from scipy.integrate import cumulative_trapezoid

from filmfriction.analysis.groundtruth.md_noise import replica_residuals, residual_statistics
from filmfriction.analysis.groundtruth.random_force import slide
from filmfriction.analysis.groundtruth.film_noise import MD_NOISE, RESIDUAL_AS_NOISE
from filmfriction.analysis.groundtruth.slip_law_controls import (CONTROLS, SCALE, SCALES,
                                                                 control_fits)
from filmfriction.analysis.slip_law.slip_law import RESOLVED_SIGMAS, VERDICTS, fit_film_force
from filmfriction.reduced_model.cycles import cycle_table

NOISE_FREE = {"velocity_noise": 0.0, "velocity_correlation": 0.9, "rattle": 0.0}


def _ms(x) -> str:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size < 2:
        return "n/a"
    return f"{x.mean():.2f} ± {x.std(ddof=1) / math.sqrt(x.size):.2f}"


def summary(fits) -> str:
    c = Counter(f.verdict for f in fits)
    verdicts = ", ".join(f"{k} {c[k]}" for k in VERDICTS if c[k])
    rows = [f"verdicts: {verdicts}"]
    for br in ("decelerating", "accelerating", "one_law"):
        b = [getattr(f, br) for f in fits]
        rows.append(f"  {br:12s} F_k {_ms([x.kinetic_force for x in b])}, "
                    f"B {_ms([x.damping for x in b])}, n {_ms([x.exponent for x in b])}")
    rows.append(f"  loop step {_ms([f.loop_step for f in fits])}, "
                f"resolved ({RESOLVED_SIGMAS:.3g} σ) in "
                f"{sum(abs(f.loop_step_sigmas) >= RESOLVED_SIGMAS for f in fits)}")
    return "\n".join(rows)


def residual(replicas: int, share: float | None) -> None:
    """The integral-form residual of the random-force replicas of the viscous control, or
    of slips resisted by F_k + B·v of viscous ``share`` (``coulomb_viscous``), at
    ``MD_NOISE`` (:mod:`~filmfriction.analysis.groundtruth.md_noise`)."""
    s = residual_statistics(replica_residuals(MD_NOISE, share=share, replicas=replicas))
    what = "viscous control" if share is None else f"viscous share {share}"
    print(f"{what}, random force {MD_NOISE}: {s['slips']} slips; residual rms {s['rms']:.2f} "
          f"σ/τ (slips {min(s['per_slip_rms']):.2f}–{max(s['per_slip_rms']):.2f}); "
          "autocorrelation at 0.25, 1, 2, 4 τ: "
          + ", ".join(f"{x:.2f}" for x in s["autocorrelation"]))


def cycle_mean_fit(run: dict, slips: int, drive_velocity: float):
    """A prototype of the remedy: the ``slips`` slips after the start-up one aligned at the
    yield, averaged over the window all of them slip in (the shortest), and the mean slip
    fitted (one slip: the pooled errors, not the spread over the cycles)."""
    t, f, v, x = run["time"], run["spring_force"], run["wall_velocity"], run["wall_position"]
    y, s = run["yield_index"][1:slips + 1], run["stick_index"][1:slips + 1]
    n = int(np.min(s - y)) + 1
    idx = y[:, None] + np.arange(n)[None, :]
    fe, ve = f[idx].mean(axis=0), v[idx].mean(axis=0)
    xe = (x[idx] - x[y][:, None]).mean(axis=0)
    tab = cycle_table(t[:n], fe, [0], [n - 1], spring_constant=SCALE["spring_constant"],
                      wall_position=xe)
    return fit_film_force(t[:n], fe, ve, tab, mass=SCALE["mass"],
                          drive_velocity=drive_velocity, wall_position=xe)


def instrumented_fit(run: dict, slips: int, floor: float = 0.2, edge: int = 3) -> np.ndarray:
    """A prototype of another remedy: each slip fitted with its Δx instrumented by the mean
    Δx of the other slips at the same lag from the yield (their noise is not this slip's),
    the branches split at the peak of the others' mean velocity.  Per slip: (F_k, B) of the
    decelerating and the accelerating branch and the whole slip's step; rows of NaN where
    a slip has too few samples."""
    t, f, v, x = run["time"], run["spring_force"], run["wall_velocity"], run["wall_position"]
    y, s = run["yield_index"][1:slips + 1], run["stick_index"][1:slips + 1]
    imp = cumulative_trapezoid(f, t, initial=0.0)
    m, dt = SCALE["mass"], float(t[1] - t[0])
    out = []
    for i in range(y.size):
        n = int(s[i] - y[i]) + 1
        others = [j for j in range(y.size) if j != i]
        lag = np.arange(n)
        xs = np.full((len(others), n), np.nan)
        vs = np.full((len(others), n), np.nan)
        for r, j in enumerate(others):
            k = min(n, int(s[j] - y[j]) + 1)
            xs[r, :k] = x[y[j]:y[j] + k] - x[y[j]]
            vs[r, :k] = v[y[j]:y[j] + k]
        with np.errstate(all="ignore"):
            zx, zv = np.nanmean(xs, axis=0), np.nanmean(vs, axis=0)
        ok = np.isfinite(zx)
        if ok.sum() < 12:
            out.append([np.nan] * 5)
            continue
        n = int(np.flatnonzero(ok)[-1]) + 1
        p = int(np.nanargmax(zv[:n]))
        fast = zv[:n] > floor * zv[p]
        fast[:edge] = False
        fast[n - edge:] = False
        idx = y[i] + lag[:n]
        resp = imp[idx] - imp[idx[0]] - m * v[idx]
        dts, dxs = lag[:n] * dt, x[idx] - x[idx[0]]
        after = np.maximum(dts - p * dt, 0.0)
        row = []
        for lo, hi, step in ((p, n, False), (0, p + 1, False), (0, n, True)):
            k = np.flatnonzero(fast[lo:hi]) + lo
            if k.size < 8:
                row += [np.nan, np.nan] if not step else [np.nan]
                continue
            k = np.arange(k[0], k[-1] + 1)
            one = np.ones(k.size)
            X = [one, dts[k], dxs[k]] + ([after[k]] if step else [])
            Z = [one, dts[k], zx[k]] + ([after[k]] if step else [])
            X, Z = np.column_stack(X), np.column_stack(Z)
            try:
                b = np.linalg.solve(Z.T @ X, Z.T @ resp[k])
            except np.linalg.LinAlgError:          # e.g. no sample past the peak
                b = np.full(X.shape[1], np.nan)
            row += [-b[-1]] if step else [b[1], b[2]]
        out.append(row)
    return np.array(out, float)


def _prototype_runs(law: str, slips: int, replicas: int):
    """The random-force replicas of control ``law`` long enough for ``slips`` slips (the
    prototypes' input) and the law's drive velocity."""
    args = SCALES["klein"].law(law)
    period = args.pop("period")
    runs = slide(**args, mass=SCALE["mass"], stiffness=SCALE["spring_constant"],
                 duration=(slips + 3) * period * 1.3, dt=SCALE["dt"],
                 replicas=replicas, seed=0, **MD_NOISE)
    return runs, args["drive_velocity"]


def instrumented(laws, slip_counts, replicas: int) -> None:
    names = ("decelerating F_k", "decelerating B", "accelerating F_k", "accelerating B",
             "loop step")
    for law in laws:
        for slips in slip_counts:
            runs, _ = _prototype_runs(law, slips, replicas)
            per = np.array([np.nanmean(instrumented_fit(r, slips), axis=0) for r in runs])
            print(f"\n## {law}, {slips} slips instrumented by the other slips, {replicas} "
                  "replicas (mean over each replica's slips, then over the replicas)\n  "
                  + ", ".join(f"{nm} {_ms(per[:, c])}" for c, nm in enumerate(names)),
                  flush=True)


def cycle_means(laws, slip_counts, replicas: int) -> None:
    for law in laws:
        for slips in slip_counts:
            runs, velocity = _prototype_runs(law, slips, replicas)
            fits = [cycle_mean_fit(r, slips, velocity) for r in runs]
            print(f"\n## {law}, {slips} slips averaged at the yield, {replicas} replicas\n"
                  + summary(fits).split("\n", 1)[1], flush=True)


#: The noises of the ensemble's table: the MD's, 1.5 times its amplitude, twice its
#: correlation time (ρ per sample to the power 1/2), and the MD's plain residual taken as
#: the noise (``residual``: 1.7 times the MD's jitter) with its 1.5x and 2tau.
def _variants(noise: dict, name: str) -> dict[str, dict]:
    return {name: noise,
            f"{name}-1.5x": {k: (v if k == "velocity_correlation" else 1.5 * v)
                             for k, v in noise.items()},
            f"{name}-2tau": noise | {"velocity_correlation": noise["velocity_correlation"] ** 0.5}}


NOISES = _variants(MD_NOISE, "md") | _variants(RESIDUAL_AS_NOISE, "residual")
#: The Coulomb + viscous laws of the table (viscous share of the film force at 0.55 σ/τ).
SHARES = (0.3, 0.6)


def _coverage(fits, branch: str, attr: str, truth: float) -> str:
    """Mean − truth ± its standard error over the replicas, and how many replicas' 2 σ
    (normal-equivalent, the fit's own dof) cover the truth."""
    from filmfriction.analysis.slip_law.slip_law_stats import sigmas
    if branch == "step":
        est = np.array([f.loop_step for f in fits])
        se = np.array([f.loop_step_stderr for f in fits])
        dof = [f.one_law.dof for f in fits]
    else:
        b = [getattr(f, branch) for f in fits]
        est = np.array([getattr(x, attr) for x in b])
        se = np.array([getattr(x, f"{attr}_stderr") for x in b])
        dof = [x.dof for x in b]
    z = np.array([sigmas(e - truth, s_, d) for e, s_, d in zip(est, se, dof)])
    ok = np.isfinite(est)
    return (f"{np.mean(est[ok]) - truth:+.2f} ± {np.std(est[ok], ddof=1) / math.sqrt(ok.sum()):.2f}"
            f" (truth {truth:.3g}), covered {int(np.sum(np.abs(z) < 2))}/{ok.sum()}")


def _paths(fits, exact, mass: float = SCALE["mass"]) -> str:
    """Which fit each verdict came from and why (choose_law's reason), and the one law's
    co-moving mass: its mean over the replicas, the noise-free fit's, and how often it is
    resolved negative (one of choose_law's reasons for the decelerating branch)."""
    why = Counter(f"{f.verdict} from {f.verdict_from}"
                  + (f" ({f.reason.split('whole slip not one law (')[1].split(':')[0]})"
                     if f.verdict_from == "decelerating" else "") for f in fits)
    mc = np.array([f.one_law.comoving_mass for f in fits])
    from filmfriction.analysis.slip_law.slip_law_stats import sigmas
    neg = sum(sigmas(f.one_law.comoving_mass, f.one_law.comoving_mass_stderr,
                     f.one_law.dof) <= -2 for f in fits)
    return ("  paths: " + "; ".join(f"{k} {n}" for k, n in why.most_common())
            + f"\n  one law m_c {mc.mean():+.1f} ± {mc.std(ddof=1) / math.sqrt(mc.size):.1f} "
            f"(noise-free {exact.one_law.comoving_mass:+.2f}; the wall {mass:g}), "
            f"below −2 s.e. in {neg}")


def ensemble_table(laws, slip_counts, replicas: int, noises, shares=SHARES,
                   scale: str = "klein") -> None:
    """The cycle ensemble's control table: verdict counts, bias and coverage of F_k and B
    (the decelerating branch and the one law) and of the loop step, the truth being the
    same fit of the noise-free slider (the law's own F_k, B for the linear laws); the
    verdicts' paths and the co-moving mass (:func:`_paths`)."""
    from filmfriction.analysis.groundtruth.slip_law_controls import dynamical_fits
    sc = SCALES[scale]
    table = NOISES if scale == "klein" else _variants(sc.noise, "md")
    cases = [(law, None) for law in laws] + [("coulomb-viscous", sh) for sh in shares]
    for noise in noises:
        for law, share in cases:
            name = law if share is None else f"{law} share {share}"
            for slips in slip_counts:
                exact = dynamical_fits(law, 1, slips, noise=NOISE_FREE, share=share,
                                       scale=scale)[0]
                fits = dynamical_fits(law, replicas, slips, noise=table[noise], share=share,
                                      unfitted=True, scale=scale)
                refused = sum(f is None for f in fits)
                fits = [f for f in fits if f is not None]
                c = Counter(f.verdict for f in fits) | Counter({"not fitted (< 3 slips)": refused})
                print(f"\n## {name}, {slips} slips, noise {noise}"
                      + (f" at the {scale} scale {table[noise]}" if scale != "klein" else "")
                      + f", {replicas} replicas: "
                      + ", ".join(f"{k} {c[k]}" for k in (*VERDICTS, "not fitted (< 3 slips)")
                                  if c[k])
                      + f"; verdict from {dict(Counter(f.verdict_from for f in fits))}")
                for br in ("decelerating", "one_law"):
                    law_ = getattr(exact, br)
                    print(f"  {br:12s} F_k {_coverage(fits, br, 'kinetic_force', law_.kinetic_force)}"
                          f"; B {_coverage(fits, br, 'damping', law_.damping)}")
                print(f"  loop step {_coverage(fits, 'step', '', exact.loop_step)}, resolved "
                      f"({RESOLVED_SIGMAS:.3g} σ) in "
                      f"{sum(abs(f.loop_step_sigmas) >= RESOLVED_SIGMAS for f in fits)}")
                print(_paths(fits, exact, sc.mass), flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--replicas", type=int, default=40)
    ap.add_argument("--laws", nargs="+", default=None, choices=list(CONTROLS),
                    help="the controls (default: all of the scale's)")
    ap.add_argument("--slips", nargs="+", type=int, default=[8, 30])
    ap.add_argument("--residual", action="store_true", help="only the residual of the replicas")
    ap.add_argument("--instrumented", action="store_true",
                    help="the prototype remedy: Δx instrumented by the other slips' mean")
    ap.add_argument("--cycle-mean", action="store_true",
                    help="the prototype remedy: the slips averaged at the yield, then fitted")
    ap.add_argument("--ensemble", action="store_true",
                    help="the cycle ensemble (the driven analysis's fit): verdicts, bias, coverage")
    ap.add_argument("--noises", nargs="+", default=["md"], choices=list(NOISES),
                    help="with --ensemble: the noises (md: MD_NOISE, residual: RESIDUAL_AS_NOISE; -1.5x: 1.5x the amplitude, -2tau: twice the correlation time)")
    ap.add_argument("--shares", nargs="*", type=float, default=list(SHARES),
                    help="with --ensemble: the Coulomb + viscous laws' viscous shares (none: no such rows)")
    ap.add_argument("--share", type=float, default=None,
                    help="with --residual: slips of F_k + B·v of this viscous share")
    ap.add_argument("--scale", default="klein", choices=list(SCALES),
                    help="with --ensemble: the controls' scale (stiff: the heavy slider's)")
    a = ap.parse_args(argv)
    if a.laws is None:
        a.laws = list(CONTROLS) if a.scale == "klein" else list(SCALES[a.scale].laws)
    if a.scale != "klein" and not a.ensemble:
        ap.error("--scale other than klein: with --ensemble only")
    if a.residual:
        residual(a.replicas, a.share)
        return 0
    if a.instrumented:
        instrumented(a.laws, a.slips, a.replicas)
        return 0
    if a.ensemble:
        ensemble_table(a.laws, a.slips, a.replicas, a.noises, a.shares, a.scale)
        return 0
    if a.cycle_mean:
        cycle_means(a.laws, a.slips, a.replicas)
        return 0
    for law in a.laws:
        for slips in a.slips:
            exact = control_fits(law, 1, slips, noise=NOISE_FREE, ensemble=False)
            print(f"\n## {law} ({CONTROLS[law]}), {slips} slips\nnoise-free slider: "
                  + summary(exact * 2).replace(" ± 0.00", "").split("\n", 1)[1].split(", resolved")[0],
                  flush=True)
            for name, injected in (("random force", False), ("added to the trace", True)):
                fits = control_fits(law, a.replicas, slips, injected=injected,
                                    **({} if injected else {"ensemble": False}))
                print(f"{name}, {a.replicas} replicas: {summary(fits)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
