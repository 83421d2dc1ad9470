"""The cost model `choose period` and `choose q` decide by: ns/point ≈ fixed + per_order ·
order of each method's compiled evaluator, fitted here by least squares on this machine's
timings and recorded in lindstedt.choose.COST_MODEL; printed beside this run's measurements.

    .venv/bin/python benchmarks/cost_model.py [--fit]

`--fit` prints the constants to paste into COST_MODEL; without it, the table compares the
recorded model with this run's timings (the model decides, the timings are reported).
"""

from __future__ import annotations

import sys
import time
from collections import defaultdict

import numpy as np
from lindstedt.choose import (
    COST_MODEL,
    _fourier_cost,
    _generated_q_cost,
    candidates,
    modelled_ns,
    ns_per_point,
)
from scipy.special import ellipj

Q_ORDERS = (1, 2, 4, 6, 8, 12, 16, 20)
FOURIER_HARMONICS = (1, 2, 4, 8, 12, 20, 30, 40)
# NOTE: enough orders for a straight line; each generated q(t) module compiles in seconds.


def measurements() -> dict[tuple[str, str], list[tuple[int, float]]]:
    rows: dict[tuple[str, str], list[tuple[int, float]]] = defaultdict(list)
    for c in candidates():
        if c.method in ("agm", "exact") or c.order <= 16 or c.order % 4 == 0:
            rows["period", c.method].append((c.order, ns_per_point(c)))
    for k in Q_ORDERS:
        rows["q", "lindstedt"].append((k, _generated_q_cost(k, 0.0, 0.5)))
    for n in FOURIER_HARMONICS:
        rows["q", "fourier"].append((n, _fourier_cost(n, 0.0, 0.5)))
    x = np.random.default_rng(0).uniform(0.0, 0.5, 200_000)
    t = np.random.default_rng(1).uniform(0, 20, x.size)
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        ellipj(np.sqrt(1 + x) * t, x / (2 * (1 + x)))
        best = min(best, time.perf_counter() - t0)
    rows["q", "exact"].append((0, best / x.size * 1e9))
    return rows


def main(fit: bool) -> None:
    rows = measurements()
    if fit:
        for (quantity, method), data in rows.items():
            k, ns = np.array(data).T
            per_order, fixed = np.polyfit(k, ns, 1) if np.ptp(k) > 0 else (0.0, ns.mean())
            print(f'{quantity:>6}  "{method}": ({fixed:.3f}, {per_order:.4f}),')
        return
    print(f"{'quantity':>8} {'method':>10} {'order':>5} {'measured ns':>12} {'model ns':>9} "
          f"{'ratio':>6}")
    ratios = []
    for (quantity, method), data in rows.items():
        for order, ns in data:
            model = modelled_ns(quantity, method, order)
            ratios.append(ns / model)
            print(f"{quantity:>8} {method:>10} {order:>5} {ns:>12.3f} {model:>9.3f} "
                  f"{ns / model:>6.2f}")
    print(f"measured/model: median {np.median(ratios):.2f}, 5–95 % "
          f"{np.percentile(ratios, 5):.2f}–{np.percentile(ratios, 95):.2f} "
          f"(the model: lindstedt.choose.COST_MODEL = {COST_MODEL})")


if __name__ == "__main__":
    main("--fit" in sys.argv[1:])
