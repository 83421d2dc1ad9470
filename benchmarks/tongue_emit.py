"""``lindstedt tongues "cos(t) + 1/2*cos(2*t)" --n 1 --order 30 --out DIR``: generation time,
the verified ε of each curve against its estimated radius, and ns per point of the emitted
ufunc and ``_into`` loop against SymPy's lambdify of the truncated series (median of 5 over
10⁶ points of ε in (0, verified], the same points for each); then the verification itself:
``methods.resum_tongue`` (240 points, the sign of |tr M| − 2 at δ ∓ 1e-10, four vectorised
monodromy calls) against the former rule (brentq on 24 points at both step counts), each a
whole derivation + resummation + verification, best of 3, alternating, on three tongues.

Run: ``cd benchmarks && ../.venv/bin/python tongue_emit.py``.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import sympy as sp
from lindstedt.algebra.resum import resum_series
from lindstedt.cli import main
from lindstedt.derive.hill import fourier_of_text, transition_curves
from lindstedt.derive.lindstedt import nearest_singularity
from lindstedt.emit.render import load_generated
from lindstedt.methods import verify as methods
from lindstedt.numerics.floquet import floquet_traces
from scipy.optimize import brentq
from timing import best, median

P, N, ORDER, POINTS = "cos(t) + 1/2*cos(2*t)", 1, 30, 10**6


VERIFIED = (("cos(t) + 1/2*cos(2*t)", 1, 30), ("cos(t)", 0, 30), ("cos(t) + sin(2*t)", 2, 20))
BASELINE_GRID = 24


def run() -> None:
    with tempfile.TemporaryDirectory() as folder:
        measure(Path(folder))
    verification()


def brentq_24(text: str, n: int, order: int) -> list[tuple[float, float]]:
    """The former rule, the baseline: per curve, brentq on |tr M| − 2 within ±1e-4 of the Padé
    value (and half the distance to the other curve) at 4096 and 8192 steps on 24 points of
    (0, ε_max]; ``(limit, largest error)`` with the limit the point before the first miss."""
    harmonics = fourier_of_text(text)
    p = {k: (float(a), float(b)) for k, (a, b) in harmonics.items()}
    forms, tops = [], []
    for curve in transition_curves(harmonics, n, order).curves:
        est = nearest_singularity(list(curve.delta), "eps", None)
        radius = (np.sqrt(est.radius) if est.variable == "eps**2" else est.radius
                  ) if est else methods.TONGUE_RANGE
        tops.append(min(methods.TONGUE_RADII * radius, methods.TONGUE_RANGE))
        forms.append(resum_series(list(curve.delta), tops[-1]))

    def root(eps: float, near: float, bracket: float, steps: int) -> float:
        def margin(d: float) -> float:
            return abs(float(floquet_traces(d, eps, p, steps=steps)[0])) - 2

        if not margin(near - bracket) * margin(near + bracket) < 0:
            return float("nan")
        return brentq(margin, near - bracket, near + bracket, xtol=1e-15)

    out = []
    for i, (top, form) in enumerate(zip(tops, forms, strict=True)):
        limit, worst = 0.0, 0.0
        for eps in np.linspace(0.0, top, BASELINE_GRID + 1)[1:]:
            value = float(form(eps))
            bracket = min([1e-4, *(abs(float(f(eps)) - value) / 2
                                   for j, f in enumerate(forms) if j != i)])
            ref, finer = (root(float(eps), value, bracket, s) for s in (4096, 8192))
            error = abs(value - finer)
            if not (abs(ref - finer) <= methods.TONGUE_TOLERANCE / 10
                    and error <= methods.TONGUE_TOLERANCE):
                break
            limit, worst = float(eps), max(worst, error)
        out.append((limit, worst))
    return out


def verification() -> None:
    methods.resum_tongue(*VERIFIED[1])  # compiles the monodromy kernel
    print(f"\n| tongue | order | 24 brentq points: s | limits (max error) | "
          f"{methods.TONGUE_GRID} bracketed points: s | limits (max error) | ratio |")
    print("| --- | ---: | ---: | --- | ---: | --- | ---: |")
    for case in VERIFIED:
        text, n, order = case
        times: dict[str, list[float]] = {"old": [], "new": []}
        for _ in range(3):  # alternating: the machine's load falls on both alike
            times["old"].append(best(lambda c=case: brentq_24(*c), 1))
            times["new"].append(best(lambda c=case: methods.resum_tongue(*c), 1))
        old = "; ".join(f"{lim:.4g} ({err:.2g})" for lim, err in brentq_24(text, n, order))
        new = "; ".join(f"{c.limit:.4g} ({c.checked:.2g})"
                        for c in methods.resum_tongue(text, n, order).curves)
        t_old, t_new = min(times["old"]), min(times["new"])
        print(f"| `{text}`, n = {n} | {order} | {t_old:.2f} | {old} | {t_new:.2f} | {new} | "
              f"{t_new / t_old:.2f} |")


def measure(out: Path) -> None:
    t0 = time.perf_counter()
    assert main(["tongues", P, "--n", str(N), "--order", str(ORDER), "--out", str(out)]) == 0
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
