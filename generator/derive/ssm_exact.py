"""The normal form of an SSM exactly: :mod:`analysis.ssm`'s ``γ_j`` in the eigenvalues' number
field, for systems with rational coefficients and at most three coordinates.

**The field.**  ``λ`` (the mode's eigenvalue) is a root of ``det(s²I + sD + S)`` (the lowered
``D = M⁻¹C``, ``S = M⁻¹K``), a rational polynomial; its irreducible factor ``p`` (degree
``d ≤ 6``) is ``λ``'s minimal polynomial and ``λ̄`` is another of its roots.  Every number
lives in ``Q(λ, λ̄) = K[λ̄]/(q)``, ``K = Q[λ]/(p)``, ``q`` the minimal polynomial of ``λ̄``
over ``K``, of degree ``e``: 1 where ``λ̄ ∈ Q(λ)`` (undamped, ``λ̄ = −λ``; one coordinate,
``λ̄ = −c − λ``; proportional damping), up to ``d − 1`` (generic damping: ``Q(λ, λ̄)`` of
degree 12 for two coordinates, 30 for three).  ``q`` is found as Trager's factorisation
finds a factor over ``K``: ``θ = λ̄ + tλ`` (the first integer ``t ≥ 2`` for which the ``d²``
sums ``α_j + tα_i`` of ``p``'s roots are apart) has the minimal polynomial ``m``, the factor of
``Res_x(p(x), p(z − tx))`` that vanishes at ``θ``, and ``q = gcd(p(y)/(y − λ), m(y + tλ))``
over ``K``.  The basis ``λ^i λ̄^j`` keeps the coefficients far smaller than a primitive
element's powers (whose λ alone had 3400-bit coefficients at degree 30).  Complex conjugation
is the automorphism ``λ ↔ λ̄``.

**The normal form** is :mod:`analysis.ssm`'s recursion, row by row and in the same
normalisation of each resonant row (``ψᵀB(W_m, V_m) = 0``), in the lowered form ``M = I``
(``L(s) = s²I + sD + S``; the left eigenvector ``w`` of ``L(λ)`` is ``Mᵀ`` times the
original one: the equations are ``M⁻¹`` times analysis.ssm's, the same ``W``, ``V``, ``γ``).
Each row's ``n × n`` (resonant: bordered ``(n + 1) × (n + 1)``) system is solved by Gaussian
elimination in the field; a row whose ``s ≠ λ`` is a root of the characteristic polynomial
is an exact internal resonance and refused.

**The normalisation** is algebraic: ``φ_i = 1`` at the component ``i`` where the mode's
shape is largest (analysis.ssm's ``φᴴMφ = 1/4`` needs a square root and a modulus).  Its
``φ = κ·φ_exact``, and scaling the amplitude ``p₁ → κp₁`` turns ``γ_j`` into ``γ_j|κ|^{2j}``:

    γ_j (analysis.ssm) = γ_j (exact) · ν^j,    ν = |κ|² = 1 / (4 φ̄ᵀ M φ),

``ν`` a real element of the field (``φ̄`` the conjugate: the null vector of ``L(λ̄)``), given
exactly and as decimals; ``converted`` holds ``γ_j ν^j`` to 30 digits, analysis.ssm's
``gamma`` to rounding.  Decimals are exact numbers evaluated in ball arithmetic (arb), the
working precision doubled until 30 digits are certain; an exactly vanishing real or imaginary
part is decided in the field and written ``0``."""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp
from flint import acb, acb_poly, ctx, fmpq, fmpq_mat, fmpq_mpoly_ctx, fmpq_poly

from ..errors import InputError
from .system import System

MAX_EXACT = 3
# NOTE: the most coordinates of the exact ground: Q(λ, λ̄) has degree up to 2n(2n − 1)
# (30 at n = 3) and each element's coefficients grow with the order.
DIGITS = 30
PRECISION = 128
# NOTE: the first working precision (bits) of the root isolation and of each decimal; doubled
# until the balls are narrow enough (certified 30 digits).


class Field:
    """``Q(λ, λ̄) = K[λ̄]/(q)``, ``K = Q[λ]/(p)``: ``p`` is λ's minimal polynomial (degree
    ``d``), ``q`` λ̄'s over ``K`` (monic, degree ``e``; its coefficients are elements of ``K``,
    lowest first).  An element ``Σ a_ij λ^i λ̄^j`` (``i < d``, ``j < e``) is the ``fmpq_poly``
    ``Σ a_ij X^(i + Bj)``, ``B = 2d − 1`` (Kronecker: a product's terms do not overlap), so
    that sums, rational multiples and products are FLINT's; a product is then reduced.
    ``root`` is λ's ball."""

    def __init__(self, p: fmpq_poly, q: list[fmpq_poly], root: acb) -> None:
        self.p, self.q, self.root = p, q, root
        d, e = p.degree(), len(q) - 1
        self.d, self.e, self.B = d, e, 2 * d - 1
        self.basis = [i + self.B * j for j in range(e) for i in range(d)]
        self.lam = fmpq_poly([0, 1])
        self.lambar = -q[0] if e == 1 else fmpq_poly([0] * self.B + [1])
        self.images = {k: self.mul(self._power(self.lambar, k % self.B),
                                   self._power(self.lam, k // self.B)) for k in self.basis}
        self._roots: dict[int, acb] = {}

    def _power(self, a: fmpq_poly, k: int) -> fmpq_poly:
        out = fmpq_poly([1])
        for _ in range(k):
            out = self.mul(out, a)
        return out

    def reduce(self, c: fmpq_poly) -> fmpq_poly:
        """A product's ``Σ c_j(λ) λ̄^j`` (``j ≤ 2e − 2``) reduced: ``λ̄^e`` by ``q``, each
        ``c_j`` modulo ``p``."""
        if self.e == 1:
            return c % self.p
        B, e, q = self.B, self.e, self.q
        slots = [c.right_shift(B * j).truncate(B) for j in range(c.degree() // B + 1)]
        for j in reversed(range(e, len(slots))):
            top = slots[j] % self.p
            for i in range(e):
                slots[j - e + i] -= top * q[i]
        return sum((slots[j] % self.p).left_shift(B * j) for j in range(min(e, len(slots))))

    def mul(self, a: fmpq_poly, b: fmpq_poly) -> fmpq_poly:
        return self.reduce(a * b)

    def inv(self, a: fmpq_poly) -> fmpq_poly:
        """``1/a``: by FLINT's xgcd in ``K``, else the rational solve of ``a·x = 1``."""
        if self.e == 1:
            g, s, _ = a.xgcd(self.p)
            return s / g[0]
        D = len(self.basis)
        columns = [self.mul(a, fmpq_poly([0] * k + [1])) for k in self.basis]
        A = fmpq_mat(D, D, [c[k] for k in self.basis for c in columns])
        x = A.solve(fmpq_mat(D, 1, [1] + [0] * (D - 1)))
        return sum((x[i, 0] * fmpq_poly([0] * k + [1]) for i, k in enumerate(self.basis)),
                   fmpq_poly())

    def conj(self, a: fmpq_poly) -> fmpq_poly:
        """Complex conjugation: ``λ ↔ λ̄``."""
        return sum((a[k] * self.images[k] for k in self.basis if a[k] != 0), fmpq_poly())

    def value(self, a: fmpq_poly, prec: int) -> acb:
        """``a`` as a ball at ``prec`` bits."""
        with ctx.workprec(prec):
            if prec not in self._roots:
                self._roots[prec] = next(z for z, _ in self.p.complex_roots()
                                         if z.overlaps(self.root))
            lam = self._roots[prec]
            bar = lam.conjugate()
            out = acb(0)
            for j in reversed(range(self.e)):
                part = fmpq_poly([a[i + self.B * j] for i in range(self.d)])
                out = out * bar + acb_poly(part)(lam)
            return out

    def expression(self, a: fmpq_poly, lam: sp.Expr, lambar: sp.Expr) -> sp.Expr:
        """``a`` as a SymPy expression of the given ``λ`` and ``λ̄``."""
        return sum((sp.Rational(int(a[k].p), int(a[k].q)) * lam ** (k % self.B)
                    * lambar ** (k // self.B) for k in self.basis), sp.Integer(0))

    def text(self, a: fmpq_poly) -> str:
        """``a`` as a polynomial in ``lambda`` and ``lambdabar`` (``3/8*lambda**2 - 1/2``)."""
        terms = []
        for k in sorted(self.basis, key=lambda k: (-(k // self.B), -(k % self.B))):
            c = a[k]
            if c == 0:
                continue
            i, j = k % self.B, k // self.B
            power = "*".join(f"{name}**{m}" if m > 1 else name
                             for name, m in (("lambda", i), ("lambdabar", j)) if m)
            if not power:
                terms.append(str(c))
            else:
                terms.append(power if c == 1 else "-" + power if c == -1 else f"{c}*{power}")
        return " + ".join(terms).replace("+ -", "- ") or "0"

    def decimal(self, a: fmpq_poly) -> tuple[str, str]:
        """``a``'s real and imaginary parts to :data:`DIGITS` digits (``0`` where exactly
        zero)."""
        b = self.conj(a)
        zero = (a + b == 0, a - b == 0)
        prec = PRECISION
        while True:
            z = self.value(a, prec)
            parts = [None if zero[i] else x for i, x in enumerate((z.real, z.imag))]
            if all(x is None or x.rel_accuracy_bits() > 3.33 * DIGITS + 8 for x in parts):
                with ctx.workprec(prec):
                    return tuple("0" if x is None else x.str(DIGITS, radius=False)
                                 for x in parts)
            prec *= 2


def _text(a: fmpq_poly, name: str) -> str:
    """A polynomial (coefficients ``a``, lowest first: rationals, or strings of ``K``'s
    elements, parenthesised where sums) written in ``name``, highest power first."""
    terms = []
    for i in reversed(range(len(a))):
        c = str(a[i])
        if c == "0":
            continue
        power = "" if i == 0 else name if i == 1 else f"{name}**{i}"
        if not power:
            terms.append(c)
        elif c in ("1", "-1"):
            terms.append(("-" if c == "-1" else "") + power)
        else:
            terms.append(f"({c})*{power}" if " " in c else f"{c}*{power}")
    return " + ".join(terms).replace("+ -", "- ") or "0"


def _field(P: fmpq_poly, mode: int) -> Field:
    """The field of mode ``mode``'s ``λ`` (by increasing ``Im λ > 0``, as analysis.ssm)."""
    with ctx.workprec(PRECISION):
        upper = sorted(((z, f, k) for f, k in P.factor()[1] for z, _ in f.complex_roots()
                        if z.imag > 0), key=lambda u: float(u[0].imag.mid()))
        if mode > len(upper):
            raise InputError(f"--mode {mode}: the system has {len(upper)} oscillating "
                             f"mode{'s' * (len(upper) != 1)} (complex eigenvalues)")
        lam, p, mult = upper[mode - 1]
        if mult > 1:
            raise InputError(f"--mode {mode}: its eigenvalue is repeated (an exact 1:1 "
                             "internal resonance: the 2-D SSM does not exist)")
        p = p / p.leading_coefficient()
        alphas = [z for z, _ in p.complex_roots()]
        t = 2
        while True:
            sums = [a + t * b for a in alphas for b in alphas]
            if not any(u.overlaps(v) for i, u in enumerate(sums) for v in sums[:i]):
                break
            t += 1
        two = fmpq_mpoly_ctx.get(("x", "z"), "lex")
        x, z = two.gens()
        zero = two.from_dict({})
        R = sum((c * x**k for k, c in enumerate(p.coeffs())), zero).resultant(
            sum((c * (z - t * x) ** k for k, c in enumerate(p.coeffs())), zero), "x")
        terms = R.to_dict()
        R = fmpq_poly([terms.get((0, k), 0) for k in range(max(e[1] for e in terms) + 1)])
        theta = lam.conjugate() + t * lam
        m = next(f for f, _ in R.factor()[1] if acb_poly(f)(theta).contains(0))
    # λ̄'s minimal polynomial over K = Q(λ): gcd(p(y)/(y − λ), m(y + tλ)) (Trager)
    def mul(a, b):
        return a * b % p

    def inv(a):
        g, s, _ = a.xgcd(p)
        return s / g[0]

    X = fmpq_poly([0, 1])
    h = [fmpq_poly([1])]
    for c in reversed(p.coeffs()[1:-1]):
        h.insert(0, c + mul(X, h[0]))
    shifted = [fmpq_poly()]
    for c in reversed(m.coeffs()):
        shifted = _padd([mul(t * X, u) for u in shifted] + [fmpq_poly()],
                        [fmpq_poly(), *shifted])
        shifted[0] += c
    q = _gcd(mul, inv, h, shifted)
    assert len(q) - 1 == m.degree() // p.degree(), "θ = λ̄ + tλ separates the roots"
    return Field(p, q, lam)


def _padd(a: list, b: list) -> list:
    n = max(len(a), len(b))
    return [(a[i] if i < len(a) else 0) + (b[i] if i < len(b) else 0) for i in range(n)]


def _trim(a: list) -> list:
    while a and a[-1] == 0:
        a = a[:-1]
    return a


def _gcd(mul, inv, a: list, b: list) -> list:
    """The monic gcd of two polynomials over ``K`` (coefficient lists, lowest first)."""
    a, b = _trim(list(a)), _trim(list(b))
    while b:
        lead = inv(b[-1])
        while len(a) >= len(b):
            c, shift = mul(a[-1], lead), len(a) - len(b)
            for i, u in enumerate(b):
                a[i + shift] = a[i + shift] - mul(c, u)
            a = _trim(a[:-1])
        a, b = b, a
    lead = inv(a[-1])
    return [mul(u, lead) for u in a]


def _eliminate(F: Field, A: list[list], rhs: list | None = None
               ) -> tuple[list[list], list[int]]:
    """The reduced row echelon form of ``A`` (augmented by the column ``rhs``), and the pivot
    columns (of ``A``'s)."""
    A = [list(row) + ([rhs[i]] if rhs is not None else []) for i, row in enumerate(A)]
    rows, cols = len(A), len(A[0]) - (rhs is not None)
    pivots: list[int] = []
    for j in range(cols):
        i = next((i for i in range(len(pivots), rows) if A[i][j] != 0), None)
        if i is None:
            continue
        r = len(pivots)
        A[r], A[i] = A[i], A[r]
        lead = F.inv(A[r][j])
        A[r] = [F.mul(u, lead) for u in A[r]]
        for i in range(rows):
            if i != r and A[i][j] != 0:
                q = A[i][j]
                A[i] = [u - F.mul(q, v) for u, v in zip(A[i], A[r], strict=True)]
        pivots.append(j)
    return A, pivots


def _solve(F: Field, A: list[list], rhs: list) -> list | None:
    """``A⁻¹ rhs``, or None where ``A`` is singular."""
    R, pivots = _eliminate(F, A, rhs)
    return [row[-1] for row in R] if len(pivots) == len(A) else None


def _null(F: Field, A: list[list]) -> list:
    """A null vector of ``A`` of rank ``n − 1``."""
    R, pivots = _eliminate(F, A)
    free = next(j for j in range(len(A)) if j not in pivots)
    x = [fmpq_poly() for _ in A]
    x[free] = fmpq_poly([1])
    for row, j in zip(R, pivots, strict=False):
        x[j] = -row[free]
    return x


def _q(r: sp.Rational) -> fmpq:
    return fmpq(int(r.p), int(r.q))


def _horner(F: Field, poly: fmpq_poly, s: fmpq_poly) -> fmpq_poly:
    out = fmpq_poly()
    for c in reversed(poly.coeffs()):
        out = F.mul(out, s) + c
    return out


def _resonance(mode: int, k: int, r: int) -> None:
    raise InputError(f"--mode {mode}: order {k}, monomial p1^{k - r} p2^{r}: s = (k - r)λ + rλ̄ "
                     "is exactly another eigenvalue (an exact internal resonance: the 2-D SSM "
                     "does not exist; lower --order below it)")


@dataclass(frozen=True)
class ExactSSM:
    """``γ_j`` of mode ``mode`` to ``order`` exactly: λ's minimal polynomial over Q (in
    ``x``) and its value (real, imaginary; 30 digits); λ̄'s minimal polynomial over Q(λ) (in
    ``x``, its coefficients polynomials in ``lambda``) and the field's degree; the
    normalisation ``φ_i = 1``; each ``γ_j`` exact (a polynomial in ``lambda`` and
    ``lambdabar``) and to 30 digits; the factor ``ν`` (exact and decimal) with ``γ_j ν^j`` =
    analysis.ssm's ``gamma`` (``converted``, 30 digits)."""

    mode: int
    order: int
    minimal_polynomial: str
    lam: tuple[str, str]
    conjugate_polynomial: str
    degree: int
    normalisation: str
    gamma_exact: tuple[str, ...]
    gamma_decimal: tuple[tuple[str, str], ...]
    factor: str
    factor_decimal: str
    converted: tuple[tuple[str, str], ...]
    number_field: Field = field(repr=False, compare=False)
    elements: tuple[fmpq_poly, ...] = field(repr=False, compare=False)
    nu: fmpq_poly = field(repr=False, compare=False)

    @property
    def gamma(self) -> tuple[complex, ...]:
        """analysis.ssm's ``gamma`` from the 30 digits (to rounding)."""
        return tuple(complex(float(re), float(im)) for re, im in self.converted)

    def json(self) -> dict:
        """The suggested ``gamma_exact`` of ``lindstedt ssm --exact --json``."""
        return {"field": {"lambda": self.minimal_polynomial,
                          "lambdabar": self.conjugate_polynomial, "degree": self.degree},
                "lambda": {"re": self.lam[0], "im": self.lam[1]},
                "normalisation": self.normalisation,
                "factor": {"exact": self.factor, "decimal": self.factor_decimal,
                           "rule": "gamma_j = gamma_exact_j * factor**j"},
                "gamma": [{"j": j, "exact": e, "re": d[0], "im": d[1],
                           "converted": {"re": c[0], "im": c[1]}}
                          for j, (e, d, c) in enumerate(zip(self.gamma_exact,
                                                            self.gamma_decimal,
                                                            self.converted, strict=True))]}


def _check(system: System, order: int) -> None:
    if not system.exact:
        raise InputError(f"--exact: {system.text}: a model read in floating point has no exact "
                         "form (drop --exact)")
    if system.size > MAX_EXACT:
        raise InputError(f"--exact: {system.size} coordinates; the exact ground takes at most "
                         f"{MAX_EXACT} (drop --exact: floating point)")
    known = set(system.coordinates) | set(system.velocities)
    left = sorted({str(x) for f in system.force for x in sp.sympify(f).free_symbols} - set(
        map(str, known)))
    if left:
        raise InputError(f"--exact: {', '.join(left)} left symbolic: give "
                         f"{'them values' if len(left) > 1 else 'it a value'} with --param")
    if order < 1:
        raise InputError(f"--order {order}: at least 1")


def exact_gamma(system: System, mode: int, order: int) -> ExactSSM:
    """The normal form's ``γ_j`` (``2j + 1 ≤ order``) of ``mode``'s SSM exactly (rational
    data, at most :data:`MAX_EXACT` coordinates)."""
    _check(system, order)
    n = system.size
    s_ = sp.Symbol("s")
    D = system.damping if system.damping is not None else sp.zeros(n, n)
    S = system.stiffness
    P = sp.Poly((s_**2 * sp.eye(n) + s_ * D + S).det(), s_)
    charpoly = fmpq_poly([_q(c) for c in reversed(P.all_coeffs())])
    F = _field(charpoly, mode)
    Dq = [[_q(D[i, j]) for j in range(n)] for i in range(n)]
    Sq = [[_q(S[i, j]) for j in range(n)] for i in range(n)]
    lam, lambar = F.lam, F.lambar

    def pencil(s: fmpq_poly) -> list[list]:
        s2 = F.mul(s, s)
        return [[(s2 if i == j else 0) + s * Dq[i][j] + Sq[i][j] for j in range(n)]
                for i in range(n)]

    def apply(A: list[list], x: list) -> list:
        return [sum((F.mul(a, u) for a, u in zip(row, x, strict=True)), fmpq_poly())
                for row in A]

    L = pencil(lam)
    phi = _null(F, L)
    left = _null(F, [list(col) for col in zip(*L, strict=True)])
    sizes = [abs(F.value(u, PRECISION)).mid() for u in phi]
    top = max(range(n), key=lambda i: (sizes[i], -i))
    scale = F.inv(phi[top])
    phi = [F.mul(u, scale) for u in phi]
    phibar = [F.conj(u) for u in phi]
    terms = []
    for i, f in enumerate(system.force):
        f = sp.expand(f)
        if f != 0:
            for powers, c in sp.Poly(f, *system.coordinates, *system.velocities).terms():
                terms.append((i, powers, _q(c)))
    Z = [None, [phi + [F.mul(lam, u) for u in phi], phibar + [F.mul(lambar, u) for u in phibar]]]
    cache: dict = {}

    def monomial(e: tuple, k: int) -> list:
        """Order ``k``'s rows of ``z^e`` (``z = (x, x')``) from the orders below ``k``."""
        i = next(i for i, a in enumerate(e) if a)
        if sum(e) == 1:
            return [row[i] for row in Z[k]]
        if (e, k) not in cache:
            rest = tuple(a - (j == i) for j, a in enumerate(e))
            out = [fmpq_poly() for _ in range(k + 1)]
            for a in range(1, k - sum(rest) + 1):
                B = monomial(rest, k - a)
                for r1, row in enumerate(Z[a]):
                    if row[i] != 0:
                        for r2, y in enumerate(B):
                            if y != 0:
                                out[r1 + r2] += F.mul(row[i], y)
            cache[e, k] = out
        return cache[e, k]

    gamma, gbar = [lam], [lambar]
    for k in range(2, order + 1):
        force = [[fmpq_poly() for _ in range(n)] for _ in range(k // 2 + 1)]
        for i, e, c in terms:
            for r, u in enumerate(monomial(e, k)[:k // 2 + 1]):
                force[r][i] += c * u
        rows = []
        for r in range(k // 2 + 1):
            QW = [fmpq_poly() for _ in range(n)]
            QV = [fmpq_poly() for _ in range(n)]
            for j in range(1, len(gamma)):
                q, rq = k - 2 * j, r - j
                if q >= 2 and 0 <= rq <= q:
                    mult = (q - rq) * gamma[j] + rq * gbar[j]
                    QW = [u + F.mul(mult, x) for u, x in zip(QW, Z[q][rq][:n], strict=True)]
                    QV = [u + F.mul(mult, x) for u, x in zip(QV, Z[q][rq][n:], strict=True)]
            s = (k - r) * lam + r * lambar
            A = pencil(s)
            rhs = [-f - u - v for f, u, v in zip(force[r], apply(
                [[s * (i == j) + Dq[i][j] for j in range(n)] for i in range(n)], QW), QV,
                strict=True)]
            resonant = k % 2 == 1 and r == (k - 1) // 2
            if resonant and s != lam and _horner(F, charpoly, s) == 0:
                _resonance(mode, k, r)
            if resonant:
                shifted = [[(s + lam) * (i == j) + Dq[i][j] for j in range(n)]
                           for i in range(n)]
                b = apply(shifted, phi)
                c = apply([list(col) for col in zip(*shifted, strict=True)], left)
                d = sum((F.mul(a, u) for a, u in zip(left, phi, strict=True)), fmpq_poly())
                e = -sum((F.mul(a, u) for a, u in zip(left, QW, strict=True)), fmpq_poly())
                x = _solve(F, [*([*row, bi] for row, bi in zip(A, b, strict=True)), [*c, d]],
                           [*rhs, e])
                if x is None:
                    _resonance(mode, k, r)
                Wm, gj = x[:n], x[n]
                gamma.append(gj)
                gbar.append(F.conj(gj))
                Vm = [F.mul(s, u) + q + F.mul(p, gj) for u, q, p in zip(Wm, QW, phi,
                                                                         strict=True)]
            else:
                Wm = _solve(F, A, rhs)
                if Wm is None:
                    _resonance(mode, k, r)
                Vm = [F.mul(s, u) + q for u, q in zip(Wm, QW, strict=True)]
            rows.append(Wm + Vm)
        rows += [[F.conj(u) for u in rows[k - r]] for r in range(k // 2 + 1, k + 1)]
        Z.append(rows)
    Mq = [[_q(system.mass[i, j]) for j in range(n)] for i in range(n)]
    nu = F.inv(4 * sum((F.mul(a, u) for a, u in zip(phibar, apply(Mq, phi), strict=True)),
                       fmpq_poly()))
    powers, u = [], fmpq_poly([1])
    for _ in gamma:
        powers.append(u)
        u = F.mul(u, nu)
    name = system.coordinates[top]
    return ExactSSM(
        mode, order, _text(F.p, "x"), F.decimal(lam),
        _text([_text(c, "lambda") for c in F.q], "x"), F.d * F.e,
        f"phi[{name}] = 1 (the mode's largest component); w: any left eigenvector",
        tuple(F.text(g) for g in gamma), tuple(F.decimal(g) for g in gamma), F.text(nu),
        F.decimal(nu)[0], tuple(F.decimal(F.mul(g, p)) for g, p in zip(gamma, powers,
                                                                       strict=True)),
        F, tuple(gamma), nu)
