"""Driven Duffing timings: μ-expansion, harmonic balance, shooting + Floquet (after compiling).

    .venv/bin/python benchmarks/driven.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
from lindstedt.analysis.driven import (
    Drive,
    amplitudes,
    first_order_branches,
    harmonic_balance,
    mu_expansion,
)
from lindstedt.analysis.response import one_harmonic_curve
from lindstedt.analysis.systems import continue_balance
from lindstedt.compiler import generate_balance
from lindstedt.emit.render import load_generated
from lindstedt.numerics.integrate import sweep
from lindstedt.numerics.shooting import shoot
from timing import best


def main() -> None:
    d = Drive(0.1, 1.0, 1.0)
    (br,) = first_order_branches(d)
    shoot(0.1, 1.0, 1.0, 0.0, np.array([2.4, 0.0]))  # compile (cached on disk afterwards)
    sweep(0.1, 0.3, 0.05, 0.6, 1.9, periods=100)
    hb = harmonic_balance(d, br, 8)
    A, _ = amplitudes(hb.coefficients, 0.0, 15)
    tmp = Path(tempfile.mkdtemp(prefix="lindstedt-balance-"))
    generate_balance(8, tmp)
    t0 = time.perf_counter()
    bal = load_generated(tmp / "balance.py")
    x0 = np.zeros(16)
    x0[0] = br.A1
    bal.newton(x0, 1.0, 0.1, 1.0, 0.0)
    compile_s = time.perf_counter() - t0
    x, ok = bal.newton(x0, 1.0, 0.1, 1.0, 0.0)
    assert ok and abs(x[0] - A[1]) < 1e-12
    rows = [
        ("mu-expansion, order 6 (eps=0.1, f=1, w=1)", best(lambda: mu_expansion(d, br, 6)), 1.0),
        ("harmonic balance, N = 8, one frequency", best(lambda: harmonic_balance(d, br, 8)), 1e-3),
        ("emitted balance (N = 8) Newton, one frequency",
         best(lambda: bal.newton(x0, 1.0, 0.1, 1.0, 0.0)), 1e-3),
        ("one-harmonic curve, all branches + stability, 1e5 w",
         best(lambda: one_harmonic_curve(0.1, 0.3, 20.0, np.linspace(0.5, 2, 100_000))), 0.1),
        ("harmonic balance continuation N = 8, both folds",
         best(lambda: continue_balance(Drive(0.1, 0.3, 0.6, 20.0).equation, 8, 0.6, 1.9), 1), 1.0),
        ("sweep simulation, 1e4 periods (compiled)",
         best(lambda: sweep(0.1, 0.3, 0.05, 0.6, 1.9)), 2.0),
        ("shooting + Floquet, one orbit",
         best(lambda: shoot(0.1, 1.0, 1.0, 0.0, np.array([sum(A.values()), 0.0]))), 10e-3),
    ]
    print(f"{'task':<44} {'seconds':>10} {'target':>9}")
    for label, sec, target in rows:
        print(f"{label:<44} {sec:>10.2e} {target:>9.0e}  {'met' if sec <= target else 'MISSED'}")
    print(f"(first import of the emitted N = 8 module, compiling it: {compile_s:.1f} s)")


if __name__ == "__main__":
    main()
