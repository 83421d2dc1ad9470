"""The methods' compiled kernels (numba): Horner blocks, the AGM, one evaluator per period
method switched on its integer kind, the cn Fourier series; the period series re-expanded
(resummed, modified, Padé) and each method's coefficients order by order."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import sympy as sp
from numba import njit

from ..algebra.resum import binomial_series, pade, series_compose, series_mul
from ..errors import InputError
from ..lower.documents import (
    FOURIER_AGM_STEPS,
)
from ..lower.forms import agm_steps, horner
from ..lower.records import (
    x_,
)

Coefficients = tuple[np.ndarray, np.ndarray]
_m = sp.Symbol("m")  # the resummed variable of the lowered period forms

AGM_STEPS = 8
# NOTE: each AGM step squares the relative gap of a and b: 3 steps reach 1e-16 for all
# x ∈ [−0.5, 10³]; 6 reach it down to x = −1 + 1e-12, next to the separatrix.
PADE_MAX = 12
# NOTE: Padé [k/k] up to [12/12] (2k ≤ the series' order).


# --- evaluation: compiled kernels --------------------------------------------------------------

BLOCK = 1024
# NOTE: Horner runs coefficient-outer, point-inner over blocks of three 8 KB arrays that stay in
# L1 (256 and 4096 measured slower): no dependency between points, so LLVM vectorises the inner
# loop (point-outer Horner cannot be).

FASTMATH = {"contract", "arcp", "nsz", "reassoc"}
# NOTE: error_model="numpy" below: Python's model checks every division for zero, which keeps
# LLVM from vectorising any loop that divides (9 ns/point instead of 1.2 for the AGM).


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _horner_block(c: np.ndarray, t: np.ndarray, acc: np.ndarray) -> None:
    acc[:] = c[c.size - 1]
    for j in range(c.size - 2, -1, -1):
        cj = c[j]
        for i in range(t.size):
            acc[i] = acc[i] * t[i] + cj


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def agm(a: np.ndarray, b: np.ndarray, steps: int) -> None:
    """Gauss's arithmetic–geometric mean in place, elementwise: ``a ← (a + b)/2, b ← √(ab)``,
    ``steps`` times (a converged pair stays put, so a fixed count serves every argument);
    the mean is then ``(a + b)/2``.  The one numeric AGM (:func:`lower.agm_steps` is its
    lowering for emitted modules)."""
    for _ in range(steps):
        for i in range(a.size):
            a[i], b[i] = 0.5 * (a[i] + b[i]), np.sqrt(a[i] * b[i])


@njit(cache=True, fastmath=FASTMATH, error_model="numpy")
def _evaluate(kind: int, num: np.ndarray, den: np.ndarray, steps: int, x: np.ndarray,
              out: np.ndarray, masked: bool = True) -> None:
    """Blocked evaluation of a candidate; kind 0: Σ num_j x^j, 1: in m with √(1 − 2m),
    2: Padé num(x)/den(x), 3: modified L–P 1/√((1 + 3x/4) g(α)), 4: ``steps`` AGM steps.
    NaN outside the candidate's domain (the free Duffing oscillator's; ``masked=False`` for
    another oscillator, whose range the chooser checks against its own reference)."""
    t = np.empty(BLOCK)
    p = np.empty(BLOCK)
    q = np.empty(BLOCK)
    for start in range(0, x.size, BLOCK):
        n = min(BLOCK, x.size - start)
        xs = x[start : start + n]
        tv, pv, qv = t[:n], p[:n], q[:n]
        if kind == 4:
            for i in range(n):
                pv[i] = np.sqrt(1.0 + xs[i])
                qv[i] = np.sqrt(1.0 + 0.5 * xs[i])
            agm(pv, qv, steps)
        else:
            if kind == 1:
                for i in range(n):
                    tv[i] = xs[i] / (2.0 + 2.0 * xs[i])
            elif kind == 3:
                for i in range(n):
                    tv[i] = 3.0 * xs[i] / (4.0 + 3.0 * xs[i])
            else:
                tv[:] = xs
            _horner_block(num, tv, pv)
            if kind == 2:
                _horner_block(den, tv, qv)
        o = out[start : start + n]
        if not masked:
            for i in range(n):
                o[i] = pv[i] / qv[i] if kind == 2 else pv[i]
        elif kind == 0:
            for i in range(n):
                o[i] = pv[i] if abs(xs[i]) < 1.0 else np.nan
        elif kind == 1:
            for i in range(n):
                o[i] = pv[i] * np.sqrt(1.0 - 2.0 * tv[i]) if xs[i] > -2.0 / 3.0 else np.nan
        elif kind == 2:
            for i in range(n):
                o[i] = pv[i] / qv[i] if xs[i] > -1.0 else np.nan
        elif kind == 3:
            for i in range(n):
                o[i] = 1.0 / np.sqrt((1.0 + 0.75 * xs[i]) * pv[i]) if xs[i] > -1.0 else np.nan
        else:
            for i in range(n):
                o[i] = 2.0 / (pv[i] + qv[i]) if xs[i] > -1.0 else np.nan


@njit(cache=True, error_model="numpy")
def cn_fourier(t: np.ndarray, x: np.ndarray, harmonics: int, out: np.ndarray) -> np.ndarray:
    """``q/A`` of the free Duffing oscillator, ``x = εA² > −1``, as the exact Fourier series
    of the elliptic function in the nome ``q = exp(−πK′/K)``, truncated to ``harmonics``
    odd harmonics of ``Ω = 2π/T``: ``cn(u|m) = (2π/(kK)) Σ qⁿ⁺¹ᐟ²/(1 + q²ⁿ⁺¹) cos((2n+1)v)``
    for ``m ≥ 0``, and for ``m < 0`` the imaginary-modulus transform ``cn(u|−μ) =
    cd(√(1+μ) u | μ/(1+μ))`` with ``cd``'s series (signs ``(−1)ⁿ``, denominators
    ``1 − q²ⁿ⁺¹``).  The L–P series in x is its expansion; this one converges for every
    ``x > −1``.  NaN for ``x ≤ −1``.  The coefficients (two AGMs and an exp) are recomputed
    only where x changes, so a run of points at one amplitude costs a cos and a recurrence.
    :func:`lower.lower_fourier` lowers the same formulas for an emitted module."""
    b = np.zeros(max(harmonics, 1))
    a2, b2 = np.empty(2), np.empty(2)  # K's and K′'s AGMs side by side
    last, omega = np.nan, 1.0  # the coefficients are recomputed only when x changes
    for i in range(t.size):
        xi = x[i]
        if not xi > -1.0:
            out[i] = np.nan
            continue
        if xi != last:
            last = xi
            m = xi / (2.0 + 2.0 * xi)
            if m == 0.0:
                b[:] = 0.0
                b[0], omega = 1.0, 1.0
            else:
                if m > 0.0:
                    mm, scale, alt = m, np.sqrt(1.0 + xi), 1.0
                else:
                    mm = -m / (1.0 - m)
                    scale, alt = np.sqrt((1.0 + xi) * (1.0 - m)), -1.0
                a2[:] = 1.0
                b2[0], b2[1] = np.sqrt(1.0 - mm), np.sqrt(mm)
                agm(a2, b2, FOURIER_AGM_STEPS)
                K = np.pi / (a2[0] + b2[0])
                nome = np.exp(-np.pi * (np.pi / (a2[1] + b2[1])) / K)
                omega = 0.5 * np.pi * scale / K
                qn, q2n1, sign = np.sqrt(nome), nome, 2.0 * np.pi / (np.sqrt(mm) * K)
                for n in range(harmonics):
                    b[n] = sign * qn / (1.0 + alt * q2n1)
                    qn *= nome
                    q2n1 *= nome * nome
                    sign *= alt
        c1 = np.cos(omega * t[i])
        w = 4.0 * c1 * c1 - 2.0
        prev, cur = c1, c1  # cos((2n+1)v) by the recurrence c_{n+2} = w c_n − c_{n−2}
        total = 0.0
        for n in range(harmonics):
            total += b[n] * cur
            prev, cur = cur, w * cur - prev
        out[i] = total
    return out


# --- derivation: the period series re-expanded --------------------------------------------------

def resummed_coefficients(tau: list[Fraction]) -> list[Fraction]:
    """``c_n`` of ``(T/2π)(x(m)) / √(1 − 2m)``, ``x(m) = 2m/(1 − 2m) = Σ_{n≥1} 2^n m^n``,
    exactly; the first k + 1 terms use ``τ_0..τ_k``."""
    k = len(tau) - 1
    # (1 − 2m)^(−1/2) = Σ binom(−1/2, n) (−2m)^n
    inv_sqrt = [c * (-2) ** n for n, c in enumerate(binomial_series(Fraction(-1, 2), k + 1))]
    xm = [Fraction(0)] + [Fraction(2**n) for n in range(1, k + 1)]
    return series_mul(series_compose(tau, xm), inv_sqrt)


def modified_coefficients(omega: list[Fraction]) -> list[Fraction]:
    """The modified L–P of Cheung, Chen & Lau: ``ω² = (1 + 3x/4)·g(α)`` with
    ``α = (3x/4)/(1 + 3x/4)``, which stays below 1 for every ``x > 0``; returns ``g``'s
    coefficients exactly (``x(α) = (4/3) Σ_{n≥1} α^n``)."""
    k = len(omega) - 1
    w2 = series_mul(omega, omega)
    h = series_mul(w2, [Fraction(-3, 4) ** n for n in range(k + 1)])  # ω² / (1 + 3x/4)
    return series_compose(h, [Fraction(0)] + [Fraction(4, 3)] * k)


def _pade(tau: list[Fraction], k: int) -> tuple[np.ndarray, np.ndarray]:
    """The diagonal ``[k/k]`` of the period series, exact (:func:`algebra.resum.pade`), its
    coefficients rounded once to doubles for the compiled kernel."""
    approximant = pade(tau[: 2 * k + 1], k, k)
    return (np.array([float(c) for c in approximant.numerator]),
            np.array([float(c) for c in approximant.denominator]))


@dataclass(frozen=True)
class PeriodSeries:
    """The exact L–P series of the free Duffing oscillator: ``τ_j`` and ``ω_j``."""

    tau: list[Fraction]
    omega: list[Fraction]


ONE = np.ones(1)
NONE = np.zeros(1)


def _floats(values: list[Fraction]) -> np.ndarray:
    return np.array([float(v) for v in values])


def _lp_orders(s: PeriodSeries, top: int) -> list[tuple[int, Coefficients]]:
    return [(k, (_floats(s.tau[: k + 1]), ONE)) for k in range(1, top + 1)]


def _resummed_orders(s: PeriodSeries, top: int) -> list[tuple[int, Coefficients]]:
    res = resummed_coefficients(s.tau)
    return [(k, (_floats(res[: k + 1]), ONE)) for k in range(1, top + 1)]


def _modified_orders(s: PeriodSeries, top: int) -> list[tuple[int, Coefficients]]:
    mod = modified_coefficients(s.omega)
    return [(k, (_floats(mod[: k + 1]), ONE)) for k in range(1, top + 1)]


def _pade_orders(s: PeriodSeries, top: int) -> list[tuple[int, Coefficients]]:
    found = []
    for k in range(1, min(top // 2, PADE_MAX) + 1):
        try:
            found.append((k, _pade(s.tau, k)))
        except InputError:  # no [k/k] approximant (a singular block, e.g. a series with gaps)
            continue
    return found


def _agm_orders(s: PeriodSeries, top: int) -> list[tuple[int, Coefficients]]:
    return [(n, (NONE, ONE)) for n in range(AGM_STEPS + 1)]


def _exact_orders(s: PeriodSeries, top: int) -> list[tuple[int, Coefficients]]:
    return [(0, (NONE, ONE))]


def _rationals(values: np.ndarray) -> list[sp.Expr]:
    """The verified doubles as exact binary rationals."""
    return [sp.Rational(float(v)) for v in values]


@dataclass(frozen=True)
class PeriodTerms:
    """A period method's coefficients at one order, as verified doubles: what it evaluates
    and lowers (a registry :class:`Candidate` is one, with its method)."""

    order: int
    num: np.ndarray
    den: np.ndarray


def _lower_lp(c: PeriodTerms) -> tuple[tuple, sp.Expr]:
    return (), horner(_rationals(c.num), x_)


def _lower_resummed(c: PeriodTerms) -> tuple[tuple, sp.Expr]:
    return ((_m, x_ / (2 + 2 * x_)),), sp.sqrt(1 - 2 * _m) * horner(_rationals(c.num), _m)


def _lower_modified(c: PeriodTerms) -> tuple[tuple, sp.Expr]:
    return (((_m, 3 * x_ / (4 + 3 * x_)),),
            1 / sp.sqrt((1 + sp.Rational(3, 4) * x_) * horner(_rationals(c.num), _m)))


def _lower_pade(c: PeriodTerms) -> tuple[tuple, sp.Expr]:
    return (), horner(_rationals(c.num), x_) / horner(_rationals(c.den), x_)


def _lower_agm(c: PeriodTerms) -> tuple[tuple, sp.Expr]:
    lines, mean = agm_steps(sp.sqrt(1 + x_), sp.sqrt(1 + x_ / 2), c.order, "")
    return tuple(lines), 1 / mean


def _not_lowered(c: PeriodTerms) -> tuple[tuple, sp.Expr]:
    raise InputError("the exact period (SciPy's ellipk) has no compiled evaluator to emit; "
                     "loosen the tolerance or narrow the range")
