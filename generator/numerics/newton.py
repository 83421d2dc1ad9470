"""The one Newton's method for a system ``R(x) = 0``, with its Jacobian or by central
differences (the fold variant): the balance of any polynomial force (eq. 10.60 one of them),
the continuation's fixed-ω polish, the folds of the one-harmonic amplitude and of the true
orbit all solve through it."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

DIFFERENCE_STEP = 1e-7
# NOTE: the central difference's step, relative to 1 + |x_k|: its truncation error ~1e-14 and
# its rounding ~1e-16/1e-7 = 1e-9 relative balance near the cube root of the double epsilon;
# Newton's quadratic convergence only needs the Jacobian to a few digits.


def difference_jacobian(residual: Callable[[np.ndarray], np.ndarray],
                        x: np.ndarray) -> np.ndarray:
    """``∂R/∂x`` by central differences, column by column (steps DIFFERENCE_STEP·(1 + |x_k|))."""
    columns = []
    for k in range(len(x)):
        e = np.zeros(len(x))
        e[k] = DIFFERENCE_STEP * (1 + abs(x[k]))
        columns.append((residual(x + e) - residual(x - e)) / (2 * e[k]))
    return np.column_stack(columns)


def newton(residual: Callable[[np.ndarray], np.ndarray],
           jacobian: Callable[[np.ndarray], np.ndarray] | None, x: np.ndarray,
           tol: float = 1e-13, max_iter: int = 50) -> tuple[np.ndarray, bool, float]:
    """Newton's method from ``x``: ``(x, converged, max |R(x)|)``.  Converged when a step is
    at most ``tol`` of ``1 + max |x|``; it stops without converging at a singular Jacobian (a
    fold: no isolated root there), a step that overflows or is not finite (a residual that
    answers NaN outside its domain stops it), or after ``max_iter`` steps.  ``jacobian``
    ``None``: :func:`difference_jacobian` (the folds, where ``R`` holds a determinant or a
    derivative and its own Jacobian is not at hand)."""
    if jacobian is None:
        def jacobian(z: np.ndarray) -> np.ndarray:
            return difference_jacobian(residual, z)
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
