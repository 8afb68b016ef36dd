"""One check of every document the project reads back (``run.json``,
``analysis.json``, ``calibration.json``, ``sfb.json``): the entries its readers use,
with their types, checked on read.

A document edited by hand or written by another program is refused with one line
naming the file, the key, the value and what is accepted (:class:`DocumentError`, a
``ValueError``: the command line's exit 2), before any reader trips over it.  JSON
booleans are never numbers (``true`` is not a spring constant of 1).  Entries a
reader does not use are not looked at, and a key that is absent is left to the
reader (which says what makes it), unless marked required.

:func:`read_document` reads and checks a file; :func:`check_document` checks a
document already read.

Examples
--------
>>> check_document({"trace_parameters": {"spring_constant": True}}, "run", "r/run.json")
Traceback (most recent call last):
...
filmfriction.analysis.files.documents.DocumentError: r/run.json: trace_parameters.spring_constant = true: expected a positive number or null
>>> check_document({"scene": {"parameters": {}}}, "run", "r/run.json")
Traceback (most recent call last):
...
filmfriction.analysis.files.documents.DocumentError: r/run.json: scene.name missing: expected a string (the scene's name)
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

__all__ = ["DocumentError", "Field", "SPECS", "MD_CALIBRATION", "check_document", "read_document"]


class DocumentError(ValueError):
    """A document the project reads is not of the form it writes."""


@dataclass(frozen=True)
class Field:
    """What an entry may hold.

    ``kind``: ``"number"`` (int or float, finite, not a boolean), ``"integer"``,
    ``"string"``, ``"boolean"``, ``"object"``, ``"array"``, ``"any"``; ``null``
    accepted when ``nullable``; ``positive`` numbers > 0; ``fields`` the entries of an
    object, ``items`` the entries of an array; ``each`` the values of an object whose
    keys are free; ``hint`` added to the message.
    """

    kind: str
    nullable: bool = False
    required: bool = False
    positive: bool = False
    fields: dict = field(default_factory=dict)
    items: "Field | None" = None
    each: "Field | None" = None
    hint: str = ""

    def accepted(self) -> str:
        words = {"number": "a number", "integer": "a whole number", "string": "a string",
                 "boolean": "true or false", "object": "a JSON object", "array": "a JSON list",
                 "any": "a value"}
        text = words[self.kind]
        if self.positive:
            text = {"a number": "a positive number",
                    "a whole number": "a positive whole number"}.get(text, text)
        if self.nullable:
            text += " or null"
        return text + (f" ({self.hint})" if self.hint else "")


def _ok(value, spec: Field) -> bool:
    if value is None:
        return spec.nullable
    kind = spec.kind
    if kind == "any":
        return True
    if kind in ("number", "integer"):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return False
        if kind == "integer" and not (isinstance(value, int) or float(value).is_integer()):
            return False
        if not math.isfinite(value):
            return False
        return value > 0 if spec.positive else True
    return isinstance(value, {"string": str, "boolean": bool, "object": dict,
                              "array": list}[kind])


def _shown(value) -> str:
    text = json.dumps(value, ensure_ascii=False, default=str)
    return text if len(text) <= 60 else text[:57] + "..."


def _check(value, spec: Field, key: str, where: str) -> None:
    if not _ok(value, spec):
        raise DocumentError(f"{where}: {key} = {_shown(value)}: expected {spec.accepted()}")
    if value is None:
        return
    if spec.kind == "object":
        for name, sub in spec.fields.items():
            sub_key = f"{key}.{name}" if key else name
            if name not in value:
                if sub.required:
                    raise DocumentError(f"{where}: {sub_key} missing: expected {sub.accepted()}")
                continue
            _check(value[name], sub, sub_key, where)
        if spec.each is not None:
            for name, v in value.items():
                _check(v, spec.each, f"{key}.{name}" if key else str(name), where)
    elif spec.kind == "array" and spec.items is not None:
        for i, v in enumerate(value):
            _check(v, spec.items, f"{key}[{i}]", where)


_NUM = Field("number", nullable=True)
_POS = Field("number", nullable=True, positive=True)
_STR = Field("string", nullable=True)
_OBJ = Field("object", nullable=True)
_ESTIMATE = Field("object", nullable=True, fields={"value": _NUM, "mean": _NUM,
                                                   "stderr": _NUM, "units": _STR})
_PARAMETERS = Field("object", nullable=True, fields={
    "spring_constant": _POS, "mass": _POS, "area": _POS, "thickness": _POS,
    "drive_velocity": _POS, "mount_damping": _NUM, "film_mass": _POS, "registry_period": _POS,
    "units": Field("string", nullable=True, hint="lj or si")})

#: An MD calibration (``calibration.json``'s ``md_calibration``, or a file of its own
#: for ``filmfriction sfb --calibration``).
MD_CALIBRATION = Field("object", nullable=True, fields={
    **{name: _NUM for name in ("yield_stress", "eta_zero", "thinning_exponent", "onset_rate",
                               "restick_stress", "sliding_stress", "yield_stress_err",
                               "eta_zero_err", "thinning_exponent_err", "onset_rate_err",
                               "restick_stress_err", "sliding_stress_err", "film_thickness")},
    "shear_rate_range": Field("array", nullable=True, items=_NUM), "source": _STR})

#: The entries each document's readers use.
SPECS: dict[str, Field] = {
    "run": Field("object", fields={
        "schema": _STR, "status": _STR, "error": Field("any", nullable=True),
        "scene": Field("object", fields={
            "name": Field("string", required=True, hint="the scene's name"),
            "parameters": Field("object", each=Field("any", nullable=True)),
            "script": _STR}),
        "trace_parameters": _PARAMETERS,
        "np": Field("integer", positive=True, hint="MPI ranks"),
        "segments": Field("array", items=Field("object")),
        "warnings": Field("array", items=Field("string")),
        "outputs": _OBJ, "versions": _OBJ, "derived": _OBJ, "layout": _OBJ,
        "lammps": _OBJ}),
    "analysis": Field("object", fields={
        "schema": _STR, "units": Field("string", nullable=True, hint="lj or si"),
        "regime": _STR,
        "source": Field("object", fields={"path": _STR, "run_dir": _STR,
                                          "parameters": _PARAMETERS,
                                          "columns": Field("object", nullable=True,
                                                           each=Field("string")),
                                          "column_units": Field("object", nullable=True,
                                                                each=Field("string"))}),
        "slips": Field("object", fields={"count": Field("integer"),
                                         "summary_skips_first": Field("integer", nullable=True),
                                         "static_force": _ESTIMATE,
                                         "kinetic_force": _ESTIMATE}),
        "detection": _OBJ, "energy": _OBJ, "sliding": _OBJ, "viscosity": _OBJ,
        "structure": _OBJ, "slip_law": _OBJ, "skipped": _OBJ, "cycles_csv": _STR}),
    "calibration": Field("object", fields={
        "schema": _STR, "units": Field("string", nullable=True, hint="lj or si"),
        "runs": Field("array", items=Field("object", fields={
            "run_dir": Field("string"), "regime": _STR, "slips": Field("integer", nullable=True),
            "static_force": _ESTIMATE, "kinetic_force": _ESTIMATE, "film_damping": _ESTIMATE,
            "eta_eff": _OBJ, "failures": _OBJ})),
        "md_calibration": MD_CALIBRATION, "rate_law": _OBJ, "notes": Field("array", items=Field("string")),
        "failures": _OBJ, "replay_trace": _STR}),
    "sfb": Field("object", fields={
        "schema": _STR, "rows": Field("array", items=Field("object", fields={
            "name": Field("string"), "klein": _NUM, "model": _NUM, "ratio": _NUM,
            "units": _STR, "source": _STR})),
        "notes": Field("array", items=Field("string")), "slips": _OBJ,
        "calibration": MD_CALIBRATION, "traces": _STR, "setup": _OBJ, "measured": _OBJ}),
    "md_calibration": MD_CALIBRATION,
}


#: ``run.json`` as ``filmfriction run --resume`` reads it: the scene in full.
SPECS["run-resume"] = Field("object", fields={
    **SPECS["run"].fields,
    "scene": Field("object", required=True, fields={
        "name": Field("string", required=True, hint="the scene's name"),
        "description": Field("string", required=True),
        "models": Field("any", required=True),
        "expected_cost": Field("any", required=True),
        "parameters": Field("object", required=True, each=Field("any", nullable=True)),
        "outputs": Field("array", items=Field("string")),
        "script": _STR,
        "lammps_packages": Field("array", items=Field("string"))}),
    "layout": Field("object", nullable=True, fields={
        "omp_threads": Field("integer", positive=True, hint="OpenMP threads per rank")}),
    "resume_offsets": Field("object", each=Field("object", each=_NUM))})


def check_document(doc, kind: str, where) -> dict:
    """``doc`` if it has the form of a ``kind`` document (a key of :data:`SPECS`);
    :class:`DocumentError` naming ``where``, the key, the value and what is accepted."""
    _check(doc, SPECS[kind], "", str(where))
    return doc


def read_document(path, kind: str, where=None) -> dict:
    """The document in the file ``path``, checked (:func:`check_document`); ``where``
    names it in messages (default the path).  ``OSError`` passes through."""
    from .util import read_json_object

    where = str(where or path)
    return check_document(read_json_object(path, where), kind, where)
