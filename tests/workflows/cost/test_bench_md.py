"""``filmfriction bench`` runs the scene as ``run`` runs it, and the runner's core layouts.

Real LAMMPS, a few hundred steps: these check what the benchmark measures and
prints, never how fast anything is (no timed tests).
"""
import json

import numpy as np
import pytest

from filmfriction.workflows.cost import bench

pytestmark = pytest.mark.md


def test_bench_times_the_scene_as_run_and_pairs_it_with_bulk(run_cli):
    res = run_cli("bench", "--steps", "400", "--set", "equilibrate_steps=100", "--repeat", "2",
                  "--np", "2", "--json")
    assert res.code == 0, res.err
    r = res.json()
    # the scene as run: the default box, equilibration + slide steps
    assert r["film_atoms"] == 616 and r["steps"] == 500
    assert abs(r["bulk_atoms"] - r["film_atoms"]) <= 0.05 * r["film_atoms"]
    keys = set(r["atom_steps_per_second"])
    assert keys == {"film 1 core (1 rank)", "bulk 1 core (1 rank)",
                    "film 2 cores (2 ranks)", "bulk 2 cores (2 ranks)"}
    for key, s in r["atom_steps_per_second"].items():
        assert s["n"] == 2 and 0 < s["min"] <= s["median"] <= s["max"] == s["best"], key
        # the whole process (set-up included) is slower than LAMMPS's loop alone
        assert s["median"] < r["loop_atom_steps_per_second"][key]["median"], key
    ratios = r["ratios"]
    assert set(ratios) >= {"film / bulk, 2 cores", "film 2 cores / film 1 core",
                           "film / bulk, 1 core"}
    rate = r["atom_steps_per_second"]
    pairs = [ratios["film / bulk, 1 core"]["min"], ratios["film / bulk, 1 core"]["max"]]
    # a paired ratio lies between the ratios of the extreme figures
    lo = rate["film 1 core (1 rank)"]["min"] / rate["bulk 1 core (1 rank)"]["max"]
    hi = rate["film 1 core (1 rank)"]["max"] / rate["bulk 1 core (1 rank)"]["min"]
    assert lo <= min(pairs) and max(pairs) <= hi
    assert r["other_cpu_seconds"] is None or r["other_cpu_seconds"] >= 0


def test_bench_prints_median_spread_and_best(run_cli):
    res = run_cli("bench", "--steps", "200", "--set", "equilibrate_steps=100", "--repeat", "1",
                  "--np", "1")
    assert res.code == 0, res.err
    assert "median" in res.out and "spread" in res.out and "best" in res.out
    assert "film 1 core (1 rank)" in res.out and "bulk 1 core (1 rank)" in res.out
    assert "CPU-s" in res.out or "unknown" in res.out


def test_the_layout_is_recorded_and_openmp_threads_run_the_same_scene(md, tmp_path):
    """1 rank x 2 OpenMP threads (-sf omp) runs the scene; its trace has the
    same physics as 1 rank (same temperature set point, spring law)."""
    scene = md.scene(slide_steps=1000, equilibrate_steps=200)
    from filmfriction.workflows.md import runner

    run_dir = runner.execute(scene, out=tmp_path / "omp", nprocs=1, progress=False, threads=2)
    record = json.loads((run_dir / "run.json").read_text())
    assert record["layout"] == {"cores": 2, "mpi_ranks": 1, "omp_threads": 2}
    assert "-sf" in record["command"] and "omp" in record["command"]
    assert record["status"] in ("completed", "completed_with_warnings")
    d = md.trace(run_dir)
    k = scene.parameters["spring_constant"]
    assert np.allclose(d["spring_force"], k * (d["drive_position"] - d["wall_position"]),
                       rtol=1e-6, atol=1e-5 * k)
    plain = runner.execute(scene, out=tmp_path / "mpi", nprocs=1, progress=False)
    assert json.loads((plain / "run.json").read_text())["layout"] == {
        "cores": 1, "mpi_ranks": 1, "omp_threads": 1}


def test_bulk_cells_match_the_atom_count_in_a_near_cubic_box():
    for n in (168, 616, 672, 2464, 100000):
        cells = bench.bulk_cells(n)
        assert abs(4 * np.prod(cells) - n) <= 0.05 * n
        assert max(cells) - min(cells) <= 3, (n, cells)
