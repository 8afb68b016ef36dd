"""The contract between ``film_slide.lmp`` and the Python that runs and reads it.

One table each for what the script and its readers must agree on:

* :data:`DATA_FILE` -- the data file the script starts from (the walls and
  the film, :mod:`filmfriction.md_inputs.geometry`), in the run directory;
* :data:`ATOM_TYPES` -- the atom types of that file and what they are;
* :data:`TRACE` -- the columns of ``trace.dat`` (the script's ``fix print``),
  in the order LAMMPS prints them, with the LAMMPS expression and format
  that print them, their unit and their meaning.

The runner (``filmfriction.workflows.md.runner``) and the analysis
(``filmfriction.analysis``) import these names; nothing else lists them.

Why the script's ``fix print`` line is *checked against* this table (by
``tests/md_inputs/test_contract.py``, which parses the script) rather than generated
from it and passed in as a variable: the script must stay a plain LAMMPS
input that runs by hand with its ``index`` defaults, and a print line handed
over through ``-var`` would need a default copy of itself in the script
anyway (a second copy, the thing this module removes), plus LAMMPS's rules
for when ``$(...)`` inside a substituted variable is evaluated (once, when
the command is read, instead of at every print).  So the script keeps its
literal line, :func:`fix_print_text` and :func:`fix_print_title` say what it
must read, and the test fails the moment the two differ.
"""
from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

__all__ = ["STUDY_FILE", "ENSEMBLE_FILE", "ENSEMBLE_REPORT_FILE", "REPLICA_DIR",
           "REPLICA_LOG", "DATA_FILE", "RUN_FILE", "SCENE_FILE", "COMMAND_FILE", "LOG_FILE", "TRACE_DAT_FILE",
           "TRACE_FILE", "RESTARTS_FILE", "ANALYSIS_FILE", "CALIBRATION_FILE", "SFB_FILE",
           "SWEEP_FILE", "AGGREGATE_FILE", "SLIDE_ORIGIN_FILE", "RESUME_OFFSETS", "AtomType", "ATOM_TYPES", "FILM_TYPES", "BOTTOM_WALL_TYPES", "TOP_WALL_TYPES",
           "WALL_TYPES", "Column", "TRACE", "DAT_COLUMNS", "TRACE_COLUMNS", "TRACE_UNITS",
           "column", "fix_print_text", "fix_print_title", "check_head"]


#: The script's ``data_file`` default: the runner writes the geometry there.
DATA_FILE = "geometry.data"

# ------------------------------------------------------------ the run directory
# Every file a run directory holds, by name: the runner, the analysis, the study,
# the sweep and the report use these names (workflows/rundir.py reads and writes
# the study's documents).
RUN_FILE = "run.json"                  #: the run's record: scene, segments, status, versions
SCENE_FILE = "scene.toml"              #: the scene as run, parameters resolved
COMMAND_FILE = "command.txt"           #: the LAMMPS command line
LOG_FILE = "lammps.log"                #: LAMMPS's log
TRACE_DAT_FILE = "trace.dat"           #: the script's ``fix print`` rows, as LAMMPS wrote them
TRACE_FILE = "trace.csv"               #: the trace in :data:`TRACE_COLUMNS`, what the analysis reads
RESTARTS_FILE = "restarts.json"        #: the restart files' ledger
ANALYSIS_FILE = "analysis.json"        #: the analysis (``analysis_cycles.csv`` beside it)
CALIBRATION_FILE = "calibration.json"  #: the reduced model calibrated on the run
SFB_FILE = "sfb.json"                  #: the SFB check (``sfb_slips.csv`` beside it)
SWEEP_FILE = "sweep.json"              #: a sweep directory's plan
AGGREGATE_FILE = "aggregate.json"      #: a finished sweep's aggregate
SLIDE_ORIGIN_FILE = "slide_origin.txt"  #: the wall's x and z at the slide's start (for a resume)
STUDY_FILE = "study.json"              #: a study of replicas: seeds, rule, checks, why it stopped
ENSEMBLE_FILE = "ensemble.json"        #: a study's observables combined over its replicas
ENSEMBLE_REPORT_FILE = "ensemble.md"   #: the same as a report
REPLICA_DIR = "replica-{index}"        #: replica ``index``'s run directory in a study (1-based)
REPLICA_LOG = "replica-{index}.log"    #: what replica ``index``'s runs printed

#: The energy ledger's running sums a resumed run continues from: the trace column at the
#: restart step -> the script's variable that starts the sum there.
RESUME_OFFSETS = {"drive_work": "drive_work0", "thermostat_heat": "heat0",
                  "mount_heat": "mount_heat0"}


# ---------------------------------------------------------------- atom types
class AtomType(IntEnum):
    """Atom types of ``film_slide.lmp`` (its data file has 5 atom types)."""

    FILM = 1
    BOTTOM_WALL = 2        # rigid walls: the whole bottom wall (fixed); flexible: its outer plane
    TOP_WALL = 3           # rigid walls: the whole top wall (one rigid body); flexible: its outer plane
    BOTTOM_FLEXIBLE = 4    # wall_model = flexible: the bottom wall's planes facing the film
    TOP_FLEXIBLE = 5       # wall_model = flexible: the top wall's planes facing the film


#: What each type is, for labels (a figure's legend, an error message).
ATOM_TYPES: dict[AtomType, str] = {
    AtomType.FILM: "film",
    AtomType.BOTTOM_WALL: "bottom wall (rigid part)",
    AtomType.TOP_WALL: "top wall (rigid part)",
    AtomType.BOTTOM_FLEXIBLE: "bottom wall (flexible planes)",
    AtomType.TOP_FLEXIBLE: "top wall (flexible planes)",
}

#: The types that make up each body, whatever the wall model: with rigid walls
#: the flexible types have no atoms.
FILM_TYPES = (AtomType.FILM,)
BOTTOM_WALL_TYPES = (AtomType.BOTTOM_WALL, AtomType.BOTTOM_FLEXIBLE)
TOP_WALL_TYPES = (AtomType.TOP_WALL, AtomType.TOP_FLEXIBLE)
WALL_TYPES = BOTTOM_WALL_TYPES + TOP_WALL_TYPES


# ---------------------------------------------------------------- the trace
@dataclass(frozen=True)
class Column:
    """One column of ``trace.dat`` / ``trace.csv``.

    ``unit`` is the LJ unit as ``run.json`` records it (``trace_units``);
    ``quantity`` is its kind, a key of ``filmfriction.analysis.files.trace.UNITS``
    (for labels in either unit system); ``expression`` and ``format`` are how
    the script's ``fix print`` prints it (``$(expression:format)``).
    """

    name: str
    unit: str
    quantity: str
    expression: str
    format: str | None
    meaning: str

    def lammps(self) -> str:
        """The column's item in the ``fix print`` line."""
        return f"$({self.expression}:{self.format})" if self.format else f"$({self.expression})"


C = Column
#: ``trace.dat`` columns in the order the script's ``fix print`` writes them.
TRACE: tuple[Column, ...] = (
    C("step", "-", "1", "step", None, "MD step since the drive started"),
    C("time", "tau", "time", "time", "%.8g", "time since the drive started"),
    C("drive_position", "sigma", "length", "v_xdrel", "%.8g",
      "spring end, relative to the wall's position at the start"),
    C("spring_force", "epsilon/sigma", "force", "v_fs", "%.8g",
      "K * (drive_position - wall_position)"),
    C("wall_position", "sigma", "length", "v_xwrel", "%.8g",
      "top wall's centre of mass along x, relative to the start"),
    C("wall_velocity", "sigma/tau", "velocity", "v_vxw", "%.8g",
      "top wall's centre-of-mass velocity along x"),
    C("wall_z", "sigma", "length", "v_zw", "%.8g", "top wall's centre of mass along z"),
    C("gap", "sigma", "length", "v_gap", "%.8g",
      "distance between the walls' innermost planes (the planes facing the film)"),
    C("film_temperature", "epsilon/k_B", "temperature", "v_T", "%.6g",
      "film temperature along y (the thermostatted, flow-free direction)"),
    C("drive_work", "epsilon", "energy", "v_wdrive", "%.10g",
      "work of the drive on spring and mount dashpot, V * integral of the force, "
      "sampled every work_every steps"),
    C("load_work", "epsilon", "energy", "v_wload", "%.10g",
      "work of the load, -P*A*(z - z0)"),
    C("thermostat_heat", "epsilon", "energy", "v_heat", "%.10g",
      "heat removed by the Langevin thermostat(s) since the drive started"),
    C("potential_energy", "epsilon", "energy", "v_pe", "%.10g", "sum of the pair energies"),
    C("kinetic_energy", "epsilon", "energy", "v_ke", "%.10g", "sum of m v^2 / 2"),
    C("spring_energy", "epsilon", "energy", "v_espring", "%.10g", "K (x_d - x)^2 / 2"),
    C("mount_heat", "epsilon", "energy", "v_qmount", "%.10g",
      "heat taken by the mount dashpot since the drive started"),
)
del C

#: ``trace.dat`` (fix print) column names, in order.
DAT_COLUMNS: tuple[str, ...] = tuple(c.name for c in TRACE)
#: ``trace.csv`` column names, in order: time first, then as in ``trace.dat``.
TRACE_COLUMNS: tuple[str, ...] = ("time",) + tuple(n for n in DAT_COLUMNS if n != "time")
#: LJ unit of each column (``run.json``'s ``trace_units``).
TRACE_UNITS: dict[str, str] = {
    c.name: c.unit for c in sorted(TRACE, key=lambda c: TRACE_COLUMNS.index(c.name))}


def column(name: str) -> Column:
    """The contract's entry for column ``name``."""
    for c in TRACE:
        if c.name == name:
            return c
    raise KeyError(f"no trace column {name!r}; the contract has: {', '.join(DAT_COLUMNS)}")


def fix_print_text() -> str:
    """The quoted text of the script's ``fix print`` (one row of ``trace.dat``)."""
    return " ".join(c.lammps() for c in TRACE)


def fix_print_title() -> str:
    """The ``title`` of the script's ``fix print`` (the header of ``trace.dat``)."""
    return "# " + " ".join(DAT_COLUMNS)


def check_head(text: str, *, timestep: float, trace_every: int, drive_velocity: float,
               spring_constant: float, temperature: float, rows: int = 4) -> str | None:
    """What breaks this contract in the first ``rows`` rows of a ``trace.dat`` (None: nothing).

    For a script other than ``film_slide.lmp``: the header names the columns in
    order; each row has them all, as numbers; the step advances by
    ``trace_every``; and the units are LJ: time = step x timestep (tau), the
    spring end moves at V (drive_position = V x time, sigma), spring_force =
    K (drive_position - wall_position) (epsilon/sigma), and the film's
    temperature is within a factor 5 of the thermostat's (epsilon/k_B).  Fewer
    rows than ``rows`` are checked as far as they go.

    Examples
    --------
    >>> head = fix_print_title() + "\\n0 0 0 0 0 0 7 3 0.7 0 0 0 -1 1 0 0\\n"
    >>> good = dict(timestep=0.005, trace_every=50, drive_velocity=0.02,
    ...             spring_constant=100.0, temperature=0.7)
    >>> check_head(head + "50 0.25 0.005 0.5 0 0 7 3 0.7 0 0 0 -1 1 0 0", **good) is None
    True
    >>> print(check_head(head + "50 250 5 5000 0 0 7 3 300 0 0 0 -1 1 0 0", **good))
    trace.dat row 2 (step 50): time = 250, expected step x timestep = 0.25 tau (LJ units)
    """
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines or lines[0].split() != fix_print_title().split():
        found = lines[0][:120] if lines else "nothing"
        return (f"trace.dat header is {found!r}, expected {fix_print_title()!r} (the "
                f"columns of md_inputs/contract.py, in order)")
    previous = None
    for i, line in enumerate(lines[1:rows + 1], start=1):
        parts = line.split()
        where = f"trace.dat row {i}"
        if len(parts) != len(TRACE):
            return (f"{where} has {len(parts)} values, expected {len(TRACE)} "
                    f"({' '.join(DAT_COLUMNS)})")
        try:
            row = dict(zip(DAT_COLUMNS, (float(x) for x in parts)))
        except ValueError:
            return f"{where} is not all numbers: {line[:120]!r}"
        step, where = row["step"], f"{where} (step {row['step']:g})"
        if previous is not None and step - previous != trace_every:
            return (f"{where}: steps advance by {step - previous:g}, expected trace_every = "
                    f"{trace_every}")
        previous = step
        checks = (("time", step * timestep, "step x timestep", "tau"),
                  ("drive_position", drive_velocity * row["time"], "V x time", "sigma"),
                  ("spring_force", spring_constant * (row["drive_position"] - row["wall_position"]),
                   "K (drive_position - wall_position)", "epsilon/sigma"))
        for name, expected, rule, unit in checks:
            if abs(row[name] - expected) > 1e-5 * max(1.0, abs(expected)):
                return (f"{where}: {name} = {row[name]:g}, expected {rule} = {expected:g} "
                        f"{unit} (LJ units)")
        T = row["film_temperature"]
        if temperature > 0 and not temperature / 5 <= T <= 5 * temperature:
            return (f"{where}: film_temperature = {T:g}, expected near the thermostat's "
                    f"{temperature:g} epsilon/k_B (LJ units)")
    return None
