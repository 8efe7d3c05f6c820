"""Work on the second core in a forked process: a computation independent of the one this process is doing
(the drive gains beside the identification), and the figures (:mod:`dynid.report.output`). A fork shares
the imported modules and the data, so nothing is imported again and only the answer is pickled back.

Forking is done only where it is safe and useful: inside :func:`allow_forks` (the CLI's commands, whose
process dynid owns: a library caller's process may run threads whose locks a child would inherit), on
Linux, with two cores or more. Anywhere else, and whenever a child fails in a way its answer cannot tell
(killed, an answer that does not pickle), the work is done in this process instead, so the results never
depend on whether a child ran it.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import sys

from ..exceptions import DynIdError
from .threads import cores

_allowed = False


@contextlib.contextmanager
def allow_forks():
    """A block within which work may go to forked children (:func:`can_fork`).

    The CLI runs its commands in it; the library alone never forks.

    Yields
    ------
    None
    """
    global _allowed
    before, _allowed = _allowed, True
    try:
        yield
    finally:
        _allowed = before


def can_fork() -> bool:
    """Whether work may go to a forked child.

    Inside :func:`allow_forks`, on Linux (fork with threads), with two cores or more.

    Returns
    -------
    bool
    """
    return _allowed and cores() >= 2 and sys.platform.startswith("linux")


def start_child(target, *args):
    """A forked child running ``target(*args)``, started (:mod:`multiprocessing`'s fork context: the child shares the
    imported modules and the data; its exit code is 0 when ``target`` returns, 1 when it raised, negative when killed).

    The standard streams are flushed first (not written twice), and the child's are /dev/null: a lock another thread
    of the parent held at the fork stays held in the child.

    Parameters
    ----------
    target : callable
    *args
        Its arguments (not pickled: the child is a fork).

    Returns
    -------
    multiprocessing.Process
        ``join()`` it; ``exitcode`` says how it ended.
    """
    sys.stdout.flush()
    sys.stderr.flush()
    child = multiprocessing.get_context("fork").Process(target=_quiet, args=(target, args))
    child.start()
    return child


def pipe():
    """A one-way pipe between this process and a child of :func:`start_child` (:func:`multiprocessing.Pipe`).

    Returns
    -------
    (Connection, Connection)
        The receiving end, then the sending end; each side closes the end it does not use.
    """
    return multiprocessing.get_context("fork").Pipe(duplex=False)


class Claims:
    """The indices ``0 … n-1`` handed out one at a time to this process and its forked children, each taking the next
    as it comes free (a counter in memory that a fork shares): iterating gives this process's share.

    Parameters
    ----------
    n : int
        Indices to hand out.
    """

    def __init__(self, n: int):
        self.n = n
        self._next = multiprocessing.get_context("fork").Value("q", 0)

    def __iter__(self):
        while True:
            with self._next.get_lock():
                i = int(self._next.value)
                self._next.value = i + 1
            if i >= self.n:
                return
            yield i


def _quiet(target, args) -> None:
    """A child's entry: its output to /dev/null, then ``target(*args)``."""
    sys.stdout = sys.stderr = open(os.devnull, "w")
    target(*args)


class ForkedCall:
    """``fn(*args)`` computed in a forked child while this process goes on (:mod:`multiprocessing`'s fork context,
    the answer back through its pipe).

    :meth:`result` returns its value or raises its exception, as calling ``fn(*args)`` here would. Without a child
    (:func:`can_fork` false) or when the child leaves no answer, :meth:`result` calls ``fn(*args)`` here.

    ``fn`` must not print, warn or report progress (the child's output goes nowhere). Its value and its
    :class:`~dynid.exceptions.DynIdError` are pickled back; any other exception is raised again by calling ``fn(*args)``
    here, with its traceback. Used as a context manager, it stops and waits for a child whose answer was not taken when
    the block ends (the work it was for failed).

    Parameters
    ----------
    fn : callable
        A module-level function (its value is pickled).
    *args
        Its arguments.
    """

    def __init__(self, fn, *args):
        self._call = (fn, args)
        self._child = None
        if not can_fork():
            return
        self._answer, sending = pipe()
        self._child = start_child(_child, sending, fn, args)
        sending.close()  # the child's end: its exit closes the pipe, so a child without an answer is seen

    def __enter__(self) -> ForkedCall:
        return self

    def __exit__(self, *exc) -> None:
        if self._child is not None:  # the answer was not taken: the child is stopped, not left behind
            self._child.kill()
            self._child.join()
            self._answer.close()
            self._child = None

    def result(self):
        """The value of ``fn(*args)``; raises what it raised.

        Returns
        -------
        object
        """
        fn, args = self._call
        if self._child is None:
            return fn(*args)
        child, self._child = self._child, None
        try:
            answer = self._answer.recv()  # EOFError: the child left without one (killed, or its answer did not pickle)
        except Exception:  # noqa: BLE001 - no answer, or one that does not unpickle: computed here instead
            answer = None
        finally:
            child.join()
            self._answer.close()
        if answer is None:
            return fn(*args)
        ok, value = answer
        if ok:
            return value
        raise value


def _child(sending, fn, args) -> None:
    """The child of :class:`ForkedCall`: compute and send ``(ok, value)``; anything else leaves no answer."""
    try:
        answer = (True, fn(*args))
    except DynIdError as exc:  # a user's mistake: the parent raises it (other errors: it calls fn itself)
        answer = (False, exc)
    sending.send(answer)
