"""Driven oscillators: μ-expansion, harmonic balance, response, subharmonic, mixing, parametric."""
