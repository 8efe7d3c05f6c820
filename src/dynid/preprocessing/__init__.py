"""Preprocessing of measured data: eq. 17 smoothing, Fourier-fit derivatives, zero-phase and parallel
filtering, and the pipeline whose defaults derive from the data's excitation band."""

from .bands import cutoffs_from_band, excitation_band
from .fourier_fit import fourier_fit_derivatives
from .pipeline import PreparedData, Preprocessing, base_chunks, prepare
from .smoothing import five_point_cubic_smoothing

__all__ = ["PreparedData", "Preprocessing", "base_chunks", "cutoffs_from_band", "excitation_band",
           "five_point_cubic_smoothing", "fourier_fit_derivatives", "prepare"]
