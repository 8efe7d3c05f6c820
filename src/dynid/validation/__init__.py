"""Validation metrics: correlation coefficient (eq. 18), RMSE, relative error (per joint and global)."""

from .metrics import correlation_coefficient, global_relative_error, relative_error, rmse

__all__ = ["correlation_coefficient", "global_relative_error", "relative_error", "rmse"]
