"""An SSM's reduced model lowered to the numbers its module and its LaTeX print: the normal
form's coefficients, the radius, each output's Fourier coefficients along the manifold and
the forced terms (A_j, B_j and the outputs' W¹) on Chebyshev nodes over the drive's range
[Reduction -> ReducedModule]."""

from __future__ import annotations

import numpy as np

from ..analysis.ssm_forced import Reduction, _flatten, chebyshev, forced_order, forced_terms
from .records import ReducedModule, provenance

FORCING_NODES = 32
# NOTE: Chebyshev nodes of the forced terms in the module: smooth over a range that holds no
# other mode, they interpolate to rounding (the module's frc agrees with ssm's to 1e-9).


def _pair(z: complex) -> tuple[float, float]:
    return float(z.real), float(z.imag)


def lower_reduction(red: Reduction, name: str, command: str) -> ReducedModule:
    """The :class:`ReducedModule` of a reduction (its forced terms over its response's
    range)."""
    m = red.model
    K = m.order
    shape = np.zeros((K + 1, 2 * K + 1, len(red.outputs)), dtype=complex)
    for k in range(1, K + 1):
        for r in range(k + 1):
            shape[k, k - 2 * r + K] += m.W[k][r, red.outputs]
    span, nodes, table, sizes = None, (), (), (0, 0, 0)
    if red.response is not None:
        lo, hi = red.span
        at = chebyshev(lo, hi, FORCING_NODES)
        forced = [forced_terms(m, float(om), red.outputs) for om in at]
        span, nodes = (lo, hi), tuple(float(x) for x in at)
        table = tuple(tuple(_pair(z) for z in _flatten(f)) for f in forced)
        sizes = (len(forced[0].A), len(forced[0].B), forced_order(m))
    return ReducedModule(
        name, f"The reduced model of the spectral submanifold of mode {m.mode} of "
        f"{red.text}, order {K}.", provenance(name, K, command, system=red.text, mode=m.mode,
                                               outputs=list(red.names), span=span),
        m.mode, K, red.names, tuple(_pair(g) for g in m.gamma),
        float(m.radius), tuple(tuple(tuple(_pair(z) for z in row) for row in order)
                               for order in shape), span, nodes, table, sizes)
