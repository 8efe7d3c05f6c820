"""Estimators of the base parameters from (W, tau): they never see robots, only the linear problem."""

from .base import Estimator, paper_objective
from .bee_colony import BeeColonyEstimator
from .least_absolute import LeastAbsoluteDeviations
from .least_squares import OrdinaryLeastSquares, WeightedLeastSquares
from .physically_consistent import PhysicallyConsistentLeastSquares

__all__ = ["Estimator", "paper_objective", "BeeColonyEstimator", "LeastAbsoluteDeviations", "OrdinaryLeastSquares", "WeightedLeastSquares",
           "PhysicallyConsistentLeastSquares"]
