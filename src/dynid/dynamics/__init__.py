"""dynid.dynamics."""
