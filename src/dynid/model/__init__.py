"""dynid.model."""
