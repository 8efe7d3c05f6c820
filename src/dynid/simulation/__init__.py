"""dynid.simulation."""
