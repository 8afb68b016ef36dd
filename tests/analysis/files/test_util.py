"""One set of small helpers (analysis/files/util.py): JSON-safe numbers, atomic writes."""
import ast
import json
import math
from pathlib import Path

import numpy as np
import pytest

from filmfriction.analysis.files import util

ROOT = Path(__file__).resolve().parents[3]


def test_finite_or_none():
    assert util.finite_or_none(None) is None
    assert util.finite_or_none(math.nan) is None
    assert util.finite_or_none(-math.inf) is None
    assert util.finite_or_none(np.float32(1.5)) == 1.5
    assert type(util.finite_or_none(np.int64(3))) is float


def test_json_safe_goes_through_documents():
    doc = {"a": [1.0, math.nan, (np.float64(2.0), np.int64(4))], "b": {"c": np.inf},
           "d": "text", "e": None, "f": True}
    safe = util.json_safe(doc)
    assert safe == {"a": [1.0, None, [2.0, 4]], "b": {"c": None}, "d": "text", "e": None,
                    "f": True}
    assert type(safe["a"][2][1]) is int
    json.dumps(safe, allow_nan=False)


def test_json_default():
    text = json.dumps({"n": np.int32(2), "x": np.float32(0.5), "p": Path("a/b")},
                      default=util.json_default)
    assert json.loads(text) == {"n": 2, "x": 0.5, "p": "a/b"}
    with pytest.raises(TypeError):
        json.dumps({"s": {1}}, default=util.json_default)


def test_write_atomic_replaces_whole_or_not_at_all(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    util.write_atomic(target, "new")
    assert target.read_text() == "new"
    util.write_atomic(target, b"\x00bytes")
    assert target.read_bytes() == b"\x00bytes"

    with pytest.raises(TypeError):
        util.write_atomic(target, 12345)          # not text nor bytes: nothing written
    assert target.read_bytes() == b"\x00bytes"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]   # no temporary left


# helpers that live in analysis/files/util.py only
HELPERS = {"write_atomic", "_num", "_finite", "_clean", "_json_default", "finite_or_none",
           "json_safe", "json_default"}
PENDING: dict = {}


def test_no_module_defines_its_own_copy_of_a_helper():
    copies = {}
    for layer in ("md_inputs", "reduced_model", "analysis", "workflows"):
        for path in (ROOT / layer).glob("*.py"):
            rel = path.relative_to(ROOT).as_posix()
            if rel == "analysis/files/util.py":
                continue
            names = {n.name for n in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
                     if isinstance(n, ast.FunctionDef)} & HELPERS
            names -= PENDING.get(rel, set())
            if names:
                copies[rel] = sorted(names)
    assert not copies, f"use filmfriction.analysis.files.util instead: {copies}"


def test_write_atomic_keeps_the_umask(tmp_path):
    import os
    import stat

    from filmfriction.analysis.files.util import write_atomic

    for mask, expected in ((0o022, 0o644), (0o002, 0o664), (0o077, 0o600)):
        old = os.umask(mask)
        try:
            p = write_atomic(tmp_path / f"f{mask:o}.json", "{}")
        finally:
            os.umask(old)
        assert stat.S_IMODE(p.stat().st_mode) == expected, oct(mask)
