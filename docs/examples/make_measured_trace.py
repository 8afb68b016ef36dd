"""Write ``sfb_trace.tsv`` and ``sfb_trace_units.txt``: measured-style SFB traces for the
guide docs/measured-traces.md.

The project's synthetic stick-slip (:func:`filmfriction.analysis.groundtruth.synthetic.klein_trace`,
Klein's K, M, B and V; slips obey his Eq. 1) sampled every millisecond, plus 1 % white
noise on the force, written the way an instrument's export might be: tab-separated, with
its own column names and units, four to six significant figures.

``sfb_trace_units.txt`` is the same trace as another instrument might export it: three
lines of metadata before the header, time in ms, force in µN, drive in nm, tab-separated,
and one force reading missing (an empty cell) at line 1004.

Run: ``python docs/examples/make_measured_trace.py`` (writes beside this file).
"""
from pathlib import Path

import numpy as np

from filmfriction.analysis.groundtruth.synthetic import klein_trace

STATIC_FORCE = 9.7e-6          # N, Klein's yield force K x0 ~ 10 uN

trace = klein_trace(cycles=5, dt=1e-3, noise=0.01 * STATIC_FORCE, seed=7)
out = Path(__file__).with_name("sfb_trace.tsv")
with out.open("w") as fh:
    fh.write("# synthetic SFB trace (filmfriction.analysis.groundtruth.synthetic.klein_trace + 1 % noise)\n")
    fh.write("t_s\tshear_force_N\tdrive_x_m\n")
    for t, f, x in zip(trace["time"], trace["spring_force"], trace["drive_position"]):
        fh.write(f"{t:.6g}\t{f:.5g}\t{x:.6g}\n")
print(f"wrote {out} ({trace['time'].size} rows)")

units = Path(__file__).with_name("sfb_trace_units.txt")
with units.open("w") as fh:
    fh.write("SFB-3 export, channel set B\nsample: mica / OMCTS / mica, 4 layers\n"
             "units: ms, uN, nm\n")
    fh.write("time_ms\tforce_uN\tdrive_nm\n")
    for i, (t, f, x) in enumerate(zip(trace["time"], trace["spring_force"],
                                      trace["drive_position"])):
        force = "" if i == 999 else f"{f * 1e6:.5g}"
        fh.write(f"{t * 1e3:.6g}\t{force}\t{x * 1e9:.6g}\n")
print(f"wrote {units} ({trace['time'].size} rows, one force missing)")
