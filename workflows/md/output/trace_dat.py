"""The script's trace (``trace.dat``, its ``fix print`` rows) read, trimmed for a
resume, and converted to ``trace.csv`` (:data:`~filmfriction.md_inputs.contract.TRACE_COLUMNS`)."""
from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from filmfriction.analysis.files.util import write_atomic
from filmfriction.md_inputs.contract import DAT_COLUMNS, SLIDE_ORIGIN_FILE, TRACE_COLUMNS

from ..scene import SceneError


def read_trace_dat(path: Path, raw: bool = False) -> np.ndarray:
    """Rows of ``trace.dat``; a final line cut off by a crash is dropped.

    A segment's first row repeats the previous segment's last step (the script
    prints at each segment's start): the later row is kept, the one a resumed
    job prints; ``raw`` keeps every row as printed.
    """
    rows = []
    if not path.exists():
        return np.empty((0, len(DAT_COLUMNS)))
    for line in path.read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        parts = line.split()
        if len(parts) != len(DAT_COLUMNS):
            continue
        try:
            rows.append([float(x) for x in parts])
        except ValueError:
            continue
    table = np.array(rows, dtype=float).reshape(-1, len(DAT_COLUMNS))
    if raw or len(table) < 2:
        return table
    later = np.append(table[1:, 0] != table[:-1, 0], True)   # last of each run of a step
    return table[later]


def write_trace_csv(dat: np.ndarray, path: Path) -> None:
    """trace.csv in TRACE_COLUMNS order, written atomically."""
    index = [DAT_COLUMNS.index(c) for c in TRACE_COLUMNS]
    table = dat[:, index] if len(dat) else np.empty((0, len(TRACE_COLUMNS)))
    fmt = ["%d" if c == "step" else "%.10g" for c in TRACE_COLUMNS]
    text = io.StringIO()
    np.savetxt(text, table, delimiter=",", header=",".join(TRACE_COLUMNS), comments="", fmt=fmt)
    write_atomic(path, text.getvalue())


def slide_origin(run_dir: Path) -> tuple[str, str]:
    """Absolute wall x and z at the slide's start (slide_origin.txt, written by LAMMPS)."""
    origin_file = run_dir / SLIDE_ORIGIN_FILE
    if not origin_file.exists():
        raise SceneError(f"{origin_file} is missing: cannot resume")
    try:
        words = origin_file.read_text(encoding="utf-8").split()
        x0, z0 = (float(w) for w in words)
        if not (math.isfinite(x0) and math.isfinite(z0)):
            raise ValueError
    except (UnicodeDecodeError, ValueError):
        shown = origin_file.read_bytes()[:60].decode("utf-8", "replace").strip()
        raise SceneError(f"{origin_file}: {shown!r}: expected two finite numbers, the wall's x "
                         "and z at the slide's start (LAMMPS writes them): cannot resume") from None
    return repr(x0), repr(z0)


def rewrite_trace_dat(path: Path, rows: np.ndarray) -> None:
    header = "# " + " ".join(DAT_COLUMNS)
    lines = [header] + [" ".join(f"{v:.10g}" for v in r) for r in rows]
    write_atomic(path, "\n".join(lines) + "\n")
