"""Evaluation forms shared by every lowering: polynomials (Horner, Estrin in the printer),
the Chebyshev recurrence of the harmonics, AGM steps, the argument guards and the scaled
variable x = εA^k computed factor by factor."""

from __future__ import annotations

import builtins
import keyword
import re
from fractions import Fraction

import sympy as sp
from sympy.logic.boolalg import BooleanFunction

from ..errors import InputError
from .printers import Polynomial
from .records import Assign


def horner(coeffs: list[sp.Expr], x: sp.Symbol) -> sp.Expr:
    """``Σ c_j x^j`` as one :class:`printers.Polynomial` node (the printer writes Horner's form,
    Estrin's split from :data:`printers.ESTRIN_FROM` coefficients); trailing zeros dropped,
    the constant itself for one coefficient, zero for none."""
    coeffs = list(coeffs)
    while coeffs and coeffs[-1] == 0:
        coeffs.pop()
    if len(coeffs) <= 1:
        return coeffs[0] if coeffs else sp.Integer(0)
    return Polynomial(x, *coeffs)


def harmonics(top: int, odd: bool, s: sp.Expr, sines: bool) -> tuple[list[Assign], dict, dict]:
    """Assignments giving ``cos n s`` (and ``sin n s`` if ``sines``) for ``n ≤ top``.

    Returns the assignments and the maps ``{n: symbol}`` for cosines and sines.
    """
    c1, s1 = sp.Symbol("c_1"), sp.Symbol("s_1")
    lines: list[Assign] = [(c1, sp.cos(s))] + ([(s1, sp.sin(s))] if sines else [])
    cos_of: dict = {1: c1}
    sin_of: dict = {1: s1}
    step = 2 if odd else 1
    if odd:
        cos_of[-1], sin_of[-1] = c1, -s1
    else:
        cos_of[0], sin_of[0] = sp.Integer(1), sp.Integer(0)
    if top > 1:
        w = sp.Symbol(f"w_{step}")  # 2 cos(step·s)
        lines.append((w, 4 * c1**2 - 2 if odd else 2 * c1))
        tables = [(cos_of, "c")] + ([(sin_of, "s")] if sines else [])
        for n in range(1 + step, top + 1, step):
            for table, kind in tables:
                cur = sp.Symbol(f"{kind}_{n}")
                lines.append((cur, w * table[n - step] - table[n - 2 * step]))
                table[n] = cur
    return lines, cos_of, sin_of


MODULE_NAMES = frozenset({
    "math", "np", "numba", "njit", "vectorize", "overload", "types", "TRIG_LIMIT", "SIN_KERNEL",
    "COS_KERNEL", "ORDER", "MODEL", "VARIABLE", "CONVENTION", "RADIUS", "ALLOW_DIVERGENT",
    "RADIUS_SPREAD", "RADIUS_LOWER", "ORBIT_LIMIT", "ORBIT_LIMIT_EXACT", "MODE", "SYSTEM",
    "OMEGA0", "OMEGA0_EXACT", "OMEGA", "PERIOD", "Q", "OMEGA_EXACT", "PERIOD_EXACT", "omega",
    "period", "error_estimate",
})
LOCAL_NAMES = frozenset({"out", "i", "t"})
# NOTE: the names an emitted periodic-orbit module defines at its top and uses inside its
# functions (templates/module.py.j2 and :func:`lower_periodic`); `_`-names need no entry,
# since a user's names never start with '_', and lower_periodic renames its x, w, s, T away
# from a user's.
_LOCAL = re.compile(r"[csw]_\d+|.*_in|.*_into")
AMPLITUDE_NAMES = frozenset({"A", "eps", "theta0"})
# NOTE: the built-in arguments of the evaluators: a parameter of these names is the argument.


def check_emitted_names(coordinates: list[str], parameters: list[str],
                        velocities: bool = True) -> None:
    """A user's parameter or coordinate that would clash with a name of the emitted module is
    refused (a parameter named ``x`` would be overwritten by the expansion variable): each
    coordinate (and its velocity ``<name>dot`` where ``velocities``) defines a function, each
    parameter is an argument."""
    taken = MODULE_NAMES | LOCAL_NAMES | frozenset(dir(builtins)) | frozenset(keyword.kwlist)
    functions = [*coordinates, *(c + "dot" for c in coordinates if velocities)]
    for name in parameters:
        if name in AMPLITUDE_NAMES:
            continue
        if name in taken or _LOCAL.fullmatch(name) or name in functions:
            raise InputError(f"parameter {name!r}: the emitted module uses this name; rename "
                             "the parameter")
    for coordinate in coordinates:
        for name in (coordinate, *([coordinate + "dot"] if velocities else [])):
            if name in taken or _LOCAL.fullmatch(name) or name in parameters:
                raise InputError(f"coordinate {coordinate!r}: the emitted module would define "
                                 f"{name!r}, which it uses already; rename the coordinate")


def _extreme(kind: type[sp.Min] | type[sp.Max], args: list[sp.Expr]) -> sp.Expr:
    """``Min``/``Max`` of ``args``: evaluated where every one is a number, else left
    unevaluated (no symbolic comparison)."""
    return kind(*args, evaluate=all(a.is_number for a in args))


def tail_bound(t1: sp.Expr, t2: sp.Expr, order: int, x: sp.Symbol, limits: list[sp.Expr]
               ) -> sp.Expr:
    """A bound on the omitted tail ``|Σ_(j>K) τ_j x^j|`` of a series summed to order ``K``
    from ``t1 = |τ_{K+1}|``, ``t2 = |τ_{K+2}|`` and the radii ``limits`` (its radius less
    spread, an orbit edge…; their smallest is ``R``): the first omitted term, then a geometric
    tail from ``τ_{K+2}`` at the ratio ``r = max(1/R, t2/t1)``.  Ratios of a branch point's
    coefficients rise toward 1/R (log, square root) or fall toward it (a pole of order > 1):
    r bounds both.  inf from ``r|x| = 1`` on."""
    if not limits:  # no radius and no edge: the omitted terms alone
        return t1 * sp.Abs(x) ** (order + 1) + t2 * sp.Abs(x) ** (order + 2)
    # over symbolic parameters Min/Max stay unevaluated: SymPy would compare polynomials in
    # them term by term (6 s of a 10 s `generate` at order 12), and the printer emits min/max
    R = _extreme(sp.Min, limits) if len(limits) > 1 else limits[0]
    r = _extreme(sp.Max, [1 / R, t2 / t1]) if t1 != 0 else 1 / R
    c = _extreme(sp.Max, [t2, r * t1])
    ax = sp.Abs(x)
    tail = t1 * ax ** (order + 1) + c * ax ** (order + 2) / (1 - r * ax)
    return sp.Piecewise((tail, r * ax < 1), (sp.oo, True))


def _hex(c: Fraction) -> str:
    """An exact rational for the provenance hash, in hex: Python's decimal conversion refuses
    integers past 4300 digits, which a Padé of order 100 in q reaches."""
    return f"{c.numerator:x}/{c.denominator:x}"


FREE_ARGUMENT_LIMIT = sp.Float(1e300)
# NOTE: a finite argument passes (NaN and ±inf fail the comparison); t = ±inf would make
# cos(ωt) invalid, a floating-point warning from the ufunc, before the guard.


def free_ranges(y: sp.Expr, params: tuple[sp.Symbol, ...]
                ) -> tuple[tuple[sp.Symbol, sp.Basic, object], ...]:
    """:func:`argument_entry`'s ranges for a free oscillator's parameters: each at most
    ``10^(300/d)`` in magnitude, ``d`` the total degree of the expansion variable ``y`` in them
    (ε A² → 1e100), so ``y`` cannot overflow before the guard; the stand-in is 1/10 for each."""
    try:
        degree = max(sp.Poly(y, *params).total_degree(), 1)
    except sp.PolynomialError:
        degree = 6
    bound = sp.Float(10.0 ** (300 // degree))
    return tuple((p, sp.Abs(p) <= bound, sp.Rational(1, 10)) for p in params)


SCALED_CLAMP = sp.Float(1e8)
# NOTE: a partial product of the expansion variable held at ±1e8 before it grows by a factor
# |a| > 1 (|a| ≤ 1e300): at most 1e308, finite; and beyond 1e8 it is out of every orbit domain.


def scaled_variable(y: sp.Expr, params: tuple[sp.Symbol, ...], x: sp.Symbol
                    ) -> tuple[tuple[Assign, ...], tuple[tuple[sp.Symbol, sp.Basic, object], ...]
                               ] | None:
    """``x = y`` for ``y = c·p·a^k`` (ε A², ε A⁴…), computed factor by factor from ``p``: each
    partial product ``p·a^i`` lies between ``|p|`` and ``|y|``, so an in-domain ``y`` is exact
    however extreme ``p`` and ``a`` are (ε = 1e300, A = 1e-200; A = 1e200, ε = 0) and only an
    out-of-domain one is clamped (:data:`SCALED_CLAMP`).  Returns the steps and
    :func:`argument_entry`'s ranges (``p`` any finite number, ``|a| ≤ 1e300``), or None for
    another form of ``y`` (then :func:`free_ranges` bounds each parameter)."""
    c, factors = y.as_coeff_Mul()
    powers: dict[sp.Symbol, int] = {}
    for f in sp.Mul.make_args(factors):
        base, e = f.as_base_exp()
        if base not in params or not e.is_Integer or e < 1:
            return None
        powers[base] = int(e)
    if len(powers) != 2 or 1 not in powers.values() or not c.is_Rational or c == 0:
        return None
    first = next(b for b, e in powers.items() if e == 1)
    other, k = next((b, e) for b, e in powers.items() if b is not first)
    clamped = sp.Min(sp.Max(x, -SCALED_CLAMP), SCALED_CLAMP) * other
    steps = [(x, first)] + [(x, sp.Piecewise((clamped, sp.Abs(other) > 1), (x * other, True)))
                            for _ in range(k)]
    if c != 1:
        steps.append((x, c * x))
    ranges = tuple((p, sp.true if p is first else sp.Abs(p) <= FREE_ARGUMENT_LIMIT,
                    sp.Rational(1, 10)) for p in params)
    return tuple(steps), ranges


def argument_entry(arguments: tuple[tuple[sp.Symbol, sp.Basic, object], ...],
                   flag: str = "inside", infinite: tuple[sp.Symbol, ...] = ()
                   ) -> tuple[list[Assign], sp.Basic]:
    """Assignments that replace every argument by its stand-in unless every argument is finite
    and meets its condition, and the condition the guard adds (a flag ``inside``, 1 or 0):
    outside, the evaluator computes at the stand-in point, where every step is finite, and
    returns NaN — no floating-point flag is raised on the way.

    Two passes: :class:`Finite` first (:class:`NotNaN` for the arguments ``infinite`` allows
    at ±inf), quiet tests, so that the conditions' ordered comparisons see no NaN — LLVM may
    compile them branch-free to a signalling compare, which raises "invalid" for NaN even where
    a branch would have skipped it.  ``tests/test_emitted_safety.py`` checks every emitted
    family for warnings: the code LLVM makes of a guard is not otherwise predictable."""
    flag = sp.Symbol(flag)
    steps: list[Assign] = []
    for inside in (sp.And(*((NotNaN if v in infinite else Finite)(v) for v, _, _ in arguments)),
                   sp.And(*(cond for _, cond, _ in arguments))):
        if steps:
            inside = sp.And(sp.Eq(flag, 1), inside)
        steps.append((flag, sp.Piecewise((sp.Integer(1), inside), (sp.Integer(0), True))))
        for v, _, safe in arguments:
            steps.append((v, sp.Piecewise((v, sp.Eq(flag, 1)), (safe, True))))
    return steps, sp.Eq(flag, 1)


class Finite(BooleanFunction):
    """True for a finite number; printed as a quiet test (numba's ``math.isfinite`` computes
    x − x, which raises "invalid" at ±inf)."""

    nargs = 1

    @classmethod
    def eval(cls, arg: sp.Expr) -> sp.Basic | None:
        """``true`` for a finite number, ``false`` for ±inf or NaN; ``None`` (left unevaluated)
        for a symbolic argument."""
        if arg.is_number:
            return sp.true if arg.is_finite else sp.false
        return None


class NotNaN(BooleanFunction):
    """True for a number that is not NaN (±inf included); printed as a quiet test (no
    "invalid", unlike an ordered comparison with NaN)."""

    nargs = 1

    @classmethod
    def eval(cls, arg: sp.Expr) -> sp.Basic | None:
        """``false`` for NaN, ``true`` for any other number (±inf included); ``None`` (left
        unevaluated) for a symbolic argument."""
        if arg.is_number:
            return sp.false if arg is sp.nan else sp.true
        return None


def nested_horner(expr: sp.Expr, gens: tuple[sp.Symbol, ...]) -> sp.Expr:
    """A polynomial in ``gens`` as Horner's rule in the first, each coefficient in the rest."""
    if not gens:
        return expr
    poly = sp.Poly(expr, gens[0])
    acc = sp.Integer(0)
    for c in poly.all_coeffs():
        acc = acc * gens[0] + nested_horner(sp.expand(c), gens[1:])
    return acc


def agm_steps(a: sp.Expr, b: sp.Expr, steps: int, prefix: str) -> tuple[list[Assign], sp.Expr]:
    """``steps`` steps of the arithmetic–geometric mean as assignments, and ``(a + b)/2``
    after them (a converged AGM stays put, so a fixed count serves every argument)."""
    a0, b0 = sp.symbols(f"{prefix}a0 {prefix}b0")
    lines: list[Assign] = [(a0, a), (b0, b)]
    a, b = a0, b0
    for n in range(1, steps + 1):
        an, bn = sp.symbols(f"{prefix}a{n} {prefix}b{n}")
        lines += [(an, (a + b) / 2), (bn, sp.sqrt(a * b))]
        a, b = an, bn
    return lines, (a + b) / 2
