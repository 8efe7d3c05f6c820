"""The one route from a recording to an estimate: the pipeline and its parts (:mod:`.pipeline`), the data-driven
choices made inside it (:mod:`.cross_validation`, :mod:`.friction_models`, :mod:`.delay`), the estimation pass over the
prepared data (:mod:`.estimation_pass`) and the closed-loop estimators (:mod:`.closed_loop_estimators`), the evidence
(:mod:`.evidence`) and the verdict (:mod:`.verdict`), the result (:mod:`.result`), drive gains (:mod:`.drive_gains`),
the runs ``dynid identify`` / ``validate`` / ``excite`` describe (:mod:`.run`, :mod:`.excite`), the fitted model
(:mod:`.fitted_model`) and the estimator facade :class:`~.identifier.Identifier`."""

from .._lazy import lazy_exports

_EXPORTS = {
    "Identifier": "identifier",
    "IdentifiedModel": "fitted_model",
    "load_results": "fitted_model",
    "run_identification": "run",
    "run_validation": "run",
    "identify_from_arrays": "run",
}

__all__ = list(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
