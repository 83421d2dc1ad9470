"""Lowering the driven oscillator: the μ-expansion's branches (Cardano's roots of the
first-order cubic), the damped μ-expansion and the harmonic-balance system."""

from __future__ import annotations

import sympy as sp

from ..analysis.mu_exact import (
    A1_,
    BalanceEquations,
    Delta_,
    MuDampedOrder,
    MuOrder,
    a_,
    damped_determinant,
    eps_,
    gamma_,
    omega_,
)
from ..analysis.mu_exact import x_ as damped_x
from .forms import argument_entry, nested_horner
from .records import ArrayKernel, Assign, Evaluator, Module, provenance


def cubic_branches(omega: sp.Symbol, eps: sp.Symbol, force: sp.Symbol) -> tuple[sp.Expr, ...]:
    """Real roots of ``(ω² − 1)A − ¾εA³ + f = 0``, largest first, as SymPy expressions.

    ``A³ + pA + q = 0`` with ``p = −4(ω² − 1)/(3ε)``, ``q = −4f/(3ε)``: three real roots by the
    trigonometric formula when ``4p³ + 27q² < 0`` (the middle one from the product of the roots;
    NaN for the missing ones otherwise), else Cardano's single root in its stable form.
    """
    return depressed_cubic_roots(-4 * (omega**2 - 1) / (3 * eps), -4 * force / (3 * eps))


def depressed_cubic_roots(p: sp.Expr, q: sp.Expr) -> tuple[sp.Expr, ...]:
    """Real roots of ``y³ + py + q = 0``, largest first (NaN for missing ones), as SymPy
    expressions: the trigonometric formula when ``4p³ + 27q² < 0``, else Cardano's one root."""
    three = 4 * p**3 + 27 * q**2 < 0
    arg = sp.Min(sp.Max(3 * q / (2 * p) * sp.sqrt(-3 / p), -1), 1)
    trig = [2 * sp.sqrt(-p / 3) * sp.cos(sp.acos(arg) / 3 - 2 * sp.pi * k / 3) for k in range(3)]
    # the middle root's cosine passes through zero (|cos| ≤ 1/2 there, the others ≥ 1/2): from
    # the product of the roots, −q, instead, or it keeps only the digits 1/√(−p) leaves it —
    # A₁ was 1e-5 off at ε = 1e-20, differently in the ufunc and in its SIMD loop
    trig[1] = -q / (trig[0] * trig[2])
    delta = q**2 / 4 + p**3 / 27

    def cbrt(z: sp.Expr) -> sp.Expr:
        return sp.sign(z) * sp.Abs(z) ** sp.Rational(1, 3)

    # u from the sum that does not cancel (√Δ taken with −q/2's sign), v = −p/(3u): the
    # difference −q/2 − √Δ loses every digit near ω = 1, where p → 0 (A₁ was 1e-5 off there)
    half = -q / 2
    u = cbrt(half + sp.sign(half) * sp.sqrt(delta))
    cardano = u - p / (3 * u)
    return (
        sp.Piecewise((trig[0], three), (cardano, True)),
        sp.Piecewise((trig[1], three), (sp.nan, True)),
        sp.Piecewise((trig[2], three), (sp.nan, True)),
    )


DRIVEN_ARGUMENT_LIMIT = 1e6
# NOTE: the undamped evaluators' range: 1e-6 ≤ |ω| ≤ 1e6, 0 < |ε| ≤ 1e6, |f| ≤ 1e6 (ε itself
# has no lower bound: the cubic's closed form is exact down to ε = 1e-20).  Outside (NaN and
# ±inf included) they computed ±inf at ω = 0 and raised floating-point warnings; there the
# arguments are replaced by ω = 2, ε = f = 1/10 (:func:`argument_entry`) and the answer is NaN.


def lower_driven(orders: tuple[MuOrder, ...], command: str) -> Module:
    """Evaluators ``A_n(omega, eps, force, branch)`` of the undamped μ-expansion at order K.

    ``branch`` 0, 1, 2 picks a real root of the first-order cubic, largest first (NaN where that
    branch does not exist).  NaN outside ``DRIVEN_ARGUMENT_LIMIT``.  The sum is NaN at a fold
    (``D = 0``) and where its last constant ``b_K`` exceeds ``b_{K−1}`` (``A₁`` for K = 1): a
    growing series is no answer.
    """
    K = len(orders)
    omega, eps, force, branch = sp.symbols("omega eps force branch")
    A1, D = sp.symbols("A1 D")
    to_args = {A1_: A1, omega_: omega, eps_: eps}
    roots = cubic_branches(omega, eps, force)
    pick = sp.Piecewise((roots[0], sp.Eq(branch, 0)), (roots[1], sp.Eq(branch, 1)),
                        (roots[2], sp.Eq(branch, 2)), (sp.nan, True))
    b = [orders[j].q.get(1, 0) for j in range(K)]  # b_j is q_j's cos τ coefficient
    last = sp.Abs(b[-1].xreplace(to_args))
    before = sp.Abs(A1) if K == 1 else sp.Abs(b[-2].xreplace(to_args))
    high = sp.Float(DRIVEN_ARGUMENT_LIMIT)
    entry, inside = argument_entry((
        (omega, sp.And(sp.Abs(omega) >= 1 / high, sp.Abs(omega) <= high), 2),
        (eps, sp.And(sp.Ne(eps, 0), sp.Abs(eps) <= high), sp.Rational(1, 10)),
        (force, sp.Abs(force) <= high, sp.Rational(1, 10)),
        (branch, sp.Or(sp.Eq(branch, 0), sp.Eq(branch, 1), sp.Eq(branch, 2)), 0)))
    guard = sp.And(inside, sp.Ne(D, 0), last <= before)
    prelude = (*entry, (A1, pick),
               (D, 1 - 1 / omega**2 - sp.Rational(9, 4) * eps * A1**2 / omega**2))
    evaluators = []
    for n in range(1, 2 * K + 2, 2):
        total = (A1 if n == 1 else 0) + sum(o.q.get(n, 0) for o in orders)
        subexprs, (out,) = sp.cse(sp.together(total.xreplace(to_args)),
                                  symbols=sp.numbered_symbols("x_"))
        evaluators.append(Evaluator(
            f"A_{n}",
            f"Coefficient of cos {n}ωt, μ-expansion order {K}, undamped (eq. 10.66–10.72).",
            (omega, eps, force, branch), prelude, guard, tuple(subexprs), out))
    evaluators.append(Evaluator(
        "first_order", "A₁ of the branch: a real root of (ω² − 1)A₁ − ¾εA₁³ + f = 0.",
        (omega, eps, force, branch), (*entry, (A1, pick)), inside, (), A1))
    return Module(
        name="driven",
        doc=f"Driven Duffing q'' + q + eps*q**3 = f cos(omega t): μ-expansion to order {K}.",
        constants=(("ORDER", K), ("MODEL", "driven (undamped)")),
        evaluators=tuple(evaluators),
        provenance=provenance("driven", K, command),
    )


ROOT_POLISH = 3
# NOTE: Newton steps on the one-harmonic cubic after its closed form: the shift of the
# depressed cubic costs the small root digits where |ε|f² ≪ (ω² − 1)², and three quadratic
# steps restore them from a closed form good to 1e-2 (a start worse than that is NaN).
ROOT_RESOLVED = 1e-9
# NOTE: the last Newton step must move the root by less than this (relative): beside a fold,
# where the root is double, it does not, and the evaluators return NaN.
DAMPED_TRUNCATION = 1e-2
# NOTE: the damped evaluators' verified domain: the first omitted term of the μ-series (its
# b_{K+1} and δ_{K+1}, which track the error against shooting within a factor 2) at most 1 % of
# A₁; beyond it, near a fold or at large εA₁², they return NaN rather than a guess.
DAMPED_HARMONICS = 5
# NOTE: A_n, B_n for n = 1, 3, 5: the harmonics the tables and charts show (and the first three of
# the undamped module's).
DAMPED_ARGUMENT_RANGE = (1e-6, 1e6)
# NOTE: the damped evaluators' arguments enter as ω^{2j}, ω/Q, εf² and 1/(ω^{2j}Δ^m): outside
# 1e-6 ≤ |ω|, Q and |ω|, |ε|, |f| ≤ 1e6 (NaN and ±inf included) they would overflow or divide by
# zero (or make NaN, which raises "invalid" in comparisons) before the guard sees them: a
# floating-point warning from the ufunc.  There the arguments are replaced by DAMPED_STAND_IN, a
# point where every step is finite, and the guard returns NaN.
DAMPED_STAND_IN = (2, sp.Rational(1, 10), sp.Rational(1, 10), 1)
# NOTE: ω, ε, f, Q far above resonance: one branch, no fold, every step finite and quiet.


def damped_entry(omega: sp.Symbol, eps: sp.Symbol, force: sp.Symbol, Q: sp.Symbol,
                 branch: sp.Symbol) -> tuple[list[Assign], sp.Basic]:
    """:func:`argument_entry` of the damped evaluators: ``DAMPED_ARGUMENT_RANGE`` (ε ≠ 0,
    Q > 0, ``Q = inf`` allowed, branch 0, 1 or 2), ``DAMPED_STAND_IN`` (branch 0) outside."""
    low, high = (sp.Float(v) for v in DAMPED_ARGUMENT_RANGE)
    w, e, f, q = DAMPED_STAND_IN
    return argument_entry((
        (omega, sp.And(sp.Abs(omega) >= low, sp.Abs(omega) <= high), w),
        (eps, sp.And(sp.Ne(eps, 0), sp.Abs(eps) <= high), e),
        (force, sp.Abs(force) <= high, f),
        (Q, low <= Q, q),
        (branch, sp.Or(sp.Eq(branch, 0), sp.Eq(branch, 1), sp.Eq(branch, 2)), 0)),
        infinite=(Q,))


def _damped_horner(expr: sp.Expr) -> sp.Expr:
    """``A₁N/(ω^{2j}Δ^m)`` (or ``N/(…)``) with ``N`` by :func:`nested_horner` in x, a, γ."""
    # NOTE: no together(): it would clear the rationals into integers beyond int64
    num, den = sp.fraction(expr)
    if num == 0:
        return num
    factor = A1_ if num.has(A1_) else sp.Integer(1)
    out = factor * nested_horner(sp.expand(num / factor), (damped_x, a_, gamma_)) / den
    # an integer literal beyond int64 does not compile: as the nearest double
    return out.xreplace({n: sp.Float(int(n), 17) for n in out.atoms(sp.Integer)
                         if abs(n) > 2**53})


def damped_cubic_branches(omega: sp.Symbol, eps: sp.Symbol, force: sp.Symbol,
                          gamma: sp.Symbol) -> tuple[list[Assign], tuple[sp.Expr, ...], sp.Expr,
                                                     sp.Expr]:
    """``z = |ε|u`` (``u = A₁²``) of each root of the one-harmonic cubic
    ``u[(1 − ω² + ¾εu)² + γ²] = f²`` (:func:`driven.one_harmonic_roots`), largest first, NaN
    where a branch does not exist, in closed form: the assignments they need, the roots, and
    the cubic ``H(z)`` with ``H'(z)`` in the symbol ``z``.

    With ``a' = sign(ε)(ω² − 1)`` the cubic is ``H = z[(¾z − a')² + γ²] − |ε|f²``, whose
    real roots are all positive (``H < 0`` for ``z ≤ 0``); ``z = y + 8a'/9`` gives the depressed
    ``y³ + py + q`` with ``p = 16γ²/9 − 16a'²/27``, ``q = 128a'³/729 + 128a'γ²/81 − 16|ε|f²/9``
    (:func:`depressed_cubic_roots`: the conventions of :func:`cubic_branches`)."""
    z, shifted, p, q = sp.symbols("z a_shifted p q")
    steps = [(shifted, sp.sign(eps) * (omega**2 - 1)),
             (p, sp.Rational(16, 9) * gamma**2 - sp.Rational(16, 27) * shifted**2),
             (q, sp.Rational(128, 729) * shifted**3 + sp.Rational(128, 81) * shifted * gamma**2
              - sp.Rational(16, 9) * sp.Abs(eps) * force**2)]
    roots = tuple(r + sp.Rational(8, 9) * shifted for r in depressed_cubic_roots(p, q))
    bracket = sp.Rational(3, 4) * z - shifted
    H = z * (bracket**2 + gamma**2) - sp.Abs(eps) * force**2
    slope = bracket**2 + gamma**2 + sp.Rational(3, 2) * z * bracket
    return steps, roots, H, slope


def lower_driven_damped(orders: tuple[MuDampedOrder, ...], command: str) -> Module:
    """Evaluators ``A_n``, ``B_n(omega, eps, force, Q, branch)`` of the damped μ-expansion at
    order K: ``q(t) = Σ A_n cos nωt + B_n sin nωt`` for odd ``n ≤ 2K + 1``.

    ``branch`` 0, 1, 2 picks a root ``u = A₁²`` of the one-harmonic cubic, largest first
    (:func:`damped_cubic_branches`, polished by ``ROOT_POLISH`` Newton steps); ``δ₀`` is
    :func:`driven.one_harmonic_phase`'s.  With ``τ = ωt − δ`` the sum ``Σ_j q_j(τ)`` has
    coefficients ``α_n`` (cos nτ), ``β_n`` (sin nτ), and ``A_n = α_n cos nδ − β_n sin nδ``,
    ``B_n = α_n sin nδ + β_n cos nδ``.  ``orders`` holds K + 1 orders: the last one only
    estimates the truncation error.  NaN (the verified domain): ``ε = 0`` (no cubic), a root
    Newton does not resolve or ``Δ = 0`` (a fold), and where the first omitted term
    ``t_{K+1} = |b_{K+1}| + A₁|δ_{K+1}|`` exceeds ``DAMPED_TRUNCATION·A₁`` or the last summed one
    ``t_K`` (near a fold ``Δ → 0`` and the terms grow).  ``Q = inf`` is the undamped
    oscillator (``A₁ > 0``, ``δ₀`` = 0 or π).
    """
    K = len(orders) - 1
    omega, eps, force, Q, branch = sp.symbols("omega eps force Q branch")
    A1, delta, z, gamma = sp.symbols("A1 delta z gamma")
    x, a, Delta = sp.symbols("x a Delta")
    steps, roots, H, slope = damped_cubic_branches(omega, eps, force, gamma)
    pick = sp.Piecewise((roots[0], sp.Eq(branch, 0)), (roots[1], sp.Eq(branch, 1)),
                        (roots[2], sp.Eq(branch, 2)), (sp.nan, True))
    zs = [sp.Symbol(f"z{k}") for k in range(ROOT_POLISH + 1)]
    zsym = sp.Symbol("z")
    entry, inside = damped_entry(omega, eps, force, Q, branch)
    prelude: list[Assign] = [*entry, (gamma, omega / Q), *steps, (zs[0], pick)]
    for k in range(ROOT_POLISH):
        prelude.append((zs[k + 1], zs[k] - (H / slope).xreplace({zsym: zs[k]})))
    to_args = {A1_: A1, omega_: omega, damped_x: x, a_: a, gamma_: gamma, Delta_: Delta}
    sign = sp.sign(force)
    prelude += [(z, zs[-1]), (A1, sp.sqrt(z / sp.Abs(eps))), (x, sp.sign(eps) * z),
                (a, omega**2 - 1), (Delta, damped_determinant().xreplace(to_args)),
                (sp.Symbol("delta0"), sp.atan2(sign * gamma,
                                               sign * (sp.Rational(3, 4) * x - a)))]
    # the phase and the last two terms' sizes, shared subexpressions first
    named = [sp.Symbol(f"delta{j}") for j in range(1, K + 2)]
    constants = [sp.Symbol(f"b{j}") for j in (K, K + 1)]
    sizes = [sp.Abs(b) + A1 * sp.Abs(d) for b, d in zip(constants, named[K - 1:], strict=True)]
    wanted = [*(o.delta for o in orders), *(o.q[0].get(1, sp.Integer(0))
                                            for o in orders[K - 1:])]
    subexprs, reduced = sp.cse([_damped_horner(e).xreplace(to_args) for e in wanted],
                               symbols=sp.numbered_symbols("d_"), order="canonical")
    prelude += [*subexprs, *zip([*named, *constants], reduced, strict=True),
                (delta, sp.Symbol("delta0") + sum(named[:K]))]
    omitted, last = sizes[1], sizes[0]
    guard = sp.And(inside, sp.Ne(Delta, 0), omitted <= last,
                   omitted <= DAMPED_TRUNCATION * A1,
                   sp.Abs(zs[-1] - zs[-2]) <= ROOT_RESOLVED * sp.Abs(z))
    summed = orders[:K]
    evaluators = []
    for n in range(1, min(2 * K + 1, DAMPED_HARMONICS) + 1, 2):
        alpha = (A1 if n == 1 else 0) + sum(_damped_horner(o.q[0].get(n, sp.Integer(0)))
                                            for o in summed)
        beta = sum(_damped_horner(o.q[1].get(n, sp.Integer(0))) for o in summed)
        c, s = sp.cos(n * delta), sp.sin(n * delta)
        for name, out, what in ((f"A_{n}", alpha * c - beta * s, f"cos {n}ωt"),
                                (f"B_{n}", alpha * s + beta * c, f"sin {n}ωt")):
            subexprs, (expr,) = sp.cse(out.xreplace(to_args), symbols=sp.numbered_symbols("x_"),
                                       order="canonical")
            evaluators.append(Evaluator(
                name, f"Coefficient of {what}, damped μ-expansion order {K} (eq. 10.66–10.72).",
                (omega, eps, force, Q, branch), tuple(prelude), guard, tuple(subexprs), expr))
    root_prelude = tuple(prelude[: len(entry) + len(steps) + ROOT_POLISH + 5])
    evaluators.append(Evaluator(
        "first_order", "A₁ of the branch: √u, u a root of u[(1 − ω² + ¾εu)² + ω²/Q²] = f².",
        (omega, eps, force, Q, branch), root_prelude,
        sp.And(inside, sp.Abs(zs[-1] - zs[-2]) <= ROOT_RESOLVED * sp.Abs(z)),
        (), A1))
    return Module(
        name="driven_damped",
        doc=f"Driven Duffing q'' + q'/Q + q + eps*q**3 = f cos(omega t): μ-expansion with phase "
            f"to order {K}.",
        constants=(("ORDER", K), ("MODEL", "driven (damped)")),
        evaluators=tuple(evaluators),
        provenance=provenance("driven_damped", K, command),
    )


def lower_balance(eqs: BalanceEquations, command: str) -> Module:
    """Compiled residual and Jacobian of N-harmonic balance, and a Newton solver over them."""
    n = len(eqs.unknowns)
    jac = [[sp.diff(r, u) for u in eqs.unknowns] for r in eqs.residuals]
    flat = [*eqs.residuals, *(e for row in jac for e in row)]
    subexprs, reduced = sp.cse(flat, symbols=sp.numbered_symbols("x_"), order="canonical")
    res, jac_flat = reduced[:n], reduced[n:]
    # NOTE: one CSE over residual and Jacobian together; each kernel keeps what it uses.
    kernels = []
    for name, doc, shape, entries in (
        ("residual", "Galerkin residual: cos and sin components for k = 1, 3, …", (n,),
         tuple(((i,), e) for i, e in enumerate(res))),
        ("jacobian", "d residual / d (a_1, a_3, …, b_1, b_3, …)", (n, n),
         tuple(((i // n, i % n), e) for i, e in enumerate(jac_flat))),
    ):
        used = set().union(*(e.free_symbols for _, e in entries))
        needed: list[Assign] = []
        for lhs, rhs in reversed(subexprs):
            if lhs in used:
                needed.append((lhs, rhs))
                used |= rhs.free_symbols
        kernels.append(ArrayKernel(name, doc, eqs.unknowns, eqs.parameters, shape,
                                   tuple(reversed(needed)), entries))
    return Module(
        name="balance",
        doc=f"Driven Duffing q'' + damping*q' + q + eps*q**3 = force*cos(omega t): harmonic "
            f"balance with {eqs.harmonics} odd harmonics.",
        constants=(("HARMONICS", eqs.harmonics),
                   ("UNKNOWNS", tuple(str(u) for u in eqs.unknowns))),
        evaluators=(),
        provenance=provenance("balance", eqs.harmonics, command),
        kernels=tuple(kernels),
        newton=True,
    )
