"""Input/output by job: :mod:`dynid.io.config` (configs), :mod:`dynid.io.logs` (logs), :mod:`dynid.io.exported` (the
exported model), results.json (:mod:`dynid.io.results`) and atomic file writing (:mod:`dynid.io.files`)."""

from .._lazy import alias_moved_modules
from .files import atomic_write_bytes, atomic_write_text, write_json

__all__ = ["atomic_write_bytes", "atomic_write_text", "write_json", "MOVED"]

MOVED = {f"dynid.io.{name}": f"dynid.io.{package}.{name}" for package, names in (
    ("config", ("config_types", "configs", "excitation_config", "identification_config", "references")),
    ("logs", ("bags", "datasets", "trajectories")), ("exported", ("export",))) for name in names} | {
    "dynid.io.tables": "dynid.io.logs.table_files"}
"""Modules of ``dynid.io`` in 0.1.0 grouped by job in 0.2 -> where they went: their old paths import them, with a
FutureWarning, for a release (docs/changelog.md). Those an earlier 0.2.0 draft added have no old path."""
alias_moved_modules(MOVED)
