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


def _slug(heading: str) -> str:
    """A Markdown heading's anchor as GitHub makes it: lower case, punctuation but ``-`` and
    ``_`` dropped, each space a ``-``."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def test_links_to_a_section_find_its_heading():
    # a renamed heading leaves its old anchor in the pages that link to it
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    links, broken = 0, []
    for page in pages:
        for target, anchor in re.findall(r"\]\(([^)#\s]*\.md)?#([^)\s]+)\)", page.read_text()):
            path = (page.parent / target) if target else page
            if not path.is_file():
                continue
            links += 1
            heads = {_slug(h) for h in re.findall(r"^#+ (.*)$", path.read_text(), re.M)}
            if anchor not in heads:
                broken.append((str(page.relative_to(ROOT)), f"{target}#{anchor}"))
    assert links > 20, "no section link found: the pattern no longer matches the guides"
    assert not broken, broken
