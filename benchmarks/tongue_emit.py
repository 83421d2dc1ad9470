"""``lindstedt tongues "cos(t) + 1/2*cos(2*t)" --n 1 --order 30 --emit DIR``: generation time,
the verified ε of each curve against its estimated radius, and ns per point of the emitted
ufunc and ``_into`` loop against SymPy's lambdify of the truncated series (median of 5 over
10⁶ points of ε in (0, verified], the same points for each).

Run: ``cd benchmarks && ../.venv/bin/python tongue_emit.py``.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import sympy as sp
from lindstedt.cli import main
from lindstedt.emit import load_generated
from lindstedt.hill import transition_curves
from lindstedt.lindstedt import nearest_singularity
from timing import median

P, N, ORDER, POINTS = "cos(t) + 1/2*cos(2*t)", 1, 30, 10**6


def run() -> None:
    with tempfile.TemporaryDirectory() as folder:
        measure(Path(folder))


def measure(out: Path) -> None:
    t0 = time.perf_counter()
    assert main(["tongues", P, "--n", str(N), "--order", str(ORDER), "--emit", str(out)]) == 0
    generated = time.perf_counter() - t0
    mod = load_generated(out / f"tongue_{N}.py")
    eps_ = sp.Symbol("eps")
    print(f"generation {generated:.1f} s (derive, resum, verify, render, write)")
    for i, curve in enumerate(transition_curves(P, N, ORDER).curves):
        limit = getattr(mod, f"LIMIT_{i}")
        radius = nearest_singularity(list(curve.delta), "eps", None).radius
        eps = np.random.default_rng(0).uniform(0.0, limit, POINTS)
        ufunc, into = getattr(mod, f"delta_{i}"), getattr(mod, f"delta_{i}_into")
        target = np.empty_like(eps)
        ufunc(eps[:10])
        into(target[:10], eps[:10])
        series = sum(sp.Rational(c.numerator, c.denominator) * eps_**k
                     for k, c in enumerate(curve.delta))
        lam = sp.lambdify(eps_, sp.horner(series), "numpy")
        calls = ((ufunc, (eps,)), (into, (target, eps)), (lam, (eps,)))
        ns = [median(lambda f=f, a=a: f(*a)) / POINTS * 1e9 for f, a in calls]
        print(f"delta_{i} ({curve.label}): radius ~{radius:.3g}, verified 0 ≤ eps ≤ {limit:g} "
              f"(max error {getattr(mod, f'CHECKED_ERROR_{i}'):.2g}); ns/point ufunc {ns[0]:.1f}"
              f", _into {ns[1]:.1f}, lambdify of the order-{ORDER} sum {ns[2]:.1f}")


if __name__ == "__main__":
    run()
