# Replicas of one study as independent jobs: a Snakemake job per replica and segment.
#
# `filmfriction run SCENE --replicas N --profile PROFILE` drives the study as without a
# profile (workflows/md/replicas/replica_study.py: the seeds, the target's checks, the segments,
# the combined analysis); for each segment it writes segments/slide-<S>.json (the replicas
# still to bring to a slide of S steps) and calls
#     python -m snakemake --snakefile workflows/sweep/replicas.smk --directory STUDY_DIR \
#         --config spec=segments/slide-<S>.json ...
# so that each replica runs as a job of its own: on this machine with --profile local, one
# Slurm job each with --profile slurm.
#
# replica job   `python -m filmfriction.workflows.sweep replica ...`: starts the replica's
#               run directory replica-<i>/ or continues it to the segment's slide (the
#               runner's execute or resume, as `filmfriction run` does), appending what it
#               prints to replica-<i>.log; the marker segments/slide-<S>/replica-<i>.done
#               says it got there
import json
import sys
from pathlib import Path

SPEC = json.loads(Path(config["spec"]).read_text())
SLIDE = int(SPEC["slide_steps"])
REPLICAS = [int(i) for i in SPEC["replicas"]]
PYTHON = config.get("python", sys.executable)
NP = int(SPEC["np"])
LMP = ["--lmp", SPEC["lmp"]] if SPEC.get("lmp") else []
# as for a sweep's point (sweep.smk): one MPI job of NP tasks, a one-task job without it
MPI_JOB = {"mpi": "yes"} if NP > 1 else {}

wildcard_constraints:
    index=r"\d+",

localrules: all


rule all:
    input:
        expand("segments/slide-{slide}/replica-{index}.done", slide=SLIDE, index=REPLICAS),


rule replica:
    output:
        "segments/slide-{slide}/replica-{index}.done",
    threads: NP  # local scheduling: a replica occupies its ranks' cores
    resources:
        launcher="mpiexec",  # what starts the ranks; the Slurm profile sets srun
        tasks=NP,  # MPI ranks (Slurm: --ntasks)
        cpus_per_task=1,
        mem_mb=2000,
        runtime=60,  # minutes per segment; raise it in the profile for long segments
        **MPI_JOB,
    params:
        lmp=LMP,
    shell:
        "{PYTHON:q} -m filmfriction.workflows.sweep replica . {wildcards.index} "
        "--slide-steps {wildcards.slide} --np {resources.tasks} "
        "--launcher {resources.launcher:q} {params.lmp:q} --done {output:q} "
        ">> replica-{wildcards.index}.log 2>&1"
