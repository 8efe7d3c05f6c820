"""Exceptions of dynid. Every error a user can cause is a :class:`DynIdError`.

The CLI prints ``str(error)`` on one line and exits with code 1; messages say what was expected,
what was found and, where possible, how to fix it.
"""


class DynIdError(Exception):
    """Base class of all errors raised by dynid for bad input or data.

    ``field`` names the setting at fault when the message starts with it (``"seed must be …"``): the library speaks of
    its settings' names, the CLI translates them to its options (``--seed``).

    Parameters
    ----------
    message : str
        One line: what was expected, what was found, how to fix it.
    field : str, optional
        The setting at fault when the message starts with it (the CLI names its option instead).
    """

    def __init__(self, message: str = "", field: str | None = None):
        super().__init__(message)
        self.field = field


class ConfigError(DynIdError, ValueError):
    """A robot description or experiment configuration is invalid (names the file and field).

    Parameters
    ----------
    message : str
        One line: what was expected, what was found, how to fix it.
    field : str, optional
        The setting at fault when the message starts with it (the CLI names its option instead).
    """


class ShapeError(DynIdError, ValueError):
    """An array has the wrong shape (says expected vs got).

    Parameters
    ----------
    message : str
        One line: what was expected, what was found, how to fix it.
    field : str, optional
        The setting at fault when the message starts with it (the CLI names its option instead).
    """


class DataError(DynIdError, ValueError):
    """Measured data is unusable (names the file, row or column).

    Parameters
    ----------
    message : str
        One line: what was expected, what was found, how to fix it.
    field : str, optional
        The setting at fault when the message starts with it (the CLI names its option instead).
    """


class IdentifiabilityError(DynIdError, ValueError):
    """The data do not excite the parameters enough (rank-deficient observation matrix).

    Parameters
    ----------
    message : str
        One line: what was expected, what was found, how to fix it.
    field : str, optional
        The setting at fault when the message starts with it (the CLI names its option instead).
    """


class NotFittedError(DynIdError, ValueError, AttributeError):
    """An estimator or an Identifier used before ``fit``: the same bases as scikit-learn's ``NotFittedError``
    (``ValueError`` and ``AttributeError``), so code written for either catches it.

    Parameters
    ----------
    message : str
        One line: what was called, and which fit to call first.
    field : str, optional
        The setting at fault when the message starts with it (the CLI names its option instead).
    """
