"""The forced response from a spectral submanifold: the non-autonomous SSM at first order in
the drive ``F cos Ωt`` and to every order in the normal-form coordinates, its steady states
(every branch, isolas included), their stability, the folds and the peaks; what ``ssm``
reports (:class:`Reduction`).

**First order in the drive.**  ``x = W(p) + ε Σ_m W¹_m p^m e^{iΩt} + c.c.``, and the reduced
dynamics ``p₁' = p₁ g(p₁p₂) + ε e^{iΩt} A(p₁p₂) + ε e^{−iΩt} p₁² B(p₁p₂)``: the terms of
``p^m e^{iΩt}`` resonant with the mode are ``m = (j, j)`` (``s = m·λ + iΩ ≈ λ``: ``A_j``) and,
for ``p₂``, ``m = (j, j + 2)`` (``s ≈ λ̄``: the conjugate of ``B_j``).  Order ``k`` of ``W¹``
solves, row by row (``s = (k − r)λ + rλ̄ + iΩ``),

    L(s) W¹_m + ((s + λ)M + C)φ A δ + ((s + λ̄)M + C)φ̄ B̄ δ'
        = F/2 δ_(k=0) − (Df·W¹)_m − (sM + C)(Q_m + P_m) − M(Q'_m + P'_m),

``Df·W¹`` the force linearised about the autonomous SSM (from orders below ``k``), ``Q`` the
autonomous ``g``'s terms acting on ``W¹`` (as in :mod:`analysis.ssm`), ``P`` the autonomous
``W``'s derivative acting on the lower ``A_j``, ``B_j``; the resonant rows bordered by the
first-order form's normalisation (``ψᵀB·(W¹, V¹) = 0``, with ``ψ̄`` on the ``B`` rows).  At
order 0 alone it is the leading-order term; every order of ``p`` counts where the response
moves the peak: the drive's projection changes along the backbone (a Duffing oscillator
driven 8 % off its linear frequency: 3 % in the peak amplitude).

**Steady states.**  With ``q = p₁e^{−iΩt} = ρe^{iψ}``: ``ρ(iΩ − g)e^{iψ} = A + ρ²B e^{2iψ}``;
the equation and its conjugate (``e^{−iψ} = 1/z``) share a root ``z`` exactly where the
resultant ``(u²|B|² − |A|²)² − u|uB(iΩ + ḡ) + Ā(iΩ − g)|²`` vanishes (``u = ρ²``; a real
polynomial in ``u``), and the common root is kept where ``|z| = 1``.  Stability: the real
Jacobian of ``q' = q(g − iΩ) + A + Bq²``, trace ``2 Re F_q`` and determinant
``|F_q|² − |F_q̄|²``.  ``A``, ``B`` and the outputs' ``W¹`` are smooth in Ω: they are computed
on Chebyshev nodes over the range, checked at the midpoints, and interpolated."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..derive.system import System
from ..errors import InputError
from .ssm import (
    BORDERED,
    DENSE_SOLVES,
    SSM,
    _bordered,
    _carried,
    _damping,
    _Force,
    _pencil,
    _Product,
    _solve,
    leading,
    peak_amplitude,
    ssm,
)

CHEBYSHEV_NODES = 8
CHEBYSHEV_MOST = 128
INTERPOLATED = 1e-8
# NOTE: A(Ω), B(Ω) and the outputs' W¹(Ω) are rational in Ω, their poles off the real axis by
# the damping (a combination 2ω₁ + Ω = ω₃ inside the range is one: a chain of 1 000 masses
# needs 128 nodes): a degree is accepted where the interpolant meets the exact values at every
# midpoint to this fraction of their largest, else doubled, and past the last every Ω is
# computed (the emitted module, which cannot compute them, fits each half instead:
# lower.ssm).
ON_CIRCLE = 1e-6
# NOTE: a common root z of the steady-state equation and its conjugate is a steady state where
# | |z| − 1 | is below this (the others come in pairs z, 1/z̄ off the circle).
FOLD_STEPS = 50
FIXED_POINT = 8
PEAK_BRACKET = 0.05
PEAK_PROBES = 100
PEAK_GRID = 17
PEAK_ZOOMS = 9
TOP_HALVINGS = 4
# NOTE: a fold is placed by 50 bisections between two frequencies of the grid; a peak along
# the curve in ρ within 5 % below its top by 9 zooms of 17 points each (each keeps the two
# cells about the best: 8⁻⁹ = 7e-9 of the bracket, golden section's 0.618³⁹, every output's
# and branch's points tried together), Ω on the curve by 8 fixed-point steps (A and B vary
# slowly with Ω); the top itself by 60 halvings of its bracket, 4 at a time (15 points tried
# together).


@dataclass(frozen=True)
class Forced:
    """The non-autonomous SSM at one Ω: ``A_j``, ``B_j`` and the outputs' ``W¹`` (order ``k``:
    a ``(k + 1) × outputs`` array, row ``r`` the monomial ``p₁^{k−r}p₂^r e^{iΩt}``)."""

    omega: float
    A: np.ndarray
    B: np.ndarray
    X: tuple[np.ndarray, ...]


def forced_order(model: SSM) -> int:
    """The order in p of the non-autonomous part: one below the SSM's (its terms enter the
    amplitude at ``ε ρ^k``, beside the autonomous ``ρ^{k+1}``)."""
    return max(model.order - 1, 0)


BATCH_VALUES = 1 << 22
# NOTE: the forced terms of several Ω are computed together (one recursion, every product
# and dense solve batched over Ω) while what the recursion keeps of them — the states and
# every cached product of the force's chains, order by order — holds at most this many
# complex numbers (64 MB): a large model's Ω go one at a time, as its memory was.


def forced_values(model: SSM, omegas: np.ndarray, outputs: np.ndarray) -> np.ndarray:
    """The first-order non-autonomous SSM at each Ω of ``omegas`` to :func:`forced_order`, a
    row per Ω: ``A_j``, ``B_j``, then the outputs' ``W¹`` order by order (row-major, as
    :class:`Forced` holds them); one recursion over the orders for a batch of Ω
    (:data:`BATCH_VALUES`)."""
    w = model.matrices
    if w.drive is None:
        raise InputError("the system is not driven: no forced response (drive one equation "
                         "with f*cos(w*t), or give drive.txt)")
    omegas = np.asarray(omegas, dtype=float)
    size = max(1, BATCH_VALUES // _kept(model))
    parts = [_forced_batch(model, omegas[at:at + size], outputs)
             for at in range(0, len(omegas), size)]
    return np.concatenate(parts) if parts else np.zeros((0, 0), dtype=complex)


def _kept(model: SSM) -> int:
    """The complex numbers the recursion of :func:`_forced_batch` keeps per Ω: ``W¹``,
    ``V¹`` and their states (``4n`` a monomial) and each chain's products (a term of degree
    ``d`` has ``d`` chains of ``d − 1`` products, a column each), over every order's
    monomials; a dense solve's matrix."""
    w = model.matrices
    K1 = forced_order(model)
    degrees = (w.force.factors >= 0).sum(axis=1)
    columns = int(np.sum(degrees * (degrees - 1)))
    dense = w.size * w.size if w.size <= DENSE_SOLVES else 0
    return (K1 + 1) * (K1 + 2) // 2 * (4 * w.size + columns) + dense


def _forced_batch(model: SSM, omegas: np.ndarray, outputs: np.ndarray) -> np.ndarray:
    """The recursion of :func:`forced_values` for one batch of Ω: ``W¹_k``, ``V¹_k`` as
    ``(k + 1, batch, n)``; a small system's solves stacked (LAPACK, the resonant rows'
    bordered matrix whole), a large one's sparse, Ω by Ω."""
    w = model.matrices
    n, K1, nb = w.size, forced_order(model), len(omegas)
    lin = model.linear
    lam, phi, left = lin.lam, lin.shape, lin.left
    lamc, phic, leftc = np.conj(lam), np.conj(phi), np.conj(left)
    M, C = w.mass, _damping(w)
    dense = n <= DENSE_SOLVES  # products with small sparse matrices cost more than dense ones
    mats = (M.toarray(), C.toarray(), w.stiffness.toarray()) if dense else None
    if dense:
        M, C, Kd = mats
    W0, V0, gamma = model.W, model.V, list(model.gamma)
    W1: list[np.ndarray] = []
    V1: list[np.ndarray] = []
    states1: list[np.ndarray] = []
    linear = _Force(w, [np.hstack([a, b]) for a, b in zip(W0, V0, strict=True)], states1,
                    _Product, lambda k: (k + 1) * nb)
    A: list[np.ndarray] = []
    B: list[np.ndarray] = []
    for k in range(K1 + 1):
        Df = linear.coeff(k).reshape(k + 1, nb, n)
        QW = _carried([X.reshape(len(X), -1) for X in W1], gamma, k, nb * n).reshape(
            k + 1, nb, n)
        QV = _carried([X.reshape(len(X), -1) for X in V1], gamma, k, nb * n).reshape(
            k + 1, nb, n)
        QW += _lifted(W0, A, B, k, n, nb)
        QV += _lifted(V0, A, B, k, n, nb)
        Wk = np.zeros((k + 1, nb, n), dtype=complex)
        Vk = np.zeros((k + 1, nb, n), dtype=complex)
        for r in range(k + 1):
            s = (k - r) * lam + r * lamc + 1j * omegas
            cw, cv = QW[r], QV[r]
            rhs = -Df[r] - s[:, None] * (M @ cw.T).T - (C @ cw.T).T - (M @ cv.T).T
            if k == 0:
                rhs = rhs + w.drive / 2
            if k - r == r:  # m = (j, j): resonant with λ, A_j
                Wm, a = _resonant_row(w, dense, mats, s, lam, phi,
                                      left, rhs, cw, (k, r, model.mode))
                A.append(a)
                Vk[r] = s[:, None] * Wm + cw + a[:, None] * phi
            elif r - (k - r) == 2:  # m = (j, j + 2): resonant with λ̄, the conjugate of B_j
                Wm, b = _resonant_row(w, dense, mats, s, lamc, phic,
                                      leftc, rhs, cw, (k, r, model.mode))
                B.append(np.conj(b))
                Vk[r] = s[:, None] * Wm + cw + b[:, None] * phic
            else:
                if dense:
                    Wm = _stacked(M, C, Kd, s, rhs, (k, r, model.mode))
                else:
                    Wm = np.array([_solve(_pencil(w, z), x, (k, r, model.mode))
                                   for z, x in zip(s, rhs, strict=True)])
                Vk[r] = s[:, None] * Wm + cw
            Wk[r] = Wm
        W1.append(Wk)
        V1.append(Vk)
        states1.append(np.concatenate([Wk, Vk], axis=2).reshape((k + 1) * nb, 2 * n))
    parts = [np.array(A, dtype=complex).reshape(-1, nb).T,
             np.array(B, dtype=complex).reshape(-1, nb).T]
    parts += [np.transpose(X[:, :, outputs], (1, 0, 2)).reshape(nb, -1) for X in W1]
    return np.concatenate(parts, axis=1)


def _stacked(M: np.ndarray, C: np.ndarray, K: np.ndarray, s: np.ndarray, rhs: np.ndarray,
             where: tuple) -> np.ndarray:
    """``L(s_b)⁻¹ rhs_b`` for each Ω of a batch (dense, stacked LAPACK); refused where
    singular, as :func:`analysis.ssm._solve`."""
    z = s[:, None, None]
    try:
        x = np.linalg.solve(z * z * M + z * C + K, rhs[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:
        x = np.full(rhs.shape, np.nan)
    if not np.all(np.isfinite(x)):
        _refused(where)
    return x


def _refused(where: tuple) -> None:
    """Raise :func:`analysis.ssm._solve`'s refusal of a singular row (``where``: order, row,
    mode)."""
    _solve(np.zeros((1, 1)), np.array([np.nan]), where)


def _resonant_row(w, dense: bool, mats: tuple | None, s: np.ndarray, lam: complex,
                  phi: np.ndarray, left: np.ndarray, rhs: np.ndarray, carried: np.ndarray,
                  where: tuple) -> tuple[np.ndarray, np.ndarray]:
    """A row resonant with ``λ`` (or ``λ̄``: the conjugate data) for each Ω of a batch:
    ``L(s)W + ((s + λ)M + C)φσ = rhs``, ``wᵀ(C + (λ + s)M)W + (wᵀMφ)σ = −wᵀM·carried``
    (the first-order form's normalisation); ``(W, σ)``."""
    if dense:
        M, C, K = mats
        n, nb = len(phi), len(s)
        z = s[:, None, None]
        J = np.zeros((nb, n + 1, n + 1), dtype=complex)
        J[:, :n, :n] = z * z * M + z * C + K
        J[:, :n, n] = (s[:, None] + lam) * (M @ phi) + C @ phi
        J[:, n, :n] = left @ C + (lam + s)[:, None] * (left @ M)
        J[:, n, n] = left @ (M @ phi)
        e = -(carried @ M.T) @ left
        try:
            x = np.linalg.solve(J, np.concatenate([rhs, e[:, None]], axis=1)[:, :, None])
        except np.linalg.LinAlgError:
            x = np.full((nb, n + 1, 1), np.nan)
        if not np.all(np.isfinite(x)):
            _refused(where)
        return x[:, :n, 0], x[:, n, 0]
    M, C = w.mass, _damping(w)
    Ws, sigmas = [], []
    for z, x, cw in zip(s, rhs, carried, strict=True):
        Wm, sigma = _bordered(_pencil(w, z), ((z + lam) * M + C) @ phi,
                              (C + (lam + z) * M).T @ left, left @ (M @ phi), x,
                              -left @ (M @ cw), abs(z - lam) <= BORDERED * abs(lam), where)
        Ws.append(Wm)
        sigmas.append(sigma)
    return np.array(Ws), np.array(sigmas, dtype=complex)


def _lifted(Z0: tuple[np.ndarray, ...], A: list[np.ndarray], B: list[np.ndarray], k: int,
            n: int, nb: int) -> np.ndarray:
    """``P`` at order ``k`` (``(k + 1, batch, n)``): the autonomous ``∂Z/∂p₁·A_j|p|^{2j}`` and
    ``∂Z/∂p₂·B̄_j p₂²…`` terms of order ``k`` from ``Z``'s orders ≥ 2 (the order-1 ones are the
    unknowns), ``A_j``, ``B_j`` one per Ω."""
    out = np.zeros((k + 1, nb, n), dtype=complex)
    for j, a in enumerate(A):  # q + (j − 1, j): row r_q + j, factor q₁
        q = k - 2 * j + 1
        if q >= 2 and q < len(Z0):
            rows = np.arange(q)  # q₁ = q − r ≥ 1
            out[j:j + q] += ((q - rows)[:, None] * a[None, :])[:, :, None] * Z0[q][:q, None]
    for j, b in enumerate(B):  # q + (j, j + 1): row r_q + j + 1, factor q₂, coefficient b̄
        q = k - 2 * j - 1
        if q >= 2 and q < len(Z0):
            rows = np.arange(q + 1)
            out[j + 1:j + q + 2] += (rows[:, None] * np.conj(b)[None, :])[:, :, None] \
                * Z0[q][:, None]
    return out


def _unflatten(model: SSM, omega: float, v: np.ndarray, m: int) -> Forced:
    K1 = forced_order(model)
    nA, nB = K1 // 2 + 1, max((K1 - 2) // 2 + 1, 0)
    X, at = [], nA + nB
    for k in range(K1 + 1):
        X.append(v[at:at + (k + 1) * m].reshape(k + 1, m))
        at += (k + 1) * m
    return Forced(omega, v[:nA], v[nA:nA + nB], tuple(X))


def _barycentric(nodes: np.ndarray, values: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Barycentric interpolation on Chebyshev points of the second kind (rows: nodes)."""
    weights = (-1.0) ** np.arange(len(nodes))
    weights[[0, -1]] *= 0.5
    diff = at[:, None] - nodes[None, :]
    exact = diff == 0
    diff[exact] = 1.0
    kernel = weights / diff
    out = (kernel @ values) / kernel.sum(axis=1)[:, None]
    hit = exact.any(axis=1)
    out[hit] = values[np.argmax(exact[hit], axis=1)]
    return out


def chebyshev(lo: float, hi: float, nodes: int) -> np.ndarray:
    """Chebyshev points of the second kind on ``[lo, hi]``."""
    return 0.5 * (lo + hi) + 0.5 * (hi - lo) * np.cos(np.pi * np.arange(nodes + 1) / nodes)


@dataclass(frozen=True)
class ForcingFit:
    """The forced terms (:func:`forced_values`' rows) on ``N + 1`` Chebyshev nodes over
    ``[lo, hi]``, and how well they interpolate: ``error``, the barycentric interpolant's
    largest discrepancy at the ``N`` midpoints from the exact values there, over the largest
    of those; ``verified`` where it is within :data:`INTERPOLATED`."""

    lo: float
    hi: float
    nodes: np.ndarray
    values: np.ndarray
    error: float
    verified: bool

    def __call__(self, at: np.ndarray) -> np.ndarray:
        """The interpolated rows at ``at`` (inside ``[lo, hi]``)."""
        return _barycentric(self.nodes, self.values, np.asarray(at, dtype=float))


def forcing_fit(model: SSM, lo: float, hi: float, outputs: np.ndarray,
                most: int | None = None) -> ForcingFit:
    """The forced terms on Chebyshev nodes over ``[lo, hi]``: ``N`` nodes
    (:data:`CHEBYSHEV_NODES` first) checked at the ``N`` midpoints, which are the new nodes of
    ``2N`` (no value is computed twice), doubled while the check fails, up to ``most``
    (:data:`CHEBYSHEV_MOST`); the last degree checked, verified or not."""
    most = CHEBYSHEV_MOST if most is None else most
    nodes = CHEBYSHEV_NODES
    at = chebyshev(lo, hi, nodes)
    values = forced_values(model, at, outputs)
    while True:
        mid = 0.5 * (lo + hi) + 0.5 * (hi - lo) * np.cos(np.pi * (np.arange(nodes) + 0.5) / nodes)
        check = forced_values(model, mid, outputs)
        scale = float(np.max(np.abs(check)))
        miss = float(np.max(np.abs(_barycentric(at, values, mid) - check)))
        error = miss / scale if scale > 0 else 0.0
        if error <= INTERPOLATED or 2 * nodes > most:
            return ForcingFit(lo, hi, at, values, error, error <= INTERPOLATED)
        merged = np.empty((2 * nodes + 1, values.shape[1]), dtype=complex)
        merged[0::2], merged[1::2] = values, check
        at, values, nodes = chebyshev(lo, hi, 2 * nodes), merged, 2 * nodes


def forcing_pieces(model: SSM, lo: float, hi: float, outputs: np.ndarray,
                   splits: int = 0) -> list[ForcingFit]:
    """:func:`forcing_fit` over ``[lo, hi]``; where it is not verified, over each half, ``splits``
    times at most (each unverified piece is reported as such: its values are not to be
    used)."""
    fit = forcing_fit(model, lo, hi, outputs)
    if fit.verified or splits <= 0:
        return [fit]
    middle = 0.5 * (lo + hi)
    return (forcing_pieces(model, lo, middle, outputs, splits - 1)
            + forcing_pieces(model, middle, hi, outputs, splits - 1))


def forcing_table(model: SSM, omegas: np.ndarray, outputs: np.ndarray) -> list[Forced]:
    """The forced terms at every ``Ω`` of ``omegas`` (:func:`forcing_rows`), one
    :class:`Forced` each."""
    return [_unflatten(model, float(om), v, len(outputs))
            for om, v in zip(omegas, forcing_rows(model, omegas, outputs), strict=True)]


def forcing_rows(model: SSM, omegas: np.ndarray, outputs: np.ndarray) -> np.ndarray:
    """The forced terms at every ``Ω`` of ``omegas`` as :func:`forced_values`' rows:
    interpolated by :func:`forcing_fit` over their range where it verifies with fewer values
    than the grid holds (``2N + 1`` for ``N`` nodes), else computed at each ``Ω``."""
    omegas = np.asarray(omegas, dtype=float)
    lo, hi = float(omegas.min()), float(omegas.max())
    most = CHEBYSHEV_NODES
    while 2 * most <= CHEBYSHEV_MOST and 4 * most + 1 < len(omegas):
        most *= 2
    fit = None
    if hi > lo and len(omegas) > 2 * CHEBYSHEV_NODES + 1:
        fit = forcing_fit(model, lo, hi, outputs, most)
    return fit(omegas) if fit is not None and fit.verified else forced_values(model, omegas,
                                                                              outputs)


def _poly(c: np.ndarray) -> np.ndarray:
    """Coefficient rows, at least one column (a missing polynomial is 0)."""
    c = np.asarray(c, dtype=complex)
    return c if c.shape[-1] else np.zeros((*c.shape[:-1], 1), dtype=complex)


def _horner(c: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``Σ_j c[..., j] x^j`` by Horner (as ``numpy.polynomial.polynomial.polyval``), row by row:
    ``c`` ``(N, d)``, ``x`` ``(N,)`` or ``(N, R)``."""
    x = np.asarray(x)
    col = (slice(None),) + (None,) * (x.ndim - 1)
    acc = c[:, -1][col] + 0 * x
    for j in range(c.shape[1] - 2, -1, -1):
        acc = acc * x + c[:, j][col]
    return acc


def _derivative(c: np.ndarray) -> np.ndarray:
    """The rows' derivative polynomials (a constant's: 0)."""
    if c.shape[1] < 2:
        return np.zeros_like(c)
    return c[:, 1:] * np.arange(1, c.shape[1])


def _times(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-by-row polynomial products (``(N, p)`` and ``(N, q)``, or one row broadcast)."""
    out = np.zeros((max(len(a), len(b)), a.shape[1] + b.shape[1] - 1),
                   dtype=np.result_type(a, b))
    for j in range(a.shape[1]):
        out[:, j:j + b.shape[1]] += a[:, j:j + 1] * b
    return out


def _plus(a: np.ndarray, b: np.ndarray, shift: int = 0) -> np.ndarray:
    """``a + u^shift·b``, row by row."""
    out = np.zeros((max(len(a), len(b)), max(a.shape[1], b.shape[1] + shift)),
                   dtype=np.result_type(a, b))
    out[:, :a.shape[1]] += a
    out[:, shift:shift + b.shape[1]] += b
    return out


def _roots(res: np.ndarray) -> np.ndarray:
    """Each row's polynomial's roots (``numpy.polynomial.polynomial.polyroots``: the reversed
    companion matrix's eigenvalues, trailing zero coefficients dropped), NaN-padded."""
    N, D = res.shape
    nonzero = res != 0
    top = np.where(nonzero.any(axis=1), D - 1 - np.argmax(nonzero[:, ::-1], axis=1), 0)
    out = np.full((N, max(D - 1, 1)), np.nan, dtype=complex)
    for n in np.unique(top):
        rows = np.flatnonzero(top == n)
        if n == 1:
            out[rows, 0] = -res[rows, 0] / res[rows, 1]
        elif n >= 2:
            mat = np.zeros((len(rows), n, n))
            mat.reshape(len(rows), -1)[:, n::n + 1] = 1
            mat[:, :, -1] -= res[rows, :n] / res[rows, n:n + 1]
            out[rows, :n] = np.linalg.eigvals(mat[:, ::-1, ::-1])
    return out


def _steady_states(model: SSM, omegas: np.ndarray, A: np.ndarray, B: np.ndarray
                   ) -> list[list[tuple[float, float]]]:
    """Every steady state ``(ρ, ψ)`` at each Ω (``A``, ``B``: the forced terms' coefficient
    rows there): the resultant's real positive roots ``u = ρ²`` whose common root
    ``z = e^{iψ}`` lies on the unit circle, ascending in ρ."""
    g = np.array(model.gamma, dtype=complex)[None, :]
    A, B = _poly(A), _poly(B)
    iw = (1j * np.asarray(omegas, dtype=float))[:, None]
    inner = _plus(_times(np.conj(A), _plus(iw, -g)), _times(B, _plus(iw, np.conj(g))), 1)
    first = _plus(-_times(A, np.conj(A)), _times(B, np.conj(B)), 2)
    res = np.real(_plus(_times(first, first), -_times(inner, np.conj(inner)), 1))
    u = _roots(res)
    with np.errstate(invalid="ignore"):
        real = (np.abs(u.imag) <= 1e-9 * np.maximum(np.abs(u), 1e-300)) & (u.real > 0)
    x = np.where(real, u.real, 0.0)
    rho = np.sqrt(x)
    gs = np.broadcast_to(g, (len(iw), g.shape[1]))
    Au, Bu, gu = _horner(A, x), _horner(B, x), _horner(gs, x)
    a1, b1, c1 = rho * rho * Bu, -rho * (iw - gu), Au
    a2, b2, c2 = np.conj(Au), rho * (iw + np.conj(gu)), rho * rho * np.conj(Bu)
    den = a2 * b1 - a1 * b2
    with np.errstate(invalid="ignore", divide="ignore"):
        z = (a1 * c2 - a2 * c1) / np.where(den == 0, 1, den)
        keep = real & (den != 0) & (np.abs(np.abs(z) - 1) <= ON_CIRCLE)
    psi = np.angle(z)
    return [sorted((float(rho[i, j]), float(psi[i, j])) for j in np.flatnonzero(keep[i]))
            for i in range(len(iw))]


def _steady_rhos(model: SSM, f: Forced) -> list[tuple[float, float]]:
    """:func:`_steady_states` at one Ω."""
    return _steady_states(model, np.array([f.omega]), f.A[None, :], f.B[None, :])[0]


def _stable(model: SSM, omegas: np.ndarray, A: np.ndarray, B: np.ndarray, rho: np.ndarray,
            psi: np.ndarray) -> np.ndarray:
    """Each steady state's stability (its Ω, forced terms' rows, ρ and ψ): trace and
    determinant of the real Jacobian of ``q' = q(g(|q|²) − iΩ) + A(|q|²) + B(|q|²)q²``."""
    u, q = rho * rho, rho * np.exp(1j * psi)
    g = np.broadcast_to(np.array(model.gamma, dtype=complex), (len(u), len(model.gamma)))
    A, B = _poly(A), _poly(B)
    gu, dg = _horner(g, u), _horner(_derivative(g), u)
    dA, Bu, dB = _horner(_derivative(A), u), _horner(B, u), _horner(_derivative(B), u)
    Fq = gu - 1j * omegas + u * dg + np.conj(q) * dA + np.conj(q) * q * q * dB + 2 * q * Bu
    Fqc = q * q * dg + q * dA + q**3 * dB
    return (2 * Fq.real < 0) & (np.abs(Fq) ** 2 - np.abs(Fqc) ** 2 > 0)


def _amplitudes(model: SSM, X: tuple[np.ndarray, ...], outputs: np.ndarray, rho: np.ndarray,
                psi: np.ndarray, column: np.ndarray | None = None) -> np.ndarray:
    """Each output's max |x_i| over a period of the steady states (ρ, ψ), each with its own
    forced terms (``X[k]``: the outputs' ``W¹`` of order ``k``, ``(states, k + 1, outputs)``):
    the autonomous SSM at ρ with phase ψ and ``W¹`` (``(states, outputs)``; given ``column``,
    only that output's at each state, ``(states, 1)``)."""
    rho, psi = np.atleast_1d(rho), np.atleast_1d(psi)
    c = model.harmonics(rho, outputs, psi)
    K, K1 = model.order, len(X) - 1
    turns = np.exp(1j * np.outer(psi, np.arange(-K1, K1 + 1)))  # e^{inψ}, n = −K1 … K1
    for k, Xk in enumerate(X):
        n = k - 2 * np.arange(k + 1)  # row r: p₁^{k−r}p₂^r e^{iΩt}, harmonic n + 1
        term = (rho[:, None] ** k * turns[:, n + K1])[:, :, None] * Xk
        c[:, K + n + 1] += term  # distinct harmonics within an order
        c[:, K - n - 1] += np.conj(term)
    if column is not None:
        c = c[np.arange(len(rho)), :, column][:, :, None]
    return peak_amplitude(c)


@dataclass(frozen=True)
class SteadyState:
    """One steady state of the forced response: ``ρ``, its phase ``ψ`` to the drive, each
    output's ``max |x_i|`` over a period, stable or not."""

    omega: float
    rho: float
    psi: float
    amplitude: np.ndarray
    stable: bool


@dataclass(frozen=True)
class Peak:
    """An output's largest amplitude on the forced response: where (Ω, ρ), how large."""

    omega: float
    rho: float
    amplitude: float


@dataclass(frozen=True)
class ForcedResponse:
    """Every steady state at each Ω of the grid, the folds between (Ω and ρ where the number
    of steady states changes), the states dropped past the radius, each output's peak."""

    states: tuple[SteadyState, ...]
    folds: tuple[tuple[float, float], ...]
    beyond: int
    peaks: tuple[Peak | None, ...]


def forced_response(model: SSM, omegas: np.ndarray, outputs: np.ndarray) -> ForcedResponse:
    """Every steady state of the reduced model at each ``Ω`` (ascending) inside the radius,
    the folds (:data:`FOLD_STEPS` bisections on the number of states) and each output's peak
    (:func:`peaks`)."""
    omegas = np.asarray(omegas, dtype=float)
    if not omegas.size:
        return ForcedResponse((), (), 0, (None,) * len(outputs))
    grid = Grid.of(model, omegas, forcing_rows(model, omegas, outputs), len(outputs))
    found, counts, beyond = [], [], 0
    for i, here in enumerate(_steady_states(model, omegas, grid.A, grid.B)):
        counts.append(len(here))  # every root: a state crossing the radius is no fold
        beyond += sum(1 for r, _ in here if r > model.radius)
        found += [(i, r, p) for r, p in here if r <= model.radius]
    states: tuple[SteadyState, ...] = ()
    if found:
        at = np.array([i for i, _, _ in found])
        rho = np.array([r for _, r, _ in found])
        psi = np.array([p for _, _, p in found])
        amp = _amplitudes(model, tuple(X[at] for X in grid.X), outputs, rho, psi)
        stable = _stable(model, omegas[at], grid.A[at], grid.B[at], rho, psi)
        states = tuple(SteadyState(float(omegas[i]), r, p, amp[k], bool(stable[k]))
                       for k, (i, r, p) in enumerate(found))
    folds = tuple(fold for fold in (_fold(model, grid.forced(i - 1), grid.forced(i),
                                          counts[i - 1])
                                    for i in range(1, len(omegas))
                                    if counts[i] != counts[i - 1])
                  if math.isfinite(fold[1]) and fold[1] <= model.radius)
    peaks_ = peaks(model, outputs, grid, np.array([state.rho for state in states]))
    return ForcedResponse(states, folds, beyond, peaks_)


def _between(a: Forced, b: Forced, omega: float) -> Forced:
    """The forced terms at ``omega`` between two of the grid, linearly."""
    t = (omega - a.omega) / (b.omega - a.omega)
    return Forced(omega, (1 - t) * a.A + t * b.A, (1 - t) * a.B + t * b.B,
                  tuple((1 - t) * x + t * y for x, y in zip(a.X, b.X, strict=True)))


def _fold(model: SSM, a: Forced, b: Forced, count: int) -> tuple[float, float]:
    """Ω and ρ where the number of steady states changes between two frequencies (where
    two merge: ρ NaN where none is left to say)."""
    lo, hi, merged = a.omega, b.omega, [r for r, _ in _steady_rhos(model, a)]
    for _ in range(FOLD_STEPS):
        mid = 0.5 * (lo + hi)
        here = [r for r, _ in _steady_rhos(model, _between(a, b, mid))]
        if len(here) == count:
            lo, merged = mid, here
        else:
            hi = mid
    if len(merged) < 2:
        return 0.5 * (lo + hi), float(merged[0]) if merged else math.nan
    k = int(np.argmin(np.diff(merged)))
    return 0.5 * (lo + hi), float(0.5 * (merged[k] + merged[k + 1]))


def _on_curve(model: SSM, rho: np.ndarray, sign: np.ndarray, grid: Grid
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(Ω, ψ, found)`` on the forced response at each ρ, on its branch ``sign``: the real
    part of ``ρ(iΩ − g) = A e^{−iψ} + ρ²B e^{iψ}`` fixes ψ (two roots, ``sign`` picks one), its
    imaginary part Ω; A and B at Ω by fixed point (linearly between the grid's frequencies).
    Not found where ρ is past the curve's top or Ω leaves the grid."""
    rho = np.asarray(rho, dtype=float)
    sign = np.broadcast_to(np.asarray(sign, dtype=float), rho.shape)
    u = rho * rho
    g = _horner(np.broadcast_to(np.array(model.gamma, dtype=complex),
                                (len(u), len(model.gamma))), u)
    omegas = grid.omegas
    As, Bs = _poly(grid.A), _poly(grid.B)
    om = np.clip(g.imag, omegas[0], omegas[-1])
    found = np.ones(len(u), dtype=bool)
    psi = np.zeros(len(u))
    with np.errstate(invalid="ignore", divide="ignore"):
        for _ in range(FIXED_POINT):
            i = np.clip(np.searchsorted(omegas, om), 1, len(omegas) - 1)
            t = ((om - omegas[i - 1]) / (omegas[i] - omegas[i - 1]))[:, None]
            A = _horner((1 - t) * As[i - 1] + t * As[i], u)
            B = _horner((1 - t) * Bs[i - 1] + t * Bs[i], u)
            alpha, beta = A.real + u * B.real, A.imag - u * B.imag
            size = np.hypot(alpha, beta)
            found &= (size != 0) & ~(np.abs(rho * g.real) > size)
            psi = np.arctan2(beta, alpha) + sign * np.arccos(
                np.clip(-rho * g.real / np.where(found, size, 1.0), -1, 1))
            step = g.imag + (A * np.exp(-1j * psi) + u * B * np.exp(1j * psi)).imag / rho
            found &= (omegas[0] <= step) & (step <= omegas[-1])
            om = np.where(found, step, om)
    return om, psi, found


@dataclass(frozen=True)
class Grid:
    """The forced terms over the grid of Ω as arrays: ``A`` and ``B`` (a row per Ω) and the
    outputs' ``W¹`` of each order ``k`` (``(Ω, k + 1, outputs)``)."""

    omegas: np.ndarray
    A: np.ndarray
    B: np.ndarray
    X: tuple[np.ndarray, ...]

    @classmethod
    def of(cls, model: SSM, omegas: np.ndarray, rows: np.ndarray, m: int) -> Grid:
        """The grid of :func:`forced_values`' ``rows`` at ``omegas`` (``m`` outputs)."""
        K1 = forced_order(model)
        nA, nB = K1 // 2 + 1, max((K1 - 2) // 2 + 1, 0)
        X, at = [], nA + nB
        for k in range(K1 + 1):
            X.append(rows[:, at:at + (k + 1) * m].reshape(len(rows), k + 1, m))
            at += (k + 1) * m
        return cls(np.asarray(omegas, dtype=float), rows[:, :nA], rows[:, nA:nA + nB],
                   tuple(X))

    def forced(self, i: int) -> Forced:
        """The forced terms at the grid's ``i``-th Ω."""
        return Forced(float(self.omegas[i]), self.A[i], self.B[i], tuple(X[i] for X in self.X))

    def at(self, omega: np.ndarray) -> tuple[np.ndarray, ...]:
        """The outputs' ``W¹`` by order at each ``omega`` inside the grid, linearly between
        its neighbours (the grid is fine: 500 points by default)."""
        i = np.clip(np.searchsorted(self.omegas, omega), 1, len(self.omegas) - 1)
        t = (omega - self.omegas[i - 1]) / (self.omegas[i] - self.omegas[i - 1])
        return tuple((1 - t)[:, None, None] * X[i - 1] + t[:, None, None] * X[i]
                     for X in self.X)


def _amplitudes_on_curve(model: SSM, grid: Grid, outputs: np.ndarray, rho: np.ndarray,
                         sign: np.ndarray, column: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(Ω, max |x_column|)`` on the curve at each ρ of its branch ``sign``, each point its
    output ``column`` (−∞ where not found)."""
    om, psi, found = _on_curve(model, rho, sign, grid)
    amp = np.full(len(rho), -math.inf)
    if found.any():
        amp[found] = _amplitudes(model, grid.at(om[found]), outputs, rho[found], psi[found],
                                 column[found])[:, 0]
    return om, amp


RANGE_END = 1e-6
# NOTE: a curve whose largest ρ lies this close to an end of the range (relative to its
# width) leaves the range there still rising: the range holds no top.


def _held(model: SSM, rho: np.ndarray, grid: Grid) -> np.ndarray:
    """Whether the curve has a state at each ``ρ`` on either branch inside the grid's range
    (on a narrow range about the peak, one branch of a lower ρ lies outside it)."""
    return _on_curve(model, rho, 1.0, grid)[2] | _on_curve(model, rho, -1.0, grid)[2]


def peaks(model: SSM, outputs: np.ndarray, grid: Grid,
          seeds: np.ndarray | None = None) -> tuple[Peak | None, ...]:
    """Each output's largest amplitude on the forced response over the grid of ``grid``: the
    curve's top ρ* (the largest ρ with a steady state, probed geometrically and at the ρ of
    the states already found, ``seeds``, then 60 halvings; one for every output),
    then zooms on both branches within :data:`PEAK_BRACKET` below it (:data:`PEAK_GRID`
    points a zoom, every output's and branch's at once); ``None`` where the top lies past
    the radius or the grid."""
    m = len(outputs)
    hi = model.radius if math.isfinite(model.radius) else 1e6
    if len(grid.omegas) < 2:
        return (None,) * m
    seeds = np.empty(0) if seeds is None else np.asarray(seeds, dtype=float)
    probe = np.union1d(np.geomspace(hi * 1e-9, hi, PEAK_PROBES), seeds[seeds < hi])
    held = _held(model, probe, grid)
    if seeds.size:  # the states found are on the curve, and so is a probe between two of them
        seed = np.isin(probe, seeds)
        held |= seed
        held[1:-1] |= held[:-2] & held[2:] & (seed[:-2] | seed[2:])
    held = held.tolist()
    if not any(held):
        return (None,) * m
    first = held.index(True)
    if all(held[first:]):
        return (None,) * m  # the curve reaches the radius: its top is not inside
    # the top of the curve that grows from the small responses (a far branch of the truncated
    # series, past where it holds, is not the resonance's)
    end = first + held[first:].index(False)
    lo, hi = probe[end - 1], probe[end]
    split = 2**TOP_HALVINGS
    for _ in range((FOLD_STEPS + 10) // TOP_HALVINGS):  # 60 halvings, a few at a time
        inner = lo + (hi - lo) * np.arange(1, split) / split
        held = _held(model, inner, grid)
        k = int(np.argmin(held)) if not held.all() else split - 1
        lo, hi = (inner[k - 1] if k else lo), (inner[k] if k < split - 1 else hi)
    top = lo
    at_top, _, held = _on_curve(model, np.array([top, top]), np.array([1.0, -1.0]), grid)
    margin = np.minimum(at_top - grid.omegas[0], grid.omegas[-1] - at_top)
    if np.any(held & (margin <= RANGE_END * (grid.omegas[-1] - grid.omegas[0]))):
        return (None,) * m  # the curve leaves the range still rising: its top is not inside
    # one search per (output, branch): output i's on rows i (branch +1) and m + i (−1)
    column = np.tile(np.arange(m), 2)
    sign = np.repeat([1.0, -1.0], m)
    rows = np.arange(2 * m)
    cells = np.linspace(0.0, 1.0, PEAK_GRID)
    a, b = np.full(2 * m, top * (1 - PEAK_BRACKET)), np.full(2 * m, top)
    ends = []
    for _ in range(PEAK_ZOOMS):
        x = a[:, None] + (b - a)[:, None] * cells  # (searches, PEAK_GRID)
        om, value = _amplitudes_on_curve(model, grid, outputs, x.ravel(),
                                         np.repeat(sign, PEAK_GRID),
                                         np.repeat(column, PEAK_GRID))
        value = value.reshape(2 * m, PEAK_GRID)
        j = np.argmax(value, axis=1)
        ends.append((x[rows, j], om.reshape(2 * m, PEAK_GRID)[rows, j], value[rows, j]))
        a, b = x[rows, np.maximum(j - 1, 0)], x[rows, np.minimum(j + 1, PEAK_GRID - 1)]
    ends.append((np.full(2 * m, top),
                 *_amplitudes_on_curve(model, grid, outputs, np.full(2 * m, top), sign, column)))
    best: list[Peak | None] = [None] * m
    for k in rows:  # each output's branch +1 first, then −1
        i = column[k]
        for x, om, value in ends:
            if value[k] > -math.inf and (best[i] is None or value[k] > best[i].amplitude):
                best[i] = Peak(float(om[k]), float(x[k]), float(value[k]))
    return tuple(best)


BACKBONE_POINTS = 41
# NOTE: the backbone's samples in ρ, from 0 to its end (the JSON's; the table shows 11).
REACH = 0.9
# NOTE: the backbone ends at this fraction of the estimated radius (where no --rho-max says).
DEFAULT_SPAN = 0.2
# NOTE: a driven system's forced response without a range: ±20 % about the mode's |λ|.
NAMED_OUTPUTS = 12
# NOTE: up to this many coordinates every one is an output by default; a larger model's
# default output is the coordinate where the mode's shape is largest.


@dataclass(frozen=True)
class Reduction:
    """What ``ssm`` reports: the system's text (or folder), the SSM, the outputs (indices
    and names), the backbone (ρ, each output's ``max |x_i|``), and the forced response where
    the system is driven, over ``span``."""

    text: str
    model: SSM
    outputs: np.ndarray
    names: tuple[str, ...]
    rho: np.ndarray
    amplitude: np.ndarray
    response: ForcedResponse | None
    span: tuple[float, float] | None = None


def reduce(system: System, mode: int, order: int, outputs: list[int] | None = None,
           rho_max: float | None = None, span: tuple[float, float] | None = None,
           points: int = 500) -> Reduction:
    """The SSM of ``mode`` to ``order``; its backbone up to ``rho_max`` (default
    :data:`REACH` of the radius, or further to the largest forced state's ρ inside it); the
    forced response of a driven system at ``points`` frequencies over ``span`` (default
    :data:`DEFAULT_SPAN` about the mode's ``|λ|``)."""
    model = ssm(system, mode, order)
    if outputs is None:
        outputs = (list(range(system.size)) if system.size <= NAMED_OUTPUTS
                   else [leading(model.linear.shape)])
    outputs = np.array(outputs, dtype=np.int64)
    names = tuple(str(system.coordinates[i]) for i in outputs)
    response = None
    if system.matrices.drive is not None:
        span = (float(span[0]), float(span[1])) if span is not None else (
            (1 - DEFAULT_SPAN) * abs(model.lam), (1 + DEFAULT_SPAN) * abs(model.lam))
        response = forced_response(model, np.linspace(*span, points), outputs)
    elif span is not None:
        raise InputError("--omega: the system is not driven (drive one equation with "
                         "f*cos(w*t), or give drive.txt)")
    end = rho_max
    if end is None:
        end = REACH * model.radius if math.isfinite(model.radius) else 1.0
        if response is not None and response.states:
            end = max(end, min(model.radius, max(s.rho for s in response.states)))
    elif end > model.radius:
        raise InputError(f"--rho-max {rho_max:g}: beyond the SSM's estimated radius "
                         f"{model.radius:.6g} in rho ({model.radius_how})")
    rho = np.linspace(0.0, end, BACKBONE_POINTS)
    return Reduction(system.text, model, outputs, names, rho, model.amplitude(rho, outputs),
                     response, span)
