"""The parametric oscillator's response against shooting, and what each route costs.

    .venv/bin/python benchmarks/parametric.py

q'' + 2ζq' + (1 + ε cos 2ωt)q + γq³ = 0 with ζ = ε/20, γ = 1: at ω² = 1, 1 + ε/4, 1 + 3ε/4
every nontrivial branch by one harmonic and by the balance (8 odd harmonics), each against the
shot orbit's first harmonic; the verdicts (slow flow, full Hill, shooting's Floquet
multipliers); the tongue's one-harmonic edges against the damped Mathieu equation's (where
q = 0 loses stability); median wall times of five runs.
"""

from __future__ import annotations

import math
import statistics
import time

from lindstedt.analysis.parametric import (
    Pump,
    balance_point,
    one_harmonic,
    shoot_orbit,
    tongue_edges,
    trivial_orbit,
)
from scipy.optimize import brentq


def median_seconds(f, repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    print(f"{'eps':>5} {'1-harm. r err':>13} {'balance r err':>13} {'verdicts agree':>14} "
          f"{'edge err (lo, hi)':>20}")
    for eps in (0.05, 0.1, 0.2, 0.4):
        p = Pump(eps, eps / 20, 1.0)
        one_err = bal_err = 0.0
        agree = total = 0
        for w2 in (1.0, 1 + eps / 4, 1 + 3 * eps / 4):
            for pt in one_harmonic(p, math.sqrt(w2))[1:]:
                bal = balance_point(p, pt)
                orbit = shoot_orbit(p, pt.omega, bal.A, bal.B)
                r = math.hypot(orbit.A[1], orbit.B[1])
                one_err, bal_err = max(one_err, abs(pt.r / r - 1)), max(bal_err, abs(bal.r / r - 1))
                agree += pt.stable == bal.stable == orbit.stable
                total += 1
        lo, hi = tongue_edges(p)

        def loss(w: float, p: Pump = p) -> float:
            return max(abs(m) for m in trivial_orbit(p, w).multipliers) - 1

        true_lo = brentq(loss, lo - 0.3 * eps, lo + 0.3 * eps, xtol=1e-13)
        true_hi = brentq(loss, hi - 0.3 * eps, hi + 0.3 * eps, xtol=1e-13)
        print(f"{eps:>5} {one_err:>13.1e} {bal_err:>13.1e} {f'{agree}/{total}':>14} "
              f"{f'{lo - true_lo:.1e}, {hi - true_hi:.1e}':>20}")
    p = Pump(0.2, 0.01, 1.0)
    pt = one_harmonic(p, 1.05)[1]
    bal = balance_point(p, pt)
    balance_point(p, pt), shoot_orbit(p, 1.05, bal.A, bal.B)  # compile, warm the caches
    print("\nper point at eps = 0.2, zeta = 0.01, omega = 1.05 (median of 5):")
    one = median_seconds(lambda: one_harmonic(p, 1.05))
    print(f"  one harmonic, every branch: {one * 1e6:.0f} us")
    print(f"  balance (8 harmonics) + full Hill: "
          f"{median_seconds(lambda: balance_point(p, pt)) * 1e3:.1f} ms")
    print(f"  shooting + Floquet: "
          f"{median_seconds(lambda: shoot_orbit(p, 1.05, bal.A, bal.B)) * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
