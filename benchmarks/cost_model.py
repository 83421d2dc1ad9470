"""The cost model every `choose` decides by: ns/point ≈ c₀ + c₁·order + c₂·order² of each
method (period, q: the compiled evaluators; amplitudes and response: each driven method per ω,
interpreted and emitted), fitted here by least squares on this machine's timings and recorded
in lindstedt.choose.COST_MODEL; printed beside this run's measurements.

    .venv/bin/python benchmarks/cost_model.py [--fit] [--only "QUANTITY/METHOD"]

`--fit` prints the constants to paste into COST_MODEL; without it, the table compares the
recorded model with this run's timings (the model decides, the timings are reported).
`--only` measures one entry of COST_MODEL, e.g. `--only "driven/mu_expansion_damped, emitted"`.
"""

from __future__ import annotations

import sys
import time
from collections import defaultdict

import numpy as np
from lindstedt.analysis.driven import Drive
from lindstedt.choose import (
    COST_MODEL,
    _fourier_cost,
    _generated_q_cost,
    candidates,
    driven_tradeoffs,
    driven_truth,
    emitted_driven,
    modelled_ns,
    ns_per_point,
)
from lindstedt.methods.registry import methods_for
from scipy.optimize import nnls
from scipy.special import ellipj

Q_ORDERS = (1, 2, 4, 6, 8, 12, 16, 20)
FOURIER_HARMONICS = (1, 2, 4, 8, 12, 20, 30, 40)
# NOTE: enough orders for a straight line; each generated q(t) module compiles in seconds.
DRIVEN_CASES = ((0.1, 0.3, np.inf), (0.1, 0.3, 20.0))
DRIVEN_OMEGAS = np.linspace(1.2, 1.4, 5)
EMITTED_MU_ORDERS = (1, 2, 3, 4, 5)
EMITTED_DAMPED_ORDERS = (1, 2, 3, 4)
EMITTED_HARMONICS = (1, 2, 4, 6, 8)
# NOTE: the driven methods at the notes' ε and f, undamped and Q = 20, on the large branch;
# the emitted μ-expansion to order 5 (order 6 takes minutes to generate), the damped one (for
# Q = 20 only) to order 4 (its generation and compile grow to minutes past that).


def wanted(only: tuple[str, str] | None, quantity: str, method: str) -> bool:
    """Whether the entry ``COST_MODEL[quantity][method]`` is measured in this run."""
    return only is None or only == (quantity, method)


def driven_measurements(rows: dict[tuple[str, str], list[tuple[int, float]]],
                        only: tuple[str, str] | None = None) -> None:
    for eps, force, Q in DRIVEN_CASES:
        applies = {m.name for m in methods_for("driven", Drive(eps, force, 1.0, Q))}
        interpreted = only is None or (only[0] == "driven" and only[1] in applies)
        orders = [("harmonic_balance", n) for n in EMITTED_HARMONICS]
        if np.isinf(Q):  # each μ-expansion module where it applies
            orders += [("mu_expansion", k) for k in EMITTED_MU_ORDERS]
        else:
            orders += [("mu_expansion_damped", k) for k in EMITTED_DAMPED_ORDERS]
        orders = [(m, k) for m, k in orders if wanted(only, "driven", f"{m}, emitted")]
        if not (interpreted or orders):
            continue
        truth = driven_truth(eps, force, Q, DRIVEN_OMEGAS)
        if interpreted:
            for t in driven_tradeoffs(truth, eps, force, Q):
                if wanted(only, "driven", t.method):
                    rows["driven", t.method].append((t.order, t.ns_per_point))
        for method, order in orders:
            t = emitted_driven(method, order, truth, eps, force, Q)
            rows["driven", t.method].append((t.order, t.ns_per_point))


def measurements(only: tuple[str, str] | None = None
                 ) -> dict[tuple[str, str], list[tuple[int, float]]]:
    rows: dict[tuple[str, str], list[tuple[int, float]]] = defaultdict(list)
    for c in candidates():
        if not wanted(only, "period", str(c.method)):
            continue
        if c.method in ("agm", "exact") or c.order <= 16 or c.order % 4 == 0:
            rows["period", c.method].append((c.order, ns_per_point(c)))
    if wanted(only, "q", "lindstedt"):
        for k in Q_ORDERS:
            rows["q", "lindstedt"].append((k, _generated_q_cost(k, 0.0, 0.5)))
    if wanted(only, "q", "fourier"):
        for n in FOURIER_HARMONICS:
            rows["q", "fourier"].append((n, _fourier_cost(n, 0.0, 0.5)))
    if wanted(only, "q", "exact"):
        x = np.random.default_rng(0).uniform(0.0, 0.5, 200_000)
        t = np.random.default_rng(1).uniform(0, 20, x.size)
        best = np.inf
        for _ in range(3):
            t0 = time.perf_counter()
            ellipj(np.sqrt(1 + x) * t, x / (2 * (1 + x)))
            best = min(best, time.perf_counter() - t0)
        rows["q", "exact"].append((0, best / x.size * 1e9))
    driven_measurements(rows, only)
    return rows


def main(fit: bool, only: tuple[str, str] | None = None) -> None:
    if only is not None and only[1] not in COST_MODEL.get(only[0], {}):
        raise SystemExit(f"--only {'/'.join(only)}: no such entry of COST_MODEL")
    rows = measurements(only)
    if fit:
        for (quantity, method), data in rows.items():
            k, ns = np.array(data).T
            if np.ptp(k) == 0:
                coefficients = [ns.mean()]
            else:  # c₀ + c₁k + c₂k², every coefficient ≥ 0 (a cost never falls with order)
                coefficients, _ = nnls(np.column_stack([np.ones_like(k), k, k**2]), ns)
            print(f'{quantity:>6}  "{method}": '
                  f'({", ".join(f"{c:.3g}" for c in coefficients)},),  # measured '
                  + ", ".join(f"{int(o)}: {v:.3g}" for o, v in zip(k, ns, strict=True)))
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
    args = sys.argv[1:]
    entry = args[args.index("--only") + 1].partition("/") if "--only" in args else None
    main("--fit" in args, (entry[0], entry[2]) if entry else None)
