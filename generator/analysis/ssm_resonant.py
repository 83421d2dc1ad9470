"""The four-dimensional spectral submanifold of two modes in near 1:1, 1:2 or 1:3 internal
resonance of ``M x'' + C x' + K x + f(x, x') = 0``: the parametrisation method of
:mod:`analysis.ssm` carried to two master modes (Li, Jain & Haller, Nonlinear Dyn. 2022),
its reduced dynamics in normal form and their polar form.

**The manifold.**  ``x = W(p)``, ``x' = V(p)`` with ``p = (p₁, p̄₁, p₂, p̄₂)`` (directions
``i = 1 … 4``, eigenvalues ``Λ = (λ₁, λ̄₁, λ₂, λ̄₂)``, right eigenvectors
``Φ = (φ₁, φ̄₁, φ₂, φ̄₂)`` normalised as the 2-D SSM's), and the reduced dynamics
``p' = R(p)``, ``R_i = Λ_i p_i + Σ_m R_{i,m} p^m``.  Order ``k`` holds the multi-indices
``m = (m₁, m₂, m₃, m₄)``, ``|m| = k``, one row each (:class:`Monomials`).

**Order k.**  At the monomial ``m`` (``s = m·Λ``), as in :mod:`analysis.ssm` with one border
per resonant direction: ``V_m = s W_m + Σ_j Φ_j R_{j,m} + Q^W_m`` and

    L(s) W_m + Σ_j ((s + Λ_j)M + C) Φ_j R_{j,m} = −f_m − (sM + C) Q^W_m − M Q^V_m,
    w_iᵀ(C + (Λ_i + s)M) W_m + Σ_j (w_iᵀ M Φ_j) R_{j,m} = −w_iᵀ M Q^W_m   (i resonant),

``Q^W_m = Σ q_i W_q R_{i,n}`` over ``q − e_i + n = m`` (``|q|, |n| ≥ 2``).  The direction
``i`` is resonant with ``m`` where ``m·ν = ν_i`` for the exact ratio ``ν = (1, −1, r, −r)``
(``ω₂ ≈ r ω₁``): those monomials, near-resonant where the ratio is not exact, stay in the
reduced dynamics (normal form, no small divisor); every other ``R_{i,m}`` is zero.  Each row
is one sparse factorization of ``L(s)``, bordered by block elimination
(:func:`analysis.ssm._bordered`, with one or two borders: r = 1 makes ``m`` resonant with
``p₁`` and ``p₂`` at once); the rows of ``m̄ = (m₂, m₁, m₄, m₃)`` are the conjugates.

**Polar form.**  With ``p_k = ρ_k e^{iθ_k}``, every kept monomial of ``p₁'`` carries
``e^{iθ₁ + iq(θ₂ − rθ₁)}`` (``q = m₃ − m₄``) and of ``p₂'`` ``e^{iθ₂ + iq(θ₂ − rθ₁)}``
(``q = m₃ − m₄ − 1``), so ``ρ₁' + iρ₁θ₁' = e^{−iθ₁}R₁`` and ``ρ₂' + iρ₂θ₂' = e^{−iθ₂}R₂``
depend on ``ρ₁, ρ₂`` and the phase difference ``ψ = θ₂ − rθ₁`` alone.

**The slow flow's variables.**  Undamped, ``φ_k`` is real, and ``slowflow SYSTEM`` writes
``x = Σ a_k s_k cos(ω_k t + φ_k)`` with its exact shapes ``s_k``: with ``φ_k = (c_k/2) s_k``
(``c_k`` real), ``a_k = |c_k| ρ_k`` and ``θ_k = ω_k t + φ_k`` (``+ π`` where ``c_k < 0``).
The normal form at the force's lowest degree d is then the first-order averaged flow:
``da_k/dt = |c_k| ρ_k'`` and ``dφ_k/dt = θ_k' − ω_k`` (:func:`slow_flow_scale`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial

import numpy as np
import scipy.sparse as sparse

from ..algebra.lazy import LazySeries
from ..derive.system import Matrices, System
from ..errors import InputError
from .ssm import (
    BORDERED,
    DENSE_SOLVES,
    SINGULAR,
    LinearMode,
    NearResonance,
    _backward,
    _bordered,
    _damping,
    _divisors,
    _Force,
    _pencil,
    _radius,
    _solve,
    linear_mode,
)

RATIOS = (1, 2, 3)
DETUNING = 0.1
# NOTE: the largest relative detuning |ω₂/ω₁ − r|/r taken as a near 1:r resonance; past it
# the kept monomials' divisors are no longer small and each mode has its own 2-D SSM.
SAME_MODE = 1e-3
# NOTE: the other modes' list entry within this (relative) of λ₂ is λ₂ itself.
CONJUGATE = (1, 0, 3, 2)
# NOTE: the direction conjugate to each of (p₁, p̄₁, p₂, p̄₂).
INVARIANT = 1e-12
# NOTE: a coefficient below this fraction of |λ| counts as zero when asking whether a mode's
# plane (p₁ = 0 or p₂ = 0) is invariant: then that mode's backbone is a family of the SSM.


class Monomials:
    """The monomials ``p^m`` of four variables, orders 0 … K: per order the exponents
    (``N_k × 4``, lexicographically descending), their rows, each row's conjugate, and the
    products' tables (which row pairs of orders i and j add to which row of i + j)."""

    def __init__(self, order: int) -> None:
        self.exponents = [np.array([(a, b, c, k - a - b - c)
                                    for a in range(k, -1, -1) for b in range(k - a, -1, -1)
                                    for c in range(k - a - b, -1, -1)], dtype=int).reshape(-1, 4)
                          for k in range(order + 1)]
        self.index = [{tuple(int(x) for x in e): i for i, e in enumerate(E)}
                      for E in self.exponents]
        # NOTE: a monomial's code Σ e_i B^{3−i} (B = K + 1) falls as its row rises (the rows
        # are lexicographically descending): rows are found by bisection on the codes
        self.weights = (order + 1) ** np.arange(3, -1, -1)
        self._codes = [-(E @ self.weights) for E in self.exponents]
        self.conjugate = [self.locate(k, E[:, [1, 0, 3, 2]])
                          for k, E in enumerate(self.exponents)]
        self._tables: dict[tuple[int, int], tuple] = {}
        self._shifts: dict[tuple, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def rows(self, k: int) -> int:
        """The number of monomials of order ``k``, ``(k + 1)(k + 2)(k + 3)/6``."""
        return len(self.exponents[k])

    def locate(self, k: int, E: np.ndarray) -> np.ndarray:
        """The rows of order ``k`` of the exponents ``E`` (each of order k)."""
        return np.searchsorted(self._codes[k], -(E @ self.weights))

    def table(self, i: int, j: int) -> tuple[np.ndarray, np.ndarray, sparse.csr_array]:
        """``(ia, ib, S)``: ``(A·B)_k = S (A[ia] * B[ib])`` for coefficients of orders i, j."""
        if (i, j) not in self._tables:
            ia, ib = np.divmod(np.arange(self.rows(i) * self.rows(j)), self.rows(j))
            sums = self.exponents[i][ia] + self.exponents[j][ib]
            ic = self.locate(i + j, sums)
            S = sparse.csr_array((np.ones(len(ic)), (ic, np.arange(len(ic)))),
                                 shape=(self.rows(i + j), len(ic)))
            self._tables[(i, j)] = (ia, ib, S)
        return self._tables[(i, j)]

    def shift(self, q: int, i: int, n: tuple[int, ...]) -> tuple[np.ndarray, ...]:
        """``(rows of order q with q_i ≥ 1, q_i, their rows q − e_i + n)``: where
        ``∂_i(p^q)·p^n`` lands."""
        key = (q, i, n)
        if key not in self._shifts:
            E = self.exponents[q]
            src = np.flatnonzero(E[:, i] >= 1)
            target = E[src] + np.array(n) - np.eye(4, dtype=int)[i]
            dst = self.locate(q + sum(n) - 1, target)
            self._shifts[key] = (src, E[src, i].astype(float), dst)
        return self._shifts[key]


class _MonomialProduct(LazySeries):
    """``a · b`` of two series in the monomials of :class:`Monomials` (order k:
    ``N_k × T``), the Cauchy sum over orders, each a scatter by the product's table."""

    def __init__(self, basis: Monomials, a: LazySeries, b: LazySeries, low_a: int,
                 low_b: int) -> None:
        super().__init__()
        self.basis, self.a, self.b, self.low_a, self.low_b = basis, a, b, low_a, low_b

    def compute(self, k: int) -> np.ndarray:
        out = None
        for i in range(self.low_a, k - self.low_b + 1):
            A, B = self.a.coeff(i), self.b.coeff(k - i)
            ia, ib, S = self.basis.table(i, k - i)
            term = S @ (A[ia] * B[ib])
            out = term if out is None else out + term
        return out


@dataclass(frozen=True)
class Term:
    """One kept monomial of the reduced dynamics: ``p_k' ∋ coefficient · p^m`` (``mode``
    1 or 2, ``monomial`` the exponents of ``(p₁, p̄₁, p₂, p̄₂)``); in polar form it adds
    ``coefficient · ρ₁^{rho1} ρ₂^{rho2} e^{i·psi·ψ}`` to ``ρ_k' + iρ_kθ_k'``."""

    mode: int
    monomial: tuple[int, int, int, int]
    coefficient: complex
    rho1: int
    rho2: int
    psi: int


@dataclass(frozen=True)
class ResonantSSM:
    """The 4-D SSM of two modes to order ``order``: ``W[k]``, ``V[k]`` (``N_k × n``), the
    reduced dynamics' coefficients ``R[k]`` (``N_k × 4``, zero off the kept monomials), the
    ratio r (ω₂ ≈ r ω₁), each order's backward error, the near resonances of the monomials
    not kept, the radius in ``max |p_k|`` estimated from the terms."""

    matrices: Matrices = field(repr=False)
    modes: tuple[int, int]
    order: int
    ratio: int
    linear: tuple[LinearMode, LinearMode]
    basis: Monomials = field(repr=False)
    W: tuple[np.ndarray, ...] = field(repr=False)
    V: tuple[np.ndarray, ...] = field(repr=False)
    R: tuple[np.ndarray, ...] = field(repr=False)
    residual: tuple[float, ...]
    near: tuple[NearResonance, ...]
    radius: float
    radius_how: str

    @property
    def lam(self) -> tuple[complex, complex]:
        return self.linear[0].lam, self.linear[1].lam

    @property
    def detuning(self) -> float:
        """``ω₂/ω₁ − r`` of the damped frequencies."""
        l1, l2 = self.lam
        return l2.imag / l1.imag - self.ratio

    def terms(self, top: int | None = None) -> list[Term]:
        """The kept monomials of ``p₁'`` and ``p₂'`` of orders 2 … ``top`` (default: all)."""
        r = self.ratio
        out = []
        for k in range(2, (self.order if top is None else top) + 1):
            for row, e in enumerate(self.basis.exponents[k].tolist()):
                for mode, direction in ((1, 0), (2, 2)):
                    c = complex(self.R[k][row, direction])
                    if c != 0:
                        q = e[2] - e[3] - (mode == 2)
                        if mode == 1 and (e[0] - e[1] - 1) != -r * q:
                            raise AssertionError(f"{e}: not resonant with p1")
                        out.append(Term(mode, tuple(e), c, e[0] + e[1], e[2] + e[3], q))
        return out

    def field(self, p1: complex, p2: complex, top: int | None = None) -> tuple[complex, complex]:
        """``(p₁', p₂')`` of the reduced dynamics to order ``top`` (default: all)."""
        p = np.array([p1, np.conj(p1), p2, np.conj(p2)])
        l1, l2 = self.lam
        out = [l1 * p1, l2 * p2]
        for k in range(2, (self.order if top is None else top) + 1):
            powers = np.prod(p[None, :] ** self.basis.exponents[k], axis=1)
            out[0] += powers @ self.R[k][:, 0]
            out[1] += powers @ self.R[k][:, 2]
        return complex(out[0]), complex(out[1])

    def polar(self, rho1: float, rho2: float, psi: float, top: int | None = None
              ) -> tuple[float, float, float, float]:
        """``(ρ₁', ρ₂', θ₁', θ₂')`` at ``ρ₁, ρ₂ > 0`` and ``ψ = θ₂ − rθ₁``
        (``ψ' = θ₂' − rθ₁'``)."""
        d1, d2 = self.field(rho1, rho2 * np.exp(1j * psi), top)
        d2 = d2 * np.exp(-1j * psi)
        return d1.real, d2.real, d1.imag / rho1, d2.imag / rho2

    def state(self, p1: complex, p2: complex) -> tuple[np.ndarray, np.ndarray]:
        """``(x, x')`` on the manifold at ``(p₁, p₂)``: ``W(p)``, ``V(p)`` (real)."""
        p = np.array([p1, np.conj(p1), p2, np.conj(p2)])
        x = np.zeros(self.matrices.size, dtype=complex)
        v = np.zeros(self.matrices.size, dtype=complex)
        for k in range(1, self.order + 1):
            powers = np.prod(p[None, :] ** self.basis.exponents[k], axis=1)
            x += powers @ self.W[k]
            v += powers @ self.V[k]
        return x.real, v.real

    def backbone(self, mode: int) -> tuple[complex, ...] | None:
        """Mode ``mode``'s backbone where its plane (the other ``p = 0``) is invariant:
        ``γ_j`` of ``p_k' = p_k Σ_j γ_j (p_k p̄_k)^j``, the 2-D SSM's normal form; ``None``
        where the resonance drives the other mode from that plane (no such family)."""
        k0, other = (0, 2) if mode == 1 else (2, 0)
        scale = abs(self.lam[mode - 1])
        gamma = [self.lam[mode - 1]]
        for k in range(2, self.order + 1):
            E = self.basis.exponents[k]
            plane = (E[:, other] == 0) & (E[:, other + 1] == 0)
            if np.max(np.abs(self.R[k][plane][:, [other, other + 1]]), initial=0) > (
                    INVARIANT * scale):
                return None
            if k % 2:
                j = (k - 1) // 2
                e = [0, 0, 0, 0]
                e[k0], e[k0 + 1] = j + 1, j
                gamma.append(complex(self.R[k][self.basis.index[k][tuple(e)], k0]))
        return tuple(gamma)


def check_pair(w: Matrices, modes: tuple[int, ...]
               ) -> tuple[tuple[int, int], LinearMode, LinearMode, int]:
    """The two modes (ascending), their linear modes and the ratio r of a near 1:r
    resonance, or a one-line refusal."""
    if len(modes) != 2:
        raise InputError(f"--mode {','.join(str(m) for m in modes)}: give one mode, or two "
                         "in internal resonance (M1,M2); more are not built")
    m1, m2 = sorted(modes)
    if m1 == m2:
        raise InputError(f"--mode {m1},{m2}: the same mode twice")
    lin1, lin2 = linear_mode(w, m1), linear_mode(w, m2)
    quotient = lin2.lam.imag / lin1.lam.imag
    r = max(1, round(quotient))
    if r not in RATIOS or abs(quotient - r) > DETUNING * r:
        raise InputError(f"--mode {m1},{m2}: omega{m2}/omega{m1} = {quotient:.6g} is not near "
                         f"1:1, 1:2 or 1:3 (within {DETUNING:.0%}); each mode has its own "
                         "2-D SSM (--mode M)")
    if abs(lin2.lam - lin1.lam) < SINGULAR * abs(lin1.lam):
        raise InputError(f"--mode {m1},{m2}: the two modes share the eigenvalue "
                         f"{lin1.lam:.6g} (their shapes are not unique); separate them by a "
                         "small detuning")
    return (m1, m2), lin1, lin2, r


def resonant_ssm(system: System, modes: tuple[int, ...], order: int) -> ResonantSSM:
    """The 4-D SSM of ``modes`` (two, in near 1:1, 1:2 or 1:3 resonance) to ``order``."""
    w = system.matrices
    n = w.size
    (m1, m2), lin1, lin2, r = check_pair(w, modes)
    M, C = w.mass, _damping(w)
    lams = np.array([lin1.lam, np.conj(lin1.lam), lin2.lam, np.conj(lin2.lam)])
    phis = np.array([lin1.shape, np.conj(lin1.shape), lin2.shape, np.conj(lin2.shape)])
    lefts = np.array([lin1.left, np.conj(lin1.left), lin2.left, np.conj(lin2.left)])
    nu = np.array([1, -1, r, -r])
    basis = Monomials(order)
    W: list[np.ndarray] = [np.zeros((1, n), dtype=complex), phis.copy()]
    V: list[np.ndarray] = [np.zeros((1, n), dtype=complex), lams[:, None] * phis]
    R: list[np.ndarray] = [np.zeros((1, 4), dtype=complex), np.diag(lams)]
    states = [np.hstack([W[0], V[0]]), np.hstack([W[1], V[1]])]
    force = _Force(w, states, product=partial(_MonomialProduct, basis), rows=basis.rows)
    # NOTE: the other master is no other mode; a large model's list holds it with its
    # first-order damping (Lanczos), off the refined λ₂ by O(ζ²): the nearest entry goes
    nearest = int(np.argmin(np.abs(lin1.others - lin2.lam))) if len(lin1.others) else -1
    others = [lam for j, lam in enumerate(lin1.others)
              if j != nearest or abs(lam - lin2.lam) > SAME_MODE * abs(lin2.lam)]
    others = np.array(others + [np.conj(lam) for lam in others], dtype=complex)
    if n <= DENSE_SOLVES:  # products with small sparse matrices cost more than dense ones
        M, C = M.toarray(), C.toarray()
    MPhi = np.array([M @ phi for phi in phis])  # (4, n)
    coupling = lefts @ MPhi.T  # w_iᵀ M Φ_j
    # NOTE: the borders are affine in s, b_j = s·MΦ_j + (Λ_j M + C)Φ_j and
    # c_i = s·Mᵀw_i + (Cᵀ + Λ_i Mᵀ)w_i: their parts made once
    border = (MPhi, np.array([(lams[j] * M + C) @ phis[j] for j in range(4)]))
    row_border = (np.array([M.T @ v for v in lefts]),
                  np.array([(C.T + lams[i] * M.T) @ lefts[i] for i in range(4)]))
    residual, near = [0.0], []
    where = f"the 4-D SSM of modes {m1},{m2} does not exist; lower --order below it"
    for k in range(2, order + 1):
        f = force.coeff(k)
        QW, QV = _carried(W, R, basis, k), _carried(V, R, basis, k)
        rows = basis.rows(k)
        Wk = np.zeros((rows, n), dtype=complex)
        Vk = np.zeros((rows, n), dtype=complex)
        Rk = np.zeros((rows, 4), dtype=complex)
        conj = basis.conjugate[k]
        worst = 0.0
        for row, e in enumerate(basis.exponents[k]):
            if conj[row] < row:
                continue  # the conjugate of a row already solved
            s = complex(e @ lams)
            rhs = -f[row] - (s * M + C) @ QW[row] - M @ QV[row]
            kept = np.flatnonzero(nu == e @ nu)
            L = _pencil(w, s)
            label = (k, tuple(int(x) for x in e), f"{m1},{m2}")
            if len(kept):
                B = (s * border[0][kept] + border[1][kept]).T
                Cb = s * row_border[0][kept] + row_border[1][kept]
                E = -lefts[kept] @ (M @ QW[row])
                singular = bool(np.any(np.abs(s - lams[kept]) <= BORDERED * np.abs(lams[kept])))
                Wm, sigma = _bordered(L, B, Cb, coupling[np.ix_(kept, kept)], rhs, E, singular,
                                      label)
                Rk[row, kept] = sigma
                worst = max(worst, _backward_bordered(L, B, Wm, sigma, rhs))
                Vk[row] = s * Wm + QW[row] + sigma @ phis[kept]
            elif not np.any(rhs):
                Wm = np.zeros(n, dtype=complex)
                Vk[row] = QW[row]
            else:
                checked = np.concatenate([others, lams])
                near += _divisors(s, checked, k, 0, label[1], where)
                Wm = _solve(L, rhs, label)
                worst = max(worst, _backward(L, Wm, rhs))
                Vk[row] = s * Wm + QW[row]
            Wk[row] = Wm
        for row in range(rows):
            if conj[row] < row:
                Wk[row], Vk[row] = np.conj(Wk[conj[row]]), np.conj(Vk[conj[row]])
                Rk[row] = np.conj(Rk[conj[row]][list(CONJUGATE)])
        W.append(Wk)
        V.append(Vk)
        R.append(Rk)
        states.append(np.hstack([Wk, Vk]))
        residual.append(worst)
    radius, how = _radius(W, [])
    if math.isfinite(radius):
        how = ("the smallest ratio (|W_(k-2)|/|W_k|)^(1/2) over the last half of the orders, "
               "of W's largest coefficient per order")
    return ResonantSSM(w, (m1, m2), order, r, (lin1, lin2), basis, tuple(W), tuple(V),
                       tuple(R), tuple(residual), tuple(near), radius, how)


def _backward_bordered(L, B: np.ndarray, x: np.ndarray, sigma: np.ndarray,
                       rhs: np.ndarray) -> float:
    """The backward error of ``L x + B σ = rhs``: :func:`analysis.ssm._backward` with the
    borders' terms in the scale (a resonant row's ``W_m`` may vanish: the force drives only
    the master directions, all taken by ``σ``)."""
    scale = float(np.max(abs(L) @ np.abs(x) + np.abs(B) @ np.abs(sigma) + np.abs(rhs)))
    return float(np.max(np.abs(L @ x + B @ sigma - rhs))) / scale if scale > 0 else 0.0


def _carried(X: list[np.ndarray], R: list[np.ndarray], basis: Monomials, k: int
             ) -> np.ndarray:
    """``Q`` at order ``k``: ``Σ q_i X_q R_{i,n}`` over ``q − e_i + n = m``, ``|q| ≥ 2``,
    ``|n| ≥ 2`` (the 2-D :func:`analysis.ssm._carried` with every direction)."""
    out = np.zeros((basis.rows(k), X[1].shape[1]), dtype=complex)
    for j in range(2, k):
        q = k - j + 1
        for row, i in zip(*np.nonzero(R[j]), strict=True):
            n = tuple(int(x) for x in basis.exponents[j][row])
            src, weight, dst = basis.shift(q, int(i), n)
            out[dst] += (weight * R[j][row, i])[:, None] * X[q][src]
    return out


def slow_flow_scale(model: ResonantSSM, shapes) -> tuple[float, float]:
    """``c_k`` of ``φ_k = (c_k/2) s_k`` for the slow flow's shapes ``s_k`` (an undamped
    pair: ``φ_k`` real; ``a_k = |c_k| ρ_k``, phases shifted by π where ``c_k < 0``)."""
    out = []
    for lin, shape in zip(model.linear, shapes, strict=True):
        s = np.array([float(x) for x in shape])
        i = int(np.argmax(np.abs(s)))
        c = 2 * lin.shape[i] / s[i]
        if abs(c.imag) > 1e-9 * abs(c) or np.max(np.abs(2 * lin.shape - c * s)) > 1e-9 * abs(c):
            raise InputError("the mode shapes are not real multiples of the slow flow's "
                             "(a damped or gyroscopic pair): the slow flow's variables do not "
                             "apply")
        out.append(float(c.real))
    return out[0], out[1]


def describe(term: Term) -> str:
    """``c p1^a p̄1^b p2^c p̄2^d`` for a table."""
    names = ("p1", "conj(p1)", "p2", "conj(p2)")
    return "*".join(f"{n}^{e}" if e > 1 else n for n, e in zip(names, term.monomial,
                                                                 strict=True) if e)

