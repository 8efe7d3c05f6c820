"""dynid.preprocessing."""
