"""Shooting: Newton's method on the flow map for a periodic orbit of one or several drive
periods with its monodromy matrix, the true fold by a bordered Newton, the true limit
cycle of a self-excited oscillator, and where a driven system settles from a state."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..display import harmonics_table
from ..errors import InputError
from ..limits import check_int
from .floquet import multipliers_stable
from .integrate import (
    NO_TERMS,
    STEPS_PER_PERIOD,
    ForceTable,
    PolynomialField,
    _system_field,
    _table_force,
    duffing_table,
    escape_bound,
    flow_table,
)
from .newton import Iteration, iterate, newton


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit of period ``2π/ω`` found by shooting, with its Floquet multipliers."""

    initial: np.ndarray  # (q(0), q̇(0))
    A: dict[int, float]  # cos nωt coefficients
    B: dict[int, float]  # sin nωt coefficients
    multipliers: np.ndarray
    stable: bool
    residual: float
    coordinates: tuple[tuple[dict[int, float], dict[int, float]], ...] = ()
    # a system's orbit: (A, B) of every coordinate (A, B above are the first's)

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
    check_int(harmonics, 1, None, f"harmonics {harmonics!r}: must be an integer ≥ 1")
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


class _Failed(Exception):
    """Raised from a shooting's evaluation at a domain event (an escape, an overflow, a failed
    integration): it carries the failure (``None``: none to report) out of Newton's method."""

    def __init__(self, failure: ShootingFailure | None) -> None:
        super().__init__()
        self.failure = failure


def _newton_failure(run: Iteration, max_iter: int, tolerance: str,
                    bound: float) -> ShootingFailure:
    """Why shooting's Newton (:func:`numerics.newton.iterate`) stopped short of an orbit: a
    singular ``M − I`` at the iterate it reached, or no convergence (a step that overflowed
    counts as none: the flow from it would have overflowed)."""
    if run.why == "singular":
        return ShootingFailure(f"M - I is singular at Newton's iterate {run.steps} (a Floquet "
                               "multiplier +1: a fold)", False, bound)
    return ShootingFailure(f"Newton's method did not converge in {max_iter} iterations "
                           f"(last step {run.step:.1e}{tolerance})", False, bound)


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

    calls = 0

    def evaluate(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        nonlocal calls
        k, calls = calls, calls + 1  # the flow of Newton's iterate k
        end, _, at = flow_table(table, force, omega, y, T, steps=steps, bound=bound,
                                extra=extra)
        if at >= 0:
            raise _Failed(escape(k, y, at))
        if not np.all(np.isfinite(end)):  # RK4 overflowed: h is too big for the amplitude
            raise _Failed(ShootingFailure(
                f"RK4 overflowed from (q, q') = ({y[0]:.6g}, {y[1]:.6g})"
                + (f" (Newton's iterate {k})" if k else "") + ": its step is too large for "
                "this amplitude", False, bound))
        return end[:2] - y, end[2:].reshape(2, 2).T - np.eye(2)  # M − I

    try:
        run = iterate(evaluate, guess, tol, max_iter)
    except _Failed as failed:
        return failed.failure
    if not run.converged:
        return _newton_failure(run, max_iter, f", tolerance {tol:g}", bound)
    y = run.x
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


def orbit_fold(eps: float, force: float, damping: float, omega: float, y0: np.ndarray,
               tol: float = 1e-11) -> tuple[float, np.ndarray] | None:
    """:func:`orbit_fold_table` on eq. 10.60 (``q + εq³ + q̇/Q``), with the escape bound of a
    softening spring's well: ``(ω, y₀)`` or ``None``."""
    found = orbit_fold_table(duffing_table(eps, damping), force, omega, y0, tol,
                             escape_bound(eps, force))
    return None if found is None else found[:2]


def orbit_fold_table(table: ForceTable, force: float, omega: float, y0: np.ndarray,
                     tol: float = 1e-11, bound: float = math.inf
                     ) -> tuple[float, np.ndarray, np.ndarray] | None:
    """A fold of the true periodic orbit of ``q̈ + g(q, q̇) = f cos ωt`` (``g`` the table):
    ``φ_T(y₀) = y₀`` with a Floquet multiplier ``+1`` (``det(M − I) = 0``), by Newton's method
    in ``(y₀, ω)`` with a central-difference Jacobian; ``(ω, y₀, multipliers)``, or ``None``
    where Newton leaves the frequencies, the flow overflows or escapes past ``bound``, or the
    Jacobian is singular (no isolated fold near the guess)."""
    def F(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        end, _, _ = flow_table(table, force, z[2], z[:2], 2 * np.pi / z[2], samples=1,
                               bound=bound)
        mono = end[2:].reshape(2, 2).T
        return np.array([*(end[:2] - z[:2]), np.linalg.det(mono - np.eye(2))]), mono

    def residual(z: np.ndarray) -> np.ndarray:
        if not z[2] > 0:  # Newton left the frequencies: no fold near this guess
            return np.full(3, np.nan)
        return F(z)[0]  # NaN where RK4 overflowed or escaped: no orbit near this guess

    with np.errstate(over="ignore", invalid="ignore"):
        z, converged, _ = newton(residual, None, np.array([*y0, omega], dtype=float), tol, 30)
        if not converged:
            return None
        _, mono = F(z)
    return float(z[2]), z[:2], np.linalg.eigvals(mono)


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
    def evaluate(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        q, T = z
        if not T > 0:
            raise _Failed(None)
        end, _, escaped = flow_table(table, 0.0, 2 * np.pi / T, np.array([q, 0.0]), T)
        if escaped >= 0 or not np.all(np.isfinite(end)):
            raise _Failed(None)
        M = end[2:].reshape(2, 2, order="F")
        g, _, _ = _table_force(end[0], end[1], table.q_powers, table.v_powers,
                               table.coefficients)
        return (end[:2] - np.array([q, 0.0]),
                np.column_stack([M[:, 0] - np.array([1.0, 0.0]), [end[1], -g]]))

    try:
        run = iterate(evaluate, np.array([q0, period], dtype=float), tol, max_iter)
    except _Failed:
        return None
    if not run.converged:
        return None
    q, T = (float(v) for v in run.x)
    end, _, _ = flow_table(table, 0.0, 2 * np.pi / T, np.array([q, 0.0]), T)
    M = end[2:].reshape(2, 2, order="F")
    mu = np.linalg.eigvals(M)
    mu = tuple(sorted((complex(m) for m in mu), key=lambda m: abs(abs(m) - 1)))
    return LimitCycleOrbit(q, T, mu, float(np.log(abs(np.linalg.det(M))) / T))


def true_limit_cycle(model: object, eps: float, cycle: int = 0, order: int = 12
                     ) -> LimitCycleOrbit | None:
    """The true orbit of limit cycle ``cycle`` of a :class:`models.SelfExcited` oscillator at
    ``eps``, shot from its L–P series at ``order`` (q(0) and T as the seed)."""
    from ..derive.cycles import derive_limit_cycle

    lc = derive_limit_cycle(model, order, cycle)
    table = ForceTable.of({(1, 0): 1.0, **{(a, b): -eps * float(c) for a, b, c in model.terms}})
    q0 = sum(float(c) * eps**j for j, c in enumerate(lc.amplitude))
    T = 2 * np.pi * sum(float(c) * eps**j for j, c in enumerate(lc.period))
    return limit_cycle_orbit(table, q0, T)


SYSTEM_RTOL = 1e-11
# NOTE: DOP853's tolerance on a system's orbit and its monodromy: the shot harmonics agree with
# a balance of 12 harmonics to ~1e-10 on the suite's 2-DOF systems.


def shoot_system(field: PolynomialField, drive: np.ndarray, omega: float, guess: np.ndarray,
                 harmonics: int = 9, tol: float = 1e-10, max_iter: int = 20,
                 rtol: float = SYSTEM_RTOL) -> PeriodicOrbit | ShootingFailure:
    """The periodic orbit of period ``2π/ω`` of ``ẍ_i + g_i(x, ẋ) = d_i cos ωt`` (``g``:
    ``field``, ``d``: ``drive``) near the state ``guess = (x(0), ẋ(0))``: Newton's method on
    ``φ_T(y₀) − y₀ = 0`` with the monodromy ``M`` from the variational equation, both by
    DOP853 (SciPy) at ``rtol``; ``M``'s eigenvalues are the Floquet multipliers (stable when
    all ``|λ| < 1``, a damped system).  Each coordinate's harmonics up to ``harmonics`` from
    ``4·harmonics`` samples of the converged orbit (the mean as ``A[0]`` unless the force is
    odd)."""
    from scipy.integrate import solve_ivp

    n = field.size
    m = 2 * n
    T = 2 * np.pi / omega
    args = (field.exponents, field.rows, field.coefficients,
            np.asarray(drive, dtype=float), float(omega), n)
    eye = np.eye(m).ravel(order="F")
    samples = 4 * harmonics + 4

    def flow(y: np.ndarray, dense: bool = False):
        return solve_ivp(lambda t, z: _system_field(t, z, *args), (0.0, T),
                         np.concatenate([y, eye]), method="DOP853", rtol=rtol,
                         atol=rtol * 1e-3,
                         t_eval=np.linspace(0.0, T, samples + 1) if dense else None)

    calls = 0

    def evaluate(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        nonlocal calls
        k, calls = calls, calls + 1  # the flow of Newton's iterate k
        sol = flow(y)
        end = sol.y[:, -1]
        if not (sol.success and np.all(np.isfinite(end))):
            raise _Failed(ShootingFailure(f"DOP853 failed from Newton's iterate {k} "
                                          f"({sol.message})", False, math.inf))
        return end[:m] - y, end[m:].reshape(m, m, order="F") - np.eye(m)  # M − I

    try:
        run = iterate(evaluate, guess, tol, max_iter)
    except _Failed as failed:
        return failed.failure
    if not run.converged:
        return _newton_failure(run, max_iter, "", math.inf)
    y = run.x
    with np.errstate(over="ignore", invalid="ignore"):
        sol = flow(y, dense=True)
    M = sol.y[m:, -1].reshape(m, m, order="F")
    lam = np.linalg.eigvals(M)
    odd = field.odd
    shapes = []
    for i in range(n):
        c = np.fft.rfft(sol.y[i, :samples]) / samples
        A = {j: float(2 * c[j].real) for j in range(1, harmonics + 1, 2 if odd else 1)}
        B = {j: float(-2 * c[j].imag) for j in range(1, harmonics + 1, 2 if odd else 1)}
        shapes.append(({0: float(c[0].real), **A} if not odd else A, B))
    return PeriodicOrbit(y, *shapes[0], lam, bool(np.all(np.abs(lam) < 1)),
                         float(np.max(np.abs(sol.y[:m, -1] - y))), tuple(shapes))


def settle_system(field: PolynomialField, drive: np.ndarray, omega: float, start: np.ndarray,
                  periods: int, rtol: float = 1e-9) -> np.ndarray:
    """Where a driven system goes from the state ``start`` (``(x, ẋ)`` at ``t = 0``): DOP853
    over ``periods`` drive periods (no variational part), each coordinate's first-harmonic
    amplitude over the last one (256 samples); NaN where the integration fails or escapes."""
    from scipy.integrate import solve_ivp

    n = field.size
    T = 2 * np.pi / omega
    args = (field.exponents, field.rows, field.coefficients,
            np.asarray(drive, dtype=float), float(omega), n)
    eye = np.eye(2 * n).ravel(order="F")
    samples = np.linspace((periods - 1) * T, periods * T, 257)[:-1]
    with np.errstate(over="ignore", invalid="ignore"):
        sol = solve_ivp(lambda t, z: _system_field(t, np.concatenate([z, eye]), *args)[:2 * n],
                        (0.0, periods * T), np.asarray(start, dtype=float), method="DOP853",
                        rtol=rtol, atol=rtol * 1e-3, t_eval=samples)
    if not (sol.success and sol.y.shape[1] == len(samples) and np.all(np.isfinite(sol.y))):
        return np.full(n, np.nan)
    return 2 * np.abs(np.fft.rfft(sol.y[:n], axis=1)[:, 1] / len(samples))
