"""Floquet multipliers: the notes' Hill equation about q₀, Hill's equation with a damped
periodic pump (compiled, in parallel over a grid), the full Hill equation about a balance
orbit, and the stability verdict of a set of multipliers."""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

from ..algebra.series import laurent_from_fourier, laurent_product
from ..errors import InputError
from .integrate import NO_TERMS, ForceTable, _rk4, _rk4_step


def _hill(omega: float, eps: float, a: float, b: float, F: float, steps: int) -> np.ndarray:
    """Monodromy over τ ∈ [0, 2π] of ω²ξ'' + (1 + 3εq₀²)ξ = 0, q₀ = a cos τ + b sin τ + F cos 3τ:
    the variational columns of :func:`_rk4` with no force and the parametric stiffness
    ``(1 + 3εq₀²)/ω²`` (``q₀²`` by the float Fourier kernel) as ``extra`` rows."""
    q0 = laurent_from_fourier(6, np.array([1, 3]), np.array([a, F]), np.array([b, 0.0]))
    square = laurent_product(q0, q0)[6:]  # c_n of q₀², n = 0 … 6
    rows = [(1.0, -(1 + 3 * eps * square[0].real) / omega**2, 0.0, 0.0)]
    rows += [(1.0, -6 * eps * abs(c) / omega**2, float(n), float(np.angle(c)))
             for n, c in enumerate(square) if n and c != 0]
    empty = ForceTable.of({})
    y, _, _ = _rk4(np.array([1.0, 0.0, 1.0, 0.0, 0.0, 1.0]), 0.0, 2 * np.pi, steps,
                   empty.q_powers, empty.v_powers, empty.coefficients, empty.cubic, 0.0, 0.0,
                   1, math.inf, np.array(rows))
    return y[2:].reshape(2, 2).T


def hill_multipliers(omega: float, eps: float, a: float, b: float, F: float,
                     steps: int = 2048) -> np.ndarray:
    """Floquet multipliers of the Hill equation (notes after eq. 10.87), Richardson-combined."""
    with np.errstate(over="ignore", invalid="ignore"):
        coarse, fine = _hill(omega, eps, a, b, F, steps), _hill(omega, eps, a, b, F, 2 * steps)
    with np.errstate(over="ignore", invalid="ignore"):
        M = fine + (fine - coarse) / 15
    if not np.all(np.isfinite(M)):  # ξ grows past 1e308 within one period: λ = ∞ and 1/λ = 0
        return np.array([np.inf, 0.0], dtype=complex)
    return np.linalg.eigvals(M)


# --- Hill's equation ẍ + 2ζẋ + (δ + ε p(t))x = 0: Floquet multipliers on a grid --------------

FLOQUET_STEPS = 256
# NOTE: RK4 steps per period 2π on the Ince–Strutt chart: |tr M| to ~1e-6 for δ ≤ 3, ε ≤ 2
# (halving h changes it by less), far below the width of any verdict near the curves.


@njit(cache=True, parallel=True)
def _floquet_points(deltas: np.ndarray, eps: np.ndarray, zeta: float, rows: np.ndarray,
                    steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Monodromy over t ∈ [0, 2π] of ``ẍ + 2ζẋ + (δ + ε p(t))x = 0`` at each point
    ``(deltas[i], eps[i])`` by :func:`_rk4_step` (the linear table ``δq + 2ζq̇`` on its cubic
    fast path, ``p`` as the parametric ``extra`` rows ``(1, −R_k, k, φ_k)`` scaled by ε);
    returns ``tr M`` and ``det M``, points in parallel."""
    trace, det = np.empty(deltas.size), np.empty(deltas.size)
    h = 2 * np.pi / steps
    empty_i, empty_f = np.zeros(0, dtype=np.int64), np.zeros(0)
    for i in prange(deltas.size):
        extra = rows.copy()
        for r in range(extra.shape[0]):
            extra[r, 1] *= eps[i]
        cubic = np.array([deltas[i], 0.0, 2.0 * zeta])
        y = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 1.0])
        k1, k2, k3, k4, tmp = np.empty(6), np.empty(6), np.empty(6), np.empty(6), np.empty(6)
        for s in range(steps):
            _rk4_step(s * h, h, y, empty_i, empty_i, empty_f, cubic, 0.0, 0.0, 0.0, extra,
                      k1, k2, k3, k4, tmp)
        trace[i] = y[2] + y[5]
        det[i] = y[2] * y[5] - y[4] * y[3]
    return trace, det


def hill_rows(p: dict[int, tuple[float, float]]) -> np.ndarray:
    """``−p(t) = −Σ (a_k cos kt + b_k sin kt)`` as :func:`_field`'s parametric rows
    ``(1, −R_k, k, φ_k)``: ``a cos kt + b sin kt = R cos(kt + φ)``, ``φ = atan2(−b, a)``."""
    return np.array([(1.0, -math.hypot(a, b), float(k), math.atan2(-b, a))
                     for k, (a, b) in sorted(p.items()) if a or b]).reshape(-1, 4)


def floquet_traces(delta: ArrayLike, eps: ArrayLike, p: dict[int, tuple[float, float]],
                   zeta: float = 0.0, steps: int = FLOQUET_STEPS
                   ) -> tuple[np.ndarray, np.ndarray]:
    """``tr M`` and ``det M`` of the monodromy over 2π of ``ẍ + 2ζẋ + (δ + ε p(t))x = 0`` at
    the points ``(δ, ε)`` (broadcast; compiled RK4, parallel): ``p`` by its harmonics
    ``{k: (a_k, b_k)}``."""
    d, e = np.broadcast_arrays(np.asarray(delta, dtype=float), np.asarray(eps, dtype=float))
    if not (np.all(np.isfinite(d)) and np.all(np.isfinite(e)) and math.isfinite(zeta)):
        raise InputError("floquet_traces: δ, ε and ζ must be finite")
    tr, det = _floquet_points(np.ascontiguousarray(d.ravel()), np.ascontiguousarray(e.ravel()),
                              float(zeta), hill_rows(p), int(steps))
    return tr.reshape(d.shape), det.reshape(d.shape)


def floquet_stable(trace: np.ndarray, zeta: float = 0.0) -> np.ndarray:
    """Both Floquet multipliers of ``ẍ + 2ζẋ + …`` inside the unit circle (ζ > 0) or on it
    (ζ = 0: ``|tr M| < 2``): with ``det M = e^(−4πζ)`` (Liouville) the roots of
    ``λ² − tr λ + det`` lie in the closed unit disc iff ``|tr M| ≤ 1 + det M`` (Jury)."""
    return np.abs(trace) < 1 + math.exp(-4 * math.pi * zeta)


# --- the full Hill equation: stability of a periodic orbit known as a Fourier sum -------------

HILL_STEPS = 2048
# NOTE: RK4 steps per orbit period for the variational equation, Richardson-combined with
# twice as many (as hill_multipliers): the multipliers to ~1e-10 for the orbits of the notes.


def orbit_hill_rows(terms: dict[tuple[int, int], float], A: dict[int, float],
                    B: dict[int, float], omega: float) -> np.ndarray:
    """The ``extra`` rows ``(1, −2|c_n|, nω, arg c_n)`` (and ``(1, −c_0, 0, 0)``) of
    ``−∂g/∂q(q(t)) ξ`` for ``q = Σ A_n cos nωt + B_n sin nωt`` and a force ``g = k(q) + c q̇``
    (``terms`` ``{(a, b): c}``): ``∂g/∂q = Σ a c_a q^(a−1)`` by the float Fourier kernel,
    exact (no truncation: ``M`` covers the top harmonic of ``q^(degree−1)``)."""
    if any(b and (a, b) != (0, 1) for a, b in terms):
        raise ValueError("orbit_hill_rows: the q̇ part of the force must be linear (c q̇)")
    orders = sorted(set(A) | set(B))
    degree = max((a for a, b in terms if b == 0), default=1)
    M = max(1, max(orders, default=0) * max(degree - 1, 1))
    q = laurent_from_fourier(M, np.array(orders), np.array([A.get(n, 0.0) for n in orders]),
                             np.array([B.get(n, 0.0) for n in orders]))
    stiffness = np.zeros(2 * M + 1, dtype=complex)
    power = np.zeros(2 * M + 1, dtype=complex)
    power[M] = 1.0  # q⁰
    for a in range(1, degree + 1):
        c = terms.get((a, 0), 0.0)
        if c:
            stiffness += a * c * power
        power = laurent_product(power, q)
    # NOTE: a harmonic below 1e-17 of the stiffness's size moves the monodromy by less than a
    # rounding error: its row is dropped (each row is a cosine per RK4 stage).
    negligible = 1e-17 * float(np.sum(np.abs(stiffness)))
    rows = [(1.0, -stiffness[M].real, 0.0, 0.0)]
    rows += [(1.0, -2 * abs(c), n * omega, float(np.angle(c)))
             for n, c in enumerate(stiffness[M + 1:], start=1) if abs(c) > negligible]
    return np.array(rows)


def orbit_hill_multipliers(terms: dict[tuple[int, int], float], A: dict[int, float],
                           B: dict[int, float], omega: float, extra: np.ndarray = NO_TERMS,
                           steps: int = HILL_STEPS) -> np.ndarray:
    """Floquet multipliers of the full Hill equation of an orbit ``q(t)`` of period ``2π/ω``
    known as a Fourier sum (harmonic balance, a series): the variational equation
    ``ξ̈ + c ξ̇ + ∂g/∂q(q(t)) ξ = Σ c_i ξ cos(ν_i t + φ_i)`` of ``q̈ + g(q, q̇) = f(t)``
    (``g = k(q) + c q̇``, ``terms``; ``extra``: parametric rows ``(1, c_i, ν_i, φ_i)`` of the
    equation itself, e.g. a pump).  Its coefficients are periodic and known: one RK4 pass of
    the monodromy columns over the period (the compiled :func:`_rk4`, Richardson pair), with no
    shooting of the nonlinear orbit.  The notes' test (:func:`hill_multipliers`) is this with
    ``q`` cut to ``q₀``.

    Why a pass and not Hill's truncated infinite determinant: the pass gives both multipliers
    themselves (the verdict and the margin), damping and a pump need nothing new, its error is
    the integrator's known O(h⁶) after Richardson; the determinant gives ``cos(2πν)`` only after
    a truncation whose convergence must be checked harmonic by harmonic, and its damped form
    needs the complex exponent."""
    rows = orbit_hill_rows(terms, A, B, omega)
    extra = np.asarray(extra, dtype=float).reshape(-1, 4)
    if np.any(extra[:, 0] != 1.0):
        raise ValueError("orbit_hill_multipliers: extra rows must be parametric (a = 1)")
    rows = np.vstack([rows, extra])
    damping = ForceTable.of({(0, 1): terms.get((0, 1), 0.0)})
    T = 2 * np.pi / omega

    def monodromy(n: int) -> np.ndarray:
        y, _, _ = _rk4(np.array([1.0, 0.0, 1.0, 0.0, 0.0, 1.0]), 0.0, T, n,
                       damping.q_powers, damping.v_powers, damping.coefficients, damping.cubic,
                       0.0, 0.0, 1, math.inf, rows)
        return y[2:].reshape(2, 2).T

    with np.errstate(over="ignore", invalid="ignore"):
        coarse, fine = monodromy(steps), monodromy(2 * steps)
        M = fine + (fine - coarse) / 15
    if not np.all(np.isfinite(M)):  # ξ grows past 1e308 within one period
        return np.array([np.inf, 0.0], dtype=complex)
    return np.linalg.eigvals(M)


def multipliers_stable(multipliers: np.ndarray, dissipative: bool) -> bool:
    """The verdict of :func:`shoot_table` on Floquet multipliers: all ``|λ| < 1`` with
    damping; without, the pair on the unit circle (``|λ₁ + λ₂| = |tr M| < 2``)."""
    lam = np.asarray(multipliers)
    if dissipative:
        return bool(np.all(np.abs(lam) < 1))
    return bool(abs(np.sum(lam).real) < 2)


# --- a system's orbit known as a Fourier sum: the monodromy of its variational equation -------

def variational_multipliers(gx: np.ndarray, gv: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Floquet multipliers of ``ξ̈ + ∂g/∂ẋ ξ̇ + ∂g/∂x ξ = 0`` about orbits of period ``2π/ω``
    (``ẍ + g(x, ẋ) = d cos ωt`` linearised), many orbits at once: ``gx``, ``gv`` of shape
    ``(P, S, n, n)`` sampled at ``θ = ωt = 2πj/S`` (``S`` divisible by 4).  The monodromy of
    ``(ξ, ξ̇)`` over ``θ ∈ [0, 2π]`` by RK4 on the samples (steps of ``4π/S``, the odd samples
    the midpoints), Richardson-combined with steps twice as long: ``(P, 2n)`` eigenvalues."""
    P, S, n, _ = gx.shape
    if S % 4:
        raise ValueError("variational_multipliers: the samples must be divisible by 4")
    w = np.asarray(omega, dtype=float).reshape(P, 1, 1, 1)
    A = np.zeros((P, S, 2 * n, 2 * n))
    A[:, :, :n, n:] = np.eye(n) / w
    A[:, :, n:, :n] = -gx / w
    A[:, :, n:, n:] = -gv / w

    def monodromy(stride: int) -> np.ndarray:
        h = 2 * np.pi * 2 * stride / S
        Y = np.broadcast_to(np.eye(2 * n), (P, 2 * n, 2 * n)).copy()
        for j in range(0, S, 2 * stride):
            a0, a1, a2 = A[:, j], A[:, j + stride], A[:, (j + 2 * stride) % S]
            k1 = a0 @ Y
            k2 = a1 @ (Y + 0.5 * h * k1)
            k3 = a1 @ (Y + 0.5 * h * k2)
            k4 = a2 @ (Y + h * k3)
            Y = Y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        return Y

    with np.errstate(over="ignore", invalid="ignore"):
        fine, coarse = monodromy(1), monodromy(2)
        M = fine + (fine - coarse) / 15
    out = np.full((P, 2 * n), np.inf, dtype=complex)
    ok = np.all(np.isfinite(M), axis=(1, 2))
    if np.any(ok):
        out[ok] = np.linalg.eigvals(M[ok])
    return out
