"""The series commands: ``series``, ``mathieu``, ``tongues``, ``slowflow``, ``models`` and
``generate``: their arguments, JSON contracts and tables."""

from __future__ import annotations

import argparse
import json
import math
from fractions import Fraction
from pathlib import Path

from ..errors import InputError
from ..limits import DRIVEN_MAX_ORDER

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .common import (
    EMITTED,
    ProgressBar,
    _deprecated,
    _flag_allow_slow,
    _flag_csv,
    _flag_harmonics,
    _flag_json,
    _flag_omega,
    _flag_order,
    _flag_oscillator,
    _flag_out,
    _flag_overwrite_edited,
    _fraction_text,
    _nonnegative,
    _order,
    _out_folder,
    _params,
    _positive,
    _positive_real,
    _real,
    check_outputs,
    write_csv,
)
from .system import _short, periodic_json, periodic_table


def _human(c: object) -> str:
    """:func:`_fraction_text` as a reader writes it: an integer without ``/1``."""
    text = _fraction_text(c)
    return text.removesuffix("/1") if text.endswith("/1") and "/" not in text[:-2] else text


def limit_cycle_json(lc) -> dict:
    """``lindstedt series`` of a self-excited oscillator: ω, T/2π and q(0) as exact "p/q" in
    ε, each q_j's cos and sin coefficients, the first-order amplitude slope and the verdict."""
    m = lc.model
    frac = _fraction_text
    return {
        "model": m.name, "order": lc.order, "variable": "eps",
        "omega": [frac(c) for c in lc.omega], "period": [frac(c) for c in lc.period],
        "amplitude": [frac(c) for c in lc.amplitude],
        "q0": [frac(c) for c in lc.amplitude],
        "first_harmonic": [frac(c) for c in lc.first_harmonic],
        "amplitudes": CYCLE_AMPLITUDES,
        "q": [{"cos": {str(n): frac(c) for n, c in sorted(cos.items())},
               "sin": {str(n): frac(c) for n, c in sorted(sin.items())}} for cos, sin in lc.q],
        "convention": "q'(0) = 0; q(0) = sum_j amplitude[j] eps^j, s = omega t",
        "equation": m.source, "slope": frac(lc.slope),
        "stable_for": "eps > 0" if lc.slope > 0 else "eps < 0",
        "stability": limit_cycle_stability(lc),
    }


CYCLE_AMPLITUDES = {
    "q0": "q(0), the displacement where the velocity vanishes (q'(0) = 0: the turning point); "
          "'amplitude' is the same series",
    "first_harmonic": "sqrt(A1^2 + B1^2) of q(s) = sum_n (A_n cos ns + B_n sin ns): the orbit's "
                      "first-harmonic amplitude",
    "slowflow_r": "not given here: slowflow's r, the averaged amplitude (van der Pol's radius "
                  "after the mean-free near-identity transformation); all three agree at order "
                  "eps and differ at eps^2 (Rayleigh: q0 2 + 17/96 eps^2, first harmonic "
                  "2 + 9/64 eps^2, r 2 + 5/64 eps^2)",
}
# NOTE: a limit cycle has several "amplitudes"; each output names its own and how they relate.


def limit_cycle_stability(lc) -> str:
    """The cycle attracts for ``ε S'(a₀) > 0`` and repels for the other sign of ε, where the
    same series holds (time reversed: t → −t, ε → −ε)."""
    good, bad = ("eps > 0", "eps < 0") if lc.slope > 0 else ("eps < 0", "eps > 0")
    return (f"stable (attracting) for {good}, unstable (repelling) for {bad}; the series holds "
            "for both signs")


def _cycles_json(cycles) -> list[dict]:
    """Every limit cycle: its first-order amplitude a₀ (exact, SymPy's str), S'(a₀) and its
    stability, smallest amplitude first."""
    return [{"amplitude0": str(c.amplitude), "slope": str(c.slope), "stability": c.stability,
             "expandable": c.slope != 0, "amplitude0_value": float(c.amplitude)}
            for c in cycles]


def _cycles_text(model, listed: list[dict]) -> str:
    lines = [f"{model.name}: {len(listed)} limit cycle(s) of S(a), by amplitude:",
             "  (S(a): the sin s coefficient of f(a cos s, -a sin s); averaged, "
             "da/dt = -eps*S(a)/2; a cycle at each root a0 > 0)"]
    for k, c in enumerate(listed, 1):
        value = "" if c["amplitude0"] == _short(c["amplitude0_value"]) else \
            f" = {c['amplitude0_value']:.15g}"
        lines.append(f"  cycle {k}: a0 = {c['amplitude0']}{value}, S'(a0) = {c['slope']}: "
                     f"{c['stability']}")
    return "\n".join(lines)


def limit_cycle_table(lc, reach=None) -> str:
    """The text table of a limit cycle's series: its convention and stability (and the radius
    of ω's series, ``reach``: :class:`analysis.curves.CycleRadius`, when computed), then
    ``ω_j``, ``(T/2π)_j`` and ``amplitude_j``, exact, for each order ``j``."""
    m = lc.model
    lines = [f"{m.name}: {m.title}, a limit cycle, expansion variable eps, order {lc.order}",
             "convention: q'(0) = 0, q(0) = sum_j amplitude_j eps^j",
             "amplitudes: amplitude_j of q(0), the displacement where the velocity vanishes; "
             "r1_j of the first harmonic sqrt(A1^2 + B1^2); slowflow's averaged r is a "
             "third, equal to both at order eps only",
             f"stability: {limit_cycle_stability(lc)}",
             *([] if reach is None else [
                 f"omega's series converges for |eps| < {reach.value:.6g} (estimated, spread "
                 f"{reach.spread:.2g})" if reach.value is not None else
                 "radius of convergence in eps not estimated at this order (from about 24)"]),
             f"{'j':>3}  {'omega_j':>22}  {'(T/2pi)_j':>22}  {'amplitude_j':>22}  "
             f"{'r1_j':>22}"]
    def shown(c: object) -> str:  # an integer as a reader writes it: 1, 0, 2
        text = _fraction_text(c)
        return text.removesuffix("/1")

    harmonic = lc.first_harmonic

    for j in range(lc.order + 1):
        lines.append(f"{j:>3}  {shown(lc.omega[j]):>22}  {shown(lc.period[j]):>22}  "
                     f"{shown(lc.amplitude[j]):>22}  {shown(harmonic[j]):>22}")
    return "\n".join(lines)


SERIES_CSV = (("omega", "frequency in units of omega0"),
              ("period", "T/(2*pi) in units of 1/omega0"))


def series_csv(c, path: Path) -> Path:
    """The CSV of ``series --csv`` of a free oscillator: the points of
    :class:`analysis.curves.SeriesCurves`, as drawn."""
    columns = (("y", f"expansion variable {c.variable}"), *SERIES_CSV,
               ("converges", "1 where |y| < the radius and a periodic orbit exists"))
    return write_csv(path, columns, zip(c.y, c.omega, c.period, map(bool, c.inside),
                                        strict=True))


def cycle_csv(c, path: Path) -> Path:
    """The CSV of ``series --csv`` of a limit cycle: :class:`analysis.curves.CycleCurves`."""
    columns = (("eps", "the small parameter"), ("amplitude", "q(0) at q'(0) = 0"),
               *SERIES_CSV)
    return write_csv(path, columns, zip(c.eps, c.amplitude, c.omega, c.period, strict=True))


def run_series(args: argparse.Namespace) -> int:
    """Run ``lindstedt series MODEL``: the exact L–P series of a free oscillator, or of a
    self-excited oscillator's limit cycles (``--cycle``: one of them); ``--singularities``:
    the nearest singularity of ω; ``--plot``, ``--csv``: its curves.  Prints a table or
    JSON; returns the exit status."""
    from ..derive.cycles import derive_limit_cycle, limit_cycles
    from ..derive.lindstedt import derive, validity
    from ..derive.models import SelfExcited, series_model

    plot, csv = check_outputs(args)
    found = series_model(args.model, args.order, _params(args.param), args.name)
    if args.cycle is not None and not isinstance(found, SelfExcited):
        raise InputError(f"--cycle {args.cycle}: {args.model!r} is conservative: a family of "
                         "orbits, no limit cycles to pick from")
    if isinstance(found, SelfExcited):
        from ..analysis.curves import cycle_curves, cycle_radius

        cycles = limit_cycles(found)
        if args.cycle is not None and not 1 <= args.cycle <= len(cycles):
            raise InputError(f"--cycle {args.cycle}: {found.name} has {len(cycles)} limit "
                             f"cycle(s), numbered 1 to {len(cycles)} by amplitude")
        listed = _cycles_json(cycles)
        first = args.cycle if args.cycle is not None else 1
        lc = derive_limit_cycle(found, args.order, first - 1)
        reach = cycle_radius(lc)
        data = {**limit_cycle_json(lc), "cycle": first, "cycles": listed,
                "radius_estimate": None if reach.value is None else
                {"variable": "eps", "value": reach.value, "spread": reach.spread}}
        omega = lc.omega
        # the table: the cycle asked for, or each in turn (one that cannot be expanded says why)
        texts = [_cycles_text(found, listed)]
        shown = [] if args.json else [first] if args.cycle is not None \
            else range(1, len(cycles) + 1)
        for k in shown:
            c = cycles[k - 1]
            if k == first:
                texts.append(f"cycle {k}: " + limit_cycle_table(lc, reach))
            elif c.slope == 0:
                texts.append(f"cycle {k}: not expanded: {c.stability}")
            else:
                texts.append(f"cycle {k}: " + limit_cycle_table(
                    derive_limit_cycle(found, args.order, k - 1)))
        text = "\n\n".join(texts)
        curves = cycle_curves(lc, reach) if plot or csv else None
        draw, tabulate = "cycle_figure", cycle_csv
    else:
        model = found  # series_model built it (model_from_text): parse and expand once
        progress = ProgressBar(f"deriving {model.name} to order {args.order}", not args.json)
        sol = derive(model, args.order, progress)
        progress.close()
        valid = validity(sol)
        data = periodic_json(sol, valid)
        text = "" if args.json else periodic_table(data, args.exact)  # only what is printed
        omega = [sol.ground.to_fraction(c) for c in sol.omega] if sol.ground.is_rational \
            else None
        if plot or csv:
            from ..analysis.curves import series_curves

            curves = series_curves(sol, valid, " and ".join(
                f for f, given in (("--plot", plot), ("--csv", csv)) if given))
        draw, tabulate = "series_figure", series_csv
    if args.singularities:
        data["singularities"], line = _singularities(omega, data["variable"])
        text += "\n" + line
    if plot is not None:
        from .. import charts_series

        getattr(charts_series, draw)(curves, plot)
    if csv is not None:
        tabulate(curves, csv)
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
    """``--out`` writes a module and prints its path: the printing flags given beside it
    (``flags``: pairs of a flag and whether it was given) are refused, not ignored."""
    others = [flag for flag, given in flags if given]
    if others:
        raise InputError(f"--out writes the module only: drop {', '.join(others)}")


def run_mathieu(args: argparse.Namespace) -> int:
    """``lindstedt mathieu a|b --m M --order K``: DLMF §28.6's series of a_m(q) or b_m(q)."""
    from ..derive.hill import mathieu_series

    if args.out is not None:
        from .. import compiler

        _emit_only((("--json", args.json), ("--singularities", args.singularities)))
        for path in compiler.generate_mathieu(args.kind, args.m, args.order,
                                              _out_folder(args.out, "--out"),
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
        print(f"{k:>4}  {_human(c)}")
    if line:
        print(line)
    return 0


DAMPING_PANEL = 0.05
# NOTE: the damped panel of `tongues --plot` without --zeta: the tongues visibly lift.


def run_tongues(args: argparse.Namespace) -> int:
    """``lindstedt tongues P --n N --order K``: the transition curves out of tongue n of
    x'' + (δ + ε p(t))x = 0, exact; ``--zeta Z``: the damped tongue's tip."""
    from ..derive.hill import fourier_of_text, tongue_tip, transition_curves
    from ..derive.lindstedt import partial_sum, series_radius

    if args.out is not None:
        from .. import compiler

        _emit_only((("--eps", args.eps is not None), ("--tol", args.tol),
                    ("--zeta", args.zeta is not None), ("--plot", args.plot),
                    ("--json", args.json), ("--singularities", args.singularities)))
        for path in compiler.generate_tongue(args.p, args.n, args.order,
                                             _out_folder(args.out, "--out"),
                                             overwrite_edited=args.overwrite_edited):
            print(path)
        return 0
    if args.tol is not None and args.eps is None:
        raise InputError("--tol: give --eps EPS, the ε the tolerance is asked at")
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
        lines += [f"{k:>4}  {_human(c)}" for k, c in enumerate(curve.delta)]
        if args.singularities:
            row["singularities"], line = _singularities(list(curve.delta), "eps",
                                                        f"delta ({curve.label})", None)
            lines.append(line)
        if args.eps is not None:
            value, error, best = partial_sum(curve.delta, args.eps)
            radius = series_radius(curve.delta)
            if abs(args.eps) >= radius:  # outside the disc of convergence: no value
                value, error = math.nan, math.inf
            if args.tol is not None and not error <= args.tol:
                _, best_error, _ = partial_sum(curve.delta[:best + 1], args.eps)
                raise InputError(f"--tol {args.tol:g}: not reached at eps = {args.eps:g} by order "
                                 f"{args.order} (estimate {error:.2g}); the best reachable is "
                                 f"{best_error:.2g} at order {best}")
            row["at"] = {"eps": args.eps, "delta": value, "error": error, "radius": radius}
            reach = (f"radius of convergence ~{radius:.4g}" if math.isfinite(radius) else
                     "radius of convergence not estimable at this order: raise --order")
            lines.append(f"at eps = {args.eps:g}: delta = {value:.15g} (truncation ~{error:.2g}"
                         f"; {reach})")
        data["curves"].append(row)
    if args.zeta is not None:
        tip = tongue_tip(p, args.n, args.order)
        eps, _, _ = partial_sum(tip.eps_min, args.zeta)
        delta, err, _ = partial_sum(tip.delta, args.zeta)
        data["damping"] = {
            "variable": "zeta", "equation": "x'' + 2 zeta x' + (delta + eps p(t)) x = 0",
            "eps_min": [_fraction_text(c) for c in tip.eps_min],
            "delta_at_min": [_fraction_text(c) for c in tip.delta],
            "mu_max": [_fraction_text(c) for c in tip.mu],
            "at": {"zeta": args.zeta, "eps_min": eps, "delta": delta, "error": err}}
        lines.append("damped tongue tip: eps_min(zeta) = sum_k e_k zeta^k at delta = sum_k "
                     "d_k zeta^k (k, e_k, d_k)")
        lines += [f"{k:>4}  {_human(e):>24}  {_human(d)}"
                  for k, (e, d) in enumerate(zip(tip.eps_min, tip.delta, strict=True))]
        lines.append(f"at zeta = {args.zeta:g}: eps_min = {eps:.12g}, delta = {delta:.12g}")
    print(json.dumps(data) if args.json else "\n".join(lines))
    if args.plot:
        from ..charts import ince_strutt_figure

        path = ince_strutt_figure(Path(args.plot), args.p, args.zeta or DAMPING_PANEL,
                                  order=args.order, tongues=range(max(4, args.n + 1)))
        if not args.json:
            print(f"Ince–Strutt chart: {path}")
    return 0


def run_models(args: argparse.Namespace) -> int:
    """Run ``lindstedt models``: the registry's named oscillators with their equations and
    aliases, as a table or JSON.  Returns the exit status."""
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


def run_generate(args: argparse.Namespace) -> int:
    """Run ``lindstedt generate MODEL``: write into ``--out`` the numba evaluator modules
    (and LaTeX) of a free oscillator or a limit cycle, or the driven oscillator's
    ``driven``, ``balance`` or ``fourier`` module; print their paths.  Returns the exit status."""
    if args.ssm is not None or args.model_dir is not None:
        from .ssm import run_generate_ssm

        return run_generate_ssm(args)
    if args.model is None:
        raise InputError("generate: give an EQUATION or a NAME (or a SYSTEM, or --ssm M with "
                         "--model DIR)")
    order = args.order
    if args.mode is not None or args.amplitude is not None:
        raise InputError("--mode/--amplitude: a system's flags (equations separated by ';')")
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
        check_emitted_names([str(model.coordinate)], [n for n, _ in model.parameters])
        # before the derivation: a clash is known at once
        progress = ProgressBar(f"deriving {model.name} to order {order + 2}")
        paths = compiler.generate(model, order, out, args.allow_divergent, progress,
                                  overwrite_edited=args.overwrite_edited)
        progress.close()
    for path in paths:
        print(path)
    return 0


def run_generate_mode(args: argparse.Namespace) -> int:
    """``generate SYSTEM --mode M``: the normal mode's module (the flags of free oscillators
    refused beside it)."""
    if args.ssm is not None or args.model_dir is not None:
        from .ssm import run_generate_ssm

        return run_generate_ssm(args)
    given = [flag for flag, on in (("--damped", args.damped),
                                   ("--resum-order", args.resum_order is not None)) if on]
    if given:
        raise InputError(f"{', '.join(given)}: not for a system's normal mode")
    from .. import compiler
    from ..derive.system import parse_system
    from ..lower.printers import identifier

    system = parse_system(args.model, _params(args.param))
    names = [str(x) for x in system.coordinates]
    if args.amplitude is not None and args.amplitude not in names:
        raise InputError(f"--amplitude {args.amplitude}: not a coordinate of the system "
                         f"({', '.join(names)})")
    amplitude = 0 if args.amplitude is None else names.index(args.amplitude)
    mode = 1 if args.mode is None else args.mode
    name = identifier(args.name or f"mode{mode}")
    command = " ".join(["lindstedt generate", f'"{args.model}"', f"--mode {mode}",
                        f"--order {args.order}", *(f"--param {p}" for p in args.param or ()),
                        *([f"--amplitude {args.amplitude}"] if args.amplitude else []),
                        f"--name {name}",
                        *(["--allow-divergent"] if args.allow_divergent else [])])
    progress = ProgressBar(f"deriving mode {mode}")
    try:
        paths = compiler.generate_nnm(system, mode, args.order, _out_folder(args.out),
                                      amplitude=amplitude, name=name, command=command,
                                      progress=progress,
                                      overwrite_edited=args.overwrite_edited,
                                      allow_divergent=args.allow_divergent)
    finally:
        progress.close()
    for path in paths:
        print(path)
    return 0


def arguments_series(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
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
    p.add_argument("--exact", action="store_true",
                   help="the table shows every number exactly (default: a long exact "
                   "rational as its decimal to 12 significant digits; --json holds both)")
    p.add_argument("--plot", metavar="FILE",
                   help="also draw into FILE (.png, .svg or .pdf) ω and T against the "
                   "expansion variable y, with the orbits' edge and the radius of convergence "
                   "marked; a limit cycle: its amplitude and ω against ε (default: none)")
    _flag_csv(p, "the curves drawn by --plot (y, omega, period, converges; a limit cycle: "
              "eps, amplitude, omega, period)")
    _flag_allow_slow(p)
    return p


def arguments_mathieu(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
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
    _flag_out(p, "write DIR/mathieu_<kind><m>.py instead: a numba ufunc of the value, "
              "Padé-resummed from the series to --order and refined by a Newton step on the "
              "recurrence's determinant, verified against the eigenvalues at 30 digits on a "
              "grid of q up to 50 and NaN beyond where it was verified", old="--emit")
    _flag_overwrite_edited(p)
    p.add_argument("--singularities", action="store_true",
                   help="also estimate the nearest singularity (radius of convergence) from "
                   "the exact series, with its spread; in q**2 for a_2n, b_2n; with --json a "
                   "key 'singularities'")
    return p


def arguments_tongues(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
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
    p.add_argument("--zeta", type=_nonnegative, metavar="ZETA",
                   help="also the tip of the tongue of x'' + 2ζ x' + (δ + ε p) x = 0, ζ the "
                   "damping ratio: ε_min and its δ as series in ζ, and their values at ZETA")
    _deprecated(p, "--damping", "--zeta", "zeta", type=_nonnegative)
    p.add_argument("--eps", type=_real, metavar="EPS",
                   help="also evaluate each curve at ε = EPS with its truncation estimate")
    _deprecated(p, "--at", "--eps", "eps", type=_real)
    p.add_argument("--tol", type=_positive_real, metavar="TOL",
                   help="with --eps: refuse unless the truncation estimate is ≤ TOL (naming "
                   "the best reachable)")
    p.add_argument("--singularities", action="store_true",
                   help="also estimate each curve's nearest singularity in eps (radius of "
                   "convergence) with its spread")
    p.add_argument("--plot", metavar="FILE",
                   help="also draw the Ince–Strutt chart of this p into FILE (.png, .svg or "
                   ".pdf): Floquet multipliers on a 400 x 400 grid, undamped and with damping "
                   f"ζ = ZETA (default {DAMPING_PANEL}), the series curves of tongues 0..max(3, N)")
    _flag_json(p, "the curves as JSON {p, n, variable, delta0, harmonics, time_origin, period, "
               "solution_variable, curves: [{label, series, solution}], damping}")
    _flag_allow_slow(p, deprecated_force=False)
    _flag_out(p, "write DIR/tongue_<N>.py instead: numba ufuncs delta_<i>(eps) and "
              "delta_<i>_error(eps), one per curve, Padé-resummed from the series to --order "
              "(≥ 12), verified against the Floquet boundary |tr M| = 2 to 1e-10 in delta on "
              "240 points up to 3 radii (at most eps = 10), NaN beyond", old="--emit")
    _flag_overwrite_edited(p)
    return p


def arguments_models(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt models``'s arguments."""
    p = sub.add_parser("models", help="list the named oscillators",
                       description="The named oscillators: each is an equation (any equation "
                       "of the family can be given instead of a name).")
    _flag_json(p, "the list as JSON")
    return p


def arguments_generate(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt generate``'s arguments."""
    p = sub.add_parser(
        "generate", help="write a numba evaluator module and LaTeX tables and derivation",
        description="Write a numba evaluator module and its LaTeX (the tables and the "
        "derivation; balance and fourier have a module alone) into --out; for a SYSTEM "
        "(equations separated by ';') the module of one nonlinear normal mode (--mode) or of "
        "its spectral submanifold (--ssm).")
    _flag_oscillator(p, emitted=True, optional=True)
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
    p.add_argument("--mode", type=_positive, default=None, metavar="M",
                   help="a SYSTEM's nonlinear normal mode, by increasing linear frequency "
                   "(default 1): ω(A), T(A) and each coordinate x_i(t, A)")
    p.add_argument("--amplitude", metavar="NAME",
                   help="a SYSTEM's coordinate at x = A at t = 0 (default: the first)")
    p.add_argument("--ssm", type=_positive, default=None, metavar="M",
                   help="the reduced model of the spectral submanifold of mode M of a damped "
                   "SYSTEM (or --model DIR): omega(rho), decay(rho), damping(rho), "
                   "error_estimate(rho), amplitude(rho) and, driven, frc(w, f); the reduced "
                   "dynamics in LaTeX (NAME_reduced.tex); see `lindstedt ssm`")
    p.add_argument("--model", dest="model_dir", metavar="FOLDER",
                   help="with --ssm: a model folder (M.mtx, K.mtx, C.mtx, nonlinear.txt, "
                   "drive.txt) instead of SYSTEM")
    p.add_argument("--output", metavar="LIST",
                   help="with --ssm: the coordinates whose amplitudes the module gives "
                   "(0-based indices or names; default as `lindstedt ssm`)")
    _flag_omega(p, ("A:B",), "with --ssm and a drive: the range of frc(w, f) (default ±20 %% "
                "about the mode's linear frequency)")
    _flag_allow_slow(p)
    _flag_overwrite_edited(p)
    return p
