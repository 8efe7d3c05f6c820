"""Excitation trajectories: finite Fourier series (paper eq. 14, Swevers form), the paper's built-in ones,
design criteria, the constraints of eq. 15 and the optimal design."""

from .._lazy import lazy_exports

_EXPORTS = {
    "ConstraintMargin": "constraints",
    "Workspace": "constraints",
    "ExcitationDesign": "design",
    "ExcitationProblem": "design",
    "InfeasibleDesignError": "design",
    "design_excitation": "design",
    "FourierTrajectory": "fourier",
    "trajectory_from_dict": "fourier",
    "paper_identification_trajectory": "paper_trajectories",
    "paper_validation_trajectory": "paper_trajectories",
}

__all__ = ["ConstraintMargin", "ExcitationDesign", "ExcitationProblem", "FourierTrajectory", "InfeasibleDesignError",
           "Workspace", "design_excitation", "paper_identification_trajectory", "paper_validation_trajectory",
           "trajectory_from_dict"]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
