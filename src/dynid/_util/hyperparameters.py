"""Parameters by name, as scikit-learn's ``BaseEstimator`` has them: ``get_params`` reads the constructor's
parameters back from the attributes of the same names, ``set_params`` sets them and refuses an unknown name."""

from __future__ import annotations

import functools
import inspect
import math
import numbers
from typing import Self

from ..exceptions import ConfigError
from .reprs import short_value


class HyperParameters:
    """Mixin: ``get_params`` / ``set_params`` over the constructor's parameters (scikit-learn's contract).

    A class stores each constructor parameter under its own name. ``PARAMETER_KINDS`` says which of its
    constructor's parameters count (:class:`inspect.Parameter` kinds); by default every named one.
    """

    PARAMETER_KINDS = frozenset({inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY})

    CONSTRAINTS: dict[str, tuple[str, float | None, float | None]] = {}
    """Name -> ``(kind, low, high)`` (scikit-learn's ``_parameter_constraints``): ``"int"`` an integer (not a bool, not a
    float like 6.0), ``"real"`` a finite number, within ``[low, high]`` (None: unbounded). Checked where the object is
    built and by :meth:`set_params`; a parameter whose default is None may be None."""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        init = cls.__dict__.get("__init__")
        if init is None:
            return

        @functools.wraps(init)
        def checked(self, *args, **kw):
            init(self, *args, **kw)
            self.check_params()

        cls.__init__ = checked  # type: ignore[method-assign]

    def check_params(self) -> None:
        """Refuse a parameter outside :attr:`CONSTRAINTS` in one line naming the class, the parameter and what was
        expected.

        Raises
        ------
        ConfigError
            ``field`` the parameter's name.
        """
        defaults = {p.name: p.default for p in inspect.signature(type(self).__init__).parameters.values()}
        for name, (kind, low, high) in self.CONSTRAINTS.items():
            if not hasattr(self, name) or (getattr(self, name) is None and defaults.get(name) is None):
                continue
            value = getattr(self, name)
            number = isinstance(value, numbers.Real) and not isinstance(value, bool)
            ok = number and (isinstance(value, numbers.Integral) if kind == "int" else math.isfinite(value))
            if ok and (low is None or value >= low) and (high is None or value <= high):
                continue
            what = "an integer" if kind == "int" else "a finite number"
            span = (f" from {low:g} to {high:g}" if low is not None and high is not None else
                    f" of at least {low:g}" if low is not None else f" of at most {high:g}" if high is not None else "")
            raise ConfigError(f"{type(self).__name__}: {name}: expected {what}{span}, got {value!r}", field=name)

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
        self.check_params()
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
