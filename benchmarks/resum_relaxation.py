"""Van der Pol's ω(ε) to ε = 10: Padé in Andersen & Geer's w against the relaxation form.

    .venv/bin/python benchmarks/resum_relaxation.py [--order 164] [--partial 58] [--emitted-only]

1. From the exact series to each order in ORDERS (one derivation, truncated): the relative
   error against DOP853 shooting (numerics.cycle_reference, rtol 1e-13, its own accuracy
   ≤ 4e-12) at ε = 1, 3, 5, 7, 10 and the largest on EPS, of resum.resum_frequency
   (√((1 − w)·Padé of ω²/(1 − w))) and of resum.resum_relaxation (two-point Padé in
   v = 1 − (1 − w)^(1/3) with Dorodnitsyn's large-ε terms), with the neighbour spread at 10.
2. The module `lindstedt generate van_der_pol --order P --resum-order K` writes (P =
   --partial, K = --order: partial sums to P, ω resummed from the series to K): its verified
   |ε|, the largest error at its shooting checks, its error against shooting on EPS, and ns
   per point (median of 5 over 10⁶ points of ε ∈ [0.1, 10]) of omega_resummed and
   period_resummed, ufunc and `_into`.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
from lindstedt.algebra.resum import resum_frequency, resum_relaxation, van_der_pol_relaxation
from lindstedt.compiler import generate_limit_cycle
from lindstedt.derive.cycles import derive_limit_cycle
from lindstedt.derive.lindstedt import nearest_singularity
from lindstedt.derive.models import series_model
from lindstedt.emit.render import load_generated
from lindstedt.numerics.references import cycle_reference
from timing import median

ORDERS = (60, 100, 130, 164)
EPS = (0.1, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5, 6.0, 6.5, 7.0,
       7.5, 8.0, 8.5, 9.0, 9.5, 10.0)
SHOWN = (1.0, 3.0, 5.0, 7.0, 10.0)


def forms(omega: list, eps: np.ndarray, truth: np.ndarray) -> None:
    print(f"\nrelative error against shooting at ε = {', '.join(f'{e:g}' for e in SHOWN)}; "
          "max on EPS; spread [L/M] − [L−1/M−1] at ε = 10:")
    print(f"{'order':<7}{'form':<12}{'[L/M]':>10}" + "".join(f"{e:>10g}" for e in SHOWN)
          + f"{'max':>10}{'spread':>10}{'s':>7}")
    cols = [list(eps).index(e) for e in SHOWN]
    relaxation = van_der_pol_relaxation()
    for K in ORDERS:
        if len(omega) <= K:
            continue
        est = nearest_singularity(omega[: K + 1])
        for name, build in (("Padé in w", lambda c, e=est: resum_frequency(c, e.radius, e.angle)),
                            ("relaxation", lambda c, e=est: resum_relaxation(
                                c, e.radius, e.angle, relaxation))):
            t0 = time.perf_counter()
            r = build(omega[: K + 1])
            took = time.perf_counter() - t0
            err = np.abs(r(eps) - truth) / truth
            print(f"{K:<7}{name:<12}{r.approximant.degrees!s:>10}"
                  + "".join(f"{err[i]:>10.1e}" for i in cols)
                  + f"{err.max():>10.1e}{float(r.spread(10.0)):>10.1e}{took:>7.1f}")


def emitted(order: int, partial: int, eps: np.ndarray | None, truth: np.ndarray | None
            ) -> None:
    x = np.random.default_rng(0).uniform(0.1, 10.0, 1_000_000)
    out = np.empty_like(x)
    partial = min(partial, order - 2)
    with tempfile.TemporaryDirectory() as folder:
        t0 = time.perf_counter()
        generate_limit_cycle(series_model("van_der_pol", partial + 2), partial, Path(folder),
                             resum_order=order)
        took = time.perf_counter() - t0
        mod = load_generated(Path(folder) / "van_der_pol.py")
        print(f"\n`lindstedt generate van_der_pol --order {partial} --resum-order {order}` "
              f"({took:.0f} s): verified to |ε| ≤ {mod.RESUMMED_LIMIT:g}, [L/M] = "
              f"{mod.RESUMMED_DEGREES}, largest error at its shooting checks "
              f"{mod.RESUMMED_ERROR:.1e} ({mod.RESUMMED_CHECKED})")
        if truth is not None:
            err = np.abs(mod.omega_resummed(eps) / truth - 1)
            inner = eps <= 1.0
            print(f"  omega_resummed against the shootings on EPS: max {err.max():.1e} "
                  f"(ε ≤ 1: {err[inner].max():.1e}; at ε = 10: {err[-1]:.1e})")
        x = np.minimum(x, mod.RESUMMED_LIMIT)
        for name in ("omega_resummed", "period_resummed"):
            f, into = getattr(mod, name), getattr(mod, name + "_into")
            f(x[:10]), into(out, x)
            ufunc = median(lambda f=f: f(x), 5) / x.size * 1e9
            loop = median(lambda i=into: i(out, x), 5) / x.size * 1e9
            print(f"  {name:<18} ufunc {ufunc:6.1f} ns   _into {loop:6.1f} ns per point")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--order", type=int, default=164)
    ap.add_argument("--partial", type=int, default=58, help="the module's partial-sum order")
    ap.add_argument("--emitted-only", action="store_true", help="part 2 alone")
    args = ap.parse_args()
    order = args.order
    if args.emitted_only:
        emitted(order, args.partial, None, None)
        return
    t0 = time.perf_counter()
    lc = derive_limit_cycle(series_model("van_der_pol", order), order)
    print(f"derivation to order {order}: {time.perf_counter() - t0:.0f} s")
    eps = np.array(EPS)
    t0 = time.perf_counter()
    truth = np.array([2 * np.pi / cycle_reference(lc.model, e).period for e in eps])
    print(f"{len(eps)} shootings: {time.perf_counter() - t0:.0f} s")
    forms(list(lc.omega), eps, truth)
    emitted(order, args.partial, eps, truth)


if __name__ == "__main__":
    main()
