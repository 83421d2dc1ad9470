"""Lowering the exact series: a family of periodic orbits of any number of coordinates (a free
oscillator's ω, T, q and q̇ with its orbit domain, a nonlinear normal mode's backbone and
shape; the radius guard, the truncation error's bound), limit cycles, their resummations,
Mathieu's characteristic values and Hill's tongues."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction

import sympy as sp

from ..algebra.resum import Pade, Resummed
from ..derive.cycles import LimitCycle
from ..derive.lindstedt import SeriesSolution, estimated_radius, nearest_singularity
from ..derive.models import Model
from ..derive.nnm import NormalModeSeries
from ..derive.nnm import radius as mode_radius
from ..derive.orbits import orbit_domain, runtime_barrier, runtime_scan
from ..errors import InputError
from ..numerics.references import mathieu_recurrence
from .forms import (
    FREE_ARGUMENT_LIMIT,
    _hex,
    argument_entry,
    check_emitted_names,
    free_ranges,
    harmonics,
    horner,
    scaled_variable,
    tail_bound,
)
from .printers import exact, exact_text, identifier, scaled
from .records import (
    Assign,
    Evaluator,
    Module,
    ResummedCycle,
    ResummedMathieu,
    ResummedTongue,
    one_line,
    provenance,
)


class OrbitInside(sp.Function):
    """``_orbit_inside(A, ε)`` of a module with a :class:`RuntimeBarrier`: 1 where the orbit
    through ``q(0) = A`` exists at that ε, else 0 (the template's compiled root-finder)."""

    def _numbacode(self, printer) -> str:
        return f"_orbit_inside({', '.join(printer._print(a) for a in self.args)})"


class OrbitReach(sp.Function):
    """``_orbit_reach(A, ε)``: the distance from ε = 0 to the nearest ε (either sign) where
    the orbit through ``A`` stops existing — a singularity of T(ε) at that A."""

    def _numbacode(self, printer) -> str:
        return f"_orbit_reach({', '.join(printer._print(a) for a in self.args)})"


@dataclass(frozen=True)
class Reach:
    """How far a series' evaluators answer: ``bound``, the radius of convergence's lower bound
    in ``y`` the guard holds ``|y|`` below (None: no radius to guard), the radius stated
    (``radius``, ``spread``; NaN where unknown), ``lower`` where the bound is stated apart
    from them, ``noun`` (what the bound is, in words) and ``empty``, why no amplitude would
    be inside (then the lowering refuses unless the series may diverge)."""

    bound: sp.Expr | None
    radius: float
    spread: float
    noun: str
    lower: float | None = None
    empty: str = ""


@dataclass(frozen=True)
class PeriodicSeries:
    """A family of periodic orbits as its L–P series, for any number of coordinates: what the
    lowering and the documents read of a free oscillator's :class:`SeriesSolution` (one
    coordinate, §10.3's q = A Σ_j y^j q_j(s)) or of a nonlinear normal mode's
    :class:`NormalModeSeries` (x_i = A Σ_j y^j Σ_n c cos ns), exact, summed to ``order``.

    ``omega[j]`` and ``tau[j]`` are ω_j (ω₀ included) and τ_j of T/2π (to ``order + 2``: the
    truncation error's two terms); ``coordinates`` each coordinate's ``{n: c}`` of
    ``cos ns`` per order; ``y`` the expansion variable in the ``parameters`` (the arguments
    after ``t``: ``A`` for a mode, ``A, eps, …`` for an oscillator).  A free oscillator adds
    ``model`` (its analytic force, for the first integral's orbit domain) with ``to_args``
    (its symbols as the arguments) and its velocity ``qdot``; a mode adds ``identity``, the
    constants naming it."""

    name: str
    title: str
    order: int
    variable: str
    convention: str
    y: sp.Expr
    amplitude: sp.Expr
    parameters: tuple[sp.Symbol, ...]
    omega: tuple[sp.Expr, ...]
    tau: tuple[sp.Expr, ...]
    coordinates: tuple[tuple[str, tuple[dict[int, sp.Expr], ...]], ...]
    odd: bool
    reach: Reach
    inputs: dict
    identity: tuple[tuple[str, object], ...] = ()
    model: Model | None = None
    to_args: dict | None = None


MODE_CONVENTION = "at t = 0 every velocity is zero and {a}(0) = A (a turning point)"
# NOTE: a normal mode's amplitude convention (the free oscillator's is its own CONVENTION).


def periodic_series(series: SeriesSolution | NormalModeSeries, order: int | None = None,
                    name: str | None = None) -> PeriodicSeries:
    """The :class:`PeriodicSeries` of a free oscillator's ``SeriesSolution`` (summed to its
    order less 2 unless ``order``) or a normal mode's ``NormalModeSeries`` (``name`` the
    module's; its radius from :func:`derive.nnm.radius`)."""
    if isinstance(series, SeriesSolution):
        m, g = series.model, series.ground
        order = series.order - 2 if order is None else order
        args = {p: sp.Symbol(identifier(p)) for p, _ in m.parameters}
        to_args = {sym: args[p] for p, sym in m.parameters}
        found = (m.radius, 0.0) if m.radius is not None else estimated_radius(
            series, to_args, lambda c: exact(g, c))
        radius, spread = found if found is not None else (None, 0.0)
        reach = Reach(
            None if radius is None else radius - sp.Float(spread, 17) if spread else radius,
            float(radius) if radius is not None and radius.is_number else float("nan"),
            float(spread), "the radius of convergence" + (
                "" if m.radius is not None else " less its spread, estimated from its τ_j"))
        return PeriodicSeries(
            m.name, m.title, order, m.variable, series.convention, m.y.xreplace(to_args),
            m.amplitude.xreplace(to_args), tuple(args.values()),
            tuple(scaled(m.frequency, exact(g, c)) for c in series.omega[: order + 1]),
            tuple(scaled(1 / m.frequency, exact(g, c)) for c in series.period[: order + 3]),
            ((identifier(str(m.coordinate)),
              tuple({n: exact(g, c) for n, c in qj.items()} for qj in series.q[: order + 1])),),
            m.odd, reach,
            {"forcing": [[(n, str(c)) for n, c in terms] for terms in m.forcing[: order + 2]],
             **({"elementary": [(n, str(a), str(w)) for n, a, w in m.elementary]}
                if m.elementary else {}),
             **({"equation": m.source, "frequency": str(m.frequency), "given": m.given,
                 "velocity_forcing": [[(a, b, str(c)) for a, b, c in terms]
                                      for terms in m.velocity_forcing[: order + 2]]}
                if m.source else {})},
            model=m, to_args=to_args)
    system = series.system
    order = series.order - 2 if order is None else order
    name = name or f"mode{series.mode}"
    names = [identifier(str(x)) for x in system.coordinates]
    A = sp.Symbol("A")
    found = mode_radius(series)
    positive = found is not None and found.lower > 0
    reach = Reach(
        sp.Float(found.lower, 17) if positive else None,
        float("nan") if found is None else found.estimate,
        float("nan") if found is None else found.spread,
        "the lower bound of the radius of convergence estimated from the exact ω_j",
        float("nan") if found is None else found.lower,
        "" if found is None or positive else found.how)
    return PeriodicSeries(
        name, f"Nonlinear normal mode {series.mode} of {system.text}", order, series.variable,
        MODE_CONVENTION.format(a=names[series.amplitude]), A**series.step, A, (A,),
        tuple(series.omega()[: order + 1]), tuple(series.period()[: order + 3]),
        tuple((x, tuple(series.coordinate(i, order))) for i, x in enumerate(names)),
        series.step == 2, reach,
        {"system": system.text, "mode": series.mode, "amplitude": names[series.amplitude]},
        identity=(("MODE", series.mode), ("SYSTEM", system.text),
                  ("OMEGA0", float(sp.N(series.omega0, DIGITS))),
                  ("OMEGA0_EXACT", str(series.omega0))))


DIGITS = 30
# NOTE: an irrational coefficient (in Q(√λ) or Q(λ)) reaches the module as the double nearest
# its 30-digit value; a rational one, or a polynomial in parameters, as itself (the printer
# rounds each number once).


def _rounded(c: sp.Expr) -> sp.Expr:
    """``c`` as the module receives it (:data:`DIGITS`)."""
    return sp.Float(sp.N(c, DIGITS), 17) if c.is_number and not c.is_Rational else c


def lower_periodic(series: SeriesSolution | NormalModeSeries, command: str,
                   order: int | None = None, name: str | None = None,
                   allow_divergent: bool = False) -> Module:
    """Evaluators ``omega``, ``period``, each coordinate's motion ``x(t, …)`` (a free
    oscillator's velocity ``xdot`` too) and ``error_estimate`` of a family of periodic orbits
    (:func:`periodic_series`), summed to ``order`` (default: the series' order less 2).

    The series must be derived two orders above it: ``τ_{K+1}``, ``τ_{K+2}`` feed the error's
    bound.  Outside the arguments' ranges, outside the orbit domain (a free oscillator's first
    integral, where known) and beyond the radius' lower bound (unless ``allow_divergent``)
    every evaluator returns NaN; a bound that leaves no amplitude is refused."""
    p = periodic_series(series, order, name)
    order = p.order
    if order < 0 or len(p.tau) < order + 3:
        raise ValueError("lower_periodic needs a series derived to order K + 2")
    m, reach = p.model, p.reach
    if reach.empty and not allow_divergent:
        raise InputError(f"{p.title}: the radius of convergence of its ω series has no "
                         f"positive lower bound ({reach.empty}): every amplitude would be NaN; "
                         "derive a longer series (--order) or emit it unguarded with "
                         "--allow-divergent")
    velocities = m is not None
    names = [x for x, _ in p.coordinates]
    params = p.parameters
    check_emitted_names(names, [str(a) for a in params], velocities)
    user = {*names, *(x + "dot" for x in names if velocities), *map(str, params)}
    # a user's name keeps its meaning: an internal name it would shadow takes a leading '_'
    # (which no user name has); the built-in models keep x, w, s, T, byte for byte
    x, w, s, total = (sp.Symbol(n if n not in user else "_" + n) for n in ("x", "w", "s", "T"))
    omega = [_rounded(c) for c in p.omega]
    tau = [_rounded(c) for c in p.tau]
    t = sp.Symbol("t")
    guard: sp.Basic = sp.true
    edges: list[sp.Expr] = []
    barrier = scan = None
    where = ""
    if m is not None:  # the first integral's orbit domain: one coordinate's
        guard = m.orbit_condition.xreplace({sp.Symbol("Y"): x})
        domain = orbit_domain(m)
        barrier = None if domain.known else runtime_barrier(m)
        others = tuple(a for a in params if a != p.amplitude)  # the arguments but A
        scan = None if domain.known or barrier is not None else runtime_scan(
            m, p.to_args, others, p.y, p.amplitude)
        at = None
        if barrier is not None:  # the edge at each (A, ε): the first integral's, at run time
            at = (p.amplitude, p.y)
        elif scan is not None:  # the edge at each call, its parameters' values in hand
            at = (p.amplitude, *others)
        if at is not None:
            guard = sp.And(guard, sp.StrictGreaterThan(OrbitInside(*at), 0))
            edges.append(OrbitReach(*at))
        lo, hi = domain.guard_bounds()
        if math.isfinite(lo):
            guard = sp.And(guard, x > sp.Float(lo, 17))
        if math.isfinite(hi):
            guard = sp.And(guard, x < sp.Float(hi, 17))
        edges[:0] = [sp.Float(v, 17) for v in (-domain.lower, domain.upper) if math.isfinite(v)]
        where = (
            "NaN where no periodic orbit exists" if domain.known else
            "NaN where no periodic orbit exists (the orbit domain at each eps: the first "
            "integral's barrier, the zeros of its force found at run time)"
            if barrier is not None else
            "NaN where no periodic orbit exists (the orbit domain at each call: the first "
            "integral's barrier, the zeros of the force nearest 0 scanned for at run time "
            "on |q| <= 64)" if scan is not None else
            f"NaN where no periodic orbit exists as far as known: no orbit domain ({domain.how})")
    guarded = reach.bound is not None and not allow_divergent
    if guarded:
        guard = sp.And(guard, sp.Abs(x) < reach.bound)
    if where:
        where += f" or beyond {reach.noun}" if guarded else ""
    else:
        where = (f"NaN beyond {reach.noun}" if guarded else
                 "no radius guard: --allow-divergent" if allow_divergent else
                 "no radius estimate: the series is too short or ends")
    scaled = scaled_variable(p.y, params, x)
    steps, ranges = scaled if scaled is not None else (((x, p.y),), free_ranges(p.y, params))
    flag = "inside" if "inside" not in user else "_inside"
    entry, inside = argument_entry(ranges, flag)
    prelude = (*entry, *steps)
    entry, inside_t = argument_entry((*ranges, (t, sp.Abs(t) <= FREE_ARGUMENT_LIMIT, 0)), flag)
    prelude_t = (*entry, *steps)
    guard, guard_t = sp.And(inside, guard), sp.And(inside_t, guard)
    frequency = horner(omega, x)
    motions: list[Evaluator] = []
    for coordinate, orders in p.coordinates:
        top = max((max(o) for o in orders if o), default=1)
        harmonic = {n: horner([_rounded(o.get(n, sp.Integer(0))) for o in orders], x)
                    for n in range(top + 1)}
        harmonic = {n: h for n, h in harmonic.items() if h != 0}
        cos_lines, cs, _ = harmonics(top, p.odd, s, sines=False)
        motions.append(Evaluator(
            coordinate,
            f"{coordinate}(t) with s = ωt, harmonics by the Chebyshev recurrence ({where}).",
            (t, *params), prelude_t, guard_t, ((w, frequency), (s, w * t), *cos_lines),
            p.amplitude * sum(h * cs[n] for n, h in sorted(harmonic.items()))))
        if velocities:
            both_lines, _, ss = harmonics(top, p.odd, s, sines=True)
            motions.append(Evaluator(
                f"{coordinate}dot", f"d{coordinate}/dt ({where}).", (t, *params), prelude_t,
                guard_t, ((w, frequency), (s, w * t), *both_lines),
                -p.amplitude * w * sum(n * h * ss[n] for n, h in sorted(harmonic.items()))))
    limits = ([] if reach.bound is None else [reach.bound]) + edges
    estimate = tail_bound(sp.Abs(tau[order + 1]), sp.Abs(tau[order + 2]), order, x,
                          limits) / sp.Abs(total)
    radius_words = ("the smaller of the radius less its spread and the distance to the "
                    "orbits' edge" if m is not None else "the radius' lower bound")
    evaluators = (
        Evaluator("omega", f"Frequency ω to order {order} ({where}).", params, prelude, guard,
                  (), frequency),
        Evaluator("period", f"Period T = 2π Σ τ_j y^j to order {order} ({where}).", params,
                  prelude, guard, (), 2 * sp.pi * horner(tau[: order + 1], x)),
        *motions,
        Evaluator(
            "error_estimate",
            "Relative truncation error of period(), a bound on the omitted tail: "
            "|τ_{K+1}| |y|^(K+1) + c |y|^(K+2) / (1 - r|y|), its terms growing at most by "
            f"r = max(1/R, |τ_{{K+2}}/τ_{{K+1}}|) an order, R {radius_words}, "
            "c = max(|τ_{K+2}|, r|τ_{K+1}|); over the truncated sum (inf from r|y| = 1 on: no "
            "bound there).",
            params, prelude, guard, ((total, horner(tau[: order + 1], x)),), estimate,
        ),
    )
    numeric: tuple = ()  # the coefficients as floats, where they are numbers
    if all(c.is_number for c in (*p.omega, *p.tau)):
        numeric = (("OMEGA", tuple(float(c) for c in p.omega)),
                   ("PERIOD", tuple(float(c) for c in p.tau[: order + 1])))
        if len(p.coordinates) == 1:  # Q[j][n]: the one coordinate's cos ns in y^j
            orders = p.coordinates[0][1]
            top = max((max(o) for o in orders if o), default=1)
            numeric += (("Q", tuple(tuple(float(o.get(n, 0)) for n in range(top + 1))
                                    for o in orders)),)
    domain_constants: tuple = ()
    if m is not None:
        domain_constants = (("ORBIT_LIMIT", (domain.lower, domain.upper)),
                            ("ORBIT_LIMIT_EXACT", (domain.lower_text, domain.upper_text)))
    constants = (
        ("ORDER", order),
        ("MODEL", p.name),
        ("VARIABLE", p.variable),
        ("CONVENTION", p.convention),
        ("RADIUS", reach.radius),
        ("RADIUS_SPREAD", reach.spread),
        *(() if reach.lower is None else (("RADIUS_LOWER", reach.lower),)),
        *domain_constants,
        ("ALLOW_DIVERGENT", allow_divergent),
        *numeric,
        ("OMEGA_EXACT", tuple(exact_text(c) for c in p.omega)),
        ("PERIOD_EXACT", tuple(exact_text(c) for c in p.tau[: order + 1])),
        *(() if barrier is None else (("ORBIT_BARRIER_EXACT", barrier.exact),)),
        *(() if barrier is None or not barrier.weight else
          (("ORBIT_WEIGHT_EXACT", barrier.weight_exact),)),
        *p.identity,
    )
    return Module(
        name=p.name,
        doc=f"{p.title}: L–P evaluators to order {order} in {p.variable}.",
        constants=constants,
        evaluators=evaluators,
        barrier=() if barrier is None else barrier.coefficients,
        barrier_weight=() if barrier is None else barrier.weight,
        scan=scan,
        provenance=provenance(p.name, order, command, allow_divergent=allow_divergent,
                              **p.inputs),
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
        ("OMEGA_EXACT", tuple(exact_text(c) for c in omega)),
        ("PERIOD_EXACT", tuple(exact_text(c) for c in tau)),
        ("AMPLITUDE_EXACT", tuple(exact_text(c) for c in amp)),
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
