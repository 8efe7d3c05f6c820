"""dynid.report."""
