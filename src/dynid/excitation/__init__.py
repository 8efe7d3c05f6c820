"""Excitation trajectories: finite Fourier series (paper eq. 14, Swevers form), the paper's built-in ones,
design criteria, the constraints of eq. 15 and the optimal design."""

from .constraints import ConstraintMargin, Workspace
from .design import ExcitationDesign, ExcitationProblem, InfeasibleDesignError, design_excitation
from .fourier import FourierTrajectory, trajectory_from_dict
from .paper_trajectories import paper_identification_trajectory, paper_validation_trajectory

__all__ = ["ConstraintMargin", "ExcitationDesign", "ExcitationProblem", "FourierTrajectory", "InfeasibleDesignError",
           "Workspace", "design_excitation", "paper_identification_trajectory", "paper_validation_trajectory",
           "trajectory_from_dict"]
