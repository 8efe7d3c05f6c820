"""dynid.validation."""
