"""Generic optimisers used by the estimators."""

from .bee_colony import minimize_bee_colony

__all__ = ["minimize_bee_colony"]
