"""The report as a document: sections of paragraphs, figures and tables, built once
and rendered twice (HTML and Markdown, :mod:`~filmfriction.workflows.report.render`)."""
from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Figure", "Table", "Section", "trace_source", "fixed_decimals"]


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
