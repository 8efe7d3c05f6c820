"""Result tables as plain data, so that one description serves the terminal and the library.

Results objects describe what they print as a list of *blocks* (a line of text or a :class:`TextTable`):
``result.summary()`` renders them as plain text for a library user, :mod:`dynid.report.console` renders the
same blocks as rich tables for the CLI. A table wider than the output is split into parts that repeat the
label columns, so that nothing is cut at 80 columns.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass, field, replace

__all__ = ["TextTable", "Line", "render_text"]

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
        """Plain text, split to a width.

        Parameters
        ----------
        width : int
            Characters.

        Returns
        -------
        str
        """
        parts = []
        for part in self.split(width):
            w = part.widths()

            def line(cells):
                return "  ".join(c.ljust(x) if i < part.labels else c.rjust(x) for i, (c, x) in enumerate(zip(cells, w))).rstrip()

            rule = "  ".join("-" * x for x in w)
            body = [part.title, line(part.columns), rule]
            for i, r in enumerate(part.rows):
                body.append(line(r))
                if i in part.section_ends and i != len(part.rows) - 1:
                    body.append("")
            parts.append("\n".join(body))
        return "\n\n".join(parts)


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
