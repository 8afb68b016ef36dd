"""Write the small real LAMMPS files beside this script (run it to make them again).

* ``trace.dat``, ``log.lammps``: the default stick-slip scene on the tests' small
  box (5 x 3 cells, ~330 atoms), 200 steps of equilibration and 2000 of slide in two
  restart segments of 1000, a trace row and a thermo row every 50 steps: the
  ``fix print`` file with its title repeated at the second segment and the
  segment's first step printed twice, and a log of three thermo runs;
* ``trace.csv``: what the runner writes from that ``trace.dat``;
* ``ave_time.dat``: a ``fix ave/time`` file of a 108-atom LJ liquid (``# TimeStep
  v_t v_pe c_thermo_temp``), 200 steps.

Run: ``python tests/analysis/data/lammps/make_lammps_files.py`` (seconds, one rank).
"""
import shutil
import subprocess
import tempfile
from pathlib import Path

from filmfriction import md_inputs
from filmfriction.md_inputs.contract import DATA_FILE
from filmfriction.workflows.md import engine, runner
from filmfriction.workflows.md.scene import load

HERE = Path(__file__).parent
SETTINGS = {"cells_x": 5, "cells_y": 3, "equilibrate_steps": 200, "slide_steps": 2000,
            "trace_every": 50, "restart_every": 1000}
AVE_TIME = """units lj
lattice fcc 0.8442
region box block 0 3 0 3 0 3
create_box 1 box
create_atoms 1 box
mass 1 1.0
velocity all create 1.0 87287 loop geom
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0 2.5
fix 1 all nve
variable t equal time
variable pe equal pe
fix 2 all ave/time 10 1 10 v_t v_pe c_thermo_temp file ave_time.dat
run 200
"""


def run(cmd, cwd):
    subprocess.run(cmd, cwd=cwd, env=engine.engine_env(), stdout=subprocess.DEVNULL,
                   stderr=subprocess.STDOUT, timeout=300, check=True)


def main():
    scene = load("stick-slip", SETTINGS)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / DATA_FILE).write_text(scene.geometry().lammps_data())
        variables = scene.lammps_variables()
        variables["thermo_every"] = str(SETTINGS["trace_every"])
        run(engine.lmp_command(1, md_inputs.script(runner.SCRIPT), variables,
                               log=Path("log.lammps")), tmp)
        runner.write_trace_csv(runner.read_trace_dat(tmp / "trace.dat"), tmp / "trace.csv")
        (tmp / "ave.in").write_text(AVE_TIME)
        run(engine.lmp_command(1, tmp / "ave.in", {}, log=Path("ave.log")), tmp)
        for name in ("trace.dat", "log.lammps", "trace.csv", "ave_time.dat"):
            shutil.copy(tmp / name, HERE / name)
    print(f"wrote trace.dat, log.lammps, trace.csv, ave_time.dat in {HERE}")


if __name__ == "__main__":
    main()
