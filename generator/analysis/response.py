"""Frequency response of ``q̈ + q̇/Q + q + εq³ = f cos ωt``: branches, folds, hysteresis (§10.4).

One harmonic: ``r²[(1 − ω² + ¾εr²)² + ω²/Q²] = f²`` is a cubic ``G(u) = 0`` in ``u = r²``.
A branch is stable where ``∂G/∂u > 0`` (the slow flow of ``a, b`` has a saddle where it is
negative, between the folds); the folds solve ``G = ∂G/∂u = 0``.  N harmonics: the balance of
:class:`driven.BalanceSystem` continued in ω by pseudo-arclength through its folds.
"""

from __future__ import annotations

import functools
import itertools
import math
import time
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..analysis.driven import (
    MAGNITUDES,
    BalanceSystem,
    Branch,
    Drive,
    HarmonicBalance,
    amplitude_residual,
    amplitude_slope,
    amplitudes,
    check_harmonics,
    first_order_branches,
    harmonic_balance,
    one_harmonic_roots,
)
from ..analysis.polynomial import DrivenEquation, PolynomialBalance, amplitude_bound
from ..errors import InputError
from ..numerics.integrate import ForceTable, Sweep, flow_table, sweep_table
from ..numerics.shooting import PeriodicOrbit, ShootingFailure, shoot_explained, shoot_table

_u, _w, _e, _f, _g = sp.symbols("u w e f g")  # u = r², w = ω², g = 1/Q
_G = _u * ((1 - _w + sp.Rational(3, 4) * _e * _u) ** 2 + _w * _g**2) - _f**2


@functools.cache
def _fold_polynomial() -> sp.Poly:
    """The resultant in u of G and ∂G/∂u (the cubic's discriminant), a polynomial in ω² whose
    positive roots with a positive double root u are the folds; derived once, on first use."""
    return sp.Poly(sp.resultant(_G, sp.diff(_G, _u), _u), _w)


@dataclass(frozen=True)
class ResponseCurve:
    """One-harmonic amplitudes ``r`` (NaN where a branch does not exist), largest first."""

    omega: np.ndarray  # (n,)
    r: np.ndarray  # (n, 3)
    stable: np.ndarray  # (n, 3) bool


def one_harmonic_curve(eps: float, force: float, Q: float, omega: np.ndarray) -> ResponseCurve:
    """All real branches of the amplitude equation over ``omega``, vectorised
    (:func:`driven.one_harmonic_roots`)."""
    d = Drive(eps, force, 1.0, Q)
    w = np.asarray(omega, dtype=float)
    if np.any(~np.isfinite(w)) or np.any(w <= 0):
        raise InputError("omega: every frequency must be finite and > 0")
    roots = one_harmonic_roots(eps, force, Q, w)
    r = np.sqrt(roots)
    with np.errstate(invalid="ignore"):
        stable = amplitude_slope(roots, w[:, None], d) > 0
    return ResponseCurve(w, r, stable & np.isfinite(r))


def one_harmonic_folds(eps: float, force: float, Q: float) -> list[float]:
    """Fold frequencies (ascending) to full double precision: ``G = ∂G/∂u = 0``.

    Candidates from the roots in ω² of the discriminant, polished by Newton's method on the
    2×2 system in ``(u, ω)``.
    """
    d = Drive(eps, force, 1.0, Q)
    if eps == 0:
        return []
    values = {_e: eps, _f: force, _g: d.damping}
    # SymPy's floats do not overflow: scale by the largest coefficient before rounding to
    # float64 (ε = 1e100 puts ε⁴f² far beyond 1e308, yet the roots in ω² are ordinary)
    exact = [sp.Float(c.subs(values), 30) for c in _fold_polynomial().all_coeffs()]
    scale = max(abs(c) for c in exact)
    coeffs = [float(c / scale) for c in exact] if scale != 0 else []
    if not coeffs or not all(np.isfinite(coeffs)):
        raise InputError(f"eps {eps:g}, force {force:g}, Q {Q:g}: the fold polynomial's "
                         "coefficients leave double precision")
    folds = []
    for w2 in np.roots(coeffs):
        if abs(w2.imag) > 1e-8 * (1 + abs(w2)) or w2.real <= 0:
            continue
        omega = float(np.sqrt(w2.real))
        # the double root u of the cubic: ∂G/∂u = 0 is quadratic in u
        a = 1 - omega**2
        us = np.roots([27 / 16 * eps**2, 3 * eps * a, a * a + omega**2 * d.damping**2])
        us = [float(x.real) for x in us if abs(x.imag) < 1e-8 * (1 + abs(x)) and x.real > 0]
        if not us:
            continue
        u = min(us, key=lambda x: abs(amplitude_residual(x, omega, d)))
        for _ in range(20):
            G, Gu = amplitude_residual(u, omega, d), amplitude_slope(u, omega, d)
            A = 1 - omega**2 + 0.75 * eps * u
            Gw = u * (-4 * omega * A + 2 * omega * d.damping**2)
            Guu = 2 * A * 0.75 * eps + 1.5 * eps * A + 1.5 * eps * u * 0.75 * eps
            Guw = 2 * A * (-2 * omega) + 2 * omega * d.damping**2 + 1.5 * eps * u * (-2 * omega)
            try:
                step = np.linalg.solve([[Gu, Gw], [Guu, Guw]], [-G, -Gu])
            except np.linalg.LinAlgError:  # singular (a cusp, or the scale of u swamps ω)
                break
            u, omega = u + step[0], omega + step[1]
            if np.max(np.abs(step)) < 1e-15 * (1 + abs(omega) + abs(u)):
                break
        if u > 0 and abs(amplitude_residual(u, omega, d)) < 1e-9 * (1 + force**2):
            folds.append(float(omega))
    return sorted({float(w) for w in folds})


@dataclass(frozen=True)
class Continuation:
    """The N-harmonic balance traced in ω by pseudo-arclength: one or more pieces, each a
    curve from one end of the range to an end (``pieces``: the index of each piece's first
    point; consecutive points of different pieces are not neighbours on the curve)."""

    omega: np.ndarray
    x: np.ndarray  # (points, 2N): a_1, a_3, …, b_1, b_3, …
    folds: list[float]  # where dω/ds changes sign, refined
    pieces: tuple[int, ...] = (0,)
    complete: bool = True  # every one-harmonic root at both ends lies on a traced piece

    def piece_slices(self) -> list[slice]:
        """The points of each piece."""
        ends = [*self.pieces[1:], len(self.omega)]
        return [slice(a, b) for a, b in zip(self.pieces, ends, strict=True)]


MAX_POINTS = 20000
CONTINUATION_SECONDS = 60.0
# NOTE: the continuation refuses a curve it estimates at more than 20000 steps or a minute of
# work (its max_seconds: the CLI's cost limit, lifted by --allow-slow) instead of running for
# ten minutes: `response --force 1e30 --harmonics 60` once ran 590 s and stopped short of the
# range, reporting a partial curve.
MAX_Q = 1e12
# NOTE: near the resonance x(ω) changes by ~Q·2e-16 relative between neighbouring doubles in ω:
# the corrector's 1e-13 then needs Q ≲ 1e3 (above, some steps take all 30 iterations: slower,
# still right); by Q ~ 1e16 the peak is narrower than the doubles around ω = 1 and the
# continuation wanders for good.  Below 1e12 it is only slower.


def point_seconds(harmonics: int) -> float:
    """Seconds per continuation point (predictor, corrector, two SVDs) on this 2-core machine,
    single-threaded BLAS: 2 ms at N = 8, 42 ms at N = 100."""
    return 1.5e-3 + 4e-6 * harmonics**2


def _curve_extent(eps: float, force: float, Q: float, lo: float, hi: float) -> float:
    """The largest one-harmonic amplitude on ``[lo, hi]`` (a grid, ω = 1 and the folds)."""
    folds = [w for w in one_harmonic_folds(eps, force, Q) if lo <= w <= hi]
    omega = np.unique(np.concatenate([np.linspace(lo, hi, 2001), [1.0] if lo <= 1 <= hi else [],
                                      folds, np.nextafter(folds, -np.inf)]))
    with np.errstate(divide="ignore"):  # undamped and linear at ω = 1: r = ∞, said as such
        r = one_harmonic_curve(eps, force, Q, omega).r
    return float(np.nanmax(r)) if np.any(~np.isnan(r)) else 0.0


def continuation_points(eps: float, force: float, Q: float, lo: float, hi: float,
                        step: float = 0.02, max_points: int = MAX_POINTS) -> float:
    """About how many continuation steps the response curve on ``[lo, hi]`` takes — its length
    in (a, b, ω) is about ``(hi − lo) + π r_max`` (see :func:`continue_balance`) —, or
    :class:`InputError` above ``max_points``."""
    r_max = _curve_extent(eps, force, Q, lo, hi)
    estimate = ((hi - lo) + np.pi * r_max) / step
    if not estimate <= max_points:
        raise InputError(f"force {force:g} (eps {eps:g}, Q {Q:g}): the response curve spans ω "
                         f"in [{lo:.3g}, {hi:.3g}] with amplitudes up to {r_max:.3g}, about "
                         f"{estimate:.2g} continuation steps of {step:g}; the limit is "
                         f"{max_points}")
    return estimate


def continuation_seconds(eps: float, force: float, Q: float, harmonics: int, lo: float,
                         hi: float) -> float:
    """The estimated wall time of :func:`continue_balance` (points × :func:`point_seconds`);
    :class:`InputError` for a curve over MAX_POINTS steps."""
    return continuation_points(eps, force, Q, lo, hi) * point_seconds(harmonics)


def response_range(eps: float, force: float, Q: float) -> tuple[float, float]:
    """The ω range a response curve is drawn on: half the lowest to 1.25 × the highest of
    ω = 1 and the one-harmonic folds."""
    folds = one_harmonic_folds(eps, force, Q)
    return 0.5 * min([1.0, *folds]), 1.25 * max([1.0, *folds])


def continue_balance(eps: float, force: float, Q: float, harmonics: int, omega_start: float,
                     omega_stop: float, step: float = 0.02, max_points: int = MAX_POINTS,
                     max_seconds: float = CONTINUATION_SECONDS) -> Continuation:
    """Trace the harmonic-balance curve on ``[lo, hi]`` (the two ends) through any number of
    folds: first from the smallest one-harmonic root at ``omega_start`` (the in-well branch
    of a softening spring, the only one below the resonance of a hardening one), until ω leaves
    the range; then from every root at either end that no traced piece has reached, each until
    it leaves the range.  A softening spring's curve is two pieces: the small-amplitude branch
    up to its fold and back down the middle branch, and the resonant branch, which leaves the
    range at its low end over the barrier.

    Refuses (:class:`InputError`) a curve too long to trace: its length in (a, b, ω) is about
    ``(hi − lo) + π r_max`` (up the resonant branch to its peak r_max and back down while the
    phase turns through π; within a factor 0.4–1.4 of the traced length from ε = −0.1 to 1,
    f = 0.05 to 10, Q = 5 to 1000), so ``length/step`` points at
    :func:`point_seconds` each must stay within ``max_points`` and ``max_seconds``;
    and a continuation whose linear algebra fails or that does not leave the range."""
    check_harmonics(harmonics)
    d = Drive(eps, force, omega_start, Q)
    Drive(eps, force, omega_stop, Q)
    sysm = BalanceSystem(eps, force, d.damping, harmonics)
    lo, hi = sorted((omega_start, omega_stop))
    where = f"force {force:g} (eps {eps:g}, Q {Q:g})"
    if np.isfinite(Q) and Q > MAX_Q:
        raise InputError(f"Q {Q:g}: the resonance is {1 / Q:.0e} wide in ω, too narrow for the "
                         f"continuation to follow in double precision; Q up to {MAX_Q:.0e}")
    estimate = continuation_points(eps, force, Q, lo, hi, step, max_points)
    seconds = estimate * point_seconds(harmonics)
    if seconds > max_seconds:
        raise InputError(f"harmonics {harmonics}: about {seconds:.0f} s of continuation "
                         f"({estimate:.0f} points × {1e3 * point_seconds(harmonics):.0f} ms) for "
                         f"{where}; the limit is {max_seconds:.0f} s, ask for fewer")
    if not first_order_branches(d):
        raise InputError(f"{where}: no one-harmonic branch at ω = {omega_start:g} to start from")
    return _continue(sysm, lambda: _end_solutions(sysm, d, omega_start, omega_stop),
                     omega_start, omega_stop, step, estimate, seconds,
                     point_seconds(harmonics), max_points, where)


def _continue(sysm: BalanceSystem | PolynomialBalance, end_solutions, omega_start: float,
              omega_stop: float, step: float, estimate: float, seconds: float,
              per_point: float, max_points: int, where: str) -> Continuation:
    """The pseudo-arclength loop of :func:`continue_balance` on any balance with ``residual``,
    ``jacobian`` and ``d_omega`` in ``(x, ω)``: from each of ``end_solutions()`` (``(ω, x,
    direction into the range)`` at the two ends, the first at ``omega_start``, and whether
    they are complete) not reached yet, until ω leaves the range; ``estimate`` points of
    ``per_point`` seconds, ``seconds`` in all, bound its steps and its time."""
    lo, hi = sorted((omega_start, omega_stop))
    limit = min(max_points, int(2 * max(seconds, CONTINUATION_SECONDS) / per_point))
    allowed = 2 * max(seconds, CONTINUATION_SECONDS)
    deadline = time.monotonic() + allowed
    points: list[np.ndarray] = []
    starts: list[int] = []
    folds: list[float] = []
    y = None
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            ends, complete = end_solutions()
            visited = [False] * len(ends)
            while not all(visited):
                k = visited.index(False)
                visited[k] = True
                omega0, x0, direction = ends[k]
                y = np.append(x0, omega0)
                t = _tangent(sysm, y, None)
                if t[-1] * direction < 0:
                    t = -t
                starts.append(len(points))
                points.append(y)
                y_old = None
                while y_old is None or lo <= y[-1] <= hi:
                    if len(points) - len(starts) >= limit:
                        raise InputError(f"{where}: the continuation did not leave ω in "
                                         f"[{lo:.3g}, {hi:.3g}] within {limit} steps of "
                                         f"{step:g} (the estimate was {estimate:.0f}); the "
                                         "curve is longer than it looks")
                    if time.monotonic() > deadline:
                        raise InputError(f"{where}: the continuation gave up after "
                                         f"{allowed:.0f} s at ω = {y[-1]:.6g}, "
                                         f"{len(points)} points in (its estimate: "
                                         f"{estimate:.0f}): the corrector does not converge "
                                         "there")
                    y_new = _corrector(sysm, y + step * t, t)
                    t_new = _tangent(sysm, y_new, t)
                    if not (np.all(np.isfinite(y_new)) and np.all(np.isfinite(t_new))):
                        raise np.linalg.LinAlgError("the balance overflowed")
                    if t_new[-1] * t[-1] < 0:
                        folds.append(_refine_fold(sysm, y, t, step))
                    y_old, y, t = y, y_new, t_new
                    points.append(y)
                # the end it left by: the nearest solution there is reached
                edge = lo if y[-1] < lo else hi
                s_edge = (edge - y_old[-1]) / (y[-1] - y_old[-1])
                x_edge = y_old[:-1] + s_edge * (y[:-1] - y_old[:-1])
                at_edge = [j for j, e in enumerate(ends) if e[0] == edge]
                if at_edge:
                    nearest = min(at_edge, key=lambda j: np.linalg.norm(ends[j][1] - x_edge))
                    if np.linalg.norm(ends[nearest][1] - x_edge) \
                            <= 1e-2 * (1 + np.linalg.norm(x_edge)):
                        visited[nearest] = True
    except np.linalg.LinAlgError as exc:
        at = "" if y is None else f" at ω = {y[-1]:.4g}"
        raise InputError(f"{where}: the harmonic-balance continuation failed{at} ({exc}): "
                         "its Jacobian is singular or the balance overflowed") from None
    arr = np.array(points)
    return Continuation(arr[:, -1], arr[:, :-1], sorted(folds), tuple(starts), complete)


def _end_solutions(sysm: BalanceSystem, d: Drive, omega_start: float, omega_stop: float
                   ) -> tuple[list[tuple[float, np.ndarray, float]], bool]:
    """The balance solutions from every one-harmonic root at both ends, as ``(ω, x, the
    direction into the range)``: the smallest root at ``omega_start`` first, then the others
    there and those at ``omega_stop``, each by amplitude (distinct solutions only); and
    whether every root's balance converged."""
    out: list[tuple[float, np.ndarray, float]] = []
    complete = True
    h = sysm.harmonics
    for omega, direction in ((omega_start, np.sign(omega_stop - omega_start)),
                             (omega_stop, np.sign(omega_start - omega_stop))):
        roots = first_order_branches(Drive(d.eps, d.force, omega, d.Q))
        for br in sorted(roots, key=lambda b: abs(b.A1)):
            x = np.zeros(2 * h)
            x[0], x[h] = br.A1 * np.cos(br.delta0), br.A1 * np.sin(br.delta0)
            try:
                x = _newton_fixed_omega(sysm, x, omega)
            except np.linalg.LinAlgError:
                x = np.full(2 * h, np.nan)
            size = np.max(np.abs(x))
            residual = np.max(np.abs(sysm.residual(x, omega)))
            if not residual <= 1e-9 * (abs(d.force) + (1 + omega**2) * size
                                       + abs(d.eps) * size**3):
                complete = False
                continue
            if all(e[0] != omega or np.linalg.norm(e[1] - x) > 1e-6 * (1 + np.linalg.norm(x))
                   for e in out):
                out.append((omega, x, float(direction)))
    if not out or out[0][0] != omega_start:
        raise np.linalg.LinAlgError(f"no balance converged at ω = {omega_start:.4g}")
    return out, complete


def _newton_fixed_omega(sysm: BalanceSystem, x: np.ndarray, omega: float) -> np.ndarray:
    for _ in range(50):
        dx = np.linalg.solve(sysm.jacobian(x, omega), -sysm.residual(x, omega))
        x = x + dx
        if np.max(np.abs(dx)) < 1e-14 * (1 + np.max(np.abs(x))):
            break
    return x


def _extended_jacobian(sysm: BalanceSystem, y: np.ndarray) -> np.ndarray:
    x, omega = y[:-1], y[-1]
    return np.column_stack([sysm.jacobian(x, omega), sysm.d_omega(x, omega)])


def _tangent(sysm: BalanceSystem, y: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
    """Unit null vector of ``[R_x | R_ω]``, oriented along ``previous``."""
    _, _, vt = np.linalg.svd(_extended_jacobian(sysm, y))
    t = vt[-1]
    if previous is not None and t @ previous < 0:
        t = -t
    return t


def _corrector(sysm: BalanceSystem, y: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Newton on ``R(y) = 0`` with ``t·(y − y_pred) = 0``."""
    y_pred = y.copy()
    for _ in range(30):
        x, omega = y[:-1], y[-1]
        F = np.append(sysm.residual(x, omega), t @ (y - y_pred))
        J = np.vstack([_extended_jacobian(sysm, y), t])
        dy = np.linalg.solve(J, -F)
        y = y + dy
        if np.max(np.abs(dy)) < 1e-13 * (1 + np.max(np.abs(y))):
            break
    return y


def _refine_fold(sysm: BalanceSystem, y: np.ndarray, t: np.ndarray, step: float) -> float:
    """Secant on the step length for ``t_ω = 0`` between two continuation points."""
    def t_omega(h: float) -> tuple[float, np.ndarray]:
        z = _corrector(sysm, y + h * t, t)
        return _tangent(sysm, z, t)[-1], z

    h0, h1 = 0.0, step
    f0, f1 = t[-1], t_omega(step)[0]
    z = y
    for _ in range(40):
        if f1 == f0:
            break
        h2 = h1 - f1 * (h1 - h0) / (f1 - f0)
        f2, z = t_omega(h2)
        h0, f0, h1, f1 = h1, f1, h2, f2
        if abs(f2) < 1e-13:
            break
    return float(z[-1])


# --- the 1/3 subharmonic (eq. 10.83–10.87) ---------------------------------------------------

_a, _b, _F, _w1, _eps1 = sp.symbols("a b F omega epsilon")


# --- every distinct periodic orbit at one ω: seeds, shooting, deduplication -----------------
# (here, after the continuation: its crossings with ω are the seeds the one-harmonic cubic lacks)

SAME_ORBIT = 1e-8
# NOTE: two shot orbits are one when their states (q(0), q̇(0)/ω) differ by at most 1e-8 of the
# larger state's norm (≈ the orbit's first-harmonic amplitude r).  Shooting converges to ~1e-12
# (near a fold, with its multiplier near +1, to ~1e-10); two distinct orbits a distance Δω from
# a fold differ by ~r·√Δω, so only orbits within ~1e-16 of a fold (one orbit, in double
# precision) are merged.
SHOOTING_TOLERANCES = (1e-12, 1e-10)
# NOTE: near a fold a Floquet multiplier nears +1, M − I is nearly singular and amplifies the
# integrator's ~1e-13 into Newton steps that never fall below 1e-12 (shooting gave up 2e-6 from
# the fold at ω = 1.49323, ε 0.1, f 0.3, Q 20): each seed is tried again at 1e-10.
BALANCE_NEAR = 1e-3
# NOTE: a converged balance is the orbit's own when its (q(0), q̇(0)) lies within 1e-3 (relative,
# as SAME_ORBIT) of the orbit's (8 harmonics: ~1e-10; the other orbits lie O(1) away, or
# ~√(distance to the fold) near one); a seed whose balance converged onto another orbit and
# whose shooting did not follow it is shown with the balance of a seed that did.
CONTINUATION_HARMONICS = 8
# NOTE: the continuation that seeds the orbits carries at most 8 harmonics (2 ms a point; its
# crossings are then polished at the harmonics asked): a seed, not an answer.
REFINED_HARMONICS = 32
# NOTE: where shooting from a balance fails, the balance is solved again with 32 harmonics and
# shot once more: an orbit near the barrier of a softening spring can be so unstable (Floquet
# multiplier 7.7e7 at ε −0.1, f 0.3, Q 20, ω 0.3) that the 8-harmonic balance's 1e-5 error
# carries its trajectory out of the well within the period; 32 harmonics bring it to ~1e-16.
CONTINUATION_BUDGET = 15.0
# NOTE: seconds the seeding continuation may take (its own estimate, checked before it starts);
# above, the seeds are the one-harmonic roots only and the result says it may be incomplete.


@dataclass(frozen=True)
class Orbit:
    """One distinct periodic orbit of period ``2π/ω`` with how it was found.

    ``seed``: ``"one_harmonic"`` when shooting from a one-harmonic root reached it,
    ``"continuation"`` when only a crossing of the continued harmonic balance did.
    ``branch``: the one-harmonic root that stands for it at first order (the root whose shooting
    reached it, the nearest when several did; or, when as many roots as orbits are left over,
    the one of the same rank in amplitude), ``None`` when no root does.
    ``balance``: the harmonic balance whose solution led to the orbit.  ``orbit`` is ``None``
    for a root whose balance converged but whose shooting did not (at the corners of the
    domain): then the branch is that balance alone (``paired = "balance"``)."""

    orbit: PeriodicOrbit | None  # None: shooting found no orbit (see periodic_orbits)
    balance: HarmonicBalance | None
    branch: Branch | None
    seed: str
    paired: str | None  # "shot" (its shooting reached it), "rank", "balance", None (no root)
    failure: ShootingFailure | None = None  # orbit None: why shooting from the balance failed

    @property
    def r(self) -> float:
        """The first-harmonic amplitude ``√(A₁² + B₁²)`` of the true orbit (of the balance
        where shooting found none)."""
        return _amplitude({"orbit": self.orbit, "balance": self.balance})


@dataclass(frozen=True)
class Orbits:
    """Every distinct orbit found at one drive, largest first, and the one-harmonic roots."""

    orbits: tuple[Orbit, ...]
    roots: tuple[tuple[Branch, int | None], ...]  # each root, the index of the orbit it stands for
    complete: bool  # whether the seeds cover the whole response curve (balance_crossings)
    note: str  # how the seeds were found
    failures: tuple[ShootingFailure | None, ...] = ()  # per root: why its shooting found none


def _guess(hb: HarmonicBalance, omega: float) -> np.ndarray:
    """``(q(0), q̇(0)) = (Σ A_n, ω Σ n B_n)`` of a balance solution."""
    A, B = amplitudes(hb.coefficients, 0.0, 2 * hb.harmonics - 1)
    return np.array([sum(A.values()), omega * sum(n * b for n, b in B.items())])


def _state_distance(a: np.ndarray, b: np.ndarray, omega: float) -> float:
    """``|Δ(q, q̇/ω)|`` relative to the larger of the two states' norms (see SAME_ORBIT)."""
    u, v = np.array([a[0], a[1] / omega]), np.array([b[0], b[1] / omega])
    size = max(float(np.linalg.norm(u)), float(np.linalg.norm(v)))
    return float(np.linalg.norm(u - v)) / size if size > 0 else 0.0


def _first_harmonic_gap(br: Branch, found: dict) -> float:
    """Distance of a root's ``(A₁ cos δ₀, A₁ sin δ₀)`` from an orbit's ``(A₁, B₁)`` (its
    balance's, where shooting found none)."""
    if found["orbit"] is None:
        A, B = amplitudes(found["balance"].coefficients, 0.0, 1)
    else:
        A, B = found["orbit"].A, found["orbit"].B
    return math.hypot(br.A1 * math.cos(br.delta0) - A[1], br.A1 * math.sin(br.delta0) - B[1])


def _amplitude(found: dict) -> float:
    """r of a found orbit, or of its balance when shooting found none."""
    if found["orbit"] is None:
        A, B = amplitudes(found["balance"].coefficients, 0.0, 1)
        return math.hypot(A[1], B[1])
    return math.hypot(found["orbit"].A[1], found["orbit"].B[1])


def try_balance(d: Drive, start: Branch | np.ndarray, harmonics: int,
                converged: bool = False) -> HarmonicBalance | None:
    """:func:`driven.harmonic_balance` from ``start``, or ``None`` where its Newton meets a
    singular Jacobian (exactly at a fold) — and, with ``converged``, where it does not
    converge."""
    try:
        hb = harmonic_balance(d, start, harmonics)
    except np.linalg.LinAlgError:
        return None
    return hb if hb.converged or not converged else None


def _balance_vector(hb: HarmonicBalance) -> np.ndarray:
    """``x = (a_1, a_3, …, b_1, b_3, …)`` of a balance solution."""
    A, B = amplitudes(hb.coefficients, 0.0, 2 * hb.harmonics - 1)
    return np.array([*A.values(), *B.values()])


@functools.lru_cache(maxsize=16)
def _traced(eps: float, force: float, Q: float, harmonics: int, lo: float,
            hi: float) -> tuple[object, str]:
    """The continued balance on ``[lo, hi]`` (cached: one curve serves every ω on it), or
    ``None`` and the reason it was refused."""
    try:
        return continue_balance(eps, force, Q, harmonics, lo, hi,
                                max_seconds=CONTINUATION_BUDGET), ""
    except InputError as exc:
        return None, str(exc)


def balance_crossings(d: Drive, harmonics: int = CONTINUATION_HARMONICS
                      ) -> tuple[list[np.ndarray], str, bool]:
    """Every point of the continued harmonic-balance curve at ``d.omega`` (damped only), as
    balance vectors ``x`` with ``harmonics`` harmonics, interpolated between continuation
    points (linearly; quadratically around each turn of ω, where both crossings near a fold
    may lie between two points): seeds, not solutions.  With how they were found, and whether
    they are complete: every piece of the curve that reaches an end of the range traced (a
    softening spring's two, see :func:`continue_balance`), or none needed (linear, one orbit;
    ω above the range, where ``response`` has one branch too).  ``False``: undamped (no
    continuation), refused, or a root at an end whose balance did not converge."""
    if d.damping == 0:
        return [], "undamped: no continuation (the response curve needs damping)", False
    if d.eps == 0:  # linear: one orbit, the root's (and the curve, up to r = fQ, is long)
        return [], "linear (eps 0): one orbit, no continuation needed", True
    lo, hi = response_range(d.eps, d.force, d.Q)
    if d.omega > hi:
        return [], (f"omega above the response curve's range (up to {hi:.6g}, 1.25 x its "
                    "highest one-harmonic fold): no continuation"), True
    lo = min(lo, max(0.98 * d.omega, MAGNITUDES[0]))
    cont, why = _traced(d.eps, d.force, d.Q, harmonics, lo, hi)
    if cont is None:
        return [], f"continuation refused ({why})", False
    seeds = []
    for piece in cont.piece_slices():
        seeds += _crossings(cont.omega[piece] - d.omega, cont.x[piece])
    note = f"continued harmonic balance (N = {harmonics}) on [{lo:.6g}, {hi:.6g}]"
    if not cont.complete:  # a root at an end whose balance did not converge: not traced
        return seeds, (f"{note}: the balance from a one-harmonic root at an end of the range "
                       "did not converge, its piece of the curve is missing"), False
    return seeds, note, True


def _crossings(w: np.ndarray, x: np.ndarray) -> list[np.ndarray]:
    """Where one piece of the continued curve meets ``w = 0`` (``w``: its ω minus the drive's),
    interpolated (see :func:`balance_crossings`)."""
    seeds = []
    for i in range(len(w) - 1):
        if w[i] * w[i + 1] <= 0 and w[i] != w[i + 1]:
            t = w[i] / (w[i] - w[i + 1])
            seeds.append(x[i] + t * (x[i + 1] - x[i]))
    for i in range(1, len(w) - 1):
        if (w[i] - w[i - 1]) * (w[i + 1] - w[i]) >= 0:
            continue
        # w(s) = w_i + b s + c s² through s = −1, 0, 1 (equal arclength steps), w(s) = 0
        b, c = (w[i + 1] - w[i - 1]) / 2, (w[i + 1] - 2 * w[i] + w[i - 1]) / 2
        disc = b * b - 4 * c * w[i]
        if c == 0 or disc < 0:
            continue
        for s in ((-b - math.sqrt(disc)) / (2 * c), (-b + math.sqrt(disc)) / (2 * c)):
            if abs(s) <= 1:
                seeds.append(x[i] + s * (x[i + 1] - x[i - 1]) / 2
                             + s * s * (x[i + 1] - 2 * x[i] + x[i - 1]) / 2)
    return seeds


def periodic_orbits(d: Drive, harmonics: int = 8, shoot_harmonics: int = 9) -> Orbits:
    """Every distinct periodic orbit of period ``2π/ω`` that the seeds reach, largest ``r``
    first, each once, with its Floquet multipliers (:func:`numerics.shoot`).

    Seeds: every real root of the one-harmonic equation (through its harmonic balance with
    ``harmonics`` harmonics, or the root itself where that balance does not converge) and,
    damped, every crossing of the continued harmonic-balance curve with this ω
    (:func:`balance_crossings`, polished at ``harmonics``): the true folds are not the
    one-harmonic ones, so near a fold the cubic has too few roots or too many.  Orbits are
    one when their states differ by at most SAME_ORBIT.  Undamped there is no continuation:
    the one-harmonic seeds only, deduplicated."""
    check_harmonics(harmonics)
    roots = first_order_branches(d)
    seeds: list[tuple[int | None, list[np.ndarray], HarmonicBalance | None]] = []
    for k, br in enumerate(roots):
        hb = try_balance(d, br, harmonics)
        first = br.A1 * np.array([math.cos(br.delta0), d.omega * math.sin(br.delta0)])
        guesses = [_guess(hb, d.omega), first] if hb is not None and hb.converged else [first]
        seeds.append((k, guesses, hb))
    crossings, note, complete = balance_crossings(d, min(harmonics, CONTINUATION_HARMONICS))
    for x in crossings:
        hb = try_balance(d, x, harmonics)
        h = len(x) // 2
        raw = np.array([x[:h].sum(), d.omega * np.sum(np.arange(1, 2 * h, 2) * x[h:])])
        seeds.append((None, [_guess(hb, d.omega), raw] if hb is not None and hb.converged
                      else [raw], hb))
    found: list[dict] = []  # orbit, balance, whether that balance is the orbit's, seed
    reached: dict[int, int] = {}  # root index -> orbit index
    failures: dict[int, ShootingFailure] = {}  # root index -> why its shooting found none
    for k, guesses, hb in seeds:
        orbit, failure = _shoot_seed(d, guesses, hb, shoot_harmonics)
        if orbit is None:
            if k is not None:
                failures[k] = failure
            continue
        j = next((j for j, f in enumerate(found) if _state_distance(
            f["orbit"].initial, orbit.initial, d.omega) <= SAME_ORBIT), None)
        # the balance shown beside the orbit: one that converged onto it, if any seed's did
        own = hb is not None and hb.converged and _state_distance(
            _guess(hb, d.omega), orbit.initial, d.omega) <= BALANCE_NEAR
        if j is None:
            j = len(found)
            found.append({"orbit": orbit, "balance": hb, "own": own,
                          "seed": "one_harmonic" if k is not None else "continuation"})
        elif own and not found[j]["own"]:
            found[j].update(balance=hb, own=True)
        if k is not None:
            reached[k] = j
    # a root whose shooting failed but whose balance converged elsewhere than every orbit found
    # (the corners of the domain, where RK4 cannot follow the scales): its balance, no orbit
    for k, _, hb in seeds:
        if k is None or k in reached or hb is None or not hb.converged:
            continue
        state = _guess(hb, d.omega)
        if all(_state_distance(state, f["orbit"].initial if f["orbit"] is not None
                               else _guess(f["balance"], d.omega), d.omega)
               > (BALANCE_NEAR if f["orbit"] is not None else SAME_ORBIT) for f in found):
            reached[k] = len(found)
            found.append({"orbit": None, "balance": hb, "own": True, "seed": "one_harmonic",
                          "failure": failures.get(k)})
    rank = sorted(range(len(found)), key=lambda j: -_amplitude(found[j]))
    found = [found[j] for j in rank]
    new_index = {old: new for new, old in enumerate(rank)}
    # the first-order root standing for each orbit: the nearest root whose shooting reached it
    owner: dict[int, int] = {}  # orbit index -> root index
    for k, old in reached.items():
        j = new_index[old]
        if j not in owner or _first_harmonic_gap(roots[k], found[j]) \
                < _first_harmonic_gap(roots[owner[j]], found[j]):
            owner[j] = k
    # ... then, when as many roots as orbits are left over, the leftovers by rank in amplitude
    free_roots = [k for k in range(len(roots)) if k not in owner.values()]
    free_orbits = [j for j in range(len(found)) if j not in owner]
    paired = {j: "shot" if found[j]["orbit"] is not None else "balance" for j in owner}
    if len(free_roots) == len(free_orbits):
        owner.update(zip(free_orbits, sorted(free_roots, key=lambda k: -abs(roots[k].A1)),
                         strict=True))
        paired.update(dict.fromkeys(free_orbits, "rank"))
    stands = {k: j for j, k in owner.items()}
    orbits = tuple(Orbit(f["orbit"], f["balance"], roots[owner[j]] if j in owner else None,
                         f["seed"], paired.get(j), f.get("failure"))
                   for j, f in enumerate(found))
    return Orbits(orbits, tuple((br, stands.get(k)) for k, br in enumerate(roots)),
                  complete, note, tuple(failures.get(k) for k in range(len(roots))))


def _shoot_seed(d: Drive, guesses: list[np.ndarray], hb: HarmonicBalance | None,
                shoot_harmonics: int) -> tuple[PeriodicOrbit | None, ShootingFailure | None]:
    """Shooting from each guess at each of SHOOTING_TOLERANCES, then (a converged balance)
    from the balance solved again with REFINED_HARMONICS; the orbit, or why the first guess
    found none."""
    first = None
    for tol, guess in itertools.product(SHOOTING_TOLERANCES, guesses):
        found = shoot_explained(d.eps, d.force, d.omega, d.damping, guess,
                                harmonics=shoot_harmonics, tol=tol)
        if isinstance(found, PeriodicOrbit):
            return found, None
        first = first or found
    if hb is not None and hb.converged and hb.harmonics < REFINED_HARMONICS:
        fine = try_balance(d, _balance_vector(hb), REFINED_HARMONICS, converged=True)
        if fine is not None:
            for tol in SHOOTING_TOLERANCES:
                found = shoot_explained(d.eps, d.force, d.omega, d.damping,
                                        _guess(fine, d.omega), harmonics=shoot_harmonics,
                                        tol=tol)
                if isinstance(found, PeriodicOrbit):
                    return found, None
    return None, first


# --- a user's driven oscillator: every orbit at one ω, from a continuation in the drive -------

class _DriveFamily:
    """A :class:`driven.PolynomialBalance` at fixed ω as a family in the drive amplitude f:
    the interface :func:`_tangent` and :func:`_corrector` take, with f in ω's place."""

    def __init__(self, system: PolynomialBalance, omega: float) -> None:
        self.system, self.omega = system, omega

    def residual(self, x: np.ndarray, f: float) -> np.ndarray:
        return self.system.residual(x, self.omega, force=f)

    def jacobian(self, x: np.ndarray, f: float) -> np.ndarray:
        return self.system.jacobian(x, self.omega)

    def d_omega(self, x: np.ndarray, f: float) -> np.ndarray:
        return -self.system.drive


@dataclass(frozen=True)
class DriveContinuation:
    """The balance traced in the drive amplitude from rest (``f = 0``, ``q = 0``) at one ω."""

    force: np.ndarray  # f at each point
    x: np.ndarray  # (points, unknowns)
    complete: bool  # it reached the amplitude bound, past which no orbit lies
    note: str


MAX_DRIVE_POINTS = 4000
# NOTE: the continuation in f stops after 4000 points (~5 s at 31 unknowns) and says its seeds
# may be incomplete; a curve up to an amplitude bound of a few hundred takes far fewer.


def continue_in_drive(system: PolynomialBalance, omega: float, bound: float | None,
                      max_points: int = MAX_DRIVE_POINTS,
                      max_seconds: float = CONTINUATION_BUDGET) -> DriveContinuation:
    """Trace the balance from ``f = 0``, ``x = 0`` by pseudo-arclength in ``(x, f)`` until the
    first harmonic exceeds ``bound`` (:func:`driven.amplitude_bound`; then every orbit at the
    drive lies on the traced part, up to isolated branches the curve does not pass) or the
    budget ends.  The step adapts: halved where the corrector fails or the tangent turns by
    more than ~25°, grown by 1.5 where it does not, up to 1 % of the curve's scale and, near
    ``±f``, to half the distance from it (down to 1e-4 of the scale)."""
    fam = _DriveFamily(system, omega)
    m = system.size
    k1 = int(np.nonzero(system.orders == 1)[0][0])
    sin1 = system.n_cos + int(np.nonzero(system.orders[system.orders > 0] == 1)[0][0])
    scale = abs(system.force) + (bound if bound is not None else 10.0)
    h_max, h_floor, h_min = scale / 100, scale * 1e-4, scale * 1e-9
    h = h_max / 4
    y = np.zeros(m + 1)
    deadline = time.monotonic() + max_seconds
    with np.errstate(over="ignore", invalid="ignore"):
        t = _tangent(fam, y, None)
        if t[-1] < 0:
            t = -t
        if abs(t[-1]) < 1e-8:  # ω at a linear resonance, undamped: q = 0 is degenerate
            t = _first_direction(fam, y, h, k1, sin1)
        points = [y]
        while True:
            r = math.hypot(y[k1], y[sin1])
            if bound is not None and r > bound:
                return _drive_curve(points, True, f"continued in the drive amplitude from 0 "
                                    f"up to the amplitude bound r = {bound:.4g}")
            if len(points) >= max_points or time.monotonic() > deadline:
                return _drive_curve(points, False, f"the continuation in the drive stopped at "
                                    f"r = {r:.4g} after {len(points)} points"
                                    + ("" if bound is None else f" (bound {bound:.4g})"))
            try:
                y_new = _corrector(fam, y + h * t, t)
                t_new = _tangent(fam, y_new, t)
            except np.linalg.LinAlgError:
                y_new = t_new = None
            good = (y_new is not None and np.all(np.isfinite(y_new))
                    and np.all(np.isfinite(t_new))
                    and np.max(np.abs(fam.residual(y_new[:-1], y_new[-1])))
                    <= 1e-9 * (1 + np.max(np.abs(y_new)))
                    and np.linalg.norm(y_new - y) <= 2 * h and t_new @ t > 0.9)
            if not good:
                h /= 2
                if h < h_min:
                    return _drive_curve(points, False, f"the continuation in the drive failed "
                                        f"at r = {r:.4g}, f = {y[-1]:.4g} (no step converges)")
                continue
            y, t = y_new, t_new
            points.append(y)
            # near ±f the steps shrink with the distance to it, so that a fold of the curve
            # just beyond ±f (two crossings close together) leaves points on both sides
            near = min(abs(y[-1] - system.force), abs(y[-1] + system.force))
            h = min(1.5 * h, h_max, max(h_floor, 0.5 * near))


def _first_direction(fam: _DriveFamily, y: np.ndarray, h: float, k1: int,
                     sin1: int) -> np.ndarray:
    """Where ``[J | −e₁]`` is singular at rest (an undamped harmonic at its linear resonance,
    the response growing like ``f^(1/3)``), the curve's first direction: the first of ±cos ωt,
    ±sin ωt whose pseudo-arclength step converges; its tangent there, pointing away from rest.
    """
    for k, sign in itertools.product((k1, sin1), (1.0, -1.0)):
        t = np.zeros_like(y)
        t[k] = sign
        try:
            z = _corrector(fam, y + h * t, t)
            if np.max(np.abs(fam.residual(z[:-1], z[-1]))) <= 1e-9 * (1 + np.max(np.abs(z))):
                t = _tangent(fam, z, z - y)
                return t
        except np.linalg.LinAlgError:
            continue
    raise InputError("the balance at rest is singular (a harmonic at its linear resonance) and "
                     "no first step from it converges")


def _drive_curve(points: list[np.ndarray], complete: bool, note: str) -> DriveContinuation:
    arr = np.array(points)
    return DriveContinuation(arr[:, -1], arr[:, :-1], complete, note)


@dataclass(frozen=True)
class EquationOrbit:
    """One distinct periodic orbit of a user's driven oscillator: its balance and, where
    shooting found it, the true orbit with its Floquet multipliers."""

    orbit: PeriodicOrbit | None
    balance: np.ndarray | None  # x of the balance solution that led to it
    converged: bool  # that balance's Newton converged
    residual: float | None
    failure: ShootingFailure | None = None

    @property
    def r(self) -> float:
        """The first-harmonic amplitude of the true orbit (of the balance where none)."""
        if self.orbit is not None:
            return math.hypot(self.orbit.A.get(1, 0.0), self.orbit.B.get(1, 0.0))
        return float("nan")


@dataclass(frozen=True)
class EquationOrbits:
    orbits: tuple[EquationOrbit, ...]
    system: PolynomialBalance
    complete: bool
    note: str
    seeds: int


def _half_period(system: PolynomialBalance, x: np.ndarray) -> np.ndarray:
    """``q(t + T/2)``: harmonic k times ``(−1)^k``; it answers ``−f cos ωt`` where ``q`` answers
    ``f cos ωt`` (the force is autonomous)."""
    sign = (-1.0) ** np.concatenate([system.orders, system.orders[system.orders > 0]])
    return sign * x


def equation_orbits(de: DrivenEquation, harmonics: int = 8,
                    shoot_harmonics: int | None = None) -> EquationOrbits:
    """Every distinct periodic orbit of period ``2π/ω`` of a :class:`driven.DrivenEquation`
    that the seeds reach, largest ``r`` first, each once, checked by shooting with its Floquet
    multipliers (:func:`numerics.shoot_table`).

    Seeds: where the balance (at most CONTINUATION_HARMONICS harmonics), continued in the drive
    amplitude from rest (:func:`continue_in_drive`), crosses ``f`` — and ``−f``, shifted by half
    a period — (:func:`_crossings`, quadratic around the folds); each is polished by Newton's
    method at ``harmonics`` and shot from; orbits within SAME_ORBIT are one."""
    check_harmonics(harmonics)
    top = 2 * harmonics - 1
    shoot_harmonics = top if shoot_harmonics is None else shoot_harmonics
    omega, f = de.omega, de.force
    coarse = PolynomialBalance(de.terms, f, min(harmonics, CONTINUATION_HARMONICS), de.odd)
    fine = PolynomialBalance(de.terms, f, harmonics, de.odd)
    bound = amplitude_bound(de.terms, omega, abs(f))
    curve = continue_in_drive(coarse, omega, bound)
    seeds = _crossings(curve.force - f, curve.x)
    seeds += [_half_period(coarse, x) for x in _crossings(curve.force + f, curve.x)]
    table = ForceTable.of(de.terms)
    found: list[EquationOrbit] = []
    for x in seeds:
        A, B = coarse.amplitudes(x)
        start = fine.vector(A, B)
        xb, converged, residual = fine.solve(start, omega)
        guesses = [fine.state(xb, omega)] if converged else []
        guesses.append(coarse.state(x, omega))
        orbit, failure = None, None
        for tol, guess in itertools.product(SHOOTING_TOLERANCES, guesses):
            shot = shoot_table(table, f, omega, guess, harmonics=shoot_harmonics, tol=tol)
            if isinstance(shot, PeriodicOrbit):
                orbit, failure = shot, None
                break
            failure = failure or shot
        if orbit is None:
            if converged and all(o.orbit is not None or _state_distance(
                    fine.state(o.balance, omega), fine.state(xb, omega), omega) > SAME_ORBIT
                    for o in found):
                found.append(EquationOrbit(None, xb, converged, residual, failure))
            continue
        j = next((j for j, o in enumerate(found) if o.orbit is not None and _state_distance(
            o.orbit.initial, orbit.initial, omega) <= SAME_ORBIT), None)
        own = converged and _state_distance(fine.state(xb, omega), orbit.initial,
                                            omega) <= BALANCE_NEAR
        if j is None:
            found.append(EquationOrbit(orbit, xb if converged else None, converged and own,
                                       residual if converged else None))
        elif own and not found[j].converged:
            found[j] = EquationOrbit(orbit, xb, True, residual)
    found.sort(key=lambda o: -(o.r if o.orbit is not None else _balance_r(fine, o.balance)))
    note = curve.note + f"; {len(seeds)} crossings of the drive amplitude"
    return EquationOrbits(tuple(found), fine, curve.complete, note, len(seeds))


def _balance_r(system: PolynomialBalance, x: np.ndarray) -> float:
    A, B = system.amplitudes(x)
    return math.hypot(A.get(1, 0.0), B.get(1, 0.0))


# --- a user's driven oscillator: the response curve in ω -------------------------------------

_poly = np.polynomial.polynomial

@dataclass(frozen=True)
class OneHarmonic:
    """``q = r cos(ωt − φ)`` in ``q̈ + g(q, q̇) = f cos ωt`` (a polynomial ``g``, its table
    ``terms``): the first harmonic of ``q̈ + g`` is ``(P_c(r), P_s(r))`` with
    ``P_c = −ω²r + Σ c ω^b C_ab r^(a+b)``, ``P_s = Σ c ω^b S_ab r^(a+b)`` (``C_ab``, ``S_ab``
    the cos θ, sin θ coefficients of ``cos^a θ (−sin θ)^b``), and ``H(r) = P_c² + P_s² − f²``
    vanishes at the amplitudes: for eq. 10.60 exactly the cubic ``G`` of the module's header
    (in ``r``), so the same folds."""

    terms: dict[tuple[int, int], float]
    force: float

    @functools.cached_property
    def _harmonics(self) -> list[tuple[int, int, float, float, float]]:
        theta = 2 * np.pi * np.arange(64) / 64
        out = []
        for (a, b), c in sorted(self.terms.items()):
            wave = np.cos(theta) ** a * (-np.sin(theta)) ** b
            out.append((a, b, c, 2 * float(np.mean(wave * np.cos(theta))),
                        2 * float(np.mean(wave * np.sin(theta)))))
        return out

    def polynomial(self, omega: float) -> np.ndarray:
        """``H(r)`` at ``omega``: its coefficients, lowest power first, trimmed."""
        d = max(a + b for a, b, *_ in self._harmonics)
        pc, ps = np.zeros(d + 1), np.zeros(d + 1)
        pc[1] = -omega**2
        for a, b, c, cos, sin in self._harmonics:
            pc[a + b] += c * omega**b * cos
            ps[a + b] += c * omega**b * sin
        H = _poly.polyadd(_poly.polymul(pc, pc), _poly.polymul(ps, ps))
        H[0] -= self.force**2
        return _poly.polytrim(H, 0)

    def amplitudes(self, omega: float) -> np.ndarray:
        """The positive real roots r of ``H``, ascending (each polished by Newton's method)."""
        H = self.polynomial(omega)
        dH = _poly.polyder(H)
        roots = _poly.polyroots(H)
        scale = 1 + np.abs(roots)
        rs = roots.real[(np.abs(roots.imag) <= 1e-7 * scale) & (roots.real > 0)]
        for _ in range(3):
            d = _poly.polyval(rs, dH)
            with np.errstate(divide="ignore", invalid="ignore"):
                rs = rs - np.where(d != 0, _poly.polyval(rs, H) / d, 0.0)
        return np.sort(rs[rs > 0])

    def phase(self, r: float, omega: float) -> float:
        """φ of the root ``r``: ``(P_c, P_s) = f (cos φ, −sin φ)``."""
        pc = -omega**2 * r + sum(c * omega**b * cos * r ** (a + b)
                                 for a, b, c, cos, _ in self._harmonics)
        ps = sum(c * omega**b * sin * r ** (a + b) for a, b, c, _, sin in self._harmonics)
        return math.atan2(-ps, pc)

    def folds(self, lo: float, hi: float, points: int = 1500) -> list[float]:
        """The ω in ``[lo, hi]`` where two amplitudes meet (``H = ∂H/∂r = 0``): where the
        number of roots changes on a geometric grid, each polished by Newton's method in
        ``(r, ω)``."""
        grid = np.geomspace(lo, hi, points)
        counts = [len(self.amplitudes(w)) for w in grid]
        out = []
        for i in range(points - 1):
            if counts[i] == counts[i + 1]:
                continue
            j = i if counts[i] > counts[i + 1] else i + 1  # the side with the pair
            rs = self.amplitudes(grid[j])
            if len(rs) < 2:
                continue
            k = int(np.argmin(np.diff(rs)))
            z = np.array([0.5 * (rs[k] + rs[k + 1]), 0.5 * (grid[i] + grid[i + 1])])
            fold = self._polish_fold(z)
            if fold is not None and grid[i] - 1e-3 * grid[i] <= fold <= grid[i + 1] * 1.001:
                out.append(fold)
        return sorted(out)

    def _polish_fold(self, z: np.ndarray) -> float | None:
        def F(z: np.ndarray) -> np.ndarray:
            H = self.polynomial(z[1])
            return np.array([_poly.polyval(z[0], H), _poly.polyval(z[0], _poly.polyder(H))])

        for _ in range(40):
            f0 = F(z)
            J = np.empty((2, 2))
            for k in range(2):
                e = np.zeros(2)
                e[k] = 1e-7 * (1 + abs(z[k]))
                J[:, k] = (F(z + e) - F(z - e)) / (2 * e[k])
            try:
                dz = np.linalg.solve(J, -f0)
            except np.linalg.LinAlgError:
                return None
            z = z + dz
            if not (np.all(np.isfinite(z)) and z[0] > 0 and z[1] > 0):
                return None
            if np.max(np.abs(dz)) < 1e-15 * (1 + np.max(np.abs(z))):
                break
        return float(z[1])

    def extent(self, lo: float, hi: float, folds: list[float]) -> float:
        """The largest amplitude on ``[lo, hi]`` (a grid and the folds)."""
        grid = np.concatenate([np.linspace(lo, hi, 400), folds])
        return float(max((r for w in grid for r in self.amplitudes(w)), default=0.0))


EQUATION_POINT_SECONDS = (2e-3, 1e-6)
# NOTE: seconds per continuation point of a user's equation, fixed + per unknown²: the
# alternating frequency/time Jacobian (S samples × m unknowns, S ≈ 2(d + 1)·2N) and the SVD;
# measured 2.5 ms at m = 31 (N = 8, a force with even terms), 16 ms at m = 127 (N = 32).


def equation_point_seconds(unknowns: int) -> float:
    return EQUATION_POINT_SECONDS[0] + EQUATION_POINT_SECONDS[1] * unknowns**2


@dataclass(frozen=True)
class EquationResponse:
    """What ``lindstedt response EQUATION`` computes before its sweeps."""

    one_harmonic: OneHarmonic
    omega_range: tuple[float, float]
    one_harmonic_folds: list[float]
    linear_frequency: float


def linear_frequency(terms: dict[tuple[int, int], float]) -> float:
    """``ω₀ = √c`` of the linear term ``c q``; :class:`InputError` where ``c ≤ 0``."""
    c = terms.get((1, 0), 0.0)
    if not c > 0:
        raise InputError(f"the linear term {c:g}*q: no oscillation about q = 0 (ω0² must be "
                         "> 0) to draw a response curve around")
    return math.sqrt(c)


def equation_range(terms: dict[tuple[int, int], float], force: float,
                   omega_min: float | None = None,
                   omega_max: float | None = None) -> EquationResponse:
    """The ω range of a response curve: as for eq. 10.60, half the lowest to 1.25 × the highest
    of ω₀ and the one-harmonic folds (looked for in ``[ω₀/10, 10ω₀]``), each end replaced by
    ``omega_min``/``omega_max`` where given."""
    w0 = linear_frequency(terms)
    one = OneHarmonic(dict(terms), float(force))
    folds = one.folds(0.1 * w0, 10 * w0)
    lo = 0.5 * min([w0, *folds]) if omega_min is None else omega_min
    hi = 1.25 * max([w0, *folds]) if omega_max is None else omega_max
    for flag, value in (("--omega-min", lo), ("--omega-max", hi)):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"{flag} {value!r}: must be finite and > 0")
    if not lo < hi:
        raise InputError(f"--omega-min {lo:g} must lie below --omega-max {hi:g}")
    return EquationResponse(one, (lo, hi), [w for w in folds if lo <= w <= hi], w0)


def equation_continuation_seconds(terms: dict[tuple[int, int], float], force: float,
                                  harmonics: int, odd: bool, lo: float, hi: float,
                                  step: float = 0.02, max_points: int = MAX_POINTS
                                  ) -> tuple[float, float]:
    """``(points, seconds)`` the continuation of :func:`continue_equation` is estimated at (its
    length ``(hi − lo) + π r_max`` over ``step``, r_max from the one-harmonic amplitudes), or
    :class:`InputError` above ``max_points``."""
    one = OneHarmonic(dict(terms), float(force))
    r_max = one.extent(lo, hi, one.folds(lo, hi, 400))
    estimate = ((hi - lo) + np.pi * r_max) / step
    if not estimate <= max_points:
        raise InputError(f"force {force:g}: the response curve spans ω in [{lo:.3g}, {hi:.3g}] "
                         f"with one-harmonic amplitudes up to {r_max:.3g}, about "
                         f"{estimate:.2g} continuation steps of {step:g}; the limit is "
                         f"{max_points}")
    unknowns = 2 * harmonics if odd else 4 * harmonics - 1
    # the ends: two continuations in the drive amplitude, each within its own deadline
    return estimate, estimate * equation_point_seconds(unknowns)


def continue_equation(de: DrivenEquation, harmonics: int, omega_start: float,
                      omega_stop: float, step: float = 0.02, max_points: int = MAX_POINTS,
                      max_seconds: float = CONTINUATION_SECONDS) -> Continuation:
    """:func:`continue_balance` for a user's :class:`driven.DrivenEquation` (its ω ignored):
    the :class:`driven.PolynomialBalance` with ``harmonics`` traced in ω through its folds,
    starting from every balance solution at the two ends that the continuation in the drive
    amplitude from rest reaches (:func:`continue_in_drive`, as ``driven EQUATION`` seeds),
    the smallest at ``omega_start`` first."""
    check_harmonics(harmonics)
    fine = PolynomialBalance(de.terms, de.force, harmonics, de.odd)
    lo, hi = sorted((omega_start, omega_stop))
    where = f"{de.name} ({de.text})"
    estimate, seconds = equation_continuation_seconds(de.terms, de.force, harmonics, de.odd,
                                                      lo, hi, step, max_points)
    if seconds > max_seconds:
        raise InputError(f"harmonics {harmonics}: about {seconds:.0f} s of continuation "
                         f"({estimate:.0f} points) for {where}; the limit is "
                         f"{max_seconds:.0f} s, ask for fewer")
    return _continue(fine, lambda: _equation_ends(de, fine, omega_start, omega_stop),
                     omega_start, omega_stop, step, estimate, seconds,
                     equation_point_seconds(fine.size), max_points, where)


def equation_solutions(de: DrivenEquation, fine: PolynomialBalance, omega: float
                       ) -> tuple[list[np.ndarray], bool]:
    """Every balance solution at ``omega`` that the continuation in the drive amplitude from
    rest crosses (at most CONTINUATION_HARMONICS harmonics, then Newton at ``fine``'s), distinct,
    by amplitude; and whether that continuation was complete and every crossing converged."""
    coarse = PolynomialBalance(de.terms, de.force, min(fine.harmonics, CONTINUATION_HARMONICS),
                               de.odd)
    curve = continue_in_drive(coarse, omega, amplitude_bound(de.terms, omega, abs(de.force)))
    seeds = _crossings(curve.force - de.force, curve.x)
    seeds += [_half_period(coarse, x) for x in _crossings(curve.force + de.force, curve.x)]
    out: list[np.ndarray] = []
    complete = curve.complete
    for x in seeds:
        A, B = coarse.amplitudes(x)
        xb, converged, _ = fine.solve(fine.vector(A, B), omega)
        if not converged:
            complete = False
            continue
        if all(np.linalg.norm(y - xb) > 1e-6 * (1 + np.linalg.norm(xb)) for y in out):
            out.append(xb)
    out.sort(key=lambda x: _balance_r(fine, x))
    return out, complete


def _equation_ends(de: DrivenEquation, fine: PolynomialBalance, omega_start: float,
                   omega_stop: float) -> tuple[list[tuple[float, np.ndarray, float]], bool]:
    """:func:`_end_solutions` for a user's equation: Newton's method on the balance from every
    one-harmonic root (:class:`OneHarmonic`) at each end; where one of them does not converge,
    the solutions the continuation in the drive amplitude crosses there
    (:func:`equation_solutions`)."""
    out: list[tuple[float, np.ndarray, float]] = []
    complete = True
    one = OneHarmonic(dict(de.terms), de.force)
    k1 = int(np.nonzero(fine.orders == 1)[0][0])
    s1 = fine.n_cos + int(np.nonzero(fine.orders[fine.orders > 0] == 1)[0][0])
    for omega, direction in ((omega_start, np.sign(omega_stop - omega_start)),
                             (omega_stop, np.sign(omega_start - omega_stop))):
        found: list[np.ndarray] = []
        for r in one.amplitudes(omega):
            x = np.zeros(fine.size)
            phi = one.phase(r, omega)
            x[k1], x[s1] = r * math.cos(phi), r * math.sin(phi)
            x, converged, _ = fine.solve(x, omega)
            if not converged:
                found, whole = equation_solutions(de, fine, omega)
                complete = complete and whole
                break
            if all(np.linalg.norm(y - x) > 1e-6 * (1 + np.linalg.norm(x)) for y in found):
                found.append(x)
        found.sort(key=lambda x: _balance_r(fine, x))
        out.extend((omega, x, float(direction)) for x in found)
    if not out or out[0][0] != omega_start:
        raise np.linalg.LinAlgError(f"no balance converged at ω = {omega_start:.4g}")
    return out, complete


def orbit_fold_table(table: ForceTable, force: float, omega: float, y0: np.ndarray,
                     tol: float = 1e-11) -> tuple[float, np.ndarray, np.ndarray] | None:
    """:func:`numerics.orbit_fold` for ``q̈ + g(q, q̇) = f cos ωt`` (``g`` the table): the true
    orbit with a Floquet multiplier ``+1`` by Newton's method in ``(y₀, ω)`` on
    ``(φ_T(y₀) − y₀, det(M − I))``; ``(ω, y₀, multipliers)`` or ``None``."""
    def F(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        end, _, _ = flow_table(table, force, z[2], z[:2], 2 * np.pi / z[2], samples=1)
        mono = end[2:].reshape(2, 2).T
        return np.array([*(end[:2] - z[:2]), np.linalg.det(mono - np.eye(2))]), mono

    z = np.array([*y0, omega], dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(30):
            if not z[2] > 0:
                return None
            f0, _ = F(z)
            J = np.empty((3, 3))
            for k in range(3):
                e = np.zeros(3)
                e[k] = 1e-7 * (1 + abs(z[k]))
                J[:, k] = (F(z + e)[0] - F(z - e)[0]) / (2 * e[k])
            if not (np.all(np.isfinite(J)) and np.all(np.isfinite(f0))):
                return None
            try:
                dz = np.linalg.solve(J, -f0)
            except np.linalg.LinAlgError:
                return None
            z = z + dz
            if np.max(np.abs(dz)) < tol * (1 + np.max(np.abs(z))):
                _, mono = F(z)
                return float(z[2]), z[:2], np.linalg.eigvals(mono)
    return None


ESCAPE_FACTOR = 10.0
# NOTE: a user's equation has no barrier in closed form: a sweep whose |q| passes 10× the largest
# |q| of any balance solution on the range (Σ|a_k| + |b_k| over the continued curve), moving
# outward, has left every steady state there: an escape (a softening spring over its barrier
# runs off to infinity within a period or two after that).

RESPONSE = "response"


def response_equation(text: str, values: dict[str, str], name: str = "oscillator",
                      method: str = RESPONSE) -> DrivenEquation:
    """A user's damped driven oscillator for a response curve in its drive frequency: the
    :class:`driven.DrivenEquation` of ``text`` (ω left free: every parameter but the drive
    frequency needs a value), refused in one line where the force depends on the drive
    frequency or has no damping (a term odd in q')."""
    from ..analysis.polynomial import driven_equation

    def lowered(omega: float) -> DrivenEquation:
        try:
            return driven_equation(text, values, omega, name)
        except InputError as exc:
            message = str(exc).replace(": driven does not apply: ", f": {method} does not apply: ")
            message = message.replace("(its value is --omega)", f"(the {method} curve's ω)")
            if " is the drive frequency; give it with --omega" in message:
                message = message.split(";")[0] + f"; {method} varies it (drop this --param)"
            raise InputError(message) from None

    de, other = lowered(1.0), lowered(2.0)
    if de.terms != other.terms or de.force != other.force:
        raise InputError(f"{name} ({text}): {method} does not apply: the force or the drive's "
                         f"amplitude depends on the drive frequency {de.frequency}, which the "
                         "curve varies")
    if not de.dissipative:
        raise InputError(f"{name} ({text}): {method} does not apply: no damping (a term odd in "
                         "the velocity, e.g. q'/Q): no steady state to draw a response curve of")
    linear_frequency(de.terms)
    return de


@dataclass(frozen=True)
class EquationCurve:
    """A user's response curve, computed once for the JSON, the table and the figure: the
    equation, its range, the continued balance, the sweeps up and down and their escape
    bound."""

    de: DrivenEquation
    er: EquationResponse
    cont: Continuation
    fine: PolynomialBalance
    table: ForceTable
    bound: float
    up: Sweep
    down: Sweep


def equation_response(text: str, values: dict[str, str], harmonics: int,
                      name: str = "oscillator", omega_min: float | None = None,
                      omega_max: float | None = None,
                      max_seconds: float = CONTINUATION_SECONDS) -> EquationCurve:
    """``response EQUATION``'s curve: the continuation over the range, then the simulated
    sweeps both ways, escapes detected past :data:`ESCAPE_FACTOR` × the largest balance."""
    from ..analysis.polynomial import PolynomialBalance

    de = response_equation(text, values, name)
    er = equation_range(de.terms, de.force, omega_min, omega_max)
    lo, hi = er.omega_range
    cont = continue_equation(de, harmonics, lo, hi, max_seconds=max_seconds)
    table = ForceTable.of(de.terms)
    bound = ESCAPE_FACTOR * float(np.max(np.sum(np.abs(cont.x), axis=1)))
    return EquationCurve(
        de, er, cont, PolynomialBalance(de.terms, de.force, harmonics, de.odd), table, bound,
        sweep_table(table, de.force, lo, hi, barrier=bound, bound=bound),
        sweep_table(table, de.force, hi, lo, barrier=bound, bound=bound))
