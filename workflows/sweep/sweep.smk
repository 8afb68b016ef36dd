# The sweep workflow: one scene over a grid of parameters.
#
# Run it through `filmfriction sweep`, which validates the grid and writes sweep.json and
# inputs/<point>.json into the sweep directory, then calls
#     python -m snakemake --snakefile workflows/sweep/sweep.smk --directory SWEEP_DIR ...
# It can be run by hand the same way on a directory that holds a sweep.json.
#
# point job      an MPI LAMMPS run through workflows.runner (mpiexec locally, srun on Slurm:
#                the `launcher` resource names the launcher, `tasks` the ranks)
# analyse job    analysis.json of the run (serial)
# aggregate job  aggregate.json/.csv, velocity_map.png, vk_map.png when V x K are swept
import json
import sys
from pathlib import Path

SPEC = json.loads(Path(config.get("spec", "sweep.json")).read_text())
POINTS = [p["name"] for p in SPEC["points"]]
KEYS = [a["key"] for a in SPEC["grid"]]
PYTHON = config.get("python", sys.executable)
NP = int(SPEC["np"])
# the calibration file is an input of the aggregate, so a new one re-draws the map
CALIBRATION = [SPEC["calibration"]] if SPEC.get("calibration") else []
AGGREGATE = ["aggregate.json", "aggregate.csv", "velocity_map.png"]
if "drive_velocity" in KEYS and "spring_constant" in KEYS:
    AGGREGATE.append("vk_map.png")
# Slurm's executor takes a job with an `mpi` resource for one MPI job of `tasks` ranks
# (sbatch --ntasks; the command runs in the batch step, where the launcher starts the ranks),
# and refuses one with a single task.  A one-rank point is a plain one-task job: the executor
# runs it inside a job step (srun -n 1), so the Slurm profile's launcher carries --overlap
# to start LAMMPS's own step beside it.  The value of `mpi` is not read; locally it means
# nothing.
MPI_JOB = {"mpi": "yes"} if NP > 1 else {}

wildcard_constraints:
    point="[^/]+",

# the aggregate and the target are cheap: never submitted to a cluster
localrules: all, aggregate


rule all:
    input:
        AGGREGATE,


rule point:
    # Inputs are rewritten only when the point's resolved parameters change, so a changed
    # --set or scene re-runs exactly the points it touches.
    input:
        "inputs/{point}.json",
    output:
        "points/{point}/run.json",
    log:
        "logs/{point}.run.log",
    threads: NP  # local scheduling: a point occupies its ranks' cores
    resources:
        launcher="mpiexec",  # what starts the ranks; the Slurm profile sets srun
        tasks=NP,  # MPI ranks (Slurm: --ntasks)
        cpus_per_task=1,  # one core per rank (Slurm would otherwise take `threads`)
        mem_mb=2000,
        runtime=60,  # minutes; raise it in the profile for production-length runs
        **MPI_JOB,
    shell:
        "{PYTHON:q} -m filmfriction.workflows.sweep point {input:q} points/{wildcards.point:q} "
        "--np {resources.tasks} --launcher {resources.launcher:q} > {log:q} 2>&1"


rule analyse:
    input:
        "points/{point}/run.json",
    output:
        "points/{point}/analysis.json",
    log:
        "logs/{point}.analyse.log",
    threads: 1
    resources:
        mem_mb=2000,
        runtime=15,
    shell:
        "{PYTHON:q} -m filmfriction.workflows.sweep analyse points/{wildcards.point:q} > {log:q} 2>&1"


rule aggregate:
    input:
        analyses=expand("points/{point}/analysis.json", point=POINTS),
        plan="sweep.json",
        calibration=CALIBRATION,
    output:
        AGGREGATE,
    log:
        "logs/aggregate.log",
    shell:
        "{PYTHON:q} -m filmfriction.workflows.sweep aggregate . > {log:q} 2>&1"
