"""The response of a driven, damped oscillator of n ≥ 1 coordinates ``ẍ_i + g_i(x, ẋ) =
d_i f cos ωt`` over the drive frequency: every branch by the one balance
(:class:`polynomial.PolynomialBalance` of every coordinate) continued in ω, sought at the ends
and interior probes (one equation: from every root of its one-harmonic balance; a system: by
the drive continuation from rest up to the power-balance bound and from the free system's
backbones); Floquet multipliers from the variational monodromy; folds, sweep jumps; a
system's points shot as true orbits, one equation's true folds and simulated sweeps (§10.4)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from dataclasses import replace as _replace

import numpy as np
import sympy as sp

from ..derive.system import System
from ..errors import InputError
from ..limits import MAX_DRIVE_POINTS
from ..numerics.integrate import (
    ForceTable,
    PolynomialField,
    Sweep,
    escape_bound,
    sweep_table,
)
from ..numerics.shooting import PeriodicOrbit, orbit_fold_table, settle_system, shoot_system
from .attractors import Dynamics, dynamics, dynamics_seconds, orbit_multipliers
from .continuation import (
    CONTINUATION_HARMONICS,
    CONTINUATION_SECONDS,
    MAX_POINTS,
    MAX_Q,
    Continuation,
    _continue,
    _tangent,
    balance_crossings,
    fold_point,
)
from .driven import Drive
from .polynomial import DrivenEquation, PolynomialBalance, check_harmonics
from .response import (
    ESCAPE_FACTOR,
    OneHarmonic,
    ResponseCurve,
    equation_continuation_seconds,
    equation_point_seconds,
    equation_solutions,
    given_range,
    linear_frequency,
    polished,
    response_equation,
    response_range,
)

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


CURVE_POINTS = 600
# NOTE: the frequencies one equation's one-harmonic curve is solved at for the figure (~0.1 ms
# each: a polynomial's roots).


@dataclass(frozen=True)
class ClosedForms:
    """What the notes' eq. 10.60 knows in closed form, data of its response: its parameters
    (``notes``: ε, f, Q as numbers), the potential's barrier ``1/√−ε`` (``inf`` hardening)
    and the escape bound past which nothing returns (:func:`numerics.integrate.escape_bound`)."""

    notes: tuple[tuple[str, float], ...]
    barrier: float
    escape: float


def notes_problem(eps: float, force: float, Q: float) -> tuple[DrivenEquation, ClosedForms]:
    """Eq. 10.60 ``q̈ + q̇/Q + q + εq³ = f cos ωt`` as the response's problem (the preset's
    equation, :attr:`driven.Drive.equation`) with its :class:`ClosedForms`; refused in one
    line without damping."""
    d = Drive(eps, force, 1.0, Q)
    if d.damping == 0:
        raise InputError("Q inf: a response curve needs damping (finite Q) for a steady state")
    barrier = 1 / math.sqrt(-eps) if eps < 0 else math.inf  # the potential's maxima
    return d.equation, ClosedForms((("eps", float(eps)), ("force", float(force)),
                                    ("Q", float(Q))), barrier, escape_bound(eps, force))


def driven_problem(text: str, values: dict[str, str], name: str = "oscillator"
                   ) -> DrivenEquation | System:
    """The response's problem of ``text`` (:func:`derive.problem.read_problem`): one equation
    lowered to its polynomial table (:func:`response.response_equation`), several to a
    :class:`derive.system.System` (:func:`driven_system`); each refused in one line where it
    has no drive, no damping or no oscillation about the origin."""
    from ..derive.problem import read_problem

    if read_problem(text).one_coordinate:
        return response_equation(text, values, name)
    return driven_system(text, values)


@dataclass(frozen=True)
class SystemBalance:
    """A driven problem's balance of n ≥ 1 coordinates, set up once: its force per equation,
    the drive (its largest amplitude ``f`` and each equation's share), the balance at
    ``harmonics`` and the coarse one that seeds it, the power-balance bound (or why there is
    none), the linear ω0 and the linear stiffness and damping (``K``, ``C``).  A system keeps
    its :class:`derive.system.System` (``system``) and its backbones; one equation its
    :class:`polynomial.DrivenEquation` (``equation``) and its one-harmonic balance
    (``one_harmonic``: every root of a polynomial, the fast seeds)."""

    equations: tuple[dict[tuple[int, ...], float], ...]
    drive: np.ndarray
    fine: PolynomialBalance
    coarse: PolynomialBalance
    bound: float | None
    why: str
    linear_frequencies: tuple[float, ...]
    stiffness: np.ndarray
    damping: np.ndarray
    system: System | None = None
    equation: DrivenEquation | None = None
    one_harmonic: OneHarmonic | None = None
    backbones: tuple[tuple[np.ndarray, np.ndarray], ...] = ()  # per mode: ω(A), x(0) on a grid

    @staticmethod
    def of(problem: System | DrivenEquation, harmonics: int) -> SystemBalance:
        """The balance of ``problem`` at ``harmonics``."""
        check_harmonics(harmonics)
        if isinstance(problem, DrivenEquation):
            return SystemBalance._of_equation(problem, harmonics)
        system = problem
        equations = system.equations()
        drive = np.array([float(d) for d in system.drive])
        f = float(np.max(np.abs(drive)))
        shape = tuple(drive / f)
        odd = PolynomialField.of(equations).odd
        bound, why = system.response_bound()
        w0 = tuple(float(sp.N(sp.sqrt(lam), 20)) for lam in system.modes())
        K = np.array(system.stiffness, dtype=float)
        C = np.zeros_like(K) if system.damping is None else np.array(system.damping,
                                                                     dtype=float)
        return SystemBalance(
            equations, drive, PolynomialBalance(equations, f, harmonics, odd, shape=shape),
            PolynomialBalance(equations, f, min(harmonics, CONTINUATION_HARMONICS), odd,
                              shape=shape), bound, why, w0, K, C, system=system,
            backbones=_backbones(system, bound, w0))

    @staticmethod
    def _of_equation(de: DrivenEquation, harmonics: int) -> SystemBalance:
        """One equation ``q̈ + g(q, q̇) = f cos ωt``: its power-balance bound where ``g`` is a
        potential's force plus ``c q̇`` (``ω r₁ ≤ |f|/c``, as :meth:`System.response_bound`
        for n = 1)."""
        terms = dict(de.terms)
        c = terms.get((0, 1), 0.0)
        if c <= 0:
            bound, why = None, "no damping" if c == 0 else "a negative damping"
        elif any(b for a, b in terms if (a, b) != (0, 1)):
            bound, why = None, "a nonlinear velocity term (the power balance needs linear damping)"
        else:
            bound, why = abs(de.force) / c, (f"power balance: |F| = {abs(de.force):.6g}, "
                                             f"c_min = {c:.6g}, the damping")
        return SystemBalance(
            (terms,), np.array([de.force]), PolynomialBalance(terms, de.force, harmonics, de.odd),
            PolynomialBalance(terms, de.force, min(harmonics, CONTINUATION_HARMONICS), de.odd),
            bound, why, (linear_frequency(terms),), np.array([[terms.get((1, 0), 0.0)]]),
            np.array([[c]]), equation=de, one_harmonic=OneHarmonic(terms, float(de.force)))

    @property
    def size(self) -> int:
        """The number of coordinates."""
        return len(self.equations)

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The coordinates' names (``q`` for one equation)."""
        if self.system is not None:
            return tuple(str(x) for x in self.system.coordinates)
        return ("q",)

    @property
    def where(self) -> str:
        """The problem named in one line, for a refusal."""
        return self.equation.where if self.equation is not None \
            else f"system {self.system.text!r}"

    def solutions(self, omega: float, probe: bool = False) -> tuple[list[np.ndarray], bool, str]:
        """Every balance solution at ``omega`` that the seeds reach, polished at the fine
        harmonics, by first-harmonic size; whether the search is complete, and its note.

        One equation: Newton from every root of the one-harmonic balance (:class:`OneHarmonic`:
        every root of a polynomial); where one does not converge, the solutions the
        continuation in the drive amplitude from rest crosses (:func:`response.
        equation_solutions`) — at a ``probe`` the unconverged root is skipped instead.  A
        system: the continuation in the drive amplitude from rest up to the bound
        (:func:`continuation.balance_crossings`) and Newton from the backbones; without a
        bound it stops at :data:`NO_BOUND_FACTOR` × the linear response, within
        :data:`NO_BOUND_POINTS`, and says it may be incomplete."""
        fine = self.fine
        if self.one_harmonic is not None:
            one, found = self.one_harmonic, []
            for r in one.amplitudes(omega):
                phi = one.phase(r, omega)
                x = fine.vector({1: r * math.cos(phi)}, {1: r * math.sin(phi)})
                x, converged, _ = fine.solve(x, omega)
                if not converged:
                    if probe:
                        continue
                    found, whole = equation_solutions(self.equation, fine, omega)
                    return found, whole, "" if whole else "the continuation in the drive " \
                        "amplitude did not finish"
                if all(np.linalg.norm(y - x) > 1e-6 * (1 + np.linalg.norm(x)) for y in found):
                    found.append(x)
            found.sort(key=fine.first_harmonic)
            return found, True, ""
        if self.bound is not None:
            seeds, curve = balance_crossings(self.coarse, omega, fine.force,
                                             1.01 * self.bound / omega)
            whole, note = curve.complete, curve.note
        else:
            cap = NO_BOUND_FACTOR * self.linear_response(omega)
            seeds, curve = balance_crossings(self.coarse, omega, fine.force, cap,
                                             NO_BOUND_POINTS)
            whole, note = False, (f"no bound: the drive continued from rest up to r = {cap:.4g}"
                                  f", {NO_BOUND_FACTOR:g} × the linear response"
                                  if curve.complete else curve.note)
        found, complete = polished(self.coarse, seeds, whole, fine, omega)
        more, _ = polished(fine, self.backbone_seeds(omega), True, fine, omega)
        found += [x for x in more if all(np.linalg.norm(y - x) > 1e-6 * (1 + np.linalg.norm(x))
                                         for y in found)]
        found.sort(key=fine.first_harmonic)
        return found, complete, note

    def linear_response(self, omega: float) -> float:
        """``|(K − ω² + iωC)⁻¹ d f|``: the linear system's first harmonic at ``omega`` (at least
        ``|d f|``, so that an undamped resonance gives a finite scale)."""
        F = self.drive
        try:
            X = np.linalg.solve(self.stiffness - omega**2 * np.eye(len(F))
                                + 1j * omega * self.damping, F)
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


@dataclass(frozen=True)
class ResponsePlan:
    """What :func:`response` will run, known before it runs: the ω range, the linear
    frequencies, the continuation's estimated points and seconds, the drive continuations
    (how many, each's cap in points) and the whole estimated seconds; one equation's
    one-harmonic folds in the range."""

    omega_range: tuple[float, float]
    linear_frequencies: tuple[float, ...]
    points: float
    continuation_seconds: float
    seconds: float
    drives: int = 0
    drive_points: int = 0
    one_harmonic_folds: tuple[float, ...] = ()


RESPONSE_FIXED_SECONDS = (3.0, 10.0)
# NOTE: `response` besides its continuation, its drive continuations (estimated by their
# points) and its stability, a system's and one equation's: SymPy's parse and modes (~1 s) and
# the shots (0.1–0.5 s each), measured 3–8 s on the documented systems; start-up with SymPy's
# parse twice (~2.5 s), the one-harmonic folds, the ends' Newton solves, each fold refined on
# the true orbit (~0.1–0.5 s each) and the two sweeps (0.1–1 s each; a force of degree 7 with
# velocity terms 2 s), bounded from measured 3–6 s.
RESPONSE_ENDS_SECONDS = 2 * 6.0
# NOTE: where a balance at an end of one equation's range does not converge from its
# one-harmonic root, its seeds come from the continuation in the drive amplitude, which stops
# itself after limits.MAX_DRIVE_POINTS points (12 s at most): counted only where the plan
# meets such an end.


def response_plan(problem: System | DrivenEquation, harmonics: int,
                  omega_min: float | None = None, omega_max: float | None = None,
                  ends: bool = False) -> ResponsePlan:
    """The :class:`ResponsePlan` of :func:`response` (its refusals, in one line, first).

    One equation: the range from half the lowest to 1.25 × the highest of ω0 and the
    one-harmonic folds (:func:`response.response_range`), the
    curve's length ``(B − A) + π r_max`` over the step 0.02, r_max the largest one-harmonic
    amplitude on the range, refused above :data:`continuation.MAX_POINTS`; with ``ends``, the
    ends where Newton from a one-harmonic root does not converge counted as drive
    continuations.  A system: half the lowest to 1.5 × the highest linear ω0, the length
    ``(B − A) + π r √n``, r the power-balance bound at the lowest ω0 (10 without one), the
    drive continuations at the ends and the probes."""
    check_harmonics(harmonics)
    if isinstance(problem, DrivenEquation):
        de = problem
        span = response_range(de.terms, de.force, omega_min, omega_max)
        (lo, hi), folds, w0 = span.omega_range, span.one_harmonic_folds, span.linear_frequency
        points, seconds = equation_continuation_seconds(de.terms, de.force, harmonics, de.odd,
                                                        lo, hi, where=de.where)
        unknowns = 2 * harmonics if de.odd else 4 * harmonics - 1
        stability = dynamics_seconds(points, unknowns, 1, lo, hi, w0,
                                     equation_point_seconds(unknowns))
        extra = 0.0
        if ends:
            one = OneHarmonic(dict(de.terms), float(de.force))
            fine = PolynomialBalance(de.terms, de.force, harmonics, de.odd)
            for w in (lo, hi):
                for r in one.amplitudes(w):
                    phi = one.phase(r, w)
                    x = fine.vector({1: r * math.cos(phi)}, {1: r * math.sin(phi)})
                    if not fine.solve(x, w)[1]:
                        extra += RESPONSE_ENDS_SECONDS / 2
                        break
        return ResponsePlan((lo, hi), (w0,), points, seconds,
                            RESPONSE_FIXED_SECONDS[1] + extra + seconds + stability,
                            one_harmonic_folds=tuple(folds))
    system = problem
    w0 = tuple(float(sp.N(sp.sqrt(lam), 20)) for lam in system.modes())
    lo, hi = given_range(0.5 * w0[0], 1.5 * w0[-1], omega_min, omega_max)
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
    seconds = points * equation_point_seconds(unknowns)
    return ResponsePlan((lo, hi), w0, points, seconds,
                        RESPONSE_FIXED_SECONDS[0] + searches + seconds + stability, drives,
                        MAX_DRIVE_POINTS if bound is not None else NO_BOUND_POINTS)


@dataclass(frozen=True)
class Response:
    """``lindstedt response``'s record for n ≥ 1 coordinates, computed once for the JSON,
    the table, the CSV and the figure: the balance of every coordinate traced over ω, every
    point with its Floquet multipliers (the monodromy of its variational equation), the
    folds, where slow sweeps jump, the bifurcations and attractors (``dynamics``) and how the
    branches were searched (``note``).

    Present where computed: a system's jumps checked by DOP853 at each fold (``sweep_jumps``)
    and points shot as true orbits (``checks``); one equation's one-harmonic folds and curve
    (its roots on :data:`CURVE_POINTS` frequencies), the simulated sweeps up and down
    (``sweeps``), the true orbit's folds
    (``true_folds``, by :func:`numerics.shooting.orbit_fold_table`) and ``barrier``, the
    ``|q|`` past which a sweep has left every steady state (the potential's maximum ``1/√−ε``
    of a softening eq. 10.60, else :data:`response.ESCAPE_FACTOR` × the largest balance
    solution); eq. 10.60's parameters (``notes``)."""

    balance: SystemBalance
    harmonics: int
    omega_range: tuple[float, float]
    linear_frequencies: tuple[float, ...]
    cont: Continuation
    closed: tuple[bool, ...]  # per piece: an isola (a closed curve inside the range)
    amplitudes: np.ndarray  # (points, n): each coordinate's first-harmonic amplitude
    multiplier: np.ndarray  # (points,): the largest |λ|
    stable: np.ndarray  # (points,) bool
    jumps: tuple[tuple[str, float, int, int], ...]  # (up | down, ω, point before, point after)
    complete: bool
    note: str
    dynamics: Dynamics | None = None  # bifurcations on the branches, attractors simulated
    checks: tuple[BranchCheck, ...] = ()
    sweep_jumps: tuple[SweepJump, ...] = ()  # the jumps, each at its fold's ω exactly
    one_harmonic_folds: tuple[float, ...] | None = None
    one_harmonic_curve: ResponseCurve | None = None  # on CURVE_POINTS frequencies
    sweeps: tuple[Sweep, Sweep] | None = None  # up, down
    true_folds: tuple[tuple[float, tuple[float, ...]], ...] | None = None  # (ω, sorted |μ|)
    barrier: float | None = None
    escape: float | None = None  # the sweeps' and the shooting's escape bound
    notes: tuple[tuple[str, float], ...] = ()

    @property
    def fine(self) -> PolynomialBalance:
        """The balance traced (its harmonics)."""
        return self.balance.fine

    @property
    def system(self) -> System | None:
        """A system's exact lowering (``None`` for one equation)."""
        return self.balance.system

    @property
    def equation(self) -> DrivenEquation | None:
        """One equation's lowering (``None`` for a system)."""
        return self.balance.equation

    @property
    def coordinates(self) -> tuple[str, ...]:
        """The coordinates' names."""
        return self.balance.coordinates

    @property
    def bound(self) -> float | None:
        """The power-balance bound: ``r1 ≤ bound/ω`` for every orbit."""
        return self.balance.bound


def _continued(sb: SystemBalance, starts, lo: float, hi: float, plan: ResponsePlan,
               max_seconds: float, step: float = 0.02, max_points: int = MAX_POINTS
               ) -> Continuation:
    """The balance traced in ω over ``[lo, hi]`` by pseudo-arclength through its folds from
    ``starts()`` (:func:`continuation._continue`), refused in one line where the damping is
    too light for double precision or the plan's seconds pass ``max_seconds``."""
    damping = float(np.max(np.abs(sb.damping)))
    if 0 < damping < 1 / MAX_Q:
        raise InputError(f"{sb.where}: the damping {damping:.0e}*q' makes the resonance "
                         f"{damping:.0e} wide in ω, too narrow for the continuation to follow "
                         f"in double precision; at least {1 / MAX_Q:.0e} (Q up to {MAX_Q:.0e})")
    if plan.continuation_seconds > max_seconds:
        raise InputError(f"harmonics {sb.fine.harmonics}: about "
                         f"{plan.continuation_seconds:.0f} s of continuation "
                         f"({plan.points:.0f} points) for {sb.where}; the limit is "
                         f"{max_seconds:.0f} s, ask for fewer")
    return _continue(sb.fine, starts, lo, hi, step, plan.points, plan.continuation_seconds,
                     equation_point_seconds(sb.fine.size), max_points, sb.where)


def continue_balance(problem: System | DrivenEquation, harmonics: int, omega_start: float,
                     omega_stop: float, step: float = 0.02, max_points: int = MAX_POINTS,
                     max_seconds: float = CONTINUATION_SECONDS) -> Continuation:
    """The balance of ``problem`` with ``harmonics`` traced in ω from every solution at the two
    ends (:meth:`SystemBalance.solutions`) through any number of folds (a softening spring's
    curve is two pieces: the small-amplitude branch up to its fold and back down the middle
    branch, and the resonant branch, which leaves the range at its low end over the
    barrier); the pieces of :func:`response` before its search for isolas."""
    sb = SystemBalance.of(problem, harmonics)
    lo, hi = sorted((omega_start, omega_stop))
    plan = response_plan(problem, harmonics, lo, hi)
    return _continued(sb, lambda: _ends(sb, omega_start, omega_stop)[:2], lo, hi, plan,
                      max_seconds, step, max_points)


def _ends(sb: SystemBalance, start: float, stop: float
          ) -> tuple[list[tuple[float, np.ndarray, float]], bool, list[str]]:
    """Every solution at both ends (``start`` first), each with the direction into the range;
    whether every search was complete; a note per end."""
    out, complete, notes = [], True, []
    for w, direction in ((start, np.sign(stop - start)), (stop, np.sign(start - stop))):
        found, whole, note = sb.solutions(w)
        complete = complete and whole
        notes.append(f"w = {w:.4g} ({len(found)} solution{'s' * (len(found) != 1)})"
                     + ("" if whole or not note else f" [{note}]"))
        out.extend((w, x, float(direction)) for x in found)
    if not out or out[0][0] != start:
        raise np.linalg.LinAlgError(f"no balance converged at ω = {start:.4g}")
    return out, complete, notes


def response(problem: System | DrivenEquation, harmonics: int = 6,
             omega_min: float | None = None, omega_max: float | None = None,
             max_seconds: float = CONTINUATION_SECONDS, closed: ClosedForms | None = None,
             checks: int | None = None) -> Response:
    """Every branch of the periodic response of ``ẍ_i + g_i(x, ẋ) = d_i f cos ωt`` (n ≥ 1
    coordinates: :func:`driven_problem`; eq. 10.60 with its :class:`ClosedForms`:
    :func:`notes_problem`) over ``[omega_min, omega_max]`` (default: :func:`response_plan`).

    The balance (:class:`PolynomialBalance` with ``harmonics``) is solved at both ends
    (:meth:`SystemBalance.solutions`), traced in ω through its folds from each solution
    there; then at interior probes (each linear ω0 and :data:`SYSTEM_PROBES` more), and along
    the backbones, any solution off the traced curve is traced too (an isola).  Each point's
    Floquet multipliers come from the monodromy of its variational equation
    (:func:`numerics.floquet.variational_multipliers`); the bifurcations along the curve and
    the attractors off it (:func:`attractors.dynamics`).  A system: the jumps of slow sweeps
    checked by DOP853 at each fold, and the middle of the longest stable and unstable
    stretches shot as true orbits (``checks`` of them, :data:`SYSTEM_CHECKS` by default).
    One equation: its one-harmonic folds, each balance fold polished into the true orbit's
    (:func:`numerics.shooting.orbit_fold_table`) and the simulated sweeps both ways (escapes
    past the barrier)."""
    plan = response_plan(problem, harmonics, omega_min, omega_max)
    sb = SystemBalance.of(problem, harmonics)
    (lo, hi), w0, fine = plan.omega_range, plan.linear_frequencies, sb.fine
    one = sb.one_harmonic is not None
    end_notes: list[str] = []
    complete = sb.bound is not None or one

    def starts() -> tuple[list[tuple[float, np.ndarray, float]], bool]:
        nonlocal complete
        out, whole, notes = _ends(sb, lo, hi)
        complete = complete and whole
        end_notes.extend(notes)
        return out, whole

    cont = _continued(sb, starts, lo, hi, plan, max_seconds)
    probes = sorted({*(w for w in w0 if lo < w < hi),
                     *np.linspace(lo, hi, SYSTEM_PROBES + 2)[1:-1]})
    closed_pieces = [False] * len(cont.pieces)
    isolas = 0

    def trace(w: float, x: np.ndarray) -> None:
        """A solution off the traced curve: its branch traced both ways and added."""
        nonlocal cont, isolas
        start = [(w, x, 1.0), (w, x, -1.0)]
        extra = _continue(fine, lambda: (start, True), lo, hi, 0.02, plan.points,
                          plan.continuation_seconds, equation_point_seconds(fine.size),
                          MAX_POINTS, sb.where)
        isolas += 1
        for piece in extra.piece_slices():
            closed_pieces.append(bool(lo < extra.omega[piece.stop - 1] < hi))
        cont = _merged(cont, extra)

    for w in probes:
        found, whole, _ = sb.solutions(float(w), probe=one)
        complete = complete and whole
        for x in found:
            if not _on_curve(cont, float(w), x):
                trace(float(w), x)
    # between the probes: Newton at a few harmonics from each backbone wherever it crosses ω
    # on a fine grid (an isola of a lightly damped system hugs its backbone)
    scanned = 0
    step = min(SCAN_STEP, (hi - lo) / 100)
    if sb.backbones:
        scan = PolynomialBalance(sb.equations, fine.force, min(harmonics, SCAN_HARMONICS),
                                 fine.odd, shape=tuple(sb.drive / fine.force))
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
    cont = _clipped(cont, lo, hi, fine)
    note = _search_note(sb, end_notes, probes, isolas, scanned, step)
    # stability of every point: the monodromy of its variational equation
    lam = orbit_multipliers(fine, cont.x, cont.omega, w0[-1])
    multiplier = np.max(np.abs(lam), axis=1)
    stable = multiplier < NEUTRAL
    amplitudes = np.array([fine.first_harmonics(x) for x in cont.x])
    jumps = _jumps(cont, np.linalg.norm(amplitudes, axis=1), stable, lo, hi)
    field = PolynomialField.of(sb.equations)
    found_dynamics = dynamics(fine, field, sb.drive, cont, lam, lo, hi, w0[-1])
    common = dict(balance=sb, harmonics=harmonics, omega_range=(lo, hi),
                  linear_frequencies=w0, cont=cont, closed=tuple(closed_pieces),
                  amplitudes=amplitudes, multiplier=multiplier, stable=stable,
                  note=note, dynamics=found_dynamics)
    if not one:
        sweep_jumps = _at_folds(sb, cont, stable, jumps)
        shots = _shot_checks(sb, cont, amplitudes, stable,
                             SYSTEM_CHECKS if checks is None else checks)
        return Response(**common, complete=complete and cont.complete,
                        jumps=tuple((j.way, j.omega, j.before, j.after) for j in sweep_jumps),
                        checks=shots, sweep_jumps=sweep_jumps)
    # one equation: the true folds, the sweeps simulated both ways
    de = sb.equation
    table = ForceTable.of(de.terms)
    if closed is None:
        barrier = ESCAPE_FACTOR * float(np.max(np.sum(np.abs(cont.x), axis=1)))
        escape = barrier
    else:
        barrier, escape = closed.barrier, closed.escape
    true_folds = []
    for w in cont.folds:  # the true orbit's fold near each of the balance's
        x = cont.x[int(np.argmin(np.abs(cont.omega - w)))]
        found = orbit_fold_table(table, de.force, w, fine.state(x, w), bound=escape)
        if found is not None:
            true_folds.append((found[0], tuple(sorted(float(abs(m)) for m in found[2]))))
    sweeps = (sweep_table(table, de.force, lo, hi, barrier=barrier, bound=escape),
              sweep_table(table, de.force, hi, lo, barrier=barrier, bound=escape))
    return Response(**common, complete=complete and cont.complete, jumps=jumps,
                    one_harmonic_folds=plan.one_harmonic_folds,
                    one_harmonic_curve=sb.one_harmonic.curve(np.linspace(lo, hi, CURVE_POINTS)),
                    sweeps=sweeps,
                    true_folds=tuple(sorted(true_folds)), barrier=barrier, escape=escape,
                    notes=() if closed is None else closed.notes)


def _search_note(sb: SystemBalance, ends: list[str], probes: list[float], isolas: int,
                 scanned: int, step: float) -> str:
    """How the branches were sought, in words."""
    if sb.one_harmonic is not None:
        how = (f"the balance from every one-harmonic root (the roots of a polynomial) at "
               f"{', '.join(ends)} and at ")
    elif sb.bound is not None:
        how = (f"every orbit has r1 <= {sb.bound:.6g}/w ({sb.why}); the drive was continued "
               f"from rest past that bound at {', '.join(ends)} and at ")
    else:
        how = (f"no amplitude bound ({sb.why}): the drive continuation from rest stopped at "
               f"{NO_BOUND_FACTOR:g} × the linear response or {NO_BOUND_POINTS} points at "
               f"{', '.join(ends)} and at ")
    seeded = (f"; Newton started from {len(sb.backbones)} backbone(s) (the free system's "
              f"normal modes, series to order {BACKBONE_ORDER}) at the probes and every "
              f"{step:.3g} in w between them ({scanned} seeds)" if sb.backbones else
              "" if sb.one_harmonic is not None else
              "; no backbone seeds (a velocity-dependent force)")
    return (how + f"{len(probes)} probes (w = {', '.join(f'{w:.4g}' for w in probes)}){seeded}: "
            f"{isolas} branch{'es' * (isolas != 1)} off the curve traced from the ends"
            + (", each traced" if isolas else "") + ". A branch reached neither from rest "
            "(in the drive, at the ends and probes) nor from a backbone is not excluded"
            if sb.one_harmonic is None else
            how + f"{len(probes)} probes (w = {', '.join(f'{w:.4g}' for w in probes)}): "
            f"{isolas} branch{'es' * (isolas != 1)} off the curve traced from the ends"
            + (", each traced" if isolas else ""))
