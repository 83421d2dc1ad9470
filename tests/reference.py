"""Independent references for the tests: exact series of the elliptic-integral periods.

Nothing here calls the package: the Taylor coefficients come from the hypergeometric series
``K(m) = π/2 Σ [(1/2)_n / n!]² m^n`` with plain ``fractions.Fraction`` arithmetic.
"""

from __future__ import annotations

from fractions import Fraction
from math import factorial


def _k_coefficients(order: int) -> list[Fraction]:
    """``(2/π) K(m) = Σ c_n m^n``, ``c_n = [(2n)! / (4^n n!²)]²``."""
    return [
        Fraction(factorial(2 * n), 4**n * factorial(n) ** 2) ** 2 for n in range(order + 1)
    ]


def _poch(a: Fraction, k: int) -> Fraction:
    out = Fraction(1)
    for i in range(k):
        out *= a + i
    return out


def duffing_period(order: int) -> list[Fraction]:
    """``T/2π`` in ``x = εA²``: ``T = 4K(m)/√(1+x)``, ``m = x/(2(1+x))``.

    ``T/2π = Σ_n c_n (x/2)^n (1+x)^(-n-1/2)``; the binomial series gives each ``x^j``.
    """
    c = _k_coefficients(order)
    out = []
    for j in range(order + 1):
        total = Fraction(0)
        for n in range(j + 1):
            k = j - n
            binom = (-1) ** k * _poch(Fraction(2 * n + 1, 2), k) / factorial(k)
            total += c[n] * Fraction(1, 2**n) * binom
        out.append(total)
    return out


def _mul(a: list[Fraction], b: list[Fraction], order: int) -> list[Fraction]:
    return [sum(a[i] * b[j - i] for i in range(j + 1)) for j in range(order + 1)]


def pendulum_period(order: int) -> list[Fraction]:
    """``T/2π = (2/π) K(sin²(θ₀/2))`` in ``y = θ₀²``.

    ``sin²(θ/2) = Σ_{k≥1} (-1)^(k+1) y^k / (2(2k)!)``.
    """
    m = [Fraction(0)] + [
        Fraction((-1) ** (k + 1), 2 * factorial(2 * k)) for k in range(1, order + 1)
    ]
    c = _k_coefficients(order)
    out = [Fraction(0)] * (order + 1)
    power = [Fraction(1)] + [Fraction(0)] * order
    for n in range(order + 1):
        out = [o + c[n] * p for o, p in zip(out, power, strict=True)]
        power = _mul(power, m, order)
    return out


def reciprocal(series: list[Fraction]) -> list[Fraction]:
    """``1 / Σ a_j y^j`` for ``a_0 = 1``."""
    out = [Fraction(1)]
    for j in range(1, len(series)):
        out.append(-sum(series[a] * out[j - a] for a in range(1, j + 1)))
    return out
