"""Validation metrics: correlation coefficient (eq. 18), RMSE, relative error."""

from .metrics import correlation_coefficient, relative_error, rmse

__all__ = ["correlation_coefficient", "relative_error", "rmse"]
