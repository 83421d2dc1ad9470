"""The slow flow: derivation time by order, the emitted right side against lambdify, and the
second-order flow's error against simulation as a function of ε (van der Pol's growth).

    .venv/bin/python benchmarks/slow_flow.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import sympy as sp
from lindstedt.charts import SLOW_FLOW_EPS, slow_flow_errors
from lindstedt.compiler import generate_slow_flow
from lindstedt.derive.averaging import PHI, R, slow_flow
from lindstedt.derive.models import oscillator
from lindstedt.emit.render import load_generated
from numba import njit
from timing import best

VDP = "q'' + q = eps*(1 - q**2)*q'"
DRIVEN = "q'' + q = eps*(-k*q' - q**3 + F*cos(w*t))"
CALLS = 20_000
POINTS = 100_000


def compiled_loop(kernel):
    """A numba loop calling ``kernel`` on each row of ``xs``: the cost inside compiled code
    (an integrator's), without Python's call overhead."""
    @njit
    def loop(xs, eps, F, sigma):
        acc = 0.0
        for i in range(xs.shape[0]):
            out = kernel(xs[i], eps, F, sigma)
            acc += out[0] + out[1]
        return acc
    return loop


def per_call(fn, *args) -> float:
    """Nanoseconds per call from Python, best of 3 loops of CALLS calls."""
    def loop():
        for _ in range(CALLS):
            fn(*args)
    return best(loop) / CALLS * 1e9


def main() -> None:
    print(f"{'derivation (best of 3)':<34} " + " ".join(f"{'order ' + str(k):>9}"
                                                       for k in range(1, 5)))
    for label, text in (("van der Pol", VDP), ("driven damped Duffing", DRIVEN)):
        osc = oscillator(text)
        row = [best(lambda osc=osc, k=k: slow_flow(osc, k)) for k in range(1, 5)]
        print(f"{label:<34} " + " ".join(f"{s:>8.3f}s" for s in row))

    osc = oscillator(DRIVEN, {"k": "1/2"}, name="forced")
    tmp = Path(tempfile.mkdtemp(prefix="lindstedt-slow-flow-"))
    generate_slow_flow(osc, 2, "benchmark", tmp)
    t0 = time.perf_counter()
    m = load_generated(tmp / "forced_slow_flow.py")
    x = np.array([1.2, 0.4])
    m.slow_flow(x, 0.1, 0.5, 0.3)
    m.slow_flow_jacobian(x, 0.1, 0.5, 0.3)
    compile_s = time.perf_counter() - t0
    flow = slow_flow(osc, 2)
    F, sigma, eps = sp.symbols("F sigma eps")
    lam = sp.lambdify((R, PHI, eps, F, sigma), flow.rates, "math")
    lam_np = sp.lambdify((R, PHI, eps, F, sigma), flow.rates, "numpy")
    assert np.allclose(m.slow_flow(x, 0.1, 0.5, 0.3), lam(1.2, 0.4, 0.1, 0.5, 0.3), rtol=1e-14)
    print(f"\nright side of the driven Duffing's order-2 flow, one (r, phi) per call "
          f"(compiling the module: {compile_s:.1f} s):")
    print(f"  emitted slow_flow (numba)        {per_call(m.slow_flow, x, 0.1, 0.5, 0.3):8.0f} ns")
    print(f"  emitted slow_flow_jacobian       "
          f"{per_call(m.slow_flow_jacobian, x, 0.1, 0.5, 0.3):8.0f} ns")
    print(f"  lambdify, math                   {per_call(lam, 1.2, 0.4, 0.1, 0.5, 0.3):8.0f} ns")
    rng = np.random.default_rng(1)
    xs = np.column_stack([rng.uniform(0.2, 3, POINTS), rng.uniform(-3, 3, POINTS)])
    loop = compiled_loop(m.slow_flow)
    loop(xs[:2], 0.1, 0.5, 0.3)
    inside = best(lambda: loop(xs, 0.1, 0.5, 0.3)) / POINTS * 1e9
    r, phi = xs[:, 0].copy(), xs[:, 1].copy()
    vectorised = best(lambda: lam_np(r, phi, 0.1, 0.5, 0.3)) / POINTS * 1e9
    print(f"  emitted slow_flow in a numba loop {inside:7.1f} ns per point ({POINTS} points)")
    print(f"  lambdify, numpy on arrays        {vectorised:8.1f} ns per point ({POINTS} points)")
    print(f"  lambdify, numpy                  "
          f"{per_call(lam_np, 1.2, 0.4, 0.1, 0.5, 0.3):8.0f} ns")

    eps_values = np.array(SLOW_FLOW_EPS)
    print("\nvan der Pol from r = 0.1, max |r_slow - r_sim| over eps*t <= 8 (DOP853 1e-12):")
    print(f"{'eps':>8} " + " ".join(f"{'order ' + str(k):>11}" for k in (1, 2, 3)))
    errors = [slow_flow_errors(k) for k in (1, 2, 3)]
    for i, e in enumerate(eps_values):
        print(f"{e:>8g} " + " ".join(f"{err[i]:>11.3e}" for err in errors))
    slopes = [np.polyfit(np.log(eps_values[1:]), np.log(err[1:]), 1)[0] for err in errors]
    print(f"{'slope':>8} " + " ".join(f"{s:>11.2f}" for s in slopes))


if __name__ == "__main__":
    main()
