"""A system of coupled oscillators from text: one equation per coordinate, separated by ``;``.

``M x'' + K x + f(x, x') = 0`` with a diagonal mass ``M`` (each equation holds one
acceleration), the stiffness ``K`` and the nonlinear force ``f`` (terms of degree ≥ 2), every
coefficient exact.  The linear modes are the roots ``λ = ω₀²`` of ``det(K − λM) = 0``, kept
exact: a rational, or an algebraic number (SymPy's ``CRootOf`` with its minimal polynomial),
never rounded; modes are numbered by increasing linear frequency.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..errors import InputError
from .equation import TIME, derivative_symbols, parse_expression, parse_sides, renamed

MAX_COORDINATES = 12
# NOTE: the FPU chains and structures a user writes by hand stay far below; exact eigenvalues
# of a larger stiffness matrix (a characteristic polynomial of degree > 12) are not sought.


@dataclass(frozen=True)
class System:
    """``M x'' + K x + f(x, x') = 0``: coordinates in the order of the equations, each an
    exact rational (``mass``, ``stiffness``) or a polynomial (``force``, the terms of degree
    ≥ 2 of each equation, divided by its mass)."""

    text: str
    coordinates: tuple[sp.Symbol, ...]
    velocities: tuple[sp.Symbol, ...]
    mass: tuple[sp.Rational, ...]
    stiffness: sp.Matrix  # M⁻¹K
    force: tuple[sp.Expr, ...]  # M⁻¹ f(x, x'), degree ≥ 2

    @property
    def size(self) -> int:
        """The number of degrees of freedom."""
        return len(self.coordinates)

    @property
    def conservative(self) -> bool:
        """No velocity in any force (time-reversible: the cosine ansatz of ``nnm`` holds)."""
        return not any(f.has(*self.velocities) for f in self.force)

    def modes(self) -> tuple[sp.Expr, ...]:
        """The exact ``λ = ω₀²`` of each linear mode, by increasing value (``M⁻¹K``'s
        eigenvalues; each root of the characteristic polynomial's irreducible factors)."""
        lam = sp.Symbol("lambda")
        poly = sp.Poly(self.stiffness.charpoly(lam).as_expr(), lam)
        roots: list[sp.Expr] = []
        for factor, multiplicity in poly.factor_list()[1]:
            roots += _roots(factor) * multiplicity
        return tuple(sorted(roots, key=lambda r: float(sp.N(r, 30))))


def _roots(factor: sp.Poly) -> list[sp.Expr]:
    """The real roots of an irreducible factor: rationals, square roots, else ``CRootOf``."""
    if factor.degree() <= 2:
        roots = sp.roots(factor, multiple=True)
        if all(r.is_real for r in roots):
            return [sp.nsimplify(r) for r in roots]
    return [sp.CRootOf(factor, k) for k in range(factor.count_roots())]


def parse_system(text: str, values: dict[str, str] | None = None) -> System:
    """A :class:`System` from ``"x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"``:
    every name but the coordinates needs an exact value (``values``, from ``--param``)."""
    values = dict(values or {})
    parts = text.split(";") if isinstance(text, str) else [text]
    if len(parts) < 2:
        raise InputError(f"system {text!r}: one equation per coordinate, separated by ';' (a "
                         "single equation is an oscillator: lindstedt series)")
    if len(parts) > MAX_COORDINATES:
        raise InputError(f"system {text!r}: {len(parts)} equations; at most "
                         f"{MAX_COORDINATES} coordinates")
    sides = [parse_sides(p.strip(), "equation") for p in parts]
    coordinates = []
    for i, (_, _, orders, _) in enumerate(sides):
        accelerations = sorted(n for n, k in orders.items() if k == 2)
        if len(accelerations) != 1:
            raise InputError(f"system {text!r}: equation {i + 1} holds "
                             f"{len(accelerations)} accelerations; write each coordinate's "
                             "equation with its own x'' alone (a diagonal mass)")
        if accelerations[0] in coordinates:
            raise InputError(f"system {text!r}: {accelerations[0]}'' leads two equations; one "
                             "equation per coordinate")
        coordinates += accelerations
    bad = sorted({n for _, _, o, _ in sides for n in o} - set(coordinates))
    if bad:
        raise InputError(f"system {text!r}: {', '.join(bad)} has no equation of its own; each "
                         "coordinate needs its acceleration (x'') and its equation")
    exprs = [renamed(lhs - rhs, coordinates) for lhs, rhs, _, _ in sides]
    names = {n for _, _, _, ns in sides for n in ns if n.rstrip("_") not in coordinates}
    if TIME in names:
        raise InputError(f"system {text!r}: t appears explicitly; a driven system is not a "
                         "free one (nnm takes autonomous systems)")
    missing = sorted(names - set(values))
    if missing:
        raise InputError(f"system {text!r}: give {', '.join(missing)} a value with --param "
                         f"(e.g. --param {missing[0]}=1/2); a system's series are in the "
                         "amplitude A")
    given = {sp.Symbol(k): parse_expression(v, f"--param {k}") for k, v in values.items()}
    for k, v in given.items():
        if not v.is_Rational:
            raise InputError(f"--param {k}={values[str(k)]}: an exact rational, e.g. 1/3")
    unused = sorted(str(k) for k in given if str(k) not in names)
    if unused:
        raise InputError(f"--param {unused[0]}: no such name in the system")
    return _lowered(text, coordinates, [e.xreplace(given) for e in exprs])


def _lowered(text: str, coordinates: list[str], exprs: list[sp.Expr]) -> System:
    """Mass, stiffness and force of each equation, checked."""
    symbols = [derivative_symbols(c) for c in coordinates]
    x = [s[0] for s in symbols]
    v = [s[1] for s in symbols]
    a = [s[2] for s in symbols]
    mass, rows, force = [], [], []
    for i, e in enumerate(exprs):
        try:
            poly = sp.Poly(sp.expand(e), *a, *x, *v)
        except sp.PolynomialError:
            raise InputError(f"system {text!r}: equation {i + 1} is not a polynomial in the "
                             "coordinates and their derivatives") from None
        if any(not c.is_Rational for c in poly.coeffs()):
            raise InputError(f"system {text!r}: equation {i + 1} has a coefficient that is "
                             "not an exact number")
        m = poly.coeff_monomial(a[i])
        rest = sp.expand(poly.as_expr() - m * a[i])
        if rest.has(*a) or not m.is_Rational or m <= 0:
            raise InputError(f"system {text!r}: equation {i + 1}: {coordinates[i]}'' must "
                             "enter linearly with a positive constant mass")
        p = sp.Poly(rest, *x, *v)
        if p.coeff_monomial(1) != 0:
            raise InputError(f"system {text!r}: equation {i + 1} has a constant term; the "
                             "origin must be an equilibrium")
        linear = [p.coeff_monomial(s) for s in x]
        damping = [p.coeff_monomial(s) for s in v]
        if any(damping):
            raise InputError(f"system {text!r}: equation {i + 1} has a linear velocity term "
                             "(damping); nnm takes conservative systems (response and "
                             "slowflow take damped ones)")
        mass.append(m)
        rows.append([c / m for c in linear])
        force.append(sp.expand((rest - sum(c * s for c, s in zip(linear, x, strict=True))) / m))
    return System(text, tuple(x), tuple(v), tuple(mass), sp.Matrix(rows), tuple(force))
