"""A nonlinear normal mode lowered to a module: the backbone ω(A), T(A) and every
coordinate's motion x_i(t, A) and the truncation error's estimate, NaN beyond the lower bound
of the radius of convergence (estimated from the exact series of ω) [NormalModeSeries -> Module]."""

from __future__ import annotations

import sympy as sp

from ..derive.nnm import NormalModeSeries, radius
from ..errors import InputError
from .forms import MODULE_NAMES, argument_entry, harmonics, horner, tail_bound
from .printers import identifier
from .records import Evaluator, ModeDerivation, ModeOrder, ModeTables, Module, provenance

NNM_ARGUMENT_LIMIT = 1e6
# NOTE: |t| beyond this loses the phase ωt to rounding (as a free oscillator's module): NaN.
DIGITS = 30
# NOTE: coefficients in Q(√λ) or Q(λ) reach the module as floats rounded from 30 digits.


def _float(c: sp.Expr) -> sp.Float:
    return sp.Float(sp.N(c, DIGITS), 17)


def lower_nnm(mode: NormalModeSeries, order: int, name: str, command: str,
              allow_divergent: bool = False) -> Module:
    """Evaluators ``omega(A)``, ``period(A)``, one ``x_i(t, A)`` per coordinate and
    ``error_estimate(A)``, summed to ``order`` (``mode`` derived two orders further at least:
    ``τ_{K+1}``, ``τ_{K+2}`` feed the estimate, every term the radius).  NaN beyond the radius'
    lower bound unless ``allow_divergent``; a bound that leaves no amplitude is refused."""
    if mode.order < order + 2:
        raise ValueError("lower_nnm needs a mode derived to order K + 2")
    coordinates = [identifier(str(x)) for x in mode.system.coordinates]
    clash = sorted(set(coordinates) & (MODULE_NAMES | {"A", "t", "MODE", "OMEGA0", "SYSTEM"}))
    if clash:
        raise InputError(f"coordinate {clash[0]!r}: also a name of the emitted module; rename "
                         "it")
    A, t = sp.Symbol("A"), sp.Symbol("t")
    y, w, s = sp.Symbol("_y"), sp.Symbol("_w"), sp.Symbol("_s")
    total = sp.Symbol("_T")
    omega = [_float(c) for c in mode.omega()[: order + 1]]
    period = mode.period()
    tau = [_float(c) for c in period[: order + 1]]
    found = radius(mode)
    if found is not None and not found.lower > 0 and not allow_divergent:
        raise InputError(f"mode {mode.mode} of {mode.system.text!r}: the radius of "
                         f"convergence of its ω series has no positive lower bound "
                         f"({found.how}): every amplitude would be NaN; derive a longer "
                         "series (--order) or emit it unguarded with --allow-divergent")
    reach = None if found is None or not found.lower > 0 else sp.Float(found.lower, 17)
    guard = sp.true if reach is None or allow_divergent else sp.Abs(y) < reach
    entry, inside = argument_entry(((A, sp.Abs(A) < sp.Float(1e150), 0),), "_inside")
    prelude = (*entry, (y, A**mode.step))
    entry_t, inside_t = argument_entry(((A, sp.Abs(A) < sp.Float(1e150), 0),
                                        (t, sp.Abs(t) <= NNM_ARGUMENT_LIMIT, 0)), "_inside")
    prelude_t = (*entry_t, (y, A**mode.step))
    if allow_divergent:
        where = "no radius guard: --allow-divergent"
    elif reach is None:
        where = "no radius estimate: the series is too short or ends"
    else:
        where = ("NaN beyond the lower bound of the radius of convergence estimated from the "
                 "exact ω_j")
    estimate = tail_bound(sp.Abs(_float(period[order + 1])), sp.Abs(_float(period[order + 2])),
                          order, y, [] if reach is None else [reach]) / sp.Abs(total)
    evaluators = [
        Evaluator("omega", f"Frequency ω(A) of mode {mode.mode} to order {order} ({where}).",
                  (A,), prelude, sp.And(inside, guard), (), horner(omega, y)),
        Evaluator("period", f"Period T(A) = 2π Σ τ_j y^j to order {order} ({where}).",
                  (A,), prelude, sp.And(inside, guard), (), 2 * sp.pi * horner(tau, y)),
    ]
    for i, coordinate in enumerate(coordinates):
        orders = mode.coordinate(i, order)
        top = max((max(o) for o in orders if o), default=1)
        lines, cos_of, _ = harmonics(top, mode.step == 2, s, sines=False)
        shape = sum(horner([_float(o.get(n, 0)) for o in orders], y) * cos_of[n]
                    for n in range(top + 1) if any(n in o for o in orders))
        evaluators.append(Evaluator(
            coordinate, f"{coordinate}(t, A) in mode {mode.mode}, s = ωt, harmonics by the "
            f"Chebyshev recurrence ({where}).", (t, A), prelude_t, sp.And(inside_t, guard),
            ((w, horner(omega, y)), (s, w * t), *lines), A * shape))
    evaluators.append(Evaluator(
        "error_estimate",
        "Relative truncation error of period() (and, to first order, of omega()), a bound on "
        "the omitted tail: |τ_{K+1}| |y|^(K+1) + c |y|^(K+2) / (1 - r|y|), its terms growing "
        "at most by r = max(1/R, |τ_{K+2}/τ_{K+1}|) an order, R the radius' lower bound, "
        "c = max(|τ_{K+2}|, r|τ_{K+1}|); over the truncated sum (inf from r|y| = 1 on: no "
        f"bound there; {where}).",
        (A,), prelude, sp.And(inside, guard), ((total, horner(tau, y)),), estimate))
    constants = (
        ("ORDER", order),
        ("MODE", mode.mode),
        ("MODEL", name),
        ("SYSTEM", mode.system.text),
        ("VARIABLE", mode.variable),
        ("OMEGA0", float(_float(mode.omega0))),
        ("OMEGA0_EXACT", str(mode.omega0)),
        ("RADIUS", float("nan") if found is None else found.estimate),
        ("RADIUS_SPREAD", float("nan") if found is None else found.spread),
        ("RADIUS_LOWER", float("nan") if found is None else found.lower),
        ("ALLOW_DIVERGENT", allow_divergent),
        ("OMEGA_EXACT", tuple(str(c) for c in mode.omega()[: order + 1])),
        ("PERIOD_EXACT", tuple(str(c) for c in period[: order + 1])),
    )
    return Module(
        name=name,
        doc=f"Nonlinear normal mode {mode.mode} of {mode.system.text}: L–P evaluators to "
        f"order {order} in {mode.variable}.",
        constants=constants,
        evaluators=tuple(evaluators),
        provenance=provenance(name, order, command, system=mode.system.text, mode=mode.mode,
                              amplitude=coordinates[mode.amplitude],
                              allow_divergent=allow_divergent),
    )


def mode_tables(mode: NormalModeSeries, order: int, name: str) -> ModeTables:
    """The LaTeX tables' record of ``mode`` to ``order``: ω and T over their linear values,
    every coordinate's coefficients, the equations with their accelerations as ẍ."""
    system = mode.system
    dots = [sp.Symbol(rf"\ddot{{{sp.latex(x)}}}") for x in system.coordinates]
    L = system.stiffness * sp.Matrix(system.coordinates)
    equations = tuple(sp.expand(dots[i] + L[i] + system.force[i])
                      for i in range(system.size))
    w0 = mode.omega0
    return ModeTables(
        name, mode.mode, equations, w0, sp.Symbol("A") ** mode.step, order,
        tuple(mode.omega_over_omega0()[: order + 1]),
        tuple(mode.period_times_omega0()[: order + 1]),
        tuple((x, tuple(tuple(sorted(o.items())) for o in mode.coordinate(i, order)))
              for i, x in enumerate(system.coordinates)),
        system.coordinates[mode.amplitude])


def mode_derivation(mode: NormalModeSeries, order: int, name: str) -> ModeDerivation:
    """The derivation's record of ``mode`` to ``order``: at each order ``j`` the right sides
    ``R_jn`` and solutions ``c_jn`` per harmonic, and ``Ω_j`` from ``ψ·(R_j1 + Ω_j φ) = 0``."""
    system = mode.system
    exact = mode.ground.to_sympy
    dots = [sp.Symbol(rf"\ddot{{{sp.latex(x)}}}") for x in system.coordinates]
    L = system.stiffness * sp.Matrix(system.coordinates)
    equations = tuple(sp.expand(dots[i] + L[i] + system.force[i])
                      for i in range(system.size))
    zero = mode.ground.scalar(0)
    orders = []
    for j in range(1, min(order, len(mode.right_sides)) + 1):
        rhs = mode.right_sides[j - 1]
        solved = mode.coefficients[j]
        harmonics = sorted(set(rhs) | {n for c in solved for n in c})
        secular = sum((p * r for p, r in zip(mode.left, rhs.get(1, ()), strict=False)), zero)
        orders.append(ModeOrder(
            j, exact(mode.omega_squared[j]), exact(secular),
            tuple((n, tuple(exact(r) for r in rhs.get(n, (zero,) * system.size)),
                   tuple(exact(c.get(n, zero)) for c in solved)) for n in harmonics)))
    return ModeDerivation(
        name, mode.mode, equations, system.stiffness, mode.lam,
        sp.Symbol("A") ** mode.step, system.coordinates[mode.amplitude], system.coordinates,
        tuple(exact(c.get(1, zero)) for c in mode.coefficients[0]),
        tuple(exact(v) for v in mode.left), tuple(orders))
