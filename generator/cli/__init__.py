"""The ``lindstedt`` command line.  Bad input: one line on stderr, exit status 2."""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

from .. import __version__
from ..costs import COST_LIMIT_SECONDS, COSTS, DRIVEN_MAX_ORDER, emit_bounds
from ..errors import InputError

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# NOTE: before NumPy is imported: the continuation's and the fits' matrices (≤ 200 × 200) run
# twice as fast on one BLAS thread as on OpenBLAS's pool on a busy machine (`response
# --harmonics 40`: 8.7 s against 17.3 s), and the cost estimates assume one thread.

FREE_MODELS = ("duffing", "pendulum", "helmholtz_duffing", "quintic", "cubic_quintic",
               "velocity_squared", "sinh_spring", "van_der_pol", "rayleigh")
# NOTE: models.MODELS, restated so that parsing arguments needs no SymPy (a test keeps them equal).
EMITTED = ("driven", "balance", "fourier")
# NOTE: generate's names for the driven oscillator's modules (not free oscillators).
SCENE_NAMES = ("clock", "hard-spring", "notes-driven")
# NOTE: choose.SCENES's keys, likewise.
DRIVEN_QUANTITIES = ("amplitudes", "response")
# NOTE: choose.DRIVEN_QUANTITIES, likewise.
SWEEP_KINDS = ("response", "stability", "subharmonic", "validity")
# NOTE: sweep.KINDS's keys, likewise.
DEFAULT_ORDER = 4
# NOTE: one default for every --order: it works for every command (`generate driven` at order 4
# takes ~13 s, at 6 about 4 min) and keeps T(A) within 1e-4 for |εA²| ≤ 0.3; ask for more.
DEFAULT_HARMONICS = 8
# NOTE: one default for every --harmonics: 8 odd harmonics put the response's folds on the true
# orbit's to 12 digits at the notes' parameters (`generate balance` compiles them in ~20 s).
MAX_HARMONICS = 100
# NOTE: driven.MAX_HARMONICS, restated (a test keeps them equal): one bound for every
# --harmonics.  The numerical balance and shooting's sampling take up to 100; the emitted
# modules stop earlier (balance 12, fourier 60) and say so; the response's continuation
# refuses what it estimates at over a minute.
PROGRESS_AFTER_SECONDS = 2.0
# NOTE: work shorter than this shows no progress bar (it would only flicker).


class Progress:
    """A one-line progress bar on stderr, drawn only when stderr is a terminal and the output is
    not JSON, and only once the work has taken ``PROGRESS_AFTER_SECONDS``; call it as
    ``progress(done, total)``, then ``progress.close()``."""

    def __init__(self, label: str, enabled: bool = True) -> None:
        self.label = label
        self.enabled = enabled and sys.stderr.isatty()
        self.start = time.monotonic()
        self.drawn = False

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled or time.monotonic() - self.start < PROGRESS_AFTER_SECONDS:
            return
        width = 30
        filled = width * done // max(total, 1)
        sys.stderr.write(f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] "
                         f"{done}/{total}")
        sys.stderr.flush()
        self.drawn = True

    def close(self) -> None:
        if self.drawn:
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()


def _rational(c: object) -> str:
    """Exact ``"p/q"`` (always with a denominator, so scripts can split on '/'); FLINT's
    ``fmpq`` prints its digits itself, however long."""
    return f"{c.p}/{c.q}"


def _monomial(powers: tuple[tuple[str, int], ...]) -> str:
    """SymPy's spelling of a monomial: ``"A**2*alpha"``, ``"1"`` for the constant."""
    return "*".join(n if e == 1 else f"{n}**{e}" for n, e in powers) or "1"


def _coefficient(sol, c: object) -> str | dict:
    """``"p/q"``, or for coefficients in ``QQ[A, params]`` an object mapping each monomial
    (SymPy's ``str``: ``"A**2*alpha"``, ``"1"``) to its exact ``"p/q"``, formatted from
    FLINT's terms (no SymPy on the way)."""
    if sol.ground.is_rational:
        return _rational(c)
    return dict(sorted((_monomial(m), _rational(v)) for m, v in sol.ground.terms(c)))


def _polynomial_text(sol, c: object) -> str:
    """A coefficient in ``QQ[A, params]`` as SymPy writes it (``3*A**2*alpha/8 - A/4``, in
    SymPy's order), formatted from FLINT's terms."""
    names = sorted({n for powers, _ in sol.ground.terms(c) for n, _ in powers})

    def order(term: tuple) -> tuple:  # SymPy's: lex on the names (sorted), descending
        powers = dict(term[0])
        return tuple(-powers.get(n, 0) for n in names)

    terms = sorted(sol.ground.terms(c), key=order)
    out = []
    for powers, v in terms:
        p, q = abs(int(v.p)), int(v.q)
        body = _monomial(powers) if powers else ""
        if body:
            body = (body if p == 1 else f"{p}*{body}") + (f"/{q}" if q != 1 else "")
        else:
            body = f"{p}/{q}" if q != 1 else f"{p}"
        out.append(("- " if v < 0 else "+ ") + body)
    if not out:
        return "0"
    text = " ".join(out)
    return text[2:] if text.startswith("+ ") else "-" + text[2:]


def series_json(sol) -> dict:
    """The contract of ``lindstedt series MODEL --order K --json`` (keys are stable)."""
    m = sol.model
    data = {
        "model": m.name,
        "order": sol.order,
        "variable": m.variable,
        "omega": [_coefficient(sol, c) for c in sol.omega],
        "period": [_coefficient(sol, c) for c in sol.period],
        "q": [{str(n): _coefficient(sol, c) for n, c in sorted(qj.items())} for qj in sol.q],
        "convention": sol.convention,
        "radius": None if m.radius is None else str(m.radius),
    }
    data.update(_domain_fields(sol))
    if m.source:
        data.update(equation=m.source, omega0=str(m.frequency),
                    units="omega in units of omega0, period in units of 2*pi/omega0")
    return data


def _domain_fields(sol) -> dict:
    """Where the series may be used: ``orbit_limit`` (the family of periodic orbits exists
    for lower < y < upper, 30 digits, or ``known`` false with the reason) and, where the
    model states no radius, ``radius_estimate`` (value and spread, from the τ_j)."""
    from ..derive.lindstedt import estimated_radius
    from ..derive.orbits import orbit_domain

    fields = {"orbit_limit": orbit_domain(sol.model).as_json()}
    if sol.model.radius is None and sol.ground.is_rational and sol.order >= 2:
        found = estimated_radius(sol, {})
        if found is not None:
            fields["radius_estimate"] = {"value": float(found[0]), "spread": found[1]}
    return fields


def series_table(sol) -> str:
    """Readable table: ω_j, T_j/2π and the harmonics of q_j per order."""
    m = sol.model
    lines = [
        f"{m.name}: {m.title}, expansion variable {m.variable}, order {sol.order}",
        f"convention: {sol.convention}",
    ]
    if m.frequency != 1:
        lines.append(f"omega in units of omega0 = {m.frequency}, T in units of 2*pi/omega0")
    domain = _domain_fields(sol)["orbit_limit"]
    y = m.variable.partition("=")[0].strip() or m.variable
    lines.append(f"periodic orbits for {domain['lower']} < {y} < {domain['upper']} "
                 f"({domain['how']})" if domain["known"] else
                 f"orbit domain not computed: {domain['how']}")
    if sol.ground.is_rational:
        lines.append(f"{'j':>3}  {'omega_j':>24}  {'(T/2pi)_j':>24}  "
                     "q_j: harmonic n -> coefficient")
        for j in range(sol.order + 1):
            harmonics = ", ".join(f"{n}: {_rational(c)}" for n, c in sorted(sol.q[j].items()))
            lines.append(f"{j:>3}  {_rational(sol.omega[j]):>24}  "
                         f"{_rational(sol.period[j]):>24}  {harmonics}")
        return "\n".join(lines)
    def g(c: object) -> str:
        return _polynomial_text(sol, c)

    for j in range(sol.order + 1):  # symbolic coefficients: one block an order
        lines.append(f"j = {j}: omega_j = {g(sol.omega[j])}")
        lines.append(f"       (T/2pi)_j = {g(sol.period[j])}")
        for n, c in sorted(sol.q[j].items()):
            lines.append(f"       q_j[cos {n}s] = {g(c)}")
    return "\n".join(lines)


def _params(pairs: Sequence[str] | None) -> dict[str, str]:
    """``--param NAME=VALUE`` pairs, each name once."""
    values: dict[str, str] = {}
    for pair in pairs or ():
        name, sep, value = pair.partition("=")
        name = name.strip()
        if not sep or not name or not value.strip():
            raise InputError(f"--param {pair!r}: write NAME=VALUE, e.g. alpha=1/3")
        if name in values:
            raise InputError(f"--param {name}: given twice")
        values[name] = value.strip()
    return values


def limit_cycle_json(lc) -> dict:
    """``lindstedt series`` of a self-excited oscillator: ω, T/2π and q(0) as exact "p/q" in
    ε, each q_j's cos and sin coefficients, the first-order amplitude slope and the verdict."""
    m = lc.model
    frac = _fraction_text
    return {
        "model": m.name, "order": lc.order, "variable": "eps",
        "omega": [frac(c) for c in lc.omega], "period": [frac(c) for c in lc.period],
        "amplitude": [frac(c) for c in lc.amplitude],
        "q": [{"cos": {str(n): frac(c) for n, c in sorted(cos.items())},
               "sin": {str(n): frac(c) for n, c in sorted(sin.items())}} for cos, sin in lc.q],
        "convention": "q'(0) = 0; q(0) = sum_j amplitude[j] eps^j, s = omega t",
        "equation": m.source, "slope": frac(lc.slope),
        "stable_for": "eps > 0" if lc.slope > 0 else "eps < 0",
        "stability": limit_cycle_stability(lc),
    }


def limit_cycle_stability(lc) -> str:
    """The cycle attracts for ``ε S'(a₀) > 0`` and repels for the other sign of ε, where the
    same series holds (time reversed: t → −t, ε → −ε)."""
    good, bad = ("eps > 0", "eps < 0") if lc.slope > 0 else ("eps < 0", "eps > 0")
    return (f"stable (attracting) for {good}, unstable (repelling) for {bad}; the series holds "
            "for both signs")


def _fraction_text(c: object) -> str:
    """``"p/q"`` of a Fraction; an algebraic number (a limit cycle in Q(a₀)) as SymPy's str,
    exact (``"-3*2**(3/4)/2560"``)."""
    if getattr(c, "is_Rational", False):  # SymPy's Rational (no import: start-up)
        c = Fraction(int(c.p), int(c.q))
    elif not isinstance(c, Fraction):
        return str(c)
    return f"{_int_text(c.numerator)}/{_int_text(c.denominator)}"


INT_TEXT_BITS = 14_000
# NOTE: below 4300 digits, Python's own str(); beyond it Python refuses (a guard against slow
# parsing of untrusted text), and van der Pol's coefficients pass it near order 150.


def _int_text(n: int) -> str:
    """The decimal digits of an exact integer, however long (FLINT's conversion beyond
    :data:`INT_TEXT_BITS`)."""
    if n.bit_length() < INT_TEXT_BITS:
        return str(n)
    from flint import fmpz

    return str(fmpz(n))


def _cycles_json(cycles) -> list[dict]:
    """Every limit cycle: its first-order amplitude a₀ (exact, SymPy's str), S'(a₀) and its
    stability, smallest amplitude first."""
    return [{"amplitude0": str(c.amplitude), "slope": str(c.slope), "stability": c.stability,
             "expandable": c.slope != 0} for c in cycles]


def _cycles_text(model, listed: list[dict]) -> str:
    lines = [f"{model.name}: {len(listed)} limit cycle(s) of S(a), by amplitude:"]
    for k, c in enumerate(listed, 1):
        lines.append(f"  cycle {k}: a0 = {c['amplitude0']}, S'(a0) = {c['slope']}: "
                     f"{c['stability']}")
    return "\n".join(lines)


def limit_cycle_table(lc) -> str:
    m = lc.model
    lines = [f"{m.name}: {m.title}, a limit cycle, expansion variable eps, order {lc.order}",
             "convention: q'(0) = 0, q(0) = sum_j amplitude_j eps^j",
             f"stability: {limit_cycle_stability(lc)}",
             f"{'j':>3}  {'omega_j':>22}  {'(T/2pi)_j':>22}  {'amplitude_j':>22}"]
    for j in range(lc.order + 1):
        lines.append(f"{j:>3}  {_fraction_text(lc.omega[j]):>22}  "
                     f"{_fraction_text(lc.period[j]):>22}  {_fraction_text(lc.amplitude[j]):>22}")
    return "\n".join(lines)


def _cmd_series(args: argparse.Namespace) -> int:
    from ..derive.cycles import derive_limit_cycle, limit_cycles
    from ..derive.lindstedt import derive
    from ..derive.models import SelfExcited, series_model

    found = series_model(args.model, args.order, _params(args.param), args.name)
    if args.cycle is not None and not isinstance(found, SelfExcited):
        raise InputError(f"--cycle {args.cycle}: {args.model!r} is conservative: a family of "
                         "orbits, no limit cycles to pick from")
    if isinstance(found, SelfExcited):
        cycles = limit_cycles(found)
        if args.cycle is not None and not 1 <= args.cycle <= len(cycles):
            raise InputError(f"--cycle {args.cycle}: {found.name} has {len(cycles)} limit "
                             f"cycle(s), numbered 1 to {len(cycles)} by amplitude")
        listed = _cycles_json(cycles)
        first = args.cycle if args.cycle is not None else 1
        lc = derive_limit_cycle(found, args.order, first - 1)
        data = {**limit_cycle_json(lc), "cycle": first, "cycles": listed}
        omega = lc.omega
        # the table: the cycle asked for, or each in turn (one that cannot be expanded says why)
        texts = [_cycles_text(found, listed)]
        shown = [] if args.json else [first] if args.cycle is not None \
            else range(1, len(cycles) + 1)
        for k in shown:
            c = cycles[k - 1]
            if k == first:
                texts.append(f"cycle {k}: " + limit_cycle_table(lc))
            elif c.slope == 0:
                texts.append(f"cycle {k}: not expanded: {c.stability}")
            else:
                texts.append(f"cycle {k}: " + limit_cycle_table(
                    derive_limit_cycle(found, args.order, k - 1)))
        text = "\n\n".join(texts)
    else:
        model = found  # series_model built it (model_from_text): parse and expand once
        progress = Progress(f"deriving {model.name} to order {args.order}", not args.json)
        sol = derive(model, args.order, progress)
        progress.close()
        data = series_json(sol)
        text = "" if args.json else series_table(sol)  # build only what is printed
        omega = [sol.ground.to_fraction(c) for c in sol.omega] if sol.ground.is_rational \
            else None
    if args.singularities:
        data["singularities"], line = _singularities(omega, data["variable"])
        text += "\n" + line
    print(json.dumps(data) if args.json else text)
    return 0


def _singularities(omega, variable: str, of: str = "omega", degree: int | None = 1
                   ) -> tuple[list[dict], str]:
    """``--singularities``: the nearest singularity of ω (or of the series ``of``) estimated
    from its exact series (``degree``: of :func:`lindstedt.nearest_singularity`)."""
    from ..derive.lindstedt import nearest_singularity

    if omega is None:
        raise InputError("--singularities: the coefficients stay symbolic; give every "
                         "parameter a value (--param)")
    name = variable.partition("=")[0].strip() or variable
    est = nearest_singularity(omega, name, degree)
    if est is None:
        return [], "singularities: too few nonzero coefficients for an estimate (raise --order)"
    row = {"variable": est.variable, "radius": est.radius, "angle": est.angle,
           "spread": est.spread, "method": est.method}
    return [row], (f"nearest singularity of {of} ({est.method}): |{est.variable}| = "
                   f"{est.radius:.6g}, angle ±{est.angle:.6g} rad, spread {est.spread:.2g}")


def _emit_only(flags) -> None:
    """``--emit`` writes a module and prints its path: the printing flags given beside it
    (``flags``: pairs of a flag and whether it was given) are refused, not ignored."""
    others = [flag for flag, given in flags if given]
    if others:
        raise InputError(f"--emit writes the module only: drop {', '.join(others)}")


def _cmd_mathieu(args: argparse.Namespace) -> int:
    """``lindstedt mathieu a|b --m M --order K``: DLMF §28.6's series of a_m(q) or b_m(q)."""
    from ..derive.hill import mathieu_series

    if args.emit is not None:
        from .. import compiler

        _emit_only((("--json", args.json), ("--singularities", args.singularities)))
        for path in compiler.generate_mathieu(args.kind, args.m, args.order,
                                              _out_folder(args.emit, "--emit"),
                                              overwrite_edited=args.overwrite_edited):
            print(path)
        return 0
    series = mathieu_series(args.kind, args.m, args.order)
    data = {"kind": args.kind, "m": args.m, "variable": "q",
            "series": [_fraction_text(c) for c in series]}
    line = ""
    if args.singularities:  # a_2n, b_2n live in q²: the estimate names q**2
        data["singularities"], line = _singularities(series, "q", f"{args.kind}_{args.m}", None)
        if data["singularities"] and data["singularities"][0]["variable"] == "q**2":
            row = data["singularities"][0]
            line += f" (|q| = {math.sqrt(row['radius']):.6g})"
    if args.json:
        print(json.dumps(data))
        return 0
    print(f"{args.kind}_{args.m}(q) of y'' + (a - 2q cos 2z) y = 0 (DLMF 28.2.1), order "
          f"{args.order}: coefficient of q^k")
    for k, c in enumerate(series):
        print(f"{k:>4}  {_fraction_text(c)}")
    if line:
        print(line)
    return 0


def _series_value(coefficients, x: float) -> tuple[float, float, int]:
    """The partial sum at ``x``, its change over the last two nonzero terms (the truncation
    error estimate) and the order K of the smallest such change (the best reachable)."""
    total, last, changes = 0.0, [], []
    for k, c in enumerate(coefficients):
        term = float(c) * x**k
        total += term
        if c:
            last.append(abs(term))
            changes.append((sum(last[-2:]), k))
    if len(changes) < 2:
        return total, 0.0, len(coefficients) - 1
    best = min(changes[1:])
    return total, changes[-1][0], best[1]


def _radius(coefficients) -> float:
    """The estimated radius of convergence in the series' own variable (inf if too short)."""
    from ..derive.lindstedt import nearest_singularity

    est = nearest_singularity(coefficients, "x", None)
    if est is None:
        return math.inf
    return math.sqrt(est.radius) if est.variable == "x**2" else est.radius


DAMPING_PANEL = 0.05
# NOTE: the damped panel of `tongues --plot` without --damping: the tongues visibly lift.


def _cmd_tongues(args: argparse.Namespace) -> int:
    """``lindstedt tongues P --n N --order K``: the transition curves out of tongue n of
    x'' + (δ + ε p(t))x = 0, exact; ``--damping Z``: the damped tongue's tip."""
    from ..derive.hill import fourier_of_text, tongue_tip, transition_curves

    if args.emit is not None:
        from .. import compiler

        _emit_only((("--at", args.at is not None), ("--tol", args.tol),
                    ("--damping", args.damping is not None), ("--plot", args.plot),
                    ("--json", args.json), ("--singularities", args.singularities)))
        for path in compiler.generate_tongue(args.p, args.n, args.order,
                                             _out_folder(args.emit, "--emit"),
                                             overwrite_edited=args.overwrite_edited):
            print(path)
        return 0
    if args.tol is not None and args.at is None:
        raise InputError("--tol: give --at EPS, the eps the tolerance is asked at")
    if args.plot:
        from ..charts import check_plot_path

        check_plot_path(Path(args.plot))  # before any work
    p = fourier_of_text(args.p)
    tongue = transition_curves(p, args.n, args.order)
    period = "2*pi" if args.n % 2 == 0 else "4*pi"
    data: dict = {
        "p": args.p, "n": args.n, "variable": "eps",
        "delta0": _fraction_text(Fraction(args.n * args.n, 4)),
        "harmonics": {str(k): [_fraction_text(a), _fraction_text(b)] for k, (a, b) in p.items()},
        "time_origin": "pi/2" if tongue.shift else "0", "period": period,
        "solution_variable": "tau = (t - time_origin)/2", "curves": []}
    lines = [f"tongue n = {args.n} of x'' + (delta + eps p(t)) x = 0, p(t) = {args.p}: "
             f"delta = {data['delta0']} + sum_k delta_k eps^k, order {args.order}; "
             f"periodic solutions of period {period}"
             + (" (in t - pi/2: p is even about t = pi/2)" if tongue.shift else "")]
    for curve in tongue.curves:
        row = {"label": curve.label, "series": [_fraction_text(c) for c in curve.delta],
               "solution": [{"cos": {str(j): _fraction_text(c) for (kind, j), c in x.items()
                                     if kind == 0},
                             "sin": {str(j): _fraction_text(c) for (kind, j), c in x.items()
                                     if kind == 1}} for x in curve.solution]}
        lines.append(f"curve {curve.label}: k, delta_k")
        lines += [f"{k:>4}  {_fraction_text(c)}" for k, c in enumerate(curve.delta)]
        if args.singularities:
            row["singularities"], line = _singularities(list(curve.delta), "eps",
                                                        f"delta ({curve.label})", None)
            lines.append(line)
        if args.at is not None:
            value, error, best = _series_value(curve.delta, args.at)
            radius = _radius(curve.delta)
            if abs(args.at) >= radius:  # outside the disc of convergence: no value
                value, error = math.nan, math.inf
            if args.tol is not None and not error <= args.tol:
                _, best_error, _ = _series_value(curve.delta[:best + 1], args.at)
                raise InputError(f"--tol {args.tol:g}: not reached at eps = {args.at:g} by order "
                                 f"{args.order} (estimate {error:.2g}); the best reachable is "
                                 f"{best_error:.2g} at order {best}")
            row["at"] = {"eps": args.at, "delta": value, "error": error, "radius": radius}
            lines.append(f"at eps = {args.at:g}: delta = {value:.15g} (truncation ~{error:.2g}"
                         f"; radius of convergence ~{radius:.4g})")
        data["curves"].append(row)
    if args.damping is not None:
        tip = tongue_tip(p, args.n, args.order)
        eps, _, _ = _series_value(tip.eps_min, args.damping)
        delta, err, _ = _series_value(tip.delta, args.damping)
        data["damping"] = {
            "variable": "zeta", "equation": "x'' + 2 zeta x' + (delta + eps p(t)) x = 0",
            "eps_min": [_fraction_text(c) for c in tip.eps_min],
            "delta_at_min": [_fraction_text(c) for c in tip.delta],
            "mu_max": [_fraction_text(c) for c in tip.mu],
            "at": {"zeta": args.damping, "eps_min": eps, "delta": delta, "error": err}}
        lines.append("damped tongue tip: eps_min(zeta) = sum_k e_k zeta^k at delta = sum_k "
                     "d_k zeta^k (k, e_k, d_k)")
        lines += [f"{k:>4}  {_fraction_text(e):>24}  {_fraction_text(d)}"
                  for k, (e, d) in enumerate(zip(tip.eps_min, tip.delta, strict=True))]
        lines.append(f"at zeta = {args.damping:g}: eps_min = {eps:.12g}, delta = {delta:.12g}")
    print(json.dumps(data) if args.json else "\n".join(lines))
    if args.plot:
        from ..charts import ince_strutt_figure

        path = ince_strutt_figure(Path(args.plot), args.p, args.damping or DAMPING_PANEL,
                                  order=args.order, tongues=range(max(4, args.n + 1)))
        if not args.json:
            print(f"Ince–Strutt chart: {path}")
    return 0


def slow_flow_json(flow) -> dict:
    """The contract of ``lindstedt slowflow … --json``: ``radial[k-1]`` and ``phase[k-1]`` are
    R_k and Φ_k of dr/dt = Σ eps^k R_k, dphi/dt = Σ eps^k Φ_k (SymPy text in r, phi and the
    parameters), for q = r cos(t + phi) (a drive: q = r cos(w t + phi), w = 1 + eps*sigma);
    ``cycles``: each limit cycle (a root of dr/dt) of an autonomous flow without symbolic
    parameters, its radius r* (to eps^(K-1)) and frequency ω (to eps^K) as series in eps."""
    return {
        "equation": flow.source, "name": flow.name, "order": flow.order, "variable": "eps",
        "parameters": [str(p) for p in flow.parameters], "driven": flow.driven,
        "convention": ("q = r cos(w t + phi), q' = -r w sin(w t + phi) + O(eps), "
                       "w = 1 + eps*sigma" if flow.driven else
                       "q = r cos(t + phi), q' = -r sin(t + phi) + O(eps)")
        + "; mean-free near-identity transformation",
        "radial": [sp_text(e) for e in flow.radial],
        "phase": [sp_text(e) for e in flow.phase],
        "cycles": [{"radius": [sp_text(c) for c in cyc.radius],
                    "omega": [sp_text(c) for c in cyc.omega],
                    "stable_for": "eps > 0" if cyc.slope < 0 else "eps < 0"}
                   for cyc in _cycles(flow)],
    }


def _cycles(flow) -> list:
    """The limit cycles of an autonomous flow with numeric coefficients (none otherwise)."""
    from ..derive.averaging import cycle_series

    return [] if flow.driven or flow.parameters else cycle_series(flow)


def sp_text(expr) -> str:
    import sympy as sp

    return sp.sstr(expr, order="lex")


def _cmd_slowflow(args: argparse.Namespace) -> int:
    """``lindstedt slowflow EQUATION|NAME --order K``: the averaged equations, exact."""
    from ..derive.averaging import slow_flow
    from ..derive.models import oscillator, registry_entry

    text, name = args.model, args.name or "oscillator"
    if (entry := registry_entry(text)) is not None:  # a name or its alias (vdp)
        text, name = entry.equation, args.name or entry.name
    out = _out_folder(args.out) if args.out is not None else None
    osc = oscillator(text, _params(args.param), name)
    flow = slow_flow(osc, args.order)
    written = []
    if out is not None:  # written before anything is printed: a refusal prints nothing
        from ..compiler import generate_slow_flow

        params = "".join(f" --param {k}={v}" for k, v in sorted(_params(args.param).items()))
        command = f'lindstedt slowflow "{text}" --name {name} --order {args.order}{params}'
        written = generate_slow_flow(osc, args.order, command, out,
                                     overwrite_edited=args.overwrite_edited)
    if args.json:
        print(json.dumps(slow_flow_json(flow)))
    else:
        frame = "q = r cos(w t + phi), w = 1 + eps*sigma" if flow.driven else \
            "q = r cos(t + phi)"
        print(f"{flow.name}: {flow.source}, the slow flow to order {flow.order} ({frame})")
        print("dr/dt = sum_k eps^k R_k, dphi/dt = sum_k eps^k Phi_k")
        for k in range(flow.order):
            print(f"R_{k + 1}   = {sp_text(flow.radial[k])}")
            print(f"Phi_{k + 1} = {sp_text(flow.phase[k])}")
        for cyc in _cycles(flow):
            print(f"limit cycle (dr/dt = 0, attracting for "
                  f"{'eps > 0' if cyc.slope < 0 else 'eps < 0'}): r = sum_j eps^j r_j, "
                  "omega = sum_j eps^j omega_j")
            print("  r_j:     " + ", ".join(sp_text(c) for c in cyc.radius))
            print("  omega_j: " + ", ".join(sp_text(c) for c in cyc.omega))
    for path in written:
        print(f"  {path}", file=sys.stderr if args.json else sys.stdout)
    return 0


def _cmd_models(args: argparse.Namespace) -> int:
    from ..derive.models import ALIASES, REGISTRY

    aliases = {e.name: sorted(a for a, name in ALIASES.items() if name == e.name)
               for e in REGISTRY.values()}
    if args.json:
        print(json.dumps([{"name": e.name, "equation": e.equation, "about": e.about,
                           "aliases": aliases[e.name]} for e in REGISTRY.values()]))
        return 0
    width = max(len(name) for name in REGISTRY)
    for e in REGISTRY.values():
        also = f" (also: {', '.join(aliases[e.name])})" if aliases[e.name] else ""
        print(f"{e.name:<{width}}  {e.equation:<44}  {e.about}{also}")
    return 0


def _cmd_generate(args: argparse.Namespace) -> int:
    order = args.order
    if args.model in EMITTED and (args.param or args.name):
        raise InputError(f"--param/--name: the {args.model} modules take neither")
    if args.model in EMITTED and args.allow_divergent:
        raise InputError(f"--allow-divergent: the {args.model} evaluators have no radius to lift")
    from .. import compiler

    if args.model in EMITTED and args.resum_order is not None:
        raise InputError(f"--resum-order: the {args.model} modules have no limit cycle to resum")
    if args.damped and args.model != "driven":
        raise InputError(f"--damped: only `generate driven` has a damped variant, not "
                         f"{args.model}")
    out = _out_folder(args.out)
    if args.model == "driven":
        paths = compiler.generate_driven(order, out, damped=args.damped,
                                         overwrite_edited=args.overwrite_edited)
    elif args.model == "balance":
        paths = compiler.generate_balance(args.harmonics, out,
                                          overwrite_edited=args.overwrite_edited)
    elif args.model == "fourier":
        paths = compiler.generate_fourier(args.harmonics, out,
                                          overwrite_edited=args.overwrite_edited)
    else:
        from ..derive.models import SelfExcited, series_model
        from ..lower.forms import check_emitted_names

        found = series_model(args.model, order + 2, _params(args.param), args.name)
        if isinstance(found, SelfExcited):
            if args.allow_divergent:
                raise InputError("--allow-divergent: a limit cycle's evaluators stop at their "
                                 "estimated radius")
            for path in compiler.generate_limit_cycle(found, order, out,
                                                      resum_order=args.resum_order,
                                                      overwrite_edited=args.overwrite_edited):
                print(path)
            return 0
        model = found
        if args.resum_order is not None:
            raise InputError(f"--resum-order: {model.name} has no limit cycle; only a limit "
                             "cycle's frequency is resummed from a longer series")
        check_emitted_names(model)  # before the derivation: a clash is known at once
        progress = Progress(f"deriving {model.name} to order {order + 2}")
        paths = compiler.generate(model, order, out, args.allow_divergent, progress,
                                  overwrite_edited=args.overwrite_edited)
        progress.close()
    for path in paths:
        print(path)
    return 0


def _out_folder(text: str, flag: str = "--out") -> Path:
    if not text.strip():
        raise InputError(f"{flag} {text!r}: empty; name a folder")
    return Path(text)


DEMO_ORDER = 12
# NOTE: the demo's free evaluators: order 12 keeps T(A) within 1e-6 for |εA²| ≤ 0.3 and the
# LaTeX a few pages long.
DRIVEN_ORDER = 3
# NOTE: the exact μ-expansion's rational functions grow fast; order 3 keeps the derivation
# readable and the emitted A_n(ω) within 1e-5 of the true orbit at the notes' parameters.
BALANCE_HARMONICS = 4
# NOTE: the demo's balance module: 4 odd harmonics reach 1e-7 at the notes' parameters and
# compile in seconds.


def _cmd_demo(args: argparse.Namespace) -> int:
    """The main job on the built-in defaults: derive, emit, evaluate against exact, typeset.
    Everything it writes goes under ``--out``: evaluators and LaTeX, ``figures/``, the PDFs."""
    out = _out_folder(args.out)  # before the heavy imports: an empty --out answers at once
    import shutil
    import subprocess

    import numpy as np

    from ..charts import (
        check_plot_path,
        driven_speed_accuracy_figure,
        gallery,
        speed_accuracy_figure,
    )
    from ..compiler import generate, generate_balance, generate_driven
    from ..derive.lindstedt import derive
    from ..derive.models import model_by_name
    from ..emit.render import check_writable, load_generated
    from ..numerics.references import duffing_period_exact, pendulum_period_exact

    figures = out / "figures"
    modules = ["duffing", "pendulum", "driven", "balance"]
    check_writable(out, [*(f"{m}.py" for m in modules), "duffing_tables.tex",
                         "duffing_derivation.tex", "pendulum_tables.tex",
                         "pendulum_derivation.tex", "driven_derivation.tex",
                         "van_der_pol_slow_flow.py", "van_der_pol_slow_flow.tex",
                         "van_der_pol.py", "van_der_pol_derivation.tex"],
                   overwrite_edited=args.overwrite_edited)
    figures.mkdir(parents=True, exist_ok=True)
    check_plot_path(figures / "speed_accuracy.png")
    print(series_table(derive(model_by_name("duffing", 6), 6)))
    print(f"\nwriting the default evaluators and LaTeX into {out}/")
    for name in ("duffing", "pendulum"):
        for path in generate(name, DEMO_ORDER, out, overwrite_edited=args.overwrite_edited):
            print(f"  {path}")
    for path in [*generate_driven(DRIVEN_ORDER, out, overwrite_edited=args.overwrite_edited),
                 *generate_balance(BALANCE_HARMONICS, out, overwrite_edited=args.overwrite_edited)]:
        print(f"  {path}")
    duf = load_generated(out / "duffing.py")
    x = np.array([-0.9, -0.5, -0.1, 0.1, 0.5, 0.9])
    exact = duffing_period_exact(1.0, x)
    print(f"\nDuffing period, order {duf.ORDER}, against 4K(m)/sqrt(1+x) (A = 1, eps = x):")
    print(f"{'x':>6} {'series T':>20} {'exact T':>20} {'rel. error':>11} {'estimate':>10}")
    for xi, ti, ei, est in zip(x, duf.period(1.0, x), exact, duf.error_estimate(1.0, x),
                               strict=True):
        print(f"{xi:>6.2f} {ti:>20.15f} {ei:>20.15f} {abs(ti / ei - 1):>11.1e} {est:>10.1e}")
    pen = load_generated(out / "pendulum.py")
    deg = np.array([5.0, 10.0, 30.0, 60.0, 90.0, 120.0])
    th = np.radians(deg)
    exact = pendulum_period_exact(th)
    drv = load_generated(out / "driven.py")
    print(f"\nDriven Duffing (eps = 0.1, f = 1, omega = 1): mu-expansion order {drv.ORDER}: "
          f"A1 = {drv.A_1(1.0, 0.1, 1.0, 0):.6f}, A3 = {drv.A_3(1.0, 0.1, 1.0, 0):.6f} "
          "(notes, numerically: 2.356, 0.0456)")
    print(f"\nGrandfather's clock: pendulum period, order {pen.ORDER}, "
          "against 4K(sin^2(theta0/2)):")
    print(f"{'theta0':>7} {'series T':>20} {'exact T':>20} {'rel. error':>11} {'s/day':>9}")
    for d, ti, ei in zip(deg, pen.period(th), exact, strict=True):
        print(f"{d:>6.0f}° {ti:>20.15f} {ei:>20.15f} {abs(ti / ei - 1):>11.1e} "
              f"{86400 * abs(ti / ei - 1):>9.1e}")
    print("\nfigures:")
    for path in gallery(figures):
        print(f"  {path}")
    # NOTE: measured costs differ run to run: these two charts are the run's own
    # (benchmarks/*speed_accuracy.py refresh the committed copies the README shows).
    print(f"  {speed_accuracy_figure(figures / 'speed_accuracy.png')}")
    print(f"  {driven_speed_accuracy_figure(figures / 'driven_speed_accuracy.png')}")
    from ..charts import ince_strutt_figure  # Hill's equation: Floquet grid and series curves

    print(f"  {ince_strutt_figure(figures / 'ince_strutt.png')}")
    _demo_limit_cycle(out, args.overwrite_edited)
    _demo_slow_flow(out, figures, args.overwrite_edited)
    _demo_parametric(figures)
    if shutil.which("pdflatex"):
        for tex in sorted(out.glob("*.tex")):
            for _ in range(2):  # longtable settles its column widths on the second pass
                subprocess.run(["pdflatex", "-interaction=batchmode", "-halt-on-error",
                                "-output-directory", str(out), str(tex)],
                               check=True, stdout=subprocess.DEVNULL)
            print(f"  typeset {tex.with_suffix('.pdf')}")
    else:
        print("\npdflatex not found: `make demo` installs it; LaTeX sources are in", out)
    return 0


DEMO_CYCLE_ORDER = 12
DEMO_CYCLE_RESUM_ORDER = 60
DEMO_CYCLE_EPS = (0.1, 1.0, 2.5, 3.5, 5.0)
DEMO_CYCLE_LONG_ORDER = 164
# NOTE: partial sums to order 12, ω resummed from the exact series to order 60 (~25 s with its
# shooting checks): verified to ε ≈ 3.75, and one point past it, where the emitted evaluator
# answers NaN.  From order 164 (Andersen & Geer's order) it reaches ε = 10 in about four
# minutes: the demo names that run instead of making it (a demo shows the tool in a minute).


def _demo_limit_cycle(out: Path, overwrite_edited: bool) -> None:
    """The demo's limit cycle: van der Pol's evaluators (the partial sum and the resummed ω,
    NaN beyond their verified ε) and its derivation, against the shot cycle."""
    import numpy as np

    from ..compiler import generate_limit_cycle
    from ..derive.models import series_model
    from ..emit.render import load_generated
    from ..numerics.references import cycle_reference, cycle_samples

    model = series_model("van_der_pol", DEMO_CYCLE_ORDER + 2)
    print(f"\nvan der Pol's limit cycle, order {DEMO_CYCLE_ORDER}, ω resummed from order "
          f"{DEMO_CYCLE_RESUM_ORDER} (lindstedt generate van_der_pol --order {DEMO_CYCLE_ORDER} "
          f"--resum-order {DEMO_CYCLE_RESUM_ORDER} --out {out}):")
    for path in generate_limit_cycle(model, DEMO_CYCLE_ORDER, out,
                                     resum_order=DEMO_CYCLE_RESUM_ORDER,
                                     overwrite_edited=overwrite_edited):
        print(f"  {path}")
    print(f"  (the longer run: --resum-order {DEMO_CYCLE_LONG_ORDER} --allow-slow verifies the "
          "resummed omega to eps = 10, in about four minutes)")
    vdp = load_generated(out / "van_der_pol.py")
    eps = np.array(DEMO_CYCLE_EPS)
    print(f"  omega against the shot cycle (DOP853); the partial sum stops at |eps| = "
          f"{vdp.RADIUS:.3g}, the resummed omega is verified to |eps| <= "
          f"{vdp.RESUMMED_LIMIT:g}; NaN beyond")
    print(f"  {'eps':>5} {'partial sum':>18} {'resummed':>18} {'shot':>18} {'rel. error':>10}")
    for e, series, resummed in zip(eps, vdp.omega(eps), vdp.omega_resummed(eps), strict=True):
        shot = 2 * np.pi / cycle_reference(model, float(e)).period
        error = f"{abs(resummed / shot - 1):>10.1e}" if np.isfinite(resummed) else f"{'-':>10}"
        print(f"  {e:>5g} {series:>18.15f} {resummed:>18.15f} {shot:>18.15f} {error}")
    if hasattr(vdp, "q_resummed"):
        e = min(2.5, vdp.Q_RESUMMED_LIMIT)
        t, shot = cycle_samples(model, e, cycle_reference(model, e), 64)
        print(f"  q_resummed(t, {e:g}) over one period against the shot orbit: max error "
              f"{np.max(np.abs(vdp.q_resummed(t, e) - shot)):.1e} ({vdp.Q_RESUMMED_HARMONICS} "
              f"harmonics, verified to |eps| <= {vdp.Q_RESUMMED_LIMIT:g}, NaN beyond)")


def _demo_slow_flow(out: Path, figures: Path, overwrite_edited: bool) -> None:
    """The demo's slow flow: van der Pol's to order 2, emitted and typeset, run from r = 0.1
    against simulation, and its two figures."""
    import numpy as np

    from ..charts import slow_flow_figures
    from ..compiler import generate_slow_flow
    from ..derive.averaging import simulate, slow_flow, transient
    from ..derive.models import REGISTRY, oscillator
    from ..emit.render import load_generated

    text = REGISTRY["van_der_pol"].equation
    osc = oscillator(text, name="van_der_pol")
    command = f'lindstedt slowflow "{text}" --name van_der_pol --order 2'
    print(f"\nthe slow flow of van der Pol to order 2 ({command} --out {out}):")
    for path in generate_slow_flow(osc, 2, command, out, overwrite_edited=overwrite_edited):
        print(f"  {path}")
    emitted = load_generated(out / "van_der_pol_slow_flow.py")
    rate = emitted.slow_flow(np.array([2.0, 0.0]), 0.1)
    print(f"  at the cycle r = 2, eps = 0.1: dr/dt = {rate[0]:.3g}, dphi/dt = {rate[1]:.6f} "
          "(-eps^2/16 = -0.000625)")
    flow, eps = slow_flow(osc, 2), 0.1
    t = np.linspace(0.0, 80.0, 9)
    r_sim = np.hypot(*simulate(osc, eps, 0.1, 0.0, t))
    r_avg = np.hypot(*transient(flow, eps, 0.1, 0.0, t))
    print(f"  from r = 0.1 at eps = {eps}:")
    print(f"  {'t':>6}  {'r (simulation)':>15}  {'r (slow flow)':>14}")
    for ti, a, b in zip(t, r_sim, r_avg, strict=True):
        print(f"  {ti:>6.0f}  {a:>15.6f}  {b:>14.6f}")
    for path in slow_flow_figures(figures):
        print(f"  {path}")


DEMO_SUBHARMONIC = (0.1, 0.5, 1.3)
# NOTE: (ε, f, ω) where the notes' q₀ Hill test calls the "−" root stable and it is not.


def _demo_parametric(figures: Path) -> None:
    """The demo's parametric block: the response figure under ``figures``, the tongue and
    onsets, and one subharmonic where the full Hill equation corrects the notes' verdict."""
    from ..charts import PARAMETRIC_FIGURE, parametric_figure

    data = parametric_json(*PARAMETRIC_FIGURE, points=2)
    print(f"  {parametric_figure(*PARAMETRIC_FIGURE, figures / 'parametric.png')}")
    print()
    for line in [*_parametric_table(data)[:5], *_subharmonic_table(subharmonic_json(
            *DEMO_SUBHARMONIC))]:
        print(line)


def driven_json(d, order: int, harmonics: int) -> dict:
    """The contract of ``lindstedt driven … --json``: every distinct 1:1 orbit found
    (:func:`response.periodic_orbits`), largest first, each three ways where it can be.

    A branch carries the first-order root that stands for it (``seed`` says how the orbit was
    found, ``first_order`` how the root was paired with it); an orbit that no one-harmonic root
    stands for (found by continuing the balance through a fold the cubic does not have) has
    ``A1``, ``r``, ``delta0`` null and no μ-expansion, with ``mu_note`` saying why."""
    from ..analysis.driven import amplitudes, mu_expansion
    from ..analysis.periodic import periodic_orbits
    from ..numerics.floquet import multipliers_stable, orbit_hill_multipliers

    damped = d.damping > 0
    top = max(2 * harmonics - 1, 2 * order + 1)
    found = periodic_orbits(d, harmonics, shoot_harmonics=top)
    branches = []
    for orb in found.orbits:
        br, orbit, hb = orb.branch, orb.orbit, orb.balance
        orders: list[dict] = []
        if br is not None:
            mu = mu_expansion(d, br, order)
            for j in range(len(mu.coefficients)):
                c, phase = mu.partial(j)
                A, B = amplitudes(c, phase, 2 * j + 1)
                entry = {"order": j, "A": _keyed(A), "delta": phase, "r": _first_harmonic(A, B)}
                if damped:
                    entry["B"] = _keyed(B)
                orders.append(entry)
            mu_converged, mu_note = mu.converged, mu.reason
        else:
            mu_converged = False
            mu_note = ("no one-harmonic root stands for this orbit (found by continuing the "
                       "harmonic balance through a fold the one-harmonic cubic does not have "
                       "at this omega): no first-order data, no mu-expansion")
        if hb is not None:
            A, B = amplitudes(hb.coefficients, 0.0, 2 * harmonics - 1)
            hb_json = {"harmonics": harmonics, "A": _keyed(A), "residual": hb.residual,
                       "converged": hb.converged, "r": _first_harmonic(A, B)}
            if damped:
                hb_json["B"] = _keyed(B)
            # the full Hill equation about this balance orbit (no shooting)
            lam = orbit_hill_multipliers({(1, 0): 1.0, (3, 0): d.eps, (0, 1): d.damping}, A,
                                         B, d.omega)
            hb_json["full_hill_stable"] = multipliers_stable(lam, damped)
            hb_json["full_hill_moduli"] = sorted(float(abs(m)) for m in lam)
        else:
            hb_json = {"harmonics": harmonics, "A": {}, "residual": None, "converged": False,
                       "r": None}
        numerical = None
        if orbit is not None:
            numerical = {"A": _keyed(orbit.A), "floquet_moduli": sorted(
                float(abs(m)) for m in orbit.multipliers), "stable": orbit.stable,
                "r": _first_harmonic(orbit.A, orbit.B),
                "initial": [float(v) for v in orbit.initial]}
            if damped:
                numerical["B"] = _keyed(orbit.B)
        branches.append({
            "A1": None if br is None else br.A1, "r": None if br is None else abs(br.A1),
            "delta0": None if br is None else br.delta0, "seed": orb.seed,
            "first_order": orb.paired, "mu_expansion": orders,
            "mu_converged": mu_converged, "mu_note": mu_note,
            "harmonic_balance": hb_json, "numerical": numerical,
            **_shooting_json(orb.failure),
        })
    failures = found.failures or (None,) * len(found.roots)
    roots = [{"A1": br.A1, "r": abs(br.A1), "delta0": br.delta0, "branch": j,
              **_shooting_json(why)} for (br, j), why in zip(found.roots, failures, strict=True)]
    return {
        "parameters": {"eps": d.eps, "force": d.force, "omega": d.omega,
                       "Q": None if math.isinf(d.Q) else d.Q, "order": order,
                       "harmonics": harmonics},
        "branches": branches,
        "one_harmonic_roots": roots,
        "seeding": {"complete": found.complete, "note": found.note},
    }


def _shooting_json(failure) -> dict:
    """Why shooting found no orbit (``None`` where it found one); ``escapes``: the trajectory
    from the seed left the well (a softening spring: it runs off to infinity)."""
    return {"escapes": bool(failure is not None and failure.escaped),
            "shooting_note": None if failure is None else failure.reason}


def _keyed(values: dict) -> dict:
    return {str(n): float(v) for n, v in sorted(values.items())}


def _first_harmonic(A: dict, B: dict) -> float:
    """r = √(A₁² + B₁²), the amplitude of the first harmonic whatever its phase."""
    return float(math.hypot(A.get(1, 0.0), B.get(1, 0.0)))


def driven_table(data: dict) -> str:
    p = data["parameters"]
    lines = [f"q'' + q'/Q + q + eps q^3 = f cos(w t): eps = {p['eps']}, f = {p['force']}, "
             f"w = {p['omega']}, Q = {p['Q'] if p['Q'] is not None else 'inf (undamped)'}"]
    damped = p["Q"] is not None
    columns = ("r", "A1", "B1", "A3", "A5") if damped else ("A1", "A3", "A5")
    for i, br in enumerate(data["branches"], 1):
        num = br["numerical"]
        verdict = (("escapes the well" if br.get("escapes") else "no orbit found") if num is None
                   else "stable" if num["stable"] else "unstable")
        if br["A1"] is None:
            found = (f"true r = {num['r']:.6f}, " if num is not None else "") + \
                "found by continuation, no one-harmonic root"
            lines.append(f"\nbranch {i}: {found} ({verdict})")
        else:
            first = (f"r = {br['r']:.6f}, phase delta0 = {br['delta0']:.6f}" if damped
                     else f"A1 = {br['A1']:.6f}")
            lines.append(f"\nbranch {i}: first-order {first} ({verdict})")
        lines.append(f"{'':>22} " + " ".join(f"{c:>12}" for c in columns))
        hb = br["harmonic_balance"]
        rows = [(f"mu-expansion order {e['order']}", e) for e in br["mu_expansion"]]
        rows.append((f"harmonic balance N={hb['harmonics']}", hb))
        if num is not None:
            rows.append(("numerical (shooting)", num))
        for label, row in rows:
            if row is hb and not hb["converged"]:
                why = "" if hb["residual"] is None else f": residual {hb['residual']:.1e}"
                lines.append(f"{label:>22} (did not converge{why})")
                continue
            values = {"r": row["r"], **{f"A{k}": v for k, v in row["A"].items()},
                      **{f"B{k}": v for k, v in row.get("B", {}).items()}}
            cells = " ".join(f"{values[c]:>12.6f}" if c in values else f"{'':>12}"
                             for c in columns)
            lines.append(f"{label:>22} {cells}")
        if "full_hill_stable" in hb:
            lines.append("  full Hill equation about the balance: "
                         f"{'stable' if hb['full_hill_stable'] else 'unstable'} (|multipliers| "
                         + ", ".join(f"{m:.6g}" for m in hb["full_hill_moduli"]) + ")")
        if br.get("first_order") == "rank":
            lines.append("  note: the first-order root of the same rank in amplitude (shooting "
                         "from it reached another orbit)")
        if not br["mu_converged"]:
            lines.append(f"  warning: {br['mu_note']}")
        if num is None and br.get("shooting_note"):
            lines.append(f"  shooting: {br['shooting_note']}")
    for root in data.get("one_harmonic_roots", []):
        if root["branch"] is None:
            first = (f"r = {root['r']:.6f}, phase delta0 = {root['delta0']:.6f}" if damped
                     else f"A1 = {root['A1']:.6f}")
            if root.get("escapes"):
                lines.append(f"\nwarning: the one-harmonic root {first} stands for no orbit: "
                             f"{root['shooting_note']}")
            else:
                lines.append(f"\nwarning: the one-harmonic root {first} stands for no orbit "
                             "found (shooting from it reached none, or one a nearer root "
                             "stands for)")
    seeding = data.get("seeding")
    if damped and seeding is not None and not seeding["complete"]:
        lines.append(f"\nwarning: seeds from the one-harmonic roots only ({seeding['note']}); "
                     "orbits beyond them may be missing")
    return "\n".join(lines)


def driven_equation_json(text: str, values: dict[str, str], omega: float, harmonics: int,
                         name: str = "oscillator") -> dict:
    """The contract of ``lindstedt driven EQUATION … --json``: every distinct 1:1 orbit found
    (:func:`response.equation_orbits`), largest first, each by its harmonic balance (``A``
    holds the constant ``"0"`` and even harmonics unless the force is odd) and, checked by
    shooting, the true orbit with its Floquet moduli and verdict."""
    from ..analysis.periodic import equation_orbits
    from ..analysis.polynomial import driven_equation

    de = driven_equation(text, values, omega, name)
    found = equation_orbits(de, harmonics)
    branches = []
    for orb in found.orbits:
        hb_json = {"harmonics": harmonics, "A": {}, "B": {}, "residual": orb.residual,
                   "converged": orb.converged, "r": None}
        if orb.balance is not None:
            A, B = found.system.amplitudes(orb.balance)
            hb_json.update(A=_keyed(A), B=_keyed(B), r=_first_harmonic(A, B))
        numerical = None
        if orb.orbit is not None:
            o = orb.orbit
            numerical = {"A": _keyed(o.A), "B": _keyed(o.B), "floquet_moduli": sorted(
                float(abs(m)) for m in o.multipliers), "stable": o.stable,
                "r": _first_harmonic(o.A, o.B), "initial": [float(v) for v in o.initial],
                "residual": o.residual}
        branches.append({
            "r": None if numerical is None else numerical["r"],
            "stable": None if numerical is None else numerical["stable"],
            "harmonic_balance": hb_json, "numerical": numerical,
            **_shooting_json(orb.failure),
        })
    return {
        "equation": text,
        "name": name,
        "parameters": {"omega": omega, "harmonics": harmonics, "values": dict(de.values),
                       "drive": {"amplitude": de.force, "frequency": de.frequency}},
        "force": [{"q": a, "dq": b, "c": c} for (a, b), c in sorted(de.terms.items())],
        "odd": de.odd,
        "branches": branches,
        "seeding": {"complete": found.complete, "note": found.note},
    }


def driven_equation_table(data: dict) -> str:
    p = data["parameters"]
    given = ", ".join(f"{k} = {v}" for k, v in p["values"].items())
    lines = [f"{data['equation']}: {given}{', ' if given else ''}{p['drive']['frequency']} = "
             f"{p['omega']}"]
    orders = ([1, 3, 5] if data["odd"] else [0, 1, 2, 3])
    columns = ["r", *(f"A{k}" for k in orders), *(f"B{k}" for k in orders if k)]
    for i, br in enumerate(data["branches"], 1):
        num = br["numerical"]
        verdict = (("escapes" if br.get("escapes") else "no orbit found") if num is None
                   else "stable" if num["stable"] else "unstable")
        moduli = "" if num is None else ", Floquet |lambda| = " + ", ".join(
            f"{m:.6f}" for m in num["floquet_moduli"])
        lines.append(f"\nbranch {i}: r = {br['r'] if br['r'] is None else round(br['r'], 6)}"
                     f" ({verdict}{moduli})")
        lines.append(f"{'':>22} " + " ".join(f"{c:>11}" for c in columns))
        hb = br["harmonic_balance"]
        rows = [(f"harmonic balance N={hb['harmonics']}", hb)]
        if num is not None:
            rows.append(("numerical (shooting)", num))
        for label, row in rows:
            if row is hb and not hb["converged"]:
                lines.append(f"{label:>22} (did not converge)")
                continue
            values = {"r": row["r"], **{f"A{k}": v for k, v in row["A"].items()},
                      **{f"B{k}": v for k, v in row["B"].items()}}
            lines.append(f"{label:>22} " + " ".join(
                f"{values[c]:>11.6f}" if c in values else f"{'':>11}" for c in columns))
        if num is None and br.get("shooting_note"):
            lines.append(f"  shooting: {br['shooting_note']}")
    seeding = data["seeding"]
    if not seeding["complete"]:
        lines.append(f"\nwarning: {seeding['note']}; orbits beyond it may be missing")
    return "\n".join(lines)


DRIVE_FLAGS = ("eps", "force", "Q")


def _cmd_driven(args: argparse.Namespace) -> int:
    from ..analysis.driven import Drive, check_steady_state

    if args.model is not None:
        given = [f"--{k}" for k in DRIVE_FLAGS if getattr(args, k) is not None]
        if given:
            raise InputError(f"{', '.join(given)}: with an equation give its parameters with "
                             "--param (e.g. --param eps=1/10) and the drive in the equation")
        if args.omega is None:
            raise InputError("--omega: the drive frequency is required")
        data = driven_equation_json(args.model, _params(args.param), args.omega,
                                    args.harmonics, args.name or "oscillator")
        print(json.dumps(data) if args.json else driven_equation_table(data))
        return 0
    if args.param or args.name:
        raise InputError("--param/--name: give an equation (EQUATION) to take them")
    missing = [f"--{k}" for k in ("eps", "force", "omega") if getattr(args, k) is None]
    if missing:
        raise InputError(f"the following arguments are required: {', '.join(missing)}")
    d = Drive(args.eps, args.force, args.omega, math.inf if args.Q is None else args.Q)
    check_steady_state(d.eps, d.Q, d.omega)
    data = driven_json(d, args.order, args.harmonics)
    print(json.dumps(data) if args.json else driven_table(data))
    return 0


def response_json(eps: float, force: float, Q: float, harmonics: int,
                  max_seconds: float = COST_LIMIT_SECONDS) -> dict:
    """The contract of ``lindstedt response … --json``: folds three ways, sweep jumps
    (``max_seconds``: the continuation's cost limit)."""
    import numpy as np

    from ..analysis.driven import BalanceSystem, Drive
    from ..analysis.response import continue_balance, one_harmonic_folds, response_range
    from ..numerics.integrate import sweep
    from ..numerics.shooting import orbit_fold

    d = Drive(eps, force, 1.0, Q)
    if d.damping == 0:
        raise InputError("Q inf: a response curve needs damping (finite Q) for a steady state")
    folds1 = one_harmonic_folds(eps, force, Q)
    lo, hi = response_range(eps, force, Q)
    cont = continue_balance(eps, force, Q, harmonics, lo, hi, max_seconds=max_seconds)
    system = BalanceSystem(eps, force, d.damping, harmonics)
    odd = system.odd
    true_folds = []
    for w in cont.folds:
        x = cont.x[int(np.argmin(np.abs(cont.omega - w)))]
        y0 = np.array([x[:harmonics].sum(), w * np.sum(odd * x[harmonics:])])
        found = orbit_fold(eps, force, d.damping, w, y0)
        if found is not None:
            true_folds.append(found[0])
    up = sweep(eps, force, d.damping, lo, hi)
    down = sweep(eps, force, d.damping, hi, lo)
    return {
        "parameters": {"eps": eps, "force": force, "Q": Q, "harmonics": harmonics,
                       "omega_range": [lo, hi]},
        "one_harmonic": {"folds": [float(w) for w in folds1]},
        "harmonic_balance": {"harmonics": harmonics, "folds": [float(w) for w in cont.folds]},
        "numerical": {"folds": sorted(true_folds), "sweep_up_jump": up.jump,
                      "sweep_down_jump": down.jump, "sweep_resolution": up.resolution,
                      "sweep_up_escape": up.escape, "sweep_down_escape": down.escape},
    }


def _report(args: argparse.Namespace, compute, draw, table) -> int:
    """The shape of every effect command: check the plot path first (nothing is computed for
    a figure that cannot be written), compute, draw, print JSON or the table.  matplotlib
    is imported only for --plot (a refused input answers without it)."""
    plot = _charts().check_plot_path(Path(args.plot)) if args.plot else None
    data = compute()
    if plot is not None:
        draw(plot)
    print(json.dumps(data) if args.json else "\n".join(table(data)))
    return 0


def _charts():
    from .. import charts

    return charts


def response_equation_json(text: str, values: dict[str, str], harmonics: int,
                           name: str = "oscillator", omega_min: float | None = None,
                           omega_max: float | None = None,
                           max_seconds: float = COST_LIMIT_SECONDS) -> dict:
    """The contract of ``lindstedt response EQUATION … --json``: the keys of
    :func:`response_json` (``parameters`` as ``driven EQUATION``'s, with ``omega_range``),
    with the folds of the general one-harmonic balance, of the continued N-harmonic balance,
    and of the true orbit (each with its Floquet moduli), the sweeps' jumps and escapes."""
    import numpy as np

    from ..analysis.periodic import orbit_fold_table
    from ..analysis.response import equation_response

    curve = equation_response(text, values, harmonics, name, omega_min, omega_max, max_seconds)
    de, er, cont, up, down = curve.de, curve.er, curve.cont, curve.up, curve.down
    lo, hi = er.omega_range
    true_folds = []
    for w in cont.folds:
        x = cont.x[int(np.argmin(np.abs(cont.omega - w)))]
        found = orbit_fold_table(curve.table, de.force, w, curve.fine.state(x, w))
        if found is not None:
            true_folds.append((found[0], sorted(float(abs(m)) for m in found[2])))
    true_folds.sort()
    bound = curve.bound
    return {
        "equation": text,
        "name": name,
        "parameters": {"harmonics": harmonics, "omega_range": [lo, hi],
                       "values": dict(de.values), "linear_frequency": er.linear_frequency,
                       "drive": {"amplitude": de.force, "frequency": de.frequency}},
        "force": [{"q": a, "dq": b, "c": c} for (a, b), c in sorted(de.terms.items())],
        "odd": de.odd,
        "one_harmonic": {"folds": [float(w) for w in er.one_harmonic_folds]},
        "harmonic_balance": {"harmonics": harmonics, "folds": [float(w) for w in cont.folds],
                             "complete": cont.complete},
        "numerical": {"folds": [w for w, _ in true_folds],
                      "fold_floquet_moduli": [m for _, m in true_folds],
                      "sweep_up_jump": up.jump, "sweep_down_jump": down.jump,
                      "sweep_resolution": up.resolution, "sweep_up_escape": up.escape,
                      "sweep_down_escape": down.escape, "escape_bound": bound},
    }


RESPONSE_EQUATION_ONLY = ("omega_min", "omega_max")


def _response_args(args: argparse.Namespace) -> None:
    """The flags of ``response`` with and without EQUATION, each refused in one line where it
    does not belong."""
    if args.model is not None:
        given = [f"--{k}" for k in DRIVE_FLAGS if getattr(args, k) is not None]
        if given:
            raise InputError(f"{', '.join(given)}: with an equation give its parameters with "
                             "--param (e.g. --param eps=1/10) and the drive in the equation")
        return
    if args.param or args.name or any(getattr(args, k) is not None
                                      for k in RESPONSE_EQUATION_ONLY):
        raise InputError("--param/--name/--omega-min/--omega-max: give an equation (EQUATION) "
                         "to take them")
    missing = [f"--{k}" for k in DRIVE_FLAGS if getattr(args, k) is None]
    if missing:
        raise InputError(f"the following arguments are required: {', '.join(missing)}")


def _cmd_response(args: argparse.Namespace) -> int:
    _response_args(args)
    limit = math.inf if args.allow_slow else COST_LIMIT_SECONDS
    if args.model is not None:
        values, name = _params(args.param), args.name or "oscillator"
        return _report(
            args, lambda: response_equation_json(args.model, values, args.harmonics, name,
                                                 args.omega_min, args.omega_max, limit),
            lambda path: _charts().response_equation_figure(
                args.model, values, args.harmonics, path, name, args.omega_min,
                args.omega_max, limit),
            _response_equation_table)
    return _report(
        args, lambda: response_json(args.eps, args.force, args.Q, args.harmonics,
                                    math.inf if args.allow_slow else COST_LIMIT_SECONDS),
        lambda path: _charts().response_figure(
            args.eps, args.force, args.Q, args.harmonics, path,
            math.inf if args.allow_slow else COST_LIMIT_SECONDS),
        _response_table)


def _response_table(data: dict) -> list[str]:
    p = data["parameters"]
    harmonics = data["harmonic_balance"]["harmonics"]
    lines = []
    lines.append(f"q'' + q'/Q + q + eps q^3 = f cos(w t): eps = {p['eps']}, f = {p['force']}, "
                 f"Q = {p['Q']}; w in [{p['omega_range'][0]:.4g}, {p['omega_range'][1]:.4g}]")
    for label, folds in (("one harmonic", data["one_harmonic"]["folds"]),
                         (f"harmonic balance N={harmonics}", data["harmonic_balance"]["folds"]),
                         ("true orbit (Floquet +1)", data["numerical"]["folds"])):
        lines.append(f"{label:>26}: folds " + (", ".join(f"{w:.12f}" for w in folds) or "none"))
    num = data["numerical"]
    for way in ("up", "down"):
        value, escape = num[f"sweep_{way}_jump"], num[f"sweep_{way}_escape"]
        if escape is not None:
            text = (f"escapes the well at {escape:.4f} (over the barrier |q| = "
                    f"{1 / math.sqrt(-p['eps']):.3g}: no steady state beyond)")
        elif value is not None:
            text = f"jumps at {value:.4f} (sweep step {num['sweep_resolution']:.1e} per period)"
        else:
            text = "no jump"
        lines.append(f"{'sweep ' + way:>26}: {text}")
    return lines


def _response_equation_table(data: dict) -> list[str]:
    p = data["parameters"]
    given = ", ".join(f"{k} = {v}" for k, v in p["values"].items())
    harmonics = data["harmonic_balance"]["harmonics"]
    lo, hi = p["omega_range"]
    lines = [f"{data['equation']}: {given}{'; ' if given else ''}{p['drive']['frequency']} in "
             f"[{lo:.4g}, {hi:.4g}] (omega0 = {p['linear_frequency']:.6g})"]
    num = data["numerical"]
    for label, folds in (("one harmonic", data["one_harmonic"]["folds"]),
                         (f"harmonic balance N={harmonics}", data["harmonic_balance"]["folds"]),
                         ("true orbit (Floquet +1)", num["folds"])):
        lines.append(f"{label:>26}: folds " + (", ".join(f"{w:.12f}" for w in folds) or "none"))
    for way in ("up", "down"):
        value, escape = num[f"sweep_{way}_jump"], num[f"sweep_{way}_escape"]
        if escape is not None:
            text = (f"escapes at {escape:.4f} (|q| past {num['escape_bound']:.3g}, 10 times "
                    "every balance solution's: no steady state beyond)")
        elif value is not None:
            text = f"jumps at {value:.4f} (sweep step {num['sweep_resolution']:.1e} per period)"
        else:
            text = "no jump"
        lines.append(f"{'sweep ' + way:>26}: {text}")
    if not data["harmonic_balance"]["complete"]:
        lines.append("warning: a balance at an end of the range did not converge from its "
                     "one-harmonic root: pieces of the curve may be missing")
    return lines


def subharmonic_json(eps: float, force: float, omega: float) -> dict:
    """The contract of ``lindstedt subharmonic … --json`` (eq. 10.83–10.87)."""
    from ..analysis.subharmonic import subharmonic

    exists, reason, solutions = subharmonic(eps, force, omega)
    return {
        "parameters": {"eps": eps, "force": force, "omega": omega, "drive": 3 * omega},
        "exists": exists,
        "reason": reason,
        "solutions": [{
            "root": s.root,
            "a": s.a,
            "F": s.F,
            "hill_stable": s.hill_stable,
            "floquet_moduli": sorted(float(abs(m)) for m in s.hill_multipliers),
            "numerical": None if s.orbit is None else {
                "a1": s.orbit.A[1], "a3": s.orbit.A[3], "stable": s.orbit.stable,
                "simulation_locks": s.locked,
                "floquet_moduli": sorted(float(abs(m)) for m in s.orbit.multipliers)},
            "full_hill": None if s.balance is None else {
                "a1": s.balance[0][1], "a3": s.balance[0][3], "stable": s.full_hill_stable,
                "floquet_moduli": sorted(float(abs(m)) for m in s.full_hill_multipliers)},
        } for s in solutions],
    }


def _equation_args(args: argparse.Namespace, flags: Sequence[str],
                   required: Sequence[str]) -> bool:
    """Whether an EQUATION was given; refuses in one line the flags it replaces beside it, its
    own flags without it, and a missing required flag without it."""
    if args.model is not None:
        given = [f"--{k}" for k in flags if getattr(args, k) is not None]
        if given:
            raise InputError(f"{', '.join(given)}: with an equation give its parameters with "
                             "--param (e.g. --param eps=1/10) and the drive in the equation")
        return True
    if args.param or args.name:
        raise InputError("--param/--name: give an equation (EQUATION) to take them")
    missing = [f"--{k}" for k in required if getattr(args, k) is None]
    if missing:
        raise InputError(f"the following arguments are required: {', '.join(missing)}")
    return False


def subharmonic_equation_json(text: str, values: dict[str, str], omega: float | None,
                              name: str = "oscillator", n: int = 3) -> dict:
    """The contract of ``lindstedt subharmonic EQUATION --n N … --json``: every orbit of n
    drive periods (balance, shooting, Floquet), the primary response and the onset.  For the
    notes' eq. 10.83 (n = 3, ``q + εq³``, undamped) the closed form's keys of
    :func:`subharmonic_json` as well."""
    from ..analysis.subharmonic import subharmonic_equation, subharmonic_orbits

    problem = subharmonic_equation(text, values, omega, n, name)
    found = subharmonic_orbits(problem)
    data = {"equation": text, "name": name, **subharmonic_orbits_json(found)}
    data["parameters"]["values"] = dict(problem.values)
    if problem.eps is not None:
        notes = subharmonic_json(problem.eps, problem.force, problem.omega)
        data = {**data, **notes, "parameters": {**data["parameters"], **notes["parameters"]}}
    return data


def subharmonic_orbits_json(found) -> dict:
    """The general fields of the subharmonic's JSON (:class:`subharmonic.SubharmonicResponse`)."""
    p = found.problem

    def moduli(orbit) -> list[float]:
        return sorted(float(abs(m)) for m in orbit.multipliers)

    def orbit_json(o) -> dict:
        return {"r": o.r, "A": _keyed(o.A), "B": _keyed(o.B), "stable": o.stable,
                "balance_residual": o.residual,
                "shooting": None if o.orbit is None else {
                    "a1": o.orbit.A.get(1, 0.0), "b1": o.orbit.B.get(1, 0.0),
                    "deviation": o.deviation, "floquet_moduli": moduli(o.orbit)}}

    primary = found.primary
    return {
        "n": p.n,
        "parameters": {"omega": p.omega, "drive": p.drive, "force": p.force,
                       "harmonics": found.harmonics},
        "exists": found.exists,
        "reason": found.reason,
        "orbits": [orbit_json(o) for o in found.orbits],
        "primary": None if primary is None else {
            "amplitude": math.hypot(primary.A.get(p.n, 0.0), primary.B.get(p.n, 0.0)),
            "stable": primary.stable,
            "floquet_moduli": None if primary.orbit is None else moduli(primary.orbit)},
        "onset": None if found.onset is None else {"force": found.onset.force,
                                                   "kind": found.onset.kind},
        "seeds": found.seeds,
    }


def _cmd_subharmonic(args: argparse.Namespace) -> int:
    n = 3 if args.n is None else args.n
    if _equation_args(args, ("eps", "force"), ("eps", "force", "omega")):
        from ..analysis.subharmonic import subharmonic_equation

        values, name = _params(args.param), args.name or "oscillator"
        problem = subharmonic_equation(args.model, values, args.omega, n, name)
        if problem.eps is not None:
            draw = lambda path: _charts().subharmonic_figure(  # noqa: E731
                problem.eps, problem.force, path)
        else:
            draw = lambda path: _charts().subharmonic_orbits_figure(  # noqa: E731
                args.model, values, args.omega, n, name, path)
        return _report(args, lambda: subharmonic_equation_json(args.model, values, args.omega,
                                                               name, n),
                       draw, _subharmonic_table)
    if n != 3:
        raise InputError(f"--n {n}: the notes' eq. 10.83 (--eps, --force) is the 1/3 "
                         "subharmonic; give an EQUATION for another n")
    return _report(args, lambda: subharmonic_json(args.eps, args.force, args.omega),
                   lambda path: _charts().subharmonic_figure(args.eps, args.force, path),
                   _subharmonic_table)


def _subharmonic_table(data: dict) -> list[str]:
    p = data["parameters"]
    if "solutions" not in data:
        return _orbits_table(data)
    lines = [f"omega^2 q'' + q + eps q^3 = f cos 3tau: eps = {p['eps']}, f = {p['force']}, "
             f"omega = {p['omega']} (drive at {p['drive']:g})",
             ("exists: " if data["exists"] else "no subharmonic: ") + data["reason"]]
    for s in data["solutions"]:
        num = s["numerical"]
        true = "no orbit found" if num is None else (
            f"true orbit a1 = {num['a1']:.6f}, {'stable' if num['stable'] else 'unstable'}, "
            f"a simulation 1% off it {'locks on' if num['simulation_locks'] else 'drifts away'}")
        full = s["full_hill"]
        lines.append(f"  root {s['root']}: a = {s['a']:.6f}, Hill: "
                     f"{'stable' if s['hill_stable'] else 'unstable'}; full Hill: "
                     + ("no balance" if full is None else
                        f"{'stable' if full['stable'] else 'unstable'} (a1 = {full['a1']:.6f})")
                     + f"; {true}")
    if "orbits" in data:
        lines += _orbits_table(data)[2:]
    return lines


def _orbits_table(data: dict) -> list[str]:
    p, n = data["parameters"], data["n"]
    lines = [f"{data['equation']}: orbits of {n} drive periods (the 1/{n} subharmonic), "
             f"omega = {p['omega']:g}, drive at {p['drive']:g}, f = {p['force']:g}",
             ("exists: " if data["exists"] else "no subharmonic: ") + data["reason"]]
    for i, o in enumerate(data["orbits"], 1):
        shot = o["shooting"]
        verdict = ("shooting found no orbit" if shot is None else
                   f"{'stable' if o['stable'] else 'unstable'} (Floquet |lambda| max "
                   f"{max(shot['floquet_moduli']):.6g}), shooting agrees to "
                   f"{shot['deviation']:.1e}")
        lines.append(f"  orbit {i}: r = {o['r']:.8f} (A1 = {o['A']['1']:.8f}, "
                     f"B1 = {o['B']['1']:.8f}); {verdict}")
    pr = data["primary"]
    if pr is not None:
        lines.append(f"  primary response (one drive period): harmonic {n} amplitude "
                     f"{pr['amplitude']:.8f}, "
                     + ("not shot" if pr["stable"] is None else
                        "stable" if pr["stable"] else "unstable"))
    on = data["onset"]
    if on is not None:
        how = "a fold" if on["kind"] == "fold" else "a bifurcation off the primary response"
        lines.append("  onset at this omega: " + (
            "none: the orbits continue down to f = 0" if on["kind"] == "none" else
            f"f = {on['force']:.8g} ({how})"))
    return lines


MAX_PARAMETRIC_POINTS = 401
# NOTE: ω points of the range: 401 draw a smooth curve; their cost with --harmonics is
# costs.parametric_cost's.
PARAMETRIC_SHOTS = 10
# NOTE: shooting at about ten ω of the range, every branch there: the numerical truth.


def parametric_json(eps: float, zeta: float, gamma: float, omega_from: float, omega_to: float,
                    points: int = 41, harmonics: int = 8) -> dict:
    """The contract of ``lindstedt parametric … --json``: the tongue, the onsets, the fold and
    every branch point (one harmonic, balance with its full-Hill verdict, shooting)."""
    import numpy as np

    from ..analysis.parametric import Pump, check_omega, fold, onsets, response, tongue_edges

    p = Pump(eps, zeta, gamma)
    lo, hi = check_omega(omega_from, "--omega-from"), check_omega(omega_to, "--omega-to")
    if not lo < hi:
        raise InputError(f"--omega-from {lo:g} --omega-to {hi:g}: the range must increase")
    if not 2 <= points <= MAX_PARAMETRIC_POINTS:
        raise InputError(f"--points {points}: must be in 2..{MAX_PARAMETRIC_POINTS}")
    if isinstance(harmonics, bool) or not 1 <= harmonics <= MAX_HARMONICS:
        raise InputError(f"--harmonics {harmonics}: must be in 1..{MAX_HARMONICS}")
    rows = response(p, np.linspace(lo, hi, points), harmonics,
                    shoot_every=max(1, (points - 1) // PARAMETRIC_SHOTS))
    edges, top = tongue_edges(p), fold(p)

    def moduli(lam) -> list[float]:
        return sorted(float(abs(m)) for m in lam)

    return {
        "equation": "q'' + 2 zeta q' + (1 + eps cos 2wt) q + gamma q^3 = 0",
        "parameters": {"eps": eps, "zeta": zeta, "gamma": gamma, "omega_from": lo,
                       "omega_to": hi, "points": points, "harmonics": harmonics},
        "tongue": None if edges is None else {"lower": edges[0], "upper": edges[1]},
        "onsets": [{"omega": o.omega, "branch": o.branch, "supercritical": o.supercritical}
                   for o in onsets(p)],
        "fold": None if top is None else {"omega": top[0], "r": top[1]},
        "branches": [{
            "branch": r.one.branch, "omega": r.one.omega,
            "one_harmonic": {"a": r.one.a, "b": r.one.b, "r": r.one.r, "stable": r.one.stable},
            "balance": None if r.balance is None else {
                "r": r.balance.r, "residual": r.balance.residual,
                "full_hill_stable": r.balance.stable,
                "floquet_moduli": moduli(r.balance.multipliers)},
            "shooting": None if r.orbit is None else {
                "r": math.hypot(r.orbit.A[1], r.orbit.B[1]), "stable": r.orbit.stable,
                "floquet_moduli": moduli(r.orbit.multipliers)},
        } for r in rows],
    }


def _parametric_table(data: dict) -> list[str]:
    p, t = data["parameters"], data["tongue"]
    lines = [f"{data['equation']}: eps = {p['eps']}, zeta = {p['zeta']}, gamma = {p['gamma']}",
             "tongue (one harmonic): " + ("closed by the damping" if t is None else
                                          f"{t['lower']:.6f} < omega < {t['upper']:.6f}")]
    for o in data["onsets"]:
        lines.append(f"onset of branch {o['branch']} at omega = {o['omega']:.6f}: "
                     + ("supercritical" if o["supercritical"] else "subcritical"))
    if data["fold"] is not None:
        lines.append(f"fold (branches + and - meet): omega = {data['fold']['omega']:.6g}, "
                     f"r = {data['fold']['r']:.6g}")
    lines.append(f"{'omega':>9} {'branch':>6} {'r (1 harm.)':>12} {'stable':>7} "
                 f"{'r (balance)':>12} {'full Hill':>9} {'r (shot)':>12} {'shot':>8}")
    lines.append("  (branch 0 is q = 0: its Floquet multipliers are Mathieu's; a balance 'none' "
                 "fell onto q = 0: the true tongue is O(eps^2) off the one-harmonic one)")
    for b in data["branches"]:
        one, bal, shot = b["one_harmonic"], b["balance"], b["shooting"]
        lines.append((
            f"{b['omega']:>9.5f} {b['branch']:>6} {one['r']:>12.8f} "
            f"{'yes' if one['stable'] else 'no':>7} "
            + (f"{'' if b['branch'] == '0' else 'none':>12} {'':>9}" if bal is None else
               f"{bal['r']:>12.8f} {'yes' if bal['full_hill_stable'] else 'no':>9}")
            + ("" if shot is None else
               f" {shot['r']:>12.8f} {'stable' if shot['stable'] else 'unstable':>8}"))
            .rstrip())
    return lines


def _cmd_parametric(args: argparse.Namespace) -> int:
    return _report(args, lambda: parametric_json(args.eps, args.zeta, args.gamma,
                                                 args.omega_from, args.omega_to, args.points,
                                                 args.harmonics),
                   lambda path: _charts().parametric_figure(args.eps, args.zeta, args.gamma,
                                                            args.omega_from, args.omega_to,
                                                            path),
                   _parametric_table)


def mixing_json(eps: float, Q: float, drives: list[tuple[float, float]]) -> dict:
    """The contract of ``lindstedt mixing … --json``: predicted and simulated tones of the
    notes' ``q̈ + q̇/Q + q + εq³`` (:func:`mixing_tones_json` of its table)."""
    from ..analysis.driven import Drive
    from ..numerics.integrate import duffing_table

    Drive(eps, 1.0, 1.0, Q)  # ε and Q first, then every drive's numbers
    for f, w in drives:
        try:
            Drive(eps, f, w, Q)
        except InputError as exc:
            raise InputError(f"drive {f!r}@{w!r}: {exc}") from None
    data = mixing_tones_json(duffing_table(eps, 1 / Q), drives)
    data["parameters"].update(eps=eps, Q=Q)
    return data


def mixing_tones_json(table, drives: list[tuple[float, float]]) -> dict:
    """Predicted (:func:`mixing.mixing_series`) and simulated tones of ``q̈ + g = Σ f_i cos
    ω_i t``, ``g`` the :class:`numerics.ForceTable`; ``eps`` and ``Q`` among the parameters
    when ``g`` is the notes' ``q + εq³ + q̇/Q``."""
    from ..analysis.mixing import mixing_series, simulated_fit, tone_label

    series = mixing_series(table, drives)
    fit = simulated_fit(table, drives, list(series.tones))
    terms = table.terms
    parameters: dict = {}
    if set(terms) <= {(1, 0), (3, 0), (0, 1)} and terms.get((1, 0)) == 1.0:
        parameters = {"eps": terms.get((3, 0), 0.0), "Q": 1 / terms[(0, 1)]}
    return {
        "parameters": {**parameters, "drives": [{"force": f, "omega": w} for f, w in drives]},
        "expansion_parameter": series.expansion_parameter,
        "converged": series.converged,
        "reason": series.reason,
        "simulated_rms_residual": fit.rms_residual,
        "tones": [{"frequency": t.frequency, "combination": tone_label(t.combination),
                   "order": t.order, "predicted": t.predicted, "simulated": float(a),
                   "simulated_uncertainty": float(u), "resolved": bool(a > 3 * u)}
                  for t, a, u in zip(series.tones, fit.amplitudes, fit.uncertainty,
                                     strict=True)],
    }


def _drive(text: str) -> tuple[float, float]:
    try:
        f, w = text.split("@")
        return float(f), float(w)
    except ValueError:
        raise argparse.ArgumentTypeError(f"drive {text!r}: expected F@W, e.g. 0.3@1.3") from None


def mixing_equation_json(text: str, values: dict[str, str], name: str = "oscillator") -> dict:
    """:func:`mixing_tones_json` of a user's equation, any polynomial force with a linear
    stiffness and damping (drives by ascending frequency), with ``equation``, ``name`` and the
    ``parameters.values`` given."""
    from ..analysis.mixing import mixing_equation

    table, drives, given = mixing_equation(text, values, name)
    data = mixing_tones_json(table, drives)
    data["parameters"]["values"] = dict(given)
    return {"equation": text, "name": name, **data}


def _cmd_mixing(args: argparse.Namespace) -> int:
    if _equation_args(args, ("eps", "Q", "drive"), ("eps", "Q", "drive")):
        from ..analysis.mixing import mixing_equation

        values, name = _params(args.param), args.name or "oscillator"
        table, drives, _ = mixing_equation(args.model, values, name)
        return _report(args, lambda: mixing_equation_json(args.model, values, name),
                       lambda path: _charts().mixing_figure(table, drives, path, args.model),
                       _mixing_table)

    def draw(path: Path) -> Path:
        from ..numerics.integrate import duffing_table

        return _charts().mixing_figure(duffing_table(args.eps, 1 / args.Q), args.drive, path,
                                       f"ε = {args.eps}, Q = {args.Q}")

    return _report(args, lambda: mixing_json(args.eps, args.Q, args.drive), draw,
                   _mixing_table)


def _mixing_table(data: dict) -> list[str]:
    p = data["parameters"]
    head = (f"{data['equation']}: " if "equation" in data else
            f"q'' + q'/Q + q + eps q^3 = sum f_i cos(w_i t): eps = {p['eps']}, Q = {p['Q']}, ")
    lines = [head + ", ".join(f"w{i} = {d['omega']} (f = {d['force']})"
                         for i, d in enumerate(p["drives"], 1)),
             ("" if data["converged"] else "warning: ") + data["reason"],
             f"{'tone':>12} {'frequency':>10} {'order':>6} {'predicted':>11} {'simulated':>11} "
             f"{'+/-':>9}"]
    for t in data["tones"]:
        lines.append(f"{t['combination']:>12} {t['frequency']:>10.4f} {t['order']:>6} "
                     f"{t['predicted']:>11.3e} {t['simulated']:>11.3e} "
                     f"{t['simulated_uncertainty']:>9.1e}"
                     + ("" if t["resolved"] else "  (below the fit's noise)"))
    return lines


def _considered(rows: Sequence[tuple[str, int, float, float]], quantity: str | None = None
                ) -> list[dict]:
    """``choose``'s per-method rows as JSON records."""
    return [{"method": str(m), "order": o, "label": _label(m, o, quantity), "max_error": e,
             "ns_per_point": ns} for m, o, e, ns in rows]


def _label(method, order: int, quantity: str | None = None) -> str:
    """A method at an order as tables print it: the registry record's own label (the Padé
    approximant names itself), else "NAME order K"."""
    label = getattr(method, "label", None)
    if label is None and quantity is not None:
        from ..methods.registry import methods_for

        label = next((m.label for m in methods_for(quantity) if m == method), None)
    return label(order) if callable(label) else f"{method} order {order}"


def _print_choice(header: str, chosen: tuple[str, int, float, float],
                  rows: Sequence[tuple[str, int, float, float]], micro: bool = False,
                  quantity: str | None = None) -> None:
    """The text report of every ``choose``: the header, the choice, each method considered
    (cost in ns/point, or µs when ``micro``)."""
    unit, scale = ("µs/point", 1e-3) if micro else ("ns/point", 1.0)
    print(header)
    m, o, e, ns = chosen
    print(f"  chosen: {_label(m, o, quantity)}: max error {e:.1e}, {ns * scale:.2f} {unit}")
    width = max(len(_label(r[0], r[1], quantity)) for r in rows)
    for m, o, e, ns in rows:
        print(f"  {_label(m, o, quantity):>{width}}: max error {e:.1e}, {ns * scale:8.2f} "
              f"{unit}")


def _cmd_choose(args: argparse.Namespace) -> int:
    if args.model is None and (args.param or args.name):
        raise InputError("--param/--name: give an EQUATION (choose period EQUATION …)")
    if args.model is not None and args.quantity != "period":
        raise InputError(f"choose {args.quantity} EQUATION: only the period is chosen for an "
                         "equation (q, amplitudes and response are the notes' Duffing "
                         "oscillator's)")
    if args.quantity in RESUMMED_QUANTITIES:
        return _choose_resummed(args)
    if args.quantity in DRIVEN_QUANTITIES:
        return _choose_driven(args)
    if args.quantity == "q":
        return _choose_q(args)
    for name in ("tol", "x_min", "x_max"):
        if getattr(args, name) is None:
            raise InputError(f"choose period needs --{name.replace('_', '-')}")
    model = None
    if args.model is not None:
        if args.emit:
            raise InputError("--emit: the chosen period module is the Duffing oscillator's; "
                             "`lindstedt generate EQUATION` emits an equation's evaluators")
        from ..derive.models import model_from_text
        from ..methods.kernels import MAX_ORDER

        model = model_from_text(args.model, MAX_ORDER, _params(args.param), args.name)
    from ..choose import choose_period, modelled_ns
    from ..compiler import generate_choice
    from ..emit.render import check_writable

    if args.emit:
        check_writable(_out_folder(args.emit, "--emit"), ["chosen_period.py"], "--emit",
                       args.overwrite_edited)
    progress = Progress("timing the verified methods", not args.json)
    choice = choose_period(args.tol, args.x_min, args.x_max, progress, model=model)
    progress.close()
    variable = "x = eps*A**2" if model is None else model.variable
    data = {"method": choice.method.name, "order": choice.order,
            "max_error": choice.max_error,
            "ns_per_point": choice.ns_per_point, "verified_on": choice.verified_on,
            "modelled_ns_per_point": modelled_ns("period", choice.method, choice.order),
            "decided_by": "cost model (lindstedt.choose.COST_MODEL); ns_per_point measured",
            "quantity": "period", "variable": variable,
            "considered": _considered(choice.considered, "period")}
    if model is not None:
        data.update(equation=model.source or model.title, omega0=str(model.frequency),
                    reference="quadrature of the scaled potential (Gauss–Legendre, 256 nodes)")
    if args.emit:
        command = (f"lindstedt choose period --tol {args.tol!r} --x-min {args.x_min!r} "
                   f"--x-max {args.x_max!r}")
        data["emitted"] = [str(p) for p in generate_choice(
            choice.candidate, command, Path(args.emit), (args.x_min, args.x_max),
            overwrite_edited=args.overwrite_edited)]
    if args.json:
        print(json.dumps(data))
        return 0
    _print_choice(f"period T(x), {variable} in [{args.x_min:g}, {args.x_max:g}], tolerance "
                  f"{args.tol:g} (relative, verified on {choice.verified_on} points):",
                  (choice.method, choice.order, choice.max_error, choice.ns_per_point),
                  choice.considered, quantity="period")
    for path in data.get("emitted", []):
        print(f"  emitted {path}")
    return 0


RESUMMED_QUANTITIES = ("cycle", "mathieu")
# NOTE: choose's quantities past the radius: van der Pol's limit-cycle ω(ε) and Mathieu's
# a_m(q), b_m(q) (partial sums, resummed evaluator, numerical reference).


def _choose_resummed(args: argparse.Namespace) -> int:
    """``choose cycle`` (ε in [x-min, x-max]) and ``choose mathieu --kind K --m M`` (q)."""
    for name in ("tol", "x_min", "x_max"):
        if getattr(args, name) is None:
            raise InputError(f"choose {args.quantity} needs --{name.replace('_', '-')}")
    if args.emit:
        raise InputError(f"--emit: choose {args.quantity} reports; `lindstedt generate "
                         "van_der_pol` and `lindstedt mathieu … --emit DIR` write the modules")
    from ..choose import choose_limit_cycle, choose_mathieu

    if args.quantity == "cycle":
        c = choose_limit_cycle(args.tol, args.x_min, args.x_max)
        what = f"van der Pol's limit-cycle ω(ε), ε in [{args.x_min:g}, {args.x_max:g}]"
    else:
        kind, m = args.kind or "a", args.m if args.m is not None else 0
        c = choose_mathieu(kind, m, args.tol, args.x_min, args.x_max)
        what = f"Mathieu's {kind}_{m}(q), q in [{args.x_min:g}, {args.x_max:g}]"
    rows = [{"method": m, "order": o, "max_error": e, "recorded_ns_per_point": r,
             "ns_per_point": ns} for m, o, e, r, ns in c.considered]
    if args.json:
        print(json.dumps({"quantity": args.quantity, "method": c.method, "order": c.order,
                          "max_error": c.max_error, "ns_per_point": c.ns_per_point,
                          "verified_on": c.verified_on, "considered": rows,
                          "decided_by": "recorded costs (lindstedt.choose.RESUMMED_COSTS)"}))
        return 0
    print(f"{what}, tolerance {args.tol:g} (relative, {c.verified_on} points): {c.method}"
          + (f" (order {c.order})" if c.order else ""))
    for r in rows:
        print(f"  {r['method']:<10} order {r['order']:>4}  max error {r['max_error']:8.1e}  "
              f"{r['recorded_ns_per_point']:10.3g} ns/point recorded, "
              f"{r['ns_per_point']:10.3g} this run")
    return 0


def _cmd_clock(args: argparse.Namespace) -> int:
    from ..choose import appendix_thresholds

    rows = [{"approximation": t.approximation, "tolerance": t.tolerance,
             "claimed_deg": t.claimed_deg, "potential_deg": t.potential_deg,
             "period_deg": t.period_deg, "holds_for_potential": t.potential_deg >= t.claimed_deg,
             "holds_for_period": t.period_deg >= t.claimed_deg} for t in appendix_thresholds()]
    if args.json:
        print(json.dumps({"claims": rows}))
        return 0
    print("The notes' appendix: 1 - cos(theta) approximated, accurate to a tolerance "
          "up to an angle")
    print(f"{'approximation':>24} {'tol':>7} {'claimed':>8} {'potential':>10} {'period':>8}"
          "  holds?")
    for r in rows:
        verdict = {(True, True): "yes", (False, False): "no"}.get(
            (r["holds_for_potential"], r["holds_for_period"]),
            "potential " + ("yes" if r["holds_for_potential"] else "no") + ", period "
            + ("yes" if r["holds_for_period"] else "no"))
        print(f"{r['approximation']:>24} {r['tolerance']:>7.0e} {r['claimed_deg']:>7.1f}° "
              f"{r['potential_deg']:>9.2f}° {r['period_deg']:>7.2f}°  {verdict}")
    return 0


def _cmd_scene(args: argparse.Namespace) -> int:
    from ..choose import SCENES

    result = SCENES[args.name]()
    if args.json:
        print(json.dumps({"scene": result.scene, "question": result.question,
                          "answer": result.answer, **result.details}))
    else:
        print(f"{result.question}: {result.answer}")
        for key, value in result.details.items():
            print(f"  {key}: {value}")
    return 0


def _choose_q(args: argparse.Namespace) -> int:
    for name in ("tol", "x_min", "x_max"):
        if getattr(args, name) is None:
            raise InputError(f"choose q needs --{name.replace('_', '-')}")
    from ..choose import choose_solution, modelled_ns
    from ..compiler import generate_method
    from ..emit.render import check_writable

    if args.emit:
        check_writable(_out_folder(args.emit, "--emit"), ["duffing.py", "duffing_tables.tex",
                                         "duffing_derivation.tex", "fourier.py"], "--emit")
    progress = Progress("verifying the L–P orders", not args.json)
    c = choose_solution(args.tol, args.x_min, args.x_max, args.t_max,
                        emittable=bool(args.emit), progress=progress)
    progress.close()
    data = {"quantity": "q", "method": c.method.name, "order": c.order,
            "max_error": c.max_error,
            "ns_per_point": c.ns_per_point, "verified_on": c.verified_on,
            "modelled_ns_per_point": modelled_ns("q", c.method, c.order),
            "decided_by": "cost model (lindstedt.choose.COST_MODEL); ns_per_point measured",
            "considered": _considered(c.considered)}
    if args.emit:
        data["emitted"] = [str(p) for p in generate_method(
            c.method, c.order, Path(args.emit), overwrite_edited=args.overwrite_edited)]
    if args.json:
        print(json.dumps(data))
        return 0
    _print_choice(f"q(t)/A to {args.tol:g} for x in [{args.x_min:g}, {args.x_max:g}], t in "
                  f"[0, {args.t_max:g}] (verified on {c.verified_on} points):",
                  (c.method, c.order, c.max_error, c.ns_per_point), c.considered)
    if c.method == "lindstedt" and not args.emit:
        print(f"  (`lindstedt generate duffing --order {c.order}` or --emit DIR writes it)")
    for path in data.get("emitted", []):
        print(f"  emitted {path}")
    return 0


def _choose_driven(args: argparse.Namespace) -> int:
    """``choose amplitudes`` and ``choose response``: one ω or a range of ω."""
    for name in ("eps", "force"):
        if getattr(args, name) is None:
            raise InputError(f"choose {args.quantity} needs --{name}")
    if args.omega is None and (args.omega_min is None or args.omega_max is None):
        raise InputError(f"choose {args.quantity} needs --omega, or --omega-min and --omega-max")
    if args.omega is not None and (args.omega_min is not None or args.omega_max is not None):
        raise InputError("give --omega or a range (--omega-min, --omega-max), not both")
    tol = args.tol or 1e-4
    lo, hi = (args.omega, None) if args.omega is not None else (args.omega_min, args.omega_max)
    from ..analysis.driven import check_steady_state

    check_steady_state(args.eps, args.Q, lo, hi)
    from ..choose import DRIVEN_MAX, choose_driven
    from ..compiler import generate_method
    from ..emit.render import check_writable

    if args.emit:
        check_writable(_out_folder(args.emit, "--emit"),
                       ["driven.py", "driven_derivation.tex", "balance.py", "driven_damped.py",
                        "driven_damped_derivation.tex"], "--emit")
    progress = Progress("shooting the true orbits", not args.json)
    c = choose_driven(args.quantity, tol, args.eps, args.force, args.Q, lo, hi,
                      emit=(emit_bounds(args.allow_slow, DRIVEN_MAX, args.quantity)
                            if args.emit else None),
                      progress=progress)
    progress.close()
    data = {"quantity": args.quantity, "method": c.method.name, "order": c.order,
            "max_error": c.max_error, "ns_per_point": c.ns_per_point,
            "verified_on": c.verified_on, "seconds": c.ns_per_point * 1e-9,
            "modelled_ns_per_point": c.modelled_ns_per_point,
            "decided_by": "cost model (lindstedt.choose.COST_MODEL); ns_per_point measured",
            "alternatives": {m: {"order": o, "max_error": e, "seconds": ns * 1e-9}
                             for m, o, e, ns in c.considered if m != c.method},
            "considered": _considered(c.considered),
            "truth_by_omega": [{"omega": float(w), "A": a.tolist(), "B": b.tolist()}
                               for w, a, b in zip(c.truth.omega, c.truth.A, c.truth.B,
                                                  strict=True)]}
    if args.omega is not None:
        data["truth"] = c.truth.A[0].tolist()
    if args.emit:
        data["emitted"] = [str(p) for p in generate_method(
            c.method, c.order, Path(args.emit), overwrite_edited=args.overwrite_edited)]
    if args.json:
        print(json.dumps(data))
        return 0
    what = {"amplitudes": "A1, A3, A5 (and B_n)", "response": "r = sqrt(A1^2 + B1^2)"}
    where = f"omega = {lo:g}" if hi is None else f"omega in [{lo:g}, {hi:g}]"
    _print_choice(f"{what[args.quantity]} to {tol:g} (absolute, largest branch, {where}, "
                  f"verified on {c.verified_on} point{'s' * (c.verified_on > 1)} against "
                  "shooting):", (c.method, c.order, c.max_error, c.ns_per_point), c.considered,
                  micro=True)
    for path in data.get("emitted", []):
        print(f"  emitted {path}")
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    """A map over a parameter grid on dask.distributed, into a resumable Zarr store."""
    if args.plot:
        from ..charts import check_plot_path

        check_plot_path(Path(args.plot))
    from ..kinds import equation_kind
    from ..store import run_sweep

    builtin = {name: getattr(args, name) for name in ("omega", "force", "eps", "Q")
               if getattr(args, name) is not None}
    kind: object = args.kind
    if args.model is not None:
        if builtin:
            raise InputError(f"{', '.join('--' + k for k in builtin)}: with an equation give "
                             "its axes with --axis NAME=A:B:N and its values with --param")
        axes = dict(args.axis or [])
        if len(axes) != len(args.axis or []):
            raise InputError("--axis: each parameter once")
        kind = equation_kind(args.kind, args.model, _params(args.param), list(axes),
                             3 if args.n is None else args.n, args.name or "oscillator")
    else:
        if args.axis or args.param or args.name or args.n is not None:
            raise InputError("--axis/--param/--name/--n: give an equation (EQUATION) to take "
                             "them; the notes' map takes --omega, --force, --eps, --Q")
        axes = builtin
    bar = Progress(f"sweep {args.kind}", not args.json)
    ds = run_sweep(kind, axes, _out_folder(args.store, "--store"), args.scheduler,
                   args.workers, args.chunk, lambda p: bar(p.finished, p.total))
    bar.close()
    if args.plot:
        from ..charts import sweep_figure

        sweep_figure(ds, Path(args.plot))
    done = ds["done"].values
    names = list(json.loads(ds.attrs["sweep"])["axes"])
    data = {"kind": args.kind, "store": str(args.store),
            "axes": {name: [float(v) for v in ds[name].values] for name in names},
            "fields": sorted(name for name in ds.data_vars if name != "done"),
            "blocks": int(done.size), "finished": int(done.sum()),
            "complete": bool(done.all())}
    if args.model is not None:
        data["equation"] = args.model
    if args.plot:
        data["plot"] = args.plot
    if args.json:
        print(json.dumps(data))
        return 0
    shape = " × ".join(f"{len(v)} {k}" for k, v in data["axes"].items())
    print(f"sweep {args.kind}: {shape} into {args.store}: {data['finished']}/{data['blocks']} "
          f"blocks done; fields {', '.join(data['fields'])}")
    if args.plot:
        print(f"  figure {args.plot}")
    return 0


SWEEP_MAX_VALUES = 100_000
# NOTE: values per axis: a bound against typos in A:B:N; the store's size is checked against
# the free disk before any work.


def _axis_values(text: str) -> list[float]:
    """Axis values: ``A:B:N`` (N evenly spaced from A to B), ``v1,v2,…`` or one value; each
    a decimal or a fraction ``p/q``."""
    from fractions import Fraction

    def number(v: str) -> float:
        return float(Fraction(v.strip())) if "/" in v else float(v)

    try:
        if ":" in text:
            start, stop, count = text.split(":")
            n = int(count)
            if not 1 <= n <= SWEEP_MAX_VALUES:
                raise argparse.ArgumentTypeError(f"{text!r}: N must be 1..{SWEEP_MAX_VALUES}")
            a, b = number(start), number(stop)
            values = [a + (b - a) * i / (n - 1) for i in range(n)] if n > 1 else [a]
        else:
            values = [number(v) for v in text.split(",")]
    except (ValueError, ZeroDivisionError):
        raise argparse.ArgumentTypeError(f"{text!r}: expected A:B:N, v1,v2,… or a number"
                                         ) from None
    if any(math.isnan(v) for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: not a number")
    return values


def _named_axis(text: str) -> tuple[str, list[float]]:
    """``NAME=VALUES`` of ``--axis`` (:func:`_axis_values`)."""
    name, sep, values = text.partition("=")
    if not sep or not name.strip().isidentifier():
        raise argparse.ArgumentTypeError(f"{text!r}: expected NAME=A:B:N, NAME=v1,v2,… or "
                                         "NAME=value")
    return name.strip(), _axis_values(values)


def _order(text: str) -> int:
    """An order K (or an index such as mathieu's m): a non-negative integer."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value}: must be ≥ 0")
    return value


def _positive(text: str) -> int:
    """A positive integer (workers, points per task)."""
    value = _order(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value}: must be ≥ 1")
    return value


def _count(text: str) -> int:
    """A number of harmonics: an integer in 1..MAX_HARMONICS."""
    value = _positive(text)
    if value > MAX_HARMONICS:
        raise argparse.ArgumentTypeError(f"{value}: must be in 1..{MAX_HARMONICS}")
    return value


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: not a number") from None


def _real(text: str) -> float:
    """A finite real number (scientific notation and a leading minus welcome)."""
    value = _number(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r}: not finite")
    return value


def _nonnegative(text: str) -> float:
    """A finite real number ≥ 0 (a damping ratio)."""
    value = _real(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be ≥ 0")
    return value


def _positive_real(text: str) -> float:
    """A finite real number > 0 (a tolerance)."""
    value = _real(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be > 0")
    return value


def _quality(text: str) -> float:
    """A quality factor Q > 0; ``inf`` means undamped."""
    if not _number(text) > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be > 0 (inf: undamped)")
    return float(text)


class _Parser(argparse.ArgumentParser):
    """argparse with the project's one-line errors (no usage dump), exit status 2, and any token
    that starts like a number (``-1e-8``, ``-.5``, ``-0.3@1.3``) taken as a value, not a flag."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?\d")

    def error(self, message: str) -> None:  # type: ignore[override]
        # one prefix for every error, a subcommand's argparse ones included
        self.exit(2, f"lindstedt: error: {self.prog.removeprefix('lindstedt ')}: {message}\n"
                  if self.prog != "lindstedt" else f"lindstedt: error: {message}\n")


class _DeprecatedForce(argparse.Action):
    """``--force`` in series/generate: the old spelling of ``--allow-slow`` (one release)."""

    def __init__(self, option_strings: Sequence[str], dest: str, **kwargs) -> None:
        super().__init__(option_strings, dest, nargs=0, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        print("lindstedt: note: --force here is deprecated, use --allow-slow (--force F is the "
              "drive amplitude in driven, response, subharmonic, mixing, choose)", file=sys.stderr)
        namespace.allow_slow = True


# One definition per flag: the same name means the same thing, with one help text and one
# default, in every command.

def _flag_oscillator(p: argparse.ArgumentParser, emitted: bool = False) -> None:
    """The oscillator: a name of `lindstedt models` or an equation, with --param and --name."""
    extra = ("; or driven: μ-expansion A_n(ω), balance: harmonic-balance Newton solver, "
             "fourier: exact Fourier series of Duffing") if emitted else ""
    p.add_argument("model", metavar="EQUATION|NAME",
                   help="an equation such as \"q'' + q + eps*(alpha*q**2 + q**3) = 0\" (q' and "
                   "q'' are the derivatives, eps the small parameter, other names parameters) "
                   f"or a name: {', '.join(FREE_MODELS)}{extra}")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="give a parameter an exact value, e.g. alpha=1/3 (repeatable; "
                   "default: parameters stay symbolic)")
    p.add_argument("--name", metavar="NAME",
                   help="the oscillator's name in output and file names (default: oscillator)")


def _flag_equation(p: argparse.ArgumentParser, example: str,
                   default: str = "the notes' equation with the flags",
                   which: str = "every parameter needs one") -> None:
    """An optional EQUATION of the command's own form, with --param and --name."""
    p.add_argument("model", metavar="EQUATION", nargs="?", default=None,
                   help=f"an equation such as {example}; default: {default}")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="with EQUATION: an exact value for each of its parameters, e.g. "
                   f"eps=1/10 (repeatable; {which})")
    p.add_argument("--name", metavar="NAME",
                   help="with EQUATION: the oscillator's name in messages (default: oscillator)")


def _flag_order(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--order", type=_order, default=DEFAULT_ORDER, metavar="K",
                   help=f"{what}, an integer ≥ 0 (default {DEFAULT_ORDER})")


def _flag_harmonics(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--harmonics", type=_count, default=DEFAULT_HARMONICS, metavar="N",
                   help=f"{what}, an integer in 1..{MAX_HARMONICS} (default {DEFAULT_HARMONICS})")


def _flag_allow_slow(p: argparse.ArgumentParser, deprecated_force: bool = True) -> None:
    """--allow-slow (and in series/generate its old spelling --force, which elsewhere is the
    drive amplitude)."""
    p.add_argument("--allow-slow", action="store_true",
                   help=f"run even when the estimate exceeds {COST_LIMIT_SECONDS:.0f} s "
                   "(default: refuse)")
    if deprecated_force:
        p.add_argument("--force", action=_DeprecatedForce, dest="allow_slow",
                       help="deprecated spelling of --allow-slow")


def _flag_overwrite_edited(p: argparse.ArgumentParser) -> None:
    p.add_argument("--overwrite-edited", action="store_true",
                   help="replace generated files even when they were edited by hand since "
                   "(default: refuse, so an edit is never lost silently)")


def _flag_json(p: argparse.ArgumentParser, what: str = "the JSON contract") -> None:
    p.add_argument("--json", action="store_true",
                   help=f"print {what} on stdout instead of the table (no progress bar)")


def _flag_plot(p: argparse.ArgumentParser) -> None:
    p.add_argument("--plot", metavar="FILE",
                   help="also draw the figure into FILE (.png, .svg or .pdf; default: none)")


def _flag_drive(p: argparse.ArgumentParser, required: bool, omega: str | None,
                Q: str | None = "optional", force: bool = True) -> None:
    """--eps, --force, --omega, --Q of q'' + q'/Q + q + eps q^3 = f cos(w t) (``omega``: its
    meaning, None for none; ``Q``: "optional", "required" or None for none)."""
    need = " (required)" if required else ""
    p.add_argument("--eps", type=_real, required=required, metavar="EPS",
                   help=f"ε, the cubic stiffness coefficient (dimensionless; > 0 hardens, "
                   f"< 0 softens){need}")
    if force:
        p.add_argument("--force", type=_real, required=required, metavar="F",
                       help=f"f, the drive amplitude, in units of the linear stiffness × length "
                       f"(q is dimensionless){need}")
    if omega is not None:
        p.add_argument("--omega", type=_real, required=required, metavar="W",
                       help=f"{omega}, in units of the linear natural frequency{need}")
    if Q == "required":
        p.add_argument("--Q", type=_quality, required=True, metavar="Q",
                       help="quality factor Q > 0 of the damping q'/Q (finite; required)")
    elif Q == "optional":
        p.add_argument("--Q", type=_quality, default=math.inf, metavar="Q",
                       help="quality factor Q > 0 of the damping q'/Q (default inf: undamped)")


def _args_series(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt series``'s arguments."""
    p = sub.add_parser("series", help="the L–P series of a free oscillator, or of its limit "
                       "cycles", description="Derive ω_j, (T/2π)_j and q_j of the L–P series "
                       "exactly; for q'' + q = eps*f(q, q') with f odd in q', of its limit "
                       "cycles (the amplitude fixed order by order).")
    _flag_oscillator(p)
    _flag_order(p, "highest order K of the series")
    p.add_argument("--cycle", type=int, default=None, metavar="N",
                   help="a self-excited oscillator's N-th limit cycle (by amplitude, from 1) "
                   "to expand; default: each in turn in the table, the first in --json "
                   "(which lists every cycle under 'cycles')")
    p.add_argument("--singularities", action="store_true",
                   help="also estimate the nearest singularities of ω from the exact series "
                   "(Domb–Sykes or Mercer–Roberts, extrapolated in 1/n; their spread over the "
                   "last orders); with --json a key 'singularities'")
    _flag_json(p)
    _flag_allow_slow(p)
    return p


def _args_mathieu(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt mathieu``'s arguments."""
    p = sub.add_parser("mathieu", help="Mathieu's characteristic values a_m(q), b_m(q) as "
                       "exact series", description="The series of a_m(q) (even solutions "
                       "ce_m) or b_m(q) (odd, se_m) of y'' + (a - 2q cos 2z) y = 0 in DLMF's "
                       "normalisation, exact rationals, by L–P about cos mz or sin mz.")
    p.add_argument("kind", choices=("a", "b"), help="a: even solutions; b: odd ones")
    p.add_argument("--m", type=_order, default=0, metavar="M",
                   help="the index m, an integer ≥ 0 (≥ 1 for b; default 0)")
    _flag_order(p, "highest power K of q")
    _flag_json(p, "the contract {kind, m, variable, series}")
    _flag_allow_slow(p, deprecated_force=False)
    p.add_argument("--emit", metavar="DIR", default=None,
                   help="write DIR/mathieu_<kind><m>.py instead: a numba ufunc of the value, "
                   "Padé-resummed from the series to --order and refined by a Newton step on "
                   "the recurrence's determinant, verified against the eigenvalues at 30 digits "
                   "on a grid of q up to 50 and NaN beyond where it was verified")
    p.add_argument("--overwrite-edited", action="store_true",
                   help="with --emit: overwrite a file edited since it was generated")
    p.add_argument("--singularities", action="store_true",
                   help="also estimate the nearest singularity (radius of convergence) from "
                   "the exact series, with its spread; in q**2 for a_2n, b_2n; with --json a "
                   "key 'singularities'")
    return p


def _args_tongues(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt tongues``'s arguments."""
    p = sub.add_parser("tongues", help="transition curves of Hill's equation x'' + (delta + "
                       "eps p(t)) x = 0 out of a tongue", description="Both transition curves "
                       "delta(eps) out of the tongue delta = n^2/4 of x'' + (delta + eps p(t))"
                       " x = 0 as exact series, with the periodic solution on each (period 2pi "
                       "for n even, 4pi for n odd); p(t) a finite sum of cos(k*t), sin(k*t) "
                       "with rational coefficients.  Mathieu's a_m, b_m: p = cos(t), "
                       "delta = a/4, eps = -q/2.")
    p.add_argument("p", help="p(t), e.g. 'cos(t)' or 'cos(t) + 1/2*cos(2*t)'")
    p.add_argument("--n", type=_order, default=1, metavar="N",
                   help="the tongue delta = N^2/4, an integer ≥ 0 (default 1)")
    _flag_order(p, "highest power K of eps")
    p.add_argument("--damping", type=_nonnegative, metavar="Z",
                   help="also the tip of the tongue of x'' + 2Z x' + (delta + eps p) x = 0: "
                   "eps_min and its delta as series in zeta, and their values at Z")
    p.add_argument("--at", type=_real, metavar="EPS",
                   help="also evaluate each curve at eps = EPS with its truncation estimate")
    p.add_argument("--tol", type=_positive_real, metavar="TOL",
                   help="with --at: refuse unless the truncation estimate is ≤ TOL (naming "
                   "the best reachable)")
    p.add_argument("--singularities", action="store_true",
                   help="also estimate each curve's nearest singularity in eps (radius of "
                   "convergence) with its spread")
    p.add_argument("--plot", metavar="FILE",
                   help="also draw the Ince–Strutt chart of this p into FILE (.png, .svg or "
                   ".pdf): Floquet multipliers on a 400 x 400 grid, undamped and with damping "
                   f"Z (default {DAMPING_PANEL}), the series curves of tongues 0..max(3, N)")
    _flag_json(p, "the curves as JSON {p, n, variable, delta0, harmonics, time_origin, period, "
               "solution_variable, curves: [{label, series, solution}], damping}")
    _flag_allow_slow(p, deprecated_force=False)
    p.add_argument("--emit", metavar="DIR", default=None,
                   help="write DIR/tongue_<N>.py instead: numba ufuncs delta_<i>(eps) and "
                   "delta_<i>_error(eps), one per curve, Padé-resummed from the series to "
                   "--order (≥ 12), verified against the Floquet boundary |tr M| = 2 to 1e-10 "
                   "in delta on 240 points up to 3 radii (at most eps = 10), NaN beyond")
    p.add_argument("--overwrite-edited", action="store_true",
                   help="with --emit: overwrite a file edited since it was generated")
    return p


def _args_models(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt models``'s arguments."""
    p = sub.add_parser("models", help="list the named oscillators",
                       description="The named oscillators: each is an equation (any equation "
                       "of the family can be given instead of a name).")
    _flag_json(p, "the list as JSON")
    return p


def _args_generate(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt generate``'s arguments."""
    p = sub.add_parser(
        "generate", help="write a numba evaluator module and LaTeX tables and derivation",
        description="Write a numba evaluator module (and for duffing, pendulum, driven its "
        "LaTeX tables and derivation) into --out.")
    _flag_oscillator(p, emitted=True)
    _flag_order(p, f"highest order K (duffing, pendulum; driven up to {DRIVEN_MAX_ORDER})")
    p.add_argument("--out", default="out", metavar="DIR",
                   help="output folder, created if missing (default out/)")
    _flag_harmonics(p, "balance (up to 12), fourier (up to 60): odd harmonics N")
    p.add_argument("--allow-divergent", action="store_true",
                   help="evaluate beyond the radius of convergence instead of returning NaN "
                   "(default: NaN)")
    p.add_argument("--damped", action="store_true",
                   help="driven only: the μ-expansion with damping 1/Q, A_n and B_n (n = 1, 3, "
                   "5) of Q < inf (driven_damped.py, driven_damped_derivation.tex)")
    p.add_argument("--resum-order", type=_order, default=None, metavar="N",
                   help="limit cycles only: derive ω's exact series to order N (at least K + 2) "
                   "for the radius estimate and the resummed evaluators (default 60: van der "
                   "Pol's omega_resummed verified to eps ≈ 3.75; 164: to eps = 10)")
    _flag_allow_slow(p)
    _flag_overwrite_edited(p)
    return p


def _args_driven(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt driven``'s arguments."""
    p = sub.add_parser("driven", help="steady 1:1 response of a driven oscillator",
                       description="q'' + q'/Q + q + eps q^3 = f cos(w t) (--eps, --force, --Q): "
                       "every 1:1 branch by the μ-expansion, harmonic balance and shooting; or "
                       "your own equation q'' + g(q, q') = f*cos(w*t), g a polynomial, with "
                       "--param for its parameters: every 1:1 orbit by harmonic balance and "
                       "shooting.")
    _flag_equation(p, "\"q'' + q + eps*q**3 + gamma*q'**3 = f*cos(w*t)\" (a polynomial "
                   "force, one drive f*cos(w*t) whose w is --omega)",
                   "eq. 10.60 with --eps, --force, --Q", "every parameter but w needs one")
    _flag_drive(p, required=False, omega="ω, the drive frequency (required)", Q="none")
    p.add_argument("--Q", type=_quality, default=None, metavar="Q",
                   help="quality factor Q > 0 of the damping q'/Q (default: inf, undamped)")
    _flag_order(p, "μ-expansion order K")
    _flag_harmonics(p, "odd harmonics N of harmonic balance")
    _flag_json(p)
    _flag_allow_slow(p, deprecated_force=False)
    return p


def _args_response(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt response``'s arguments."""
    p = sub.add_parser("response", help="folds and hysteresis of the damped driven oscillator",
                       description="Response curve over ω: folds three ways, sweep jumps. "
                       "q'' + q'/Q + q + eps q^3 = f cos(w t) (--eps, --force, --Q), or your "
                       "own damped equation q'' + g(q, q') = f*cos(w*t), g a polynomial, with "
                       "--param for every parameter but w.")
    _flag_equation(p, "\"q'' + 0.05*q' + q + eps*(q**2 + q**3) = f*cos(w*t)\" (a "
                   "polynomial force with damping, one drive f*cos(w*t) whose w the curve "
                   "varies)", "eq. 10.60 with --eps, --force, --Q", "every parameter but w "
                   "needs one")
    _flag_drive(p, required=False, omega=None, Q=None)
    p.add_argument("--Q", type=_quality, default=None, metavar="Q",
                   help="quality factor Q > 0 of the damping q'/Q (finite; required without "
                   "EQUATION)")
    p.add_argument("--omega-min", type=_real, metavar="W",
                   help="with EQUATION: the lowest ω of the curve (default: half the lowest of "
                   "the linear frequency ω0 and the one-harmonic folds)")
    p.add_argument("--omega-max", type=_real, metavar="W",
                   help="with EQUATION: the highest ω of the curve (default: 1.25 × the highest "
                   "of ω0 and the one-harmonic folds)")
    _flag_harmonics(p, "odd harmonics N of the continued balance (with EQUATION: harmonics "
                    "1..2N-1, with the constant and even ones unless the force is odd)")
    _flag_json(p)
    _flag_plot(p)
    _flag_allow_slow(p, deprecated_force=False)
    return p


def _args_subharmonic(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt subharmonic``'s arguments."""
    p = sub.add_parser("subharmonic", help="orbits of n drive periods (the 1/n subharmonic) "
                       "and their stability",
                       description="Your own driven oscillator q'' + g(q, q') = f cos(n w t), g "
                       "any polynomial (damped or not): every orbit of n drive periods by "
                       "harmonic balance on the harmonics of w, each shot for its Floquet "
                       "stability, the primary response and the onset (the smallest drive "
                       "amplitude with such an orbit at this w). Without EQUATION: the notes' "
                       "omega^2 q'' + q + eps q^3 = f cos 3τ in closed form (--eps, --force, "
                       "--omega).")
    _flag_equation(p, "\"x'' + 0.05*x' + x + x**2 = f*cos(w*t)\" (the drive at n times the "
                   "subharmonic's frequency ω: w = n*omega in f*cos(w*t), w = omega in "
                   "f*cos(n*w*t), or a number n*omega without --omega)")
    p.add_argument("--n", type=_positive, default=None, metavar="N",
                   help="the subharmonic's order: orbits of N drive periods, 2..12 (default 3; "
                   "1/2 needs an even power in the force, 1/3 an odd one)")
    _flag_drive(p, required=False, omega="ω, the subharmonic's own frequency: the drive is at "
                "n·ω (required, unless the equation's drive frequency is a number)", Q=None)
    _flag_json(p)
    _flag_plot(p)
    return p


def _args_parametric(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt parametric``'s arguments."""
    p = sub.add_parser("parametric", help="the parametrically driven oscillator's response "
                       "in its first tongue",
                       description="q'' + 2 zeta q' + (1 + eps cos 2wt) q + gamma q^3 = 0: the "
                       "1:1 response at w (the pump at 2w), every branch with its stability "
                       "(one harmonic, harmonic balance with the full Hill equation, shooting), "
                       "the tongue's edges, the onsets and the fold.")
    p.add_argument("--eps", type=_real, required=True, metavar="EPS",
                   help="ε, the pump depth, 0 < ε < 1 (required)")
    p.add_argument("--zeta", type=_real, default=0.0, metavar="ZETA",
                   help="ζ ≥ 0, the damping ratio of 2ζq' (default 0: undamped)")
    p.add_argument("--gamma", type=_real, default=1.0, metavar="GAMMA",
                   help="γ, the cubic stiffness (> 0 hardens, < 0 softens; default 1)")
    p.add_argument("--omega-from", type=_real, required=True, metavar="W",
                   help="the lowest ω, half the pump frequency (required)")
    p.add_argument("--omega-to", type=_real, required=True, metavar="W",
                   help="the highest ω (required)")
    p.add_argument("--points", type=_positive, default=41, metavar="N",
                   help=f"ω points in the range, 2..{MAX_PARAMETRIC_POINTS} (default 41)")
    _flag_harmonics(p, "odd harmonics of the balance (1, 3, …, 2N − 1)")
    _flag_json(p)
    _flag_plot(p)
    return p


def _args_mixing(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt mixing``'s arguments."""
    p = sub.add_parser("mixing", help="combination tones of a two-tone drive",
                       description="Your own q'' + g(q, q') = Σ f_i cos(w_i t), g any "
                       "polynomial with a linear stiffness and damping: the combination tones "
                       "predicted to the second order of the nonlinearity, beside a simulated "
                       "steady state; or the notes' q'' + q'/Q + q + eps q^3 (--eps, --Q, "
                       "--drive).")
    _flag_equation(p, "\"x'' + x'/20 + x + x**2/5 + x**3/10 = 0.3*cos(1.3*t) + "
                   "0.3*cos(1.7*t)\" (every frequency a number: the tones are numbered by "
                   "ascending frequency)")
    _flag_drive(p, required=False, omega=None, Q=None, force=False)
    p.add_argument("--Q", type=_quality, default=None, metavar="Q",
                   help="quality factor Q > 0 of the damping q'/Q (finite; required without "
                   "EQUATION)")
    p.add_argument("--drive", type=_drive, action="append", metavar="F@W",
                   help="a drive f cos(w t): amplitude F at frequency W (units of the linear "
                   "natural frequency), e.g. 0.3@1.3; repeat for each tone (required without "
                   "EQUATION)")
    _flag_json(p)
    _flag_plot(p)
    return p


def _args_choose(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt choose``'s arguments."""
    p = sub.add_parser("choose", help="the cheapest verified method for a tolerance and a range",
                       description="Time and verify every method, report the cheapest that "
                       "meets the tolerance on the range.")
    p.add_argument("quantity", choices=("period", "q", *DRIVEN_QUANTITIES,
                                        *RESUMMED_QUANTITIES),
                   help="period T(x); q(t); amplitudes A_n, B_n; response r(ω); cycle: van der "
                   "Pol's limit-cycle ω(ε), ε in [x-min, x-max]; mathieu: a_m(q) or b_m(q) "
                   "(--kind, --m), q in [x-min, x-max]")
    p.add_argument("--kind", choices=("a", "b"), default=None,
                   help="mathieu: a (even solutions, default) or b (odd)")
    p.add_argument("--m", type=_order, default=None, metavar="M",
                   help="mathieu: the index m (default 0)")
    _flag_equation(p, "\"q'' + q + eps*q**5 = 0\" (period only: a free oscillator with a "
                   "polynomial force, judged by quadrature; x is then its expansion variable)")
    p.add_argument("--tol", type=_real, metavar="TOL",
                   help="tolerance > 0 (period, q: relative, required; amplitudes, response: "
                   "absolute, default 1e-4)")
    p.add_argument("--x-min", type=_real, metavar="X",
                   help="period, q: smallest x = εA² of the range (required)")
    p.add_argument("--x-max", type=_real, metavar="X",
                   help="period, q: largest x = εA² of the range (required)")
    p.add_argument("--t-max", type=_real, default=20.0, metavar="T",
                   help="q: times 0..T, in units of 1/(linear natural frequency) (default 20)")
    _flag_drive(p, required=False, omega="amplitudes, response: one drive frequency ω")
    p.add_argument("--omega-min", type=_real, metavar="W",
                   help="amplitudes, response: lowest ω of a range (instead of --omega)")
    p.add_argument("--omega-max", type=_real, metavar="W",
                   help="amplitudes, response: highest ω of a range (instead of --omega)")
    p.add_argument("--emit", metavar="DIR", help="write just the chosen evaluator into DIR "
                   "(period: chosen_period.py; q: duffing.py or fourier.py; amplitudes, "
                   "response: driven.py or balance.py, only emittable methods compete; "
                   "default: write nothing)")
    _flag_json(p)
    _flag_overwrite_edited(p)
    _flag_allow_slow(p, deprecated_force=False)
    return p


def _args_sweep(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt sweep``'s arguments."""
    p = sub.add_parser("sweep", help="maps over parameter grids on a Dask cluster, resumable",
                       description="Map a driven oscillator over a grid of parameters on "
                       "dask.distributed (a LocalCluster here by default), block by block into "
                       "a Zarr store; run the same command again to resume an interrupted "
                       "sweep. Your own equation: any of its parameters (the drive frequency "
                       "included) an --axis, the rest --param; without EQUATION the notes' "
                       "q'' + q'/Q + q + eps q^3 = f cos(wt) over --omega, --force, --eps, --Q.")
    p.add_argument("kind", choices=SWEEP_KINDS,
                   help="response: r of every branch; stability: Floquet verdicts of the true "
                   "orbits (with an EQUATION both: every orbit shot, r and its verdict); "
                   "subharmonic: orbits of n drive periods (the notes': the 1/3 of eq. 10.87); "
                   "validity: μ-expansion error (the notes' equation only)")
    p.add_argument("model", metavar="EQUATION", nargs="?", default=None,
                   help="a driven equation such as \"q'' + 0.05*q' + q + eps*(alpha*q**2 + "
                   "q**3) = f*cos(w*t)\"; default: the notes' equation with --omega, --force, "
                   "--eps, --Q")
    p.add_argument("--axis", type=_named_axis, action="append", metavar="NAME=VALUES",
                   help="with EQUATION: a parameter swept, e.g. w=0.8:1.6:41 or alpha=0,1/2,1 "
                   "(A:B:N, v1,v2,… or one value; repeatable; the store's coordinates take "
                   "these names)")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="with EQUATION: an exact value for each parameter that is no axis, "
                   "e.g. eps=1/10 (repeatable)")
    p.add_argument("--name", metavar="NAME",
                   help="with EQUATION: the oscillator's name in messages (default: oscillator)")
    p.add_argument("--n", type=_positive, default=None, metavar="N",
                   help="with EQUATION, subharmonic: orbits of N drive periods (default 3)")
    for name, meaning in (("omega", "ω, drive frequency (subharmonic: its own, drive at 3ω)"),
                          ("force", "f, drive amplitude"), ("eps", "ε, cubic stiffness"),
                          ("Q", "quality factor (inf: undamped)")):
        p.add_argument(f"--{name}", type=_axis_values, metavar="VALUES",
                       help=f"the notes' equation: {meaning}: A:B:N (N values from A to B), "
                       "v1,v2,… or one value (each axis the kind takes is required: response, "
                       "stability, validity take all four, subharmonic omega, force, eps)")
    p.add_argument("--store", required=True, metavar="PATH",
                   help="the Zarr store (a folder) the map is written into, block by block "
                   "(required; an existing store of the same sweep resumes)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="tcp://host:port of a running dask scheduler whose workers have "
                   "lindstedt (default: a LocalCluster on this machine)")
    p.add_argument("--workers", type=_positive, default=2, metavar="N",
                   help="worker processes of the LocalCluster, one thread each (default 2)")
    p.add_argument("--chunk", type=_positive, default=None, metavar="POINTS",
                   help="grid points per task (default: the kind's, about 1 s of work)")
    _flag_json(p, "a JSON summary")
    _flag_plot(p)
    _flag_allow_slow(p, deprecated_force=False)
    return p


def _args_clock(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt clock``'s arguments."""
    p = sub.add_parser("clock", help="the notes' grandfather's-clock accuracy claims, checked")
    _flag_json(p, "JSON")
    return p


def _args_scene(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt scene``'s arguments."""
    p = sub.add_parser("scene", help="named scenes: the smallest model that meets each")
    p.add_argument("name", choices=SCENE_NAMES, help="the scene")
    _flag_json(p, "JSON")
    return p


def _args_slowflow(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt slowflow``'s arguments."""
    p = sub.add_parser("slowflow", help="the slow flow (averaging) of q'' + q = eps*f, free, "
                       "self-excited or driven", description="Average q'' + q = eps*f(q, q') "
                       "(+ eps*F*cos(w*t), w = 1 + eps*sigma) to order K: dr/dt and dphi/dt "
                       "exactly, for q = r cos(t + phi); with --out the compiled right sides and "
                       "the LaTeX of the flow.")
    _flag_oscillator(p)
    p.add_argument("--order", type=_order, default=2, metavar="K",
                   help="the order in eps, 1..6 (default 2)")
    _flag_json(p, "the contract {equation, name, order, variable, parameters, driven, "
               "convention, radial, phase, cycles}")
    p.add_argument("--out", metavar="DIR", help="also write <name>_slow_flow.py (numba "
                   "slow_flow, slow_flow_jacobian, slow_flow_cartesian) and "
                   "<name>_slow_flow.tex into DIR")
    _flag_overwrite_edited(p)
    return p


def _args_demo(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt demo``'s arguments."""
    p = sub.add_parser("demo", help="derive, emit, evaluate and typeset the built-in defaults",
                       description="The main job on the built-in defaults; writes only under "
                       "--out.")
    p.add_argument("--out", default="out", metavar="DIR",
                   help="output folder for evaluators, LaTeX, PDFs and figures/ (default out/)")
    _flag_overwrite_edited(p)
    return p


@dataclass(frozen=True)
class Command:
    """One command: its name, the function that adds its arguments (a subparser), the one that
    runs it, and its cost estimate (:data:`costs.COSTS`, checked before it runs; ``None``: a
    command too quick to estimate).  The parser, the cost guard and ``--help`` loop over
    :data:`COMMANDS`."""

    name: str
    arguments: Callable[[argparse._SubParsersAction], argparse.ArgumentParser]
    run: Callable[[argparse.Namespace], int]
    cost: Callable[[argparse.Namespace], object] | None


COMMANDS: tuple[Command, ...] = tuple(
    Command(name, arguments, run, COSTS.get(name)) for name, arguments, run in (
    ("series", _args_series, _cmd_series),
    ("mathieu", _args_mathieu, _cmd_mathieu),
    ("tongues", _args_tongues, _cmd_tongues),
    ("models", _args_models, _cmd_models),
    ("generate", _args_generate, _cmd_generate),
    ("driven", _args_driven, _cmd_driven),
    ("response", _args_response, _cmd_response),
    ("subharmonic", _args_subharmonic, _cmd_subharmonic),
    ("parametric", _args_parametric, _cmd_parametric),
    ("mixing", _args_mixing, _cmd_mixing),
    ("choose", _args_choose, _cmd_choose),
    ("sweep", _args_sweep, _cmd_sweep),
    ("clock", _args_clock, _cmd_clock),
    ("scene", _args_scene, _cmd_scene),
    ("slowflow", _args_slowflow, _cmd_slowflow),
    ("demo", _args_demo, _cmd_demo),
))
COMMAND = {c.name: c for c in COMMANDS}


def build_parser() -> argparse.ArgumentParser:
    """The parser: one subparser per :data:`COMMANDS` entry, in its order."""
    parser = _Parser(
        prog="lindstedt",
        description="Exact Lindstedt–Poincaré series for nonlinear oscillators, "
        "emitted as numba evaluators and LaTeX.",
    )
    parser.add_argument("--version", action="version", version=f"lindstedt {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in COMMANDS:
        command.arguments(sub).set_defaults(func=command.run)
    return parser


def check_cost(args: argparse.Namespace) -> None:
    """Every command's estimate (lindstedt.costs.COSTS) before it runs: bounds that no switch
    lifts, then a refusal above COST_LIMIT_SECONDS without --allow-slow."""
    estimate = COMMAND[args.command].cost
    if estimate is None:
        return
    cost = estimate(args)
    if cost.seconds > COST_LIMIT_SECONDS and not getattr(args, "allow_slow", False):
        raise InputError(cost.refusal())


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        check_cost(args)
        status = args.func(args)
        sys.stdout.flush()  # a reader that went away (`| head`) is noticed here, not at exit
        return status
    except InputError as exc:
        print(f"lindstedt: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The Python docs' recipe (signal module, "Note on SIGPIPE"): stdout's reader closed
        # the pipe; point stdout at devnull so the interpreter's final flush cannot fail
        # again, and exit 1 as Python does on EPIPE.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1
