"""The slip law pooled over runs, on controls of known law: verdicts, bias and coverage.

    python benchmarks/slip_law/pooled_controls_rates.py [--runs 6] [--slips 8] [--replicas 100]
        [--laws coulomb viscous] [--shares 0.3 0.6] [--static-spread 0.3] [--law-spread 0.0]
        [--scale stiff] [--noise-scale 1.0] [--loop LAW W D] [--lag TAU] [--stop-velocity V]
        [--md RUN...]

Each replica is G runs of one law at the heavy slider's scale (``SCALES["stiff"]``, its
calibrated noise; ``--scale m1e4``: the K = 8 film's slider at M = 10⁴, ``SCALES["m1e4"]``),
``--noise-scale``: the scale's noise with its amplitudes times that (its correlation kept);
each run with its own yield force and, with ``--law-spread``, its own film
(:mod:`filmfriction.analysis.groundtruth.pooled_controls`).  The runs' slips are pooled and
fitted (:func:`~filmfriction.analysis.slip_law.slip_law_pooled.fit_pooled_ensemble`)
with the jackknife over the runs, and the same pooled slips with the jackknife over the
slips (the comparison that treats them as one run's; ``--jackknife runs``: the first
alone).  Printed per law: the verdicts of both (the rule's, which branch it read, and the decelerating branch's alone), and for the
decelerating branch and the one law the bias of F_k and B (mean − truth
± its standard error over the replicas; the truth is the noise-free pooled fit: the law's
own F_k, B for a law without a loop; with ``--loop``, the loop law's own noise-free fit,
whose branches still carry what is left of its loop there) and how many replicas' 2 σ
cover the truth, for each jackknife, and the same for the loop force (the truth the
noise-free pooled fit's); how many replicas read the one law and the
decelerating branch each way, what the rule reads without the film's mass
(``Scale.film_mass``), and resolve the loop (the
branches' own lines apart, and the step beyond the one law's co-moving mass).  ``--loop LAW W
D``: the shares' mixes with a yield loop (``melting``, ``slip-weakening`` or ``maxwell``,
:mod:`~filmfriction.analysis.groundtruth.random_force`); ``--lag TAU``: the shares' mixes with
their viscous force lagging the velocity by TAU (``maxwell``; with ``--loop slip-weakening``,
``maxwell-weakening``); ``--corrugation DF LAMBDA PHI``: the mixes with a force
periodic in the wall's position (``corrugated``, the registry of commensurate walls; with
``--lag``, lagging too; with ``--loop melting`` or ``slip-weakening``, ``corrugated-loop``;
not with ``--loop maxwell``);
``--registry-period LAMBDA``: every fit (the truth's too) with a force of that period
fitted beside the law (the MD's runs of aligned walls are: ``registry_period``); ``--stop-velocity``: the mixes
re-stick at that velocity once armed (negative: once the wall recoils that fast; the truth
is still the noise-free slips re-sticking at the scale's own stop velocity); ``--md RUN…``: the MD runs'
slips' duration and share after their peak velocity, printed beside each table's first
replica's.  Each table opens with the noise-free pooled fit's signature (the one law's
co-moving mass, the loop step and force, the decelerating branch; ``--replicas 0``: that
alone, in seconds).  Seeds are fixed: the counts are deterministic.
"""
from __future__ import annotations

import argparse
import math
import sys
from collections import Counter
from dataclasses import replace

import numpy as np

from filmfriction.analysis.groundtruth.pooled_controls import STATIC_SPREAD, pooled_runs, yield_loop
from filmfriction.analysis.groundtruth.random_force import NOISE_FREE
from filmfriction.analysis.groundtruth.film_noise import scaled
from filmfriction.analysis.groundtruth.slip_law_controls import SCALES
from filmfriction.analysis.slip_law.slip_law import VERDICTS, loop_step_branch
from filmfriction.analysis.slip_law.slip_law_cycles import MD_NOISE_TIME
from filmfriction.analysis.slip_law.slip_law_pooled import JACKKNIFE, fit_pooled_ensemble
from filmfriction.analysis.slip_law.slip_law_stats import sigmas
from filmfriction.analysis.slip_law.slip_law_verdict import choose_law



def coverage(fits, branch: str, attr: str, truth: float) -> str:
    """Mean − truth ± its standard error over the replicas, and the replicas whose 2 σ
    (normal-equivalent at the fit's dof) cover the truth."""
    b = [getattr(f, branch) for f in fits]
    est = np.array([getattr(x, attr) for x in b])
    se = np.array([getattr(x, f"{attr}_stderr") for x in b])
    z = np.array([sigmas(e - truth, s, x.dof) for e, s, x in zip(est, se, b)])
    ok = np.isfinite(est)
    return (f"{np.mean(est[ok]) - truth:+.3g} ± {np.std(est[ok], ddof=1) / math.sqrt(ok.sum()):.2g}"
            f" (truth {truth:.4g}), covered {int(np.sum(np.abs(z) < 2))}/{ok.sum()}")


def slip_shape(runs) -> str:
    """The slips' median duration and the median share of a slip after its peak velocity
    (the peak of the velocity's 10 τ running mean), with their 10–90 % ranges."""
    dur, after = [], []
    for r in runs:
        dt = r.time[1] - r.time[0]
        w = max(1, int(round(10.0 / dt)))
        for a, b in zip(r.table.yield_index, r.table.stick_index):
            v = np.convolve(r.wall_velocity[int(a):int(b) + 1], np.ones(w) / w, "same")
            dur.append((int(b) - int(a)) * dt)
            after.append(1.0 - np.argmax(v) / max(v.size, 1))
    q = lambda x: f"{np.median(x):.3g} ({np.percentile(x, 10):.3g}–{np.percentile(x, 90):.3g})"
    return f"{len(dur)} slips: duration {q(dur)} τ, share after the peak velocity {q(after)}"


def fit(runs, velocity, jackknife, scale="stiff", registry_period=None):
    sc = SCALES[scale]
    return fit_pooled_ensemble(runs, mass=sc.mass, drive_velocity=velocity,
                               mount_damping=sc.mount_damping, min_window_time=MD_NOISE_TIME,
                               jackknife=jackknife, film_mass=sc.film_mass,
                               registry_period=registry_period)


def without_film_mass(f, mass: float) -> tuple[str, str]:
    """The rule's branch and verdict on fit ``f`` were the film's mass not known."""
    frm, verdict, _ = choose_law(f.decelerating, f.one_law, loop_step_branch(f), mass)
    return frm, verdict


def table(law: str, share, args) -> None:
    sc = SCALES[args.scale]
    if args.stop_velocity is not None:
        sc = replace(sc, mix={**sc.mix, "stop_velocity": args.stop_velocity})
    kw = dict(share=share, static_spread=args.static_spread, law_spread=args.law_spread,
              scale=sc)
    if share is not None and args.loop:
        law, w, d = yield_loop(*args.loop)
        kw |= {"loop_law": law, "weakening": (w, d)}
    if share is not None and args.lag is not None:
        kw["lag"] = args.lag
    if share is not None and args.corrugation:
        kw["corrugation"] = tuple(args.corrugation)
    noisy = {} if args.noise_scale == 1.0 else {
        "noise": scaled(SCALES[args.scale].noise, args.noise_scale)}
    name = law if share is None else f"coulomb-viscous share {share}" + (
        f" with a yield loop ({' '.join(args.loop)})" if args.loop else "") + (
        f" lagging by τ_r = {args.lag:g} τ" if args.lag is not None else "") + (
        " with the registry's force {:g} sin(2π x/{:g} + {:g})".format(*args.corrugation)
        if args.corrugation else "") + (
        f", fitted with the registry of period {args.registry_period:g} σ"
        if args.registry_period else "") + (
        "" if args.stop_velocity is None else
        f", re-sticking at v <= {args.stop_velocity:g} σ/τ")
    # the truth: noise-free, re-sticking as the scale's mixes do (once slowed to its stop
    # velocity; a re-stick at a recoil velocity < 0 never comes without the noise): the
    # law's own F_k, B for a mix without a loop
    try:
        exact = fit(*pooled_runs(law, args.runs, args.slips, noise=NOISE_FREE,
                                 **(kw | {"law_spread": 0.0, "scale": SCALES[args.scale]})),
                    "runs", args.scale, args.registry_period)
    except ValueError as exc:       # noise-free, a run of this law slides without a slip
        print(f"\n## {name}: not measured: its noise-free truth has no slips to fit ({exc})",
              flush=True)
        return
    print(f"\n## {name}: noise-free (re-sticking at the scale's stop velocity): one law m_c "
          f"{exact.one_law.comoving_mass:.4g} m, loop step {exact.loop_step:+.3g}, loop force "
          f"{exact.loop_force:+.3g} ε/σ; decelerating F_k {exact.decelerating.kinetic_force:.4g}, "
          f"B {exact.decelerating.damping:.4g} m/τ; the rule: {exact.verdict_from} "
          f"{exact.verdict}", flush=True)
    if not args.replicas:
        return
    fits = {j: [] for j in args.jackknife}
    unfitted = []
    for k in range(args.replicas):
        rs, v = pooled_runs(law, args.runs, args.slips, seed=(args.seed, k), **kw, **noisy)
        if k == 0:
            shape = slip_shape(rs)
        try:
            got = {j: fit(rs, v, j, args.scale, args.registry_period) for j in args.jackknife}
        except ValueError as exc:       # a run without slips: its film slid smoothly
            unfitted.append(str(exc))
            continue
        for j in args.jackknife:
            fits[j].append(got[j])
    print(f"\n## {name}: {args.replicas} replicas of {args.runs} runs x {args.slips} slips "
          f"(static spread ±{args.static_spread:g}, law spread {args.law_spread:g})",
          flush=True)
    print(f"  the first replica's {shape}")
    if unfitted:
        print(f"  {len(unfitted)} replicas not fitted (a run in them has no slip to pool, as "
              f"no MD run of the pools has), e.g. {unfitted[0]}; the counts are of the "
              f"{args.replicas - len(unfitted)} others")
    if not fits[args.jackknife[0]]:
        return
    for j in args.jackknife:
        c = Counter(f.verdict for f in fits[j])
        d = Counter(f.decelerating.verdict for f in fits[j])
        print(f"  jackknife over {j}: " + ", ".join(f"{v} {c[v]}" for v in VERDICTS if c[v])
              + f"; verdict from {dict(Counter(f.verdict_from for f in fits[j]))}; the "
              "decelerating branch alone: " + ", ".join(f"{v} {d[v]}" for v in VERDICTS if d[v]))
        both = Counter((f.one_law.verdict, f.decelerating.verdict) for f in fits[j])
        print("    one law / decelerating branch: " + ", ".join(
            f"{a}/{b} {n}" for (a, b), n in sorted(both.items(), key=lambda x: -x[1])))
        old = Counter(without_film_mass(f, SCALES[args.scale].mass)[1] for f in fits[j])
        print(f"    the rule without the film's mass ({SCALES[args.scale].film_mass:g} m): "
              + ", ".join(f"{v} {old[v]}" for v in VERDICTS if old[v]))
        zl = np.array([f.loop_step_sigmas for f in fits[j]])
        zm = np.array([sigmas(f.one_law.comoving_mass, f.one_law.comoving_mass_stderr,
                              f.one_law.dof) for f in fits[j]])
        zf = np.array([sigmas(f.loop_force, f.loop_force_stderr, f.one_law.dof)
                       for f in fits[j]])
        lf = np.array([f.loop_force for f in fits[j]])
        lz = np.array([sigmas(f.loop_force - exact.loop_force, f.loop_force_stderr,
                              f.one_law.dof) for f in fits[j]])
        print(f"    loop force (the branches' own lines apart) ≥ +2 σ in "
              f"{int(np.sum(zf >= 2))}, ≥ +3 σ in {int(np.sum(zf >= 3))}; "
              f"{np.nanmean(zf):+.2f} ± {np.nanstd(zf):.2f} σ; mean − truth "
              f"{np.nanmean(lf) - exact.loop_force:+.3g} ± "
              f"{np.nanstd(lf, ddof=1) / math.sqrt(np.isfinite(lf).sum()):.2g} (truth "
              f"{exact.loop_force:.3g}), covered {int(np.sum(np.abs(lz) < 2))}/{lf.size}")
        print(f"    loop step ≥ +2 σ in {int(np.sum(zl >= 2))}, m_c ≤ −2 σ in "
              f"{int(np.sum(zm <= -2))}, both in {int(np.sum((zl >= 2) & (zm <= -2)))}; "
              f"loop step {np.nanmean(zl):+.2f} ± {np.nanstd(zl):.2f} σ, m_c "
              f"{np.nanmean(zm):+.2f} ± {np.nanstd(zm):.2f} σ (mean ± sd over the replicas)")
        for br in ("decelerating", "one_law"):
            truth = getattr(exact, br)
            print(f"    {br:12s} F_k {coverage(fits[j], br, 'kinetic_force', truth.kinetic_force)}"
                  f"; B {coverage(fits[j], br, 'damping', truth.damping)}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=6)
    ap.add_argument("--slips", type=int, default=8)
    ap.add_argument("--replicas", type=int, default=100,
                    help="noisy replicas per table (0: the noise-free fit's signature alone)")
    ap.add_argument("--laws", nargs="*", default=["coulomb", "viscous"],
                    choices=sorted({n for sc in SCALES.values() for n in sc.laws}))
    ap.add_argument("--shares", nargs="*", type=float, default=[0.3, 0.6])
    ap.add_argument("--static-spread", type=float, default=STATIC_SPREAD)
    ap.add_argument("--law-spread", type=float, default=0.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--scale", default="stiff", choices=[n for n in SCALES if n != "klein"],
                    help="the controls' scale (SCALES; stiff: K 8, M 1e5; m1e4: K 8, M 1e4)")
    ap.add_argument("--loop", nargs=3, metavar=("LAW", "W", "D"), default=None,
                    help="the shares' mixes with a yield loop: LAW melting (D a velocity), "
                         "slip-weakening (D a distance) or maxwell (D a time: the film holds "
                         "ΔF at the yield, its viscous force lagging by D), ΔF = W·(F_s − F_k)")
    ap.add_argument("--lag", type=float, default=None, metavar="TAU",
                    help="the shares' mixes with their viscous force lagging the velocity by "
                         "TAU (a Maxwell film, τ); with --loop slip-weakening, that loop too")
    ap.add_argument("--jackknife", nargs="+", choices=JACKKNIFE, default=list(JACKKNIFE),
                    help="the jackknifes measured (runs: the errors; slips: the comparison)")
    ap.add_argument("--corrugation", nargs=3, type=float, default=None,
                    metavar=("DF", "LAMBDA", "PHI"),
                    help="the shares' mixes with a force DF·sin(2π·x/LAMBDA + PHI) of the wall's "
                         "position (commensurate walls' registry; ε/σ, σ, rad)")
    ap.add_argument("--registry-period", type=float, default=None, metavar="LAMBDA",
                    help="fit a force periodic in the wall's position, of this period (σ), "
                         "beside the law (as the MD's runs of aligned walls are fitted)")
    ap.add_argument("--stop-velocity", type=float, default=None,
                    help="the shares' mixes re-stick once armed at this velocity (σ/τ; "
                         "negative: once the wall recoils that fast; the scale's by default)")
    ap.add_argument("--md", nargs="*", default=[], metavar="RUN",
                    help="MD run directories whose slips' shape to print beside the controls'")
    ap.add_argument("--noise-scale", type=float, default=1.0,
                    help="the scale's noise amplitudes times this (1: as calibrated)")
    args = ap.parse_args(argv)
    if args.replicas < 0:
        ap.error(f"--replicas {args.replicas}: 0 or more")
    missing = [law for law in args.laws if law not in SCALES[args.scale].laws]
    if missing:
        ap.error(f"--laws {' '.join(missing)}: not a control at the {args.scale} scale "
                 f"({', '.join(SCALES[args.scale].laws)})")
    if args.loop:
        try:
            yield_loop(*args.loop)
        except ValueError as exc:
            ap.error(f"--loop {' '.join(args.loop)}: {exc}")
    if args.lag is not None and (not (math.isfinite(args.lag) and args.lag > 0) or (
            args.loop and args.loop[0] != "slip-weakening")):
        ap.error(f"--lag {args.lag!r}: a relaxation time > 0, finite, and with --loop only "
                 "slip-weakening")
    if args.corrugation and ((args.loop and args.loop[0] == "maxwell") or not all(
            map(math.isfinite, args.corrugation)) or not args.corrugation[1] > 0):
        ap.error(f"--corrugation {args.corrugation!r}: finite, LAMBDA > 0, and not with "
                 "--loop maxwell")
    if args.registry_period is not None and not (math.isfinite(args.registry_period)
                                                 and args.registry_period > 0):
        ap.error(f"--registry-period {args.registry_period!r}: a period > 0, finite")
    if args.stop_velocity is not None and not (math.isfinite(args.stop_velocity)
                                               or args.stop_velocity == -math.inf):
        ap.error(f"--stop-velocity {args.stop_velocity!r}: finite or -inf")
    shown = {k: v for k, v in vars(args).items() if k != "md"} | {"md runs": len(args.md)}
    print(f"pooled slip-law controls at the {args.scale} scale: {shown}")
    if args.md:
        from filmfriction.analysis.calibration.slip_law_runs import read_runs
        print(f"the MD runs' {slip_shape(read_runs(args.md)[0])}")
    for law in args.laws:
        table(law, None, args)
    for share in args.shares:
        table("coulomb", share, args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
