"""Lindstedt–Poincaré series of a free oscillator, and the naive expansion it replaces.

With ``s = ωt``, ``ω = Σ ω_j y^j``, ``u = Σ y^j u_j(s)`` (notes §10.3), the ``y^j`` equation is::

    u_j'' + u_j = F_j(s) = -Σ_{a=1..j} W_a u_{j-a}'' - [y^j] Σ_k y^k Σ_n c_kn u^n,

where ``ω² = Σ W_a y^a``, ``W_j = 2ω_j + S_j`` and ``S_j = Σ_{a=1..j-1} ω_a ω_{j-a}``.  ``ω_j``
enters ``F_j`` only as ``W_j cos s`` (from ``-W_j u_0''``), so the secular condition (no
``cos s`` in ``F_j``) fixes it.  Amplitude convention of the notes: ``q(0) = A``,
``q̇(0) = 0``, hence ``u_j(0) = 0`` for ``j ≥ 1`` (the free ``cos s`` of each ``u_j`` is set by
it; the first-harmonic convention would give other coefficients).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from math import factorial
from typing import Any

import sympy as sp

from ..algebra.lazy import LazySeries, Linear, Mapped, Product, Terms
from ..algebra.resum import Singularity as Singularity
from ..algebra.resum import nearest_singularity
from ..algebra.resum import partial_sum as partial_sum
from ..algebra.resum import series_radius as series_radius
from ..algebra.series import Basis, Ground, solve_oscillator, to_fourier
from ..display import SHOWN_ORDERS, latex_aligned, latex_sum, latex_text, more
from ..errors import InputError
from .models import Model, check_order, t

CONVENTION = "q(0) = A, q'(0) = 0, so q_j(0) = 0 for j >= 1"
s = sp.Symbol("s")


@dataclass(frozen=True, repr=False)
class SeriesSolution:
    """The L–P series to order K, exact, in the scaled variable ``y`` of the model.

    ``omega[j]`` and ``period[j]`` are the coefficients of ``y^j`` in ``ω`` and ``T/2π``;
    ``q[j]`` maps harmonic ``n`` to the coefficient of ``y^j · amplitude · cos(n s)``.
    """

    model: Model
    order: int
    ground: Ground
    omega: tuple
    period: tuple
    q: tuple[dict[int, Any], ...]
    forcing: tuple  # F_j without its W_j cos s term, in the kernel's basis (display only)
    convention: str = CONVENTION

    def omega_expr(self) -> sp.Expr:
        """The frequency ``ω = Σ_j ω_j coupling^j`` to the solution's order, a SymPy expression in
        the model's own symbols (``A``, ``eps`` and the parameters; for a user's equation in
        its names, ω₀ included): ``1 + 3*A**2*eps/8 - 15*A**4*eps**2/256`` for Duffing."""
        m = self.model
        return sp.Add(*(c * m.coupling**j for j, c in enumerate(omega_coefficients(self))))

    def period_expr(self) -> sp.Expr:
        """The period ``T = (2π/ω₀) Σ_j τ_j y^j`` to the solution's order (SymPy, the model's
        symbols)."""
        return period_series(self)

    def q_expr(self, time: sp.Symbol | None = None) -> sp.Expr:
        """The motion ``q(t) = A Σ_j coupling^j q_j(ωt)`` to the solution's order, with ``ω``
        truncated at the same order (SymPy, the model's symbols; ``time`` defaults to ``t``)."""
        return solution_expression(self, t if time is None else time)

    def __repr__(self) -> str:
        """What the series is and its frequency, as mathematics (SymPy's spelling), the first
        orders only: ``<duffing: L–P series to order 6 in y = A**2*eps; omega = 1 + …>``."""
        m = self.model
        shown = min(self.order, SHOWN_ORDERS)
        terms = omega_coefficients(self)[: shown + 1]
        omega = sp.sstr(sp.Add(*(c * m.coupling**j for j, c in enumerate(terms))),
                        order="rev-lex")  # ascending powers: 1 + 3*A**2*epsilon/8 - …
        tail = " + …" if shown < self.order else ""
        return (f"<{m.name}: L–P series to order {self.order} in y = {sp.sstr(m.y)}; "
                f"omega = {omega}{tail}>")

    __str__ = __repr__

    def _repr_latex_(self) -> str:
        """ω, T/2π and the first q_j in y (Jupyter), the first orders only."""
        m, g = self.model, self.ground.to_sympy
        shown = min(self.order, SHOWN_ORDERS)
        tail = (r" + \cdots" if shown < self.order else "") + f" + O(y^{{{self.order + 1}}})"

        def series(coeffs: tuple) -> str:
            return latex_sum((g(c), _power("y", j)) for j, c in enumerate(coeffs[: shown + 1]))

        amp, coord = sp.latex(m.amplitude), sp.latex(m.coordinate)
        lines = [rf"&{m.latex}, \qquad y = {sp.latex(m.y)}, \quad {latex_text('order')}\ "
                 rf"{self.order}",
                 rf"\omega &= {series(self.omega)}{tail}",
                 rf"\frac{{T}}{{2\pi}} &= {series(self.period)}{tail}",
                 rf"{coord} &= {amp} \sum_{{j}} y^{{j}} q_j(s), \quad s = \omega t"]
        lines += [rf"q_{{{j}}}(s) &= "
                  + latex_sum((g(c), _cosine(n)) for n, c in sorted(self.q[j].items()))
                  for j in range(shown + 1)]
        if shown < self.order:
            lines.append("&" + latex_text(more(self.order, shown)))
        return latex_aligned(lines)


def _power(var: str, j: int) -> str:
    return "" if j == 0 else var if j == 1 else f"{var}^{{{j}}}"


def _cosine(n: int) -> str:
    return "" if n == 0 else r"\cos s" if n == 1 else rf"\cos {n}s"


def derive(model: Model, order: int,
           progress: Callable[[int, int], None] | None = None) -> SeriesSolution:
    """ω₀…ω_K, u₀…u_K and T/2π of ``model`` to order K (notes §10.3, carried to order K);
    ``progress(j, K)`` is called after each order (the command line draws a bar with it)."""
    order = check_order(order)
    if model.exact_to is not None and order > model.exact_to:
        raise InputError(f"order {order}: the {model.name} model holds its equation's terms to "
                         f"order {model.exact_to} only, so orders above it would be wrong; "
                         f"build it for order {order} (e.g. {model.name}({order}))")
    basis = Basis(model.odd)
    ground = Ground.for_coefficients(model.coefficients())
    zero, one = ground.scalar(0), ground.scalar(1)
    # u_0 = cos s: one monomial at the resonant index.
    r = basis.resonant
    P = [ground.poly([zero] * r + [one])]
    DP = [P[0] * ground.scalar(-1)]  # u_0'' = -u_0
    omega, W, rests = [one], [one], []
    forces = _Forces(model, P, W, basis, ground)
    elementary = [_Elementary(P, ground, name, lam, weight)
                  for name, lam, weight in model.elementary]
    for j in range(1, order + 1):
        G = ground.poly([])
        for e in elementary:
            G = G - e.forcing(j)
        for k in range(1, j + 1):
            term = forces.term(k, j - k)
            if term is not None:
                G = G - term
        for a in range(1, j):
            G = G - DP[j - a] * W[a]
        g = G.coeffs()
        g = g + [zero] * (r + 1 - len(g))
        solved = solve_oscillator(g, basis, ground)
        S = sum((omega[a] * omega[j - a] for a in range(1, j)), zero)
        Wj = -solved.secular  # the secular condition: [cos s] F_j = secular + W_j = 0
        W.append(Wj)
        omega.append((Wj - S) * ground.scalar(Fraction(1, 2)))
        p = solved.particular
        p[r] = -sum((c for k, c in enumerate(p) if k != r), zero)  # u_j(0) = 0
        Pj = ground.poly(p)
        P.append(Pj)
        for e in elementary:
            e.solved(j)
        g[r] = g[r] + Wj
        DP.append(ground.poly(g) - Pj)  # u_j'' = F_j - u_j
        rests.append(G)
        if progress is not None:
            progress(j, order)
    period = [one]
    for j in range(1, order + 1):
        period.append(-sum((omega[a] * period[j - a] for a in range(1, j + 1)), zero))
    return SeriesSolution(
        model=model,
        order=order,
        ground=ground,
        omega=tuple(omega),
        period=tuple(period),
        q=tuple(to_fourier(Pj, basis, ground) for Pj in P),
        forcing=tuple(rests),
    )


class _Elementary:
    """``[y^j] w (F(λAu) − λAu)/A`` for ``F = sin`` or ``sinh``, ``y = A²``, by the recurrences
    of sine and cosine of a power series (J. C. P. Miller's rule for ``F(λ g)``).

    With ``t = A`` and ``g(t) = t u(t²) = Σ t^(2i+1) u_i``, ``s = F(λg)`` and its partner
    ``c = F'(λg)`` (cos or cosh) obey ``n s_n = λ Σ k g_k c_(n−k)`` and
    ``n c_n = ∓λ Σ k g_k s_(n−k)``: two convolutions an order instead of one power table per
    Taylor term (the pendulum at order 100: from K^4.6 to K^3).  ``s_(2j+1)`` less its
    ``λ u_j`` is the force of order j (it needs ``u_0..u_(j−1)`` only).  Odd basis: ``s`` is
    stored over C, ``c`` (even) in ``v = C²``.
    """

    def __init__(self, P: list, ground: Ground, name: str, lam: Any, weight: Any) -> None:
        if name not in ("sin", "sinh"):
            raise ValueError(f"elementary force {name!r}: sin or sinh only")
        self.P, self.ground = P, ground
        self.lam, self.weight = ground.scalar(lam), ground.scalar(weight)
        self.sign = -1 if name == "sin" else 1
        self.s: dict[int, Any] = {}
        self.c: dict[int, Any] = {0: ground.poly([ground.scalar(1)])}
        self.partial: Any = ground.poly([])
        self.kP: list = []
        self.solved(0)  # s_1 = λ u_0 and c_2

    def _k(self, i: int) -> Any:
        """``k g_k`` over C, ``k = 2i + 1`` (kept: each is used at every later order)."""
        while len(self.kP) <= i:
            self.kP.append(self.P[len(self.kP)] * (2 * len(self.kP) + 1))
        return self.kP[i]

    def forcing(self, j: int) -> Any:
        n = 2 * j + 1
        acc = self.P[0] * self.c[n - 1]
        for i in range(1, j):
            acc = acc + self._k(i) * self.c[n - 2 * i - 1]
        self.partial = acc * (self.lam * self.ground.scalar(Fraction(1, n)))
        return self.partial * self.weight

    def solved(self, j: int) -> None:
        """``u_j`` is known: complete ``s_(2j+1)`` and make ``c_(2j+2)``."""
        n = 2 * j + 1
        self.s[n] = self.partial + self.P[j] * self.lam
        m = n + 1
        acc = self.P[0] * self.s[m - 1]
        for i in range(1, j + 1):
            acc = acc + self._k(i) * self.s[m - 2 * i - 1]
        scale = self.ground.scalar(Fraction(self.sign, m)) * self.lam
        self.c[m] = acc.left_shift(1) * scale  # (C·P)(C·s) = v·(P s)


def _slope_squared(P: list, W: list, basis: Basis, ground: Ground) -> LazySeries:
    """``Y = ω² u'²``: ``u' = −sin s·du/dC`` gives ``u'² = (1 − C²)(du/dC)²``, a cosine sum
    (even), and ``ω² = Σ W_i y^i`` is known below the order being solved.  ``du/dC`` in the
    odd basis: ``d/dC Σ p_k C^(2k+1) = Σ (2k+1) p_k v^k`` (even, plain in v)."""
    one, zero = ground.scalar(1), ground.scalar(0)
    # (1 − C²) in the basis: 1 − v (odd: even functions live in v) or 1 − C²
    sine2 = ground.poly([one, -one] if basis.odd else [one, zero, -one])

    def slope(p: Any) -> Any:
        cs = p.coeffs()
        if basis.odd:
            return ground.poly([c * (2 * k + 1) for k, c in enumerate(cs)])
        return ground.poly([c * k for k, c in enumerate(cs)][1:])

    R = Mapped(Terms(P), slope)
    return Mapped(Product(Product(R, R), Terms(W)), lambda c: c * sine2)


class _Forces:
    """Every polynomial force ``Σ c u^a (ω u')^b`` of the model as series nodes
    (:class:`algebra.lazy.LazySeries`), in Horner form with shared subexpressions:
    ``u·H(u², Y)`` for odd forces (``u⁵ + 2u³Y + uY²/3`` costs three and a half convolutions
    an order, not seven and a half by power tables), ``H(u, Y)`` otherwise, ``Y = ω²u'²``.
    In the odd basis a node is stored over C (``C·P(v)``, odd) or plain in ``v`` (even): the
    product of two odd nodes is ``C²·(…) = v·(…)``, a shift; in the full basis every node is
    plain in C."""

    def __init__(self, model: Model, P: list, W: list, basis: Basis, ground: Ground) -> None:
        self.basis, self.ground = basis, ground
        self.u = Terms(P)  # u itself: P_i, appended by derive as each order is solved
        self.odd: dict[LazySeries, bool] = {self.u: basis.odd}
        self.memo: dict = {}
        self.Y: LazySeries | None = None
        self.P, self.W = P, W
        z, y = sp.symbols("z y")
        self.z, self.y = z, y
        self.by_order: list[LazySeries | None] = []
        for k in range(max(len(model.forcing), len(model.velocity_forcing))):
            poly = sp.Integer(0)
            for n, c in (model.forcing[k] if k < len(model.forcing) else ()):
                poly += self._monomial(n, 0) * c
            for a, b, c in (model.velocity_forcing[k] if k < len(model.velocity_forcing)
                            else ()):
                poly += self._monomial(a, b) * c
            self.by_order.append(self._compile(sp.expand(poly)) if poly != 0 else None)

    def _monomial(self, a: int, b: int) -> sp.Expr:
        """``u^a Y^(b/2)`` in the Horner variables (``z = u²`` over the factored u if odd)."""
        if self.basis.odd:
            return self.z ** ((a - 1) // 2) * self.y ** (b // 2)
        return self.z**a * self.y ** (b // 2)

    def _compile(self, poly: sp.Expr) -> LazySeries:
        if not poly.free_symbols & {self.z, self.y}:  # c·u (odd basis, a = 1)
            return self._linear([(self.ground.scalar(poly), self.u)])
        node = self._node(sp.horner(poly, self.z, self.y))
        return self._product(self.u, node) if self.basis.odd else node

    def _linear(self, terms: list[tuple[Any, LazySeries]], constant: Any = None
                ) -> LazySeries:
        """``constant + Σ c·node`` (every node of one parity)."""
        node = Linear(terms, self.ground.poly([]),
                      self.ground.poly([constant]) if constant else None)
        self.odd[node] = self.odd[terms[0][1]]
        return node

    def _product(self, a: LazySeries, b: LazySeries) -> LazySeries:
        key = ("*", *sorted((id(a), id(b))))
        if key not in self.memo:
            shift = self.basis.odd and self.odd[a] and self.odd[b]
            node = Product(a, b, (lambda c: c.left_shift(1)) if shift else None)
            self.odd[node] = self.odd[a] != self.odd[b]
            self.memo[key] = node
        return self.memo[key]

    def _leaf(self, symbol: sp.Symbol) -> LazySeries:
        if symbol == self.y:
            if self.Y is None:
                self.Y = _slope_squared(self.P, self.W, self.basis, self.ground)
                self.odd[self.Y] = False
            return self.Y
        if self.basis.odd:  # z = u²: even
            return self._product(self.u, self.u)
        return self.u

    def _node(self, expr: sp.Expr) -> LazySeries:
        """A series node for a polynomial expression in z, y (memoised by expression)."""
        if expr in self.memo:
            return self.memo[expr]
        if expr.is_Symbol:
            node = self._leaf(expr)
        elif expr.is_Pow:
            base, n = self._node(expr.base), int(expr.exp)
            node = base
            for _ in range(n - 1):
                node = self._product(node, base)
        elif expr.is_Mul:
            scalar = sp.Integer(1)
            nodes = []
            for f in expr.args:
                if f.free_symbols & {self.z, self.y}:
                    nodes.append(self._node(f))
                else:
                    scalar *= f
            node = nodes[0]
            for other in nodes[1:]:
                node = self._product(node, other)
            if scalar != 1:
                node = self._linear([(self.ground.scalar(scalar), node)])
        elif expr.is_Add:
            constant, terms = None, []
            for f in expr.args:
                if f.free_symbols & {self.z, self.y}:
                    inner = self._node(f)
                    if isinstance(inner, Linear) and inner.first is None:
                        terms.extend(inner.terms)
                    else:
                        terms.append((self.ground.scalar(1), inner))
                else:
                    constant = self.ground.scalar(f)
            node = self._linear(terms, constant)
        else:
            raise ValueError(f"force {expr}: not a polynomial in u and u'²")
        self.memo[expr] = node
        return node

    def term(self, k: int, m: int) -> Any:
        """``[y^m]`` of the order-k force (over C^parity), or None when it has none."""
        node = self.by_order[k - 1] if k <= len(self.by_order) else None
        return None if node is None else node.coeff(m)


def omega_coefficients(solution: SeriesSolution) -> list[sp.Expr]:
    """Physical ``ω_j`` (coefficient of ``coupling^j``): ``ω₀ ω_j^scaled · order_factor^j``."""
    m = solution.model
    return [m.frequency * solution.ground.to_sympy(w) * m.order_factor**j
            for j, w in enumerate(solution.omega)]


def period_series(solution: SeriesSolution) -> sp.Expr:
    """``T(A) = 2π Σ τ_j y^j`` (notes: ``T ≅ 2π(1 - 3εA²/8 + 57(εA²)²/256)``)."""
    y = solution.model.y
    return 2 * sp.pi / solution.model.frequency * sum(
        solution.ground.to_sympy(c) * y**j for j, c in enumerate(solution.period)
    )


def q_expression(solution: SeriesSolution, j: int, var: sp.Symbol = s) -> sp.Expr:
    """Physical ``q_j(s)``, the coefficient of ``coupling^j`` in ``q``."""
    m = solution.model
    scale = m.amplitude * m.order_factor**j
    return scale * sum(
        solution.ground.to_sympy(c) * sp.cos(n * var) for n, c in sorted(solution.q[j].items())
    )


def solution_expression(solution: SeriesSolution, var: sp.Symbol = t) -> sp.Expr:
    """``q(t)`` to order K with ``s = ω t`` and ω truncated at the same order."""
    m = solution.model
    omega = sum(c * m.coupling**j for j, c in enumerate(omega_coefficients(solution)))
    return sum(
        m.coupling**j * q_expression(solution, j, var).subs(var, omega * var)
        for j in range(solution.order + 1)
    )


@dataclass(frozen=True)
class OrderTerms:
    """Order ``j`` of §10.3 in exact scaled numbers (factor ``amplitude · order_factor^j``).

    ``F_j(s) = (resonant + 2ω_j) cos s + Σ_{n≠1} forcing[n] cos ns`` (``ω_j`` scaled), the secular
    condition ``resonant + 2ω_j = 0``, and the solution ``q_j = Σ q[n] cos ns``.
    """

    order: int
    forcing: dict[int, sp.Rational]
    resonant: sp.Expr
    omega: sp.Expr
    q: dict[int, sp.Expr]


def order_terms(solution: SeriesSolution, j: int,
                convert: Callable[[Any], sp.Expr] | None = None) -> OrderTerms:
    """The pieces of the ``y^j`` equation, from the kernel's ``F_j`` (Fourier, exact), each
    exact coefficient made an expression by ``convert`` (default ``Ground.to_sympy``; the
    LaTeX lowering passes its own, which keeps a polynomial in the parameters whole)."""
    if not 1 <= j <= solution.order:
        raise ValueError(f"order {j}: equations exist for 1..{solution.order}")
    g = solution.ground
    convert = g.to_sympy if convert is None else convert
    basis = Basis(solution.model.odd)
    rest = to_fourier(solution.forcing[j - 1], basis, g)
    resonant = rest.get(1, g.scalar(0))
    for a in range(1, j):
        resonant = resonant + solution.omega[a] * solution.omega[j - a]
    return OrderTerms(
        order=j,
        forcing={n: convert(c) for n, c in sorted(rest.items()) if n != 1},
        resonant=convert(resonant),
        omega=convert(solution.omega[j]),
        q={n: convert(c) for n, c in sorted(solution.q[j].items())},
    )


@dataclass(frozen=True)
class OrderEquation:
    """The ``coupling^j`` equation of §10.3 with its secular condition, as SymPy objects."""

    order: int
    equation: sp.Eq  # q_j'' + q_j = F_j(s), ω_j left as a symbol
    secular_condition: sp.Eq  # [cos s] F_j = 0
    omega: sp.Eq  # ω_j = … (the secular condition solved)
    solution: sp.Eq  # q_j(s) = …

    def _repr_latex_(self) -> str:
        """The four equations of order j, aligned (Jupyter)."""
        labels = ("equation", "secular condition", "solved", "solution")
        eqs = (self.equation, self.secular_condition, self.omega, self.solution)
        return latex_aligned(f"{latex_text(k)}: &\\ {sp.latex(e)}"
                             for k, e in zip(labels, eqs, strict=True))


def order_equation(solution: SeriesSolution, j: int) -> OrderEquation:
    """Order ``j ≥ 1`` as the notes write it: ``q̈_j + q_j = F_j(s)``, secular term, ω_j, q_j."""
    terms = order_terms(solution, j)
    m = solution.model
    scale = m.amplitude * m.order_factor**j
    omega_j = sp.Symbol(f"omega_{j}")  # physical ω_j = order_factor^j · scaled ω_j
    resonant = sp.expand(scale * terms.resonant + 2 * m.amplitude * omega_j)
    F = resonant * sp.cos(s) + sum(scale * c * sp.cos(n * s) for n, c in terms.forcing.items())
    qj = sp.Function(f"q_{j}")(s)
    return OrderEquation(
        order=j,
        equation=sp.Eq(qj.diff(s, 2) + qj, F),
        secular_condition=sp.Eq(resonant, 0),
        omega=sp.Eq(omega_j, sp.factor(terms.omega * m.order_factor**j)),
        solution=sp.Eq(qj, q_expression(solution, j)),
    )


@dataclass(frozen=True)
class NaiveSolution:
    """Successive approximation ``q = Σ coupling^j q_j(t)`` without frequency strain.

    ``terms[j]`` maps ``(m, n, "cos" | "sin")`` to the coefficient of
    ``y^j · amplitude · t^m · cos|sin(n t)``; terms with ``m > 0`` are the secular terms.
    """

    model: Model
    order: int
    terms: tuple[dict[tuple[int, int, str], sp.Rational], ...]


def naive_expansion(model: Model, order: int) -> NaiveSolution:
    """The naive series of §10.3 (``q₁ = -A³(3t sin t/8 + (cos t - cos 3t)/32)``).

    Successive approximation with ``q(0) = A``, ``q̇(0) = 0`` has a unique solution at each
    order, which is the Taylor expansion in ``y`` at fixed ``t`` of the exact solution; the
    L–P series is that solution with ``s = ωt``.  Expanding ``cos(n(1 + δ)t)`` with
    ``δ = Σ_{j≥1} ω_j y^j`` in powers of ``y`` therefore gives every ``q_j(t)`` exactly, its
    secular terms ``t^m cos|sin(nt)`` included.
    """
    order = check_order(order)
    lp = derive(model, order)
    g = lp.ground
    delta = [sp.Integer(0)] + [g.to_sympy(w) for w in lp.omega[1:]]
    # delta_pow[m][i] = [y^i] δ^m
    delta_pow = [[sp.Integer(1)] + [sp.Integer(0)] * order]
    for _ in range(order):
        prev = delta_pow[-1]
        delta_pow.append(
            [sum(prev[a] * delta[i - a] for a in range(i + 1)) for i in range(order + 1)]
        )
    # d^m/dθ^m cos θ = sign · (cos|sin) θ
    derivs = [(1, "cos"), (-1, "sin"), (-1, "cos"), (1, "sin")]
    terms: list[dict] = [{} for _ in range(order + 1)]
    for i, harmonics in enumerate(lp.q):
        for n, a in harmonics.items():
            a = g.to_sympy(a)
            for mpow in range(order - i + 1):
                sign, trig = derivs[mpow % 4]
                weight = sign * a * sp.Integer(n) ** mpow / factorial(mpow)
                for jj in range(mpow, order - i + 1):
                    c = weight * delta_pow[mpow][jj]
                    if c:
                        key = (mpow, n, trig)
                        bucket = terms[i + jj]
                        bucket[key] = bucket.get(key, 0) + c
    cleaned = tuple({k: v for k, v in sorted(b.items()) if v != 0} for b in terms)
    return NaiveSolution(model=model, order=order, terms=cleaned)


def naive_expression(naive: NaiveSolution, j: int) -> sp.Expr:
    """Physical naive ``q_j(t)``, coefficient of ``coupling^j``."""
    m = naive.model
    trig = {"cos": sp.cos, "sin": sp.sin}
    return (m.amplitude * m.order_factor**j) * sum(
        c * t**mp * trig[f](n * t) for (mp, n, f), c in naive.terms[j].items()
    )


def estimated_radius(solution: SeriesSolution, to_args: dict,
                     convert: Callable[[Any], sp.Expr] | None = None
                     ) -> tuple[sp.Expr, float] | None:
    """The radius of convergence of ``T/2π = Σ τ_j y^j`` where the model knows none, and its
    spread (an error bar; the guard and the error estimate take the radius minus it).

    Rational coefficients: the root test ``min_j |τ_j|^(−1/j)`` over the upper half of the
    derived orders, Domb–Sykes' line of the ratios in 1/j where it fits, and from 12 nonzero
    coefficients :func:`lindstedt.nearest_singularity` (its extrapolations' spread) — the
    smallest of them, with the spread of the estimator used, or the distance between the
    root test and Domb–Sykes below 12 (the range of the root tests without Domb–Sykes).
    Coefficients in ``QQ[A, …]``: the root test as an expression (each τ_j made one by
    ``convert``, default ``Ground.to_sympy``; ``Min`` unevaluated: SymPy would compare the
    polynomials term by term), spread 0 (no number to state).  None when every τ_j there
    vanishes (a series that stops: no bound to state)."""
    top = solution.order
    g = solution.ground
    if not g.is_rational:
        convert = g.to_sympy if convert is None else convert
        roots = []
        for j in range(max(1, top // 2), top + 1):
            c = convert(solution.period[j]).xreplace(to_args)
            if c != 0:
                roots.append(sp.Abs(c) ** sp.Rational(-1, j))
        return (sp.Min(*roots, evaluate=False) if len(roots) > 1 else roots[0], 0.0) \
            if roots else None
    import mpmath

    fractions = [g.to_fraction(c) for c in solution.period]
    tau = [abs(mpmath.mpf(c.numerator) / c.denominator) for c in fractions]
    roots = [float(tau[j] ** (mpmath.mpf(-1) / j))
             for j in range(max(1, top // 2), top + 1) if tau[j]]
    if not roots:
        return None
    radius, spread = min(roots), max(roots) - min(roots)
    # Domb–Sykes: |τ_j/τ_(j−1)| = (1 − (1 + γ)/j)/R for a singularity on the real axis; its
    # line in 1/j finds R from ten terms where the root test is still 40 % high (Duffing: 1.0000
    # against 1.36 at order 10) — taken when the line fits
    js = [j for j in range(max(2, top // 2), top + 1) if tau[j] and tau[j - 1]]
    if len(js) >= 3:
        import numpy as np

        ratios = np.array([float(tau[j] / tau[j - 1]) for j in js])
        design = np.vstack([np.ones(len(js)), 1.0 / np.array(js, dtype=float)]).T
        (a, b), *_ = np.linalg.lstsq(design, ratios, rcond=None)
        if a > 0 and np.max(np.abs(design @ np.array([a, b]) - ratios) / ratios) < DOMB_SYKES_FIT:
            spread = abs(radius - 1 / a)
            radius = min(radius, 1 / a)
    est = nearest_singularity(fractions, "y", None)
    if est is not None:
        r = math.sqrt(est.radius) if est.variable.endswith("**2") else est.radius
        r_spread = est.spread / (2 * r) if est.variable.endswith("**2") else est.spread
        if r <= radius:
            radius, spread = r, r_spread
    return sp.Float(radius, 17), float(spread)


DOMB_SYKES_FIT = 0.02
# NOTE: the largest relative misfit of the ratios' line for its R to count (a pair of complex
# singularities makes the ratios oscillate: no line, no estimate from it)


@dataclass(frozen=True)
class Validity:
    """Where a free oscillator's series may be used: the family of periodic orbits
    (``orbit``, a :class:`derive.orbits.OrbitDomain` in ``y``) and the radius of convergence
    of ``T/2π = Σ τ_j y^j`` in ``|y|`` — the model's exact one (``exact``, ``spread`` 0), or
    :func:`estimated_radius` from the τ_j of the solution (``exact`` None), or none
    (``radius`` None: symbolic coefficients, or too few orders)."""

    orbit: Any  # OrbitDomain (derive.orbits, imported lazily: mpmath, SciPy)
    radius: float | None
    exact: sp.Expr | None
    spread: float
    order: int  # the order the estimate was made from

    @property
    def reach(self) -> float | None:
        """The radius less its spread (where the evaluators stop), or None."""
        return None if self.radius is None else self.radius - self.spread


def validity(solution: SeriesSolution) -> Validity:
    """The :class:`Validity` of ``solution``: its orbit domain and its radius, the one
    computation the JSON, the table, the figure and the LaTeX print."""
    from .orbits import orbit_domain

    m = solution.model
    orbit = orbit_domain(m)
    if m.radius is not None:
        value = float(m.radius) if m.radius.is_number else None
        return Validity(orbit, value, m.radius, 0.0, solution.order)
    if solution.ground.is_rational and solution.order >= 2:
        found = estimated_radius(solution, {})
        if found is not None:
            return Validity(orbit, float(found[0]), None, float(found[1]), solution.order)
    return Validity(orbit, None, None, 0.0, solution.order)
