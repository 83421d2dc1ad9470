"""Lowering: solutions to IR records, and the printers."""
