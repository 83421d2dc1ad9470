"""Numerical references: the one integrator, shooting, Floquet, quadratures."""
