"""The methods, one record each: what it answers and for which oscillators (and why not), how it
derives, evaluates and lowers, and what it is checked against.

``choose`` loops over :data:`METHODS`; the compiler asks a record's :class:`Target` what to
derive and lower for ``generate`` and ``choose --emit``.  Adding a method is adding a record.

The free Duffing period ``T/2π`` as a function of ``x = εA²`` (``choose period``):

* ``lindstedt``: the L–P series ``Σ τ_j x^j`` truncated at order k (radius |x| < 1, set by the
  separatrix at x = −1);
* ``resummed``: the same series re-expanded in ``m = x/(2(1+x))``:
  ``T/2π = √(1 − 2m) Σ c_n m^n`` — analytic for ``|m| < 1``, i.e. ``x > −2/3``, and
  ``m < 1/2`` for every ``x ≥ 0``, so it converges out to ``εA² → ∞``;
* ``pade``: the diagonal Padé approximant ``[k/k]`` of the L–P series;
* ``modified``: the modified L–P of Cheung, Chen & Lau, re-expanded from the exact series;
* ``agm``: the exact period through Gauss's arithmetic–geometric mean,
  ``T/2π = 1/AGM(√(1+x), √(1+x/2))`` (``K(m) = π/(2 AGM(1, √(1−m)))``, scaled), stopped after
  n steps — the order; each step squares the relative error, so 2–3 steps are exact to
  double precision everywhere except next to the separatrix;
* ``exact``: ``4K(m)/√(1+x)`` (SciPy's ``ellipk``), the baseline any method must beat.

Each is checked against :func:`reference_period` (mpmath, 30 digits).  The solution q(t)
(``choose q``): the L–P series, the exact Fourier series in the nome (:func:`cn_fourier`) and
SciPy's cn, checked against cn.  The driven amplitudes (``choose amplitudes|response``): one
harmonic, the μ-expansion (its emitted module undamped, ``mu_expansion``, or for a finite Q,
``mu_expansion_damped``), harmonic balance and shooting, checked against shooting with
Richardson-combined RK4.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from types import ModuleType

import mpmath
import numpy as np
import sympy as sp
from numba import njit
from scipy.integrate import solve_ivp
from scipy.special import ellipj

from ..algebra.resum import (
    Resummed,
    resum_frequency,
    resum_harmonic,
    resum_relaxation,
    resum_series,
    van_der_pol_relaxation,
)
from ..analysis.driven import (
    Branch,
    Drive,
    amplitudes,
    balance_equations,
    damped_determinant,
    first_order_branches,
    harmonic_balance,
    mu_expansion,
    mu_expansion_damped,
    mu_expansion_exact,
    one_harmonic,
)
from ..derive.averaging import slow_flow
from ..derive.lindstedt import derive, derive_limit_cycle, nearest_singularity
from ..derive.models import Model, SelfExcited, check_order, duffing
from ..errors import InputError
from ..lower.lowering import (
    FOURIER_AGM_STEPS,
    MuDampedDerivation,
    MuDerivation,
    NotesTable,
    PeriodFormula,
    ResummedCurve,
    ResummedCycle,
    ResummedMathieu,
    ResummedTongue,
    Unit,
    agm_steps,
    horner,
    lower_balance,
    lower_choice,
    lower_cycle_derivation,
    lower_derivation,
    lower_driven,
    lower_driven_damped,
    lower_fourier,
    lower_free,
    lower_limit_cycle,
    lower_mathieu,
    lower_slow_flow,
    lower_tongue,
    x_,
)
from ..numerics.integrate import cycle_reference, cycle_samples, duffing_period_exact, shoot

Progress = Callable[[int, int], None]

MAX_ORDER = 60
# NOTE: order 60 of the exact series takes ~0.1 s and reaches 1e-16 wherever |x| ≤ 0.5.
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

def _mul(a: list[Fraction], b: list[Fraction]) -> list[Fraction]:
    """Product of power series truncated to ``len(a)`` terms."""
    return [sum(a[i] * b[n - i] for i in range(n + 1)) for n in range(len(a))]


def _compose(outer: list[Fraction], inner: list[Fraction]) -> list[Fraction]:
    """``outer(inner(t))`` truncated to ``len(outer)`` terms (``inner`` has no constant)."""
    total = [Fraction(0)] * len(outer)
    power = [Fraction(1)] + [Fraction(0)] * (len(outer) - 1)
    for c in outer:
        total = [s + c * p for s, p in zip(total, power, strict=True)]
        power = _mul(power, inner)
    return total


def resummed_coefficients(tau: list[Fraction]) -> list[Fraction]:
    """``c_n`` of ``(T/2π)(x(m)) / √(1 − 2m)``, ``x(m) = 2m/(1 − 2m) = Σ_{n≥1} 2^n m^n``,
    exactly; the first k + 1 terms use ``τ_0..τ_k``."""
    k = len(tau) - 1
    inv_sqrt = [Fraction(1)]
    for n in range(1, k + 1):  # (1 − 2m)^(−1/2) = Σ binom(2n, n) (m/2)^n·2^n
        inv_sqrt.append(inv_sqrt[-1] * Fraction(2 * n - 1, n))
    xm = [Fraction(0)] + [Fraction(2**n) for n in range(1, k + 1)]
    return _mul(_compose(tau, xm), inv_sqrt)


def modified_coefficients(omega: list[Fraction]) -> list[Fraction]:
    """The modified L–P of Cheung, Chen & Lau: ``ω² = (1 + 3x/4)·g(α)`` with
    ``α = (3x/4)/(1 + 3x/4)``, which stays below 1 for every ``x > 0``; returns ``g``'s
    coefficients exactly (``x(α) = (4/3) Σ_{n≥1} α^n``)."""
    k = len(omega) - 1
    w2 = _mul(omega, omega)
    h = _mul(w2, [Fraction(-3, 4) ** n for n in range(k + 1)])  # ω² / (1 + 3x/4)
    return _compose(h, [Fraction(0)] + [Fraction(4, 3)] * k)


def _pade(tau: list[Fraction], k: int) -> tuple[np.ndarray, np.ndarray]:
    with mpmath.workdps(60):
        p, q = mpmath.pade([mpmath.mpf(t.numerator) / t.denominator for t in tau[: 2 * k + 1]],
                           k, k)
        return np.array([float(c) for c in p]), np.array([float(c) for c in q])


@dataclass(frozen=True)
class PeriodSeries:
    """The exact L–P series of the free Duffing oscillator: ``τ_j`` and ``ω_j``."""

    tau: list[Fraction]
    omega: list[Fraction]


Coefficients = tuple[np.ndarray, np.ndarray]
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
        except ZeroDivisionError:  # no [k/k] approximant (e.g. a series in A with gaps)
            continue
    return found


def _agm_orders(s: PeriodSeries, top: int) -> list[tuple[int, Coefficients]]:
    return [(n, (NONE, ONE)) for n in range(AGM_STEPS + 1)]


def _exact_orders(s: PeriodSeries, top: int) -> list[tuple[int, Coefficients]]:
    return [(0, (NONE, ONE))]


# --- lowering: a period candidate as x-expressions ---------------------------------------------

_m = sp.Symbol("m")


def _rationals(values: np.ndarray) -> list[sp.Expr]:
    """The verified doubles as exact binary rationals."""
    return [sp.Rational(float(v)) for v in values]


def _lower_lp(c: Candidate) -> tuple[tuple, sp.Expr]:
    return (), horner(_rationals(c.num), x_)


def _lower_resummed(c: Candidate) -> tuple[tuple, sp.Expr]:
    return ((_m, x_ / (2 + 2 * x_)),), sp.sqrt(1 - 2 * _m) * horner(_rationals(c.num), _m)


def _lower_modified(c: Candidate) -> tuple[tuple, sp.Expr]:
    return (((_m, 3 * x_ / (4 + 3 * x_)),),
            1 / sp.sqrt((1 + sp.Rational(3, 4) * x_) * horner(_rationals(c.num), _m)))


def _lower_pade(c: Candidate) -> tuple[tuple, sp.Expr]:
    return (), horner(_rationals(c.num), x_) / horner(_rationals(c.den), x_)


def _lower_agm(c: Candidate) -> tuple[tuple, sp.Expr]:
    lines, mean = agm_steps(sp.sqrt(1 + x_), sp.sqrt(1 + x_ / 2), c.order, "")
    return tuple(lines), 1 / mean


def _not_lowered(c: Candidate) -> tuple[tuple, sp.Expr]:
    raise InputError("the exact period (SciPy's ellipk) has no compiled evaluator to emit; "
                     "loosen the tolerance or narrow the range")


# --- what a method applies to ------------------------------------------------------------------

def _free(subject: object) -> str | None:
    if not isinstance(subject, Model):
        return "a free oscillator's series: give an equation without a drive"
    return None


def _series_period(subject: object) -> str | None:
    """The L–P series and its Padé: the free Duffing oscillator, or a free polynomial one
    whose period is one exact rational series in one variable (every parameter given)."""
    if _free_duffing(subject) is None:
        return None
    return _polynomial_free(subject)


def _polynomial_free(subject: object) -> str | None:
    if not isinstance(subject, Model):
        return "a free oscillator's series: give an equation without a drive"
    if any(subject.velocity_forcing) or subject.elementary or subject.exact_to is not None:
        return ("its period is checked by quadrature of a polynomial potential: no velocity "
                "terms, no sin/sinh or Taylor-expanded force")
    values = [c for terms in subject.forcing for _, c in terms]
    if not all(sp.sympify(c).is_Rational for c in values):
        return ("its series must be one rational series in one variable: give every "
                "parameter a value (--param) and one power p = a + b - 1 or no eps")
    return None


def _free_duffing(subject: object) -> str | None:
    if not isinstance(subject, Model) or subject.name != "duffing" or subject.source:
        return ("its closed form is the free Duffing oscillator's (x = εA², the separatrix "
                "at x = -1)")
    return None


def _driven(subject: object) -> str | None:
    if not isinstance(subject, Drive):
        return "a driven oscillator's steady state: give a drive f cos(ωt)"
    return None


def _undamped(subject: object) -> str | None:
    if _driven(subject):
        return _driven(subject)
    if subject.damping != 0:
        return ("a finite Q: the undamped module has no q̇/Q term; the damped one is "
                "mu_expansion_damped's")
    return None


def _damped(subject: object) -> str | None:
    if _driven(subject):
        return _driven(subject)
    if subject.damping == 0:
        return ("the damped μ-expansion is for a finite Q (q̇/Q in the equation); Q = inf is "
                "the undamped mu_expansion's")
    return None


def _always(subject: object) -> str | None:
    return None


# --- emission: what `generate` derives and lowers ------------------------------------------------

@dataclass(frozen=True)
class Request:
    """One emission asked for: its order (or harmonics), the command that asked, and what the
    target needs besides (the free oscillator, the verified candidate and range)."""

    order: int
    command: str
    model: Model | SelfExcited | None = None
    allow_divergent: bool = False
    candidate: Candidate | None = None
    verified: tuple[float, float] = (0.0, 0.0)
    mathieu: tuple[str, int] | None = None  # (kind, m) of a Mathieu characteristic value
    tongue: tuple[str, int] | None = None  # (p(t) as text, n) of a tongue's transition curves
    resum_order: int | None = None  # a limit cycle's ω series for the radius and resummation


@dataclass(frozen=True)
class Target:
    """What a method emits: its files, and its derive and lower stages (the compiler calls
    each once, in order, then renders and writes)."""

    files: Callable[[Request], tuple[str, ...]]
    derive: Callable[[Request, Progress | None], object]
    lower: Callable[[object, Request], Unit]


def _free_files(r: Request) -> tuple[str, ...]:
    name = r.model.name
    return (f"{name}.py", f"{name}_tables.tex", f"{name}_derivation.tex")


def _free_derive(r: Request, progress: Progress | None) -> object:
    return derive(r.model, r.order + 2, progress)


def _free_lower(solution: object, r: Request) -> Unit:
    module = lower_free(solution, r.command, r.allow_divergent)
    return Unit(module, (lower_derivation(solution, r.order),))


def _cycle_files(r: Request) -> tuple[str, ...]:
    return (f"{r.model.name}.py", f"{r.model.name}_derivation.tex")


RADIUS_ORDER = 60
# NOTE: a limit cycle's radius is estimated from ω to at least this order (1 % from order 60
# for van der Pol), whatever order its evaluators sum.


def cycle_series_order(order: int, resum_order: int | None) -> int:
    """The order a limit cycle's exact series is derived to when its evaluators sum
    ``order``: ``resum_order`` when given (its radius estimate and resummed ω use every
    term), else :data:`RADIUS_ORDER`, and never below ``order + 2``."""
    return max(order + 2, RADIUS_ORDER if resum_order is None else resum_order)


def _cycle_derive(r: Request, progress: Progress | None) -> object:
    from ..derive.lindstedt import limit_cycles

    first = limit_cycles(r.model)[0]
    if not first.rational:
        raise InputError(f"{r.model.name}: the limit cycle's amplitude {first.amplitude} is "
                         "irrational: `lindstedt series` gives its exact series in "
                         f"Q({first.amplitude}); the evaluators and their resummation need "
                         "rational coefficients and are not emitted for it")
    lc = derive_limit_cycle(r.model, cycle_series_order(r.order, r.resum_order))
    return lc, resum_cycle(lc)


def _cycle_lower(derived: object, r: Request) -> Unit:
    import sys

    cycle, resummed = derived
    # NOTE: the exact coefficients pass Python's 4300-digit int → str limit from order ~150
    # (the module's OMEGA_EXACT, AMPLITUDE_EXACT and the LaTeX); lifted while lowering.
    limit = sys.get_int_max_str_digits()
    sys.set_int_max_str_digits(0)
    try:
        return Unit(lower_limit_cycle(cycle, r.command, r.order, resummed),
                    (lower_cycle_derivation(cycle, r.order),))
    finally:
        sys.set_int_max_str_digits(limit)


RESUM_TOLERANCE = 1e-6
# NOTE: the relative error the resummed limit-cycle evaluators are verified to (issue #13's
# target for 1 < ε ≤ 10); within |ε| ≤ 1 they are far better (3e-14 from order 60 on).
RESUM_RANGE = 10.0
RESUM_GRID = 400
RESUM_SPREAD_MARGIN = 10.0
# NOTE: the neighbour spread [L/M] − [L−1/M−1] underestimates van der Pol's true error by up
# to 7× at large ε (order 130): the dense grid asks the spread for tolerance/10, and the
# shooting references then check it.
RELAXATION_SPREAD_MARGIN = 1.0
# NOTE: for the relaxation form (resum.resum_relaxation) the spread is 0.3× (order 130) to
# 10× (order 164) van der Pol's true error at ε = 10 (benchmarks/resum_relaxation.py): the
# grid asks it for the tolerance itself, and the shooting checks at every integer ε and at
# the end decide (the error grows monotonically with ε on the measured grid).
RESUM_CHECKS = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0)
RELAXATION_TERMS = {
    frozenset({(0, 1, 1), (2, 1, -1)}): van_der_pol_relaxation,  # van der Pol
    frozenset({(0, 1, 1), (0, 3, Fraction(-1, 3))}): van_der_pol_relaxation,  # Rayleigh
}
# NOTE: the oscillators whose relaxation limit is known (Rayleigh's q̇ obeys van der Pol's
# equation, so the two share ω(ε)); keyed by the terms q^a q̇^b c of f(q, q̇).


def resum_cycle(lc: object, tolerance: float = RESUM_TOLERANCE) -> ResummedCycle | None:
    """The resummed ω(ε) of a limit cycle (:func:`resum.resum_relaxation` for the oscillators
    of :data:`RELAXATION_TERMS`, else :func:`resum.resum_frequency`) and its amplitude
    q(0) (Padé in ε², :func:`resum.resum_series`), each with the |ε| up to which it is
    verified: the neighbour spread below ``tolerance/margin`` on a dense grid of ``(0, 10]``, then
    DOP853 shooting (:func:`numerics.cycle_reference`) at the check points up to there and at
    its end, the domain cut at the last one passed when one fails.  None for a series with
    odd powers of ε or without a singularity estimate (the amplitude alone: None in it)."""
    import numpy as np

    est = nearest_singularity(lc.omega)
    if est is None or not est.variable.endswith("**2") or est.method != "Mercer–Roberts":
        return None
    relaxation = RELAXATION_TERMS.get(frozenset(
        (a, b, Fraction(c)) for a, b, c in getattr(lc.model, "terms", ())))
    try:
        form = (resum_relaxation(lc.omega, est.radius, est.angle, relaxation())
                if relaxation else resum_frequency(lc.omega, est.radius, est.angle))
    except InputError:
        return None
    refs: dict[float, object] = {}

    def reference(e: float) -> object:
        if e not in refs:
            refs[e] = cycle_reference(lc.model, e, guess=float(lc.amplitude[0]))
        return refs[e]

    omega = _verified(form, lambda e: 2 * np.pi / reference(e).period, tolerance,
                      RELAXATION_SPREAD_MARGIN if form.log is not None else RESUM_SPREAD_MARGIN)
    if omega is None:
        return None
    try:
        amplitude = resum_series(lc.amplitude, RESUM_RANGE)
    except InputError:
        amplitude = None
    amp = _verified(amplitude, lambda e: reference(e).q0, tolerance) if amplitude else None
    harmonics, q_verified = _resum_q(lc, form, tolerance, reference)
    return ResummedCycle(form, *omega, tolerance=tolerance,
                         amplitude=amplitude if amp else None,
                         amplitude_verified=amp if amp else (0.0, (), float("nan")),
                         harmonics=harmonics, harmonics_verified=q_verified)


HARMONIC_TAIL = 1e-3
# NOTE: q_resummed's harmonics are resummed in increasing n until two in a row stay below
# tolerance·HARMONIC_TAIL wherever the summed spread allows (van der Pol from order 100: ~40
# of its 201 cos/sin series); then the smallest are dropped while their largest values on the
# verified range add up to less than tolerance·HARMONIC_TAIL.
Q_SAMPLES = 64
# NOTE: q_resummed is checked against the shot cycle at this many times of one period.


def _resum_q(lc: object, form: Resummed, tolerance: float, reference: Callable
             ) -> tuple[tuple[tuple[str, int, Resummed], ...],
                        tuple[float, tuple[float, ...], float]]:
    """The Fourier coefficients of ``q(s)`` each resummed (:func:`resum.resum_harmonic`, in
    ω's ``w``) and the |ε| up to which their sum, at ``s = form(ε)·t``, is within
    ``tolerance`` of max |q| of the shot cycle over one period: the summed neighbour spread
    on the grid of :func:`resum_cycle`, then the shooting checks (nothing when ω's form has
    no ``w`` or no coefficient resums)."""
    none: tuple = ((), (0.0, (), float("nan")))
    if form.R is None:
        return none
    table: dict[tuple[str, int], list[Fraction]] = {}
    K = len(lc.q) - 1
    for j, (cos, sin) in enumerate(lc.q):
        for kind, part in (("cos", cos), ("sin", sin)):
            for n, c in part.items():
                table.setdefault((kind, n), [Fraction(0)] * (K + 1))[j] = Fraction(c)
    grid = np.linspace(0.0, RESUM_RANGE, RESUM_GRID + 1)[1:]
    spread = np.zeros_like(grid)
    forms: list[tuple[str, int, Resummed]] = []
    quiet = 0
    for n in sorted({n for _, n in table}):
        largest = 0.0
        for kind in ("cos", "sin"):
            if (kind, n) not in table:
                continue
            try:
                f = resum_harmonic(table[kind, n], form.R, form.p)
            except InputError:  # too few terms, or poles: left out, the checks decide
                continue
            forms.append((kind, n, f))
            spread = spread + np.nan_to_num(f.spread(grid), nan=np.inf)
            inside = grid[: _first_false(spread <= tolerance)]
            largest = max(largest, float(np.max(np.abs(f(inside)))) if inside.size else 0.0)
        quiet = quiet + 1 if largest <= tolerance * HARMONIC_TAIL else 0
        if quiet == 2:
            break
    end = _first_false(spread <= tolerance)
    if not forms or end == 0:
        return none
    inside = grid[:end]
    sizes = sorted(((float(np.max(np.abs(f(inside)))), i) for i, (_, _, f) in enumerate(forms)))
    dropped, total = set(), 0.0
    for size, i in sizes:
        if total + size > tolerance * HARMONIC_TAIL:
            break
        dropped.add(i)
        total += size
    forms = [h for i, h in enumerate(forms) if i not in dropped]

    def q(t: np.ndarray, e: float) -> np.ndarray:
        s = float(form(e)) * t
        return sum(f(e) * (np.cos(n * s) if kind == "cos" else np.sin(n * s))
                   for kind, n, f in forms)

    def error(e: float) -> float:
        t, truth = cycle_samples(lc.model, e, reference(e), Q_SAMPLES)
        return float(np.max(np.abs(q(t, e) - truth)) / np.max(np.abs(truth)))

    checked = _checked(round(float(inside[-1]), 12), error, tolerance)
    return (tuple(forms), checked) if checked else none


def _first_false(ok: np.ndarray) -> int:
    """The index of the first False in ``ok`` (its length when there is none)."""
    return int(np.argmin(ok)) if not ok.all() else len(ok)


def _checked(limit: float, error: Callable[[float], float], tolerance: float
             ) -> tuple[float, tuple[float, ...], float] | None:
    """``(limit, points, worst)``: ``error`` at the check points below ``limit`` and at
    ``limit`` itself, the domain cut at the last point passed when one misses ``tolerance``;
    None when the first misses."""
    points, worst = [], 0.0
    for e in [e for e in RESUM_CHECKS if e < limit] + [limit]:  # and the end itself
        err = error(e)
        if not err <= tolerance:
            limit = points[-1] if points else 0.0
            break
        points.append(e)
        worst = max(worst, err)
    return (float(limit), tuple(points), worst) if points else None


def _verified(form: Resummed, truth: Callable[[float], float], tolerance: float,
              margin: float = RESUM_SPREAD_MARGIN
              ) -> tuple[float, tuple[float, ...], float] | None:
    """``(limit, points, worst)`` of :func:`resum_cycle`'s rule, None if not even its first
    check point passes."""
    import numpy as np

    grid = np.linspace(0.0, RESUM_RANGE, RESUM_GRID + 1)[1:]
    end = _first_false(form.spread(grid) <= tolerance / margin)
    if end == 0:
        return None

    def error(e: float) -> float:
        value = truth(e)
        return abs(float(form(e)) - value) / abs(value)

    return _checked(round(float(grid[end - 1]), 12), error, tolerance)


MATHIEU_TOLERANCE = 1e-15
# NOTE: relative to max(1, |a|), about four units in the last place: the Padé value is the
# start of a Newton step on the determinant of the recurrence (numerics.mathieu_newton),
# verified against numerics.mathieu_refined (30 digits); SciPy's mathieu_a, mathieu_b are
# 2e-16 … 0.7 off (benchmarks/resum.py).
MATHIEU_START_TOLERANCE = 1e-9
# NOTE: the Padé value must be this close for one Newton step: the step squares the relative
# error (times |a| over the gap to the neighbouring eigenvalue, ≥ 1 here), so 1e-9 → ~1e-18.
MATHIEU_TRUNCATION = 1e-17
# NOTE: relative to max(1, |a|): the truncated recurrence's eigenvalue is within this of the
# infinite one (numerics.mathieu_truncation_bound), well below the rounding of a float64.
MATHIEU_NEWTON_STEPS = 1
MATHIEU_RANGE = 50.0
MATHIEU_GRID = 400
# NOTE: q ∈ (0, 50] on 400 points: beyond q ≈ 50 no Padé of an order-100 series is within
# 1e-9 (a_m(q) ~ −2q + 2(2m + 1)√q, a branch at infinity); the eigenvalue solver is the
# method there.


def mathieu_rows(kind: str, m: int, q: float, a: float) -> int:
    """The fewest rows of the recurrence whose eigenvalue is within ``MATHIEU_TRUNCATION``
    ·max(1, |a|) of the infinite one at ``q`` (:func:`numerics.mathieu_truncation_bound`)."""
    from ..numerics.integrate import mathieu_recurrence, mathieu_truncation_bound

    rows = mathieu_recurrence(kind, m, 1)[0] + 2
    while mathieu_truncation_bound(kind, m, q, a, rows) > MATHIEU_TRUNCATION * max(1.0, abs(a)):
        rows += 1
    return rows


MATHIEU_STARTS = (1.0, 0.75, 0.5, 0.4, 0.3, 0.2)
# NOTE: the Padé start is a measured choice, not the user's order: the near-diagonal Padé of
# the exact series truncated at ⌊f·order⌋ for each fraction f here is verified (Padé start
# within MATHIEU_START_TOLERANCE, refined value within the tolerance, the same grid and rule);
# the start kept is the one of fewest Padé degrees L + M whose limit is within one grid step
# of the longest found (a tie → the higher order).  The ufunc's time is the start's Horner
# pair and the Newton step's rows: for a_1 at order 100 the truncation at 50 ([21/29] in q)
# holds to q = 4.75 at 27 ns per point, the [50/50] of the whole series only to 2.625 at 93 ns
# (benchmarks/resum.py).


def _mathieu_verified(kind: str, m: int, form: Resummed, grid, ref, scale, tolerance: float
                      ) -> tuple[int, int, float]:
    """How many grid points from the first one ``form`` then the Newton step hold (the Padé
    start within ``MATHIEU_START_TOLERANCE``, the refined value within ``tolerance``), with
    the rows used and the largest error there (0 points: no rows, NaN)."""
    import numpy as np

    from ..numerics.integrate import mathieu_newton

    start = form(grid)
    ok = np.abs(start - ref) / scale <= MATHIEU_START_TOLERANCE
    n = int(np.argmin(ok)) if not ok.all() else len(grid)
    if n == 0:
        return 0, 0, float("nan")
    rows = 1 + max(mathieu_rows(kind, m, float(q), float(a)) for q, a in zip(grid[:n], ref[:n],
                                                                             strict=True))
    value = mathieu_newton(kind, m, grid[:n], start[:n], rows, MATHIEU_NEWTON_STEPS)
    error = np.abs(value - ref[:n]) / scale[:n]
    ok = error <= tolerance
    n = int(np.argmin(ok)) if not ok.all() else n
    return n, rows, float(error[:n].max()) if n else float("nan")


def resum_mathieu(kind: str, m: int, order: int, tolerance: float = MATHIEU_TOLERANCE
                  ) -> ResummedMathieu:
    """Padé of Mathieu's exact series (:func:`hill.mathieu_series`, in q², or in q when it
    has odd powers), then one Newton step on the determinant of the recurrence truncated to
    the rows :func:`mathieu_rows` asks for on the whole range (one row more, for between the
    grid points), verified on a dense grid of ``(0, 50]`` against
    :func:`numerics.mathieu_refined`: ``limit`` is the last grid point before the first
    where the Padé start misses ``MATHIEU_START_TOLERANCE`` or the refined value misses
    ``tolerance``.  The start is the series truncated at one of ``MATHIEU_STARTS`` × ``order``
    (the rule in its NOTE)."""
    import numpy as np

    from ..derive.hill import mathieu_series
    from ..numerics.integrate import mathieu_refined

    series = mathieu_series(kind, m, order)
    grid = np.linspace(0.0, MATHIEU_RANGE, MATHIEU_GRID + 1)[1:]
    ref = np.array([float(mathieu_refined(kind, m, float(q))) for q in grid])
    scale = np.maximum(1.0, np.abs(ref))
    found = []
    for k in sorted({int(f * order) for f in MATHIEU_STARTS}, reverse=True):
        try:
            form = resum_series(series[: k + 1], MATHIEU_RANGE)
        except InputError:
            continue
        n, rows, checked = _mathieu_verified(kind, m, form, grid, ref, scale, tolerance)
        if n:
            found.append((sum(form.approximant.degrees), -k, n, rows, checked, form))
    if not found:
        raise InputError(f"{kind}_{m}, order {order}: no resummed start is within "
                         f"{MATHIEU_START_TOLERANCE:g}, refined to {tolerance:g}, already at "
                         f"q = {grid[0]:g}; raise --order")
    longest = max(c[2] for c in found)
    _, _, n, rows, checked, form = min(c for c in found if c[2] >= longest - 1)
    return ResummedMathieu(kind, m, order, form, float(grid[n - 1]), tolerance, checked, rows,
                           MATHIEU_NEWTON_STEPS)


def _mathieu_files(r: Request) -> tuple[str, ...]:
    kind, m = r.mathieu
    return (f"mathieu_{kind}{m}.py",)


def _mathieu_derive(r: Request, progress: Progress | None) -> object:
    kind, m = r.mathieu
    return resum_mathieu(kind, m, r.order)


def _mathieu_lower(derived: object, r: Request) -> Unit:
    return Unit(lower_mathieu(derived, r.command))


TONGUE_TOLERANCE = 1e-10
# NOTE: absolute, in δ.  The boundary is brentq on |tr M| − 2 with the compiled RK4 monodromy
# at TONGUE_STEPS and twice as many; a grid point counts only where the two agree to
# TONGUE_TOLERANCE / 10 (measured for p = cos t + cos 2t/2, n = 1: ≤ 5e-13 up to ε = 3).
TONGUE_STEPS = 4096
TONGUE_RADII = 3.0
TONGUE_RANGE = 10.0
TONGUE_GRID = 240
# NOTE: each curve is verified on 240 points of (0, ε_max], ε_max = 3 × its estimated radius
# (lindstedt.nearest_singularity; TONGUE_RANGE without an estimate), capped at 10: past a few
# radii no near-diagonal Padé of an order-30 series holds 1e-10.  At each point |tr M| − 2
# must change sign between δ ∓ b (b = the tolerance, or half the distance to another curve if
# less: the curves of tongue n split at ε^n only), which puts a boundary within the
# tolerance; the root by linear interpolation there (|tr M| is smooth on 2b ≤ 2e-10) is the
# measured error.  Four monodromies a point in four vectorised calls, no root search: 240
# points cost what 24 brentq searches did.


def boundary_bracket(p: dict[int, tuple[float, float]], eps: np.ndarray, near: np.ndarray,
                     bracket: np.ndarray, steps: int) -> np.ndarray:
    """The δ in ``near ± bracket`` where ``|tr M| = 2`` at each ``eps`` (the sign change of
    ``|tr M| − 2`` between the two ends of :func:`numerics.floquet_traces`, the root by linear
    interpolation), NaN where the sign does not change (no boundary or two in the bracket)."""
    from ..numerics.integrate import floquet_traces

    below, above = (np.abs(floquet_traces(near + s * bracket, eps, p, steps=steps)[0]) - 2
                    for s in (-1, 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        root = near - bracket + 2 * bracket * below / (below - above)
    return np.where(below * above < 0, root, np.nan)


def resum_tongue(text: str, n: int, order: int, tolerance: float = TONGUE_TOLERANCE
                 ) -> ResummedTongue:
    """Each transition curve of tongue ``n`` of ``ẍ + (δ + ε p(t))x = 0`` (``p`` as text) as
    the Padé of its exact series (:func:`hill.transition_curves`, :func:`resum.resum_series`),
    verified against the Floquet boundary (:func:`boundary_bracket` at ``TONGUE_STEPS`` and
    twice as many, agreeing to ``tolerance / 10``) on ``TONGUE_GRID`` points of
    ``(0, ε_max]``: ``limit`` is the last grid point before the first miss.
    :class:`InputError` if a curve misses at the first point."""
    import numpy as np

    from ..derive.hill import fourier_of_text, transition_curves

    harmonics = fourier_of_text(text)
    p = {k: (float(a), float(b)) for k, (a, b) in harmonics.items()}
    series = transition_curves(harmonics, n, order).curves
    tops, forms = [], []
    for curve in series:
        est = nearest_singularity(list(curve.delta), "eps", None)
        radius = (math.sqrt(est.radius) if est.variable == "eps**2" else est.radius
                  ) if est else TONGUE_RANGE
        tops.append(min(TONGUE_RADII * radius, TONGUE_RANGE))
        forms.append(resum_series(list(curve.delta), tops[-1]))
    curves = []
    for i, (curve, top, form) in enumerate(zip(series, tops, forms, strict=True)):
        grid = np.linspace(0.0, top, TONGUE_GRID + 1)[1:]
        values = form(grid)
        bracket = np.full(grid.size, tolerance)
        for j, other in enumerate(forms):
            if j != i:
                bracket = np.minimum(bracket, np.abs(other(grid) - values) / 2)
        usable = np.isfinite(values) & (bracket > 0)  # NaN in floquet_traces is an InputError
        near, bracket = np.where(usable, values, 0.0), np.where(usable, bracket, tolerance)
        ref, finer = (boundary_bracket(p, grid, near, bracket, steps)
                      for steps in (TONGUE_STEPS, 2 * TONGUE_STEPS))
        error = np.abs(values - finer)
        held = usable & (np.abs(ref - finer) <= tolerance / 10) & (error <= tolerance)
        count = grid.size if held.all() else int(np.argmin(held))
        if count == 0:
            raise InputError(f"tongue {n} of p(t) = {text!r}, curve {curve.label}: the "
                             f"resummed series misses the Floquet boundary by more than "
                             f"{tolerance:g} already at eps = {grid[0]:g}; raise --order (or "
                             "the curves coincide: a closed tongue)")
        curves.append(ResummedCurve(curve.label, form, round(float(grid[count - 1]), 12),
                                    float(error[:count].max())))
    return ResummedTongue(text, n, order, tolerance, tuple(curves))


def _tongue_derive(r: Request, progress: Progress | None) -> object:
    text, n = r.tongue
    return resum_tongue(text, n, r.order)


def _tongue_lower(derived: object, r: Request) -> Unit:
    return Unit(lower_tongue(derived, r.command))


NOTES_DRIVE = (0.1, 1.0, 1.0)
# NOTE: ε, f, ω of the notes' table (§10.4, undamped), reproduced in every driven derivation.
NOTES_TABLE_ORDERS = 6


def notes_table() -> NotesTable:
    """The notes' table: A₁, A₃, A₅ by μ-order, harmonic balance and shooting."""
    eps, force, omega = NOTES_DRIVE
    d = Drive(eps, force, omega)
    (branch,) = first_order_branches(d)
    mu = mu_expansion(d, branch, NOTES_TABLE_ORDERS)

    def cells(A: dict) -> tuple[tuple[int, float | str], ...]:
        return tuple((n, A[n] if A.get(n) else "") for n in (1, 3, 5))

    rows = [(f"$\\mu$-expansion, order {j}", cells(amplitudes(*mu.partial(j), 2 * j + 1)[0]))
            for j in range(NOTES_TABLE_ORDERS + 1)]
    hb = harmonic_balance(d, branch, 8)
    A, _ = amplitudes(hb.coefficients, 0.0, 15)
    rows.append(("harmonic balance, $N = 8$", cells(A)))
    orbit = shoot(eps, force, omega, 0.0, np.array([sum(A.values()), 0.0]))
    rows.append(("numerical (shooting)", cells(orbit.A)))
    rows.append(("notes: numerical", ((1, "2.356"), (3, "0.0456"), (5, "0.0008"))))
    return NotesTable(eps, force, omega, tuple(rows))


def _mu_derive(r: Request, progress: Progress | None) -> object:
    return mu_expansion_exact(r.order), notes_table()


def _mu_lower(derived: object, r: Request) -> Unit:
    orders, table = derived
    return Unit(lower_driven(orders, r.command), (MuDerivation(r.order, orders, table),))


def _balance_derive(r: Request, progress: Progress | None) -> object:
    return balance_equations(r.order)


def _balance_lower(eqs: object, r: Request) -> Unit:
    return Unit(lower_balance(eqs, r.command))


def _fourier_derive(r: Request, progress: Progress | None) -> object:
    harmonics = r.order
    if isinstance(harmonics, bool) or not isinstance(harmonics, int) or not 1 <= harmonics <= 60:
        raise InputError(f"harmonics {harmonics!r}: must be an integer in 1..60")
    return harmonics  # closed form: nothing to derive but the count


def _fourier_lower(harmonics: object, r: Request) -> Unit:
    return Unit(lower_fourier(harmonics, r.command))


def _choice_derive(r: Request, progress: Progress | None) -> object:
    return r.candidate  # derived and verified by choose


def _choice_lower(c: object, r: Request) -> Unit:
    return Unit(lower_choice(c.method.formula(c), r.command, r.verified))


FREE = Target(_free_files, _free_derive, _free_lower)
LIMIT_CYCLE = Target(_cycle_files, _cycle_derive, _cycle_lower)
MU = Target(lambda r: ("driven.py", "driven_derivation.tex"), _mu_derive, _mu_lower)
BALANCE = Target(lambda r: ("balance.py",), _balance_derive, _balance_lower)


DAMPED_MAX = 11
# NOTE: the damped μ-expansion is emitted at orders 1..11 (its derivation's bound, one order
# more estimates the truncation error); interpreted, it is the float μ-expansion's solve.


def _mu_damped_derive(r: Request, progress: Progress | None) -> object:
    if isinstance(r.order, bool) or not isinstance(r.order, int) or not 1 <= r.order <= DAMPED_MAX:
        raise InputError(f"order {r.order!r}: the damped μ-expansion is emitted at orders "
                         f"1..{DAMPED_MAX}")
    return mu_expansion_damped(r.order + 1)  # one order more: the truncation error's estimate


def _mu_damped_lower(orders: object, r: Request) -> Unit:
    return Unit(lower_driven_damped(orders, r.command),
                (MuDampedDerivation(r.order, orders[: r.order], damped_determinant()),))


MU_DAMPED = Target(lambda r: ("driven_damped.py", "driven_damped_derivation.tex"),
                   _mu_damped_derive, _mu_damped_lower)
FOURIER = Target(lambda r: ("fourier.py",), _fourier_derive, _fourier_lower)
CHOSEN_PERIOD = Target(lambda r: ("chosen_period.py",), _choice_derive, _choice_lower)
SLOW_FLOW = Target(lambda r: (f"{r.model.name}_slow_flow.py", f"{r.model.name}_slow_flow.tex"),
                   lambda r, progress: slow_flow(r.model, r.order),
                   lambda flow, r: lower_slow_flow(flow, r.command))
# NOTE: the slow flow's request carries the user's models.Oscillator as its model.
MATHIEU = Target(_mathieu_files, _mathieu_derive, _mathieu_lower)
TONGUE = Target(lambda r: (f"tongue_{r.tongue[1]}.py",), _tongue_derive, _tongue_lower)


# --- driven: one method at one order at one ω ---------------------------------------------------

Solved = tuple[bool, tuple[dict, dict]]


def _solve_mu(d: Drive, branch: Branch, order: int) -> Solved:
    mu = mu_expansion(d, branch, order)
    ok = len(mu.coefficients) > order and mu.converged
    return ok, amplitudes(*mu.partial(min(order, len(mu.coefficients) - 1)), 5)


def _solve_balance(d: Drive, branch: Branch, order: int) -> Solved:
    hb = harmonic_balance(d, branch, order)
    return hb.converged, amplitudes(hb.coefficients, 0.0, 5)


def _solve_shooting(d: Drive, branch: Branch, order: int) -> Solved:
    guess = branch.A1 * np.array([np.cos(branch.delta0), d.omega * np.sin(branch.delta0)])
    orbit = shoot(d.eps, d.force, d.omega, d.damping, guess, steps=order)
    return (True, (orbit.A, orbit.B)) if orbit is not None else (False, ({}, {}))


Emitted = tuple[np.ndarray, np.ndarray, Callable[[], object], int]


def _run_mu_module(mod: ModuleType, omega: np.ndarray, eps: float, force: float, Q: float,
                   order: int) -> Emitted:
    """A_1, A_3, A_5 of an emitted μ-expansion module at ``omega`` (B_n = 0: undamped), and a
    run over 10⁵ ω through the ``_into`` twins to time."""
    n = omega.size
    A, B = np.zeros((n, 3)), np.zeros((n, 3))  # harmonics the module lacks are zero
    fns = {k: getattr(mod, f"A_{h}_into") for k, h in enumerate((1, 3, 5))
           if hasattr(mod, f"A_{h}_into")}  # the order's harmonics; the rest stay 0
    for k, f in fns.items():
        A[:, k] = f(np.empty(n), omega, eps, force, 0.0)
    dense = np.resize(omega, 100_000)
    buf = np.empty_like(dense)
    return A, B, lambda: [f(buf, dense, eps, force, 0.0) for f in fns.values()], dense.size


def _run_mu_damped_module(mod: ModuleType, omega: np.ndarray, eps: float, force: float,
                          Q: float, order: int) -> Emitted:
    """A_n, B_n (n = 1, 3, 5) of an emitted damped μ-expansion module at ``omega`` on the
    largest branch (NaN outside its verified domain), and a run over 10⁵ ω to time."""
    n = omega.size
    A, B = np.zeros((n, 3)), np.zeros((n, 3))  # harmonics the module lacks are zero
    fns = {(k, c): getattr(mod, f"{c}_{h}_into") for k, h in enumerate((1, 3, 5)) for c in "AB"
           if hasattr(mod, f"{c}_{h}_into")}
    for (k, c), f in fns.items():
        (A if c == "A" else B)[:, k] = f(np.empty(n), omega, eps, force, Q, 0.0)
    dense = np.resize(omega, 100_000)
    buf = np.empty_like(dense)
    return A, B, lambda: [f(buf, dense, eps, force, Q, 0.0) for f in fns.values()], dense.size


def _run_balance_module(mod: ModuleType, omega: np.ndarray, eps: float, force: float, Q: float,
                        order: int) -> Emitted:
    """A_n, B_n of an emitted balance module: its compiled Newton, one solve per ω from the
    one-harmonic root; and a run over every ω to time."""
    n = omega.size
    A, B = np.zeros((n, 3)), np.zeros((n, 3))
    a1, b1 = one_harmonic_amplitudes(eps, force, Q, omega)
    x0 = np.zeros((n, 2 * order))
    x0[:, 0], x0[:, order] = a1, b1
    damping = Drive(eps, force, 1.0, Q).damping
    xs = [mod.newton(x, w, eps, force, damping)[0] for x, w in zip(x0, omega, strict=True)]
    for k in range(min(order, 3)):
        A[:, k] = [x[k] for x in xs]
        B[:, k] = [x[order + k] for x in xs]
    return A, B, lambda: [mod.newton(x, w, eps, force, damping)
                          for x, w in zip(x0, omega, strict=True)], n


def one_harmonic_amplitudes(eps: float, force: float, Q: float,
                            omegas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``A₁ = r cos δ₀``, ``B₁ = r sin δ₀`` of the largest one-harmonic branch, vectorised
    (:func:`driven.one_harmonic`)."""
    A, delta = one_harmonic(eps, force, Q, omegas)
    return A[:, 0] * np.cos(delta[:, 0]), A[:, 0] * np.sin(delta[:, 0])


DRIVEN_MAX = 12
# NOTE: μ-orders 0..12 and 1..12 odd harmonics: at the notes' parameters both reach 1e-12
# well before that; more only costs.
SHOOTING_STEPS = (64, 128, 256, 512, 1024)
# NOTE: the "numerical" method: shooting from the one-harmonic guess with plain RK4 at these
# steps per period (the truth uses 4096 and 8192, Richardson-combined).


# --- references ----------------------------------------------------------------------------------

def reference_period(x: np.ndarray) -> np.ndarray:
    """``T/2π = (2/π) K(m)/√(1+x)`` in 30-digit arithmetic (mpmath): the judge of every
    candidate, SciPy's ``ellipk`` included."""
    with mpmath.workdps(30):
        return np.array([float(2 / mpmath.pi * mpmath.ellipk(mpmath.mpf(v) / (2 * (1 + v)))
                               / mpmath.sqrt(1 + mpmath.mpf(v))) for v in x])


QUADRATURE_NODES = 256
# NOTE: Gauss–Legendre nodes in θ (u = m + h sin θ between the turning points): the integrand
# is analytic there for simple turning points, and 256 nodes meet the Duffing oscillator's
# elliptic period to 1e-15 for |x| ≤ 0.9 (tests/test_choose.py).


def quadrature_period(model: Model, x: np.ndarray) -> np.ndarray:
    """``T/2π`` of a free polynomial oscillator at ``y = x`` by quadrature, independent of the
    series: its scaled form ``u'' + u + Σ_k x^k Σ_n c_kn u^n = 0`` (time in units of 1/ω₀,
    ``u(0) = 1``) has the potential ``V(u) = u²/2 + Σ x^k c_kn u^(n+1)/(n+1)``, and
    ``T = 2∫ du/√(2(V(1) − V(u)))`` from the turning point below 1 (the largest root of
    ``V(u) = V(1)`` under 1) up to 1.  NaN where the motion from u = 1 is unbounded (no
    turning point below) or 1 is no turning point."""
    theta, weights = np.polynomial.legendre.leggauss(QUADRATURE_NODES)
    theta, weights = theta * np.pi / 2, weights * np.pi / 2
    out = np.full(x.shape, np.nan)
    for i, xv in enumerate(np.asarray(x, dtype=float)):
        V = np.zeros(2)  # V(u) low to high
        V = np.polynomial.polynomial.polyadd(V, [0.0, 0.0, 0.5])
        for k, terms in enumerate(model.forcing, start=1):
            for n, c in terms:
                coeff = np.zeros(n + 2)
                coeff[n + 1] = float(c) * xv**k / (n + 1)
                V = np.polynomial.polynomial.polyadd(V, coeff)
        dV = np.polynomial.polynomial.polyder(V)
        if np.polynomial.polynomial.polyval(1.0, dV) <= 0:
            continue  # u = 1 is no turning point of a bounded swing
        level = np.polynomial.polynomial.polyval(1.0, V)
        shifted = np.polynomial.polynomial.polysub(V, [level])
        roots = np.polynomial.polynomial.polyroots(shifted)
        below = sorted(r.real for r in roots if abs(r.imag) < 1e-9 and r.real < 1 - 1e-9)
        if not below:
            continue
        u_min = below[-1]
        if np.polynomial.polynomial.polyval(u_min, dV) >= 0:
            continue  # the swing does not turn there: it escapes
        for _ in range(3):  # Newton polish of the turning point
            u_min -= (np.polynomial.polynomial.polyval(u_min, shifted)
                      / np.polynomial.polynomial.polyval(u_min, dV))
        # V(1) − V(u) = (1 − u)(u − u_min) S(u), and with u = m + h sin θ the product
        # (1 − u)(u − u_min) = h² cos²θ cancels du = h cos θ dθ: T = 2∫ dθ/√(2 S(u)),
        # smooth, with no difference of nearly equal numbers near the turning points
        S, _ = np.polynomial.polynomial.polydiv(
            shifted, np.polynomial.polynomial.polyfromroots([1.0, u_min]))
        u = (1 + u_min) / 2 + (1 - u_min) / 2 * np.sin(theta)
        s_u = np.polynomial.polynomial.polyval(u, S)
        if np.any(s_u <= 0):
            continue  # another turning point between: no swing between these two
        out[i] = 2 * float(np.sum(weights / np.sqrt(2 * s_u))) / (2 * np.pi)
    return out


def reference_q(t: np.ndarray, x: float) -> np.ndarray:
    """``q/A = cn(√(1+x) t | m)``, ``m = x/(2(1+x))``: SciPy for m ≥ 0, mpmath below."""
    m = x / (2 * (1 + x))
    if m >= 0:
        return ellipj(np.sqrt(1 + x) * t, m)[1]
    with mpmath.workdps(20):
        return np.array([float(mpmath.re(mpmath.ellipfun("cn", np.sqrt(1 + x) * v, m)))
                         for v in t])


INTEGRATION_RTOLS = (1e-4, 1e-7, 1e-10, 1e-13)
# NOTE: DOP853 tolerances for the "numerical" method: from plotting accuracy to nearly exact.


def integrated_period(x: float, rtol: float) -> float:
    """``T/2π`` by integrating ``u'' + u + x u³ = 0`` from ``u = 1`` to the half period
    (``u'`` back to zero), SciPy's DOP853 at ``rtol``."""
    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], -y[0] - x * y[0] ** 3]

    def half(_t: float, y: np.ndarray) -> float:
        return y[1]

    half.terminal, half.direction = True, 1.0
    sol = solve_ivp(rhs, (0.0, 100.0 / np.sqrt(1 + max(x, 0.0)) + 100.0), [1.0, 0.0],
                    method="DOP853", rtol=rtol, atol=rtol * 1e-3, events=half)
    return float(2 * sol.t_events[0][0] / (2 * np.pi))


# --- the records ---------------------------------------------------------------------------------

Lowered = tuple[tuple, sp.Expr]


@dataclass(frozen=True, eq=False)
class Method:
    """One method for one quantity.  A method is known by its name: it compares equal to it
    (``choice.method == "agm"``) and prints as it, so tables and JSON show the name."""

    name: str
    quantity: str  # "period", "q" or "driven"
    about: str
    reference: str  # what its answers are checked against
    applies: Callable[[object], str | None] = _always  # why not, for a Model or a Drive
    kind: int = -1  # period: the compiled kernel's branch (-1: SciPy's ellipk)
    steps: bool = False  # period: the order counts steps, not terms (listed first)
    domain: sp.Basic = sp.true  # period: where the formula holds, in x_
    orders: Callable[[PeriodSeries, int], list[tuple[int, Coefficients]]] | None = None
    lowered: Callable[[Candidate], Lowered] = _not_lowered
    solve: Callable[[Drive, Branch, int], Solved] | None = None  # driven: one ω, one order
    driven_orders: tuple[int, ...] = ()
    target: Target | None = None  # what `generate` / `--emit` writes for it
    bound: int = -1  # driven: which of ``choose``'s emit bounds caps its order (-1: none)
    run_emitted: Callable[..., Emitted] | None = None  # driven: read its emitted module
    emittable: Callable[[object], str | None] = _always  # why its module cannot be emitted
    describe: Callable[[int], str] | None = None  # its name at an order (default: "NAME order K")

    def label(self, order: int) -> str:
        """What the method is at ``order``, as tables print it ("lindstedt order 8",
        "[12/12] Padé, 25 coefficients")."""
        return self.describe(order) if self.describe is not None else f"{self.name} order {order}"

    def why_not(self, subject: object) -> str | None:
        """None when the method applies to ``subject`` (a Model or a Drive), else why not."""
        return self.applies(subject)

    def evaluate(self, c: Candidate, x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """``T/2π`` of candidate ``c`` at ``x`` (period methods)."""
        if self.kind < 0:
            return duffing_period_exact(1.0, x) / (2 * np.pi)
        out = np.empty_like(x) if out is None else out
        _evaluate(self.kind, c.num, c.den, c.order, x, out, c.masked)
        return out

    def formula(self, c: Candidate) -> PeriodFormula:
        """Candidate ``c`` lowered: its assignments and value in x_, inside the domain."""
        body, value = self.lowered(c)
        return PeriodFormula(self.name, c.order, self.domain, body, value,
                             tuple(float(v) for v in c.num), tuple(float(v) for v in c.den))

    @property
    def rank(self) -> int:
        """Ties of cost go to the simplest formula: its place in :data:`SIMPLEST_FIRST`."""
        return SIMPLEST_FIRST.index(self.name)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Method):
            return (self.name, self.quantity) == (other.name, other.quantity)
        return isinstance(other, str) and self.name == other

    def __hash__(self) -> int:
        return hash(self.name)

    def __str__(self) -> str:
        return self.name

    def __format__(self, spec: str) -> str:
        return format(self.name, spec)


SIMPLEST_FIRST = ("lindstedt", "one_harmonic", "pade", "resummed", "modified", "agm",
                  "mu_expansion", "mu_expansion_damped", "harmonic_balance", "fourier",
                  "shooting", "exact")
# NOTE: the tie order of methods (the simplest formula first).

_PERIOD = "free Duffing T/2π against mpmath's K(m) at 30 digits"
_Q = "free Duffing q(t)/A against cn (SciPy's ellipj for m ≥ 0, mpmath below)"
_DRIVEN = "A₁, A₃, A₅ and B_n against shooting (RK4, Richardson-combined, Floquet-checked)"

METHODS: tuple[Method, ...] = (
    # the period, in the order its candidates are listed
    Method("exact", "period", "4K(m)/√(1+x), SciPy's ellipk", _PERIOD, _free_duffing,
           steps=True, orders=_exact_orders),
    Method("agm", "period", "1/AGM(√(1+x), √(1+x/2)), n steps", _PERIOD, _free_duffing,
           kind=4, steps=True, domain=x_ > -1, orders=_agm_orders, lowered=_lower_agm,
           target=CHOSEN_PERIOD),
    Method("lindstedt", "period", "the L–P series Σ τ_j x^j", _PERIOD, _series_period,
           kind=0, domain=sp.And(x_ > -1, sp.Abs(x_) < 1), orders=_lp_orders,
           lowered=_lower_lp, target=CHOSEN_PERIOD),
    Method("resummed", "period", "the series in m = x/(2(1+x)) times √(1 − 2m)", _PERIOD,
           _free_duffing, kind=1, domain=x_ > sp.Rational(-2, 3), orders=_resummed_orders,
           lowered=_lower_resummed, target=CHOSEN_PERIOD),
    Method("modified", "period", "modified L–P (Cheung, Chen & Lau)", _PERIOD, _free_duffing,
           kind=3, domain=x_ > -1, orders=_modified_orders, lowered=_lower_modified,
           target=CHOSEN_PERIOD),
    Method("pade", "period", "diagonal Padé [k/k] of the L–P series", _PERIOD, _series_period,
           kind=2, domain=x_ > -1, orders=_pade_orders, lowered=_lower_pade,
           target=CHOSEN_PERIOD, describe=lambda k: f"[{k}/{k}] Padé, {2 * k + 1} coefficients"),
    # q(t)
    Method("lindstedt", "q", "the L–P series of q(t) (generate NAME)",
           "q(t) against cn; any free oscillator's period against quadrature", _free,
           target=FREE),
    Method("fourier", "q", "the exact Fourier series of cn in the nome, N odd harmonics", _Q,
           _free_duffing, target=FOURIER),
    Method("exact", "q", "cn by SciPy's ellipj (x ≥ 0; no emitted evaluator)", _Q,
           _free_duffing),
    # the driven amplitudes A_n(ω) and the response r(ω)
    Method("one_harmonic", "driven", "the one-harmonic cubic in closed form", _DRIVEN,
           _driven, driven_orders=(1,)),
    Method("mu_expansion", "driven", "the μ-expansion with phase, order K", _DRIVEN, _driven,
           solve=_solve_mu, driven_orders=tuple(range(DRIVEN_MAX + 1)), target=MU,
           bound=0, run_emitted=_run_mu_module, emittable=_undamped),
    Method("mu_expansion_damped", "driven",
           "the μ-expansion with phase for a finite Q, exact orders (generate driven --damped)",
           _DRIVEN, _damped, solve=_solve_mu, driven_orders=tuple(range(1, DAMPED_MAX + 1)),
           target=MU_DAMPED, bound=0, run_emitted=_run_mu_damped_module, emittable=_damped),
    Method("harmonic_balance", "driven", "Galerkin harmonic balance, N odd harmonics", _DRIVEN,
           _driven, solve=_solve_balance, driven_orders=tuple(range(1, DRIVEN_MAX + 1)),
           target=BALANCE, bound=1, run_emitted=_run_balance_module),
    Method("shooting", "driven", "shooting with plain RK4, N steps a period", _DRIVEN, _driven,
           solve=_solve_shooting, driven_orders=SHOOTING_STEPS),
)


def method(quantity: str, name: str) -> Method:
    """The record of ``name`` for ``quantity``."""
    for m in METHODS:
        if m.quantity == quantity and m.name == name:
            return m
    raise KeyError(f"no method {name!r} for {quantity}")


def methods_for(quantity: str, subject: object | None = None) -> tuple[Method, ...]:
    """The methods of ``quantity`` (that apply to ``subject``, when given), in registry order."""
    return tuple(m for m in METHODS if m.quantity == quantity
                 and (subject is None or m.why_not(subject) is None))


# --- period candidates: every method at every order ----------------------------------------------

@dataclass(frozen=True)
class Candidate:
    """One period method at one order with its coefficients (as verified doubles)."""

    method: Method
    order: int
    num: np.ndarray
    den: np.ndarray
    masked: bool = True  # NaN outside the free Duffing oscillator's domain (see _evaluate)

    def __call__(self, x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        return self.method.evaluate(self, x, out)


def period_series(max_order: int, model: Model | None = None) -> PeriodSeries:
    """The exact τ_j and ω_j of ``model`` (the free Duffing oscillator by default)."""
    sol = derive(model or duffing(), check_order(max_order))
    return PeriodSeries([sol.ground.to_fraction(c) for c in sol.period],
                        [sol.ground.to_fraction(c) for c in sol.omega])


@functools.cache
def candidates(max_order: int = MAX_ORDER, model: Model | None = None
               ) -> tuple[Candidate, ...]:
    """Every period method at every order up to ``max_order`` (Padé up to [12/12]) for
    ``model`` (the free Duffing oscillator by default), derived once: the fixed-order ones
    (exact, the AGM's steps) first, then order by order."""
    subject = model or duffing()
    series = period_series(max_order, subject)
    masked = model is None or _free_duffing(model) is None
    found = []
    for rank, m in enumerate(methods_for("period", subject)):
        for order, (num, den) in m.orders(series, max_order):
            found.append(((not m.steps, 0 if m.steps else order, rank),
                          Candidate(m, order, num, den, masked)))
    found.sort(key=lambda item: item[0])
    return tuple(c for _, c in found)
