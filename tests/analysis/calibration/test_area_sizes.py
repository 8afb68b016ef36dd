"""The yield stress and pooled slip law by box size (benchmarks/slip_law/area_sizes.py), on
Klein-type runs of known law at two contact sizes."""
from __future__ import annotations

import json

import pytest

from filmfriction.analysis.analyze import analyse_run
from filmfriction.analysis.groundtruth.synthetic import klein_trace, run_directory

AREA_1 = 12 * 1.1 * 7 * 3 ** 0.5 * 1.1        # run_directory's box (σ²)


def _sweep(root, scale):
    for i in range(3):
        analyse_run(run_directory(root / "points" / f"seed={i}", trajectory=False, seed=i,
                                  scale=scale))
    return root


def test_an_extensive_film_reads_the_same_per_area_at_every_size(tmp_path, benchmark_module,
                                                                capsys):
    # the same viscous film (B = 40 m/τ, F_s = 3 ε/σ at the small box) on a box four times
    # larger with K, M and the forces scaled: per area every number is the small box's,
    # and each is its known value.  The spring's force peaks above F_s (the drive still
    # gains on the slowly starting block): its noise-free peak is the yield the detector reads
    main = benchmark_module("slip_law/area_sizes").main
    peak = klein_trace(spring_constant=8.0, mass=500.0, damping=40.0, drive_velocity=0.01,
                       static_force=3.0, backward_force=1.0, cycles=4,
                       dt=0.5)["spring_force"].max()
    assert 3.0 < peak < 3.1
    small, large = _sweep(tmp_path / "a1", 1.0), _sweep(tmp_path / "a4", 4.0)
    out = tmp_path / "sizes.json"
    assert main([f"1x={small}", f"4x={large}", "--json", str(out)]) == 0
    got = {g["label"]: g for g in json.loads(out.read_text())}
    assert got["4x"]["area"] == pytest.approx(4 * AREA_1)
    for g in got.values():
        assert g["runs"] == 3 and g["changed_state"] == 0
        assert g["first_yield_stress"][0] == pytest.approx(peak / AREA_1, rel=0.01)
        assert g["later_yield_stress"][0] == pytest.approx(peak / AREA_1, rel=0.01)
        law = g["pooled"]
        assert law["verdict"] == "viscous"
        assert law["damping_per_area"][0] == pytest.approx(40.0 / AREA_1, rel=0.05)
        assert abs(law["kinetic_stress"][0]) < 3 * law["kinetic_stress"][1] + 1e-3
    rows = [r for r in capsys.readouterr().out.splitlines() if r.startswith("| 1x |")
            or r.startswith("| 4x |")]
    assert len(rows) == 2 and all("`viscous`" in r for r in rows)


def test_a_group_is_one_size(tmp_path, benchmark_module, capsys):
    main = benchmark_module("slip_law/area_sizes").main
    a = _sweep(tmp_path / "a1", 1.0)
    b = run_directory(tmp_path / "b", trajectory=False, scale=2.0)
    analyse_run(b)
    with pytest.raises(SystemExit, match="mixes areas"):
        main([f"x={a}", f"x={b}"])
    with pytest.raises(SystemExit, match="LABEL=RUN_DIR"):
        main([str(a)])
    with pytest.raises(SystemExit, match="no analysed runs"):
        main([f"x={tmp_path}"])
