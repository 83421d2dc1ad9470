"""Seconds per order: the exact engine against the textbook SymPy route, in one process.

    .venv/bin/python benchmarks/derive.py [--textbook-max 8] [--orders 20 100 300]

The textbook route is what a careful SymPy user writes (notes §10.3): substitute the series,
expand, take the ε^j coefficient, product-to-sum (``TR8``), set the cos s coefficient to zero
for ω_j, and ``dsolve`` q_j'' + q_j = F_j with q_j(0) = q_j'(0) = 0.  Both routes are checked
to agree before any time is printed.
"""

from __future__ import annotations

import argparse

import sympy as sp
from lindstedt.derive.lindstedt import derive
from lindstedt.derive.models import duffing, pendulum
from sympy.simplify.fu import TR8
from timing import best


def textbook(order: int) -> list[sp.Rational]:
    """ω_1..ω_K of ω² u'' + u + x u³ = 0 by expand / TR8 / dsolve at each order."""
    s, x = sp.symbols("s x")
    f = sp.Function("f")
    us = [sp.cos(s)]
    omegas = [sp.Integer(1)]
    for j in range(1, order + 1):
        wj = sp.Symbol("w_j")
        omega = sum(w * x**i for i, w in enumerate(omegas)) + wj * x**j
        u = sum(ui * x**i for i, ui in enumerate(us))
        expr = sp.expand(omega**2 * sp.diff(u, s, 2) + u + x * u**3)
        F = -TR8(sp.expand(expr.coeff(x, j)))
        F = sp.expand(F)
        secular = F.coeff(sp.cos(s))
        wval = sp.solve(secular, wj)[0]
        F = sp.expand(F.subs(wj, wval))
        sol = sp.dsolve(
            f(s).diff(s, 2) + f(s) - F, f(s), ics={f(0): 0, f(s).diff(s).subs(s, 0): 0}
        )
        us.append(sp.expand(sol.rhs))
        omegas.append(wval)
    return omegas


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--textbook-max", type=int, default=8)
    ap.add_argument("--orders", type=int, nargs="*", default=[20, 50, 100, 200, 300])
    args = ap.parse_args()

    print("Duffing L–P, all q_j exact: engine vs textbook SymPy (same process)")
    print(f"{'order':>5} {'engine [s]':>12} {'textbook [s]':>13} {'ratio':>9}")
    for k in range(2, args.textbook_max + 1, 2):
        t_text = best(lambda k=k: textbook(k), 1)
        t_eng = best(lambda k=k: derive(duffing(), k), 20)
        sol = derive(duffing(), k)
        assert [sp.Rational(int(w.p), int(w.q)) for w in sol.omega] == textbook(k)
        print(f"{k:>5} {t_eng:>12.2e} {t_text:>13.3f} {t_text / t_eng:>8.0f}x")
    print()
    print(f"{'order':>5} {'duffing [s]':>12} {'pendulum [s]':>13}")
    for k in args.orders:
        t_d = best(lambda k=k: derive(duffing(), k), 3 if k <= 100 else 1)
        t_p = best(lambda k=k: derive(pendulum(k), k), 1) if k <= 100 else float("nan")
        print(f"{k:>5} {t_d:>12.3f} {t_p:>13.3f}")


if __name__ == "__main__":
    main()
