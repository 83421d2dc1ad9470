"""The damped μ-expansion exact at every order: derivation time per order (damped against
undamped), emitted A_n, B_n evaluators (ns per point) and their accuracy against shooting.

    .venv/bin/python benchmarks/driven_damped.py
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np
from lindstedt.analysis.driven import Drive, first_order_branches
from lindstedt.analysis.mu_exact import mu_expansion_damped, mu_expansion_exact
from lindstedt.compiler import generate_driven
from lindstedt.emit.render import load_generated
from lindstedt.numerics.shooting import shoot
from timing import median

DAMPED_ORDERS = range(1, 7)
UNDAMPED_ORDERS = range(1, 5)
EMITTED_ORDERS = (1, 2, 3, 4)
POINTS = 100_000
SCENES = (Drive(0.1, 0.3, 1.2, 20.0), Drive(0.1, 1.0, 1.0, 10.0))
# NOTE: a damped point with three branches, and the notes' drive (§10.4) with Q = 10.


def derivation_times() -> None:
    print(f"load {os.getloadavg()[0]:.1f}; derivation, median of 3 (s)")
    print("order | damped | undamped")
    for K in DAMPED_ORDERS:
        def damped(K: int = K) -> None:
            mu_expansion_damped.cache_clear()
            mu_expansion_damped(K)

        def undamped(K: int = K) -> None:
            mu_expansion_exact.cache_clear()
            mu_expansion_exact(K)

        u = f"{median(undamped, 3):.3g}" if K in UNDAMPED_ORDERS else "—"
        print(f"{K} | {median(damped, 3):.3g} | {u}")


def emitted() -> None:
    out = Path(tempfile.mkdtemp(prefix="lindstedt-damped-"))
    omega = np.linspace(0.8, 1.6, POINTS)
    buf = np.empty(POINTS)
    print(f"load {os.getloadavg()[0]:.1f}; emitted, median of 5, {POINTS} points")
    print("order | ns/point A_1 | ns/point all six | max error vs shooting per scene")
    for K in EMITTED_ORDERS:
        folder = out / str(K)
        generate_driven(K, folder, damped=True)
        mod = load_generated(folder / "driven_damped.py")
        names = [f"{c}_{n}" for n in (1, 3, 5) for c in "AB" if hasattr(mod, f"{c}_{n}_into")]
        fns = [getattr(mod, f"{name}_into") for name in names]
        for f in fns:  # compile (cached on disk afterwards)
            f(buf, omega, 0.1, 0.3, 20.0, 0.0)

        def run(fns: list = fns) -> None:
            for f in fns:
                f(buf, omega, 0.1, 0.3, 20.0, 0.0)

        one = median(lambda f=fns[0]: f(buf, omega, 0.1, 0.3, 20.0, 0.0)) / POINTS * 1e9
        six = median(run) / POINTS * 1e9
        errors = []
        for d in SCENES:
            worst = 0.0
            for k, _ in enumerate(first_order_branches(d)):
                args = (d.omega, d.eps, d.force, d.Q, k)
                A = {n: getattr(mod, f"A_{n}")(*args) for n in (1, 3, 5) if hasattr(mod, f"A_{n}")}
                B = {n: getattr(mod, f"B_{n}")(*args) for n in (1, 3, 5) if hasattr(mod, f"B_{n}")}
                if not all(np.isfinite([*A.values(), *B.values()])):
                    worst = np.nan  # outside the verified domain: the evaluators refuse
                    continue
                guess = np.array([sum(A.values()), d.omega * sum(n * b for n, b in B.items())])
                orbit = shoot(d.eps, d.force, d.omega, d.damping, guess)
                worst = max(worst, *(abs(A[n] - orbit.A[n]) for n in A),
                            *(abs(B[n] - orbit.B[n]) for n in B))
            errors.append(f"{worst:.1e}")
        print(f"{K} | {one:.0f} | {six:.0f} | {' / '.join(errors)}")


if __name__ == "__main__":
    derivation_times()
    emitted()
