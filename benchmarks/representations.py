"""Which exact representation should the kernel use?  Same L–P recurrence, three of them.

    .venv/bin/python benchmarks/representations.py [--orders 20 50 100]
    SYMPY_GROUND_TYPES=flint .venv/bin/python benchmarks/representations.py

1. kernel: monomial basis of C = cos s (odd models: v = C²) on FLINT ``fmpq_poly`` (shipped);
2. laurent: Laurent polynomials in z = e^{is} on FLINT ``fmpq_poly``, cos ns = (z^n + z^-n)/2;
3. dense-QQ: the shipped recurrence on SymPy dense lists over ``QQ`` (gmpy2 ground types by
   default, python-flint ones with SYMPY_GROUND_TYPES=flint).
All three must give the same ω_j before a time is printed.
"""

from __future__ import annotations

import argparse
import time
from unittest import mock

from flint import fmpq, fmpq_poly
from lindstedt.algebra.series import Ground
from lindstedt.derive import lindstedt
from lindstedt.derive.models import duffing
from sympy.external.gmpy import GROUND_TYPES
from sympy.polys.domains import QQ


def laurent(order: int) -> list[fmpq]:
    """ω_j of Duffing with series stored as z^-N p(z) (offsets tracked per series)."""

    def add(a, b):
        (pa, na), (pb, nb) = a, b
        if na < nb:
            pa, na, pb, nb = pb, nb, pa, na
        return (pa + pb.left_shift(na - nb), na)

    half = fmpq(1, 2)
    u = [(fmpq_poly([half, 0, half]), 1)]
    upp = [(-u[0][0], 1)]
    u2 = [(u[0][0] * u[0][0], 2)]
    omega, W = [fmpq(1)], [fmpq(1)]
    for j in range(1, order + 1):
        m = j - 1
        if m >= 1:
            acc = (fmpq_poly([]), 0)
            for a in range(m + 1):
                acc = add(acc, (u[a][0] * u[m - a][0], u[a][1] + u[m - a][1]))
            u2.append(acc)
        acc = (fmpq_poly([]), 0)
        for a in range(j):
            acc = add(acc, (u[a][0] * u2[m - a][0], u[a][1] + u2[m - a][1]))
        F = (-acc[0], acc[1])
        for a in range(1, j):
            F = add(F, (-upp[j - a][0] * W[a], upp[j - a][1]))
        S = sum((omega[a] * omega[j - a] for a in range(1, j)), fmpq(0))
        p, N = F
        wj = -(S + 2 * p[N + 1]) / 2
        omega.append(wj)
        W.append(2 * wj + S)
        p, N = add(F, (fmpq_poly([W[j] / 2, 0, W[j] / 2]), 1))
        sol = [c / (1 - (i - N) ** 2) if abs(i - N) != 1 else fmpq(0)
               for i, c in enumerate(p.coeffs())]
        total = sum(sol, fmpq(0))
        sol[N + 1] -= total / 2
        sol[N - 1] -= total / 2
        s = fmpq_poly(sol)
        u.append((s, N))
        upp.append((p - s, N))
    return omega


class _DenseQQ(Ground):
    @property
    def is_rational(self) -> bool:  # route QQ through the dense SymPy backend
        return False


def dense_qq(order: int) -> list:
    with mock.patch.object(Ground, "for_coefficients", staticmethod(lambda _: _DenseQQ(QQ))):
        sol = lindstedt.derive(duffing(), order)
    return [QQ.to_sympy(w) for w in sol.omega]


def kernel(order: int) -> list:
    return list(lindstedt.derive(duffing(), order).omega)


def timed(fn, order: int) -> tuple[float, list]:
    t0 = time.perf_counter()
    out = fn(order)
    return time.perf_counter() - t0, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--orders", type=int, nargs="*", default=[20, 50, 100])
    args = ap.parse_args()
    kernel(4), laurent(4), dense_qq(4)  # warm-up: imports and first-call costs
    print(f"SymPy ground types: {GROUND_TYPES}")
    print(f"{'order':>5} {'kernel [s]':>11} {'laurent [s]':>12} {'dense-QQ [s]':>13}")
    for k in args.orders:
        t_k, ref = timed(kernel, k)
        t_l, lau = timed(laurent, k)
        t_d, den = timed(dense_qq, k) if k <= 60 else (float("nan"), None)
        assert [str(w) for w in lau] == [str(w) for w in ref]
        if den is not None:
            assert [str(w) for w in den] == [str(w) for w in ref]
        print(f"{k:>5} {t_k:>11.3f} {t_l:>12.3f} {t_d:>13.3f}")


if __name__ == "__main__":
    main()
