"""The one power-series toolkit (algebra.resum): reciprocal, square root, composition, Horner
(exact and in floats), partial sums and the radius, each against an independent reference,
over the rationals (Fraction) and over the quadratic number field Q(√2)."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp
from flint import fmpq, fmpq_mpoly_ctx
from lindstedt.algebra.resum import (
    binomial_series,
    horner_exact,
    horner_float,
    nearest_singularity,
    partial_sum,
    ring_inverse,
    series_compose,
    series_mul,
    series_radius,
    series_reciprocal,
    series_sqrt,
)
from sympy.polys.domains import QQ

N = 12
K = QQ.algebraic_field(sp.sqrt(2))
ROOT2 = K.convert(sp.sqrt(2))


def field(x: Fraction | int) -> object:
    """A rational as an element of Q(√2)."""
    x = Fraction(x)
    return K.convert(sp.Rational(x.numerator, x.denominator))


def half_binomial(k: int) -> Fraction:
    """``binom(1/2, k) = (−1)^(k+1) C(2k, k) / (4^k (2k − 1))``, the closed form."""
    return Fraction((-1) ** (k + 1) * math.comb(2 * k, k), 4**k * (2 * k - 1))


def test_reciprocal_of_the_geometric_series_is_one_minus_x():
    assert series_reciprocal([Fraction(1)] * N) == [1, -1] + [0] * (N - 2)
    assert series_reciprocal([K.one] * N) == [K.one, -K.one] + [K.zero] * (N - 2)


def test_reciprocal_with_another_constant_term_and_a_given_length():
    # 1/(2 + x) = Σ (−1)^k x^k / 2^(k+1)
    got = series_reciprocal([Fraction(2), Fraction(1)], N)
    assert got == [Fraction((-1) ** k, 2 ** (k + 1)) for k in range(N)]
    # 1/(1 − √2 x) = Σ (√2)^k x^k
    got = series_reciprocal([K.one, -ROOT2], N)
    assert got == [ROOT2**k for k in range(N)]


def test_reciprocal_times_the_series_is_one():
    a = [Fraction(k * k + 1, k + 2) for k in range(N)]
    assert series_mul(a, series_reciprocal(a)) == [1] + [0] * (N - 1)


def test_square_root_of_one_plus_x_has_the_binomial_coefficients():
    expected = [half_binomial(k) for k in range(N)]
    assert series_sqrt([Fraction(1), Fraction(1)], N) == expected
    assert binomial_series(Fraction(1, 2), N) == expected
    # √(1 + √2 x) = Σ binom(1/2, k) (√2)^k x^k
    got = series_sqrt([K.one, ROOT2], N)
    assert got == [field(c) * ROOT2**k for k, c in enumerate(expected)]


def test_square_root_with_a_given_root_squares_back():
    a = [Fraction(4), Fraction(1), Fraction(-3, 7)] + [Fraction(0)] * (N - 3)
    s = series_sqrt(a, root=Fraction(2))
    assert s[:2] == [2, Fraction(1, 4)]  # 2√(1 + x/4 − …) = 2 + x/4 + …
    assert series_mul(s, s) == a
    b = [field(2), ROOT2] + [K.zero] * (N - 2)  # √(2 + √2 x) = √2 · √(1 + x/√2)
    s = series_sqrt(b, root=ROOT2)
    assert series_mul(s, s) == b


def test_square_root_refuses_a_constant_term_other_than_one_without_its_root():
    with pytest.raises(ValueError):
        series_sqrt([Fraction(4), Fraction(1)])


def exp_series(n: int) -> list[Fraction]:
    return [Fraction(1, math.factorial(k)) for k in range(n)]


def test_composition_of_exp_and_log_is_one_plus_x():
    log1p = [Fraction(0)] + [Fraction((-1) ** (k + 1), k) for k in range(1, N)]
    assert series_compose(exp_series(N), log1p) == [1, 1] + [0] * (N - 2)


def test_composition_of_exp_with_a_multiple_of_x():
    # exp(3x): 3^k / k!, by FLINT's Horner (rationals) and by the power sum (a tidy given)
    inner = [Fraction(0), Fraction(3)] + [Fraction(0)] * (N - 2)
    expected = [Fraction(3**k, math.factorial(k)) for k in range(N)]
    assert series_compose(exp_series(N), inner) == expected
    assert series_compose(exp_series(N), inner, tidy=lambda c: c) == expected
    # exp(√2 x) over Q(√2): (√2)^k / k!
    inner = [K.zero, ROOT2] + [K.zero] * (N - 2)
    got = series_compose([field(c) for c in exp_series(N)], inner)
    assert got == [ROOT2**k * field(Fraction(1, math.factorial(k))) for k in range(N)]


def test_composition_of_the_geometric_series_with_x_over_one_plus_x():
    # 1/(1 − y), y = x/(1 + x): (1 + x), exactly
    inner = [Fraction(0)] + [Fraction((-1) ** (k + 1)) for k in range(1, N)]
    assert series_compose([Fraction(1)] * N, inner) == [1, 1] + [0] * (N - 2)
    # the truncation to fewer terms than the outer series
    assert series_compose([Fraction(1)] * N, inner, 4) == [1, 1, 0, 0]


def test_composition_refuses_an_inner_series_with_a_constant_term():
    with pytest.raises(ValueError):
        series_compose([Fraction(1)] * 3, [Fraction(1), Fraction(1)])


def test_horner_exact_is_the_sum_of_the_terms():
    coeffs = [Fraction(3, k + 1) * (-1) ** k for k in range(N)]
    x = Fraction(-5, 7)
    assert horner_exact(coeffs, x) == sum(c * x**k for k, c in enumerate(coeffs))
    coeffs = [field(k) + ROOT2 * field(Fraction(1, k + 1)) for k in range(N)]
    x = field(Fraction(1, 3)) - ROOT2
    total = K.zero
    for k, c in enumerate(coeffs):
        total = total + c * x**k
    assert horner_exact(coeffs, x) == total


def test_horner_float_matches_numpy_polyval():
    coeffs = [Fraction(1, k + 1) * (-2) ** (k % 3) for k in range(N)]
    x = np.linspace(-1.5, 1.5, 101)
    expected = np.polyval([float(c) for c in reversed(coeffs)], x)
    assert np.array_equal(horner_float(coeffs, x), expected)


def test_partial_sum_of_the_geometric_series():
    total, error, best = partial_sum([Fraction(1)] * N, 0.5)
    assert total == pytest.approx(2 - 0.5 ** (N - 1), abs=1e-15)
    assert error == pytest.approx(0.5 ** (N - 2) + 0.5 ** (N - 1))
    assert best == N - 1  # the terms keep falling: the last order is the best


def test_radius_of_known_series():
    # 1/(1 − x/3): one real singularity at 3
    assert series_radius([Fraction(1, 3**k) for k in range(30)]) == pytest.approx(3, rel=1e-6)
    # √(1 − x/2): a branch point at 2 (Domb–Sykes' line in 1/n)
    root = series_sqrt([Fraction(1), Fraction(-1, 2)], 40)
    assert series_radius(root) == pytest.approx(2, rel=1e-3)
    # 1/(1 + x²/4): even, read in x², the pair ±2i at radius 2 in x
    even = [Fraction((-1) ** (k // 2), 4 ** (k // 2)) if k % 2 == 0 else Fraction(0)
            for k in range(40)]
    assert series_radius(even) == pytest.approx(2, rel=1e-6)
    assert nearest_singularity(even, "x").variable == "x**2"
    # too short: no estimate
    assert series_radius([Fraction(1)] * 5) == math.inf


def test_ring_inverse_over_each_ground():
    assert ring_inverse(3) == Fraction(1, 3)
    assert ring_inverse(Fraction(2, 3)) == Fraction(3, 2)
    assert ring_inverse(fmpq(5, 7)) == fmpq(7, 5)
    assert ring_inverse(ROOT2) * ROOT2 == K.one
    ctx = fmpq_mpoly_ctx.get(("_C", "a"), "lex")
    assert ring_inverse(ctx.constant(4)) * 4 == ctx.constant(1)
    ring = QQ.algebraic_field(sp.sqrt(3))[sp.Symbol("a")]
    assert ring_inverse(ring(2)) * 2 == ring.one
