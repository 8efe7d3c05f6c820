"""The user's own estimators and preprocessing strategies, loaded where a config or a command names them.

A new estimator or strategy is one Python file that registers it (:func:`dynid.estimators.register`,
:func:`dynid.preprocessing.strategies.register_strategy`). dynid imports such files or modules

- named by ``--plugin FILE_OR_MODULE`` on the command line (``dynid --plugin my_ridge.py identify arm.toml``);
- listed in the environment variable ``DYNID_PLUGINS`` (separated by ``os.pathsep``), which worker processes of a
  local Dask cluster inherit;
- declared by an installed package as an entry point of the group ``dynid.plugins`` (``[project.entry-points.
  "dynid.plugins"] ridge = "my_package.ridge"`` in its ``pyproject.toml``).

They are imported when a name is not a built-in one, once per process (a file as the module named after it), and on
every worker of the Dask clusters dynid starts or joins (:func:`share_with`: a file is uploaded).
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import sys
from pathlib import Path

from .exceptions import ConfigError

__all__ = ["ENTRY_POINT_GROUP", "ENVIRONMENT", "load_plugins", "add_plugins", "share_with", "origin"]

ENTRY_POINT_GROUP = "dynid.plugins"
"""Entry-point group of installed plugin packages."""

ENVIRONMENT = "DYNID_PLUGINS"
"""Environment variable listing plugin files or modules (``os.pathsep``-separated)."""

_LOADED: dict[str, str] = {}
"""plugin (as named) -> module name, for the plugins this process imported."""


def add_plugins(plugins) -> None:
    """Name plugins for this process and the processes it starts (``DYNID_PLUGINS``), and import them.

    Parameters
    ----------
    plugins : iterable of str
        Python files (``.py``) or importable module names.

    Raises
    ------
    ConfigError
        A plugin that cannot be found or imported (one line naming it).
    """
    plugins = [str(p) for p in plugins]
    if not plugins:
        return
    resolved = [str(Path(p).resolve()) if p.endswith(".py") else p for p in plugins]
    for given, plugin in zip(plugins, resolved):
        if plugin not in _LOADED:
            _LOADED[plugin] = _import(plugin, f"--plugin {given}")
    listed = [p for p in os.environ.get(ENVIRONMENT, "").split(os.pathsep) if p]
    os.environ[ENVIRONMENT] = os.pathsep.join(dict.fromkeys(listed + resolved))


def load_plugins() -> tuple[str, ...]:
    """Import every plugin named by ``DYNID_PLUGINS`` and the ``dynid.plugins`` entry points, those not imported yet.

    Returns
    -------
    tuple of str
        The plugins imported by this call.

    Raises
    ------
    ConfigError
        A plugin that cannot be found or imported (one line naming it and where it was named).
    """
    named = [(p, f"from {ENVIRONMENT}") for p in os.environ.get(ENVIRONMENT, "").split(os.pathsep) if p]
    try:
        from importlib.metadata import entry_points

        named += [(ep.value, f"entry point {ep.name!r} of {ENTRY_POINT_GROUP}") for ep in entry_points(group=ENTRY_POINT_GROUP)]
    except Exception:  # a broken distribution's metadata: the plugins named otherwise still load
        pass
    done = []
    for plugin, where in named:
        if plugin in _LOADED:
            continue
        _LOADED[plugin] = _import(plugin, where)
        done.append(plugin)
    return tuple(done)


def _import(plugin: str, where: str) -> str:
    """Import one plugin; its module's name."""
    try:
        if plugin.endswith(".py"):
            path = Path(plugin)
            if not path.is_file():
                raise ConfigError(f"plugin {plugin} ({where}): no such file")
            name = path.stem  # as Dask's upload_file names it on the workers (share_with)
            known = sys.modules.get(name)
            if known is not None:
                if Path(getattr(known, "__file__", "") or "").resolve() != path.resolve():
                    raise ConfigError(f"plugin {plugin} ({where}): its name {name!r} is the module {known.__name__} "
                                      f"already imported from {getattr(known, '__file__', 'elsewhere')}: rename the file")
                return name
            spec = importlib.util.spec_from_file_location(name, path)
            assert spec is not None and spec.loader is not None
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            try:
                spec.loader.exec_module(module)
            except BaseException:
                del sys.modules[name]
                raise
            return name
        importlib.import_module(plugin.split(":")[0])
        return plugin.split(":")[0]
    except ConfigError:
        raise
    except Exception as exc:  # the plugin's own error, said in one line
        raise ConfigError(f"plugin {plugin} ({where}): cannot import it: {type(exc).__name__}: {exc}") from None


def share_with(client) -> None:
    """Import this process's plugins on every worker of a Dask cluster: a file is uploaded (the workers of a remote
    cluster need not have it), a module imported.

    Parameters
    ----------
    client : distributed.Client

    Raises
    ------
    ConfigError
        A plugin the workers cannot import (one line naming it).
    """
    for plugin, module in list(_LOADED.items()):
        try:
            if plugin.endswith(".py"):
                client.upload_file(plugin, load=True)
            else:
                client.run(importlib.import_module, module)
        except Exception as exc:
            raise ConfigError(f"plugin {plugin}: the Dask workers cannot import it: {type(exc).__name__}: {exc}") from None


def origin(builder) -> str:
    """Where an estimator's or a strategy's builder is defined, ``module.qualname`` of its class (or of the builder),
    or the ``"module:attribute"`` text naming it: a plugin imported again registers the same origin, which is no
    conflict.

    Parameters
    ----------
    builder : class, instance, callable or str

    Returns
    -------
    str
    """
    if isinstance(builder, str):
        return builder
    target = builder if hasattr(builder, "__qualname__") else type(builder)  # a class or a function, else an instance
    return f"{target.__module__}.{target.__qualname__}"


class Registry:
    """Names of one kind of the user's extensible parts (estimators, preprocessing strategies) -> their entries.

    One register/unregister/look-up for both kinds: a key is case-insensitive; registering a key again is an error
    unless ``replace`` or the same origin (:func:`origin`: a plugin imported again); a name not known is looked up
    again after :func:`load_plugins`.

    Parameters
    ----------
    what : str
        The kind, in messages: ``"estimator"``, ``"preprocessing strategy"``.
    builder : callable
        entry -> what :func:`origin` reads (the entry itself, or its ``build``).

    Attributes
    ----------
    entries : dict
        key -> entry, in registration order.
    built_in : tuple of str
        The keys registered when :meth:`seal` was called (dynid's own).
    """

    def __init__(self, what: str, builder=lambda entry: entry):
        self.what = what
        self.builder = builder
        self.entries: dict = {}
        self.built_in: tuple[str, ...] = ()
        self._built_in_origins: dict[str, str] = {}

    @staticmethod
    def key(name) -> str:
        """``name`` as stored: stripped, in lower case.

        Parameters
        ----------
        name : str
            A name as a user or a plugin wrote it.

        Returns
        -------
        str
        """
        return str(name).strip().lower()

    def add(self, key: str, entry, *, replace: bool = False) -> None:
        """Register ``entry`` under ``key`` (already checked by the caller).

        Parameters
        ----------
        key : str
            In lower case.
        entry : object
        replace : bool
            Replace an entry of another origin.

        Raises
        ------
        ValueError
            ``key`` registered already, from another origin, without ``replace``.
        """
        known = self.entries.get(key)
        if known is not None and not replace and origin(self.builder(known)) != origin(self.builder(entry)):
            raise ValueError(f"{self.what} {key!r} is registered already (pass replace=True to replace it)")
        self.entries[key] = entry

    def remove(self, name: str) -> None:
        """Forget a registered entry.

        Parameters
        ----------
        name : str

        Raises
        ------
        KeyError
            An unknown name.
        """
        del self.entries[self.key(name)]

    def seal(self) -> tuple[str, ...]:
        """Record the entries registered so far as the built-in ones.

        Returns
        -------
        tuple of str
            Their keys.
        """
        self.built_in = tuple(self.entries)
        self._built_in_origins = {k: origin(self.builder(self.entries[k])) for k in self.built_in}
        return self.built_in

    def is_plugin(self, name: str) -> bool:
        """Whether ``name``'s entry is the user's (a plugin's, or a built-in key replaced by one).

        Parameters
        ----------
        name : str

        Returns
        -------
        bool
        """
        k = self.key(name)
        return k not in self._built_in_origins or origin(self.builder(self.entries[k])) != self._built_in_origins[k]

    def find(self, name: str):
        """The entry of ``name``, the plugins loaded first if it is not known.

        Parameters
        ----------
        name : str

        Returns
        -------
        object or None
            None: not registered, even by a plugin.
        """
        k = self.key(name)
        if k not in self.entries:
            load_plugins()
        return self.entries.get(k)

    def by_user(self, keys) -> dict:
        """The entries among ``keys`` (already checked) that are not built in, for another process to register.

        Parameters
        ----------
        keys : iterable of str

        Returns
        -------
        dict
            key -> entry.
        """
        return {k: self.entries[k] for k in keys if k not in self.built_in}

    def ensure(self, entries: dict) -> None:
        """Register the entries that this process does not know (a worker process).

        Parameters
        ----------
        entries : dict
            key -> entry, from :meth:`by_user` in the process that had them.
        """
        for key, entry in entries.items():
            self.entries.setdefault(key, entry)
