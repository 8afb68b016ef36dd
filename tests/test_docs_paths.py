"""Every test file that README.md and docs/ cite as the evidence of a claim exists
(tests/ mirrors the packages: a moved test left its old path in the guides)."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_cited_test_files_exist():
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    cited = {(page.relative_to(ROOT), path) for page in pages
             for path in re.findall(r"tests/[A-Za-z0-9_/]+\.py", page.read_text())}
    assert cited, "no test file cited: the pattern no longer matches the guides"
    missing = sorted((str(page), path) for page, path in cited if not (ROOT / path).is_file())
    assert not missing, missing
