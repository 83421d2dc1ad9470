"""Hill's equation: the Ince–Strutt grid, the transition-curve series and Mathieu's radii.

    .venv/bin/python benchmarks/ince_strutt.py [--radii]

1. Floquet multipliers of ẍ + 2ζẋ + (δ + cos t · ε)x = 0 on a 400 × 400 (δ, ε) grid
   (δ ∈ [−0.5, 2.5], ε ∈ [0, 1.5]; compiled RK4, 256 steps per period, parallel) against a
   baseline measured in the same run: SciPy's solve_ivp (DOP853, rtol 1e-9) per point on a
   20 × 20 sub-grid, extrapolated to the 160 000 points; the verdicts of both compared there.
2. The exact transition curves to order 100 and the damped tongue's tip to order 40.
3. Radii of convergence from order 100 (and 150) against DLMF Table 28.6.1, and whether the
   reported spread covers the error (``--radii``: this part only).
Wall times: median and best of 3 runs (the machine is shared: the load average is printed).
"""

from __future__ import annotations

import math
import os
import statistics
import sys
import time

import numpy as np
from lindstedt.derive.hill import mathieu_series, tongue_tip, transition_curves
from lindstedt.derive.lindstedt import nearest_singularity
from lindstedt.numerics.floquet import floquet_stable, floquet_traces
from scipy.integrate import solve_ivp

GRID = 400
SUB = 20
P = {1: (1.0, 0.0)}
TABLE_28_6_1 = {("a", 0): 1.4687686138, ("a", 2): 1.4687686138, ("b", 2): 6.9289547588,
                ("a", 1): 3.7699574940, ("b", 1): 3.7699574940, ("a", 3): 3.7699574940,
                ("a", 4): 7.2681468935, ("b", 6): 16.8030898254, ("a", 5): 11.2709852655}


def runs(fn, repeat: int = 3) -> tuple[float, float]:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), min(times)


def scipy_trace(delta: float, eps: float, zeta: float) -> float:
    def rhs(t, y):
        k = delta + eps * math.cos(t)
        return [y[1], -2 * zeta * y[1] - k * y[0], y[3], -2 * zeta * y[3] - k * y[2]]
    sol = solve_ivp(rhs, (0, 2 * math.pi), [1, 0, 0, 1], method="DOP853", rtol=1e-9,
                    atol=1e-12)
    return sol.y[0, -1] + sol.y[3, -1]


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    d, e = np.meshgrid(np.linspace(-0.5, 2.5, GRID), np.linspace(0.0, 1.5, GRID))
    floquet_traces(0.25, 0.1, P)  # compile (cached after the first run)
    for zeta in (0.0, 0.05):
        med, best = runs(lambda z=zeta: floquet_traces(d, e, P, z))
        sub = (slice(None, None, GRID // SUB), slice(None, None, GRID // SUB))
        t0 = time.perf_counter()
        ref = np.array([scipy_trace(a, b, zeta) for a, b in zip(d[sub].ravel(), e[sub].ravel(),
                                                               strict=True)])
        per_point = (time.perf_counter() - t0) / ref.size
        trace, _ = floquet_traces(d[sub], e[sub], P, zeta)
        agree = np.mean(floquet_stable(trace.ravel(), zeta) == floquet_stable(ref, zeta))
        print(f"zeta = {zeta}: {GRID}x{GRID} grid {med:.2f} s median ({best:.2f} s best; target "
              f"≤ 10 s); solve_ivp {per_point * 1e3:.1f} ms/point -> {per_point * GRID**2:.0f} s "
              f"extrapolated ({per_point * GRID**2 / med:.0f}x); |tr| max diff "
              f"{np.max(np.abs(trace.ravel() - ref)):.1e}, verdicts agree on {agree:.1%} of "
              f"{ref.size} points")
    for text, n, order in (("cos(t)", 1, 100), ("cos(t)", 2, 100),
                           ("cos(t) + 1/2*cos(2*t)", 1, 100), ("cos(t) + sin(2*t)", 2, 60)):
        med, best = runs(lambda t=text, m=n, k=order: transition_curves(t, m, k), repeat=1)
        print(f"transition curves p = {text}, n = {n}, order {order}: {med:.2f} s")
    med, _ = runs(lambda: tongue_tip("cos(t)", 1, 40), repeat=1)
    print(f"damped tongue tip p = cos(t), n = 1, order 40: {med:.2f} s")
    radii()


def radii() -> None:
    """Part 3 alone with ``--radii``: each estimate, its error against the table in its own
    variable (q or q²) and the spread it reports, which must cover the error."""
    print(f"{'series':<6} {'order':>5} {'variable':>8} {'radius |q|':>12} {'Table 28.6.1':>13} "
          f"{'rel. diff':>10} {'error':>9} {'spread':>9} {'covered':>8}  method")
    for (kind, m), rho in TABLE_28_6_1.items():
        for order in (100, 150):
            est = nearest_singularity(mathieu_series(kind, m, order), "q", None)
            squared = est.variable == "q**2"
            radius = math.sqrt(est.radius) if squared else est.radius
            error = abs(est.radius - (rho**2 if squared else rho))
            print(f"{kind}_{m:<4} {order:>5} {est.variable:>8} {radius:>12.8f} {rho:>13.10f} "
                  f"{radius / rho - 1:>10.2e} {error:>9.1e} {est.spread:>9.1e} "
                  f"{'yes' if error <= est.spread else 'NO':>8}  {est.method}")


if __name__ == "__main__":
    radii() if "--radii" in sys.argv else main()
