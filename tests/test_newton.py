"""The one Newton's method (numerics.newton): the core iteration and its variants against roots
known in closed form, and every way each of them stops."""

from __future__ import annotations

import math

import numpy as np
import pytest
from lindstedt.numerics.newton import (
    STOPS,
    Iteration,
    bordered,
    iterate,
    newton,
    safeguarded,
    secant,
)
from lindstedt.numerics.shooting import ShootingFailure, shoot_explained

# x³ − 2x − 5 = 0, Newton's own example: Cardano's real root
DISC = math.sqrt(25 / 4 - 8 / 27)
CARDANO = math.cbrt(5 / 2 + DISC) + math.cbrt(5 / 2 - DISC)


def cubic(x: float) -> float:
    return x**3 - 2 * x - 5


def circle_and_line(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x² + y² = 4 and x = y: the root (√2, √2)."""
    x, y = z
    return np.array([x * x + y * y - 4, x - y]), np.array([[2 * x, 2 * y], [1.0, -1.0]])


def test_iterate_converges_to_the_closed_form_root_with_its_record():
    seen = []

    def evaluate(z):
        seen.append(z.copy())
        return circle_and_line(z)

    run = iterate(evaluate, [3.0, 1.0], tol=1e-14)
    assert isinstance(run, Iteration) and run.why == "converged" and run.converged
    assert run.x == pytest.approx([math.sqrt(2)] * 2, abs=1e-15)
    # one evaluation a step and none after the last: the residual is the last evaluation's,
    # at the iterate before the last step
    assert len(seen) == run.steps
    assert run.residual == float(np.max(np.abs(circle_and_line(seen[-1])[0])))
    assert run.step == pytest.approx(float(np.max(np.abs(run.x - seen[-1]))), abs=4e-16)
    assert run.step <= 1e-14 * (1 + np.max(np.abs(run.x)))
    assert 3 <= run.steps <= 8  # quadratic from an O(1) start


def test_iterate_stops_at_a_singular_jacobian_before_any_step():
    run = iterate(lambda z: (z**2 - 1, np.diag(2 * z)), [0.0])
    assert (run.why, run.converged, run.steps) == ("singular", False, 0)
    assert run.x.tolist() == [0.0] and run.residual == 1.0 and math.isnan(run.step)


def test_iterate_does_not_take_a_step_that_is_not_finite():
    run = iterate(lambda z: (np.array([1e308]), np.array([[1e-308]])), [2.0])
    assert (run.why, run.converged, run.steps) == ("not finite", False, 0)
    assert run.x.tolist() == [2.0] and math.isinf(run.step)
    nan = iterate(lambda z: (np.array([math.nan]), np.array([[1.0]])), [2.0])
    assert nan.why == "not finite" and nan.x.tolist() == [2.0]


def test_iterate_stops_after_max_iter_steps():
    # x² + 1 has no real root: Newton wanders for ever
    run = iterate(lambda z: (z**2 + 1, np.diag(2 * z)), [0.5], max_iter=7)
    assert (run.why, run.converged, run.steps) == ("max_iter", False, 7)
    assert run.residual >= 1 and math.isfinite(run.step)
    assert iterate(circle_and_line, [3.0, 1.0], max_iter=0).why == "max_iter"
    assert set(STOPS) == {"converged", "singular", "not finite", "max_iter"}


def test_iterate_lets_a_domain_event_raised_by_evaluate_through():
    class Escaped(Exception):
        pass

    def evaluate(z):
        if abs(z[0]) > 10:
            raise Escaped(z[0])
        return z**2 + 1, np.diag(2 * z)  # from 0.01 the first step goes to ~−50

    with pytest.raises(Escaped):
        iterate(evaluate, [0.01])


def test_newton_keeps_its_signature_and_results():
    def residual(z):
        return np.array([cubic(z[0])])

    def jacobian(z):
        return np.array([[3 * z[0] ** 2 - 2]])

    for jac in (jacobian, None):  # the Jacobian given, or by central differences
        x, converged, size = newton(residual, jac, np.array([2.0]))
        assert converged and x[0] == pytest.approx(CARDANO, abs=1e-15)
        assert size == abs(cubic(x[0]))  # evaluated at the root it returns
    x, converged, size = newton(lambda z: z**2 + 1, lambda z: np.diag(2 * z), [0.5],
                                max_iter=5)
    assert not converged and size >= 1
    x, converged, _ = newton(lambda z: z**2 - 1, lambda z: np.diag(2 * z), [0.0])
    assert not converged and x.tolist() == [0.0]  # singular at the start


def test_bordered_finds_the_point_of_the_circle_on_the_hyperplane():
    """x² + y² = 1 bordered by t·(z − z₀) = 0: with t = (1, 0) the point of abscissa z₀'s,
    with t along (1, 1) the circle's point on the line x + y = z₀'s sum."""
    def circle(z):
        return np.array([z @ z - 1]), np.array([2 * z])

    run = bordered(circle, np.array([1.0, 0.0]), [0.6, 0.9])
    assert run.converged and run.x == pytest.approx([0.6, 0.8], abs=1e-15)
    t = np.array([1.0, 1.0]) / math.sqrt(2)
    run = bordered(circle, t, [0.5, 0.9])
    s = 1.4  # x + y = s on the circle: x, y = (s ± √(2 − s²))/2
    assert run.converged
    assert run.x == pytest.approx([(s - math.sqrt(2 - s * s)) / 2,
                                   (s + math.sqrt(2 - s * s)) / 2], abs=1e-15)
    # at (0, 1) bordered by (0, 1) (the border along the circle's normal) the augmented
    # Jacobian [[0, 2], [0, 1]] is singular: no step
    assert bordered(circle, np.array([0.0, 1.0]), [0.0, 1.0]).why == "singular"


def test_secant_finds_the_cubic_root():
    calls = []

    def f(x):
        calls.append(x)
        return cubic(x)

    run = secant(f, 2.0, 2.2, cubic(2.0), cubic(2.2), tol=1e-15)
    assert run.converged and run.why == "converged"
    assert run.x == pytest.approx(CARDANO, abs=1e-15)
    assert len(calls) == run.steps and run.x == calls[-1] and run.residual == abs(cubic(run.x))
    # superlinear: a handful of steps; by the value alone
    by_value = secant(cubic, 2.0, 2.2, cubic(2.0), cubic(2.2), ftol=1e-10)
    assert by_value.converged and by_value.residual <= 1e-10
    assert abs(by_value.x - CARDANO) <= 1e-10


def test_secant_stops_on_equal_values_a_value_not_finite_and_max_iter():
    flat = secant(lambda x: 1.0, 0.0, 1.0, 1.0, 1.0)
    assert (flat.why, flat.steps, flat.x) == ("singular", 0, 1.0)
    broken = secant(lambda x: math.nan, 2.0, 2.2, cubic(2.0), cubic(2.2))
    assert (broken.why, broken.steps, broken.converged) == ("not finite", 1, False)
    assert secant(cubic, 2.0, 2.2, math.inf, math.inf).why == "not finite"
    slow = secant(cubic, 2.0, 2.2, cubic(2.0), cubic(2.2), max_iter=2)
    assert (slow.why, slow.steps) == ("max_iter", 2)


def test_bracketed_secant_stays_inside_its_bracket():
    """Illinois on the cubic from [1, 3] and on a function false position alone crawls on
    (x¹⁰ − 1/2 on [0, 1]: one end would stay put for ever), always inside the bracket."""
    for g, a, b, root in ((cubic, 1.0, 3.0, CARDANO),
                          (lambda x: x**10 - 0.5, 0.0, 1.0, 0.5 ** 0.1)):
        seen = []

        def f(x, g=g, seen=seen):
            seen.append(x)
            return g(x)

        run = secant(f, a, b, g(a), g(b), ftol=1e-14, max_iter=60, bracketed=True)
        assert run.converged and run.x == pytest.approx(root, abs=1e-13)
        assert all(a < x < b for x in seen) and run.steps < 30
    # equal values at both ends: the midpoint (bisection)
    seen = []
    secant(lambda x: seen.append(x) or 1.0, 0.0, 4.0, -1.0, -1.0, max_iter=1, bracketed=True)
    assert seen == [2.0]


def test_safeguarded_newton_on_many_roots_inside_their_brackets():
    c = np.array([2.0, 3.0, 10.0, 0.25])

    def value_slope(i, x):
        return x * x - c[i], 2 * x

    roots = safeguarded(value_slope, np.full(4, 5.0), lo=np.zeros(4), hi=np.full(4, 5.0))
    assert roots == pytest.approx(np.sqrt(c), rel=4e-16)
    # a first step that leaves the bracket is clipped to its end: from 0.1, x² − 2 steps to
    # ~10, clipped to 1.5, then converges from there
    assert safeguarded(lambda i, x: (x * x - 2, 2 * x), [0.1], 0.0, 1.5, max_iter=1)[0] == 1.5
    # a zero slope does not move the root
    assert safeguarded(lambda i, x: (x * x - 2, 0 * x), [1.0])[0] == 1.0
    # at most max_iter steps: one step from 1 on x² − 2 is Newton's 3/2
    assert safeguarded(lambda i, x: (x * x - 2, 2 * x), [1.0], max_iter=1)[0] == 1.5


def test_shooting_reports_newton_running_out_of_steps_as_before():
    failed = shoot_explained(0.1, 0.3, 1.2, 10.0, np.array([0.5, 0.0]), max_iter=1)
    assert isinstance(failed, ShootingFailure) and not failed.escaped
    assert failed.reason.startswith("Newton's method did not converge in 1 iterations (last "
                                    "step ")
    assert failed.reason.endswith(", tolerance 1e-12)")
