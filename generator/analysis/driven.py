"""The driven Duffing oscillator ``q̈ + q̇/Q + q + εq³ = f cos ωt`` (notes §10.4, eq. 10.60).

Two perturbative routes to its steady 1:1 response:

* the μ-expansion with phase (eq. 10.66–10.72): with ``τ = ωt − δ(μ)``,
  ``q'' + q = μ[(1 − 1/ω²) q − q'/(ωQ) − (ε/ω²) q³ + (f/ω²) cos(τ + δ)]``,
  ``q = Σ μʲ q_j``, ``δ = Σ μʲ δ_j``.  Order 1's secular conditions give the cubic
  ``(ω² − 1)A₁ − ¾εA₁³ + f cos δ₀ = 0`` and ``f sin δ₀ = A₁ω/Q``; each later order's fix the
  constant ``b_j`` of ``q_j = b_j cos τ + …`` and the phase ``δ_j`` (a 2×2 linear system
  whose determinant vanishes at a fold of the response curve).
* harmonic balance with N odd harmonics, solved by Newton's method from every root of the
  one-harmonic equation.

Both work on Fourier sums stored as complex coefficients ``c_n`` of ``e^{inτ}``
(``q = Σ c_n e^{inτ}``, ``c_{−n} = c̄_n``), where products are exact convolutions: the float
kernel of :mod:`series` (``laurent_*``).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING

import numpy as np
import sympy as sp
from sympy.polys.domains import QQ

from ..algebra.series import (
    Basis,
    Ground,
    Trig,
    laurent_cos,
    laurent_derivative,
    laurent_from_fourier,
    laurent_harmonics,
    laurent_product,
    laurent_secular,
    laurent_solve,
    laurent_to_fourier,
    solve_oscillator,
    solve_trig,
    to_fourier,
    trig_power,
)
from ..display import SHOWN_ROWS, harmonics_table, html_table
from ..errors import InputError

if TYPE_CHECKING:  # numerics (numba) is imported where an orbit is shot
    pass

MAGNITUDES = (1e-16, 1e16)
# NOTE: every nonzero |ε|, |f|, ω and finite Q lies in this window.  The closed-form cubic in
# u = r² raises (1 − ω²)/ε to the sixth power, shooting cubes amplitudes up to fQ: within
# 1e±16 every such combination stays inside double precision (1e±288), beyond it some overflow.
# (Only εf² matters for the shape: q → λq maps ε, f to ελ², f/λ — rescale rather than widen.)


@dataclass(frozen=True)
class Drive:
    """Parameters of eq. 10.60; ``Q = inf`` is the undamped oscillator."""

    eps: float
    force: float
    omega: float
    Q: float = math.inf

    def __post_init__(self) -> None:
        for name in ("eps", "force", "omega", "Q"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InputError(f"{name} {value!r}: not a number")
            if math.isnan(value) or (math.isinf(value) and name != "Q"):
                raise InputError(f"{name} {value!r}: not finite")
        if self.Q <= 0:
            raise InputError(f"Q {self.Q}: must be > 0 (Q = inf for no damping)")
        if self.omega <= 0:
            raise InputError(f"omega {self.omega}: must be > 0")
        if self.force == 0:
            raise InputError("force 0: no drive, the response is q = 0 (free oscillations: "
                             "`lindstedt series duffing`)")
        low, high = MAGNITUDES
        for name, also in (("eps", " (or 0)"), ("force", ""), ("omega", ""), ("Q", " (or inf)")):
            value = getattr(self, name)
            if value != 0 and not math.isinf(value) and not low <= abs(value) <= high:
                raise InputError(f"{name} {value!r}: |{name}| outside {low:g}..{high:g}{also}; "
                                 "the methods square and cube it, which must stay normal doubles")

    @property
    def damping(self) -> float:
        """``1/Q`` (zero when undamped)."""
        return 0.0 if math.isinf(self.Q) else 1.0 / self.Q


def check_steady_state(eps: float, Q: float, omega_min: float,
                       omega_max: float | None = None) -> None:
    """:class:`InputError` where no method can answer: the undamped linear oscillator driven
    at its resonance ω = 1 (in ``[omega_min, omega_max]``) has no steady state."""
    hi = omega_min if omega_max is None else omega_max
    if eps == 0 and math.isinf(Q) and omega_min <= 1 <= hi:
        where = "omega 1" if omega_max is None else f"omega in [{omega_min:g}, {hi:g}]"
        raise InputError(f"eps 0, Q inf, {where}: an undamped linear oscillator driven at its "
                         "resonance has no steady state (its amplitude grows like f t/2)")


def amplitudes(c: np.ndarray, phase: float, harmonics: int) -> tuple[dict, dict]:
    """``A_n``, ``B_n`` of ``q(t) = Σ A_n cos nωt + B_n sin nωt`` from ``c_n`` of ``e^{inτ}``,
    ``τ = ωt − phase``, for odd ``n ≤ harmonics``."""
    orders = np.arange(1, min(harmonics, (len(c) - 1) // 2) + 1, 2)
    a, b = laurent_to_fourier(c, orders, phase)
    return dict(zip(orders.tolist(), a, strict=True)), dict(zip(orders.tolist(), b, strict=True))


# --- one harmonic: the cubic in u = r² -------------------------------------------------------

def _cubic(u: np.ndarray, a: np.ndarray, wg2: np.ndarray, eps: float,
           f2: float) -> tuple[np.ndarray, np.ndarray]:
    """``G`` and ``∂G/∂u`` at ``u`` from ``a = 1 − ω²``, ``wg2 = ω²/Q²`` and ``f2 = f²``."""
    s = a + 0.75 * eps * u
    s2 = s * s + wg2
    return u * s2 - f2, s2 + 1.5 * eps * u * s


def amplitude_residual(u: np.ndarray, omega: np.ndarray, d: Drive) -> np.ndarray:
    """``G(u) = u[(1 − ω² + ¾εu)² + ω²/Q²] − f²`` (``d.omega`` unused: ``omega`` is given)."""
    return _cubic(u, (1 - omega) * (1 + omega), (omega * d.damping) ** 2, d.eps, d.force**2)[0]


def amplitude_slope(u: np.ndarray, omega: np.ndarray, d: Drive) -> np.ndarray:
    """``∂G/∂u``: positive on stable one-harmonic branches."""
    return _cubic(u, (1 - omega) * (1 + omega), (omega * d.damping) ** 2, d.eps, d.force**2)[1]


def _two_sum(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    s = x + y
    z = s - x
    return s, (x - (s - z)) + (y - z)


def _two_product(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    def split(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c = 134217729.0 * v  # 2²⁷ + 1: Veltkamp's split into two 26-bit halves
        h = c - (c - v)
        return h, v - h

    p = x * y
    (xh, xl), (yh, yl) = split(x), split(y)
    return p, ((xh * yh - p) + xh * yl + xl * yh) + xl * yl


def _dd_mul(x: tuple, y: tuple) -> tuple[np.ndarray, np.ndarray]:
    p, e = _two_product(x[0], y[0])
    return _two_sum(p, e + (x[0] * y[1] + x[1] * y[0]))


def _dd_add(x: tuple, y: tuple) -> tuple[np.ndarray, np.ndarray]:
    s, e = _two_sum(x[0], y[0])
    return _two_sum(s, e + (x[1] + y[1]))


def _exact_residual(u: np.ndarray, omega: np.ndarray, eps: float, force: float,
                    Q: float) -> np.ndarray:
    """``G(u)`` in double-double arithmetic, on the exact values of the doubles ``omega``, ε,
    f, Q: right where the plain sum is only rounding (at a fold ``G`` is flat, and its roots
    there need ``G`` to twice the digits)."""
    zero = np.zeros_like(u)
    a = _dd_mul(_two_sum(1.0, -omega), _two_sum(1.0, omega))
    s = _dd_add(a, _dd_mul(_two_product(0.75 + zero, eps + zero), (u, zero)))
    wg = (zero, zero)
    if not math.isinf(Q):  # ω/Q and the rest of the division, (ω − (ω/Q)Q)/Q
        p, e = _two_product(omega / Q, Q + zero)
        wg = _two_sum(omega / Q, ((omega - p) - e) / Q)
    t = _dd_add(_dd_mul(s, s), _dd_mul(wg, wg))
    f2 = _two_product(force + zero, force + zero)
    G = _dd_add(_dd_mul(t, (u, zero)), (-f2[0], -f2[1]))
    return G[0] + G[1]


FLAT = 1e-4
# NOTE: where G is within FLAT·f² of zero at a zero of ∂G/∂u (beside a fold), its sign there
# and the roots of the two pieces beside it are found on the double-double G.
ROOT_STEPS = 200
# NOTE: at most this many Newton steps per root; from inside a piece of one curvature Newton
# converges monotonically, and from the starts below in 2–6 steps (≈50 beside a fold).


def one_harmonic_roots(eps: float, force: float, Q: float, omega: np.ndarray) -> np.ndarray:
    """Every positive root ``u = r²`` of the one-harmonic cubic ``G`` (:func:`amplitude_residual`)
    at each ``omega``: shape ``(n, 3)``, largest first, NaN where a branch does not exist.

    ``G(0) = −f² < 0`` and ``G`` grows without end.  Cut ``u > 0`` at the zeros of
    ``∂G/∂u`` (a pair, positive where ``ε(1 − ω²) < 0`` and ``(1 − ω²)² > 3ω²/Q²``), of
    ``∂²G/∂u²`` (``u = −8(1 − ω²)/(9ε)``) and at a bound above every root: on each piece
    ``G`` is monotone and of one curvature, so a piece whose ends differ in sign holds exactly
    one root — no root is lost, however far apart the roots — and Newton's method kept inside
    the piece converges to it monotonically (after at most one step).  Each piece starts from
    the quadratic model of ``G`` at its zero of ``∂G/∂u`` (near a fold that is the root to a
    few digits) or else from its end where ``G`` and ``∂²G/∂u²`` agree in sign."""
    d = Drive(eps, force, 1.0, Q)
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    a = (1 - w) * (1 + w)
    wg = w * d.damping
    wg2 = wg * wg
    f2 = force * force
    roots = np.full((w.size, 3), np.nan)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        k = a * a + wg2  # ∂G/∂u at u = 0
        linear = np.where(k > 0, f2 / k, np.nan)  # Newton's first step from u = 0
        if eps == 0:
            roots[:, 0] = linear
            return roots
        bent = -8 * a / (9 * eps)  # ∂²G/∂u² = 0
        D = (np.abs(a) - math.sqrt(3) * wg) * (np.abs(a) + math.sqrt(3) * wg)
        turns = (bent > 0) & (D > 0)
        far = 8 / (9 * abs(eps)) * (np.abs(a) + 0.5 * np.sqrt(np.maximum(D, 0)))
        mid = np.maximum(bent, 0)
        c1 = np.where(turns, 16 * k / (27 * eps * eps) / far, mid)  # the pair's product
        c2 = np.where(turns, far, mid)
        # above every root: u(1 − ω² + ¾εu)² ≤ f² bounds |¾εu + (1 − ω²)| by f/√u
        top = np.where(bent > 0, (np.abs(a) + np.sqrt(f2 / bent)) * 4 / (3 * abs(eps)),
                       2 * np.fmin(linear, np.cbrt(16 * f2 / (9 * eps * eps))))
        top = np.maximum(top, c2)
        ends = (np.zeros_like(w), c1, mid, c2, top)
        G = [np.full_like(w, -f2)] + [_cubic(e, a, wg2, eps, f2)[0] for e in ends[1:]]
        flat = {p: turns & (np.abs(G[p]) < FLAT * f2) for p in (1, 3)}  # beside a fold
        for p, i in flat.items():  # whether two roots there or none: on the double-double G
            G[p][i] = _exact_residual(ends[p][i], w[i], eps, force, Q)
        # the quadratic model of G at c1 and c2: G(c ± h) ≈ G(c) + ∂²G/∂u² h²/2
        h1 = np.sqrt(np.abs(2 * G[1] / (27 / 8 * eps * eps * c1 + 3 * eps * a)))
        h2 = np.sqrt(np.abs(2 * G[3] / (27 / 8 * eps * eps * c2 + 3 * eps * a)))
        starts = (np.where(turns, np.fmax(linear, c1 - h1), linear), c1 + h1, c2 - h2,
                  np.where(turns, np.fmin(top, c2 + h2), top))
    found = [((G[p] < 0) & (G[p + 1] >= 0)) | ((G[p] > 0) & (G[p + 1] <= 0)) for p in range(4)]
    rows = [np.flatnonzero(found[p]) for p in range(4)]
    above = [sum(found[q].astype(int) for q in range(p + 1, 4)) for p in range(3)] + [0 * w]
    pieces = [[v[rows[p]] for v in (ends[p], ends[p + 1], starts[p], a, wg2)] for p in range(4)]
    lo, hi, x, a, wg2 = (np.concatenate(v) for v in zip(*pieces, strict=True))
    r = np.concatenate(rows)
    fine = np.concatenate([flat[p // 2 * 2 + 1][rows[p]] for p in range(4)])

    def residual(i: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        value, slope = _cubic(x, a[i], wg2[i], eps, f2)
        k = fine[i]
        if k.any():  # beside a fold G is flat: its roots need G to twice the digits
            value[k] = _exact_residual(x[k], w[r[i[k]]], eps, force, Q)
        return value, slope

    x = _newton(np.clip(x, lo, hi), lo, hi, residual)
    rank = np.concatenate([above[p][rows[p]] for p in range(4)]).astype(int)
    roots[r, rank] = x  # the pieces ascend in u: largest first, NaN last
    return roots


def _newton(x: np.ndarray, lo: np.ndarray, hi: np.ndarray, G: Callable) -> np.ndarray:
    """Newton's method on each root ``x`` kept inside its piece ``[lo, hi]``, until its moves stop
    shrinking or reach rounding; ``G(i, x)`` gives ``G`` and ``∂G/∂u`` of the roots ``i`` at
    ``x``."""
    x = x.copy()
    todo = np.arange(x.size)  # the roots still moving
    moved = np.full(x.shape, np.inf)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for _ in range(ROOT_STEPS):
            if not todo.size:
                break
            xt = x[todo]
            value, slope = G(todo, xt)
            new = np.clip(xt - np.where(slope != 0, value / slope, 0.0), lo[todo], hi[todo])
            move = np.abs(new - xt)
            x[todo] = new
            going = (move > 2.0**-52 * new) & (move < moved[todo])
            moved[todo] = move
            todo = todo[going]
    return x


def one_harmonic_phase(eps: float, force: float, Q: float, omega: np.ndarray,
                       r: np.ndarray) -> np.ndarray:
    """``δ₀`` of the one-harmonic root ``r``: ``f sin δ₀ = rω/Q``,
    ``f cos δ₀ = ¾εr³ − (ω² − 1)r`` (0 or π undamped)."""
    damping = 0.0 if math.isinf(Q) else 1.0 / Q
    sign = math.copysign(1.0, force)
    return np.arctan2(sign * r * omega * damping, sign * (0.75 * eps * r**3 - (omega**2 - 1) * r))


def one_harmonic(eps: float, force: float, Q: float,
                 omega: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``A₁`` and ``δ₀`` of every one-harmonic branch, each ``(n, 3)``, largest ``r`` first (NaN
    where none): damped ``A₁ = r``; undamped ``δ₀ = 0`` and ``A₁ = ±r``, the sign of
    ``cos δ₀`` (``A₁ < 0``: in antiphase)."""
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    r = np.sqrt(one_harmonic_roots(eps, force, Q, w))
    delta = one_harmonic_phase(eps, force, Q, w[:, None], r)
    if math.isinf(Q):
        return np.copysign(r, np.cos(delta)), np.where(np.isfinite(r), 0.0, np.nan)
    return r, delta


# --- first order: the branches --------------------------------------------------------------

@dataclass(frozen=True)
class Branch:
    """One root of the first-order secular conditions: ``q₀ = A₁ cos τ``, phase ``δ₀``."""

    A1: float
    delta0: float

    def _repr_html_(self) -> str:
        return html_table("first-order branch: q₀ = A₁ cos τ, τ = ωt − δ₀", ("A₁", "δ₀"),
                          [(self.A1, self.delta0)])


def first_order_branches(d: Drive) -> list[Branch]:
    """All real roots of the secular conditions at order 1, largest ``A₁`` first.

    Undamped: ``(ω² − 1)A₁ − ¾εA₁³ + f = 0`` with ``δ₀ = 0`` (``A₁ < 0`` is the branch in
    antiphase).  Damped: ``r²[(1 − ω² + ¾εr²)² + ω²/Q²] = f²`` (cubic in ``r²``) with
    ``f sin δ₀ = rω/Q`` and ``f cos δ₀ = ¾εr³ − (ω² − 1)r``: :func:`one_harmonic`.
    """
    A, delta = one_harmonic(d.eps, d.force, d.Q, np.array([d.omega]))
    return sorted((Branch(float(a), float(dl)) for a, dl in zip(A[0], delta[0], strict=True)
                   if math.isfinite(a)), key=lambda b: -b.A1)


# --- the μ-expansion -------------------------------------------------------------------------

@dataclass(frozen=True)
class MuExpansion:
    """Orders 0..K of the μ-expansion on one branch (notes' convention: order j is
    ``q₀ + … + q_j`` with ``b_j`` fixed by the secular conditions at order ``j + 1``)."""

    branch: Branch
    coefficients: tuple[np.ndarray, ...]  # c_n of q_j, index n + M
    deltas: tuple[float, ...]
    determinants: tuple[float, ...]  # of the 2×2 secular system at each order (0 at a fold)
    converged: bool
    reason: str

    def partial(self, j: int) -> tuple[np.ndarray, float]:
        """Coefficients of ``q₀ + … + q_j`` and the phase ``δ₀ + … + δ_j``."""
        return sum(self.coefficients[: j + 1]), sum(self.deltas[: j + 1])

    def _repr_html_(self) -> str:
        """``A_n`` (and ``B_n`` when damped) of ``q₀ + … + q_j`` per order, the last orders."""
        K = len(self.coefficients)
        rows = [(j, *amplitudes(*self.partial(j), 2 * j + 1)) for j in range(K)]
        damped = any(abs(b) > 1e-14 for _, _, B in rows for b in B.values())
        heads = [f"A{n}" for n in (1, 3, 5)] + [f"B{n}" for n in (1, 3, 5) if damped]
        table = [(j, *(A.get(n) for n in (1, 3, 5)),
                  *(B.get(n) for n in (1, 3, 5) if damped), self.partial(j)[1])
                 for j, A, B in rows[-SHOWN_ROWS:]]
        verdict = "converged" if self.converged else "NOT converged"
        skipped = f"orders 0–{K - SHOWN_ROWS - 1} not shown; " if K > SHOWN_ROWS else ""
        return html_table(f"μ-expansion on the branch A₁ = {self.branch.A1:.6g} "
                          "(order j: q₀ + … + q_j)", ("order", *heads, "δ"), table,
                          note=f"{skipped}{verdict}: {self.reason}")


def _forcing(d: Drive, q: list, cubes: list, E: list, delta0: float, j: int) -> np.ndarray:
    """``F_j`` of eq. 10.68: needs ``q_{j−1}``, ``[μ^{j−1}] q³`` and ``E_{j−1}``."""
    M = (len(q[0]) - 1) // 2
    w2 = d.omega**2
    prev = q[j - 1]
    F = (1 - 1 / w2) * prev - d.damping / d.omega * laurent_derivative(prev) \
        - d.eps / w2 * cubes[j - 1]
    # [μ^{j−1}] cos(τ + δ) = Re(e^{i(τ+δ₀)} E_{j−1}),  E = exp(i Σ_{k≥1} δ_k μ^k)
    return F + d.force / w2 * laurent_cos(M, np.exp(1j * delta0) * E[j - 1])


def _extend(q: list, squares: list, cubes: list, E: list, deltas: list, m: int) -> None:
    """Append ``[μ^m]`` of ``q²``, ``q³`` and ``E`` (``m E_m = i Σ k δ_k E_{m−k}``)."""
    squares.append(sum(laurent_product(q[a], q[m - a]) for a in range(m + 1)))
    cubes.append(sum(laurent_product(q[a], squares[m - a]) for a in range(m + 1)))
    E.append(1j * sum(k * deltas[k] * E[m - k] for k in range(1, m + 1)) / m)


JUDGED_FROM = 3
# NOTE: the convergence test reads four terms: below order 3 the expansion is carried to order
# 3 to be judged, and returned at the order asked (a first-order answer is never unjudged).


def mu_expansion(d: Drive, branch: Branch, order: int) -> MuExpansion:
    """The μ-expansion (eq. 10.66–10.72) to ``order`` on ``branch``, numerically (float64),
    judged by the size of its terms up to ``max(order, 3)``."""
    if isinstance(order, bool) or not isinstance(order, int) or not 0 <= order <= 200:
        raise InputError(f"order {order!r}: must be an integer in 0..200")
    top = max(order, JUDGED_FROM)
    M = 2 * top + 5
    q = [laurent_cos(M, branch.A1)]
    deltas = [branch.delta0]
    squares = [laurent_product(q[0], q[0])]
    cubes = [laurent_product(q[0], squares[0])]
    E = [1.0 + 0j]
    dets: list[float] = []

    def stop(j: int, reason: str) -> MuExpansion:
        """The orders found before order ``j`` failed, not converged, with the reason."""
        return MuExpansion(branch, tuple(q[: order + 1]), tuple(deltas[: order + 1]),
                           tuple(dets[:order]), False, f"order {j}: {reason}")

    for j in range(1, top + 1):
        with np.errstate(over="ignore", invalid="ignore"):
            F = _forcing(d, q, cubes, E, branch.delta0, j)
            p = laurent_solve(F).particular

            def secular_next(b: float, delta: float, p: np.ndarray = p,
                             j: int = j) -> np.ndarray:
                """Secular part of F_{j+1} for trial b_j, δ_j (it is affine in both)."""
                qs, ds = [*q, p + laurent_cos(M, b)], [*deltas, delta]
                sq, cb, Es = list(squares), list(cubes), list(E)
                _extend(qs, sq, cb, Es, ds, j)
                return laurent_secular(_forcing(d, qs, cb, Es, branch.delta0, j + 1))

            s0 = secular_next(0.0, 0.0)
            J = np.column_stack([secular_next(1.0, 0.0) - s0, secular_next(0.0, 1.0) - s0])
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(J)) and np.all(np.isfinite(s0))):
            return stop(j, "the terms overflow double precision (the μ-series diverges here)")
        det = float(np.linalg.det(J))
        dets.append(det)
        if abs(det) < 1e-12 * (1 + abs(d.force) + abs(d.eps) * branch.A1**2):
            return stop(j, "singular secular system (a fold: branches merge)")
        b, delta = np.linalg.solve(J, -s0)
        q.append(p + laurent_cos(M, b))
        deltas.append(float(delta))
        with np.errstate(over="ignore", invalid="ignore"):
            _extend(q, squares, cubes, E, deltas, j)
        if not (np.all(np.isfinite(q[-1])) and np.all(np.isfinite(cubes[-1]))
                and np.isfinite(delta)):
            q.pop(), deltas.pop()
            return stop(j, "the terms overflow double precision (the μ-series diverges here)")
    converged, reason = _convergence(q)
    return MuExpansion(branch, tuple(q[: order + 1]), tuple(deltas[: order + 1]),
                       tuple(dets[:order]), converged, reason)


def _convergence(q: list[np.ndarray]) -> tuple[bool, str]:
    """Judge the series by the size of its last terms: a growing tail, or a last term still
    above 1 % of the leading one, is no answer."""
    sizes = [float(np.abs(c).sum()) for c in q]
    tail = sizes[-3:]
    if tail[-1] > tail[0] and tail[-1] > 1e-14 * sizes[0]:
        return False, f"terms grow ({tail[0]:.1e} -> {tail[-1]:.1e}): the μ-series diverges here"
    if tail[-1] > 1e-2 * sizes[0]:
        return False, (f"last term {tail[-1]:.1e} is {tail[-1] / sizes[0]:.0%} of the first: "
                       "the μ-series is not converging here")
    return True, f"last term {tail[-1]:.1e}"


# --- harmonic balance ------------------------------------------------------------------------

@dataclass(frozen=True)
class HarmonicBalance:
    """Harmonic balance with odd harmonics ``1, 3, …, 2N − 1`` (cos and sin when damped)."""

    harmonics: int
    coefficients: np.ndarray  # c_n of e^{inωt}, index n + M
    residual: float
    converged: bool

    def _repr_html_(self) -> str:
        A, B = amplitudes(self.coefficients, 0.0, 2 * self.harmonics - 1)
        return harmonics_table(f"harmonic balance, N = {self.harmonics} odd harmonics", A, B,
                               f"residual {self.residual:.1e}, "
                               f"{'converged' if self.converged else 'NOT converged'}")


@dataclass(frozen=True)
class BalanceSystem:
    """The Galerkin residual of eq. 10.60 in ``x = (a_1, a_3, …, b_1, b_3, …)`` and ``ω``
    (exact: products are convolutions, no aliasing), with its derivatives."""

    eps: float
    force: float
    damping: float
    harmonics: int

    @property
    def odd(self) -> np.ndarray:
        return np.arange(1, 2 * self.harmonics, 2)

    @property
    def M(self) -> int:
        return 3 * (2 * self.harmonics - 1)

    def coefficients(self, x: np.ndarray) -> np.ndarray:
        """``c_n`` of ``e^{inωt}`` for ``q = Σ a_k cos kωt + b_k sin kωt``."""
        h = self.harmonics
        return laurent_from_fourier(self.M, self.odd, x[:h], x[h:])

    def _project(self, R: np.ndarray) -> np.ndarray:
        return np.concatenate(laurent_to_fourier(R, self.odd))

    def _linear(self, omega: float) -> np.ndarray:
        n = laurent_harmonics(self.M)
        return -(n * omega) ** 2 + 1j * n * omega * self.damping + 1

    def residual(self, x: np.ndarray, omega: float) -> np.ndarray:
        c = self.coefficients(x)
        return self._project(self._linear(omega) * c
                             + self.eps * laurent_product(c, laurent_product(c, c))
                             - laurent_cos(self.M, self.force))

    def jacobian(self, x: np.ndarray, omega: float) -> np.ndarray:
        """``∂R/∂x``: ``dR_n/dc_m = lin_n δ_nm + 3ε (q²)_{n−m}``, ``c_{±m} = (a_m ∓ i b_m)/2``."""
        odd, M = self.odd, self.M
        c = self.coefficients(x)
        q2 = laurent_product(c, c)
        K_plus = np.diag(self._linear(omega)[M + odd]) + 3 * self.eps * q2[M + odd[:, None]
                                                                           - odd[None, :]]
        K_minus = 3 * self.eps * q2[M + odd[:, None] + odd[None, :]]
        dR_da, dR_db = (K_plus + K_minus) / 2, -1j * (K_plus - K_minus) / 2
        return np.block([[2 * dR_da.real, 2 * dR_db.real], [-2 * dR_da.imag, -2 * dR_db.imag]])

    def d_omega(self, x: np.ndarray, omega: float) -> np.ndarray:
        """``∂R/∂ω``: only the linear part depends on ω."""
        n = laurent_harmonics(self.M)
        return self._project((-2 * n * n * omega + 1j * n * self.damping)
                             * self.coefficients(x))


MAX_HARMONICS = 100
# NOTE: the numerical balance's bound (200 unknowns, dense 200×200 Newton steps): the CLI's
# --harmonics takes the same range in every command.


def check_harmonics(harmonics: object) -> None:
    """:class:`InputError` unless ``harmonics`` is an integer in 1..MAX_HARMONICS."""
    if isinstance(harmonics, bool) or not isinstance(harmonics, (int, np.integer)) \
            or not 1 <= harmonics <= MAX_HARMONICS:
        raise InputError(f"harmonics {harmonics!r}: must be an integer in 1..{MAX_HARMONICS}")


def harmonic_balance(d: Drive, start: Branch | np.ndarray, harmonics: int, tol: float = 1e-13,
                     max_iter: int = 50) -> HarmonicBalance:
    """Newton's method on :class:`BalanceSystem`, started from a one-harmonic root, or from a
    balance ``x = (a_1, a_3, …, b_1, b_3, …)`` with any number of harmonics (cut to, or padded
    with zeros up to, ``harmonics``)."""
    check_harmonics(harmonics)
    system = BalanceSystem(d.eps, d.force, d.damping, harmonics)
    x = np.zeros(2 * harmonics)
    if isinstance(start, Branch):
        x[0] = start.A1 * math.cos(start.delta0)
        x[harmonics] = start.A1 * math.sin(start.delta0)
    else:
        given = np.asarray(start, dtype=float)
        k = min(len(given) // 2, harmonics)
        x[:k], x[harmonics : harmonics + k] = given[:k], given[len(given) // 2 :][:k]
    converged = False
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(max_iter):
            try:
                step = np.linalg.solve(system.jacobian(x, d.omega),
                                       -system.residual(x, d.omega))
            except np.linalg.LinAlgError:  # a singular Jacobian: a fold, Newton cannot go on
                break
            if not np.all(np.isfinite(step)):  # Newton diverged (overflow)
                break
            x = x + step
            if np.max(np.abs(step)) <= tol * (1 + np.max(np.abs(x))):
                converged = True
                break
        residual = float(np.max(np.abs(system.residual(x, d.omega))))
    return HarmonicBalance(harmonics, system.coefficients(x), residual, converged)


# --- the first-order secular conditions, symbolically (display, tests) -----------------------

def first_order_secular() -> tuple[sp.Expr, sp.Expr]:
    """The cos τ and sin τ coefficients of ``ω²F₁(τ)`` (eq. 10.72 with damping), by SymPy.

    ``F₁ = (1 − 1/ω²)q₀ − q₀'/(ωQ) − (ε/ω²)q₀³ + (f/ω²)cos(τ + δ₀)``, ``q₀ = A₁ cos τ``.
    """
    tau, A1, w, eps, f, Q, d0 = sp.symbols("tau A_1 omega epsilon f Q delta_0", real=True)
    q0 = A1 * sp.cos(tau)
    F1 = (1 - 1 / w**2) * q0 - sp.diff(q0, tau) / (w * Q) - eps / w**2 * q0**3 \
        + f / w**2 * sp.cos(tau + d0)
    F1 = sp.expand(w**2 * F1)
    cos_c = sp.simplify(sp.integrate(F1 * sp.cos(tau), (tau, 0, 2 * sp.pi)) / sp.pi)
    sin_c = sp.simplify(sp.integrate(F1 * sp.sin(tau), (tau, 0, 2 * sp.pi)) / sp.pi)
    return sp.expand(cos_c), sp.expand(sin_c)


# --- the undamped μ-expansion, exactly (for display, LaTeX and emitted evaluators) -----------

A1_, omega_, eps_, force_ = sp.symbols("A_1 omega epsilon f")


@dataclass(frozen=True)
class MuOrder:
    """Order ``j`` of the undamped μ-expansion in ``A₁, ω, ε`` (``A₁`` a root of the cubic)."""

    order: int
    forcing: dict[int, sp.Expr]  # F_j: coefficients of cos nτ, n ≠ 1
    secular: sp.Expr  # cos τ coefficient of F_j (= 0), with b_{j−1} as a symbol
    unknown: sp.Symbol  # what it fixes: A₁ (order 1) or b_{j−1}
    value: sp.Expr | None  # b_{j−1} (None at order 1: the cubic is solved per branch)
    q: dict[int, sp.Expr]  # q_j: coefficients of cos nτ, b_j (fixed at order j+1) included


@functools.lru_cache(maxsize=4)
def mu_expansion_exact(order: int) -> tuple[MuOrder, ...]:
    """Orders 1..K of eq. 10.68 (``Q → ∞``, so ``δ = 0``) with exact rational functions.

    The kernel of :mod:`series` does the algebra in the monomial basis of ``C = cos τ`` over
    ``QQ(A₁, ω, ε)``.  ``F₁`` holds ``f/ω² cos τ``; its secular condition is the cubic
    ``(ω² − 1)A₁ − ¾εA₁³ + f = 0``, which removes ``f`` from every later order.  At order
    ``j + 1`` the secular condition is affine in ``b_j``: ``s₀ + D b_j = 0`` with
    ``D = 1 − 1/ω² − 9εA₁²/(4ω²)``, which vanishes at a fold.
    """
    if isinstance(order, bool) or not isinstance(order, int) or not 1 <= order <= 12:
        raise InputError(f"order {order!r}: the exact μ-expansion takes 1..12")
    ground = Ground(QQ.frac_field(A1_, omega_, eps_))
    basis = Basis(odd=True)
    lin = ground.scalar(1 - 1 / omega_**2)
    cub = ground.scalar(-eps_ / omega_**2)
    D = lin + cub * ground.scalar(sp.Rational(9, 4) * A1_**2)
    P = [ground.poly([A1_])]  # q₀ = A₁ cos τ = C·P₀

    def cube(m: int) -> object:
        """``[μ^m] P³`` by direct convolution (low orders only)."""
        acc = ground.poly([])
        for a in range(m + 1):
            for b in range(m + 1 - a):
                acc = acc + P[a] * P[b] * P[m - a - b]
        return acc

    def forcing(j: int) -> object:
        return P[j - 1] * lin + cube(j - 1).left_shift(1) * cub

    def fourier(poly: object) -> dict[int, sp.Expr]:
        return {n: sp.factor(ground.to_sympy(c))
                for n, c in to_fourier(poly, basis, ground).items()}

    forcings, seculars, values, b_symbols = [], [], [], []
    for j in range(1, order + 2):
        s0 = solve_oscillator(forcing(j).coeffs() or [ground.scalar(0)], basis, ground).secular
        if j == 1:  # the cubic (its f/ω² cos τ term stands outside the kernel's QQ(A₁, ω, ε))
            seculars.append(sp.expand(ground.to_sympy(s0) + force_ / omega_**2))
            values.append(None)
            b_symbols.append(A1_)
        else:  # s₀ + D b_{j−1} = 0 fixes the constant of q_{j−1}
            b = -s0 * (ground.scalar(1) / D)
            b_sym = sp.Symbol(f"b_{j - 1}")
            seculars.append(sp.factor(ground.to_sympy(s0)) + sp.factor(ground.to_sympy(D)) * b_sym)
            values.append(sp.factor(ground.to_sympy(b)))
            b_symbols.append(b_sym)
            P[j - 1] = P[j - 1] + ground.poly([b])
        if j == order + 1:
            break
        F = forcing(j)
        forcings.append({n: c for n, c in fourier(F).items() if n != 1})
        P.append(ground.poly(solve_oscillator(F.coeffs(), basis, ground).particular))
    return tuple(
        MuOrder(order=j, forcing=forcings[j - 1], secular=seculars[j - 1],
                unknown=b_symbols[j - 1], value=values[j - 1], q=fourier(P[j]))
        for j in range(1, order + 1)
    )


# --- the damped μ-expansion, exactly (LaTeX and emitted evaluators for Q < ∞) ---------------

x_, a_, gamma_, Delta_, Q_, delta0_ = sp.symbols("x a gamma Delta Q delta_0")


@dataclass(frozen=True)
class MuDampedOrder:
    """Order ``j`` of the damped μ-expansion (:func:`mu_expansion_damped`) in
    ``A₁, ω, x = εA₁², a = ω² − 1, γ = ω/Q`` and the symbol ``Δ``
    (:func:`damped_determinant`): each value is ``A₁ N/(ω^{2j} Δ^m)`` (``δ_j`` without the
    ``A₁``), ``N`` a polynomial over QQ in ``(x, a, γ)``."""

    order: int
    forcing: tuple[dict[int, sp.Expr], dict[int, sp.Expr]]  # F_j: cos nτ, sin nτ (n ≠ 1)
    secular: tuple[sp.Expr, sp.Expr]  # ω² × the cos τ, sin τ parts of F_j (= 0)
    unknowns: tuple[sp.Symbol, sp.Symbol]  # b_{j−1}, δ_{j−1} (A₁, δ₀ at order 1)
    values: tuple[sp.Expr, sp.Expr] | None  # b_{j−1}, δ_{j−1} (None at order 1: the cubic)
    q: tuple[dict[int, sp.Expr], dict[int, sp.Expr]]  # q_j: cos nτ, sin nτ, b_j included
    delta: sp.Expr  # δ_j


def damped_determinant() -> sp.Expr:
    """``Δ = (a − 9x/4)(a − 3x/4) + γ²``: the determinant of the secular system in
    ``(b_j, δ_j)`` over ``A₁``; ``A₁²Δ/ω⁴`` is ``∂G/∂u`` of the one-harmonic cubic
    (:func:`amplitude_slope`), zero at a fold."""
    return (a_ - sp.Rational(9, 4) * x_) * (a_ - sp.Rational(3, 4) * x_) + gamma_**2


def _moments(n: int) -> list[Fraction]:
    """``(1/π)∫₀^{2π} cos^k s ds`` for ``k < n``: 2, 0, 1, 0, 3/4, …"""
    out = [Fraction(2), Fraction(0)]
    for k in range(2, n):
        out.append(out[k - 2] * Fraction(k - 1, k))
    return out[:n]


def _resonant_parts(t: Trig) -> tuple[object, object]:
    """Fourier coefficients of ``cos s`` and ``sin s`` in ``t = P(C) + S·R(C)``:
    ``(1/π)∫ C·P(C) ds`` and ``(1/π)∫ (1 − C²)·R(C) ds``."""
    g = t.ground
    P, R = t.cos_part.coeffs(), t.sin_part.coeffs()
    m = _moments(max(len(P), len(R)) + 3)
    acc_c, acc_s = g.scalar(0), g.scalar(0)
    for k, c in enumerate(P):
        if m[k + 1]:
            acc_c = acc_c + c * g.scalar(m[k + 1])
    for k, c in enumerate(R):
        if m[k] - m[k + 2]:
            acc_s = acc_s + c * g.scalar(m[k] - m[k + 2])
    return acc_c, acc_s


def _delta_power(j: int) -> int:
    """``Δ``'s power under order ``j``: each 2×2 solve divides by ``Δ`` once, and order j's
    products reach ``Δ^{2j−2}`` before it (q₁·q₁·q_{j−2}, δ₁δ_{j−1})."""
    return 2 * j - 1 if j else 0


@functools.lru_cache(maxsize=4)
def mu_expansion_damped(order: int) -> tuple[MuDampedOrder, ...]:
    """Orders 1..K of eq. 10.68 with damping, exactly, on the sine-capable kernel (:class:`Trig`).

    The representation keeps expressions small: ``q = A₁ q̃`` gives the same equation with
    ``ε → x = εA₁²``, and order 1's conditions ``f cos δ₀ = A₁(¾x − a)``, ``f sin δ₀ = A₁γ``
    (``a = ω² − 1``, ``γ = ω/Q``) remove ``f`` and ``δ₀`` from every later order, whose drive
    is ``(f/ω²) Re(e^{i(τ+δ₀)} E_j)``, ``E = exp(iΣ_{k≥1} δ_k μ^k)``.  Each order carries one
    ``1/ω²`` and each 2×2 solve of the cos τ, sin τ secular conditions
    ``[[a − 9x/4, −γ], [γ, a − 3x/4]]·(b_j/A₁, δ_j) = −(s_c, s_s)`` divides by its determinant
    ``Δ`` (:func:`damped_determinant`): order ``j`` is ``A₁N_j/(ω^{2j} Δ^{2j−1})`` with
    numerators ``N_j`` over QQ in three variables (FLINT's ``fmpq_mpoly``: no rational-function
    gcds).  Convention: ``q_j`` (``j ≥ 1``) has no ``sin τ`` component (that is ``δ_j``'s) and
    its ``cos τ`` component is ``b_j``; at ``γ = 0`` these are :func:`mu_expansion_exact`'s
    orders."""
    if isinstance(order, bool) or not isinstance(order, int) or not 1 <= order <= 12:
        raise InputError(f"order {order!r}: the exact damped μ-expansion takes 1..12")
    ground = Ground(QQ.poly_ring(x_, a_, gamma_))
    s = ground.scalar
    zero, one = s(0), s(1)
    x, a, gamma = s(x_), s(a_), s(gamma_)
    fc, fs = s(sp.Rational(3, 4) * x_ - a_), gamma  # f cos δ₀/A₁, f sin δ₀/A₁
    m11, m22 = s(a_ - sp.Rational(9, 4) * x_), s(a_ - sp.Rational(3, 4) * x_)
    powers = [one, s(damped_determinant())]

    def lift(value: object, have: int, want: int) -> object:
        """A numerator over ``Δ^have`` as one over ``Δ^want``."""
        while len(powers) <= want - have:
            powers.append(powers[-1] * powers[1])
        return value * powers[want - have] if want > have else value

    cos1 = Trig.from_fourier({1: one}, {}, ground)
    q, deltas = [cos1], [zero]  # numerators of q_j/A₁ and δ_j over ω^{2j} Δ^{_delta_power(j)}
    sq, cu, X, Y = [cos1 * cos1], [cos1 * cos1 * cos1], [one], [zero]  # q², q³, E = X + iY

    def extend(j: int, want: int) -> None:
        """Append ``[μ^j]`` of q², q³ and E (without ``iδ_j``) over ``Δ^want``."""
        pairs = [(i, j - i, _delta_power(i) + _delta_power(j - i)) for i in range(1, j)]
        last = _delta_power(j - 1)  # q[j] is still order j's particular solution
        sq.append(sum((lift(q[i] * q[k], m, want) for i, k, m in pairs),
                      lift(q[j] * cos1 * 2, last, want)))
        cu.append(sum((lift(q[i] * sq[k], m, want) for i, k, m in pairs),
                      lift(q[j] * sq[0], last, want) + lift(sq[j] * cos1, want, want)))
        X.append(sum((lift(deltas[i] * Y[k] * s(Fraction(-i, j)), m, want)
                      for i, k, m in pairs), zero))
        Y.append(sum((lift(deltas[i] * X[k] * s(Fraction(i, j)), m, want)
                      for i, k, m in pairs), zero))

    def forcing(j: int) -> Trig:
        """``ω² F_{j+1}/A₁`` from order ``j`` (eq. 10.68), over order j's denominator."""
        drive = Trig.from_fourier({1: fc * X[j] - fs * Y[j]}, {1: -(fc * Y[j] + fs * X[j])},
                                  ground)
        return q[j] * a - q[j].derivative() * gamma - cu[j] * x + drive

    def real(c: object, j: int, m: int, amplitude: bool = True) -> sp.Expr:
        """A numerator of order ``j`` over ``Δ^m`` as its value, the powers of ``Δ`` that
        divide it cancelled."""
        while m and c:
            quotient, remainder = divmod(c, powers[1])
            if remainder:
                break
            c, m = quotient, m - 1
        value = ground.to_sympy(c) / (omega_ ** (2 * j) * Delta_**m)
        return A1_ * value if amplitude else value

    def fourier(t: Trig, j: int, m: int, skip: int) -> tuple[dict[int, sp.Expr], ...]:
        return tuple({n: real(c, j, m) for n, c in sorted(part.items()) if n != skip}
                     for part in t.to_fourier())

    out: list[MuDampedOrder] = []
    F = forcing(0)  # ω²F₁/A₁ with f eliminated: its secular parts vanish identically
    pending = ((A1_ * (omega_**2 - 1) - sp.Rational(3, 4) * eps_ * A1_**3
                + force_ * sp.cos(delta0_), A1_ * omega_ / Q_ - force_ * sp.sin(delta0_)),
               (A1_, delta0_), None)
    for j in range(1, order + 1):
        solved = solve_trig(F)
        if solved.secular_cos or solved.secular_sin:
            raise ArithmeticError(f"order {j}: secular terms left in F_{j}")
        c1, s1 = _resonant_parts(solved.particular)
        p = solved.particular - Trig.from_fourier({1: c1}, {1: s1}, ground)
        forcing_j = fourier(F, j, _delta_power(j - 1), 1)
        trial = _delta_power(j) - 1  # order j with b_j = δ_j = 0, over Δ^(2j − 2)
        q.append(p)
        deltas.append(zero)
        extend(j, trial)
        q[j] = lift(p, _delta_power(j - 1), trial)
        sc, ss = _resonant_parts(forcing(j))
        b = -(m22 * sc + gamma * ss)  # adj(M)·(−s): the 1/Δ goes into the next power
        delta = gamma * sc - m11 * ss
        bj, dj = sp.Symbol(f"b_{j}"), sp.Symbol(f"delta_{j}")
        secular = (real(sc, j, trial) + ground.to_sympy(m11) * bj
                   - A1_ * ground.to_sympy(gamma) * dj,
                   real(ss, j, trial) + ground.to_sympy(gamma) * bj
                   + A1_ * ground.to_sympy(m22) * dj)
        up = _delta_power(j)
        q[j] = lift(q[j], trial, up) + cos1 * b
        deltas[j] = delta
        sq[j] = lift(sq[j], trial, up) + cos1 * cos1 * (b * 2)
        cu[j] = lift(cu[j], trial, up) + cos1 * cos1 * cos1 * (b * 3)
        X[j] = lift(X[j], trial, up)
        Y[j] = lift(Y[j], trial, up) + delta
        out.append(MuDampedOrder(order=j, forcing=forcing_j, secular=pending[0],
                                 unknowns=pending[1], values=pending[2],
                                 q=fourier(q[j], j, up, 0), delta=real(delta, j, up, False)))
        pending = (secular, (bj, dj), (real(b, j, up), real(delta, j, up, False)))
        F = forcing(j)
    return tuple(out)


# --- harmonic balance, symbolically (emitted as compiled residual and Jacobian) --------------

@dataclass(frozen=True)
class BalanceEquations:
    """Galerkin residual of eq. 10.60 for ``q = Σ a_k cos kωt + b_k sin kωt``, k odd ≤ 2N − 1."""

    harmonics: int
    unknowns: tuple[sp.Symbol, ...]  # a_1, a_3, …, b_1, b_3, …
    parameters: tuple[sp.Symbol, ...]  # omega, eps, force, damping (= 1/Q)
    residuals: tuple[sp.Expr, ...]  # cos kωt and sin kωt components, same order as unknowns


def balance_equations(harmonics: int) -> BalanceEquations:
    """``−(kω)² q_k + kω/Q q̃_k + q_k + ε[q³]_k − f δ_k1`` for every odd ``k ≤ 2N − 1``."""
    if isinstance(harmonics, bool) or not isinstance(harmonics, int) or not 1 <= harmonics <= 12:
        raise InputError(f"harmonics {harmonics!r}: the symbolic balance takes 1..12")
    odd = range(1, 2 * harmonics, 2)
    a = [sp.Symbol(f"a_{k}") for k in odd]
    b = [sp.Symbol(f"b_{k}") for k in odd]
    w, eps, f, g = sp.symbols("omega eps force damping")
    cube_cos, cube_sin = trig_power(dict(zip(odd, a, strict=True)),
                                    dict(zip(odd, b, strict=True)), 3)
    cos_res, sin_res = [], []
    for k, ak, bk in zip(odd, a, b, strict=True):
        # q̇ contributes kω(b_k cos − a_k sin), q̈ contributes −(kω)² q
        cos_res.append(sp.expand((1 - (k * w) ** 2) * ak + g * k * w * bk
                                 + eps * cube_cos.get(k, 0) - (f if k == 1 else 0)))
        sin_res.append(sp.expand((1 - (k * w) ** 2) * bk - g * k * w * ak
                                 + eps * cube_sin.get(k, 0)))
    return BalanceEquations(harmonics, (*a, *b), (w, eps, f, g), (*cos_res, *sin_res))


# --- a user's driven oscillator: q'' + g(q, q') = f cos(w t), g a polynomial -----------------

DRIVEN = "driven"


@dataclass(frozen=True)
class DrivenEquation:
    """A user's equation lowered to data: ``q̈ + Σ c q^a q̇^b = f cos ωt`` at one ω.

    ``terms`` maps ``(a, b)`` to the float ``c`` (the linear part included); ``force`` is the
    drive amplitude ``f``, ``omega`` the drive frequency (the value of ``frequency``, the
    symbol in the cosine's argument), ``values`` the parameter values as given (text)."""

    name: str
    text: str
    terms: dict[tuple[int, int], float]
    force: float
    omega: float
    frequency: str
    values: tuple[tuple[str, str], ...]

    @property
    def odd(self) -> bool:
        """``g(−q, −q̇) = −g(q, q̇)``: the response holds odd harmonics only."""
        return all((a + b) % 2 == 1 for a, b in self.terms)

    @property
    def dissipative(self) -> bool:
        """A term odd in ``q̇``: stability asks every Floquet multiplier inside the unit circle."""
        return any(b % 2 == 1 for _, b in self.terms)

    @property
    def degree(self) -> int:
        return max(a + b for a, b in self.terms)


def driven_equation(text: str, values: dict[str, str], omega: float,
                    name: str = "oscillator") -> DrivenEquation:
    """Lower ``text`` (see :mod:`lindstedt.derive.equation`) to a :class:`DrivenEquation`: a
    polynomial force and a single drive ``f cos(w t)``, every parameter but ``w`` given in
    ``values`` (exact text, ``eps`` included), ``w = omega``.  A one-line :class:`InputError`
    says why where it cannot: no drive or more than one, a drive that is not ``f cos(w t)``, a
    term in both t and q (parametric), a force that is not a polynomial in q and q', a missing
    value."""
    from ..derive.equation import parse_expression
    from ..derive.models import oscillator

    if isinstance(omega, bool) or not isinstance(omega, (int, float)) \
            or not math.isfinite(omega) or omega <= 0:
        raise InputError(f"--omega {omega!r}: the drive frequency must be finite and > 0")
    values = dict(values)
    small = values.pop("eps", None)
    osc = oscillator(text, values, name)
    q, v, t = osc.coordinate, osc.velocity, osc.equation.time
    subs: dict[sp.Symbol, sp.Expr] = {}
    if small is not None:
        if osc.equation.small is None:
            raise InputError(f"--param eps: not a parameter of {text!r}")
        number = parse_expression(small, "--param eps")
        if not number.is_Rational:
            raise InputError(f"--param eps={small}: not a rational number")
        subs[osc.equation.small] = number
    if osc.parametric != 0:
        raise osc.refuse(DRIVEN, f"{sp.sstr(osc.parametric)} depends on both t and {q} "
                         "(parametric excitation); give a drive in t alone")
    drive = osc.drive.xreplace(subs)
    if drive == 0:
        raise osc.refuse(DRIVEN, f"no drive: write it on the right, e.g. {q}'' + ... = "
                         "f*cos(w*t)")
    terms = sp.Add.make_args(sp.expand(drive))
    if len(terms) > 1:
        raise osc.refuse(DRIVEN, f"the drive {sp.sstr(drive)} has {len(terms)} terms; it takes "
                         "one, f*cos(w*t) (several tones: `lindstedt mixing`)")
    amplitude, wave = drive.as_independent(t, as_Add=False)
    if not isinstance(wave, sp.cos):
        raise osc.refuse(DRIVEN, f"the drive {sp.sstr(drive)} is not f*cos(w*t) (a sine or "
                         "another function of t: shift t or rewrite it as f*cos(w*t))")
    w, rest = wave.args[0].as_independent(t, as_Add=False)
    if rest != t or not isinstance(w, sp.Symbol):
        raise osc.refuse(DRIVEN, f"the drive's argument {sp.sstr(wave.args[0])} is not w*t "
                         "with the frequency a name w (its value is --omega)")
    if str(w) in values:
        raise InputError(f"--param {w}: {w} is the drive frequency; give it with --omega")
    subs[w] = sp.Rational(str(float(omega)))
    force_expr = sp.expand(osc.force.xreplace(subs))
    amplitude = amplitude.xreplace(subs)
    missing = sorted(str(s) for s in (force_expr.free_symbols | amplitude.free_symbols)
                     - {q, v})
    if missing:
        raise osc.refuse(DRIVEN, "give " + ", ".join(missing) + " a value (--param "
                         + " --param ".join(f"{m}=..." for m in missing) + ")")
    if not force_expr.is_polynomial(q, v):
        raise osc.refuse(DRIVEN, f"the force {sp.sstr(osc.force)} is not a polynomial in {q} "
                         f"and {v} (expand it: driven evaluates polynomial forces)")
    poly = sp.Poly(force_expr, q, v)
    table: dict[tuple[int, int], float] = {}
    for (a, b), c in zip(poly.monoms(), poly.coeffs(), strict=True):
        value = float(c)
        if not math.isfinite(value) or (value != 0 and not MAGNITUDES[0] <= abs(value)
                                        <= MAGNITUDES[1]):
            raise osc.refuse(DRIVEN, f"the coefficient {c} of {sp.sstr(q**a * v**b)} is "
                             f"outside {MAGNITUDES[0]:g}..{MAGNITUDES[1]:g}")
        if value != 0:
            table[(a, b)] = value
    if table.get((0, 0)):
        raise osc.refuse(DRIVEN, f"the constant force {table[(0, 0)]:g} moves the equilibrium "
                         f"off {q} = 0; shift {q} to it")
    if not any(a + b == 1 for a, b in table) and (1, 0) not in table:
        raise osc.refuse(DRIVEN, f"no linear term in {q}: q = 0 is no oscillator's equilibrium")
    f = float(amplitude)
    if f == 0 or not math.isfinite(f) or not MAGNITUDES[0] <= abs(f) <= MAGNITUDES[1]:
        raise osc.refuse(DRIVEN, f"the drive amplitude {amplitude} must be nonzero, within "
                         f"{MAGNITUDES[0]:g}..{MAGNITUDES[1]:g}")
    given = [(k, str(val)) for k, val in sorted({**values, **({"eps": small} if small
                                                               else {})}.items())]
    return DrivenEquation(name, text, table, f, float(omega), str(w), tuple(given))


class PolynomialBalance:
    """The Galerkin residual of ``q̈ + g(q, q̇) = f cos ωt`` for a polynomial ``g`` (a
    :class:`DrivenEquation`'s terms), by alternating frequency and time: ``q`` and ``q̇`` sampled
    on ``S`` points of a period, ``g`` evaluated there, projected back on the harmonics.  ``S``
    exceeds ``(degree + 1)`` times the top harmonic, so no product aliases: the projection is the
    exact Galerkin residual (as :class:`BalanceSystem`'s convolutions are for εq³).

    ``drive_harmonic = n`` puts the drive on ``cos nωt`` instead: the balance of a 1/n
    subharmonic, ω its own frequency.
    Unknowns ``x = (a_k …, b_k …)`` of ``q = Σ a_k cos kωt + b_k sin kωt`` over ``orders``:
    ``1, 3, …, 2N − 1`` for an odd force (:class:`BalanceSystem`'s layout), else
    ``0, 1, 2, …, 2N − 1`` (the constant ``a_0``, no ``b_0``).  The same interface as
    :class:`BalanceSystem` (``residual``, ``jacobian``, ``d_omega`` in ``(x, ω)``), with the drive
    amplitude ``force`` as a keyword for the continuation in it."""

    def __init__(self, terms: dict[tuple[int, int], float], force: float, harmonics: int,
                 odd: bool, drive_harmonic: int = 1) -> None:
        check_harmonics(harmonics)
        self.terms, self.force, self.harmonics, self.odd = dict(terms), force, harmonics, odd
        self.drive_harmonic = drive_harmonic
        top = 2 * harmonics - 1
        if drive_harmonic > top or (odd and drive_harmonic % 2 == 0):
            raise InputError(f"harmonic {drive_harmonic} of the drive is not among the "
                             f"balance's orders (top {top}{', odd only' if odd else ''})")
        self.orders = np.arange(1, top + 1, 2) if odd else np.arange(0, top + 1)
        degree = max(a + b for a, b in terms)
        samples = 16
        while samples <= (degree + 1) * top:
            samples *= 2
        theta = 2 * np.pi * np.arange(samples) / samples
        k = self.orders
        sines = k[k > 0]
        self.n_cos = len(k)
        cos, sin = np.cos(np.outer(theta, k)), np.sin(np.outer(theta, sines))
        self.basis = np.hstack([cos, sin])  # (S, m): q = basis @ x
        self.d_basis = np.hstack([-k * np.sin(np.outer(theta, k)),
                                  sines * np.cos(np.outer(theta, sines))])  # d/dθ
        weights = np.where(k == 0, 1.0, 2.0)
        self.project = np.vstack([weights[:, None] * cos.T, 2.0 * sin.T]) / samples
        self.k2 = np.concatenate([k, sines]).astype(float) ** 2
        self.drive = np.zeros(len(self.k2))
        # the cos(n ωt) component, n = drive_harmonic (n > 1: a 1/n subharmonic's balance)
        self.drive[int(np.nonzero(k == drive_harmonic)[0][0])] = 1.0
        self.powers = [(a, b, c) for (a, b), c in sorted(terms.items())]

    @property
    def size(self) -> int:
        return len(self.k2)

    def _force(self, x: np.ndarray, omega: float) -> tuple[np.ndarray, ...]:
        """``g``, ``∂g/∂q``, ``∂g/∂q̇`` on the sample points."""
        q, v = self.basis @ x, omega * (self.d_basis @ x)
        g, gq, gv = np.zeros_like(q), np.zeros_like(q), np.zeros_like(q)
        for a, b, c in self.powers:
            qa, vb = q**a, v**b
            g += c * qa * vb
            if a:
                gq += c * a * q ** (a - 1) * vb
            if b:
                gv += c * b * qa * v ** (b - 1)
        return g, gq, gv

    def residual(self, x: np.ndarray, omega: float, force: float | None = None) -> np.ndarray:
        g, _, _ = self._force(x, omega)
        f = self.force if force is None else force
        return -omega**2 * self.k2 * x + self.project @ g - f * self.drive

    def jacobian(self, x: np.ndarray, omega: float, force: float | None = None) -> np.ndarray:
        _, gq, gv = self._force(x, omega)
        J = self.project @ (gq[:, None] * self.basis + omega * gv[:, None] * self.d_basis)
        return J - np.diag(omega**2 * self.k2)

    def d_omega(self, x: np.ndarray, omega: float, force: float | None = None) -> np.ndarray:
        _, _, gv = self._force(x, omega)
        return -2 * omega * self.k2 * x + self.project @ (gv * (self.d_basis @ x))

    def amplitudes(self, x: np.ndarray) -> tuple[dict[int, float], dict[int, float]]:
        """``A_k``, ``B_k`` of ``x`` (``A_0`` the mean, when the orders hold it)."""
        A = {int(k): float(a) for k, a in zip(self.orders, x[: self.n_cos], strict=True)}
        B = {int(k): float(b) for k, b in zip(self.orders[self.orders > 0], x[self.n_cos:],
                                              strict=True)}
        return A, B

    def vector(self, A: dict[int, float], B: dict[int, float]) -> np.ndarray:
        """The unknowns of ``A``, ``B`` (harmonics beyond the orders dropped, missing ones 0)."""
        return np.array([A.get(int(k), 0.0) for k in self.orders]
                        + [B.get(int(k), 0.0) for k in self.orders if k > 0])

    def state(self, x: np.ndarray, omega: float) -> np.ndarray:
        """``(q(0), q̇(0))`` of a balance solution: a shooting guess."""
        A, B = self.amplitudes(x)
        return np.array([sum(A.values()), omega * sum(k * b for k, b in B.items())])

    def solve(self, x: np.ndarray, omega: float, tol: float = 1e-13,
              max_iter: int = 50) -> tuple[np.ndarray, bool, float]:
        """Newton's method from ``x``: the solution, whether it converged, its residual."""
        x = np.array(x, dtype=float)
        converged = False
        with np.errstate(over="ignore", invalid="ignore"):
            for _ in range(max_iter):
                try:
                    step = np.linalg.solve(self.jacobian(x, omega), -self.residual(x, omega))
                except np.linalg.LinAlgError:  # singular: exactly at a fold
                    break
                if not np.all(np.isfinite(step)):
                    break
                x = x + step
                if np.max(np.abs(step)) <= tol * (1 + np.max(np.abs(x))):
                    converged = True
                    break
            residual = float(np.max(np.abs(self.residual(x, omega))))
        return x, converged and math.isfinite(residual), residual


def amplitude_bound(terms: dict[tuple[int, int], float], omega: float,
                    force: float) -> float | None:
    """A first-harmonic amplitude ``r`` beyond which ``q = r cos(ωt + φ)`` balances no drive of
    amplitude ``force``, doubled: ``None`` where none exists (the top degree even, or its
    terms not dominating: the response may grow without end).

    On ``q = r cos θ`` the first harmonic of ``q̈ + g`` is exactly
    ``P = (Σ_a κ_a c_a0 r^a − ω² r, −Σ_b κ_b c_0b (ωr)^b)`` over the odd pure powers
    (``κ_n = C(n, (n−1)/2)/2^(n−1)``, ¾ for n = 3; even pure powers have no first harmonic),
    plus at most ``2|c| r^a (ωr)^b`` from each mixed term ``c q^a q̇^b``: no orbit where
    ``|P| > force + Σ 2|c| r^a (ωr)^b``, i.e. beyond every root of the polynomial
    ``|P|² − (force + Σ …)²``; the largest modulus of its roots, complex ones included (a
    window where the two nearly touch counts).  The distortion of a true orbit by its higher
    harmonics is what the factor 2 leaves room for (a one-harmonic bound, not a proof)."""
    d = max(a + b for a, b in terms)
    if d % 2 == 0 or d < 3:
        return None

    def kappa(n: int) -> float:
        return math.comb(n, (n - 1) // 2) / 2 ** (n - 1)

    cos = [(a, kappa(a) * c) for (a, b), c in terms.items() if b == 0 and a % 2]
    sin = [(b, -kappa(b) * c * omega**b) for (a, b), c in terms.items() if a == 0 and b % 2]
    mixed = [(a + b, 2 * abs(c) * omega**b) for (a, b), c in terms.items() if a and b]
    P = np.polynomial.Polynomial
    pc, ps, pm = P([0.0, -omega**2]), P([0.0]), P([abs(force)])
    for n, c in cos:
        pc = pc + P([0.0] * n + [c])
    for n, c in sin:
        ps = ps + P([0.0] * n + [c])
    for n, c in mixed:
        pm = pm + P([0.0] * n + [c])
    H = (pc * pc + ps * ps - pm * pm).trim()
    if H.degree() < 2 * d or not H.coef[-1] > 0:
        return None
    roots = H.roots()
    return 2 * float(np.max(np.abs(roots))) if roots.size else 2e-6


@dataclass(frozen=True)
class DrivenForm:
    """A user's equation ``q̈ + g(q, q̇) = Σ f_i cos(ν_i t)`` once its values are given: ``g`` a
    polynomial, ``terms`` its exact coefficients ``{(a, b): c}`` of ``c q^a q̇^b`` (the linear
    part included); each drive ``(f, c, w)`` with ``ν = c·w``, ``c`` a positive rational and
    ``w`` a name left free (``None``: ``ν = c``)."""

    terms: dict[tuple[int, int], sp.Rational]
    drives: tuple[tuple[float, sp.Rational, sp.Symbol | None], ...]
    values: tuple[tuple[str, str], ...]

    def floats(self) -> dict[tuple[int, int], float]:
        """``terms`` as floats (a :class:`numerics.ForceTable`'s)."""
        return {k: float(c) for k, c in self.terms.items() if c != 0}


def driven_form(text: str, values: dict[str, str], name: str, method: str, why: str,
                free_frequency: bool) -> DrivenForm:
    """Map ``text`` onto :class:`DrivenForm` or refuse in one line naming what ``method``
    (``why``: its ansatz) needs: a force polynomial in q and q' with rational coefficients, no
    constant term, a linear term; the drive a sum of ``f cos(ν t)``; every parameter given,
    except, with ``free_frequency``, one name in the drives' frequencies."""
    from ..derive.models import oscillator

    osc = oscillator(text, values, name)
    q, v, t = osc.coordinate, osc.velocity, osc.equation.time
    if osc.parametric != 0:
        raise osc.refuse(method, f"{sp.sstr(osc.parametric)} depends on both t and {q}: {why}")
    force = sp.expand(osc.force)
    missing = sorted(str(s) for s in force.free_symbols - {q, v})
    if missing:
        raise osc.refuse(method, "give " + ", ".join(missing) + " a value (--param "
                         + " --param ".join(f"{m}=..." for m in missing) + ")")
    if not force.is_polynomial(q, v):
        raise osc.refuse(method, f"the force {sp.sstr(force)} is not a polynomial in {q} and "
                         f"{v}: {why}")
    poly = sp.Poly(force, q, v)
    if any(not c.is_Rational for c in poly.coeffs()):
        raise osc.refuse(method, f"the force {sp.sstr(force)}: its coefficients must be "
                         "rational numbers")
    terms = {k: sp.Rational(c) for k, c in zip(poly.monoms(), poly.coeffs(), strict=True)}
    if terms.get((0, 0)):
        raise osc.refuse(method, f"the constant force {terms[(0, 0)]} moves the equilibrium "
                         f"off {q} = 0; shift {q} to it")
    if not terms.get((1, 0)):
        raise osc.refuse(method, f"no linear term in {q}: q = 0 is no oscillator's "
                         "equilibrium")
    drive = sp.expand(osc.drive)
    if drive == 0:
        raise osc.refuse(method, f"no drive: write it on the right, e.g. {q}'' + ... = "
                         "f*cos(w*t)")
    drives = []
    frequencies: set[sp.Symbol] = set()
    for term in sp.Add.make_args(drive):
        amplitude, wave = term.as_independent(t, as_Add=False)
        if not isinstance(wave, sp.cos):
            raise osc.refuse(method, f"the drive term {sp.sstr(term)} is not f*cos(w*t) (a "
                             "sine or another function of t: shift t or rewrite it)")
        c, rest = wave.args[0].as_independent(t, as_Add=False)
        if rest != t:
            raise osc.refuse(method, f"the drive's argument {sp.sstr(wave.args[0])} is not "
                             "w*t")
        number, symbols = c.as_coeff_Mul()
        symbol = None
        if symbols != 1:
            if not (free_frequency and isinstance(symbols, sp.Symbol)):
                need = ", ".join(sorted(str(s) for s in c.free_symbols))
                raise osc.refuse(method, f"give {need} a value (--param {need}=...): the "
                                 "drive frequencies must be numbers")
            symbol = symbols
            frequencies.add(symbol)
        missing = sorted(str(s) for s in amplitude.free_symbols)
        if missing:
            raise osc.refuse(method, "give " + ", ".join(missing) + " a value (--param "
                             + " --param ".join(f"{m}=..." for m in missing) + ")")
        if not (number.is_Rational and amplitude.is_Rational):
            raise osc.refuse(method, f"the drive term {sp.sstr(term)}: its amplitude and "
                             "frequency must be rational numbers")
        if not number > 0:
            raise osc.refuse(method, f"the drive term {sp.sstr(term)}: its frequency must be "
                             "> 0")
        drives.append((float(amplitude), number, symbol))
    if len(frequencies) > 1:
        raise osc.refuse(method, "the drives' frequencies name "
                         + ", ".join(sorted(map(str, frequencies))) + "; give them values")
    return DrivenForm(terms, tuple(drives), tuple((str(k), str(val)) for k, val in osc.values))
