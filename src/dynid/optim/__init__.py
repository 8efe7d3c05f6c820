"""Generic optimisers used by the estimators."""

from .bee_colony import minimize_bee_colony
from .particle_swarm import minimize_particle_swarm

__all__ = ["minimize_bee_colony", "minimize_particle_swarm"]
