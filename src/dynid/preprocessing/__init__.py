"""Preprocessing of measured data: eq. 17 smoothing and Fourier-fit derivatives."""

from .fourier_fit import fourier_fit_derivatives
from .smoothing import five_point_cubic_smoothing

__all__ = ["five_point_cubic_smoothing", "fourier_fit_derivatives"]
