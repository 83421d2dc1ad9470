"""The one pseudo-arclength continuation of the package (:class:`Arclength`: the predictor,
the corrector, the step control and the fold detection), parameterised by what it follows: the
drive frequency ω (:func:`_continue`: a curve in ω with its pieces, through its folds), the
drive amplitude f from rest at one ω (:func:`continue_in_drive`: the seeds of every orbit), or
an onset's drive amplitude (``subharmonic.subharmonic_onset``: f followed down to a fold or a
branch point); and the crossings of a traced curve with a level."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..limits import MAX_DRIVE_POINTS
from ..numerics.newton import bordered, secant
from .polynomial import DrivenEquation, PolynomialBalance, amplitude_bound


@dataclass(frozen=True)
class Continuation:
    """The N-harmonic balance traced in ω by pseudo-arclength: one or more pieces, each a
    curve from one end of the range to an end, or closed inside it (an isola, its first point
    repeated at its end) (``pieces``: the index of each piece's first point; consecutive
    points of different pieces are not neighbours on the curve)."""

    omega: np.ndarray
    x: np.ndarray  # (points, unknowns): a_1, a_3, …, b_1, b_3, … of each coordinate in turn
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
MIN_STEP = 1 / 1024
# NOTE: the continuation halves its step (down to 1/1024 of it) where a step turns the tangent
# by more than ~25°, lands far from the prediction or does not converge, and grows it back by
# 1.5 a step: a 2-DOF system's superharmonic resonance (ω0/3, Q = 20) turns within 0.005 in ω.
MAX_Q = 1e12
# NOTE: near the resonance x(ω) changes by ~Q·2e-16 relative between neighbouring doubles in ω:
# the corrector's 1e-13 then needs Q ≲ 1e3 (above, some steps take all 30 iterations: slower,
# still right); by Q ~ 1e16 the peak is narrower than the doubles around ω = 1 and the
# continuation wanders for good.  Below 1e12 it is only slower.
RETAKES = 3
# NOTE: corrector steps per allowed point, retaken (halved) ones included: a curve takes ~1.2–1.6
# a point; three bound a corrector that keeps failing somewhere by work, not by the clock.


@dataclass(frozen=True)
class Onset:
    """Where a branch of orbits is born as one parameter is followed: ``parameter`` (``force``,
    the drive amplitude, followed down at one ω; ``omega``, the pump frequency at a tongue's
    edge) at ``value``, and how: a ``fold`` (two orbits are born), a ``bifurcation`` off
    another state (the primary response, or rest at a tongue's edge: ``supercritical`` where
    the branch grows into the region where that state is unstable, else subcritical), or
    ``none`` (the orbits reach ``value`` = 0).  ``branch`` names the branch where there are
    several."""

    parameter: str
    value: float
    kind: str  # fold | bifurcation | none
    branch: str | None = None
    supercritical: bool | None = None


class Arclength:
    """The one pseudo-arclength predictor–corrector of the package, on a family ``fam`` of
    balances in one free parameter λ — what it follows: ω (a :class:`PolynomialBalance`
    itself: ``residual``, ``jacobian`` and ``d_omega`` in ``(x, ω)``), the drive amplitude f
    at one ω (:class:`DriveFamily`), or an onset's drive amplitude (the same, f decreasing).
    ``y = (x, λ)`` and its unit tangent ``t``; each :meth:`attempt` predicts ``y + h t``,
    corrects (:func:`_corrector`) and takes the point where it converged, did not turn the
    tangent by more than ~25°, and landed within ``2h``, then grows the step
    (``grow(y, h)``); else it retakes the step at half the length while ``h`` is above
    ``floor``: the ω continuation (``take_at_floor``) takes a step at or below the floor as
    it is (a narrow resonance's sharp turn; a singular or overflowing step raises
    ``LinAlgError``), any other gives up where the halved step falls below the floor
    (:attr:`stuck`).  A fold is where the tangent's λ
    component changes sign over a taken step (:attr:`fold`; its point:
    :func:`fold_point`)."""

    def __init__(self, fam: object, y: np.ndarray, t: np.ndarray, step: float, floor: float,
                 grow: Callable[[np.ndarray, float], float],
                 take_at_floor: bool = False) -> None:
        self.fam, self.y, self.t, self.h = fam, y, t, step
        self.floor, self.grow, self.take_at_floor = floor, grow, take_at_floor
        self.previous: tuple[np.ndarray, np.ndarray, float] | None = None  # (y, t, h) before
        self.fold = False  # the last step taken passed a fold
        self.stuck = False  # no step above the floor converges

    def attempt(self) -> bool:
        """One corrector step from :attr:`y`: whether it was taken (:attr:`y`, :attr:`t`,
        :attr:`previous`, :attr:`fold` then moved on), or retaken at half the length (or,
        below the floor, :attr:`stuck`)."""
        fam, y, t, h = self.fam, self.y, self.t, self.h
        try:
            y_new = _corrector(fam, y + h * t, t)
            t_new = _tangent(fam, y_new, t)
        except np.linalg.LinAlgError:
            if self.take_at_floor and h <= self.floor:
                raise
            return self._retake()
        finite = bool(np.all(np.isfinite(y_new)) and np.all(np.isfinite(t_new)))
        if not finite and self.take_at_floor:  # the ω continuation: refused
            raise np.linalg.LinAlgError("the balance overflowed")
        # a step that turns the tangent by more than ~25°, lands far or does not converge is
        # retaken at half the length (a narrow resonance's sharp turn)
        if not (finite and t_new @ t >= 0.9 and np.linalg.norm(y_new - y) <= 2 * h
                and np.max(np.abs(fam.residual(y_new[:-1], y_new[-1])))
                <= 1e-9 * (1 + np.max(np.abs(y_new)))) \
                and not (self.take_at_floor and h <= self.floor):
            return self._retake()
        self.previous, self.fold = (y, t, h), bool(t_new[-1] * t[-1] < 0)
        self.y, self.t, self.h = y_new, t_new, self.grow(y_new, h)
        return True

    def _retake(self) -> bool:
        self.h /= 2
        self.stuck = not self.take_at_floor and self.h < self.floor
        return False


def _continue(sysm: PolynomialBalance, end_solutions, omega_start: float,
              omega_stop: float, step: float, estimate: float, seconds: float,
              per_point: float, max_points: int, where: str) -> Continuation:
    """The pseudo-arclength loop of :func:`analysis.systems.continue_balance` on any balance
    with ``residual``, ``jacobian`` and ``d_omega`` in ``(x, ω)``: from each of
    ``end_solutions()`` (``(ω, x, direction)``: at the two ends, the first at
    ``omega_start``, or a point inside the range taken both ways; and whether they are
    complete) not reached yet, until ω leaves the range
    or the piece closes on its start (an isola); the step halves where a step turns or fails
    (:data:`MIN_STEP`); ``estimate`` points of ``per_point`` seconds, ``seconds`` in all,
    bound its points (twice the larger of ``seconds`` and :data:`CONTINUATION_SECONDS` in
    points, at most ``max_points``) and its corrector steps, retaken ones included
    (:data:`RETAKES` per point) — never the clock, so that a run gives the same curve on a busy
    machine as on a quiet one."""
    lo, hi = sorted((omega_start, omega_stop))
    limit = min(max_points, int(2 * max(seconds, CONTINUATION_SECONDS) / per_point))
    attempts, max_attempts = 0, RETAKES * limit
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
                path = Arclength(sysm, y, _oriented(sysm, y, direction), step,
                                 step * MIN_STEP, lambda _, h: min(step, 1.5 * h), True)
                starts.append(len(points))
                points.append(y)
                y_start, away = y, False
                while path.previous is None or lo <= y[-1] <= hi:
                    # a closed curve (an isola) ends where it meets its start again
                    gap = np.linalg.norm(y - y_start)
                    away = away or gap > 3 * step
                    if away and gap < 1.5 * step:
                        points.append(y_start)
                        break
                    if len(points) - len(starts) >= limit:
                        raise InputError(f"{where}: the continuation did not leave ω in "
                                         f"[{lo:.3g}, {hi:.3g}] within {limit} steps of "
                                         f"{step:g} (the estimate was {estimate:.0f}); the "
                                         "curve is longer than it looks")
                    attempts += 1
                    if attempts > max_attempts:
                        raise InputError(f"{where}: the continuation gave up after "
                                         f"{max_attempts} corrector steps at ω = {y[-1]:.6g}, "
                                         f"{len(points)} points in (its estimate: "
                                         f"{estimate:.0f}): the corrector does not converge "
                                         "there")
                    if not path.attempt():
                        continue
                    if path.fold:
                        folds.append(_refine_fold(sysm, *path.previous))
                    y = path.y
                    points.append(y)
                if lo <= y[-1] <= hi:  # closed: the same start taken the other way is done
                    for j, e in enumerate(ends):
                        if e[0] == omega0 and np.array_equal(e[1], x0):
                            visited[j] = True
                    continue
                # the end it left by: the nearest solution there is reached
                edge = lo if y[-1] < lo else hi
                y_old = path.previous[0]
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


def _extended_jacobian(sysm: PolynomialBalance, y: np.ndarray) -> np.ndarray:
    x, omega = y[:-1], y[-1]
    return np.column_stack([sysm.jacobian(x, omega), sysm.d_omega(x, omega)])


def _tangent(sysm: PolynomialBalance, y: np.ndarray, previous: np.ndarray | None) -> np.ndarray:
    """Unit null vector of ``[R_x | R_ω]``, oriented along ``previous``."""
    _, _, vt = np.linalg.svd(_extended_jacobian(sysm, y))
    t = vt[-1]
    if previous is not None and t @ previous < 0:
        t = -t
    return t


def _oriented(fam: object, y: np.ndarray, direction: float) -> np.ndarray:
    """The first tangent of a path from ``y``: its parameter component along ``direction``
    (``+1`` increasing, ``−1`` decreasing; left as it comes where it is 0)."""
    t = _tangent(fam, y, None)
    return -t if t[-1] * direction < 0 else t


def _corrector(sysm: PolynomialBalance, y: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Newton on ``R(y) = 0`` with ``t·(y − y_pred) = 0`` (:func:`numerics.newton.bordered`,
    30 steps): the point it reached; NaN where a step overflowed; ``LinAlgError`` where the
    bordered Jacobian is singular."""
    def evaluate(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return sysm.residual(z[:-1], z[-1]), _extended_jacobian(sysm, z)

    run = bordered(evaluate, t, y, 1e-13, 30)
    if run.why == "singular":
        raise np.linalg.LinAlgError("Singular matrix")
    if run.why == "not finite":
        return np.full_like(run.x, np.nan)
    return run.x


def _refine_fold(sysm: PolynomialBalance, y: np.ndarray, t: np.ndarray, step: float) -> float:
    """The ω of :func:`fold_point`."""
    return float(fold_point(sysm, y, t, step)[-1])


def fold_point(sysm: PolynomialBalance, y: np.ndarray, t: np.ndarray, step: float
               ) -> np.ndarray:
    """The fold ``(x, ω)`` near the continuation point ``y`` along its tangent ``t``: secant on
    the step length for ``t_ω = 0`` (:func:`numerics.newton.secant`, each iterate corrected
    onto the curve), from ``0`` and ``step``."""
    return _secant_turn(sysm, y, t, step, t[-1], y)


def _secant_turn(fam: object, y: np.ndarray, t: np.ndarray, step: float, f0: float,
                 z: np.ndarray | None) -> np.ndarray | None:
    """The point where the tangent's last component vanishes along ``y + h t``: the secant on
    ``h`` from ``0`` (where it is ``f0``) and ``step`` (40 steps, until ``|t_last| ≤ 1e-13``),
    each iterate corrected onto the curve; the last one corrected, ``z`` where there is none
    (the secant's two values equal at once)."""
    last = [z]

    def t_last(h: float) -> float:
        last[0] = _corrector(fam, y + h * t, t)
        return _tangent(fam, last[0], t)[-1]

    f1 = _tangent(fam, _corrector(fam, y + step * t, t), t)[-1]
    secant(t_last, 0.0, step, f0, f1, ftol=1e-13, max_iter=40)
    return last[0]


CONTINUATION_HARMONICS = 8
# NOTE: the continuation that seeds the orbits carries at most 8 harmonics (2 ms a point; its
# crossings are then polished at the harmonics asked): a seed, not an answer.
DRIVE_RETAKES = 2
# NOTE: corrector steps per allowed point, halved ones included (a curve takes ~1.2–1.6).


def _crossings(w: np.ndarray, x: np.ndarray) -> list[np.ndarray]:
    """Where one piece of the continued curve meets ``w = 0`` (``w``: its ω minus the drive's),
    interpolated (see :func:`drive_crossings`)."""
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


# --- a user's driven oscillator: every orbit at one ω, from a continuation in the drive -------

class DriveFamily:
    """A :class:`driven.PolynomialBalance` at fixed ω as a family in the drive amplitude f:
    the interface :class:`Arclength` follows, with f in ω's place."""

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


DRIVE_STEP, DRIVE_GROWTH = 1 / 25, 2.0


def continue_in_drive(system: PolynomialBalance, omega: float, bound: float | None,
                      max_points: int = MAX_DRIVE_POINTS) -> DriveContinuation:
    """Trace the balance from ``f = 0``, ``x = 0`` by pseudo-arclength in ``(x, f)`` until the
    first harmonic exceeds ``bound`` (:func:`driven.amplitude_bound`; then every orbit at the
    drive lies on the traced part, up to isolated branches the curve does not pass) or after
    ``max_points`` points (:data:`DRIVE_RETAKES` corrector steps each, halved ones included).
    The step adapts (:class:`Arclength`): halved where the corrector fails or the tangent
    turns by more than ~25° (down to 1e-9 of the curve's scale), doubled where it does not,
    up to :data:`DRIVE_STEP` of the scale (of the point's size far out) and, near ``±f``,
    to twice the distance from it (down to 1e-3 of the scale)."""
    fam = DriveFamily(system, omega)
    m = system.size
    k1 = int(np.nonzero(system.orders == 1)[0][0])
    sin1 = system.n_cos + int(np.nonzero(system.orders[system.orders > 0] == 1)[0][0])
    scale = abs(system.force) + (bound if bound is not None else 10.0)
    h_max, h_floor, h_min = scale * DRIVE_STEP, scale * 1e-3, scale * 1e-9
    y = np.zeros(m + 1)
    attempts = 0

    def grow(y: np.ndarray, h: float) -> float:
        # near ±f the steps shrink with the distance to it, so that a fold of the curve
        # just beyond ±f (two crossings close together) leaves points on both sides
        near = min(abs(y[-1] - system.force), abs(y[-1] + system.force))
        # far out (the drive or the higher harmonics grown past the scale) the steps grow
        # with the distance from rest: a crossing of ±f lies only where near is small
        reach = max(h_max, DRIVE_STEP * float(np.max(np.abs(y))))
        return min(DRIVE_GROWTH * h, reach, max(h_floor, 2.0 * near))

    with np.errstate(over="ignore", invalid="ignore"):
        t = _oriented(fam, y, 1.0)
        if abs(t[-1]) < 1e-8:  # ω at a linear resonance, undamped: q = 0 is degenerate
            t = _first_direction(fam, y, h_max / 4, k1, sin1)
        path = Arclength(fam, y, t, h_max / 4, h_min, grow)
        points = [y]
        while True:
            y = path.y
            r = system.first_harmonic(y[:-1])
            if bound is not None and r > bound:
                return _drive_curve(points, True, f"continued in the drive amplitude from 0 "
                                    f"up to the amplitude bound r = {bound:.4g}")
            if len(points) >= max_points or attempts >= DRIVE_RETAKES * max_points:
                return _drive_curve(points, False, f"the continuation in the drive stopped at "
                                    f"r = {r:.4g} after {len(points)} points ({attempts} "
                                    "steps)" + ("" if bound is None else
                                                f" (bound {bound:.4g})"))
            attempts += 1
            if path.attempt():
                points.append(path.y)
            elif path.stuck:
                return _drive_curve(points, False, f"the continuation in the drive failed "
                                    f"at r = {r:.4g}, f = {y[-1]:.4g} (no step converges)")


def _first_direction(fam: DriveFamily, y: np.ndarray, h: float, k1: int,
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


def _half_period(system: PolynomialBalance, x: np.ndarray) -> np.ndarray:
    """``q(t + T/2)``: harmonic k times ``(−1)^k``; it answers ``−f cos ωt`` where ``q`` answers
    ``f cos ωt`` (the force is autonomous)."""
    sign = (-1.0) ** np.concatenate([system.orders, system.orders[system.orders > 0]])
    return np.tile(sign, system.coordinates) * x


def balance_crossings(coarse: PolynomialBalance, omega: float, force: float,
                      bound: float | None, max_points: int = MAX_DRIVE_POINTS
                      ) -> tuple[list[np.ndarray], DriveContinuation]:
    """The seeds of every solution of ``coarse`` at ``omega`` and drive amplitude ``force``
    that the continuation in the drive from rest reaches (:func:`continue_in_drive`, up to the
    first-harmonic ``bound``, at most ``max_points``): where the traced curve crosses
    ``force`` — and ``−force``, shifted by half a period (:func:`_half_period`) —, quadratic
    around the folds (:func:`_crossings`); with the traced curve (its ``complete`` and ``note``)."""
    curve = continue_in_drive(coarse, omega, bound, max_points)
    seeds = _crossings(curve.force - force, curve.x)
    seeds += [_half_period(coarse, x) for x in _crossings(curve.force + force, curve.x)]
    return seeds, curve


def drive_crossings(de: DrivenEquation, harmonics: int
                    ) -> tuple[PolynomialBalance, list[np.ndarray], DriveContinuation]:
    """:func:`balance_crossings` of a user's equation at its ω: the balance with at most
    CONTINUATION_HARMONICS harmonics, up to its amplitude bound; with that balance."""
    coarse = PolynomialBalance(de.terms, de.force, min(harmonics, CONTINUATION_HARMONICS),
                               de.odd)
    seeds, curve = balance_crossings(coarse, de.omega, de.force,
                                     amplitude_bound(de.terms, de.omega, abs(de.force)))
    return coarse, seeds, curve
