"""Lowering to documents and single evaluators: the derivations' LaTeX records (a family of
periodic orbits' tables and derivation, one coordinate or a normal mode's several; a limit
cycle's), the Fourier (AGM) period, a chosen period formula and the slow flow."""

from __future__ import annotations

import builtins
import dataclasses
import keyword
import re

import sympy as sp

from ..derive.averaging import PHI as PHI_SLOW
from ..derive.averaging import R as R_SLOW
from ..derive.averaging import SlowFlow
from ..derive.averaging import U as U_SLOW
from ..derive.averaging import V as V_SLOW
from ..derive.cycles import LimitCycle
from ..derive.equation import parse_equation
from ..derive.lindstedt import SeriesSolution, order_terms, validity
from ..derive.models import Model
from ..derive.nnm import NormalModeSeries
from ..derive.nnm import radius as mode_radius
from ..derive.system import System
from ..errors import InputError
from .forms import _LOCAL, LOCAL_NAMES, MODULE_NAMES, agm_steps, harmonics
from .printers import exact, latex_equation, latex_expr
from .records import (
    ArrayKernel,
    Assign,
    CycleDerivation,
    CycleOrderPieces,
    DerivationOrder,
    Evaluator,
    LinearPart,
    Module,
    PeriodFormula,
    SeriesDerivation,
    SeriesTables,
    SlowFlowDocument,
    Unit,
    provenance,
    x_,
)

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


def _equation_latex(m: Model) -> str:
    """``m``'s equation typeset as its user wrote it (:func:`printers.latex_equation`), the
    parameter values given with it substituted; a built-in model's own LaTeX."""
    if not m.source:
        return m.latex
    eq = parse_equation(m.source)
    given = dict(m.given)
    values = {p: sp.sympify(given[p.name]) for p in eq.parameters if p.name in given}
    return latex_equation(dataclasses.replace(eq, lhs=eq.lhs.xreplace(values),
                                              rhs=eq.rhs.xreplace(values)))


def _title(name: str) -> str:
    """A model's name as a title's words: ``van_der_pol`` → ``Van der pol``."""
    return name.replace("_", " ").capitalize()


def _system_equations(system: System) -> tuple[str, ...]:
    """A system's equations as mathematics: ``ẍ_i + (Lx)_i + g_i(x) = 0``."""
    dots = [sp.Symbol(rf"\ddot{{{sp.latex(x)}}}") for x in system.coordinates]
    L = system.stiffness * sp.Matrix(system.coordinates)
    return tuple(latex_expr(sp.expand(dots[i] + L[i] + system.force[i])) + " = 0"
                 for i in range(system.size))


def lower_tables(series: SeriesSolution | NormalModeSeries, order: int) -> SeriesTables:
    """The tables' record of a free oscillator's series or a normal mode's to ``order``:
    ``ω_j/ω₀``, ``τ_j ω₀`` and every coordinate's coefficients, exact."""
    if isinstance(series, SeriesSolution):
        m, g = series.model, series.ground
        return SeriesTables(
            _title(m.name), (_equation_latex(m),), m.frequency, m.y, order,
            tuple(exact(g, c) for c in series.omega[: order + 1]),
            tuple(exact(g, c) for c in series.period[: order + 1]),
            ((m.coordinate, tuple(tuple((n, exact(g, c)) for n, c in sorted(qj.items()))
                                  for qj in series.q[: order + 1])),),
            m.coordinate, m.amplitude, validity(series))
    system = series.system
    found = mode_radius(series)
    return SeriesTables(
        f"Nonlinear normal mode {series.mode}", _system_equations(system), series.omega0,
        sp.Symbol("A") ** series.step, order,
        tuple(series.omega_over_omega0()[: order + 1]),
        tuple(series.period_times_omega0()[: order + 1]),
        tuple((x, tuple(tuple(sorted(o.items())) for o in series.coordinate(i, order)))
              for i, x in enumerate(system.coordinates)),
        system.coordinates[series.amplitude], sp.Symbol("A"),
        radius=None if found is None else (found.estimate, found.spread, found.lower))


def lower_series_derivation(series: SeriesSolution | NormalModeSeries, order: int
                            ) -> SeriesDerivation:
    """The derivation's record of a free oscillator's series (§10.3: ``F_j``, the secular
    condition's ω_j, ``q_j``) or a normal mode's (``R_jn``, ``Ω_j`` from
    ``ψ·(R_j1 + Ω_j φ) = 0``, ``c_jn``) at orders 1 to ``order``."""
    if isinstance(series, SeriesSolution):
        m, g = series.model, series.ground
        orders = []
        for j in range(1, order + 1):
            t = order_terms(series, j, lambda c: exact(g, c))
            orders.append(DerivationOrder(
                j, (((1, t.resonant), *sorted(t.forcing.items())),), t.resonant, t.omega,
                (tuple(sorted(t.q.items())),)))
        return SeriesDerivation(
            _title(m.name), (_equation_latex(m),), (m.coordinate,), m.coordinate, m.amplitude,
            m.amplitude, m.y, m.coupling, m.order_factor, order, r"\omega", (2 * m.amplitude,),
            tuple(orders), validity=validity(series))
    system = series.system
    value = series.ground.to_sympy
    zero = series.ground.scalar(0)
    size = system.size
    orders = []
    for j in range(1, min(order, len(series.right_sides)) + 1):
        rhs = series.right_sides[j - 1]
        solved = series.coefficients[j]
        secular = sum((p * r for p, r in zip(series.left, rhs.get(1, ()), strict=False)),
                      zero)
        orders.append(DerivationOrder(
            j, tuple(tuple((n, value(r[i])) for n, r in sorted(rhs.items()))
                     for i in range(size)),
            value(secular), value(series.omega_squared[j]),
            tuple(tuple((n, value(c)) for n, c in sorted(solved[i].items()) if c)
                  for i in range(size))))
    phi = tuple(value(c.get(1, zero)) for c in series.coefficients[0])
    return SeriesDerivation(
        f"Nonlinear normal mode {series.mode}", _system_equations(system),
        system.coordinates, system.coordinates[series.amplitude], sp.Symbol("A"), sp.Integer(1),
        sp.Symbol("A") ** series.step, sp.Symbol("A") ** series.step, sp.Integer(1),
        order, r"\Omega", phi, tuple(orders),
        linear=LinearPart(system.stiffness, series.lam, phi,
                          tuple(value(v) for v in series.left)))


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
    return CycleDerivation(lc.model.name, parse_equation(lc.model.source), a0, rational(lc.slope),
                           _rational_items(lc.linearisation[0]),
                           _rational_items(lc.linearisation[1]), pieces)


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
    doc = SlowFlowDocument(flow.name, parse_equation(flow.source), flow.order, flow.driven,
                           tuple(e.xreplace({R_SLOW: r, PHI_SLOW: phi}) for e in flow.radial),
                           tuple(e.xreplace({R_SLOW: r, PHI_SLOW: phi}) for e in flow.phase))
    return Unit(module, (doc,))

