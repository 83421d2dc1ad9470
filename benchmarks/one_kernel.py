"""Timings of what moved onto the one float Fourier kernel and the one RK4 step (best of N).

    .venv/bin/python benchmarks/one_kernel.py
"""

from __future__ import annotations

import numpy as np
import timing
from lindstedt.analysis.driven import Drive, first_order_branches, harmonic_balance, mu_expansion
from lindstedt.numerics.floquet import hill_multipliers
from lindstedt.numerics.integrate import duffing_table, flow, steady_state_amplitudes, sweep


def best(f, n: int) -> float:
    """The compiled kernels warm up (compile) on a first call, then the timing rule."""
    f()
    return timing.best(f, n)


def main() -> None:
    d = Drive(0.1, 0.3, 1.2, 20.0)
    br = first_order_branches(d)[0]
    y0 = np.array([0.5, 0.0])
    rows = [
        ("flow: Duffing, one period, Richardson", lambda: flow(y0, 2 * np.pi / 1.2, 0.1, 0.3,
                                                               1.2, 0.05), 20),
        ("sweep 0.5 -> 2, 10 000 periods", lambda: sweep(0.1, 0.3, 0.05, 0.5, 2.0), 3),
        ("hill_multipliers", lambda: hill_multipliers(1.05, 0.1, 1.0, 0.0, -0.03), 10),
        ("steady_state_amplitudes, 2 drives", lambda: steady_state_amplitudes(
            duffing_table(0.1, 1 / 15), [0.2, 0.1], [0.8, 1.9], [0.8, 1.9, 2.4]), 3),
        ("mu_expansion order 20", lambda: mu_expansion(d, br, 20), 5),
        ("harmonic_balance N = 40", lambda: harmonic_balance(d, br, 40), 5),
    ]
    for name, f, n in rows:
        print(f"{name:40s} {best(f, n) * 1e3:9.3f} ms")


if __name__ == "__main__":
    main()
