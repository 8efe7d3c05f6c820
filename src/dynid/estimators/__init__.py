"""Estimators of the base parameters from (W, tau): they never see robots, only the linear problem.

:mod:`dynid.estimators.registry` builds any of them from a method key (:mod:`dynid.estimators.names`);
the classes load on first use, so that reading method names (a config check) imports no solver.
"""

from .._lazy import lazy_exports

_EXPORTS = {
    "Estimator": "base", "BoxSearchEstimator": "base", "paper_objective": "base", "weighted_rows": "base",
    "BeeColonyEstimator": "bee_colony",
    "BootstrapIntervals": "bootstrap", "bootstrap_intervals": "bootstrap",
    "DifferentialEvolutionEstimator": "global_search", "ParticleSwarmEstimator": "global_search",
    "LeastAbsoluteDeviations": "least_absolute",
    "OrdinaryLeastSquares": "least_squares", "WeightedLeastSquares": "least_squares",
    "PhysicallyConsistentLeastSquares": "physically_consistent", "consistency_margin": "physically_consistent",
    "IterativelyReweightedLeastSquares": "robust",
    "AccumulatingEstimator": "base",
    "register": "registry", "unregister": "registry", "EstimatorSpec": "registry", "FitData": "registry",
    "Estimation": "estimation",
    "check_estimator": "contract", "EstimatorCheckError": "contract",
}

__all__ = list(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
