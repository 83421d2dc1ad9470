"""``lindstedt slowflow``: the averaged equations of one oscillator ``q'' + q = eps*f`` to any
order, or of a system's modes in internal resonance — one method (:func:`derive.averaging.
slow_flow`), one record, one JSON contract, one table; the one oscillator's phase portrait and
emitted right sides, a system's coupled modes and energy exchange, each where the record holds
it."""

from __future__ import annotations

import argparse
import json
import math
import sys
from functools import partial
from pathlib import Path

from ..errors import InputError
from .common import (
    _flag_csv,
    _flag_json,
    _flag_oscillator,
    _flag_overwrite_edited,
    _out_folder,
    _params,
    _positive,
    _real,
    check_outputs,
    sp_text,
    write_csv,
)

PORTRAIT_EPS = 0.1
# NOTE: the ε of `slowflow --plot/--csv` without --eps: small enough for the averaged flow to
# hold over the slow times drawn, at any order.
START_AMPLITUDE = 0.1
START_SEED = 0.01
# NOTE: the default start of a system's energy exchange: the highest resonant mode at amplitude
# 0.1, the others seeded at 1 % of it (a swing spring set bouncing, its swing growing from a
# nudge).
EXCHANGE_SAMPLES = 801
# NOTE: the points of `slowflow SYSTEM --plot/--csv`'s amplitudes over two exchanges.
SLOWFLOW_RADIUS = ("r, the averaged amplitude: van der Pol's radius after the mean-free "
                   "near-identity transformation (the slow flow's variable), not q(0) (series' "
                   "q0: the displacement where the velocity vanishes) nor the orbit's first "
                   "harmonic (series' first_harmonic); the three agree at order eps and differ "
                   "at eps^2 (Rayleigh: r 2 + 5/64 eps^2, q0 2 + 17/96, first harmonic "
                   "2 + 9/64)")


def _cycles(flow) -> list:
    """The limit cycles of one oscillator's autonomous flow with numeric coefficients (none
    otherwise)."""
    from ..derive.averaging import cycle_series

    if flow.system is not None or flow.driven or flow.parameters:
        return []
    return cycle_series(flow)


def slowflow_json(flow, coupled: tuple = (), exchange=None) -> dict:
    """The contract of ``lindstedt slowflow … --json``, a pure function of the record: the
    flow's equations (``equations``: ``a_k'`` and ``phi_k'`` of each mode, ``r'`` and
    ``phi'`` for one oscillator, SymPy text) and ``radial``/``phase`` (per mode, the terms
    ``R_j``, ``Φ_j`` of each order ``eps^j``); one oscillator adds its equation, parameters,
    drive, convention and limit cycles (each cycle's radius r* to eps^(K−1) and ω to eps^K);
    a system its resonant modes, their exact ω0 and shapes, the resonances, the coupled modes
    (phase-locked, every amplitude steady) and the energy exchange (``exchange``, a
    :class:`numerics.references.Exchange`)."""
    text = str if flow.system is not None else sp_text
    equations = {}
    for k, (a, phi) in enumerate(zip(flow.a, flow.phi, strict=True)):
        equations[f"{a}'"] = text(flow.rates[k])
        equations[f"{phi}'"] = text(flow.rates[len(flow.a) + k])
    shared = {"kind": "slowflow", "order": flow.order, "equations": equations,
              "radial": [text(e) for e in flow.radial], "phase": [text(e) for e in flow.phase]}
    if flow.system is None:
        data = {"equation": flow.source, "name": flow.name, "order": flow.order,
                "variable": "eps", "parameters": [str(p) for p in flow.parameters],
                "driven": flow.driven,
                "convention": ("q = r cos(w t + phi), q' = -r w sin(w t + phi) + O(eps), "
                               "w = 1 + eps*sigma" if flow.driven else
                               "q = r cos(t + phi), q' = -r sin(t + phi) + O(eps)")
                + "; mean-free near-identity transformation",
                "radial": shared["radial"], "phase": shared["phase"],
                "cycles": [{"radius": [sp_text(c) for c in cyc.radius],
                            "averaged_radius": [sp_text(c) for c in cyc.radius],
                            "radius_meaning": SLOWFLOW_RADIUS,
                            "omega": [sp_text(c) for c in cyc.omega],
                            "stable_for": "eps > 0" if cyc.slope < 0 else "eps < 0"}
                           for cyc in _cycles(flow)]}
    else:
        names = [str(a) for a in flow.a]
        data = {"kind": "slowflow", "system": flow.system.text, "order": flow.order,
                "modes": list(flow.modes), "omega0": [str(w) for w in flow.omega],
                "resonances": list(flow.resonances),
                "shapes": [[str(v) for v in shape] for shape in flow.shapes],
                "variables": "x = sum_k shape_k a_k cos(omega0_k t + phi_k), slowly varying "
                             "a_k, phi_k",
                "equations": equations,
                "coupled_modes": [{"gamma": str(g), "ratio": str(r), "ratio_value": float(r)}
                                  for g, r in coupled],
                "exchange": {"start": dict(zip(names, exchange.start, strict=True)),
                             "period": exchange.period,
                             "how": "the averaged flow by DOP853 from zero phases: time "
                                    "between two maxima of a1"}}
    return {**data, **{k: v for k, v in shared.items() if k not in data}}


def slowflow_table(data: dict) -> str:
    """The readable slow flow of :func:`slowflow_json`'s data."""
    if "system" in data:
        lines = [f"{data['system']}: internal resonance {'; '.join(data['resonances'])}",
                 f"the slow flow to order 1 ({data['variables']})"]
        lines += [f"  {k} = {v}" for k, v in data["equations"].items()]
        for c in data["coupled_modes"]:
            lines.append(f"coupled mode: resonant angle {c['gamma']}, a2/a1 = {c['ratio']} "
                         f"({c['ratio_value']:.6g})")
        ex = data["exchange"]
        start = ", ".join(f"{k} = {v:g}" for k, v in ex["start"].items())
        lines.append(f"energy exchange from {start}: period {ex['period']:.6g}")
        return "\n".join(lines)
    frame = "q = r cos(w t + phi), w = 1 + eps*sigma" if data["driven"] else "q = r cos(t + phi)"
    lines = [f"{data['name']}: {data['equation']}, the slow flow to order {data['order']} "
             f"({frame})", "dr/dt = sum_k eps^k R_k, dphi/dt = sum_k eps^k Phi_k"]
    for k, (r, phi) in enumerate(zip(data["radial"], data["phase"], strict=True), 1):
        lines += [f"R_{k}   = {r}", f"Phi_{k} = {phi}"]
    for cyc in data["cycles"]:
        lines += [f"limit cycle (dr/dt = 0, attracting for {cyc['stable_for']}): "
                  "r = sum_j eps^j r_j, omega = sum_j eps^j omega_j",
                  "  r_j:     " + ", ".join(cyc["radius"]),
                  "  (r: the averaged amplitude, van der Pol's radius after the mean-free "
                  "near-identity transformation; series' q(0) and first harmonic equal it at "
                  "order eps, not beyond)",
                  "  omega_j: " + ", ".join(cyc["omega"])]
    return "\n".join(lines)


def portrait_csv(p, path: Path) -> Path:
    """The CSV of ``slowflow --csv`` (one oscillator): every trajectory of
    :class:`analysis.curves.Portrait`, point by point, as drawn."""
    columns = (("trajectory", "number from 1"), ("t", "time"), ("x", "r cos(phi)"),
               ("y", "r sin(phi)"))
    return write_csv(path, columns, ((k, *point) for k, tr in enumerate(p.trajectories, 1)
                                     for point in tr.T))


def exchange_csv(exchange, path: Path) -> Path:
    """The CSV of ``slowflow SYSTEM --csv``: the amplitudes a_k at each slow time, as drawn."""
    n = exchange.a.shape[0]
    columns = (("t", "time"), *((f"a{k}", f"amplitude of resonant mode {k}")
                                for k in range(1, n + 1)))
    return write_csv(path, columns, zip(exchange.t, *exchange.a, strict=True))


def check_weak(flow, start: list[float], given: bool) -> None:
    """Refuse a start (``given`` by --start, else the default) where the nonlinear force
    reaches the linear one (limits.WEAK_NONLINEARITY): the first-order slow flow assumes a
    weak nonlinearity."""
    from ..derive.resonance import force_ratio
    from ..limits import WEAK_NONLINEARITY

    log_ratio, factor = force_ratio(flow, tuple(start), WEAK_NONLINEARITY)
    if log_ratio <= math.log10(WEAK_NONLINEARITY):
        return
    values = ", ".join(f"a{k}={a:g}" for k, a in enumerate(start, 1))
    ratio = f"{10**log_ratio:.3g}" if log_ratio < 300 else f"1e{log_ratio:.0f}"
    raise InputError(
        f"{'--start' if given else 'the default start'} {values}: the nonlinear force there "
        f"is {ratio} times the slowest mode's linear restoring force ω0²·a, where the "
        f"first-order slow flow needs a weak nonlinearity (below {WEAK_NONLINEARITY:g}×): "
        f"scale the amplitudes so that the largest is ≤ {max(start) * factor:.3g}")


def _start(flow, pairs: list[str] | None) -> list[float]:
    """The energy exchange's starting amplitudes: the default, each ``--start NAME=VALUE``
    replacing one."""
    names = [str(a) for a in flow.a]
    start = [START_AMPLITUDE * (1 if k == len(names) - 1 else START_SEED)
             for k in range(len(names))]
    for pair in pairs or ():
        name, _, value = pair.partition("=")
        if name.strip() not in names:
            raise InputError(f"--start {pair!r}: write NAME=VALUE with NAME one of "
                             f"{', '.join(names)}")
        try:
            number = float(value)
        except ValueError:
            raise InputError(f"--start {pair!r}: {value!r} is not a number") from None
        if not 0 < number < math.inf:
            raise InputError(f"--start {pair!r}: an amplitude must be > 0 and finite")
        start[names.index(name.strip())] = number
    return start


def one_oscillator(args: argparse.Namespace):
    """The problem of ``slowflow EQUATION|NAME`` as the method takes it (an
    :class:`derive.models.Oscillator`; a preset by its equation) and its default order, 2."""
    from ..derive.models import oscillator, registry_entry

    text, name = args.model, args.name or "oscillator"
    if (entry := registry_entry(text)) is not None:  # a name or its alias (vdp)
        text, name = entry.equation, args.name or entry.name
    return oscillator(text, _params(args.param), name), 2


def resonant_modes(args: argparse.Namespace):
    """The problem of ``slowflow SYSTEM`` as the method takes it (a
    :class:`derive.system.System`) and its default order, 1 (the only one built)."""
    from ..derive.system import parse_system

    return parse_system(args.model, _params(args.param)), 1


def run_slowflow(args: argparse.Namespace, lowered=one_oscillator) -> int:
    """``lindstedt slowflow MODEL --order K``: the averaged equations, exact, of the problem
    ``lowered`` reads (:func:`one_oscillator`, :func:`resonant_modes`); every flag checked
    against the record before anything is written or printed."""
    from ..derive.averaging import slow_flow

    problem, default = lowered(args)
    args.order = default if args.order is None else args.order
    flow = slow_flow(problem, args.order)
    one = flow.system is None
    if one and args.start:
        raise InputError("--start: a system's flag (equations separated by ';')")
    if not one and (args.eps is not None or args.sigma is not None):
        raise InputError("--eps/--sigma: a one-coordinate portrait's values; a system's "
                         "--plot/--csv draw its energy exchange from --start")
    if not one and args.out is not None:
        raise InputError("--out: a system's slow flow is printed, not emitted (not built)")
    if one and (args.eps is not None or args.sigma is not None) and not (args.plot or args.csv):
        raise InputError("--eps/--sigma: the portrait's values; give --plot or --csv")
    if args.sigma is not None and not flow.driven:
        raise InputError("--sigma: the detuning of a drive; this flow is not driven")
    plot, csv = check_outputs(args)
    out = _out_folder(args.out) if args.out is not None else None
    coupled, exchange, drawn = (), None, None
    if not one:
        from ..derive.resonance import coupled_modes
        from ..numerics.references import energy_exchange

        start = _start(flow, args.start)
        check_weak(flow, start, bool(args.start))
        coupled = coupled_modes(flow)
        exchange = energy_exchange(flow, start, samples=EXCHANGE_SAMPLES if plot or csv else 0)
    elif plot or csv:
        from ..analysis.curves import portrait

        drawn = portrait(flow, PORTRAIT_EPS if args.eps is None else args.eps,
                         {"sigma": args.sigma or 0.0} if flow.driven else {})
    written = []
    if out is not None:  # written before anything is printed: a refusal prints nothing
        from ..compiler import generate_slow_flow

        params = "".join(f" --param {k}={v}" for k, v in sorted(_params(args.param).items()))
        command = (f'lindstedt slowflow "{flow.source}" --name {flow.name} --order '
                   f"{args.order}{params}")
        written = generate_slow_flow(problem, args.order, command, out,
                                     overwrite_edited=args.overwrite_edited)
    if plot is not None:
        if one:
            from ..charts_series import portrait_figure

            portrait_figure(drawn, plot)
        else:
            from ..charts_modes import exchange_figure

            exchange_figure(flow, exchange, plot)
    if csv is not None:
        portrait_csv(drawn, csv) if one else exchange_csv(exchange, csv)
    data = slowflow_json(flow, coupled, exchange)
    print(json.dumps(data) if args.json else slowflow_table(data))
    for path in written:
        print(f"  {path}", file=sys.stderr if args.json else sys.stdout)
    return 0


run_resonant_modes = partial(run_slowflow, lowered=resonant_modes)


def arguments_slowflow(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt slowflow``'s arguments."""
    p = sub.add_parser("slowflow", help="the slow flow (averaging) of q'' + q = eps*f, free, "
                       "self-excited or driven; of a system's modes in internal resonance",
                       description="Average q'' + q = eps*f(q, q') (+ eps*F*cos(w*t), w = 1 + "
                       "eps*sigma) to order K: dr/dt and dphi/dt exactly, for q = r cos(t + "
                       "phi); with --out the compiled right sides and the LaTeX of the flow. A "
                       "SYSTEM (equations separated by ';') whose linear frequencies are "
                       "commensurate: the first-order slow flow of the resonant modes, its "
                       "coupled modes and the energy-exchange period.")
    _flag_oscillator(p)
    p.add_argument("--order", type=_positive, default=None, metavar="K",
                   help="the order in eps, 1..6 (default 2; a SYSTEM: 1, the only one built)")
    p.add_argument("--start", action="append", metavar="NAME=VALUE",
                   help="a SYSTEM: the starting amplitude a_k of a resonant mode for the "
                   "energy exchange, e.g. a1=0.001 (repeatable; default: the highest mode at "
                   "0.1, the others at 0.001)")
    _flag_json(p, "the contract {kind, order, equations, radial, phase} with {equation, name, "
               "variable, parameters, driven, convention, cycles}; a SYSTEM: with {system, "
               "modes, omega0, resonances, shapes, variables, coupled_modes, exchange}")
    p.add_argument("--out", metavar="DIR", help="also write <name>_slow_flow.py (numba "
                   "slow_flow, slow_flow_jacobian, slow_flow_cartesian) and "
                   "<name>_slow_flow.tex into DIR")
    p.add_argument("--plot", metavar="FILE",
                   help="also draw the phase portrait into FILE (.png, .svg or .pdf): "
                   "trajectories in the plane (r cos phi, r sin phi) from 8 starts, the limit "
                   "cycles and fixed points; a SYSTEM: each resonant amplitude a_k over two "
                   "energy exchanges from --start (default: none)")
    _flag_csv(p, "the portrait's trajectories (trajectory, t, x = r cos phi, y = r sin phi); "
              "a SYSTEM: t, a1, a2, ... as drawn")
    p.add_argument("--eps", type=_real, default=None, metavar="EPS",
                   help=f"with --plot/--csv: the value of eps (default {PORTRAIT_EPS})")
    p.add_argument("--sigma", type=_real, default=None, metavar="SIGMA",
                   help="with --plot/--csv, a driven flow: the detuning sigma of w = 1 + "
                   "eps*sigma (default 0)")
    _flag_overwrite_edited(p)
    return p
