"""An SSM's reduced model lowered to the numbers its module and its LaTeX print: the normal
form's coefficients, the radius, each output's Fourier coefficients along the manifold and
the forced terms (A_j, B_j and the outputs' W¹) on Chebyshev nodes over the drive's range,
with the interpolation error they reach [Reduction -> ReducedModule]."""

from __future__ import annotations

import textwrap

import numpy as np

from ..analysis.ssm_forced import (
    CHEBYSHEV_MOST,
    INTERPOLATED,
    Reduction,
    forced_order,
    forcing_pieces,
)
from .records import ForcingPiece, ReducedModule, provenance

FORCING_SPLITS = 3
# NOTE: the forced terms are fitted as the in-process forced response fits them
# (analysis.ssm_forced.forcing_fit: Chebyshev nodes doubled on their own midpoints up to 128,
# to INTERPOLATED); where that fails over the range (another mode's or a combination
# resonance inside it), over each half, up to 3 times (8 pieces). A piece that still fails is
# recorded as unverified and the module's frc is NaN there: it cannot compute the terms
# itself.


def _pair(z: complex) -> tuple[float, float]:
    return float(z.real), float(z.imag)


def lower_reduction(red: Reduction, name: str, command: str) -> ReducedModule:
    """The :class:`ReducedModule` of a reduction (its forced terms over its response's
    range, in pieces where one fit does not verify)."""
    m = red.model
    K = m.order
    shape = np.zeros((K + 1, 2 * K + 1, len(red.outputs)), dtype=complex)
    for k in range(1, K + 1):
        for r in range(k + 1):
            shape[k, k - 2 * r + K] += m.W[k][r, red.outputs]
    span, pieces, nodes, table, sizes = None, (), [], [], (0, 0, 0)
    if red.response is not None:
        span = red.span
        K1 = forced_order(m)
        sizes = (K1 // 2 + 1, max((K1 - 2) // 2 + 1, 0), K1)
        out = []
        for fit in forcing_pieces(m, span[0], span[1], red.outputs, FORCING_SPLITS):
            count = len(fit.nodes) if fit.verified else 0
            out.append(ForcingPiece(float(fit.lo), float(fit.hi), len(nodes), count,
                                    float(fit.error), bool(fit.verified)))
            if fit.verified:
                nodes += [float(x) for x in fit.nodes]
                table += [tuple(_pair(z) for z in row) for row in fit.values]
        pieces = tuple(out)
    doc = (f"The reduced model of the spectral submanifold of mode {m.mode} of {red.text}, "
           f"order {K}.")
    if pieces:
        doc += "\n\n" + _forcing_note(pieces, span)
    return ReducedModule(
        name, doc, provenance(name, K, command, system=red.text, mode=m.mode,
                              outputs=list(red.names), span=span,
                              forcing=[list(p) for p in pieces]),
        m.mode, K, red.names, tuple(_pair(g) for g in m.gamma),
        float(m.radius), tuple(tuple(tuple(_pair(z) for z in row) for row in order)
                               for order in shape), span, pieces, tuple(nodes),
        tuple(table), sizes, INTERPOLATED)


def _forcing_note(pieces: tuple[ForcingPiece, ...], span: tuple[float, float]) -> str:
    """What the module's docstring says of its forced terms: nodes, the error reached, where
    frc is NaN because the tolerance was not."""
    good = [p for p in pieces if p.verified]
    bad = [p for p in pieces if not p.verified]
    lines = []
    if good:
        lines.append(
            f"The forced terms (A_j, B_j, the outputs' W1) are interpolated on Chebyshev nodes "
            f"over w in [{span[0]!r}, {span[1]!r}]"
            + ("" if len(pieces) == 1 else f" in {len(pieces)} pieces")
            + f" ({', '.join(str(p.count) for p in good)} nodes), each piece checked against the "
            f"exact terms at its midpoints: the largest interpolation error is "
            f"{max(p.error for p in good):.2e} (relative to the largest term; "
            f"INTERPOLATION_ERROR), within the tolerance {INTERPOLATED:g}.")
    for p in bad:
        lines.append(f"On [{p.lo!r}, {p.hi!r}] the tolerance {INTERPOLATED:g} was not reached "
                     f"with {CHEBYSHEV_MOST} nodes (error {p.error:.2e}): frc is NaN there "
                     "(UNVERIFIED).")
    return "\n".join(textwrap.fill(line, 90) for line in lines)
