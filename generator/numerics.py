"""Exact and high-accuracy references: elliptic-integral periods, the Jacobi-cn solution."""

from __future__ import annotations

import numpy as np
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
