"""The normal form of an SSM exactly: :mod:`analysis.ssm`'s ``γ_j`` in the eigenvalues' number
field, for systems with rational coefficients and at most three coordinates.

**The field.**  ``λ`` (the mode's eigenvalue) is a root of ``det(s²I + sD + S)`` (the lowered
``D = M⁻¹C``, ``S = M⁻¹K``); its irreducible factor ``p`` (degree ``d ≤ 6``) is λ's minimal
polynomial, and ``λ̄`` another of its roots.  Every number lives in
``Q(λ, λ̄) = K[λ̄]/(q)``, ``K = Q[λ]/(p)``, ``q`` λ̄'s minimal polynomial over ``K``, of
degree ``e``: 1 where ``λ̄ ∈ Q(λ)`` (undamped, ``λ̄ = −λ``; one coordinate, ``λ̄ = −c − λ``;
proportional damping), up to ``d − 1`` (generic damping: degree 12 for two coordinates, 30 for
three).  ``q`` is Trager's factor: ``θ = λ̄ + tλ`` (the first integer ``t ≥ 2`` for which the
``d²`` sums ``α_j + tα_i`` of p's roots are apart) has the minimal polynomial ``m``, the factor
of ``Res_x(p(x), p(z − tx))`` vanishing at θ, and ``q = gcd(p(y)/(y − λ), m(y + tλ))`` over
``K``.  The basis ``λ^i λ̄^j`` keeps the coefficients far smaller than a primitive element's
powers (λ alone had 3400-bit coefficients in θ's at degree 30, and order 3 took 36 s, not
0.2 s).  Complex conjugation is the automorphism ``λ ↔ λ̄``.

**The normal form** is analysis.ssm's recursion row by row, each resonant row in the same
normalisation (``ψᵀB(W_m, V_m) = 0``), in the lowered form ``M = I``: its equations are
``M⁻¹`` times analysis.ssm's and its left eigenvector ``Mᵀ`` times theirs, so ``W``, ``V``,
``γ`` are the same.  Each row's ``n × n`` (resonant: bordered ``(n + 1) × (n + 1)``) system is
solved by Gaussian elimination in the field; a row whose ``s ≠ λ`` is exactly an eigenvalue
is an exact internal resonance, refused.

**The normalisation** is algebraic: ``φ_i = 1`` at the component ``i`` where the mode's shape
is largest (analysis.ssm's ``φᴴMφ = 1/4`` needs a modulus and a square root).  There
``φ = κ·φ_exact``; scaling the amplitude ``p₁ → κp₁`` turns ``γ_j`` into ``γ_j|κ|^{2j}``:

    γ_j (analysis.ssm) = γ_j (exact) · ν^j,    ν = |κ|² = 1 / (4 φ̄ᵀ M φ),

``ν`` a real element of the field (``φ̄`` the conjugate of the exact φ, ``M`` the system's
mass).  Decimals are the exact numbers evaluated in ball arithmetic (arb), the precision
doubled until 30 digits are certain; a real or imaginary part that vanishes exactly is decided
in the field and written ``0``."""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp
from flint import acb, acb_poly, ctx, fmpq, fmpq_mat, fmpq_mpoly_ctx, fmpq_poly, fmpz, fmpz_mat

from ..errors import InputError
from .system import System

MAX_EXACT = 3
# NOTE: the most coordinates of the exact ground: Q(λ, λ̄) has degree up to 2n(2n − 1) (30 at
# n = 3), and its elements' coefficients grow with the order (10⁴ bits at order 15, degree 12).
DIGITS = 30
PRECISION = 128
# NOTE: the first working precision (bits) of the root isolation and of each decimal; doubled
# until the balls are narrow enough (certified 30 digits).


class Field:
    """``Q(λ, λ̄) = K[λ̄]/(q)``: ``p`` λ's minimal polynomial (degree ``d``), ``q`` λ̄'s over
    ``K`` (monic, degree ``e``, coefficients in ``K`` lowest first), ``root`` λ's ball.  An
    element ``Σ a_ij λ^i λ̄^j`` (``i < d``, ``j < e``) is the ``fmpq_poly``
    ``Σ a_ij X^(i + Bj)``, ``B = 2d − 1`` (Kronecker: a product's terms do not overlap), so
    sums, rational multiples and products are FLINT's; a product is then reduced."""

    def __init__(self, p: fmpq_poly, q: list[fmpq_poly], root: acb) -> None:
        self.p, self.q, self.root = p, q, root
        d, e = p.degree(), len(q) - 1
        self.d, self.e, self.B = d, e, 2 * d - 1
        self.basis = [i + self.B * j for j in range(e) for i in range(d)]
        self._roots: dict[int, acb] = {}
        if e > 1:  # every monomial of a product reduced, over one denominator
            rows = [self._reduced(fmpq_poly([0] * k + [1]))
                    for k in range(self.B * (2 * e - 2) + 2 * d - 1)]
            self.den = fmpz(1)
            for r in rows:
                self.den = self.den.lcm(r.denom())
            self.table = fmpz_mat(len(rows), len(self.basis),
                                  [(r[k] * self.den).p for r in rows for k in self.basis])
        self.lam = fmpq_poly([0, 1])
        self.lambar = -q[0] if e == 1 else fmpq_poly([0] * self.B + [1])
        self.images = {k: self.mul(self.power(self.lambar, k % self.B),
                                   self.power(self.lam, k // self.B)) for k in self.basis}

    def power(self, a: fmpq_poly, k: int) -> fmpq_poly:
        """``a^k``."""
        out = fmpq_poly([1])
        for _ in range(k):
            out = self.mul(out, a)
        return out

    def _reduced(self, c: fmpq_poly) -> fmpq_poly:
        """``Σ c_j(λ) λ̄^j`` reduced: ``λ̄^e`` by ``q``, each ``c_j`` modulo ``p`` (tabulated
        once for :meth:`reduce`)."""
        B, e = self.B, self.e
        slots = [c.right_shift(B * j).truncate(B) for j in range(c.degree() // B + 1)]
        for j in reversed(range(e, len(slots))):
            top = slots[j] % self.p
            for i in range(e):
                slots[j - e + i] -= top * self.q[i]
        return sum((slots[j] % self.p).left_shift(B * j) for j in range(min(e, len(slots))))

    def reduce(self, c: fmpq_poly) -> fmpq_poly:
        """A product reduced to the basis: modulo ``p``, or one integer matrix product."""
        if self.e == 1:
            return c % self.p
        coeffs = c.numer().coeffs()
        coeffs += [0] * (self.table.nrows() - len(coeffs))
        full = [0] * (self.basis[-1] + 1)
        for k, x in zip(self.basis, (fmpz_mat(1, len(coeffs), coeffs) * self.table).entries(),
                        strict=True):
            full[k] = x
        return fmpq_poly(full, c.denom() * self.den)

    def mul(self, a: fmpq_poly, b: fmpq_poly) -> fmpq_poly:
        return self.reduce(a * b)

    def inv(self, a: fmpq_poly) -> fmpq_poly:
        """``1/a``: FLINT's xgcd in ``K``, else the rational solve of ``a·x = 1``."""
        if self.e == 1:
            g, s, _ = a.xgcd(self.p)
            return s / g[0]
        D = len(self.basis)
        columns = [self.mul(a, fmpq_poly([0] * k + [1])) for k in self.basis]
        x = fmpq_mat(D, D, [c[k] for k in self.basis for c in columns]).solve(
            fmpq_mat(D, 1, [1] + [0] * (D - 1)))
        return sum((x[i, 0] * fmpq_poly([0] * k + [1]) for i, k in enumerate(self.basis)),
                   fmpq_poly())

    def conj(self, a: fmpq_poly) -> fmpq_poly:
        """Complex conjugation, ``λ ↔ λ̄``."""
        return sum((a[k] * self.images[k] for k in self.basis if a[k] != 0), fmpq_poly())

    def slots(self, a: fmpq_poly) -> list[fmpq_poly]:
        """``a``'s coefficients of ``λ̄^j`` (elements of ``K``), lowest first."""
        return [fmpq_poly([a[i + self.B * j] for i in range(self.d)]) for j in range(self.e)]

    def value(self, a: fmpq_poly, prec: int) -> acb:
        """``a`` as a ball at ``prec`` bits."""
        with ctx.workprec(prec):
            if prec not in self._roots:
                self._roots[prec] = next(z for z, _ in self.p.complex_roots()
                                         if z.overlaps(self.root))
            lam = self._roots[prec]
            out = acb(0)
            for part in reversed(self.slots(a)):
                out = out * lam.conjugate() + acb_poly(part)(lam)
            return out

    def expression(self, a: fmpq_poly, lam: sp.Expr, lambar: sp.Expr) -> sp.Expr:
        """``a`` as a SymPy expression of the given ``λ`` and ``λ̄``."""
        return sum((sp.Rational(int(c.p), int(c.q)) * lam**i * lambar**j
                    for j, part in enumerate(self.slots(a)) for i, c in enumerate(part.coeffs())),
                   sp.Integer(0))

    def text(self, a: fmpq_poly) -> str:
        """``a`` in ``lambda`` and ``lambdabar``: ``(3/2*lambda + 1)*lambdabar - lambda``."""
        return _text([_text(part, "lambda") for part in self.slots(a)], "lambdabar")

    def decimal(self, a: fmpq_poly) -> tuple[str, str]:
        """``a``'s real and imaginary parts to :data:`DIGITS` digits."""
        b = self.conj(a)
        zero = (a + b == 0, a - b == 0)
        prec = PRECISION
        while True:
            z = self.value(a, prec)
            parts = [None if zero[i] else x for i, x in enumerate((z.real, z.imag))]
            if all(x is None or x.rel_accuracy_bits() > 3.33 * DIGITS + 8 for x in parts):
                return tuple("0" if x is None else x.str(DIGITS, radius=False) for x in parts)
            prec *= 2


def _text(a, name: str) -> str:
    """A polynomial in ``name`` (coefficients ``a`` lowest first: rationals, or strings,
    parenthesised where sums), highest power first."""
    terms = []
    for i in reversed(range(len(a))):
        c = str(a[i])
        if c == "0":
            continue
        power = "" if i == 0 else name if i == 1 else f"{name}**{i}"
        if not power:
            terms.append(c)
        elif c in ("1", "-1"):
            terms.append(c[:-1] + power)
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
            sum((c * (z - t * x) ** k for k, c in enumerate(p.coeffs())), zero), "x").to_dict()
        R = fmpq_poly([R.get((0, k), 0) for k in range(max(k for _, k in R) + 1)])
        m = next(f for f, _ in R.factor()[1]
                 if acb_poly(f)(lam.conjugate() + t * lam).contains(0))

    def mul(a: fmpq_poly, b: fmpq_poly) -> fmpq_poly:
        return a * b % p

    def inv(a: fmpq_poly) -> fmpq_poly:
        g, s, _ = a.xgcd(p)
        return s / g[0]

    X = fmpq_poly([0, 1])
    h = [fmpq_poly([1])]  # p(y)/(y − λ) over K
    for c in reversed(p.coeffs()[1:-1]):
        h.insert(0, c + mul(X, h[0]))
    shifted: list[fmpq_poly] = []  # m(y + tλ) over K
    for c in reversed(m.coeffs()):
        new = [fmpq_poly() for _ in range(len(shifted) + 1)]
        for i, u in enumerate(shifted):
            new[i + 1] += u
            new[i] += mul(t * X, u)
        new[0] += c
        shifted = new
    q = _gcd(mul, inv, h, shifted)
    assert len(q) - 1 == m.degree() // p.degree(), "θ = λ̄ + tλ separates the roots"
    return Field(p, q, lam)


def _gcd(mul, inv, a: list, b: list) -> list:
    """The monic gcd of two polynomials over ``K`` (coefficient lists, lowest first)."""
    def trim(a: list) -> list:
        while a and a[-1] == 0:
            a = a[:-1]
        return a

    a, b = trim(list(a)), trim(list(b))
    while b:
        lead = inv(b[-1])
        while len(a) >= len(b):
            c, shift = mul(a[-1], lead), len(a) - len(b)
            for i, u in enumerate(b):
                a[i + shift] -= mul(c, u)
            a = trim(a[:-1])
        a, b = b, a
    lead = inv(a[-1])
    return [mul(u, lead) for u in a]


def _eliminate(F: Field, A: list[list], rhs: list | None = None
               ) -> tuple[list[list], list[int]]:
    """The reduced row echelon form of ``A`` (augmented by the column ``rhs``) and its pivot
    columns."""
    A = [list(row) + ([rhs[i]] if rhs is not None else []) for i, row in enumerate(A)]
    pivots: list[int] = []
    for j in range(len(A[0]) - (rhs is not None)):
        i = next((i for i in range(len(pivots), len(A)) if A[i][j] != 0), None)
        if i is None:
            continue
        r = len(pivots)
        A[r], A[i] = A[i], A[r]
        lead = F.inv(A[r][j])
        A[r] = [F.mul(u, lead) for u in A[r]]
        for i in range(len(A)):
            if i != r and A[i][j] != 0:
                c = A[i][j]
                A[i] = [u - F.mul(c, v) for u, v in zip(A[i], A[r], strict=True)]
        pivots.append(j)
    return A, pivots


def _solve(F: Field, A: list[list], rhs: list) -> list | None:
    """``A⁻¹ rhs``, or None where ``A`` is singular."""
    R, pivots = _eliminate(F, A, rhs)
    return [row[-1] for row in R] if len(pivots) == len(A) else None


def _null(F: Field, A: list[list]) -> list:
    """A null vector of ``A`` (rank ``n − 1``)."""
    R, pivots = _eliminate(F, A)
    free = next(j for j in range(len(A)) if j not in pivots)
    x = [fmpq_poly([int(j == free)]) for j in range(len(A))]
    for row, j in zip(R, pivots, strict=False):
        x[j] = -row[free]
    return x


def _q(r: sp.Rational) -> fmpq:
    return fmpq(int(r.p), int(r.q))


@dataclass(frozen=True)
class ExactSSM:
    """``γ_j`` of mode ``mode`` to ``order`` exactly: λ's minimal polynomial over Q (in ``x``)
    and its value (real, imaginary: 30 digits); λ̄'s minimal polynomial over Q(λ) (in ``x``,
    coefficients in ``lambda``) and the field's degree over Q; the normalisation; each ``γ_j``
    exact (in ``lambda``, ``lambdabar``) and to 30 digits; the factor ``ν`` (exact, decimal)
    with ``γ_j ν^j`` analysis.ssm's ``gamma`` (``converted``: 30 digits)."""

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
    elements: tuple[fmpq_poly, ...] = field(repr=False, compare=False)  # γ_j
    nu: fmpq_poly = field(repr=False, compare=False)

    @property
    def gamma(self) -> tuple[complex, ...]:
        """analysis.ssm's ``gamma``, from the 30 digits."""
        return tuple(complex(float(re), float(im)) for re, im in self.converted)

    def json(self) -> dict:
        """The suggested ``gamma_exact`` of ``lindstedt ssm --exact --json``."""
        return {"field": {"lambda_polynomial": self.minimal_polynomial,
                          "lambdabar_polynomial": self.conjugate_polynomial,
                          "degree": self.degree},
                "lambda": {"re": self.lam[0], "im": self.lam[1]},
                "normalisation": self.normalisation,
                "factor": {"exact": self.factor, "decimal": self.factor_decimal,
                           "rule": "gamma[j] = gamma_exact[j] * factor**j"},
                "gamma": [{"j": j, "exact": e, "re": d[0], "im": d[1],
                           "converted": {"re": c[0], "im": c[1]}}
                          for j, (e, d, c) in enumerate(zip(
                              self.gamma_exact, self.gamma_decimal, self.converted,
                              strict=True))]}


def _check(system: System, order: int) -> None:
    if not system.exact:
        raise InputError(f"--exact: {system.text}: a model read in floating point has no exact "
                         "form (drop --exact)")
    if system.size > MAX_EXACT:
        raise InputError(f"--exact: {system.size} coordinates; the exact ground takes at most "
                         f"{MAX_EXACT} (drop --exact: floating point)")
    known = {str(x) for x in (*system.coordinates, *system.velocities)}
    left = sorted({str(x) for f in system.force for x in sp.sympify(f).free_symbols} - known)
    if left:
        raise InputError(f"--exact: {', '.join(left)} left symbolic: give "
                         f"{'them values' if len(left) > 1 else 'it a value'} with --param")
    if order < 1:
        raise InputError(f"--order {order}: at least 1")


def _resonance(mode: int, k: int, r: int) -> None:
    raise InputError(f"--mode {mode}: order {k}, monomial p1^{k - r} p2^{r}: s = (k - r)λ + rλ̄ "
                     "is exactly another eigenvalue (an exact internal resonance: the 2-D SSM "
                     "does not exist; lower --order below it)")


def exact_gamma(system: System, mode: int, order: int) -> ExactSSM:
    """The normal form's ``γ_j`` (``2j + 1 ≤ order``) of ``mode``'s SSM exactly (rational
    data, at most :data:`MAX_EXACT` coordinates)."""
    _check(system, order)
    n = system.size
    D = system.damping if system.damping is not None else sp.zeros(n, n)
    s_ = sp.Symbol("s")
    P = sp.Poly((s_**2 * sp.eye(n) + s_ * D + system.stiffness).det(), s_)
    charpoly = fmpq_poly([_q(c) for c in reversed(P.all_coeffs())])
    F = _field(charpoly, mode)
    Dq = [[_q(D[i, j]) for j in range(n)] for i in range(n)]
    Sq = [[_q(system.stiffness[i, j]) for j in range(n)] for i in range(n)]
    lam, lambar = F.lam, F.lambar

    def dot(a: list, b: list) -> fmpq_poly:
        return sum((F.mul(x, y) for x, y in zip(a, b, strict=True)), fmpq_poly())

    def shifted(s: fmpq_poly) -> list[list]:  # sI + D
        return [[s * (i == j) + Dq[i][j] for j in range(n)] for i in range(n)]

    def pencil(s: fmpq_poly) -> list[list]:  # L(s) = s²I + sD + S
        return [[F.mul(s, a) + Sq[i][j] for j, a in enumerate(row)]
                for i, row in enumerate(shifted(s))]

    L = pencil(lam)
    phi = _null(F, L)
    left = _null(F, [list(col) for col in zip(*L, strict=True)])
    top = max(range(n), key=lambda i: (abs(F.value(phi[i], PRECISION)).mid(), -i))
    scale = F.inv(phi[top])
    phi = [F.mul(u, scale) for u in phi]
    phibar = [F.conj(u) for u in phi]
    terms = [(i, powers, _q(c)) for i, f in enumerate(system.force) if sp.expand(f) != 0
             for powers, c in sp.Poly(f, *system.coordinates, *system.velocities).terms()]
    # Z[k][r]: order k's row r (monomial p1^(k−r) p2^r) of the state (W, V)
    Z = [None, [phi + [F.mul(lam, u) for u in phi], phibar + [F.mul(lambar, u) for u in phibar]]]
    cache: dict = {}

    def monomial(e: tuple, k: int) -> list:
        """Order ``k``'s rows of ``z^e`` (``z = (x, x')``), from the orders below ``k``."""
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
            QW = [fmpq_poly() for _ in range(n)]  # Σ_j W_q (m₁γ_j + m₂γ̄_j), q = k − 2j
            QV = [fmpq_poly() for _ in range(n)]
            for j in range(1, len(gamma)):
                q, rq = k - 2 * j, r - j
                if q >= 2 and 0 <= rq <= q:
                    g = (q - rq) * gamma[j] + rq * gbar[j]
                    QW = [u + F.mul(g, x) for u, x in zip(QW, Z[q][rq][:n], strict=True)]
                    QV = [u + F.mul(g, x) for u, x in zip(QV, Z[q][rq][n:], strict=True)]
            s = (k - r) * lam + r * lambar
            rhs = [-f - dot(row, QW) - v for f, row, v in zip(force[r], shifted(s), QV,
                                                                strict=True)]
            if k % 2 == 1 and r == (k - 1) // 2:  # resonant: γ_j, bordered
                if s != lam and sum(F.mul(c, F.power(s, i))
                                    for i, c in enumerate(charpoly.coeffs())) == 0:
                    _resonance(mode, k, r)
                A = shifted(s + lam)
                b = [dot(row, phi) for row in A]
                c = [dot(col, left) for col in zip(*A, strict=True)]
                x = _solve(F, [*([*row, bi] for row, bi in zip(pencil(s), b, strict=True)),
                               [*c, dot(left, phi)]], [*rhs, -dot(left, QW)])
                if x is None:
                    _resonance(mode, k, r)
                Wm, g = x[:n], x[n]
                gamma.append(g)
                gbar.append(F.conj(g))
                Vm = [F.mul(s, u) + w + F.mul(v, g) for u, w, v in zip(Wm, QW, phi, strict=True)]
            else:
                Wm = _solve(F, pencil(s), rhs)
                if Wm is None:
                    _resonance(mode, k, r)
                Vm = [F.mul(s, u) + w for u, w in zip(Wm, QW, strict=True)]
            rows.append(Wm + Vm)
        rows += [[F.conj(u) for u in rows[k - r]] for r in range(k // 2 + 1, k + 1)]
        Z.append(rows)
    mass = [[_q(system.mass[i, j]) for j in range(n)] for i in range(n)]
    nu = F.inv(4 * dot(phibar, [dot([fmpq_poly([m]) for m in row], phi) for row in mass]))
    converted = [F.mul(g, F.power(nu, j)) for j, g in enumerate(gamma)]
    return ExactSSM(
        mode, order, _text(F.p, "x"), F.decimal(lam),
        _text([_text(c, "lambda") for c in F.q], "x"), F.d * F.e,
        f"phi[{system.coordinates[top]}] = 1 (the mode's largest component)",
        tuple(F.text(g) for g in gamma), tuple(F.decimal(g) for g in gamma), F.text(nu),
        F.decimal(nu)[0], tuple(F.decimal(g) for g in converted), F, tuple(gamma), nu)
