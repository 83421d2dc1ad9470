"""Oscillator definitions as data.

Every free oscillator here is written, with ``q = scale · u`` and ``s = ωt``, in the scaled
form the L–P engine solves (notes §10.3, EOM ``ω² q'' + q + ε q³ = 0``)::

    ω² u'' + u + Σ_k y^k Σ_n c_kn u^n = 0,     u(0) = 1, u'(0) = 0,

with ``y = coupling · order_factor`` the expansion variable (``x = εA²`` for Duffing,
``θ₀²`` for the pendulum) and ``forcing[k-1] = ((n, c_kn), ...)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import sympy as sp

from .errors import InputError

t, eps, A, theta0 = sp.symbols("t epsilon A theta_0")
Y = sp.Symbol("Y")  # stands for the expansion variable y in conditions


@dataclass(frozen=True)
class Model:
    """One free oscillator ``q̈ + q + ε f(q) = 0`` in the engine's scaled form."""

    name: str
    title: str  # the equation of motion in plain text
    latex: str  # the equation of motion in LaTeX
    equation: sp.Eq  # the physical equation of motion, for display
    coordinate: sp.Symbol  # q or θ
    amplitude: sp.Symbol  # A or θ₀ (q(0) = amplitude, q̇(0) = 0)
    coupling: sp.Expr  # ε, or 1 when the amplitude is the only small quantity
    order_factor: sp.Expr  # y = coupling · order_factor
    variable: str  # the expansion variable as the JSON contract names it
    forcing: tuple[tuple[tuple[int, sp.Expr], ...], ...]
    radius: sp.Expr | None  # radius of convergence of ω(y), T(y) in |y| (None: unknown)
    parameters: tuple[tuple[str, sp.Symbol], ...] = ()  # argument name -> symbol, in order
    orbit_condition: sp.Basic = sp.true  # in the symbol Y = y: a periodic orbit exists
    exact_to: int | None = None  # the highest order its forcing is complete for (None: all)

    @property
    def odd(self) -> bool:
        """All forcing powers odd: the solution holds odd harmonics only."""
        return all(n % 2 == 1 for terms in self.forcing for n, _ in terms)

    @property
    def y(self) -> sp.Expr:
        return self.coupling * self.order_factor

    def coefficients(self) -> list[sp.Expr]:
        return [c for terms in self.forcing for _, c in terms]


def duffing() -> Model:
    """``q̈ + q + ε q³ = 0`` (notes §10.3); ``x = εA²``; radius 1 (separatrix at ``x = -1``)."""
    q = sp.Symbol("q")
    return Model(
        name="duffing",
        title="q'' + q + eps*q**3 = 0",
        latex=r"\ddot q + q + \varepsilon q^3 = 0",
        equation=sp.Eq(sp.Derivative(q, t, 2) + q + eps * q**3, 0),
        coordinate=q,
        amplitude=A,
        coupling=eps,
        order_factor=A**2,
        variable="x = eps*A**2",
        forcing=(((3, sp.Integer(1)),),),
        radius=sp.Integer(1),
        parameters=(("A", A), ("eps", eps)),
        orbit_condition=sp.Gt(Y, -1),  # εA² ≤ -1: the orbit reaches the separatrix
    )


def pendulum(order: int) -> Model:
    """``θ̈ + sin θ = 0`` (notes App. 4.1), expanded in ``θ₀²``.

    ``sin(θ₀u)/θ₀ = u + Σ_k (-1)^k θ₀^(2k) u^(2k+1)/(2k+1)!``: order K needs exactly the
    terms ``k = 1..K`` of the Taylor series of sin, and the model holds no more.
    The period ``4K(sin²(θ₀/2))`` is singular at the separatrix ``θ₀ = π``: radius ``π²``.
    """
    order = check_order(order)
    th = sp.Symbol("theta")
    forcing = tuple(
        ((2 * k + 1, sp.Rational((-1) ** k, math.factorial(2 * k + 1))),)
        for k in range(1, order + 1)
    )
    return Model(
        name="pendulum",
        title="theta'' + sin(theta) = 0",
        latex=r"\ddot\theta + \sin\theta = 0",
        equation=sp.Eq(sp.Derivative(th, t, 2) + sp.sin(th), 0),
        coordinate=th,
        amplitude=theta0,
        coupling=sp.Integer(1),
        order_factor=theta0**2,
        variable="theta0**2",
        forcing=forcing,
        radius=sp.pi**2,
        parameters=(("theta0", theta0),),
        orbit_condition=sp.Lt(Y, sp.pi**2),  # |θ₀| ≥ π: over the top, no libration
        exact_to=order,
    )


def polynomial(coefficients: dict[int, object]) -> Model:
    """``q̈ + q + ε Σ c_n qⁿ = 0`` for powers ``n ≥ 2`` (odd and even).

    One power ``n``: ``y = εA^(n-1)`` and exact rational coefficients.  Several powers:
    ``y = ε`` and the coefficients ``c_n A^(n-1)`` live in ``QQ[A, …]``.  Coefficients may
    be numbers or SymPy symbols (which then stay symbolic in every result).
    """
    if not coefficients:
        raise InputError("polynomial force: give at least one power n ≥ 2 with its coefficient")
    terms = []
    for n, c in sorted(coefficients.items()):
        if isinstance(n, bool) or not isinstance(n, int) or n < 2:
            raise InputError(f"polynomial force: power {n!r} is not an integer ≥ 2")
        value = _finite(c, f"coefficient of q^{n}")
        if value != 0:
            terms.append((n, value))
    if not terms:
        raise InputError("polynomial force: every coefficient is zero (a linear oscillator)")
    q = sp.Symbol("q")
    force = sum(c * q**n for n, c in terms)
    if len(terms) == 1:
        (n, c), = terms
        factor, forcing = A ** (n - 1), (((n, c),),)
        variable = f"x = eps*A**{n - 1}"
    else:
        factor, forcing = sp.Integer(1), (tuple((n, c * A ** (n - 1)) for n, c in terms),)
        variable = "eps"
    return Model(
        name="polynomial",
        title=f"q'' + q + eps*({sp.sstr(force)}) = 0",
        latex=rf"\ddot q + q + \varepsilon\left({sp.latex(force)}\right) = 0",
        equation=sp.Eq(sp.Derivative(q, t, 2) + q + eps * force, 0),
        coordinate=q,
        amplitude=A,
        coupling=eps,
        order_factor=factor,
        variable=variable,
        forcing=forcing,
        radius=None,
        parameters=(("A", A), ("eps", eps), *((str(s), s) for s in sorted(
            set().union(*(sp.sympify(c).free_symbols for _, c in terms)), key=str))),
    )


MODELS = ("duffing", "pendulum")


def model_by_name(name: str, order: int) -> Model:
    """The named model, sized for ``order`` (the pendulum takes exactly what it needs)."""
    if name == "duffing":
        return duffing()
    if name == "pendulum":
        return pendulum(order)
    raise InputError(f"model {name!r}: unknown; choose one of {', '.join(MODELS)}")


MAX_ORDER = 100_000
# NOTE: a hard sanity bound only; the CLI asks for --allow-slow far below it (cost estimate).


def check_order(order: object) -> int:
    """A non-negative integer order, or :class:`InputError` naming the input."""
    if isinstance(order, bool) or not isinstance(order, int):
        raise InputError(f"order {order!r}: not an integer")
    if order < 0:
        raise InputError(f"order {order}: must be ≥ 0")
    if order > MAX_ORDER:
        raise InputError(f"order {order}: above the limit {MAX_ORDER}")
    return order


def _finite(value: object, what: str) -> sp.Expr:
    try:
        expr = sp.sympify(value, strict=True) if not isinstance(value, sp.Basic) else value
    except (sp.SympifyError, TypeError) as exc:
        raise InputError(f"{what} {value!r}: not a number or SymPy expression") from exc
    if expr.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
        raise InputError(f"{what} {value!r}: not finite")
    if expr.is_number:
        if not expr.is_real:
            raise InputError(f"{what} {value!r}: not real")
        if isinstance(expr, sp.Float):
            if not math.isfinite(float(expr)):
                raise InputError(f"{what} {value!r}: not finite")
            expr = sp.Rational(str(expr))  # exact algebra needs exact input
        elif not expr.is_Rational:
            raise InputError(f"{what} {value!r}: must be rational or a symbol for exact algebra")
    return expr
