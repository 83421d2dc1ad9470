"""Derivation: equations, models, L–P series, limit cycles, Hill, averaging."""
