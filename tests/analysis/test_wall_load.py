"""benchmarks/wall_load.py on traces with known answers: the static force of a pinned wall,
a freely sliding wall, and the fit F_s = F_0 + mu L with error bars that cover the truth
(its table: docs/results/wall-load.md)."""
import json

import numpy as np


def _run(tmp_path, name, wall, force, drive, dt=0.1):
    """A run directory with the trace.dat columns the study reads."""
    n = len(force)
    data = np.zeros((n, 16))
    data[:, 0] = np.arange(n) * 20
    data[:, 1] = np.arange(n) * dt
    data[:, 2], data[:, 3], data[:, 4] = drive, force, wall
    data[:, 7], data[:, 8] = 4.7, 0.71
    run = tmp_path / name
    run.mkdir()
    np.savetxt(run / "trace.dat", data)
    (run / "run.json").write_text(json.dumps({
        "status": "completed", "derived": {"area": 58.7},
        "scene": {"parameters": {"wall_spacing": 1.1}}}))
    return run


def test_a_pinned_wall_yields_at_its_static_force_and_a_free_wall_is_not_pinned(
        tmp_path, benchmark_module):
    wl = benchmark_module("wall_load")
    rng = np.random.default_rng(3)
    K, V, dt = 20.0, 0.08, 0.1
    t = np.arange(800) * dt
    drive = V * t
    # stuck until the spring reaches 50, then the wall jumps 2 sigma and sticks again
    wall = np.where(K * drive < 50.0, 0.0, 2.0) + 0.01 * rng.standard_normal(t.size)
    force = K * (drive - wall)
    m = wl.measure(_run(tmp_path, "pinned", wall, force, drive))
    assert m["pinned"] and abs(m["static_force"] - 50.0) < 0.5
    # a free wall follows the drive with a small noisy force
    wall = drive - (0.5 + 0.2 * rng.standard_normal(t.size)) / K
    force = K * (drive - wall)
    m = wl.measure(_run(tmp_path, "free", wall, force, drive))
    assert not m["pinned"] and m["static_force"] is None


def test_the_fit_recovers_adhesion_and_slope_within_its_errors(benchmark_module):
    wl = benchmark_module("wall_load")
    rng = np.random.default_rng(11)
    loads = np.repeat([0.587, 5.87, 17.6, 58.7], 2)
    covered = np.zeros((200, 2), dtype=bool)
    for i in range(200):
        force = 50.0 + 0.3 * loads + 3.0 * rng.standard_normal(loads.size)
        r = wl.fit(list(zip(loads, force)))
        covered[i] = abs(r["F0"] - 50.0) <= r["F0_se"], abs(r["mu"] - 0.3) <= r["mu_se"]
    # each +-1 s.e. bar covers its truth about 65 % of the time (Student's t with 6
    # degrees of freedom; 200 repeats: +-3.4 %)
    rate = covered.mean(axis=0)
    assert np.all((0.55 < rate) & (rate < 0.76)), rate
