"""Excitation trajectories: finite Fourier series (paper eq. 14) and the paper's built-in ones."""

from .fourier import FourierTrajectory
from .paper_trajectories import paper_identification_trajectory, paper_validation_trajectory

__all__ = ["FourierTrajectory", "paper_identification_trajectory", "paper_validation_trajectory"]
