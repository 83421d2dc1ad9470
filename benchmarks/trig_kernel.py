"""The sine-capable kernel: P(C) + S·R(C) against the Laurent form in z = e^{is}, exact over QQ.

    .venv/bin/python benchmarks/trig_kernel.py [--harmonics 10 40 160]

A Fourier sum with N harmonics, ``Σ a_n cos ns + b_n sin ns``, is in the kernel a pair of
polynomials of degree N in C (``Trig``); in the Laurent form it is ``Σ c_n z^n``, ``|n| ≤ N``,
with Gaussian-rational ``c_n = (a_n ∓ i b_n)/2``: a pair of ``fmpq_poly`` (real and imaginary
parts) of length 2N + 1, whose product takes three real products (Karatsuba's trick).  Both
products are checked to give the same Fourier coefficients before any time is printed.
"""

from __future__ import annotations

import argparse
import random
from fractions import Fraction

from flint import fmpq, fmpq_poly
from lindstedt.algebra.series import Ground, Trig
from timing import best

QQ = Ground.for_coefficients([])


def random_sum(n: int, rng: random.Random) -> tuple[dict, dict]:
    def r() -> Fraction:
        return Fraction(rng.randint(-999, 999), rng.randint(1, 99))

    return {k: r() for k in range(n + 1)}, {k: r() for k in range(1, n + 1)}


def laurent(cos: dict, sin: dict, n: int) -> tuple[fmpq_poly, fmpq_poly]:
    """(Re, Im) of Σ c_k z^(k+n): c_0 = a_0, c_{±k} = (a_k ∓ i b_k)/2."""
    re = [fmpq(0)] * (2 * n + 1)
    im = [fmpq(0)] * (2 * n + 1)
    re[n] = fmpq(cos.get(0, Fraction(0)).numerator, cos.get(0, Fraction(0)).denominator)
    for k in range(1, n + 1):
        a, b = cos.get(k, Fraction(0)) / 2, sin.get(k, Fraction(0)) / 2
        re[n + k] = re[n - k] = fmpq(a.numerator, a.denominator)
        im[n + k] = fmpq(-b.numerator, b.denominator)
        im[n - k] = fmpq(b.numerator, b.denominator)
    return fmpq_poly(re), fmpq_poly(im)


def laurent_product(x: tuple, y: tuple) -> tuple[fmpq_poly, fmpq_poly]:
    (a, b), (c, d) = x, y
    ac, bd = a * c, b * d
    return ac - bd, (a + b) * (c + d) - ac - bd


def laurent_fourier(z: tuple, n: int) -> tuple[dict, dict]:
    re, im = z[0].coeffs(), z[1].coeffs()
    re += [fmpq(0)] * (2 * n + 1 - len(re))
    im += [fmpq(0)] * (2 * n + 1 - len(im))
    cos = {0: Fraction(int(re[n].p), int(re[n].q))} if re[n] else {}
    sin = {}
    for k in range(1, n + 1):
        a = 2 * re[n + k]
        b = -2 * im[n + k]
        if a:
            cos[k] = Fraction(int(a.p), int(a.q))
        if b:
            sin[k] = Fraction(int(b.p), int(b.q))
    return cos, sin


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--harmonics", type=int, nargs="*", default=[10, 40, 160])
    args = ap.parse_args()
    rng = random.Random(1)
    print(f"{'N':>5} {'P(C)+S R(C) [µs]':>18} {'Laurent z [µs]':>15} {'ratio':>7}")
    for n in args.harmonics:
        (ac, as_), (bc, bs) = random_sum(n, rng), random_sum(n, rng)
        ta = Trig.from_fourier({k: QQ.scalar(v) for k, v in ac.items()},
                               {k: QQ.scalar(v) for k, v in as_.items()}, QQ)
        tb = Trig.from_fourier({k: QQ.scalar(v) for k, v in bc.items()},
                               {k: QQ.scalar(v) for k, v in bs.items()}, QQ)
        za, zb = laurent(ac, as_, n), laurent(bc, bs, n)
        cos, sin = (ta * tb).to_fourier()
        got = ({k: QQ.to_fraction(v) for k, v in cos.items()},
               {k: QQ.to_fraction(v) for k, v in sin.items()})
        assert got == laurent_fourier(laurent_product(za, zb), 2 * n)
        t_trig = best(lambda ta=ta, tb=tb: ta * tb, 50)
        t_laurent = best(lambda za=za, zb=zb: laurent_product(za, zb), 50)
        print(f"{n:>5} {t_trig * 1e6:>18.1f} {t_laurent * 1e6:>15.1f} "
              f"{t_laurent / t_trig:>6.2f}x")


if __name__ == "__main__":
    main()
