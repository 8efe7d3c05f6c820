"""Former home of the identification route, the simulated studies and the fleet tools (dynid 0.1.0), kept so that old
imports still work for one release: ``dynid.experiment.X`` now lives in :mod:`dynid.identification`,
:mod:`dynid.studies` or :mod:`dynid.fleet` (docs/changelog.md). Each old name imports the new module and says where it
went with a ``FutureWarning``."""

from __future__ import annotations

import importlib

from .._lazy import alias_moved_modules, moved

MOVED = {
    "drive_gains": "dynid.identification.drive_gains",
    "excitation": "dynid.identification.excite",
    "identification": "dynid.identification.estimation_pass",
    "identification_run": "dynid.identification.run",
    "identified": "dynid.identification.fitted_model",
    "identifier": "dynid.identification.identifier",
    "montecarlo": "dynid.studies.montecarlo",
    "paper": "dynid.studies.paper",
    "paper_reference": "dynid.studies.paper_reference",
    "simulated_logs": "dynid.studies.simulated_logs",
}
"""Submodule of ``dynid.experiment`` in 0.1.0 → the module it became (those an earlier 0.2.0 draft added there and
moved on have no old path: no release had them)."""

_NAMES = {"PaperExperimentConfig": "dynid.studies.paper", "PaperRunResult": "dynid.studies.paper",
          "run_paper_experiment": "dynid.studies.paper"}


alias_moved_modules({f"{__name__}.{old}": new for old, new in MOVED.items()})


def __getattr__(name):
    if name in _NAMES:
        moved(f"{__name__}.{name}", _NAMES[name])
        value = globals()[name] = getattr(importlib.import_module(_NAMES[name]), name)
        return value
    if name in MOVED:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
