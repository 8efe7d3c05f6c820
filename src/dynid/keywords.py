"""Keyword-only arguments after the data, introduced without breaking a caller: a call that still passes them by
position works as before, with a ``FutureWarning`` naming them (scikit-learn's way of making arguments keyword-only).
"""

from __future__ import annotations

import functools
import inspect
import warnings
from collections.abc import Callable
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])

SINCE = "0.2"
"""The release whose functions took these arguments keyword-only; a later release refuses them by position."""


def keyword_only_after_data(function: F) -> F:
    """Accept, with a ``FutureWarning``, by position the keyword-only arguments of ``function`` that it took by position
    before :data:`SINCE` (in their order).

    Parameters
    ----------
    function : callable
        Its signature has the data positional and the settings after ``*``.

    Returns
    -------
    callable
        The same function, which maps extra positional arguments onto the keyword-only ones and warns.
    """
    signature = inspect.signature(function)
    positional = [p.name for p in signature.parameters.values()
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    keyword_only = [p.name for p in signature.parameters.values() if p.kind is p.KEYWORD_ONLY]

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        extra = len(args) - len(positional)
        if extra <= 0:
            return function(*args, **kwargs)
        if extra > len(keyword_only):
            raise TypeError(f"{function.__qualname__}() takes {len(positional)} positional arguments but {len(args)} "
                            "were given")
        names = keyword_only[:extra]
        given = [n for n in names if n in kwargs]
        if given:
            raise TypeError(f"{function.__qualname__}() got multiple values for argument {given[0]!r}")
        warnings.warn(f"{function.__qualname__}: pass {', '.join(f'{n}=...' for n in names)} by name; by position it "
                      f"is refused in the release after {SINCE}", FutureWarning, stacklevel=2)
        return function(*args[:len(positional)], **dict(zip(names, args[len(positional):])), **kwargs)

    return wrapper  # type: ignore[return-value]
