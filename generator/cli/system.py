"""A system of coupled oscillators: ``nnm`` (its nonlinear normal modes) and ``slowflow
SYSTEM``: JSON and tables (``response SYSTEM`` is ``response``'s, :mod:`.response`)."""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import textwrap
from functools import partial
from pathlib import Path

from ..errors import InputError

# NOTE: nothing heavy is imported here: `lindstedt --help` and argument errors must answer in
# well under 0.3 s, so each command imports its stages (SymPy, numba, SciPy, matplotlib) itself.
from .common import (
    ProgressBar,
    _flag_allow_slow,
    _flag_csv,
    _flag_json,
    _flag_order,
    _params,
    _positive,
    _rational,
    check_outputs,
    write_csv,
)

CONVENTION = ("at t = 0 every velocity is zero and {a}(0) = A (a turning point); "
              "x_i = A sum_j y^j sum_n c[j][n] cos(n*omega*t), y the expansion variable")


def _monomial(powers: tuple[tuple[str, int], ...]) -> str:
    """SymPy's spelling of a monomial: ``"A**2*alpha"``, ``"1"`` for the constant."""
    return "*".join(n if e == 1 else f"{n}**{e}" for n, e in powers) or "1"


def _ground_text(ground, c: object) -> str | dict:
    """An exact coefficient of a free oscillator's ground: ``"p/q"``, or for ``QQ[A, params]``
    an object mapping each monomial (SymPy's ``str``: ``"A**2*alpha"``, ``"1"``) to its exact
    ``"p/q"``, formatted from FLINT's terms (no SymPy on the way)."""
    if ground.is_rational:
        return _rational(c)
    return dict(sorted((_monomial(m), _rational(v)) for m, v in ground.terms(c)))


def _finite(x: float) -> float | None:
    """``x``, or ``None`` (JSON's null) where it is not a finite number."""
    return x if math.isfinite(x) else None


def _decimal(c: object) -> str:
    """A rational's 12 significant digits, from its own integers (no SymPy): in double
    precision where it is a normal double, else (order 300's 1e-330, a denominator past
    1e308) by decimal arithmetic, never a 0 or a subnormal's false digits."""
    p, q = int(c.p), int(c.q)
    try:
        x = p / q
    except OverflowError:
        x = math.inf
    if p == 0 or (math.isfinite(x) and abs(x) >= sys.float_info.min):
        return f"{x:.12g}"
    from decimal import Decimal, localcontext

    with localcontext() as ctx:
        ctx.prec = 12
        return f"{Decimal(p) / Decimal(q):.12g}"


def periodic_json(series, valid=None) -> dict:
    """The JSON of a family of periodic orbits' series, the contract of ``series MODEL
    --json`` (a free oscillator's :class:`derive.lindstedt.SeriesSolution`, ``valid`` its
    :class:`derive.lindstedt.Validity`) and of ``nnm SYSTEM --json`` (a
    :class:`derive.nnm.NormalModeSeries`); keys are stable.  Both: ``kind``, ``order``,
    ``variable``, ω and T/2π per order (``omega``, ``period``), every coordinate's Fourier
    coefficients (``coordinates``, harmonic → coefficient per order), the ``amplitude``
    coordinate, ``omega0`` and the ``convention``, each exact, and beside each number its
    decimal (``*_decimal``, 12 significant digits) where the coefficients are numbers.  One
    coordinate adds ``model``, ``title``, ``q`` (its coefficients), ``radius`` (exact) or
    ``radius_estimate``, ``orbit_limit`` and, for a user's equation, ``equation`` and
    ``units`` (ω in units of ω₀); a system adds ``mode``, ``system``, ``lambda`` (ω₀²),
    every mode's ω₀², ω₀'s minimal polynomial, the ``parameters`` left symbols, the
    ``mass`` and ``radius_estimate`` (``valid``, the mode's :class:`derive.nnm.ModeRadius`:
    the ω series' radius in y estimated from its terms, its spread, the lower bound emitted
    modules stop at and that bound in A, ``reach``; ``None`` where not estimated)."""
    from ..derive.lindstedt import SeriesSolution

    if isinstance(series, SeriesSolution):
        m, g = series.model, series.ground
        names = [str(m.coordinate)]
        omega, period, orders = series.omega, series.period, [series.q]
        text = partial(_ground_text, g)
        decimal = _decimal if g.is_rational else None
        amplitude, aliases = names[0], {"q": names[0]}  # its coefficients, also as "q"
        leading = ("model", "order", "variable", "omega", "period", "q", "convention",
                   "radius", "orbit_limit", "radius_estimate", "equation", "omega0", "units")
        head = {"kind": "series", "model": m.name, "title": m.title, "order": series.order,
                "variable": m.variable, "omega0": str(m.frequency),
                "convention": series.convention}
        extra = {"radius": None if m.radius is None else str(m.radius),
                 "radius_value": valid.radius if valid.exact is not None else None,
                 "orbit_limit": valid.orbit.as_json()}
        if valid.exact is None and valid.radius is not None:
            extra["radius_estimate"] = {"value": valid.radius, "spread": valid.spread}
        if m.source:
            extra.update(equation=m.source,
                         units="omega in units of omega0, period in units of 2*pi/omega0")
    else:
        from ..lower.printers import decimal_text, minimal_polynomial

        system = series.system
        names = [str(x) for x in system.coordinates]
        omega, period = series.omega(), series.period()
        orders = [series.coordinate(i) for i in range(len(names))]
        text, decimal = str, decimal_text
        amplitude, aliases = names[series.amplitude], {}
        leading = ("kind", "mode", "omega0", "variable", "order", "omega", "period",
                   "coordinates", "system", "amplitude", "lambda",
                   "linear_frequencies_squared", "convention", "parameters", "period_units",
                   "omega0_decimal", "omega0_minimal_polynomial", "lambda_decimal",
                   "linear_frequencies_squared_decimal", "omega_decimal", "period_decimal",
                   "coordinates_decimal", "mass")
        root = minimal_polynomial(series.omega0, "x")
        head = {"kind": "nnm", "mode": series.mode, "order": series.order,
                "variable": series.variable, "omega0": str(series.omega0),
                "convention": CONVENTION.format(a=names[series.amplitude])}
        extra = {
            "system": system.text, "lambda": str(series.lam),
            "linear_frequencies_squared": [str(x) for x in system.modes()],
            "parameters": sorted({str(s) for f in system.force for s in f.free_symbols}
                                 - set(names) - {str(v) for v in system.velocities}),
            "period_units": "T/(2*pi): period[j] is the coefficient of y^j",
            "omega0_decimal": decimal_text(series.omega0),
            "omega0_minimal_polynomial": None if root is None else str(root),
            "lambda_decimal": decimal_text(series.lam),
            "linear_frequencies_squared_decimal": [decimal_text(x) for x in system.modes()],
            "mass": [[str(c) for c in system.mass.row(i)] for i in range(len(names))],
            "radius_estimate": None if valid is None else {
                "value": _finite(valid.estimate), "spread": _finite(valid.spread),
                "lower": valid.lower, "reach": valid.reach, "how": valid.how}}

    def per_order(form) -> dict:
        return {name: [{str(n): form(c) for n, c in sorted(o.items())} for o in coordinate]
                for name, coordinate in zip(names, orders, strict=True)}

    data = {**head, "omega": [text(c) for c in omega], "period": [text(c) for c in period],
            "coordinates": per_order(text), "amplitude": amplitude}
    if decimal is not None:
        data.update(omega_decimal=[decimal(c) for c in omega],
                    period_decimal=[decimal(c) for c in period],
                    coordinates_decimal=per_order(decimal))
    data.update({key: data["coordinates"][name] for key, name in aliases.items()}, **extra)
    # NOTE: each command's keys in the order it has always printed them, the shared ones after
    return {**{key: data[key] for key in leading if key in data}, **data}


TEXT_WIDTH = 200
# NOTE: no line of the table is longer; --exact prints a long exact number on lines of its
# own, broken at this width.
SHORT_EXACT = 24
# NOTE: as lower.printers.EXACT_WIDTH (not imported: the table must not load SymPy).
CELL = 28
ROW_CELL = 24
# NOTE: the width of the ω_j and (T/2π)_j columns, narrower where one coordinate's harmonics
# share the row; a longer cell lists the orders one block each.


def _powers(monomial: str) -> dict[str, int]:
    """``"A**2*alpha"`` → ``{"A": 2, "alpha": 1}`` (``"1"`` → ``{}``)."""
    return {name: int(e or 1) for name, e in
            re.findall(r"([A-Za-z_][A-Za-z0-9_]*)(?:\*\*(\d+))?", monomial)}


def _exact_text(value: str | dict) -> str:
    """An exact JSON value as a reader writes it: ``3/8``, an integer without ``/1``, a
    polynomial's ``{monomial: "p/q"}`` as SymPy writes it, ``-21*A**4/256 + A**3/12``
    (lex on the names, descending powers)."""
    if isinstance(value, str):
        return value.removesuffix("/1") if value.endswith("/1") else value
    names = sorted({name for monomial in value for name in _powers(monomial)})

    def order(item: tuple[str, str]) -> tuple[int, ...]:
        powers = _powers(item[0])
        return tuple(-powers.get(name, 0) for name in names)

    terms = []
    for monomial, c in sorted(value.items(), key=order):
        p, _, q = c.partition("/")
        sign, p = ("-", p[1:]) if p.startswith("-") else ("+", p)
        body = p if monomial == "1" else monomial if p == "1" else f"{p}*{monomial}"
        terms.append(f"{sign} {body}" + (f"/{q}" if q and q != "1" else ""))
    text = " ".join(terms) or "0"
    return text[2:] if text.startswith("+ ") else "-" + text[2:]


def _shown(exact: str | dict, decimal: str | None, full: bool) -> str:
    """The exact form when it is short, ``full`` (--exact) or has no decimal, else the
    decimal."""
    text = _exact_text(exact)
    return text if full or decimal is None or len(text) <= SHORT_EXACT else decimal


def _short(x: float) -> str:
    """A float as its shortest text, an integer without ``.0`` (``2``, ``1.5``)."""
    return str(int(x)) if float(x).is_integer() else repr(float(x))


def _radius_line(data: dict, y: str) -> str:
    """The table's line on the radius of convergence of a free oscillator's series in ``y``."""
    if data["radius"] is not None:
        value = data["radius_value"]
        shown = "" if value is None or data["radius"] == _short(value) else f" = {value:.12g}"
        return f"the series converges for |{y}| < {data['radius']}{shown} (the radius, exact)"
    if "radius_estimate" in data:
        r = data["radius_estimate"]
        return (f"the series converges for |{y}| < {r['value']:.6g} (the radius estimated "
                f"from tau_j to order {data['order']}, spread {r['spread']:.2g})")
    return ("radius of convergence not estimated (symbolic coefficients, or order < 2: "
            "raise --order, give the parameters values)")


def _coordinate_named(convention: str, name: str) -> str:
    """The convention in the user's coordinate: ``theta(0) = A, theta'(0) = 0, …``."""
    return convention if name == "q" else re.sub(r"\bq(_j)?(?=\(|'\()", name + r"\1",
                                                 convention)


def _header(data: dict, exact: bool) -> list[str]:
    """The table's first lines: what the series is, its convention and where it holds (one
    coordinate: its orbits and radius; a system: every mode's ω₀²)."""
    if data["kind"] == "series":
        y = data["variable"].partition("=")[0].strip() or data["variable"]
        domain = data["orbit_limit"]
        return [
            f"{data['model']}: {data['title']}, expansion variable {data['variable']}, order "
            f"{data['order']}",
            f"convention: {_coordinate_named(data['convention'], data['amplitude'])}",
            *([f"omega in units of omega0 = {data['omega0']}, T in units of 2*pi/omega0"]
              if data["omega0"] != "1" else []),
            f"periodic orbits for {domain['lower']} < {y} < {domain['upper']} "
            f"({domain['how']})" if domain["known"] else
            f"orbit domain not computed: {domain['how']}",
            _radius_line(data, y)]
    w0 = _shown(data["omega0"], data["omega0_decimal"], exact)
    if w0 != data["omega0"]:
        w0 += f" (a root of {data['omega0_minimal_polynomial']})"
    squares = ", ".join(_shown(e, d, exact) for e, d in zip(
        data["linear_frequencies_squared"], data["linear_frequencies_squared_decimal"],
        strict=True))
    return [f"mode {data['mode']} of {data['system']}",
            f"omega0 = {w0} (omega0^2 of every mode: {squares}), expansion variable "
            f"{data['variable']}, order {data['order']}",
            f"convention: {data['convention']}", _reach_line(data)]


def _reach_line(data: dict) -> str:
    """The table's line on where a mode's series holds: the radius of its ω series estimated
    from the terms and the lower bound (in y and in A) that emitted modules stop at."""
    r = data.get("radius_estimate")
    if r is None:
        return ("radius of convergence not estimated (symbolic coefficients, a series that "
                "ends, or too few terms): the series' reach is unknown")
    y = data["variable"].partition("=")[0].strip() or data["variable"]
    estimate = ("" if r["value"] is None else
                f"the omega series' radius in {y} is estimated at {r['value']:.6g} "
                f"(spread {r['spread']:.2g}) from its terms; ")
    return (f"{estimate}its lower bound {r['lower']:.6g} (A < {r['reach']:.6g}; "
            f"{r['how']}) is where emitted modules stop: NaN beyond, error_estimate inside")


def periodic_table(data: dict, exact: bool = False) -> str:
    """The readable table of :func:`periodic_json`'s ``data``, for one coordinate or a
    system: where the series holds, then ω_j and (T/2π)_j per order and each coordinate's
    harmonics per order — one coordinate's beside ω_j and (T/2π)_j on each order's row
    (narrower columns, :data:`ROW_CELL`), a system's in a block per coordinate.  A long
    exact number is shown as its decimal (12 significant digits) where the data holds one,
    unless ``exact`` (--exact); a cell still wider than its column lists the orders one
    block each instead of rows; no line over :data:`TEXT_WIDTH`."""
    lines = _header(data, exact)
    decimals = {key: data.get(f"{key}_decimal") for key in ("omega", "period", "coordinates")}
    beside = len(data["coordinates"]) == 1
    width = ROW_CELL if beside else CELL

    def decimal(key: str, j: int) -> str | None:
        return None if decimals[key] is None else decimals[key][j]

    def harmonics(name: str, j: int) -> list[tuple[str, str]]:
        shown = (decimals["coordinates"] or {}).get(name)
        return [(n, _shown(c, None if shown is None else shown[j].get(n), exact))
                for n, c in data["coordinates"][name][j].items()]

    cells = [(_shown(w, decimal("omega", j), exact), _shown(t, decimal("period", j), exact))
             for j, (w, t) in enumerate(zip(data["omega"], data["period"], strict=True))]
    rows = not any(len(w) > width or len(t) > width for w, t in cells)
    if rows:
        lines.append(f"{'j':>3}  {'omega_j':>{width}}  {'(T/2pi)_j':>{width}}" + "".join(
            f"  {name}_j: harmonic n -> coefficient" for name in data["coordinates"] if beside))
    for j, (w, t) in enumerate(cells):
        if rows:
            lines.append(f"{j:>3}  {w:>{width}}  {t:>{width}}" + "".join(
                "  " + ", ".join(f"{n}: {c}" for n, c in harmonics(name, j))
                for name in data["coordinates"] if beside))
            continue
        lines += [f"j = {j}: omega_j = {w}", f"       (T/2pi)_j = {t}"]
        lines += [f"       {name}_j[cos {n}s] = {c}" for name in data["coordinates"] if beside
                  for n, c in harmonics(name, j)]
    for name, orders in data["coordinates"].items():
        if beside:
            break
        lines.append(f"{name}: harmonic n -> coefficient, per order")
        lines += [f"{j:>3}  " + ", ".join(f"{n}: {c}" for n, c in harmonics(name, j))
                  for j in range(len(orders))]
    return "\n".join(piece for line in lines for piece in textwrap.wrap(
        line, TEXT_WIDTH, subsequent_indent="     ", break_on_hyphens=False) or [""])


def backbone_csv(b, path: Path) -> Path:
    """``nnm --csv``: the mode's backbone (:class:`analysis.curves.Backbone`), from its series
    to --order, up to 95 % of its estimated reach."""
    columns = (("A", f"amplitude of {b.amplitude} at its turning point"),
               ("omega", "frequency"), ("period", "T"))
    return write_csv(path, columns, zip(b.A, b.omega, b.period, strict=True))


def run_nnm(args: argparse.Namespace) -> int:
    """Run ``lindstedt nnm``: parse the system, derive the mode, print JSON or the table."""
    from ..derive.nnm import normal_mode, radius
    from ..derive.system import parse_system

    plot, csv = check_outputs(args)
    system = parse_system(args.system, _params(args.param), symbolic=True)
    symbols = sorted({str(s) for f in system.force for s in f.free_symbols}
                     - {str(x) for x in (*system.coordinates, *system.velocities)})
    if symbols and (plot or csv):
        flags = " and ".join(f for f, given in (("--plot", plot), ("--csv", csv)) if given)
        raise InputError(f"{flags}: give {', '.join(symbols)} a value with --param (the chart "
                         "and the CSV evaluate the series; without a value it is kept as a "
                         "symbol)")
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
    data = periodic_json(mode, None if symbols else radius(mode))
    if plot is not None:
        from ..analysis.curves import FEP_ORDER, frequency_energy
        from ..charts_modes import nnm_figure

        nnm_figure(frequency_energy(system, max(args.order, FEP_ORDER)), plot)
    if csv is not None:
        from ..analysis.curves import backbone

        backbone_csv(backbone(mode), csv)
    print(json.dumps(data) if args.json else periodic_table(data, args.exact))
    return 0


def arguments_nnm(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """``lindstedt nnm``'s arguments."""
    p = sub.add_parser("nnm", help="a nonlinear normal mode of coupled oscillators as an exact "
                       "series: the backbone ω(A), T(A) and the mode's shape",
                       description="The Lindstedt–Poincaré series of one nonlinear normal mode "
                       "of a conservative system M x'' + Kx + f(x) = 0 (one equation per "
                       "coordinate, separated by ';'; M constant, diagonal or symmetric "
                       "positive definite; one equation or a preset's name is a system of one "
                       "coordinate): ω and T against the amplitude A and "
                       "every coordinate's Fourier coefficients, exact (ω0 an algebraic "
                       "number, never rounded). An internal resonance with another mode is "
                       "refused, naming it.")
    p.add_argument("system", metavar="SYSTEM",
                   help="equations such as \"x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 "
                   "= 0\" (x'' the accelerations: each equation its own, or a full mass "
                   "matrix's row; every other name a parameter: a value with --param, or "
                   "left a symbol in the nonlinear terms)")
    p.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="an exact value for a parameter, e.g. beta=1/10 (repeatable; those in "
                   "the linear part need one, those in the nonlinear terms may stay symbols: "
                   "the coefficients are then polynomials in them)")
    p.add_argument("--mode", type=_positive, default=1, metavar="M",
                   help="the mode, numbered 1, 2, … by increasing linear frequency (default 1)")
    p.add_argument("--amplitude", metavar="NAME",
                   help="the coordinate at its turning point x = A at t = 0 (default: the "
                   "first)")
    _flag_order(p, "highest power K of the expansion variable")
    _flag_json(p)
    p.add_argument("--exact", action="store_true",
                   help="the table shows every number exactly (default: a long exact form, "
                   "such as an algebraic ω0 or a coefficient in Q(ω0²), as its decimal to 12 "
                   "significant digits; --json holds both)")
    p.add_argument("--plot", metavar="FILE",
                   help="also draw the frequency–energy plot of every mode (at most 4) into "
                   "FILE (.png, .svg or .pdf): each backbone from its series (to order 24, or "
                   "--order if higher) beside orbits shot by DOP853, the series' reach, the "
                   "internal-resonance lines (default: none)")
    _flag_csv(p, "the mode's backbone (A, omega, period) summed from its series to --order, "
              "up to 95 %% of the series' estimated reach (to A = 0.95 without an estimate)")
    _flag_allow_slow(p, deprecated_force=False)
    return p
