"""Benchmark of the analysis: prints figures.

* a 10⁶-sample stick-slip trace (SFB-like, Klein's parameters, noisy) —
  target ≤ 1 s for detection + cycle table + energy + slip-viscosity fits;
  reading it (comma-separated text, tab-separated text with its own column
  names, the binary copy in ``.filmfriction/``) and reading + the full ``analyze``
  document — target ≤ 0.3 s — each as median, min and max of 7 runs;
* trajectory analyses of a 2288-atom film on one core — target ≥ 1000 frames/s
  (median and spread of several runs, wall and CPU time) — and ψ6 on two
  processes through MDAnalysis's ``multiprocessing`` backend (wall time).

Run: ``.venv/bin/python benchmarks/bench_analysis.py`` (``--trajectory-only``:
the trajectory part alone).  BLAS and OpenMP run one thread each (``OMP_NUM_THREADS``,
when set, gives another count), set through ``threadpoolctl`` (a dependency of
MDAnalysis) once numpy is loaded.
"""
from __future__ import annotations

import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

warnings.filterwarnings("ignore", category=DeprecationWarning)


CPU = {}


def _best(fn, repeat=3):
    """Best wall time of ``repeat`` calls (CPU time of that call in CPU[fn])."""
    best, cpu = np.inf, np.inf
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        wall, c = time.perf_counter() - t0, time.process_time() - c0
        if wall < best:
            best, cpu = wall, c
    CPU["last"] = cpu
    return best, out


def _cpu() -> str:
    return f"(CPU {CPU['last']:.3f} s)"


def bench_trace(n=1_000_000):
    from filmfriction.analysis import stickslip, viscosity
    from filmfriction.analysis.stick_ramps import ramp_forces
    from filmfriction.reduced_model.cycles import cycle_table
    from filmfriction.analysis.energy.partition import energy_table
    from filmfriction.analysis.analyze import analyze
    from filmfriction.analysis.groundtruth.synthetic import klein_trace, write_csv
    from filmfriction.analysis.files.trace_reader import read_trace
    from filmfriction.analysis.files.trace_cache import write_binary_copy

    k, m, fs = 97.0, 1.47e-3, 9.7e-6
    tr = klein_trace(cycles=60, noise=0.005 * fs, dt=1e-5)      # ~0.7 s per cycle
    t, f = tr["time"][:n], tr["spring_force"][:n]
    print(f"trace: {t.size} samples")

    def pipeline():
        ev = stickslip.detect_slips(t, f)
        tab = cycle_table(t, f, ev.yield_index, ev.stick_index, spring_constant=k)
        tab = ramp_forces(t, f, tab)
        et = energy_table(t, f, tab, k, mass=m, noise=ev.noise)
        return ev, tab, et

    dt, (ev, tab, et) = _best(pipeline)
    print(f"  detect + cycle table + energy: {dt:.3f} s {_cpu()}  ({ev.count} slips)"
          "  target <= 1 s")
    dtv, sv = _best(lambda: viscosity.slip_viscosity(
        t, f, tab, mass=m, spring_constant=k, area=4e-10, thickness=3.5e-9,
        drive_velocity=1e-7), repeat=1)
    print(f"  slip-equation fits ({sv.n} slips): {dtv:.3f} s {_cpu()}  "
          f"(η_eff = {sv.eta_eff:.2f} ± {sv.eta_eff_stderr:.2f} Pa·s)")
    params = dict(spring_constant=k, mass=m, area=4e-10, thickness=3.5e-9,
                  drive_velocity=1e-7, units="si")
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "trace.csv"
        write_csv(p, {"time": t, "spring_force": f, "drive_position": tr["drive_position"][:n]})
        # the same trace tab-separated with its own column names, read through a mapping
        q = Path(d) / "sfb.tsv"
        names = {"t_s": "time", "F_N": "spring_force", "x_drive_m": "drive_position"}
        np.savetxt(q, np.column_stack([t, f, tr["drive_position"][:n]]), delimiter="\t",
                   header="\t".join(names), comments="", fmt="%.10g")
        mapping = {v: k_ for k_, v in names.items()}
        text = _spread(lambda: read_trace(p, **params))
        tsv = _spread(lambda: read_trace(q, columns=mapping, **params))
        trace = read_trace(p, **params)
        write_binary_copy(trace)
        binary = _spread(lambda: read_trace(p, **params))
        assert read_trace(p, **params).layout.binary
        full_text = _spread(lambda: analyze(read_trace(q, columns=mapping, **params)))
        full_binary = _spread(lambda: analyze(read_trace(p, **params)))
    print(f"  read text trace (comma):             {text}")
    print(f"  read text trace (tab, mapped names): {tsv}")
    print(f"  read binary copy (.filmfriction/):   {binary}")
    print(f"  read text + full analyze():          {full_text}")
    print(f"  read binary + full analyze():        {full_binary}   target <= 0.3 s")


def _spread(fn, repeat=7) -> str:
    """'median s (min, max; CPU median) of ``repeat`` calls': wall times, and the CPU time
    of this process (the honest figure when other work shares the cores)."""
    times, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return (f"median {np.median(times):.3f} s (min {min(times):.3f}, max {max(times):.3f}; "
            f"CPU median {np.median(cpu):.3f} s; {repeat} runs)")


def _rates(fn, frames, repeat):
    """frames/s of ``repeat`` calls: wall and CPU, each as (median, min, max)."""
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(frames / (time.perf_counter() - t0))
        cpu.append(frames / (time.process_time() - c0))
    return [(float(np.median(r)), min(r), max(r)) for r in (wall, cpu)]


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _print_rates(name, rates, target=""):
    (wm, wlo, whi), (cm, clo, chi) = rates
    print(f"  {name:15s} {wm:6.0f} frames/s ({wlo:.0f}–{whi:.0f});  CPU {cm:.0f} "
          f"({clo:.0f}–{chi:.0f}){target}")


def bench_trajectory(frames=400, repeat=7):
    import MDAnalysis as mda

    from filmfriction.analysis.structure.hexatic import HexaticOrder
    from filmfriction.analysis.structure.layering import DensityProfile, FilmThickness
    from filmfriction.analysis.groundtruth.synthetic import layered_film

    with tempfile.TemporaryDirectory() as d:
        top, traj = layered_film(d, layers=4, nx=22, ny=13, frames=frames,
                                 melt_frames=range(frames // 2, frames))
        u = mda.Universe(str(top), str(traj), format="DCD", topology_format="DATA",
                         atom_style="id type x y z")
        film = u.select_atoms("type 1")
        print(f"trajectory: {film.n_atoms} film atoms ({u.atoms.n_atoms} with walls), "
              f"{frames} frames (the first half crystalline, the second shear-melted), one "
              f"core; median (min–max) of {repeat} runs")
        prof = DensityProfile(film).run()
        edges = prof.results.layers["edges"]
        _print_rates("DensityProfile", _rates(lambda: DensityProfile(film).run(), frames, repeat))
        _print_rates("HexaticOrder", _rates(lambda: HexaticOrder(film, edges).run(), frames,
                                            repeat), "   target >= 1000")
        workers = min(2, os.cpu_count() or 1)
        if workers > 1:
            # MDAnalysis's split-apply-combine backend: frames shared between processes
            # (in 4 parts per process: melted frames cost 4x crystalline ones, so
            # contiguous halves would leave one process waiting)
            par = {"backend": "multiprocessing", "n_workers": workers, "n_parts": 4 * workers}
            wall = [frames / _timed(lambda: HexaticOrder(film, edges).run(**par))
                    for _ in range(repeat)]
            print(f"  HexaticOrder on {workers} processes (backend='multiprocessing', n_parts={4 * workers}): "
                  f"{np.median(wall):.0f} frames/s wall ({min(wall):.0f}–{max(wall):.0f})"
                  "   target >= 1000")
        half = frames // 2
        for part, kw in (("crystalline", {"stop": half}), ("melted", {"start": half})):
            _print_rates(f"  {part}", _rates(lambda: HexaticOrder(film, edges).run(**kw),
                                             frames - half, repeat))
        _print_rates("FilmThickness", _rates(lambda: FilmThickness(
            u.select_atoms("type 2"), u.select_atoms("type 3")).run(), frames, repeat))


def _lammps_running() -> bool:
    import subprocess

    try:
        return subprocess.run(["pgrep", "-f", "lmp"], capture_output=True).returncode == 0
    except OSError:
        return False


if __name__ == "__main__":
    print(f"load average: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores "
          "(wall times inflate when the machine is shared)"
          + ("; LAMMPS is running (pgrep -f lmp)" if _lammps_running() else ""))
    with threadpool_limits(limits=int(os.environ.get("OMP_NUM_THREADS", "1"))):
        if "--trajectory-only" not in sys.argv:
            bench_trace()
        bench_trajectory()
