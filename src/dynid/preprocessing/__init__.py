"""Preprocessing of measured data: eq. 17 smoothing, Fourier-fit derivatives, zero-phase and parallel
filtering, and the pipeline whose defaults derive from the data's excitation band."""

from .._lazy import lazy_exports

_EXPORTS = {
    "cutoffs_from_band": "bands",
    "excitation_band": "bands",
    "fourier_fit_derivatives": "fourier_fit",
    "PreparedData": "prepared",
    "Preprocessing": "settings",
    "base_chunks": "preparation",
    "prepare": "preparation",
    "five_point_cubic_smoothing": "smoothing",
}

__all__ = ["PreparedData", "Preprocessing", "base_chunks", "cutoffs_from_band", "excitation_band",
           "five_point_cubic_smoothing", "fourier_fit_derivatives", "prepare"]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
