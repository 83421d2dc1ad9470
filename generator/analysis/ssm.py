"""Spectral submanifolds of ``M x'' + C x' + K x + f(x, x') = F cos ωt``: the two-dimensional
SSM of one mode by the parametrisation method, normal-form style, in floating point with the
system's sparse matrices; its reduced dynamics, backbone and damping, each output's physical
amplitude (its forced response: :mod:`analysis.ssm_forced`).

**The manifold.**  ``x = W(p)``, ``x' = V(p)`` with ``p = (p₁, p₂)``, ``p₂ = p̄₁`` on real
motions, and the reduced dynamics in normal form ``p₁' = p₁ g(p₁p₂)``, ``g(u) = Σ_j γ_j u^j``,
``γ₀ = λ`` (the mode's eigenvalue, ``(λ²M + λC + K)φ = 0``).  With ``p₁ = ρ e^{iθ}``:
``ρ' = ρ a(ρ)``, ``θ' = ω(ρ)``, ``a = Re g(ρ²)``, ``ω = Im g(ρ²)``, and the damping ratio
``ζ(ρ) = −a/√(a² + ω²)``.  Order ``k`` holds the monomials ``p₁^{k−r} p₂^r`` (``r = 0 … k``),
one row each: ``W_k`` is a ``(k + 1) × n`` array; ``W₁ = (φ, φ̄)``.

**Order k.**  ``DW·R = V`` and ``M DV·R + C V + K W + f(W, V) = 0`` at the monomial ``m`` of
row ``r`` (``s = (k − r)λ + r λ̄``): ``V_m = s W_m + φ γ_j δ + Q^W_m`` and

    L(s) W_m + ((s + λ)M + C) φ γ_j δ = −f_m − (sM + C) Q^W_m − M Q^V_m,   L(s) = s²M + sC + K,

``Q`` the terms of ``DW·R`` and ``DV·R`` from lower orders (``Σ_{j≥1} W_q (m₁γ_j + m₂γ̄_j)``),
``f_m`` from orders below ``k`` only (``f`` has degree ≥ 2), ``δ = 1`` on the near-resonant
row ``m = (j + 1, j)`` (``s = λ + 2j Re λ``, equal to ``λ`` undamped), where ``γ_j`` is the
unknown that keeps ``W_m`` bounded: the equation is bordered by the first-order form's
normalisation ``ψᵀB(W_m, V_m) = 0`` (``ψ = (w, λw)``, ``w`` the left eigenvector,
``B = [[C, M], [M, 0]]``):

    wᵀ(C + (λ + s)M) W_m + (wᵀMφ) γ_j = −wᵀM Q^W_m.

Each row is one sparse factorization of ``L(s)`` (bordered on the resonant row); rows
``r > k/2`` are the conjugates of rows ``k − r``.  Nothing of size n² is formed."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sparse

from ..algebra.lazy import LazySeries
from ..derive.system import DENSE_MODES, Matrices, System
from ..errors import InputError
from ..numerics.newton import iterate, sparse_solve

NEAR_RESONANCE = 0.1
# NOTE: a divisor |s − λ_j| below this fraction of |λ_j| is reported as a near resonance of
# the monomial with mode j (its coefficients grow as 1/divisor); below SINGULAR the row has
# no solution and the mode is refused (an internal resonance: a 4-D SSM is needed).
SINGULAR = 1e-8
REFINE = 2
# NOTE: steps of iterative refinement of each sparse solve (a beam's L(s) is conditioned like
# 1e12: the homological equations' residual falls from 4.5e-4 to rounding).
BORDERED = 1e-3
# NOTE: where s lies this close to λ (relative), the resonant row is solved as one bordered
# matrix (undamped: L(λ) is singular); further off, by block elimination, which keeps L's
# sparsity (the bordered matrix's dense row and column fill its factors in: 20 ms against
# 1 ms for a chain of 1000 masses).
EIGEN_STEPS = 12
# NOTE: Newton steps refining the mode's eigenpair (from the dense eigenvalue problem or the
# undamped Lanczos mode: quadratic convergence takes 3 to 6).
OTHER_MODES = 8
# NOTE: a large model's divisors are checked against this many modes above the lowest (and
# every mode below the chosen one): the near resonances of low orders lie among them.
THETA_SAMPLES = 64
# NOTE: samples of one period per harmonic order for the physical amplitude max |x_i(θ)|,
# whose sampled maximum is then refined by Newton on x_i'(θ) = 0 to rounding.
REFINE_STEPS = 6


@dataclass(frozen=True)
class LinearMode:
    """The mode's eigenvalue ``λ`` (``Im λ > 0``), its right eigenvector ``φ`` (``φᴴMφ = 1/4``,
    its largest component real and positive: the linear motion is ``x = ρ·2Re(φ e^{iθ})``),
    the left eigenvector ``w`` (``wᵀ(C + 2λM)φ = 1``), and the eigenvalues of the modes
    the divisors are checked against, with which they are."""

    lam: complex
    shape: np.ndarray
    left: np.ndarray
    others: np.ndarray
    checked: str


def _pencil(w: Matrices, s: complex) -> sparse.csc_array | np.ndarray:
    """``L(s) = s²M + sC + K``: sparse, or dense up to :data:`DENSE_SOLVES` coordinates."""
    if w.size <= DENSE_SOLVES:
        L = s * s * w.mass.toarray() + w.stiffness.toarray()
        return L + s * w.damping.toarray() if w.damping is not None else L.astype(complex)
    L = s * s * w.mass + w.stiffness
    if w.damping is not None:
        L = L + s * w.damping
    return sparse.csc_array(L, dtype=complex)


DENSE_SOLVES = 64
# NOTE: up to this many coordinates L(s) is dense and solved by LAPACK: SuperLU's set-up costs
# more than the solve itself for a small system (the forced terms solve ~30 rows per Ω).


def _damping(w: Matrices) -> sparse.csr_array:
    return w.damping if w.damping is not None else sparse.csr_array(w.mass.shape)


def linear_mode(w: Matrices, mode: int) -> LinearMode:
    """Mode ``mode`` (1, 2, … by increasing ``Im λ`` among the oscillating modes): dense up
    to :data:`DENSE_MODES` coordinates (every eigenvalue of the first-order pencil, LAPACK),
    else the undamped mode by shift-invert Lanczos and its damping to first order; then
    Newton on ``L(λ)φ = 0`` (sparse, bordered by the normalisation) to rounding."""
    n = w.size
    M, C, K = w.mass, _damping(w), w.stiffness
    if n <= DENSE_MODES:
        Md, Cd, Kd = M.toarray(), C.toarray(), K.toarray()
        # the pencil (A, diag(I, M)) as one matrix, M being positive definite: NumPy's LAPACK,
        # no SciPy import on a small system's path (Newton below refines the pair to rounding)
        A = np.block([[np.zeros((n, n)), np.eye(n)],
                      [-np.linalg.solve(Md, Kd), -np.linalg.solve(Md, Cd)]])
        lams, vecs = np.linalg.eig(A)
        scale = max(1.0, float(np.max(np.abs(lams[np.isfinite(lams)]), initial=1.0)))
        upper = [k for k in np.argsort(lams.imag) if lams[k].imag > 1e-12 * scale]
        if mode > len(upper):
            raise InputError(f"--mode {mode}: the system has {len(upper)} oscillating "
                             f"mode{'s' * (len(upper) != 1)} (complex eigenvalues)")
        k = upper[mode - 1]
        lam, phi = complex(lams[k]), vecs[:n, k]
        others = np.array([lams[j] for j in upper if j != k])
        checked = f"every mode ({len(upper)}, dense)"
    else:
        from scipy.sparse.linalg import eigsh

        count = min(n - 2, mode + OTHER_MODES)
        squares, shapes = eigsh(K.tocsc(), count, M.tocsc(), sigma=0, which="LM")
        order = np.argsort(squares)
        squares, shapes = squares[order], shapes[:, order]
        if not squares[0] > 0:
            raise InputError(f"the lowest linear mode has ω0² = {squares[0]:.6g}: no "
                             "oscillation about the origin")
        u = shapes[:, mode - 1]
        w0 = math.sqrt(squares[mode - 1])
        lam = complex(-0.5 * float(u @ (C @ u)) / float(u @ (M @ u)), w0)
        phi = u.astype(complex)
        others = np.array([complex(-0.5 * float(v @ (C @ v)), math.sqrt(q))
                           for j, (q, v) in enumerate(zip(squares, shapes.T, strict=True))
                           if j != mode - 1 and q > 0])
        checked = f"the lowest {count} modes (Lanczos)"
    lam, phi = _refined(w, lam, phi, mode)
    phi = phi * np.exp(-1j * np.angle(phi[leading(phi)]))
    phi = phi / (2 * math.sqrt(float(np.real(np.conj(phi) @ (M @ phi)))))
    left = _left(w, lam, phi)
    left = left / (left @ ((C + 2 * lam * M) @ phi))
    return LinearMode(lam, phi, left, others, checked)


def leading(v: np.ndarray) -> int:
    """The index of ``v``'s largest component: the first of those within :data:`TIE` of the
    largest (components equal in exact arithmetic, as in ``(1, −1)/√2``, differ by rounding that
    LAPACK's kernels do not share across machines; the choice must not depend on it)."""
    size = np.abs(v)
    return int(np.flatnonzero(size >= (1 - TIE) * size.max())[0])


TIE = 1e-9


def _refined(w: Matrices, lam: complex, phi: np.ndarray, mode: int
             ) -> tuple[complex, np.ndarray]:
    """Newton on ``(L(λ)φ = 0, rᵀφ = 1)``, ``r = Mφ̄₀``: the eigenpair to rounding.  Each
    step's bordered system is solved by block elimination (:func:`_eliminated`: one sparse
    factorization of ``L(λ)``, which keeps its sparsity — nonlinear inverse iteration)."""
    n = w.size
    M, C = w.mass, _damping(w)
    r = np.conj(M @ phi)
    x0 = np.append(phi / (r @ phi), lam)

    def evaluate(x: np.ndarray) -> tuple[np.ndarray, tuple]:
        v, s = x[:n], x[n]
        L = _pencil(w, s)
        return np.append(L @ v, r @ v - 1), (L, (2 * s * M + C) @ v, r)

    run = iterate(evaluate, x0, tol=1e-13, max_iter=EIGEN_STEPS, solve=_eliminated)
    v, s = run.x[:n], complex(run.x[n])
    scale = abs(s) ** 2 * float(abs(M).sum()) + float(abs(w.stiffness).sum())
    if not np.linalg.norm(_pencil(w, s) @ v) <= 1e-9 * scale * np.linalg.norm(v):
        raise InputError(f"--mode {mode}: its eigenvalue did not converge in {EIGEN_STEPS} "
                         f"Newton steps from {lam:.6g} ({run.why})")
    return s, v


def _eliminated(J: tuple, rhs: np.ndarray) -> np.ndarray:
    """``[[L, b], [rᵀ, 0]]⁻¹ rhs`` by block elimination; ``LinAlgError`` where ``L`` is
    exactly singular (the eigenvalue is exact: Newton stops there)."""
    L, b, r = J
    y = sparse_solve(L, np.column_stack([rhs[:-1], b]))
    mu = (r @ y[:, 0] - rhs[-1]) / (r @ y[:, 1])
    return np.append(y[:, 0] - y[:, 1] * mu, mu)


def _left(w: Matrices, lam: complex, phi: np.ndarray) -> np.ndarray:
    """The left eigenvector ``L(λ)ᵀ w = 0``: φ itself where M, C, K are symmetric, else one
    step of inverse iteration ``L(λ)ᵀ w = Mφ`` (λ is exact to rounding), or the bordered
    solve ``[[L(λ)ᵀ, Mφ], [(Mφ)ᵀ, 0]] (w, μ) = (0, 1)`` where ``L(λ)`` is exactly singular."""
    mats = [w.mass, w.stiffness] + ([w.damping] if w.damping is not None else [])
    if all(abs(A - A.T).max() == 0 if A.nnz else True for A in mats):
        return phi
    n = w.size
    b = w.mass @ phi
    try:
        left = sparse_solve(_pencil(w, lam).T, b)
        if np.all(np.isfinite(left)):
            return left
    except np.linalg.LinAlgError:
        pass
    J = sparse.bmat([[sparse.csc_array(_pencil(w, lam).T), sparse.csc_array(b[:, None])],
                     [sparse.csc_array(b[None, :]), None]], format="csc")
    return sparse_solve(J, np.append(np.zeros(n), 1.0))[:n]


class _Column(LazySeries):
    """One factor of the force's terms as a series in ρ: order k's rows of ``(x, x')`` at the
    factor's index, one column per term."""

    def __init__(self, states: list[np.ndarray], index: np.ndarray) -> None:
        super().__init__()
        self.states, self.index = states, index

    def compute(self, k: int) -> np.ndarray:
        return self.states[k][:, self.index]


class _Product(LazySeries):
    """``a · b`` of two series in the monomials ``p₁^{k−r}p₂^r`` (order k: ``(k + 1) × T``,
    or ``(k + 1)·batch × T``, monomial-major, for a factor that differs over a batch of drive
    frequencies, as :mod:`analysis.ssm_forced`'s first-order states do): the Cauchy sum over
    orders from each factor's lowest (``low_a``, ``low_b``), each a convolution of the rows,
    batched where either factor is."""

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


class _Force:
    """``f(W, V)`` order by order — or, given ``varied`` (the states of a first-order change
    ``Z¹``), its linear part ``Df(Z)·Z¹``: the term table grouped by degree, each group a chain
    of lazy products of its factors' columns (for ``Df·Z¹`` one chain per factor, that factor's
    column taken from ``Z¹``), summed into the equations by a sparse matrix."""

    def __init__(self, w: Matrices, states: list[np.ndarray],
                 varied: list[np.ndarray] | None = None,
                 product: Callable[..., LazySeries] = _Product,
                 rows: Callable[[int], int] | None = None) -> None:
        # NOTE: ``product`` and ``rows`` (order -> its number of monomials) name the monomials'
        # layout: p₁^{k−r}p₂^r rows by default, multi-indices for several master modes
        # (:mod:`analysis.ssm_resonant`)
        self.rows = rows if rows is not None else (lambda k: k + 1)
        table = w.force
        degrees = (table.factors >= 0).sum(axis=1) if len(table.coefficient) else np.array([])
        self.groups = []
        for d in sorted(set(degrees.tolist())):
            keep = degrees == d
            factors = table.factors[keep][:, :d]
            sums = sparse.csr_array((table.coefficient[keep], (table.equation[keep],
                                                                np.arange(keep.sum()))),
                                    shape=(w.size, int(keep.sum())))
            picks = [[states] * d] if varied is None else [
                [varied if level == v else states for level in range(d)] for v in range(d)]
            chains = [_chain(factors, sources, varied, product) for sources in picks]
            self.groups.append((d if varied is None else d - 1, chains, sums))
        self.n = w.size

    def coeff(self, k: int) -> np.ndarray:
        """Order ``k`` (``(k + 1) × n``, or one row per monomial), from the states below
        ``k``."""
        out = np.zeros((self.rows(k), self.n), dtype=complex)
        for lowest, chains, sums in self.groups:
            if k >= lowest:
                for chain in chains:
                    out += (sums @ chain.coeff(k).T).T
        return out


def _chain(factors: np.ndarray, sources: list[list[np.ndarray]],
           varied: list[np.ndarray] | None,
           product: Callable[..., LazySeries] = _Product) -> LazySeries:
    """The product of the factors' columns, column ``l`` from ``sources[l]`` (a series from
    order 1, or ``varied``, from order 0), each step a ``product``."""
    low = 0 if sources[0] is varied else 1
    chain: LazySeries = _Column(sources[0], factors[:, 0])
    for level in range(1, len(sources)):
        this = 0 if sources[level] is varied else 1
        chain = product(chain, _Column(sources[level], factors[:, level]), low, this)
        low += this
    return chain


def _carried(X: list[np.ndarray], gamma: list[complex], k: int, n: int) -> np.ndarray:
    """``Q`` at order ``k``: ``Σ_{j≥1} W_q (m₁γ_j + m₂γ̄_j)`` over ``q = k − 2j ≥ 2``, row
    ``r' + j`` for row ``r'`` of order ``q``."""
    out = np.zeros((k + 1, n), dtype=complex)
    for j in range(1, len(gamma)):
        q = k - 2 * j
        if q < 2:
            break
        r = np.arange(q + 1)
        out[j:j + q + 1] += ((q - r) * gamma[j] + r * np.conj(gamma[j]))[:, None] * X[q]
    return out


@dataclass(frozen=True)
class NearResonance:
    """A monomial ``p₁^{m₁}p₂^{m₂}`` of order ``m₁ + m₂`` whose ``s = m₁λ + m₂λ̄`` lies near
    another mode's eigenvalue: ``divisor = |s − λ_j|`` (relative: over ``|λ_j|``); a 4-D
    SSM's monomial has four exponents."""

    order: int
    monomial: tuple[int, ...]
    eigenvalue: complex
    divisor: float
    relative: float


@dataclass(frozen=True)
class SSM:
    """The 2-D SSM of one mode to order ``order``: ``W[k]``, ``V[k]`` (``(k + 1) × n`` each,
    ``k = 0 … K``), the normal form's ``gamma`` (``γ_j``, ``2j + 1 ≤ K``), each order's
    relative residual of its homological equations, the near resonances and the radius in ρ
    estimated from the terms."""

    matrices: Matrices = field(repr=False)
    mode: int
    order: int
    linear: LinearMode
    W: tuple[np.ndarray, ...] = field(repr=False)
    V: tuple[np.ndarray, ...] = field(repr=False)
    gamma: tuple[complex, ...]
    residual: tuple[float, ...]
    near: tuple[NearResonance, ...]
    radius: float
    radius_how: str

    @property
    def lam(self) -> complex:
        return self.linear.lam

    def g(self, rho: np.ndarray) -> np.ndarray:
        """``g(ρ²) = a(ρ) + iω(ρ)``."""
        u = np.asarray(rho, dtype=float) ** 2
        return sum(c * u**j for j, c in enumerate(self.gamma))

    def omega(self, rho: np.ndarray) -> np.ndarray:
        """The backbone's frequency ``ω(ρ)``."""
        return np.imag(self.g(rho))

    def decay(self, rho: np.ndarray) -> np.ndarray:
        """``a(ρ)``: ``ρ' = ρ a(ρ)``."""
        return np.real(self.g(rho))

    def damping_ratio(self, rho: np.ndarray) -> np.ndarray:
        """``ζ(ρ) = −a/√(a² + ω²)`` (the linear ζ at ρ = 0)."""
        g = self.g(rho)
        return -np.real(g) / np.abs(g)

    def error(self, rho: np.ndarray) -> np.ndarray:
        """The error estimate of ``g``: its last term ``|γ_J| ρ^{2J}`` (0 at order 1), over
        ``|g|``."""
        J = len(self.gamma) - 1
        rho = np.asarray(rho, dtype=float)
        return abs(self.gamma[J]) * rho ** (2 * J) / np.abs(self.g(rho)) if J else 0 * rho

    def harmonics(self, rho: np.ndarray, outputs: np.ndarray,
                  phase: np.ndarray | None = None) -> np.ndarray:
        """The outputs' Fourier coefficients in θ at each ρ (``(P, 2K + 1, outputs)``,
        harmonic ``h = −K … K`` at index ``h + K``): ``Σ_k ρ^k W_k[r] e^{ih(θ + phase)}``."""
        rho = np.atleast_1d(np.asarray(rho, dtype=float))
        K = self.order
        out = np.zeros((len(rho), 2 * K + 1, len(outputs)), dtype=complex)
        for k in range(1, K + 1):
            for r in range(k + 1):
                out[:, k - 2 * r + K] += rho[:, None] ** k * self.W[k][r, outputs][None, :]
        if phase is not None:
            h = np.arange(-K, K + 1)
            out *= np.exp(1j * h[None, :] * np.atleast_1d(phase)[:, None])[:, :, None]
        return out

    def amplitude(self, rho: np.ndarray, outputs: np.ndarray) -> np.ndarray:
        """``max_θ |x_i|`` along the backbone, ``(P, outputs)``."""
        return peak_amplitude(self.harmonics(rho, outputs))


def peak_amplitude(c: np.ndarray) -> np.ndarray:
    """``max_θ |Σ_h c_h e^{ihθ}|`` of real trigonometric polynomials (``c``: ``(P, H, m)``,
    harmonics ``−K … K``): sampled (:data:`THETA_SAMPLES` per harmonic order), the largest
    sample refined by Newton on ``x'(θ) = 0``."""
    H = c.shape[1]
    K = (H - 1) // 2
    h = np.arange(-K, K + 1)
    N = THETA_SAMPLES * max(K, 1)
    theta = 2 * np.pi * np.arange(N) / N
    waves = np.exp(1j * np.outer(h, theta))  # (H, N)
    cc = np.transpose(c, (0, 2, 1))  # (P, m, H)
    x = cc.real @ waves.real - cc.imag @ waves.imag  # Re Σ_h c_h e^{ihθ}: two real products
    t = theta[np.argmax(np.abs(x), axis=2)]  # (P, m)
    for _ in range(REFINE_STEPS):
        e = np.exp(1j * h[None, None, :] * t[:, :, None])  # (P, m, H)
        cc = np.transpose(c, (0, 2, 1))
        d1 = np.real(np.sum(1j * h * cc * e, axis=2))
        d2 = np.real(np.sum(-(h**2) * cc * e, axis=2))
        step = np.where(d2 != 0, d1 / np.where(d2 != 0, d2, 1), 0.0)
        t = t - np.clip(step, -np.pi / N, np.pi / N)
    e = np.exp(1j * h[None, None, :] * t[:, :, None])
    value = np.abs(np.real(np.sum(np.transpose(c, (0, 2, 1)) * e, axis=2)))
    return np.maximum(value, np.max(np.abs(x), axis=2))


def ssm(system: System, mode: int, order: int) -> SSM:
    """The SSM of ``mode`` to ``order`` (≥ 1) of the system as written in floating point."""
    w = system.matrices
    n = w.size
    lin = linear_mode(w, mode)
    lam, phi, left = lin.lam, lin.shape, lin.left
    M, C = w.mass, _damping(w)
    W: list[np.ndarray] = [np.zeros((1, n), dtype=complex), np.array([phi, np.conj(phi)])]
    V: list[np.ndarray] = [np.zeros((1, n), dtype=complex),
                           np.array([lam * phi, np.conj(lam * phi)])]
    states = [np.hstack([W[0], V[0]]), np.hstack([W[1], V[1]])]
    force = _Force(w, states)
    gamma, residual, near = [lam], [0.0], []
    others = np.concatenate([lin.others, np.conj(lin.others), [np.conj(lam)]])
    for k in range(2, order + 1):
        f = force.coeff(k)
        QW, QV = _carried(W, gamma, k, n), _carried(V, gamma, k, n)
        Wk = np.zeros((k + 1, n), dtype=complex)
        Vk = np.zeros((k + 1, n), dtype=complex)
        worst = 0.0
        for r in range(k // 2 + 1):
            s = (k - r) * lam + r * np.conj(lam)
            rhs = -f[r] - (s * M + C) @ QW[r] - M @ QV[r]
            L = _pencil(w, s)
            resonant = k % 2 == 1 and r == (k - 1) // 2
            if resonant:
                b = ((s + lam) * M + C) @ phi
                c = ((C + (lam + s) * M).T @ left)
                Wm, g = _bordered(L, b, c, left @ (M @ phi), rhs, -left @ (M @ QW[r]),
                                  abs(s - lam) <= BORDERED * abs(lam), (k, r, mode))
                gamma.append(g)
                worst = max(worst, _backward(L, Wm, rhs - b * g))
                Vk[r] = s * Wm + QW[r] + phi * g
            elif not np.any(rhs):  # nothing drives this monomial (an odd force's even orders)
                Wm = np.zeros(n, dtype=complex)
                Vk[r] = QW[r]
            else:
                near += _divisors(s, others, k, r)
                Wm = _solve(L, rhs, (k, r, mode))
                worst = max(worst, _backward(L, Wm, rhs))
                Vk[r] = s * Wm + QW[r]
            Wk[r] = Wm
        for r in range(k // 2 + 1, k + 1):
            Wk[r], Vk[r] = np.conj(Wk[k - r]), np.conj(Vk[k - r])
        W.append(Wk)
        V.append(Vk)
        states.append(np.hstack([Wk, Vk]))
        residual.append(worst)
    radius, how = _radius(W, gamma)
    return SSM(w, mode, order, lin, tuple(W), tuple(V), tuple(gamma), tuple(residual),
               tuple(near), radius, how)


def _solve(J: sparse.csc_array, rhs: np.ndarray, where: tuple) -> np.ndarray:
    """``J⁻¹ rhs`` (columns); refused where singular (``where``: order, row or a 4-D SSM's
    exponents, mode or modes)."""
    try:
        x = sparse_solve(J, rhs, REFINE)
    except np.linalg.LinAlgError:
        x = np.full(rhs.shape, np.nan)
    if not np.all(np.isfinite(x)):
        k, r, mode = where
        name = _monomial_name(r) if isinstance(r, tuple) else f"p1^{k - r} p2^{r}"
        what = "this mode's 2-D SSM" if isinstance(mode, int) else "the modes' SSM"
        raise InputError(f"--mode {mode}: order {k}, monomial {name}: the homological "
                         f"equation is singular (an exact internal resonance: {what} does "
                         "not exist)")
    return x


def _bordered(L: sparse.csc_array, b: np.ndarray, c: np.ndarray, d, rhs: np.ndarray,
              e, singular: bool, where: tuple[int, int, int]) -> tuple[np.ndarray, complex]:
    """``(x, σ)`` of ``L x + b σ = rhs``, ``cᵀx + d σ = e``: by block elimination with one
    factorization of ``L`` (two solves), or, where ``L`` is (nearly) singular, the bordered
    matrix factorized whole (its dense row and column fill in).  Several borders: ``b`` an
    ``n × m`` array, ``c`` ``m × n``, ``d`` ``m × m``, ``e`` and ``σ`` of length m (a 4-D SSM's
    monomial resonant with two master directions)."""
    one = b.ndim == 1
    B, Cb = (b[:, None], c[None, :]) if one else (b, c)
    D, E = np.atleast_2d(d), np.atleast_1d(e)
    if singular:
        J = sparse.bmat([[sparse.csc_array(L), sparse.csc_array(B)],
                         [sparse.csc_array(Cb), sparse.csc_array(D)]], format="csc")
        x = _solve(J, np.append(rhs, E), where)
        m = B.shape[1]
        return (x[:-1], complex(x[-1])) if one else (x[:-m], x[-m:])
    y = _solve(L, np.column_stack([rhs, B]), where)
    if one:
        sigma = (c @ y[:, 0] - e) / (c @ y[:, 1] - d)
        return y[:, 0] - y[:, 1] * sigma, complex(sigma)
    sigma = np.linalg.solve(Cb @ y[:, 1:] - D, Cb @ y[:, 0] - E)
    return y[:, 0] - y[:, 1:] @ sigma, sigma


def _backward(L: sparse.csc_array, x: np.ndarray, rhs: np.ndarray) -> float:
    """The solve's backward error ``max|Lx − rhs| / max(|L||x| + |rhs|)``: rounding (1e-16)
    for a solve that is exact to the data, whatever ``L``'s condition."""
    scale = float(np.max(abs(L) @ np.abs(x) + np.abs(rhs)))
    return float(np.max(np.abs(L @ x - rhs))) / scale if scale > 0 else 0.0


def _divisors(s: complex, others: np.ndarray, k: int, r: int,
              monomial: tuple[int, ...] | None = None,
              refusal: str = "the 2-D SSM does not exist; lower --order below it"
              ) -> list[NearResonance]:
    """The near resonances of the row's ``s`` with the modes checked; refused where exact
    (``monomial``: the row's exponents, by default ``(k − r, r)``)."""
    monomial = (k - r, r) if monomial is None else monomial
    out = []
    for lam in others:
        divisor = abs(s - lam)
        relative = divisor / abs(lam)
        if relative < SINGULAR:
            raise InputError(f"order {k}, monomial {_monomial_name(monomial)}: s = {s:.6g} "
                             f"equals the eigenvalue {lam:.6g} of another mode (an internal "
                             f"resonance: {refusal})")
        if relative < NEAR_RESONANCE:
            out.append(NearResonance(k, monomial, complex(lam), divisor, relative))
    return out


def _monomial_name(monomial: tuple[int, ...]) -> str:
    """``p1^a p2^b …`` (every exponent written, as the 2-D rows always were)."""
    return " ".join(f"p{i + 1}^{e}" for i, e in enumerate(monomial))


def _radius(W: list[np.ndarray], gamma: list[complex]) -> tuple[float, str]:
    """The radius in ρ: the smallest ratio ``(|c_(k−2)|/|c_k|)^{1/2}`` over the last half of
    the orders, of ``W``'s largest coefficient per order (two orders apart: even and odd
    orders alternate in size where the force has even and odd terms) and of ``g``'s terms
    (in ρ², ``(|γ_(j−1)|/|γ_j|)^{1/2}``); inf where every term past the linear one vanishes
    (a linear system's SSM is its modal plane)."""
    norms = [float(np.max(np.abs(X))) for X in W]
    K = len(W) - 1
    ratios = [math.sqrt(norms[k - 2] / norms[k]) for k in range(max(3, K // 2 + 1), K + 1)
              if norms[k] > 0 and norms[k - 2] > 0]
    J = len(gamma) - 1
    ratios += [math.sqrt(abs(gamma[j - 1]) / abs(gamma[j])) for j in range(max(1, J // 2 + 1),
                                                                        J + 1)
               if abs(gamma[j]) > 0 and abs(gamma[j - 1]) > 0]
    if not ratios:
        return math.inf, "no term past the linear one: the SSM is the modal plane"
    return min(ratios), ("the smallest ratio of terms two orders apart over the last half of "
                         "the orders (of W's largest coefficient, and of g in rho^2)")
