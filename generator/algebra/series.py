"""Exact Fourier-series algebra: the fast kernel of every derivation.

An even (cosine) Fourier sum ``Σ a_n cos(n s)`` is a polynomial in ``C = cos s``
(``cos n s = T_n(C)``).  The kernel stores it in the monomial basis of ``C``, which
turns every product of Fourier sums into a plain polynomial product, done by FLINT
(python-flint ``fmpq_poly``) in C on exact rationals.  For forces made of odd powers the
sums hold odd harmonics only, ``u = C · P(C²)``, and the kernel works with ``P`` in
``v = C²``: a quarter of the length of the Laurent polynomial in ``z = e^{is}``.
``docs/benchmarks.md`` records the representations that were measured against it.

Coefficients stay exact: rationals (FLINT), elements of a number field ``Q(θ)``
(:class:`NFPoly`, FLINT underneath), or, when a parameter is left symbolic, elements of a
SymPy polynomial domain such as ``QQ[A]`` (:class:`DensePoly`, :class:`MPoly`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction
from functools import cache
from typing import Any

import numpy as np
import sympy as sp
from flint import fmpq, fmpq_mpoly_ctx, fmpq_poly
from sympy.polys.densearith import dup_add, dup_mul, dup_mul_ground, dup_neg, dup_sub
from sympy.polys.domains import QQ


@dataclass(frozen=True)
class Basis:
    """Monomials ``C^n`` of ``C = cos s`` kept by a series: ``n = parity + stride·k``.

    ``odd=True`` keeps only odd harmonics (``u = C·P(C²)``, index ``k`` ↔ ``n = 2k + 1``);
    ``odd=False`` keeps all of them (index ``k`` ↔ ``n = k``).
    """

    odd: bool

    @property
    def parity(self) -> int:
        """The power of ``C`` carried by index 0: 1 for odd harmonics, else 0."""
        return 1 if self.odd else 0

    @property
    def stride(self) -> int:
        """The step in the power of ``C`` between neighbouring indices: 2 (odd harmonics) or 1."""
        return 2 if self.odd else 1

    def harmonic(self, k: int) -> int:
        """Power of ``C`` (and highest harmonic) carried by index ``k``."""
        return self.parity + self.stride * k

    @property
    def resonant(self) -> int:
        """Index of ``C¹ = cos s``, the harmonic in resonance with ``q'' + q``."""
        return 0 if self.odd else 1

    @property
    def step(self) -> int:
        """Index distance from ``C^n`` to ``C^(n-2)``."""
        return 2 // self.stride

    def power_shift(self, n: int) -> int:
        """``u^n = C^parity · v^shift · P^n`` for ``u = C^parity · P(v)``."""
        return (n - 1) // 2 if self.odd else 0


class DensePoly:
    """Dense univariate polynomial over a SymPy domain (e.g. ``QQ[A]``).

    The same interface as FLINT's ``fmpq_poly`` as far as the kernel uses it: ``+ - *``,
    ``coeffs()`` (low to high), ``left_shift``, multiplication by a domain element.
    """

    __slots__ = ("dom", "rep")

    def __init__(self, coeffs: Sequence[Any], dom: Any) -> None:
        rep = [dom.convert(c) for c in reversed(list(coeffs))]
        while rep and not rep[0]:
            rep.pop(0)
        self.dom, self.rep = dom, rep

    @classmethod
    def _wrap(cls, rep: list, dom: Any) -> DensePoly:
        out = cls.__new__(cls)
        out.dom, out.rep = dom, rep
        return out

    def coeffs(self) -> list:
        """The coefficients, low to high (as FLINT's ``fmpq_poly.coeffs()``)."""
        return self.rep[::-1]

    def left_shift(self, k: int) -> DensePoly:
        """The polynomial times its variable to the power ``k``."""
        return self._wrap(self.rep + [self.dom.zero] * k if self.rep else [], self.dom)

    def __add__(self, other: DensePoly) -> DensePoly:
        return self._wrap(dup_add(self.rep, other.rep, self.dom), self.dom)

    def __sub__(self, other: DensePoly) -> DensePoly:
        return self._wrap(dup_sub(self.rep, other.rep, self.dom), self.dom)

    def __neg__(self) -> DensePoly:
        return self._wrap(dup_neg(self.rep, self.dom), self.dom)

    def __mul__(self, other: Any) -> DensePoly:
        if isinstance(other, DensePoly):
            return self._wrap(dup_mul(self.rep, other.rep, self.dom), self.dom)
        return self._wrap(dup_mul_ground(self.rep, self.dom.convert(other), self.dom), self.dom)

    __rmul__ = __mul__


class MPoly:
    """Polynomial in ``C`` over ``QQ[params]``, held as one FLINT ``fmpq_mpoly`` in
    ``(C, params…)``: products run in C (``DensePoly`` over SymPy's ``QQ[params]`` took 25 s
    where this takes well under 1 s, Helmholtz–Duffing at order 30).  Coefficients are
    ``fmpq_mpoly`` of the same context free of ``C``."""

    __slots__ = ("p",)

    def __init__(self, p: Any) -> None:
        self.p = p

    def coeffs(self) -> list:
        """The coefficients of ``C⁰, C¹, …`` (low to high), each an ``fmpq_mpoly`` free of
        ``C``."""
        terms = self.p.to_dict()
        if not terms:
            return []
        buckets: list[dict] = [{} for _ in range(max(k[0] for k in terms) + 1)]
        for k, c in terms.items():
            buckets[k[0]][(0, *k[1:])] = c
        ctx = self.p.context()
        return [ctx.from_dict(b) for b in buckets]

    def left_shift(self, k: int) -> MPoly:
        """The polynomial times ``C^k``."""
        ctx = self.p.context()
        return MPoly(self.p * ctx.gen(0) ** k) if k else self

    def __add__(self, other: MPoly) -> MPoly:
        return MPoly(self.p + other.p)

    def __sub__(self, other: MPoly) -> MPoly:
        return MPoly(self.p - other.p)

    def __neg__(self) -> MPoly:
        return MPoly(-self.p)

    def __mul__(self, other: Any) -> MPoly:
        return MPoly(self.p * (other.p if isinstance(other, MPoly) else other))

    __rmul__ = __mul__


class NFPoly:
    """Polynomial in ``C`` over a number field ``Q(θ) = Q[t]/m(t)`` (SymPy's
    ``AlgebraicField``), held as its ``k = deg m`` parts, the coefficients of ``θ⁰ … θ^(k−1)``,
    each a FLINT ``fmpq_poly`` in ``C``: a product is ``k²`` products in C and a reduction of
    ``θ^k … θ^(2k−2)`` by ``m`` (:class:`DensePoly` over SymPy's field took 135 s where this
    takes a few, a normal mode of two coordinates in ``Q(√10441)`` to order 40).  Its
    coefficients are SymPy's field elements (``ANP``)."""

    __slots__ = ("field", "parts")

    def __init__(self, parts: list, field: _NumberField) -> None:
        self.parts, self.field = parts, field

    @classmethod
    def from_coeffs(cls, coeffs: Sequence[Any], field: _NumberField) -> NFPoly:
        """From field elements (``ANP``, or rationals), low to high in ``C``."""
        rows = [field.parts(c) for c in coeffs]
        return cls([fmpq_poly([r[i] for r in rows]) for i in range(field.k)], field)

    def coeffs(self) -> list:
        """The coefficients of ``C⁰, C¹, …`` (low to high), each an ``ANP`` of the field."""
        lists = [p.coeffs() for p in self.parts]
        top = max(map(len, lists))
        zero = fmpq(0)
        return [self.field.element([c[n] if n < len(c) else zero for c in lists])
                for n in range(top)]

    def left_shift(self, k: int) -> NFPoly:
        """The polynomial times ``C^k``."""
        return NFPoly([p.left_shift(k) for p in self.parts], self.field)

    def __add__(self, other: NFPoly) -> NFPoly:
        return NFPoly([a + b for a, b in zip(self.parts, other.parts, strict=True)],
                      self.field)

    def __sub__(self, other: NFPoly) -> NFPoly:
        return NFPoly([a - b for a, b in zip(self.parts, other.parts, strict=True)],
                      self.field)

    def __neg__(self) -> NFPoly:
        return NFPoly([-a for a in self.parts], self.field)

    def __mul__(self, other: Any) -> NFPoly:
        k = self.field.k
        if isinstance(other, NFPoly):
            right = other.parts
        elif isinstance(other, int):
            return NFPoly([a * other for a in self.parts], self.field)
        else:
            right = self.field.parts(other)
        out = [fmpq_poly() for _ in range(2 * k - 1)]
        for i, a in enumerate(self.parts):
            if a.is_zero():
                continue
            for j, b in enumerate(right):
                if b:
                    out[i + j] += a * b
        for i in range(k, 2 * k - 1):
            if not out[i].is_zero():
                for m, r in enumerate(self.field.powers[i - k]):
                    if r:
                        out[m] += out[i] * r
        return NFPoly(out[:k], self.field)

    __rmul__ = __mul__


@dataclass(frozen=True)
class _NumberField:
    """``Q(θ)`` for :class:`NFPoly`: the degree ``k``, ``θ^i`` for ``i = k … 2k−2`` in the
    basis ``θ⁰ … θ^(k−1)`` (rationals, low to high), and SymPy's field for its elements."""

    domain: Any
    k: int
    powers: tuple[tuple[Any, ...], ...]

    def parts(self, c: Any) -> list:
        """A field element (``ANP``, or a rational) as its ``k`` rationals, low to high."""
        if not hasattr(c, "to_list"):
            c = self.domain.convert(c)
        low = [_fmpq(x) for x in reversed(c.to_list())]
        return low + [fmpq(0)] * (self.k - len(low))

    def element(self, low: list) -> Any:
        """The ``ANP`` of rationals ``low`` (low to high)."""
        q = self.domain.dom
        return self.domain.new([q(int(x.p), int(x.q)) for x in reversed(low)])


def _fmpq(x: Any) -> fmpq:
    return x if isinstance(x, fmpq) else fmpq(int(x.numerator), int(x.denominator))


@cache
def _number_field(domain: Any) -> _NumberField:
    """The reduction data of SymPy's ``AlgebraicField`` ``domain`` (its minimal polynomial
    made monic: ``θ^k = −Σ a_l θ^l``), computed once per field."""
    mod = [_fmpq(x) for x in reversed(domain.mod.to_list())]  # low to high
    k = len(mod) - 1
    cur = [-c / mod[k] for c in mod[:k]]  # θ^k
    top, powers = cur, []
    for _ in range(k - 1):
        powers.append(tuple(cur))
        shifted = [fmpq(0), *cur[:-1]]  # θ·cur, its θ^k part reduced by θ^k itself
        cur = [s + cur[-1] * t for s, t in zip(shifted, top, strict=True)]
    return _NumberField(domain, k, tuple(powers))


@cache
def _mpoly_context(names: tuple[str, ...]) -> Any:
    # NOTE: "_C" cannot be a parameter's name (user names never start with '_')
    return fmpq_mpoly_ctx.get(("_C", *names), "lex")


@dataclass(frozen=True)
class Ground:
    """The exact coefficient ring of a derivation and its polynomial type."""

    domain: Any  # a SymPy domain: QQ, or QQ[params] for symbolic coefficients

    @property
    def is_rational(self) -> bool:
        """Whether the ring is QQ (FLINT ``fmpq`` coefficients, no symbolic parameter)."""
        return self.domain == QQ

    @property
    def _flint_ring(self) -> Any:
        """FLINT's context for ``QQ[params]`` (with ``C`` first), or None for other domains."""
        if self.domain.is_PolynomialRing and self.domain.domain == QQ:
            return _mpoly_context(tuple(str(g) for g in self.domain.symbols))
        return None

    def scalar(self, value: Any) -> Any:
        """An exact ring element from an int, Fraction, SymPy number or expression."""
        if self.is_rational:
            if type(value) is int:  # the common case, without SymPy
                return fmpq(value)
            if isinstance(value, Fraction):
                return fmpq(value.numerator, value.denominator)
            r = sp.Rational(value)
            return fmpq(int(r.p), int(r.q))
        ctx = self._flint_ring
        element = self.domain.from_sympy(sp.sympify(value))
        if ctx is None:
            return element
        return ctx.from_dict({(0, *k): fmpq(int(c.numerator), int(c.denominator))
                              for k, c in element.items()})

    def poly(self, coeffs: Sequence[Any]) -> Any:
        """Polynomial from coefficients listed low to high."""
        if self.is_rational:
            return fmpq_poly(list(coeffs))
        if self.domain.is_AlgebraicField:
            return NFPoly.from_coeffs(coeffs, _number_field(self.domain))
        ctx = self._flint_ring
        if ctx is None:
            return DensePoly(coeffs, self.domain)
        terms: dict = {}
        for i, c in enumerate(coeffs):
            for k, v in c.to_dict().items():
                terms[(i, *k[1:])] = v
        return MPoly(ctx.from_dict(terms))

    def to_sympy(self, c: Any) -> sp.Expr:
        """An exact ring element as a SymPy expression: a ``Rational``, or a polynomial in the
        parameters."""
        if self.is_rational:
            return sp.Rational(int(c.p), int(c.q))
        if self._flint_ring is None:
            return self.domain.to_sympy(c)
        gens = self.domain.symbols
        return sp.Add(*(sp.Rational(int(v.p), int(v.q))
                        * sp.Mul(*(g**e for g, e in zip(gens, k[1:], strict=True)))
                        for k, v in c.to_dict().items()))

    def terms(self, c: Any) -> list[tuple[tuple[tuple[str, int], ...], Any]]:
        """The monomials of an exact coefficient straight from FLINT, without SymPy: pairs of
        ``((name, power), …)`` (names sorted, powers ≥ 1; ``()`` for the constant) and the
        rational (``fmpq``) multiplying it; no pair for a zero coefficient."""
        if self.is_rational:
            return [((), c)] if c != 0 else []
        names = [str(g) for g in self.domain.symbols]
        if self._flint_ring is None:
            items = [(k, fmpq(int(v.numerator), int(v.denominator))) for k, v in c.items()]
        else:
            items = [(k[1:], v) for k, v in c.to_dict().items()]
        return [(tuple(sorted((n, e) for n, e in zip(names, k, strict=True) if e)), v)
                for k, v in items if v != 0]

    def to_fraction(self, c: Any) -> Fraction:
        """A rational ring element as a :class:`Fraction`; ``TypeError`` when the ring has
        symbolic parameters."""
        if not self.is_rational:
            raise TypeError("coefficients with symbolic parameters have no Fraction value")
        return Fraction(int(c.p), int(c.q))

    @staticmethod
    def for_coefficients(values: Sequence[sp.Expr]) -> Ground:
        """QQ when every value is rational, else ``QQ[free symbols]`` (sorted by name)."""
        symbols = sorted(set().union(*(sp.sympify(v).free_symbols for v in values)), key=str)
        return Ground(QQ.poly_ring(*symbols)) if symbols else Ground(QQ)


@dataclass(frozen=True)
class Solved:
    """Result of solving ``u'' + u = G`` in the kernel's basis (see :func:`solve_oscillator`)."""

    particular: list  # coefficients of the particular solution, resonant index left at zero
    secular: Any  # Fourier coefficient of cos s in G: must vanish for a periodic solution


def solve_oscillator(g: Sequence[Any], basis: Basis, ground: Ground) -> Solved:
    """Particular periodic solution of ``u'' + u = G(s)`` and the secular part of ``G``.

    In the monomial basis ``(d²/ds² + 1) C^n = (1 - n²) C^n + n(n-1) C^(n-2)`` is triangular,
    so back-substitution from the top degree solves it: the Fourier route's
    ``c cos ns / (1 - n²)`` without leaving the basis.  The row of ``C¹`` has a zero pivot;
    what remains in it is the Fourier coefficient of ``cos s`` in ``G`` (the resonant,
    secular forcing), returned separately.
    """
    top = len(g) - 1
    p = [ground.scalar(0)] * (top + 1)
    zero = ground.scalar(0)
    step = basis.step
    r = basis.resonant
    secular = zero
    for k in range(top, -1, -1):
        above = k + step
        rhs = g[k]
        if above <= top:
            n_above = basis.harmonic(above)
            rhs = rhs - p[above] * (n_above * (n_above - 1))
        if k == r:
            secular = rhs
            continue
        n = basis.harmonic(k)
        p[k] = rhs * ground.scalar(Fraction(1, 1 - n * n))
    return Solved(p, secular)


def to_fourier(poly: Any, basis: Basis, ground: Ground) -> dict[int, Any]:
    """Fourier cosine coefficients ``{n: a_n}`` of ``C^parity · P(v)``.

    ``z = e^{is}`` with ``z·C = (z² + 1)/2``: ``z^D · u`` is a polynomial in ``z`` whose
    coefficient of ``z^(D+n)`` is ``a_n / 2`` (``a_0`` itself for ``n = 0``), built by halves
    (:func:`_in_z`).
    """
    cs = poly.coeffs()
    if not cs:
        return {}
    half = ground.scalar(Fraction(1, 2))
    zc = ground.poly([half, ground.scalar(0), half])
    w = zc if basis.stride == 1 else zc * zc
    top = len(cs) - 1
    acc = _in_z(cs, 0, len(cs), w, basis.stride, ground, {1: w})
    if basis.parity:
        acc = acc * zc
    degree = basis.harmonic(top)
    z = acc.coeffs()
    out = {}
    for n in range(degree, -1, -1):
        c = z[degree + n] if degree + n < len(z) else ground.scalar(0)
        if n:
            c = c * 2
        if c:
            out[n] = c
    return out


HORNER_BELOW = 16
# NOTE: pieces shorter than this go by Horner's rule; longer ones split in halves, so the
# conversion costs a few large products (FLINT's fast multiplication) instead of n small ones:
# Duffing's q_j at order 300 convert 2–3× faster (benchmarks: 16 measured best of 8…96).


def _in_z(cs: list, lo: int, hi: int, w: Any, stride: int, ground: Ground, powers: dict
          ) -> Any:
    """``F = Σ_{k<n} c_(lo+k) w^k z^(stride·(n−1−k))`` for ``n = hi − lo`` (``w = (zC)^stride``):
    with ``P = L + v^h H``, ``F(P) = z^(stride(n−h))·F(L) + w^h·F(H)``."""
    n = hi - lo
    if n <= HORNER_BELOW:
        acc = ground.poly([cs[hi - 1]])
        for k in range(hi - 2, lo - 1, -1):
            acc = acc * w + ground.poly([cs[k]]).left_shift(stride * (hi - 1 - k))
        return acc
    h = n // 2
    if h not in powers:
        powers[h] = _power(w, h, powers)
    left = _in_z(cs, lo, lo + h, w, stride, ground, powers)
    right = _in_z(cs, lo + h, hi, w, stride, ground, powers)
    return left.left_shift(stride * (n - h)) + powers[h] * right


def _power(w: Any, h: int, powers: dict) -> Any:
    """``w^h`` from the cached powers (halving)."""
    if h in powers:
        return powers[h]
    half = _power(w, h // 2, powers)
    result = half * half if h % 2 == 0 else half * half * w
    powers[h] = result
    return result


def from_fourier(coeffs: dict[int, Any], basis: Basis, ground: Ground) -> Any:
    """Inverse of :func:`to_fourier`: ``Σ a_n cos(ns)`` in the monomial basis.

    Raises ``ValueError`` for a harmonic the basis cannot hold (an even one in the odd basis).
    """
    if not coeffs:
        return ground.poly([])
    top = max(coeffs)
    if any(basis.odd and n % 2 == 0 for n in coeffs):
        raise ValueError(f"harmonics {sorted(coeffs)}: the odd basis holds odd harmonics only")
    # Chebyshev recurrence on monomial coefficient lists: T_{n+1} = 2 C T_n - T_{n-1}.
    cheb = [[1], [0, 1]]
    for _ in range(2, top + 1):
        a, b = cheb[-1], cheb[-2]
        nxt = [0] + [2 * x for x in a]
        for i, x in enumerate(b):
            nxt[i] -= x
        cheb.append(nxt)
    if ground.domain.is_AlgebraicField:  # each rational part by FLINT, not SymPy's field
        field = _number_field(ground.domain)
        sums = [fmpq_poly() for _ in range(field.k)]
        for n, a in coeffs.items():
            t = fmpq_poly(cheb[n])
            for i, c in enumerate(field.parts(a)):
                if c:
                    sums[i] += t * c
        return NFPoly([fmpq_poly(p.coeffs()[basis.parity :: basis.stride]) for p in sums],
                      field)
    mono = [ground.scalar(0)] * (top + 1)
    for n, a in coeffs.items():
        for i, t in enumerate(cheb[n]):
            if t:
                mono[i] = mono[i] + a * t
    return ground.poly(mono[basis.parity :: basis.stride])


@dataclass(frozen=True)
class Trig:
    """A Fourier sum with sines, ``Σ a_n cos ns + Σ b_n sin ns = P(C) + S·R(C)``.

    ``C = cos s``, ``S = sin s`` (``cos ns = T_n(C)``, ``sin ns = S·U_{n-1}(C)``) and
    ``S² = 1 − C²`` close the algebra on pairs of polynomials over the ground ring: a product
    is four polynomial products, ``d/ds`` stays in the basis, and ``u'' + u = F`` is triangular
    in both halves (:func:`solve_trig`).  ``docs/benchmarks.md`` measures it against the
    Laurent form in ``z = e^{is}``.
    """

    cos_part: Any  # P(C)
    sin_part: Any  # R(C)
    ground: Ground

    @classmethod
    def from_fourier(cls, cosines: dict[int, Any], sines: dict[int, Any], ground: Ground
                     ) -> Trig:
        """From ``{n: a_n}`` and ``{n: b_n}`` (``n ≥ 1`` for sines)."""
        if any(n < 1 for n in sines):
            raise ValueError(f"sine harmonics {sorted(sines)}: n must be ≥ 1")
        P = from_fourier(cosines, Basis(False), ground)
        top = max(sines, default=0)
        mono = [ground.scalar(0)] * max(top, 1)
        cheb = [[1], [0, 2]]  # U_0 = 1, U_1 = 2C, U_{n+1} = 2C U_n − U_{n−1}
        for _ in range(2, top):
            a, b = cheb[-1], cheb[-2]
            nxt = [0] + [2 * x for x in a]
            for i, x in enumerate(b):
                nxt[i] -= x
            cheb.append(nxt)
        for n, b in sines.items():
            for i, u in enumerate(cheb[n - 1]):
                if u:
                    mono[i] = mono[i] + b * u
        return cls(P, ground.poly(mono), ground)

    def to_fourier(self) -> tuple[dict[int, Any], dict[int, Any]]:
        """``({n: a_n}, {n: b_n})``, zero coefficients left out."""
        g = self.ground
        basis = Basis(False)
        cs = self.cos_part.coeffs()
        if g.is_rational and len(cs) > 1 and not any(cs[0::2]):  # odd harmonics: in C²
            cosines = to_fourier(g.poly(cs[1::2]), Basis(True), g)
        else:
            cosines = to_fourier(self.cos_part, basis, g)
        rs = self.sin_part.coeffs()
        if g.is_rational and len(rs) > 1 and not any(rs[1::2]):  # R even in C: odd harmonics
            # S·R(C) = −d/ds Q(C) with Q = ∫R dC = C·Σ r_k v^k/(2k+1): sin ns gets n γ_n
            Q = g.poly([r * g.scalar(Fraction(1, 2 * k + 1)) for k, r in enumerate(rs[0::2])])
            sines = {n: gamma * n for n, gamma in to_fourier(Q, Basis(True), g).items()}
            return cosines, {n: b for n, b in sorted(sines.items()) if b}
        # S·R(C) with R(C) = Σ ρ_n cos ns: cos ns · sin s = (sin(n+1)s − sin(n−1)s)/2
        half = g.scalar(Fraction(1, 2))
        sines = {}
        for n, rho in to_fourier(self.sin_part, basis, g).items():
            if n == 0:
                sines[1] = sines.get(1, g.scalar(0)) + rho
                continue
            sines[n + 1] = sines.get(n + 1, g.scalar(0)) + rho * half
            if n > 1:
                sines[n - 1] = sines.get(n - 1, g.scalar(0)) - rho * half
        return cosines, {n: b for n, b in sorted(sines.items()) if b}

    def __add__(self, other: Trig) -> Trig:
        return Trig(self.cos_part + other.cos_part, self.sin_part + other.sin_part, self.ground)

    def __sub__(self, other: Trig) -> Trig:
        return Trig(self.cos_part - other.cos_part, self.sin_part - other.sin_part, self.ground)

    def __mul__(self, other: Trig | Any) -> Trig:
        if not isinstance(other, Trig):
            return Trig(self.cos_part * other, self.sin_part * other, self.ground)
        one_minus_c2 = _constants(self.ground)[1]
        cos_part = self.cos_part * other.cos_part + one_minus_c2 * (self.sin_part
                                                                    * other.sin_part)
        sin_part = self.cos_part * other.sin_part + self.sin_part * other.cos_part
        return Trig(cos_part, sin_part, self.ground)

    def derivative(self) -> Trig:
        """``d/ds``: ``d P(C) = −S P'(C)``, ``d(S R(C)) = C R − (1 − C²) R'``."""
        g = self.ground
        dP, dR = _dC(self.cos_part, g), _dC(self.sin_part, g)
        C, one_minus_c2, minus_one = _constants(g)
        return Trig(C * self.sin_part - one_minus_c2 * dR, dP * minus_one, g)


@cache
def _constants(ground: Ground) -> tuple[Any, Any, Any]:
    """``C``, ``1 − C²`` and −1 of a ground, made once."""
    zero, one = ground.scalar(0), ground.scalar(1)
    return (ground.poly([zero, one]), ground.poly([one, zero, -one]), ground.scalar(-1))


def _dC(poly: Any, ground: Ground) -> Any:
    if ground.is_rational:  # FLINT's own derivative
        return poly.derivative()
    cs = poly.coeffs()
    return ground.poly([c * k for k, c in enumerate(cs)][1:])


@dataclass(frozen=True)
class TrigSolved:
    """``u'' + u = F`` in the sine-capable basis: a particular solution and the secular parts."""

    particular: Trig  # up to the homogeneous a cos s + b sin s (the caller's convention)
    secular_cos: Any  # Fourier coefficient of cos s in F
    secular_sin: Any  # Fourier coefficient of sin s in F


def solve_trig(F: Trig) -> TrigSolved:
    """Particular periodic solution of ``u'' + u = F`` and the resonant (secular) parts of F.

    The cosine half is :func:`solve_oscillator`'s back-substitution; in the sine half
    ``(d²/ds² + 1)(S C^n) = S[(1 − (n+1)²) C^n + n(n−1) C^(n−2)]`` is triangular too, with a
    zero pivot at ``S C⁰ = sin s``, whose remainder is the Fourier coefficient of ``sin s``.
    """
    g = F.ground
    zero = g.scalar(0)
    c = F.cos_part.coeffs()
    c = c + [zero] * (2 - len(c))
    cos_solved = solve_oscillator(c, Basis(False), g)
    r = F.sin_part.coeffs() or [zero]
    top = len(r) - 1
    p = [zero] * (top + 1)
    secular_sin = zero
    for n in range(top, -1, -1):
        rhs = r[n]
        if n + 2 <= top:
            rhs = rhs - p[n + 2] * ((n + 2) * (n + 1))
        if n == 0:
            secular_sin = rhs
            continue
        p[n] = rhs * g.scalar(Fraction(1, 1 - (n + 1) ** 2))
    cos_particular = list(cos_solved.particular)
    return TrigSolved(Trig(g.poly(cos_particular), g.poly(p), g), cos_solved.secular,
                      secular_sin)



def trig_power(cosines: dict[int, sp.Expr], sines: dict[int, sp.Expr], power: int
               ) -> tuple[dict[int, sp.Expr], dict[int, sp.Expr]]:
    """Fourier coefficients ``({n: a_n}, {n: b_n})`` of ``(Σ a_k cos ks + Σ b_k sin ks)^power``
    for SymPy coefficients (polynomials over QQ in their symbols): the :class:`Trig` kernel
    over ``QQ[symbols]``, back in SymPy."""
    ground = Ground.for_coefficients([*cosines.values(), *sines.values()])
    base = Trig.from_fourier({n: ground.scalar(c) for n, c in cosines.items()},
                             {n: ground.scalar(c) for n, c in sines.items()}, ground)
    out = base
    for _ in range(power - 1):
        out = out * base
    cos, sin = out.to_fourier()
    return ({n: ground.to_sympy(c) for n, c in cos.items()},
            {n: ground.to_sympy(c) for n, c in sin.items()})

# --- the float kernel: the same algebra in the Laurent form, for the numeric methods ---------
# A real Fourier sum is held as the complex coefficients ``c_n`` of ``z^n = e^{ins}`` for
# ``|n| ≤ M`` (``c_{−n} = c̄_n``), a complex128 array indexed ``n + M``: products are
# convolutions (numpy's, in C), ``d/ds`` is ``i n``, and ``u'' + u = F`` is ``F_n/(1 − n²)``.
# In floating point the Laurent form is the natural one (no exact cancellation to keep);
# ``docs/benchmarks.md`` ("One Fourier kernel") records what moved onto it.


def laurent_harmonics(M: int) -> np.ndarray:
    """``n = −M … M``, the index of each coefficient."""
    return np.arange(-M, M + 1)


def laurent_cos(M: int, amplitude: complex = 1.0) -> np.ndarray:
    """``amplitude · e^{is}/2 + c.c.``: ``A cos s`` for real ``A`` (``Re(A e^{is})`` else)."""
    out = np.zeros(2 * M + 1, dtype=complex)
    out[M + 1] = amplitude / 2
    out[M - 1] = np.conj(amplitude) / 2
    return out


def laurent_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The product, truncated to the same harmonics ``|n| ≤ M``."""
    M = (len(a) - 1) // 2
    return np.convolve(a, b)[M : 3 * M + 1]


def laurent_derivative(c: np.ndarray) -> np.ndarray:
    """``d/ds``: ``c_n → i n c_n``."""
    return 1j * laurent_harmonics((len(c) - 1) // 2) * c


def laurent_secular(F: np.ndarray) -> np.ndarray:
    """``(cos s, sin s)`` coefficients of ``F``: ``2 Re c₁``, ``−2 Im c₁``."""
    M = (len(F) - 1) // 2
    return np.array([2 * F[M + 1].real, -2 * F[M + 1].imag])


@dataclass(frozen=True)
class LaurentSolved:
    """``u'' + u = F`` in the Laurent form: :class:`TrigSolved`'s fields in floating point."""

    particular: np.ndarray  # c_n of u, the resonant n = ±1 left at zero
    secular_cos: float  # Fourier coefficient of cos s in F
    secular_sin: float  # Fourier coefficient of sin s in F


def laurent_solve(F: np.ndarray) -> LaurentSolved:
    """Particular periodic solution of ``u'' + u = F`` and the resonant (secular) parts of F:
    ``u_n = F_n/(1 − n²)`` for ``|n| ≠ 1`` (the exact kernel's :func:`solve_trig`)."""
    n = laurent_harmonics((len(F) - 1) // 2)
    resonant = np.abs(n) == 1
    particular = np.where(resonant, 0, F / np.where(resonant, 1, 1 - n * n))
    cos1, sin1 = laurent_secular(F)
    return LaurentSolved(particular, float(cos1), float(sin1))


def laurent_from_fourier(M: int, orders: np.ndarray, cosines: np.ndarray,
                         sines: np.ndarray | None = None) -> np.ndarray:
    """``c_n`` of ``Σ a_k cos ks + b_k sin ks`` over ``orders`` (distinct, ``0 ≤ k ≤ M``, the
    mean ``a_0`` at ``k = 0``; ``sines`` all zero when None)."""
    orders = np.asarray(orders)
    c = np.zeros(2 * M + 1, dtype=complex)
    z = (np.asarray(cosines) - 1j * (0 if sines is None else np.asarray(sines))) / 2
    c[M + orders] = z
    c[M - orders] = np.conj(z)
    if np.any(orders == 0):
        c[M] = 2 * c[M].real
    return c


def laurent_to_fourier(c: np.ndarray, orders: np.ndarray,
                       phase: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """``(a_k, b_k)`` of the sum ``Σ c_n e^{in(s − phase)}`` over ``orders`` (``k ≥ 0``):
    ``2 Re``, ``−2 Im`` of ``c_k e^{−ik·phase}``, the mean ``a_0 = c_0`` (the inverse of
    :func:`laurent_from_fourier` at ``phase = 0``)."""
    orders = np.asarray(orders)
    z = c[(len(c) - 1) // 2 + orders]
    if phase:
        z = z * np.exp(-1j * orders * phase)
    if np.any(orders == 0):
        z = np.where(orders == 0, z.real / 2, z)
    return 2 * z.real, -2 * z.imag
