"""Lowering: derived solutions -> IR records a template can lay out (no code strings here).

An :class:`Evaluator` is one numba ufunc: a prelude (what its domain guard needs), the guard
(outside it the ufunc returns NaN), the body and one output.  Polynomials are in Horner
form; all harmonics of ``cos n s`` / ``sin n s`` come from one ``cos``/``sin`` pair by the
Chebyshev recurrence ``c_{n+2} = 2cos(2s)·c_n - c_{n-2}`` (odd harmonics) or
``c_{n+1} = 2cos(s)·c_n - c_{n-1}`` (all harmonics).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass

import sympy as sp

from . import __version__
from .lindstedt import SeriesSolution
from .printers import identifier

Assign = tuple[sp.Symbol, sp.Expr]


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


@dataclass(frozen=True)
class Provenance:
    """What a generated file says about where it came from (no timestamp: reproducible)."""

    model: str
    order: int
    command: str
    inputs: str  # sha256 of the canonical description of the inputs

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


def provenance(model: str, order: int, command: str, **inputs: object) -> Provenance:
    """Provenance with a hash over the canonical JSON of every input that shapes the output."""
    payload = json.dumps(
        {"version": __version__, "model": model, "order": order, **inputs},
        sort_keys=True, default=str,
    )
    return Provenance(model, order, command, hashlib.sha256(payload.encode()).hexdigest())


def horner(coeffs: list[sp.Expr], x: sp.Symbol) -> sp.Expr:
    """``Σ c_j x^j`` in Horner form (``sympy.horner``), zero for no coefficients."""
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
    g = solution.ground
    args = {name: sp.Symbol(identifier(name)) for name, _ in m.parameters}
    to_args = {sym: args[name] for name, sym in m.parameters}
    x, w, s, total = sp.symbols("x w s T")
    y = m.y.xreplace(to_args)
    amplitude = m.amplitude.xreplace(to_args)
    omega = [g.to_sympy(c) for c in solution.omega[: order + 1]]
    tau = [g.to_sympy(c) for c in solution.period[: order + 1]]
    guard = m.orbit_condition.xreplace({sp.Symbol("Y"): x})
    radius = m.radius
    if radius is not None and not allow_divergent:
        guard = sp.And(guard, sp.Abs(x) < radius)
    prelude = ((x, y),)
    params = tuple(args.values())

    top = max(max(qj) for qj in solution.q[: order + 1])
    harmonic = {
        n: horner([g.to_sympy(solution.q[j].get(n, g.scalar(0))) for j in range(order + 1)], x)
        for n in range(top + 1)
    }
    harmonic = {n: h for n, h in harmonic.items() if h != 0}
    t = sp.Symbol("t")
    cos_lines, cs, _ = harmonics(top, m.odd, s, sines=False)
    both_lines, _, ss = harmonics(top, m.odd, s, sines=True)
    name_of = identifier(str(m.coordinate))
    domain = "NaN where no periodic orbit exists" + (
        "" if allow_divergent or radius is None else " or beyond the radius of convergence"
    )
    tail = abs(g.to_sympy(solution.period[order + 1]))
    estimate = tail * sp.Abs(x) ** (order + 1) / sp.Abs(total)
    if radius is not None:
        estimate = estimate / (1 - sp.Abs(x) / radius)
    evaluators = (
        Evaluator("omega", f"Frequency ω to order {order} ({domain}).", params, prelude, guard,
                  (), horner(omega, x)),
        Evaluator("period", f"Period T = 2π Σ τ_j y^j to order {order} ({domain}).", params,
                  prelude, guard, (), 2 * sp.pi * horner(tau, x)),
        Evaluator(
            name_of,
            f"{name_of}(t) with s = ωt, harmonics by the Chebyshev recurrence ({domain}).",
            (t, *params), prelude, guard,
            ((w, horner(omega, x)), (s, w * t), *cos_lines),
            amplitude * sum(h * cs[n] for n, h in sorted(harmonic.items())),
        ),
        Evaluator(
            f"{name_of}dot", f"d{name_of}/dt ({domain}).", (t, *params), prelude, guard,
            ((w, horner(omega, x)), (s, w * t), *both_lines),
            -amplitude * w * sum(n * h * ss[n] for n, h in sorted(harmonic.items())),
        ),
        Evaluator(
            "error_estimate",
            "Relative truncation error of period(), from the first omitted term "
            "|τ_{K+1} y^(K+1)| / (1 - |y|/R) over the truncated sum.",
            params, prelude, guard, ((total, horner(tau, x)),), estimate,
        ),
    )
    Q = tuple(
        tuple(float(g.to_sympy(solution.q[j].get(n, g.scalar(0)))) for n in range(top + 1))
        for j in range(order + 1)
    )
    constants = (
        ("ORDER", order),
        ("MODEL", m.name),
        ("VARIABLE", m.variable),
        ("CONVENTION", solution.convention),
        ("RADIUS", float(radius) if radius is not None else float("nan")),
        ("ALLOW_DIVERGENT", allow_divergent),
        ("OMEGA", tuple(float(c) for c in omega)),
        ("PERIOD", tuple(float(c) for c in tau)),
        ("Q", Q),
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
        ),
    )
