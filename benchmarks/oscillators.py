"""Your own oscillator: parsing and derivation times against their targets, in one process.

    .venv/bin/python benchmarks/oscillators.py [--quick]

Each row is timed in this process (best of a few runs) beside a baseline measured in the same
run: parsing against SymPy's ``parse_expr`` of the same text (the unsafe route lindstedt does
not take), a user's equation against the built-in model of the same physics, and the
symbolic-parameter derivation against the same equation with the parameter given.  The
coefficients of each pair are checked to agree before anything is printed.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import sympy as sp
from lindstedt.derive.equation import parse_equation
from lindstedt.derive.lindstedt import derive
from lindstedt.derive.models import duffing, model_from_text, oscillator, pendulum
from sympy.core.cache import clear_cache
from sympy.parsing.sympy_parser import parse_expr
from timing import best

HELMHOLTZ = "q'' + q + eps*(alpha*q**2 + q**3) = 0"
DEGREE5 = "q'' + q + eps*(q**5 + 2*q**3*q'**2 + q*q'**4/3) = 0"
# NOTE: f(q, q'²) of degree 5 with rational coefficients: one power p = 4, exact in x = εA⁴


def _row(what: str, seconds: float, target: float | None, base: str, base_seconds: float) -> str:
    goal = f"{target:g}" if target is not None else "-"
    ok = "" if target is None else ("yes" if seconds <= target else "NO")
    return (f"{what:<44} {seconds:>9.4f} {goal:>7} {ok:>4}  {base:<34} {base_seconds:>9.4f} "
            f"{seconds / base_seconds:>7.2f}x")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller orders (a smoke run)")
    args = ap.parse_args()
    scale = 4 if args.quick else 1

    print(f"{'what':<44} {'seconds':>9} {'target':>7} {'met':>4}  {'baseline (same run)':<34} "
          f"{'seconds':>9} {'ratio':>8}")
    text = "x'' + w0**2*x + eps*x**3 + x'/Q = f*cos(w*t)"

    def cold(fn):  # SymPy caches expressions: clear it, or every run after the first is free
        return lambda: (clear_cache(), fn())

    t_parse = best(cold(lambda: oscillator(text)), 20)
    t_sympy = best(cold(lambda: parse_expr(
        "Derivative(x, t, 2) + w0**2*x + eps*x**3 - f*cos(w*t)")), 20)
    print(_row("parse + Oscillator record", t_parse, 0.020, "parse_expr (no record, unsafe)",
               t_sympy))
    t_walk = best(cold(lambda: parse_equation(text)), 20)
    print(_row("parse alone (whitelist walker)", t_walk, None, "parse_expr", t_sympy))

    k = 100 // scale
    ref = derive(duffing(), k)
    mine = derive(model_from_text("q'' + q + eps*q**3 = 0", k), k)
    assert mine.omega == ref.omega and mine.q == ref.q
    t_mine = best(lambda: derive(model_from_text("q'' + q + eps*q**3 = 0", k), k), 3)
    t_ref = best(lambda: derive(duffing(), k), 3)
    print(_row(f"Duffing as an equation, order {k}", t_mine, 0.25 if k == 100 else None,
               "built-in duffing()", t_ref))

    k = 100 // scale
    t_pend = best(lambda: derive(model_from_text("theta'' + sin(theta) = 0", k), k), 1)
    t_builtin = best(lambda: derive(pendulum(k), k), 1)
    assert derive(model_from_text("theta'' + sin(theta) = 0", 8), 8).omega == \
        derive(pendulum(8), 8).omega
    print(_row(f"pendulum as an equation, order {k}", t_pend, 3.0 if k == 100 else None,
               "built-in pendulum(K)", t_builtin))

    k = 30 // (2 if args.quick else 1)
    t_sym = best(lambda: derive(model_from_text(HELMHOLTZ, k), k), 2)
    t_num = best(lambda: derive(model_from_text(HELMHOLTZ, k, {"alpha": "1/3"}), k), 2)
    sym = derive(model_from_text(HELMHOLTZ, 6), 6)
    num = derive(model_from_text(HELMHOLTZ, 6, {"alpha": "1/3"}), 6)
    alpha = sp.Symbol("alpha")
    assert all(sp.expand(sym.ground.to_sympy(a).subs(alpha, sp.Rational(1, 3))
                         - num.ground.to_sympy(b)) == 0 for a, b in zip(sym.omega, num.omega,
                                                                        strict=True))
    print(_row(f"Helmholtz-Duffing, alpha symbolic, order {k}", t_sym, 1.0 if k == 30 else None,
               "the same with alpha = 1/3", t_num))

    k = 100 // scale
    t_deg5 = best(lambda: derive(model_from_text(DEGREE5, k), k), 1)
    t_duf = best(lambda: derive(duffing(), k), 3)
    print(_row(f"f(q, q'^2) of degree 5, order {k}", t_deg5, 2.0 if k == 100 else None,
               "Duffing at the same order", t_duf))

    k = 300 // scale
    cli = Path(sys.executable).with_name("lindstedt")
    start = time.perf_counter()
    subprocess.run([str(cli), "series", "duffing", "--order", str(k), "--json", "--allow-slow"],
                   check=True, stdout=subprocess.DEVNULL)
    t_cli = time.perf_counter() - start
    t_in = best(lambda: derive(duffing(), k), 1)
    print(_row(f"series duffing --order {k} --json (CLI)", t_cli, 1.5 * t_in,
               "in-process derive (target 1.5x)", t_in))


if __name__ == "__main__":
    main()
