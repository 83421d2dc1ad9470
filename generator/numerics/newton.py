"""The one Newton's method of the package and its variants.

* :func:`iterate`, the core: Newton's method on ``R(x) = 0`` from ``evaluate(x) -> (R, J)``
  (one evaluation gives both: a flow gives the residual and the monodromy together), with an
  :class:`Iteration` record of how it stopped;
* :func:`newton`, ``(residual, jacobian)`` apart or the Jacobian by central differences (the
  fold variant, :func:`difference_jacobian`): the balance of any polynomial force (eq. 10.60
  one of them), the continuation's fixed-ω polish, the folds of the one-harmonic amplitude and
  of the true orbit;
* :func:`bordered`, ``R`` and ``J`` augmented by the row ``t·(x − x₀) = 0``: the
  pseudo-arclength corrector of the continuation;
* :func:`secant`, a scalar root without its derivative: the plain secant (a fold along the
  continuation's tangent, the return map of a limit cycle) or, ``bracketed``, Illinois' false
  position kept inside its bracket with a bisection fallback (a multiplier's crossing of the
  unit circle);
* :func:`safeguarded`, vectorised scalar Newton on many roots at once, each step clipped to
  its root's bracket (the one-harmonic cubic's roots, a polynomial's roots polished).

Every hand-written root iteration of the package goes through these; the few that stay apart
say why in a NOTE beside them."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

DIFFERENCE_STEP = 1e-7
# NOTE: the central difference's step, relative to 1 + |x_k|: its truncation error ~1e-14 and
# its rounding ~1e-16/1e-7 = 1e-9 relative balance near the cube root of the double epsilon;
# Newton's quadratic convergence only needs the Jacobian to a few digits.

STOPS = ("converged", "singular", "not finite", "max_iter")


@dataclass(frozen=True)
class Iteration:
    """How an iteration ended.  ``x``: the last iterate (a step that was not finite is not
    taken); ``residual``: ``max |R|`` of the last evaluation, at the iterate before the last
    step (nothing is evaluated after it: NaN when nothing was); ``steps``: the steps taken;
    ``step``: ``max |Δx|`` of the last step tried (NaN before any); ``why``: one of
    :data:`STOPS` — "converged" (a step at most ``tol`` of ``1 + max |x|``), "singular" (the
    Jacobian, or the secant's slope, is singular: no step), "not finite" (a step or a value
    overflowed or is NaN), "max_iter"."""

    x: np.ndarray | float
    converged: bool
    residual: float
    steps: int
    step: float
    why: str


def _dense_solve(J: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    return np.linalg.solve(J, rhs)


def sparse_solve(J, rhs: np.ndarray, refine: int = 0) -> np.ndarray:
    """``J⁻¹ rhs`` for a sparse ``J`` (SuperLU; a dense one by LAPACK), with ``refine`` steps
    of iterative refinement (the residual's correction by the same factors: a stiff
    structure's L(s), conditioned like 1e12, loses digits to the factorization otherwise); a
    singular ``J`` raises ``LinAlgError``."""
    if isinstance(J, np.ndarray):
        return np.linalg.solve(J, rhs)
    from scipy.sparse.linalg import splu  # here: a dense J needs no SciPy (start-up)

    J = J.tocsc()
    try:
        lu = splu(J)
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise np.linalg.LinAlgError(str(exc)) from None
    x = lu.solve(rhs)
    for _ in range(refine):
        x = x + lu.solve(rhs - J @ x)
    return x


def iterate(evaluate: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], x: np.ndarray,
            tol: float = 1e-13, max_iter: int = 50,
            solve: Callable[[np.ndarray, np.ndarray], np.ndarray] = _dense_solve) -> Iteration:
    """Newton's method on ``R(x) = 0`` from ``x``, ``evaluate(x)`` giving ``(R(x), ∂R/∂x)``:
    ``x ← x + Δ``, ``J Δ = −R``, until ``max |Δ| ≤ tol·(1 + max |x|)`` (after the step),
    a singular ``J``, a step not finite, or ``max_iter`` steps.  A caller whose evaluation
    meets a domain event (a trajectory that escapes, an integrator that fails) raises from
    ``evaluate``; it passes through.  A complex ``x`` stays complex (an eigenpair); ``solve``
    takes ``(J, −R)`` (:func:`sparse_solve` for a sparse ``J``: nothing n² is formed)."""
    x = np.array(x, dtype=complex if np.iscomplexobj(x) else float)
    residual, size, steps, why = math.nan, math.nan, 0, "max_iter"
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(max_iter):
            R, J = evaluate(x)
            residual = float(np.max(np.abs(R)))
            try:
                step = solve(J, -R)
            except np.linalg.LinAlgError:  # singular: exactly at a fold
                why = "singular"
                break
            size = float(np.max(np.abs(step)))
            if not np.all(np.isfinite(step)):  # diverged (overflow)
                why = "not finite"
                break
            x = x + step
            steps += 1
            if size <= tol * (1 + np.max(np.abs(x))):
                why = "converged"
                break
    return Iteration(x, why == "converged", residual, steps, size, why)


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
    """:func:`iterate` from ``x``: ``(x, converged, max |R(x)|)``, the residual evaluated at
    the root returned.  It stops without converging at a singular Jacobian (a fold: no
    isolated root there), a step that overflows or is not finite (a residual that answers NaN
    outside its domain stops it), or after ``max_iter`` steps.  ``jacobian`` ``None``:
    :func:`difference_jacobian` (the folds, where ``R`` holds a determinant or a derivative
    and its own Jacobian is not at hand)."""
    if jacobian is None:
        def jacobian(z: np.ndarray) -> np.ndarray:
            return difference_jacobian(residual, z)

    def evaluate(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        J = jacobian(z)
        return residual(z), J

    run = iterate(evaluate, x, tol, max_iter)
    with np.errstate(over="ignore", invalid="ignore"):
        size = float(np.max(np.abs(residual(run.x))))
    return run.x, bool(run.converged and np.isfinite(size)), size


def bordered(evaluate: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
             row: np.ndarray, x: np.ndarray, tol: float = 1e-13,
             max_iter: int = 30) -> Iteration:
    """:func:`iterate` on ``R(x) = 0`` bordered by ``row·(x − x₀) = 0`` (``x₀`` the start):
    ``evaluate`` gives ``R`` (n values) and its ``n × (n + 1)`` Jacobian, the border makes it
    square — the pseudo-arclength corrector, ``row`` the tangent, ``x₀`` the predictor."""
    start = np.array(x, dtype=float)
    row = np.asarray(row, dtype=float)

    def augmented(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        R, J = evaluate(z)
        return np.append(R, row @ (z - start)), np.vstack([J, row])

    return iterate(augmented, start, tol, max_iter)


def secant(f: Callable[[float], float], a: float, b: float, fa: float, fb: float,
           tol: float = 0.0, ftol: float = 0.0, max_iter: int = 50,
           bracketed: bool = False) -> Iteration:
    """A root of the scalar ``f`` from ``(a, f(a))`` and ``(b, f(b))`` (given: the caller
    often has them): each new point ``s = b − f(b)(b − a)/(f(b) − f(a))``.  Plain: the last
    two points carried (the secant method).  ``bracketed`` (``a < b``, ``f(a)``, ``f(b)`` of
    opposite signs): Illinois' false position — ``s`` replaces the end of its sign and the
    end kept twice in a row has its value halved — with ``s`` at the midpoint where it falls
    outside ``(a, b)`` or the values are equal.  Converged where ``|f(s)| ≤ ftol`` or
    ``|s − previous point| ≤ tol·(1 + |s|)``; "singular" where the plain secant's two values
    are equal, "not finite" where ``f(b)`` or a value is not finite (that point kept as
    ``x``: a caller's ``f`` may return NaN for a failed evaluation).  ``x`` is the last point
    evaluated (``b`` if none), ``residual`` its ``|f|``, ``step`` its distance from the point
    before."""
    a, b, fa, fb = float(a), float(b), float(fa), float(fb)
    x, fx, size, steps, why, side = b, fb, math.nan, 0, "max_iter", 0
    if not math.isfinite(fb):
        return Iteration(x, False, abs(fx), 0, size, "not finite")
    for _ in range(max_iter):
        if bracketed:
            s = b - fb * (b - a) / (fb - fa) if fb != fa else 0.5 * (a + b)
            if not a < s < b:
                s = 0.5 * (a + b)
        elif fb == fa:
            why = "singular"
            break
        else:
            s = b - fb * (b - a) / (fb - fa)
        fs = float(f(s))
        size, x, fx = abs(s - x), s, fs
        steps += 1
        if not bracketed:
            a, fa, b, fb = b, fb, s, fs
        if not math.isfinite(fs):
            why = "not finite"
            break
        if abs(fs) <= ftol or size <= tol * (1 + abs(s)):
            why = "converged"
            break
        if not bracketed:
            continue
        if (fs > 0) == (fa > 0):  # Illinois: halve the end kept twice
            a, fa = s, fs
            if side == -1:
                fb /= 2
            side = -1
        else:
            b, fb = s, fs
            if side == 1:
                fa /= 2
            side = 1
    return Iteration(x, why == "converged", abs(fx), steps, size, why)


def safeguarded(evaluate: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]],
                x: np.ndarray, lo: np.ndarray | float = -math.inf,
                hi: np.ndarray | float = math.inf, max_iter: int = 200) -> np.ndarray:
    """Scalar Newton's method on many roots at once, each kept inside its bracket ``[lo, hi]``
    (each step clipped to it; a zero slope does not move), each until its moves stop
    shrinking or reach rounding (``≤ 2⁻⁵² x``), or after ``max_iter`` steps; ``evaluate(i,
    x)`` gives the value and the slope of the roots ``i`` (indices into ``x``) at ``x``.
    From inside a piece where the function is monotone and of one curvature it converges
    monotonically (after at most one step)."""
    x = np.array(x, dtype=float)
    lo = np.broadcast_to(np.asarray(lo, dtype=float), x.shape)
    hi = np.broadcast_to(np.asarray(hi, dtype=float), x.shape)
    todo = np.arange(x.size)  # the roots still moving
    moved = np.full(x.shape, np.inf)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for _ in range(max_iter):
            if not todo.size:
                break
            xt = x[todo]
            value, slope = evaluate(todo, xt)
            new = np.clip(xt - np.where(slope != 0, value / slope, 0.0), lo[todo], hi[todo])
            move = np.abs(new - xt)
            x[todo] = new
            going = (move > 2.0**-52 * new) & (move < moved[todo])
            moved[todo] = move
            todo = todo[going]
    return x
