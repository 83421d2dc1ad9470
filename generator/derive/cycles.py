"""The limit cycles of ``q'' + q = ε f(q, q')``: every root of the first-order amplitude
equation S(a) with its stability, and the L–P series of one cycle to any order, exact in Q
or in the number field Q(a₀) of an irrational amplitude (relaxed products of ε-series)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import sympy as sp
from sympy.polys.domains import QQ

from ..algebra.lazy import LazySeries, Mapped, RelaxedProduct, Terms
from ..algebra.resum import binomial_series, series_compose, series_mul, series_reciprocal
from ..algebra.series import Ground, Trig, solve_trig
from ..errors import InputError
from .models import check_order


@dataclass(frozen=True)
class LimitCycle:
    """The L–P series of a limit cycle of ``q̈ + q = ε f(q, q̇)``, exact, in powers of ε.

    Phase: ``q̇(0) = 0``.  ``omega[j]``, ``period[j]``: coefficients of ``ε^j`` in ω and T/2π;
    ``amplitude[j]``: of ``q(0)``; ``q[j] = ({n: a_n}, {n: b_n})``, the cos and sin
    coefficients of ``q_j(s)``, ``s = ωt``.  ``slope``: ``S'(a₀)`` of the first-order amplitude
    function ``S(a) = [sin s] f(a cos s, −a sin s)``; the cycle attracts for ``ε S'(a₀) > 0``.
    """

    model: Any
    order: int
    omega: tuple[Fraction, ...]
    period: tuple[Fraction, ...]
    amplitude: tuple[Fraction, ...]
    q: tuple[tuple[dict[int, Fraction], dict[int, Fraction]], ...]
    slope: Fraction
    linearisation: tuple[dict[int, Fraction], dict[int, Fraction]] = ({}, {})
    orders: tuple[CycleOrder, ...] = ()  # the first DOCUMENTED_ORDERS, for the LaTeX

    @property
    def first_harmonic(self) -> tuple[Any, ...]:
        """The ε-series of the orbit's first-harmonic amplitude ``√(A₁² + B₁²)`` (``A₁``,
        ``B₁``: the cos s and sin s coefficients of ``q(s)``), exact, to the same order.
        Beside ``amplitude`` (``q(0)``, the displacement where the velocity vanishes) it is
        the other "amplitude" of a cycle; they differ at ε² (Rayleigh: q(0) = 2 + 17/96 ε²,
        the first harmonic 2 + 9/64 ε²), and the slow flow's averaged radius r is a third
        (its convention's; 2 + 5/64 ε²), equal to both at order ε only.  With ``A₁(0) = a₀ ≠
        0``: ``A₁ √(1 + u)``, ``u = (B₁/A₁)²``, the binomial series in ``u``."""
        n = self.order + 1
        A = [q[0].get(1, 0) for q in self.q]
        B = [q[1].get(1, 0) for q in self.q]
        exact = all(isinstance(c, (int, Fraction)) for c in (*A, *B))
        fix = None if exact else (lambda c: sp.radsimp(sp.expand(c)))
        first = 1 / A[0] if exact else sp.radsimp(1 / sp.sympify(A[0]))
        ratio = series_mul(B, series_reciprocal(A, n, inverse=first, tidy=fix), n, fix)
        u = series_mul(ratio, ratio, n, fix)  # u = O(ε²)
        root = series_compose(binomial_series(Fraction(1, 2), n), u, n, tidy=fix)
        return tuple(series_mul(A, root, n, fix))


DOCUMENTED_ORDERS = 6
# NOTE: orders whose equations a LimitCycle keeps for its document (each costs two Fourier
# conversions; a page holds about this many).


@dataclass(frozen=True)
class CycleOrder:
    """Order j as derived: ``q_j'' + q_j = F_j = K_j + a_(j−1) L + a₀ W_j cos s`` with ``K_j``
    (``known``, cos and sin coefficients) made of the lower orders, ``L`` the linearisation of
    f at q₀ (:attr:`LimitCycle.linearisation`, with ``W_1 cos s``); the sin s condition gives
    ``a_prev = a_(j−1)`` (None at j = 1), the cos s one ``W_j``, then ``ω_j``; ``q`` is the
    periodic solution with ``q_j'(0) = 0``, its own cos s left to order j + 1."""

    j: int
    known: tuple[dict[int, Fraction], dict[int, Fraction]]
    a_prev: Fraction | None
    W: Fraction
    omega: Fraction
    q: tuple[dict[int, Fraction], dict[int, Fraction]]


@dataclass(frozen=True)
class Cycle:
    """One positive root ``a₀`` of the first-order amplitude function ``S(a)`` (exact: a
    rational or an algebraic number) and ``S'(a₀)``: the cycle attracts for ``ε S'(a₀) > 0``
    and repels for the other sign of ε; ``S'(a₀) = 0``: semi-stable (a double root)."""

    amplitude: sp.Expr
    slope: sp.Expr

    @property
    def rational(self) -> bool:
        """Whether ``a₀`` is rational (else an algebraic number)."""
        return bool(self.amplitude.is_Rational)

    @property
    def stability(self) -> str:
        """The verdict in words: attracting for the sign of ε with ``ε S'(a₀) > 0``, repelling
        for the other; semi-stable, with no series in ε, where ``S'(a₀) = 0``."""
        if self.slope == 0:
            return "semi-stable (a double root of S(a)): no series in eps"
        good, bad = ("eps > 0", "eps < 0") if self.slope > 0 else ("eps < 0", "eps > 0")
        return f"stable (attracting) for {good}, unstable (repelling) for {bad}"


def limit_cycles(model: Any) -> tuple[Cycle, ...]:
    """Every positive root ``a₀`` of ``S(a) = [sin s] f(a cos s, −a sin s)`` (the first-order
    secular condition) with ``S'(a₀)``, smallest first; a one-line :class:`InputError` says
    why when there is none (every orbit decays or grows)."""
    a = sp.Symbol("a")
    g = Ground.for_coefficients([a])
    x = Trig.from_fourier({1: g.scalar(a)}, {}, g)
    f = _force_of(model.terms, x, x.derivative(), g)
    _, sines = f.to_fourier()
    S = sp.expand(g.to_sympy(sines.get(1, g.scalar(0))))
    found: list[Cycle] = []
    for root in sp.Poly(S, a).real_roots() if S.has(a) else []:
        if root <= 0 or any(c.amplitude == root for c in found):
            continue
        found.append(Cycle(root, sp.nsimplify(sp.expand(sp.diff(S, a).subs(a, root)))))
    if not found:
        probe = S.subs(a, 1) if S.has(a) else S
        # NOTE: S(a) > 0 shrinks the amplitude for eps > 0 (averaged: da/dt = −ε S(a)/2)
        fate = ("for eps > 0 every orbit loses energy and decays to rest (all energy "
                "dissipated; for eps < 0 every orbit grows)" if probe > 0 else
                "for eps > 0 every orbit gains energy and grows (for eps < 0 all energy is "
                "dissipated)" if probe < 0 else "the terms odd in q' do no work at first order")
        raise InputError(f"{model.name} ({model.source}): no limit cycle: the first-order "
                         f"amplitude function S(a) = {S} has no positive root, so no cycle "
                         f"branches from the linear oscillator at eps = 0: {fate}")
    return tuple(found)


def limit_cycle_amplitudes(model: Any) -> list[tuple[Fraction, Fraction]]:
    """The cycles of :func:`limit_cycles` as exact ``(a₀, S'(a₀))`` fractions, for the series;
    an irrational amplitude is refused (the series are exact rationals)."""
    out = []
    for k, c in enumerate(limit_cycles(model)):
        if not c.rational:
            raise InputError(f"{model.name}: limit cycle {k + 1}'s amplitude {c.amplitude} is "
                             "irrational; the exact series need a rational one")
        out.append((_fraction(c.amplitude), _fraction(c.slope)))
    return out


def _fraction(r: sp.Expr) -> Fraction:
    r = sp.Rational(r)
    return Fraction(int(r.p), int(r.q))


def _force_of(terms: Any, x: Trig, v: Trig, g: Ground) -> Trig:
    """``Σ c x^a v^b`` of Trig sums (the first order's force, any ground)."""
    total = Trig(g.poly([]), g.poly([]), g)
    for a, b, c in terms:
        term = Trig(g.poly([g.scalar(c)]), g.poly([]), g)
        for _ in range(a):
            term = term * x
        for _ in range(b):
            term = term * v
        total = total + term
    return total


def derive_limit_cycle(model: Any, order: int, cycle: int = 0) -> LimitCycle:
    """ω, T/2π, q(0) and q_j of limit cycle ``cycle`` (by amplitude, smallest first) to order
    K.  At order j, ``q_j'' + q_j = F_j`` holds ``a_(j−1)`` (the unknown cos s of ``q_(j−1)``)
    and ``W_j`` (from ω²) linearly: the sin s condition fixes ``a_(j−1)``, the cos s one
    ``W_j``; ``q_j'(0) = 0`` fixes its sin s.  ``F_j = [ε^(j−1)] f(q, ω q') −
    Σ_(i<j) W_i q''_(j−i) + W_j a₀ cos s``: every ε-product is a :class:`RelaxedProduct`."""
    order = check_order(order)
    top = order + 1  # q_K's cos s (so q(0)'s ε^K) is fixed by the secular condition of K + 1
    cycles = limit_cycles(model)
    if not 0 <= cycle < len(cycles):
        raise InputError(f"cycle {cycle}: {model.name} has {len(cycles)} limit cycle(s)")
    chosen = cycles[cycle]
    if chosen.rational:
        g = Ground.for_coefficients([])
        a0, slope = _fraction(chosen.amplitude), _fraction(chosen.slope)
        exact: Callable[[Any], Any] = g.to_fraction
    else:  # exact in the number field Q(a₀): a₀ reduced by its minimal polynomial
        field = QQ.algebraic_field(chosen.amplitude)
        g = Ground(field)
        a0, slope = chosen.amplitude, chosen.slope

        def exact(c: Any) -> sp.Expr:
            return sp.radsimp(field.to_sympy(c))
    if slope == 0:
        raise InputError(f"{model.name}: the cycle at amplitude {a0} is semi-stable (a double "
                         "root of the first-order amplitude function S(a), S'(a) = 0): the "
                         "secular conditions cannot fix its amplitude order by order, and it "
                         "need not persist for eps ≠ 0; no series in eps")
    zero = g.scalar(0)
    nothing = Trig(g.poly([]), g.poly([]), g)
    a0_g = g.scalar(a0)

    def constant(c: Any) -> Trig:
        return Trig(g.poly([c]), g.poly([]), g)

    cos_s = Trig.from_fourier({1: g.scalar(1)}, {}, g)
    qs = [cos_s * a0_g]
    W, omega = [g.scalar(1)], [g.scalar(1)]
    # the series: q, q', q'', ω, X = (ω² − 1)/ε (X_k = W_(k+1)), and the products of f
    q = Terms(qs)
    slope_q = Mapped(q, Trig.derivative)
    curvature = Mapped(slope_q, Trig.derivative)
    omegas = Terms([constant(g.scalar(1))])
    X = Terms([])
    nodes: list[LazySeries] = [slope_q, curvature]
    products: dict[tuple[str, int], LazySeries] = {("q", 1): q}

    def product(a: LazySeries, b: LazySeries) -> RelaxedProduct:
        node = RelaxedProduct(a, b)
        nodes.append(node)
        return node

    products[("v", 1)] = product(omegas, slope_q)  # [ε^i] ω q'

    def power(kind: str, n: int) -> LazySeries:  # each power made once, by squaring
        if (kind, n) not in products:
            half = power(kind, n // 2)
            products[(kind, n)] = product(half, half) if n % 2 == 0 else \
                product(power(kind, n - 1), power(kind, 1))
        return products[(kind, n)]

    terms = []  # (series of q^a (ω q')^b, c); the constant term is only at ε^0
    for a, b, c in model.terms:
        if a and b:
            terms.append((product(power("q", a), power("v", b)), g.scalar(c)))
        elif a or b:
            terms.append((power("q", a) if a else power("v", b), g.scalar(c)))
        else:
            terms.append((None, g.scalar(c)))
    X_curvature = product(X, curvature)  # [ε^(j−1)]: Σ_(i≤j) W_i q''_(j−i), W_j (unknown) as 0

    def force(i: int) -> Trig:  # [ε^i] f(q, ω q')
        total = nothing
        for series, c in terms:
            if series is not None:
                total = total + series.coeff(i) * c
            elif i == 0:
                total = total + constant(c)
        return total

    def fourier(x: Trig) -> tuple[dict[int, Any], dict[int, Any]]:
        return tuple({n: exact(c) for n, c in part.items() if c}
                     for part in x.to_fourier())

    documented: list[CycleOrder] = []
    lin = None  # the a_(j−1) cos s part's image in F_j: f's linearisation at q_0, + W_1 cos s
    for j in range(1, top + 1):
        X.terms.append(nothing)  # X_(j−1) = W_j, found below
        known = force(j - 1) - X_curvature.coeff(j - 1)
        shown = fourier(known) if j <= DOCUMENTED_ORDERS else None
        a_prev = zero
        kc, ks = _secular_parts(known, g)
        if j >= 2:
            if lin is None:
                lin = _linearisation(model, qs[0], g) + cos_s * W[1]
                lc_, ls = _secular_parts(lin, g)
            a_prev = -ks / ls if ls else zero  # the sin s condition
            # F_j holds a_(j−1) linearly, through f's linearisation at q_0 and W_1 q_(j−1)''
            known = known + lin * a_prev
            kc = kc + lc_ * a_prev
        Wj = -kc / a0_g  # the cos s condition, kc + W_j a0 = 0 (−W_j q_0'' = W_j a0 cos s)
        W.append(Wj)
        S = sum((omega[a] * omega[j - a] for a in range(1, j)), zero)
        omega.append((Wj - S) * g.scalar(Fraction(1, 2)))
        # order j − 1 of every input is final now: q_(j−1) with its cos s, X_(j−1) = W_j
        if j >= 2:
            qs[j - 1] = qs[j - 1] + cos_s * a_prev
        X.terms[j - 1] = constant(Wj)
        omegas.terms.append(constant(omega[j]))
        for node in nodes:
            node.forget(j - 1)
        F = known + cos_s * (Wj * a0_g)
        p = solve_trig(F).particular
        # its cos s (a_j) waits for the next order's sin s condition; its sin s makes
        # q_j'(0) = R(1) = 0 (d/ds of S·R(C) at s = 0 is R(1); of P(C), 0): R's constant term
        r = p.sin_part.coeffs()
        r_at_one = sum(r, zero)
        qs.append(Trig(p.cos_part, p.sin_part - g.poly([r_at_one]), g))
        if shown is not None:
            documented.append(CycleOrder(j, shown, exact(a_prev) if j >= 2 else None,
                                         exact(Wj), exact(omega[j]), fourier(qs[j])))
    period = [g.scalar(1)]
    for j in range(1, order + 1):
        period.append(-sum((omega[a] * period[j - a] for a in range(1, j + 1)), zero))
    fourier_q = [fourier(qj) for qj in qs[: order + 1]]
    return LimitCycle(
        model=model, order=order,
        omega=tuple(exact(w) for w in omega[: order + 1]),
        period=tuple(exact(p) for p in period),
        amplitude=tuple(sum(cos.values(), Fraction(0)) if chosen.rational
                        else sp.radsimp(sp.Add(*cos.values())) for cos, _ in fourier_q),
        q=tuple(fourier_q), slope=slope,
        linearisation=fourier(lin) if lin is not None else ({}, {}), orders=tuple(documented))


def _linearisation(model: Any, q0: Trig, g: Ground) -> Trig:
    """``d/dλ f(q_0 + λ cos s, q_0' + λ (cos s)')`` at λ = 0: how ``a cos s`` added to
    ``q_(j−1)`` moves ``[ε^(j−1)] f`` (ω₀ = 1)."""
    x = Trig.from_fourier({1: g.scalar(1)}, {}, g)
    v0 = q0.derivative()
    lin = Trig(g.poly([]), g.poly([]), g)
    for a, b, c in model.terms:  # d/dλ (q0 + λx)^a (v0 + λx')^b at λ = 0
        if a:
            lin = lin + (_trig_power(q0, a - 1, g) * _trig_power(v0, b, g) * x
                         * g.scalar(c * a))
        if b:
            lin = lin + (_trig_power(q0, a, g) * _trig_power(v0, b - 1, g)
                         * x.derivative() * g.scalar(c * b))
    return lin


def _trig_power(x: Trig, n: int, g: Ground) -> Trig:
    out = Trig(g.poly([g.scalar(1)]), g.poly([]), g)
    for _ in range(n):
        out = out * x
    return out


def _secular_parts(F: Trig, g: Ground) -> tuple[Any, Any]:
    """The Fourier coefficients of cos s and sin s in ``F``."""
    solved = solve_trig(F)
    return solved.secular_cos, solved.secular_sin
