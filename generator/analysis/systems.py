"""A driven, damped system of coupled oscillators ``ẍ_i + g_i(x, ẋ) = d_i f cos ωt``: every
branch of its periodic response by the one balance (:class:`polynomial.PolynomialBalance` of
every coordinate) continued in ω, sought from rest by the drive continuation up to the
power-balance bound and from the free system's backbones; Floquet multipliers from the
variational monodromy; folds, sweep jumps, points shot as true orbits."""

from __future__ import annotations

import math
from dataclasses import dataclass
from dataclasses import replace as _replace

import numpy as np
import sympy as sp

from ..derive.system import System
from ..errors import InputError
from ..numerics.integrate import PolynomialField
from ..numerics.shooting import PeriodicOrbit, settle_system, shoot_system
from .attractors import Dynamics, dynamics, dynamics_seconds, orbit_multipliers
from .continuation import (
    CONTINUATION_HARMONICS,
    CONTINUATION_SECONDS,
    MAX_DRIVE_POINTS,
    MAX_POINTS,
    Continuation,
    _continue,
    _tangent,
    balance_crossings,
    fold_point,
)
from .polynomial import PolynomialBalance, check_harmonics
from .response import equation_point_seconds, polished

SYSTEM_PROBES = 6
# NOTE: interior frequencies, besides each linear ω0 in the range, where the drive is continued
# from rest to look for branches the continuation from the two ends does not pass (isolas).
SYSTEM_CHECKS = 12
# NOTE: stretches of the traced curve (stable or unstable) whose middle points are shot as true
# orbits (DOP853, ~0.1–0.5 s each): the longest of every branch, then the longest of the rest.
NO_BOUND_FACTOR = 10.0
NO_BOUND_POINTS = 600
# NOTE: without the power-balance bound (no potential, nonlinear damping) the drive is continued
# from rest up to 10 × the linear response's size, 600 points at most per frequency (~3.5 s at
# N = 8 on a 2-DOF system; unbounded, it ran 15 s at each of the ten frequencies: two minutes;
# 130–300 points reach the cap on the suite's systems); the result says it may be incomplete.
# Points, not seconds: the same command finds the same orbits on a busy machine.
DRIVE_POINTS_TYPICAL = 500
# NOTE: the points a drive continuation up to the power-balance bound is estimated at (150–550
# measured on the documented systems; 3300 at half the lowest ω0 of a hardening system winding
# through its superharmonic resonances; at most continuation.MAX_DRIVE_POINTS).
NEUTRAL = 1 + 1e-8
# NOTE: a point is stable when every Floquet |λ| < 1 + 1e-8: a neutral direction (an undamped
# coordinate the drive leaves at rest, |λ| = 1 to rounding) counts as stable, not unstable.
SCAN_HARMONICS = 3
SCAN_STEP = 0.01
# NOTE: the balance that scans along each backbone for branches off the traced curve (a Newton
# solve ~1 ms on a 2-DOF system); a hit is polished at the harmonics asked.


@dataclass(frozen=True)
class BranchCheck:
    """A point of the traced curve shot as the true orbit: the balance's and the shot orbit's
    first-harmonic amplitude of each coordinate, the largest difference of any harmonic
    coefficient, the shot orbit's Floquet multipliers and both stability verdicts."""

    omega: float
    piece: int
    balance: tuple[float, ...]
    shot: tuple[float, ...]
    error: float  # NaN where shooting failed
    multipliers: tuple[complex, ...]  # the shot monodromy's eigenvalues, by modulus
    stable: bool | None  # the shot orbit's verdict (None: not shot)
    balance_stable: bool
    note: str = ""


@dataclass(frozen=True)
class SweepJump:
    """Where a slow sweep leaves a stable stretch and where it lands, both at the fold's ω:
    leaving, the fold point of the balance (polished: ``t_ω = 0``); landing, Newton on the
    other stable stretch at exactly that ω from its nearest point; checked by DOP853 from the
    fold state pushed towards the unstable side."""

    way: str  # up | down
    omega: float  # the fold's ω (where the stretch loses stability, when not at a fold)
    at_fold: bool
    leaving: tuple[float, ...]  # each coordinate's first-harmonic amplitude
    landing: tuple[float, ...]
    landing_converged: bool  # Newton at ω converged (else: the nearest point's amplitudes)
    landing_multiplier: float  # its largest Floquet |λ|
    simulated: tuple[float, ...]  # where DOP853 from the fold state settles (NaN: failed)
    difference: float  # max |simulated − landing| over the coordinates
    before: int  # the curve's points nearest the fold and the landing
    after: int


@dataclass(frozen=True)
class SystemResponse:
    """``response SYSTEM``: the balance of a driven, damped system traced over ω, every point
    with its Floquet multipliers (the monodromy of the variational equation about it), the
    folds, the jumps of slow sweeps, points shot as true orbits, and how the search for
    branches was made (``note``)."""

    system: System
    harmonics: int
    omega_range: tuple[float, float]
    linear_frequencies: tuple[float, ...]
    cont: Continuation
    closed: tuple[bool, ...]  # per piece: an isola (a closed curve inside the range)
    amplitudes: np.ndarray  # (points, n): each coordinate's first-harmonic amplitude
    multiplier: np.ndarray  # (points,): the largest |λ|
    stable: np.ndarray  # (points,) bool
    jumps: tuple[tuple[str, float, int, int], ...]  # (up | down, ω, point before, point after)
    checks: tuple[BranchCheck, ...]
    bound: float | None  # r1 ≤ bound/ω for every orbit
    complete: bool
    note: str
    sweep_jumps: tuple[SweepJump, ...] = ()  # the jumps, each at its fold's ω exactly
    dynamics: Dynamics | None = None  # bifurcations on the branches, attractors simulated


def driven_system(text: str, values: dict[str, str]) -> System:
    """The system of ``response SYSTEM``, refused in one line where it has no drive, no
    damping, or a linear mode that is not an oscillation."""
    from ..derive.system import parse_system

    system = parse_system(text, values, driven=True)
    if system.frequency is None:
        raise InputError(f"system {text!r}: no drive; write f*cos(w*t) on the right of an "
                         "equation (w is the frequency the response varies)")
    if system.damping is None and not any(f.has(*system.velocities) for f in system.force):
        raise InputError(f"system {text!r}: no damping (a velocity term): no steady state to "
                         "draw a response curve of (lindstedt nnm gives the free modes)")
    for k, lam in enumerate(system.modes(), 1):
        if not sp.N(lam, 30) > 0:
            raise InputError(f"system {text!r}: mode {k} has ω0² = {lam}: no oscillation "
                             "about the origin (every ω0² must be > 0)")
    return system


def _on_curve(cont: Continuation, omega: float, x: np.ndarray) -> bool:
    """Whether the solution ``x`` at ``omega`` lies on a traced piece (within 1 % of its size,
    the curve interpolated between its points)."""
    for piece in cont.piece_slices():
        w, X = cont.omega[piece], cont.x[piece]
        for i in np.nonzero((w[:-1] - omega) * (w[1:] - omega) <= 0)[0]:
            s = 0.0 if w[i + 1] == w[i] else (omega - w[i]) / (w[i + 1] - w[i])
            if np.linalg.norm(X[i] + s * (X[i + 1] - X[i]) - x) \
                    <= 1e-2 * (1 + np.linalg.norm(x)):
                return True
    return False


def _clipped(cont: Continuation, lo: float, hi: float, fine: PolynomialBalance
             ) -> Continuation:
    """The pieces with the last point that left ``[lo, hi]`` moved back onto the edge it
    crossed (linear between it and the point before, then Newton there; left as it was where
    Newton does not converge)."""
    omega, x = cont.omega.copy(), cont.x.copy()
    for piece in cont.piece_slices():
        k = piece.stop - 1
        if k > piece.start and not lo <= omega[k] <= hi:
            edge = lo if omega[k] < lo else hi
            t = (edge - omega[k - 1]) / (omega[k] - omega[k - 1])
            try:
                z, converged, _ = fine.solve(x[k - 1] + t * (x[k] - x[k - 1]), edge)
            except np.linalg.LinAlgError:
                converged = False
            if converged:
                x[k], omega[k] = z, edge
    return Continuation(omega, x, cont.folds, cont.pieces, cont.complete)


def _merged(a: Continuation | None, b: Continuation) -> Continuation:
    if a is None:
        return b
    return Continuation(np.concatenate([a.omega, b.omega]), np.vstack([a.x, b.x]),
                        sorted(a.folds + b.folds),
                        a.pieces + tuple(len(a.omega) + p for p in b.pieces),
                        a.complete and b.complete)


def _runs(flags: np.ndarray, piece: slice) -> list[tuple[int, int]]:
    """The maximal runs ``[i, j)`` of equal ``flags`` within a piece."""
    out, start = [], piece.start
    for i in range(piece.start + 1, piece.stop + 1):
        if i == piece.stop or flags[i] != flags[start]:
            out.append((start, i))
            start = i
    return out


def _jumps(cont: Continuation, r: np.ndarray, stable: np.ndarray, lo: float, hi: float
           ) -> tuple[tuple[str, float, int, int], ...]:
    """Where a slow sweep up (from ``lo``) and down (from ``hi``) leaves a stable stretch that
    ends inside the range (a fold or a loss of stability) and lands on the stable stretch at
    that ω nearest in state (its basin is not computed): ``(way, ω, point before, point
    after)``, the points' indices."""
    stretches = []  # (ω low, ω high, points) of each stable stretch, ω monotone along it
    for piece in cont.piece_slices():
        for i, j in _runs(stable, piece):
            if stable[i] and j - i >= 2:
                stretches.append((i, j))
    out = []
    for way, start, sign in (("up", lo, 1.0), ("down", hi, -1.0)):
        here = [k for k, (i, j) in enumerate(stretches)
                if min(cont.omega[i:j]) <= start + 1e-9 * abs(start)
                and max(cont.omega[i:j]) >= start - 1e-9 * abs(start)]
        if not here:
            continue
        k = min(here, key=lambda k: np.min(r[stretches[k][0]:stretches[k][1]]))
        for _ in range(10):
            i, j = stretches[k]
            w = cont.omega[i:j]
            end = int(np.argmax(sign * w)) + i
            w_end = cont.omega[end]
            if sign * w_end >= sign * (hi if sign > 0 else lo) - 1e-9:
                break
            ahead = [(m, (a, b)) for m, (a, b) in enumerate(stretches) if m != k
                     and min(cont.omega[a:b]) <= w_end <= max(cont.omega[a:b])
                     and sign * max(sign * cont.omega[a:b]) > sign * w_end]
            if not ahead:
                break
            m, (a, b) = min(ahead, key=lambda e: np.min(np.linalg.norm(
                cont.x[e[1][0]:e[1][1]] - cont.x[end], axis=1)
                + 1e3 * np.abs(cont.omega[e[1][0]:e[1][1]] - w_end)))
            land = a + int(np.argmin(np.abs(cont.omega[a:b] - w_end)))
            out.append((way, float(w_end), end, land))
            k = m
    return tuple(out)


JUMP_PUSH = 0.05
JUMP_PERIODS = 300
# NOTE: the check of a jump: DOP853 from the fold state pushed by 5 % of its size towards the
# unstable branch, over 300 drive periods.  At the fold's ω the state drifts off along the
# centre direction (~50–100 periods from a 3 % push on the suite's 2-DOF system; a 1 % push
# had not left after 200), then decays onto the landing orbit (|λ| ≈ 0.9 a period there: 1e-8
# after 150 periods); ~1 s of DOP853 a jump.


def _at_folds(sb: SystemBalance, cont: Continuation, stable: np.ndarray,
              jumps: tuple[tuple[str, float, int, int], ...]) -> tuple[SweepJump, ...]:
    """Each jump of :func:`_jumps` at its fold's ω exactly: the fold point polished from the
    last two stable points (:func:`continuation.fold_point`), where the curve's ω turns there;
    the landing solved by Newton at that ω from the landing stretch's nearest point; DOP853
    from the fold state pushed towards the unstable side (:data:`JUMP_PUSH`), where it
    settles after :data:`JUMP_PERIODS` periods.  A stretch that loses stability without a fold
    leaves from its last stable point, at its ω."""
    fine = sb.fine
    field = PolynomialField.of(sb.equations)
    out = []
    for way, w_end, end, land in jumps:
        piece = next(p for p in cont.piece_slices() if p.start <= end < p.stop)
        d = 1 if end - 1 >= piece.start and stable[end - 1] else -1  # along the stretch
        x, w = cont.x[end], float(w_end)
        # the curve's ω turns within two points of the stretch's end (the balance's fold and
        # the variational equation's |λ| = 1 may lie a point apart): polished from the point
        # before the turn
        turns = [i for i in range(end - 2 * d, end + 3 * d, d)
                 if piece.start <= i - 1 and i + 1 < piece.stop
                 and (cont.omega[i] - cont.omega[i - 1]) * (cont.omega[i + 1] - cont.omega[i])
                 < 0]
        at_fold = False
        if turns:
            i = min(turns, key=lambda i: abs(i - end))
            y0 = np.append(cont.x[i - d], cont.omega[i - d])
            y1 = np.append(cont.x[i], cont.omega[i])
            try:
                with np.errstate(over="ignore", invalid="ignore"):
                    z = fold_point(fine, y0, _tangent(fine, y0, y1 - y0),
                                   float(np.linalg.norm(y1 - y0)))
                at_fold = bool(np.all(np.isfinite(z))
                               and abs(z[-1] - cont.omega[i]) <= abs(cont.omega[i + d]
                                                                     - cont.omega[i - d])
                               and np.max(np.abs(fine.residual(z[:-1], z[-1])))
                               <= 1e-9 * (1 + np.max(np.abs(z))))
            except np.linalg.LinAlgError:
                at_fold = False
            if at_fold:
                x, w = z[:-1], float(z[-1])
        beyond = (i if at_fold else end) + d
        try:
            landed, converged, _ = fine.solve(cont.x[land], w)
        except np.linalg.LinAlgError:
            converged = False
        if not converged:
            landed = cont.x[land]
        multiplier = float(sb.multiplier(landed[None], np.array([w]))[0])
        push = cont.x[beyond] - x if piece.start <= beyond < piece.stop else x
        # (towards the unstable side, where the state drifts off at the fold's ω)
        push = JUMP_PUSH * np.linalg.norm(x) * push / (np.linalg.norm(push) or 1.0)
        simulated = settle_system(field, sb.drive, w, fine.state(x + push, w), JUMP_PERIODS)
        landing = fine.first_harmonics(landed)
        out.append(SweepJump(way, w, at_fold, tuple(float(a) for a in fine.first_harmonics(x)),
                             tuple(float(a) for a in landing), bool(converged), multiplier,
                             tuple(float(a) for a in simulated),
                             float(np.max(np.abs(simulated - landing))), end, land))
    return tuple(out)


@dataclass(frozen=True)
class SystemPlan:
    """What ``response SYSTEM`` will run, known before it runs: the system, the ω range, the
    linear frequencies, the continuation's estimated points, the drive continuations (how many,
    each's cap in points) and the whole estimated seconds."""

    system: System
    omega_range: tuple[float, float]
    linear_frequencies: tuple[float, ...]
    points: float
    seconds: float
    drives: int = 0
    drive_points: int = 0


SYSTEM_FIXED_SECONDS = 3.0
# NOTE: `response SYSTEM` besides its continuation and its drive continuations (estimated by
# their points): SymPy's parse and modes (~1 s), the Floquet pass
# (~0.1 ms a point) and the shots (0.1–0.5 s each); measured 3–8 s on the documented systems.


def system_plan(text: str, values: dict[str, str], harmonics: int,
                omega_min: float | None = None, omega_max: float | None = None) -> SystemPlan:
    """The :class:`SystemPlan` of :func:`system_response` (its refusals, in one line, first):
    the range defaults to half the lowest to 1.5 × the highest linear ω0; the curve's length
    ``(B − A) + π r √n`` over the step 0.02, r the power-balance bound at the lowest ω0 (10
    without one)."""
    check_harmonics(harmonics)
    system = driven_system(text, values)
    w0 = tuple(float(sp.N(sp.sqrt(lam), 20)) for lam in system.modes())
    lo = 0.5 * w0[0] if omega_min is None else omega_min
    hi = 1.5 * w0[-1] if omega_max is None else omega_max
    for flag, value in (("--omega A", lo), ("--omega B", hi)):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"{flag} = {value!r}: must be finite and > 0")
    if not lo < hi:
        raise InputError(f"--omega {lo:g}:{hi:g}: A must lie below B")
    bound, _ = system.response_bound()
    # NOTE: not capped: a strong drive's curve is long (KERSCHEN at f = 1000 ran 20 000 steps,
    # 85 s, before its continuation refused); the bound is loose (3× at f = 1, 10× at f = 10) but
    # grows as the curve does, so the refusal comes before the work
    r_scale = 10.0 if bound is None else bound / w0[0]
    points = ((hi - lo) + np.pi * r_scale * math.sqrt(len(w0))) / 0.02
    odd = PolynomialField.of(system.equations()).odd
    unknowns = system.size * (2 * harmonics if odd else 4 * harmonics - 1)
    # each drive continuation (the ends and the probes) at the coarse balance's size: its
    # typical length up to the bound, its cap without one
    coarse = min(harmonics, CONTINUATION_HARMONICS)
    drives = 2 + SYSTEM_PROBES + sum(lo < w < hi for w in w0)
    searches = drives * (DRIVE_POINTS_TYPICAL if bound is not None else NO_BOUND_POINTS) \
        * equation_point_seconds(system.size * (2 * coarse if odd else 4 * coarse - 1))
    # every point's multipliers, the crossings refined, the simulations (analysis.attractors)
    stability = dynamics_seconds(points, unknowns, system.size, lo, hi, w0[-1],
                                 equation_point_seconds(unknowns))
    return SystemPlan(system, (lo, hi), w0, points, SYSTEM_FIXED_SECONDS + searches
                      + points * equation_point_seconds(unknowns) + stability, drives,
                      MAX_DRIVE_POINTS if bound is not None else NO_BOUND_POINTS)


@dataclass(frozen=True)
class SystemBalance:
    """A driven system's balance, set up once: its force per equation, the drive (its largest
    amplitude ``f`` and each equation's share), the balance at ``harmonics`` and the coarse one
    that seeds it, the power-balance bound (or why there is none) and the linear ω0."""

    system: System
    equations: tuple[dict[tuple[int, ...], float], ...]
    drive: np.ndarray
    fine: PolynomialBalance
    coarse: PolynomialBalance
    bound: float | None
    why: str
    linear_frequencies: tuple[float, ...]
    backbones: tuple[tuple[np.ndarray, np.ndarray], ...] = ()  # per mode: ω(A), x(0) on a grid

    @staticmethod
    def of(system: System, harmonics: int) -> SystemBalance:
        equations = system.equations()
        drive = np.array([float(d) for d in system.drive])
        f = float(np.max(np.abs(drive)))
        shape = tuple(drive / f)
        odd = PolynomialField.of(equations).odd
        bound, why = system.response_bound()
        w0 = tuple(float(sp.N(sp.sqrt(lam), 20)) for lam in system.modes())
        return SystemBalance(
            system, equations, drive, PolynomialBalance(equations, f, harmonics, odd,
                                                        shape=shape),
            PolynomialBalance(equations, f, min(harmonics, CONTINUATION_HARMONICS), odd,
                              shape=shape), bound, why, w0, _backbones(system, bound, w0))

    def solutions(self, omega: float) -> tuple[list[np.ndarray], bool, str]:
        """Every balance solution at ``omega`` the continuation in the drive amplitude from
        rest reaches up to the bound (:func:`continuation.balance_crossings`), and those Newton
        reaches from the backbones there, polished at the fine harmonics; whether the drive
        continuation passed the bound (without one it stops at :data:`NO_BOUND_FACTOR` × the
        linear response, within :data:`NO_BOUND_POINTS`, and says it may be incomplete), and
        its note."""
        if self.bound is not None:
            seeds, curve = balance_crossings(self.coarse, omega, self.fine.force,
                                             1.01 * self.bound / omega)
            whole, note = curve.complete, curve.note
        else:
            cap = NO_BOUND_FACTOR * self.linear_response(omega)
            seeds, curve = balance_crossings(self.coarse, omega, self.fine.force, cap,
                                             NO_BOUND_POINTS)
            whole, note = False, (f"no bound: the drive continued from rest up to r = {cap:.4g}"
                                  f", {NO_BOUND_FACTOR:g} × the linear response"
                                  if curve.complete else curve.note)
        found, complete = polished(self.coarse, seeds, whole, self.fine, omega)
        more, _ = polished(self.fine, self.backbone_seeds(omega), True, self.fine, omega)
        found += [x for x in more if all(np.linalg.norm(y - x) > 1e-6 * (1 + np.linalg.norm(x))
                                         for y in found)]
        found.sort(key=self.fine.first_harmonic)
        return found, complete, note

    def linear_response(self, omega: float) -> float:
        """``|(K − ω² + iωC)⁻¹ d f|``: the linear system's first harmonic at ``omega`` (at least
        ``|d f|``, so that an undamped resonance gives a finite scale)."""
        system = self.system
        K = np.array(system.stiffness, dtype=float)
        C = np.zeros_like(K) if system.damping is None else np.array(system.damping,
                                                                     dtype=float)
        F = self.drive
        try:
            X = np.linalg.solve(K - omega**2 * np.eye(len(F)) + 1j * omega * C, F)
        except np.linalg.LinAlgError:
            return float(np.linalg.norm(F)) * 1e3
        return float(max(np.linalg.norm(X), np.linalg.norm(F)))

    def backbone_seeds(self, omega: float, balance: PolynomialBalance | None = None
                       ) -> list[np.ndarray]:
        """Where a backbone (the free system's nonlinear normal mode, its series) passes
        ``omega``: the mode's shape at that amplitude, in quadrature with the drive (``±`` its
        ``x(0)`` on ``sin ωt``: the phase of a damped resonance), as unknowns of ``balance``
        (the fine one by default)."""
        fine = self.fine if balance is None else balance
        m = len(fine.k2)
        s1 = fine.n_cos + int(np.nonzero(fine.orders[fine.orders > 0] == 1)[0][0])
        out = []
        for om, starts in self.backbones:
            for i in np.nonzero((om[:-1] - omega) * (om[1:] - omega) <= 0)[0]:
                t = 0.0 if om[i + 1] == om[i] else (omega - om[i]) / (om[i + 1] - om[i])
                shape = starts[:, i] + t * (starts[:, i + 1] - starts[:, i])
                for sign in (1.0, -1.0):
                    x = np.zeros(fine.size)
                    x[np.arange(fine.coordinates) * m + s1] = sign * shape
                    out.append(x)
        return out

    def multiplier(self, X: np.ndarray, omega: np.ndarray) -> np.ndarray:
        """The largest Floquet ``|λ|`` of each balance solution ``X[k]`` at ``omega[k]``: the
        monodromy of its variational equation (:func:`numerics.floquet.
        variational_multipliers`), the samples per period growing with ω0/ω."""
        lam = orbit_multipliers(self.fine, X, omega, self.linear_frequencies[-1])
        return np.max(np.abs(lam), axis=1)


BACKBONE_ORDER = 6
# NOTE: the order of the free system's normal-mode series whose backbones seed the balance
# (0.01–0.1 s a mode): a seed, polished by Newton, not an answer.
BACKBONE_POINTS = 400


def _backbones(system: System, bound: float | None, w0: tuple[float, ...]
               ) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    """Each mode's backbone ω(A) and its x(0) on a grid of amplitudes up to the power-balance
    bound at that mode's ω0 (10 without one), from the series of the free system (damping and
    drive removed), the first-order backbone beyond where ω(A) stops being monotone; none
    where the free system has a velocity-dependent force, and none for a mode in internal
    resonance (the series is refused)."""
    from ..derive.nnm import normal_mode

    if any(f.has(*system.velocities) for f in system.force):
        return ()
    free = _replace(system, damping=None, drive=(), frequency=None)
    out = []
    for k in range(1, system.size + 1):
        for a in range(system.size):
            try:
                mode = normal_mode(free, k, BACKBONE_ORDER, a)
                first = normal_mode(free, k, 1, a)
            except InputError:  # x_a does not move in this mode, or an internal resonance
                continue
            top = 10.0 if bound is None else 1.2 * bound / w0[k - 1]
            grid = np.linspace(0.0, top, BACKBONE_POINTS)
            with np.errstate(over="ignore", invalid="ignore"):
                omega, _, starts = mode.evaluate(grid)
                omega1, _, starts1 = first.evaluate(grid)
            # the series is kept up to where ω(A) stops being monotone or finite (past its
            # radius, or near an internal resonance, the partial sums swing), the first-order
            # backbone beyond: a seed there, not an answer
            step = np.sign(np.diff(omega))
            bad = np.nonzero((step != step[0]) | ~np.isfinite(omega[1:])
                             | ~np.all(np.isfinite(starts[:, 1:]), axis=0))[0]
            keep = len(omega) if not len(bad) else int(bad[0]) + 1
            out.append((np.concatenate([omega[:keep], omega1[keep:]]),
                        np.hstack([starts[:, :keep], starts1[:, keep:]])))
            break
    return tuple(out)


def system_response(text: str, values: dict[str, str], harmonics: int = 6,
                    omega_min: float | None = None, omega_max: float | None = None,
                    max_seconds: float = CONTINUATION_SECONDS, checks: int = SYSTEM_CHECKS
                    ) -> SystemResponse:
    """Every branch of the periodic response of ``ẍ_i + g_i(x, ẋ) = d_i f cos ωt`` over
    ``[omega_min, omega_max]`` (default: half the lowest to 1.5 × the highest linear ω0).

    The balance (:class:`PolynomialBalance` with ``harmonics``) is solved at both ends by the
    continuation in the drive amplitude from rest up to the power-balance bound on the
    amplitude (:meth:`System.response_bound`: every orbit lies below it), traced in ω through
    its folds from each solution there; then at interior probes (each linear ω0 and
    :data:`SYSTEM_PROBES` more) the drive continuation again, and any solution off the traced
    curve is traced too (an isola).  Each point's Floquet multipliers come from the monodromy
    of its variational equation (:func:`numerics.floquet.variational_multipliers`); the middle
    of the longest stable and unstable stretches is shot as the true orbit (DOP853) and
    compared."""
    plan = system_plan(text, values, harmonics, omega_min, omega_max)
    system, (lo, hi), w0 = plan.system, plan.omega_range, plan.linear_frequencies
    sb = SystemBalance.of(system, harmonics)
    fine, bound, why, solutions = sb.fine, sb.bound, sb.why, sb.solutions
    where = f"system {text!r}"
    notes: list[str] = []
    complete = bound is not None

    def ends() -> tuple[list[tuple[float, np.ndarray, float]], bool]:
        nonlocal complete
        out = []
        for w, direction in ((lo, 1.0), (hi, -1.0)):
            found, whole, note = solutions(w)
            complete = complete and whole
            notes.append(f"w = {w:.4g} ({len(found)} solution{'s' * (len(found) != 1)})"
                         + ("" if whole else f" [{note}]"))
            out.extend((w, x, direction) for x in found)
        if not out or out[0][0] != lo:
            raise np.linalg.LinAlgError(f"no balance converged at ω = {lo:.4g}")
        return out, True

    estimate, per_point = plan.points, equation_point_seconds(fine.size)
    cont = _continue(fine, ends, lo, hi, 0.02, estimate, max_seconds, per_point, MAX_POINTS,
                     where)
    probes = sorted({*(w for w in w0 if lo < w < hi),
                     *np.linspace(lo, hi, SYSTEM_PROBES + 2)[1:-1]})
    closed = [False] * len(cont.pieces)
    isolas = 0

    def trace(w: float, x: np.ndarray) -> None:
        """A solution off the traced curve: its branch traced both ways and added."""
        nonlocal cont, isolas
        start = [(w, x, 1.0), (w, x, -1.0)]
        extra = _continue(fine, lambda: (start, True), lo, hi, 0.02, estimate, max_seconds,
                          per_point, MAX_POINTS, where)
        isolas += 1
        for piece in extra.piece_slices():
            closed.append(bool(lo < extra.omega[piece.stop - 1] < hi))
        cont = _merged(cont, extra)

    for w in probes:
        found, whole, _ = solutions(float(w))
        complete = complete and whole
        for x in found:
            if not _on_curve(cont, float(w), x):
                trace(float(w), x)
    # between the probes: Newton at a few harmonics from each backbone wherever it crosses ω
    # on a fine grid (an isola of a lightly damped system hugs its backbone)
    scan = PolynomialBalance(sb.equations, fine.force, min(harmonics, SCAN_HARMONICS),
                             fine.odd, shape=tuple(sb.drive / fine.force))
    step = min(SCAN_STEP, (hi - lo) / 100)
    scanned = 0
    for w in np.arange(lo + step / 2, hi, step):
        for seed in sb.backbone_seeds(float(w), scan):
            scanned += 1
            try:
                x, converged, _ = scan.solve(seed, float(w), 1e-10, 15)
                if converged:
                    x, converged, _ = fine.solve(fine.refined(scan, x), float(w))
            except np.linalg.LinAlgError:
                continue
            if converged and not _on_curve(cont, float(w), x):
                trace(float(w), x)
    seeded = (f"; Newton started from {len(sb.backbones)} backbone(s) (the free system's "
              f"normal modes, series to order {BACKBONE_ORDER}) at the probes and every "
              f"{step:.3g} in w between them ({scanned} seeds)"
              if sb.backbones else "; no backbone seeds (a velocity-dependent force)")
    probed = (f"{len(probes)} probes (w = {', '.join(f'{w:.4g}' for w in probes)}){seeded}: "
              f"{isolas} branch{'es' * (isolas != 1)} off the curve traced from the ends"
              + (", each traced" if isolas else "") + ". A branch reached neither from rest "
              "(in the drive, at the ends and probes) nor from a backbone is not excluded")
    cont = _clipped(cont, lo, hi, fine)
    # stability of every point: the monodromy of its variational equation
    lam = orbit_multipliers(fine, cont.x, cont.omega, w0[-1])
    multiplier = np.max(np.abs(lam), axis=1)
    stable = multiplier < NEUTRAL
    amplitudes = np.array([fine.first_harmonics(x) for x in cont.x])
    shots = _shot_checks(sb, cont, amplitudes, stable, checks)
    how = (f"every orbit has r1 <= {bound:.6g}/w ({why}); the drive was continued from rest "
           f"past that bound at {', '.join(notes)} and at "
           if bound is not None else
           f"no amplitude bound ({why}): the drive continuation from rest stopped at "
           f"{NO_BOUND_FACTOR:g} × the linear response or {NO_BOUND_POINTS} points at "
           f"{', '.join(notes)} and at ")
    jumps = _at_folds(sb, cont, stable, _jumps(cont, np.linalg.norm(amplitudes, axis=1),
                                               stable, lo, hi))
    return SystemResponse(system, harmonics, (lo, hi), w0, cont, tuple(closed), amplitudes,
                          multiplier, stable,
                          tuple((j.way, j.omega, j.before, j.after) for j in jumps),
                          shots, bound, complete and cont.complete, how + probed, jumps,
                          dynamics(fine, PolynomialField.of(sb.equations), sb.drive, cont, lam,
                                   lo, hi, w0[-1]))


def _shot_checks(sb: SystemBalance, cont: Continuation, amplitudes: np.ndarray,
                 stable: np.ndarray, checks: int) -> tuple[BranchCheck, ...]:
    """The middle point of the longest stretch (stable or unstable) of every branch, then of
    the longest of the rest up to ``checks`` in all, shot as the true orbit and compared
    harmonic by harmonic; by branch and ω."""
    fine = sb.fine
    field = PolynomialField.of(sb.equations)
    stretches = sorted(((j - i, k, i, j) for k, piece in enumerate(cont.piece_slices())
                        for i, j in _runs(stable, piece) if j - i >= 3), reverse=True)
    first: dict[int, tuple] = {}
    for item in stretches:
        first.setdefault(item[1], item)
    chosen = sorted(first.values(), reverse=True)
    chosen += [item for item in stretches if item not in chosen]
    shots = []
    for _, k, i, j in chosen[:max(checks, len(first))]:
        mid = (i + j) // 2
        x, w = cont.x[mid], float(cont.omega[mid])
        orbit = shoot_system(field, sb.drive, w, fine.state(x, w),
                             harmonics=2 * fine.harmonics - 1)
        balance = tuple(float(a) for a in amplitudes[mid])
        if not isinstance(orbit, PeriodicOrbit):
            shots.append(BranchCheck(w, k, balance, (), math.nan, (), None, bool(stable[mid]),
                                     orbit.reason))
            continue
        error = 0.0
        for c, (A, B) in enumerate(orbit.coordinates):
            a, b = fine.amplitudes(x, c)
            error = max(error, *(abs(A.get(h, 0.0) - a.get(h, 0.0)) for h in set(A) | set(a)),
                        *(abs(B.get(h, 0.0) - b.get(h, 0.0)) for h in set(B) | set(b)))
        shots.append(BranchCheck(
            w, k, balance, tuple(math.hypot(A.get(1, 0.0), B.get(1, 0.0))
                                 for A, B in orbit.coordinates), float(error),
            tuple(sorted((complex(m) for m in orbit.multipliers), key=abs)), orbit.stable,
            bool(stable[mid])))
    return tuple(sorted(shots, key=lambda c: (c.piece, c.omega)))
