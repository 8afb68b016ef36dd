"""The film's random force of the slip-law controls, calibrated to the MD at each slider's scale.

Each noise is the keywords of :func:`~filmfriction.analysis.groundtruth.random_force.slide` (LJ
units): u an AR(1) of ``velocity_noise`` σ/τ rms and correlation ``velocity_correlation`` per
sample (0.25 τ), the wall's thermal rattling white at ``rattle`` σ/τ.  Each is calibrated on the
MD's analysed slips against replicas of a control measured alike
(:mod:`~filmfriction.analysis.groundtruth.md_noise`;
``benchmarks/slip_law/md_noise_calibration.py``), and the residuals it was matched on say
whether it stands for the walls' registry force too (read without the registry's terms) or
only for what is left beside it (``*_REGISTRY_NOISE``: the noise of controls that carry a
registry force).  The scales that use them:
:mod:`~filmfriction.analysis.groundtruth.slip_law_controls`.

Example
-------
>>> scaled(STIFF_NOISE, 2 / 3) == STIFF_REGISTRY_NOISE
True
>>> round(M1E4_REGISTRY_NOISE["velocity_noise"], 3)
0.014
"""
from __future__ import annotations

__all__ = ["MD_NOISE", "RESIDUAL_AS_NOISE", "scaled", "STIFF_NOISE", "STIFF_REGISTRY_NOISE",
           "M1E4_NOISE", "M1E4_REGISTRY_NOISE", "LIGHT_NOISE",
           "LIGHT_REGISTRY_NOISE", "M3E3_NOISE", "M3E3_REGISTRY_NOISE",
           "K16M3E3_REGISTRY_NOISE", "M25E3_REGISTRY_NOISE", "K4M3E3_REGISTRY_NOISE"]

#: The film's random force of the controls, calibrated to the MD (LJ units; the keywords of
#: :func:`~filmfriction.analysis.groundtruth.random_force.slide`): u an AR(1) of 0.45 σ/τ
#: rms and correlation 0.9 per 0.25 τ (2.4 τ), the wall's rattling white at
#: √(kT/M) = 0.15 σ/τ.  On the 47 slips of three ``sfb-similar`` runs of 2.8 M steps
#: (f952bc8) and on 40 random-force replicas of the ``viscous`` control, measured alike
#: (:mod:`~filmfriction.analysis.groundtruth.md_noise`, each slip 2.5 τ off its ends):
#:
#: * the wall's velocity changes over 0.25, 1, 2 τ by 0.29, 0.33, 0.36 σ/τ rms in the MD,
#:   0.28, 0.34, 0.34 in the replicas;
#: * the residual of F_k + B·v with Δt², Δt³ fitted besides (the part faster than the
#:   slip): MD 0.229 ± 0.007 σ/τ, autocorrelation 0.19, −0.03, −0.05 at 0.25, 1, 2 τ;
#:   replicas 0.223, 0.23, −0.07, −0.08;
#: * the plain residual of F_k + B·v: MD 0.69 ± 0.05 σ/τ, 0.78, 0.57, 0.38; replicas 0.34,
#:   0.61, 0.27, 0.04.  No process of this family gives the MD's (the fit takes up the
#:   slow part of a force that moves the wall; a u large enough for the rms, 1.9 σ/τ,
#:   makes the wall jitter twice as much as the MD's): the rest of the MD's residual is
#:   a shape as long as the slip, half of it common to all slips, that F_k + B·v misses.
#:
#: ``python benchmarks/slip_law/md_noise_calibration.py RUN …`` (docs/results/slip-law.md, "The
#: MD's noise").
MD_NOISE = {"velocity_noise": 0.45, "velocity_correlation": 0.9, "rattle": 0.15}

#: The MD's plain residual taken as u itself (0.75 σ/τ, 0.9 per 0.25 τ, rattling 0.25):
#: the wall jitters 1.6 times as much as the MD's (0.46, 0.56, 0.58 σ/τ over 0.25, 1,
#: 2 τ).  Kept for comparison.
RESIDUAL_AS_NOISE = {"velocity_noise": 0.75, "velocity_correlation": 0.9, "rattle": 0.25}


def scaled(noise: dict, factor: float) -> dict:
    """``noise`` with its amplitudes (u's rms, the rattling) times ``factor``, its
    correlations kept."""
    return {k: (v if k == "velocity_correlation" else
                tuple(factor * x for x in v) if isinstance(v, (tuple, list)) else factor * v)
            for k, v in noise.items()}


#: The film's random force at the heavy slider's scale, calibrated as :data:`MD_NOISE` on the
#: 50 slips of six ``sfb-thick-stiff`` runs against 40 replicas of the stiff ``viscous``
#: control: u an AR(1) of 0.0042 σ/τ rms, 0.993 per 0.25 τ (36 τ), no rattling (the heavy
#: wall's thermal motion is slow).  Its fast residual (with Δt², Δt³: 0.00284, the MD's 0.00287
#: ± 0.00012) and jitter over 16 τ are the MD's read without the walls' registry force, which
#: it therefore carries as noise (docs/results/slip-law.md, "Controls at the heavy slider's scale").
STIFF_NOISE = {"velocity_noise": 0.0042, "velocity_correlation": 0.993, "rattle": 0.0}
#: The same beside the registry force: u 0.0028 σ/τ at 0.993, the residuals of the MD (ten
#: runs, 89 slips) and of replicas whose mix carries 20 ε/σ at 1.1 σ read with the registry's
#: terms (fast residual 0.00161, the MD's 0.00158 ± 0.00007: docs/results/slip-law.md, "The
#: MD's noise beside the registry").  The noise of controls that carry a registry force.
STIFF_REGISTRY_NOISE = scaled(STIFF_NOISE, 2 / 3)

#: The film's random force at M = 10⁴, calibrated as :data:`STIFF_NOISE` on the 137 analysed
#: slips of the ten M = 10⁴ runs (seeds 1–5, 8–12; 40 replicas of this scale's ``viscous``
#: control, measured alike, 10 slips each; a grid of u 0.018–0.026 σ/τ at 0.98–0.998 per
#: sample scanned before, 20 replicas each): u an AR(1) of 0.024 σ/τ rms and correlation
#: 0.99 per 0.25 τ (25 τ), no rattling (√(kT/M) = 0.0079 σ/τ white would make the wall jitter
#: 10 times the MD's over 0.25 τ).  The residual with Δt², Δt³ fitted besides (0.0103, the
#: MD's 0.0102 ± 0.0003), the plain residual (0.0124, the MD's 0.0126 ± 0.0004) and its mean
#: shape's share (0.09, the MD's 0.09) are the MD's, the wall's velocity change over 8 τ
#: 1.06 times the MD's (0.0186 for 0.0176 σ/τ); over 0.25, 1, 4 τ the replicas' wall
#: jitters 3.0, 1.9 and 1.3 times the MD's and their residual is less correlated at 1–4 τ
#: (0.75, 0.23 for the MD's 0.91, 0.44): below the slip's tenth (≈ 11 τ) the MD's wall is
#: smoother than any process of this family (docs/results/slip-law.md, "Controls at the
#: M = 10⁴ scale of the K = 8 film").
M1E4_NOISE = {"velocity_noise": 0.024, "velocity_correlation": 0.99, "rattle": 0.0}
#: The same beside the registry force: u 0.014 σ/τ at 0.99 (0.58 of :data:`M1E4_NOISE`), the
#: residuals of six M = 10⁴ runs (seeds 1–6) and of 40 replicas of the scale's mix of share
#: 0.5 carrying 20 ε/σ at 1.1 σ, read with the registry's terms (fast residual 0.00540, the
#: MD's 0.00541 ± 0.00022; u 0.012 and 0.016 give 0.00480 and 0.00613, :data:`M1E4_NOISE`
#: 0.00850: docs/results/slip-law.md, "A viscous force that lags").
M1E4_REGISTRY_NOISE = {"velocity_noise": 0.014, "velocity_correlation": 0.99, "rattle": 0.0}

#: The film's random force at M = 10² and 10³, calibrated as :data:`M1E4_NOISE` on the MD's
#: analysed slips of 20 s or longer (93 of the 20 M = 10² runs', 111 of the 8 M = 10³ runs')
#: against 40 replicas of the scale's mix of viscous share 0.26 (0.25) whose film carries
#: m_c = 179 m (243 m), the one law's readings (without it the slips are too brief to
#: measure): u an AR(1) of 0.3 σ/τ rms, 0.94 per 0.25 τ (4 τ) at M = 10²: the wall's
#: velocity change over 0.25, 1, 2 τ 0.102, 0.188, 0.241 σ/τ (MD 0.103, 0.197, 0.216), the
#: residual 0.193 (MD 0.190 ± 0.007), with Δt², Δt³ fitted besides 0.125 (MD 0.127); u of
#: 0.1 σ/τ, 0.98 (12 τ) at M = 10³: 0.020, 0.039, 0.074 over 0.25, 1, 4 τ (MD 0.012, 0.034,
#: 0.077), residual 0.043 (MD 0.049 ± 0.002), 0.034 with Δt², Δt³ (MD 0.038): as at the
#: heavier scales the MD's wall is smoother over the shortest lags.
#: ``python benchmarks/slip_law/md_noise_calibration.py RUN… --scale m1e2 --share 0.26
#: --comoving-mass 179 --lags 1 4 8 16 --noise U RHO 0`` (m1e3: 0.25, 243, lags 1 4 16 32).
LIGHT_NOISE = {1e2: {"velocity_noise": 0.3, "velocity_correlation": 0.94, "rattle": 0.0},
               1e3: {"velocity_noise": 0.1, "velocity_correlation": 0.98, "rattle": 0.0}}
#: The same beside the registry force: :data:`LIGHT_NOISE`'s processes (the registry's terms
#: take little of the light sliders' residual).  Read with the registry's terms, against 40
#: replicas of the scale's mix carrying 20 ε/σ at 1.1 σ: at M = 10³ the eight runs' fast
#: residual 0.0269 ± 0.0009 σ/τ, the replicas' (share 0.5) 0.0281; at M = 10² the eight runs'
#: (37 slips of 20 τ or longer) 0.117 ± 0.003 and the wall's velocity change over 0.25, 1, 2 τ
#: 0.104, 0.200, 0.219 σ/τ, the replicas' (share 0.26, m_c 179 m) 0.108 ± 0.003 (2.1 combined
#: errors low) and 0.100, 0.186, 0.239 (u 0.33: 0.125 ± 0.007, but 0.116, 0.213, 0.278, the
#: wall jittering more than the MD's): kept, the fast residual a little low at M = 10²
#: (docs/results/slip-law.md, "A viscous force that lags").
LIGHT_REGISTRY_NOISE = {mass: dict(noise) for mass, noise in LIGHT_NOISE.items()}

#: The film's random force at M = 3×10³, calibrated as :data:`M1E4_NOISE` on the 118 analysed
#: slips of the mass ladder's eight M = 3×10³ runs against 40 replicas of the scale's mix of
#: share 0.5: read without the registry's terms u an AR(1) of 0.07 σ/τ rms, 0.99 per 0.25 τ
#: (25 τ): fast residual (with Δt², Δt³) 0.0212 for the MD's 0.0207 ± 0.0006 σ/τ, plain
#: 0.0256 for 0.0257 (u 0.05 and 0.08 give 0.0158 and 0.0237).  Beside the registry force
#: (replicas carrying 20 ε/σ at 1.1 σ, every residual read with the registry's terms) u 0.05
#: at 0.99: 0.0129 ± 0.0002 for the MD's 0.0131 ± 0.0005 (u 0.035 gives 0.0095; the plain
#: noise, 0.0171); the wall's velocity change over 0.25, 1,
#: 4, 8 τ 0.0071, 0.0144, 0.0296, 0.0400 σ/τ for the MD's 0.0038, 0.0115, 0.0316, 0.0457 (its
#: wall smoother over the shortest lags, as at the other scales).
#: ``python benchmarks/slip_law/md_noise_calibration.py RUN… --scale m3e3 --replicas 40
#: --lags 1 4 16 32 64 --share 0.5 [--corrugation 20 1.1 -0.97 --registry-period 1.1]
#: --noise U 0.99 0`` (docs/results/slip-law.md, "A viscous force that lags").
M3E3_NOISE = {"velocity_noise": 0.07, "velocity_correlation": 0.99, "rattle": 0.0}
M3E3_REGISTRY_NOISE = {"velocity_noise": 0.05, "velocity_correlation": 0.99, "rattle": 0.0}
#: The same film at M = 3×10³ on a spring twice as stiff (K = 16), calibrated alike on the 128
#: slips of that rung's eight runs beside the registry force: u 0.055 at 0.99 leaves a fast
#: residual of 0.0109 ± 0.0001 for the MD's 0.0112 ± 0.0004 σ/τ, plain 0.0137 for 0.0146
#: (u 0.05: 0.0102, u 0.06: 0.0117); ``--scale k16m3e3``, the rest as above.
K16M3E3_REGISTRY_NOISE = {"velocity_noise": 0.055, "velocity_correlation": 0.99, "rattle": 0.0}
#: The film at M = 2.5×10³ (K = 8), calibrated alike on the 220 slips of that rung's sixteen
#: runs beside the registry force: u 0.055 at 0.99 leaves a fast residual of 0.0140 ± 0.0002
#: for the MD's 0.0139 ± 0.0003 σ/τ (u 0.06: 0.0148); ``--scale m25e3``.
M25E3_REGISTRY_NOISE = {"velocity_noise": 0.055, "velocity_correlation": 0.99, "rattle": 0.0}
#: The film at M = 3×10³ on a spring half as stiff (K = 4), calibrated alike on the 154 slips of
#: that rung's sixteen runs beside the registry force, against replicas of its mix of share 0.3
#: (the rung's own viscous share): u 0.043 at 0.99 leaves a fast residual of 0.0140 ± 0.0002
#: for the MD's 0.0140 ± 0.0004 σ/τ, plain 0.0173 for 0.0175 (u 0.04: 0.0130, u 0.05: 0.0156);
#: ``--scale k4m3e3 --share 0.3``, the rest as above.
K4M3E3_REGISTRY_NOISE = {"velocity_noise": 0.043, "velocity_correlation": 0.99, "rattle": 0.0}
