"""What each command costs: an estimate of its wall time from its own measured fit, and the
bounds of what it accepts.  The command line asks :data:`COSTS` before it runs a command and
refuses above :data:`COST_LIMIT_SECONDS` unless ``--allow-slow`` is given.

Every fit was measured on the project's 2-core reference machine; `benchmarks/command_costs.py`
runs the commands and prints each estimate beside the measured time (docs/benchmarks.md).
Nothing heavy is imported here: the estimators of cheap commands answer in microseconds, and
those that need a stage (the response curve's length, a sweep's kind) import it themselves,
as the command they precede would.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from .errors import InputError
from .limits import (
    COST_LIMIT_SECONDS,
    DRIVE_POINT_SECONDS,
    DRIVEN_MAX_ORDER,
    EXCHANGE_MAX_STEPS,
    GENERATE_MAX_ORDER,
    MAX_DRIVE_POINTS,
    PERIOD_SERIES_ORDER,
    SLOW_FLOW_MAX_ORDER,
    SLOW_LIMIT_SECONDS,
)


@dataclass(frozen=True)
class Cost:
    """A command's estimated wall time, and the input it grows with (named in a refusal)."""

    seconds: float
    subject: str  # e.g. "order 200", "--harmonics 60", "a 10⁶-point grid"
    what: str  # e.g. "the μ-expansion", "generating duffing"

    def refusal(self) -> str:
        """The one-line refusal: the input, the estimated time of the work, and
        ``--allow-slow`` to run it anyway (past :data:`limits.SLOW_LIMIT_SECONDS`, that
        nothing runs it)."""
        about = (f"about {self.seconds:,.0f} s" if self.seconds < 1e7
                 else f"about {self.seconds:.1e} s" if math.isfinite(self.seconds)
                 else "more than 1e300 s")
        if self.seconds > SLOW_LIMIT_SECONDS:
            return (f"{self.subject}: {about} of {self.what} on this machine, past the week "
                    "that --allow-slow admits")
        return (f"{self.subject}: {about} of {self.what} on this machine; pass --allow-slow "
                "to run it")


def power_law(fixed: float, at_reference: float, reference: float, growth: float | str,
              size: float) -> float:
    """``fixed + at_reference · (size/reference)^growth`` seconds, or, for a string ``growth``
    (the base per unit of size), ``fixed + at_reference · growth^(size − reference)``; inf
    where that overflows."""
    if size > 1e100:  # an order of a hundred digits: inf s (and no float overflow below)
        return math.inf
    if isinstance(growth, str):
        log = math.log(at_reference) + (size - reference) * math.log(float(growth))
    else:
        log = math.log(at_reference or 1e-300) + growth * (math.log(max(size, 1))
                                                           - math.log(reference))
    return fixed + (math.exp(log) if log < 700 else math.inf)


SERIES_COSTS = {
    "duffing": (0.9, 13.6, 300, 3.5),
    "pendulum": (0.9, 2.0, 100, 3.2),
    "oscillator": (0.9, 22.0, 100, 4.6),
}
# NOTE: `lindstedt series MODEL --order K` (start-up, then derive): Duffing grows like K^3.5
# (13.6 s at K = 300); the pendulum (sin by recurrence) like K^3.2; a user's oscillator is
# bounded by the Taylor route (one power table per term, like K^4.6: 22 s at K = 100).

GENERATE_COSTS = {
    # model: (fixed s, s at the reference size, reference size, growth: power, or "exp" base)
    "duffing": (1.2, 1.3, 100, 2.3),
    "pendulum": (1.2, 2.15, 100, 2.9),
    "oscillator": (1.2, 2.15, 100, 2.9),
    "balance": (1.0, 17.8, 12, 3.5),
    "fourier": (1.0, 0.0, 60, 1.0),
    "driven": (12.0, 29.0, 5, "6"),
    "driven_damped": (2.0, 53.0, 6, "1.8"),
}
# NOTE: wall time of `lindstedt generate MODEL` (derive, lower, print, compile) against its size
# (--order; --harmonics for balance and fourier), each fitted to its own runs; duffing, pendulum,
# balance and fourier refitted once polynomials printed as one node (duffing 1.3, 1.7, 2.5,
# 3.6 s at orders 20, 60, 100, 130; pendulum 1.3, 1.8, 2.3, 3.4, 4.7 s at 20, 60, 80, 100, 120;
# balance 1.1, 1.5, 5.3, 18.8 s at 2, 4, 8, 12 harmonics; load ~1.5 on 2 cores).  driven_damped
# (`generate driven --damped`): 5.7 s at order 2, 16 at 4, 55 at 6 (load 5 on 2 cores).

DRIVEN_COSTS = (3.0, 13.3, 100, 3.5)
# NOTE: `lindstedt driven --order K`: start-up, the numba kernels from cache, balance and
# shooting on every branch (~3 s, whatever --harmonics up to 100 says), then the numerical
# μ-expansion to order K on every branch: 16 s at K = 100, 57 s at 150, undamped or not.

FIXED_COSTS = {
    "models": 1.0,
    "subharmonic": 6.0,
    "mixing": 12.0,
    "clock": 5.0,
    "scene": 12.0,
    "choose period": 10.0,
    "choose q": 20.0,
    "choose amplitudes": 12.0,
    "choose response": 12.0,
    "choose cycle": 60.0,
    "choose mathieu": 30.0,
    "choose backbone": 15.0,
}
# NOTE: commands whose work no input scales (bounded by the inputs' own bounds: at most four
# drives, a fixed set of candidates and verification points): their wall time at most, from
# benchmarks/command_costs.py (measured 3.3–14.6 s under load).

RESPONSE_FIXED = 6.0
# NOTE: `lindstedt response` before its problem is known (a flag missing: the command says
# which): start-up; with the problem, analysis.systems.response_plan estimates the work.

SWEEP_START = 15.0
# NOTE: start-up, a LocalCluster's start and warm-up, the store (15–17 s measured for small
# grids on the loaded machine), on top of the points' work.


def _fit(table: dict, model: str) -> tuple:
    """A named model's own fit, else the one for a user's oscillator."""
    return table.get(model, table["oscillator"])


LIMIT_CYCLE_FIT = (0.9, 50.0, 164, 4.8)
# NOTE: `series` of a limit cycle (van der Pol, relaxed ε-products; CPU seconds, which are the
# wall time of a quiet machine): 0.55 at order 60, 6.2 at 100, 28 at 130, 50 at 164
# (benchmarks/limit_cycle.py); a minute buys order 169.
SYMBOLIC_FIT = (0.0, 1.7, 30, 4.0)
# NOTE: a series in ε with coefficients in QQ[A, α] (Helmholtz–Duffing, α symbolic): 0.29 s at
# order 20, 1.7 at 30, 4.8 at 40 under load; each further symbol 1.5× (α, β: 2.0 s at 30).


def oscillator_seconds(text: str, pairs: list[str] | None, order: int) -> float:
    """Estimated derivation time of a user's equation at ``order``: the Duffing fit scaled by
    its force's degree d (polynomials ~(d−1)/2 times longer, ~((d−1)/2)³ dearer: ``eps*q**63``
    to order 40, 4.4 min, is estimated at 6.5), the symbolic fit when coefficients stay
    polynomials in A or parameters, the Taylor route's fit for a non-polynomial force.  The
    equation is parsed here (its errors come first, as the command's own)."""
    import sympy as sp

    from .derive.equation import SMALL, parse_equation

    eq = parse_equation(text)
    q, v, a = eq.derivatives
    force = sp.expand(eq.expression.xreplace({a: 0}))
    if not force.is_polynomial(q, v):
        if force.has(sp.sin, sp.sinh) and not force.has(sp.exp, sp.log, sp.sqrt, sp.cos,
                                                        sp.cosh, sp.tanh):
            return power_law(*SERIES_COSTS["pendulum"], order)
        return power_law(*SERIES_COSTS["oscillator"], order)
    poly = sp.Poly(force, q, v)
    if _has_odd_velocity(poly):  # its limit cycles
        return power_law(*LIMIT_CYCLE_FIT, order)
    degree = max(1, poly.total_degree())
    scale = max(1.0, ((degree - 1) / 2) ** 3)
    given = {pair.partition("=")[0].strip() for pair in pairs or ()}
    free = [p for p in eq.parameters if str(p) not in given]
    small = [] if eq.small is None or SMALL in given else [eq.small]
    powers = {sum(m) - 1 for m in poly.monoms() if sum(m) > 1}
    symbols = len(free) + (1 if small and len(powers) > 1 else 0)
    if symbols:
        return 0.9 + power_law(*SYMBOLIC_FIT, order) * 1.5 ** (symbols - 1) * scale
    fixed, *fit = SERIES_COSTS["duffing"]
    return fixed + power_law(0.0, *fit, order) * scale


def _has_odd_velocity(poly: object) -> bool:
    """A term odd in q': the oscillator is self-excited (``series`` derives its limit cycles)."""
    return any(b % 2 for _, b in poly.monoms())


def limit_cycle_text(model: str) -> str | None:
    """The equation of ``model`` (a registry name or a user's text) when its force is a
    polynomial with a term odd in q' (a limit cycle's), else None; unparsable text is None
    (the command's own parse reports it)."""
    import sympy as sp

    from .derive.equation import parse_equation
    from .derive.models import registry_entry
    from .errors import InputError

    entry = registry_entry(model) if model.isidentifier() else None
    text = entry.equation if entry else model
    try:
        eq = parse_equation(text)
    except InputError:
        return None
    q, v, a = eq.derivatives
    force = sp.expand(eq.expression.xreplace({a: 0}))
    if not force.is_polynomial(q, v):
        return None
    return text if _has_odd_velocity(sp.Poly(force, q, v)) else None


CYCLE_CHECKS = 25.0
# NOTE: `generate` of a limit cycle derives its series to at least methods.RADIUS_ORDER and
# shoots the cycle (DOP853) at the resummed evaluators' check points (methods.resum_cycle):
# 24 s and 26 s wall at orders 12 and 58 (load 2–3), everything but the derivation.  The
# verified range and so the checks grow with the order (ε ≤ 2.98 from order 60, 5.18 from 128,
# where a run took 337 s at load 7, with Padé in w; the relaxation form reaches 3.75 and 10):
# scaled by (order/60)².


def series_cost(args: argparse.Namespace) -> Cost:
    """``series``: the model's own fit at ``--order`` (Duffing, pendulum), else the
    estimated derivation of its equation (:func:`oscillator_seconds`)."""
    if args.model in SERIES_COSTS:
        seconds = power_law(*SERIES_COSTS[args.model], args.order)
    elif args.model.isidentifier():  # another registry name: its equation is known
        from .derive.models import registry_entry

        entry = registry_entry(args.model)
        seconds = (oscillator_seconds(entry.equation, args.param, args.order) if entry
                   else power_law(*SERIES_COSTS["oscillator"], args.order))
    else:
        seconds = oscillator_seconds(args.model, args.param, args.order)
    name = args.model if args.model in SERIES_COSTS else "the oscillator"
    return Cost(seconds, f"order {args.order}", f"derivation for {name}")


def generate_seconds(model: str, size: int) -> float:
    """Estimated wall time of ``lindstedt generate MODEL`` at ``size`` (GENERATE_COSTS)."""
    return power_law(*_fit(GENERATE_COSTS, model), size)


def _generate_bounds(args: argparse.Namespace) -> None:
    """generate's bounds, for every method: no switch lifts them."""
    if args.model == "driven" and args.order > DRIVEN_MAX_ORDER:
        raise InputError(f"order {args.order}: the exact μ-expansion is emitted up to order "
                         f"{DRIVEN_MAX_ORDER} (its rational functions grow fast)")
    if args.model not in ("driven", "balance", "fourier") and args.order > GENERATE_MAX_ORDER:
        raise InputError(f"order {args.order}: generate stops at order {GENERATE_MAX_ORDER} (numba "
                         "compiles that module in about a minute on its first import); "
                         "`lindstedt series` derives higher orders")


def generate_mode_cost(args: argparse.Namespace) -> Cost:
    """``generate SYSTEM --mode M``: the normal mode's series to the radius order, emitted."""
    from .methods.targets import NNM_RADIUS_ORDER

    if getattr(args, "ssm", None) is not None:
        return ssm_cost(args, emitted=True)
    _generate_bounds(args)
    series = nnm_cost(argparse.Namespace(system=args.model,
                                         order=max(args.order + 2, NNM_RADIUS_ORDER)))
    return Cost(series.seconds + generate_seconds("duffing", args.order), series.subject,
                "generating the normal mode's evaluators")


SSM_FIT = (1.5, 4.6e-5, 12.0)
# NOTE: `lindstedt ssm`: start-up, then ~4.6e-5 s per coordinate and squared order (sparse
# solves and force products): chains of 1 000 masses at order 7 took 1.4 s, of 10 000 at
# order 5 6.3 s, of 10⁵ at order 5 116 s (the fit); a beam of 2 997 coordinates at order 7
# 5.0 s; `generate --ssm` adds the module's first numba compile (~12 s).


def _model_size(folder: str) -> int:
    """The coordinates of a model folder, from M.mtx's size line (0 where unreadable: the
    command refuses it itself)."""
    from pathlib import Path

    try:
        with (Path(folder) / "M.mtx").open() as fh:
            for line in fh:
                if not line.startswith("%") and line.strip():
                    return int(line.split()[0])
    except (OSError, ValueError, UnicodeDecodeError):
        pass
    return 0


def ssm_cost(args: argparse.Namespace, emitted: bool = False) -> Cost:
    """``ssm`` (and ``generate --ssm``): :data:`SSM_FIT` in the coordinates and the order."""
    from .derive.problem import read_problem

    folder = getattr(args, "model_dir", None) if emitted else getattr(args, "model", None)
    text = getattr(args, "model" if emitted else "system", None)
    n = _model_size(folder) if folder else (read_problem(text).size if text else 0)
    fixed, per, compile_ = SSM_FIT
    return Cost(fixed + per * n * args.order**2 + (compile_ if emitted else 0.0),
                f"order {args.order}, {n} coordinates", "the spectral submanifold")


def generate_cost(args: argparse.Namespace) -> Cost:
    """Bounds first (no switch lifts them), then the model's own fit."""
    if getattr(args, "ssm", None) is not None or getattr(args, "model_dir", None):
        return ssm_cost(args, emitted=True)
    if args.model is None:
        raise InputError("generate: give an EQUATION or a NAME (or a SYSTEM, or --ssm M with "
                         "--model DIR)")
    _generate_bounds(args)
    harmonic = args.model in ("balance", "fourier")
    size = args.harmonics if harmonic else args.order
    if args.model not in GENERATE_COSTS:  # a user's: its derivation, then Duffing's emission
        derivation = series_cost(argparse.Namespace(model=args.model, param=args.param,
                                                    order=size + 2)).seconds
        if limit_cycle_text(args.model) is not None:
            from .methods.targets import RADIUS_ORDER, cycle_series_order

            resum = getattr(args, "resum_order", None)
            derived = cycle_series_order(size, resum)
            return Cost(power_law(*LIMIT_CYCLE_FIT, derived)
                        + CYCLE_CHECKS * (derived / RADIUS_ORDER) ** 2,
                        f"order {size}" + (f", --resum-order {resum}" if resum else ""),
                        "generating the limit cycle's evaluators")
        return Cost(derivation + generate_seconds("duffing", size), f"order {size}",
                    "generating the oscillator")
    if args.model == "driven" and getattr(args, "damped", False):
        return Cost(generate_seconds("driven_damped", size), f"order {size}",
                    "generating driven --damped")
    return Cost(generate_seconds(args.model, size),
                f"--harmonics {size}" if harmonic else f"order {size}",
                f"generating {args.model if args.model in GENERATE_COSTS else 'the oscillator'}")


DRIVEN_EQUATION_FIXED = 4.0
DRIVEN_EQUATION_CONTINUATION = MAX_DRIVE_POINTS * DRIVE_POINT_SECONDS
# NOTE: `lindstedt driven EQUATION`: start-up with SymPy's parse and the numba kernels from
# cache (~2.5 s), then the continuation in the drive amplitude, which stops itself after
# limits.MAX_DRIVE_POINTS points (12 s at most; 0.1–2 s measured on the documented equations),
# then Newton at N harmonics and shooting (0.05–0.5 s) on every crossing.


def driven_equation_seconds(harmonics: int) -> float:
    """An upper bound of ``driven EQUATION``: the fixed part, the continuation's points,
    and three crossings' Newton solves at N harmonics (up to 4N − 1 unknowns, 50 dense steps
    at ~1 GFlop/s) with their shooting (0.5 s each at most: 4 tries of up to 30 periods)."""
    unknowns = 4 * harmonics - 1
    return (DRIVEN_EQUATION_FIXED + DRIVEN_EQUATION_CONTINUATION
            + 3 * (50 * unknowns**3 / 1e9 + 0.5))


def driven_cost(args: argparse.Namespace) -> Cost:
    """``driven``: for an EQUATION the bound of its continuation, balance and shooting at
    ``--harmonics``; else the μ-expansion's fit at ``--order``."""
    if getattr(args, "model", None) is not None:
        return Cost(driven_equation_seconds(args.harmonics), f"--harmonics {args.harmonics}",
                    "the continuation, balance and shooting of the equation")
    return Cost(power_law(*DRIVEN_COSTS, args.order), f"order {args.order}",
                "the μ-expansion on every branch")


def _values(args: argparse.Namespace) -> dict[str, str]:
    """``--param NAME=VALUE`` pairs as a dict (the command checks them)."""
    values: dict[str, str] = {}
    for pair in args.param or ():
        key, _, value = pair.partition("=")
        values[key.strip()] = value.strip()
    return values


def _count(points: float) -> str:
    """A count a person reads: whole below a million, else two digits and an exponent."""
    return f"{points:.0f}" if points < 1e6 else f"{points:.2g}"


def response_cost(args: argparse.Namespace) -> Cost:
    """``response`` (eq. 10.60 by its flags, an EQUATION or a SYSTEM): the problem lowered
    (refused in one line before anything runs) and its :func:`analysis.systems.response_plan`:
    the continuation, the drive continuations, the Floquet multipliers and the rest, as the
    command will run them (the fixed part alone when ε, f or Q is missing: the command says
    so)."""
    from .analysis.systems import driven_problem, notes_problem, response_plan

    if getattr(args, "model", None) is not None:
        problem = driven_problem(args.model, _values(args), args.name or "oscillator")
    elif any(getattr(args, k, None) is None for k in ("eps", "force", "Q")):
        return Cost(RESPONSE_FIXED, "response", "response")  # the command says what is missing
    else:
        problem, _ = notes_problem(args.eps, args.force, args.Q)
    plan = response_plan(problem, args.harmonics, getattr(args, "omega_min", None),
                         getattr(args, "omega_max", None), ends=True)
    given = "".join(f", --param {pair}" for pair in args.param or ())
    drives = (f", {plan.drives} drive continuations (at most {plan.drive_points} points "
              "each)" if plan.drives else "")
    return Cost(plan.seconds, f"--harmonics {args.harmonics}{given}",
                f"the continuation of about {_count(plan.points)} points{drives}, Floquet "
                "multipliers, bifurcations, simulations and checks")


def sweep_cost(args: argparse.Namespace) -> Cost:
    """The grid's points times its kind's cost per point, over the local workers (a running
    scheduler's workers are not known before connecting: its estimate is the CPU time)."""
    from .sweep.kinds import kind_named

    kind = kind_named(args.kind)
    points = math.prod(len(getattr(args, a) or [0]) for a in kind.axes)
    workers = 1 if args.scheduler else args.workers
    return Cost(SWEEP_START + points * kind.point_seconds / workers,
                f"a grid of {points:,} points", f"{args.kind} sweep on {workers} "
                f"worker{'s' * (workers > 1)}")


EQUATION_PARSE = 2.0
# NOTE: an EQUATION given to subharmonic or mixing: SymPy's import and the parse (~1.5 s
# measured), on top of the command's fixed work, which the mapped parameters leave as it is.


def fixed_cost(name: str) -> Callable[[argparse.Namespace], Cost]:
    """The estimator of a command whose work no input scales: its :data:`FIXED_COSTS`
    entry, plus an EQUATION's parse when one is given."""
    def cost(args: argparse.Namespace) -> Cost:
        extra = EQUATION_PARSE if getattr(args, "model", None) is not None else 0.0
        return Cost(FIXED_COSTS[name] + extra, name, name)
    return cost


EMIT_FACTOR = 2.0
# NOTE: `choose amplitudes|response --out` generates a candidate's module, imports (compiles)
# it to judge and time it, and writes it again into --out (the derivation is cached): about
# twice `generate` (order 4: 7.5 s to generate, 17 s to compile, against 17 s estimated).


def emission_seconds(model: str, size: int) -> float:
    """The estimated cost of trying one emitted module in ``choose … --out``."""
    return EMIT_FACTOR * generate_seconds(model, size)


def choose_cost(args: argparse.Namespace) -> Cost:
    """The choice's fixed work, and for the driven quantities with --out the dearest module
    :func:`emit_bounds` lets compete."""
    fixed = FIXED_COSTS[f"choose {args.quantity}"]
    seconds = fixed
    if getattr(args, "model", None) is not None:  # its series to order 60, its quadrature
        seconds += power_law(*SERIES_COSTS["oscillator"], PERIOD_SERIES_ORDER) + QUADRATURE_SECONDS
    if args.out and args.quantity in ("amplitudes", "response"):
        mu, harmonics = emit_bounds(args.allow_slow, EMIT_MAX_HARMONICS, args.quantity)
        seconds += max(emission_seconds("driven", mu), emission_seconds("balance", harmonics))
    return Cost(seconds, f"choose {args.quantity}", "verifying the candidates")


QUADRATURE_SECONDS = 2.0
# NOTE: the quadrature reference on 401 points (0.7 s measured, 1.6 s under load).

EMIT_MAX_HARMONICS = 12
# NOTE: choose.DRIVEN_MAX, restated (a test keeps them equal): the most harmonics a choice tries.


def emit_bounds(allow_slow: bool, max_harmonics: int = EMIT_MAX_HARMONICS,
                quantity: str = "amplitudes") -> tuple[int, int]:
    """The highest μ-order (up to DRIVEN_MAX_ORDER) and the most harmonics (up to
    ``max_harmonics``) whose emitted module ``choose QUANTITY --out`` can try within the cost
    limit, after its fixed work; with ``allow_slow`` every one: what may compete."""
    budget = COST_LIMIT_SECONDS - FIXED_COSTS[f"choose {quantity}"]

    def largest(model: str, top: int) -> int:
        fits = [k for k in range(1, top + 1)
                if allow_slow or emission_seconds(model, k) <= budget]
        return max(fits, default=0)
    return largest("driven", DRIVEN_MAX_ORDER), largest("balance", max_harmonics)


MATHIEU_FIT = (0.4, 0.5, 100, 3.0)
# NOTE: `lindstedt mathieu`: start-up, then K orders of growing exact rationals (0.48 s at 100).


def mathieu_cost(args: argparse.Namespace) -> Cost:
    """``mathieu``: the Mathieu series' fit at ``--order``."""
    return Cost(power_law(*MATHIEU_FIT, args.order), f"order {args.order}",
                "the Mathieu series")


INCE_STRUTT_SECONDS = 20.0
# NOTE: `tongues --plot`: two 400 × 400 Floquet grids (~5 s each, 2 cores) and the curves.
TONGUES_FIT = (0.5, 0.4, 100, 3.0)
# NOTE: `lindstedt tongues`: both curves of p = cos t at order 100 in 0.35 s; the harmonics of
# x_k grow with p's highest harmonic h, the cost as h^2.5 (2.2 s for h = 2 at order 100).

TONGUE_EMIT_SECONDS = 6.0
# NOTE: `tongues --out`: per curve 24 Floquet boundaries at 4096 and 8192 RK4 steps (brentq)
# and the numba compilation on import: 5.4 s for p = cos t + cos 2t/2, n = 1, order 30.


def tongues_cost(args: argparse.Namespace) -> Cost:
    """``tongues``: the fit at ``--order`` times p's highest harmonic to the power 2.5,
    doubled with ``--zeta``, plus ``--plot``'s chart and ``--out``'s checks."""
    from .derive.hill import fourier_of_text

    top = max(fourier_of_text(args.p))
    seconds = power_law(*TONGUES_FIT, args.order) * top**2.5
    if args.zeta is not None:
        seconds *= 2
    if args.plot:
        seconds += INCE_STRUTT_SECONDS
    if getattr(args, "out", None) is not None:
        seconds += TONGUE_EMIT_SECONDS
    return Cost(seconds, f"order {args.order}, harmonic {top}", "the transition curves")


SLOW_FLOW_FIT = (2.0, 0.95, 4, "2.2")
# NOTE: `lindstedt slowflow` (start-up, then derive): the driven Duffing, the costliest family,
# takes 0.95 s to derive at order 4, and the whole command 4.2 s at order 5, 6.1 s at order 6
# (load 6): about 2.2× per order; van der Pol a third of that.


EXCHANGE_STEP_SECONDS = 5e-4
# NOTE: one DOP853 step of a system's resonant slow flow (lambdified rates): 0.28 ms measured on
# the swing spring, 0.5 ms allowed for load; the exchange period takes at most
# EXCHANGE_MAX_STEPS of them, whatever --start says (the flow is rescaled to unit amplitude).


def slow_flow_cost(args: argparse.Namespace) -> Cost:
    """``slowflow``: the fit at ``--order`` (default 2; beyond :data:`SLOW_FLOW_MAX_ORDER` the
    fixed part only: the derivation refuses at once, in its own one-line message)."""
    return _averaging_cost(args.order if args.order is not None else 2, 0.0)


def resonant_flow_cost(args: argparse.Namespace) -> Cost:
    """``slowflow SYSTEM``: the fit at ``--order`` (default 1) and the energy exchange's
    bounded integration (:data:`EXCHANGE_MAX_STEPS` steps), the same for every ``--start``."""
    return _averaging_cost(args.order if args.order is not None else 1,
                           EXCHANGE_MAX_STEPS * EXCHANGE_STEP_SECONDS)


def _averaging_cost(asked: int, exchange: float) -> Cost:
    order = asked if asked <= SLOW_FLOW_MAX_ORDER else 0
    return Cost(power_law(*SLOW_FLOW_FIT, order) + exchange, f"order {asked}",
                "the slow flow" + " and its energy exchange" * bool(exchange))


PARAMETRIC_FIT = (2.0, 1.5e-3)
# NOTE: `lindstedt parametric`: start-up and ten shot ω, then per ω and nontrivial branch a
# balance and a full Hill pass, ~1.5 ms per odd harmonic (measured at load 5: 401 points
# 10.5 s at 8 harmonics, 116 s at 100).


def parametric_cost(args: argparse.Namespace) -> Cost:
    """Two branches at each of the N points of ``--omega A:B:N``, each ``--harmonics`` deep;
    above the limit a bound (no --allow-slow: fewer points or harmonics answer the same)."""
    points, harmonics = max(args.points, 1), max(args.harmonics, 8)
    seconds = PARAMETRIC_FIT[0] + 2 * points * PARAMETRIC_FIT[1] * harmonics
    if seconds > COST_LIMIT_SECONDS:
        raise InputError(f"--omega with {args.points} points, --harmonics {args.harmonics}: "
                         "about "
                         f"{seconds:,.0f} s of balances; the limit is {COST_LIMIT_SECONDS:.0f} "
                         "s: give fewer points or harmonics")
    return Cost(seconds, f"{args.points} points", "the parametric response")


NNM_FIT = (0.6, 4.6e-5, 2.5)
# NOTE: start-up + c·K³·(d/2)^e seconds for order K and d coordinates: Kerschen's 2-DOF system
# at order 60 took 7–12 s, the 8-mass FPU-β chain (in Q(ω₀²), a cubic field) at order 10 2.4 s.


def nnm_cost(args: argparse.Namespace) -> Cost:
    """``nnm``: the fit :data:`NNM_FIT` in the order and the number of equations."""
    from .derive.problem import read_problem

    fixed, c, e = NNM_FIT
    d = max(read_problem(args.system).size, 2)
    return Cost(fixed + c * args.order**3 * (d / 2) ** e, f"order {args.order}, {d} coordinates",
                "the normal mode's series")


COSTS: Mapping[str, Callable[[argparse.Namespace], Cost]] = {
    "series": series_cost,
    "generate": generate_cost,
    "driven": driven_cost,
    "response": response_cost,
    "subharmonic": fixed_cost("subharmonic"),
    "parametric": parametric_cost,
    "mixing": fixed_cost("mixing"),
    "choose": choose_cost,
    "sweep": sweep_cost,
    "clock": fixed_cost("clock"),
    "scene": fixed_cost("scene"),
    "models": fixed_cost("models"),
    "mathieu": mathieu_cost,
    "tongues": tongues_cost,
    "slowflow": slow_flow_cost,
    "nnm": nnm_cost,
    "ssm": ssm_cost,
}
ROUTE_COSTS: Mapping[str, Callable[[argparse.Namespace], Cost]] = {
    "generate normal mode": generate_mode_cost,
    "slowflow resonant flow": resonant_flow_cost,
}
# NOTE: the estimators of a command's other methods (cli.COMMANDS' routes), by command and
# method.
# NOTE: one estimator per command; `demo` has none: its work is the fixed built-in job
# (`make demo`), which nothing on its command line scales.
