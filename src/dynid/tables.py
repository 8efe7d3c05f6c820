"""Result tables as plain data, so that one description serves the terminal and the library.

Results objects describe what they print as a list of *blocks* (a line of text or a :class:`TextTable`):
``result.summary()`` renders them as plain text for a library user, :mod:`dynid.report.console` prints the same
blocks in the terminal; both draw a table with rich (:func:`rich_tables`), the plain text without colour. A table wider than the output is split into parts that repeat the
label columns, so that nothing is cut at 80 columns.
"""

from __future__ import annotations

import io
import textwrap
from dataclasses import dataclass, field, replace

__all__ = ["TextTable", "Line", "render_text", "rich_tables"]

PADDING = 2
"""Characters each column adds to its cells: the separator and one space (rich: collapsed padding)."""
EDGES = 0
"""Characters a table adds at its edges beyond :data:`PADDING` (rich: ``pad_edge=False``)."""


@dataclass(frozen=True)
class Line:
    """A line of text in a summary.

    Attributes
    ----------
    text : str
    kind : str
        "text", "title" or "warning".
    """

    text: str
    kind: str = "text"


@dataclass(frozen=True)
class TextTable:
    """A table of strings.

    Attributes
    ----------
    title : str
    columns : tuple of str
        Column headers.
    rows : tuple of tuples of str
        Each as long as ``columns``.
    labels : int
        Leading label columns: left-aligned and repeated in every part of a split.
    section_ends : frozenset of int
        Rows after which a separating rule is drawn.
    """

    title: str
    columns: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    labels: int = 1
    section_ends: frozenset = field(default_factory=frozenset)

    def widths(self) -> list[int]:
        """Width of each column: its longest cell or header.

        Returns
        -------
        list of int
        """
        return [max([len(c)] + [len(r[i]) for r in self.rows]) for i, c in enumerate(self.columns)]

    def split(self, width: int) -> list[TextTable]:
        """Parts no wider than a width (as far as the label columns allow), each repeating the label columns.

        Parameters
        ----------
        width : int
            Characters.

        Returns
        -------
        list of TextTable
            ``[self]`` when it fits.
        """
        w = self.widths()
        total = sum(x + PADDING for x in w) + EDGES
        if total <= width or len(self.columns) <= self.labels + 1:
            return [self]
        room = width - EDGES - sum(x + PADDING for x in w[:self.labels])
        groups: list = []
        current: list = []
        used = 0
        for i in range(self.labels, len(self.columns)):
            if current and used + w[i] + PADDING > room:
                groups.append(current)
                current, used = [], 0
            current.append(i)
            used += w[i] + PADDING
        groups.append(current)
        keep = list(range(self.labels))
        return [replace(self, title=f"{self.title} ({k + 1} of {len(groups)})",
                        columns=tuple(self.columns[i] for i in keep + g),
                        rows=tuple(tuple(r[i] for i in keep + g) for r in self.rows))
                for k, g in enumerate(groups)]

    def render(self, width: int = 100) -> str:
        """Plain text, split to a width: the terminal's tables (:func:`rich_tables`) rendered by rich without
        colour.

        Parameters
        ----------
        width : int
            Characters.

        Returns
        -------
        str
        """
        from rich.console import Console

        out = io.StringIO()
        console = Console(file=out, width=width, color_system=None, force_terminal=False, highlight=False)
        for k, (title, table) in enumerate(rich_tables(self, width)):
            if k:
                console.print()
            if title:
                console.print(title, markup=False)
            console.print(table)
        return "\n".join(line.rstrip() for line in out.getvalue().strip("\n").splitlines())


def rich_tables(table: TextTable, width: int) -> list:
    """A text table as rich tables no wider than a width: one renderer for the terminal and the plain text.

    Parameters
    ----------
    table : TextTable
    width : int
        Columns available.

    Returns
    -------
    list of (str, rich.table.Table)
        Parts repeating the label columns, each with its title: a paragraph printed above it (as wide as the output, not
        wrapped to the table's width).
    """
    from rich import box
    from rich.markup import escape
    from rich.table import Table

    out = []
    for part in table.split(width):
        t = Table(box=box.SIMPLE_HEAD, padding=(0, 1), collapse_padding=True, pad_edge=False)
        for i, col in enumerate(part.columns):
            t.add_column(escape(col), justify="left" if i < part.labels else "right", no_wrap=True)
        for i, row in enumerate(part.rows):
            t.add_row(*(escape(c) for c in row), end_section=i in part.section_ends)
        out.append((part.title, t))
    return out


def render_text(blocks, width: int = 100) -> str:
    """Plain text of a summary's blocks.

    Parameters
    ----------
    blocks : iterable of Line or TextTable
    width : int
        Characters.

    Returns
    -------
    str
    """
    out = []
    for b in blocks:
        if isinstance(b, TextTable):
            out.append("\n" + b.render(width) + "\n")
        else:
            out.append(textwrap.fill(("warning: " if b.kind == "warning" else "") + b.text, width, break_long_words=False))
    return "\n".join(out).strip("\n") + "\n"
