"""The terminal side of the commands: summaries (blocks of :mod:`dynid.tables`) as rich tables that fit the
terminal, warnings, the "wrote …" line, and progress.

Progress goes to standard error: on a terminal a live line (description, detail, elapsed time; a step's share done as
a bar with the time left at its pace so far); when standard error is a pipe or a file, one plain line each time a step
starts, so a log shows what ran and when. ``quiet``
silences progress and summaries; warnings and errors are still printed (on standard error).
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape

from ..tables import Line, TextTable, rich_tables

DEFAULT_WIDTH = 100
"""Columns of the output when it is not a terminal and ``COLUMNS`` is not set."""


def make_console(stderr: bool = False) -> Console:
    """A console of the terminal's width, or, for pipes and logs, of ``COLUMNS`` (else 100 columns: the tables' width;
    without ``COLUMNS`` lines are not wrapped there, :class:`Reporter`).

    Parameters
    ----------
    stderr : bool
        Write to standard error.

    Returns
    -------
    rich.console.Console
    """
    c = Console(stderr=stderr)
    if c.is_terminal:
        return c
    columns = os.environ.get("COLUMNS", "")
    return Console(stderr=stderr, width=int(columns) if columns.isdigit() else DEFAULT_WIDTH)


class Reporter:
    """What a command prints.

    Summaries and the "wrote" line on standard output, warnings and progress on standard error.

    Parameters
    ----------
    quiet : bool
        Keep only warnings and errors.
    out, err : rich.console.Console, optional
        Consoles of standard output and error (made by :func:`make_console` by default).
    """

    def __init__(self, quiet: bool = False, out: Console | None = None, err: Console | None = None):
        self.quiet = quiet
        self.out = out or make_console()
        self.err = err or make_console(stderr=True)
        # a pipe or a log file gets one line a line, unless COLUMNS asks for a width (a terminal wraps at its own)
        self.unwrapped = not (self.out.is_terminal or os.environ.get("COLUMNS", "").isdigit())

    def warning(self, text: str) -> None:
        """Print a warning on standard error.

        Parameters
        ----------
        text : str
            One line.
        """
        self.err.print(f"[yellow]warning:[/] {escape(text)}", highlight=False, soft_wrap=True)

    def error(self, text: str) -> None:
        """Print an error on standard error.

        Parameters
        ----------
        text : str
            One line.
        """
        self.err.print(f"[bold red]error:[/] {escape(text)}", highlight=False, soft_wrap=True)

    def line(self, text: str) -> None:
        """Print a line on standard output (unless quiet).

        Parameters
        ----------
        text : str
        """
        if not self.quiet:
            self.out.print(text, markup=False, highlight=False, soft_wrap=self.unwrapped)

    def blocks(self, blocks) -> None:
        """Print a summary: tables split to the console's width, titles in bold, warnings on standard error.

        Parameters
        ----------
        blocks : iterable of Block
            What :mod:`dynid.report.summaries` builds.
        """
        for b in blocks:
            if isinstance(b, Line) and b.kind == "warning":
                self.warning(b.text)
            elif self.quiet:
                continue
            elif isinstance(b, TextTable):
                for title, t in rich_tables(b, self.out.width):
                    if title:  # a paragraph as wide as the output (one line in a pipe), not the table's width
                        self.out.print(title, style="italic", markup=False, highlight=False, soft_wrap=self.unwrapped)
                    self.out.print(t)
            elif b.kind == "title":
                self.out.print("\n" + escape(b.text), style="bold", highlight=False, soft_wrap=self.unwrapped)
            else:  # a pipe or a log file: one line a line (a terminal wraps at its width)
                self.out.print(b.text, markup=False, highlight=False, soft_wrap=self.unwrapped)

    def wrote(self, paths: list[Path]) -> None:
        """One line: the first file, the other files by name, and how many figures (where there are any), in which
        folder.

        Parameters
        ----------
        paths : list of Path
            Files written.
        """
        pngs = [p for p in paths if p.suffix == ".png"]
        others = "".join(f", {p.name}" for p in paths[1:] if p.suffix != ".png")
        figures = f" and {count(len(pngs), 'figure')}" if pngs else ""  # "and no figures" read as a missing output
        self.line(f"wrote {paths[0]}{others}{figures} in {paths[0].parent}/")

    def progress(self, command: str) -> Progress:
        """A progress reporter for a command.

        Parameters
        ----------
        command : str

        Returns
        -------
        Progress
        """
        return Progress(command, self.err, self.quiet)


class _LiveLine:
    """The terminal's live line of a :class:`Progress`, written again at each of the terminal's redraws (rich calls
    ``__rich__``): its elapsed time and the step's time left go on between two reports, as the spinner does."""

    def __init__(self, progress: Progress):
        self.progress = progress

    def __str__(self) -> str:
        p = self.progress
        step, detail = p._shown
        elapsed = time.perf_counter() - p.t0
        if step not in p._started:  # before the first step
            return f"{p.command}: {step}  {elapsed:.0f} s"
        return f"{p.command}: {step} {bar(detail, elapsed - p._started[step])}  {elapsed:.0f} s"

    def __rich__(self) -> str:
        return escape(str(self))


def count(n: int, noun: str) -> str:
    """A count with its noun: ``"no figures"``, ``"1 figure"``, ``"3 figures"``.

    Parameters
    ----------
    n : int
    noun : str
        Singular.

    Returns
    -------
    str
    """
    return f"no {noun}s" if n == 0 else f"1 {noun}" if n == 1 else f"{n} {noun}s"


BAR_CELLS = 20
"""Cells of the progress bar a step with a share done shows on a terminal."""


def bar(detail: str, seconds: float) -> str:
    """A step's detail as the terminal shows it: a share done (``"40 %"``) as a bar with the time left at the step's
    pace so far (nothing at 0 %, which most steps say only as they start), anything else as it is.

    Parameters
    ----------
    detail : str
        The step's detail (:meth:`Progress.update`).
    seconds : float
        The step's time so far [s].

    Returns
    -------
    str
    """
    text = detail.strip()
    if not text.endswith("%"):
        return detail
    try:
        share = float(text[:-1]) / 100.0
    except ValueError:
        return detail
    share = min(max(share, 0.0), 1.0)
    if share == 0.0:  # a step that announces its start alone: no bar to read yet
        return ""
    filled = int(round(share * BAR_CELLS))
    left = f", about {seconds * (1 - share) / share:.0f} s left" if 0 < share < 1 and seconds >= 1.0 else ""
    return f"{'█' * filled}{'░' * (BAR_CELLS - filled)} {100 * share:.0f} %{left}"


class Progress:
    """Progress of a command on standard error.

    On a terminal a live line; in a pipe or log one line when a step starts (with the elapsed time). Used as
    ``with reporter.progress("identify") as p: p.update("regressor", "40 %")``.

    Parameters
    ----------
    command : str
        The command's name, shown first.
    console : rich.console.Console
        Standard error's console.
    quiet : bool
        Print nothing.
    """

    def __init__(self, command: str, console: Console, quiet: bool = False):
        self.command, self.console, self.quiet = command, console, quiet
        self.live = console.is_terminal and not quiet
        self.seen: set[str] = set()
        self.t0 = time.perf_counter()
        self._status: Any = None
        self._started: dict[str, float] = {}  # each step's start [s since t0]: its time left from its share done
        self._shown = ("starting", "")  # the live line's step and detail, drawn with the time as it is
        self._line = _LiveLine(self)

    def __enter__(self) -> Progress:
        if self.live:
            self._status = self.console.status(self._line, spinner="line")
            self._status.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        if self._status is not None:
            self._status.__exit__(*exc)

    def update(self, step: str, detail: str = "") -> None:
        """Report that a step is running.

        Parameters
        ----------
        step : str
            The step's name.
        detail : str
            Iteration, best value, percentage…
        """
        if self.quiet:
            return
        elapsed = time.perf_counter() - self.t0
        self._started.setdefault(step, elapsed)
        if self.live:
            self._shown = (step, detail)
            self._status.update(self._line)  # drawn now, not at the next redraw
        elif step not in self.seen:  # steps may run side by side: each is announced once
            self.console.print(f"{self.command}: {step} (at {elapsed:.1f} s)", markup=False, highlight=False)
        self.seen.add(step)
