"""Exact and high-accuracy references: elliptic-integral periods, the Jacobi-cn solution,
periodic orbits of the driven oscillator by shooting, and their Floquet multipliers."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike
from scipy.special import ellipj, ellipk

from ..algebra.series import laurent_from_fourier, laurent_product
from ..display import harmonics_table
from ..errors import InputError


def duffing_period_exact(A: ArrayLike, eps: ArrayLike) -> np.ndarray:
    """``T = 4K(m)/√(1+x)``, ``m = x/(2(1+x))``, ``x = εA²`` (notes App. 4.9); NaN for x ≤ -1.

    SciPy's ``ellipk`` takes any ``m < 1``, so softening springs (``-1 < x < 0``, ``m < 0``)
    are exact too.
    """
    x = np.asarray(eps, dtype=float) * np.asarray(A, dtype=float) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        out = 4 * ellipk(x / (2 * (1 + x))) / np.sqrt(1 + x)
    return np.where(x > -1, out, np.nan)


def duffing_q_exact(t: ArrayLike, A: ArrayLike, eps: ArrayLike) -> np.ndarray:
    """``q(t) = A cn(√(1+x) t | m)`` for ``x = εA² ≥ 0`` (SciPy's ``ellipj`` needs 0 ≤ m ≤ 1)."""
    A = np.asarray(A, dtype=float)
    x = np.asarray(eps, dtype=float) * A**2
    if np.any(x < 0):
        raise ValueError("duffing_q_exact: x = εA² < 0 needs cn with m < 0 (use mpmath)")
    m = x / (2 * (1 + x))
    return A * ellipj(np.sqrt(1 + x) * np.asarray(t, dtype=float), m)[1]


def pendulum_period_exact(theta0: ArrayLike) -> np.ndarray:
    """``T = 4K(sin²(θ₀/2))`` (notes App. 4.1); NaN for ``|θ₀| ≥ π``."""
    th = np.asarray(theta0, dtype=float)
    out = 4 * ellipk(np.sin(th / 2) ** 2)
    return np.where(np.abs(th) < np.pi, out, np.nan)


# --- periodic orbits of the driven oscillator: shooting and Floquet multipliers ---------------

@dataclass(frozen=True)
class ForceTable:
    """A polynomial force ``g(q, q̇) = Σ c_i q^(a_i) q̇^(b_i)`` of ``q̈ + g(q, q̇) = f cos ωt``
    (its linear part included), as the arrays the compiled integrator reads."""

    q_powers: np.ndarray  # a_i (int64)
    v_powers: np.ndarray  # b_i (int64)
    coefficients: np.ndarray  # c_i (float64)

    @staticmethod
    def of(terms: dict[tuple[int, int], float]) -> ForceTable:
        """From ``{(a, b): c}``; zero coefficients are dropped."""
        items = sorted((key, float(c)) for key, c in terms.items() if c != 0)
        return ForceTable(np.array([a for (a, _), _ in items], dtype=np.int64),
                          np.array([b for (_, b), _ in items], dtype=np.int64),
                          np.array([c for _, c in items], dtype=np.float64))

    @property
    def terms(self) -> dict[tuple[int, int], float]:
        return {(int(a), int(b)): float(c) for a, b, c in
                zip(self.q_powers, self.v_powers, self.coefficients, strict=True)}

    @property
    def odd(self) -> bool:
        """``g(−q, −q̇) = −g(q, q̇)``: a periodic response to ``cos ωt`` holds odd harmonics."""
        return bool(np.all((self.q_powers + self.v_powers) % 2 == 1))

    @property
    def dissipative(self) -> bool:
        """A term odd in ``q̇``: the flow does not keep area (``det M ≠ 1`` in general), so
        stability asks every Floquet multiplier inside the unit circle."""
        return bool(np.any(self.v_powers % 2 == 1))

    @property
    def cubic(self) -> np.ndarray | None:
        """``(k₁, k₃, γ)`` when the force is ``k₁q + k₃q³ + γq̇`` (eq. 10.60's form, any of
        them zero): the integrator's unrolled fast path; else ``None``."""
        terms = self.terms
        if not set(terms) <= {(1, 0), (3, 0), (0, 1)}:
            return None
        return np.array([terms.get((1, 0), 0.0), terms.get((3, 0), 0.0),
                         terms.get((0, 1), 0.0)])

    @property
    def degree(self) -> int:
        return int(np.max(self.q_powers + self.v_powers, initial=1))


def duffing_table(eps: float, damping: float) -> ForceTable:
    """Eq. 10.60's force ``q + εq³ + q̇/Q`` as a :class:`ForceTable`."""
    return ForceTable.of({(1, 0): 1.0, (3, 0): eps, (0, 1): damping})


@njit(cache=True)
def _power(x: float, n: int) -> float:
    """``x**n`` for an integer ``n ≥ 0`` by multiplication (the low powers unrolled)."""
    if n == 0:
        return 1.0
    if n == 1:
        return x
    if n == 2:
        return x * x
    if n == 3:
        return x * x * x
    out = x * x * x
    for _ in range(n - 3):
        out *= x
    return out


@njit(cache=True)
def _table_force(q: float, p: float, qp: np.ndarray, vp: np.ndarray,
                 cs: np.ndarray) -> tuple[float, float, float]:
    """``g = Σ c q^a p^b`` and its partial derivatives ``∂g/∂q``, ``∂g/∂p``."""
    g, gq, gp = 0.0, 0.0, 0.0
    for i in range(cs.size):
        a, b, c = qp[i], vp[i], cs[i]
        qa, pb = _power(q, a), _power(p, b)
        g += c * qa * pb
        if a > 0:
            gq += c * a * _power(q, a - 1) * pb
        if b > 0:
            gp += c * b * qa * _power(p, b - 1)
    return g, gq, gp


@njit(cache=True)
def _rhs(t: float, y: np.ndarray, qp: np.ndarray, vp: np.ndarray, cs: np.ndarray,
         cubic: np.ndarray | None, force: float, omega: float, out: np.ndarray) -> None:
    """``q̈ = f cos ωt − Σ c q^a q̇^b`` and its variational equation:
    y = (q, p, M11, M21, M12, M22).  ``cubic``: ``None``, or ``(k₁, k₃, γ)`` when the table
    is ``k₁q + k₃q³ + γq̇`` (:attr:`ForceTable.cubic`): then the force is evaluated unrolled
    (numba compiles the kernel once for each case and drops the branch not taken)."""
    q, p = y[0], y[1]
    if cubic is not None:  # the fast path (eq. 10.60)
        g = cubic[0] * q + cubic[1] * q * q * q + cubic[2] * p
        gq, gp = cubic[0] + 3.0 * cubic[1] * q * q, cubic[2]
    else:
        g, gq, gp = _table_force(q, p, qp, vp, cs)
    out[0] = p
    out[1] = force * np.cos(omega * t) - g
    for col in range(2):
        u, w = y[2 + 2 * col], y[3 + 2 * col]
        out[2 + 2 * col] = w
        out[3 + 2 * col] = -gq * u - gp * w


NO_TERMS = np.zeros((0, 4))
# NOTE: the ``extra`` rows of :func:`_rk4_step` when there are none.


@njit(cache=True, inline="always")
def _field(t: float, y: np.ndarray, qp: np.ndarray, vp: np.ndarray, cs: np.ndarray,
           cubic: np.ndarray | None, force: float, omega: float, beta: float,
           extra: np.ndarray, out: np.ndarray) -> None:
    """:func:`_rhs` with the drive's phase ``ωt + βt²/2`` (a linear chirp; ``β = 0`` leaves
    ``ωt`` exact) and the time-dependent terms ``extra``: each row ``(a, c, ν, φ)`` adds
    ``c q^a cos(νt + φ)`` to ``q̈`` — ``a = 0`` another drive, ``a = 1`` a parametric
    stiffness (carried into the variational columns)."""
    _rhs(t, y, qp, vp, cs, cubic, force, omega + 0.5 * beta * t, out)
    for i in range(extra.shape[0]):
        w = extra[i, 1] * np.cos(extra[i, 2] * t + extra[i, 3])
        if extra[i, 0] == 0.0:
            out[1] += w
        else:
            for j in range(1, 6, 2):
                out[j] += w * y[j - 1]


@njit(cache=True, inline="always")
def _rk4_step(t: float, h: float, y: np.ndarray, qp: np.ndarray, vp: np.ndarray,
              cs: np.ndarray, cubic: np.ndarray | None, force: float, omega: float,
              beta: float, extra: np.ndarray, k1: np.ndarray, k2: np.ndarray, k3: np.ndarray,
              k4: np.ndarray, tmp: np.ndarray) -> None:
    """One classical RK4 step of ``h`` from ``t``, in place on ``y = (q, p, M11, M21, M12,
    M22)`` (the state and the monodromy columns) for ``q̈ + Σ c q^a q̇^b = f cos(ωt + βt²/2)
    + extra`` (:func:`_field`): every integrator of this module steps with it.
    ``k1 … k4, tmp``: work arrays of six entries (no temporaries in the loop)."""
    # NOTE: six entries always, even where the columns are not read: loops of a constant
    # length unroll (the flow 0.76 ms with y.size, 0.58 ms with 6).
    _field(t, y, qp, vp, cs, cubic, force, omega, beta, extra, k1)
    for j in range(6):
        tmp[j] = y[j] + 0.5 * h * k1[j]
    _field(t + 0.5 * h, tmp, qp, vp, cs, cubic, force, omega, beta, extra, k2)
    for j in range(6):
        tmp[j] = y[j] + 0.5 * h * k2[j]
    _field(t + 0.5 * h, tmp, qp, vp, cs, cubic, force, omega, beta, extra, k3)
    for j in range(6):
        tmp[j] = y[j] + h * k3[j]
    _field(t + h, tmp, qp, vp, cs, cubic, force, omega, beta, extra, k4)
    for j in range(6):
        y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])


@njit(cache=True)
def _rk4(y0: np.ndarray, t0: float, t1: float, steps: int, qp: np.ndarray, vp: np.ndarray,
         cs: np.ndarray, cubic: np.ndarray | None, force: float, omega: float, samples: int,
         bound: float, extra: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Classical RK4 with ``steps`` steps on ``q̈ + Σ c q^a q̇^b = f cos ωt`` (the table
    ``qp, vp, cs``, and the rows ``extra`` of :func:`_field`); returns the end state,
    ``samples`` equispaced values of q on [t0, t1) (``steps`` must be a multiple of
    ``samples``) and the time the trajectory escaped (−1 if it did not): ``|q| > bound``
    moving outward (``q q̇ ≥ 0``), where it stops, the state and the samples not reached NaN."""
    h = (t1 - t0) / steps
    y = y0.copy()
    k1, k2, k3, k4 = np.empty(6), np.empty(6), np.empty(6), np.empty(6)
    tmp = np.empty(6)
    qs = np.empty(samples)
    every = steps // samples
    escaped = -1.0
    for i in range(steps):
        if i % every == 0:
            qs[i // every] = y[0]
        t = t0 + i * h
        _rk4_step(t, h, y, qp, vp, cs, cubic, force, omega, 0.0, extra, k1, k2, k3, k4, tmp)
        if abs(y[0]) > bound and y[0] * y[1] >= 0.0:
            escaped = t + h
            for j in range(i // every + 1, samples):
                qs[j] = np.nan
            y[:] = np.nan
            break
    return y, qs, escaped


STEPS_PER_PERIOD = 4096
# NOTE: RK4 at 4096 and 8192 steps per period, Richardson-combined (error ∝ h⁴ cancels):
# the remaining O(h⁶) is ~1e-13 for the amplitudes of the notes' table.


def escape_bound(eps: float, force: float) -> float:
    """The largest ``|q|`` any periodic orbit reaches, and past which nothing returns: ``inf``
    for ``ε ≥ 0``; for a softening spring the positive root of ``|ε|x³ − x − |f| = 0`` (just
    beyond the barrier ``1/√−ε``).

    At the largest ``|q|`` of an orbit ``q̇ = 0`` and ``q q̈ ≤ 0``: ``q² (|ε|q² − 1) ≤ |f q|``.
    Past the root, ``q q̈ > 0`` wherever ``q̇ = 0``, so a trajectory there moving outward
    (``q q̇ ≥ 0``) never turns back: ``|q|`` grows without bound (it escapes the well)."""
    if not eps < 0:
        return math.inf
    k, f = -float(eps), abs(float(force))
    x = max(math.sqrt(2 / k), (2 * f / k) ** (1 / 3))  # right of the root: g(x) ≥ 0
    for _ in range(100):  # Newton on the convex g from the right: monotone
        step = (k * x**3 - x - f) / (3 * k * x * x - 1)
        x -= step
        if step <= 1e-15 * x:
            break
    return x


def flow_table(table: ForceTable, force: float, omega: float, y0: np.ndarray, period: float,
               samples: int = 64, steps: int | None = None,
               bound: float = math.inf, extra: np.ndarray = NO_TERMS
               ) -> tuple[np.ndarray, np.ndarray, float]:
    """One period of ``q̈ + g(q, q̇) = f cos ωt`` (``g`` the table; the time-dependent rows
    ``extra`` of :func:`_field` added) from ``y0`` with its monodromy columns, ``samples``
    values of q over it and the time the trajectory escaped past ``bound`` (−1 if it did not;
    the state and the samples from there are NaN): Richardson-extrapolated from two RK4 step
    sizes, or plain RK4 with ``steps`` steps."""
    state = np.concatenate([np.asarray(y0, dtype=float), [1.0, 0.0, 0.0, 1.0]])
    bound = float(bound)
    args = (table.q_powers, table.v_powers, table.coefficients, table.cubic, float(force),
            float(omega))
    extra = np.asarray(extra, dtype=float).reshape(-1, 4)
    if steps is not None:
        return _rk4(state, 0.0, period, steps, *args, samples, bound, extra)
    coarse, qc, tc = _rk4(state, 0.0, period, STEPS_PER_PERIOD, *args, samples, bound, extra)
    fine, qf, tf = _rk4(state, 0.0, period, 2 * STEPS_PER_PERIOD, *args, samples, bound, extra)
    escaped = min((t for t in (tc, tf) if t >= 0), default=-1.0)
    return fine + (fine - coarse) / 15, qf + (qf - qc) / 15, escaped


def flow_escape(y0: np.ndarray, period: float, eps: float, force: float, omega: float,
                damping: float, samples: int = 64, steps: int | None = None,
                bound: float = math.inf) -> tuple[np.ndarray, np.ndarray, float]:
    """:func:`flow` and the time the trajectory escaped past ``bound`` (−1 if it did not; the
    state and the samples from there are NaN)."""
    return flow_table(duffing_table(eps, damping), force, omega, y0, period, samples, steps,
                      bound)


def flow(y0: np.ndarray, period: float, eps: float, force: float, omega: float,
         damping: float, samples: int = 64,
         steps: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """State after one period (with monodromy columns) and q sampled over it, Richardson-
    extrapolated from two RK4 step sizes; or plain RK4 with ``steps`` steps (a multiple of
    ``samples``) when given.  NaN where the trajectory escaped the well
    (:func:`escape_bound`)."""
    end, qs, _ = flow_escape(y0, period, eps, force, omega, damping, samples, steps,
                             escape_bound(eps, force))
    return end, qs


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit of period ``2π/ω`` found by shooting, with its Floquet multipliers."""

    initial: np.ndarray  # (q(0), q̇(0))
    A: dict[int, float]  # cos nωt coefficients
    B: dict[int, float]  # sin nωt coefficients
    multipliers: np.ndarray
    stable: bool
    residual: float

    def _repr_html_(self) -> str:
        moduli = ", ".join(f"{abs(m):.6g}" for m in self.multipliers)
        return harmonics_table(
            f"periodic orbit by shooting: q(0) = {self.initial[0]:.6g}, "
            f"q̇(0) = {self.initial[1]:.6g}", self.A, self.B,
            f"Floquet |λ| = {moduli}: {'stable' if self.stable else 'unstable'}; "
            f"residual {self.residual:.1e}")


SAMPLES = 64
# NOTE: q is sampled 64 times per orbit for its harmonics (up to 31); more harmonics take the
# next power of two above twice their number, a divisor of the RK4 step count.


def _samples(harmonics: int, steps: int) -> int:
    """Samples of q per orbit that resolve ``harmonics`` (FFT bins 0..samples/2) and divide
    ``steps``; :class:`InputError` when the steps cannot carry that many."""
    if isinstance(harmonics, bool) or not isinstance(harmonics, (int, np.integer)) \
            or harmonics < 1:
        raise InputError(f"harmonics {harmonics!r}: must be an integer ≥ 1")
    samples = SAMPLES
    while samples // 2 <= harmonics:
        samples *= 2
    if samples > steps or steps % samples:
        raise InputError(f"harmonics {harmonics}: shooting with {steps} RK4 steps per orbit "
                         f"resolves at most harmonic {steps // 2 - 1}")
    return samples


@dataclass(frozen=True)
class ShootingFailure:
    """Why shooting found no orbit.  ``escaped``: the trajectory from the guess itself left the
    well (:func:`escape_bound`): a state there runs off to infinity, no orbit passes through
    it; an orbit near it, if any, is too unstable for single shooting to reach."""

    reason: str
    escaped: bool
    bound: float  # the escape bound |q| of these parameters (inf: no well to leave)


def shoot(eps: float, force: float, omega: float, damping: float, guess: np.ndarray,
          harmonics: int = 9, tol: float = 1e-12, max_iter: int = 30,
          periods: int = 1, steps: int | None = None) -> PeriodicOrbit | None:
    """The orbit of :func:`shoot_explained`, or ``None`` where it found none."""
    found = shoot_explained(eps, force, omega, damping, guess, harmonics, tol, max_iter,
                            periods, steps)
    return found if isinstance(found, PeriodicOrbit) else None


def shoot_explained(eps: float, force: float, omega: float, damping: float, guess: np.ndarray,
                    harmonics: int = 9, tol: float = 1e-12, max_iter: int = 30,
                    periods: int = 1, steps: int | None = None
                    ) -> PeriodicOrbit | ShootingFailure:
    """:func:`shoot_table` on eq. 10.60 (``q + εq³ + q̇/Q``), with the escape bound of a
    softening spring's well (:func:`escape_bound`)."""
    return shoot_table(duffing_table(eps, damping), force, omega, guess, harmonics, tol,
                       max_iter, periods, steps, escape_bound(eps, force))


def shoot_table(table: ForceTable, force: float, omega: float, guess: np.ndarray,
                harmonics: int = 9, tol: float = 1e-12, max_iter: int = 30,
                periods: int = 1, steps: int | None = None, bound: float = math.inf,
                extra: np.ndarray = NO_TERMS) -> PeriodicOrbit | ShootingFailure:
    """Newton's method on ``φ_T(y₀) − y₀ = 0`` for ``q̈ + g(q, q̇) = f cos ωt`` (``g`` the
    polynomial ``table``); the monodromy matrix is its Jacobian + I.

    Stability from the Floquet multipliers: dissipative (a term odd in q̇, e.g. q̇/Q), stable
    when all ``|λ| < 1``; otherwise (area-preserving, ``det M = 1``), linearly stable when the
    pair lies on the unit circle, i.e. ``|tr M| < 2`` (a real pair ``λ, 1/λ`` with
    ``|tr M| > 2`` is unstable).  ``A``, ``B``: the odd harmonics for an odd force, else every
    harmonic up to ``harmonics`` with the mean as ``A[0]``.
    ``periods = p`` looks for an orbit of p drive periods; its ``A``, ``B`` are then the
    coefficients of ``cos(nωt/p)``, ``sin(nωt/p)``.  ``steps``: plain RK4 with that many
    steps per orbit instead of the Richardson pair (cheaper, less accurate).  Where Newton's
    method finds no orbit, a :class:`ShootingFailure` says why: a trajectory that escapes
    past ``bound`` (a softening spring's well: ``|q|`` past :func:`escape_bound` moving
    outward, from the guess or from a Newton iterate), RK4 overflowing, a singular ``M − I``,
    or no convergence.  ``extra``: the time-dependent rows of :func:`_field` (a pump
    ``c q cos(νt + φ)``, further drives), of a period dividing the orbit's.
    """
    T = periods * 2 * np.pi / omega  # periods = 3: the 1/3 subharmonic (eq. 10.83)
    samples = _samples(harmonics, STEPS_PER_PERIOD if steps is None else steps)
    y = np.array(guess, dtype=float)

    def escape(k: int | None, y: np.ndarray, at: float) -> ShootingFailure:
        where = ("the trajectory from the guess" if k == 0 else "the converged trajectory"
                 if k is None else f"the trajectory from Newton's iterate {k}")
        return ShootingFailure(
            f"{where} (q, q') = ({y[0]:.6g}, {y[1]:.6g}) escapes the well at t = {at:.4g} "
            f"(of a period {T:.4g}): |q| passes {bound:.6g} moving outward, past which no "
            "trajectory returns and no periodic orbit reaches"
            + ("; an orbit near this state, if any, is too unstable for single shooting"
               if k == 0 else ""), k == 0, bound)

    step = np.full(2, np.nan)
    for k in range(max_iter):
        end, _, at = flow_table(table, force, omega, y, T, steps=steps, bound=bound,
                                extra=extra)
        if at >= 0:
            return escape(k, y, at)
        if not np.all(np.isfinite(end)):  # RK4 overflowed: h is too big for the amplitude
            return ShootingFailure(
                f"RK4 overflowed from (q, q') = ({y[0]:.6g}, {y[1]:.6g})"
                + (f" (Newton's iterate {k})" if k else "") + ": its step is too large for "
                "this amplitude", False, bound)
        Mono = end[2:].reshape(2, 2).T
        r = end[:2] - y
        try:
            step = np.linalg.solve(Mono - np.eye(2), -r)
        except np.linalg.LinAlgError:
            return ShootingFailure(f"M - I is singular at Newton's iterate {k} (a Floquet "
                                   "multiplier +1: a fold)", False, bound)
        y = y + step
        if np.max(np.abs(step)) < tol * (1 + np.max(np.abs(y))):
            break
    else:
        return ShootingFailure(f"Newton's method did not converge in {max_iter} iterations "
                               f"(last step {np.max(np.abs(step)):.1e}, tolerance {tol:g})",
                               False, bound)
    end, qs, at = flow_table(table, force, omega, y, T, samples=samples, steps=steps,
                             bound=bound, extra=extra)
    if at >= 0:
        return escape(None, y, at)
    if not (np.all(np.isfinite(end)) and np.all(np.isfinite(qs))):
        return ShootingFailure("RK4 overflowed on the converged orbit", False, bound)
    Mono = end[2:].reshape(2, 2).T
    lam = np.linalg.eigvals(Mono)
    stable = multipliers_stable(lam, table.dissipative)
    c = np.fft.rfft(qs) / len(qs)
    odd = table.odd
    A = {n: float(2 * c[n].real) for n in range(1, harmonics + 1, 2 if odd else 1)}
    B = {n: float(-2 * c[n].imag) for n in range(1, harmonics + 1, 2 if odd else 1)}
    if not odd:
        A = {0: float(c[0].real), **A}
    return PeriodicOrbit(y, A, B, lam, stable, float(np.max(np.abs(end[:2] - y))))


@njit(cache=True)
def _sweep(qp: np.ndarray, vp: np.ndarray, cs: np.ndarray, cubic: np.ndarray | None,
           force: float, omega0: float, omega1: float, periods: int, steps: int,
           bound: float) -> tuple[np.ndarray, np.ndarray]:
    """RK4 on ``q̈ + Σ c q^a q̇^b = f cos(ω₀t + βt²/2)`` (the table ``qp, vp, cs``; ``cubic``
    as in :func:`_rhs`) through a linear frequency sweep ``ω(t) = ω₀ + βt`` of ``periods``
    drive periods; per period: the mean ω and max |q|.  Where ``|q|`` passes ``bound`` moving
    outward (``q q̇ ≥ 0``) the trajectory has escaped: it stops at the end of that period,
    the later ones' max |q| NaN."""
    mean = 0.5 * (omega0 + omega1)
    duration = periods * 2 * np.pi / mean
    beta = (omega1 - omega0) / duration
    h = 2 * np.pi / (max(omega0, omega1) * steps)
    n = int(duration / h) + 1
    h = duration / n
    q, p, t = 0.0, 0.0, 0.0
    omegas = np.zeros(periods)
    amps = np.zeros(periods)
    counts = np.zeros(periods)
    y, tmp = np.zeros(6), np.zeros(6)  # (q, p) and a zero variational part
    k1, k2, k3, k4 = np.empty(6), np.empty(6), np.empty(6), np.empty(6)
    escaped = periods
    for _ in range(n):
        phase = omega0 * t + 0.5 * beta * t * t
        k = min(int(phase / (2 * np.pi)), periods - 1)
        if k > escaped:  # the period of the escape is complete: stop
            for j in range(k, periods):  # ω at the middle of the periods not reached
                amps[j] = np.nan
                omegas[j] = np.sqrt(max(omega0**2 + 4 * np.pi * beta * (j + 0.5), 0.0))
                counts[j] = 1
            break
        amps[k] = max(amps[k], abs(q))
        omegas[k] += omega0 + beta * t
        counts[k] += 1
        _rk4_step(t, h, y, qp, vp, cs, cubic, force, omega0, beta, NO_TERMS, k1, k2, k3, k4,
                  tmp)
        q, p = y[0], y[1]
        t += h
        if escaped == periods and abs(q) > bound and q * p >= 0.0:
            escaped = k
            amps[k] = max(amps[k], abs(q))
    return omegas / np.maximum(counts, 1), amps


@dataclass(frozen=True)
class Sweep:
    """A simulated slow sweep: amplitude per drive period and where it jumps."""

    omega: np.ndarray
    amplitude: np.ndarray
    jump: float | None  # ω where the amplitude crosses between the branches, if it jumps
    resolution: float = float("nan")  # the change of ω per drive period (the sweep's step)
    escape: float | None = None  # ω where a softening spring left its well (then no jump)


SWEEP_STEPS = 64
# NOTE: RK4 steps per drive period; the amplitude per period needs ~1e-6, not 1e-12.
JUMP_RATIO = 2.0
JUMP_WINDOW = 50
# NOTE: the amplitude changing by 2× within 50 drive periods (a few damping times at the
# Q of interest, a small step in ω at the default sweep rate) is a jump, not a slope.


def sweep(eps: float, force: float, damping: float, omega_from: float, omega_to: float,
          periods: int = 10_000) -> Sweep:
    """Sweep the drive frequency slowly from ``omega_from`` to ``omega_to`` (compiled RK4): the
    amplitude per drive period, the jump between branches if any, or — a softening spring
    driven over its barrier ``|q| = 1/√−ε`` — the ω where it escapes (amplitudes NaN from there,
    no jump reported)."""
    barrier = 1 / np.sqrt(-eps) if eps < 0 else np.inf  # the potential's maxima, |q| = 1/√−ε
    return sweep_table(duffing_table(eps, damping), force, omega_from, omega_to, periods,
                       barrier, escape_bound(eps, force))


def sweep_table(table: ForceTable, force: float, omega_from: float, omega_to: float,
                periods: int = 10_000, barrier: float = math.inf,
                bound: float = math.inf) -> Sweep:
    """:func:`sweep` of ``q̈ + g(q, q̇) = f cos ωt`` (``g`` the polynomial ``table``): an
    amplitude past ``barrier``, or a trajectory past ``bound`` moving outward (where the
    integration stops), or one that overflows, is an escape."""
    omegas, amps = _sweep(table.q_powers, table.v_powers, table.coefficients, table.cubic,
                          float(force), float(omega_from), float(omega_to), periods,
                          SWEEP_STEPS, float(bound))
    step = abs(omega_to - omega_from) / periods
    with np.errstate(invalid="ignore"):
        out = ~np.isfinite(amps) | (amps > barrier)
    if out.any():  # over the barrier the orbit runs off to infinity: no branch to jump to
        first = int(np.argmax(out))
        amps = np.where(np.arange(amps.size) < first, amps, np.nan)
        return Sweep(omegas, amps, None, step, float(omegas[first]))
    skip = periods // 20  # the start-up transient
    a = amps[skip:]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.maximum(a[JUMP_WINDOW:] / a[:-JUMP_WINDOW], a[:-JUMP_WINDOW] / a[JUMP_WINDOW:])
    hits = np.nonzero(ratio > JUMP_RATIO)[0]
    if not hits.size:
        return Sweep(omegas, amps, None, step)
    # the jump is where the amplitude crosses the geometric mean of the two branches' amplitudes
    # around it, inside the window that detected it (interpolated in log amplitude)
    i = int(hits[0])
    seg = np.log(a[i:i + JUMP_WINDOW + 1])
    middle = 0.5 * (seg[0] + seg[-1])
    k = int(np.argmax(np.sign(seg - middle) != np.sign(seg[0] - middle)))
    frac = (middle - seg[k - 1]) / (seg[k] - seg[k - 1]) if k > 0 and seg[k] != seg[k - 1] else 0
    w0, w1 = omegas[skip + i + k - 1], omegas[skip + i + k]
    return Sweep(omegas, amps, float(w0 + frac * (w1 - w0)), step)


def orbit_fold(eps: float, force: float, damping: float, omega: float, y0: np.ndarray,
               tol: float = 1e-11) -> tuple[float, np.ndarray] | None:
    """A fold of the true periodic orbit: ``φ_T(y₀) = y₀`` with a Floquet multiplier ``+1``
    (``det(M − I) = 0``), by Newton's method in ``(y₀, ω)`` with a difference Jacobian."""
    def F(z: np.ndarray) -> np.ndarray:
        end, _ = flow(z[:2], 2 * np.pi / z[2], eps, force, z[2], damping, samples=1)
        Mono = end[2:].reshape(2, 2).T
        return np.array([*(end[:2] - z[:2]), np.linalg.det(Mono - np.eye(2))])

    z = np.array([*y0, omega], dtype=float)
    for _ in range(30):
        if not z[2] > 0:  # Newton left the frequencies: no fold near this guess
            return None
        f0 = F(z)
        J = np.empty((3, 3))
        for k in range(3):
            h = 1e-7 * (1 + abs(z[k]))
            e = np.zeros(3)
            e[k] = h
            J[:, k] = (F(z + e) - F(z - e)) / (2 * h)
        if not (np.all(np.isfinite(J)) and np.all(np.isfinite(f0))):
            return None  # RK4 overflowed: no orbit near this guess
        try:
            dz = np.linalg.solve(J, -f0)
        except np.linalg.LinAlgError:  # singular: no isolated fold here
            return None
        z = z + dz
        if np.max(np.abs(dz)) < tol * (1 + np.max(np.abs(z))):
            return float(z[2]), z[:2]
    return None


def _hill(omega: float, eps: float, a: float, b: float, F: float, steps: int) -> np.ndarray:
    """Monodromy over τ ∈ [0, 2π] of ω²ξ'' + (1 + 3εq₀²)ξ = 0, q₀ = a cos τ + b sin τ + F cos 3τ:
    the variational columns of :func:`_rk4` with no force and the parametric stiffness
    ``(1 + 3εq₀²)/ω²`` (``q₀²`` by the float Fourier kernel) as ``extra`` rows."""
    q0 = laurent_from_fourier(6, np.array([1, 3]), np.array([a, F]), np.array([b, 0.0]))
    square = laurent_product(q0, q0)[6:]  # c_n of q₀², n = 0 … 6
    rows = [(1.0, -(1 + 3 * eps * square[0].real) / omega**2, 0.0, 0.0)]
    rows += [(1.0, -6 * eps * abs(c) / omega**2, float(n), float(np.angle(c)))
             for n, c in enumerate(square) if n and c != 0]
    empty = ForceTable.of({})
    y, _, _ = _rk4(np.array([1.0, 0.0, 1.0, 0.0, 0.0, 1.0]), 0.0, 2 * np.pi, steps,
                   empty.q_powers, empty.v_powers, empty.coefficients, empty.cubic, 0.0, 0.0,
                   1, math.inf, np.array(rows))
    return y[2:].reshape(2, 2).T


def hill_multipliers(omega: float, eps: float, a: float, b: float, F: float,
                     steps: int = 2048) -> np.ndarray:
    """Floquet multipliers of the Hill equation (notes after eq. 10.87), Richardson-combined."""
    with np.errstate(over="ignore", invalid="ignore"):
        coarse, fine = _hill(omega, eps, a, b, F, steps), _hill(omega, eps, a, b, F, 2 * steps)
    with np.errstate(over="ignore", invalid="ignore"):
        M = fine + (fine - coarse) / 15
    if not np.all(np.isfinite(M)):  # ξ grows past 1e308 within one period: λ = ∞ and 1/λ = 0
        return np.array([np.inf, 0.0], dtype=complex)
    return np.linalg.eigvals(M)


@njit(cache=True)
def _simulate(qp: np.ndarray, vp: np.ndarray, cs: np.ndarray, cubic: np.ndarray | None,
              forces: np.ndarray, omegas: np.ndarray, h: float, n_skip: int, n_keep: int,
              every: int, q0: float, p0: float) -> np.ndarray:
    """RK4 (:func:`_rk4_step`) on ``q̈ + Σ c q^a q̇^b = Σ f_i cos ω_i t`` from (q0, p0); after
    ``n_skip`` steps keep q every ``every`` steps, ``n_keep`` values."""
    extra = np.zeros((forces.size - 1, 4))  # the drives after the first: rows (0, f, ω, 0)
    extra[:, 1], extra[:, 2] = forces[1:], omegas[1:]
    y, t = np.array([q0, p0, 0.0, 0.0, 0.0, 0.0]), 0.0  # no columns: they stay 0
    k1, k2, k3, k4, tmp = np.empty(6), np.empty(6), np.empty(6), np.empty(6), np.empty(6)
    out = np.empty(n_keep)
    total = n_skip + n_keep * every
    for i in range(total):
        if i >= n_skip and (i - n_skip) % every == 0:
            out[(i - n_skip) // every] = y[0]
        _rk4_step(t, h, y, qp, vp, cs, cubic, forces[0], omegas[0], 0.0, extra, k1, k2, k3, k4,
                  tmp)
        t += h
    return out


MAX_STEPS = 100_000_000
MAX_FIT_ENTRIES = 30_000_000
# NOTE: 1e8 compiled RK4 steps are ~20 s with four drives; 3e7 entries (240 MB) hold the
# least-squares fit of four drives' 228 tones at drive frequencies up to ~2.5.


@dataclass(frozen=True)
class ToneFit:
    """The simulated steady state's amplitude at each frequency, its standard error, and the
    rms of what the fit leaves (every tone not asked for counts as noise)."""

    amplitudes: np.ndarray
    uncertainty: np.ndarray
    rms_residual: float


def steady_state_amplitudes(table: ForceTable, forces: list[float],
                            omegas: list[float], frequencies: list[float],
                            settle: float | None = None, window: float = 2000.0,
                            initial: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """The amplitudes of :func:`steady_state_fit`."""
    return steady_state_fit(table, forces, omegas, frequencies, settle, window,
                            initial).amplitudes


def steady_state_fit(table: ForceTable, forces: list[float],
                     omegas: list[float], frequencies: list[float],
                     settle: float | None = None, window: float = 2000.0,
                     initial: tuple[float, float] = (0.0, 0.0)) -> ToneFit:
    """Amplitudes of the simulated steady state of ``q̈ + g(q, q̇) = Σ f_i cos ω_i t`` (``g``
    the polynomial ``table``; eq. 10.60's is :func:`duffing_table`) at ``frequencies`` (least
    squares on cos/sin over a long window after the transients, ``40/γ`` time units for the
    linear damping ``γq̇``, have died out), starting
    from ``initial`` = (q, q̇) — which decides the attractor where several coexist — with
    their standard errors: the covariance ``σ²(XᵀX)⁻¹`` of the fit, ``σ`` the rms residual,
    carried to each amplitude ``√(c² + s²)`` (``√((var c + var s)/2)`` where it is 0).

    NaN amplitudes when the simulated orbit overflows (it escapes to infinity: a softening
    spring driven over its barrier, or RK4 unstable at that amplitude).  :class:`InputError`
    when the simulation would exceed :data:`MAX_STEPS` or its fit :data:`MAX_FIT_ENTRIES`."""
    damping = table.terms.get((0, 1), 0.0)
    if settle is None:
        if not damping > 0:
            raise InputError("damping 0 (Q inf): the transients never die out, there is no "
                             "steady state to settle into")
        settle = 40.0 / damping
    fastest = max(max(omegas), max(frequencies))
    every = 4
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        h = 2 * np.pi / (np.float64(fastest) * 64)
        steps = (settle + window) / h
        entries = window / (h * every) * (2 * len(frequencies) + 1)
    if not steps <= MAX_STEPS:
        if settle > window:
            raise InputError(f"Q {1 / damping:g}: the transients die out over 40Q = {settle:.3g} "
                             f"time units, {steps:.2g} RK4 steps at 64 a period of frequency "
                             f"{fastest:g}; the limit is {MAX_STEPS:.0e} steps")
        raise InputError(f"frequency {fastest:g} (a drive or its tone): 64 RK4 steps a period "
                         f"over {settle + window:g} time units is {steps:.2g} steps; the limit "
                         f"is {MAX_STEPS:.0e}")
    if not entries <= MAX_FIT_ENTRIES:
        raise InputError(f"frequency {fastest:g} with {len(frequencies)} tones: the fit over "
                         f"{window:g} time units needs {entries:.2g} matrix entries; the limit is "
                         f"{MAX_FIT_ENTRIES:.0e}")
    n_keep = int(window / (h * every))
    with np.errstate(over="ignore", invalid="ignore"):
        q = _simulate(table.q_powers, table.v_powers, table.coefficients, table.cubic,
                      np.array(forces, float), np.array(omegas, float), float(h),
                      int(settle / h), n_keep, every, float(initial[0]), float(initial[1]))
    if not np.all(np.isfinite(q)):
        nan = np.full(len(frequencies), np.nan)
        return ToneFit(nan, nan, math.nan)
    t = settle + np.arange(n_keep) * h * every
    basis = [np.ones_like(t)]
    for nu in frequencies:
        basis += [np.cos(nu * t), np.sin(nu * t)]
    X = np.column_stack(basis)
    coef, *_ = np.linalg.lstsq(X, q, rcond=None)
    residual = q - X @ coef
    sigma2 = float(residual @ residual) / max(len(q) - X.shape[1], 1)
    cov = sigma2 * np.linalg.pinv(X.T @ X)
    c, s = coef[1::2], coef[2::2]
    var_c, var_s = np.diag(cov)[1::2], np.diag(cov)[2::2]
    cov_cs = np.diag(cov, 1)[1::2]
    amp = np.hypot(c, s)
    with np.errstate(invalid="ignore", divide="ignore"):
        var = np.where(amp > 0, (c * c * var_c + s * s * var_s + 2 * c * s * cov_cs)
                       / np.where(amp > 0, amp * amp, 1.0), (var_c + var_s) / 2)
    return ToneFit(amp, np.sqrt(np.maximum(var, 0.0)), math.sqrt(sigma2))


@dataclass(frozen=True)
class LimitCycleOrbit:
    """A limit cycle of the autonomous ``q̈ + g(q, q̇) = 0`` found by shooting: ``q(0)`` at the
    turn ``q̇(0) = 0``, its period, and its Floquet multipliers (one is 1, the phase; the other
    ``det M``) with the exponent ``ln|det M| / T`` (< 0: the cycle attracts)."""

    q0: float
    period: float
    multipliers: tuple[complex, complex]
    exponent: float


def limit_cycle_orbit(table: ForceTable, q0: float, period: float, tol: float = 1e-12,
                      max_iter: int = 30) -> LimitCycleOrbit | None:
    """Newton's method on ``φ_T(q₀, 0) − (q₀, 0) = 0`` in ``(q₀, T)`` (the phase fixed by
    ``q̇(0) = 0``): the Jacobian is ``[M e₁ − e₁, ẏ(T)]`` with the monodromy ``M`` from the one
    compiled RK4 step (Richardson pair).  None when Newton does not converge."""
    q, T = float(q0), float(period)
    for _ in range(max_iter):
        if not (np.isfinite(q) and np.isfinite(T) and T > 0):
            return None
        end, _, escaped = flow_table(table, 0.0, 2 * np.pi / T, np.array([q, 0.0]), T)
        if escaped >= 0 or not np.all(np.isfinite(end)):
            return None
        residual = end[:2] - np.array([q, 0.0])
        M = end[2:].reshape(2, 2, order="F")
        g, _, _ = _table_force(end[0], end[1], table.q_powers, table.v_powers,
                               table.coefficients)
        jacobian = np.column_stack([M[:, 0] - np.array([1.0, 0.0]), [end[1], -g]])
        try:
            step = np.linalg.solve(jacobian, -residual)
        except np.linalg.LinAlgError:
            return None
        q, T = q + step[0], T + step[1]
        if np.max(np.abs(step)) < tol * max(1.0, abs(q), T):
            end, _, _ = flow_table(table, 0.0, 2 * np.pi / T, np.array([q, 0.0]), T)
            M = end[2:].reshape(2, 2, order="F")
            mu = np.linalg.eigvals(M)
            mu = tuple(sorted((complex(m) for m in mu), key=lambda m: abs(abs(m) - 1)))
            return LimitCycleOrbit(q, T, mu, float(np.log(abs(np.linalg.det(M))) / T))
    return None


def true_limit_cycle(model: object, eps: float, cycle: int = 0, order: int = 12
                     ) -> LimitCycleOrbit | None:
    """The true orbit of limit cycle ``cycle`` of a :class:`models.SelfExcited` oscillator at
    ``eps``, shot from its L–P series at ``order`` (q(0) and T as the seed)."""
    from ..derive.lindstedt import derive_limit_cycle

    lc = derive_limit_cycle(model, order, cycle)
    table = ForceTable.of({(1, 0): 1.0, **{(a, b): -eps * float(c) for a, b, c in model.terms}})
    q0 = sum(float(c) * eps**j for j, c in enumerate(lc.amplitude))
    T = 2 * np.pi * sum(float(c) * eps**j for j, c in enumerate(lc.period))
    return limit_cycle_orbit(table, q0, T)


# --- Hill's equation ẍ + 2ζẋ + (δ + ε p(t))x = 0: Floquet multipliers on a grid --------------

FLOQUET_STEPS = 256
# NOTE: RK4 steps per period 2π on the Ince–Strutt chart: |tr M| to ~1e-6 for δ ≤ 3, ε ≤ 2
# (halving h changes it by less), far below the width of any verdict near the curves.


@njit(cache=True, parallel=True)
def _floquet_points(deltas: np.ndarray, eps: np.ndarray, zeta: float, rows: np.ndarray,
                    steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Monodromy over t ∈ [0, 2π] of ``ẍ + 2ζẋ + (δ + ε p(t))x = 0`` at each point
    ``(deltas[i], eps[i])`` by :func:`_rk4_step` (the linear table ``δq + 2ζq̇`` on its cubic
    fast path, ``p`` as the parametric ``extra`` rows ``(1, −R_k, k, φ_k)`` scaled by ε);
    returns ``tr M`` and ``det M``, points in parallel."""
    trace, det = np.empty(deltas.size), np.empty(deltas.size)
    h = 2 * np.pi / steps
    empty_i, empty_f = np.zeros(0, dtype=np.int64), np.zeros(0)
    for i in prange(deltas.size):
        extra = rows.copy()
        for r in range(extra.shape[0]):
            extra[r, 1] *= eps[i]
        cubic = np.array([deltas[i], 0.0, 2.0 * zeta])
        y = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 1.0])
        k1, k2, k3, k4, tmp = np.empty(6), np.empty(6), np.empty(6), np.empty(6), np.empty(6)
        for s in range(steps):
            _rk4_step(s * h, h, y, empty_i, empty_i, empty_f, cubic, 0.0, 0.0, 0.0, extra,
                      k1, k2, k3, k4, tmp)
        trace[i] = y[2] + y[5]
        det[i] = y[2] * y[5] - y[4] * y[3]
    return trace, det


def hill_rows(p: dict[int, tuple[float, float]]) -> np.ndarray:
    """``−p(t) = −Σ (a_k cos kt + b_k sin kt)`` as :func:`_field`'s parametric rows
    ``(1, −R_k, k, φ_k)``: ``a cos kt + b sin kt = R cos(kt + φ)``, ``φ = atan2(−b, a)``."""
    return np.array([(1.0, -math.hypot(a, b), float(k), math.atan2(-b, a))
                     for k, (a, b) in sorted(p.items()) if a or b]).reshape(-1, 4)


def floquet_traces(delta: ArrayLike, eps: ArrayLike, p: dict[int, tuple[float, float]],
                   zeta: float = 0.0, steps: int = FLOQUET_STEPS
                   ) -> tuple[np.ndarray, np.ndarray]:
    """``tr M`` and ``det M`` of the monodromy over 2π of ``ẍ + 2ζẋ + (δ + ε p(t))x = 0`` at
    the points ``(δ, ε)`` (broadcast; compiled RK4, parallel): ``p`` by its harmonics
    ``{k: (a_k, b_k)}``."""
    d, e = np.broadcast_arrays(np.asarray(delta, dtype=float), np.asarray(eps, dtype=float))
    if not (np.all(np.isfinite(d)) and np.all(np.isfinite(e)) and math.isfinite(zeta)):
        raise InputError("floquet_traces: δ, ε and ζ must be finite")
    tr, det = _floquet_points(np.ascontiguousarray(d.ravel()), np.ascontiguousarray(e.ravel()),
                              float(zeta), hill_rows(p), int(steps))
    return tr.reshape(d.shape), det.reshape(d.shape)


def floquet_stable(trace: np.ndarray, zeta: float = 0.0) -> np.ndarray:
    """Both Floquet multipliers of ``ẍ + 2ζẋ + …`` inside the unit circle (ζ > 0) or on it
    (ζ = 0: ``|tr M| < 2``): with ``det M = e^(−4πζ)`` (Liouville) the roots of
    ``λ² − tr λ + det`` lie in the closed unit disc iff ``|tr M| ≤ 1 + det M`` (Jury)."""
    return np.abs(trace) < 1 + math.exp(-4 * math.pi * zeta)


# --- the full Hill equation: stability of a periodic orbit known as a Fourier sum -------------

HILL_STEPS = 2048
# NOTE: RK4 steps per orbit period for the variational equation, Richardson-combined with
# twice as many (as hill_multipliers): the multipliers to ~1e-10 for the orbits of the notes.


def orbit_hill_rows(terms: dict[tuple[int, int], float], A: dict[int, float],
                    B: dict[int, float], omega: float) -> np.ndarray:
    """The ``extra`` rows ``(1, −2|c_n|, nω, arg c_n)`` (and ``(1, −c_0, 0, 0)``) of
    ``−∂g/∂q(q(t)) ξ`` for ``q = Σ A_n cos nωt + B_n sin nωt`` and a force ``g = k(q) + c q̇``
    (``terms`` ``{(a, b): c}``): ``∂g/∂q = Σ a c_a q^(a−1)`` by the float Fourier kernel,
    exact (no truncation: ``M`` covers the top harmonic of ``q^(degree−1)``)."""
    if any(b and (a, b) != (0, 1) for a, b in terms):
        raise ValueError("orbit_hill_rows: the q̇ part of the force must be linear (c q̇)")
    orders = sorted(set(A) | set(B))
    degree = max((a for a, b in terms if b == 0), default=1)
    M = max(1, max(orders, default=0) * max(degree - 1, 1))
    q = laurent_from_fourier(M, np.array(orders), np.array([A.get(n, 0.0) for n in orders]),
                             np.array([B.get(n, 0.0) for n in orders]))
    stiffness = np.zeros(2 * M + 1, dtype=complex)
    power = np.zeros(2 * M + 1, dtype=complex)
    power[M] = 1.0  # q⁰
    for a in range(1, degree + 1):
        c = terms.get((a, 0), 0.0)
        if c:
            stiffness += a * c * power
        power = laurent_product(power, q)
    # NOTE: a harmonic below 1e-17 of the stiffness's size moves the monodromy by less than a
    # rounding error: its row is dropped (each row is a cosine per RK4 stage).
    negligible = 1e-17 * float(np.sum(np.abs(stiffness)))
    rows = [(1.0, -stiffness[M].real, 0.0, 0.0)]
    rows += [(1.0, -2 * abs(c), n * omega, float(np.angle(c)))
             for n, c in enumerate(stiffness[M + 1:], start=1) if abs(c) > negligible]
    return np.array(rows)


def orbit_hill_multipliers(terms: dict[tuple[int, int], float], A: dict[int, float],
                           B: dict[int, float], omega: float, extra: np.ndarray = NO_TERMS,
                           steps: int = HILL_STEPS) -> np.ndarray:
    """Floquet multipliers of the full Hill equation of an orbit ``q(t)`` of period ``2π/ω``
    known as a Fourier sum (harmonic balance, a series): the variational equation
    ``ξ̈ + c ξ̇ + ∂g/∂q(q(t)) ξ = Σ c_i ξ cos(ν_i t + φ_i)`` of ``q̈ + g(q, q̇) = f(t)``
    (``g = k(q) + c q̇``, ``terms``; ``extra``: parametric rows ``(1, c_i, ν_i, φ_i)`` of the
    equation itself, e.g. a pump).  Its coefficients are periodic and known: one RK4 pass of
    the monodromy columns over the period (the compiled :func:`_rk4`, Richardson pair), with no
    shooting of the nonlinear orbit.  The notes' test (:func:`hill_multipliers`) is this with
    ``q`` cut to ``q₀``.

    Why a pass and not Hill's truncated infinite determinant: the pass gives both multipliers
    themselves (the verdict and the margin), damping and a pump need nothing new, its error is
    the integrator's known O(h⁶) after Richardson; the determinant gives ``cos(2πν)`` only after
    a truncation whose convergence must be checked harmonic by harmonic, and its damped form
    needs the complex exponent."""
    rows = orbit_hill_rows(terms, A, B, omega)
    extra = np.asarray(extra, dtype=float).reshape(-1, 4)
    if np.any(extra[:, 0] != 1.0):
        raise ValueError("orbit_hill_multipliers: extra rows must be parametric (a = 1)")
    rows = np.vstack([rows, extra])
    damping = ForceTable.of({(0, 1): terms.get((0, 1), 0.0)})
    T = 2 * np.pi / omega

    def monodromy(n: int) -> np.ndarray:
        y, _, _ = _rk4(np.array([1.0, 0.0, 1.0, 0.0, 0.0, 1.0]), 0.0, T, n,
                       damping.q_powers, damping.v_powers, damping.coefficients, damping.cubic,
                       0.0, 0.0, 1, math.inf, rows)
        return y[2:].reshape(2, 2).T

    with np.errstate(over="ignore", invalid="ignore"):
        coarse, fine = monodromy(steps), monodromy(2 * steps)
        M = fine + (fine - coarse) / 15
    if not np.all(np.isfinite(M)):  # ξ grows past 1e308 within one period
        return np.array([np.inf, 0.0], dtype=complex)
    return np.linalg.eigvals(M)


def multipliers_stable(multipliers: np.ndarray, dissipative: bool) -> bool:
    """The verdict of :func:`shoot_table` on Floquet multipliers: all ``|λ| < 1`` with
    damping; without, the pair on the unit circle (``|λ₁ + λ₂| = |tr M| < 2``)."""
    lam = np.asarray(multipliers)
    if dissipative:
        return bool(np.all(np.abs(lam) < 1))
    return bool(abs(np.sum(lam).real) < 2)


@dataclass(frozen=True)
class CycleReference:
    """A limit cycle shot by SciPy's DOP853: ``q(0)`` at the maximum (``q̇(0) = 0``), the
    period, and ``accuracy``: the relative difference of the periods at ``rtol`` and at
    ``100 rtol`` (the reference's own error is below it)."""

    q0: float
    period: float
    accuracy: float


CYCLE_RTOL = 1e-13
# NOTE: DOP853's tolerance for the references: at 1e-13 (atol 1e-14) van der Pol's period
# agrees with the 1e-11 run to ≤ 1e-12 up to ε = 10 (6.663286859323127 at ε = 1: 5e-16 from
# the literature's 6.66328685932313019)


def _cycle_return(rhs: Callable, a: float, rtol: float, t_max: float) -> tuple[float, float]:
    """From the maximum ``(a, 0)`` to the next maximum: ``(q, t)`` there."""
    from scipy.integrate import solve_ivp

    def turn(t: float, y: np.ndarray) -> float:
        return y[1]
    turn.direction = -1  # q̇ from + to −: a maximum of q
    sol = solve_ivp(rhs, (0.0, t_max), [a, 0.0], method="DOP853", rtol=rtol, atol=rtol / 10,
                    events=turn)
    for t, y in zip(sol.t_events[0], sol.y_events[0], strict=True):
        if t > 1e-9:
            return float(y[0]), float(t)
    return math.nan, math.nan


def _cycle_rhs(model: object, eps: float) -> Callable:
    """The right-hand side ``(q̇, q̈)`` of ``q̈ + q = ε f(q, q̇)``, ``f = Σ c q^a q̇^b`` (the
    terms of a :class:`models.SelfExcited`), for SciPy's ``solve_ivp``."""
    terms = [(a, b, float(c)) for a, b, c in model.terms]

    def rhs(t: float, y: np.ndarray) -> list[float]:
        q, v = y
        return [v, -q + eps * sum(c * q**a * v**b for a, b, c in terms)]
    return rhs


def cycle_reference(model: object, eps: float, guess: float = 2.0, period: float = 2 * np.pi,
                    rtol: float = CYCLE_RTOL) -> CycleReference:
    """The attracting limit cycle of ``q̈ + q = ε f(q, q̇)`` (a :class:`models.SelfExcited`)
    at any ``eps > 0``, relaxation oscillations included: the return map to the maximum of q
    (Poincaré section q̇ = 0), a few plain returns from ``guess`` and then the secant method
    on ``P(a) − a``; repeated at ``100 rtol`` for :attr:`CycleReference.accuracy`."""
    rhs = _cycle_rhs(model, eps)

    def solve(tol: float) -> tuple[float, float]:
        t_max = 4 * max(period, 2 * np.pi + 2 * eps)
        a = guess
        for _ in range(3):
            a, _ = _cycle_return(rhs, a, tol, t_max)
        a0, a1 = a, a * (1 + 1e-7)
        g0, g1 = _cycle_return(rhs, a0, tol, t_max)[0] - a0, _cycle_return(
            rhs, a1, tol, t_max)[0] - a1
        for _ in range(30):
            if g1 == g0 or not math.isfinite(g1):
                break
            a0, g0, a1 = a1, g1, a1 - g1 * (a1 - a0) / (g1 - g0)
            g1 = _cycle_return(rhs, a1, tol, t_max)[0] - a1
            if abs(a1 - a0) < 1e-15 * abs(a1):
                break
        return _cycle_return(rhs, a1, tol, t_max)

    q0, T = solve(rtol)
    _, T_coarse = solve(rtol * 100)
    return CycleReference(q0, T, abs(T - T_coarse) / T)


def cycle_samples(model: object, eps: float, reference: CycleReference, points: int
                  ) -> tuple[np.ndarray, np.ndarray]:
    """``(t, q(t))`` at ``points`` equally spaced times of one period of the shot cycle
    (:func:`cycle_reference`), from its maximum ``(q(0), 0)`` by DOP853 at its tolerance."""
    from scipy.integrate import solve_ivp

    t = reference.period * np.arange(points) / points
    sol = solve_ivp(_cycle_rhs(model, eps), (0.0, reference.period), [reference.q0, 0.0],
                    method="DOP853", rtol=CYCLE_RTOL, atol=CYCLE_RTOL / 10, t_eval=t)
    return t, sol.y[0]


def mathieu_reference(kind: str, m: int, q: float, size: int | None = None,
                      dps: int | None = None) -> float:
    """Mathieu's characteristic value ``a_m(q)`` or ``b_m(q)`` (DLMF §28.2, ``y'' + (a − 2q
    cos 2z) y = 0``) as an eigenvalue of the truncated recurrence of the Fourier coefficients
    (DLMF 28.4.5–8), symmetrised (``√2`` in the ``ce_(2n)`` coupling): ``size`` terms (enough
    that the tail decays, ~|q|^(1/2) + 30 by default), in float64 or, with ``dps``, in mpmath
    at that precision.  The eigenvalues of each parity class are sorted, the m-th taken."""
    even = m % 2 == 0
    n = size if size is not None else int(2 * math.sqrt(abs(q)) + 40)
    if kind == "a":
        orders = [2 * k + (0 if even else 1) for k in range(n)]
    else:
        orders = [2 * k + (2 if even else 1) for k in range(n)]
    diag = [float(r * r) for r in orders]
    off = [q] * (n - 1)
    if kind == "a" and even:
        off[0] = q * math.sqrt(2)  # ce_(2n): A_0 couples to A_2 through 2q (DLMF 28.4.5)
    if kind == "a" and not even:
        diag[0] = 1.0 + q  # ce_(2n+1): a − 1 − q on A_1 (DLMF 28.4.6)
    if kind == "b" and not even:
        diag[0] = 1.0 - q  # se_(2n+1): a − 1 + q on B_1 (DLMF 28.4.7)
    index = m // 2 if kind == "a" or not even else m // 2 - 1
    if dps is None:
        from scipy.linalg import eigvalsh_tridiagonal

        return float(eigvalsh_tridiagonal(np.array(diag), np.array(off))[index])
    import mpmath

    with mpmath.workdps(dps):
        qq = mpmath.mpf(q)
        A = mpmath.zeros(n, n)
        for i in range(n):
            A[i, i] = mpmath.mpf(orders[i] ** 2)
        if kind == "a" and not even:
            A[0, 0] = 1 + qq
        if kind == "b" and not even:
            A[0, 0] = 1 - qq
        for i in range(n - 1):
            A[i, i + 1] = A[i + 1, i] = qq * (mpmath.sqrt(2) if (kind == "a" and even
                                                                 and i == 0) else 1)
        values = sorted(mpmath.eigsy(A, eigvals_only=True))
        return float(values[index])


def mathieu_recurrence(kind: str, m: int, rows: int
                       ) -> tuple[int, tuple[tuple[int, int], ...], tuple[int, ...]]:
    """The symmetrised recurrence of the Fourier coefficients of ``ce_m`` or ``se_m`` (DLMF
    28.4.5–8) as exact integers, ``rows`` of it: the diagonal ``c_j = r_j² + s_j q`` as
    ``(r_j², s_j)``, the squared couplings ``e_j² = t_j q²`` as ``t_j`` (2 for ``A_0``–``A_2``,
    the ``√2`` of the symmetrised ``ce_(2n)``), and the index of ``m`` among its class's sorted
    eigenvalues."""
    even = m % 2 == 0
    if kind == "a":
        orders = [2 * k + (0 if even else 1) for k in range(rows)]
    else:
        orders = [2 * k + (2 if even else 1) for k in range(rows)]
    diag = [(r * r, 0) for r in orders]
    if not even:
        diag[0] = (1, 1 if kind == "a" else -1)  # a − 1 ∓ q on A_1, B_1 (DLMF 28.4.6–7)
    couplings = [2 if (kind == "a" and even and j == 0) else 1 for j in range(rows - 1)]
    index = m // 2 if kind == "a" or not even else m // 2 - 1
    return index, tuple(diag), tuple(couplings)


def mathieu_newton(kind: str, m: int, q: ArrayLike, start: ArrayLike, rows: int,
                   steps: int) -> np.ndarray:
    """Newton steps on ``det(T_rows − a)`` of :func:`mathieu_recurrence`'s matrix from
    ``start``, vectorised over q (DLMF 28.6.16–20 in determinant form, no division but the
    step's).  The matrix is split after row ``k = rows // 2``: the leading minors ``p_j =
    (c_j − a) p_(j−1) − e²_(j−1) p_(j−2)`` (rows 0…k) and the trailing ones ``s_j = (c_j − a)
    s_(j+1) − e²_j s_(j+2)`` (rows j…rows−1) are two independent chains, and ``det = p_k
    s_(k+1) − e²_k p_(k−1) s_(k+2)``; the a-derivatives run beside them.  The emitted
    evaluators unroll the same steps (:func:`lower.mathieu_newton_steps`)."""
    _, diag, couplings = mathieu_recurrence(kind, m, rows)
    q = np.asarray(q, dtype=float)
    a = np.asarray(start, dtype=float) + 0.0 * q
    qq = q * q
    k = rows // 2
    for _ in range(steps):
        one, zero = np.ones_like(a), np.zeros_like(a)
        p_prev, dp_prev, p, dp = one, zero, diag[0][0] + diag[0][1] * q - a, -one
        for j in range(1, k + 1):
            c = diag[j][0] + diag[j][1] * q - a
            e2 = couplings[j - 1] * qq
            p, p_prev, dp, dp_prev = (c * p - e2 * p_prev, p, c * dp - p - e2 * dp_prev, dp)
        s_next, ds_next, s, ds = one, zero, diag[rows - 1][0] + diag[rows - 1][1] * q - a, -one
        for j in range(rows - 2, k, -1):
            c = diag[j][0] + diag[j][1] * q - a
            e2 = couplings[j] * qq
            s, s_next, ds, ds_next = (c * s - e2 * s_next, s, c * ds - s - e2 * ds_next, ds)
        e2 = couplings[k] * qq
        det = p * s - e2 * p_prev * s_next
        ddet = dp * s + p * ds - e2 * (dp_prev * s_next + p_prev * ds_next)
        a = a - det / ddet
    return a


def mathieu_truncation_bound(kind: str, m: int, q: float, a: float, rows: int) -> float:
    """A bound on ``|a_rows − a|``: the eigenvalue of the ``rows``-row truncation (N = rows)
    against the exact ``a`` of the infinite recurrence, with ``v`` its unit eigenvector.

    Cutting the coupling ``e = e_(N−1)`` leaves ``A' = T_N ⊕ T_tail`` and ``(A' − a)v =
    −e(v_N u_(N−1) + v_(N−1) u_N)``: the Rayleigh quotient ``ρ = a − 2e v_(N−1) v_N`` and the
    residual ``r ≤ e (v²_(N−1) + v²_N)^½``; by Kato–Temple ``|μ − ρ| ≤ r²/g`` for the one
    eigenvalue ``μ`` of ``A'`` within the gap ``g`` of ``ρ`` to the rest of its spectrum
    (``T_N``'s neighbours of ``μ``, and ``T_tail ≥ c_N − 2ê`` by Gershgorin).  So ``|μ − a| ≤
    2e|v_(N−1) v_N| + r²/g``.  Past the first row ``J`` with ``c_j − a ≥ 2ê`` (``ê = √2 |q|``
    ≥ every coupling), the tail's continued fraction ``B_j = e²_(j−1) / (c_j − a − B_(j+1))``
    stays in ``[0, ê]``, so ``|v_j / v_(j−1)| = e_(j−1) / (c_j − a − B_(j+1)) ≤ ê / (c_j − a
    − ê)`` and ``|v_n| ≤ Π_(j=J…n) ê / (c_j − a − ê)``.  ``inf`` when the tail starts past
    ``N − 1`` or the gap closes."""
    from scipy.linalg import eigvalsh_tridiagonal

    index, diag, couplings = mathieu_recurrence(kind, m, rows + 1)
    e = math.sqrt(2.0) * abs(q)
    if e == 0.0:
        return 0.0
    c = [r2 + s * q - a for r2, s in diag]
    J = next((j for j in range(1, rows) if all(c[i] >= 2 * e for i in range(j, rows + 1))),
             None)
    if J is None:
        return math.inf
    v = [1.0]
    for j in range(J, rows + 1):
        v.append(v[-1] * e / (c[j] - e))
    v_last, v_cut = v[-2], v[-1]  # |v_(N−1)|, |v_N|
    first = 2 * e * v_last * v_cut
    values = eigvalsh_tridiagonal(
        np.array([float(r2 + s * q) for r2, s in diag[:rows]]),
        np.array([math.sqrt(t) * abs(q) for t in couplings[: rows - 1]]))
    others = [abs(x - a) for i, x in enumerate(values) if i != index]
    others.append(diag[rows][0] + diag[rows][1] * q - 2 * e - a)
    gap = min(others) - first - 1e-9 * max(1.0, abs(a))  # the float64 eigenvalues' error
    if gap <= 0:
        return math.inf
    return first + e * e * (v_last**2 + v_cut**2) / gap


def mathieu_refined(kind: str, m: int, q: float, dps: int = 30) -> float:
    """``a_m(q)`` or ``b_m(q)`` to ``dps`` digits, fast: the float64 eigenvalue of
    :func:`mathieu_reference` refined by Newton steps on the determinant of the same
    truncated recurrence in mpmath (quadratic: 1e-15 → 1e-30 in one step; a third step
    checks it), as an ``mpf``."""
    import mpmath

    n = int(2 * math.sqrt(abs(q)) + 40)
    _, diag, couplings = mathieu_recurrence(kind, m, n)
    with mpmath.workdps(dps + 5):
        qq = mpmath.mpf(q)
        a = mpmath.mpf(mathieu_reference(kind, m, q))
        for step in range(3):
            p_prev, dp_prev = mpmath.mpf(1), mpmath.mpf(0)
            p, dp = diag[0][0] + diag[0][1] * qq - a, mpmath.mpf(-1)
            for j in range(1, n):
                c = diag[j][0] + diag[j][1] * qq - a
                e2 = couplings[j - 1] * qq * qq
                p, p_prev, dp, dp_prev = (c * p - e2 * p_prev, p, c * dp - p - e2 * dp_prev, dp)
            delta = p / dp
            a -= delta
            if step == 2 and abs(delta) > mpmath.mpf(10) ** (-dps) * max(1, abs(a)):
                raise RuntimeError(f"mathieu_refined {kind}_{m}({q}): Newton did not converge")
        return +a
