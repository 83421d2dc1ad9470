"""Property tests of the Fourier kernel against product-to-sum on plain Fraction dicts."""

from __future__ import annotations

from fractions import Fraction

from hypothesis import given, settings
from hypothesis import strategies as st
from lindstedt.algebra.series import (
    Basis,
    Ground,
    Trig,
    from_fourier,
    solve_oscillator,
    solve_trig,
    to_fourier,
)

QQ = Ground.for_coefficients([])
rationals = st.builds(Fraction, st.integers(-99, 99).filter(bool), st.integers(1, 50))


def cos_series(odd: bool):
    harmonics = st.integers(0, 9).map(lambda n: 2 * n + 1 if odd else n)
    return st.dictionaries(harmonics, rationals, max_size=6)


def product_to_sum(a: dict[int, Fraction], b: dict[int, Fraction]) -> dict[int, Fraction]:
    """cos ms·cos ns = (cos(m+n)s + cos(m-n)s)/2: the textbook rule, not the kernel."""
    out: dict[int, Fraction] = {}
    for m, x in a.items():
        for n, y in b.items():
            for k in (m + n, abs(m - n)):
                out[k] = out.get(k, Fraction(0)) + x * y / 2
    return {k: v for k, v in out.items() if v}


def as_fractions(d):
    return {n: QQ.to_fraction(c) for n, c in d.items()}


def roundtrip(d, basis):
    return as_fractions(to_fourier(from_fourier({n: QQ.scalar(c) for n, c in d.items()}, basis, QQ),
                                   basis, QQ))


@settings(max_examples=60, deadline=None)
@given(st.booleans(), st.data())
def test_roundtrip(odd, data):
    d = data.draw(cos_series(odd))
    assert roundtrip(d, Basis(odd)) == d


@settings(max_examples=60, deadline=None)
@given(cos_series(False), cos_series(False))
def test_product_is_product_to_sum(a, b):
    basis = Basis(False)
    pa = from_fourier({n: QQ.scalar(c) for n, c in a.items()}, basis, QQ)
    pb = from_fourier({n: QQ.scalar(c) for n, c in b.items()}, basis, QQ)
    assert as_fractions(to_fourier(pa * pb, basis, QQ)) == product_to_sum(a, b)


@settings(max_examples=60, deadline=None)
@given(st.booleans(), st.data())
def test_particular_solution_and_secular_part(odd, data):
    """u'' + u = Σ g_n cos ns: u_n = g_n/(1-n²) for n ≠ 1, and the secular part is g_1."""
    g = data.draw(cos_series(odd))
    basis = Basis(odd)
    mono = from_fourier({n: QQ.scalar(c) for n, c in g.items()}, basis, QQ)
    coeffs = mono.coeffs() or [QQ.scalar(0)]
    coeffs = coeffs + [QQ.scalar(0)] * (basis.resonant + 1 - len(coeffs))
    solved = solve_oscillator(coeffs, basis, QQ)
    assert QQ.to_fraction(solved.secular) == g.get(1, 0)
    u = as_fractions(to_fourier(QQ.poly(solved.particular), basis, QQ))
    u.pop(1, None)  # the particular solution is defined up to the homogeneous cos s
    expected = {n: c / (1 - n * n) for n, c in g.items() if n != 1}
    assert u == expected


def test_even_harmonic_in_odd_basis_is_refused():
    import pytest

    with pytest.raises(ValueError, match="odd harmonics"):
        from_fourier({2: QQ.scalar(1)}, Basis(True), QQ)


# The sine-capable kernel (P(C) + S·R(C)) against the textbook product-to-sum rules.

def sine_series():
    return st.dictionaries(st.integers(1, 9), rationals, max_size=5)


def trig_product(a: tuple[dict, dict], b: tuple[dict, dict]) -> tuple[dict, dict]:
    """cos·cos, cos·sin, sin·sin by product-to-sum on Fraction dicts (sin(-n) = -sin n)."""
    cos: dict[int, Fraction] = {}
    sin: dict[int, Fraction] = {}

    def put(table, n, v, odd):
        if odd and n < 0:
            n, v = -n, -v
        n = abs(n)
        if odd and n == 0:
            return
        table[n] = table.get(n, Fraction(0)) + v

    (ac, as_), (bc, bs) = a, b
    for m, x in ac.items():
        for n, y in bc.items():
            put(cos, m + n, x * y / 2, False)
            put(cos, m - n, x * y / 2, False)
        for n, y in bs.items():  # cos m · sin n = (sin(n+m) + sin(n-m))/2
            put(sin, n + m, x * y / 2, True)
            put(sin, n - m, x * y / 2, True)
    for m, x in as_.items():
        for n, y in bc.items():
            put(sin, m + n, x * y / 2, True)
            put(sin, m - n, x * y / 2, True)
        for n, y in bs.items():  # sin m · sin n = (cos(m-n) - cos(m+n))/2
            put(cos, m - n, x * y / 2, False)
            put(cos, m + n, -x * y / 2, False)
    return ({k: v for k, v in cos.items() if v}, {k: v for k, v in sin.items() if v})


def trig(cos: dict, sin: dict) -> Trig:
    return Trig.from_fourier({n: QQ.scalar(c) for n, c in cos.items()},
                             {n: QQ.scalar(c) for n, c in sin.items()}, QQ)


def fractions_of(t: Trig) -> tuple[dict, dict]:
    c, s = t.to_fourier()
    return as_fractions(c), as_fractions(s)


@settings(max_examples=60, deadline=None)
@given(cos_series(False), sine_series(), cos_series(False), sine_series())
def test_trig_roundtrip_and_product(ac, as_, bc, bs):
    assert fractions_of(trig(ac, as_)) == (ac, as_)
    assert fractions_of(trig(ac, as_) * trig(bc, bs)) == trig_product((ac, as_), (bc, bs))


@settings(max_examples=60, deadline=None)
@given(cos_series(False), sine_series())
def test_trig_derivative(ac, as_):
    """d/ds: a_n cos ns -> -n a_n sin ns, b_n sin ns -> n b_n cos ns."""
    cos = {n: n * b for n, b in as_.items()}
    sin = {n: -n * a for n, a in ac.items() if n}
    assert fractions_of(trig(ac, as_).derivative()) == (
        {n: c for n, c in cos.items() if c}, {n: c for n, c in sin.items() if c})


@settings(max_examples=60, deadline=None)
@given(cos_series(False), sine_series())
def test_trig_particular_solution_and_both_secular_parts(fc, fs):
    """u'' + u = F: u_n = F_n/(1 - n²) for n ≠ 1 in both halves; secular parts F_1."""
    solved = solve_trig(trig(fc, fs))
    assert QQ.to_fraction(solved.secular_cos) == fc.get(1, 0)
    assert QQ.to_fraction(solved.secular_sin) == fs.get(1, 0)
    uc, us = fractions_of(solved.particular)
    uc.pop(1, None)  # defined up to the homogeneous a cos s + b sin s
    us.pop(1, None)
    assert uc == {n: c / (1 - n * n) for n, c in fc.items() if n != 1}
    assert us == {n: c / (1 - n * n) for n, c in fs.items() if n != 1}


def test_trig_over_symbolic_parameters():
    """QQ[a, b]: (a cos s + b sin s)² = (a² + b²)/2 + (a² − b²)/2 cos 2s + ab sin 2s."""
    import sympy as sp

    a, b = sp.symbols("a b")
    g = Ground.for_coefficients([a, b])
    x = Trig.from_fourier({1: g.scalar(a)}, {1: g.scalar(b)}, g)
    cos, sin = (x * x).to_fourier()
    assert {n: sp.expand(g.to_sympy(c)) for n, c in cos.items()} == {
        0: sp.expand((a**2 + b**2) / 2), 2: sp.expand((a**2 - b**2) / 2)}
    assert {n: g.to_sympy(c) for n, c in sin.items()} == {2: a * b}


# The float kernel (Laurent form, complex128) against the exact one on random rational sums.

import numpy as np  # noqa: E402
from lindstedt.algebra.series import (  # noqa: E402
    laurent_derivative,
    laurent_from_fourier,
    laurent_product,
    laurent_solve,
    laurent_to_fourier,
)

LAURENT_M = 40  # holds every product below (harmonics ≤ 18) untruncated


def laurent(cos: dict, sin: dict) -> np.ndarray:
    orders = sorted(set(cos) | set(sin))
    return laurent_from_fourier(LAURENT_M, np.array(orders, dtype=int),
                                np.array([float(cos.get(n, 0)) for n in orders]),
                                np.array([float(sin.get(n, 0)) for n in orders]))


def close(c: np.ndarray, exact: tuple[dict, dict]) -> bool:
    """Every cos/sin coefficient of ``c`` within rounding of the exact ``({n: a}, {n: b})``."""
    a, b = laurent_to_fourier(c, np.arange(LAURENT_M + 1))
    cos, sin = exact
    want_a = np.array([float(cos.get(n, 0)) for n in range(LAURENT_M + 1)])
    want_b = np.array([float(sin.get(n, 0)) for n in range(LAURENT_M + 1)])
    scale = 1 + max(np.abs(want_a).max(), np.abs(want_b).max())
    return bool(np.allclose(a, want_a, rtol=0, atol=1e-13 * scale)
                and np.allclose(b, want_b, rtol=0, atol=1e-13 * scale))


@settings(max_examples=60, deadline=None)
@given(cos_series(False), sine_series(), cos_series(False), sine_series())
def test_laurent_roundtrip_and_product_against_trig(ac, as_, bc, bs):
    assert close(laurent(ac, as_), fractions_of(trig(ac, as_)))
    assert close(laurent_product(laurent(ac, as_), laurent(bc, bs)),
                 fractions_of(trig(ac, as_) * trig(bc, bs)))


@settings(max_examples=60, deadline=None)
@given(cos_series(False), sine_series())
def test_laurent_derivative_against_trig(ac, as_):
    assert close(laurent_derivative(laurent(ac, as_)), fractions_of(trig(ac, as_).derivative()))


@settings(max_examples=60, deadline=None)
@given(cos_series(False), sine_series())
def test_laurent_solve_and_secular_parts_against_trig(fc, fs):
    """u'' + u = F: the particular solution (resonant harmonic aside) and both secular parts."""
    exact = solve_trig(trig(fc, fs))
    solved = laurent_solve(laurent(fc, fs))
    assert abs(solved.secular_cos - float(QQ.to_fraction(exact.secular_cos))) <= 1e-13 * (
        1 + abs(solved.secular_cos))
    assert abs(solved.secular_sin - float(QQ.to_fraction(exact.secular_sin))) <= 1e-13 * (
        1 + abs(solved.secular_sin))
    cos, sin = fractions_of(exact.particular)
    cos.pop(1, None)  # the homogeneous a cos s + b sin s: each kernel's own convention
    sin.pop(1, None)
    assert close(solved.particular, (cos, sin))
    assert solved.particular[LAURENT_M + 1] == 0 == solved.particular[LAURENT_M - 1]
