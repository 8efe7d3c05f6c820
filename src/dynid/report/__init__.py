"""Plots (the paper's figures) and run reports; thin layers over the library."""
