"""Where the family of periodic orbits of a free oscillator ends, from its first integral.

A model's scaled equation (time in units of 1/ω₀, ``u(0) = 1``, ``u'(0) = 0``) is

    u'' + G(u, u'²; y) = 0,     G = g₀(u; y) + h(u; y) u'²,

with ``y`` the expansion variable.  With ``H = ∫₀ᵘ h`` and ``p = u'²``, ``d(p e^{2H})/du =
-2 g₀ e^{2H}``: the first integral ``p e^{2H(u)} = W(1) − W(u)``, ``W(u) = ∫₀ᵘ 2 g₀ e^{2H}``
(``2V`` for a potential force).  ``e^{2H} > 0``, so ``W`` rises and falls where ``g₀`` says:
the orbit from ``u = 1`` swings back (time reversibility closes it) exactly when ``g₀ > 0`` on
``(0, 1]`` and ``W(1)`` stays below the barrier on the other side — ``W`` at the nearest
negative zero of ``g₀`` (a saddle), or ``W(−∞)`` where there is none.  The family through
``y = 0`` ends at the first ``y`` on each side where this fails: the separatrix, where the
period diverges, so no convergent series reaches past it either.

The edge is found in double precision (a scan outward, then bisection) and refined to
:data:`DIGITS` digits in mpmath on the equation that holds there (a zero of ``g₀`` reaching
``u = 1``, or ``W(1) = W(saddle)``).
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import mpmath
import numpy as np
import sympy as sp

from .models import Model, oscillator

DIGITS = 30
# NOTE: the edge is stated to 30 significant digits (mpmath works at 40).
SCAN = (1e-6, 1e12, 1.08)
SCAN_TRANSCENDENTAL = 1e3
# NOTE: the scan variable from 1e-6 outward by 8 % steps to 1e12 (a polynomial force) or 1e3
# (any other, whose exponentials overflow doubles beyond): a family that ends has its
# separatrix where the first of these fails; the bisection then closes in on it.  No failure:
# no edge up to the scan's end, and the module's radius guard alone holds beyond it.
ZERO_GRID = (64.0, 4001)
# NOTE: zeros of a non-polynomial g₀ are looked for on |u| ≤ 64 (4001 points a side), then on
# 2000 points spaced geometrically to 64·10⁵, then Brent; a polynomial's come from its
# companion matrix, all of them.


BARRIER_SLACK = 1e-9


@dataclass(frozen=True)
class OrbitDomain:
    """The family of periodic orbits exists for ``lower < y < upper`` (±inf: no end on that
    side); ``lower_text``/``upper_text`` hold the edges to :data:`DIGITS` digits (``"-inf"``,
    ``"inf"``); ``how`` says what ends it.  ``known`` False: no domain could be computed
    (``how`` says why), and the bounds are ±inf."""

    variable: str
    lower: float
    upper: float
    lower_text: str
    upper_text: str
    how: str
    known: bool = True

    @property
    def distance(self) -> float:
        """The distance from ``y = 0`` to the nearer edge: the series' radius is no larger."""
        return min(-self.lower, self.upper)

    def guard_bounds(self) -> tuple[float, float]:
        """The edges as doubles rounded toward ``y = 0``: inside them an orbit exists."""
        lo = self.lower if math.isinf(self.lower) else _toward_zero(self.lower_text)
        hi = self.upper if math.isinf(self.upper) else _toward_zero(self.upper_text)
        return lo, hi

    def as_json(self) -> dict:
        """The domain as the JSON contract gives it: the variable, the edges as text (to
        :data:`DIGITS` digits), ``known`` and ``how``."""
        return {"variable": self.variable, "lower": self.lower_text, "upper": self.upper_text,
                "known": self.known, "how": self.how}


def _toward_zero(text: str) -> float:
    value = float(text)
    exact = mpmath.mpf(text)
    if abs(mpmath.mpf(value)) > abs(exact):
        value = math.nextafter(value, 0.0)
    return value


def unknown(model: Model, why: str) -> OrbitDomain:
    """An :class:`OrbitDomain` with no edges (±inf, ``known`` False) whose ``how`` says
    ``why``."""
    return OrbitDomain(model.variable, -math.inf, math.inf, "-inf", "inf", why, known=False)


@dataclass(frozen=True)
class _Scaled:
    """``g₀(u; s)`` and ``h(u; s)`` of the scaled equation at the scan variable ``s`` (``y``, or
    the amplitude when ``y = A^step``), and how ``s`` maps to ``y``."""

    u: sp.Symbol
    s: sp.Symbol
    g0: sp.Expr
    h: sp.Expr
    power: int  # y = s**power (1: s is y)
    both_sides: bool  # s < 0 is an orbit of its own (not a mirror of s > 0)

    @property
    def polynomial(self) -> bool:
        return self.h == 0 and self.g0.is_polynomial(self.u)

    @functools.cached_property
    def numeric(self) -> dict:
        """Compiled once: ``g₀``'s coefficients in u as functions of s (where it is a
        polynomial in u), ``g₀(u, s)`` and the weight ``e^{2H}(u, s)`` for NumPy."""
        H = sp.integrate(self.h, (self.u, 0, self.u)) if self.h != 0 else sp.Integer(0)
        out = {"g0": sp.lambdify((self.u, self.s), self.g0, "numpy"),
               "weight": sp.lambdify((self.u, self.s), sp.exp(2 * H), "numpy")}
        if self.g0.is_polynomial(self.u):
            coefficients = sp.Poly(self.g0, self.u).all_coeffs()[::-1]
            out["coefficients"] = [sp.lambdify(self.s, c, "math") for c in coefficients]
        return out


def orbit_domain(model: Model) -> OrbitDomain:
    """The range of the expansion variable over which ``model``'s family of periodic orbits
    exists, from the first integral (see the module's docstring); ``known`` False with the
    reason where it cannot be computed (symbolic parameters, several scalings, velocity terms
    beyond ``q'²``)."""
    scaled = _scaled(model)
    if isinstance(scaled, str):
        return unknown(model, scaled)
    try:
        return _domain(model.variable, scaled)
    except (ValueError, ArithmeticError, TypeError) as exc:
        # NOTE: a force the numerics cannot follow (a root finder without a bracket, a
        # quadrature that fails): no edge is stated, and the radius guard stands alone
        return unknown(model, f"the first integral could not be followed ({type(exc).__name__}"
                       f": {str(exc)[:80]})")


class EdgeError(ValueError):
    """An edge found in doubles that the refinement in mpmath could not confirm."""


def _scaled(model: Model) -> _Scaled | str:
    u, P, s = sp.Symbol("u"), sp.Symbol("P"), sp.Symbol("s")
    if model.order_factor == 1:  # y = ε, the coefficients in QQ[A, …]
        return ("the orbits depend on eps and A separately (several powers of A): no single "
                "edge in eps")
    if any(sp.sympify(c).free_symbols for c in model.coefficients()):
        return "the coefficients hold symbolic parameters: give them values (--param)"
    # y = ε·A^p: s = y; y = A^power (no ε: the amplitude is small): s = A
    power = 1 if model.coupling != 1 else sp.Poly(model.order_factor, model.amplitude).degree()
    if model.exact_to is None:  # the model's terms are the whole force, y = s^power
        G = sp.Integer(0)
        for k, terms in enumerate(model.forcing, start=1):
            G += sum(s**(power * k) * c * u**n for n, c in terms)
        for k, terms in enumerate(model.velocity_forcing, start=1):
            G += sum(s**(power * k) * c * u**a * P**b for a, b, c in terms)
        for name, lam, w in model.elementary:  # y = A²: s is the amplitude
            F = sp.sin if name == "sin" else sp.sinh
            G += w * (F(lam * s * u) - lam * s * u) / s
        G += u
    else:  # a Taylor-expanded force: the equation's own, in s = A
        osc = oscillator(model.source, dict(model.given), model.name)
        if osc.parameters:
            return "the force holds symbolic parameters: give them values (--param)"
        q, v = osc.coordinate, osc.velocity
        G = osc.force.xreplace({q: s * u, v: s * model.frequency * P}) / (s * model.frequency**2)
    G = sp.expand(G)
    if not G.is_polynomial(P):
        return "a velocity term that is not polynomial in q': no first integral in closed form"
    by_degree = sp.Poly(G, P).as_dict()
    if any(d[0] not in (0, 2) for d in by_degree):
        return ("velocity terms beyond q'**2: no first integral in closed form (the radius "
                "estimate alone guards the module)")
    g0 = sp.expand(by_degree.get((0,), sp.Integer(0)))
    h = sp.expand(by_degree.get((2,), sp.Integer(0)))
    return _Scaled(u, s, g0, h, power, power % 2 == 1)


# --- the condition at one s, in doubles ------------------------------------------------------

@dataclass
class _Float:
    """``g₀``, ``W`` at one ``s`` in doubles (polynomial: exact roots and antiderivative)."""

    g0: Callable
    W: Callable
    zeros: Callable  # (side: +1 | -1) -> nearest zero of g₀ on that side, or None
    W_infinity: Callable  # the limit of W toward -inf on the negative side
    edges: set  # the sides where zeros() met the end of the force's domain (NaN), not a zero


def _float_at(sc: _Scaled, s: float) -> _Float:
    roots = None
    if "coefficients" in sc.numeric:
        coeffs = [float(c(s)) for c in sc.numeric["coefficients"]]
        g = np.polynomial.Polynomial(coeffs)
        # g₀(0) = 0: the other zeros are those of g₀/u (no spurious root next to 0)
        roots = [r.real for r in np.polynomial.Polynomial(coeffs[1:]).roots()
                 if abs(r.imag) <= 1e-7 * abs(r)]

        def polynomial_zeros(side: int) -> float | None:
            found = [r for r in roots if r * side > 0]
            return min(found, key=abs) if found else None

        if sc.polynomial:
            return _Float(g, 2 * g.integ(), polynomial_zeros, lambda: math.inf, set())
    g0_us, weight_us = sc.numeric["g0"], sc.numeric["weight"]
    # NOTE: SciPy only here (a transcendental force): a polynomial's edge needs none, and
    # `series` should not pay its import
    from scipy.integrate import IntegrationWarning, quad
    from scipy.optimize import brentq

    def g0(x: float | np.ndarray) -> float | np.ndarray:
        return g0_us(x, s)

    def integrand(t: float) -> float:
        return 2 * g0_us(t, s) * weight_us(t, s)

    def W(x: float) -> float:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", IntegrationWarning)
            return quad(integrand, 0.0, x, limit=200)[0]

    edges: set[int] = set()

    def zeros(side: int) -> float | None:
        L, n = ZERO_GRID
        grid = side * np.concatenate([np.linspace(0.0, L, n)[1:],
                                      np.geomspace(L, L * 1e5, n // 2)[1:]])
        with np.errstate(all="ignore"):
            values = np.asarray(g0(grid), dtype=float) * np.ones_like(grid)
        if values[0] * side <= 0:  # within the first step: g₀ ~ u there, so a zero is near
            return float(brentq(g0, side * 1e-12, grid[0], xtol=1e-15))
        # NOTE: an exact 0 is an underflow (u e^(−su) far out), not a zero: skipped; NaN is
        # outside the force's domain (log, sqrt), an edge; ±inf keeps its sign
        keep = np.nonzero(values != 0)[0]
        grid, values = grid[keep], values[keep]
        bad = np.isnan(values)
        change = np.nonzero((values[1:] * values[:-1] < 0) | bad[1:])[0]
        if change.size == 0:
            return None
        i = int(change[0])
        if bad[i + 1]:  # NOTE: marked as an edge of the force's domain, not a zero
            edges.add(side)
            inside, outside = float(grid[i]), float(grid[i + 1])
            for _ in range(80):  # the last finite point, by bisection
                mid = (inside + outside) / 2
                if mid in (inside, outside):
                    break
                with np.errstate(all="ignore"):
                    finite = not math.isnan(float(g0(mid)))
                inside, outside = (mid, outside) if finite else (inside, mid)
            return inside
        return float(brentq(g0, grid[i], grid[i + 1], xtol=1e-15))

    def W_infinity() -> float:
        with warnings.catch_warnings():
            warnings.simplefilter("error", IntegrationWarning)
            try:
                with np.errstate(all="ignore"):
                    value = quad(integrand, -np.inf, 0.0, limit=400)[0]
            except (IntegrationWarning, ZeroDivisionError, OverflowError):
                return math.inf
        return -value if math.isfinite(value) and abs(value) < 1e200 else math.inf

    return _Float(g0, W, polynomial_zeros if roots is not None else zeros, W_infinity, edges)


def _closes(sc: _Scaled, s: float) -> tuple[bool | None, str]:
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return _closes_at(sc, s)


def _closes_at(sc: _Scaled, s: float) -> tuple[bool | None, str]:
    """Whether the orbit from ``u = 1`` at ``s`` swings back, and if not, why (the edge's kind:
    "saddle above" — ``g₀`` has a zero in (0, 1]; "barrier" — ``W(1)`` reaches the saddle or
    the limit below)."""
    f = _float_at(sc, s)
    up = f.zeros(+1)
    if up is not None and up <= 1.0:
        return False, "domain edge" if +1 in f.edges else "saddle above"
    if float(f.g0(1.0)) < 0:  # (an exact 0 there is an underflow: e^(−su) at large s)
        return False, "saddle above"
    down = f.zeros(-1)
    barrier = f.W(down) if down is not None else f.W_infinity()
    if math.isnan(barrier):  # the integral overflowed on its way down: unbounded
        barrier = math.inf
    level = f.W(1.0)
    if not math.isfinite(level):  # beyond what doubles hold: the scan ends here
        return None, "overflow"
    # NOTE: W(1) within 1e-9 of W(−∞) counts as inside: doubles cannot tell them apart
    # (q q'² with x < 0: W(1) = (1 − e^(−|x|))/|x| below W(−∞) = 1/|x| by e^(−|x|)); a true
    # edge is then found a hair late and the refinement puts it back in place
    if not level < barrier * (1 + (BARRIER_SLACK if down is None else 0.0)):
        if down is not None and -1 in f.edges:
            return False, "domain edge"
        return False, "barrier" if down is not None else "barrier at infinity"
    return True, ""


# --- the edge, scanned, bisected, refined ----------------------------------------------------

def _domain(variable: str, sc: _Scaled) -> OrbitDomain:
    lo, hi, hows = -math.inf, math.inf, []
    lo_text, hi_text = "-inf", "inf"
    name = variable.partition("=")[0].strip() or variable
    for side in ((+1, -1) if sc.both_sides else (+1,)):
        where = f"{name} {'>' if side > 0 else '<'} 0"
        try:
            edge = _edge(sc, side)
        except EdgeError as exc:  # a doubles' artefact that 40 digits do not confirm
            hows.append(f"{where}: none stated ({exc})")
            continue
        if edge is None:
            continue
        s_edge, kind = edge
        digits = DIGITS if kind != "domain edge" else 16
        with mpmath.workdps(DIGITS + 10):
            y = s_edge**sc.power
            text = mpmath.nstr(y, digits, min_fixed=-math.inf, max_fixed=math.inf)
        hows.append(f"{where}: {_describe(kind)} at {name} = {mpmath.nstr(y, 12)}")
        if side > 0:
            hi, hi_text = float(y), text
        else:
            lo, lo_text = float(y), text
    if len(hows) < (2 if sc.both_sides else 1):
        reach = (f"|{name}| = {SCAN[1]:g}" if sc.g0.is_polynomial(sc.u, sc.s) else
                 f"A = {SCAN_TRANSCENDENTAL:g} or where doubles overflow")
        hows.append(f"no edge {'on the other side ' if hows else ''}out to {reach}")
    how = "; ".join(hows)
    if sc.power != 1:  # y = A^power ≥ 0: the other side holds no real amplitude
        lo, lo_text = -math.inf, "-inf"
    return OrbitDomain(variable, lo, hi, lo_text, hi_text,
                       "the first integral's separatrix: " + how)


def _describe(kind: str) -> str:
    return {"saddle above": "a saddle of the potential reaches the turning point",
            "barrier": "the swing reaches the saddle on the far side",
            "barrier at infinity": "the swing escapes to infinity on the far side",
            "domain edge": "the swing reaches the end of the force's domain (to double "
                           "precision)"}[kind]


def _edge(sc: _Scaled, side: int) -> tuple[mpmath.mpf, str] | None:
    start, stop, factor = SCAN
    if not sc.polynomial and not sc.g0.is_polynomial(sc.u, sc.s):
        stop = SCAN_TRANSCENDENTAL
    good, s = 0.0, start
    while s <= stop:
        ok, kind = _closes(sc, side * s)
        if ok is None:  # doubles overflow before any edge: none found
            return None
        if not ok:
            break
        good, s = s, s * factor
    else:
        return None
    bad = s
    for _ in range(200):  # bisection to the doubles' resolution
        mid = (good + bad) / 2
        if not good < mid < bad:
            break
        ok, why = _closes(sc, side * mid)
        if ok or ok is None:
            good = mid
        else:
            bad, kind = mid, why
    return _refine(sc, side * (good + bad) / 2, kind), kind


def _refine(sc: _Scaled, s0: float, kind: str) -> mpmath.mpf:
    """The edge to :data:`DIGITS` digits: Newton/secant in mpmath on the equation that holds
    there, from the bisection's double ``s0`` (kept as it is at the end of the force's
    domain, where the force has no value to solve with)."""
    if kind == "domain edge":
        return mpmath.mpf(s0)
    u, s = sc.u, sc.s
    with mpmath.workdps(DIGITS + 10):
        g0 = sp.lambdify((u, s), sc.g0, "mpmath")
        H = sp.integrate(sc.h, (u, 0, u)) if sc.h != 0 else sp.Integer(0)
        if sc.polynomial:
            V = sp.lambdify((u, s), 2 * sp.integrate(sc.g0, (u, 0, u)), "mpmath")

            def W(x: mpmath.mpf, sv: mpmath.mpf) -> mpmath.mpf:
                return V(x, sv)
        else:
            weight = sp.lambdify((u, s), sp.exp(2 * H), "mpmath")

            def W(x: mpmath.mpf, sv: mpmath.mpf) -> mpmath.mpf:
                return mpmath.quad(lambda t: 2 * g0(t, sv) * weight(t, sv), [0, x])

        def zero_near(u0: float, sv: mpmath.mpf) -> mpmath.mpf:
            return mpmath.findroot(lambda x: g0(x, sv), mpmath.mpf(u0))

        # NOTE: where a saddle reaches u = 1 exactly as the barrier closes (a symmetric well:
        # both at once), W(1) − W(saddle) has a double root; g₀(1; s) a simple one
        if kind == "saddle above" or abs(g0(mpmath.mpf(1), mpmath.mpf(s0))) < 1e-6:
            def F(sv: mpmath.mpf) -> mpmath.mpf:
                return g0(mpmath.mpf(1), sv)
        else:
            with np.errstate(all="ignore"):
                down = _float_at(sc, s0).zeros(-1)
            if down is None:  # the limit below: W(1) = W(−∞)
                def F(sv: mpmath.mpf) -> mpmath.mpf:
                    return W(mpmath.mpf(1), sv) - W(-mpmath.inf, sv)
            else:
                state = {"u": down}

                def F(sv: mpmath.mpf) -> mpmath.mpf:
                    state["u"] = zero_near(state["u"], sv)
                    return W(mpmath.mpf(1), sv) - W(state["u"], sv)
        try:
            root = mpmath.findroot(F, (mpmath.mpf(s0) * (1 - 1e-9), mpmath.mpf(s0) * (1 + 1e-9)),
                                   solver="secant", verify=False)
        except (ValueError, ZeroDivisionError) as exc:
            raise EdgeError(f"the orbits' edge near {s0:.6g}: the refinement to {DIGITS} "
                            f"digits failed ({exc})") from exc
        if abs(root - s0) > 1e-6 * abs(s0):
            raise EdgeError(f"the orbits' edge near {s0:.6g}: the refinement left the "
                            f"bisection's bracket ({mpmath.nstr(root, 10)})")
        step = abs(root) * mpmath.mpf(10) ** -(DIGITS - 4)
        if mpmath.sign(F(root - step)) * mpmath.sign(F(root + step)) >= 0:
            raise EdgeError(f"the orbits' edge near {s0:.6g}: the condition does not change "
                            "sign there in 40 digits")
        return root


# --- the domain at run time: a force whose orbits depend on ε and A separately ----------------

@dataclass(frozen=True)
class RuntimeBarrier:
    """Where no single edge in the expansion variable exists (``y = ε``, the orbits depending
    on ε and A separately), the data an emitted module needs to decide at each ``(A, ε)``
    whether the orbit through ``q(0) = A``, ``q'(0) = 0`` exists, for ``q'' + g₀(q) + h(q) q'²
    = 0``: ``g₀(q)/q = Σ_j g_j(ε) q^j`` with ``g_j(ε) = Σ_i coefficients[j][i] ε^i`` (``g_0(0)
    = ω₀²``) and ``2H(q) = 2∫₀^q h = Σ_j w_j(ε) q^j`` likewise in ``weight`` (empty: no velocity
    term, a potential force).  The orbit exists when ``A`` lies between the nearest nonzero
    zeros of ``g₀`` on either side and ``W(A)`` stays below ``W`` at the nearest one on the
    other side, or below its limit there where there is none (``W = ∫ 2 g₀ e^{2H}``: the first
    integral's barrier, as :func:`orbit_domain` and the module's docstring)."""

    coefficients: tuple[tuple[float, ...], ...]  # [j][i]: of q^j ε^i in g₀(q)/q
    exact: tuple[str, ...]  # each g_j(ε) as text (the provenance)
    weight: tuple[tuple[float, ...], ...] = ()  # [j][i]: of q^j ε^i in 2H(q)
    weight_exact: tuple[str, ...] = ()


def _by_powers(expr: sp.Expr, q: sp.Symbol, eps: sp.Symbol) -> tuple[tuple, tuple]:
    """``expr``, a polynomial in ``q`` and ``eps``, as rows ``[j][i]`` of ``q^j ε^i`` (floats)
    and each ``q^j`` coefficient as text."""
    rows = [sp.Poly(c, eps) for c in sp.Poly(expr, q).all_coeffs()[::-1]]
    return (tuple(tuple(float(c) for c in row.all_coeffs()[::-1]) for row in rows),
            tuple(str(row.as_expr()) for row in rows))


def runtime_barrier(model: Model) -> RuntimeBarrier | None:
    """The :class:`RuntimeBarrier` of a user's force ``g₀(q) + h(q) q'²``, both polynomials in
    ``q`` with coefficients polynomial in the coupling ε (no other symbol, no other velocity
    term), where :func:`orbit_domain` finds no single edge; None for any other model."""
    if model.order_factor != 1 or not model.source:
        return None
    osc = oscillator(model.source, dict(model.given), model.name)
    if osc.parameters:
        return None
    q, v, eps = osc.coordinate, osc.velocity, sp.Symbol(str(model.coupling))
    force = sp.expand(osc.force.xreplace({s: eps for s in osc.force.free_symbols
                                          if str(s) == str(model.coupling)}))
    if force.free_symbols - {q, v, eps} or not force.is_polynomial(q, v, eps):
        return None
    by_degree = sp.Poly(force, v).as_dict()
    if any(d[0] not in (0, 2) for d in by_degree):
        return None
    g0 = by_degree.get((0,), sp.Integer(0))
    if g0.subs(q, 0) != 0:
        return None
    coefficients, exact = _by_powers(sp.cancel(g0 / q), q, eps)
    h = by_degree.get((2,), sp.Integer(0))
    if h == 0:
        return RuntimeBarrier(coefficients, exact)
    weight, weight_exact = _by_powers(sp.expand(2 * sp.integrate(h, (q, 0, q))), q, eps)
    return RuntimeBarrier(coefficients, exact, weight, weight_exact)


# --- the domain at run time: a force whose parameters stay symbols ---------------------------

@dataclass(frozen=True)
class RuntimeScan:
    """Where the orbit domain depends on parameters left as symbols (the module's arguments
    ``args``), what the emitted module needs to find it at each call, for the raw equation
    ``q'' + g₀(q) + h(q) q'² = 0`` in ``u`` (the coordinate): ``g0``, ``two_h`` = 2∫₀ᵘ h (0: a
    potential force), ``half_w`` = ∫₀ᵘ g₀ e^{2H} in closed form where SymPy finds one (None:
    the module integrates it by quadrature), and ``y`` the expansion variable at amplitude
    ``a`` (to turn an edge in the amplitude into a distance in y).  The orbit through ``q(0) =
    A`` exists when ``g₀`` has the sign of ``q`` near 0 and ``|A|`` is below the edge on its
    side: the nearest zero of ``g₀`` there, or first where ``W`` reaches its barrier on the
    other side (the first integral, as :func:`orbit_domain`)."""

    args: tuple[sp.Symbol, ...]
    u: sp.Symbol
    a: sp.Symbol
    g0: sp.Expr
    two_h: sp.Expr
    half_w: sp.Expr | None
    y: sp.Expr


def runtime_scan(model: Model, to_args: dict, args: tuple[sp.Symbol, ...],
                 y: sp.Expr, amplitude: sp.Symbol) -> RuntimeScan | None:
    """The :class:`RuntimeScan` of a user's equation whose force holds parameters left
    symbolic (``to_args`` maps the model's symbols to the module's arguments ``args``; ``y``,
    the expansion variable in them, ``amplitude`` its amplitude symbol), where the force is
    ``g₀(q) + h(q) q'²`` and ``y`` holds the amplitude (y = A^p or ε A^p: an edge in A is one in
    y); None for any other model (numbers: :func:`orbit_domain` computes the domain at
    generate time)."""
    if not model.source or not y.has(amplitude):
        return None  # y = ε alone: the reach in ε at each A is runtime_barrier's (polynomials)
    osc = oscillator(model.source, dict(model.given), model.name)
    q, v = osc.coordinate, osc.velocity
    names = {str(s): arg for s, arg in to_args.items() if arg in args} | {
        str(arg): arg for arg in args}
    rename = {s: names[str(s)] for s in osc.force.free_symbols - {q, v} if str(s) in names}
    force = sp.expand(osc.force.xreplace(rename))
    u, a = sp.Symbol("_u"), sp.Symbol("_a")
    if force.free_symbols - {q, v, *args} or not force.is_polynomial(v):
        return None
    by_degree = sp.Poly(force, v).as_dict()
    if any(d[0] not in (0, 2) for d in by_degree):
        return None
    g0 = by_degree.get((0,), sp.Integer(0)).xreplace({q: u})
    h = by_degree.get((2,), sp.Integer(0)).xreplace({q: u})
    if sp.simplify(g0.subs(u, 0)) != 0:
        return None
    two_h = sp.Integer(0) if h == 0 else sp.expand(2 * sp.integrate(h, (u, 0, u)))
    if two_h.has(sp.Integral):
        return None
    half_w = None
    if h == 0:
        half_w = sp.integrate(g0, (u, 0, u))
        if half_w.has(sp.Integral, sp.Piecewise):
            half_w = None
    return RuntimeScan(tuple(args), u, a, g0, two_h, half_w, y.xreplace({amplitude: a}))
