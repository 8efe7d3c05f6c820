"""dynid.estimators."""
