"""Every distinct periodic orbit at one drive: seeds (the one-harmonic roots and the
crossings of a continued balance), Newton's balance from each, shooting with its Floquet
multipliers, deduplication; the notes' Duffing and a user's polynomial force; the true fold."""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..numerics.floquet import orbit_hill_multipliers
from ..numerics.integrate import ForceTable
from ..numerics.shooting import PeriodicOrbit, ShootingFailure, shoot_explained, shoot_table
from .continuation import (
    CONTINUATION_BUDGET,
    CONTINUATION_HARMONICS,
    _balance_r,
    _crossings,
    _half_period,
    continue_in_drive,
)
from .driven import (
    MAGNITUDES,
    Branch,
    Drive,
    HarmonicBalance,
    MuExpansion,
    amplitudes,
    first_order_branches,
    harmonic_balance,
    mu_expansion,
)
from .polynomial import DrivenEquation, PolynomialBalance, amplitude_bound, check_harmonics
from .response import continue_balance, response_range

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
REFINED_HARMONICS = 32
# NOTE: where shooting from a balance fails, the balance is solved again with 32 harmonics and
# shot once more: an orbit near the barrier of a softening spring can be so unstable (Floquet
# multiplier 7.7e7 at ε −0.1, f 0.3, Q 20, ω 0.3) that the 8-harmonic balance's 1e-5 error
# carries its trajectory out of the well within the period; 32 harmonics bring it to ~1e-16.
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


@dataclass(frozen=True)
class BranchReport:
    """One orbit of ``driven``'s report, three ways where it can be: the μ-expansion on the
    first-order root that stands for it (``None``: no root does), its harmonic balance (in
    :class:`Orbit`) with the full Hill equation's multipliers about it (``None``: no balance),
    and the true orbit shot (in :class:`Orbit`)."""

    orbit: Orbit
    mu: MuExpansion | None
    balance_amplitudes: tuple[dict[int, float], dict[int, float]] | None
    full_hill: np.ndarray | None


@dataclass(frozen=True)
class DrivenReport:
    """Everything ``lindstedt driven`` prints for the notes' damped driven Duffing at one ω:
    every distinct orbit (:func:`periodic_orbits`), largest first, each with its μ-expansion
    to ``order`` and its balance with ``harmonics`` harmonics; the one-harmonic roots."""

    drive: Drive
    order: int
    harmonics: int
    found: Orbits
    branches: tuple[BranchReport, ...]


def driven_report(d: Drive, order: int, harmonics: int) -> DrivenReport:
    """The :class:`DrivenReport` at ``d``: shooting resolves ``max(2N − 1, 2K + 1)``
    harmonics, the balance's full Hill multipliers are the variational equation's about it
    (no shooting)."""
    top = max(2 * harmonics - 1, 2 * order + 1)
    found = periodic_orbits(d, harmonics, shoot_harmonics=top)
    table = {(1, 0): 1.0, (3, 0): d.eps, (0, 1): d.damping}
    branches = []
    for orb in found.orbits:
        mu = None if orb.branch is None else mu_expansion(d, orb.branch, order)
        balance = hill = None
        if orb.balance is not None:
            balance = amplitudes(orb.balance.coefficients, 0.0, 2 * harmonics - 1)
            hill = orbit_hill_multipliers(table, *balance, d.omega)
        branches.append(BranchReport(orb, mu, balance, hill))
    return DrivenReport(d, order, harmonics, found, tuple(branches))
