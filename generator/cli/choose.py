"""``choose``, ``clock`` and ``scene``: the cheapest verified method, and the notes' claims."""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from pathlib import Path

from ..costs import emit_bounds
from ..errors import InputError
from ..limits import PERIOD_SERIES_ORDER

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .common import (
    DRIVEN_QUANTITIES,
    SCENE_NAMES,
    ProgressBar,
    _deprecated,
    _flag_allow_slow,
    _flag_drive,
    _flag_equation,
    _flag_json,
    _flag_out,
    _flag_overwrite_edited,
    _flag_range_bounds,
    _flag_span,
    _order,
    _out_folder,
    _params,
    _positive,
    _real,
    interval,
)


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


def run_choose(args: argparse.Namespace) -> int:
    """Run ``lindstedt choose QUANTITY``: the cheapest verified method for a tolerance and
    a range (the period, of the Duffing oscillator or an EQUATION, with ``--out`` its
    module; q, the driven amplitudes and response, a limit cycle's ω and Mathieu's
    values by their own helpers), as a table or JSON.  Returns the exit status."""
    if args.model is None and (args.param or args.name):
        raise InputError("--param/--name: give an EQUATION (choose period EQUATION …)")
    if args.quantity == "backbone":
        return _choose_backbone(args)
    if args.mode is not None:
        raise InputError("--mode: choose backbone's flag (a system's normal mode)")
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
    _need_range(args, "choose period")
    model = None
    if args.model is not None:
        if args.out:
            raise InputError("--out: the chosen period module is the Duffing oscillator's; "
                             "`lindstedt generate EQUATION` emits an equation's evaluators")
        from ..derive.models import model_from_text

        model = model_from_text(args.model, PERIOD_SERIES_ORDER, _params(args.param), args.name)
    from ..choose import choose_period, modelled_ns
    from ..compiler import generate_choice
    from ..emit.render import check_writable

    if args.out:
        check_writable(_out_folder(args.out, "--out"), ["chosen_period.py"], "--out",
                       args.overwrite_edited)
    progress = ProgressBar("timing the verified methods", not args.json)
    choice = choose_period(args.tol, args.x_min, args.x_max, progress, model=model)
    progress.close()
    variable = "y = eps*A**2" if model is None else model.variable
    data = {"method": choice.method.name, "order": choice.order,
            "max_error": choice.max_error,
            "ns_per_point": choice.ns_per_point, "verified_on": choice.verified_on,
            "modelled_ns_per_point": modelled_ns("period", choice.method, choice.order),
            "decided_by": "cost model (lindstedt.choose.COST_MODEL); ns_per_point measured",
            "quantity": "period", "variable": variable,
            "error_measure": "relative: max |T/T_ref - 1|",
            "considered": _considered(choice.considered, "period")}
    if model is not None:
        data.update(equation=model.source or model.title, omega0=str(model.frequency),
                    reference="quadrature of the scaled potential (Gauss–Legendre, 256 nodes)")
    if args.out:
        command = (f"lindstedt choose period --tol {args.tol!r} "
                   f"--range {args.x_min!r}:{args.x_max!r}")
        data["emitted"] = [str(p) for p in generate_choice(
            choice.candidate, command, Path(args.out), (args.x_min, args.x_max),
            overwrite_edited=args.overwrite_edited)]
    if args.json:
        print(json.dumps(data))
        return 0
    _print_choice(f"period T(y), {variable} in {interval(args.x_min, args.x_max, 6)}, tolerance "
                  f"{args.tol:g} (relative, verified on {choice.verified_on} points):",
                  (choice.method, choice.order, choice.max_error, choice.ns_per_point),
                  choice.considered, quantity="period")
    for path in data.get("emitted", []):
        print(f"  emitted {path}")
    return 0


def _choose_backbone(args: argparse.Namespace) -> int:
    """``choose backbone SYSTEM --mode M --tol TOL --range A:B``: the smallest order of the
    mode's period within the tolerance of shot orbits."""
    from ..choose import choose_backbone
    from ..derive.system import parse_system

    if args.model is None:
        raise InputError("choose backbone needs a SYSTEM (equations separated by ';')")
    if args.out:
        raise InputError("--out: `lindstedt generate SYSTEM --mode M --order K` writes the "
                         "chosen backbone's module")
    _need_range(args, "choose backbone")
    mode = 1 if args.mode is None else args.mode
    progress = ProgressBar("shooting the verification orbits", not args.json)
    try:
        c = choose_backbone(parse_system(args.model, _params(args.param)), mode, args.tol,
                            args.x_min, args.x_max, progress=progress)
    finally:
        progress.close()
    data = {"quantity": "backbone", "mode": c.mode, "method": "lindstedt", "order": c.order,
            "max_error": c.max_error, "errors": list(c.errors), "verified_on": c.verified_on,
            "reach": c.radius, "tol": args.tol, "range": [args.x_min, args.x_max],
            "error_measure": "relative: max |T/T_shot - 1|",
            "reference": "orbits shot by DOP853 (rtol 1e-13, in units of A), a continuation "
                         "in A"}
    if args.json:
        print(json.dumps(data))
        return 0
    print(f"backbone T(A) of mode {c.mode}, A in {interval(args.x_min, args.x_max, 6)}, tolerance "
          f"{args.tol:g} (relative, verified on {c.verified_on} shot orbits):")
    print(f"  chosen: L–P order {c.order}: max error {c.max_error:.1e} (the series reaches "
          f"A < {c.radius:.4g})")
    print("  " + ", ".join(f"order {k}: {e:.1e}" for k, e in enumerate(c.errors)))
    print(f"  (`lindstedt generate SYSTEM --mode {c.mode} --order {c.order}` writes it)")
    return 0


RESUMMED_QUANTITIES = ("cycle", "mathieu")
# NOTE: choose's quantities past the radius: van der Pol's limit-cycle ω(ε) and Mathieu's
# a_m(q), b_m(q) (partial sums, resummed evaluator, numerical reference).


def _choose_resummed(args: argparse.Namespace) -> int:
    """``choose cycle`` (ε in [x-min, x-max]) and ``choose mathieu --kind K --m M`` (q)."""
    _need_range(args, f"choose {args.quantity}")
    if args.out:
        raise InputError(f"--out: choose {args.quantity} reports; `lindstedt generate "
                         "van_der_pol` and `lindstedt mathieu … --out DIR` write the modules")
    from ..choose import choose_limit_cycle, choose_mathieu

    if args.quantity == "cycle":
        c = choose_limit_cycle(args.tol, args.x_min, args.x_max)
        what = f"van der Pol's limit-cycle ω(ε), ε in {interval(args.x_min, args.x_max, 6)}"
    else:
        kind, m = args.kind or "a", args.m if args.m is not None else 0
        c = choose_mathieu(kind, m, args.tol, args.x_min, args.x_max)
        what = f"Mathieu's {kind}_{m}(q), q in {interval(args.x_min, args.x_max, 6)}"
    rows = [{"method": m, "order": o, "max_error": e, "recorded_ns_per_point": r,
             "ns_per_point": ns} for m, o, e, r, ns in c.considered]
    if args.json:
        print(json.dumps({"quantity": args.quantity, "method": c.method, "order": c.order,
                          "max_error": c.max_error, "ns_per_point": c.ns_per_point,
                          "verified_on": c.verified_on, "considered": rows,
                          "error_measure": "relative",
                          "decided_by": "recorded costs (lindstedt.choose.RESUMMED_COSTS)"}))
        return 0
    print(f"{what}, tolerance {args.tol:g} (relative, {c.verified_on} points): {c.method}"
          + (f" (order {c.order})" if c.order else ""))
    for r in rows:
        print(f"  {r['method']:<10} order {r['order']:>4}  max error {r['max_error']:8.1e}  "
              f"{r['recorded_ns_per_point']:10.3g} ns/point recorded, "
              f"{r['ns_per_point']:10.3g} this run")
    return 0


def run_clock(args: argparse.Namespace) -> int:
    """Run ``lindstedt clock``: the notes' appendix claims on approximations of
    ``1 − cos θ`` against the true threshold angles (potential and period), as a table or
    JSON.  Returns the exit status."""
    from ..choose import appendix_thresholds

    rows = [{"approximation": t.approximation, "tolerance": t.tolerance,
             "claimed_deg": t.claimed_deg, "potential_deg": t.potential_deg,
             "period_deg": t.period_deg, "holds_for_potential": t.potential_deg >= t.claimed_deg,
             "holds_for_period": t.period_deg >= t.claimed_deg} for t in appendix_thresholds()]
    if args.json:
        print(json.dumps({"claims": rows}))
        return 0
    print("Hand & Finch's appendix: 1 - cos(theta) approximated, accurate to a tolerance "
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


def run_scene(args: argparse.Namespace) -> int:
    """Run ``lindstedt scene NAME``: the named scene's question, answer and details, as text
    or JSON.  Returns the exit status."""
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
    _need_range(args, "choose q")
    from ..choose import choose_solution, modelled_ns
    from ..compiler import generate_method
    from ..emit.render import check_writable

    if args.out:
        check_writable(_out_folder(args.out, "--out"), ["duffing.py", "duffing_tables.tex",
                                         "duffing_derivation.tex", "fourier.py"], "--out")
    progress = ProgressBar("verifying the L–P orders", not args.json)
    c = choose_solution(args.tol, args.x_min, args.x_max, args.t_max,
                        emittable=bool(args.out), progress=progress)
    progress.close()
    data = {"quantity": "q", "method": c.method.name, "order": c.order,
            "max_error": c.max_error,
            "ns_per_point": c.ns_per_point, "verified_on": c.verified_on,
            "modelled_ns_per_point": modelled_ns("q", c.method, c.order),
            "decided_by": "cost model (lindstedt.choose.COST_MODEL); ns_per_point measured",
            "error_measure": "relative to the amplitude: max |q/A - q_ref/A|",
            "considered": _considered(c.considered)}
    if args.out:
        data["emitted"] = [str(p) for p in generate_method(
            c.method, c.order, Path(args.out), overwrite_edited=args.overwrite_edited)]
    if args.json:
        print(json.dumps(data))
        return 0
    _print_choice(f"q(t)/A to {args.tol:g} for y = εA² in "
                  f"{interval(args.x_min, args.x_max, 6)}, t in [0, {args.t_max:g}] (verified "
                  f"on {c.verified_on} points):",
                  (c.method, c.order, c.max_error, c.ns_per_point), c.considered)
    if c.method == "lindstedt" and not args.out:
        print(f"  (`lindstedt generate duffing --order {c.order}` or --out DIR writes it)")
    for path in data.get("emitted", []):
        print(f"  emitted {path}")
    return 0


def _choose_driven(args: argparse.Namespace) -> int:
    """``choose amplitudes`` and ``choose response``: one ω or a range of ω."""
    for name in ("eps", "force"):
        if getattr(args, name) is None:
            raise InputError(f"choose {args.quantity} needs --{name}")
    if args.omega is None and (args.omega_min is None or args.omega_max is None):
        raise InputError(f"choose {args.quantity} needs --omega W or --omega A:B")
    if args.omega is not None and (args.omega_min is not None or args.omega_max is not None):
        raise InputError("--omega: give one value W or a range A:B, not both")
    tol = args.tol or 1e-4
    lo, hi = (args.omega, None) if args.omega is not None else (args.omega_min, args.omega_max)
    from ..analysis.driven import check_steady_state

    check_steady_state(args.eps, args.Q, lo, hi)
    from ..choose import DRIVEN_MAX, choose_driven
    from ..compiler import generate_method
    from ..emit.render import check_writable

    if args.out:
        check_writable(_out_folder(args.out, "--out"),
                       ["driven.py", "driven_derivation.tex", "balance.py", "driven_damped.py",
                        "driven_damped_derivation.tex"], "--out")
    progress = ProgressBar("shooting the true orbits", not args.json)
    c = choose_driven(args.quantity, tol, args.eps, args.force, args.Q, lo, hi,
                      emit=(emit_bounds(args.allow_slow, DRIVEN_MAX, args.quantity)
                            if args.out else None),
                      progress=progress)
    progress.close()
    data = {"quantity": args.quantity, "method": c.method.name, "order": c.order,
            "max_error": c.max_error, "ns_per_point": c.ns_per_point,
            "verified_on": c.verified_on, "seconds": c.ns_per_point * 1e-9,
            "error_measure": "absolute: max |A_n - A_n,shot|, |B_n - B_n,shot|"
                             if args.quantity == "amplitudes" else "absolute: max |r - r_shot|",
            "scale": float(max(c.truth.r)),  # the largest true r: what the error compares to
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
    if args.out:
        data["emitted"] = [str(p) for p in generate_method(
            c.method, c.order, Path(args.out), overwrite_edited=args.overwrite_edited)]
    if args.json:
        print(json.dumps(data))
        return 0
    what = {"amplitudes": "A1, A3, A5 (and B_n)", "response": "r = sqrt(A1^2 + B1^2)"}
    where = f"omega = {lo:g}" if hi is None else f"omega in {interval(lo, hi, 6)}"
    _print_choice(f"{what[args.quantity]} to {tol:g} (absolute, largest branch, {where}, "
                  f"verified on {c.verified_on} point{'s' * (c.verified_on > 1)} against "
                  "shooting):", (c.method, c.order, c.max_error, c.ns_per_point), c.considered,
                  micro=True)
    for path in data.get("emitted", []):
        print(f"  emitted {path}")
    return 0


def _need_range(args: argparse.Namespace, command: str) -> None:
    """``--tol`` and ``--range A:B``, which every quantity over a range needs."""
    if args.tol is None:
        raise InputError(f"{command} needs --tol")
    if args.x_min is None or args.x_max is None:
        raise InputError(f"{command} needs --range A:B")


def arguments_choose(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt choose``'s arguments."""
    p = sub.add_parser("choose", help="the cheapest verified method for a tolerance and a range",
                       description="Time and verify every method, report the cheapest that "
                       "meets the tolerance on the range.")
    p.add_argument("quantity", choices=("period", "q", *DRIVEN_QUANTITIES,
                                        *RESUMMED_QUANTITIES, "backbone"),
                   help="period T(y); q(t); amplitudes A_n, B_n; response r(ω); cycle: van der "
                   "Pol's limit-cycle ω(ε); mathieu: a_m(q) or b_m(q) (--kind, --m); "
                   "backbone: a SYSTEM's normal mode T(A) (--mode); each over --range")
    p.add_argument("--kind", choices=("a", "b"), default=None,
                   help="mathieu: a (even solutions, default) or b (odd)")
    p.add_argument("--m", type=_order, default=None, metavar="M",
                   help="mathieu: the index m (default 0)")
    p.add_argument("--mode", type=_positive, default=None, metavar="M",
                   help="backbone: the system's mode, by increasing linear frequency "
                   "(default 1)")
    _flag_equation(p, "\"q'' + q + eps*q**5 = 0\" (period: a free oscillator with a "
                   "polynomial force, judged by quadrature; y is then its expansion variable; "
                   "backbone: a SYSTEM, equations separated by ';')")
    p.add_argument("--tol", type=_real, metavar="TOL",
                   help="tolerance > 0 (period, q: relative, required; amplitudes, response: "
                   "absolute, default 1e-4)")
    _flag_span(p, "--range", ("A:B",), "the range A:B of the variable: period, q: y = εA² "
               "(or an EQUATION's expansion variable); cycle: ε; mathieu: q; backbone: "
               "the amplitude A (required)",
               (None, "x_min", "x_max"))
    _deprecated(p, "--x-min", "--range A:B", "x_min", type=_real)
    _deprecated(p, "--x-max", "--range A:B", "x_max", type=_real)
    p.add_argument("--t-max", type=_real, default=20.0, metavar="T",
                   help="q: times 0..T, in units of 1/(linear natural frequency) (default 20)")
    _flag_drive(p, required=False, omega="amplitudes, response: the drive frequency ω, one "
                "value W or a range A:B", omega_forms=("W", "A:B"))
    _flag_range_bounds(p, "--omega-min", "--omega-max")
    _flag_out(p, "write just the chosen evaluator into DIR (period: chosen_period.py; q: "
              "duffing.py or fourier.py; amplitudes, response: driven.py or balance.py, only "
              "emittable methods compete; default: write nothing)", old="--emit")
    _flag_json(p)
    _flag_overwrite_edited(p)
    _flag_allow_slow(p, deprecated_force=False)
    return p


def arguments_clock(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt clock``'s arguments."""
    p = sub.add_parser("clock", help="a pendulum clock's accuracy claims (its period against "
                       "its swing), checked")
    _flag_json(p, "JSON")
    return p


def arguments_scene(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt scene``'s arguments."""
    p = sub.add_parser("scene", help="named scenes: the smallest model that meets each")
    p.add_argument("name", choices=SCENE_NAMES, help="the scene")
    _flag_json(p, "JSON")
    return p
