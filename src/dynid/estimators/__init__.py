"""Estimators of the base parameters from (W, tau): they never see robots, only the linear problem."""

from .base import BoxSearchEstimator, Estimator, paper_objective
from .bee_colony import BeeColonyEstimator
from .bootstrap import BootstrapIntervals, bootstrap_intervals
from .global_search import DifferentialEvolutionEstimator, ParticleSwarmEstimator
from .least_absolute import LeastAbsoluteDeviations
from .least_squares import OrdinaryLeastSquares, WeightedLeastSquares
from .physically_consistent import PhysicallyConsistentLeastSquares, consistency_margin
from .robust import IterativelyReweightedLeastSquares

__all__ = ["Estimator", "BoxSearchEstimator", "paper_objective", "BeeColonyEstimator", "BootstrapIntervals",
           "bootstrap_intervals", "DifferentialEvolutionEstimator", "ParticleSwarmEstimator", "LeastAbsoluteDeviations",
           "OrdinaryLeastSquares", "WeightedLeastSquares", "PhysicallyConsistentLeastSquares",
           "IterativelyReweightedLeastSquares", "consistency_margin"]
