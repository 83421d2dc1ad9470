"""Property tests of the Fourier kernel against product-to-sum on plain Fraction dicts."""

from __future__ import annotations

from fractions import Fraction

from hypothesis import given, settings
from hypothesis import strategies as st
from lindstedt.series import Basis, Ground, from_fourier, solve_oscillator, to_fourier

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
