"""The one route from a recording to an estimate: the pipeline and its parts (:mod:`.pipeline`), the data-driven
choices made inside it (:mod:`.cross_validation`, :mod:`.friction_models`, :mod:`.delay`), the estimators run on the
prepared data incl. the closed-loop ones (:mod:`.identify`, :mod:`.closed_loop`), drive gains (:mod:`.drive_gains`), the
runs ``dynid identify`` / ``validate`` / ``excite`` describe (:mod:`.run`, :mod:`.excitation_run`), the identified model
(:mod:`.identified`) and :class:`~.identifier.Identifier`."""

from .._lazy import lazy_exports

_EXPORTS = {
    "Identifier": "identifier",
    "IdentifiedModel": "identified",
    "load_results": "identified",
    "run_identification": "run",
    "run_validation": "run",
    "identify_from_arrays": "run",
}

__all__ = list(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
