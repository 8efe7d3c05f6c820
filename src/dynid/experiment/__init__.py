"""dynid.experiment."""
