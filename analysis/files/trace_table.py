"""A text trace's table: its header, its delimiter and its rows of numbers.

The header line names the columns; they are separated by commas, tabs, semicolons or
whitespace (detected from the header, :func:`detect_delimiter`).  Comment lines
(``#``, or the ``comments`` given) and the first ``skip_rows`` lines are skipped;
when the first other line is numbers, the header is the comment line before it
(LAMMPS's ``fix print`` and ``fix ave/time`` files).  An empty cell is a missing value
(NaN); anything else that is not a number is an error naming its line.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = ["detect_delimiter", "split_header", "head_bytes", "read_header", "read_table",
           "COMMENTS", "SKIP_HINT", "DELIMITER_NAMES"]

def detect_delimiter(header: str, first_row: str | None = None) -> str | None:
    """The delimiter of a trace's header line: ``","``, ``"\\t"`` or ``";"``, the first
    of these that the header holds (and the first data row, when given, splits into as
    many fields with), else ``None``: runs of whitespace.

    >>> detect_delimiter("t_s\\tF_N"), detect_delimiter("time;force"), detect_delimiter("a  b")
    ('\\t', ';', None)
    """
    for sep in (",", "\t", ";"):
        if sep in header and (first_row is None
                              or len(first_row.split(sep)) == len(header.split(sep))):
            return sep
    return None


def split_header(line: str, sep: str | None) -> list[str]:
    """A header line's names: split at ``sep``, blanks and quotes stripped."""
    return [h.strip().strip('"').strip("'").strip() for h in
            (line.split(sep) if sep is not None else line.split())]


#: What starts a comment line by default (``--comment`` gives others).
COMMENTS = ("#",)
SKIP_HINT = ("instrument lines before the header? skip them with --skip-rows N or a "
              "comment prefix --comment TEXT")


def _is_comment(line: str, comments) -> bool:
    stripped = line.lstrip()
    return any(stripped.startswith(c) for c in comments)


def _numbers(line: str, sep: str | None) -> bool:
    """Whether every field of ``line`` is a number (a data row, not a header)."""
    fields = line.split(sep) if sep is not None else line.split()
    try:
        [float(f) for f in fields]
    except ValueError:
        return False
    return bool(fields)


def head_bytes(path: Path, lines: int = 64) -> bytes:
    """The file's first 64 kB, or more until it holds ``lines`` whole lines (a header
    wider than 64 kB is read whole) or the file ends."""
    with open(path, "rb") as fh:
        raw = fh.read(65536)
        while raw.count(b"\n") <= lines:
            more = fh.read(1 << 20)
            if not more:
                break
            raw += more
    return raw


def read_header(raw: bytes, path: Path, skip_rows: int = 0,
            comments=COMMENTS) -> tuple[int, str, str | None]:
    """Where the data rows start (line index), the header's text and the delimiter.

    The header is the first line after ``skip_rows`` lines, blank lines and comment
    lines; when that line is a row of numbers, it is the last comment line before it,
    its prefix removed: LAMMPS's convention (``fix print``'s ``title "# step time
    ..."``, ``fix ave/time``'s ``# TimeStep v_a v_b``).
    """
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise ValueError(f"{path}: UTF-16 text (a spreadsheet's 'Unicode text' export): save it "
                         "as UTF-8 or plain CSV")
    if b"\0" in raw[:65536]:
        raise ValueError(f"{path}: binary data (compressed, NumPy, an image, ...), not a text "
                         "trace: give a header line, then rows of numbers (decompress or export "
                         "it as text first)")
    # utf-8-sig: a spreadsheet's CSV export may start with a byte-order mark
    head_bytes = raw[:65536] if raw[:65536].count(b"\n") > skip_rows + 64 else raw
    head = head_bytes.decode("utf-8-sig", errors="replace").splitlines()
    if skip_rows and skip_rows >= len(head):
        raise ValueError(f"--skip-rows {skip_rows}: {path} has {len(head)} lines")
    start, last_comment = skip_rows, None
    while start < len(head) and (not head[start].strip() or _is_comment(head[start], comments)):
        if head[start].strip():
            last_comment = head[start]
        start += 1
    if start == len(head):
        raise ValueError(f"{path}: empty file (no header line" +
                         (f" after the {skip_rows} rows skipped)" if skip_rows else ")"))
    first = head[start]
    plain = detect_delimiter(first)
    if _numbers(first, plain):
        if last_comment is None:
            raise ValueError(f"{path}: line {start + 1} is a row of numbers, not a header: give "
                             "a line naming the columns before the data (or LAMMPS's '# name "
                             "name ...' comment line)")
        text = last_comment.lstrip()
        text = text[next(len(c) for c in comments if text.startswith(c)):].strip()
        sep = detect_delimiter(text, first)
        return start, text, sep
    first_row = head[start + 1] if start + 1 < len(head) else None
    sep = detect_delimiter(first, first_row)
    named = next((s for s in (",", "\t", ";") if s in first), None)
    if sep is None and named is not None and first_row is not None and named in first_row:
        raise ValueError(f"{path}: the header has {len(first.split(named))} "
                         f"{DELIMITER_NAMES[named]}-separated columns, the first data row (line "
                         f"{start + 2}) {len(first_row.split(named))}: every row needs one value "
                         f"per column ({SKIP_HINT})")
    return start + 1, first, sep


def _cell(text: str) -> float:
    """One cell: a number; an empty cell is NaN (a missing value)."""
    text = text.strip().strip('"')
    return float(text) if text else math.nan


def _parse_rows(lines: list[str], numbers: np.ndarray, sep: str | None, names: list[str],
                path: Path) -> np.ndarray:
    """Rows parsed one by one: empty cells are NaN; a cell that is neither a number nor
    empty, or a row of the wrong length, is an error naming its line."""
    data = np.empty((len(lines), len(names)))
    for i, line in enumerate(lines):
        fields = line.split(sep) if sep is not None else line.split()
        if len(fields) != len(names):
            raise ValueError(f"{path}: line {numbers[i]} has {len(fields)} "
                             f"{DELIMITER_NAMES[sep]}-separated values, the header "
                             f"{len(names)} ({SKIP_HINT})")
        for j, field_ in enumerate(fields):
            try:
                data[i, j] = _cell(field_)
            except ValueError:
                raise ValueError(f"{path}: line {numbers[i]}, column {names[j]}: "
                                 f"{field_.strip()!r} is not a number (a missing value is an "
                                 "empty cell or NaN)") from None
    return data


def _row_lines(body: bytes, start: int, comments) -> tuple[np.ndarray, int]:
    """The file's line number of each data row of ``body`` (the text after the header,
    which starts at line index ``start``), and how many comment lines lie among them."""
    numbers, n_comments = [], 0
    for i, line in enumerate(body.decode("utf-8", errors="replace").splitlines()):
        if _is_comment(line, comments):
            n_comments += 1
        elif line.strip():
            numbers.append(start + 1 + i)
    return np.asarray(numbers, dtype=int), n_comments


def read_table(path: Path, skip_rows: int = 0, comments=COMMENTS):
    """The header's names, the data rows (2-D), each row's line number in the file,
    remarks, and the delimiter of a text trace."""
    notes = []
    raw = path.read_bytes()
    start, header, sep = read_header(raw, path, skip_rows, comments)
    names = split_header(header, sep)
    if any(not n for n in names) or len(set(names)) != len(names):
        raise ValueError(f"{path}: bad header {header!r} (need unique column names separated "
                         f"by commas, tabs, semicolons or spaces; {SKIP_HINT})")
    body = raw.split(b"\n", start)[-1] if raw.count(b"\n") >= start else b""
    decimal_commas = sep == ";" and b"," in body
    if not decimal_commas and body.strip():
        # the common case, parsed by NumPy's C reader from the file (comment and blank
        # lines skipped); anything it refuses goes the slow way below
        import warnings

        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                data = np.loadtxt(path, delimiter=sep, skiprows=start, ndmin=2, dtype=float,
                                  comments=list(comments), encoding="utf-8")
        except ValueError:
            data = None
        if data is not None and data.shape[0] and data.shape[1] == len(names):
            n_lines = body.count(b"\n") + (not body.endswith(b"\n"))
            if data.shape[0] == n_lines:
                return names, data, np.arange(start + 1, start + 1 + n_lines), notes, sep
            numbers, n_comments = _row_lines(body, start, comments)
            if numbers.size == data.shape[0]:
                if n_comments:
                    notes.append(f"skipped {n_comments} comment line"
                                 f"{'s' if n_comments > 1 else ''} among the data rows")
                return names, data, numbers, notes, sep
    text = body.decode("utf-8", errors="replace")
    if decimal_commas:
        # a semicolon-separated table may write decimal commas (1,5;2,25)
        text = text.replace(",", ".")
        notes.append("decimal commas read as decimal points")
    lines = text.splitlines()
    numbers = np.arange(start + 1, start + 1 + len(lines))
    keep = [i for i, line in enumerate(lines) if line.strip() and not _is_comment(line, comments)]
    if len(keep) != len(lines):
        n_comments = sum(1 for line in lines if line.strip() and _is_comment(line, comments))
        if n_comments:
            notes.append(f"skipped {n_comments} comment line{'s' if n_comments > 1 else ''} "
                         "among the data rows")
        lines, numbers = [lines[i] for i in keep], numbers[keep]
    if lines and not raw.endswith(b"\n"):
        fields = lines[-1].split(sep) if sep is not None else lines[-1].split()
        if len(fields) != len(names) or not fields[-1].strip():
            notes.append(f"dropped truncated last line {numbers[-1]}")
            lines, numbers = lines[:-1], numbers[:-1]
    if not lines:
        raise ValueError(f"{path}: no data rows after the header")
    try:
        data = np.loadtxt(lines, delimiter=sep, ndmin=2, dtype=float, comments=None)
    except ValueError:
        data = _parse_rows(lines, numbers, sep, names, path)
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: header has {len(names)} columns ({DELIMITER_NAMES[sep]}-"
                         f"separated), rows have {data.shape[1]} ({SKIP_HINT})")
    return names, data, numbers, notes, sep


DELIMITER_NAMES = {",": "comma", "\t": "tab", ";": "semicolon", None: "whitespace"}
