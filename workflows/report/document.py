"""The report as a document: sections of paragraphs, figures and tables, built once
and rendered twice (HTML and Markdown, :mod:`~filmfriction.workflows.report.render`)."""
from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Figure", "Table", "Section", "trace_source", "fixed_decimals", "anchor", "link"]


# ---------------------------------------------------------------------------
# document model
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Figure:
    """A PNG figure with a file stem and a caption."""

    name: str
    png: bytes
    caption: str


@dataclass(frozen=True)
class Table:
    """A table: header and rows of strings."""

    header: tuple
    rows: tuple


@dataclass
class Section:
    """A titled list of blocks (str paragraphs, Figure, Table)."""

    title: str
    blocks: list = field(default_factory=list)
    #: why the section's inputs are absent ("" when it has them): left out with one line
    absent: str = ""

    @property
    def anchor(self) -> str:
        """The section's id: its title as GitHub slugs a Markdown heading."""
        return anchor(self.title)

    def p(self, text: str) -> None:
        self.blocks.append(str(text))

    def add(self, block) -> None:
        self.blocks.append(block)


def trace_source(units: str) -> str:
    """What made the trace, as the report names it: an MD run (LJ) or a measurement (SI)."""
    return "MD" if units == "lj" else "measured"


def fixed_decimals(x, decimals: int) -> str:
    """``x`` with fixed decimals; "–" for a value the document has not (null)."""
    return "–" if x is None else f"{x:.{decimals}f}"


def anchor(title: str) -> str:
    """A heading's anchor as GitHub writes it: lower case, punctuation dropped, spaces to
    hyphens (letters of any script kept), so that one link serves HTML and Markdown.

    >>> anchor("Effective viscosity η_eff(γ̇)")
    'effective-viscosity-η_effγ'
    """
    import re
    return re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")


def link(title: str, text: str | None = None) -> str:
    """A link to the section called ``title``, as the report's text writes it."""
    return f"[{text or title}](#{anchor(title)})"
