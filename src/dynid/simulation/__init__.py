"""Simulated measurements: torques from Pinocchio's RNEA plus friction, currents (eq. 16), noise."""

from .measurements import Measurements, NoiseModel, simulate_measurements

__all__ = ["Measurements", "NoiseModel", "simulate_measurements"]
