"""Package exports imported on first use, so that importing one submodule (a config parser, say) does not
import every heavy dependency of its package."""

from __future__ import annotations

import importlib


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
