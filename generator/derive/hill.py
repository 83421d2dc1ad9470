"""Hill's equation ``ẍ + (δ + ε p(t))x = 0`` for a finite trigonometric ``p``: the transition
curves out of every tongue ``δ = n²/4`` as exact series in ε with the periodic solution on each,
the tip of a damped tongue, and Mathieu's a_m(q), b_m(q) (DLMF §28.6) as the named case.

L–P in ``τ = t/2`` (:func:`transition_curves`): with ``x = Σ ε^k x_k``, ``α = 4δ = n² +
Σ α_k ε^k`` and ``P = 4p(2τ)``, order k reads ``x_k'' + n² x_k = −P x_(k−1) − Σ_(i=1..k) α_i
x_(k−i)``; the secular conditions (no ``cos nτ``, ``sin nτ`` on the right) give α_k and, where
the two kernel directions mix, the kernel part of x_(k−1); x_k follows harmonic by harmonic,
``c_j / (n² − j²)``.  Products of harmonics by ``cos x cos y = (cos(x−y) + cos(x+y))/2`` and
its sine forms are the whole algebra: exact rationals (FLINT), no secular term left.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import flint
import sympy as sp
from flint import fmpq, fmpq_poly, fmpq_series

from ..errors import InputError
from ..limits import HILL_MAX_INDEX as MAX_M
from ..limits import check_int
from .equation import TIME, parse_expression
from .models import check_order

KINDS = ("a", "b")


def mathieu_series(kind: str, m: int, order: int) -> list[Fraction]:
    """``[c_0, c_1, …, c_K]`` with ``a_m(q)`` (kind "a", m ≥ 0) or ``b_m(q)`` (kind "b",
    m ≥ 1) ``= Σ c_k q^k``, DLMF's normalisation ``y'' + (a − 2q cos 2z) y = 0``."""
    if kind not in KINDS:
        raise InputError(f"kind {kind!r}: a (even solutions ce_m) or b (odd, se_m)")
    check_int(m, 0 if kind == "a" else 1, MAX_M,
              f"--m {m!r}: an integer 1..{MAX_M} for b_m (b_0 does not exist)" if kind == "b"
              else f"--m {m!r}: an integer 0..{MAX_M}")
    order = check_order(order)
    # NOTE: y(z) = x(t) with t = 2z: ẍ + (δ + ε cos t)x = 0 with δ = a/4, ε = −q/2 — the named
    # case of transition_curves: cos mz ↔ its first curve, sin mz ↔ its second.
    curve = transition_curves({1: (Fraction(1), Fraction(0))}, m, order).curves[
        0 if kind == "a" else 1]
    return [4 * d * Fraction(-1, 2) ** k for k, d in enumerate(curve.delta)]


# --- Hill's equation ẍ + (δ + ε p(t)) x = 0: the transition curves out of every tongue --------

MAX_HARMONIC = 64
# NOTE: the highest harmonic of p(t) taken; a user's p is a short trigonometric sum.
QUARTER = {0: (1, 0), 1: (0, 1), 2: (-1, 0), 3: (0, -1)}
# NOTE: (cos kπ/2, sin kπ/2) for k mod 4: a quarter-period shift keeps p's coefficients exact.

Harmonics = dict[int, tuple[Fraction, Fraction]]  # k -> (cos kt, sin kt) coefficients of p
Modes = dict[tuple[int, int], Fraction]  # (0, j): cos(jτ), (1, j): sin(jτ), τ = t/2


@dataclass(frozen=True)
class TransitionCurve:
    """One transition curve ``δ = Σ_k delta[k] ε^k`` out of the tongue ``δ = n²/4`` of
    ``ẍ + (δ + ε p(t))x = 0``, and the periodic solution on it: ``solution[k]`` holds the
    Fourier coefficients of the ε^k term in ``τ = (t − shift)/2``: ``{(0, j): c}`` for
    ``c cos jτ``, ``{(1, j): c}`` for ``c sin jτ`` (period 2π in t for n even, 4π for n odd)."""

    label: str
    delta: tuple[Fraction, ...]
    solution: tuple[Modes, ...]


@dataclass(frozen=True)
class Tongue:
    """The transition curves of tongue ``n`` (one for n = 0, two otherwise), for ``p`` given by
    its harmonics; ``shift``: the quarter periods ``t₀ = shift·π/2`` by which ``p`` was moved
    to make it even (the solutions are written in ``t − t₀``; the curves do not move)."""

    n: int
    p: Harmonics
    shift: int
    curves: tuple[TransitionCurve, ...]


def fourier_of_text(text: str) -> Harmonics:
    """``p(t)`` given as text (the oscillator parser's whitelist) as its harmonics ``{k: (a_k,
    b_k)}`` of ``Σ a_k cos kt + b_k sin kt``; :class:`InputError` unless it is a finite
    trigonometric polynomial of period 2π in t with rational coefficients."""
    expr = parse_expression(text, "p(t)")
    t = sp.Symbol(TIME)
    others = sorted(str(s) for s in expr.free_symbols - {t})
    if others:
        raise InputError(f"p(t) {text!r}: {', '.join(others)} is not t; give numbers "
                         "(p may depend on t only)")
    out: Harmonics = {}

    def add(k: int, a: Fraction, b: Fraction) -> None:
        if k > MAX_HARMONIC:
            raise InputError(f"p(t) {text!r}: harmonic {k} above the limit {MAX_HARMONIC}")
        old = out.get(k, (Fraction(0), Fraction(0)))
        out[k] = (old[0] + a, old[1] + b)

    for term in sp.Add.make_args(sp.expand(expr)):
        coeff, factors = term.as_coeff_mul()
        if not coeff.is_Rational:
            raise InputError(f"p(t) {text!r}: the coefficient {coeff} is not rational")
        modes: Modes = {(0, 0): Fraction(coeff.p, coeff.q)}
        for factor in factors:
            base, power = factor.as_base_exp()
            if not (power.is_Integer and power > 0) or not isinstance(base, (sp.cos, sp.sin)):
                reason = ("a coefficient that is not rational" if t not in factor.free_symbols
                          else "not a finite sum of cos(k*t), sin(k*t) with integer k")
                raise InputError(f"p(t) {text!r}: {factor} is {reason}")
            k = sp.simplify(base.args[0] / t)
            if not k.is_Rational or k.free_symbols:
                raise InputError(f"p(t) {text!r}: {base} is not periodic in t as a sum of "
                                 "cos(k*t), sin(k*t) (k an integer)")
            if not k.is_Integer:
                raise InputError(f"p(t) {text!r}: {base} has period {sp.Abs(2 * sp.pi / k)}, "
                                 "not 2*pi (write t for the period-2π time: k an integer)")
            kind, k = int(isinstance(base, sp.sin)), int(k)
            one = {(kind, abs(k)): Fraction(-1 if kind and k < 0 else 1)} if k else \
                {(0, 0): Fraction(1 - kind)}
            for _ in range(int(power)):
                modes = _product(modes, one)
        for (kind, k), c in modes.items():
            add(k, c if kind == 0 else Fraction(0), c if kind == 1 else Fraction(0))
    out = {k: ab for k, ab in sorted(out.items()) if ab != (0, 0)}
    if not any(k for k in out):
        raise InputError(f"p(t) {text!r}: no harmonic k ≥ 1 (a constant p only moves δ)")
    return out


def _product(a: Modes, b: Modes) -> Modes:
    """The product of two trigonometric sums by ``cos x cos y = (cos(x−y) + cos(x+y))/2`` and
    its sine forms, exact (Fraction or fmpq coefficients)."""
    out: Modes = {}
    for (ka, i), ca in a.items():
        for (kb, j), cb in b.items():
            c = ca * cb / 2
            d, s = abs(i - j), (1 if i >= j else -1)
            if ka == 0 and kb == 0:
                terms = (((0, i + j), c), ((0, d), c))
            elif ka == 1 and kb == 1:
                terms = (((0, d), c), ((0, i + j), -c))
            elif ka == 1:  # sin i cos j
                terms = (((1, i + j), c), ((1, d), s * c))
            else:  # cos i sin j
                terms = (((1, i + j), c), ((1, d), -s * c))
            for key, v in terms:
                if key != (1, 0):
                    out[key] = out.get(key, 0) + v
    return {key: v for key, v in out.items() if v}


def _shifted(p: Harmonics, quarters: int) -> Harmonics:
    """``p(t + quarters·π/2)``: ``cos k(t+t₀) = cos kt cos kt₀ − sin kt sin kt₀`` and sine."""
    out = {}
    for k, (a, b) in p.items():
        c, s = QUARTER[(k * quarters) % 4]
        out[k] = (a * c + b * s, b * c - a * s)
    return out


def _rational_sqrt(x: Fraction) -> Fraction | None:
    if x < 0:
        return None
    num, den = math.isqrt(x.numerator), math.isqrt(x.denominator)
    return Fraction(num, den) if num * num == x.numerator and den * den == x.denominator \
        else None


def _dot(f: Modes, u: Modes) -> Fraction:
    return sum(c * f.get(key, 0) for key, c in u.items())


def transition_curves(p: Harmonics | str, n: int, order: int) -> Tongue:
    """Both transition curves out of the tongue ``δ = n²/4`` of ``ẍ + (δ + ε p(t))x = 0`` (one
    for n = 0) to ``ε^order``, exact, by L–P in ``τ = t/2``: ``x'' + (α + εP(τ))x = 0`` with
    ``α = 4δ = n² + Σ α_k ε^k``, ``P = 4p(2τ)``, ``x = Σ ε^k x_k``.  Order k reads
    ``x_k'' + n² x_k = −P x_(k−1) − Σ_(i=1..k) α_i x_(k−i)``: its right side must hold no
    ``x₀`` (that gives α_k) and no ``w``, the other solution of period 2π of ``x'' + n²x = 0``
    (that gives the w-part β_(k−1) of x_(k−1): degenerate perturbation theory, divided by the
    first-order split of the two curves).  ``x₀``, ``w``: ``cos nτ``, ``sin nτ`` when p is
    even (about t = 0 or, after a shift, about t = π/2: the two never mix); otherwise the
    eigenvectors of the first-order 2 × 2 problem, where the split is a rational number.
    Refused (one line) where neither holds: the split is irrational or comes only at a
    higher order."""
    if isinstance(p, str):
        p = fourier_of_text(p)
    check_int(n, 0, MAX_M, f"--n {n!r}: the tongue index, an integer 0..{MAX_M} (δ = n²/4)")
    order = check_order(order)
    shift = next((s for s in (0, 1) if all(b == 0 for _, b in _shifted(p, s).values())), None)
    q = _shifted(p, shift or 0)
    P: Modes = {}
    for k, (a, b) in q.items():
        for kind, c in ((0, a), (1, b)):
            if c and (kind, 2 * k) != (1, 0):
                P[(kind, 2 * k)] = 4 * c
    if n == 0:
        bases = [({(0, 0): Fraction(1)}, {}, "1")]
    else:
        cos_n, sin_n = {(0, n): Fraction(1)}, {(1, n): Fraction(1)}
        half = {1: "t/2", 2: "t"}.get(n, f"{n}*t/2" if n % 2 else f"{n // 2}*t")
        if shift is not None:
            bases = [(cos_n, sin_n, f"cos({half})"), (sin_n, cos_n, f"sin({half})")]
        else:
            A = _dot(_product(P, cos_n), cos_n)
            B = _dot(_product(P, sin_n), cos_n)
            D = _dot(_product(P, sin_n), sin_n)
            root = _rational_sqrt(((A - D) / 2) ** 2 + B * B)
            if not root:
                why = ("the first-order split is irrational (sqrt of "
                       f"{((A - D) / 2) ** 2 + B * B})" if root is None else
                       f"p has no harmonic {n} (the curves split only at a higher order)")
                raise InputError(f"p(t): tongue n = {n}: p is even about no quarter period "
                                 f"and {why}; the curves do not split over the rationals")
            bases = []
            for sign, name in ((1, "lower"), (-1, "upper")):  # δ₁ = −λ/4
                lam = (A + D) / 2 + sign * root  # eigenvalue of the kernel block of P
                u, v = (B, lam - A) if B else ((1, 0) if lam == A else (0, 1))
                scale = math.lcm(Fraction(u).denominator, Fraction(v).denominator)
                u, v = int(u * scale), int(v * scale)  # the smallest integer eigenvector
                g = math.gcd(u, v)
                u, v = u // g, v // g
                x0 = {key: Fraction(c) for key, c in (((0, n), u), ((1, n), v)) if c}
                w = {key: Fraction(c) for key, c in (((0, n), -v), ((1, n), u)) if c}
                bases.append((x0, w, f"{name} ({u}*cos({half}) {'-' if v < 0 else '+'} "
                                     f"{abs(v)}*sin({half}))"))
    curves = tuple(_curve(P, n, x0, w, label, order) for x0, w, label in bases)
    return Tongue(n, dict(p), shift or 0, curves)


def _polys(f: Modes) -> tuple[fmpq_poly, fmpq_poly]:
    """A trigonometric sum as two dense FLINT polynomials: cos jτ and sin jτ at x^j."""
    top = max((j for _, j in f), default=0) + 1
    cos, sin = [0] * top, [0] * top
    for (kind, j), c in f.items():
        (sin if kind else cos)[j] = c
    return fmpq_poly(cos), fmpq_poly(sin)


def _modes(cos: fmpq_poly, sin: fmpq_poly) -> Modes:
    out = {(0, j): c for j, c in enumerate(cos.coeffs()) if c}
    out.update({(1, j): c for j, c in enumerate(sin.coeffs()) if c})
    return out


def _curve(P: Modes, n: int, x0: Modes, w: Modes, label: str, order: int) -> TransitionCurve:
    """One curve of :func:`transition_curves` about ``x₀`` (``w``: the other kernel
    direction, empty for n = 0)."""
    kernel = {(0, n), (1, n)}
    # NOTE: FLINT inside the loop: fmpq for the products, and each x_k also as two fmpq_poly
    # (one denominator per vector) for Σ α_i x_(k−i), the O(K³) part: 7× and again 3× faster
    # than Fraction dicts at order 100.
    P = {key: fmpq(c.numerator, c.denominator) for key, c in P.items()}
    x0 = {key: fmpq(c.numerator, c.denominator) for key, c in x0.items()}
    w = {key: fmpq(c.numerator, c.denominator) for key, c in w.items()}
    norm0, normw = _dot(x0, x0), _dot(w, w)
    gap = (_dot(_product(P, w), w) / normw - _dot(_product(P, x0), x0) / norm0) if w \
        else fmpq(0)
    xs: list[Modes] = [dict(x0)]
    vectors = [_polys(x0)]
    alphas = [fmpq(n * n)]
    for k in range(1, order + 1):
        cos, sin = _polys(_product(P, xs[k - 1]))
        for i in range(1, k):
            if alphas[i]:  # (half of them vanish where p is even)
                cos += alphas[i] * vectors[k - i][0]
                sin += alphas[i] * vectors[k - i][1]
        rhs = {key: -c for key, c in _modes(cos, sin).items()}
        if w and k > 1:  # the w-part of x_(k−1): this order's right side holds no w
            along = _dot(rhs, w)
            if along and not gap:
                raise InputError(f"p(t): tongue n = {n}: the two curves split only at order "
                                 f"{k}; not handled")
            beta = along / (gap * normw) if along else fmpq(0)
            if beta:
                # adding βw to x_(k−1) adds −β(P + α₁)w here (and β w to the solution)
                for key, c in w.items():
                    xs[k - 1][key] = xs[k - 1].get(key, fmpq(0)) + beta * c
                vectors[k - 1] = _polys(xs[k - 1])
                extra = _product(P, {key: beta * c for key, c in w.items()})
                for key, c in extra.items():
                    rhs[key] = rhs.get(key, fmpq(0)) - c
                for key, c in w.items():
                    rhs[key] = rhs.get(key, fmpq(0)) - alphas[1] * beta * c
        alpha = _dot(rhs, x0) / norm0  # the secular condition along x₀
        alphas.append(alpha)
        xs.append({key: c / (n * n - key[1] ** 2) for key, c in rhs.items()
                   if key not in kernel and c})
        vectors.append(_polys(xs[k]))
    return TransitionCurve(label, tuple(_fraction(a / 4) for a in alphas),
                           tuple({key: _fraction(c) for key, c in sorted(x.items())} for x in xs))


def _fraction(x: fmpq) -> Fraction:
    return Fraction(int(x.p), int(x.q))


@dataclass(frozen=True)
class TongueTip:
    """The lowest point of tongue ``n`` of the damped ``ẍ + 2ζẋ + (δ + ε p(t))x = 0``:
    ``ε_min(ζ) = Σ eps_min[k] ζ^k`` at ``δ = Σ delta[k] ζ^k``; and on the way the largest
    Floquet exponent of the undamped equation inside the tongue, ``μ_max(ε) = Σ mu[k] ε^k``."""

    n: int
    eps_min: tuple[Fraction, ...]
    delta: tuple[Fraction, ...]
    mu: tuple[Fraction, ...]


def _derivative(f: Modes) -> Modes:
    """d/dτ: ``cos jτ → −j sin jτ``, ``sin jτ → j cos jτ``."""
    return {(1 - kind, j): (-j * c if kind == 0 else j * c) for (kind, j), c in f.items() if j}


def _reflection(f: Modes, g: Modes) -> fmpq:
    """``(1/π)∫₀^2π f(τ) g(−τ) dτ`` from the coefficients (cosines +, sines −, the mean 2×)."""
    return sum(((2 if j == 0 else 1) * (1 if kind == 0 else -1)) * c * g.get((kind, j), 0)
               for (kind, j), c in f.items())


def tongue_tip(p: Harmonics | str, n: int, order: int) -> TongueTip:
    """The tip of tongue ``n ≥ 1`` under damping, exact, for ``p`` even (about t = 0 or a
    quarter period) with a harmonic ``n`` (the tongue opens at first order in ε).

    ``x = e^(−ζt) y`` turns ``ẍ + 2ζẋ + (δ + εp)x = 0`` into ``ÿ + (δ − ζ² + εp)y = 0``: x is
    stable where y's Floquet exponent μ < ζ, so the tongue's lowest ε is where ``μ_max(ε) =
    max_δ μ = ζ``, at ``δ = δ* + ζ²``.  In ``τ = t/2`` the Floquet form ``y = e^(μ̃τ)φ(τ)``
    (``μ̃ = 2μ``, φ of period 2π) reads ``φ'' + 2μ̃φ' + (μ̃² + α + εP)φ = 0``; the maximum over
    α holds where ``∫φ(τ)φ(−τ)dτ = 0`` (``y(−τ)`` is the other Floquet solution; ``∂μ/∂α`` is
    that integral over their Wronskian).  L–P in ε with ``α = n² + Σσ_kε^k``, ``μ̃ = Σ m_kε^k``:
    order k's two secular conditions give ``σ_k, m_k``; the integral condition fixes the
    ``w``-part of ``φ_(k−1)``.  Then ``ε_min(ζ)`` is the reversion of ``ζ = μ̃(ε)/2``."""
    if isinstance(p, str):
        p = fourier_of_text(p)
    check_int(n, 1, MAX_M, f"--n {n!r}: the damped tongue's index, an integer 1..{MAX_M}")
    wanted = check_order(order)
    order = max(wanted, 1)  # ζ = μ̃(ε)/2 starts at ε¹: its reversion needs that term
    shift = next((s for s in (0, 1) if all(b == 0 for _, b in _shifted(p, s).values())), None)
    if shift is None:
        raise InputError("--zeta: p(t) must be even about t = 0 or a quarter period (then "
                         "the damped tongue's tip is an exact series)")
    q = _shifted(p, shift)
    if not q.get(n, (0, 0))[0]:
        raise InputError(f"--zeta: p(t) has no harmonic {n}: tongue n = {n} opens only at "
                         "a higher order in ε (its tip under damping is not handled)")
    P = {(0, 2 * k): fmpq(4 * a.numerator, a.denominator) for k, (a, _) in q.items() if a}
    kernel = {(0, n), (1, n)}

    def solve(rhs: Modes, phi0: Modes, dphi0: Modes) -> tuple[fmpq, fmpq]:
        """σ, m with the kernel part of ``rhs − σφ₀ − 2m φ₀'`` zero (Cramer)."""
        r = [rhs.get(key, fmpq(0)) for key in sorted(kernel)]
        a = [phi0.get(key, fmpq(0)) for key in sorted(kernel)]
        b = [2 * dphi0.get(key, fmpq(0)) for key in sorted(kernel)]
        det = a[0] * b[1] - a[1] * b[0]
        return (r[0] * b[1] - r[1] * b[0]) / det, (a[0] * r[1] - a[1] * r[0]) / det

    for s in (1, -1):  # φ₀ = cos nτ − s sin nτ: the max condition at order 0, μ̃₁ > 0
        phi0 = {(0, n): fmpq(1), (1, n): fmpq(-s)}
        w = {(0, n): fmpq(s), (1, n): fmpq(1)}
        dphi0 = _derivative(phi0)
        sigma1, m1 = solve({key: -c for key, c in _product(P, phi0).items()}, phi0, dphi0)
        if m1 > 0:
            break
    phis, sigmas, ms = [phi0], [fmpq(0), sigma1], [fmpq(0), m1]
    wgap = 2 * _reflection(phi0, w)
    dphis = [dphi0]
    for k in range(1, order + 1):
        if k > 1:  # the w-part of φ_(k−1) from the integral condition at order k − 1
            known = sum((_reflection(phis[i], phis[k - 1 - i]) for i in range(1, k - 1)),
                        fmpq(0))
            gamma = -known / wgap
            if gamma:
                for key, c in w.items():
                    phis[k - 1][key] = phis[k - 1].get(key, 0) + gamma * c
                dphis[k - 1] = _derivative(phis[k - 1])
        rhs: Modes = {key: -c for key, c in _product(P, phis[k - 1]).items()}
        for i in range(1, k):
            for coeff, fs in ((sigmas[i], phis[k - i]), (2 * ms[i], dphis[k - i])):
                if coeff:
                    for key, c in fs.items():
                        rhs[key] = rhs.get(key, 0) - coeff * c
        for i in range(1, k):
            for j in range(1, k - i + 1):
                coeff = ms[i] * ms[j]
                if coeff:
                    for key, c in phis[k - i - j].items():
                        rhs[key] = rhs.get(key, 0) - coeff * c
        if k > 1:
            sigma, m = solve(rhs, phi0, dphi0)
            sigmas.append(sigma)
            ms.append(m)
            for key, c in phi0.items():
                rhs[key] = rhs.get(key, 0) - sigma * c
            for key, c in dphi0.items():
                rhs[key] = rhs.get(key, 0) - 2 * m * c
        else:
            for key, c in phi0.items():
                rhs[key] = rhs.get(key, 0) - sigma1 * c
            for key, c in dphi0.items():
                rhs[key] = rhs.get(key, 0) - 2 * m1 * c
        phi = {key: c / (n * n - key[1] ** 2) for key, c in rhs.items()
               if key not in kernel and c}
        phis.append(phi)
        dphis.append(_derivative(phi))
    prec = order + 1
    cap, flint.ctx.cap = flint.ctx.cap, prec  # FLINT's series keep ctx.cap terms
    try:
        zeta = fmpq_series([m / 2 for m in ms], prec=prec)  # ζ = μ_max(ε) = μ̃/2
        eps_min = zeta.reversion()
        alpha = fmpq_series([fmpq(0), *sigmas[1:]], prec=prec)  # α − n²
        z = fmpq_series([0, 1], prec=prec)
        tip = (alpha(eps_min) / 4 + z * z).coeffs()
        eps = eps_min.coeffs()
    finally:
        flint.ctx.cap = cap
    tip = [fmpq(n * n, 4) + (tip[0] if tip else 0)] + [
        tip[i] if i < len(tip) else fmpq(0) for i in range(1, prec)]
    eps = [eps[i] if i < len(eps) else fmpq(0) for i in range(prec)]
    return TongueTip(n, tuple(map(_fraction, eps[:wanted + 1])),
                     tuple(map(_fraction, tip[:wanted + 1])),
                     tuple(_fraction(m / 2) for m in ms[:wanted + 1]))
