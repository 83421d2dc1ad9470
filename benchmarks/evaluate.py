"""ns/point of the generated numba evaluators against lambdify, numpy.polyval and C loops.

"numba (generated)" is the ufunc (broadcasting, strided loop); "…_into" its contiguous twin.

    .venv/bin/python benchmarks/evaluate.py [--points 1000000 10000000] [--order 12]

The C loops are printed from the same IR as the numba module (SymPy's C99 printer), compiled
with ``gcc -O3 -march=native`` with and without ``-ffast-math``; the q(t) variants are the
Chebyshev recurrence (as emitted) and one ``cos`` call per harmonic.  Every variant is
checked against the numba result before its time is printed.  Last: the wall time of a fresh
process that imports the cached module and makes its first call.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import sympy as sp
from lindstedt.compiler import generate
from lindstedt.derive.lindstedt import derive, period_series, solution_expression
from lindstedt.derive.models import A, duffing, eps, t
from lindstedt.emit.render import load_generated
from lindstedt.lower.records import Evaluator
from lindstedt.lower.series import lower_periodic
from sympy.codegen.rewriting import create_expand_pow_optimization, optimize
from sympy.printing.c import C99CodePrinter
from timing import best


def c_function(ev: Evaluator, name: str, per_harmonic_cos: bool = False) -> str:
    """A C loop over arrays for one evaluator (benchmark baseline only)."""
    printer = C99CodePrinter()
    expand_pow = create_expand_pow_optimization(32)  # x*x*… not pow(): a fair C baseline
    ev = Evaluator(ev.name, ev.doc, ev.args, ev.prelude, ev.guard,
                   tuple((lhs, optimize(rhs, [expand_pow])) for lhs, rhs in ev.body),
                   optimize(ev.output, [expand_pow]))
    body = list(ev.body)
    output = ev.output
    if per_harmonic_cos:  # replace the recurrence by cos(n*s) for every harmonic
        s = sp.Symbol("s")
        body = [(lhs, rhs) for lhs, rhs in body if not str(lhs).startswith(("c_", "w_2"))]
        subs = {sym: sp.cos(int(str(sym)[2:]) * s) for sym in output.free_symbols
                if str(sym).startswith("c_")}
        output = output.xreplace(subs)
    args = [str(a) for a in ev.args]
    lines = [f"void {name}(long n, {', '.join(f'const double *{a}_' for a in args)}, double *out)",
             "{", "  for (long i = 0; i < n; ++i) {"]
    lines += [f"    const double {a} = {a}_[i];" for a in args]
    lines += [f"    const double {lhs} = {printer.doprint(rhs)};" for lhs, rhs in ev.prelude]
    lines += [f"    if (!({printer.doprint(ev.guard)})) {{ out[i] = NAN; continue; }}"]
    lines += [f"    const double {lhs} = {printer.doprint(rhs)};" for lhs, rhs in body]
    lines += [f"    out[i] = {printer.doprint(output)};", "  }", "}"]
    return "\n".join(lines)


def build_c(module_ir, flags: list[str], tmp: Path, tag: str) -> ctypes.CDLL:
    evs = {ev.name: ev for ev in module_ir.evaluators}
    src = "#include <math.h>\n\n" + "\n\n".join([
        c_function(evs["period"], "period_c"),
        c_function(evs["q"], "q_rec"),
        c_function(evs["q"], "q_cos", per_harmonic_cos=True),
    ])
    c_file, so = tmp / f"eval_{tag}.c", tmp / f"eval_{tag}.so"
    c_file.write_text(src)
    subprocess.run(["gcc", "-O3", "-march=native", *flags, "-shared", "-fPIC", str(c_file),
                    "-o", str(so), "-lm"], check=True)
    lib = ctypes.CDLL(str(so))
    ptr = ctypes.POINTER(ctypes.c_double)
    lib.period_c.argtypes = [ctypes.c_long, ptr, ptr, ptr]
    for f in (lib.q_rec, lib.q_cos):
        f.argtypes = [ctypes.c_long, ptr, ptr, ptr, ptr]
    return lib


LAMBDIFY_POINTS = 100_000


def p(a: np.ndarray):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


def measure(n, rng, mod, libs, f_period, f_q) -> None:
    """One table: ns/point of every variant at n points, checked against the numba result."""
    A_ = rng.uniform(0.2, 1.5, n)
    e_ = rng.uniform(-0.4, 0.4, n) / A_**2
    t_ = rng.uniform(0, 50, n)
    out = np.empty(n)
    ref_T, ref_q = mod.period(A_, e_), mod.q(t_, A_, e_)
    tau = np.array(mod.PERIOD)[::-1]
    rows = []

    def add(label, fn, check, ref, points=n):
        fn()
        assert np.allclose(check(), ref, rtol=1e-12, atol=1e-12), label
        rows.append((label, best(fn) / points * 1e9))

    # NOTE: lambdify of q costs ~50 µs/point; it runs on a slice so the script ends in minutes.
    k = min(n, LAMBDIFY_POINTS)
    As, es, ts = A_[:k], e_[:k], t_[:k]

    out2 = np.empty(n)  # every compiled variant writes into a preallocated array
    add("period: numba (generated)", lambda: mod.period(A_, e_, out=out2), lambda: out2, ref_T)
    add("period: numba period_into", lambda: mod.period_into(out2, A_, e_), lambda: out2, ref_T)
    polyval = lambda: 2 * np.pi * np.polyval(tau, e_ * A_**2)  # noqa: E731
    add("period: numpy.polyval", polyval, polyval, ref_T)
    add("period: sympy.lambdify", lambda: f_period(A_, e_), lambda: f_period(A_, e_), ref_T)
    for tag, lib in libs.items():
        add(f"period: {tag}", lambda lib=lib: lib.period_c(n, p(A_), p(e_), p(out)),
            lambda: out.copy(), ref_T)
    add("q: numba (generated)", lambda: mod.q(t_, A_, e_, out=out2), lambda: out2, ref_q)
    add("q: numba q_into", lambda: mod.q_into(out2, t_, A_, e_), lambda: out2, ref_q)
    add(f"q: sympy.lambdify ({k:,} pts)", lambda: f_q(ts, As, es), lambda: f_q(ts, As, es),
        ref_q[:k], k)
    for tag, lib in libs.items():
        for fn_name, kind in (("q_rec", "recurrence"), ("q_cos", "cos per harmonic")):
            f = getattr(lib, fn_name)
            add(f"q: {tag}, {kind}",
                lambda f=f: f(n, p(t_), p(A_), p(e_), p(out)), lambda: out.copy(), ref_q)
    print(f"\n{n:,} points")
    base = {"period": rows[0][1], "q": next(r[1] for r in rows if r[0].startswith("q: numba"))}
    print(f"{'variant':<38} {'ns/point':>9} {'this / numba':>13}")
    for label, ns in rows:
        print(f"{label:<38} {ns:>9.2f} {ns / base[label.split(':')[0]]:>13.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, nargs="*", default=[1_000_000, 10_000_000])
    ap.add_argument("--order", type=int, default=12)
    args = ap.parse_args()
    K = args.order
    tmp = Path(tempfile.mkdtemp(prefix="lindstedt-bench-"))
    generate("duffing", K, tmp)
    mod = load_generated(tmp / "duffing.py")
    sol = derive(duffing(), K + 2)
    ir = lower_periodic(sol, "bench")
    sol_k = derive(duffing(), K)
    f_period = sp.lambdify((A, eps), period_series(sol_k), "numpy")
    f_q = sp.lambdify((t, A, eps), solution_expression(sol_k), "numpy")
    libs = {"C -O3": build_c(ir, [], tmp, "o3"), "C -O3 fast-math": build_c(ir, ["-ffast-math"],
                                                                             tmp, "fm")}
    rng = np.random.default_rng(0)
    print(f"Duffing order {K}; machine: {os.cpu_count()} cores; times are best of 3")
    for n in args.points:
        measure(n, rng, mod, libs, f_period, f_q)
    code = (f"import sys; sys.path.insert(0, {str(tmp)!r}); import duffing; "
            "duffing.q(1.0, 1.0, 0.1); duffing.period(1.0, 0.1)")
    subprocess.run([sys.executable, "-c", code], check=True)  # make sure the cache is written
    walls = []
    for _ in range(3):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True)
        walls.append(time.perf_counter() - t0)
    print(f"\nfresh process: import cached module + first call: {min(walls):.2f} s wall "
          "(interpreter start included)")


if __name__ == "__main__":
    main()
