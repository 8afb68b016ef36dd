"""The parameters a scene may set: their table (name, type, range, unit, help), the
checks between them, the quantities derived from them, and ``--set KEY=VALUE``.

Every value is a known name, of the declared type, finite and inside the declared
range (:func:`resolve`), and reaches LAMMPS only as a number formatted by
:meth:`filmfriction.workflows.md.scene.Scene.lammps_variables`.  The shipped scenes
(the ``*.toml`` files beside this module) are checked against this table.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from filmfriction.md_inputs.geometry import ConfinedFilm, fewest_wall_planes


class SceneError(ValueError):
    """A scene or a parameter value is not acceptable; the message says why."""


@dataclass(frozen=True)
class Parameter:
    """One scene parameter: type, unit, default and allowed range (inclusive).

    A parameter with ``choices`` is a name from that list (``kind`` str); LAMMPS
    receives its position in the list, never the text.
    """

    name: str
    kind: type            # int, float or str (with choices)
    unit: str
    default: float | int | str
    low: float
    high: float
    help: str
    low_open: bool = False  # True: the lower bound itself is excluded
    choices: tuple[str, ...] = ()

    def check(self, value: Any) -> float | int | str:
        if self.choices:
            if not isinstance(value, str) or value not in self.choices:
                raise SceneError(f"{self.name} = {value!r}: must be one of "
                                 f"{', '.join(self.choices)} ({self.help})")
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SceneError(
                f"{self.name} = {value!r}: must be a number ({self.kind.__name__}, "
                f"{self.unit}), not {type(value).__name__}")
        if self.kind is int:
            if isinstance(value, float):
                if not value.is_integer():
                    raise SceneError(f"{self.name} = {value!r}: must be a whole number in "
                                     f"[{self.low}, {self.high}] ({self.help})")
                value = int(value)
        else:
            value = float(value)
            if not math.isfinite(value):
                raise SceneError(f"{self.name} = {value!r}: must be finite")
        below = value <= self.low if self.low_open else value < self.low
        if below or value > self.high:
            bracket = "(" if self.low_open else "["
            raise SceneError(
                f"{self.name} = {value}{'' if self.unit == '-' else ' ' + self.unit}: outside "
                "the allowed range "
                f"{bracket}{self.low}, {self.high}] ({self.help})")
        return value


# Steps between samples of the drive's and the mount's power (at most): they
# change over hundreds of steps, and sampling every step cost a fifth of a run.
WORK_EVERY = 10

# Flexible walls: an LJ crystal of atoms twice as strongly bound and twice as
# heavy as the film's, so its fastest vibration is the film's own (the time
# step limit is unchanged) while it stays crystalline at kT = 1 (kT/eps_ww = 0.5,
# below the LJ triple point 0.69).
FLEXIBLE_WALL_EPSILON = 2.0
FLEXIBLE_WALL_ATOM_MASS = 2.0
# Hottest the flexible walls may be run at: half their bond energy, well below
# their melting near kT = 0.7 eps_ww (tests/test_md_walls.py runs it).
FLEXIBLE_WALL_MAX_TEMPERATURE = 0.5 * FLEXIBLE_WALL_EPSILON

# A twisted top wall is stretched to fit the box: at most this strain along x or y.
TWISTED_WALL_MAX_STRAIN = 0.05

# A cutoff at the LJ minimum leaves only the repulsion (Weeks-Chandler-Andersen).
WCA_CUTOFF = 2.0 ** (1.0 / 6.0)

P = Parameter
#: the largest seed a scene takes: fix langevin refuses seeds above 900 000 000 and the
#: flexible walls' thermostats use seed + 4 (film_slide.lmp's segment seeds stay below it)
SEED_MAX = 899_999_990

# Physics' own names: these are the user-facing contract.
PARAMETERS: dict[str, Parameter] = {p.name: p for p in [
    P("drive_velocity", float, "sigma/tau", 0.02, 0.0, 5.0,
      "velocity of the spring's far end (0 only with release_offset > 0)"),
    P("release_offset", float, "sigma", 0.0, 0.0, 1000.0,
      "release test: the spring's far end starts this far ahead of the wall (x0), "
      "so the wall is let go from a stretched spring; 0 = no offset"),
    P("preload_force", float, "epsilon/sigma", 0.0, 0.0, 1.0e4,
      "start-up shortcut: over the first preload_steps the spring's end runs ahead of the "
      "drive until the spring holds this much more force (a ramp; choose it below the "
      "static friction force); 0 = none"),
    P("preload_steps", int, "steps", 0, 0, 2**31 - 1,
      "length of the preload ramp (longer than the wall's ringing period on the film)"),
    P("hold_gap", int, "-", 0, 0, 1,
      "1 = the top wall's z frozen for the slide (free along x only, at the gap it reached "
      "under the load while equilibrating: the load does no work); 0 = free along z"),
    P("spring_constant", float, "epsilon/sigma^2", 100.0, 0.0, 1.0e5,
      "stiffness of the drive spring", low_open=True),
    P("normal_pressure", float, "epsilon/sigma^3", 1.0, 0.0, 100.0,
      "normal load per area on the top wall"),
    P("temperature", float, "epsilon/k_B", 0.7, 0.0, 5.0,
      "film thermostat temperature"),
    P("film_layers", int, "-", 3, 1, 8, "close-packed layers of film atoms"),
    P("wall_mass", float, "m", 500.0, 0.0, 1.0e7,
      "total mass of the rigid top wall", low_open=True),
    P("wall_fluid_epsilon", float, "epsilon", 1.0, 0.0, 10.0,
      "wall-film LJ interaction strength", low_open=True),
    P("wall_spacing", float, "sigma", 1.1, 0.8, 1.6,
      "nearest-neighbour distance in the walls' (111) planes"),
    P("film_spacing", float, "sigma", 1.1, 0.8, 1.6,
      "in-plane spacing the film is built with (sets its atom count)"),
    P("wall_layers", int, "-", 0, 0, 20,
      "(111) planes per wall; 0 = fewest that span the cutoff"),
    P("cells_x", int, "-", 7, 1, 200, "wall rows along x (Lx = cells_x * wall_spacing)"),
    P("cells_y", int, "-", 4, 1, 200,
      "wall row pairs along y (Ly = cells_y * sqrt(3) * wall_spacing)"),
    P("timestep", float, "tau", 0.005, 0.0, 0.05, "integration step", low_open=True),
    P("cutoff", float, "sigma", 2.5, WCA_CUTOFF, 6.0,
      "LJ cutoff (2^(1/6) = purely repulsive WCA)"),
    P("thermostat_damping", float, "tau", 1.0, 0.0, 1.0e6,
      "Langevin damping time of the film thermostat", low_open=True),
    P("wall_model", str, "-", "rigid", 0, 0,
      "rigid: each wall one rigid body; flexible: the planes facing the film are an LJ "
      "crystal on a rigid outer plane, so heat and strain can enter the walls",
      choices=("rigid", "flexible")),
    P("top_wall_twist", str, "-", "aligned", 0, 0,
      "aligned: the top wall's close-packed rows along x, as the bottom wall's and the "
      "film's; twisted: turned by 90 degrees about z (30 degrees off the rows), its lattice "
      "stretched to the box, so the film is in registry with the bottom wall only",
      choices=("aligned", "twisted")),
    P("wall_vacancies", float, "-", 0.0, 0.0, 0.5,
      "fraction of each wall's plane facing the film left vacant, at random sites "
      "drawn from seed"),
    P("thermostat_placement", str, "-", "film", 0, 0,
      "film: Langevin on the film along y only; walls: on the flexible walls' atoms "
      "(the film unthermostatted, as in an experiment); both",
      choices=("film", "walls", "both")),
    P("mount_damping", float, "1/tau", 0.3, 0.0, 100.0,
      "mount dashpot: -gamma*M*(vx - V) in parallel with the spring, -gamma*M*vz along z"),
    # the script derives seed+1 .. seed+4 for the flexible walls: all stay a 32-bit int
    P("seed", int, "-", 4928459, 1, SEED_MAX, "random seed (velocities, thermostat)"),
    P("equilibrate_steps", int, "steps", 10000, 0, 10**9,
      "loaded and thermostatted, spring off"),
    # LAMMPS's run command takes at most 2^31 - 1 steps
    P("slide_steps", int, "steps", 100000, 1, 2**31 - 1, "spring drive on"),
    P("trace_every", int, "steps", 50, 1, 10**7, "interval of trace.csv rows"),
    P("restart_every", int, "steps", 20000, 0, 10**9,
      "restart-file interval for --resume (0 = none)"),
    P("dump_every", int, "steps", 500, 1, 10**9,
      "trajectory frame interval (used only when the scene asks for structure)"),
    P("profile_every", int, "steps", 5000, 1, 10**9,
      "density/velocity profile interval (used only when profiles are asked for)"),
    P("profile_bin", float, "sigma", 0.05, 0.0, 1.0,
      "profile bin width along z", low_open=True),
]}
del P

# The scene's outputs: what each asks of the engine beyond the trace (the trace's own
# quantities, or a trajectory, or profiles); a scene lists the ones it needs.
OUTPUTS = {
    "stick_slip": "stick-slip events from the spring force (trace)",
    "energy": "energy partition and ledger (trace)",
    "viscosity_from_slip": "effective viscosity from the slip dynamics (trace)",
    "viscosity_steady": "effective viscosity from steady sliding (trace)",
    "structure": "layering and in-plane order of the film (DCD trajectory)",
    "profiles": "density and velocity profiles across the gap (fix ave/chunk)",
}
NEEDS_TRAJECTORY = {"structure"}
NEEDS_PROFILES = {"profiles"}

# LJ time step limits.  0.01 tau is where velocity Verlet stops conserving
# energy for LJ atoms of unit mass at liquid density; a stiffer wall-film
# interaction shortens the fastest vibration as 1/sqrt(eps_wf).
LJ_TIMESTEP_LIMIT = 0.01
# Resolve the wall-on-spring oscillation with at least this many steps.
STEPS_PER_SPRING_PERIOD = 50


def geometry(p: dict) -> ConfinedFilm:
    """The walls and the film the parameters describe (built with ASE when asked for)."""
    return ConfinedFilm(
        wall_spacing=p["wall_spacing"], film_spacing=p["film_spacing"],
        cells=(p["cells_x"], p["cells_y"]), film_layers=p["film_layers"],
        wall_planes=p["wall_layers"] or fewest_wall_planes(p["cutoff"], p["wall_spacing"]),
        cutoff=p["cutoff"], flexible_walls=p["wall_model"] == "flexible",
        top_wall_twisted=p["top_wall_twist"] == "twisted",
        vacancy_fraction=p["wall_vacancies"], vacancy_seed=p["seed"])


def derived_quantities(p: dict) -> dict[str, float]:
    """Box, atom counts and time scales implied by the parameters (before LAMMPS runs)."""
    # the walls' (111) planes, and the film's, stretched to fit the walls' box
    # (the geometry film_slide.lmp reads from its data file)
    g = geometry(p)
    wall, film, wall_layers = g.bottom, g.film, g.wall_planes
    lx, ly = wall.box
    omega = math.sqrt(p["spring_constant"] / p["wall_mass"])
    flexible = p["wall_model"] == "flexible"
    wall_per_layer = wall.atoms_per_plane
    return {
        "box_x": lx, "box_y": ly, "area": lx * ly,
        "film_atoms_per_layer": film.atoms_per_plane,
        "film_atoms": film.n_atoms,
        "film_strain_x": film.strain[0],
        "film_strain_y": film.strain[1],
        "wall_layers": wall_layers,
        "wall_atoms_per_layer": wall_per_layer,
        # the top wall's planes facing the film, mobile when the walls are flexible
        "top_flexible_mass": ((wall_layers - 1) * g.top.atoms_per_plane
                              - g.vacancies_per_wall[1]) * FLEXIBLE_WALL_ATOM_MASS
        if flexible else 0.0,
        "top_wall_strain_x": g.top.strain[0],
        "top_wall_strain_y": g.top.strain[1],
        "spring_period": 2.0 * math.pi / omega,
        "timestep_limit": min(LJ_TIMESTEP_LIMIT / math.sqrt(max(1.0, p["wall_fluid_epsilon"])),
                              2.0 * math.pi / omega / STEPS_PER_SPRING_PERIOD),
        "slide_time": p["slide_steps"] * p["timestep"],
        "drive_distance": p["slide_steps"] * p["timestep"] * p["drive_velocity"],
    }


def check_consistency(p: dict) -> None:
    """Checks between parameters, each naming the values and the reason."""
    if p["drive_velocity"] == 0.0 and p["release_offset"] == 0.0:
        raise SceneError(
            "drive_velocity = 0.0 sigma/tau: must be > 0, or a release test "
            "(release_offset > 0: the wall let go from a spring stretched by x0, undriven)")
    if (p["preload_force"] > 0.0) != (p["preload_steps"] > 0):
        raise SceneError(
            f"preload_force = {p['preload_force']:g} epsilon/sigma with preload_steps = "
            f"{p['preload_steps']}: give both (a force > 0 reached over > 0 steps) or neither")
    if p["preload_steps"] > p["slide_steps"]:
        raise SceneError(
            f"preload_steps = {p['preload_steps']} is longer than slide_steps = "
            f"{p['slide_steps']}: the preload ramp must end within the slide")
    q = derived_quantities(p)
    dt = p["timestep"]
    lj_limit = LJ_TIMESTEP_LIMIT / math.sqrt(max(1.0, p["wall_fluid_epsilon"]))
    if dt > lj_limit:
        raise SceneError(
            f"timestep {dt:g} tau is above the stability limit {lj_limit:.3g} tau of the LJ "
            f"interactions (0.01 tau / sqrt(max(1, wall_fluid_epsilon = "
            f"{p['wall_fluid_epsilon']:g})))")
    spring_limit = q["spring_period"] / STEPS_PER_SPRING_PERIOD
    if dt > spring_limit:
        raise SceneError(
            f"timestep {dt:g} tau is above the stability limit {spring_limit:.3g} tau for "
            f"spring_constant K={p['spring_constant']:g} epsilon/sigma^2 and wall_mass "
            f"M={p['wall_mass']:g} m (the wall's period 2*pi*sqrt(M/K) = "
            f"{q['spring_period']:.3g} tau needs >= {STEPS_PER_SPRING_PERIOD} steps)")
    for axis in ("x", "y"):
        length = q[f"box_{axis}"]
        if length < 2.0 * p["cutoff"]:
            cells = f"cells_{axis}"
            raise SceneError(
                f"lateral box L{axis} = {length:.3g} sigma (cells_{axis}={p[cells]}) is "
                f"shorter than 2 cutoffs = {2 * p['cutoff']:.3g} sigma: an atom would feel "
                f"its own periodic image; raise {cells}")
    for axis in ("x", "y"):
        strain = q[f"film_strain_{axis}"]
        if abs(strain) > 0.1:
            raise SceneError(
                f"film_spacing {p['film_spacing']:g} sigma does not fit the box along {axis} "
                f"(the film would be strained by {100 * strain:+.0f} %, limit 10 %): change "
                f"cells_{axis} or film_spacing")
    if p["normal_pressure"] == 0.0 and p["cutoff"] <= WCA_CUTOFF * (1.0 + 1e-9):
        raise SceneError(
            f"normal_pressure 0 with cutoff {p['cutoff']:.6g} sigma (purely repulsive WCA): "
            f"nothing holds the top wall on the film, it drifts off and LAMMPS loses atoms; "
            f"give normal_pressure > 0 or a cutoff > 2^(1/6) sigma (wall-film adhesion)")
    if p["thermostat_damping"] < 10.0 * dt:
        raise SceneError(
            f"thermostat_damping {p['thermostat_damping']:g} tau is shorter than 10 time steps "
            f"({10 * dt:g} tau): the Langevin thermostat would be unstable")
    if p["top_wall_twist"] == "twisted":
        for axis, strain in zip("xy", (q["top_wall_strain_x"], q["top_wall_strain_y"])):
            if abs(strain) > TWISTED_WALL_MAX_STRAIN:
                raise SceneError(
                    f"top_wall_twist = 'twisted' does not fit the box along {axis}: the turned "
                    f"top wall would be strained by {100 * strain:+.1f} % (limit "
                    f"{100 * TWISTED_WALL_MAX_STRAIN:g} %); choose cells_x, cells_y with "
                    f"cells_x close to sqrt(3) * cells_y * k / m for whole k, m (7 x 4: 1 %)")
    flexible_mass = q["top_flexible_mass"]
    if p["wall_mass"] <= flexible_mass:
        raise SceneError(
            f"wall_mass {p['wall_mass']:g} m is not above the mass of the top wall's flexible "
            f"planes ({flexible_mass:g} m: {q['wall_layers'] - 1} planes of "
            f"{q['wall_atoms_per_layer']} atoms of {FLEXIBLE_WALL_ATOM_MASS:g} m); with "
            f"wall_model = 'flexible' the rigid backing carries the rest of M: raise wall_mass")
    if p["wall_model"] == "flexible" and p["temperature"] > FLEXIBLE_WALL_MAX_TEMPERATURE:
        raise SceneError(
            f"temperature {p['temperature']:g} epsilon/k_B is above "
            f"{FLEXIBLE_WALL_MAX_TEMPERATURE:g}, the limit for flexible walls (LJ crystals "
            f"of eps_ww = {FLEXIBLE_WALL_EPSILON:g} epsilon melt near kT = 0.7 eps_ww): "
            f"use wall_model = 'rigid' for a hotter film")
    if p["thermostat_placement"] != "film" and p["wall_model"] != "flexible":
        raise SceneError(
            f"thermostat_placement = {p['thermostat_placement']!r} needs wall_model = "
            f"'flexible': rigid walls have no thermal motion to thermostat")
    if p["profile_bin"] > 0.5 * q["wall_layers"] * math.sqrt(2 / 3) * p["wall_spacing"]:
        raise SceneError(f"profile_bin {p['profile_bin']:g} sigma is too coarse to resolve layers")


def resolve(raw: dict[str, Any], overrides: dict[str, Any] | None = None) -> dict:
    """Defaults + scene values + overrides, each checked; returns typed parameters."""
    values: dict[str, Any] = {}
    for source in (raw, overrides or {}):
        for key, value in source.items():
            if key not in PARAMETERS:
                raise SceneError(
                    f"unknown parameter {key!r}; known: {', '.join(sorted(PARAMETERS))}")
            values[key] = PARAMETERS[key].check(value)
    resolved = {name: values.get(name, spec.default) for name, spec in PARAMETERS.items()}
    for name, spec in PARAMETERS.items():
        resolved[name] = spec.check(resolved[name])
    check_consistency(resolved)
    return resolved


def split_parameter(text: str, flag: str, form: str) -> tuple[str, str]:
    """``KEY`` and the text after ``=`` of a command-line ``KEY=...`` (``--set``,
    ``--grid``); KEY must name a scene parameter."""
    if "=" not in text:
        raise SceneError(f"{flag} {text!r}: expected {form}")
    key, _, rest = text.partition("=")
    key = key.strip()
    if key not in PARAMETERS:
        raise SceneError(f"{flag} {text!r}: unknown parameter {key!r}; known: "
                         f"{', '.join(sorted(PARAMETERS))}")
    return key, rest


def parse_assignment(text: str) -> tuple[str, float | int]:
    """``KEY=VALUE`` from the command line; VALUE must be a number or, for a
    parameter with choices, one of them."""
    key, value = split_parameter(text, "--set", "KEY=VALUE")
    if PARAMETERS[key].choices:
        return key, PARAMETERS[key].check(value.strip())
    spec = PARAMETERS[key]
    try:
        number = float(value)
        if spec.kind is int:
            # 1e5 or 3.0 are whole numbers too (a TOML file may write them so as well)
            number = int(value) if value.strip().lstrip("+-").isdigit() else int(number) \
                if number.is_integer() else None
            if number is None:
                raise ValueError(value)
    except (ValueError, OverflowError):
        bracket = "(" if spec.low_open else "["
        what = (f"a whole number in [{spec.low}, {spec.high}]" if spec.kind is int
                else f"a number in {bracket}{spec.low:g}, {spec.high:g}] {spec.unit}")
        raise SceneError(f"--set {key}={value.strip()!r}: not {what} ({spec.help})") from None
    return key, number
