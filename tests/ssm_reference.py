"""An independent full-order reference for the SSM tests: periodic orbits of the damped, driven

    M x'' + C x' + K x + f(x, x') = F cos(ω t)

by single shooting, judged by residuals.

Nothing here imports the package ``generator``: NumPy and SciPy only.  (The conservative
backbone's RK4 loop of a large model is compiled by numba as well.)  Time is rescaled to
``τ = ω t`` so that every orbit has period ``2π``; the state is ``y = (x, v)`` with ``v = dx/dt``.
One period of the state and of its variational equations (the monodromy ``Φ = ∂y(2π)/∂y(0)``
and ``z = ∂y(2π)/∂ω``) is integrated by ``solve_ivp(method="DOP853", rtol=1e-12, atol=1e-13)``.

* ``forced_orbit``: Newton on ``y(2π) - y(0) = 0`` at fixed ω; the orbit is accepted only when
  the residual ``|y(2π) - y(0)| / |y(0)|`` is at most a stated threshold (1e-11 by default;
  never on a solver flag), else ``ShootingError``.
* ``forced_curve``: natural-parameter continuation over a grid of ω; reports folds instead of
  jumping across them.
* ``trace_branch`` and ``peak``: pseudo-arclength continuation in ``(y(0), ω)`` (through
  folds), and the peak of an amplitude where its derivative along the arclength vanishes.
* ``free_decay``: the unforced motion from given initial conditions.
* ``backbone`` and ``free_orbit``: the periodic orbits of the conservative ``M x'' + K x + f(x)
  = 0`` along one mode (the backbone), by half-period shooting from rest with the period
  unknown, continued in amplitude from the linear mode; RK4 with a fixed step under a stiff
  model's stability limit, or DOP853; each orbit judged by a whole period's residual.
* ``linear_amplitude``: the closed-form linear amplitudes, for checks.

Every loop is bounded by a number of steps, never by time; nothing is random.  One period of a
2-DOF system costs ~15-30 ms, an orbit ~0.1 s, a peak through a fold ~100 periods (2-3 s).

The force is ``None`` (linear), a table of monomials (``terms_force``, exact Jacobians), a
``Force`` or ``(f, dfdx, dfdv)`` triple, or a bare callable ``f(x, v)`` (``callable_force``,
central finite differences).  Amplitudes are ``max_t |x_i(t)|`` over one period: the largest of
400 samples of the dense output, refined by Newton on ``v_i(τ) = 0``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np
from scipy.integrate import solve_ivp

TWO_PI = 2.0 * math.pi
RTOL, ATOL = 1e-12, 1e-13
TINY = np.finfo(float).tiny
TRACE_TOL = 1e-6  # residual of the intermediate points of ``peak``'s traces
STEP_MAX = 8.0  # the largest pseudo-arclength step is STEP_MAX / points (scaled units)


class ShootingError(RuntimeError):
    """Newton's method did not bring the shooting residual below its threshold."""


class ContinuationError(RuntimeError):
    """A continuation could not proceed within its bounded number of steps."""


# --------------------------------------------------------------------------- forces


class Force:
    """A nonlinear force ``f(x, v)`` with its Jacobians; unpacks as ``(f, dfdx, dfdv)``.

    ``through(A)`` is the fast path the integrator uses: a function of ``y = (x, v)``
    returning ``(A @ f, A @ [dfdx | dfdv])``."""

    def __init__(self, f: Callable, dfdx: Callable, dfdv: Callable,
                 through: Callable | None = None):
        self.f, self.dfdx, self.dfdv = f, dfdx, dfdv
        self._through = through

    def __iter__(self):
        return iter((self.f, self.dfdx, self.dfdv))

    def through(self, A: np.ndarray) -> Callable:
        if self._through is not None:
            return self._through(A)
        n = A.shape[1]

        def at(y):
            x, v = y[:n], y[n:]
            jac = np.hstack((np.asarray(self.dfdx(x, v), float),
                             np.asarray(self.dfdv(x, v), float)))
            return A @ np.asarray(self.f(x, v), float), A @ jac

        return at


def terms_force(n: int, terms: Sequence) -> Force:
    """The force of a table of monomials, with exact Jacobians.

    Each entry ``(i, [j, k, ...], c)`` adds ``c * z[j] * z[k] * ...`` to ``f_i``, where
    ``z = concatenate(x, v)``: an index below ``n`` is ``x_j``, one at or above ``n`` is
    ``v_{j-n}``.  Repeated indices give powers (``(0, [0, 0, 0], 1.0)`` is ``x_0³``)."""
    table = [(int(i), [int(j) for j in js], float(c)) for i, js, c in terms]
    for i, js, _ in table:
        if not 0 <= i < n or any(not 0 <= j < 2 * n for j in js):
            raise ValueError(f"term ({i}, {js}) out of range for n = {n}")
    N, m = 2 * n, len(table)
    degree = max([1] + [len(js) for _, js, _ in table])
    index = np.full((m, degree), N)  # z[N] = 1 pads monomials of lower degree
    for r, (_, js, _) in enumerate(table):
        index[r, :len(js)] = js
    row = np.array([i for i, _, _ in table], dtype=int)
    coef = np.array([c for _, _, c in table])
    # slot (p, r), p-major: the other factors of monomial r, and the z index it differentiates
    others = np.array([np.delete(index[r], p) for p in range(degree) for r in range(m)],
                      dtype=int).reshape(m * degree, degree - 1)
    wrt = index.T.ravel()
    select = np.zeros((m * degree, N + 1))
    select[np.arange(m * degree), wrt] = 1.0
    select = select[:, :N]  # the padding 1 is no variable
    rows = np.zeros((n, m))
    rows[row, np.arange(m)] = coef
    product = np.multiply.reduce

    def through(A):
        z = np.ones(N + 1)
        value, slope = A @ rows, np.tile(A @ rows, degree)

        def at(y):
            z[:N] = y
            return (value @ product(z[index], axis=1),
                    (slope * product(z[others], axis=1)) @ select)

        return at

    plain = through(np.eye(n))

    def split(x, v):
        return plain(np.concatenate((np.asarray(x, float), np.asarray(v, float))))

    return Force(lambda x, v: split(x, v)[0], lambda x, v: split(x, v)[1][:, :n],
                 lambda x, v: split(x, v)[1][:, n:], through)


def callable_force(f: Callable, n: int, step: float = 1e-6) -> Force:
    """A bare ``f(x, v) -> ndarray`` with Jacobians by central differences of relative step
    ``step`` (errors ~1e-10: Newton and the multipliers are fine, amplitudes are exact); each
    right-hand side then calls ``f`` 1 + 4n times, ~10x slower than ``terms_force``."""

    def jacobian(x, v, which):
        x, v = np.asarray(x, float), np.asarray(v, float)
        out = np.empty((n, n))
        for j in range(n):
            z = [x.copy(), v.copy()]
            h = step * max(1.0, abs(z[which][j]))
            z[which][j] += h
            up = np.asarray(f(*z), float)
            z[which][j] -= 2 * h
            out[:, j] = (up - np.asarray(f(*z), float)) / (2 * h)
        return out

    return Force(f, lambda x, v: jacobian(x, v, 0), lambda x, v: jacobian(x, v, 1))


def _as_force(force, n: int) -> Force | None:
    if force is None or isinstance(force, Force):
        return force
    if callable(force):
        return callable_force(force, n)
    force = list(force)
    if len(force) == 3 and all(callable(g) for g in force):
        return Force(*force)
    return terms_force(n, force)


# --------------------------------------------------------------------------- the system


class _System:
    """``y' = g(y, τ) / ω`` in ``τ = ω t``, with the variational equations of ``(y0, ω)``.

    The integrated state is ``Q = [y | Φ | z]``, an ``N × (N+2)`` matrix flattened by rows."""

    def __init__(self, M, C, K, force, F):
        M = np.atleast_2d(np.asarray(M, float))
        n = M.shape[0]
        C = np.atleast_2d(np.asarray(C, float))
        K = np.atleast_2d(np.asarray(K, float))
        F = np.atleast_1d(np.asarray(F, float))
        if C.shape != (n, n) or K.shape != (n, n) or F.shape != (n,):
            raise ValueError("M, C, K must be n×n and F of length n")
        minv = np.linalg.inv(M)
        self.n, self.N = n, 2 * n
        self.M, self.C, self.K, self.F = M, C, K, F
        self.mkc, self.mf = minv @ np.hstack((K, C)), minv @ F
        force = _as_force(force, n)
        self.nonlinear = None if force is None else force.through(minv)

    def accel(self, y, tau):
        """``dv/dt`` at ``y = (x, v)`` and forcing phase ``τ``."""
        acc = self.mf * math.cos(tau) - self.mkc @ y
        if self.nonlinear is not None:
            acc -= self.nonlinear(y)[0]
        return acc

    def rhs(self, omega: float) -> Callable:
        """``dQ/dτ``: the state and its sensitivities ``[Φ | z]`` to ``(y0, ω)``."""
        n, N = self.n, self.N
        mkc, mf, nonlinear = self.mkc, self.mf, self.nonlinear
        inv = 1.0 / omega

        def fun(tau, Y):
            Q = Y.reshape(N, N + 2)
            y = Q[:, 0]
            out = np.empty((N, N + 2))
            out[:n] = Q[n:]
            if nonlinear is None:
                out[n:, 0] = mf * math.cos(tau) - mkc @ y
                out[n:, 1:] = -mkc @ Q[:, 1:]
            else:
                g, jac = nonlinear(y)
                out[n:, 0] = mf * math.cos(tau) - mkc @ y - g
                out[n:, 1:] = -(mkc + jac) @ Q[:, 1:]
            out *= inv
            out[:, -1] -= out[:, 0] * inv  # ∂/∂ω of g/ω is -g/ω²
            return out.ravel()

        return fun

    def linear_phasor(self, omega: float) -> np.ndarray:
        """``X`` with ``(K - ω²M + iωC) X = F``: the linear response ``Re(X e^{iωt})``."""
        return np.linalg.solve(self.K - omega**2 * self.M + 1j * omega * self.C, self.F)

    def linear_guess(self, omega: float) -> np.ndarray:
        X = self.linear_phasor(omega)
        return np.concatenate((X.real, -omega * X.imag))


@dataclass
class _Shot:
    y0: np.ndarray
    omega: float
    yT: np.ndarray
    Phi: np.ndarray
    z: np.ndarray
    sol: object | None

    @property
    def residual(self) -> float:
        return float(np.linalg.norm(self.yT - self.y0) / max(np.linalg.norm(self.y0), TINY))


def _shoot(system: _System, y0: np.ndarray, omega: float, dense: bool = False) -> _Shot:
    """One period of the state and of ``[Φ | z]`` from ``y0``."""
    N = system.N
    start = np.hstack((np.asarray(y0, float)[:, None], np.eye(N), np.zeros((N, 1))))
    sol = solve_ivp(system.rhs(omega), (0.0, TWO_PI), start.ravel(), method="DOP853",
                    rtol=RTOL, atol=ATOL, dense_output=dense)
    if sol.status != 0 or not np.all(np.isfinite(sol.y[:, -1])):
        raise ShootingError(f"integration failed at omega = {omega}: {sol.message}")
    Q = sol.y[:, -1].reshape(N, N + 2)
    return _Shot(np.array(y0, float), float(omega), Q[:, 0].copy(), Q[:, 1:-1].copy(),
                 Q[:, -1].copy(), sol.sol if dense else None)


def _at(shot: _Shot, tau) -> np.ndarray:
    """``Q(τ) = [y | Φ | z]`` from the dense output: ``(N, N+2)`` or ``(N, N+2, len(τ))``."""
    N = len(shot.y0)
    Y = shot.sol(tau)
    return Y.reshape((N, N + 2, *Y.shape[1:]))


def _peak_times(system: _System, shot: _Shot, samples: int = 400) -> tuple:
    """``max_τ |x_i(τ)|`` and its ``τ`` for every coordinate: the largest sample of the dense
    output, then Newton on ``v_i(τ) = 0`` (``dv_i/dτ = a_i / ω``), steps within one sample."""
    n, omega = system.n, shot.omega
    grid = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    xs = _at(shot, grid)[:n, 0]
    spacing = TWO_PI / samples
    amplitude, times = np.zeros(n), np.zeros(n)
    for i in range(n):
        tau = grid[int(np.argmax(np.abs(xs[i])))]
        for _ in range(8):
            y = _at(shot, tau % TWO_PI)[:, 0]
            acc = system.accel(y, tau)[i]
            if acc == 0.0:
                break
            step = float(np.clip(-omega * y[n + i] / acc, -spacing, spacing))
            tau += step
            if abs(step) < 1e-15:
                break
        tau %= TWO_PI
        times[i] = tau
        amplitude[i] = max(abs(_at(shot, tau)[i, 0]), np.max(np.abs(xs[i])))
    return amplitude, times


# --------------------------------------------------------------------------- one orbit


@dataclass(frozen=True)
class Orbit:
    """A periodic orbit of period ``2π/ω``.

    ``y0 = (x(0), v(0))``; ``residual = |y(T) - y0| / |y0|``; ``multipliers`` are the Floquet
    multipliers (eigenvalues of the monodromy); ``stable`` means all ``|μ| < 1``;
    ``amplitude[i] = max_t |x_i(t)|``; ``steps`` is the number of integrations Newton used;
    ``tolerance`` the threshold the residual was judged against."""

    omega: float
    y0: np.ndarray
    residual: float
    multipliers: np.ndarray
    stable: bool
    amplitude: np.ndarray
    steps: int
    tolerance: float = field(repr=False, default=1e-11)


def _orbit(system: _System, shot: _Shot, steps: int, tol: float) -> Orbit:
    mu = np.linalg.eigvals(shot.Phi)
    amplitude, _ = _peak_times(system, shot)
    return Orbit(shot.omega, shot.y0, shot.residual, mu, bool(np.all(np.abs(mu) < 1.0)),
                 amplitude, steps, tol)


def _newton(system: _System, omega: float, y0: np.ndarray, tol: float,
            max_steps: int = 30, max_halvings: int = 6) -> tuple[_Shot, int]:
    """Newton on ``y(2π) - y0`` at fixed ω, halving steps that do not lower the residual; at
    most ``max_steps`` integrations, and it gives up after ``max_halvings`` halvings in a row
    (a stall: no orbit near, typically past a fold).  Returns a dense shot whose residual is
    at most ``tol``, else ``ShootingError``."""
    N = system.N
    y, base, delta, base_res, res = np.array(y0, float), None, None, math.inf, math.inf
    halvings = 0
    for step in range(1, max_steps + 1):
        try:
            shot = _shoot(system, y, omega, dense=base_res < 1e-4)  # dense: likely the last
            res = shot.residual
        except ShootingError:
            if delta is None:
                raise
            shot, res = None, math.inf
        if delta is not None and not res < base_res:
            if halvings == max_halvings:
                break
            halvings += 1
            delta = delta / 2  # backtrack towards the last accepted iterate
            y = base + delta
            continue
        if res <= tol:
            if shot.sol is None:
                shot = _shoot(system, y, omega, dense=True)
                step += 1
            return shot, step
        base, base_res, halvings = y, res, 0
        delta = -np.linalg.solve(shot.Phi - np.eye(N), shot.yT - y)
        y = base + delta
    raise ShootingError(f"omega = {omega:.12g}: residual {base_res:.3e} above {tol:.1e} after "
                        f"{step} Newton steps ({halvings} halvings in a row)")


def forced_orbit(M, C, K, force, F, omega: float, guess=None, tol: float = 1e-11) -> Orbit:
    """The periodic orbit of period ``2π/ω`` of ``M x'' + C x' + K x + f(x, x') = F cos ωt``
    near ``guess`` (``y0 = (x(0), x'(0))``; ``None``: the linear response), by single shooting.

    Newton on ``y(T) - y(0) = 0`` with the monodromy from the variational equations, at most
    30 integrations; the orbit is returned only if ``|y(T) - y0| / |y0| <= tol``, else
    ``ShootingError`` says which residual was reached."""
    system = _System(M, C, K, force, F)
    y0 = system.linear_guess(omega) if guess is None else np.asarray(guess, float)
    shot, steps = _newton(system, float(omega), y0, tol)
    return _orbit(system, shot, steps, tol)


def linear_amplitude(M, C, K, F, omega: float) -> np.ndarray:
    """``|X_i|`` with ``(K - ω²M + iωC) X = F``: the closed-form linear amplitudes."""
    return np.abs(_System(M, C, K, None, F).linear_phasor(omega))


# --------------------------------------------------------------------------- natural parameter


@dataclass(frozen=True)
class Curve:
    """A response curve over a grid of ω (``amplitude[k, i] = max_t |x_i|`` at ``omegas[k]``).

    ``folds`` lists the indices past a fold: the branch followed by pseudo-arclength from the
    previous orbit turned back before reaching that ω.  With ``stop_at_fold`` the entries from
    the first fold on are NaN (``stable`` False); ``residual`` is each orbit's shooting
    residual."""

    omegas: np.ndarray
    amplitude: np.ndarray
    stable: np.ndarray
    residual: np.ndarray
    y0: np.ndarray
    folds: list


def _same(a: np.ndarray, b: np.ndarray, rel: float = 1e-6) -> bool:
    return bool(np.linalg.norm(a - b) <= rel * max(np.linalg.norm(a), np.linalg.norm(b), TINY))


def forced_curve(M, C, K, force, F, omegas, guess=None, tol: float = 1e-11,
                 stop_at_fold: bool = True) -> Curve:
    """Natural-parameter continuation over an increasing grid ``omegas``.

    The first orbit starts from ``guess`` (default: the linear response ``(K - ω²M + iωC) X =
    F``; ``ShootingError`` if Newton fails there), every later one from the linear
    extrapolation of the previous one along its tangent ``dy0/dω = -(Φ - I)⁻¹ z`` (from the
    variational equations, exact to first order).  This follows ONE branch, the one
    connected to the start; it cannot pass a fold, and it reports one rather than silently
    jumping: where Newton fails, or where the orbit it finds is far from the extrapolation
    (more than twice the predicted step and 2 % of |y0|), the branch is followed from the
    previous orbit to the new ω by pseudo-arclength.  If it gets there without turning back,
    that orbit is the next point (a steep stretch, no fold); if it turns back, the index goes
    to ``folds``.  ``stop_at_fold``: NaN from there on; otherwise go on from the orbit Newton
    found (or from the linear response, if it found none).  A jump smaller than both bounds
    (near a cusp) is not examined."""
    system = _System(M, C, K, force, F)
    omegas = np.asarray(omegas, float)
    if np.any(np.diff(omegas) <= 0):
        raise ValueError("omegas must increase")
    n, N, m = system.n, system.N, len(omegas)
    amplitude, y0s = np.full((m, n), np.nan), np.full((m, N), np.nan)
    stable, residual = np.zeros(m, bool), np.full(m, np.nan)
    folds: list[int] = []
    last: _Shot | None = None  # the previous orbit, None at the start and after a restart
    for k, omega in enumerate(omegas):
        if last is None:
            pred = system.linear_guess(omega) if guess is None or k else np.asarray(guess, float)
        else:
            pred = last.y0 - (omega - last.omega) * np.linalg.solve(last.Phi - np.eye(N), last.z)
        try:
            shot, steps = _newton(system, omega, pred, tol)
        except ShootingError:
            if k == 0:
                raise
            shot, steps = None, 0
        if last is not None:
            suspicious = shot is None or np.linalg.norm(shot.y0 - pred) > max(
                2 * np.linalg.norm(pred - last.y0), 0.02 * np.linalg.norm(last.y0))
            if suspicious:
                bridged = _bridge(system, last, omega, tol)
                if bridged is None:
                    folds.append(k)
                    if stop_at_fold:
                        break
                shot = bridged or shot
        last = shot
        if shot is not None:
            orbit = _orbit(system, shot, steps, tol)
            amplitude[k], y0s[k] = orbit.amplitude, orbit.y0
            stable[k], residual[k] = orbit.stable, orbit.residual
    return Curve(omegas, amplitude, stable, residual, y0s, folds)


# --------------------------------------------------------------------------- pseudo-arclength


@dataclass
class _Point:
    """A converged point of a branch, in scaled coordinates ``w = (y0, ω) / scale``."""

    w: np.ndarray
    shot: _Shot
    tangent: np.ndarray
    amplitude: np.ndarray
    slope: float  # d amplitude[coordinate] / ds along ``tangent``
    stable: bool


def _scale(system: _System, lo: float, hi: float, points: int) -> np.ndarray:
    """Scales of ``(x, v, ω)``: the largest linear |X| and ω|X| over [lo, hi], and hi - lo."""
    grid = np.linspace(lo, hi, max(points, 2) * 4)
    X = np.array([np.linalg.norm(system.linear_phasor(w)) for w in grid])
    sx, sv = max(X.max(), TINY), max((grid * X).max(), TINY)
    n = system.n
    return np.concatenate((np.full(n, sx), np.full(n, sv), [hi - lo]))


def _jacobian(shot: _Shot, scale: np.ndarray) -> np.ndarray:
    """``∂R/∂w`` of the scaled residual ``R = (y(2π) - y0) / scale``."""
    N = len(shot.y0)
    J = np.hstack((shot.Phi - np.eye(N), shot.z[:, None])) * scale
    return J / scale[:N, None]


def _tangent(J: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
    """The unit null vector of ``J``, oriented along ``previous`` (or the last singular one)."""
    if previous is None:
        return np.linalg.svd(J)[2][-1]
    t = np.linalg.solve(np.vstack((J, previous)), np.eye(len(previous))[-1])
    return t / np.linalg.norm(t)


def _point(system: _System, scale: np.ndarray, w: np.ndarray, shot: _Shot,
           previous: np.ndarray | None, coordinate: int) -> _Point:
    t = _tangent(_jacobian(shot, scale), previous)
    amplitude, times = _peak_times(system, shot)
    Q = _at(shot, times[coordinate])
    sens = Q[coordinate, 1:] * scale  # ∂x_c(τ*)/∂w
    slope = float(np.sign(Q[coordinate, 0]) * sens @ t)
    stable = bool(np.all(np.abs(np.linalg.eigvals(shot.Phi)) < 1.0))
    return _Point(w, shot, t, amplitude, slope, stable)


def _correct(system: _System, scale: np.ndarray, w: np.ndarray, normal: np.ndarray,
             level: float, tol: float, max_iter: int = 8):
    """Newton on ``R(w) = 0``, ``normal · w = level`` (the bordered system); ``None`` if it
    diverges or needs more than ``max_iter`` integrations, else ``(w, dense shot)``."""
    N = system.N
    previous = math.inf
    for it in range(max_iter):
        y0, omega = w[:N] * scale[:N], w[N] * scale[N]
        if omega <= 0:
            return None
        try:
            shot = _shoot(system, y0, omega, dense=it > 0)  # likely the last one
        except ShootingError:
            return None
        res = shot.residual
        if res <= tol:
            if shot.sol is None:
                shot = _shoot(system, y0, omega, dense=True)
            return w, shot
        if res > 2 * previous:
            return None
        previous = res
        A = np.vstack((_jacobian(shot, scale), normal))
        b = np.concatenate(((shot.yT - y0) / scale[:N], [normal @ w - level]))
        w = w - np.linalg.solve(A, b)
    return None


def _omega(point: _Point, scale: np.ndarray) -> float:
    return float(point.w[-1] * scale[-1])


def _first(system, scale, shot: _Shot, coordinate, direction) -> _Point:
    """The branch point of a converged dense ``shot``, its tangent towards ``direction`` in ω."""
    w = np.concatenate((shot.y0, [shot.omega])) / scale
    point = _point(system, scale, w, shot, None, coordinate)
    if point.tangent[-1] * direction < 0:
        point.tangent, point.slope = -point.tangent, -point.slope
    return point


def _start(system, scale, omega, coordinate, direction, tol) -> _Point:
    """The orbit at ``omega`` by Newton from the linear response, as a branch point."""
    shot, _ = _newton(system, omega, system.linear_guess(omega), tol)
    return _first(system, scale, shot, coordinate, direction)


def _trace(system, scale, start: _Point, lo, hi, coordinate, points, tol,
           max_steps=None) -> list[_Point]:
    """Pseudo-arclength from ``start`` along its tangent until ω leaves [lo, hi] (the last
    point returned is the first outside).  In scaled ``w``, the predictor is the tangent plus
    the curvature through the previous point, the corrector Newton on the bordered system
    (residual and the hyperplane normal to the tangent).  The step starts at 1/points, halves
    on failure or a turn of more than ~37°, grows by 1.5 (up to STEP_MAX/points) after a turn
    of less than ~18°.  At most ``max_steps`` (default ``20 * points``) steps, else
    ``ContinuationError``."""
    ds_max, ds_min = STEP_MAX / points, 1e-7
    ds, branch = 1.0 / points, [start]
    max_steps = 20 * points if max_steps is None else max_steps
    for _ in range(max_steps):
        p = branch[-1]
        bend = np.zeros_like(p.w)
        if len(branch) > 1:  # w(-h) = w_k - h t + h² c through the previous point
            back = branch[-2].w - p.w
            h = -p.tangent @ back
            bend = (back + h * p.tangent) / h**2
        while True:
            pred = p.w + ds * p.tangent + ds**2 * bend
            out = _correct(system, scale, pred, p.tangent, p.tangent @ pred, tol)
            if out is not None:
                new = _point(system, scale, out[0], out[1], p.tangent, coordinate)
                if new.tangent @ p.tangent > 0.8:
                    break
            ds /= 2
            if ds < ds_min:
                raise ContinuationError(f"step below {ds_min:g} at omega = "
                                        f"{_omega(p, scale):.12g}")
        branch.append(new)
        ds = min(1.5 * ds, ds_max) if new.tangent @ p.tangent > 0.95 else ds
        if not lo < _omega(new, scale) < hi:
            return branch
    raise ContinuationError(f"no exit from [{lo}, {hi}] after {max_steps} steps")


def _at_omega(system, scale, inside: _Point, outside: _Point, omega, coordinate, tol) -> _Point:
    """The branch point at exactly ω between two consecutive points."""
    a, b = _omega(inside, scale), _omega(outside, scale)
    guess = inside.w + (outside.w - inside.w) * (omega - a) / (b - a)
    normal = np.eye(len(guess))[-1]
    out = _correct(system, scale, guess, normal, omega / scale[-1], tol, max_iter=30)
    if out is None:
        raise ContinuationError(f"could not land on omega = {omega}")
    return _point(system, scale, out[0], out[1], inside.tangent, coordinate)


def _bridge(system: _System, back: _Shot, omega: float, tol: float) -> _Shot | None:
    """The orbit at ``omega`` on the branch through ``back`` (a dense shot at a lower ω),
    followed by pseudo-arclength; ``None`` if the branch turns back first (a fold) or cannot be
    followed there."""
    lo, hi = back.omega, omega
    scale = _scale(system, lo, hi, 4)
    try:
        branch = _trace(system, scale, _first(system, scale, back, 0, +1), lo, hi, 0, 8,
                        max(tol, TRACE_TOL))
        if _omega(branch[-1], scale) < hi:
            return None
        return _at_omega(system, scale, branch[-2], branch[-1], hi, 0, tol).shot
    except ContinuationError:
        return None


def _tighten(system, scale, p: _Point, coordinate, tol) -> _Point:
    """``p`` corrected to residual ``tol`` on its own tangent hyperplane."""
    if p.shot.residual <= tol:
        return p
    out = _correct(system, scale, p.w, p.tangent, p.tangent @ p.w, tol, max_iter=30)
    if out is None:
        raise ContinuationError(f"could not tighten the point at omega = {_omega(p, scale)}")
    return _point(system, scale, out[0], out[1], p.tangent, coordinate)


def _bracket(system, scale, branch, k, coordinate, tol):
    """Branch points ``k, k+1`` at residual ``tol`` with ``dA/ds`` going from + to - (moving
    along the branch if the traced slopes, at a looser residual, put the sign change one
    interval off); ``None`` if the tightened slopes show no maximum there after all."""
    tight: dict[int, _Point] = {}

    def at(j):
        if j not in tight:
            tight[j] = _tighten(system, scale, branch[j], coordinate, tol)
        return tight[j]

    while True:
        a, b = at(k), at(k + 1)
        if a.slope > 0 >= b.slope:
            return a, b
        if a.slope <= 0 and k > 0:
            k -= 1
        elif b.slope > 0 and k + 2 < len(branch):
            k += 1
        else:
            return None


def _refine(system, scale, a: _Point, b: _Point, coordinate, tol, xtol=1e-10) -> _Point:
    """The point between ``a`` and ``b`` where ``slope`` (dA/ds) vanishes: Illinois regula falsi
    on ``σ = t_a · (w - w_a)``, each value from the bordered corrector at level σ; stops when
    the step in σ (scaled, so ω moves by at most ``(hi-lo)·xtol``) is below ``xtol``."""
    t = a.tangent
    known = [(0.0, a), (float(t @ (b.w - a.w)), b)]

    def evaluate(sigma):
        s0, p0 = min(known, key=lambda sp: abs(sp[0] - sigma))
        guess = p0.w + (sigma - s0) / (t @ p0.tangent) * p0.tangent
        out = _correct(system, scale, guess, t, t @ a.w + sigma, tol, max_iter=30)
        if out is None:
            raise ContinuationError("corrector failed while refining a peak")
        point = _point(system, scale, out[0], out[1], t, coordinate)
        known.append((sigma, point))
        return point

    (sa, pa), (sb, pb) = known
    ga, gb = pa.slope, pb.slope
    last, side, best = None, 0, None
    for _ in range(60):
        sigma = sb - gb * (sb - sa) / (gb - ga)
        best = evaluate(sigma)
        g = best.slope
        if (last is not None and abs(sigma - last) < xtol) or g == 0.0 or sb - sa < xtol:
            return best
        last = sigma
        if g > 0:
            sa, ga = sigma, g
            if side == +1:
                gb /= 2
            side = +1
        else:
            sb, gb = sigma, g
            if side == -1:
                ga /= 2
            side = -1
    raise ContinuationError("peak refinement did not converge in 60 steps")


@dataclass(frozen=True)
class Branch:
    """A branch by pseudo-arclength: ω, amplitudes ``max_t |x_i|``, stability and
    ``slope = d amplitude[coordinate] / ds`` at every point (the last one outside [lo, hi]).
    ``folds`` are the indices after which ω turned back (a saddle-node between k and k+1)."""

    omegas: np.ndarray
    amplitude: np.ndarray
    stable: np.ndarray
    slope: np.ndarray
    y0: np.ndarray
    folds: list


def _as_branch(points: list[_Point], scale: np.ndarray) -> Branch:
    omegas = np.array([_omega(p, scale) for p in points])
    dw = np.array([p.tangent[-1] for p in points])
    folds = [k for k in range(len(points) - 1) if dw[k] * dw[k + 1] < 0]
    return Branch(omegas, np.array([p.amplitude for p in points]),
                  np.array([p.stable for p in points]), np.array([p.slope for p in points]),
                  np.array([p.shot.y0 for p in points]), folds)


def trace_branch(M, C, K, force, F, lo: float, hi: float, coordinate: int = 0,
                 points: int = 40, start: str = "lo", tol: float = 1e-9) -> Branch:
    """The branch through the orbit at ω = ``lo`` (``start="lo"``, leaving towards higher ω)
    or ``hi`` (towards lower ω), seeded by the linear response, followed by pseudo-arclength
    through folds until ω leaves [lo, hi] (the last point is the first one outside): at most
    ``20 * points`` steps.  Points are accepted at residual ``tol``; ``slope`` is
    ``d amplitude[coordinate] / ds``."""
    if start not in ("lo", "hi"):
        raise ValueError('start is "lo" or "hi"')
    system = _System(M, C, K, force, F)
    scale = _scale(system, lo, hi, points)
    omega, direction = (lo, +1) if start == "lo" else (hi, -1)
    first = _start(system, scale, omega, coordinate, direction, tol)
    return _as_branch(_trace(system, scale, first, lo, hi, coordinate, points, tol), scale)


def _candidates(system, scale, branch, lo, hi, coordinate, tol) -> list[_Point]:
    """The branch's start, its landing on the boundary it left by, and its interior maxima."""
    out = [branch[0]]
    last, inside = branch[-1], branch[-2]
    edge = hi if _omega(last, scale) >= hi else lo
    out.append(_at_omega(system, scale, inside, last, edge, coordinate, tol))
    for k, (a, b) in enumerate(pairwise(branch)):
        if a.slope > 0 >= b.slope:
            pair = _bracket(system, scale, branch, k, coordinate, tol)
            top = pair and _refine(system, scale, *pair, coordinate, tol)
            if top and lo <= _omega(top, scale) <= hi:
                out.append(top)
    return out


def _starts(system, scale, lo, hi, coordinate, tol) -> tuple:
    """The orbits at ``lo`` and ``hi`` from the linear response (``None`` where Newton fails)."""
    out = []
    for omega, direction in ((lo, +1), (hi, -1)):
        try:
            out.append(_start(system, scale, omega, coordinate, direction, tol))
        except ShootingError:
            out.append(None)
    if out == [None, None]:
        raise ShootingError(f"no orbit from the linear response at either {lo} or {hi}")
    return tuple(out)


def peak(M, C, K, force, F, lo: float, hi: float, coordinate: int, points: int = 40,
         tol: float = 1e-11) -> tuple[float, float]:
    """``(ω, A)`` of the largest ``A = max_t |x_coordinate(t)|`` over ω in [lo, hi].

    The branch through the orbit at ``lo`` (Newton from the linear response) is traced by
    pseudo-arclength towards higher ω, through folds, so a hardening or softening peak's upper
    branch is followed to its top, until ω leaves [lo, hi]; so is the branch through the orbit
    at ``hi`` towards lower ω, unless the first trace landed on that very orbit.  Candidates
    are the branches' ends on [lo, hi] and every point where ``dA/ds`` (from the variational
    equations at the time of the maximum) changes sign from + to -, refined by Illinois regula
    falsi on ``dA/ds`` until the step moves ω by less than ``1e-10·(hi-lo)``; the largest
    candidate wins.  Trace points are accepted at residual 1e-6 (TRACE_TOL), every candidate
    at ``tol``.  ``points`` sets the resolution: steps of 1/points to 8/points of the scaled
    ``(y0/|X|max, ω/(hi-lo))``, at most ``20 * points`` of them per trace.

    Where ``max_t |x_c|`` switches between two humps of ``x_c(t)`` along the branch, ``A`` has
    a kink and ``dA/ds`` jumps; if the jump is from + to -, regula falsi converges to the kink,
    which is then the maximum."""
    system = _System(M, C, K, force, F)
    if not np.any(system.F) or not 0 < lo < hi:
        raise ValueError("peak needs F != 0 and 0 < lo < hi")
    scale = _scale(system, lo, hi, points)
    trace_tol = max(tol, TRACE_TOL)
    first, end = _starts(system, scale, lo, hi, coordinate, tol)
    found: list[_Point] = []
    if first is not None:
        forward = _trace(system, scale, first, lo, hi, coordinate, points, trace_tol)
        found += _candidates(system, scale, forward, lo, hi, coordinate, tol)
        landed = found[1]
        if end is None or (math.isclose(_omega(landed, scale), hi, rel_tol=1e-12)
                           and _same(landed.shot.y0, end.shot.y0)):
            end = None  # the orbit at hi is on the branch just traced
    if end is not None:
        backward = _trace(system, scale, end, lo, hi, coordinate, points, trace_tol)
        found += _candidates(system, scale, backward, lo, hi, coordinate, tol)
    best = max(found, key=lambda p: p.amplitude[coordinate])
    return _omega(best, scale), float(best.amplitude[coordinate])


# --------------------------------------------------------------------------- free decay


def free_decay(M, C, K, force, x0, v0, times) -> tuple[np.ndarray, np.ndarray]:
    """The unforced motion from ``x(0) = x0``, ``x'(0) = v0``, sampled at ``times`` (increasing,
    t ≥ 0, dense output): ``(x, v)``, each of shape ``(len(times), n)``.  DOP853, rtol 1e-12,
    atol 1e-14."""
    system = _System(M, C, K, force, np.zeros(np.atleast_2d(M).shape[0]))
    n = system.n
    times = np.asarray(times, float)

    def fun(t, y):
        return np.concatenate((y[n:], system.accel(y, 0.0)))

    start = np.concatenate((np.asarray(x0, float), np.asarray(v0, float)))
    sol = solve_ivp(fun, (0.0, float(times.max())), start, method="DOP853", rtol=1e-12,
                    atol=1e-14, t_eval=times)
    if sol.status != 0:
        raise RuntimeError(f"free decay integration failed: {sol.message}")
    return sol.y[:n].T.copy(), sol.y[n:].T.copy()


# --------------------------------------------------------------------------- conservative backbone


@dataclass(frozen=True)
class FreeOrbit:
    """A periodic orbit of the conservative ``M x'' + K x + f(x) = 0``, of period ``2π/ω``,
    starting at rest: ``y0 = (x(0), 0)``.

    ``residual = |(x(T) − x(0), v(T)/ω)| / |x(0)|`` (dimensionless: velocities over ω): one
    whole period integrated afresh from the converged ``y0``, by a finer integration than
    Newton's (the judge: it holds the integration error as well as Newton's); ``half`` is the
    half-period condition ``|v(T/2)| / (ω|x(0)|)`` at Newton's last integration (before its
    last update where the judge stopped it: :data:`EARLY`);
    ``amplitude[i] = max_t |x_i(t)|`` over the period's steps; ``steps`` the RK4 steps a
    period (Newton's; the judge takes twice as many); ``newton`` the half-period
    integrations Newton used; ``seconds`` the wall time it took (the one field that varies
    from run to run)."""

    omega: float
    y0: np.ndarray
    residual: float
    half: float
    amplitude: np.ndarray
    steps: int
    newton: int
    tolerance: float = field(repr=False, default=1e-9)
    seconds: float = field(repr=False, compare=False, default=0.0)  # wall time, guess to judge


def _monomials(n: int, terms: Sequence) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A table of monomials in ``x`` alone (``(i, [j, k, ...], c)``, degree ≤ 3) as arrays:
    equation, factors padded with −1 to three, coefficient."""
    table = [(int(i), [int(j) for j in js], float(c)) for i, js, c in terms]
    if any(not 0 <= i < n or not 1 <= len(js) <= 3 or any(not 0 <= j < n for j in js)
           for i, js, _ in table):
        raise ValueError("a conservative backbone takes monomials of x of degree ≤ 3")
    return (np.array([i for i, _, _ in table], dtype=np.int64),
            np.array([[*js, -1, -1][:3] for _, js, _ in table], dtype=np.int64).reshape(-1, 3),
            np.array([c for _, _, c in table], dtype=float))


def _field(y, P, mk, minv, eq, fac, coef, variational):
    """``(y', P')``: the state's field and the variational one (compiled by numba)."""
    n = mk.shape[0]
    f = np.zeros(n)
    J = np.zeros((n, n))
    for t in range(coef.size):
        i, a, b, c = eq[t], fac[t, 0], fac[t, 1], fac[t, 2]
        xa, xb = y[a], y[b]
        if c < 0:
            f[i] += coef[t] * xa * xb
            if variational:
                J[i, a] += coef[t] * xb
                J[i, b] += coef[t] * xa
        else:
            xc = y[c]
            f[i] += coef[t] * xa * xb * xc
            if variational:
                J[i, a] += coef[t] * xb * xc
                J[i, b] += coef[t] * xa * xc
                J[i, c] += coef[t] * xa * xb
    dy = np.empty(2 * n)
    dy[:n] = y[n:]
    dy[n:] = -(mk @ y[:n]) - minv @ f
    if not variational:
        return dy, P
    dP = np.empty_like(P)
    dP[:n] = P[n:]
    dP[n:] = -(mk + minv @ J) @ P[:n]
    return dy, dP


def _flow(y, P, h, steps, mk, minv, eq, fac, coef, variational, path):
    """``steps`` classical RK4 steps of ``_jit_field`` (compiled by numba: :func:`_compiled`)."""
    for s in range(steps):
        a1, b1 = _jit_field(y, P, mk, minv, eq, fac, coef, variational)
        a2, b2 = _jit_field(y + h / 2 * a1, P + h / 2 * b1, mk, minv, eq, fac, coef,
                            variational)
        a3, b3 = _jit_field(y + h / 2 * a2, P + h / 2 * b2, mk, minv, eq, fac, coef,
                            variational)
        a4, b4 = _jit_field(y + h * a3, P + h * b3, mk, minv, eq, fac, coef, variational)
        y = y + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        if variational:
            P = P + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4)
        if path.shape[0] > 1:
            path[s + 1] = y
    return y, P


_jit_field = None  # the compiled field, set before _flow is compiled
_COMPILED: tuple = ()
COMPILE_ABOVE = 12
# NOTE: above this many coordinates the RK4 loop is compiled by numba (10-20 s the first
# time, cached on disk; then ~10x faster); up to it, NumPy on dense tensors of the force
# (n⁴ numbers) in a Python loop, no compilation.


def _compiled() -> tuple:
    """``(field, flow)`` compiled by numba (cached on disk)."""
    global _jit_field, _COMPILED
    if not _COMPILED:
        from numba import njit

        _jit_field = njit(cache=True)(_field)
        _COMPILED = (_jit_field, njit(cache=True)(_flow))
    return _COMPILED


def _tensor_field(mk, minv, eq, fac, coef):
    """:func:`_field` by NumPy on dense tensors: ``M⁻¹f = F₂(x⊗x) + F₃(x⊗x⊗x)`` and its
    Jacobian ``G₂ x + G₃ (x⊗x)``, reshaped ``n × n``."""
    n = mk.shape[0]
    T2, T3 = np.zeros((n, n, n)), np.zeros((n, n, n, n))
    for i, (a, b, c), value in zip(eq, fac, coef, strict=True):
        if c < 0:
            T2[i, a, b] += value
        else:
            T3[i, a, b, c] += value
    T2 = np.einsum("ij,jab->iab", minv, T2)
    T3 = np.einsum("ij,jabc->iabc", minv, T3)
    F2, F3 = T2.reshape(n, n * n), T3.reshape(n, n**3)
    G2 = (T2 + T2.transpose(0, 2, 1)).reshape(n * n, n)
    G3 = (T3 + T3.transpose(0, 2, 1, 3) + T3.transpose(0, 3, 1, 2)).reshape(n * n, n * n)

    def field(y, P, *_):
        x = y[:n]
        xx = np.outer(x, x).ravel()
        dy = np.concatenate((y[n:], -(mk @ x) - F2 @ xx - F3 @ np.outer(xx, x).ravel()))
        if P is None:
            return dy, None
        J = (G2 @ x + G3 @ xx).reshape(n, n)
        return dy, np.concatenate((P[n:], -((mk + J) @ P[:n])))

    def flow(y, P, h, steps, mk, minv, eq, fac, coef, variational, path):
        P = P if variational else None
        for s in range(steps):
            a1, b1 = field(y, P)
            if variational:
                a2, b2 = field(y + h / 2 * a1, P + h / 2 * b1)
                a3, b3 = field(y + h / 2 * a2, P + h / 2 * b2)
                a4, b4 = field(y + h * a3, P + h * b3)
                P = P + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4)
            else:
                a2 = field(y + h / 2 * a1, None)[0]
                a3 = field(y + h / 2 * a2, None)[0]
                a4 = field(y + h * a3, None)[0]
            y = y + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
            if path.shape[0] > 1:
                path[s + 1] = y
        return y, P

    return field, flow


class _Conservative:
    """``x'' = −M⁻¹(K x + f(x))`` and its variational equation for perturbations of ``x(0)``
    alone (``v(0) = 0`` held): by classical RK4 with a fixed step (a stiff model takes tens
    of thousands of steps a period), the loop compiled by numba above
    :data:`COMPILE_ABOVE` coordinates (or as ``compiled`` says); or by SciPy's DOP853 on the
    force's dense tensors (``method="DOP853"``: small models, n⁴ numbers)."""

    def __init__(self, M, K, terms, compiled: bool | None = None, method: str = "RK4"):
        M = np.atleast_2d(np.asarray(M, float))
        self.n = n = M.shape[0]
        self.minv = np.linalg.inv(M)
        self.mk = self.minv @ np.atleast_2d(np.asarray(K, float))
        self.table = _monomials(n, terms)
        self.fastest = float(np.sqrt(np.max(np.abs(np.linalg.eigvals(self.mk)))))
        if method not in ("RK4", "DOP853"):
            raise ValueError(f"method {method!r}: RK4 or DOP853")
        self.method = method
        if method == "RK4" and (n > COMPILE_ABOVE if compiled is None else compiled):
            self._field, self._flow = _compiled()
        else:
            self._field, self._flow = _tensor_field(self.mk, self.minv, *self.table)

    def accel(self, y: np.ndarray) -> np.ndarray:
        n = self.n
        return self._field(np.asarray(y, float), np.zeros((2 * n, n)), self.mk, self.minv,
                           *self.table, False)[0][n:]

    def static(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``M⁻¹(K x + f(x))`` and its Jacobian ``M⁻¹(K + ∂f/∂x)``."""
        n = self.n
        P = np.vstack((np.eye(n), np.zeros((n, n))))
        y = np.concatenate((np.asarray(x, float), np.zeros(n)))
        dy, dP = self._field(y, P, self.mk, self.minv, *self.table, True)
        return -dy[n:], -dP[n:]

    def quasi_static(self, x: np.ndarray, fast: np.ndarray, left: np.ndarray) -> np.ndarray:
        """``x`` with its components on the ``fast`` modes (columns, ``left`` their rows of
        ``Φᵀ M``) put where those modes are in static equilibrium, ``Φ_fᵀ(K x + f(x)) = 0``
        (Newton, a few steps): at a turning point of an orbit the fast modes follow the slow
        ones nearly statically, so this is the guess Newton's shooting starts nearest from."""
        x = np.array(x, float)
        for _ in range(8):
            g, J = self.static(x)
            r = left @ g
            if np.linalg.norm(r) <= 1e-14 * np.linalg.norm(left @ (self.mk @ x)):
                break
            x -= fast @ np.linalg.solve(left @ J @ fast, r)
        return x

    def flow(self, x0: np.ndarray, duration: float, steps: int, variational: bool,
             keep: bool = False, fine: bool = False):
        """The flow over ``duration`` from ``(x0, 0)``: the end state, the sensitivities
        ``∂y/∂x(0)`` (``2n × n``; None without ``variational``), and with ``keep`` the state
        at ``steps + 1`` equally spaced times (``(steps + 1, 2n)``).  RK4: ``steps`` steps
        (``2·steps`` when ``fine``); DOP853: rtol 1e-12, atol 1e-13 (both 10 times smaller
        when ``fine``)."""
        n = self.n
        y = np.concatenate((np.asarray(x0, float), np.zeros(n)))
        P = np.vstack((np.eye(n), np.zeros((n, n))))
        if self.method == "DOP853":
            size = 2 * n * (n + 1) if variational else 2 * n

            def fun(t, Y):
                a, b = self._field(Y[:2 * n], Y[2 * n:].reshape(2 * n, n) if variational
                                   else None)
                return np.concatenate((a, b.ravel())) if variational else a

            start = np.concatenate((y, P.ravel())) if variational else y
            scale = 0.1 if fine else 1.0
            sol = solve_ivp(fun, (0.0, duration), start[:size], method="DOP853",
                            rtol=RTOL * scale, atol=ATOL * scale, dense_output=keep)
            if sol.status != 0 or not np.all(np.isfinite(sol.y[:, -1])):
                raise ShootingError(f"integration failed: {sol.message}")
            end = sol.y[:, -1]
            path = sol.sol(np.linspace(0.0, duration, steps + 1))[:2 * n].T if keep else None
            return end[:2 * n], (end[2 * n:].reshape(2 * n, n) if variational else None), path
        if fine:
            steps *= 2
        path = np.empty((steps + 1 if keep else 1, 2 * n))
        path[0] = y
        y, P = self._flow(y, P, duration / steps, steps, self.mk, self.minv, *self.table,
                          variational, path)
        return y, (P if variational else None), (path if keep else None)


STEP_STABILITY = 0.5
# NOTE: the fixed step keeps ω_max·h ≤ 0.5 (RK4 is stable to 2.83 on the imaginary axis):
# the stiffest mode (a beam's axial ones, thousands of times the lowest frequency) then sets
# the step, not the accuracy, and the slow motion is integrated far below 1e-12.
MIN_STEPS = 4096
# NOTE: and at least this many steps a period (ω h ≤ 1.6e-3 on the orbit's own frequency): a
# mildly stiff model's step is set by accuracy (its fast modes' phase error), not stability.


def free_orbit(M, K, terms, coordinate: int, amplitude: float, x0, omega: float,
               tol: float = 1e-9, steps: int | None = None, max_steps: int = 12,
               method: str = "RK4", system: _Conservative | None = None) -> FreeOrbit:
    """The periodic orbit of the conservative system through ``x_coordinate(0) = amplitude``
    at rest, near the guess ``(x0, ω)``, by half-period shooting.

    The system is reversible (``t → −t``): an orbit with ``v(0) = 0`` and ``v(T/2) = 0`` is
    ``T``-periodic.  The unknowns are ``x(0)`` but its ``coordinate`` (held at ``amplitude``:
    the amplitude condition) and ``ω`` (the period is unknown; ``v(0) = 0`` is the phase
    condition); the equations ``v(T/2) = 0``, ``n`` of them, solved by Newton with the
    variational equations (``∂v(T/2)/∂ω = −(π/ω²) a(T/2)``).

    ``method="RK4"``: classical RK4 with a fixed step, ``steps`` a period (default: a power
    of two with ``ω_max h ≤`` :data:`STEP_STABILITY`, at least :data:`MIN_STEPS`), so that a
    stiff model (a slender beam's axial modes) costs steps, not failures; the judge
    integrates a whole period with half the step.  ``method="DOP853"``: SciPy's adaptive
    DOP853 (rtol 1e-12), for a mildly stiff model, where it takes far fewer steps; the judge
    integrates a whole period at tolerances ten times smaller (``steps``: samples of the
    amplitude, default 400).  The orbit is returned only when the judge's
    ``|(x(T) − x(0), v(T)/ω)| / |x(0)| ≤ tol``, else :class:`ShootingError` — never on a
    flag."""
    start = time.perf_counter()
    system = system or _Conservative(M, K, terms, method=method)
    n = system.n
    if steps is None and system.method == "DOP853":
        steps = 400
    elif steps is None:
        steps = max(MIN_STEPS, 2 ** math.ceil(math.log2(system.fastest * TWO_PI / omega
                                                        / STEP_STABILITY)))
    free = np.delete(np.arange(n), coordinate)
    x = np.array(x0, float)
    x[coordinate] = amplitude
    omega = float(omega)
    def judge() -> tuple[float, np.ndarray]:
        end, _, path = system.flow(x, TWO_PI / omega, steps, False, keep=True, fine=True)
        gap = end - np.concatenate((x, np.zeros(n)))
        gap[n:] /= omega  # velocities in units of displacement: the residual is dimensionless
        return float(np.linalg.norm(gap) / np.linalg.norm(x)), path

    half, used, residual, path = math.inf, 0, math.inf, None
    while used < max_steps:
        used += 1
        y, P, _ = system.flow(x, math.pi / omega, steps // 2, True)
        r = y[n:]  # v(T/2)
        half = float(np.linalg.norm(r) / (omega * np.linalg.norm(x)))
        if half <= 1e-3 * tol:
            residual, path = judge()
            break
        J = np.column_stack((P[n:][:, free], -math.pi / omega**2 * system.accel(y)))
        delta = np.linalg.solve(J, -r)
        x[free] += delta[:-1]
        omega += float(delta[-1])
        if half <= EARLY:  # Newton's next step would be ~half²: the judge may accept it now
            residual, path = judge()
            if residual <= 1e-2 * tol:
                break
    y0 = np.concatenate((x, np.zeros(n)))
    if not residual <= tol:
        raise ShootingError(f"amplitude {amplitude:.6g}: periodicity residual {residual:.3e} "
                            f"above {tol:.1e} (half-period condition {half:.1e}, {used} "
                            "Newton steps)")
    peak = np.max(np.abs(path[:, :n]), axis=0)
    return FreeOrbit(omega, y0, residual, half, peak, steps, used, tol,
                     time.perf_counter() - start)


EARLY = 1e-5
# NOTE: once the half-period condition is this small, each Newton update is followed by the
# judge's whole period, and Newton stops when it closes to 1e-2 tol: the quadratic step has
# landed, and the half period that would only confirm it is saved.
FAST = 3.0
# NOTE: modes above this multiple of the lowest frequency start each orbit's Newton in static
# equilibrium (:meth:`_Conservative.quasi_static`): a beam's axial modes, stretched by the
# bending one, would else ring at their own frequency and cost Newton two or three steps.


def backbone(M, K, terms, coordinate: int, amplitudes, tol: float = 1e-9,
             steps: int | None = None, method: str = "RK4") -> list[FreeOrbit]:
    """The conservative backbone of the lowest mode at increasing ``amplitudes`` of
    ``x_coordinate``: continuation from the linear mode (``K φ = ω₀² M φ``, scaled to the
    first amplitude), each next guess extrapolated linearly in the amplitude from the last
    two orbits (scaled from the last one at the second); in each guess the modes above
    :data:`FAST` times the lowest frequency are put in static equilibrium."""
    from scipy.linalg import eigh

    M = np.atleast_2d(np.asarray(M, float))
    K = np.atleast_2d(np.asarray(K, float))
    system = _Conservative(M, K, terms, method=method)
    lam, phi = eigh(K, M)
    mode = phi[:, 0] / phi[coordinate, 0]
    n = len(mode)
    fast = phi[:, lam > FAST**2 * lam[0]]  # φᵀMφ = I: the rows of φᵀM are the left ones
    left = fast.T @ M
    orbits: list[FreeOrbit] = []
    done: list[float] = []
    for A in amplitudes:
        if not orbits:
            x0, omega = A * mode, math.sqrt(lam[0])
        elif len(orbits) == 1:
            x0, omega = orbits[0].y0[:n] * A / done[0], orbits[0].omega
        else:
            a, b = orbits[-2], orbits[-1]
            t = (A - done[-1]) / (done[-1] - done[-2])
            x0 = b.y0[:n] + t * (b.y0[:n] - a.y0[:n])
            omega = b.omega + t * (b.omega - a.omega)
        x0 = system.quasi_static(x0, fast, left) if fast.size else x0
        orbits.append(free_orbit(M, K, terms, coordinate, A, x0, omega, tol, steps,
                                 system=system))
        done.append(float(A))
    return orbits
