"""``viscosity``: the film's effective viscosity, from steady sliding, the slips and the profiles.

The physics is :mod:`filmfriction.analysis.viscosity`; this file writes into
``analysis.json["viscosity"]`` what the run allows of

* ``steady``: η_eff = (F/A)/(V/D) over the last half of a ``smooth`` run;
* ``profile``: the velocity profile's internal shear rate and the slip at
  each wall (``profiles/`` of the run directory), and ``internal``: η from the
  steady stress over that shear rate when the film shears inside;
* ``from_slip``: Klein's Eq. (1) fitted to each analysed slip, η_eff = (B − γM)·D/A,
  with the fitted ``damping`` and ``eta_eff`` of each slip in
  ``analysis_cycles.csv`` (unprefixed);

and shows in the report the table, η_eff of each slip with their mean, and
the velocity profile across the gap with the density.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import viscosity
from ..stickslip import Regime
from ..files.trace import MissingInput, unit
from ..files.util import finite_or_none
from .observable import Context, Observable, format_estimate, format_value, png_bytes, pyplot
from ..film_state import FRAMES_NOT_CUT

__all__ = ["Viscosity", "read_profiles", "averaged_profile"]

VELOCITY_PROFILE = "profiles/velocity.profile"
DENSITY_PROFILE = "profiles/density.profile"


def averaged_profile(path, prefixes: tuple, fallback: str | None = None):
    """One column of a LAMMPS ``ave/chunk`` profile, averaged over the last half
    of its frames: ``(z, values, name)``, the column the first of ``prefixes``
    begins (else ``fallback``)."""
    from ..files.chunk_file import read_chunk_file

    prof = read_chunk_file(path)
    z = np.array([c["coord"][0][0] for c in prof.chunks])
    names = list(prof.chunks[0])
    name = next((k for p in prefixes for k in names if k.startswith(p)), fallback)
    if name is None:
        raise KeyError(f"no column beginning with {' or '.join(prefixes)}")
    last = slice(len(prof.timesteps) // 2, None)
    return z, np.array([np.mean(c[name][last]) for c in prof.chunks]), name


def read_profiles(velocity_path, density_path=None) -> dict:
    """The time-averaged profiles across the gap over the last half of their frames.

    Returns
    -------
    dict
        ``z`` (bin centres), ``vx`` (the sliding direction's velocity),
        ``density`` and ``density_column`` (the density file's ``density*``
        column, else the velocity file's atom count ``ncount``).
    """
    z, vx, _ = averaged_profile(velocity_path, ("vx", "v"))
    if density_path is not None:
        _, rho, col = averaged_profile(density_path, ("density",), "ncount")
    else:
        _, rho, col = averaged_profile(velocity_path, ("ncount",))
    return {"z": z, "vx": vx, "density": rho, "density_column": col}


def _profile_section(ctx: Context, prof_v: Path, prof_d: Path | None) -> dict:
    trace, half = ctx.trace, ctx.last_half
    prof = read_profiles(prof_v, prof_d)
    v_top, _ = (float(np.mean(trace.columns["wall_velocity"][half])), "") \
        if trace.has("wall_velocity") else trace.drive_velocity()
    if v_top is None:
        raise ValueError("top-wall velocity unknown (no wall_velocity column or drive velocity)")
    ps = viscosity.profile_shear(prof["z"], prof["vx"], prof["density"], wall_velocity_top=v_top)
    out = {"shear_rate": ctx.value(ps.shear_rate, ps.shear_rate_stderr, "shear_rate"),
           "slip_bottom": ctx.value(ps.slip_bottom, None, "velocity"),
           "slip_top": ctx.value(ps.slip_top, None, "velocity"),
           "film_edges": [ps.z_bottom, ps.z_top], "frames": "last half"}
    # where the wall's velocity is taken up: inside the film, or by slip at a wall
    if v_top:
        inside = ps.shear_rate * (ps.z_top - ps.z_bottom) / v_top
        shares = {"inside": inside, "bottom_wall": ps.slip_bottom / v_top,
                  "top_wall": ps.slip_top / v_top}
        out["velocity_shares"] = {k: finite_or_none(v) for k, v in shares.items()}
        out["shears"] = ("inside the film" if inside >= 0.5 else
                         "by slip at the " + ("bottom" if ps.slip_bottom >= ps.slip_top else "top")
                         + " wall")
    return out


class Viscosity(Observable):
    """η_eff from steady sliding, from the velocity profile and from each slip."""

    key = "viscosity"
    title = "Viscosity of this run: steady sliding, the slips, the velocity profile"
    order = 40
    column_prefix = ""
    table_header = ("viscosity of this run", "value")
    absent = "No viscosity"

    def compute(self, ctx: Context) -> tuple[dict, dict]:
        trace, p = ctx.trace, ctx.trace.parameters
        t, f, half = trace.time, trace.spring_force, ctx.last_half
        visc: dict = {}
        per_slip: dict = {}
        try:
            if ctx.regime != Regime.SMOOTH:
                why = ctx.regime_note or f"regime is {ctx.regime}"
                raise MissingInput("steady sliding", f"steady viscosity ({why})")
            area = p.require("area", "η_eff = (F/A)/γ̇")
            v_drive, v_src = trace.drive_velocity()
            if v_drive is None:
                raise MissingInput("--drive-velocity", "γ̇ = V/D")
            d, d_src = trace.film_thickness(half)
            # the run's mount dashpot acts on the wall's velocity relative to the
            # drive: in steady sliding it exerts no mean force
            sv = viscosity.steady_viscosity(f[half], area, v_drive, d)
            visc["steady"] = {
                "eta_eff": ctx.value(sv.eta_eff, sv.eta_eff_stderr, "viscosity"),
                "shear_rate": ctx.value(sv.shear_rate, None, "shear_rate"),
                "shear_stress": ctx.value(sv.shear_stress, None, "stress"),
                "thickness": ctx.value(sv.thickness, None, "length", source=d_src),
                "velocity_source": v_src, "samples": "last half of the trace"}
        except MissingInput as exc:
            ctx.skip_part("viscosity.steady", exc)
        prof_v = trace.optional_path(VELOCITY_PROFILE)
        prof_d = trace.optional_path(DENSITY_PROFILE)
        if prof_v is not None and ctx.sections.get("film_state_change"):
            ctx.skip_part("viscosity.profile", FRAMES_NOT_CUT.format(what="the profiles'"))
        elif prof_v is not None:
            try:
                visc["profile"] = _profile_section(ctx, prof_v, prof_d)
                prof, steady = visc["profile"], visc.get("steady")
                # η from the film's own shear rate, where it shears inside (steady sliding)
                g = (prof.get("shear_rate") or {}).get("mean")
                if steady and g and g > 0 and prof.get("shears") == "inside the film":
                    stress = steady["shear_stress"]["mean"]
                    visc["internal"] = {
                        "eta_eff": ctx.value(stress / g, None, "viscosity"),
                        "shear_rate": ctx.value(g, None, "shear_rate"),
                        "note": "steady shear stress over the velocity profile's internal shear "
                                "rate (the film shears inside)"}
                elif steady:
                    ctx.skip_part("viscosity.internal",
                                  f"the film shears {prof.get('shears', 'nowhere measurable')}: "
                                  "no internal shear rate to divide by")
            except (ValueError, RuntimeError, KeyError) as exc:
                ctx.skip_part("viscosity.profile", f"{prof_v}: {exc}")
        try:
            if len(ctx.all_slips) == 0:
                raise MissingInput("slips", "the slip fit")
            k = p.require("spring_constant", "the slip fit")
            mass = p.require("mass", "the slip fit")
            area = p.require("area", "η_eff = B·D/A")
            d, d_src = trace.film_thickness()
            v_drive, v_src = trace.drive_velocity()
            if v_drive is None:
                v_drive, v_src = 0.0, "spring end taken fixed (no drive velocity given)"
            sl = viscosity.slip_viscosity(t, f, ctx.table, mass=mass, spring_constant=k,
                                          area=area, thickness=d, drive_velocity=v_drive,
                                          mount_damping=p.mount_damping or 0.0)
            b_ok = sl.damping[np.isfinite(sl.damping)]
            # a film damping below the mount's dashpot is unphysical: said, slip by slip
            negative = [ctx.skip + i + 1 for i, e in enumerate(sl.eta_eff_per_slip) if e < 0]
            visc["from_slip"] = {
                "eta_eff": ctx.value(sl.eta_eff, sl.eta_eff_stderr, "viscosity",
                                     fit_stderr=finite_or_none(sl.eta_eff_fit_stderr), n=sl.n),
                "damping": ctx.value(b_ok.mean() if b_ok.size else math.nan,
                                     b_ok.std(ddof=1) / math.sqrt(b_ok.size) if b_ok.size > 1
                                     else math.nan, "damping"),
                "thickness": ctx.value(d, None, "length", source=d_src),
                "velocity_source": v_src, "failures": list(sl.failures)}
            if negative:
                visc["from_slip"]["unphysical"] = {
                    "slips": negative,
                    "note": f"{len(negative)} of {sl.n} slips give η_eff < 0 (their fitted B "
                            "is below the mount's dashpot): the film's drag is not resolved "
                            "slip by slip; they are kept in the mean, which stays unbiased"}
            per_slip = {"damping": sl.damping.tolist(), "eta_eff": sl.eta_eff_per_slip.tolist()}
        except MissingInput as exc:
            ctx.skip_part("viscosity.from_slip", exc)
        return visc, per_slip

    # -- the report ----------------------------------------------------------
    def rows(self, section: dict) -> list[tuple[str, str]]:
        rows = []
        steady = section.get("steady")
        if steady:
            rows += [("steady sliding: η_eff = (F/A)/(V/D)", format_estimate(steady["eta_eff"])),
                     ("steady sliding: shear rate V/D", format_estimate(steady["shear_rate"])),
                     ("steady sliding: shear stress F/A", format_estimate(steady["shear_stress"]))]
        slip = section.get("from_slip")
        if slip:
            rows += [("slips (Klein's Eq. 1): η_eff = (B − γM)·D/A",
                      format_estimate(slip["eta_eff"])),
                     ("slips: fitted damping B (mount included)",
                      format_estimate(slip["damping"])),
                     ("slips: film thickness D", f"{format_estimate(slip['thickness'])} "
                                                 f"({slip['thickness'].get('source', '')})")]
        prof = section.get("profile")
        if prof:
            rows += [("profile: internal shear rate", format_estimate(prof["shear_rate"])),
                     ("profile: slip at the bottom wall", format_estimate(prof["slip_bottom"])),
                     ("profile: slip at the top wall", format_estimate(prof["slip_top"]))]
            if prof.get("shears"):
                rows.append(("profile: the film shears", prof["shears"]))
            shares = prof.get("velocity_shares") or {}
            if shares:
                rows.append(("profile: shares of the wall's velocity (inside / bottom / top)",
                             " / ".join(format_value(shares.get(k), 2)
                                        for k in ("inside", "bottom_wall", "top_wall"))))
        internal = section.get("internal")
        if internal:
            rows.append(("η from the internal shear rate", format_estimate(internal["eta_eff"])))
        return rows

    def notes(self, section: dict) -> list[str]:
        slip = section.get("from_slip") or {}
        failures = slip.get("failures") or []
        out = [f"Slip fits that failed: {'; '.join(map(str, failures))}."] if failures else []
        bad = slip.get("unphysical")
        if bad:
            out.append(f"Unphysical: slip{'s' if len(bad['slips']) > 1 else ''} "
                       f"{', '.join(map(str, bad['slips']))}: {bad['note']}.")
        if slip or section.get("steady"):
            out.append("These are the analysis' own estimates; the run's one η_eff, and which "
                       "of these it is, is named in the section on the effective viscosity "
                       "(from `filmfriction calibrate`).")
        return out

    def figures(self, run) -> list[tuple[str, bytes, str]]:
        out = []
        section = run.analysis.get(self.key) or {}
        eta = np.asarray(run.cycles.get("eta_eff", []), float)[run.skip:]
        if section.get("from_slip") and np.isfinite(eta).any():
            out.append(("eta-per-slip", fig_eta_per_slip(run, eta, section["from_slip"]),
                        "η_eff of each analysed slip from Klein's Eq. (1) fitted to it, with "
                        "their mean and its standard error (band); a negative one (red "
                        "cross) is unphysical."))
        prof_v = run.run_dir / VELOCITY_PROFILE
        if prof_v.exists():
            prof_d = run.run_dir / DENSITY_PROFILE
            out.append(("velocity-profile",
                        fig_velocity_profile(run, read_profiles(
                            prof_v, prof_d if prof_d.exists() else None),
                            section.get("profile")),
                        "The film's velocity across the gap (last half of the run, time "
                        "averaged; bins holding at least a tenth of the peak density) beside "
                        "its density, with the line fitted to it (the internal shear rate) and "
                        "the walls' velocities."))
        return out


def fig_eta_per_slip(run, eta: np.ndarray, from_slip: dict) -> bytes:
    """η_eff of each analysed slip with the mean ± stderr."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 3.4))
    slip = np.arange(run.skip + 1, run.skip + eta.size + 1)
    ok = np.isfinite(eta) & (eta >= 0)
    ax.plot(slip[ok], eta[ok], "o", color="tab:blue", ms=6, label="one slip")
    bad = np.isfinite(eta) & (eta < 0)
    if bad.any():
        ax.plot(slip[bad], eta[bad], "x", color="tab:red", ms=8, mew=2,
                label="unphysical (η_eff < 0)")
        ax.axhline(0.0, color="0.5", lw=0.8)
    mean = from_slip["eta_eff"].get("mean")
    err = from_slip["eta_eff"].get("stderr")
    units = from_slip["eta_eff"]["units"]
    if mean is not None:
        ax.axhline(mean, color="tab:red", lw=1.2,
                   label=f"mean {mean:.3g}" + (f" ± {err:.2g}" if err is not None else "")
                   + f" {units}")
        if err is not None:
            ax.axhspan(mean - err, mean + err, color="tab:red", alpha=0.15, lw=0)
    ax.set_xlabel("slip number [1]")
    ax.set_ylabel(f"η_eff [{units}]")
    ax.set_xticks(slip)
    ax.legend(fontsize=8, loc="best")
    return png_bytes(fig)


def fig_velocity_profile(run, prof: dict, section: dict | None) -> bytes:
    """v_x(z) of the film's occupied bins (marker area ∝ density) beside the
    density across the gap, with the walls' velocities and the fitted internal shear."""
    plt = pyplot()
    lab = lambda q: unit(run.trace.units, q)  # noqa: E731
    fig, (ax, axd) = plt.subplots(1, 2, figsize=(8.4, 3.8), sharey=True,
                                  gridspec_kw={"width_ratios": [3, 2]})
    z, vx, rho = prof["z"], prof["vx"], prof["density"]
    occupied = rho >= 0.1 * rho.max()      # the bins profile_shear fits (the film's)
    ax.scatter(vx[occupied], z[occupied], s=40 * rho[occupied] / rho.max(), color="tab:blue",
               label="film bins (area ∝ density)")
    ax.axvline(0.0, color="0.4", lw=0.8, ls="-.", label="bottom wall at rest")
    v_drive, _ = run.trace.drive_velocity()
    if v_drive:
        ax.axvline(v_drive, color="0.4", lw=0.8, ls="--", label="drive velocity V")
    edges = section.get("film_edges") if section else None
    g = ((section or {}).get("shear_rate") or {}).get("mean")
    if edges and g is not None and occupied.sum() >= 2:
        zb, zt = edges
        # the fitted line, through the film's density-weighted mean velocity at its mean height
        w = rho[occupied]
        zc, vc = np.average(z[occupied], weights=w), np.average(vx[occupied], weights=w)
        zz = np.array([zb, zt])
        ax.plot(vc + g * (zz - zc), zz, "-", color="tab:red", lw=1.5,
                label=f"internal shear rate {g:.3g} {lab('shear_rate')}")
    if occupied.any():
        lo, hi = float(z[occupied].min()), float(z[occupied].max())
        pad = 0.15 * (hi - lo) + 0.5
        ax.set_ylim(lo - pad, hi + pad)
    ax.set_xlabel(f"velocity v_x [{lab('velocity')}]")
    ax.set_ylabel(f"z [{lab('length')}]")
    ax.legend(fontsize=7, loc="upper left")
    axd.plot(rho, z, color="tab:gray")
    col = prof["density_column"]
    axd.set_xlabel(f"number density [{lab('number_density')}]" if col.startswith("density")
                   else "atoms per bin [1]")
    fig.tight_layout()
    return png_bytes(fig)
