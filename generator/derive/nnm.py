"""Nonlinear normal modes of a conservative system as exact Lindstedt–Poincaré series.

With ``τ = ωt``, ``x = A u(τ)`` and ``Ω = ω²``, the system ``x'' + Lx + g(x) = 0``
(``L = M⁻¹K``) reads ``Ω u_ττ + L u + Σ_p A^(p−1) g_p(u) = 0``, ``g_p`` the force's terms of
degree ``p``.  In the expansion variable ``y`` (``A``, or ``A²`` when every degree is odd)
``u = Σ_j y^j u_j``, ``Ω = Σ_j Ω_j y^j`` with ``Ω₀ = λ = ω₀²`` of the mode, and harmonic ``n``
of order ``j`` solves

    (L − n²λ) c_jn = n² Σ_{k=1..j} Ω_k c_(j−k)n − N_jn,

``N_j`` the ``y^j`` part of the force, computed in the one Fourier kernel
(:mod:`lindstedt.algebra.series`).  At ``n = 1`` the matrix is singular: the left null vector
``ψ`` must annihilate the right side — the secular condition, which fixes ``Ω_j`` — and the
amplitude convention ``u_j(0)[a] = 0`` (``j ≥ 1``) picks the solution.  At another ``n`` a
singular matrix is an internal resonance ``1:n`` with another mode; where the right side has a
component along it, no periodic series exists and the derivation is refused, naming it.
Exact over Q when ``λ`` is rational, else over the number field Q(λ); ω itself is
``√λ · √(Ω/λ)``, its coefficients in Q(√λ).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import sympy as sp
from sympy.polys.domains import QQ

from ..algebra.lazy import LazySeries, Product, Terms
from ..algebra.resum import (
    horner_float,
    nearest_singularity,
    ring_inverse,
    series_reciprocal,
    series_sqrt,
)
from ..algebra.series import Basis, Ground, from_fourier, to_fourier
from ..errors import InputError
from ..limits import check_int
from .system import System

NNM_MAX_ORDER = 200
# NOTE: far above order 60 for two coordinates (seconds); each order multiplies
# series of every coordinate, so a large system reaches minutes first.
ALL_HARMONICS = Basis(odd=False)


@dataclass(frozen=True)
class NormalModeSeries:
    """The L–P series of one nonlinear normal mode: ``Ω_j`` and each coordinate's Fourier
    coefficients ``coefficients[j][i] = {n: c}`` of ``x_i = A Σ_j y^j Σ_n c cos nτ``, exact
    elements of ``ground`` (Q or Q(λ))."""

    system: System
    mode: int  # 1-based, by increasing linear frequency
    amplitude: int  # the coordinate at its turning point x = A at t = 0
    lam: sp.Expr  # λ = ω₀², exact
    step: int  # y = A**step
    ground: Ground
    omega_squared: tuple[Any, ...]
    coefficients: tuple[tuple[dict[int, Any], ...], ...]
    left: tuple[Any, ...] = ()  # ψ, the left null vector of L − λ
    right_sides: tuple[dict[int, tuple[Any, ...]], ...] = ()
    # order j ≥ 1 (index j − 1): harmonic n → R_jn = n² Σ_k Ω_k c_(j−k)n − N_jn, before Ω_j

    @property
    def order(self) -> int:
        """The highest power of ``y``."""
        return len(self.omega_squared) - 1

    @property
    def omega0(self) -> sp.Expr:
        """The linear frequency ``ω₀ = √λ``, exact."""
        return sp.sqrt(self.lam)

    @property
    def variable(self) -> str:
        """The expansion variable as the JSON contract names it: ``A`` or ``y = A**2``."""
        return "A" if self.step == 1 else f"y = A**{self.step}"

    def _exact(self, c: Any) -> sp.Expr:
        return self.ground.to_sympy(c)

    def omega(self) -> list[sp.Expr]:
        """``ω = Σ_j ω_j y^j`` exactly: ``√λ`` times the series of ``√(Ω/λ)``."""
        return list(self._omega)

    def period(self) -> list[sp.Expr]:
        """``T/2π = Σ_j τ_j y^j`` exactly: ``1/√λ`` times the series of ``(Ω/λ)^(−1/2)``."""
        return list(self._period)

    def omega_over_omega0(self) -> list[sp.Expr]:
        """``ω_j/ω₀``, exact in the ground (no square root of λ)."""
        return list(self._ratios[0])

    def period_times_omega0(self) -> list[sp.Expr]:
        """``τ_j ω₀``, exact in the ground."""
        return list(self._ratios[1])

    @cached_property
    def _ratios(self) -> tuple[tuple[sp.Expr, ...], tuple[sp.Expr, ...]]:
        root = series_sqrt(self._ratio())
        return (tuple(map(self._exact, root)),
                tuple(map(self._exact, series_reciprocal(root))))

    @cached_property
    def _omega(self) -> tuple[sp.Expr, ...]:
        return tuple(self.omega0 * c for c in self._ratios[0])

    @cached_property
    def _period(self) -> tuple[sp.Expr, ...]:
        return tuple(c / self.omega0 for c in self._ratios[1])

    def _ratio(self) -> list[Any]:
        inv = self.ground.scalar(1) / self.omega_squared[0]
        return [c * inv for c in self.omega_squared]

    def evaluate(self, A: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The series summed in floats at amplitudes ``A``: ω(A), T(A) and every coordinate
        at t = 0 (rows), where the orbit starts (a seed for shooting, a point to plot)."""
        A = np.asarray(A, dtype=float)
        y = A**self.step
        omega = horner_float(self.omega(), y)
        period = 2 * np.pi * horner_float(self.period(), y)
        starts = np.array([A * horner_float([sum(o.values()) for o in orders], y)
                           for orders in map(self.coordinate, range(self.system.size))])
        return omega, period, starts

    def coordinate(self, i: int, order: int | None = None) -> list[dict[int, sp.Expr]]:
        """Coordinate ``i``'s coefficients per order (up to ``order``; default all): ``{n: c}``
        of ``cos nτ``, exact."""
        top = self.order if order is None else order
        return [{n: self._exact(c) for n, c in sorted(orders[i].items()) if c}
                for orders in self.coefficients[: top + 1]]


def _echelon(rows: list[list[Any]], width: int) -> tuple[list[list[Any]], list[int]]:
    """The reduced row echelon form of ``rows`` over its first ``width`` columns (the rest
    carried along) and its pivot columns; exact, any field (pivots numbers when the ring is a
    polynomial ring over one)."""
    rows = [list(r) for r in rows]
    pivots: list[int] = []
    r = 0
    for col in range(width):
        pick = next((i for i in range(r, len(rows)) if rows[i][col]), None)
        if pick is None:
            continue
        rows[r], rows[pick] = rows[pick], rows[r]
        inv = ring_inverse(rows[r][col])
        rows[r] = [v * inv for v in rows[r]]
        for i in range(len(rows)):
            if i != r and rows[i][col]:
                f = rows[i][col]
                rows[i] = [a - f * b for a, b in zip(rows[i], rows[r], strict=True)]
        pivots.append(col)
        r += 1
    return rows, pivots


def _solve(matrix: list[list[Any]], rhs: list[Any], zero: Any) -> list[Any] | None:
    """A solution of ``matrix · c = rhs`` (free unknowns at zero), None if inconsistent."""
    width = len(matrix[0])
    rows, pivots = _echelon([[*m, b] for m, b in zip(matrix, rhs, strict=True)], width)
    if any(row[-1] for row in rows[len(pivots):]):
        return None
    c = [zero] * width
    for row, col in zip(rows, pivots, strict=False):
        c[col] = row[-1]
    return c


def _null_vector(matrix: list[list[Any]], one: Any) -> list[Any]:
    """A vector spanning the (one-dimensional) null space of ``matrix``."""
    width = len(matrix[0])
    rows, pivots = _echelon(matrix, width)
    free = next(col for col in range(width) if col not in pivots)
    v = [one * 0] * width
    v[free] = one
    for row, col in zip(rows, pivots, strict=False):
        v[col] = -row[free]
    return v


class _Monomials:
    """The y-series of every monomial of the coordinates, built as prefix products
    ``u_i1·u_i2·…`` (:class:`algebra.lazy.Product`, each coefficient once)."""

    def __init__(self, series: list[list[Any]]) -> None:
        self.nodes: dict[tuple[int, ...], LazySeries] = {
            (i,): Terms(terms) for i, terms in enumerate(series)}

    def node(self, factors: tuple[int, ...]) -> LazySeries:
        """The series of ``Π u_i`` over ``factors``."""
        if factors not in self.nodes:
            self.nodes[factors] = Product(self.node(factors[:-1]), self.node(factors[-1:]))
        return self.nodes[factors]

    def coeff(self, factors: tuple[int, ...], m: int) -> Any:
        """The ``y^m`` coefficient (a polynomial in ``C = cos τ``) of ``Π u_i``."""
        return self.node(factors).coeff(m)


def normal_mode(system: System, mode: int, order: int, amplitude: int = 0,
                progress: Callable[[int, int], None] | None = None) -> NormalModeSeries:
    """The L–P series of nonlinear normal mode ``mode`` (1-based, by increasing linear
    frequency) to ``order``, with ``x_amplitude(0) = A`` and every velocity zero at t = 0."""
    check_int(order, 0, NNM_MAX_ORDER, f"--order {order}: must be in 0..{NNM_MAX_ORDER}")
    names = [str(x) for x in system.coordinates]
    if not system.conservative:
        raise InputError(f"system {system.text!r}: a velocity-dependent force is not "
                         "conservative; nnm takes x'' + Kx + f(x) = 0 (response and slowflow "
                         "take damped or self-excited systems)")
    lams = system.modes()
    for k, lam in enumerate(lams, 1):
        if not sp.N(lam, 30) > 0:
            raise InputError(f"system {system.text!r}: mode {k} has ω0² = {lam}: "
                             f"{'a rigid-body' if lam == 0 else 'an unstable'} linear mode; "
                             "nnm needs every ω0² > 0")
    if not 1 <= mode <= len(lams):
        raise InputError(f"--mode {mode}: the system has modes 1..{len(lams)} (by increasing "
                         "linear frequency)")
    lam = lams[mode - 1]
    if sum(1 for other in lams if other == lam) > 1:
        raise InputError(f"--mode {mode}: ω0² = {lam} is shared by two linear modes (a 1:1 "
                         "internal resonance): the mode shape is not unique, and the slow "
                         "flow of a 1:1 resonance is not built (slowflow SYSTEM takes modes "
                         "whose ω0 are in ratios 1:n, n ≥ 2)")
    params = sorted(set().union(*(f.free_symbols for f in system.force))
                    - set(system.coordinates) - set(system.velocities), key=str)
    field = QQ if lam.is_Rational else QQ.algebraic_field(lam)
    g = Ground(field[tuple(params)] if params else field)
    zero, one = g.scalar(0), g.scalar(1)
    lam_g = g.scalar(lam)
    d = system.size
    L = [[g.scalar(system.stiffness[i, k]) for k in range(d)] for i in range(d)]

    def shifted(n: int) -> list[list[Any]]:
        return [[L[i][k] - (lam_g * (n * n) if i == k else zero) for k in range(d)]
                for i in range(d)]

    singular = shifted(1)
    phi = _null_vector(singular, one)
    psi = _null_vector([list(col) for col in zip(*singular, strict=True)], one)
    if not phi[amplitude]:
        raise InputError(f"--amplitude {names[amplitude]}: this coordinate does not move in "
                         f"mode {mode}; pick one that does")
    scale = one / phi[amplitude]
    phi = [v * scale for v in phi]
    psi_phi = sum((p * v for p, v in zip(psi, phi, strict=True)), zero)

    terms = _force_terms(system, g)
    degrees = {p for row in terms for _, _, p in row}
    step = 2 if degrees and all(p % 2 for p in degrees) else 1
    coefficients: list[list[dict[int, Any]]] = [[{1: v} if v else {} for v in phi]]
    series = [[from_fourier(c, ALL_HARMONICS, g)] for c in coefficients[0]]
    products = _Monomials(series)
    omega2 = [lam_g]
    right_sides: list[dict[int, tuple[Any, ...]]] = []
    for j in range(1, order + 1):
        force = []
        for row in terms:
            acc = g.poly([])
            for c, factors, p in row:
                m = j - (p - 1) // step
                if m >= 0 and (p - 1) % step == 0:
                    acc = acc + products.coeff(factors, m) * c
            force.append(to_fourier(acc, ALL_HARMONICS, g))
        harmonics = sorted({n for f in force for n in f} | {1} | {
            n for k in range(1, j) for c in coefficients[j - k] for n in c})
        rhs: dict[int, list[Any]] = {}
        for n in harmonics:
            r = [zero - force[i].get(n, zero) for i in range(d)]
            for k in range(1, j):
                for i in range(d):
                    c = coefficients[j - k][i].get(n)
                    if c:
                        r[i] = r[i] + omega2[k] * c * (n * n)
            rhs[n] = r
        right_sides.append({n: tuple(r) for n, r in rhs.items()})
        w = zero - sum((p * v for p, v in zip(psi, rhs[1], strict=True)), zero) / psi_phi
        omega2.append(w)
        rhs[1] = [r + w * v for r, v in zip(rhs[1], phi, strict=True)]
        solved: dict[int, list[Any]] = {}
        for n in harmonics:
            if n == 1:
                continue
            c = _solve(shifted(n), rhs[n], zero)
            if c is None:
                raise InputError(_resonance(system, mode, lams, n, j, step))
            solved[n] = c
        shift = zero - sum((c[amplitude] for c in solved.values()), zero)
        first = _solve([*singular, [one if k == amplitude else zero for k in range(d)]],
                       [*rhs[1], shift], zero)
        solved[1] = first
        order_j = [{n: c[i] for n, c in sorted(solved.items()) if c[i]} for i in range(d)]
        coefficients.append(order_j)
        for i in range(d):
            series[i].append(from_fourier(order_j[i], ALL_HARMONICS, g))
        if progress is not None:
            progress(j, order)
    return NormalModeSeries(system, mode, amplitude, lam, step, g, tuple(omega2),
                            tuple(tuple(c) for c in coefficients), tuple(psi),
                            tuple(right_sides))


def _force_terms(system: System, g: Ground) -> list[list[tuple[Any, tuple[int, ...], int]]]:
    """Each coordinate's force as ``(coefficient, factor indices, degree)`` per monomial."""
    out = []
    for f in system.force:
        row = []
        for powers, c in sp.Poly(f, *system.coordinates).terms():
            if not c:
                continue
            factors = tuple(i for i, e in enumerate(powers) for _ in range(e))
            row.append((g.scalar(c), factors, len(factors)))
        out.append(row)
    return out


def _resonance(system: System, mode: int, lams: tuple, n: int, j: int, step: int) -> str:
    """The refusal of an internal resonance: which modes, which ratio, where it enters."""
    lam = lams[mode - 1]
    target = float(sp.N(n * n * lam, 40))
    other = next((k for k, x in enumerate(lams, 1)
                  if abs(float(sp.N(x, 40)) - target) <= 1e-12 * max(1.0, target)), None)
    which = f"mode {other} (ω0² = {lams[other - 1]})" if other else "another mode"
    power = "A" if step == 1 else f"y = A**{step}"
    return (f"system {system.text!r}: mode {mode} (ω0² = {lam}) is in 1:{n} internal resonance "
            f"with {which}: harmonic {n} of order {j} in {power} forces it, and the L–P "
            "series of the mode does not exist there (the modes exchange energy: lindstedt "
            "slowflow SYSTEM gives their slow flow)")


RELIABLE_SPREAD = 0.5
# NOTE: an estimate whose spread is below this fraction of it bounds the radius from below by
# itself less its spread; a larger spread (the ratios of ω_j still swinging, as where several
# singularities lie at nearly one distance) falls back on the smallest ratio of the tail.


@dataclass(frozen=True)
class ModeRadius:
    """The radius of convergence of a mode's ω series in ``y``: the estimate, its spread and
    a lower bound ``lower > 0`` (in ``y``), with how the bound was found; ``reach`` is the
    bound in the amplitude A."""

    estimate: float
    spread: float
    lower: float
    how: str
    step: int

    @property
    def reach(self) -> float:
        """The lower bound in the amplitude: ``lower^(1/step)``."""
        return self.lower ** (1 / self.step)


MIN_RATIOS = 6
# NOTE: terms past ω₀ below which a series gives no bound at all (no estimate, too few
# ratios): the emitted module then says "no radius estimate".


def radius(mode: NormalModeSeries) -> ModeRadius | None:
    """The estimated radius of convergence of ω in ``y`` (:func:`nearest_singularity`) with a
    real, positive lower bound; None when the series ends (a polynomial ω converges
    everywhere) or holds fewer than :data:`MIN_RATIOS` terms past ω₀.  Where no singularity
    fits the coefficients (they swing: no estimate), the bound is the smallest ratio alone.
    The bound is the estimate less its spread where the spread is below
    :data:`RELIABLE_SPREAD` of it, else the smaller of the estimate and the smallest ratio
    ``|c_(n−1)/c_n|`` over the last half of the coefficients: swinging ratios pass below
    their limit, which is the radius."""
    coefficients = mode.omega_over_omega0()
    est = nearest_singularity(coefficients, "y", None)
    values = [float(sp.N(c, 30)) for c in coefficients]
    while values and values[-1] == 0:
        values.pop()
    if est is None and sum(1 for v in values[1:] if v) < MIN_RATIOS:
        return None  # a series that ends (a polynomial ω) or too short to say
    square = est.variable.endswith("**2") if est is not None else not any(values[1::2])
    if square:  # read in y², the radius converted back to y
        values = values[::2]
    ratios = [abs(values[n - 1] / values[n]) for n in range(max(2, len(values) // 2),
                                                           len(values))
              if values[n] and values[n - 1]]
    r, spread = (est.radius, est.spread) if est is not None else (math.nan, math.inf)
    if math.isfinite(r) and r > 0 and math.isfinite(spread) and spread < RELIABLE_SPREAD * r:
        lower, how = r - spread, "the estimate less its spread"
    else:
        candidates = [x for x in (r, *ratios) if math.isfinite(x) and x > 0]
        lower = min(candidates, default=0.0)
        how = ("the smallest of the estimate and the ratios |c_(n-1)/c_n| of the last half "
               f"of the {len(values)} coefficients (the estimate's spread {spread:.3g} is "
               f"not below {RELIABLE_SPREAD:g} of it)")
    if square:
        root = math.sqrt(r) if r > 0 else math.nan
        return ModeRadius(root, spread / (2 * root) if r > 0 else math.inf,
                          math.sqrt(lower), how, mode.step)
    return ModeRadius(r, spread, lower, how, mode.step)
