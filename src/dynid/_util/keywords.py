"""Keyword-only arguments after the data, introduced without breaking a caller: a call that still passes them by
position works as before, with a ``FutureWarning`` naming them (scikit-learn's way of making arguments keyword-only).
"""

from __future__ import annotations

import functools
import inspect
import warnings
from collections.abc import Callable
from typing import Any, TypeVar

from ..exceptions import ConfigError

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


def renamed_keyword(old: str, new: str) -> Callable[[F], F]:
    """Accept, with a ``FutureWarning``, a keyword argument under its former name.

    Parameters
    ----------
    old : str
        The former name (``"seed"``).
    new : str
        The name the function takes now (``"rng"``).

    Returns
    -------
    callable
        A decorator: the function it wraps maps ``old=`` onto ``new=`` and warns; both given is a ``TypeError``. Its
        signature (``inspect.signature``, scikit-learn's ``get_params``) is the function's own.
    """

    def decorate(function: F) -> F:
        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            if old in kwargs:
                if new in kwargs:
                    raise TypeError(f"{function.__qualname__}() got {old}= and {new}=: give {new}= only")
                warnings.warn(f"{function.__qualname__}: {old}= is now {new}= (one name for the random state in dynid, as "
                              f"NumPy's and SciPy's); {old}= is refused in the release after {SINCE}", FutureWarning,
                              stacklevel=2)
                kwargs[new] = kwargs.pop(old)
            return function(*args, **kwargs)

        return wrapper  # type: ignore[return-value]

    return decorate


def seed_of(rng, default: int = 0) -> int:
    """The integer seed of a random state given as dynid's ``rng`` settings take it (NumPy's SPEC 7).

    Parameters
    ----------
    rng : int, numpy.random.Generator or None
        An integer is the seed itself; a generator gives one draw (so the same generator state gives the same seed);
        None is ``default``.
    default : int

    Returns
    -------
    int

    Raises
    ------
    TypeError
        Anything else (a float, a legacy ``RandomState``).
    ConfigError
        A negative integer (NumPy takes no negative seed).
    """
    import numpy as np

    if rng is None:
        return int(default)
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool):
        if rng < 0:
            raise ConfigError(f"rng: expected a seed >= 0 (or a numpy.random.Generator), got {int(rng)}")
        return int(rng)
    if isinstance(rng, np.random.Generator):
        return int(rng.integers(2**31))
    raise TypeError(f"rng: expected an int, a numpy.random.Generator or None, got {type(rng).__name__}")
