"""The one Newton's method for a system ``R(x) = 0`` with its Jacobian: the balance of the
notes' Duffing, of any polynomial force, and the continuation's fixed-ω polish all solve
through it."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def newton(residual: Callable[[np.ndarray], np.ndarray],
           jacobian: Callable[[np.ndarray], np.ndarray], x: np.ndarray, tol: float = 1e-13,
           max_iter: int = 50) -> tuple[np.ndarray, bool, float]:
    """Newton's method from ``x``: ``(x, converged, max |R(x)|)``.  Converged when a step is
    at most ``tol`` of ``1 + max |x|``; it stops without converging at a singular Jacobian (a
    fold: no isolated root there), a step that overflows, or after ``max_iter`` steps."""
    x = np.array(x, dtype=float)
    converged = False
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(max_iter):
            try:
                step = np.linalg.solve(jacobian(x), -residual(x))
            except np.linalg.LinAlgError:  # singular: exactly at a fold
                break
            if not np.all(np.isfinite(step)):  # diverged (overflow)
                break
            x = x + step
            if np.max(np.abs(step)) <= tol * (1 + np.max(np.abs(x))):
                converged = True
                break
        size = float(np.max(np.abs(residual(x))))
    return x, bool(converged and np.isfinite(size)), size
