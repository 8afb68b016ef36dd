"""Small helpers the analysis and the workflows share: files written atomically,
JSON-safe numbers, numbers as report text, figures as PNG bytes.

* :func:`write_atomic` -- one way to write a file: readers (a report, a resumed
  sweep, another process) never see a half-written file: the data go to a
  temporary file in the same directory, which then replaces the target in one
  ``os.replace``.  On any failure the temporary file is removed and the old
  target, if any, is untouched.
* :func:`finite_or_none` -- a number as a JSON-safe float (NaN/inf -> None).
* :func:`json_safe` -- a document made JSON-safe, recursively (NaN/inf ->
  None, NumPy scalars -> Python numbers), for ``json.dumps(allow_nan=False)``.
* :func:`json_default` -- the ``default=`` of ``json.dumps`` for NumPy scalars
  and paths.
* :func:`format_value`, :func:`format_estimate` -- a number, or an
  ``analysis.json`` entry ``{"mean", "stderr", "units"}``, as the report writes it.
* :func:`pyplot`, :func:`png_bytes` -- matplotlib without a display, and a
  figure as PNG bytes (the figure closed).
* :func:`json_schema` -- the JSON Schema of an output (``analysis``, ``sfb``),
  shipped in ``analysis/schemas/``.
"""
from __future__ import annotations

import io
import math
import os
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["write_atomic", "finite_or_none", "json_safe", "json_default",
           "format_value", "format_estimate", "pyplot", "png_bytes", "read_json_object",
           "json_schema"]


def _umask() -> int:
    """The process umask (read by setting it and setting it back: there is no getter)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def write_atomic(path, data: str | bytes) -> Path:
    """Write ``data`` (text or bytes) to ``path`` atomically; return the path.

    The file gets the mode a plain ``open(path, "w")`` would give (0666 less the
    process umask), not the 0600 of a temporary file: a group can read a run on a
    shared cluster when the umask says so.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "x.txt"
    >>> write_atomic(p, "hello").read_text()
    'hello'
    """
    path = Path(path)
    mode = "wb" if isinstance(data, (bytes, bytearray)) else "w"
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.fchmod(fd, 0o666 & ~_umask())
        with os.fdopen(fd, mode) as fh:
            fh.write(data)
        os.replace(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError) and exc.filename is None:
            exc.filename = str(path)        # a failed write (a full disk) names its file
        raise
    return path


def finite_or_none(x) -> float | None:
    """``x`` as a float, or None when it is None, NaN or infinite (JSON has no NaN)."""
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def json_safe(obj):
    """``obj`` with every float made :func:`finite_or_none` and every NumPy
    integer an int, through dicts, lists and tuples (tuples become lists)."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, (float, np.floating)):
        return finite_or_none(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def json_default(obj):
    """``json.dumps(..., default=json_default)``: NumPy scalars and paths."""
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating):
        return float(obj)
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(type(obj))


def format_value(x, digits: int = 4) -> str:
    """``x`` to ``digits`` significant figures; "–" for None, NaN or infinity.

    >>> format_value(3.14159), format_value(7), format_value(None), format_value(float("nan"))
    ('3.142', '7', '–', '–')
    """
    if x is None:
        return "–"
    if isinstance(x, int) and not isinstance(x, bool):
        return str(x)
    try:
        x = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(x):
        return "–"
    return f"{x:.{digits}g}"


def format_estimate(e, digits: int = 3) -> str:
    """'value ± stderr units' of an ``analysis.json`` entry (``mean`` or ``value``,
    ``stderr``, ``units``; units ``"1"`` not written) or of an object with
    ``value``, ``stderr`` and ``units``; "–" for None.

    >>> format_estimate({"mean": 2.5, "stderr": 0.1234, "units": "ε/σ"})
    '2.5 ± 0.12 ε/σ'
    >>> format_estimate({"mean": 0.5, "stderr": None, "units": "1"})
    '0.5'
    >>> format_estimate({"value": 0.0, "stderr": None, "units": "N", "at_bound": True})
    '0 N (at bound)'
    >>> format_estimate({"value": 0.0, "stderr": None, "units": "N", "at_bound": True,
    ...                  "upper_limit_95": 2.5e-7})
    '0 N (at bound; below 2.5e-07 N at 95 %)'
    """
    if e is None:
        return "–"
    if isinstance(e, dict):
        v, s, u = e.get("mean", e.get("value")), e.get("stderr"), e.get("units", "")
        bound, limit = bool(e.get("at_bound")), e.get("upper_limit_95")
    else:
        v, s, u = e.value, e.stderr, e.units
        bound, limit = bool(getattr(e, "at_bound", False)), getattr(e, "limit", None)
    err = f" ± {format_value(s, 2)}" if s is not None and math.isfinite(float(s)) else ""
    text = f"{format_value(v, digits)}{err} {'' if u == '1' else u}".strip()
    if not bound:
        return text
    if limit is not None and math.isfinite(float(limit)):
        return (f"{text} (at bound; below {format_value(limit, 2)} "
                f"{'' if u == '1' else u} at 95 %)").replace("  ", " ")
    return text + " (at bound)"


def format_pm(value, stderr, digits: int = 4) -> str:
    """'value ± stderr', or 'value (no standard error)' where the error is 0, NaN or None
    (not known, or the value is a fit's bound): never "± 0".

    >>> format_pm(2.5, 0.1234), format_pm(0.0, 0.0)
    ('2.5 ± 0.12', '0 (no standard error)')
    """
    if stderr is None or not math.isfinite(float(stderr)) or float(stderr) <= 0.0:
        return f"{format_value(value, digits)} (no standard error)"
    return f"{format_value(value, digits)} ± {format_value(stderr, 2)}"


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def png_bytes(fig) -> bytes:
    """The matplotlib figure ``fig`` as PNG bytes (110 dpi, tight); the figure is closed."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def read_json_object(path, where: str | None = None, *, what: str = "a JSON object") -> dict:
    """The JSON object in the file ``path``; ``ValueError`` naming ``where`` (default the
    path) and the reason when the file is not UTF-8, not JSON, or not an object.
    (``OSError`` for a file that cannot be read passes through.)

    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "x.json"
    >>> _ = p.write_text("[1]")
    >>> read_json_object(p, "x.json")
    Traceback (most recent call last):
    ...
    ValueError: x.json: must be a JSON object, this is a list
    """
    import json

    where = where or str(path)
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise ValueError(f"{where}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"{where}: not valid JSON: line {exc.lineno} column {exc.colno}: "
                         f"{exc.msg}") from None
    if not isinstance(data, dict):
        raise ValueError(f"{where}: must be {what}, this is a {type(data).__name__}")
    return data


def json_schema(name: str) -> dict:
    """The JSON Schema (draft 2020-12) of the output ``name``: ``"analysis"``
    (``analysis.json``) or ``"sfb"`` (``sfb.json``), from ``analysis/schemas/``.

    >>> json_schema("analysis")["properties"]["schema"]
    {'const': 'filmfriction.analysis/1'}
    """
    import json

    path = Path(__file__).parents[1] / "schemas" / f"{name}.schema.json"
    if not path.is_file():
        known = sorted(p.name.removesuffix(".schema.json")
                       for p in path.parent.glob("*.schema.json"))
        raise ValueError(f"no schema {name!r}; the schemas are {', '.join(known)}")
    return json.loads(path.read_text(encoding="utf-8"))
