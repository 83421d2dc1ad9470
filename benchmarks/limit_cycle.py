"""Van der Pol's limit cycle, exact to order K: the relaxed ε-products against term-by-term ones.

    .venv/bin/python benchmarks/limit_cycle.py [--orders 60 100 164 300] [--baseline-to 100]
                                               [--repeat 3]

``derive_limit_cycle`` multiplies its ε-series online in squares of orders packed into one
integer polynomial (``lazy.RelaxedProduct``); the baseline below is the algorithm it replaced:
every ``[ε^i]`` of ``q^n`` and ``(ω q')^n`` summed term by term (i Trig products at order i),
the order whose amplitude arrives late made again.  Both give the same ω, amplitude and q_j
(checked before any time is printed, at every order both run).  Medians of ``--repeat`` runs,
wall and process (CPU) time: on a shared machine the CPU time is the steadier one.

The floor: the exact q_j grow by about 0.7 j² bits (their denominators are products of the
primes ≤ j + 1 to powers that grow with j), so q to order K holds ~K⁴ bits; column "one q²"
is one FLINT square of that whole q, packed (``square_floor``), which any exact method that
forms q² must at least pay; "cpu / q²" is the derivation's cost in such squares.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from fractions import Fraction

from lindstedt.algebra.series import Ground, Trig, solve_trig
from lindstedt.derive.cycles import (
    _linearisation,
    _secular_parts,
    derive_limit_cycle,
    limit_cycle_amplitudes,
)
from lindstedt.derive.models import oscillator, self_excited_model

VDP = "q'' + q = eps*(1 - q**2)*q'"


def term_by_term(model, order: int) -> tuple[list, list]:
    """ω and the amplitude q(0) by the previous algorithm (the baseline)."""
    top = order + 1
    a0, _ = limit_cycle_amplitudes(model)[0]
    g = Ground.for_coefficients([])
    zero = g.scalar(0)
    cos_s = Trig.from_fourier({1: g.scalar(1)}, {}, g)
    one = Trig(g.poly([g.scalar(1)]), g.poly([]), g)
    qs = [cos_s * g.scalar(a0)]
    W, omega = [g.scalar(1)], [g.scalar(1)]
    powers: dict[tuple[str, int], list] = {}
    slopes: dict[int, Trig] = {}
    curvatures: dict[int, Trig] = {}

    def slope_of(i):
        if i not in slopes:
            slopes[i] = qs[i].derivative()
        return slopes[i]

    def curvature_of(i):
        if i not in curvatures:
            curvatures[i] = slope_of(i).derivative()
        return curvatures[i]

    def velocity(i):
        acc = slope_of(i)
        for k in range(1, i + 1):
            acc = acc + slope_of(i - k) * omega[k]
        return acc

    def series(kind, n, i):
        if n == 0:
            return one if i == 0 else None
        table = powers.setdefault((kind, n), [])
        while len(table) <= i:
            m = len(table)
            if n == 1:
                table.append(qs[m] if kind == "q" else velocity(m))
                continue
            base = [series(kind, 1, k) for k in range(m + 1)]
            acc = series(kind, n - 1, 0) * base[m]
            for k in range(1, m + 1):
                acc = acc + series(kind, n - 1, k) * base[m - k]
            table.append(acc)
        return table[i]

    def force(i):
        total = Trig(g.poly([]), g.poly([]), g)
        for a, b, c in model.terms:
            for k in range(i + 1):
                left, right = series("q", a, k), series("v", b, i - k)
                if left is not None and right is not None:
                    total = total + left * right * g.scalar(c)
        return total

    lin = None
    for j in range(1, top + 1):
        known = force(j - 1)
        for i in range(1, j):
            known = known - curvature_of(j - i) * W[i]
        if j >= 2:
            if lin is None:
                lin = _linearisation(model, qs[0], g) + cos_s * W[1]
            _, ks = _secular_parts(known, g)
            _, ls = _secular_parts(lin, g)
            a_prev = -ks / ls if ls else zero
            qs[j - 1] = qs[j - 1] + cos_s * a_prev
            for key in powers:
                del powers[key][j - 1:]
            slopes.pop(j - 1, None)
            curvatures.pop(j - 1, None)
            known = known + lin * a_prev
        kc, _ = _secular_parts(known, g)
        Wj = -kc / g.scalar(a0)
        W.append(Wj)
        S = sum((omega[a] * omega[j - a] for a in range(1, j)), zero)
        omega.append((Wj - S) * g.scalar(Fraction(1, 2)))
        p = solve_trig(known + cos_s * (Wj * g.scalar(a0))).particular
        r_at_one = sum(p.sin_part.coeffs(), zero)
        qs.append(Trig(p.cos_part, p.sin_part - g.poly([r_at_one]), g))
    amplitude = [sum(qj.to_fourier()[0].values(), zero) for qj in qs[: order + 1]]
    return ([g.to_fraction(w) for w in omega[: order + 1]],
            [g.to_fraction(a) if a else Fraction(0) for a in amplitude])


def square_floor(lc) -> tuple[float, float]:
    """CPU seconds of one square of the whole exact q and its size in megabytes: every q_j's
    nonzero Fourier coefficients as integers over q_j's common denominator, packed in ε (a
    stride of twice the longest q_j, room for a product) into one FLINT polynomial.  A lower
    bound for the derivation, which forms q², (q²)(ωq'), ωq' and Wq'' online."""
    from flint import fmpz_poly

    rows, bits = [], 0
    for cos, sin in lc.q:
        values = [v for _, v in sorted(cos.items())] + [v for _, v in sorted(sin.items())]
        den = 1
        for v in values:
            den = den * v.denominator // math.gcd(den, v.denominator)
        row = [v.numerator * (den // v.denominator) for v in values]
        bits += sum(abs(x).bit_length() for x in row) + den.bit_length()
        rows.append(row)
    stride = 2 * max(len(r) for r in rows)
    packed = fmpz_poly([x for r in rows for x in r + [0] * (stride - len(r))])
    start = time.process_time()
    packed * packed
    return time.process_time() - start, bits / 8e6


def timed(fn, repeat: int) -> tuple[float, float, object]:
    """Medians of wall and CPU seconds over ``repeat`` calls, and the last result."""
    walls, cpus = [], []
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return statistics.median(walls), statistics.median(cpus), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--orders", type=int, nargs="*", default=[60, 100, 164, 300])
    ap.add_argument("--baseline-to", type=int, default=100,
                    help="run the term-by-term baseline up to this order (it grows like K^5)")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    model = self_excited_model(oscillator(VDP, name="van_der_pol"))
    print(f"load average at start: {os.getloadavg()[0]:.2f} (2 cores)")
    print(f"{'order':>5} {'relaxed wall':>13} {'cpu':>8} {'q (MB)':>7} {'one q² cpu':>11}"
          f" {'cpu / q²':>9} {'term-by-term wall':>18} {'cpu':>8} {'ratio (cpu)':>12}")
    for order in args.orders:
        repeat = args.repeat if order <= 164 else 1
        wall, cpu, lc = timed(lambda k=order: derive_limit_cycle(model, k), repeat)
        floor, size = square_floor(lc)
        row = (f"{order:>5} {wall:>12.2f}s {cpu:>7.2f}s {size:>7.1f} {floor:>10.2f}s"
               f" {cpu / floor:>8.1f}x")
        if order <= args.baseline_to:
            b_wall, b_cpu, (omega, amplitude) = timed(lambda k=order: term_by_term(model, k),
                                                      repeat)
            assert list(lc.omega) == omega and list(lc.amplitude) == amplitude
            row += f" {b_wall:>17.2f}s {b_cpu:>7.2f}s {b_cpu / cpu:>11.2f}x"
        print(row, flush=True)
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
