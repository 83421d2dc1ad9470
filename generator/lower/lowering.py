"""Lowering: derived solutions -> IR records a template can lay out (no code strings here).

An :class:`Evaluator` is one numba ufunc: a prelude (what its domain guard needs), the guard
(outside it the ufunc returns NaN), the body and one output.  Polynomials are in Horner
form; all harmonics of ``cos n s`` / ``sin n s`` come from one ``cos``/``sin`` pair by the
Chebyshev recurrence ``c_{n+2} = 2cos(2s)·c_n - c_{n-2}`` (odd harmonics) or
``c_{n+1} = 2cos(s)·c_n - c_{n-1}`` (all harmonics).
"""

from __future__ import annotations

import builtins
import hashlib
import json
import keyword
import math
import re
import unicodedata
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction

import sympy as sp
from sympy.logic.boolalg import BooleanFunction

from .. import __version__
from ..algebra.resum import Pade, Resummed
from ..analysis.driven import (
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
from ..analysis.driven import x_ as damped_x
from ..derive.averaging import PHI as PHI_SLOW
from ..derive.averaging import R as R_SLOW
from ..derive.averaging import SlowFlow
from ..derive.averaging import U as U_SLOW
from ..derive.averaging import V as V_SLOW
from ..derive.lindstedt import (
    LimitCycle,
    SeriesSolution,
    estimated_radius,
    nearest_singularity,
    order_terms,
)
from ..derive.models import Model
from ..derive.orbits import OrbitDomain, orbit_domain
from ..errors import InputError
from ..lower.printers import identifier
from ..numerics.integrate import mathieu_recurrence

Assign = tuple[sp.Symbol, sp.Expr]


def _unsafe(ch: str) -> bool:
    """Control, format, surrogate, private or unassigned, line or paragraph separator."""
    category = unicodedata.category(ch)
    return category[0] == "C" or category in ("Zl", "Zp")


def one_line(text: str) -> str:
    """``text`` as data on one line of a generated file: every character that could end a
    comment line or hide text (newline, other controls, separators) becomes a visible escape.

    >>> one_line("lindstedt generate\\nimport os")
    'lindstedt generate\\\\nimport os'
    """
    return "".join(ch.encode("unicode_escape").decode("ascii") if _unsafe(ch) else ch
                   for ch in str(text))


def docstring_text(text: str) -> str:
    """``text`` as data inside a generated ``\"\"\"`` docstring: backslashes and quotes
    escaped (no quote can close it), lines kept, other unsafe characters escaped."""
    text = str(text).replace("\\", "\\\\").replace('"', '\\"')
    return "\n".join(one_line(line) for line in text.split("\n"))


@dataclass(frozen=True)
class Evaluator:
    """Everything needed to emit one numba ufunc."""

    name: str
    doc: str
    args: tuple[sp.Symbol, ...]
    prelude: tuple[Assign, ...]
    guard: sp.Basic  # SymPy boolean; false -> NaN
    body: tuple[Assign, ...]
    output: sp.Expr

    def __post_init__(self) -> None:
        object.__setattr__(self, "doc", docstring_text(self.doc))


@dataclass(frozen=True)
class ArrayKernel:
    """One numba ``@njit`` function returning an array: ``x`` unpacked into named symbols,
    shared subexpressions, then ``out[index] = value`` entries."""

    name: str
    doc: str
    unpack: tuple[sp.Symbol, ...]  # x[0], x[1], … bound to these names
    args: tuple[sp.Symbol, ...]  # scalar arguments after x
    shape: tuple[int, ...]
    subexprs: tuple[Assign, ...]
    entries: tuple[tuple[tuple[int, ...], sp.Expr], ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "doc", docstring_text(self.doc))


@dataclass(frozen=True)
class Provenance:
    """What a generated file says about where it came from (no timestamp: reproducible)."""

    model: str
    order: int
    command: str
    inputs: str  # sha256 of the canonical description of the inputs

    def __post_init__(self) -> None:
        # NOTE: the command is the caller's text: it reaches the banner only as one line of data.
        object.__setattr__(self, "command", one_line(self.command))

    @property
    def version(self) -> str:
        return __version__


@dataclass(frozen=True)
class Module:
    """One generated Python module: constants and evaluators."""

    name: str
    doc: str
    constants: tuple[tuple[str, object], ...]  # name -> int, float, str or tuple of them
    evaluators: tuple[Evaluator, ...]
    provenance: Provenance
    kernels: tuple[ArrayKernel, ...] = ()
    newton: bool = False  # emit newton(x0, …) driving the kernels "residual" and "jacobian"

    def __post_init__(self) -> None:
        object.__setattr__(self, "doc", docstring_text(self.doc))


def provenance(model: str, order: int, command: str, **inputs: object) -> Provenance:
    """Provenance with a hash over the canonical JSON of every input that shapes the output."""
    payload = json.dumps(
        {"version": __version__, "model": model, "order": order, **inputs},
        sort_keys=True, default=str,
    )
    return Provenance(model, order, command, hashlib.sha256(payload.encode()).hexdigest())


ESTRIN_FROM = 8
# NOTE: polynomials of this many coefficients or more are split by Estrin's scheme (Knuth,
# TAOCP 2, §4.6.4): Horner's chain of n dependent multiply-adds runs at the FPU's latency in
# the ufuncs, which numba calls point by point; the split chain is ~2 log2 n long.  Degree 43
# as a scalar ufunc: 29 ns per point by Horner, 8 ns split (the `_into` loops, vectorised
# across points, hide the latency either way).


def horner(coeffs: list[sp.Expr], x: sp.Symbol) -> sp.Expr:
    """``Σ c_j x^j``: Horner's form (``sympy.horner``) below :data:`ESTRIN_FROM`
    coefficients, above it ``L(x) + x^m H(x)`` with ``m`` the largest power of two below
    the length, each half split again; zero for no coefficients."""
    if len(coeffs) >= ESTRIN_FROM:
        m = 1 << ((len(coeffs) - 1).bit_length() - 1)
        high = horner(coeffs[m:], x)
        return horner(coeffs[:m], x) + x**m * high if high != 0 else horner(coeffs[:m], x)
    poly = sum((c * x**j for j, c in enumerate(coeffs)), sp.Integer(0))
    return sp.horner(poly, x) if poly.has(x) else poly


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
    "RADIUS_SPREAD", "ORBIT_LIMIT", "ORBIT_LIMIT_EXACT",
    "OMEGA", "PERIOD", "Q", "OMEGA_EXACT", "PERIOD_EXACT", "omega", "period", "error_estimate",
})
LOCAL_NAMES = frozenset({"out", "i", "t"})
# NOTE: the names an emitted free module defines at its top and uses inside its functions
# (templates/module.py.j2 and :func:`lower_free`); `_`-names need no entry, since a user's
# names never start with '_', and lower_free renames its x, w, s, T away from a user's.
_LOCAL = re.compile(r"[csw]_\d+|.*_in|.*_into")


def check_emitted_names(model: Model) -> None:
    """A user's parameter or coordinate that would clash with a name of the emitted module is
    refused (a parameter named ``x`` would be overwritten by the expansion variable)."""
    coordinate = str(model.coordinate)
    taken = MODULE_NAMES | LOCAL_NAMES | frozenset(dir(builtins)) | frozenset(keyword.kwlist)
    for name, _ in model.parameters:
        if name in ("A", "eps", "theta0"):
            continue
        if name in taken or _LOCAL.fullmatch(name) or name in (coordinate,
                                                                coordinate + "dot"):
            raise InputError(f"parameter {name!r}: the emitted module uses this name; rename "
                             "the parameter")
    for name in (coordinate, coordinate + "dot"):
        if name in taken or _LOCAL.fullmatch(name):
            raise InputError(f"coordinate {coordinate!r}: the emitted module would define "
                             f"{name!r}, which it uses already; rename the coordinate")


def _truncation_bound(solution: SeriesSolution, order: int, x: sp.Symbol,
                      reach: sp.Expr | None, domain: OrbitDomain) -> sp.Expr:
    """A bound on ``|Σ_(j>K) τ_j y^j|`` (in units of 2π/ω₀): the first omitted term, then a
    geometric tail from ``τ_{K+2}`` at the ratio ``r = max(1/R, |τ_{K+2}/τ_{K+1}|)``, ``R``
    the smaller of ``reach`` (radius less spread) and the distance to the orbits' edge — a
    singularity of T, where the period diverges.  Ratios of a branch point's coefficients
    rise toward 1/R (log, square root) or fall toward it (a pole of order > 1): r bounds both.
    inf from ``r|y| = 1`` on."""
    g, w0 = solution.ground, solution.model.frequency
    t1 = sp.Abs(g.to_sympy(solution.period[order + 1]) / w0)
    t2 = sp.Abs(g.to_sympy(solution.period[order + 2]) / w0)
    edges = [sp.Float(v, 17) for v in (-domain.lower, domain.upper) if math.isfinite(v)]
    limits = [e for e in ([reach] if reach is not None else []) + edges]
    if not limits:  # no radius and no edge: the omitted terms alone
        return t1 * sp.Abs(x) ** (order + 1) + t2 * sp.Abs(x) ** (order + 2)
    R = sp.Min(*limits) if len(limits) > 1 else limits[0]
    r = sp.Max(1 / R, t2 / t1) if t1 != 0 else 1 / R
    c = sp.Max(t2, r * t1)
    ax = sp.Abs(x)
    tail = t1 * ax ** (order + 1) + c * ax ** (order + 2) / (1 - r * ax)
    return sp.Piecewise((tail, r * ax < 1), (sp.oo, True))


def lower_free(solution: SeriesSolution, command: str, allow_divergent: bool = False) -> Module:
    """Evaluators ω, T, q, q̇ and the truncation-error estimate of a free oscillator.

    ``solution`` must be derived two orders above the emitted order K: ``τ_{K+1}`` feeds
    :func:`error_estimate`.  Outside the orbit condition the ufuncs return NaN, and beyond
    the radius of convergence too unless ``allow_divergent``.
    """
    m = solution.model
    order = solution.order - 2
    if order < 0:
        raise ValueError("lower_free needs a solution derived to order K + 2")
    check_emitted_names(m)
    g = solution.ground
    args = {name: sp.Symbol(identifier(name)) for name, _ in m.parameters}
    to_args = {sym: args[name] for name, sym in m.parameters}
    user = {str(m.coordinate), str(m.coordinate) + "dot", *args}
    # a user's name keeps its meaning: an internal name it would shadow takes a leading '_'
    # (which no user name has); the built-in models keep x, w, s, T, byte for byte
    x, w, s, total = (sp.Symbol(n if n not in user else "_" + n) for n in ("x", "w", "s", "T"))
    y = m.y.xreplace(to_args)
    amplitude = m.amplitude.xreplace(to_args)
    # ω₀ = 1 but for a user's linear frequency: ω = ω₀ Σ ω_j y^j, T = (2π/ω₀) Σ τ_j y^j
    omega = [m.frequency * g.to_sympy(c) for c in solution.omega[: order + 1]]
    tau = [g.to_sympy(c) / m.frequency for c in solution.period[: order + 1]]
    params = tuple(args.values())
    t = sp.Symbol("t")
    guard = m.orbit_condition.xreplace({sp.Symbol("Y"): x})
    domain = orbit_domain(m)
    lo, hi = domain.guard_bounds()
    if math.isfinite(lo):
        guard = sp.And(guard, x > sp.Float(lo, 17))
    if math.isfinite(hi):
        guard = sp.And(guard, x < sp.Float(hi, 17))
    found = (m.radius, 0.0) if m.radius is not None else estimated_radius(solution, to_args)
    radius, spread = found if found is not None else (None, 0.0)
    reach = None if radius is None else radius - sp.Float(spread, 17) if spread else radius
    if reach is not None and not allow_divergent:
        guard = sp.And(guard, sp.Abs(x) < reach)
    scaled = scaled_variable(y, params, x)
    steps, ranges = scaled if scaled is not None else (((x, y),), free_ranges(y, params))
    flag = "inside" if "inside" not in user else "_inside"
    entry, inside = argument_entry(ranges, flag)
    prelude, guard_t = (*entry, *steps), guard
    guard = sp.And(inside, guard)
    entry, inside = argument_entry((*ranges, (t, sp.Abs(t) <= FREE_ARGUMENT_LIMIT, 0)), flag)
    prelude_t, guard_t = (*entry, *steps), sp.And(inside, guard_t)

    top = max((max(qj) for qj in solution.q[: order + 1] if qj), default=1)
    harmonic = {
        n: horner([g.to_sympy(solution.q[j].get(n, g.scalar(0))) for j in range(order + 1)], x)
        for n in range(top + 1)
    }
    harmonic = {n: h for n, h in harmonic.items() if h != 0}
    cos_lines, cs, _ = harmonics(top, m.odd, s, sines=False)
    both_lines, _, ss = harmonics(top, m.odd, s, sines=True)
    name_of = identifier(str(m.coordinate))
    where = ("NaN where no periodic orbit exists" if domain.known else
             f"NaN where no periodic orbit exists as far as known: no orbit domain ({domain.how})")
    where += ("" if allow_divergent or radius is None else
              " or beyond the radius of convergence"
              + ("" if m.radius is not None else " less its spread, estimated from its τ_j"))
    estimate = _truncation_bound(solution, order, x, reach, domain) / sp.Abs(total)
    evaluators = (
        Evaluator("omega", f"Frequency ω to order {order} ({where}).", params, prelude, guard,
                  (), horner(omega, x)),
        Evaluator("period", f"Period T = 2π Σ τ_j y^j to order {order} ({where}).", params,
                  prelude, guard, (), 2 * sp.pi * horner(tau, x)),
        Evaluator(
            name_of,
            f"{name_of}(t) with s = ωt, harmonics by the Chebyshev recurrence ({where}).",
            (t, *params), prelude_t, guard_t,
            ((w, horner(omega, x)), (s, w * t), *cos_lines),
            amplitude * sum(h * cs[n] for n, h in sorted(harmonic.items())),
        ),
        Evaluator(
            f"{name_of}dot", f"d{name_of}/dt ({where}).", (t, *params), prelude_t, guard_t,
            ((w, horner(omega, x)), (s, w * t), *both_lines),
            -amplitude * w * sum(n * h * ss[n] for n, h in sorted(harmonic.items())),
        ),
        Evaluator(
            "error_estimate",
            "Relative truncation error of period(), a bound on the omitted tail: "
            "|τ_{K+1}| |y|^(K+1) + c |y|^(K+2) / (1 - r|y|), its terms growing at most by "
            "r = max(1/R, |τ_{K+2}/τ_{K+1}|) an order, R the smaller of the radius less its "
            "spread and the distance to the orbits' edge, c = max(|τ_{K+2}|, r|τ_{K+1}|); "
            "over the truncated sum (inf from r|y| = 1 on: no bound there).",
            params, prelude, guard, ((total, horner(tau, x)),), estimate,
        ),
    )
    numeric = ()  # the coefficients as floats, where they are numbers (no symbolic parameter)
    if g.is_rational:
        Q = tuple(
            tuple(float(g.to_sympy(solution.q[j].get(n, g.scalar(0)))) for n in range(top + 1))
            for j in range(order + 1)
        )
        numeric = (("OMEGA", tuple(float(c) for c in omega)),
                   ("PERIOD", tuple(float(c) for c in tau)), ("Q", Q))
    constants = (
        ("ORDER", order),
        ("MODEL", m.name),
        ("VARIABLE", m.variable),
        ("CONVENTION", solution.convention),
        ("RADIUS", float(radius) if radius is not None and radius.is_number
         else float("nan")),
        ("RADIUS_SPREAD", float(spread)),
        ("ORBIT_LIMIT", (domain.lower, domain.upper)),
        ("ORBIT_LIMIT_EXACT", (domain.lower_text, domain.upper_text)),
        ("ALLOW_DIVERGENT", allow_divergent),
        *numeric,
        ("OMEGA_EXACT", tuple(str(c) for c in omega)),
        ("PERIOD_EXACT", tuple(str(c) for c in tau)),
    )
    return Module(
        name=m.name,
        doc=f"{m.title}: L–P evaluators to order {order} in {m.variable}.",
        constants=constants,
        evaluators=evaluators,
        provenance=provenance(
            m.name, order, command, allow_divergent=allow_divergent,
            forcing=[[(n, str(c)) for n, c in terms] for terms in m.forcing[: order + 2]],
            **({"elementary": [(n, str(a), str(w)) for n, a, w in m.elementary]}
               if m.elementary else {}),
            **({"equation": m.source, "frequency": str(m.frequency), "given": m.given,
                "velocity_forcing": [[(a, b, str(c)) for a, b, c in terms]
                                     for terms in m.velocity_forcing[: order + 2]]}
               if m.source else {}),
        ),
    )


LIMIT_CYCLE_MARGIN = sp.Rational(9, 10)
# NOTE: the emitted limit-cycle series answer NaN from 90 % of the estimated radius on (in ε):
# the estimate is good to ~1 % from order 60, and near the radius the terms decay slowly.


CUBE_ROOT_STEPS = 2
CUBE_ROOT_START = (sp.Rational("0.338153"), sp.Rational("2.00238"), sp.Rational("1.35592"))
# NOTE: (1 − w)^(1/3) of the relaxation form: y = 1 − w scaled by 8^k into [1/8, 1] (selects,
# k ≤ 3: y ≥ 1/4096, |eps| ≲ 50), the start (a + b y)/(1 + c y) (minimax, 0.65 % on [1/8, 1]),
# then Halley's iteration, cubic: 2e-7 after one step, 4.4e-16 (numpy's cbrt) after two.
# `**(1/3)` calls libm's pow, which kept the order-60 loop from vectorizing (85 against 20 ns
# per point); five steps from 0.29 + 0.71 y, the former start, were a chain of five divisions.


LOG_TERMS = 16
# NOTE: ln s of the relaxation form as 4·2 atanh(u) of s^(1/4), |u| ≤ 0.28 for 1 − w ≥ 1e-3
# (with the cube root's range): 16 terms of the odd series leave < 1e-17 relative, and the
# loop vectorizes (math.log, a libm call, kept it scalar: 27.5 against 13 ns per point).


def resummed_expression(r: Resummed, z: sp.Symbol, approximant: Pade | None = None
                        ) -> tuple[tuple[Assign, ...], sp.Expr]:
    """The body and output of a :class:`resum.Resummed` at ``z``: ``x = z**power``, Andersen
    & Geer's ``w`` when the form has one, numerator and denominator in Horner form (exact
    rationals: the printer rounds each once)."""
    P = approximant or r.approximant
    x = sp.Symbol("x")
    body: list[Assign] = [(x, z**r.power)]

    def rational(c: Fraction) -> sp.Rational:
        return sp.Rational(c.numerator, c.denominator)

    if r.R is None:
        return tuple(body), (horner([rational(c) for c in P.numerator], x)
                             / horner([rational(c) for c in P.denominator], x))
    w = sp.Symbol("w")
    body.append((w, x / sp.sqrt(x**2 - 2 * rational(r.p) * x + rational(r.R) ** 2)))
    if r.log is None:
        ratio = horner([rational(c) for c in P.numerator], w) / horner(
            [rational(c) for c in P.denominator], w)
        return tuple(body), sp.sqrt((1 - w) * ratio)
    y, y8, scale, s, v, tail = sp.symbols("y y8 scale s v tail")
    a, b, c = CUBE_ROOT_START

    def by_range(value: Callable[[int], sp.Rational]) -> sp.Piecewise:
        return sp.Piecewise(*((value(k), y < sp.Rational(1, 8**k)) for k in (3, 2, 1)),
                            (sp.Float(1.0), True))

    body += [(y, 1 - w), (scale, by_range(lambda k: sp.Rational(1, 2**k))),
             (y8, y * by_range(lambda k: sp.Integer(8**k))), (s, (a + b * y8) / (1 + c * y8))]
    for _ in range(CUBE_ROOT_STEPS):  # Halley on s³ = y8: no libm call, so the loop vectorizes
        body.append((s, s * (s**3 + 2 * y8) / (2 * s**3 + y8)))
    body.append((s, s * scale))
    half, quarter, u, u2 = sp.symbols("half quarter u u2")
    series = horner([sp.Rational(1, 2 * k + 1) for k in range(LOG_TERMS)], u2)
    body += [(v, w / (1 + s + s**2)),  # v = 1 − s, without the cancellation near w = 0
             # s³ ln s = y·4 ln s^(1/4) = 8y·atanh(u), u = (s^(1/4) − 1)/(s^(1/4) + 1)
             (half, sp.sqrt(s)), (quarter, sp.sqrt(half)), (u, (quarter - 1) / (quarter + 1)),
             (u2, u**2), (tail, 8 * y * u * series)]
    ratio = horner([rational(c) for c in P.numerator], v) / horner(
        [rational(c) for c in P.denominator], v)
    return tuple(body), sp.sqrt((1 - w) * (ratio + rational(r.log) * tail))


@dataclass(frozen=True)
class ResummedCycle:
    """A limit cycle's resummed frequency and where it was verified: ``|ε| ≤ limit``, with
    the largest measured error ``checked`` against the numerical references at ``points``;
    the same for its amplitude q(0) when its Padé form verified anywhere."""

    form: Resummed
    limit: float
    points: tuple[float, ...]
    checked: float
    tolerance: float
    amplitude: Resummed | None = None  # q(0), Padé in ε², with its (limit, points, checked)
    amplitude_verified: tuple[float, tuple[float, ...], float] = (0.0, (), float("nan"))
    harmonics: tuple[tuple[str, int, Resummed], ...] = ()  # q(s): ("cos"|"sin", n, a_n(ε))
    harmonics_verified: tuple[float, tuple[float, ...], float] = (0.0, (), float("nan"))


def lower_resummed_cycle(r: ResummedCycle) -> tuple[Evaluator, ...]:
    """``omega_resummed(eps)``, ``period_resummed(eps)`` and ``resummed_error(eps)`` (the
    relative difference of the neighbouring approximants), NaN beyond the verified |ε|."""
    eps = sp.Symbol("eps")
    guard = sp.Abs(eps) <= sp.Rational(repr(r.limit))
    body, value = resummed_expression(r.form, eps)
    _, other = resummed_expression(r.form, eps, r.form.neighbour)
    omega, lower = sp.Symbol("omega"), sp.Symbol("omega_lower")
    L, M = r.form.approximant.degrees
    domain = (f"NaN for |eps| > {r.limit:g}, where it was not verified to "
              f"{r.tolerance:g} against shooting")
    form = (f"sqrt((1 - w) [{L}/{M}](w)), w = eps²/(eps⁴ - 2 eps² p + R²)^(1/2), R = {r.form.R}"
            f", p = R cos β = {r.form.p}")
    if r.form.log is not None:
        form = (f"sqrt((1 - w) ([{L}/{M}](v) + λ s³ ln s)), s = (1 - w)^(1/3) = 1 - v, "
                f"λ = {float(r.form.log)!r}, two-point Padé (the series and the relaxation "
                f"limit), w = eps²/(eps⁴ - 2 eps² p + R²)^(1/2), R = {r.form.R}, "
                f"p = R cos β = {r.form.p}")
    return (
        Evaluator("omega_resummed", f"Frequency ω resummed: {form} ({domain}).", (eps,), (),
                  guard, body, value),
        Evaluator("period_resummed", f"Period 2π/ω of omega_resummed ({domain}).", (eps,), (),
                  guard, (*body, (omega, value)), 2 * sp.pi / omega),
        Evaluator("resummed_error", "Relative difference of omega_resummed and the next "
                  f"lower approximant [{L - 1}/{M - 1}] (an error estimate; {domain}).",
                  (eps,), (), guard, (*body, (omega, value), (lower, other)),
                  sp.Abs(lower - omega) / omega),
        *_lower_resummed_amplitude(r),
        *_lower_resummed_q(r),
    )


def _lower_resummed_q(r: ResummedCycle) -> tuple[Evaluator, ...]:
    """``q_resummed(t, eps)``: each harmonic's Padé in ``w`` times cos ns or sin ns with
    ``s = omega_resummed(eps)·t``, NaN beyond the harmonics' own verified |ε|."""
    if not r.harmonics:
        return ()
    eps, t, phase, w = sp.symbols("eps t phase w")
    body, omega = resummed_expression(r.form, eps)
    top = max(n for _, n, _ in r.harmonics)
    lines, cs, ss = harmonics(top, False, phase, sines=True)

    def rational(c: Fraction) -> sp.Rational:
        return sp.Rational(c.numerator, c.denominator)

    value = sp.Integer(0)
    for kind, n, form in r.harmonics:
        P = form.approximant
        a_n = horner([rational(c) for c in P.numerator], w) / horner(
            [rational(c) for c in P.denominator], w)
        value += (eps * a_n if form.odd else a_n) * (cs[n] if kind == "cos" else ss[n])
    limit, _, worst = r.harmonics_verified
    entry, guard = argument_entry(((eps, sp.Abs(eps) <= sp.Float(limit), 0),
                                   (t, sp.Abs(t) <= FREE_ARGUMENT_LIMIT, 0)))
    return (Evaluator(
        "q_resummed", f"q(t) on the cycle (q'(0) = 0), {len(r.harmonics)} Fourier coefficients "
        f"each Padé in w, s = omega_resummed(eps)·t (NaN for |eps| > {limit:g}; "
        f"{worst:.1e} of max |q| at its checks over one period).", (t, eps), tuple(entry),
        guard, (*body, (phase, omega * t), *lines), value),)


def _lower_resummed_amplitude(r: ResummedCycle) -> tuple[Evaluator, ...]:
    """``amplitude_resummed(eps)``: q(0) as the Padé form in ε², NaN beyond its own verified
    |ε| (none without a verified form)."""
    if r.amplitude is None:
        return ()
    eps = sp.Symbol("eps")
    limit, _, _ = r.amplitude_verified
    body, value = resummed_expression(r.amplitude, eps)
    L, M = r.amplitude.approximant.degrees
    return (Evaluator(
        "amplitude_resummed", f"q(0) at q̇(0) = 0, Padé [{L}/{M}] in eps² (NaN for |eps| > "
        f"{limit:g}, where it was not verified to {r.tolerance:g} against shooting).", (eps,),
        (), sp.Abs(eps) <= sp.Rational(repr(limit)), body, value),)


@dataclass(frozen=True)
class ResummedMathieu:
    """Mathieu's ``a_m(q)`` or ``b_m(q)``: the Padé of its exact series to ``order`` as the
    start of ``steps`` Newton steps on the determinant of the recurrence truncated to ``rows``
    rows, and where it was verified against the high-precision reference: ``0 ≤ q ≤ limit``
    (``|q|`` when the series is even in q), the largest error ``checked`` there, relative to
    max(1, |a|)."""

    kind: str
    m: int
    order: int
    form: Resummed
    limit: float
    tolerance: float
    checked: float
    rows: int
    steps: int


def mathieu_newton_steps(kind: str, m: int, q: sp.Symbol, start: sp.Expr, rows: int,
                         steps: int) -> tuple[tuple[Assign, ...], sp.Expr, sp.Expr]:
    """The body, value and last correction of ``steps`` Newton steps on ``det(T_rows − a)``
    from ``start``, unrolled: the leading minors ``p_j`` (rows 0…k, ``k = rows // 2``) and
    trailing ones ``s_j`` (rows j…rows−1) with their a-derivatives, two independent chains
    (:func:`numerics.mathieu_newton`, the same recurrences, which the verification runs)."""
    _, diag, couplings = mathieu_recurrence(kind, m, rows)
    qq = sp.Symbol("qq")
    a = sp.Symbol("a_0")
    body: list[Assign] = [(qq, q**2), (a, start)]
    step = sp.Integer(0)
    k = rows // 2

    def c(j: int) -> sp.Expr:
        return sp.Integer(diag[j][0]) + diag[j][1] * q - a

    for n in range(1, steps + 1):
        p_prev, dp_prev, p, dp = sp.Integer(1), sp.Integer(0), c(0), sp.Integer(-1)
        s_next, ds_next, s, ds = sp.Integer(1), sp.Integer(0), c(rows - 1), sp.Integer(-1)
        forward = list(range(1, k + 1))
        backward = list(range(rows - 2, k, -1))
        for i in range(max(len(forward), len(backward))):  # the two chains interleaved
            if i < len(forward):
                j = forward[i]
                pj, dpj = sp.symbols(f"p{n}_{j} dp{n}_{j}")
                e2 = couplings[j - 1] * qq
                body += [(pj, c(j) * p - e2 * p_prev), (dpj, c(j) * dp - p - e2 * dp_prev)]
                p, p_prev, dp, dp_prev = pj, p, dpj, dp
            if i < len(backward):
                j = backward[i]
                sj, dsj = sp.symbols(f"s{n}_{j} ds{n}_{j}")
                e2 = couplings[j] * qq
                body += [(sj, c(j) * s - e2 * s_next), (dsj, c(j) * ds - s - e2 * ds_next)]
                s, s_next, ds, ds_next = sj, s, dsj, ds
        e2 = couplings[k] * qq
        det, ddet = sp.symbols(f"det_{n} ddet_{n}")
        step, a_next = sp.Symbol(f"step_{n}"), sp.Symbol(f"a_{n}")
        body += [(det, p * s - e2 * p_prev * s_next),
                 (ddet, dp * s + p * ds - e2 * (dp_prev * s_next + p_prev * ds_next)),
                 (step, det / ddet), (a_next, a - step)]
        a = a_next
    return tuple(body), a, step


def lower_mathieu(r: ResummedMathieu, command: str) -> Module:
    """``{kind}{m}(q)`` (say ``a0``): the Padé value refined by Newton on the recurrence's
    determinant, and ``{kind}{m}_error(q)`` (the relative size of the last Newton step, the
    error of the value it corrects), NaN outside the verified q."""
    q = sp.Symbol("q")
    name = f"{r.kind}{r.m}"
    bound = sp.Rational(repr(r.limit))
    guard = sp.Abs(q) <= bound if r.form.power == 2 else sp.And(q >= 0, q <= bound)
    pade, start = resummed_expression(r.form, q)
    newton, value, step = mathieu_newton_steps(r.kind, r.m, q, start, r.rows, r.steps)
    body = (*pade, *newton)
    L, M = r.form.approximant.degrees
    var = "q²" if r.form.power == 2 else "q"
    domain = (f"NaN outside {'|q|' if r.form.power == 2 else '0 ≤ q'} ≤ {r.limit:g}, where "
              f"it was verified to {r.tolerance:g}·max(1, |{name}|) against the eigenvalues "
              "of the recurrence's matrix at 30 digits")
    method = (f"Padé [{L}/{M}] in {var} of the exact series (of the Padé of its truncations "
              f"to order ≤ {r.order}, the one of fewest degrees verified as far), then "
              f"{r.steps} Newton step(s) on the determinant of the recurrence's {r.rows} rows")
    evaluators = (
        Evaluator(name, f"Mathieu's {r.kind}_{r.m}(q) (DLMF 28.2): {method} ({domain}).",
                  (q,), (), guard, body, value),
        Evaluator(f"{name}_error", f"|last Newton step| / max(1, |{name}|): the error of the "
                  f"value the step corrects, an upper estimate ({domain}).", (q,), (), guard,
                  body, sp.Abs(step) / sp.Max(1, sp.Abs(value))),
    )
    constants = (
        ("ORDER", r.order), ("MODEL", f"mathieu_{name}"), ("VARIABLE", "q"),
        ("LIMIT", r.limit), ("TOLERANCE", r.tolerance), ("CHECKED_ERROR", r.checked),
        ("DEGREES", (L, M)), ("SYMMETRIC", r.form.power == 2), ("ROWS", r.rows),
        ("NEWTON_STEPS", r.steps),
    )
    return Module(
        name=f"mathieu_{name}",
        doc=f"Mathieu's characteristic value {r.kind}_{r.m}(q) of y'' + (a - 2q cos 2z) y = 0, "
            "resummed past the radius of its series and refined by Newton.",
        constants=constants, evaluators=evaluators,
        provenance=provenance(f"mathieu_{name}", r.order, command,
                              numerator=[_hex(c) for c in r.form.approximant.numerator],
                              denominator=[_hex(c) for c in r.form.approximant.denominator],
                              limit=r.limit, rows=r.rows, steps=r.steps),
    )


@dataclass(frozen=True)
class ResummedCurve:
    """One transition curve ``δ(ε)`` as the Padé of its exact series, verified against the
    Floquet boundary on ``0 ≤ ε ≤ limit`` (``|ε|`` when the series is even in ε), with the
    largest error ``checked`` there (absolute, in δ)."""

    label: str
    form: Resummed
    limit: float
    checked: float


@dataclass(frozen=True)
class ResummedTongue:
    """The transition curves of tongue ``n`` of ``ẍ + (δ + ε p(t))x = 0`` (``p`` as its user
    text, data only), each resummed and verified to ``tolerance`` in δ."""

    p: str
    n: int
    order: int
    tolerance: float
    curves: tuple[ResummedCurve, ...]


def lower_tongue(r: ResummedTongue, command: str) -> Module:
    """``delta_<i>(eps)`` for curve i of the tongue (the Padé of its series), and
    ``delta_<i>_error(eps)`` (|difference to the next lower approximant|, an estimate), NaN
    outside the verified ε."""
    eps = sp.Symbol("eps")
    evaluators: list[Evaluator] = []
    constants: list[tuple[str, object]] = [("ORDER", r.order), ("MODEL", f"tongue_{r.n}"),
                                           ("VARIABLE", "eps"), ("TOLERANCE", r.tolerance)]
    for i, c in enumerate(r.curves):
        bound = sp.Rational(repr(c.limit))
        guard = sp.Abs(eps) <= bound if c.form.power == 2 else sp.And(eps >= 0, eps <= bound)
        body, value = resummed_expression(c.form, eps)
        _, other = resummed_expression(c.form, eps, c.form.neighbour)
        L, M = c.form.approximant.degrees
        var = "eps²" if c.form.power == 2 else "eps"
        domain = (f"NaN outside {'|eps|' if c.form.power == 2 else '0 ≤ eps'} ≤ {c.limit:g}, "
                  f"where it was verified to {r.tolerance:g} in delta against the Floquet "
                  "boundary |tr M| = 2")
        delta, lower = sp.Symbol("delta"), sp.Symbol("delta_lower")
        name = f"delta_{i}"
        evaluators += [
            Evaluator(name, f"Transition curve {c.label} of tongue {r.n}: Padé [{L}/{M}] in "
                      f"{var} of the exact series to order {r.order} ({domain}).", (eps,), (),
                      guard, body, value),
            Evaluator(f"{name}_error", f"|{name} − Padé [{L - 1}/{M - 1}]|: an error estimate "
                      f"in delta ({domain}).", (eps,), (), guard,
                      (*body, (delta, value), (lower, other)), sp.Abs(delta - lower)),
        ]
        constants += [(f"LABEL_{i}", one_line(c.label)), (f"LIMIT_{i}", c.limit),
                      (f"CHECKED_ERROR_{i}", c.checked), (f"DEGREES_{i}", (L, M)),
                      (f"SYMMETRIC_{i}", c.form.power == 2)]
    return Module(
        name=f"tongue_{r.n}",
        doc=f"Transition curves delta(eps) out of tongue n = {r.n} (delta = n²/4) of "
            f"x'' + (delta + eps p(t)) x = 0, p(t) = {r.p}, resummed past the radius of "
            "their series.",
        constants=tuple(constants), evaluators=tuple(evaluators),
        provenance=provenance(f"tongue_{r.n}", r.order, command, p=r.p, n=r.n, curves=[
            {"numerator": [_hex(x) for x in c.form.approximant.numerator],
             "denominator": [_hex(x) for x in c.form.approximant.denominator],
             "limit": c.limit} for c in r.curves]),
    )


def _hex(c: Fraction) -> str:
    """An exact rational for the provenance hash, in hex: Python's decimal conversion refuses
    integers past 4300 digits, which a Padé of order 100 in q reaches."""
    return f"{c.numerator:x}/{c.denominator:x}"


def lower_limit_cycle(lc: LimitCycle, command: str, order: int,
                      resummed: ResummedCycle | None = None) -> Module:
    """Evaluators ``omega(eps)``, ``period(eps)``, ``amplitude(eps)`` (q(0), at q̇(0) = 0),
    ``q(t, eps)`` and ``error_estimate(eps)`` of a limit cycle's L–P series to ``order``
    (``lc`` derived further: K + 2 for the estimate, and far enough for the radius), NaN where
    |ε| is beyond 90 % of the radius :func:`lindstedt.nearest_singularity` estimates from ω's
    exact coefficients."""
    if not 1 <= order <= lc.order - 2:
        raise ValueError(f"order {order}: the cycle is derived to {lc.order}, not K + 2")
    eps, t, w, s, total = sp.symbols("eps t w s T")
    rational = [sp.Rational(c.numerator, c.denominator) for c in lc.omega]
    omega = rational[: order + 1]
    tau = [sp.Rational(c.numerator, c.denominator) for c in lc.period[: order + 1]]
    amp = [sp.Rational(c.numerator, c.denominator) for c in lc.amplitude[: order + 1]]
    est = nearest_singularity(lc.omega)
    radius = None
    if est is not None:
        radius = est.radius ** 0.5 if est.variable.endswith("**2") else est.radius
        radius = LIMIT_CYCLE_MARGIN * sp.Rational(repr(float(radius)))
    # without a radius, |ε| ≤ 10^(300/(K+2)) keeps ε^(K+2) finite; q(t, ε) also needs t finite
    within = sp.Abs(eps) < radius if radius is not None else \
        sp.Abs(eps) <= sp.Float(10.0 ** (300 // (order + 2)))
    entry, guard = argument_entry(((eps, within, 0),))
    entry_t, guard_t = argument_entry(((eps, within, 0),
                                       (t, sp.Abs(t) <= FREE_ARGUMENT_LIMIT, 0)))
    top = max(max((*cos, *sin), default=1) for cos, sin in lc.q[: order + 1])
    cos_lines, cs, ss = harmonics(top, False, s, sines=True)

    def in_eps(table: dict) -> sp.Expr:
        return horner([table.get(j, sp.Integer(0)) for j in range(order + 1)], eps)

    cos_h: dict[int, dict] = {}
    sin_h: dict[int, dict] = {}
    for j, (cos, sin) in enumerate(lc.q[: order + 1]):
        for n, c in cos.items():
            cos_h.setdefault(n, {})[j] = sp.Rational(c.numerator, c.denominator)
        for n, c in sin.items():
            sin_h.setdefault(n, {})[j] = sp.Rational(c.numerator, c.denominator)
    q_value = sum((in_eps(h) * cs[n] for n, h in sorted(cos_h.items())), sp.Integer(0)) + sum(
        (in_eps(h) * ss[n] for n, h in sorted(sin_h.items())), sp.Integer(0))
    tail = abs(sp.Rational(lc.period[order + 1].numerator, lc.period[order + 1].denominator))
    tail2 = abs(sp.Rational(lc.period[order + 2].numerator, lc.period[order + 2].denominator))
    estimate = (tail * sp.Abs(eps) ** (order + 1) + tail2 * sp.Abs(eps) ** (order + 2)) \
        / sp.Abs(total)
    domain = ("NaN from 90 % of the estimated radius of convergence on"
              if radius is not None else "no radius estimate: no guard")
    args = (eps,)
    entry = tuple(entry)
    evaluators = (
        Evaluator("omega", f"Frequency ω of the limit cycle to order {order} ({domain}).",
                  args, entry, guard, (), horner(omega, eps)),
        Evaluator("period", f"Period 2π Σ τ_j ε^j to order {order} ({domain}).", args, entry,
                  guard, (), 2 * sp.pi * horner(tau, eps)),
        Evaluator("amplitude", f"q(0) at q̇(0) = 0, to order {order} ({domain}).", args,
                  entry, guard, (), horner(amp, eps)),
        Evaluator("q", f"q(t) on the cycle, q̇(0) = 0, s = ωt ({domain}).", (t, eps),
                  tuple(entry_t), guard_t,
                  ((w, horner(omega, eps)), (s, w * t), *cos_lines), q_value),
        Evaluator("error_estimate", "Relative truncation error of period(): its first two "
                  "omitted terms over the sum.", args, entry, guard,
                  ((total, horner(tau, eps)),), estimate),
    )
    m = lc.model
    constants = (
        ("ORDER", order),
        ("MODEL", m.name),
        ("VARIABLE", "eps"),
        ("CONVENTION", "q'(0) = 0; q(0) = amplitude(eps)"),
        ("RADIUS", float(radius) if radius is not None else float("nan")),
        ("OMEGA_EXACT", tuple(str(c) for c in omega)),
        ("PERIOD_EXACT", tuple(str(c) for c in tau)),
        ("AMPLITUDE_EXACT", tuple(str(c) for c in amp)),
    )
    if resummed is not None:
        evaluators = (*evaluators, *lower_resummed_cycle(resummed))
        constants = (*constants, *resummed_constants(resummed))
    return Module(
        name=m.name,
        doc=f"{m.title}: its limit cycle's L–P evaluators to order {order} in eps.",
        constants=constants,
        evaluators=evaluators,
        provenance=provenance(m.name, order, command, equation=m.source,
                              terms=[(a, b, str(c)) for a, b, c in m.terms],
                              **({"resummed": resummed_constants(resummed)}
                                 if resummed is not None else {})),
    )


def resummed_constants(r: ResummedCycle) -> tuple[tuple[str, object], ...]:
    """What the module states about its resummed evaluators: the verified |ε|, the
    tolerance, the largest error measured at the reference points, the degrees."""
    return (("RESUMMED_LIMIT", r.limit), ("RESUMMED_TOLERANCE", r.tolerance),
            ("RESUMMED_CHECKED", tuple(r.points)), ("RESUMMED_ERROR", r.checked),
            ("RESUMMED_DEGREES", r.form.approximant.degrees),
            *((("AMPLITUDE_RESUMMED_LIMIT", r.amplitude_verified[0]),
               ("AMPLITUDE_RESUMMED_ERROR", r.amplitude_verified[2]))
              if r.amplitude is not None else ()),
            *((("Q_RESUMMED_LIMIT", r.harmonics_verified[0]),
               ("Q_RESUMMED_ERROR", r.harmonics_verified[2]),
               ("Q_RESUMMED_HARMONICS", len(r.harmonics)))
              if r.harmonics else ()))


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
        if arg.is_number:
            return sp.true if arg.is_finite else sp.false
        return None


class NotNaN(BooleanFunction):
    """True for a number that is not NaN (±inf included); printed as a quiet test (no
    "invalid", unlike an ordered comparison with NaN)."""

    nargs = 1

    @classmethod
    def eval(cls, arg: sp.Expr) -> sp.Basic | None:
        if arg.is_number:
            return sp.false if arg is sp.nan else sp.true
        return None


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


def nested_horner(expr: sp.Expr, gens: tuple[sp.Symbol, ...]) -> sp.Expr:
    """A polynomial in ``gens`` as Horner's rule in the first, each coefficient in the rest."""
    if not gens:
        return expr
    poly = sp.Poly(expr, gens[0])
    acc = sp.Integer(0)
    for c in poly.all_coeffs():
        acc = acc * gens[0] + nested_horner(sp.expand(c), gens[1:])
    return acc


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


FOURIER_AGM_STEPS = 16
# NOTE: AGM(1, b) converges for any b ≥ 1e-300 within 16 steps (about log₂ ln(1/b) + 5).


def lower_fourier(terms: int, command: str) -> Module:
    """``q(t, A, eps)`` and ``omega(A, eps)`` of the free Duffing oscillator from the exact
    Fourier series of its elliptic-function solution in the nome ``q = exp(−πK′/K)``,
    truncated to ``terms`` odd harmonics; ``K``, ``K′`` by the AGM (see
    ``methods.cn_fourier``, which the chooser verifies; same formulas and AGM steps)."""
    t, A, eps, x, m, mm, scale, alt, K, Kp, nome, w = sp.symbols(
        "t A eps x m mm scale alt K K_prime nome w")
    hardening = m >= 0
    body: list[Assign] = [
        (m, x / (2 + 2 * x)),
        (mm, sp.Piecewise((m, hardening), (-m / (1 - m), True))),
        (scale, sp.Piecewise((sp.sqrt(1 + x), hardening), (sp.sqrt((1 + x) * (1 - m)), True))),
        (alt, sp.Piecewise((1, hardening), (-1, True))),
    ]
    for symbol, arg, prefix in ((K, sp.sqrt(1 - mm), "k"), (Kp, sp.sqrt(mm), "kp")):
        lines, mean = agm_steps(sp.Integer(1), arg, FOURIER_AGM_STEPS, prefix)
        body += [*lines, (symbol, sp.pi / (2 * mean))]
    body += [(nome, sp.exp(-sp.pi * Kp / K)), (w, sp.pi * scale / (2 * K))]
    lines, cos_of, _ = harmonics(2 * terms - 1, True, w * t, False)
    series = sum(2 * sp.pi / (sp.sqrt(mm) * K) * alt**n * sp.sqrt(nome) * nome**n
                 / (1 + alt * nome ** (2 * n + 1)) * cos_of[2 * n + 1] for n in range(terms))
    prelude = ((x, eps * A**2),)
    q = Evaluator("q", f"q(t, A, eps): exact Fourier series, {terms} odd harmonics; NaN for "
                  "eps*A**2 <= -1.", (t, A, eps), prelude, x > -1, (*body, *lines),
                  A * sp.Piecewise((sp.cos(t), sp.Eq(m, 0)), (series, True)))
    omega = Evaluator("omega", "omega(A, eps) = 2 pi / T, exact (AGM); NaN for eps*A**2 <= -1.",
                      (A, eps), prelude, x > -1, tuple(body), w)
    return Module(
        name="fourier",
        doc=f"Duffing q'' + q + eps*q**3 = 0: the exact solution A cn(sqrt(1+x) t | m) as its "
            f"Fourier series in the nome, {terms} odd harmonics.",
        constants=(("HARMONICS", terms),),
        evaluators=(q, omega),
        provenance=provenance("fourier", terms, command),
    )


x_ = sp.Symbol("x")
# NOTE: x = εA², the variable of every period formula (:class:`PeriodFormula`).


@dataclass(frozen=True)
class PeriodFormula:
    """``T/2π`` of one verified period candidate in ``x = εA²``: assignments, then the value,
    inside the method's domain; its coefficients as the verified doubles (provenance)."""

    method: str
    order: int
    domain: sp.Basic  # SymPy boolean in x_
    body: tuple[Assign, ...]
    value: sp.Expr
    num: tuple[float, ...]
    den: tuple[float, ...]


def lower_choice(formula: PeriodFormula, command: str, verified: tuple[float, float]) -> Module:
    """The period evaluator ``choose period`` picked, as one numba ufunc ``period(A, eps)``,
    NaN outside the range ``verified = (x_min, x_max)`` of ``x = εA²`` it was verified on (as
    well as outside the method's domain).

    Coefficients and bounds enter as the exact binary values of the verified doubles (so the
    emitted evaluator computes what was verified, up to FMA contraction)."""
    A, eps = sp.symbols("A eps")
    lo, hi = (sp.Rational(float(v)) for v in verified)
    guard = sp.And(formula.domain, x_ >= lo, x_ <= hi)
    ev = Evaluator("period", f"Duffing period T(A, eps): {formula.method} order "
                   f"{formula.order}, the method `lindstedt choose` verified for x = eps*A**2 "
                   f"in [{float(lo)!r}, {float(hi)!r}]; NaN outside that range.", (A, eps),
                   ((x_, eps * A**2),), guard, formula.body, 2 * sp.pi * formula.value)
    return Module(
        name="chosen_period",
        doc=f"The period evaluator chosen by `{command}`.",
        constants=(("METHOD", formula.method), ("ORDER", formula.order),
                   ("VERIFIED_X", (float(lo), float(hi)))),
        evaluators=(ev,),
        provenance=provenance("duffing", formula.order, command, method=formula.method,
                              num=list(formula.num), den=list(formula.den)),
    )


# --- documents: the LaTeX beside a module, as SymPy objects (printed by emit) ---------------

@dataclass(frozen=True)
class OrderPieces:
    """The ``y^j`` equation of a free oscillator: its forcing, resonant part, ω_j, q_j."""

    j: int
    resonant: sp.Expr
    omega: sp.Expr
    forcing: tuple[tuple[int, sp.Expr], ...]
    q: tuple[tuple[int, sp.Expr], ...]


@dataclass(frozen=True)
class Derivation:
    """The tables and the order-by-order derivation of a free oscillator's series to
    ``order`` (templates ``tables.tex.j2``, ``derivation.tex.j2``)."""

    model: str
    latex: str  # the equation of motion, as the model typesets it
    y: sp.Expr
    coordinate: sp.Symbol
    amplitude: sp.Expr
    order_factor: sp.Expr
    coupling: sp.Expr
    order: int
    omega: tuple[sp.Expr, ...]
    period: tuple[sp.Expr, ...]
    q: tuple[tuple[tuple[int, sp.Expr], ...], ...]
    orders: tuple[OrderPieces, ...]


def lower_derivation(solution: SeriesSolution, order: int) -> Derivation:
    """The document of ``solution`` at order ``K ≤ solution.order``."""
    m, g = solution.model, solution.ground
    pieces = []
    for j in range(1, order + 1):
        t = order_terms(solution, j)
        pieces.append(OrderPieces(j, t.resonant, t.omega, tuple(sorted(t.forcing.items())),
                                  tuple(sorted(t.q.items()))))
    return Derivation(
        model=m.name, latex=m.latex, y=m.y, coordinate=m.coordinate, amplitude=m.amplitude,
        order_factor=m.order_factor, coupling=m.coupling, order=order,
        omega=tuple(g.to_sympy(c) for c in solution.omega[: order + 1]),
        period=tuple(g.to_sympy(c) for c in solution.period[: order + 1]),
        q=tuple(tuple((n, g.to_sympy(c)) for n, c in sorted(solution.q[j].items()))
                for j in range(order + 1)),
        orders=tuple(pieces))


@dataclass(frozen=True)
class NotesTable:
    """The notes' driven table: A₁, A₃, A₅ by μ-order, harmonic balance and shooting at
    ``(eps, force, omega)``; a cell is a number, or the notes' own printed digits."""

    eps: float
    force: float
    omega: float
    rows: tuple[tuple[str, tuple[tuple[int, float | str], ...]], ...]


@dataclass(frozen=True)
class MuDerivation:
    """The μ-expansion's derivation to ``order`` and the notes' table (``mu_derivation.tex.j2``)."""

    order: int
    orders: tuple[MuOrder, ...]
    table: NotesTable


@dataclass(frozen=True)
class MuDampedDerivation:
    """The damped μ-expansion's derivation to ``order`` (``mu_damped_derivation.tex.j2``):
    ``F_j``, both secular conditions, ``b_{j−1}``, ``δ_{j−1}``, ``q_j`` and ``δ_j`` per order."""

    order: int
    orders: tuple[MuDampedOrder, ...]
    determinant: sp.Expr  # Δ in x, a, γ


@dataclass(frozen=True)
class CycleOrderPieces:
    """Order j of a limit cycle's document: ``F_j = K_j + a_(j−1) L + a₀ W_j cos s``, the two
    secular conditions and ``q_j`` (exact rationals; :class:`lindstedt.CycleOrder`)."""

    j: int
    known_cos: tuple[tuple[int, sp.Rational], ...]
    known_sin: tuple[tuple[int, sp.Rational], ...]
    a_prev: sp.Rational | None  # a_(j−1), from the sin s condition (None at j = 1)
    W: sp.Rational
    omega: sp.Rational
    q_cos: tuple[tuple[int, sp.Rational], ...]
    q_sin: tuple[tuple[int, sp.Rational], ...]


@dataclass(frozen=True)
class CycleDerivation:
    """The order-by-order derivation of a limit cycle (``cycle_derivation.tex.j2``): the
    amplitude equation ``S(a₀) = 0``, the linearisation ``L`` and the first orders."""

    model: str
    equation: str  # q'' + q = eps*f(q, q') as the user wrote it
    a0: sp.Rational
    slope: sp.Rational
    lin_cos: tuple[tuple[int, sp.Rational], ...]
    lin_sin: tuple[tuple[int, sp.Rational], ...]
    orders: tuple[CycleOrderPieces, ...]


def _rational_items(d: dict) -> tuple[tuple[int, sp.Rational], ...]:
    return tuple((n, sp.Rational(c.numerator, c.denominator)) for n, c in sorted(d.items()))


def lower_cycle_derivation(lc: LimitCycle, order: int) -> CycleDerivation:
    """The document of ``lc``'s first ``min(order, len(lc.orders))`` orders."""

    def rational(c):
        return sp.Rational(c.numerator, c.denominator)

    pieces = tuple(CycleOrderPieces(
        o.j, _rational_items(o.known[0]), _rational_items(o.known[1]),
        None if o.a_prev is None else rational(o.a_prev), rational(o.W), rational(o.omega),
        _rational_items(o.q[0]), _rational_items(o.q[1])) for o in lc.orders[:order])
    a0 = rational(lc.amplitude[0])
    return CycleDerivation(lc.model.name, lc.model.source, a0, rational(lc.slope),
                           _rational_items(lc.linearisation[0]),
                           _rational_items(lc.linearisation[1]), pieces)


@dataclass(frozen=True)
class Unit:
    """What one command writes: a module and the documents beside it."""

    module: Module
    documents: tuple[Derivation | MuDerivation | MuDampedDerivation
                     | SlowFlowDocument | CycleDerivation, ...] = ()


# --- the slow flow (averaging) ---------------------------------------------------------------


@dataclass(frozen=True)
class SlowFlowDocument:
    """The slow flow's equations for ``slow_flow.tex.j2``: ``R_k``, ``Φ_k`` by order."""

    name: str
    source: str  # the equation as the user wrote it
    order: int
    driven: bool
    radial: tuple[sp.Expr, ...]
    phase: tuple[sp.Expr, ...]


def lower_slow_flow(flow: SlowFlow, command: str) -> Unit:
    """Compiled right sides of the slow flow: ``slow_flow`` (``x = (r, φ)``),
    ``slow_flow_jacobian`` and ``slow_flow_cartesian`` (``x = (u, v)``, ``u = r cos φ``,
    ``v = −r sin φ``: regular through ``r = 0``), all in t, with the LaTeX of the flow."""
    eps = sp.Symbol("eps")
    taken = MODULE_NAMES | LOCAL_NAMES | frozenset(dir(builtins)) | frozenset(keyword.kwlist)
    for p in flow.parameters:
        if str(p) in taken or _LOCAL.fullmatch(str(p)) or re.fullmatch(r"x_\d+", str(p)):
            raise InputError(f"parameter {str(p)!r}: the emitted module uses this name; "
                             "rename the parameter")
    params = tuple(sp.Symbol(str(p)) for p in flow.parameters)
    r, phi, u, v = sp.symbols("r phi u v")
    polar = [e.xreplace({R_SLOW: r, PHI_SLOW: phi}) for e in flow.rates]
    cart = [sp.Add(*(eps ** (k + 1) * G[i] for k, G in enumerate(flow.cartesian)))
            .xreplace({U_SLOW: u, V_SLOW: v}) for i in range(2)]
    args = (eps, *params)
    kernels = []
    for name, doc, unpack, shape, entries in (
        ("slow_flow", "(dr/dt, dphi/dt) at x = (r, phi); q = r cos("
         + ("w t + phi), w = 1 + eps*sigma" if flow.driven else "t + phi)"), (r, phi), (2,),
         tuple(((i,), e) for i, e in enumerate(polar))),
        ("slow_flow_jacobian", "d(dr/dt, dphi/dt)/d(r, phi)", (r, phi), (2, 2),
         tuple(((i, j), sp.diff(e, x)) for i, e in enumerate(polar)
               for j, x in enumerate((r, phi)))),
        ("slow_flow_cartesian", "(du/dt, dv/dt) at x = (u, v); q = u cos "
         + ("w t + v sin w t" if flow.driven else "t + v sin t"),
         (u, v), (2,), tuple(((i,), e) for i, e in enumerate(cart))),
    ):
        exprs = [e for _, e in entries]
        subexprs, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x_"),
                                   order="canonical")
        kernels.append(ArrayKernel(
            name, doc, unpack, args, shape, tuple(subexprs),
            tuple((idx, e) for (idx, _), e in zip(entries, reduced, strict=True))))
    module = Module(
        name=f"{flow.name}_slow_flow",
        doc=f"The slow flow of {flow.source} to order {flow.order} in eps (averaging, "
            "near-identity transformation with mean-free generators)"
            + (": the drive's frequency is w = 1 + eps*sigma" if flow.driven else "") + ".",
        constants=(("ORDER", flow.order), ("UNKNOWNS", ("r", "phi")),
                   ("PARAMETERS", tuple(str(a) for a in args))),
        evaluators=(),
        provenance=provenance(f"{flow.name}_slow_flow", flow.order, command,
                              source=flow.source, parameters=[str(p) for p in params]),
        kernels=tuple(kernels),
    )
    doc = SlowFlowDocument(flow.name, flow.source, flow.order, flow.driven,
                           tuple(e.xreplace({R_SLOW: r, PHI_SLOW: phi}) for e in flow.radial),
                           tuple(e.xreplace({R_SLOW: r, PHI_SLOW: phi}) for e in flow.phase))
    return Unit(module, (doc,))
