"""Exact and high-accuracy references: elliptic-integral periods, the Jacobi-cn solution,
periodic orbits of the driven oscillator by shooting, and their Floquet multipliers."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import ArrayLike
from scipy.special import ellipj, ellipk


def duffing_period_exact(A: ArrayLike, eps: ArrayLike) -> np.ndarray:
    """``T = 4K(m)/√(1+x)``, ``m = x/(2(1+x))``, ``x = εA²`` (notes App. 4.9); NaN for x ≤ -1.

    SciPy's ``ellipk`` takes any ``m < 1``, so softening springs (``-1 < x < 0``, ``m < 0``)
    are exact too.
    """
    x = np.asarray(eps, dtype=float) * np.asarray(A, dtype=float) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        out = 4 * ellipk(x / (2 * (1 + x))) / np.sqrt(1 + x)
    return np.where(x > -1, out, np.nan)


def duffing_q_exact(t: ArrayLike, A: ArrayLike, eps: ArrayLike) -> np.ndarray:
    """``q(t) = A cn(√(1+x) t | m)`` for ``x = εA² ≥ 0`` (SciPy's ``ellipj`` needs 0 ≤ m ≤ 1)."""
    A = np.asarray(A, dtype=float)
    x = np.asarray(eps, dtype=float) * A**2
    if np.any(x < 0):
        raise ValueError("duffing_q_exact: x = εA² < 0 needs cn with m < 0 (use mpmath)")
    m = x / (2 * (1 + x))
    return A * ellipj(np.sqrt(1 + x) * np.asarray(t, dtype=float), m)[1]


def pendulum_period_exact(theta0: ArrayLike) -> np.ndarray:
    """``T = 4K(sin²(θ₀/2))`` (notes App. 4.1); NaN for ``|θ₀| ≥ π``."""
    th = np.asarray(theta0, dtype=float)
    out = 4 * ellipk(np.sin(th / 2) ** 2)
    return np.where(np.abs(th) < np.pi, out, np.nan)


# --- periodic orbits of the driven oscillator: shooting and Floquet multipliers ---------------

@njit(cache=True)
def _rhs(t: float, y: np.ndarray, eps: float, force: float, omega: float, damping: float,
         out: np.ndarray) -> None:
    """Eq. 10.60 and its variational equation: y = (q, p, M11, M21, M12, M22)."""
    q, p = y[0], y[1]
    out[0] = p
    out[1] = force * np.cos(omega * t) - damping * p - q - eps * q**3
    k = -1.0 - 3.0 * eps * q * q
    for col in range(2):
        a, b = y[2 + 2 * col], y[3 + 2 * col]
        out[2 + 2 * col] = b
        out[3 + 2 * col] = k * a - damping * b


@njit(cache=True)
def _rk4(y0: np.ndarray, t0: float, t1: float, steps: int, eps: float, force: float,
         omega: float, damping: float, samples: int) -> tuple[np.ndarray, np.ndarray]:
    """Classical RK4 with ``steps`` steps; returns the end state and ``samples`` equispaced
    values of q on [t0, t1) (``steps`` must be a multiple of ``samples``)."""
    h = (t1 - t0) / steps
    y = y0.copy()
    k1, k2, k3, k4 = np.empty(6), np.empty(6), np.empty(6), np.empty(6)
    tmp = np.empty(6)
    qs = np.empty(samples)
    every = steps // samples
    for i in range(steps):
        if i % every == 0:
            qs[i // every] = y[0]
        t = t0 + i * h
        _rhs(t, y, eps, force, omega, damping, k1)
        tmp[:] = y + 0.5 * h * k1
        _rhs(t + 0.5 * h, tmp, eps, force, omega, damping, k2)
        tmp[:] = y + 0.5 * h * k2
        _rhs(t + 0.5 * h, tmp, eps, force, omega, damping, k3)
        tmp[:] = y + h * k3
        _rhs(t + h, tmp, eps, force, omega, damping, k4)
        y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return y, qs


STEPS_PER_PERIOD = 4096
# NOTE: RK4 at 4096 and 8192 steps per period, Richardson-combined (error ∝ h⁴ cancels):
# the remaining O(h⁶) is ~1e-13 for the amplitudes of the notes' table.


def flow(y0: np.ndarray, period: float, eps: float, force: float, omega: float,
         damping: float, samples: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """State after one period (with monodromy columns) and q sampled over it, Richardson-
    extrapolated from two RK4 step sizes."""
    state = np.concatenate([y0, [1.0, 0.0, 0.0, 1.0]])
    coarse, qc = _rk4(state, 0.0, period, STEPS_PER_PERIOD, eps, force, omega, damping, samples)
    fine, qf = _rk4(state, 0.0, period, 2 * STEPS_PER_PERIOD, eps, force, omega, damping,
                    samples)
    return fine + (fine - coarse) / 15, qf + (qf - qc) / 15


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit of period ``2π/ω`` found by shooting, with its Floquet multipliers."""

    initial: np.ndarray  # (q(0), q̇(0))
    A: dict[int, float]  # cos nωt coefficients
    B: dict[int, float]  # sin nωt coefficients
    multipliers: np.ndarray
    stable: bool
    residual: float


def shoot(eps: float, force: float, omega: float, damping: float, guess: np.ndarray,
          harmonics: int = 9, tol: float = 1e-12, max_iter: int = 30) -> PeriodicOrbit | None:
    """Newton's method on ``φ_T(y₀) − y₀ = 0`` (the monodromy matrix is its Jacobian + I).

    Stability from the Floquet multipliers: damped, stable when all ``|λ| < 1``; undamped
    (Hamiltonian, ``det M = 1``), linearly stable when the pair lies on the unit circle,
    i.e. ``|tr M| < 2`` (a real pair ``λ, 1/λ`` with ``|tr M| > 2`` is unstable).
    Returns ``None`` when Newton's method does not converge.
    """
    T = 2 * np.pi / omega
    y = np.array(guess, dtype=float)
    for _ in range(max_iter):
        end, _ = flow(y, T, eps, force, omega, damping)
        Mono = end[2:].reshape(2, 2).T
        r = end[:2] - y
        try:
            step = np.linalg.solve(Mono - np.eye(2), -r)
        except np.linalg.LinAlgError:
            return None
        y = y + step
        if np.max(np.abs(step)) < tol * (1 + np.max(np.abs(y))):
            break
    else:
        return None
    end, qs = flow(y, T, eps, force, omega, damping)
    Mono = end[2:].reshape(2, 2).T
    lam = np.linalg.eigvals(Mono)
    stable = bool(np.all(np.abs(lam) < 1) if damping > 0 else abs(np.trace(Mono)) < 2)
    c = np.fft.rfft(qs) / len(qs)
    A = {n: float(2 * c[n].real) for n in range(1, harmonics + 1, 2)}
    B = {n: float(-2 * c[n].imag) for n in range(1, harmonics + 1, 2)}
    return PeriodicOrbit(y, A, B, lam, stable, float(np.max(np.abs(end[:2] - y))))
