"""dynid.io."""
