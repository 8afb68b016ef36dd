"""The slip law's MD positive control (docs/results/slip-law.md): liquid-release runs fitted.

    filmfriction run liquid-release --np 1 --md-only --set seed=S --out RUN_S   # per seed
    (add --set hold_gap=1 for the held-gap control: the wall free along x only)
    python benchmarks/slip_law/fit_release_runs.py --viscosity ETA ETA_ERR [--load-work] [--per-release] RUN_1 RUN_2 ...

Prints the slip law fitted to the runs' mean release, its errors the jackknife's over
the releases (:func:`filmfriction.analysis.groundtruth.release_control.fit_release_ensemble`;
``--per-release``: each release's slip fitted and the slips' scatter taken,
:func:`~filmfriction.analysis.groundtruth.release_control.fit_releases`, which the film's
own noise biases: docs/results/slip-law.md): the verdict
and the law it is, each branch and the whole slip, the whole slip with a co-moving
mass — the one law — and the loop step beyond it), how many releases the rule would
need at the releases' own scatter (the kinetic force, or the loop step, ruled out at
half the film force: :func:`~filmfriction.analysis.slip_law.slip_law.detectable` < F̄/2 with
the per-release standard deviation; with the ensemble fit the standard deviation of the
jackknife's pseudo-values), each run's layer velocity
shares, where the shear sits and the width W = D + 2b of its profile, and
B = η·A/W with η the liquid's viscosity at the film's state point
(``filmfriction viscosity``).  ``--load-work``: the film force less the load's work on
the gap (``fit_film_force(load_work=…)``), its dissipative part.
"""
from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np

from scipy.signal import savgol_filter

from filmfriction.analysis.groundtruth.release_control import (couette_comoving_mass,
                                                               fit_release_ensemble,
                                                               fit_releases, release_gap,
                                                               release_profile, release_slip)
from filmfriction.analysis.slip_law.slip_law import DOMINANT_SHARE, RESOLVED_SIGMAS, detectable


def releases_needed(per_release_sd: float, target: float, most: int = 1000) -> int | None:
    """Releases at which a term of size ``target`` would be resolved at 95 % power (2.24 σ),
    with ``per_release_sd`` the standard deviation of its per-release fits (None: not
    within ``most``)."""
    if not (per_release_sd > 0 and target > 0):
        return None
    for n in range(2, most + 1):
        if detectable(per_release_sd / math.sqrt(n), n - 1) < target:
            return n
    return None


def kinetic_needed(branch) -> int | None:
    """Releases at which a kinetic force of DOMINANT_SHARE·F̄ would be resolved, with the
    branch's per-release scatter of F_k."""
    fk = branch.per_slip_kinetic_force[np.isfinite(branch.per_slip_kinetic_force)]
    if fk.size < 2:
        return None
    return releases_needed(float(fk.std(ddof=1)), DOMINANT_SHARE * branch.mean_force)


def _slip_window(tr, smoothing: float):
    """A release's time, wall position, stick index, sample interval and the odd
    Savitzky–Golay window of ``smoothing`` × the slip's duration."""
    t, x = tr["time"], tr["wall_position"]
    _, s = release_slip(t, x)
    dt = float(t[1] - t[0])
    return t, x, s, dt, int(round(smoothing * (t[s] - t[0]) / dt)) | 1


def branch_bins(traces, mass: float, law: tuple, load: float, edges=(0.2, 0.4, 0.6, 0.8, 1.0),
                smoothing: float = 0.1, corrected: bool = False) -> dict:
    """Where the loop sits: per branch and bin of v / v_peak, the mean over the releases of the
    film force (F_spring − M·a, Savitzky–Golay over ``smoothing`` of the slip, as the fit
    smooths) minus ``law`` (F_k, B, m_c), of the load's term P·A·dD/dx (``load`` = P·A, the
    same smoothing), and of the film force minus the samples' own law (F_k + B·v + m_c·a
    fitted to each release's smoothed samples); each a list of (mean, standard error).
    ``corrected``: the film force less the load's term in the first row (the law then
    being the corrected fit's)."""
    rows = {}
    samples_law = []
    for tr in traces:
        t, x, s, dt, w = _slip_window(tr, smoothing)
        v, a = (savgol_filter(x, w, 2, deriv=k, delta=dt) for k in (1, 2))
        force = savgol_filter(tr["spring_force"], w, 2) - mass * a
        dgap = savgol_filter(tr["gap"], w, 2, deriv=1, delta=dt)
        sl = slice(w // 2 + 1, s - w // 2 + 1)
        v, a, force, dgap = v[sl], a[sl], force[sl], dgap[sl]
        p = int(np.argmax(v))
        fast = v > edges[0] * v[p]
        coef = np.linalg.lstsq(np.column_stack([np.ones(fast.sum()), v[fast], a[fast]]),
                               force[fast], rcond=None)[0]
        samples_law.append(coef)
        work = load * dgap / v
        terms = {("film force − P·A·dD/dx − the law" if corrected else "film force − the law"):
                 force - corrected * work - (law[0] + law[1] * v + law[2] * a),
                 "P·A·dD/dx": work,
                 "film force − the samples' law": force - (coef[0] + coef[1] * v + coef[2] * a)}
        for branch, idx in (("accelerating", np.arange(p + 1)), ("decelerating", np.arange(p, v.size))):
            k = np.digitize(v[idx] / v[p], edges) - 1
            for name, arr in terms.items():
                rows.setdefault((branch, name), []).append(
                    [arr[idx][k == j].mean() if np.any(k == j) else np.nan
                     for j in range(len(edges) - 1)])
    out = {}
    for key, vals in rows.items():
        vals = np.array(vals)
        n = np.isfinite(vals).sum(axis=0)
        out[key] = list(zip(np.nanmean(vals, axis=0), np.nanstd(vals, axis=0, ddof=1) / np.sqrt(n)))
    c = np.array(samples_law)
    out["samples' law"] = list(zip(c.mean(axis=0), c.std(axis=0, ddof=1) / math.sqrt(len(c))))
    return out


def load_term_coefficient(traces, mass: float, floor: float = 0.2, smoothing: float = 0.1):
    """The load's work fitted as a term instead of taken out: per release, the one law's
    integral design (∫F_spring dt on 1, Δt, Δx, Δv of the smoothed velocity, the step's
    time past the peak) with the regressor ∫(dW_L/dt)/v dt beside it, whose coefficient is
    −c, c = 1 when the film force carries the whole load's work on the gap.  Returns the
    (mean, standard error) over the releases of F_k, B, m_c, c and the step."""
    from scipy.integrate import cumulative_trapezoid
    per = []
    for tr in traces:
        t, x, s, dt, w = _slip_window(tr, smoothing)
        g = savgol_filter(x[:s + 1], w, 2, deriv=1, delta=dt)
        p = int(np.argmax(g))
        fast = g > floor * g[p]
        fast[:w // 2 + 1] = fast[s - w // 2:] = False
        k = np.flatnonzero(fast)
        i = np.arange(k[0], k[-1] + 1)
        dtt = t[i] - t[i[0]]
        rate = np.gradient(tr["load_work"][:s + 1], t[:s + 1])[i]
        cols = [np.ones(i.size), dtt, x[i] - x[i[0]], g[i] - g[i[0]],
                cumulative_trapezoid(rate / np.maximum(g[i], floor * g[p]), t[i], initial=0.0),
                np.maximum(dtt - (t[p] - t[i[0]]), 0.0)]
        c = np.linalg.lstsq(np.column_stack(cols), cumulative_trapezoid(
            tr["spring_force"][i], t[i], initial=0.0), rcond=None)[0]
        per.append([c[1], c[2], c[3] - mass, -c[4], -c[5]])
    per = np.array(per)
    return list(zip(per.mean(axis=0), per.std(axis=0, ddof=1) / math.sqrt(len(per))))


def mean_gap_fit(traces, mass: float, members, points: int = 201, fit=fit_release_ensemble):
    """The fit with the load's work of the mean gap taken out: W_L averaged over the
    releases ``members`` (indices) at each share of the slip's duration, and that mean
    curve taken out of every release's film force (the gap's breathing averaged away)."""
    share, curves, shares = np.linspace(0.0, 1.0, points), [], []
    for tr in traces:
        _, s = release_slip(tr["time"], tr["wall_position"])
        u = (tr["time"] - tr["time"][0]) / (tr["time"][s] - tr["time"][0])
        curves.append(np.interp(share, u, tr["load_work"] - tr["load_work"][0]))
        shares.append(u)
    mean = np.mean([curves[j] for j in members], axis=0)
    return fit([tr | {"load_work": np.interp(u, share, mean)}
                for tr, u in zip(traces, shares)], mass=mass, load_work=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--viscosity", nargs=2, type=float, metavar=("ETA", "ERR"), required=True)
    ap.add_argument("--load-work", action="store_true",
                    help="take the load's work on the gap out of the film force")
    ap.add_argument("--per-release", action="store_true",
                    help="fit each release's slip and take their scatter (biased by the "
                         "film's noise) instead of the mean release with jackknife errors")
    a = ap.parse_args(argv)
    fitter = fit_releases if a.per_release else fit_release_ensemble
    if not a.per_release and len(a.runs) < 3:
        print(f"error: {len(a.runs)} run(s): the mean release's jackknife needs 3 or more "
              "(or --per-release)", file=sys.stderr)
        return 2
    traces, mass, film_mass, gaps, moves = [], None, None, [], []
    for run in a.runs:
        tr = np.genfromtxt(f"{run}/trace.csv", delimiter=",", names=True)
        traces.append({k: tr[k] for k in tr.dtype.names})
        with open(f"{run}/run.json", encoding="utf-8") as fh:
            record = json.load(fh)
        p = record["trace_parameters"]
        mass = p["mass"]
        pressure = record["scene"]["parameters"]["normal_pressure"]
        moves.append(release_gap(traces[-1], pressure=pressure, area=p["area"]))
        film_mass = record["derived"]["film_atoms"]   # m each
    fit = fitter(traces, mass=mass, load_work=a.load_work)
    with_mass = fit.one_law
    print(f"{len(traces)} releases, M = {mass:g}, "
          f"{'each release fitted' if a.per_release else 'the mean release fitted, jackknife errors'}"
          f"{', the load’s work on the gap taken out' if a.load_work else ''}: verdict {fit.verdict}, the {fit.verdict_from}'s "
          f"({fit.reason})")
    for br in (fit.decelerating, fit.accelerating, fit.whole, with_mass):
        name = "whole + m_c" if br is with_mass else br.branch
        mc = (f", m_c = {br.comoving_mass:.0f} ± {br.comoving_mass_stderr:.0f}"
              if br is with_mass else "")
        print(f"  {name:14s} F_k = {br.kinetic_force:.2f} ± {br.kinetic_force_stderr:.2f} "
              f"({br.kinetic_sigmas:+.1f} σ), B = {br.damping:.2f} ± {br.damping_stderr:.2f} "
              f"({br.damping_sigmas:+.1f} σ){mc}; F̄ = {br.mean_force:.2f}, "
              f"n = {br.exponent:.2f} ± {br.exponent_stderr:.2f}; verdict {br.verdict}; "
              f"releases the rule needs: {kinetic_needed(br)}")
        print(f"      per release{'' if a.per_release else ' (jackknife pseudo-values)'}: "
              f"F_k {np.round(br.per_slip_kinetic_force, 2).tolist()}, "
              f"B {np.round(br.per_slip_damping, 2).tolist()}")
    # the one law's condition: the loop step ruled out at half the one law's film force
    step_sd = fit.loop_step_stderr * math.sqrt(len(traces))
    print(f"  loop step beyond m_c, F_acc − F_dec = {fit.loop_step:.2f} ± "
          f"{fit.loop_step_stderr:.2f} ({fit.loop_step_sigmas:+.1f} σ); 95 % power at {RESOLVED_SIGMAS:.3g} σ for "
          f"{fit.detectable_loop_step:.2f} against F̄/2 = "
          f"{DOMINANT_SHARE * with_mass.mean_force:.2f}; releases that rules it out: "
          f"{releases_needed(step_sd, DOMINANT_SHARE * with_mass.mean_force)}")
    # the gap: the film at release against the film sliding, and the load's work on its opening
    def mean_se(vals):
        v = np.asarray(vals, float)
        return v.mean(axis=0), v.std(axis=0, ddof=1) / math.sqrt(len(v))
    for name, vals in (("gap at release", [m["at_release"] for m in moves]),
                       ("gap by fifths of the slip", [m["by_part"] for m in moves])):
        m_, se = mean_se(vals)
        print(f"  {name}: {np.round(m_, 3).tolist()} ± {np.round(se, 3).tolist()}")
    dil = np.array([m["dilation_force"] for m in moves])
    (fa, fd), (sa, sd) = mean_se(dil)
    ds, dse = mean_se(dil[:, 0] - dil[:, 1])
    print(f"  load's work on the gap's opening, P·A·ΔD/Δx: accelerating {fa:.2f} ± {sa:.2f}, "
          f"decelerating {fd:.2f} ± {sd:.2f}, difference {ds:.2f} ± {dse:.2f} ε/σ "
          f"(the loop step: {fit.loop_step:.2f} ± {fit.loop_step_stderr:.2f})")
    one = (with_mass.kinetic_force, with_mass.damping, with_mass.comoving_mass)
    bins = branch_bins(traces, mass, one, pressure * p["area"], corrected=a.load_work)
    (fk, sfk), (bb, sbb), (mc, smc) = bins.pop("samples' law")
    print(f"  where the loop sits (bins of v/v_peak 0.2-0.4-0.6-0.8-1; the law: the one law "
          f"above; the samples' law F_k = {fk:.2f} ± {sfk:.2f}, B = {bb:.2f} ± {sbb:.2f}, "
          f"m_c = {mc:.1f} ± {smc:.1f}):")
    for (branch, name), vals in bins.items():
        print(f"    {branch:12s} {name:34s} " + "  ".join(f"{m:+.2f} ± {e:.2f}" for m, e in vals))
    if a.load_work:
        (fk, sfk), (bb, sbb), (mc, smc), (c, sc), (st, sst) = load_term_coefficient(traces, mass)
        print(f"  the load's work as a fitted term (per release, with the step): c = {c:.2f} ± "
              f"{sc:.2f} of P·A (1: all of it in the film force), step {st:.2f} ± {sst:.2f}, "
              f"F_k = {fk:.2f} ± {sfk:.2f}, B = {bb:.2f} ± {sbb:.2f}, m_c = {mc:.0f} ± {smc:.0f}")
        n, half = len(traces), len(traces) // 2
        for name, members in (("all", range(n)), ("first half", range(half)),
                              ("second half", range(half, n))):
            f = mean_gap_fit(traces, mass, list(members), fit=fitter)
            o = f.one_law
            print(f"  the mean gap of {name} of the releases taken out: step {f.loop_step:.2f} ± "
                  f"{f.loop_step_stderr:.2f} ({f.loop_step_sigmas:+.1f} σ), one law F_k = "
                  f"{o.kinetic_force:.2f} ± {o.kinetic_force_stderr:.2f}, B = {o.damping:.2f} ± "
                  f"{o.damping_stderr:.2f}, m_c = {o.comoving_mass:.0f} ± "
                  f"{o.comoving_mass_stderr:.0f}; verdict {f.verdict} ({f.verdict_from})")
    widths = []
    for run in a.runs:
        prof = release_profile(run)
        widths.append((prof["width"], prof["width_stderr"]))
        print(f"  {run}: shares {np.round(prof['share'], 2).tolist()} ± "
              f"{np.round(prof['share_stderr'], 2).tolist()}; jumps {np.round(prof['jump'], 2).tolist()}"
              f"; {prof['location']}; W = {prof['width']:.2f} ± {prof['width_stderr']:.2f}")
    w = np.array(widths)
    wm = float(w[:, 0].mean())
    wse = float(w[:, 0].std(ddof=1) / math.sqrt(len(w))) if len(w) > 1 else float(w[0, 1])
    eta, eta_se = a.viscosity
    b = eta * prof["area"] / wm
    b_se = b * math.hypot(eta_se / eta, wse / wm)
    print(f"W = {wm:.2f} ± {wse:.2f}, A = {prof['area']:.2f}: eta*A/W = {b:.2f} ± {b_se:.2f}")
    for prof_run, tr in zip(a.runs, traces):
        gaps.append(float(np.mean(tr["gap"])))
    gap = float(np.mean(gaps))
    print(f"  co-moving mass of a quasi-static Couette film (film {film_mass} m, W = {wm:.2f}): "
          + ", ".join(f"D = {d:.2f} σ: {couette_comoving_mass(film_mass, d, max(wm, d)):.0f} m"
                      for d in (gap, gap - 1.0))
          + f" (mean gap {gap:.2f} σ; the fit: {with_mass.comoving_mass:.0f} ± "
          f"{with_mass.comoving_mass_stderr:.0f} m)")
    for name, br in (("decelerating", fit.decelerating), ("whole", fit.whole),
                     ("whole + m_c", with_mass)):
        r = br.damping / b
        print(f"  {name:14s} B / (eta*A/W) = {r:.2f} ± "
              f"{r * math.hypot(br.damping_stderr / br.damping, b_se / b):.2f}; "
              f"B − eta*A/W = {br.damping - b:.2f} ± {math.hypot(br.damping_stderr, b_se):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
