"""Parameters by name, as scikit-learn's ``BaseEstimator`` has them: ``get_params`` reads the constructor's
parameters back from the attributes of the same names, ``set_params`` sets them and refuses an unknown name."""

from __future__ import annotations

import inspect
from typing import Self

from .reprs import short_value


class HyperParameters:
    """Mixin: ``get_params`` / ``set_params`` over the constructor's parameters (scikit-learn's contract).

    A class stores each constructor parameter under its own name. ``PARAMETER_KINDS`` says which of its
    constructor's parameters count (:class:`inspect.Parameter` kinds); by default every named one.
    """

    PARAMETER_KINDS = frozenset({inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY})

    def get_params(self, deep: bool = True) -> dict:
        """The constructor's parameters and their values.

        Parameters
        ----------
        deep : bool
            Unused (no nested estimators); scikit-learn's signature.

        Returns
        -------
        dict
            Name -> value, in the constructor's order.
        """
        parameters = list(inspect.signature(type(self).__init__).parameters.values())[1:]  # not ``self``
        return {p.name: getattr(self, p.name) for p in parameters if p.kind in self.PARAMETER_KINDS}

    def set_params(self, **params) -> Self:
        """Set constructor parameters by name.

        Parameters
        ----------
        **params
            Name -> value.

        Returns
        -------
        self

        Raises
        ------
        ValueError
            An unknown name (the message names the class and the known names).
        """
        known = self.get_params()
        for name, value in params.items():
            if name not in known:
                raise ValueError(f"{type(self).__name__} has no parameter {name!r}; expected one of {sorted(known)}")
            setattr(self, name, value)
        return self

    def __repr__(self) -> str:
        """scikit-learn's: the class and the parameters that differ from the constructor's defaults, an array by its
        shape (``BeeColonyEstimator(colony_size=60)``).

        Returns
        -------
        str
        """
        defaults = {p.name: p.default for p in inspect.signature(type(self).__init__).parameters.values()}
        shown = [f"{name}={short_value(value)}" for name, value in self.get_params().items()
                 if not _is_default(value, defaults.get(name, inspect.Parameter.empty))]
        return f"{type(self).__name__}({', '.join(shown)})"


def _is_default(value, default) -> bool:
    """Whether a parameter's value is its default (an array never is, unless it is the default object)."""
    if value is default:
        return True
    if hasattr(value, "shape") or hasattr(default, "shape"):
        return False
    try:
        return bool(value == default)
    except (TypeError, ValueError):
        return False
