"""Small helpers the analysis and the workflows share: files written atomically,
JSON-safe numbers.

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
"""
from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["write_atomic", "finite_or_none", "json_safe", "json_default"]


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
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
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
