"""Reprs that fit a screen (issue "Parts carry their settings, one route", item 6): a record typed at a prompt shows its
fields, an array by its shape, a long sequence or mapping by its length, a nested record by its own short repr."""

from __future__ import annotations

import dataclasses
from pathlib import PurePath

__all__ = ["short_repr", "short_value"]

INLINE = 80
"""Characters a field's value may take in a record's repr; a longer one is said by its kind and length."""


def short_value(value) -> str:
    """A value as a record's repr shows it: an array by its shape, a number, a short string or a short sequence as
    itself, a record by its short repr, a long string by its beginning, anything longer by its type and length.

    Parameters
    ----------
    value : object

    Returns
    -------
    str
    """
    shape = getattr(value, "shape", None)
    if isinstance(shape, tuple) and shape:  # an array (a NumPy scalar's shape is ())
        return f"<array {shape}>"
    if isinstance(value, float) or shape == () and getattr(getattr(value, "dtype", None), "kind", "") == "f":
        return f"{float(value):.6g}"
    if isinstance(value, PurePath):
        value = str(value)
    text = repr(value) if not _is_record(value) else short_repr_of(value)
    if len(text) <= INLINE:
        return text
    if isinstance(value, str):  # its beginning, which names it
        return repr(value[:INLINE - 8] + "...")
    if isinstance(value, (list, tuple, dict, set, frozenset)):
        kinds = sorted({type(v).__name__ for v in (value.values() if isinstance(value, dict) else value)})
        return f"<{type(value).__name__} of {len(value)}{' ' + kinds[0] if len(kinds) == 1 else ''}>"
    return f"<{type(value).__name__}>"


def _is_record(value) -> bool:
    return dataclasses.is_dataclass(value) and not isinstance(value, type)


def short_repr_of(record) -> str:
    """A dataclass instance's repr with each field as :func:`short_value` shows it (fields declared ``repr=False``
    left out).

    Parameters
    ----------
    record : dataclass instance

    Returns
    -------
    str
    """
    shown = [f"{f.name}={short_value(getattr(record, f.name))}" for f in dataclasses.fields(record) if f.repr]
    return f"{type(record).__name__}({', '.join(shown)})"


def short_repr(cls: type) -> type:
    """Class decorator, above ``@dataclass``: the class's repr is :func:`short_repr_of`.

    Parameters
    ----------
    cls : type
        A dataclass.

    Returns
    -------
    type
        The same class.
    """
    cls.__repr__ = short_repr_of  # type: ignore[assignment,method-assign]
    return cls
