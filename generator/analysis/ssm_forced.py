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

from ..algebra.lazy import LazySeries
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
    _solve,
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
PEAK_STEPS = 32
FIXED_POINT = 8
PEAK_BRACKET = 0.05
PEAK_PROBES = 100
# NOTE: a fold is placed by 50 bisections between two frequencies of the grid; a peak by
# golden section (0.618³² of the bracket) along the curve in ρ within 5 % below its top, Ω on
# the curve by 8 fixed-point steps (A and B vary slowly with Ω).


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


def forced_terms(model: SSM, omega: float, outputs: np.ndarray) -> Forced:
    """The first-order non-autonomous SSM at ``Ω`` to :func:`forced_order` (sparse solves)."""
    return _unflatten(model, omega, forced_values(model, np.array([omega]), outputs)[0],
                      len(outputs))


BATCH_VALUES = 1 << 22
# NOTE: the forced terms of several Ω are computed together (one recursion, every product
# and dense solve batched over Ω) while their states hold at most this many complex numbers
# (64 MB); a large model's Ω go a few at a time.


def forced_values(model: SSM, omegas: np.ndarray, outputs: np.ndarray) -> np.ndarray:
    """:func:`forced_terms` at each Ω of ``omegas``, flattened as :func:`_flatten` (a row per
    Ω): one recursion over orders for a batch of Ω (:data:`BATCH_VALUES`)."""
    w = model.matrices
    if w.drive is None:
        raise InputError("the system is not driven: no forced response (drive one equation "
                         "with f*cos(w*t), or give drive.txt)")
    omegas = np.asarray(omegas, dtype=float)
    K1 = forced_order(model)
    per = 4 * w.size * (K1 + 1) * (K1 + 2) // 2
    size = max(1, BATCH_VALUES // per)
    parts = [_forced_batch(model, omegas[at:at + size], outputs)
             for at in range(0, len(omegas), size)]
    return np.concatenate(parts) if parts else np.zeros((0, 0), dtype=complex)


class _BatchedProduct(LazySeries):
    """:class:`analysis.ssm._Product` over a batch of Ω: a factor's order ``i`` holds
    ``(i + 1)·batch`` rows (monomial-major, one per Ω: the first-order states ``Z¹``) or
    ``i + 1`` (the autonomous ``Z``, the same at every Ω); the product is batched where either
    factor is."""

    def __init__(self, a: LazySeries, b: LazySeries, low_a: int, low_b: int) -> None:
        super().__init__()
        self.a, self.b, self.low_a, self.low_b = a, b, low_a, low_b

    def compute(self, k: int) -> np.ndarray | None:
        out = None
        for i in range(self.low_a, k - self.low_b + 1):
            A, B = self.a.coeff(i), self.b.coeff(k - i)
            A = A.reshape(i + 1, -1, A.shape[-1])  # (rows, batch or 1, terms)
            B = B.reshape(k - i + 1, -1, B.shape[-1])
            if out is None:
                out = np.zeros((k + 1, max(A.shape[1], B.shape[1]), A.shape[2]),
                               dtype=complex)
            if A.shape[0] <= B.shape[0]:  # a loop over the shorter factor's rows
                for row in range(A.shape[0]):
                    out[row:row + B.shape[0]] += A[row] * B
            else:
                for row in range(B.shape[0]):
                    out[row:row + A.shape[0]] += B[row] * A
        return None if out is None else out.reshape(-1, out.shape[2])


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
                    _BatchedProduct, lambda k: (k + 1) * nb)
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


def _flatten(f: Forced) -> np.ndarray:
    return np.concatenate([f.A, f.B, *(X.ravel() for X in f.X)])


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
    """The forced terms at every ``Ω`` of ``omegas``: interpolated by :func:`forcing_fit` over
    their range where it verifies with fewer values than the grid holds (``2N + 1`` for ``N``
    nodes), else computed at each ``Ω``."""
    omegas = np.asarray(omegas, dtype=float)
    lo, hi = float(omegas.min()), float(omegas.max())
    most = CHEBYSHEV_NODES
    while 2 * most <= CHEBYSHEV_MOST and 4 * most + 1 < len(omegas):
        most *= 2
    fit = None
    if hi > lo and len(omegas) > 2 * CHEBYSHEV_NODES + 1:
        fit = forcing_fit(model, lo, hi, outputs, most)
    rows = fit(omegas) if fit is not None and fit.verified else forced_values(model, omegas,
                                                                             outputs)
    return [_unflatten(model, float(om), v, len(outputs))
            for om, v in zip(omegas, rows, strict=True)]


def _poly(c: np.ndarray) -> np.ndarray:
    return np.asarray(c, dtype=complex) if len(c) else np.zeros(1, dtype=complex)


def _steady_rhos(model: SSM, f: Forced) -> list[tuple[float, float]]:
    """Every steady state ``(ρ, ψ)`` at ``f.omega``: the resultant's real positive roots
    ``u = ρ²`` whose common root ``z = e^{iψ}`` lies on the unit circle, ascending in ρ."""
    P = np.polynomial.polynomial
    g = np.array(model.gamma, dtype=complex)
    A, B = _poly(f.A), _poly(f.B)
    iw = 1j * f.omega
    inner = P.polyadd(P.polymul([0, 1], P.polymul(B, P.polyadd([iw], np.conj(g)))),
                      P.polymul(np.conj(A), P.polysub([iw], g)))
    first = P.polysub(P.polymul([0, 0, 1], P.polymul(B, np.conj(B))), P.polymul(A, np.conj(A)))
    res = P.polysub(P.polymul(first, first), P.polymul([0, 1], P.polymul(inner, np.conj(inner))))
    res = np.real(res)
    top = len(res) - 1
    while top > 0 and res[top] == 0:
        top -= 1
    if top == 0:
        return []
    out = []
    for u in P.polyroots(res[:top + 1]):
        if abs(u.imag) > 1e-9 * max(abs(u), 1e-300) or not u.real > 0:
            continue
        rho = math.sqrt(u.real)
        Au, Bu, gu = P.polyval(u.real, A), P.polyval(u.real, B), P.polyval(u.real, g)
        a1, b1, c1 = rho * rho * Bu, -rho * (iw - gu), Au
        a2, b2, c2 = np.conj(Au), rho * (iw + np.conj(gu)), rho * rho * np.conj(Bu)
        den = a2 * b1 - a1 * b2
        if den == 0:
            continue
        z = (a1 * c2 - a2 * c1) / den
        if abs(abs(z) - 1) <= ON_CIRCLE:
            out.append((rho, float(np.angle(z))))
    return sorted(out)


def _stable(model: SSM, f: Forced, rho: float, psi: float) -> bool:
    """The steady state's stability: trace and determinant of the real Jacobian of
    ``q' = q(g(|q|²) − iΩ) + A(|q|²) + B(|q|²)q²``."""
    P = np.polynomial.polynomial
    u, q = rho * rho, rho * np.exp(1j * psi)
    g = np.array(model.gamma, dtype=complex)
    A, B = _poly(f.A), _poly(f.B)
    gu, dg = P.polyval(u, g), P.polyval(u, P.polyder(g)) if len(g) > 1 else 0j
    dA = P.polyval(u, P.polyder(A)) if len(A) > 1 else 0j
    Bu = P.polyval(u, B)
    dB = P.polyval(u, P.polyder(B)) if len(B) > 1 else 0j
    Fq = gu - 1j * f.omega + u * dg + np.conj(q) * dA + np.conj(q) * q * q * dB + 2 * q * Bu
    Fqc = q * q * dg + q * dA + q**3 * dB
    return bool(2 * Fq.real < 0 and abs(Fq) ** 2 - abs(Fqc) ** 2 > 0)


def _amplitudes(model: SSM, forced: list[Forced], outputs: np.ndarray, rho: np.ndarray,
                psi: np.ndarray) -> np.ndarray:
    """Each output's max |x_i| over a period of the steady states (ρ, ψ), each with its own
    forced terms (``(states, outputs)``): the autonomous SSM at ρ with phase ψ and ``W¹``."""
    rho, psi = np.atleast_1d(rho), np.atleast_1d(psi)
    c = model.harmonics(rho, outputs, psi)
    K = model.order
    for k in range(len(forced[0].X)):
        X = np.stack([f.X[k] for f in forced])  # (states, k + 1, outputs)
        for r in range(k + 1):
            h = k - 2 * r + 1
            term = (rho**k * np.exp(1j * (k - 2 * r) * psi))[:, None] * X[:, r]
            c[:, K + h] += term
            c[:, K - h] += np.conj(term)
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
    (:func:`peak`)."""
    omegas = np.asarray(omegas, dtype=float)
    table = forcing_table(model, omegas, outputs)
    found, counts, beyond = [], [], 0
    for f in table:
        here = _steady_rhos(model, f)
        counts.append(len(here))  # every root: a state crossing the radius is no fold
        beyond += sum(1 for r, _ in here if r > model.radius)
        found += [(f, r, p) for r, p in here if r <= model.radius]
    states: tuple[SteadyState, ...] = ()
    if found:
        rho = np.array([r for _, r, _ in found])
        psi = np.array([p for _, _, p in found])
        amp = _amplitudes(model, [f for f, _, _ in found], outputs, rho, psi)
        states = tuple(SteadyState(f.omega, r, p, amp[i], _stable(model, f, r, p))
                       for i, (f, r, p) in enumerate(found))
    folds = tuple(fold for fold in (_fold(model, table[i - 1], table[i], counts[i - 1])
                                    for i in range(1, len(omegas))
                                    if counts[i] != counts[i - 1])
                  if math.isfinite(fold[1]) and fold[1] <= model.radius)
    grid = Grid.of(table)
    peaks = tuple(peak(model, outputs, i, grid) for i in range(len(outputs)))
    return ForcedResponse(states, folds, beyond, peaks)


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


def _on_curve(model: SSM, rho: float, sign: float, grid: Grid, outputs: np.ndarray,
              output: int, amplitude: bool = True) -> tuple[float, float] | None:
    """``(Ω, max |x_output|)`` on the forced response at ρ, on its branch ``sign``: the real
    part of ``ρ(iΩ − g) = A e^{−iψ} + ρ²B e^{iψ}`` fixes ψ (two roots, ``sign`` picks one), its
    imaginary part Ω; A and B at Ω by fixed point.  None where ρ is past the curve's top."""
    P = np.polynomial.polynomial
    u = rho * rho
    g = complex(P.polyval(u, np.array(model.gamma)))
    omegas, As, Bs = grid.omegas, grid.A, grid.B
    om = min(max(g.imag, omegas[0]), omegas[-1])
    for _ in range(FIXED_POINT):
        i = int(np.clip(np.searchsorted(omegas, om), 1, len(omegas) - 1))
        t = (om - omegas[i - 1]) / (omegas[i] - omegas[i - 1])
        A = P.polyval(u, _poly((1 - t) * As[i - 1] + t * As[i]))
        B = P.polyval(u, _poly((1 - t) * Bs[i - 1] + t * Bs[i]))
        alpha, beta = A.real + u * B.real, A.imag - u * B.imag
        size = math.hypot(alpha, beta)
        if size == 0 or abs(rho * g.real) > size:
            return None
        psi = math.atan2(beta, alpha) + sign * math.acos(-rho * g.real / size)
        om = g.imag + (A * np.exp(-1j * psi) + u * B * np.exp(1j * psi)).imag / rho
        if not omegas[0] <= om <= omegas[-1]:
            return None
    if not amplitude:
        return om, math.nan
    amp = _amplitudes(model, [grid.at(om)], outputs, np.array([rho]),
                      np.array([psi]))[0, output]
    return om, float(amp)


@dataclass(frozen=True)
class Grid:
    """The forced terms over the grid of Ω, with their Ω, A and B as arrays (the peak's
    search interpolates them many times)."""

    table: tuple[Forced, ...]
    omegas: np.ndarray
    A: np.ndarray
    B: np.ndarray

    @classmethod
    def of(cls, table: list[Forced]) -> Grid:
        return cls(tuple(table), np.array([f.omega for f in table]),
                   np.array([f.A for f in table]), np.array([f.B for f in table]))

    def at(self, omega: float) -> Forced:
        """The forced terms at ``omega`` inside the grid, linearly between its neighbours
        (the grid is fine: 500 points by default)."""
        i = int(np.clip(np.searchsorted(self.omegas, omega), 1, len(self.table) - 1))
        return _between(self.table[i - 1], self.table[i], omega)


def peak(model: SSM, outputs: np.ndarray, output: int, grid: Grid) -> Peak | None:
    """Output ``output``'s largest amplitude on the forced response over the grid of
    ``grid``: the curve's top ρ* (the largest ρ with a steady state, by bisection), then
    golden section along both branches within :data:`PEAK_BRACKET` below it; ``None`` where
    the top lies past the radius or the grid."""
    hi = model.radius if math.isfinite(model.radius) else 1e6
    lo = 0.0
    def exists(r: float) -> bool:
        return _on_curve(model, r, 1.0, grid, outputs, output, False) is not None

    probe = np.geomspace(hi * 1e-9, hi, PEAK_PROBES)
    held = [exists(r) for r in probe]
    if not any(held):
        return None
    first = held.index(True)
    if all(held[first:]):
        return None  # the curve reaches the radius: its top is not inside
    # the top of the curve that grows from the small responses (a far branch of the truncated
    # series, past where it holds, is not the resonance's)
    end = first + held[first:].index(False)
    lo, hi = probe[end - 1], probe[end]
    for _ in range(FOLD_STEPS + 10):
        mid = 0.5 * (lo + hi)
        if not exists(mid):
            hi = mid
        else:
            lo = mid
    top = lo
    best = None
    ratio = (math.sqrt(5) - 1) / 2
    for sign in (1.0, -1.0):
        def value(r: float, sign: float = sign) -> float:
            got = _on_curve(model, r, sign, grid, outputs, output)
            return -math.inf if got is None else got[1]

        a, b = top * (1 - PEAK_BRACKET), top
        x1, x2 = b - ratio * (b - a), a + ratio * (b - a)
        f1, f2 = value(x1), value(x2)
        for _ in range(PEAK_STEPS):
            if f1 > f2:
                b, x2, f2 = x2, x1, f1
                x1 = b - ratio * (b - a)
                f1 = value(x1)
            else:
                a, x1, f1 = x1, x2, f2
                x2 = a + ratio * (b - a)
                f2 = value(x2)
        for x in (x1, x2, top):
            got = _on_curve(model, x, sign, grid, outputs, output)
            if got is not None and (best is None or got[1] > best.amplitude):
                best = Peak(got[0], x, got[1])
    return best


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
                   else [int(np.argmax(np.abs(model.linear.shape)))])
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
