"""The calibration on a known example: a trace with F_k = 2.0 µN and B = 1.5 kg/s, in
N, m, s and in µN, nm, ms.

    .venv/bin/python benchmarks/calibration_example.py

Klein's SFB wall (K = 97 N/m, M = 1.47 g, V = 100 nm/s, F_s = 9.7 µN) with a Coulomb +
viscous slip, M x'' + B x' = K(x_d − x) − F_k, that re-sticks when the wall has slowed to
5 V (:func:`~filmfriction.analysis.groundtruth.synthetic.klein_trace`; the slip is
overdamped, B/2√(KM) = 2, and without a re-stick speed it would not stop), 6 cycles
sampled every ms, 1 % white noise on the force (seed 7).  Each unit system's trace is
written as a run directory and calibrated as ``filmfriction calibrate`` does; the printout
gives F_k and B in µN and kg/s with z = (fit − truth)/stderr.
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from filmfriction.analysis.calibration import calibrate as cal_mod
from filmfriction.analysis.groundtruth.synthetic import klein_trace, write_csv

K, M, V, FS, FK, B = 97.0, 1.47e-3, 1.0e-7, 9.7e-6, 2.0e-6, 1.5      # SI
AREA, GAP = 4.0e-10, 3.5e-9
#: (force, length, time) of one unit of each system, in SI
SYSTEMS = {"N, m, s": (1.0, 1.0, 1.0), "µN, nm, ms": (1e-6, 1e-9, 1e-3)}


def example_trace() -> dict:
    """The example's trace (SI)."""
    return klein_trace(spring_constant=K, mass=M, damping=B, drive_velocity=V, static_force=FS,
                       backward_force=0.0, kinetic_force=FK, restick_velocity=5.0 * V,
                       cycles=6, dt=1e-3, noise=0.01 * FS, seed=7)


def write_run(directory: Path, trace: dict, units: tuple) -> Path:
    """``trace`` as a run directory in the unit system ``units`` (force, length, time)."""
    fu, xu, tu = units
    directory.mkdir(parents=True)
    write_csv(directory / "trace.csv", {"time": trace["time"] / tu,
                                        "spring_force": trace["spring_force"] / fu,
                                        "drive_position": trace["drive_position"] / xu,
                                        "gap": np.full(trace["time"].size, GAP / xu)})
    params = {"spring_constant": K / (fu / xu), "mass": M / (fu * tu * tu / xu),
              "area": AREA / xu ** 2, "thickness": None, "drive_velocity": V / (xu / tu),
              "units": "si"}
    (directory / "run.json").write_text(json.dumps({
        "schema": "filmfriction.run/1", "status": "completed",
        "scene": {"name": "issue-21 example", "parameters": {}}, "trace_parameters": params}))
    return directory


def calibrate_in(units: tuple, root: Path, trace: dict):
    """(F_k, its error) in N and (B, its error) in kg/s, from the calibration in ``units``."""
    fu, xu, tu = units
    rc = cal_mod.calibrate([write_run(root, trace, units)]).main
    fk, b = rc.kinetic_force, rc.film_damping
    damping = fu * tu / xu
    return rc, (fk.value * fu, fk.stderr * fu, fk.at_bound), (b.value * damping,
                                                             b.stderr * damping, b.at_bound)


def main() -> int:
    trace = example_trace()
    root = Path(tempfile.mkdtemp(prefix="calibration-example-"))
    print("| units | slips | F_k (µN) | z | B (kg/s) | z |")
    print("|---|---|---|---|---|---|")
    for i, (name, units) in enumerate(SYSTEMS.items()):
        rc, (fk, efk, _), (b, eb, _) = calibrate_in(units, root / f"u{i}", trace)
        print(f"| {name} | {rc.run.n_slips} | {fk * 1e6:.4g} ± {efk * 1e6:.2g} | "
              f"{(fk - FK) / efk:+.2f} | {b:.4g} ± {eb:.2g} | {(b - B) / eb:+.2f} |")
    print(f"\ntruth: F_k = {FK * 1e6:g} µN, B = {B:g} kg/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
