"""`lindstedt series … --json` and `lindstedt generate …` as a user meets them: each command's
wall time against the in-process derivation plus the start-up, measured in the same run.

    .venv/bin/python benchmarks/series_output.py [--order 30] [--repeat 3]

`generate` derives two orders more than it writes (the truncation bound needs τ_{K+1},
τ_{K+2}), so its baseline is the derivation to K + 2; it writes the numba module, the LaTeX
tables and the derivation.

The target: the command within 1.5× of derivation +
start-up, i.e. the output (exact coefficients formatted from FLINT's terms) costs at most half
as much again.  The baseline row is the output through SymPy (``to_sympy``, ``expand``,
``str``), the route the command took before, timed on the same solution.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time

import sympy as sp
from lindstedt.cli.system import periodic_json
from lindstedt.derive.lindstedt import derive, validity
from lindstedt.derive.models import series_model

EQUATIONS = ("q'' + q + eps*(alpha*q**2 + q**3) = 0", "q'' + q + eps*q**3 = 0",
             "q'' + q + eps*(q**2 + q**3) = 0")


def wall(args: list[str], repeat: int) -> float:
    """The median wall time of a command (output to a pipe, as a script reads it)."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run(args, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return sorted(times)[len(times) // 2]


def sympy_output(sol) -> dict:
    """The former route: every coefficient through SymPy's expand and str."""
    def coefficient(c):
        if sol.ground.is_rational:
            return f"{int(c.p)}/{int(c.q)}"
        expr = sp.expand(sol.ground.to_sympy(c))
        gens = sorted(expr.free_symbols, key=str)
        terms = sp.Poly(expr, *gens).terms() if gens else ([((), expr)] if expr != 0 else [])
        return {str(sp.Mul(*(g**e for g, e in zip(gens, p, strict=True)))):
                f"{int(v.p)}/{int(v.q)}" for p, v in terms}
    return {"omega": [coefficient(c) for c in sol.omega],
            "q": [{n: coefficient(c) for n, c in qj.items()} for qj in sol.q]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--order", type=int, default=30)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    lindstedt = [sys.executable, "-m", "lindstedt"]
    startup = wall([*lindstedt, "models"], args.repeat)
    print(f"start-up (`lindstedt models`): {startup:.2f} s; order {args.order}, median of "
          f"{args.repeat}")
    print(f"{'equation':42} {'derive':>7} {'output':>7} {'SymPy out':>9} {'command':>8} "
          f"{'ratio':>6} {'derive+2':>8} {'generate':>8} {'ratio':>6}")
    for text in EQUATIONS:
        model = series_model(text, args.order, {}, None)
        start = time.perf_counter()
        sol = derive(model, args.order)
        derived = time.perf_counter() - start
        start = time.perf_counter()
        json.dumps(periodic_json(sol, validity(sol)))
        output = time.perf_counter() - start
        start = time.perf_counter()
        sympy_output(sol)
        through_sympy = time.perf_counter() - start
        command = wall([*lindstedt, "series", text, "--order", str(args.order), "--json"],
                       args.repeat)
        start = time.perf_counter()
        derive(series_model(text, args.order + 2, {}, None), args.order + 2)
        derived2 = time.perf_counter() - start
        with tempfile.TemporaryDirectory() as out:
            generate = wall([*lindstedt, "generate", text, "--order", str(args.order),
                             "--out", out, "--force"], args.repeat)
        print(f"{text:42} {derived:>6.2f}s {output:>6.2f}s {through_sympy:>8.2f}s "
              f"{command:>7.2f}s {command / (derived + startup):>6.2f} {derived2:>7.2f}s "
              f"{generate:>7.2f}s {generate / (derived2 + startup):>6.2f}")
    print("ratio: the command's wall time over (derivation + start-up); target ≤ 1.5")


if __name__ == "__main__":
    main()
