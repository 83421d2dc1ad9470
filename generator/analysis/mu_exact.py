"""The driven oscillator exactly: the μ-expansion undamped (in QQ(A₁, ω, ε)) and damped (in
QQ[x, a, γ], one Δ power per order), its first-order secular conditions, and the harmonic
balance as symbolic residuals: for display, LaTeX and the emitted evaluators."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from fractions import Fraction

import sympy as sp
from sympy.polys.domains import QQ

from ..algebra.series import (
    Basis,
    Ground,
    Trig,
    solve_oscillator,
    solve_trig,
    to_fourier,
    trig_power,
)
from ..limits import MU_EXACT_MAX_ORDER, check_int

# --- the first-order secular conditions, symbolically (display, tests) -----------------------

def first_order_secular() -> tuple[sp.Expr, sp.Expr]:
    """The cos τ and sin τ coefficients of ``ω²F₁(τ)`` (eq. 10.72 with damping), by SymPy.

    ``F₁ = (1 − 1/ω²)q₀ − q₀'/(ωQ) − (ε/ω²)q₀³ + (f/ω²)cos(τ + δ₀)``, ``q₀ = A₁ cos τ``.
    """
    tau, A1, w, eps, f, Q, d0 = sp.symbols("tau A_1 omega epsilon f Q delta_0", real=True)
    q0 = A1 * sp.cos(tau)
    F1 = (1 - 1 / w**2) * q0 - sp.diff(q0, tau) / (w * Q) - eps / w**2 * q0**3 \
        + f / w**2 * sp.cos(tau + d0)
    F1 = sp.expand(w**2 * F1)
    cos_c = sp.simplify(sp.integrate(F1 * sp.cos(tau), (tau, 0, 2 * sp.pi)) / sp.pi)
    sin_c = sp.simplify(sp.integrate(F1 * sp.sin(tau), (tau, 0, 2 * sp.pi)) / sp.pi)
    return sp.expand(cos_c), sp.expand(sin_c)


# --- the undamped μ-expansion, exactly (for display, LaTeX and emitted evaluators) -----------

A1_, omega_, eps_, force_ = sp.symbols("A_1 omega epsilon f")


@dataclass(frozen=True)
class MuOrder:
    """Order ``j`` of the undamped μ-expansion in ``A₁, ω, ε`` (``A₁`` a root of the cubic)."""

    order: int
    forcing: dict[int, sp.Expr]  # F_j: coefficients of cos nτ, n ≠ 1
    secular: sp.Expr  # cos τ coefficient of F_j (= 0), with b_{j−1} as a symbol
    unknown: sp.Symbol  # what it fixes: A₁ (order 1) or b_{j−1}
    value: sp.Expr | None  # b_{j−1} (None at order 1: the cubic is solved per branch)
    q: dict[int, sp.Expr]  # q_j: coefficients of cos nτ, b_j (fixed at order j+1) included


@functools.lru_cache(maxsize=4)
def mu_expansion_exact(order: int) -> tuple[MuOrder, ...]:
    """Orders 1..K of eq. 10.68 (``Q → ∞``, so ``δ = 0``) with exact rational functions.

    The kernel of :mod:`series` does the algebra in the monomial basis of ``C = cos τ`` over
    ``QQ(A₁, ω, ε)``.  ``F₁`` holds ``f/ω² cos τ``; its secular condition is the cubic
    ``(ω² − 1)A₁ − ¾εA₁³ + f = 0``, which removes ``f`` from every later order.  At order
    ``j + 1`` the secular condition is affine in ``b_j``: ``s₀ + D b_j = 0`` with
    ``D = 1 − 1/ω² − 9εA₁²/(4ω²)``, which vanishes at a fold.
    """
    check_int(order, 1, MU_EXACT_MAX_ORDER,
              f"order {order!r}: the exact μ-expansion takes 1..{MU_EXACT_MAX_ORDER}")
    ground = Ground(QQ.frac_field(A1_, omega_, eps_))
    basis = Basis(odd=True)
    lin = ground.scalar(1 - 1 / omega_**2)
    cub = ground.scalar(-eps_ / omega_**2)
    D = lin + cub * ground.scalar(sp.Rational(9, 4) * A1_**2)
    P = [ground.poly([A1_])]  # q₀ = A₁ cos τ = C·P₀

    def cube(m: int) -> object:
        """``[μ^m] P³`` by direct convolution (low orders only)."""
        acc = ground.poly([])
        for a in range(m + 1):
            for b in range(m + 1 - a):
                acc = acc + P[a] * P[b] * P[m - a - b]
        return acc

    def forcing(j: int) -> object:
        return P[j - 1] * lin + cube(j - 1).left_shift(1) * cub

    def fourier(poly: object) -> dict[int, sp.Expr]:
        return {n: sp.factor(ground.to_sympy(c))
                for n, c in to_fourier(poly, basis, ground).items()}

    forcings, seculars, values, b_symbols = [], [], [], []
    for j in range(1, order + 2):
        s0 = solve_oscillator(forcing(j).coeffs() or [ground.scalar(0)], basis, ground).secular
        if j == 1:  # the cubic (its f/ω² cos τ term stands outside the kernel's QQ(A₁, ω, ε))
            seculars.append(sp.expand(ground.to_sympy(s0) + force_ / omega_**2))
            values.append(None)
            b_symbols.append(A1_)
        else:  # s₀ + D b_{j−1} = 0 fixes the constant of q_{j−1}
            b = -s0 * (ground.scalar(1) / D)
            b_sym = sp.Symbol(f"b_{j - 1}")
            seculars.append(sp.factor(ground.to_sympy(s0)) + sp.factor(ground.to_sympy(D)) * b_sym)
            values.append(sp.factor(ground.to_sympy(b)))
            b_symbols.append(b_sym)
            P[j - 1] = P[j - 1] + ground.poly([b])
        if j == order + 1:
            break
        F = forcing(j)
        forcings.append({n: c for n, c in fourier(F).items() if n != 1})
        P.append(ground.poly(solve_oscillator(F.coeffs(), basis, ground).particular))
    return tuple(
        MuOrder(order=j, forcing=forcings[j - 1], secular=seculars[j - 1],
                unknown=b_symbols[j - 1], value=values[j - 1], q=fourier(P[j]))
        for j in range(1, order + 1)
    )


# --- the damped μ-expansion, exactly (LaTeX and emitted evaluators for Q < ∞) ---------------

x_, a_, gamma_, Delta_, Q_, delta0_ = sp.symbols("x a gamma Delta Q delta_0")


@dataclass(frozen=True)
class MuDampedOrder:
    """Order ``j`` of the damped μ-expansion (:func:`mu_expansion_damped`) in
    ``A₁, ω, x = εA₁², a = ω² − 1, γ = ω/Q`` and the symbol ``Δ``
    (:func:`damped_determinant`): each value is ``A₁ N/(ω^{2j} Δ^m)`` (``δ_j`` without the
    ``A₁``), ``N`` a polynomial over QQ in ``(x, a, γ)``."""

    order: int
    forcing: tuple[dict[int, sp.Expr], dict[int, sp.Expr]]  # F_j: cos nτ, sin nτ (n ≠ 1)
    secular: tuple[sp.Expr, sp.Expr]  # ω² × the cos τ, sin τ parts of F_j (= 0)
    unknowns: tuple[sp.Symbol, sp.Symbol]  # b_{j−1}, δ_{j−1} (A₁, δ₀ at order 1)
    values: tuple[sp.Expr, sp.Expr] | None  # b_{j−1}, δ_{j−1} (None at order 1: the cubic)
    q: tuple[dict[int, sp.Expr], dict[int, sp.Expr]]  # q_j: cos nτ, sin nτ, b_j included
    delta: sp.Expr  # δ_j


def damped_determinant() -> sp.Expr:
    """``Δ = (a − 9x/4)(a − 3x/4) + γ²``: the determinant of the secular system in
    ``(b_j, δ_j)`` over ``A₁``; ``A₁²Δ/ω⁴`` is ``∂G/∂u`` of the one-harmonic cubic
    (:func:`amplitude_slope`), zero at a fold."""
    return (a_ - sp.Rational(9, 4) * x_) * (a_ - sp.Rational(3, 4) * x_) + gamma_**2


def _moments(n: int) -> list[Fraction]:
    """``(1/π)∫₀^{2π} cos^k s ds`` for ``k < n``: 2, 0, 1, 0, 3/4, …"""
    out = [Fraction(2), Fraction(0)]
    for k in range(2, n):
        out.append(out[k - 2] * Fraction(k - 1, k))
    return out[:n]


def _resonant_parts(t: Trig) -> tuple[object, object]:
    """Fourier coefficients of ``cos s`` and ``sin s`` in ``t = P(C) + S·R(C)``:
    ``(1/π)∫ C·P(C) ds`` and ``(1/π)∫ (1 − C²)·R(C) ds``."""
    g = t.ground
    P, R = t.cos_part.coeffs(), t.sin_part.coeffs()
    m = _moments(max(len(P), len(R)) + 3)
    acc_c, acc_s = g.scalar(0), g.scalar(0)
    for k, c in enumerate(P):
        if m[k + 1]:
            acc_c = acc_c + c * g.scalar(m[k + 1])
    for k, c in enumerate(R):
        if m[k] - m[k + 2]:
            acc_s = acc_s + c * g.scalar(m[k] - m[k + 2])
    return acc_c, acc_s


def _delta_power(j: int) -> int:
    """``Δ``'s power under order ``j``: each 2×2 solve divides by ``Δ`` once, and order j's
    products reach ``Δ^{2j−2}`` before it (q₁·q₁·q_{j−2}, δ₁δ_{j−1})."""
    return 2 * j - 1 if j else 0


@functools.lru_cache(maxsize=4)
def mu_expansion_damped(order: int) -> tuple[MuDampedOrder, ...]:
    """Orders 1..K of eq. 10.68 with damping, exactly, on the sine-capable kernel (:class:`Trig`).

    The representation keeps expressions small: ``q = A₁ q̃`` gives the same equation with
    ``ε → x = εA₁²``, and order 1's conditions ``f cos δ₀ = A₁(¾x − a)``, ``f sin δ₀ = A₁γ``
    (``a = ω² − 1``, ``γ = ω/Q``) remove ``f`` and ``δ₀`` from every later order, whose drive
    is ``(f/ω²) Re(e^{i(τ+δ₀)} E_j)``, ``E = exp(iΣ_{k≥1} δ_k μ^k)``.  Each order carries one
    ``1/ω²`` and each 2×2 solve of the cos τ, sin τ secular conditions
    ``[[a − 9x/4, −γ], [γ, a − 3x/4]]·(b_j/A₁, δ_j) = −(s_c, s_s)`` divides by its determinant
    ``Δ`` (:func:`damped_determinant`): order ``j`` is ``A₁N_j/(ω^{2j} Δ^{2j−1})`` with
    numerators ``N_j`` over QQ in three variables (FLINT's ``fmpq_mpoly``: no rational-function
    gcds).  Convention: ``q_j`` (``j ≥ 1``) has no ``sin τ`` component (that is ``δ_j``'s) and
    its ``cos τ`` component is ``b_j``; at ``γ = 0`` these are :func:`mu_expansion_exact`'s
    orders."""
    check_int(order, 1, MU_EXACT_MAX_ORDER,
              f"order {order!r}: the exact damped μ-expansion takes 1..{MU_EXACT_MAX_ORDER}")
    ground = Ground(QQ.poly_ring(x_, a_, gamma_))
    s = ground.scalar
    zero, one = s(0), s(1)
    x, a, gamma = s(x_), s(a_), s(gamma_)
    fc, fs = s(sp.Rational(3, 4) * x_ - a_), gamma  # f cos δ₀/A₁, f sin δ₀/A₁
    m11, m22 = s(a_ - sp.Rational(9, 4) * x_), s(a_ - sp.Rational(3, 4) * x_)
    powers = [one, s(damped_determinant())]

    def lift(value: object, have: int, want: int) -> object:
        """A numerator over ``Δ^have`` as one over ``Δ^want``."""
        while len(powers) <= want - have:
            powers.append(powers[-1] * powers[1])
        return value * powers[want - have] if want > have else value

    cos1 = Trig.from_fourier({1: one}, {}, ground)
    q, deltas = [cos1], [zero]  # numerators of q_j/A₁ and δ_j over ω^{2j} Δ^{_delta_power(j)}
    sq, cu, X, Y = [cos1 * cos1], [cos1 * cos1 * cos1], [one], [zero]  # q², q³, E = X + iY

    def extend(j: int, want: int) -> None:
        """Append ``[μ^j]`` of q², q³ and E (without ``iδ_j``) over ``Δ^want``."""
        pairs = [(i, j - i, _delta_power(i) + _delta_power(j - i)) for i in range(1, j)]
        last = _delta_power(j - 1)  # q[j] is still order j's particular solution
        sq.append(sum((lift(q[i] * q[k], m, want) for i, k, m in pairs),
                      lift(q[j] * cos1 * 2, last, want)))
        cu.append(sum((lift(q[i] * sq[k], m, want) for i, k, m in pairs),
                      lift(q[j] * sq[0], last, want) + lift(sq[j] * cos1, want, want)))
        X.append(sum((lift(deltas[i] * Y[k] * s(Fraction(-i, j)), m, want)
                      for i, k, m in pairs), zero))
        Y.append(sum((lift(deltas[i] * X[k] * s(Fraction(i, j)), m, want)
                      for i, k, m in pairs), zero))

    def forcing(j: int) -> Trig:
        """``ω² F_{j+1}/A₁`` from order ``j`` (eq. 10.68), over order j's denominator."""
        drive = Trig.from_fourier({1: fc * X[j] - fs * Y[j]}, {1: -(fc * Y[j] + fs * X[j])},
                                  ground)
        return q[j] * a - q[j].derivative() * gamma - cu[j] * x + drive

    def real(c: object, j: int, m: int, amplitude: bool = True) -> sp.Expr:
        """A numerator of order ``j`` over ``Δ^m`` as its value, the powers of ``Δ`` that
        divide it cancelled."""
        while m and c:
            quotient, remainder = divmod(c, powers[1])
            if remainder:
                break
            c, m = quotient, m - 1
        value = ground.to_sympy(c) / (omega_ ** (2 * j) * Delta_**m)
        return A1_ * value if amplitude else value

    def fourier(t: Trig, j: int, m: int, skip: int) -> tuple[dict[int, sp.Expr], ...]:
        return tuple({n: real(c, j, m) for n, c in sorted(part.items()) if n != skip}
                     for part in t.to_fourier())

    out: list[MuDampedOrder] = []
    F = forcing(0)  # ω²F₁/A₁ with f eliminated: its secular parts vanish identically
    pending = ((A1_ * (omega_**2 - 1) - sp.Rational(3, 4) * eps_ * A1_**3
                + force_ * sp.cos(delta0_), A1_ * omega_ / Q_ - force_ * sp.sin(delta0_)),
               (A1_, delta0_), None)
    for j in range(1, order + 1):
        solved = solve_trig(F)
        if solved.secular_cos or solved.secular_sin:
            raise ArithmeticError(f"order {j}: secular terms left in F_{j}")
        c1, s1 = _resonant_parts(solved.particular)
        p = solved.particular - Trig.from_fourier({1: c1}, {1: s1}, ground)
        forcing_j = fourier(F, j, _delta_power(j - 1), 1)
        trial = _delta_power(j) - 1  # order j with b_j = δ_j = 0, over Δ^(2j − 2)
        q.append(p)
        deltas.append(zero)
        extend(j, trial)
        q[j] = lift(p, _delta_power(j - 1), trial)
        sc, ss = _resonant_parts(forcing(j))
        b = -(m22 * sc + gamma * ss)  # adj(M)·(−s): the 1/Δ goes into the next power
        delta = gamma * sc - m11 * ss
        bj, dj = sp.Symbol(f"b_{j}"), sp.Symbol(f"delta_{j}")
        secular = (real(sc, j, trial) + ground.to_sympy(m11) * bj
                   - A1_ * ground.to_sympy(gamma) * dj,
                   real(ss, j, trial) + ground.to_sympy(gamma) * bj
                   + A1_ * ground.to_sympy(m22) * dj)
        up = _delta_power(j)
        q[j] = lift(q[j], trial, up) + cos1 * b
        deltas[j] = delta
        sq[j] = lift(sq[j], trial, up) + cos1 * cos1 * (b * 2)
        cu[j] = lift(cu[j], trial, up) + cos1 * cos1 * cos1 * (b * 3)
        X[j] = lift(X[j], trial, up)
        Y[j] = lift(Y[j], trial, up) + delta
        out.append(MuDampedOrder(order=j, forcing=forcing_j, secular=pending[0],
                                 unknowns=pending[1], values=pending[2],
                                 q=fourier(q[j], j, up, 0), delta=real(delta, j, up, False)))
        pending = (secular, (bj, dj), (real(b, j, up), real(delta, j, up, False)))
        F = forcing(j)
    return tuple(out)


# --- harmonic balance, symbolically (emitted as compiled residual and Jacobian) --------------

@dataclass(frozen=True)
class BalanceEquations:
    """Galerkin residual of eq. 10.60 for ``q = Σ a_k cos kωt + b_k sin kωt``, k odd ≤ 2N − 1."""

    harmonics: int
    unknowns: tuple[sp.Symbol, ...]  # a_1, a_3, …, b_1, b_3, …
    parameters: tuple[sp.Symbol, ...]  # omega, eps, force, damping (= 1/Q)
    residuals: tuple[sp.Expr, ...]  # cos kωt and sin kωt components, same order as unknowns


def balance_equations(harmonics: int) -> BalanceEquations:
    """``−(kω)² q_k + kω/Q q̃_k + q_k + ε[q³]_k − f δ_k1`` for every odd ``k ≤ 2N − 1``."""
    check_int(harmonics, 1, MU_EXACT_MAX_ORDER,
              f"harmonics {harmonics!r}: the symbolic balance takes 1..{MU_EXACT_MAX_ORDER}")
    odd = range(1, 2 * harmonics, 2)
    a = [sp.Symbol(f"a_{k}") for k in odd]
    b = [sp.Symbol(f"b_{k}") for k in odd]
    w, eps, f, g = sp.symbols("omega eps force damping")
    cube_cos, cube_sin = trig_power(dict(zip(odd, a, strict=True)),
                                    dict(zip(odd, b, strict=True)), 3)
    cos_res, sin_res = [], []
    for k, ak, bk in zip(odd, a, b, strict=True):
        # q̇ contributes kω(b_k cos − a_k sin), q̈ contributes −(kω)² q
        cos_res.append(sp.expand((1 - (k * w) ** 2) * ak + g * k * w * bk
                                 + eps * cube_cos.get(k, 0) - (f if k == 1 else 0)))
        sin_res.append(sp.expand((1 - (k * w) ** 2) * bk - g * k * w * ak
                                 + eps * cube_sin.get(k, 0)))
    return BalanceEquations(harmonics, (*a, *b), (w, eps, f, g), (*cos_res, *sin_res))
