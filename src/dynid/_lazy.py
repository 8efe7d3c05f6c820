"""Package exports imported on first use, so that importing one submodule (a config parser, say) does not
import every heavy dependency of its package; and the old paths of modules that moved, kept for a release."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings


def lazy_exports(package: str, exports: dict[str, str]):
    """``__getattr__`` and ``__dir__`` for a package whose public names ``exports`` maps to submodules
    (relative to ``package``, or absolute when they start with "dynid.")."""

    def __getattr__(name):
        if name in exports:
            module = exports[name]
            return getattr(importlib.import_module(module if module.startswith("dynid.") else f"{package}.{module}"), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(exports)

    return __getattr__, __dir__


def moved(old: str, new: str) -> None:
    """Say, with a ``FutureWarning``, that a module or a name moved."""
    warnings.warn(f"{old} moved to {new}; the old name goes in a later release", FutureWarning, stacklevel=3)


class ModuleAliases(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports an old module path as the module it became (the same module object, so state is shared), with a
    ``FutureWarning`` naming the new path.

    Parameters
    ----------
    paths : dict
        Old dotted path -> new dotted path.
    """

    def __init__(self, paths: dict[str, str]):
        self.paths = dict(paths)

    def find_spec(self, fullname, path=None, target=None):
        return importlib.util.spec_from_loader(fullname, self) if fullname in self.paths else None

    def create_module(self, spec):
        new = self.paths[spec.name]
        moved(spec.name, new)
        module = importlib.import_module(new)
        spec.loader_state = (module.__spec__, module.__loader__)  # the import system writes the alias's over them
        return module

    def exec_module(self, module):
        module.__spec__, module.__loader__ = module.__spec__.loader_state


def alias_moved_modules(paths: dict[str, str]) -> None:
    """Let the old paths of moved modules import (once per set of paths, whatever imports it again).

    Parameters
    ----------
    paths : dict
        Old dotted path -> new dotted path.
    """
    if not any(isinstance(f, ModuleAliases) and f.paths == paths for f in sys.meta_path):
        sys.meta_path.append(ModuleAliases(paths))
