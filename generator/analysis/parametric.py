"""The parametrically driven oscillator ``q̈ + 2ζq̇ + (1 + ε cos 2ωt)q + γq³ = 0``: its 1:1
response at half the pump's frequency inside the first tongue, all branches and their stability.

One harmonic, ``q = a cos ωt + b sin ωt`` (:func:`parametric_secular`), with
``κ = 1 − ω² + ¾γr²``::

    (κ + ε/2) a + 2ζω b = 0,      −2ζω a + (κ − ε/2) b = 0.

Besides ``a = b = 0`` (the trivial branch) a solution needs the determinant
``κ² − ε²/4 + 4ζ²ω² = 0``: ``κ = ±s``, ``s = √(ε²/4 − 4ζ²ω²)``, i.e.

    r² = (4/(3γ)) [(ω² − 1) ± s]      (the branches "+" and "−", where r² ≥ 0).

The trivial branch is unstable inside the tongue ``(1 − ω²)² < s²``, whose edges are
``ω² = 1 − 2ζ² ± √((1 − 2ζ²)² − 1 + ε²/4)`` (``1 ± ε/2`` undamped; the true edges of the
undamped tongue are ``1 ± ε/2 + ε²/32 + O(ε³)``, Mathieu's ``a₁``, ``b₁``).  The slow flow
``ȧ = P_s/(2ω)``, ``ḃ = −P_c/(2ω)`` (``P`` the balance residual) has trace ``−2ζ`` and
determinant ``det ∂P/∂(a, b) / (4ω²) = 3γκr² / (4ω²)`` on a nontrivial branch: the branch with
``γκ > 0`` is stable, the other a saddle.  So for ``γ > 0`` the "+" branch leaves ``r = 0`` at
the lower edge into the tongue (supercritical) and the "−" branch at the upper edge out of it
(subcritical, unstable); for ``γ < 0`` the sides swap.  They meet at the fold ``s = 0``,
``ω = ε/(4ζ)``, ``r² = 4(ω² − 1)/(3γ)`` where that is positive.

Beyond one harmonic: :class:`ParametricBalance` (the alternating-frequency/time balance of
:class:`driven.PolynomialBalance` with the pump), shooting (:func:`numerics.shoot_table` with
the pump as an ``extra`` row) as the truth, and the full Hill equation
(:func:`numerics.orbit_hill_multipliers`) for the stability of a balance orbit.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..algebra.series import trig_power
from ..errors import InputError
from ..limits import MAGNITUDES, MAX_HARMONICS, PARAMETRIC_MAX_POINTS, check_int
from ..numerics.floquet import multipliers_stable, orbit_hill_multipliers
from ..numerics.integrate import ForceTable
from ..numerics.shooting import PeriodicOrbit, shoot_table
from .continuation import Onset
from .polynomial import PolynomialBalance

_a, _b, _w, _e, _z, _g = sp.symbols("a b omega epsilon zeta gamma")


@functools.cache
def parametric_secular() -> tuple[sp.Expr, sp.Expr]:
    """The cos ωt and sin ωt coefficients of ``q̈ + 2ζq̇ + (1 + ε cos 2ωt)q + γq³`` for
    ``q = a cos ωt + b sin ωt``, by the exact Fourier kernel (:func:`series.trig_power`);
    ``q cos 2ωt`` by product to sum: ``(a/2)(cos ωt + cos 3ωt) + (b/2)(sin 3ωt − sin ωt)``."""
    cube_cos, cube_sin = trig_power({1: _a}, {1: _b}, 3)
    cos_eq = (1 - _w**2) * _a + 2 * _z * _w * _b + _e * _a / 2 + _g * cube_cos[1]
    sin_eq = (1 - _w**2) * _b - 2 * _z * _w * _a - _e * _b / 2 + _g * cube_sin[1]
    return sp.expand(cos_eq), sp.expand(sin_eq)


@dataclass(frozen=True)
class Pump:
    """``q̈ + 2ζq̇ + (1 + ε cos 2ωt)q + γq³ = 0``: the pump depth ``0 < ε < 1``, damping ``ζ ≥ 0``,
    cubic stiffness ``γ`` (each finite; checked here, one line per bad input)."""

    eps: float
    zeta: float
    gamma: float

    def __post_init__(self) -> None:
        for name, value in (("eps", self.eps), ("zeta", self.zeta), ("gamma", self.gamma)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value):
                raise InputError(f"{name} {value!r}: must be a finite number")
        if not self.eps > 0:
            raise InputError(f"eps {self.eps!r}: the pump depth must be > 0 (its sign is a "
                             "shift of time by a quarter pump period)")
        if not self.eps < 1:
            raise InputError(f"eps {self.eps!r}: must be < 1 (1 + eps cos 2wt > 0: a spring at "
                             "every instant; the first tongue's analysis is for a shallow pump)")
        if not 0 <= self.zeta <= 1:
            raise InputError(f"zeta {self.zeta!r}: the damping ratio must be in 0..1 (from "
                             "eps/4 on the first tongue is closed; above 1 overdamped)")
        low, high = MAGNITUDES
        for name, value in (("zeta", self.zeta), ("gamma", self.gamma)):  # nonzero: normal
            if value != 0 and not low <= abs(value) <= high:
                raise InputError(f"{name} {value!r}: |{name}| outside {low:g}..{high:g} (or 0); "
                                 "the balance cubes it, which must stay a normal double")
        if self.eps < low:
            raise InputError(f"eps {self.eps!r}: below {low:g}")

    @property
    def terms(self) -> dict[tuple[int, int], float]:
        """The autonomous force ``q + γq³ + 2ζq̇`` as ``{(a, b): c}``."""
        return {(1, 0): 1.0, (3, 0): float(self.gamma), (0, 1): 2.0 * self.zeta}

    def extra(self, omega: float) -> np.ndarray:
        """The pump ``−ε q cos 2ωt`` as an ``extra`` row of :func:`numerics._field`."""
        return np.array([[1.0, -float(self.eps), 2.0 * omega, 0.0]])


OMEGA_RANGE = (0.05, 20.0)
# NOTE: ω of the response (the pump at 2ω): the Floquet pass takes 2048 RK4 steps per period
# 2π/ω, ≥ 40 per natural period 2π from ω = 0.05; above 20 the pump is far past every tongue
# (they lie at ω ≈ 1/n).


def check_omega(omega: float, name: str = "omega") -> float:
    """A finite ``ω`` in :data:`OMEGA_RANGE` (half the pump's frequency), else
    :class:`InputError`."""
    lo, hi = OMEGA_RANGE
    if isinstance(omega, bool) or not isinstance(omega, (int, float, np.floating)) \
            or not lo <= omega <= hi:
        raise InputError(f"{name} {omega!r}: must be a number in {lo:g}..{hi:g} (the first "
                         "tongue is at 1)")
    return float(omega)


def _s2(p: Pump, omega: np.ndarray) -> np.ndarray:
    """``s² = ε²/4 − 4ζ²ω²``."""
    return p.eps**2 / 4 - 4 * p.zeta**2 * omega**2


def tongue_edges(p: Pump) -> tuple[float, float] | None:
    """The one-harmonic edges ``(ω₋, ω₊)`` of the first tongue, where ``(1 − ω²)² = s²``:
    ``ω² = 1 − 2ζ² ± √((1 − 2ζ²)² − 1 + ε²/4)``; ``None`` when the damping closes it
    (``ε`` below about ``4ζ``)."""
    c = 1 - 2 * p.zeta**2
    disc = c * c - 1 + p.eps**2 / 4
    if disc < 0 or c - math.sqrt(disc) <= 0:
        return None
    return math.sqrt(c - math.sqrt(disc)), math.sqrt(c + math.sqrt(disc))


def fold(p: Pump) -> tuple[float, float] | None:
    """``(ω, r)`` where the two nontrivial branches meet (``s = 0``: ``ω = ε/(4ζ)``,
    ``r² = 4(ω² − 1)/(3γ)``); ``None`` undamped, linear, or where that ``r²`` is negative."""
    if p.zeta == 0 or p.gamma == 0:
        return None
    w = p.eps / (4 * p.zeta)
    r2 = 4 * (w * w - 1) / (3 * p.gamma)
    return (w, math.sqrt(r2)) if r2 > 0 else None


ONE_HARMONIC_NONLINEARITY = 1.0
# NOTE: the one-harmonic model is a weakly nonlinear one: the cubic's share of the stiffness,
# ¾|γ|r², against the linear 1.  At the fold ω² − 1 = ¾γr², so a fold at ω = ε/(4ζ) far above
# 1 is a far larger amplitude than the model describes (ε = 0.5, ζ = 0.01: ω = 12.5, r = 14.4,
# ¾γr² = 155); where it stays below 1 the balance of 8 harmonics agrees to ~1 % (ε = 0.5, ζ =
# 0.01, r ≤ 0.8: 0.2 %).


def outside_model(p: Pump, r: float) -> str:
    """Why a one-harmonic point of amplitude ``r`` lies outside the model's validity (the
    cubic's share ``¾|γ|r²`` of the stiffness above :data:`ONE_HARMONIC_NONLINEARITY`), or
    ``""`` inside it."""
    share = 0.75 * abs(p.gamma) * r * r
    if share <= ONE_HARMONIC_NONLINEARITY:
        return ""
    return (f"outside the one-harmonic model: 3/4 |gamma| r^2 = {share:.3g} > "
            f"{ONE_HARMONIC_NONLINEARITY:g} (not weakly nonlinear)")


def onsets(p: Pump) -> tuple[Onset, ...]:
    """The two onsets, lower edge first: for ``γ > 0`` "+" at ``ω₋`` (supercritical) and "−" at
    ``ω₊`` (subcritical); for ``γ < 0`` "+" at ``ω₋`` (subcritical) and "−" at ``ω₊``
    (supercritical).  None for ``γ = 0`` or a closed tongue."""
    edges = tongue_edges(p)
    if edges is None or p.gamma == 0:
        return ()
    hard = p.gamma > 0
    return (Onset("omega", edges[0], "bifurcation", "+", hard),
            Onset("omega", edges[1], "bifurcation", "-", not hard))


@dataclass(frozen=True)
class OneHarmonicPoint:
    """A one-harmonic solution ``q = a cos ωt + b sin ωt`` with its slow-flow verdict."""

    branch: str  # "0" (trivial), "+" or "-"
    omega: float
    a: float
    b: float
    stable: bool

    @property
    def r(self) -> float:
        """The amplitude ``r = √(a² + b²)``."""
        return math.hypot(self.a, self.b)


def one_harmonic(p: Pump, omega: float) -> list[OneHarmonicPoint]:
    """Every one-harmonic solution at ``ω``: the trivial one (stable outside the tongue) and the
    nontrivial ones of the module docstring (stable where ``γκ > 0``; undamped, ``γκ > 0`` is a
    centre of the slow flow: linearly stable).  Of each ± pair ``(a, b)``, ``(−a, −b)`` (the
    same orbit half a period on) the one with ``a ≥ 0`` is given."""
    omega = check_omega(omega)
    s2 = float(_s2(p, omega))
    out = [OneHarmonicPoint("0", omega, 0.0, 0.0, not (1 - omega**2) ** 2 < s2)]
    if p.gamma == 0 or s2 < 0:
        return out
    s = math.sqrt(s2)
    for sign, kappa in (("+", s), ("-", -s)):
        r2 = 4 * (omega**2 - 1 + kappa) / (3 * p.gamma)
        if not r2 > 0:
            continue
        # the null vector of [[κ + ε/2, 2ζω], [−2ζω, κ − ε/2]] from its larger row
        row1 = (kappa + p.eps / 2, 2 * p.zeta * omega)
        row2 = (-2 * p.zeta * omega, kappa - p.eps / 2)
        u, v = max(row1, row2, key=lambda r: math.hypot(*r))
        a, b = v, -u
        scale = math.sqrt(r2) / math.hypot(a, b)
        a, b = a * scale, b * scale
        if a < 0 or (a == 0 and b < 0):
            a, b = -a, -b
        out.append(OneHarmonicPoint(sign, omega, a, b, p.gamma * kappa > 0))
    return out


class ParametricBalance(PolynomialBalance):
    """:class:`driven.PolynomialBalance` of ``q + γq³ + 2ζq̇`` (odd harmonics ``1, 3, …,
    2N − 1``, no drive) with the pump ``ε q cos 2θ`` added on the same sample points: still
    the exact Galerkin residual (``q cos 2θ`` reaches harmonic ``2N + 1``, far below the
    samples' limit ``4(2N − 1)``)."""

    def __init__(self, p: Pump, harmonics: int) -> None:
        super().__init__(p.terms, 0.0, harmonics, odd=True)
        cos1 = self.basis[:, 0]  # cos θ (the order-1 column)
        self.pump = p.eps * (2 * cos1 * cos1 - 1)  # ε cos 2θ on the samples

    def residual(self, x: np.ndarray, omega: float, force: float | None = None) -> np.ndarray:
        """:meth:`PolynomialBalance.residual` plus the harmonics of the pump ``ε q cos 2θ``."""
        return super().residual(x, omega, force) + self.project @ (self.pump * (self.basis @ x))

    def jacobian(self, x: np.ndarray, omega: float, force: float | None = None) -> np.ndarray:
        """:meth:`PolynomialBalance.jacobian` plus the pump's term, the projection of
        ``ε cos 2θ · ∂q/∂x``."""
        return super().jacobian(x, omega, force) + self.project @ (self.pump[:, None]
                                                                   * self.basis)


PARAMETRIC_HARMONICS = 8
# NOTE: odd harmonics 1 … 15, the command line's default: the balance's first harmonic within
# 4e-14 (relative) of shooting at ε ≤ 0.4 (benchmarks/parametric.py; the harmonics fall like
# (γr²/32)^k).


@dataclass(frozen=True)
class BalancePoint:
    """An N-harmonic balance solution refined from a one-harmonic point, with the full Hill
    equation's Floquet multipliers about it."""

    start: OneHarmonicPoint
    A: dict[int, float]
    B: dict[int, float]
    converged: bool
    residual: float
    multipliers: np.ndarray
    stable: bool

    @property
    def r(self) -> float:
        """The first harmonic's amplitude ``√(A₁² + B₁²)``."""
        return math.hypot(self.A[1], self.B[1])


def balance_point(p: Pump, point: OneHarmonicPoint,
                  harmonics: int = PARAMETRIC_HARMONICS) -> BalancePoint | None:
    """Newton's method on :class:`ParametricBalance` from a nontrivial one-harmonic point;
    ``None`` when it does not converge or falls onto the trivial solution."""
    system = ParametricBalance(p, harmonics)
    x0 = np.zeros(system.size)
    x0[0], x0[harmonics] = point.a, point.b
    x, converged, residual = system.solve(x0, point.omega)
    if not converged or math.hypot(x[0], x[harmonics]) < 1e-3 * point.r:
        return None
    A, B = system.amplitudes(x)
    lam = orbit_hill_multipliers(p.terms, A, B, point.omega, p.extra(point.omega))
    return BalancePoint(point, A, B, converged, residual, lam,
                        multipliers_stable(lam, p.zeta > 0))


SHOOT_HARMONICS = 11


def shoot_orbit(p: Pump, omega: float, A: dict[int, float],
                B: dict[int, float]) -> PeriodicOrbit | None:
    """The true orbit of period ``2π/ω`` near the Fourier sum ``A, B``, by shooting with the
    pump as an ``extra`` row; ``None`` when Newton finds none or falls onto ``q = 0``."""
    guess = np.array([sum(A.values()), omega * sum(k * b for k, b in B.items())])
    found = shoot_table(ForceTable.of(p.terms), 0.0, omega, guess, SHOOT_HARMONICS,
                        extra=p.extra(omega))
    if not isinstance(found, PeriodicOrbit) or math.hypot(*found.initial) < 1e-6:
        return None
    return found


@dataclass(frozen=True)
class ResponseRow:
    """One branch point of the response curve: the one-harmonic amplitude and verdict, the
    balance's (with the full Hill verdict) and, where asked, the shot orbit's."""

    one: OneHarmonicPoint
    balance: BalancePoint | None
    orbit: PeriodicOrbit | None


def response(p: Pump, omegas: np.ndarray, harmonics: int = PARAMETRIC_HARMONICS,
             shoot_every: int = 0) -> list[ResponseRow]:
    """Every branch at every ``ω`` of ``omegas``; nontrivial points refined by the balance;
    every ``shoot_every``-th ω (0: none) also shot (the trivial branch by the Floquet
    multipliers of ``q = 0``, i.e. of Mathieu's equation)."""
    rows = []
    for i, w in enumerate(np.asarray(omegas, dtype=float)):
        shoot_here = shoot_every > 0 and i % shoot_every == 0
        for pt in one_harmonic(p, float(w)):
            if pt.branch == "0":
                orbit = trivial_orbit(p, pt.omega) if shoot_here else None
                rows.append(ResponseRow(pt, None, orbit))
                continue
            bal = balance_point(p, pt, harmonics)
            orbit = None
            if shoot_here:
                orbit = shoot_orbit(p, pt.omega, *((bal.A, bal.B) if bal else
                                                   ({1: pt.a}, {1: pt.b})))
            rows.append(ResponseRow(pt, bal, orbit))
    return rows


def trivial_orbit(p: Pump, omega: float) -> PeriodicOrbit:
    """``q = 0`` with its Floquet multipliers (those of the damped Mathieu equation)."""
    lam = orbit_hill_multipliers(p.terms, {1: 0.0}, {1: 0.0}, omega, p.extra(omega))
    return PeriodicOrbit(np.zeros(2), {1: 0.0}, {1: 0.0}, lam,
                         multipliers_stable(lam, p.zeta > 0), 0.0)


SHOTS = 10
# NOTE: shooting at about ten ω of the range, every branch there: the numerical truth.


@dataclass(frozen=True)
class ParametricReport:
    """Everything ``lindstedt parametric`` prints: the pump, the ω grid and the harmonics, the
    tongue's edges, the onsets, the fold of the one-harmonic branches and every branch point
    of the response (:func:`response`), shot at about :data:`SHOTS` ω."""

    pump: Pump
    omega_range: tuple[float, float]
    points: int
    harmonics: int
    tongue: tuple[float, float] | None
    onsets: tuple[Onset, ...]
    fold: tuple[float, float] | None
    rows: tuple[ResponseRow, ...]


def parametric_report(eps: float, zeta: float, gamma: float, omega_from: float,
                      omega_to: float, points: int = 41,
                      harmonics: int = PARAMETRIC_HARMONICS) -> ParametricReport:
    """The :class:`ParametricReport` of the pumped oscillator over ``points`` ω of
    ``[omega_from, omega_to]``; each input refused in one line where it does not belong."""
    p = Pump(eps, zeta, gamma)
    lo, hi = check_omega(omega_from, "--omega A"), check_omega(omega_to, "--omega B")
    if not lo < hi:
        raise InputError(f"--omega {lo:g}:{hi:g}: the range must increase")
    check_int(points, 2, PARAMETRIC_MAX_POINTS,
              f"--omega A:B:N, N = {points}: must be in 2..{PARAMETRIC_MAX_POINTS}")
    check_int(harmonics, 1, MAX_HARMONICS, f"--harmonics {harmonics}: must be in "
              f"1..{MAX_HARMONICS}")
    rows = response(p, np.linspace(lo, hi, points), harmonics,
                    shoot_every=max(1, (points - 1) // SHOTS))
    return ParametricReport(p, (lo, hi), points, harmonics, tongue_edges(p), onsets(p),
                            fold(p), tuple(rows))
