"""The walls' registry force and the lag of the film's viscous force, read on controls of known
kind: a registry constant, trailing the wall or weighted by the slip's branch
(benchmarks/slip_law/registry_spectrum.py --branches), and a viscous force that lags by a
slip distance (benchmarks/slip_law/viscous_lag_profile.py).  The MD read against them:
docs/results/slip-law.md, "The registry force on each branch of the slip" and "A viscous
force that lags by a distance, not a time".
"""
import pytest

from filmfriction.analysis.groundtruth.pooled_controls import pooled_runs
from filmfriction.analysis.groundtruth.slip_law_controls import SCALES
from filmfriction.analysis.slip_law.slip_law_cycles import MD_NOISE_TIME

QUIET = {"velocity_noise": 0.0, "velocity_correlation": 0.0, "rattle": 0.0}
STIFF = SCALES["stiff"]


def _branch_differences(main, capsys, argv):
    """The branch table's rows (accelerating − decelerating, first − second half) of each
    pool: F_k, B, the first harmonic, its phase, the second harmonic."""
    assert main(argv) == 0
    out = capsys.readouterr().out
    rows = [r for r in out.splitlines() if r.startswith("| ") and "samples" not in r]
    cells = [[tuple(map(float, c.split(" ± "))) for c in r.split("|")[3:-1]] for r in rows]
    return cells


def test_a_constant_registry_force_reads_nearly_alike_on_both_branches(benchmark_module,
                                                                        capsys):
    # the branch table's ground truth: controls whose registry force is one amplitude and
    # phase everywhere (20 ε/σ at −0.97 rad, the rung's size at M = 10⁴) read the first
    # harmonic on the accelerating and the decelerating branch within 2 ε/σ and 0.15 rad of
    # each other (the controls' spread the MD's differences are read against), the
    # decelerating branch's phase within 0.1 rad of the truth and its amplitude low (the
    # smoothing of the force over 5 τ), and the halves of the slips as alike
    main = benchmark_module("slip_law/registry_spectrum").main
    cells = _branch_differences(main, capsys, ["--control", "m1e4", "12", "13", "--pools",
                                               "1", "--window", "5"])
    acc, dec, branches, first, second, halves = cells
    for diff in (branches, halves):
        assert abs(diff[2][0]) < 2.5 and abs(diff[3][0]) < 0.15, diff
    assert 14.0 < dec[2][0] < 20.0 and abs(dec[3][0] + 0.97) < 0.1, dec
    with pytest.raises(SystemExit):
        main(["--control", "klein", "6", "6"])
    assert "SCALE one of" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main([])
    assert "RUN_DIR… or --control" in capsys.readouterr().err


def test_a_registry_that_trails_the_wall_reads_its_phase_behind_and_ahead_while_speeding_up(
        benchmark_module, capsys):
    # ``lagged-registry`` controls (τ_g 5 τ at M = 10⁴) against the same pool with the
    # registry in step: the film's registry trails the wall by ≈ v·τ_g, so the whole phase
    # reads ≈ 2π·v̄·τ_g/λ behind −0.97 rad, and by less while the slip speeds up than while it
    # slows, so the accelerating branch's phase reads further ahead of the decelerating's
    main = benchmark_module("slip_law/registry_spectrum").main
    argv = ["--control", "m1e4", "12", "13", "--pools", "1", "--window", "5"]
    in_step = _branch_differences(main, capsys, argv)
    trailing = _branch_differences(main, capsys, argv + ["--registry-lag", "5"])
    assert trailing[1][3][0] < -0.97 - 0.5, trailing[1]
    assert trailing[2][3][0] > in_step[2][3][0], (trailing[2], in_step[2])


def test_a_registry_weighted_by_the_slips_branch_reads_weaker_and_ahead_while_speeding_up(
        benchmark_module, capsys):
    # ``branching-registry`` controls at M = 10⁴ against the same pool with a constant
    # registry: a first harmonic 0.4 weaker and 1 rad ahead and a second harmonic
    # (10 ε/σ) twice as strong while the slip speeds up read so on the branch table (the
    # constant registry's differences within 2.5 ε/σ, 0.15 rad: the test above)
    main = benchmark_module("slip_law/registry_spectrum").main
    argv = ["--control", "m1e4", "12", "13", "--pools", "1", "--window", "5"]
    constant = _branch_differences(main, capsys, argv)
    branching = _branch_differences(main, capsys, argv + ["--branching", "10", "-1.58", "0.4",
                                                          "1.0", "1.0"])
    diff, const = branching[2], constant[2]
    assert diff[2][0] < const[2][0] - 3.0, (diff, const)          # the first harmonic
    assert diff[3][0] > const[3][0] + 0.2, (diff, const)          # its phase
    assert diff[4][0] > 3.0, diff                                 # the second harmonic
    with pytest.raises(SystemExit):
        main(argv + ["--branching", "10", "0", "1.5", "0", "0"])
    assert "W1 <= 1" in capsys.readouterr().err


def test_a_viscous_force_lagging_by_a_distance_reads_as_a_time_lag_of_that_distance_over_v(
        benchmark_module):
    # ``distance-lag`` controls (d = 0.3 σ), noise-free, at M = 10⁵ and 10⁴: the lag profile
    # reads each as a time lag τ̂ of about d over the slips' mean velocity, so τ̂ differs
    # between the scales as 1/v̄ (a lag in time would read one τ̂ at both)
    vlp = benchmark_module("slip_law/viscous_lag_profile")
    lags = [0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 15.0, 20.0, 25.0, 30.0, 40.0]
    tau, speed = {}, {}
    for name in ("stiff", "m1e4"):
        sc = SCALES[name]
        rs, vd = pooled_runs("x", 4, 4, share=0.5, scale=sc, noise=QUIET,
                             corrugation=(20.0, 1.1, -0.97), lag_distance=0.3)
        fits = vlp.profile(rs, lags, mass=sc.mass, drive_velocity=vd, film_mass=sc.film_mass,
                           mount_damping=sc.mount_damping, min_window_time=MD_NOISE_TIME,
                           registry_period=1.1)
        tau[name] = vlp.crossing(lags, fits)[0]
        slips = [(r.wall_position[s] - r.wall_position[y], r.time[s] - r.time[y]) for r in rs
                 for y, s in zip(r.table.yield_index, r.table.stick_index)]
        speed[name] = sum(d for d, _ in slips) / sum(t for _, t in slips)
    # (τ̂·v̄ 0.31 and 0.33 σ; τ̂ 20 and 9.5 τ)
    for name in tau:
        assert 0.5 * 0.3 < tau[name] * speed[name] < 1.2 * 0.3, (tau, speed)
    assert tau["stiff"] / tau["m1e4"] == pytest.approx(speed["m1e4"] / speed["stiff"],
                                                       rel=0.3), (tau, speed)


def test_the_lag_profiles_new_control_options_refuse_bad_input_before_any_compute(
        benchmark_module, capsys):
    main = benchmark_module("slip_law/viscous_lag_profile").main
    for argv, said in ((["--control", "0.5", "0", "--lag-distance", "-1"], "--lag-distance"),
                       (["--control", "0.5", "10", "--lag-distance", "0.3"], "TAU 0"),
                       (["--control", "0.5", "10", "--branching", "8", "0", "0.3", "0.5", "0"],
                        "--branching"),
                       (["--control", "0.5", "0", "--branching", "8", "0", "2", "0.5", "0"],
                        "W1 <= 1"),
                       (["--control", "0.5", "0", "--lag-yield-exponent", "3"], "TAU > 0"),
                       (["--control", "0.5", "4", "--lag-yield-exponent", "nan"],
                        "--lag-yield-exponent nan"),
                       (["/nonexistent-run", "--lag-yield-exponent", "3"], "controls'"),
                       (["/nonexistent-run", "--lag-distance", "0.3"], "controls'")):
        with pytest.raises(SystemExit):
            main(argv)
        err = capsys.readouterr().err
        assert said in err and "Traceback" not in err, (argv, err)


BRANCH = (10.0, 0.0, 0.3, 0.5, 0.5)


@pytest.mark.parametrize("kw, said", [
    ({"registry_lag": 5.0}, "registry_lag"),
    ({"corrugation": (20.0, 1.1, -0.97), "registry_lag": 5.0, "lag": 10.0}, "registry_lag"),
    ({"branching": BRANCH}, "branching"),
    ({"corrugation": (20.0, 1.1, -0.97), "branching": BRANCH, "registry_lag": 5.0},
     "branching"),
    ({"lag_distance": 0.3}, "lag_distance"),
    ({"corrugation": (20.0, 1.1, -0.97), "lag_distance": 0.3, "lag": 10.0}, "lag_distance"),
    ({"lag_yield_exponent": 3.0}, "lag_yield_exponent"),
    ({"lag": 4.0, "lag_yield_exponent": 3.0, "weakening": (0.3, 0.5)}, "lag_yield_exponent")])
def test_a_registry_control_refuses_what_its_law_cannot_carry(kw, said):
    # each needs the walls' registry, and none carries a viscous lag in time beside it
    with pytest.raises(ValueError, match=said):
        pooled_runs("x", 3, 2, share=0.5, scale=STIFF, **kw)


def test_a_loop_that_keeps_a_noise_free_run_sliding_leaves_the_noisy_pools_read(
        benchmark_module, capsys):
    # the K = 4 rung's loop (slip-weakening 0.5 over 6 σ): noise-free, one run of the first
    # pool never re-sticks; the profile says so in the noise-free table's place and reads the
    # noisy pools, where the random force ends each slip
    main = benchmark_module("slip_law/viscous_lag_profile").main
    assert main(["--control", "0.3", "0", "--loop", "slip-weakening", "0.5", "6", "--scale",
                 "k4m3e3", "--stop-velocity=-0.0144", "--runs", "16", "--slips", "10",
                 "--replicas", "1", "--lags", "0", "2"]) == 0
    out = capsys.readouterr().out
    assert "(none: run 15: no slip relaxes the spring" in out
    assert "over the 1 pools: the one law's m_c" in out


def test_the_velocity_split_partitions_the_slips_and_reads_a_time_lag_in_the_fast_half(
        benchmark_module):
    # ``--split velocity``: each run's slips at or below the pool's median slip velocity in
    # the slow half, the others in the fast one (a run left without a slip dropped); a film
    # whose viscous force lags by one time (4 τ, noise-free, M = 3×10³) reads that time in
    # the fast half.  Noise-free the split sorts whole runs (each its own law): the slow
    # half, the runs of the larger viscous force, reads a negative m_c with no lag at all,
    # so a slow half's m_c is read against split controls, never alone
    import numpy as np

    vlp = benchmark_module("slip_law/viscous_lag_profile")
    sc = SCALES["m3e3"]
    lags = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 15.0, 20.0]
    fit_kw = dict(mass=sc.mass, film_mass=sc.film_mass, mount_damping=sc.mount_damping,
                  min_window_time=MD_NOISE_TIME, registry_period=1.1)
    halves = {}
    for lag in (4.0, None):
        rs, vd = pooled_runs("x", 8, 6, share=0.5, scale=sc, noise=QUIET, law_spread=0.15,
                             corrugation=(20.0, 1.1, -0.97), lag=lag)
        (slow, v_slow), (fast, v_fast) = vlp.split_by_velocity(rs)
        speed = [np.concatenate([r.table.slip_distance / r.table.slip_duration for r in h])
                 for h in (slow, fast)]
        assert sum(map(len, speed)) == sum(len(r.table) for r in rs)
        assert speed[0].max() <= speed[1].min() and v_slow < v_fast
        assert v_slow == pytest.approx(speed[0].mean())
        halves[lag] = [vlp.profile(h, lags, drive_velocity=vd, **fit_kw) for h in (slow, fast)]
    assert vlp.crossing(lags, halves[4.0][1])[0] == pytest.approx(4.0, abs=0.5)
    slow0, fast0 = (h[0].one_law for h in halves[None])
    assert slow0.comoving_mass < -3 * slow0.comoving_mass_stderr
    assert fast0.comoving_mass > 0


def test_the_split_controls_read_each_half_and_its_coverage_of_a_known_lag(benchmark_module,
                                                                          capsys):
    # ``--control … --split velocity``: over the pools each half's m_c and τ̂, and how often
    # each half's τ̂ ± 2 errors covers the control's own lag in time
    main = benchmark_module("slip_law/viscous_lag_profile").main
    assert main(["--control", "0.5", "3.7", "--scale", "m3e3", "--stop-velocity=-0.0144",
                 "--runs", "8", "--slips", "8", "--replicas", "2", "--lags", "0", "2", "4",
                 "6", "8", "--split", "velocity"]) == 0
    out = capsys.readouterr().out
    assert "over the 2 pools: mean slip velocity" in out
    # the fast half, where the lag marks the one law most (m_c ≤ −2 errors in both pools),
    # finds it within its errors in both (seeds fixed: deterministic)
    assert "and 2 of 2 (fast)" in out.split("covers the lag of 3.7 τ in ")[1]


def test_a_lag_tied_to_the_yield_force_speeds_the_weak_yields_slips():
    # ``lag_yield_exponent`` = α: each run's lag τ_r·(F̄_s/F_s)^α.  With one yield force for
    # every run it is the plain lag, to the sample; with the runs' yields spread (± 30 %,
    # noise-free, one film law) the weakest-yield run lags longest, and its slips run faster
    # than under one lag (a lagging viscous force resists the slip's start less) while the
    # strongest-yield run's, lagging less, run slower: a velocity split files long lags fast
    import numpy as np

    kw = dict(share=0.5, scale=SCALES["m3e3"], noise=QUIET, law_spread=0.0,
              corrugation=(20.0, 1.1, -0.97), lag=4.0)
    same = [pooled_runs("x", 3, 4, static_spread=0.0, lag_yield_exponent=a, **kw)[0]
            for a in (0.0, 3.0)]
    for one, tied in zip(*same):
        np.testing.assert_array_equal(one.spring_force, tied.spring_force)
    runs = {a: pooled_runs("x", 8, 6, lag_yield_exponent=a, **kw)[0] for a in (0.0, 3.0)}
    speed = {a: np.array([np.mean(r.table.slip_distance / r.table.slip_duration) for r in rs])
             for a, rs in runs.items()}
    yields = np.array([r.table.static_force.mean() for r in runs[0.0]])
    weak, strong = np.argmin(yields), np.argmax(yields)
    assert yields[weak] < 0.8 * 46.0 and yields[strong] > 1.2 * 46.0
    assert speed[3.0][weak] > 1.2 * speed[0.0][weak]
    assert speed[3.0][strong] < 0.95 * speed[0.0][strong]
