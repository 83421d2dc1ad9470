"""Exact algebra: the one Fourier kernel (series) and Padé resummation (resum)."""
