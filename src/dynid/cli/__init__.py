"""dynid.cli."""
