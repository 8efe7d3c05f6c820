"""Excitation trajectories: finite Fourier series (paper eq. 14, Swevers form), the paper's built-in ones,
design criteria, the constraints of eq. 15 and the optimal design."""

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


def __getattr__(name):  # exports are imported on first use, so that importing a submodule stays light
    if name in _EXPORTS:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
