"""Preprocessing of measured data: eq. 17 smoothing, Fourier-fit derivatives, zero-phase and parallel
filtering, and the pipeline whose defaults derive from the data's excitation band."""

_EXPORTS = {
    "cutoffs_from_band": "bands",
    "excitation_band": "bands",
    "fourier_fit_derivatives": "fourier_fit",
    "PreparedData": "pipeline",
    "Preprocessing": "settings",
    "base_chunks": "pipeline",
    "prepare": "pipeline",
    "five_point_cubic_smoothing": "smoothing",
}

__all__ = ["PreparedData", "Preprocessing", "base_chunks", "cutoffs_from_band", "excitation_band",
           "five_point_cubic_smoothing", "fourier_fit_derivatives", "prepare"]


def __getattr__(name):  # exports are imported on first use, so that importing a submodule stays light
    if name in _EXPORTS:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
