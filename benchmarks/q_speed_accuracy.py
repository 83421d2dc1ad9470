"""Speed against accuracy for q(t): generated L–P evaluators at several orders, the exact
Fourier (nome) series at several truncations, the exact Jacobi-cn solution (SciPy's ellipj)
and numerical integration (DOP853) at several tolerances.

    .venv/bin/python benchmarks/q_speed_accuracy.py

Error: max |q − A cn(√(1+x) t | m)| / A over t ∈ [0, 20], at x = εA² = 0.1 and 0.5.
Cost: ns per point of q(t) on 10⁶ points (integration: per time point of a dense solution).
Writes docs/figures/q_speed_accuracy.png and prints the table.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from lindstedt.compiler import generate
from lindstedt.emit.render import load_generated
from lindstedt.methods.kernels import cn_fourier
from scipy.integrate import solve_ivp
from scipy.special import ellipj
from timing import best

X = (0.1, 0.5)
ORDERS = (1, 2, 4, 8, 12, 16)
RTOLS = (1e-4, 1e-7, 1e-10, 1e-13)
HARMONICS = (2, 4, 8, 12)


def exact(t: np.ndarray, x: float) -> np.ndarray:
    m = x / (2 * (1 + x))
    return ellipj(np.sqrt(1 + x) * t, m)[1]


def main() -> None:
    t_err = np.linspace(0, 20, 4001)
    t_cost = np.random.default_rng(0).uniform(0, 20, 1_000_000)
    rows = []  # (method, parameter, x, error, ns)
    tmp = Path(tempfile.mkdtemp(prefix="lindstedt-q-"))
    for k in ORDERS:
        out = tmp / f"order{k}"
        generate("duffing", k, out)
        mod = load_generated(out / "duffing.py")
        for x in X:
            err = np.max(np.abs(mod.q(t_err, 1.0, x) - exact(t_err, x)))
            buf = np.empty_like(t_cost)
            mod.q_into(buf[:10], t_cost[:10], 1.0, x)
            ns = best(lambda mod=mod, x=x, buf=buf: mod.q_into(buf, t_cost, 1.0, x)) / t_cost.size
            rows.append(("L–P", k, x, err, ns * 1e9))
        del sys.modules["duffing"]
    for x in X:
        ns = best(lambda x=x: exact(t_cost, x)) / t_cost.size * 1e9
        rows.append(("Jacobi cn (SciPy)", 0, x, 0.0, ns))
        xs, buf = np.full_like(t_cost, x), np.empty_like(t_cost)
        for n in HARMONICS:
            err = np.max(np.abs(cn_fourier(t_err, np.full_like(t_err, x), n,
                                           np.empty_like(t_err)) - exact(t_err, x)))
            cn_fourier(t_cost[:10], xs[:10], n, buf[:10])
            ns = best(lambda n=n, xs=xs, buf=buf: cn_fourier(t_cost, xs, n, buf)) / t_cost.size
            rows.append(("exact Fourier", n, x, err, ns * 1e9))
        for rtol in RTOLS:
            def run(rtol=rtol, x=x):
                return solve_ivp(lambda _t, y: [y[1], -y[0] - x * y[0] ** 3], (0, 20), [1.0, 0.0],
                                 method="DOP853", rtol=rtol, atol=rtol * 1e-3, dense_output=True)
            t0 = time.perf_counter()
            sol = run()
            q = sol.sol(t_cost)[0]
            ns = (time.perf_counter() - t0) / t_cost.size * 1e9
            err = np.max(np.abs(sol.sol(t_err)[0] - exact(t_err, x)))
            rows.append(("DOP853", rtol, x, err, ns))
            assert q.shape == t_cost.shape
    print(f"{'method':<18} {'order/rtol':>10} {'x':>5} {'max error':>10} {'ns/point':>9}")
    for method, p, x, err, ns in rows:
        print(f"{method:<18} {p:>10g} {x:>5g} {err:>10.1e} {ns:>9.2f}")
    fig, axes = plt.subplots(1, len(X), figsize=(10, 4), sharey=True)
    for ax, x in zip(axes, X, strict=True):
        for method, style in (("L–P", "C0o-"), ("exact Fourier", "C2^-"), ("DOP853", "C4s-"),
                              ("Jacobi cn (SciPy)", "k*")):
            pts = [(ns, max(err, 1e-17)) for m, _, xx, err, ns in rows if m == method and xx == x]
            ax.plot(*zip(*pts, strict=True), style, label=method)
        ax.set(xscale="log", yscale="log", title=f"q(t), x = εA² = {x}", xlabel="ns / point")
    axes[0].set_ylabel("max |q − q_exact| / A, t ∈ [0, 20]")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig("docs/figures/q_speed_accuracy.png", dpi=110, metadata={"Software": None})
    print("wrote docs/figures/q_speed_accuracy.png")


if __name__ == "__main__":
    main()
