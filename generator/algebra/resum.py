"""Resummation of exact power series past their radius of convergence.

A series ``Σ c_k x^k`` with exact rational ``c_k`` (the limit cycle's ω(ε²), Mathieu's a_m(q))
becomes a Padé approximant ``[L/M] = P_L(x)/Q_M(x)``, ``Q_M(0) = 1``, computed over QQ (FLINT
``fmpq_mat`` solve of the ``M`` linear conditions, Baker & Graves-Morris eq. 1.1.6) and rounded
to floats only at the end; or first re-expanded in Andersen & Geer's variable
``w = x/(x² − 2xR cos β + R²)^½`` (SIAM J. Appl. Math. 42, 678 (1982)), which maps the two
conjugate branch points at ``x = R e^(±iβ)`` onto ``|w| = 1`` and ``x = ∞`` onto ``w = 1``.

A Padé approximant is trusted only where its denominator has no real zero (a spurious pole, a
Froissart doublet, sits on the interval otherwise) and where it agrees with its neighbour
``[L−1/M−1]``: :func:`check_poles` and :func:`neighbour_spread` measure both; the caller
compares with its numerical reference and fixes the verified interval.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import Any

import flint
import numpy as np

from ..errors import InputError

# --- the one power-series toolkit ------------------------------------------------------------
# A truncated power series ``Σ a_k x^k`` is the list of its coefficients, low to high, over any
# exact ring the package uses: Fraction, FLINT's fmpq and fmpq_mpoly, SymPy's numbers and
# expressions, the elements of a derivation's ``Ground`` (SymPy's number fields, K[params]).
# Each operation is written once, with the ring's own +, −, × and the inverse of one element
# (:func:`ring_inverse`); ``tidy`` (default: none) is applied to each coefficient made (e.g.
# SymPy's radsimp for algebraic numbers).  The partial sums (Horner exact, in floats, and the
# truncation estimate) and the radius of convergence estimated from the coefficients live
# here too.


def _kept(tidy: Callable[[Any], Any] | None) -> Callable[[Any], Any]:
    return (lambda c: c) if tidy is None else tidy


def ring_inverse(x: Any) -> Any:
    """``1/x`` of a nonzero ring element: a field's (Fraction, fmpq, a number field's ANP, a
    SymPy number), a constant of FLINT's ``fmpq_mpoly``, or a constant polynomial of SymPy's
    ``K[params]`` (which inverts a constant only through its domain)."""
    if type(x) is int:
        return Fraction(1, x)
    try:
        return x ** -1
    except ValueError:
        ring = x.ring
        if not x.is_ground:
            raise
        return ring.ground_new(ring.domain.quo(ring.domain.one, x.LC))


def series_mul(a: Sequence[Any], b: Sequence[Any], n: int | None = None,
               tidy: Callable[[Any], Any] | None = None) -> list[Any]:
    """The product ``Σ_i a_i b_(k−i)`` truncated to ``n`` terms (default ``len(a)``); a
    coefficient past either list's end is zero."""
    n = len(a) if n is None else n
    tidy = _kept(tidy)
    zero = a[0] * 0
    return [tidy(sum((a[i] * b[k - i] for i in range(max(0, k - len(b) + 1), min(k, len(a) - 1)
                                                      + 1)), zero))
            for k in range(n)]


def series_reciprocal(a: Sequence[Any], n: int | None = None, *, inverse: Any = None,
                      tidy: Callable[[Any], Any] | None = None) -> list[Any]:
    """``1 / Σ a_k x^k`` to ``n`` terms (default ``len(a)``): ``p_0 = 1/a_0`` (``inverse``, when
    the caller has it in its own form; else :func:`ring_inverse`), then
    ``p_k = −p_0 Σ_(i=1..k) a_i p_(k−i)``."""
    n = len(a) if n is None else n
    tidy = _kept(tidy)
    p = [ring_inverse(a[0]) if inverse is None else inverse]
    zero = a[0] * 0
    for k in range(1, n):
        acc = sum((a[i] * p[k - i] for i in range(1, min(k, len(a) - 1) + 1)), zero)
        p.append(tidy(-p[0] * acc))
    return p


def series_sqrt(a: Sequence[Any], n: int | None = None, *, root: Any = None,
                tidy: Callable[[Any], Any] | None = None) -> list[Any]:
    """``√(Σ a_k x^k)`` to ``n`` terms (default ``len(a)``): ``s_0 = root``, a square root of
    ``a_0`` (default 1, when ``a_0 = 1``), then ``2 s_0 s_k = a_k − Σ_(0<i<k) s_i s_(k−i)``."""
    n = len(a) if n is None else n
    tidy = _kept(tidy)
    if root is None:
        root = a[0] ** 0
        if a[0] != root:
            raise ValueError("series_sqrt: a_0 is not 1; give its square root")
    scale = ring_inverse(root + root)
    zero = a[0] * 0
    s = [root]
    for k in range(1, n):
        acc = a[k] if k < len(a) else zero
        for i in range(1, k):
            acc = acc - s[i] * s[k - i]
        s.append(tidy(acc * scale))
    return s


def binomial_series(alpha: Fraction, n: int) -> list[Fraction]:
    """``(1 + x)^α`` to ``n`` terms: ``binom(α, j)``, exact for rational ``α``."""
    out, c = [], Fraction(1)
    for j in range(n):
        out.append(c)
        c = c * (alpha - j) / (j + 1)
    return out


_RATIONAL = (int, Fraction, flint.fmpq)


def series_compose(outer: Sequence[Any], inner: Sequence[Any], n: int | None = None, *,
                   tidy: Callable[[Any], Any] | None = None) -> list[Any]:
    """``Σ_j c_j inner(x)^j`` to ``n`` terms (default ``len(outer)``; ``inner(0) = 0``).

    Over QQ (ints, Fractions, fmpq; no ``tidy``) by Horner's rule in FLINT's truncated
    products, returned as Fractions; over any other ring as the sum of ``c_j`` times the powers
    of ``inner``, each power by :func:`series_mul`."""
    n = len(outer) if n is None else n
    if inner and inner[0]:
        raise ValueError("compose: the inner series must vanish at 0")
    outer = list(outer[:n])
    if tidy is None and all(isinstance(c, _RATIONAL) for c in (*outer, *inner)):
        g = flint.fmpq_poly([_fmpq(c) for c in inner[:n]])
        acc = flint.fmpq_poly([])
        for c in reversed(outer):
            acc = acc.mul_low(g, n) + _fmpq(c)
        return [_fraction(acc[i]) for i in range(n)]
    tidy = _kept(tidy)
    total, power = [0] * n, [1] + [0] * (n - 1)
    for j, c in enumerate(outer):
        if j:
            power = series_mul(power, inner, n, tidy)
        total = [tidy(t + c * q) for t, q in zip(total, power, strict=True)]
    return total


def horner_exact(coeffs: Sequence[Any], x: Any) -> Any:
    """``Σ c_k x^k`` (coefficients low to high) by Horner's rule in the ring's own arithmetic
    (Fractions: exactly)."""
    acc = x * 0
    for c in reversed(coeffs):
        acc = acc * x + c
    return acc


def horner_float(coeffs: Sequence[Any], x: np.ndarray) -> np.ndarray:
    """``Σ c_k x^k`` (coefficients low to high) at float ``x`` by Horner's rule, each
    coefficient rounded to float64 first."""
    acc = np.zeros_like(x)
    for c in reversed(coeffs):
        acc = acc * x + float(c)
    return acc


def partial_sum(coefficients: Sequence, x: float) -> tuple[float, float, int]:
    """The partial sum at ``x``, its change over the last two nonzero terms (the truncation
    error estimate) and the order K of the smallest such change (the best reachable)."""
    total, last, changes = 0.0, [], []
    for k, c in enumerate(coefficients):
        term = float(c) * x**k
        total += term
        if c:
            last.append(abs(term))
            changes.append((sum(last[-2:]), k))
    if len(changes) < 2:
        return total, 0.0, len(coefficients) - 1
    best = min(changes[1:])
    return total, changes[-1][0], best[1]


@dataclass(frozen=True)
class Singularity:
    """The nearest singularities of a series, estimated from its coefficients: at ``radius``
    and ``±angle`` (radians) in the plane of ``variable``; ``spread``: the error bar of
    ``radius`` — how far the extrapolations from the last orders lie apart, or, if more, how
    far the fit of one degree more in 1/n lies from it (the first neglected term)."""

    variable: str
    radius: float
    angle: float
    spread: float
    method: str


def nearest_singularity(coefficients: Sequence[Fraction], variable: str = "eps",
                        degree: int | None = 1) -> Singularity | None:
    """Domb–Sykes (ratios c_n/c_(n−1), for one real singularity: a tail of one sign or of
    alternating signs) or Mercer–Roberts (a complex-conjugate pair: B_n² = (c_(n+1)c_(n−1) −
    c_n²)/(c_n c_(n−2) − c_(n−1)²) → 1/R², cos θ from the same), each estimate extrapolated
    linearly in 1/n over the last orders — or by a polynomial of ``degree`` in 1/n (the
    ratios of an algebraic branch point go as 1 + a/n + b/n² + …); ``degree=None`` takes the
    degree 1..3 whose fits over the last orders spread least.  A series with zero odd terms is
    read in the square of ``variable``.  None with fewer than 12 usable coefficients."""
    import mpmath
    import sympy as sp

    c = list(coefficients)
    if len(c) > 2 and all(x == 0 for x in c[1::2]):
        c, variable = c[::2], f"{variable}**2"
    c = [mpmath.mpf(x.numerator) / x.denominator if isinstance(x, Fraction)
         else mpmath.mpf(sp.N(x, 40)) for x in c]  # an algebraic number: 40 digits
    while c and c[-1] == 0:
        c.pop()
    if len(c) < 12:
        return None
    tail = c[len(c) // 2:]
    signs = [mpmath.sign(x) for x in tail]
    real = all(s == signs[0] for s in signs) or all(
        signs[k] == -signs[k + 1] for k in range(len(signs) - 1))
    ns, radii, angles = [], [], []
    for n in range(max(3, len(c) // 2), len(c) - 1):
        if real:
            if c[n - 1] == 0:
                continue
            ratio = abs(c[n] / c[n - 1])
            radii.append(1 / ratio)
            angles.append(0.0 if signs[0] == signs[-1] and all(
                s == signs[0] for s in signs) else math.pi)
        else:
            den = c[n] * c[n - 2] - c[n - 1] ** 2
            if den == 0 or c[n] == 0:
                continue
            b2 = (c[n + 1] * c[n - 1] - c[n] ** 2) / den
            if b2 <= 0:
                continue
            b = mpmath.sqrt(b2)
            cos_t = (c[n - 1] * b / c[n] + c[n + 1] / (b * c[n])) / 2
            radii.append(1 / b)
            angles.append(float(mpmath.acos(max(-1, min(1, cos_t)))))
        ns.append(n)
    if len(ns) < 4:
        return None

    def extrapolate(values: list, lo: int, degree: int) -> float:
        x = [1 / mpmath.mpf(n) for n in ns[lo:]]
        y = [mpmath.mpf(v) for v in values[lo:]]
        if degree == 1:
            mx, my = sum(x) / len(x), sum(y) / len(y)
            sxx = sum((a - mx) ** 2 for a in x)
            slope = sum((a - mx) * (b - my) for a, b in zip(x, y, strict=True)) / sxx
            return float(my - slope * mx)
        with mpmath.workdps(50):  # least squares in x·n_lo ∈ (0, 1]: well conditioned
            A = mpmath.matrix([[(a * ns[lo]) ** d for d in range(degree + 1)] for a in x])
            return float(mpmath.lu_solve(A.T * A, A.T * mpmath.matrix(y))[0])

    half = len(ns) // 2
    degrees = [degree] if degree is not None else [
        d for d in (1, 2, 3) if len(ns) - half >= d + 2]
    best = None
    for d in degrees:
        try:
            fits = [extrapolate(radii, lo, d) for lo in range(0, half + 1)]
        except ZeroDivisionError:  # too few distinct orders for this degree
            continue
        if best is None or max(fits) - min(fits) < best[1]:
            best = (d, max(fits) - min(fits), fits)
    if best is None:
        return None
    chosen, spread, fits = best
    angle_fits = [extrapolate(angles, lo, chosen) for lo in range(0, half + 1)]
    radius, angle = fits[-1], angle_fits[-1] if not real else angles[-1]
    if chosen < 3 and len(ns) - half >= chosen + 3:
        # NOTE: the fits' spread alone missed the error of the linear fit of a complex pair
        # (Mathieu's a_1 at order 100: 1.1e-3 for an error of 1.8e-3 against DLMF Table
        # 28.6.1); the quadratic fit's distance (4.5e-3) bounds it on every row of the table.
        spread = max(spread, abs(extrapolate(radii, half, chosen + 1) - radius))
    method = "Domb–Sykes" if real else "Mercer–Roberts"
    if degree is None:
        method += f", degree {chosen} in 1/n"
    return Singularity(variable, radius, float(angle), float(spread), method)


def series_radius(coefficients: Sequence) -> float:
    """The estimated radius of convergence in the series' own variable (inf if too short)."""
    est = nearest_singularity(coefficients, "x", None)
    if est is None:
        return math.inf
    return math.sqrt(est.radius) if est.variable == "x**2" else est.radius


@dataclass(frozen=True)
class Pade:
    """``[L/M](x) = Σ p_i x^i / Σ q_j x^j`` with ``q_0 = 1``, exact; ``variable`` says what
    ``x`` is in terms of the caller's argument (``"eps**2"``, ``"q"``, ``"w"``)."""

    numerator: tuple[Fraction, ...]
    denominator: tuple[Fraction, ...]
    variable: str

    @property
    def degrees(self) -> tuple[int, int]:
        """``(L, M)``: the degrees of the numerator and the denominator."""
        return len(self.numerator) - 1, len(self.denominator) - 1

    def __call__(self, x: np.ndarray | float) -> np.ndarray:
        """The approximant in float64 (Horner on the rounded coefficients)."""
        x = np.asarray(x, dtype=float)
        return horner_float(self.numerator, x) / horner_float(self.denominator, x)

    def exact(self, x: Fraction) -> Fraction:
        """The approximant at a rational ``x``, exactly."""
        return horner_exact(self.numerator, x) / horner_exact(self.denominator, x)


def _fmpq(c: Fraction | int | flint.fmpq) -> flint.fmpq:
    if isinstance(c, flint.fmpq):
        return c
    return flint.fmpq(c.numerator, c.denominator)


def _fraction(c: flint.fmpq) -> Fraction:
    return Fraction(int(c.p), int(c.q))


def pade(coefficients: Sequence[Fraction], L: int, M: int, variable: str = "x") -> Pade:
    """The exact Padé approximant ``[L/M]`` of ``Σ c_k x^k`` from ``c_0 … c_(L+M)``.

    The denominator solves ``Σ_(j=0..M) q_j c_(L+k−j) = 0`` (k = 1..M, ``q_0 = 1``, ``c_i = 0``
    for i < 0) over QQ; the numerator is the product's truncation ``p_i = Σ_j q_j c_(i−j)``.
    A singular system (the block structure of the Padé table) is an :class:`InputError`.

    >>> pade([Fraction(1)] * 3, 0, 1).denominator   # 1/(1 − x)
    (Fraction(1, 1), Fraction(-1, 1))
    """
    if L < 0 or M < 0:
        raise InputError(f"Padé [{L}/{M}]: degrees must be ≥ 0")
    c = [Fraction(x) for x in coefficients]
    if len(c) < L + M + 1:
        raise InputError(f"Padé [{L}/{M}]: needs {L + M + 1} coefficients, got {len(c)}")

    f = [_fmpq(x) for x in c[: L + M + 1]]  # FLINT's rationals: Fraction's gcds dominate

    def at(i: int) -> flint.fmpq:
        return f[i] if i >= 0 else flint.fmpq(0)

    q = [flint.fmpq(1)]
    if M:
        A = flint.fmpq_mat(M, M, [at(L + k - j) for k in range(1, M + 1)
                                  for j in range(1, M + 1)])
        b = flint.fmpq_mat(M, 1, [-at(L + k) for k in range(1, M + 1)])
        try:
            x = A.solve(b)
        except ZeroDivisionError as exc:
            raise InputError(f"Padé [{L}/{M}] in {variable}: singular (a block of the Padé "
                             "table); choose other degrees") from exc
        q += [x[j, 0] for j in range(M)]
    product = (flint.fmpq_poly(q) * flint.fmpq_poly(f[: L + 1])).coeffs()
    p = [product[i] if i < len(product) else flint.fmpq(0) for i in range(L + 1)]
    return Pade(tuple(map(_fraction, p)), tuple(map(_fraction, q)), variable)


def real_poles(approximant: Pade, lo: float, hi: float) -> list[float]:
    """The real zeros of the denominator in ``[lo, hi]`` (FLINT's certified root isolation):
    an approximant with any is not trusted there (a spurious pole, Froissart doublet)."""
    den = flint.fmpq_poly([_fmpq(c) for c in approximant.denominator])
    if den.degree() < 1:
        return []
    roots = [float(r.real.mid()) for r, _ in den.complex_roots()
             if r.imag.contains(0) and abs(float(r.imag.mid())) < 1e-30]
    return sorted(r for r in roots if lo <= r <= hi)


def neighbour_spread(approximant: Pade, neighbour: Pade, x: np.ndarray) -> np.ndarray:
    """``|[L/M] − [L'/M']| / |[L/M]|`` at ``x``: the error estimate of the pair (the nearer
    approximant's error is below it wherever the sequence converges)."""
    a, b = approximant(x), neighbour(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.abs(a - b) / np.abs(a)


def w_substitution(R: Fraction, p: Fraction, order: int) -> list[Fraction]:
    """``x(w)`` to ``w^order``, the inverse of ``w = x/(x² − 2px + R²)^½`` (``p = R cos β``),
    near ``x = w = 0``: ``x = w(R√(1 − (1 − p²/R²)w²) − pw)/(1 − w²)``, exact for rational
    R and p."""
    n = order + 1
    k = 1 - p * p / (R * R)
    root = [Fraction(0)] * n  # √(1 − k w²) = Σ binom(1/2, i) (−k)^i w^(2i)
    for i, coeff in enumerate(binomial_series(Fraction(1, 2), (n + 1) // 2)):
        root[2 * i] = coeff * (-k) ** i
    num = [Fraction(0)] * n  # w (R √(…) − p w)
    for i in range(n - 1):
        num[i + 1] += R * root[i]
    if n > 2:
        num[2] -= p
    x = [Fraction(0)] * n  # / (1 − w²) = × Σ w^(2i)
    for i in range(n):
        x[i] = sum((num[i - 2 * j] for j in range(i // 2 + 1)), Fraction(0))
    return x


def compose(coefficients: Sequence[Fraction], inner: Sequence[Fraction], order: int
            ) -> list[Fraction]:
    """``Σ c_k inner(w)^k`` to ``w^order`` (``inner(0) = 0``), exactly
    (:func:`series_compose`)."""
    return series_compose(coefficients, inner, order + 1)


def w_of(x: np.ndarray, R: float, p: float) -> np.ndarray:
    """Andersen & Geer's ``w = x/(x² − 2px + R²)^½``."""
    return x / np.sqrt(x * x - 2 * p * x + R * R)


@dataclass(frozen=True)
class Resummed:
    """A resummed function of one argument ``z``: ``x = z**power`` (``power`` 2 for a series
    with even powers only), then either the Padé approximant in ``x`` or — when ``R`` and ``p``
    are set — ``√((1 − w) [L/M](w))`` with Andersen & Geer's ``w(x)`` (the form of a frequency
    that falls as ``x^(−1/2)``: ``ω²/(1 − w)`` is what is approximated).  With ``log`` set (a
    relaxation oscillation, :func:`resum_relaxation`) the approximant is in
    ``v = 1 − (1 − w)^(1/3)`` and ``log · s³ ln s`` (``s = 1 − v``) is added to it before
    the square root.  ``rooted`` False (a Fourier coefficient, :func:`resum_harmonic`) takes
    ``[L/M](w)`` itself; ``odd`` multiplies the value by ``z`` (a series ``z·Σ c_k z^(2k)``).
    ``neighbour`` is ``[L−1/M−1]`` of the same series, for the error estimate."""

    power: int
    approximant: Pade
    neighbour: Pade
    R: Fraction | None = None
    p: Fraction | None = None
    log: Fraction | None = None
    rooted: bool = True
    odd: bool = False

    def _x(self, z: np.ndarray) -> np.ndarray:
        return np.asarray(z, dtype=float) ** self.power

    def _value(self, approximant: Pade, z: np.ndarray) -> np.ndarray:
        if self.odd:
            return np.asarray(z, dtype=float) * replace(self, odd=False)._value(approximant, z)
        x = self._x(z)
        if self.R is None:
            return approximant(x)
        w = w_of(x, float(self.R), float(self.p))
        if not self.rooted:
            return approximant(w)
        if self.log is None:
            return np.sqrt((1 - w) * approximant(w))
        s = np.cbrt(1 - w)
        v = w / (1 + s + s * s)  # 1 − s without the cancellation near w = 0
        with np.errstate(divide="ignore", invalid="ignore"):
            tail = np.where(w < 1, (1 - w) * np.log1p(-w) / 3, 0.0)  # s³ ln s
        return np.sqrt((1 - w) * (approximant(v) + float(self.log) * tail))

    def __call__(self, z: np.ndarray | float) -> np.ndarray:
        return self._value(self.approximant, z)

    def spread(self, z: np.ndarray | float) -> np.ndarray:
        """``|f_[L/M] − f_[L−1/M−1]| / |f_[L/M]|``: the error estimate."""
        a, b = self._value(self.approximant, z), self._value(self.neighbour, z)
        with np.errstate(divide="ignore", invalid="ignore"):
            relative = self.rooted and self.R is not None  # a frequency; else absolute below 1
            return np.abs(a - b) / np.maximum(np.abs(a), 0.0 if relative else 1.0)


def in_power(coefficients: Sequence[Fraction]) -> tuple[int, list[Fraction]]:
    """``(2, [c_0, c_2, …])`` for a series with only even powers (read in ``z²``), else
    ``(1, c)``."""
    c = [Fraction(x) for x in coefficients]
    if len(c) > 2 and all(x == 0 for x in c[1::2]):
        return 2, c[::2]
    return 1, c


def diagonal_pade(coefficients: Sequence, lo: float, hi: float, variable: str = "x",
                  build: Callable[[Sequence, int, int, str], Pade] | None = None
                  ) -> tuple[Pade, Pade]:
    """The pair ``[L/M]``, ``[L−1/M−1]`` with ``L + M`` = the last index and ``M`` nearest
    ``L`` (then ``L + 1``, ``L − 1``, … while one of the pair has a real pole on
    ``[lo, hi]``): the near-diagonal approximants converge best in the cut plane.  ``build``
    makes one approximant (default :func:`pade`, exact over QQ)."""
    build = build or pade
    N = len(coefficients) - 1
    if N < 2:
        raise InputError(f"Padé: {N + 1} coefficients are too few to resum")
    half = N // 2
    for M in sorted(range(1, N), key=lambda m: (abs(m - half), -m)):
        try:
            pair = (build(coefficients, N - M, M, variable),
                    build(coefficients, N - M - 1, M - 1, variable))
        except InputError:
            continue
        if not any(real_poles(P, lo, hi) for P in pair):
            return pair
    raise InputError(f"Padé in {variable}: every near-diagonal approximant has a pole on "
                     f"[{lo}, {hi}]")


def resum_series(coefficients: Sequence[Fraction], hi: float) -> Resummed:
    """Padé in ``z`` or ``z²`` (even series) of ``Σ c_k z^k``, pole-free on ``0 ≤ z ≤ hi``
    (Mathieu's a_m(q), b_m(q))."""
    power, c = in_power(coefficients)
    approximant, neighbour = diagonal_pade(c, 0.0, hi**power, "z**2" if power == 2 else "z")
    return Resummed(power, approximant, neighbour)


ANGLE_DIGITS = 1000
# NOTE: R and R cos β of the measured singularity are rounded to rationals with denominators
# ≤ 1000: w's re-expansion stays exact, and the measured convergence does not depend on the
# third digit of the singularity (the transform only needs its neighbourhood).


def resum_frequency(coefficients: Sequence[Fraction], radius: float, angle: float
                    ) -> Resummed:
    """A limit cycle's ω(ε) (a series in ε² with the nearest singularities at ``radius ·
    e^(±i angle)`` in the ε² plane, :func:`lindstedt.nearest_singularity`) as
    ``√((1 − w) [L/M](w))``: the series of ``ω²/(1 − w)`` re-expanded exactly in
    ``w = ε²/(ε⁴ − 2ε²R cos β + R²)^½``, then Padé in w, pole-free on ``0 ≤ w ≤ 1``.

    Measured (benchmarks/resum.py, van der Pol to order 130 against DOP853 shooting): the best
    of the forms tried — Padé of ω, T/2π or (T/2π)² in ε² (3e-3 … 7e-2 at ε = 10, spurious
    real poles in most near-diagonal ones), the partial sums in w (0.2 at ε = 10), Padé of ω
    or ω² in w (4e-4 … 3e-3) — and the only one with every near-diagonal approximant
    pole-free: 3e-14 to ε = 1, 1e-10 to ε = 3, 1e-7 to ε = 5, 2e-4 at ε = 10.
    """
    power, c = in_power(coefficients)
    if power != 2:
        raise InputError("resum_frequency: ω must be a series in ε² (only even powers)")
    R, p = _singularity(radius, angle)
    approximant, neighbour = diagonal_pade(_over_one_minus_w(c, R, p), 0.0, 1.0, "w")
    return Resummed(2, approximant, neighbour, R, p)


def resum_harmonic(coefficients: Sequence[Fraction], R: Fraction, p: Fraction) -> Resummed:
    """One Fourier coefficient of a limit cycle's ``q(s)`` as a function of ε (its series even
    in ε, or ε times an even one) as Padé in Andersen & Geer's ``w`` (``R``, ``p = R cos β``
    of ω's singularity, :func:`resum_frequency`): the series re-expanded in ``w`` and the
    near-diagonal ``[L/M](w)`` pole-free on ``0 ≤ w ≤ 1``, both in balls at
    :data:`RELAXATION_PRECISION` bits (the exact route costs seconds per harmonic at order
    100).  Measured (van der Pol, order 100, the harmonics summed against DOP853): 2.6e-8 at
    ε = 2.5, 4.7e-6 at 3, 2e-1 at 6 where Padé in ε² has poles past ε ≈ 4."""
    c = [Fraction(x) for x in coefficients]
    odd = len(c) > 3 and not any(c[0::2])
    power, c = in_power(c[1:] if odd else c)
    if power != 2:
        raise InputError("resum_harmonic: the series must be even in ε or ε times an even one")
    N = len(c) - 1
    if sum(1 for x in c if x) < 3:
        raise InputError(f"resum_harmonic: {sum(1 for x in c if x)} nonzero terms are too few")
    old, flint.ctx.prec = flint.ctx.prec, RELAXATION_PRECISION
    try:
        g = flint.arb_poly([_arb(x) for x in w_substitution(R, p, N)])
        acc = flint.arb_poly([])
        for x in reversed(c):  # Σ c_k x(w)^k to w^N, Horner in truncated products
            acc = (acc * g).truncate(N + 1) + _arb(x)
        series = [acc[k] if k < acc.length() else flint.arb(0) for k in range(N + 1)]
    finally:
        flint.ctx.prec = old
    pair = diagonal_pade(series, 0.0, 1.0, "w",
                         lambda c, L, M, v: two_point_pade(c, [], L, M, v))  # in balls
    return Resummed(2, *pair, R, p, rooted=False, odd=odd)


def _singularity(radius: float, angle: float) -> tuple[Fraction, Fraction]:
    """``R`` and ``R cos β`` as rationals (:data:`ANGLE_DIGITS`)."""
    return (Fraction(radius).limit_denominator(ANGLE_DIGITS),
            Fraction(radius * math.cos(angle)).limit_denominator(ANGLE_DIGITS))


def _over_one_minus_w(c: Sequence[Fraction], R: Fraction, p: Fraction) -> list[Fraction]:
    """The series of ``ω²/(1 − w)`` in ``w`` from ω's in ``x``, exactly."""
    N = len(c) - 1
    squared = series_mul(c, c)
    in_w = compose(squared, w_substitution(R, p, N), N)
    return [sum(in_w[: k + 1], Fraction(0)) for k in range(N + 1)]  # / (1 − w)


RELAXATION_PRECISION = 3000
# NOTE: bits of the ball arithmetic of the two-point Padé: its linear system mixes exact
# rationals of ~7000 digits (order 164) with ln 2, π and the Airy zero; the solution's balls
# are checked to be below 2^−200 relative, so that rounding to float64 is the only error.


@dataclass(frozen=True)
class Relaxation:
    """The large-ε period of a relaxation oscillation, ``T = a ε + b ε^(−1/3) + c ε^(−1) ln ε
    + O(ε^(−1))``: van der Pol's (Dorodnitsyn 1947; Grasman, *Asymptotic Methods for
    Relaxation Oscillations*, §3) has ``a = 3 − 2 ln 2``, ``b = 3·2.338107…`` (the first zero
    of Ai(−x)), ``c = −2/3``."""

    a: flint.arb
    b: flint.arb
    c: Fraction


def van_der_pol_relaxation() -> Relaxation:
    """:class:`Relaxation` of ``q̈ + q = ε(1 − q²)q̇`` (and of Rayleigh's equation, whose q̇
    obeys it), at :data:`RELAXATION_PRECISION` bits."""
    old, flint.ctx.prec = flint.ctx.prec, RELAXATION_PRECISION
    try:
        return Relaxation(3 - 2 * flint.arb(2).log(), -3 * flint.arb.airy_ai_zero(1),
                          Fraction(-2, 3))
    finally:
        flint.ctx.prec = old


def _exact(x: flint.arb) -> Fraction:
    """The midpoint of a ball as an exact rational, refused when the ball is wide."""
    if not x.rad() <= abs(x.mid()) * flint.arb(2) ** -200 + flint.arb(2) ** -4000:
        raise InputError(f"two-point Padé: coefficient {x} not resolved at "
                         f"{RELAXATION_PRECISION} bits")
    man, exp = x.mid().man_exp()
    return Fraction(int(man)) * Fraction(2) ** int(exp)


def two_point_pade(at_zero: Sequence[flint.arb | Fraction], at_one: Sequence[flint.arb | Fraction],
                   L: int, M: int, variable: str = "v") -> Pade:
    """``[L/M](v)`` that matches ``Σ c_k v^k`` to ``v^(L+M−n)`` and ``Σ d_j (1 − v)^j`` to
    ``(1 − v)^(n−1)`` (``n = len(at_one)``): the linear conditions of both expansions
    (Baker & Graves-Morris §7.1, two-point Padé) solved in ball arithmetic (exact rationals
    are taken at :data:`RELAXATION_PRECISION` bits; balls as given)."""
    n1 = len(at_one)
    n0 = L + M + 1 - n1
    if n0 > len(at_zero) or n0 < 1:
        raise InputError(f"two-point Padé [{L}/{M}]: needs {n0} coefficients at 0, got "
                         f"{len(at_zero)}")
    old, flint.ctx.prec = flint.ctx.prec, RELAXATION_PRECISION
    try:
        zero = flint.arb(0)
        at_zero = [x if isinstance(x, flint.arb) else _arb(x) for x in at_zero[:n0]]
        at_one = [x if isinstance(x, flint.arb) else _arb(x) for x in at_one]

        def c(i: int) -> flint.arb:
            return at_zero[i] if i >= 0 else zero

        rows, rhs = [], []
        for i in range(n0):  # v^i of P − cQ, q_0 = 1
            rows += [flint.arb(int(k == i)) for k in range(L + 1)]
            rows += [-c(i - j) for j in range(1, M + 1)]
            rhs.append(c(i))
        for m in range(n1):  # (1 − v)^m of P − dQ: v^i = Σ_m C(i, m) (−1)^m (1 − v)^m
            rows += [flint.arb(math.comb(i, m) * (-1) ** m) for i in range(L + 1)]
            rows += [-sum((math.comb(j, r) * (-1) ** r * at_one[m - r] for r in range(m + 1)),
                          zero) for j in range(1, M + 1)]
            rhs.append(at_one[m])
        size = L + M + 1
        try:
            x = flint.arb_mat(size, size, rows).solve(flint.arb_mat(size, 1, rhs))
        except ZeroDivisionError as exc:
            raise InputError(f"two-point Padé [{L}/{M}] in {variable}: singular") from exc
        p = tuple(_exact(x[k, 0]) for k in range(L + 1))
        q = (Fraction(1), *(_exact(x[L + 1 + j, 0]) for j in range(M)))
    finally:
        flint.ctx.prec = old
    return Pade(p, q, variable)


def _arb(c: Fraction) -> flint.arb:
    return flint.arb(_fmpq(c))


def resum_relaxation(coefficients: Sequence[Fraction], radius: float, angle: float,
                     relaxation: Relaxation) -> Resummed:
    """A relaxation oscillator's ω(ε) from its series in ε² and its period's large-ε terms:
    ``ω² = (1 − w)(G(v) + λ s³ ln s)`` with Andersen & Geer's ``w`` (:func:`resum_frequency`),
    ``s = (1 − w)^(1/3) = 1 − v`` and ``G`` the two-point Padé in ``v`` of
    ``ω²/(1 − w) − λ s³ ln s``: its series at ``v = 0`` (exact: ``w = 1 − (1 − v)³``), and at
    ``v = 1`` (ε = ∞) ``g₀(1 − A s²) + O(s³)``.  From ``T = aε(1 + (b/a)ε^(−4/3) +
    (c/a)ε^(−2) ln ε + …)`` and ``1 − w = −p/ε² + O(ε^(−4))``: ``g₀ = 4π²/(a²(−p))``,
    ``A = 2(b/a)(−p)^(−2/3)``, ``λ = 3c g₀/(a(−p))``.  The cube root makes the ε^(−4/3) term
    of T analytic at v = 1 and λ removes the leading logarithm, the two things that keep
    Padé in w from converging at large ε.

    Measured (benchmarks/resum_relaxation.py, van der Pol against DOP853 shooting):
    relative error at ε = 10 of 1.3e-4, 7.6e-6, 3.6e-6, 7.7e-8 from orders 60, 100, 130, 164
    (:func:`resum_frequency`: 1.4e-2 … 2.2e-4), ≤ 3.1e-14 on (0, 1].
    """
    power, c = in_power(coefficients)
    if power != 2:
        raise InputError("resum_relaxation: ω must be a series in ε² (only even powers)")
    R, p = _singularity(radius, angle)
    if p >= 0:
        raise InputError(f"resum_relaxation: R cos β = {p} ≥ 0: w → 1 from above as ε → ∞")
    N = len(c) - 1
    g = _over_one_minus_w(c, R, p)
    in_v = compose(g, [Fraction(0), Fraction(3), Fraction(-3), Fraction(1)], N)
    log = [Fraction(0)] + [Fraction(-1, k) for k in range(1, N + 1)]  # ln(1 − v)
    cube = (1, -3, 3, -1)  # (1 − v)³
    tail = [sum((cube[j] * log[i - j] for j in range(4) if i >= j), Fraction(0))
            for i in range(N + 1)]
    old, flint.ctx.prec = flint.ctx.prec, RELAXATION_PRECISION
    try:
        a, b, mp = relaxation.a, relaxation.b, _arb(-p)
        g0 = 4 * flint.arb.pi() ** 2 / (a * a * mp)
        A = 2 * b / a * mp ** (flint.arb(-2) / 3)
        lam = 3 * _arb(relaxation.c) * g0 / (a * mp)
        series = [_arb(x) - lam * _arb(y) for x, y in zip(in_v, tail, strict=True)]
        ends = [g0, flint.arb(0), -g0 * A]
        lam = _exact(lam)
    finally:
        flint.ctx.prec = old
    total = N + len(ends)  # L + M: every coefficient at v = 0 and the three at v = 1
    for L in sorted(range(2, total - 1), key=lambda k: (abs(2 * k - total - 1), -k)):
        M = total - L
        try:
            pair = (two_point_pade(series, ends, L, M), two_point_pade(
                series[: N - 1], ends, L - 1, M - 1))
        except InputError:
            continue
        if not any(real_poles(P, 0.0, 1.0) for P in pair):
            return Resummed(2, *pair, R, p, lam)
    raise InputError("two-point Padé in v: every near-diagonal approximant has a pole on "
                     "[0, 1]")
