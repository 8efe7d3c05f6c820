"""Optional dependencies: the heavy parts a user may not need (Dask for ``dynid montecarlo``, rosbags for ROS 2 bags),
installed by the package's extras, and a one-line message naming the extra when one is missing."""

from __future__ import annotations

import importlib
from types import ModuleType

from ..exceptions import ConfigError

EXTRAS = {"montecarlo": ("distributed",), "fleet": ("distributed", "pyarrow"), "ros": ("rosbags",), "mujoco": ("mujoco",),
          "xacro": ("yaml",)}
"""Extra (``pip install "dynid[extra]"``) -> the modules it brings."""


def require(module: str, extra: str, what: str) -> ModuleType:
    """Import an optional dependency.

    Parameters
    ----------
    module : str
        The module to import, e.g. ``"distributed"``.
    extra : str
        The extra of dynid that installs it (a key of :data:`EXTRAS`).
    what : str
        What needs it, for the message (``"dynid montecarlo"``).

    Returns
    -------
    module

    Raises
    ------
    ConfigError
        The module is not installed: says what needs it and the command that installs it.
    """
    try:
        return importlib.import_module(module)
    except ImportError:
        raise ConfigError(f"{what} needs {module.split('.')[0]}, which is not installed: pip install \"dynid[{extra}]\"") from None
