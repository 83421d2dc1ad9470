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

import math
from dataclasses import dataclass

import numpy as np

from ..algebra.series import (
    laurent_cos,
    laurent_derivative,
    laurent_product,
    laurent_secular,
    laurent_solve,
    laurent_to_fourier,
)
from ..display import SHOWN_ROWS, html_table
from ..errors import InputError
from ..limits import MAGNITUDES, MU_MAX_ORDER, check_int
from ..numerics.newton import safeguarded
from .polynomial import DrivenEquation, HarmonicBalance, PolynomialBalance

DUFFING_TEXT = "q'' + q'/Q + q + eps*q**3 = f*cos(w*t)"


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
    def terms(self) -> dict[tuple[int, int], float]:
        """The force ``q + εq³ + q̇/Q`` as a table ``(power of q, power of q̇) -> c`` (the
        terms that vanish left out): eq. 10.60 as any polynomial oscillator."""
        table = {(1, 0): 1.0, (3, 0): float(self.eps), (0, 1): self.damping}
        return {k: c for k, c in table.items() if c != 0 or k == (1, 0)}

    @property
    def equation(self) -> DrivenEquation:
        """Eq. 10.60 at these parameters as a user's :class:`DrivenEquation`: every analysis of
        a polynomial oscillator takes it."""
        values = (("Q", repr(float(self.Q))), ("eps", repr(float(self.eps))),
                  ("f", repr(float(self.force))))
        return DrivenEquation("duffing", DUFFING_TEXT, self.terms, float(self.force),
                              float(self.omega), "w", values)

    def balance(self, harmonics: int) -> PolynomialBalance:
        """The Galerkin balance of eq. 10.60 with odd harmonics ``1, 3, …, 2N − 1``."""
        return PolynomialBalance(self.terms, float(self.force), harmonics, odd=True)

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
    the piece (:func:`numerics.newton.safeguarded`) converges to it monotonically (after at
    most one step).  Each piece starts from the quadratic model of ``G`` at its zero of
    ``∂G/∂u`` (near a fold that is the root to a few digits) or else from its end where ``G``
    and ``∂²G/∂u²`` agree in sign."""
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

    x = safeguarded(residual, np.clip(x, lo, hi), lo, hi, ROOT_STEPS)
    rank = np.concatenate([above[p][rows[p]] for p in range(4)]).astype(int)
    roots[r, rank] = x  # the pieces ascend in u: largest first, NaN last
    return roots


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
    check_int(order, 0, MU_MAX_ORDER, f"order {order!r}: must be an integer in 0..{MU_MAX_ORDER}")
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

def harmonic_balance(d: Drive, start: Branch | np.ndarray, harmonics: int, tol: float = 1e-13,
                     max_iter: int = 50) -> HarmonicBalance:
    """Newton's method on the balance of eq. 10.60 (:meth:`Drive.balance`, odd harmonics
    ``1, 3, …, 2N − 1``), started from a one-harmonic root, or from a balance
    ``x = (a_1, a_3, …, b_1, b_3, …)`` with any number of harmonics (cut to, or padded with
    zeros up to, ``harmonics``)."""
    system = d.balance(harmonics)
    x = np.zeros(2 * harmonics)
    if isinstance(start, Branch):
        x[0] = start.A1 * math.cos(start.delta0)
        x[harmonics] = start.A1 * math.sin(start.delta0)
    else:
        given = np.asarray(start, dtype=float)
        k = min(len(given) // 2, harmonics)
        x[:k], x[harmonics : harmonics + k] = given[:k], given[len(given) // 2 :][:k]
    found = system.solution(x, d.omega, tol, max_iter)
    if found is None:  # exactly at a fold
        raise np.linalg.LinAlgError("the balance's Jacobian is singular")
    return found
