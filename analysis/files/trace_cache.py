"""The binary copy of a large text trace, in the project's cache folder beside it.

A text trace is parsed by NumPy's C reader (~0.2 s per 10⁶ rows of three columns); a
binary copy (:func:`write_binary_copy`, written by ``filmfriction analyze`` for traces
of :data:`BINARY_MIN_ROWS` rows or more) is read instead while the text's content is the
one it was made from (~0.01 s; see ``benchmarks/bench_analysis.py``).  The copy lives
in the project's cache folder beside the text, ``.filmfriction/``, under a name keyed by
the SHA-256 of the text's bytes (:func:`binary_copy_path`): it never takes a name the
user may use, and a text replaced by another (of any date) is read again.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .provenance import file_sha256
from .trace import Trace, TraceLayout

__all__ = ["write_binary_copy", "read_binary_copy", "binary_copy_path", "cache_digest",
           "BINARY_MIN_ROWS", "CACHE_DIR", "CACHE_MIN_BYTES"]

#: A text trace of at least this many rows gets a binary copy when
#: ``filmfriction analyze`` reads it (:func:`write_binary_copy`).
BINARY_MIN_ROWS = 100_000
#: Text files smaller than this are read as text (their hash is not taken).
CACHE_MIN_BYTES = 1 << 20
#: The project's cache folder, beside a trace file.
CACHE_DIR = ".filmfriction"


def cache_digest(path: Path) -> str | None:
    """The SHA-256 of a text trace large enough to have a binary copy
    (:data:`CACHE_MIN_BYTES` or more), else None (a smaller one is read as text)."""
    if path.is_file() and path.stat().st_size >= CACHE_MIN_BYTES:
        return file_sha256(path)
    return None


def binary_copy_path(path, digest: str | None = None) -> Path:
    """Where the binary copy of the text trace ``path`` lives: the cache folder beside it,
    keyed by the text's content, ``.filmfriction/<name>.<sha256>.npy`` (``digest``: the
    SHA-256 already taken)."""
    path = Path(path)
    digest = digest or file_sha256(path)
    return path.parent / CACHE_DIR / f"{path.name}.{digest}.npy"


def write_binary_copy(trace: "Trace") -> Path:
    """Write the binary copy of ``trace``'s text file (atomically) into the cache folder
    beside it: a NumPy structured array whose fields are the file's columns, named as
    in its header, under the SHA-256 of the text as read (``trace.layout.content_sha256``).

    :func:`read_csv_trace` reads it instead of the text while the text's bytes are the
    ones it was made from and it has the header's names; older copies of the same file
    are removed.
    """
    import io

    from .util import write_atomic

    layout = trace.layout or TraceLayout()
    if layout.column_units or layout.dropped or layout.kind != "table" or trace.notes:
        raise ValueError(f"{trace.path}: read with unit conversions, dropped rows or notes "
                         f"({'; '.join(trace.notes)}): a binary copy holds a text table's "
                         "columns as written, so none is made")
    if layout.binary or not layout.content_sha256:
        raise ValueError(f"{trace.path}: not read from a text file of {CACHE_MIN_BYTES} bytes "
                         "or more; no binary copy is made")
    names = [layout.columns.get(name, name) for name in trace.columns]
    table = np.empty(len(trace), dtype=[(name, "<f8") for name in names])
    for name, values in zip(names, trace.columns.values()):
        table[name] = values
    buf = io.BytesIO()
    np.save(buf, table, allow_pickle=False)
    copy = binary_copy_path(trace.path, layout.content_sha256)
    cache = copy.parent
    if cache.exists() and (cache.is_symlink() or not cache.is_dir()):
        raise ValueError(f"{cache}: not the project's cache folder (a file or a link); "
                         "no binary copy is made")
    cache.mkdir(exist_ok=True)
    write_atomic(copy, buf.getvalue())
    import glob
    import re

    ours = re.compile(re.escape(Path(trace.path).name) + r"\.[0-9a-f]{64}\.npy")
    for old in cache.glob(glob.escape(Path(trace.path).name) + ".*.npy"):
        if old != copy and ours.fullmatch(old.name):
            old.unlink(missing_ok=True)
    return copy


def read_binary_copy(path: Path, names: list[str], digest: str | None) -> dict | None:
    """The columns of ``path``'s binary copy, or None when there is none for the text's
    content ``digest`` or its fields are not the header's ``names``."""
    if digest is None:
        return None
    copy = binary_copy_path(path, digest)
    try:
        table = np.load(copy, allow_pickle=False)
    except (OSError, ValueError):
        return None
    if table.ndim != 1 or table.dtype.names is None or list(table.dtype.names) != names:
        return None
    return {name: np.ascontiguousarray(table[name], dtype=float) for name in names}
