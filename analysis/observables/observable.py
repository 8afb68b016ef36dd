"""The observable interface, the registry, and what observables share.

An observable is one section of ``analysis.json`` and one section of the
report, declared in one file of this package:

* what it needs -- :attr:`Observable.needs`, trace columns (:func:`column`) and
  parameters (:func:`parameter`).  When one is absent the analysis does not call
  it: ``skipped[key]`` says which is missing and what for (``missing
  wall_velocity (needed for ...)``, ``missing --mass (needed for ...)``);
* what it computes -- :meth:`Observable.compute` gets a :class:`Context` (the
  trace, the slips, the regime, the unit labels, the sections computed before
  it ...) and returns its section of ``analysis.json`` and its per-slip columns
  for ``analysis_cycles.csv``.  A need that only the run can reveal (no slips
  at all) is a :class:`~filmfriction.analysis.files.trace.MissingInput` raised from
  ``compute``: the analysis records it in ``skipped`` too; a part of the
  section that cannot be computed is recorded with :meth:`Context.skip_part`;
* where it comes -- :attr:`~Observable.order` (the slips 10, the energy 20,
  the sliding state 30, the viscosity 40, the structure 50, others 100 by
  default), which slips its per-slip columns cover
  (:attr:`~Observable.per_slip`) and what their names begin with
  (:attr:`~Observable.column_prefix`);
* what it adds to the report -- :attr:`~Observable.title`,
  :meth:`~Observable.lead` (paragraphs first), :meth:`~Observable.figure`, PNG
  bytes drawn from the run directory
  (:class:`~filmfriction.analysis.calibration.rundata.RunData`), shown with
  :attr:`~Observable.caption` (or :meth:`~Observable.figures` for several),
  :meth:`~Observable.rows` (label, value) for a table with
  :attr:`~Observable.table_header`, and :meth:`~Observable.notes` (paragraphs
  after it).  The report (``workflows/report/render.py``) renders every registered
  observable with one function; nothing here knows the report.

Registry
--------
Every subclass of :class:`Observable` registers itself under its ``key`` in
:data:`REGISTRY` when its class statement runs (``__init_subclass__``), as the
friction laws of :mod:`filmfriction.reduced_model.laws` do.  A subclass that is
not an observable of its own (a helper base, a broken variant in a test) opts
out with ``class X(Observable, register=False)``.  A key is the observable's
``analysis.json`` section, so it must be unique and may not be a key of
the document itself (:data:`BUILT_IN`: the schema, the source, the
regime, the detection ...); its per-slip columns are written as
``<key>_<name>`` unless it names a :attr:`~Observable.column_prefix`.

Example
-------
>>> import numpy as np
>>> class SlipTemperature(Observable, register=False):
...     key = "slip_temperature"
...     title = "Film temperature during the slips"
...     needs = (column("film_temperature", "the film's temperature during each slip"),)
...
...     def compute(self, ctx):
...         temp = ctx.trace.columns["film_temperature"]
...         per_slip = [float(np.mean(temp[y:s + 1]))
...                     for y, s in zip(ctx.table.yield_index, ctx.table.stick_index)]
...         return {"mean": ctx.statistic(per_slip, "temperature")}, {"mean": per_slip}
...
...     def rows(self, section):
...         return [("mean film temperature of a slip", format_estimate(section["mean"]))]
>>> SlipTemperature.needs[0].label, SlipTemperature.key in REGISTRY
('film_temperature', False)
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from filmfriction.reduced_model.cycles import CycleTable, stats

from ..files.trace import PARAMETERS, MissingInput, Trace, unit
from ..files.util import finite_or_none, format_estimate, format_value, png_bytes, pyplot

__all__ = ["Observable", "Context", "Need", "column", "parameter", "REGISTRY", "registered",
           "BUILT_IN", "entry", "value", "MissingInput",
           "format_estimate", "format_value", "png_bytes", "pyplot", "shade_slips"]

#: key -> observable class, for every registered :class:`Observable` subclass
REGISTRY: dict[str, type[Observable]] = {}

#: The ``analysis.json`` keys that the analysis writes itself, around the
#: observables' sections (no observable may take one).
BUILT_IN = frozenset({"schema", "units", "source", "regime", "regime_criterion", "regime_note",
                      "detection", "skipped", "cycles_csv", "provenance"})

_KEY = re.compile(r"[a-z][a-z0-9_]*")


# ---------------------------------------------------------------------------
# the schema's entries
# ---------------------------------------------------------------------------
def entry(statistics: dict, units: str) -> dict:
    """The schema's statistic ``{"mean", "std", "stderr", "n", "units"}`` from
    :func:`~filmfriction.reduced_model.cycles.stats` (NaN -> None)."""
    return {"mean": finite_or_none(statistics["mean"]), "std": finite_or_none(statistics["std"]),
            "stderr": finite_or_none(statistics["stderr"]), "n": statistics["n"], "units": units}


def value(mean, stderr, units: str, **extra) -> dict:
    """The schema's single value ``{"mean", "stderr", "units"}`` plus ``extra`` (NaN -> None)."""
    out = {"mean": finite_or_none(mean), "stderr": finite_or_none(stderr), "units": units}
    out.update(extra)
    return out


# ---------------------------------------------------------------------------
# needs
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Need:
    """A trace column or a parameter an observable cannot do without.

    Attributes
    ----------
    kind : str
        ``"column"`` (a column of the trace CSV) or ``"parameter"`` (a
        :class:`~filmfriction.analysis.files.trace.TraceParameters` field).
    name : str
        The column's or the parameter's name (``wall_velocity``, ``mass``).
    needed_for : str
        What the observable needs it for (said when it is missing).
    """

    kind: str
    name: str
    needed_for: str = ""

    def __post_init__(self):
        if self.kind not in ("column", "parameter"):
            raise ValueError(f"need kind {self.kind!r}: 'column' or 'parameter'")
        if self.kind == "parameter" and self.name not in PARAMETERS:
            raise ValueError(f"parameter {self.name!r}: not one of {', '.join(PARAMETERS)}")

    @property
    def label(self) -> str:
        """As the user meets it: the CSV header's name, or the command-line flag."""
        return self.name if self.kind == "column" else "--" + self.name.replace("_", "-")

    def missing(self, trace: Trace) -> MissingInput | None:
        """The :class:`MissingInput` naming this need when ``trace`` lacks it, else None."""
        present = (trace.has(self.name) if self.kind == "column"
                   else getattr(trace.parameters, self.name) is not None)
        return None if present else MissingInput(self.label, self.needed_for)


def column(name: str, needed_for: str = "") -> Need:
    """A trace column the observable needs (``column("wall_velocity", "the film force")``)."""
    return Need("column", name, needed_for)


def parameter(name: str, needed_for: str = "") -> Need:
    """A trace parameter the observable needs (``parameter("mass", "M·a")``)."""
    return Need("parameter", name, needed_for)


# ---------------------------------------------------------------------------
# what an observable is given
# ---------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Context:
    """What the analysis found before its sections, for :meth:`Observable.compute`.

    Attributes
    ----------
    trace : Trace
        The trace (its columns, :class:`~filmfriction.analysis.files.trace.TraceParameters`,
        ``drive_velocity()``, ``film_thickness()``, ``wall_position()``).
    all_slips : CycleTable
        Every slip detected (the start-up slips included).
    skip : int
        Slips left out of the summaries (the start-up yield).
    events : stickslip.SlipEvents
        The detection (``noise``, ``threshold``, ``unfinished_yield``).
    regime : Regime
        The regime (:class:`~filmfriction.analysis.stickslip.Regime`), with the
        sliding check of the last half already applied.
    regime_note : str or None
        Why the regime is ``unresolved`` (None otherwise).
    last_half : slice
        The samples of the trace's last half.
    sliding : dict
        :func:`~filmfriction.analysis.sliding.sliding_state` of the last half.
    trajectory_analyses : bool
        Whether the trajectory analyses were asked for (``--no-structure`` says no).
    sections : dict
        The sections computed so far, by key (those of a lower :attr:`Observable.order`).
    skipped : dict
        The analysis' ``skipped``; :meth:`skip` adds to it.
    """

    trace: Trace
    all_slips: CycleTable
    skip: int
    events: object
    regime: object = None
    regime_note: str | None = None
    last_half: slice = field(default_factory=lambda: slice(None))
    sliding: dict = field(default_factory=dict)
    trajectory_analyses: bool = True
    sections: dict = field(default_factory=dict)
    skipped: dict = field(default_factory=dict)

    @property
    def table(self) -> CycleTable:
        """The analysed slips: the cycle table after the ``skip`` start-up slips.
        Per-slip columns of an observable with ``per_slip = "analysed"`` have one
        value per row of it."""
        return self.all_slips[self.skip:]

    @property
    def units(self) -> str:
        """The unit system, ``lj`` or ``si`` (labels only: nothing is converted)."""
        return self.trace.units

    def unit(self, quantity: str) -> str:
        """The label of ``quantity`` (``"force"``, ``"temperature"`` ...; see
        :data:`~filmfriction.analysis.files.trace.UNITS`) in this trace's unit system."""
        return unit(self.units, quantity)

    def value(self, mean, stderr, quantity: str, **extra) -> dict:
        """:func:`value` labelled with ``quantity``'s unit."""
        return value(mean, stderr, self.unit(quantity), **extra)

    def statistic(self, per_slip, quantity: str) -> dict:
        """:func:`entry` of the finite per-slip values, labelled with ``quantity``'s unit."""
        return entry(stats(np.asarray(per_slip, dtype=float)), self.unit(quantity))

    def skip_part(self, name: str, reason: str) -> None:
        """Record that ``name`` (a section's key, or ``key.part`` for one of its
        entries) was not computed, and why (``analysis.json``'s ``skipped``)."""
        self.skipped[name] = str(reason)


# ---------------------------------------------------------------------------
# the interface
# ---------------------------------------------------------------------------
class Observable:
    """One section of ``analysis.json`` and of the report (see the module text).

    Class attributes
    ----------------
    key : str
        The ``analysis.json`` section (lower case, digits, ``_``) and the stem
        of the report's figure file.
    title : str
        The report section's title.
    needs : tuple of Need
        The columns and parameters without which :meth:`compute` is not called.
    table_header : tuple of 2 str
        The header of the report's table of :meth:`rows`.
    caption : str
        The caption of :meth:`figure`.
    absent : str
        How the report begins the sentence that says why the section is not there
        (``"<absent>: <the reason in skipped>."``).
    order : int
        Where the section comes, in ``analysis.json``, in ``analysis_cycles.csv``
        and in the report: lower first (ties by key).  The analysis computes the
        sections in this order, so one may read an earlier one's result
        (``ctx.sections``).  The slips are 10, the energy 20, the sliding state
        30, the viscosity 40, the structure 50; the default, 100, comes after them.
    per_slip : str
        Which slips the per-slip columns of :meth:`compute` cover: ``"analysed"``
        (one value per row of ``ctx.table``; the start-up slips' cells are left
        empty) or ``"all"`` (one per row of ``ctx.all_slips``).
    column_prefix : str or None
        What the per-slip columns' names begin with in ``analysis_cycles.csv``
        (None: ``"<key>_"``).
    """

    key: str = ""
    title: str = ""
    needs: tuple = ()
    table_header: tuple = ("quantity", "value")
    caption: str = ""
    absent: str = "Not computed"
    order: int = 100
    per_slip: str = "analysed"
    column_prefix: str | None = None

    def __init_subclass__(cls, register: bool = True, **kwargs):
        super().__init_subclass__(**kwargs)
        if register:
            _register(cls)

    # -- the analysis --------------------------------------------------------
    def applies(self, ctx: Context) -> bool:
        """False when the section has no place in this analysis at all (the
        trajectory analyses switched off, a CSV trace without a run directory):
        then nothing is written, not even a reason in ``skipped``."""
        return True

    def compute(self, ctx: Context) -> tuple[dict | None, dict]:
        """The section of ``analysis.json`` (JSON-ready: numbers, strings, lists,
        dicts; NaN allowed, written as null) and the per-slip columns
        ``{name: one value per slip}`` (``{}`` for none; see :attr:`per_slip`).

        Raise :class:`MissingInput` for an input that only the run can lack.  A
        part that cannot be computed while the rest can is recorded with
        ``ctx.skip_part("<key>.<part>", reason)``; a section of None is not
        written (its reason recorded with ``ctx.skip_part(key, ...)``)."""
        raise NotImplementedError(f"{type(self).__name__}.compute()")

    def column_name(self, name: str) -> str:
        """The ``analysis_cycles.csv`` name of the per-slip column ``name``."""
        return (f"{self.key}_" if self.column_prefix is None else self.column_prefix) + name

    # -- the report ----------------------------------------------------------
    def shown(self, section: dict) -> bool:
        """Whether the report shows the section (else it says why not: ``absent``)."""
        return bool(section)

    def lead(self, run) -> list[str]:
        """Paragraphs before the figures (``run``: see :meth:`figure`)."""
        return []

    def rows(self, section: dict) -> list[tuple[str, str]]:
        """(label, value) rows of the report's table, both strings
        (:func:`format_estimate` and :func:`format_value` write the numbers)."""
        return []

    def notes(self, section: dict) -> list[str]:
        """Paragraphs after the table (``**bold**`` and ```code``` are rendered)."""
        return []

    def figure(self, run) -> bytes | None:
        """A PNG figure (:func:`pyplot`, :func:`png_bytes`) of a run directory
        (:class:`~filmfriction.analysis.calibration.rundata.RunData`: ``trace``, ``analysis``,
        ``cycles``, ``skip``), or None when there is nothing to draw."""
        return None

    def figures(self, run) -> list[tuple[str, bytes, str]]:
        """The report's figures, (file stem, PNG bytes, caption) each; by
        default :meth:`figure` named after the key, with :attr:`caption`.  An
        observable with several figures, or a caption that depends on the run,
        defines this instead."""
        png = self.figure(run)
        return [] if png is None else [(self.key, png, self.caption)]


def shade_slips(ax, run, *, label: bool = True) -> None:
    """Shade every detected slip (y → s) of ``run`` (a ``RunData``) on a time axis ``ax``;
    ``label``: name the shading in the legend."""
    t = run.trace.time
    yi = np.asarray(run.cycles.get("yield_index", []), int)
    si = np.asarray(run.cycles.get("stick_index", []), int)
    for i, (y, s) in enumerate(zip(yi, si)):
        ax.axvspan(t[y], t[s], color="tab:red", alpha=0.12, lw=0,
                   label="slip (y → s)" if label and i == 0 else None)


def _register(cls) -> None:
    key = cls.__dict__.get("key") or getattr(cls, "key", "")
    where = f"{cls.__module__}.{cls.__qualname__}"
    if not isinstance(key, str) or not _KEY.fullmatch(key):
        raise TypeError(f"observable {where}: key {key!r} must be lower case letters, digits "
                        "and '_' (it names its analysis.json section)")
    if key in BUILT_IN:
        raise TypeError(f"observable {where}: key {key!r} is a key analysis.json has of its own")
    if not cls.title:
        raise TypeError(f"observable {where}: no title (the report section's)")
    if not isinstance(cls.needs, (tuple, list)):
        raise TypeError(f"observable {where}: needs must be a tuple of column(...) and "
                        f"parameter(...), got {cls.needs!r}")
    if not isinstance(cls.order, int):
        raise TypeError(f"observable {where}: order must be an int, got {cls.order!r}")
    if cls.per_slip not in ("analysed", "all"):
        raise TypeError(f"observable {where}: per_slip {cls.per_slip!r}: 'analysed' or 'all'")
    for need in cls.needs:
        if not isinstance(need, Need):
            raise TypeError(f"observable {where}: needs holds {need!r}; use column(...) or "
                            "parameter(...)")
    other = REGISTRY.get(key)
    if other is not None and (other.__module__, other.__qualname__) != (cls.__module__,
                                                                       cls.__qualname__):
        raise TypeError(f"observable key {key!r} ({where}) is already registered by "
                        f"{other.__module__}.{other.__qualname__}: choose another key, or define "
                        "it with register=False")
    REGISTRY[key] = cls        # (the same class statement run again, e.g. a reload, replaces it)


def registered() -> tuple[Observable, ...]:
    """An instance of every registered observable, by :attr:`~Observable.order`, then key."""
    return tuple(REGISTRY[key]() for key in sorted(REGISTRY,
                                                   key=lambda k: (REGISTRY[k].order, k)))

