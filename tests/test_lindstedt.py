"""L–P engine against independent references: elliptic-integral series, the notes, residuals."""

from __future__ import annotations

from fractions import Fraction

import pytest
import sympy as sp
from lindstedt.derive.lindstedt import (
    derive,
    naive_expansion,
    naive_expression,
    omega_coefficients,
    order_equation,
    period_series,
    q_expression,
)
from lindstedt.derive.models import A, duffing, eps, pendulum, polynomial, t
from lindstedt.errors import InputError
from reference import duffing_period, pendulum_period, reciprocal


def fractions(sol, key):
    return [sol.ground.to_fraction(c) for c in getattr(sol, key)]


@pytest.fixture(scope="module")
def duffing40():
    return derive(duffing(), 40)


def test_duffing_period_and_frequency_equal_elliptic_series(duffing40):
    exact = duffing_period(40)
    assert fractions(duffing40, "period") == exact
    assert fractions(duffing40, "omega") == reciprocal(exact)


def test_pendulum_period_and_frequency_equal_elliptic_series():
    sol = derive(pendulum(32), 32)
    exact = pendulum_period(32)
    assert fractions(sol, "period") == exact
    assert fractions(sol, "omega") == reciprocal(exact)


def test_notes_first_and_second_order(duffing40):
    s = sp.Symbol("s")
    w1, w2 = sp.Rational(3, 8) * A**2, -sp.Rational(21, 256) * A**4
    assert omega_coefficients(duffing40)[1:3] == [w1, w2]
    q1 = -A**3 / 32 * (sp.cos(s) - sp.cos(3 * s))
    q2 = A**5 / 1024 * (23 * sp.cos(s) - 24 * sp.cos(3 * s) + sp.cos(5 * s))
    assert sp.expand(q_expression(duffing40, 1) - q1) == 0
    assert sp.expand(q_expression(duffing40, 2) - q2) == 0
    # T ≅ 2π(1 - 3εA²/8 + 57(εA²)²/256) (notes, after eq. for ω_2)
    T = sp.expand(period_series(derive(duffing(), 2)))
    assert sp.expand(2 * sp.pi * (1 - sp.Rational(3, 8) * eps * A**2
                                       + sp.Rational(57, 256) * eps**2 * A**4)) == T


def _taylor_sin(order):
    """sin(θ₀u)/θ₀ − u = Σ_k (−1)^k θ₀^(2k) u^(2k+1)/(2k+1)!, term k at order k of θ₀²."""
    return tuple(((2 * k + 1, sp.Rational((-1) ** k, sp.factorial(2 * k + 1))),)
                 for k in range(1, order + 1))


def _residual_polynomial(model, order, forcing=None):
    """ω² u'' + u + Σ y^k P_k(u) as a polynomial in (y, C = cos s), by SymPy's Poly alone.

    ``cos ns`` is Chebyshev's ``T_n(C)`` and ``(cos ns)'' = -n² cos ns``.
    """
    sol = derive(model, order)
    y, C = sp.symbols("y C")
    g = sol.ground.to_sympy

    def poly(expr):
        return sp.Poly(expr, y, C, domain="QQ")

    cheb = {n: poly(sp.chebyshevt(n, C)) for qj in sol.q for n in qj}
    zero = poly(0)
    u = sum((poly(y**j) * cheb[n] * g(c) for j, qj in enumerate(sol.q)
             for n, c in qj.items()), zero)
    upp = sum((poly(y**j) * cheb[n] * (-n * n * g(c)) for j, qj in enumerate(sol.q)
               for n, c in qj.items()), zero)
    omega = sum((poly(y**j) * g(w) for j, w in enumerate(sol.omega)), zero)
    force = sum((poly(y**k) * (u**n) * c for k, terms in enumerate(forcing or model.forcing, 1)
                 for n, c in terms), zero)
    return omega**2 * upp + u + force, y


@pytest.mark.parametrize("model,order,forcing", [(duffing(), 6, None),
                                                 (pendulum(5), 5, _taylor_sin(5))])
def test_residual_is_exactly_of_next_order(model, order, forcing):
    poly, _y = _residual_polynomial(model, order, forcing)
    by_power: dict[int, list] = {}
    for (py, _), c in poly.terms():
        by_power.setdefault(py, []).append(c)
    assert min(by_power) == order + 1  # orders 0..K vanish identically
    assert any(c != 0 for c in by_power[order + 1])


def test_initial_conditions_amplitude_convention(duffing40):
    for j, qj in enumerate(duffing40.q):
        total = sum(duffing40.ground.to_fraction(c) for c in qj.values())
        assert total == (1 if j == 0 else 0)  # q_j(0) = 0 for j ≥ 1


def test_secular_condition_vanishes_and_equation_holds_at_every_order():
    sol = derive(duffing(), 6)
    s = sp.Symbol("s")
    for j in range(1, 7):
        eq = order_equation(sol, j)
        omega_j = eq.omega.lhs
        assert eq.secular_condition.lhs.subs(omega_j, eq.omega.rhs).expand() == 0
        F = eq.equation.rhs.subs(omega_j, eq.omega.rhs)
        qj = eq.solution.rhs
        # q_j'' + q_j = F_j, and F_j has no cos s left (the secular term is gone)
        assert sp.expand(sp.diff(qj, s, 2) + qj - F) == 0
        assert sp.expand(F).coeff(sp.cos(s)) == 0


def test_notes_second_order_forcing():
    """F_2 = -3q0²q1 + 2(q1 + q0³)ω1 + q0(2ω2 - 3ω1²) is what the engine's F_2 must equal."""
    sol = derive(duffing(), 2)
    s = sp.Symbol("s")
    eq = order_equation(sol, 2)
    w1, w2 = sp.Rational(3, 8) * A**2, sp.Symbol("omega_2")
    q0, q1 = A * sp.cos(s), -A**3 / 32 * (sp.cos(s) - sp.cos(3 * s))
    notes = -3 * q0**2 * q1 + 2 * (q1 + q0**3) * w1 + q0 * (2 * w2 - 3 * w1**2)
    assert sp.expand(sp.expand_trig(sp.expand(notes - eq.equation.rhs))) == 0


def test_naive_first_order_matches_notes():
    naive = naive_expansion(duffing(), 4)
    q1 = -A**3 * (sp.Rational(3, 8) * t * sp.sin(t) + (sp.cos(t) - sp.cos(3 * t)) / 32)
    assert sp.expand(naive_expression(naive, 1) - q1) == 0
    for j in range(1, 5):  # secular t^j·sin|cos at order j
        assert max(m for m, _, _ in naive.terms[j]) == j


def test_naive_expansion_solves_successive_approximation():
    K = 4
    naive = naive_expansion(duffing(), K)
    q = sum(eps**j * naive_expression(naive, j) for j in range(K + 1))
    res = sp.expand(sp.diff(q, t, 2) + q + eps * q**3)
    for j in range(K + 1):
        assert sp.simplify(sp.expand_trig(res.coeff(eps, j))) == 0
    assert sp.simplify(q.subs(t, 0) - A) == 0
    assert sp.simplify(sp.diff(q, t).subs(t, 0)) == 0


def test_polynomial_force_symbolic_coefficients():
    """q̈ + q + αq² + βq³: ω = 1 + (3β/8 - 5α²/12)A² (Landau & Lifshitz §28), ε = 1."""
    al, be = sp.symbols("alpha beta")
    sol = derive(polynomial({2: al, 3: be}), 2)
    omegas = omega_coefficients(sol)
    total = sp.expand(sum(omegas)).coeff(A, 2)
    assert sp.simplify(total - (sp.Rational(3, 8) * be - sp.Rational(5, 12) * al**2)) == 0


def test_single_power_polynomial_is_duffing():
    sol = derive(polynomial({3: 1}), 10)
    assert fractions(sol, "period") == duffing_period(10)
    assert polynomial({3: 1}).variable == "y = eps*A**2"


@pytest.mark.parametrize("bad", [-1, 1.5, "3", True, None])
def test_bad_order(bad):
    with pytest.raises(InputError, match="order"):
        derive(duffing(), bad)


@pytest.mark.parametrize("coeffs", [{3: float("nan")}, {3: float("inf")}, {1: 1}, {}, {3: "1"}])
def test_bad_polynomial_force(coeffs):
    with pytest.raises(InputError):
        polynomial(coeffs)


def test_order_zero():
    sol = derive(duffing(), 0)
    assert fractions(sol, "omega") == [Fraction(1)]
    assert sol.q[0] == {1: sol.ground.scalar(1)}


def test_a_model_too_small_for_the_order_is_refused():
    """A Taylor-expanded force built for order 4 holds its terms to q⁹ only: its order-8 series
    would be wrong from j = 5 on, so derive refuses.  The pendulum's sin is summed by
    recurrence, exact at every order: pendulum(4) to order 8 gives the elliptic-integral
    coefficients."""
    from lindstedt.derive.models import model_from_text

    with pytest.raises(InputError, match=r"order 8: the oscillator model holds .* to order 4"):
        derive(model_from_text("q'' + q*exp(-q**2) = 0", 4), 8)
    exact = pendulum_period(8)
    for model in (pendulum(8), pendulum(4), model_from_text("theta'' + sin(theta) = 0", 8)):
        got = derive(model, 8)
        assert [got.ground.to_fraction(c) for c in got.period] == exact


@pytest.mark.parametrize("text,order", [("x'' + 4*x + eps*x**3 = 0", 3),
                                        ("q'' + q + eps*(q**2 + q**3) = 0", 3)])
def test_the_solution_in_sympy_satisfies_its_equation(text, order):
    """``solution.q_expr()``, ``omega_expr()``, ``period_expr()``: SymPy in one call, in the
    equation's own symbols.  Checked against the equation itself: q(t) put into it leaves a
    residual whose ε-series vanishes through ε^K (at a rational A and t, 50 digits), q(0) = A,
    q̇(0) = 0, and ω·T = 2π through ε^K; ``repr`` reads as mathematics, no FLINT text."""
    from lindstedt.derive.lindstedt import derive
    from lindstedt.derive.models import series_model

    sol = derive(series_model(text, order, {}, None), order)
    m = sol.model
    e, a, time = sp.Symbol("eps"), m.amplitude, sp.Symbol("t")
    q, omega, period = sol.q_expr(), sol.omega_expr(), sol.period_expr()
    assert {str(v) for v in q.free_symbols} == {"A", "eps", "t"}
    w0sq = 4 if text.startswith("x") else 1
    cubic = text.startswith("x")
    residual = sp.diff(q, time, 2) + w0sq * q + e * (q**3 if cubic else q**2 + q**3)
    at = {a: sp.Rational(1, 2), time: sp.Rational(7, 5)}

    def size(expr: sp.Expr, small: sp.Rational) -> float:
        return abs(float(sp.N(expr.subs({**at, e: small}), 60)))

    # an O(ε^(K+1)) residual: ten times smaller ε, 10^(K+1) times smaller (within 1 %)
    for expr in (residual, omega * period - 2 * sp.pi):
        big, small = size(expr, sp.Rational(1, 10**6)), size(expr, sp.Rational(1, 10**7))
        assert abs(big / small / 10 ** (order + 1) - 1) < 0.01, (big, small)
    for e_value in (sp.Rational(1, 7), sp.Rational(-1, 3)):
        start = {time: 0, a: sp.Rational(1, 2), e: e_value}
        assert abs(sp.N(q.subs(start) - sp.Rational(1, 2), 60)) < 1e-50
        assert abs(sp.N(sp.diff(q, time).subs(start), 60)) < 1e-50
    text_repr = repr(sol)
    assert text_repr.startswith(f"<{m.name}: L–P series to order {order}") and "^" not in text_repr
    assert str(sol) == text_repr
