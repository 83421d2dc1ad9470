"""``nnm``: the nonlinear normal modes of a system of coupled oscillators (JSON contract and
table)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ..errors import InputError

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .common import (
    ProgressBar,
    _flag_allow_slow,
    _flag_json,
    _flag_order,
    _order,
    _params,
)

CONVENTION = ("at t = 0 every velocity is zero and {a}(0) = A (a turning point); "
              "x_i = A sum_j y^j sum_n c[j][n] cos(n*omega*t)")


def nnm_json(mode) -> dict:
    """The contract of ``lindstedt nnm … --json``: ω₀, the expansion variable, ω and T/2π
    per order and every coordinate's Fourier coefficients, each exact (SymPy's str)."""
    names = [str(x) for x in mode.system.coordinates]
    return {
        "kind": "nnm", "mode": mode.mode, "omega0": str(mode.omega0),
        "variable": mode.variable, "order": mode.order,
        "omega": [str(c) for c in mode.omega()],
        "period": [str(c) for c in mode.period()],
        "coordinates": {name: [{str(n): str(c) for n, c in order.items()}
                               for order in mode.coordinate(i)]
                        for i, name in enumerate(names)},
        "system": mode.system.text, "amplitude": names[mode.amplitude],
        "lambda": str(mode.lam),
        "linear_frequencies_squared": [str(x) for x in mode.system.modes()],
        "convention": CONVENTION.format(a=names[mode.amplitude]),
        "period_units": "T/(2*pi): period[j] is the coefficient of y^j",
    }


def nnm_table(data: dict) -> str:
    """The readable table: ω_j, (T/2π)_j and each coordinate's harmonics per order."""
    lines = [f"mode {data['mode']} of {data['system']}",
             f"omega0 = {data['omega0']} (omega0^2 of every mode: "
             f"{', '.join(data['linear_frequencies_squared'])}), expansion variable "
             f"{data['variable']}, order {data['order']}",
             f"convention: {data['convention']}",
             f"{'j':>3}  {'omega_j':>28}  {'(T/2pi)_j':>28}"]
    for j, (w, t) in enumerate(zip(data["omega"], data["period"], strict=True)):
        lines.append(f"{j:>3}  {w:>28}  {t:>28}")
    for name, orders in data["coordinates"].items():
        lines.append(f"{name}: harmonic n -> coefficient, per order")
        for j, order in enumerate(orders):
            lines.append(f"{j:>3}  " + ", ".join(f"{n}: {c}" for n, c in order.items()))
    return "\n".join(lines)


def run_nnm(args: argparse.Namespace) -> int:
    """Run ``lindstedt nnm``: parse the system, derive the mode, print JSON or the table."""
    from ..derive.nnm import normal_mode
    from ..derive.system import parse_system

    if args.plot:
        from ..charts import check_plot_path

        check_plot_path(Path(args.plot))
    system = parse_system(args.system, _params(args.param))
    names = [str(x) for x in system.coordinates]
    amplitude = 0
    if args.amplitude is not None:
        if args.amplitude not in names:
            raise InputError(f"--amplitude {args.amplitude}: not a coordinate of the system "
                             f"({', '.join(names)})")
        amplitude = names.index(args.amplitude)
    progress = ProgressBar(f"deriving mode {args.mode} to order {args.order}", not args.json)
    try:
        mode = normal_mode(system, args.mode, args.order, amplitude, progress)
    finally:
        progress.close()
    data = nnm_json(mode)
    if args.plot:
        from ..charts_modes import nnm_figure

        nnm_figure(system, Path(args.plot))
    print(json.dumps(data) if args.json else nnm_table(data))
    return 0


def arguments_nnm(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt nnm``'s arguments."""
    p = sub.add_parser("nnm", help="a nonlinear normal mode of coupled oscillators as an exact "
                       "series: the backbone ω(A), T(A) and the mode's shape",
                       description="The Lindstedt–Poincaré series of one nonlinear normal mode "
                       "of a conservative system x'' + Kx + f(x) = 0 (one equation per "
                       "coordinate, separated by ';'): ω and T against the amplitude A and "
                       "every coordinate's Fourier coefficients, exact (ω0 an algebraic "
                       "number, never rounded). An internal resonance with another mode is "
                       "refused, naming it.")
    p.add_argument("system", metavar="SYSTEM",
                   help="equations such as \"x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 "
                   "= 0\" (x'' the accelerations, one per equation; every other name a "
                   "parameter given with --param)")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="an exact value for a parameter, e.g. beta=1/10 (repeatable; every "
                   "parameter needs one)")
    p.add_argument("--mode", type=_order, default=1, metavar="M",
                   help="the mode, numbered 1, 2, … by increasing linear frequency (default 1)")
    p.add_argument("--amplitude", metavar="NAME",
                   help="the coordinate at its turning point x = A at t = 0 (default: the "
                   "first)")
    _flag_order(p, "highest power K of the expansion variable")
    _flag_json(p)
    p.add_argument("--plot", metavar="FILE",
                   help="also draw the frequency–energy plot of every mode (at most 4) into "
                   "FILE (.png, .svg or .pdf): each backbone from its series beside orbits shot "
                   "by DOP853, the series' reach, the internal-resonance lines (default: none)")
    _flag_allow_slow(p, deprecated_force=False)
    return p
