"""Every distinct periodic orbit at one drive, of any polynomial force (eq. 10.60 one of
them): seeds (the crossings of the balance continued in the drive amplitude and, for eq. 10.60,
the one-harmonic roots), Newton's balance from each, shooting with its Floquet multipliers,
deduplication; the report of ``driven``."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace

import numpy as np

from ..numerics.floquet import orbit_hill_multipliers
from ..numerics.integrate import ForceTable, escape_bound
from ..numerics.shooting import PeriodicOrbit, ShootingFailure, shoot_table
from .continuation import drive_crossings
from .driven import (
    Branch,
    Drive,
    MuExpansion,
    first_order_branches,
    harmonic_balance,
    mu_expansion,
)
from .polynomial import DrivenEquation, HarmonicBalance, PolynomialBalance, check_harmonics

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

    ``seed``: ``"one_harmonic"`` when shooting from a one-harmonic root of eq. 10.60 reached
    it, ``"continuation"`` when only a crossing of the balance continued in the drive did.
    ``branch``: the one-harmonic root that stands for it at first order (the root whose shooting
    reached it, the nearest when several did; or, when as many roots as orbits are left over,
    the one of the same rank in amplitude), ``None`` when no root does (always, for a user's
    equation).  ``balance``: the harmonic balance whose solution led to the orbit, ``own`` when
    it converged onto this orbit (within BALANCE_NEAR).  ``orbit`` is ``None`` for a seed whose
    balance converged but whose shooting did not (at the corners of the domain): then the
    branch is that balance alone (``paired = "balance"``)."""

    orbit: PeriodicOrbit | None  # None: shooting found no orbit (see periodic_orbits)
    balance: HarmonicBalance | None
    branch: Branch | None = None
    seed: str = "continuation"
    paired: str | None = None  # "shot" (its shooting reached it), "rank", "balance", None
    failure: ShootingFailure | None = None  # orbit None: why shooting from the balance failed
    own: bool = True

    @property
    def r(self) -> float:
        """The first-harmonic amplitude ``√(A₁² + B₁²)`` of the true orbit (of the balance
        where shooting found none)."""
        if self.orbit is None:
            return self.balance.r
        return math.hypot(self.orbit.A.get(1, 0.0), self.orbit.B.get(1, 0.0))


@dataclass(frozen=True)
class Orbits:
    """Every distinct orbit found at one drive, largest first; for eq. 10.60 also its
    one-harmonic roots, each with the index of the orbit it stands for and, where its
    shooting found none, why."""

    orbits: tuple[Orbit, ...]
    roots: tuple[tuple[Branch, int | None], ...]
    complete: bool  # whether the seeds cover every orbit (drive_crossings' curve complete)
    note: str  # how the seeds were found
    failures: tuple[ShootingFailure | None, ...] = ()  # per root: why its shooting found none
    seeds: int = 0  # crossings of the drive amplitude


@dataclass(frozen=True)
class _Seed:
    """Where shooting starts: the guesses ``(q(0), q̇(0))`` in order, the balance solved from
    the seed (``None``: singular), the index of the one-harmonic root it came from."""

    guesses: tuple[np.ndarray, ...]
    balance: HarmonicBalance | None
    root: int | None = None


def _state_distance(a: np.ndarray, b: np.ndarray, omega: float) -> float:
    """``|Δ(q, q̇/ω)|`` relative to the larger of the two states' norms (see SAME_ORBIT)."""
    u, v = np.array([a[0], a[1] / omega]), np.array([b[0], b[1] / omega])
    size = max(float(np.linalg.norm(u)), float(np.linalg.norm(v)))
    return float(np.linalg.norm(u - v)) / size if size > 0 else 0.0


def _first_harmonic_gap(br: Branch, orbit: Orbit) -> float:
    """Distance of a root's ``(A₁ cos δ₀, A₁ sin δ₀)`` from an orbit's ``(A₁, B₁)`` (its
    balance's, where shooting found none)."""
    A, B = orbit.balance.amplitudes() if orbit.orbit is None else (orbit.orbit.A, orbit.orbit.B)
    return math.hypot(br.A1 * math.cos(br.delta0) - A.get(1, 0.0),
                      br.A1 * math.sin(br.delta0) - B.get(1, 0.0))


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


def periodic_orbits(system: Drive | DrivenEquation, harmonics: int = 8,
                    shoot_harmonics: int | None = None) -> Orbits:
    """Every distinct periodic orbit of period ``2π/ω`` of eq. 10.60 (a :class:`Drive`) or of a
    user's :class:`DrivenEquation` that the seeds reach, largest ``r`` first, each once, with
    its Floquet multipliers (:func:`numerics.shooting.shoot_table`, ``shoot_harmonics``
    harmonics resolved, default ``2N − 1``).

    Seeds: every crossing of the balance continued in the drive amplitude from rest
    (:func:`continuation.drive_crossings`), and for eq. 10.60 first every real root of the
    one-harmonic cubic (which stands for the orbit its shooting reaches); each is polished by
    Newton's method on the balance with ``harmonics`` harmonics and shot from
    (:func:`_shoot_seed`).  Orbits within SAME_ORBIT are one; a seed whose balance converged
    but whose shooting found nothing, farther than BALANCE_NEAR from every orbit, is kept as
    its balance alone."""
    check_harmonics(harmonics)
    if isinstance(system, Drive):
        de, roots, bound = system.equation, first_order_branches(system), escape_bound(
            system.eps, system.force)
    else:
        de, roots, bound = system, [], math.inf
    top = 2 * harmonics - 1
    shoot_harmonics = top if shoot_harmonics is None else shoot_harmonics
    omega = de.omega
    fine = PolynomialBalance(de.terms, de.force, harmonics, de.odd)
    seeds = []
    for k, br in enumerate(roots):
        first = br.A1 * np.array([math.cos(br.delta0), omega * math.sin(br.delta0)])
        hb = fine.solution(fine.vector({1: br.A1 * math.cos(br.delta0)},
                                       {1: br.A1 * math.sin(br.delta0)}), omega)
        good = hb is not None and hb.converged
        seeds.append(_Seed((hb.state(omega), first) if good else (first,), hb, k))
    coarse, crossings, curve = drive_crossings(de, harmonics)
    for x in crossings:
        hb = fine.solution(fine.vector(*coarse.amplitudes(x)), omega)
        raw = coarse.state(x, omega)
        good = hb is not None and hb.converged
        seeds.append(_Seed((hb.state(omega), raw) if good else (raw,), hb))
    table = ForceTable.of(de.terms)
    found: list[Orbit] = []
    reached: dict[int, int] = {}  # root index -> orbit index
    failures: dict[int, ShootingFailure] = {}  # root index -> why its shooting found none
    unshot: list[tuple[_Seed, ShootingFailure | None]] = []
    for seed in seeds:
        orbit, failure = _shoot_seed(de, table, seed, shoot_harmonics, bound)
        if orbit is None:
            if seed.root is not None:
                failures[seed.root] = failure
            unshot.append((seed, failure))
            continue
        hb = seed.balance
        j = next((j for j, o in enumerate(found) if _state_distance(
            o.orbit.initial, orbit.initial, omega) <= SAME_ORBIT), None)
        # the balance shown beside the orbit: one that converged onto it, if any seed's did
        own = hb is not None and hb.converged and _state_distance(
            hb.state(omega), orbit.initial, omega) <= BALANCE_NEAR
        if j is None:
            j = len(found)
            found.append(Orbit(orbit, hb, seed="one_harmonic" if seed.root is not None
                               else "continuation", own=own))
        elif own and not found[j].own:
            found[j] = replace(found[j], balance=hb, own=True)
        if seed.root is not None:
            reached[seed.root] = j
    # a seed whose shooting failed but whose balance converged elsewhere than every orbit found
    # (the corners of the domain, where RK4 cannot follow the scales): its balance, no orbit
    for seed, failure in unshot:
        hb = seed.balance
        if hb is None or not hb.converged or seed.root in reached:
            continue
        state = hb.state(omega)
        if all(_state_distance(state, o.orbit.initial if o.orbit is not None
                               else o.balance.state(omega), omega)
               > (BALANCE_NEAR if o.orbit is not None else SAME_ORBIT) for o in found):
            if seed.root is not None:
                reached[seed.root] = len(found)
            found.append(Orbit(None, hb, seed="one_harmonic" if seed.root is not None
                               else "continuation", failure=failure))
    rank = sorted(range(len(found)), key=lambda j: -found[j].r)
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
    paired = {j: "shot" if found[j].orbit is not None else "balance" for j in owner}
    if roots and len(free_roots) == len(free_orbits):
        owner.update(zip(free_orbits, sorted(free_roots, key=lambda k: -abs(roots[k].A1)),
                         strict=True))
        paired.update(dict.fromkeys(free_orbits, "rank"))
    stands = {k: j for j, k in owner.items()}
    orbits = tuple(replace(o, branch=roots[owner[j]] if j in owner else None,
                           paired=paired.get(j)) for j, o in enumerate(found))
    note = curve.note + f"; {len(crossings)} crossings of the drive amplitude"
    return Orbits(orbits, tuple((br, stands.get(k)) for k, br in enumerate(roots)),
                  curve.complete, note, tuple(failures.get(k) for k in range(len(roots))),
                  len(crossings))


def _shoot_seed(de: DrivenEquation, table: ForceTable, seed: _Seed, shoot_harmonics: int,
                bound: float) -> tuple[PeriodicOrbit | None, ShootingFailure | None]:
    """Shooting from each guess at each of SHOOTING_TOLERANCES, then (a converged balance)
    from the balance solved again with REFINED_HARMONICS; the orbit, or why the first guess
    found none."""
    first = None
    for tol, guess in itertools.product(SHOOTING_TOLERANCES, seed.guesses):
        found = shoot_table(table, de.force, de.omega, guess, harmonics=shoot_harmonics,
                            tol=tol, bound=bound)
        if isinstance(found, PeriodicOrbit):
            return found, None
        first = first or found
    hb = seed.balance
    if hb is not None and hb.converged and hb.harmonics < REFINED_HARMONICS:
        system = PolynomialBalance(de.terms, de.force, REFINED_HARMONICS, de.odd)
        fine = system.solution(system.vector(*hb.amplitudes()), de.omega)
        if fine is not None and fine.converged:
            for tol in SHOOTING_TOLERANCES:
                found = shoot_table(table, de.force, de.omega, fine.state(de.omega),
                                    harmonics=shoot_harmonics, tol=tol, bound=bound)
                if isinstance(found, PeriodicOrbit):
                    return found, None
    return None, first


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
    """Everything ``lindstedt driven`` prints at one ω, for the notes' driven Duffing (``drive``:
    its parameters) or a user's equation (``drive`` None): every distinct orbit
    (:func:`periodic_orbits`), largest first, each with its balance with ``harmonics``
    harmonics and, for eq. 10.60, its μ-expansion to ``order``; the one-harmonic roots."""

    equation: DrivenEquation
    drive: Drive | None
    order: int
    harmonics: int
    found: Orbits
    branches: tuple[BranchReport, ...]


def driven_report(system: Drive | DrivenEquation, order: int, harmonics: int) -> DrivenReport:
    """The :class:`DrivenReport` of eq. 10.60 at a :class:`Drive` or of a user's equation at its
    ω: shooting resolves ``max(2N − 1, 2K + 1)`` harmonics, the balance's full Hill multipliers
    are the variational equation's about it (no shooting; where the force's velocity part is
    linear, ``c q̇``, as :func:`numerics.floquet.orbit_hill_rows` takes it).  Beside each orbit
    stands the balance that led to it; for a user's equation only one that converged onto it
    (``Orbit.own``)."""
    drive = system if isinstance(system, Drive) else None
    de = system.equation if drive is not None else system
    top = max(2 * harmonics - 1, 2 * order + 1)
    found = periodic_orbits(system, harmonics, shoot_harmonics=top)
    hill_known = all(b == 0 or (a, b) == (0, 1) for a, b in de.terms)
    branches = []
    for orb in found.orbits:
        mu = None if drive is None or orb.branch is None else mu_expansion(drive, orb.branch,
                                                                           order)
        balance = hill = None
        shown = orb.balance is not None and (drive is not None
                                             or (orb.balance.converged and orb.own))
        if shown:
            balance = orb.balance.amplitudes()
            if hill_known:
                hill = orbit_hill_multipliers(de.terms, *balance, de.omega)
        branches.append(BranchReport(orb, mu, balance, hill))
    return DrivenReport(de, drive, order, harmonics, found, tuple(branches))
