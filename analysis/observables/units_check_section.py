"""``units_check``: do the trace's numbers agree with its K and V, in the units read?

While the surface sticks, the spring's end moves at V and the spring force rises at
K·V (less when the film yields elastically or creeps: by k_f/(K + k_f) for a film
of stiffness k_f in series).  The ratio of the stick ramps' slope to K·V therefore
lies a little below 1 on a trace read in its own units, and a unit read wrongly
moves it by the factor of that unit: a force in µN read as N multiplies it by 10⁶,
a time in ms read as s by 10⁻³.  Likewise the drive column's slope is V.

The check
---------
* the stick ramps: each stick (re-stick s to the next yield y, the slips the
  analysis found; the start-up ramp left out), its middle 60 % (the ringing after
  s and the creep before y left out) fitted by a straight line; the median of the
  slopes over K·V.  It agrees when it lies within :data:`RAMP_BAND`, 0.1 to 3:
  no stick rises faster than K·V beyond its noise, a film ten times softer than
  the spring still passes (the default MD scene on the tests' small box gives
  0.61, a film about 1.5 times as stiff as its spring; the SFB example 1.00), and a unit's prefix moves
  the ratio by 10³ or more;
* the drive column: its straight-line slope over ``--drive-velocity`` (when both
  are given), agreeing within :data:`DRIVE_BAND` (±10 %: a drive is prescribed);
* the columns' names: a name that ends in a unit (``t_ms``, ``F [uN]``) of the
  right quantity, read in another unit.

A disagreement is a warning in the section's ``warnings`` (printed by
``filmfriction analyze``), which names the units that would make the numbers
agree: for an SI trace the force, time and drive prefixes whose change brings
every ratio into its band, fewest changes first.
"""
from __future__ import annotations

import itertools
import math
import re

import numpy as np

from ..files.trace import MissingInput
from .observable import Context, Observable, format_value

__all__ = ["UnitsCheck", "RAMP_BAND", "DRIVE_BAND", "stick_ramp_slopes", "likely_units",
           "name_hint"]

#: The ratio of the stick ramps' slope to K·V that agrees with the units read.
RAMP_BAND = (0.1, 3.0)
#: The ratio of the drive column's slope to V that agrees.
DRIVE_BAND = (0.9, 1.1)

# the units tried when a ratio disagrees (SI traces), per column
_CANDIDATES = {"spring_force": ("N", "mN", "uN", "nN", "pN"),
               "time": ("s", "ms", "us", "ns"),
               "drive_position": ("m", "mm", "um", "nm")}
_SI_BASE = {"spring_force": "N", "time": "s", "drive_position": "m"}


def stick_ramp_slopes(time, force, yield_index, stick_index) -> np.ndarray:
    """The slope of each stick (s to the next y) over its middle 60 %, by least
    squares; sticks of fewer than 5 samples there are left out."""
    slopes = []
    for s, y in zip(stick_index[:-1], yield_index[1:]):
        s, y = int(s), int(y)
        n = y - s
        a, b = s + int(round(0.2 * n)), s + int(round(0.8 * n))
        if b - a + 1 < 5:
            continue
        t, f = time[a:b + 1], force[a:b + 1]
        slopes.append(np.polyfit(t - t[0], f, 1)[0])
    return np.asarray(slopes, dtype=float)


def name_hint(column_name: str, quantity: str) -> str | None:
    """The unit a column's name ends in (``t_ms`` -> ``ms``, ``F [uN]`` -> ``uN``) when it
    is a unit of ``quantity``, else None.

    >>> name_hint("t_ms", "time"), name_hint("shear_force_N", "force"), name_hint("v_fs", "force")
    ('ms', 'N', None)
    """
    from filmfriction.reduced_model.units import parse_unit

    tokens = [t for t in re.split(r"[_\s\[\]\(\){}]+", column_name) if t]
    if len(tokens) < 2:
        return None
    try:
        unit_ = parse_unit(tokens[-1])
    except ValueError:
        return None
    return tokens[-1] if unit_.system == "si" and unit_.dimension_of(quantity) else None


def _factor(unit_text: str) -> float:
    from filmfriction.reduced_model.units import parse_unit

    return parse_unit(unit_text).factor


def likely_units(ratios: dict, current: dict, bands: dict,
                 named: dict | None = None) -> list[dict]:
    """The units of ``spring_force``, ``time`` and ``drive_position`` that would bring
    every ratio into its band, fewest changes from ``current`` first (at most three);
    those that agree with the units the columns' names suggest (``named``) before all.

    Parameters
    ----------
    ratios : dict
        ``{"stick_ramp": r, "drive": r_d}`` (either may be absent): measured / expected.
    current : dict
        The unit each of the three columns was read in.
    bands : dict
        The band of each ratio.
    named : dict, optional
        Column -> the unit its name ends in (:func:`name_hint`).

    Examples
    --------
    >>> likely_units({"stick_ramp": 0.9e6}, {"spring_force": "N", "time": "s"},
    ...              {"stick_ramp": RAMP_BAND})[0]
    {'spring_force': 'uN'}
    """
    columns = ["spring_force", "time"] + (["drive_position"] if "drive" in ratios else [])
    found = []
    for combo in itertools.product(*(_CANDIDATES[c] for c in columns)):
        units = dict(zip(columns, combo))
        scale = {c: _factor(units[c]) / _factor(current[c]) for c in columns}
        new = {}
        if "stick_ramp" in ratios:
            new["stick_ramp"] = ratios["stick_ramp"] * scale["spring_force"] / scale["time"]
        if "drive" in ratios:
            new["drive"] = ratios["drive"] * scale["drive_position"] / scale["time"]
        if all(bands[k][0] <= v <= bands[k][1] for k, v in new.items()):
            changed = {c: units[c] for c in columns if _factor(units[c]) != _factor(current[c])}
            if changed:
                misfit = sum(abs(math.log10(v)) for v in new.values())
                as_named = all(_factor(units[c]) == _factor(u)
                               for c, u in (named or {}).items() if c in units)
                found.append((len(changed), misfit, changed, bool(named) and as_named))
    found.sort(key=lambda x: (x[0], x[1]))
    if not found:
        return []
    fewest = found[0][0]
    chosen = [f for f in found if f[0] <= fewest + 1 or f[3]]
    chosen.sort(key=lambda f: not f[3])
    return [f[2] for f in chosen][:3]


def _say(change: dict, where: dict) -> str:
    said = [f"{name} ({where.get(name, name)}) in {unit}" for name, unit in change.items()]
    return said[0] if len(said) == 1 else ", ".join(said[:-1]) + " and " + said[-1]


def _times(x: float) -> str:
    """A ratio as people write it: 0.98, 1.2e3, 1e-6."""
    if 0.01 <= abs(x) < 100:
        return f"{x:.2g}"
    x = float(f"{x:.2g}")
    e = math.floor(math.log10(abs(x)))
    return f"{x / 10 ** e:.2g}e{e}"


class UnitsCheck(Observable):
    """The stick ramps against K·V and the drive column against V."""

    key = "units_check"
    title = "Units: the stick ramps against K·V"
    order = 90
    table_header = ("check", "value")
    absent = "No units check"

    def compute(self, ctx: Context) -> tuple[dict, dict]:
        trace = ctx.trace
        K = trace.parameters.spring_constant
        V_given = trace.parameters.drive_velocity
        V, v_from = trace.drive_velocity()
        layout = trace.layout
        given_units = dict(layout.column_units) if layout is not None else {}
        file_names = dict(layout.columns) if layout is not None else {}
        rate = f"{ctx.unit('force')}/{ctx.unit('time')}"
        section = {"band": {"stick_ramp": list(RAMP_BAND), "drive": list(DRIVE_BAND)},
                   "warnings": []}
        ratios = {}
        if K is None:
            ctx.skip_part("units_check.stick_ramp",
                          MissingInput("--spring-constant", "the stick ramps' expected slope K·V"))
        elif V is None:
            ctx.skip_part("units_check.stick_ramp",
                          MissingInput("--drive-velocity (or a drive_position column)",
                                       "the stick ramps' expected slope K·V"))
        elif not V > 0:
            ctx.skip_part("units_check.stick_ramp", f"the drive's velocity V = {V:g} ({v_from}) "
                                                    "is not positive")
        else:
            table = ctx.all_slips
            slopes = stick_ramp_slopes(trace.time, trace.spring_force, table.yield_index,
                                       table.stick_index)
            if slopes.size == 0:
                ctx.skip_part("units_check.stick_ramp",
                              "no stick between two slips with 5 samples or more in its "
                              "middle 60 %")
            else:
                r = slopes / (K * V)
                ratio = float(np.median(r))
                ratios["stick_ramp"] = ratio
                section["stick_ramp"] = {
                    "ratio": ratio, "min": float(r.min()), "max": float(r.max()),
                    "sticks": int(r.size),
                    "expected_slope": {"mean": K * V, "stderr": None, "units": rate,
                                       "velocity_from": v_from},
                    "agrees": bool(RAMP_BAND[0] <= ratio <= RAMP_BAND[1])}
        if trace.has("drive_position") and V_given is not None and len(trace) > 1:
            slope = float(np.polyfit(trace.time - trace.time[0],
                                     trace.columns["drive_position"], 1)[0])
            ratio = slope / V_given
            ratios["drive"] = ratio
            section["drive"] = {"ratio": ratio, "slope": {"mean": slope, "stderr": None,
                                                          "units": ctx.unit("velocity")},
                                "agrees": bool(DRIVE_BAND[0] <= ratio <= DRIVE_BAND[1])}
        elif trace.has("drive_position"):
            ctx.skip_part("units_check.drive", "V is the drive column's own slope "
                                               "(no --drive-velocity to compare it with)")
        hints = []
        for name, quantity in (("time", "time"), ("spring_force", "force"),
                               ("drive_position", "length"), ("wall_position", "length")):
            src = file_names.get(name)
            hint = name_hint(src, quantity) if src else None
            read_in = given_units.get(name, _SI_BASE.get(name, "m"))
            if (hint and trace.units == "si" and trace.has(name)
                    and not math.isclose(_factor(hint), _factor(read_in))):
                hints.append({"column": name, "file_column": src, "named": hint,
                              "read_in": read_in})
                section["warnings"].append(
                    f"column {src!r} is named like {hint} but read in {read_in}: if it is in "
                    f"{hint}, give --column {name}={src}:{hint}")
        section["name_hints"] = hints
        bad = {k: v for k, v in ratios.items()
               if not section["band"][k][0] <= v <= section["band"][k][1]}
        if bad:
            named = {h["column"]: h["named"] for h in hints}
            section["warnings"].append(self._warning(trace, ratios, bad, given_units, file_names,
                                                     K, V, rate, named))
        if not (section.get("stick_ramp") or section.get("drive") or section["warnings"]):
            why = ctx.skipped.pop("units_check.stick_ramp", "nothing to check")
            ctx.skipped.pop("units_check.drive", None)
            ctx.skip_part("units_check", why)
            return None, {}
        return section, {}

    @staticmethod
    def _warning(trace, ratios, bad, given_units, file_names, K, V, rate, named) -> str:
        said = []
        if "stick_ramp" in bad:
            said.append(f"the stick ramps rise at {_times(bad['stick_ramp'])} × K·V "
                        f"(K·V = {K * V:.3g} {rate})")
        if "drive" in bad:
            said.append(f"the drive column moves at {_times(bad['drive'])} × V")
        band = (f"agreement: {RAMP_BAND[0]:.2g} to {RAMP_BAND[1]:.2g} for the ramps, "
                f"{DRIVE_BAND[0]:.2g} to {DRIVE_BAND[1]:.2g} for the drive")
        text = "units: " + "; ".join(said) + f" ({band})"
        if trace.units != "si":
            return (text + ": check K and V (run.json, --spring-constant, --drive-velocity) "
                           "and the columns' units")
        current = {c: given_units.get(c, _SI_BASE[c]) for c in _CANDIDATES}
        guesses = likely_units(ratios, current, {"stick_ramp": RAMP_BAND, "drive": DRIVE_BAND},
                               named)
        if guesses:
            alternatives = "; or ".join(_say(g, file_names) for g in guesses)
            example = next(iter(guesses[0].items()))
            return (text + f": is {alternatives}? Give a column's unit with --column "
                           f"{example[0]}={file_names.get(example[0], example[0])}:{example[1]} "
                           "(or is K or V off by that factor?)")
        if any(v < 0 for v in bad.values()):
            return text + (": a negative ratio: the force or the drive counts the other way "
                           "(a sign convention), or the columns are not what they are named")
        return text + ": no change of the force, time or drive units explains it; check K and V"

    def shown(self, section: dict) -> bool:
        return bool(section.get("stick_ramp") or section.get("drive") or section.get("warnings"))

    def rows(self, section: dict) -> list[tuple[str, str]]:
        rows = []
        ramp = section.get("stick_ramp")
        if ramp:
            rows.append(("stick ramps' slope / K·V (median over "
                         f"{ramp['sticks']} sticks)",
                         f"{format_value(ramp['ratio'], 3)} "
                         f"({'agrees' if ramp['agrees'] else 'disagrees'})"))
        drive = section.get("drive")
        if drive:
            rows.append(("drive column's slope / V",
                         f"{format_value(drive['ratio'], 3)} "
                         f"({'agrees' if drive['agrees'] else 'disagrees'})"))
        return rows

    def notes(self, section: dict) -> list[str]:
        lo, hi = section["band"]["stick_ramp"]
        out = [f"While the surface sticks the spring force rises at K·V, less by the film's "
               f"compliance or creep; a ratio outside {lo:.2g} to {hi:.2g} means a column, K or "
               "V is in other units than the analysis takes."]
        out += [f"**Warning**: {w}" for w in section.get("warnings", [])]
        return out
