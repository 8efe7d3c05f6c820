"""Former home of the identification route, the simulated studies and the fleet tools (dynid ≤ 0.8), kept so that old
imports still work for one release: ``dynid.experiment.X`` now lives in :mod:`dynid.identification`,
:mod:`dynid.studies` or :mod:`dynid.fleet` (docs/changelog.md). Each old name imports the new module and says where it
went with a ``FutureWarning``."""

from __future__ import annotations

import importlib

from .._lazy import alias_moved_modules, moved

MOVED = {
    "closed_loop": "dynid.identification.closed_loop",
    "closed_loop_study": "dynid.studies.closed_loop",
    "delay": "dynid.identification.delay",
    "drive_gains": "dynid.identification.drive_gains",
    "excitation": "dynid.identification.excitation_run",
    "fleet": "dynid.fleet.identification",
    "identification": "dynid.identification.identify",
    "identification_pipeline": "dynid.identification.pipeline",
    "identification_run": "dynid.identification.run",
    "identified": "dynid.identification.identified",
    "identifier": "dynid.identification.identifier",
    "monitor": "dynid.fleet.monitor",
    "montecarlo": "dynid.studies.montecarlo",
    "paper": "dynid.studies.paper",
    "paper_reference": "dynid.studies.paper_reference",
    "simulated_fleet": "dynid.studies.simulated_fleet",
    "simulated_logs": "dynid.studies.simulated_logs",
}
"""Old submodule of ``dynid.experiment`` → the module it became."""

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
