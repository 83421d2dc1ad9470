"""An SSM's reduced model lowered to the numbers its module and its LaTeX print: the normal
form's coefficients, the radius, each output's Fourier coefficients along the manifold and
the forcing on Chebyshev nodes over the drive's range [Reduction -> ReducedModule]."""

from __future__ import annotations

import numpy as np

from ..analysis.ssm import Reduction, forcing
from .records import ReducedModule, provenance

FORCING_NODES = 32
# NOTE: Chebyshev nodes of S(Ω) and X(Ω) in the module: smooth over a range that holds no
# other mode, they interpolate to rounding (the module's frc agrees with ssm's to 1e-9).


def _pair(z: complex) -> tuple[float, float]:
    return float(z.real), float(z.imag)


def lower_reduction(red: Reduction, name: str, command: str) -> ReducedModule:
    """The :class:`ReducedModule` of a reduction (its forcing over its response's range)."""
    m = red.model
    K = m.order
    shape = np.zeros((K + 1, 2 * K + 1, len(red.outputs)), dtype=complex)
    for k in range(1, K + 1):
        for r in range(k + 1):
            shape[k, k - 2 * r + K] += m.W[k][r, red.outputs]
    span, nodes, table = None, (), ()
    if red.response is not None:
        lo, hi = red.span
        at = 0.5 * (lo + hi) + 0.5 * (hi - lo) * np.cos(
            np.pi * np.arange(FORCING_NODES + 1) / FORCING_NODES)
        fo = forcing(m, at, red.outputs)
        span, nodes = (lo, hi), tuple(float(x) for x in at)
        table = tuple((_pair(S), *(_pair(x) for x in X)) for S, X in zip(fo.S, fo.X,
                                                                          strict=True))
    return ReducedModule(
        name, f"The reduced model of the spectral submanifold of mode {m.mode} of "
        f"{red.text}, order {K}.", provenance(name, K, command, system=red.text, mode=m.mode,
                                               outputs=list(red.names), span=span),
        m.mode, K, red.names, tuple(_pair(g) for g in m.gamma),
        float(m.radius), tuple(tuple(tuple(_pair(z) for z in row) for row in order)
                               for order in shape), span, nodes, table)
