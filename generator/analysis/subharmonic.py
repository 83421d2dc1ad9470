"""Subharmonic responses of a driven oscillator: the orbits of period ``n`` drive periods.

Two routes, one stack.  The notes' eq. 10.83, ``ω²q'' + q + εq³ = f cos 3τ``, keeps its closed
form (eq. 10.87's amplitudes, Hill's stability about ``q₀``) as the method it is; every other
equation ``q̈ + g(q, q̇) = f cos Ωt`` (``g`` any polynomial, damped or not) and any ``n`` goes
through :func:`subharmonic_orbits`: harmonic balance on the harmonics of ``ω = Ω/n`` (the drive
on the n-th, :class:`driven.PolynomialBalance`), seeded over the first harmonic's amplitude and
phase, each orbit shot over ``n`` drive periods for its Floquet multipliers, and the onset (the
smallest drive amplitude with a 1/n orbit) by continuation in the drive amplitude.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..algebra.series import trig_power
from ..errors import InputError
from ..limits import SUBHARMONIC_MAX_N as MAX_N
from ..limits import check_int
from ..numerics.floquet import hill_multipliers, multipliers_stable, orbit_hill_multipliers
from ..numerics.integrate import ForceTable, duffing_table, steady_state_amplitudes
from ..numerics.newton import newton
from ..numerics.shooting import PeriodicOrbit, shoot, shoot_table
from .continuation import Arclength, DriveFamily, Onset, _oriented, _secant_turn
from .driven import Drive
from .periodic import SHOOTING_TOLERANCES
from .polynomial import PolynomialBalance, amplitude_bound, driven_form

_a, _b, _F, _w1, _eps1 = sp.symbols("a b F omega epsilon")


# --- the notes' eq. 10.83: the 1/3 subharmonic of q + εq³ in closed form ----------------------

def subharmonic_secular() -> tuple[sp.Expr, sp.Expr]:
    """The cos τ and sin τ coefficients of ``ω²q₀'' + q₀ + εq₀³ − f cos 3τ`` divided by ε,
    ``q₀ = a cos τ + b sin τ + F cos 3τ``, ``F = f/(1 − 9ω²)`` (eq. 10.85, 10.86), by the
    exact Fourier kernel (:func:`series.trig_power`)."""
    cube_cos, cube_sin = trig_power({1: _a, 3: _F}, {1: _b}, 3)
    cos_eq = sp.expand(((1 - _w1**2) * _a + _eps1 * cube_cos[1]) / _eps1)
    sin_eq = sp.expand(((1 - _w1**2) * _b + _eps1 * cube_sin[1]) / _eps1)
    return cos_eq, sin_eq


@dataclass(frozen=True)
class Subharmonic:
    """One root of eq. 10.87 with its Hill and true-orbit verdicts."""

    root: str  # "+" or "-"
    a: float
    F: float  # f/(1 − 9ω²), the amplitude of cos 3τ
    hill_multipliers: np.ndarray
    hill_stable: bool
    orbit: object | None  # numerics.PeriodicOrbit of period 2π/ω, or None
    locked: bool | None  # a simulation started 1 % off the true orbit stays on it
    balance: tuple[dict, dict] | None = None  # (A, B) of the harmonic balance from this root
    full_hill_multipliers: np.ndarray | None = None  # the full Hill equation's, about it
    full_hill_stable: bool | None = None  # None: the balance did not converge to this root


LOCK_WINDOW = 400.0
LOCK_TOLERANCE = 0.05
# NOTE: ~75 periods of the subharmonic: a stable orbit keeps its first harmonic within 5 %
# (the 1 % kick stays bounded), an unstable one loses it well within that window.
ORBIT_MATCH = 0.25
# NOTE: the true orbit's phase: its sin τ part within 25 % of its cos τ part (the b = 0 family;
# a copy shifted by a drive period has b = ±(√3/2)a).  Which root it belongs to: its first
# harmonic is nearer that root's a(f) than the other root's, their shifted copies (−a/2) and the
# 1:1 response (0).  Near the existence boundary a(f) is O(ε) off: at f = 7.8, ω = 1.05 the
# unstable orbit has a₁ = 0.3727 against a(f) = 0.266 (40 %).


MAX_AMPLITUDE = 1e100
# NOTE: the Hill equation and shooting cube the orbit: its cube must stay below ~1e300.


SUBHARMONIC_HARMONICS = 12
# NOTE: odd harmonics 1 … 23 of ω: on the hill_check grid's orbits (ε ≤ 1, f ≤ 10) the
# balance's a₁ within 4e-13 (relative) of shooting and the full Hill multipliers within 7e-13
# of the shot orbit's; 5 harmonics leave 2e-7 and 8e-7.


def subharmonic_balance(eps: float, force: float, omega: float, a: float, F: float,
                        marks: list[float], harmonics: int = SUBHARMONIC_HARMONICS
                        ) -> tuple[dict[int, float], dict[int, float]] | None:
    """The whole periodic orbit ``q(t)`` of eq. 10.83 near ``q₀ = a cos ωt + F cos 3ωt``, by
    harmonic balance (:class:`driven.PolynomialBalance` of ``q + εq³`` over the odd harmonics
    of ω, the drive moved to the third): ``(A, B)``, or ``None`` when Newton does not converge
    or lands on another orbit (its first harmonic nearer another of ``marks`` than ``a``, or
    out of phase: :data:`ORBIT_MATCH`)."""
    system = PolynomialBalance({(1, 0): 1.0, (3, 0): eps}, force, harmonics, odd=True,
                               drive_harmonic=3)
    x0 = np.zeros(system.size)
    x0[0], x0[1] = a, F
    x, converged, _ = system.solve(x0, omega)
    if not converged:
        return None
    A, B = system.amplitudes(x)
    if min(marks, key=lambda m: abs(A[1] - m)) != a or abs(B[1]) > ORBIT_MATCH * abs(A[1]):
        return None
    return A, B


def subharmonic(eps: float, force: float, omega: float) -> tuple[bool, str, list[Subharmonic]]:
    """The b = 0 solutions ``a(f) = −F/2 ± √((16(ω² − 1)/ε − 21F²)/12)`` of eq. 10.87.

    Returns ``(exists, reason, solutions)``; each solution's stability comes from the Hill
    equation ``ω²ξ'' + (1 + 3εq₀²)ξ = 0`` (stable when ``|tr M| < 2``), from the full Hill
    equation about the harmonic-balance orbit near it (:func:`subharmonic_balance`,
    :func:`numerics.orbit_hill_multipliers`), and from the Floquet multipliers of the true
    orbit found by shooting (period three drive periods).
    """
    d = Drive(eps, force, omega)  # validation
    if abs(1 - 9 * omega**2) < 1e-12:
        return False, "omega = 1/3: the drive is resonant with q'' + q itself (F infinite)", []
    if d.eps == 0:
        return False, "eps = 0: a linear oscillator has no subharmonic response", []
    F = force / (1 - 9 * omega**2)
    disc = (16 * (omega**2 - 1) / eps - 21 * F**2) / 12
    if disc < 0:
        return False, (f"16(omega^2 - 1)/eps = {16 * (omega**2 - 1) / eps:.6g} < 21 F^2 = "
                       f"{21 * F**2:.6g}: eq. 10.87 has no real amplitude"), []
    size = abs(F) / 2 + np.sqrt(disc)
    if not size <= MAX_AMPLITUDE:
        raise InputError(f"eps {eps:g}, omega {omega:g}: the subharmonic's amplitude |a| = "
                         f"{size:.3g} (eps a^2 ≈ 4(omega^2 - 1)/3) exceeds {MAX_AMPLITUDE:g}, "
                         "where its cube stops being a normal double")
    out = []
    roots = {"+": -F / 2 + np.sqrt(disc), "-": -F / 2 - np.sqrt(disc)}
    marks = [0.0, *roots.values(), *(-r / 2 for r in roots.values())]
    for sign in ("+", "-"):
        a = roots[sign]
        lam = hill_multipliers(omega, eps, a, 0.0, F)
        orbit = shoot(eps, force, 3 * omega, 0.0, np.array([a + F, 0.0]), harmonics=5,
                      periods=3)
        if orbit is not None:
            a1, b1 = orbit.A[1], orbit.B.get(1, 0.0)
            nearest = min(marks, key=lambda m: abs(a1 - m))
            if nearest != a or abs(b1) > ORBIT_MATCH * abs(a1):
                orbit = None  # Newton fell onto another orbit (1:1, the other root, a copy)
        locked = None
        if orbit is not None:
            q0, p0 = orbit.initial
            amp = steady_state_amplitudes(duffing_table(eps, 0.0), [force], [3 * omega],
                                          [omega], settle=0.0,
                                          window=LOCK_WINDOW, initial=(1.01 * q0, p0))[0]
            locked = bool(abs(amp - abs(orbit.A[1])) < LOCK_TOLERANCE * abs(orbit.A[1]))
        balance = subharmonic_balance(eps, force, omega, a, F, marks)
        full = None if balance is None else orbit_hill_multipliers(
            {(1, 0): 1.0, (3, 0): eps}, *balance, omega)
        out.append(Subharmonic(sign, float(a), float(F), lam,
                               bool(abs(np.sum(lam).real) < 2), orbit, locked, balance, full,
                               None if full is None else multipliers_stable(full, False)))
    return True, "16(omega^2 - 1)/eps >= 21 F^2", out


SUBHARMONIC_ANSATZ = "an orbit of n drive periods of q'' + g(q, q') = f*cos(n*w*t)"


def subharmonic_equation(text: str, values: dict[str, str], omega: float | None, n: int = 3,
                         name: str = "oscillator") -> SubharmonicProblem:
    """The problem ``subharmonic EQUATION --n N`` poses (:func:`driven.driven_form`, one
    drive): its frequency ``c·w`` is the drive at ``nω``, so ``w = nω/c`` (``f*cos(3*w*t)`` with
    n = 3: ``w = ω``); a numeric frequency ``c`` is ``nω`` itself (then no ``omega``).  Whether
    it is the notes' eq. 10.83 (``q + εq³``, undamped, n = 3) is :attr:`SubharmonicProblem.eps`.
    """
    check_n(n)
    form = driven_form(text, values, name, "subharmonic", SUBHARMONIC_ANSATZ, True)
    where = f"{name} ({text}): subharmonic does not apply: "
    if len(form.drives) != 1:
        raise InputError(where + f"{len(form.drives)} drive terms; the subharmonic takes one, "
                         f"f*cos({n}*w*t)")
    force, c, symbol = form.drives[0]
    if symbol is None:
        if omega is not None:
            raise InputError(f"--omega: the drive's frequency {c} is given in the equation "
                             f"(omega = {c}/{n}); drop --omega or write the drive as "
                             f"f*cos({n}*w*t)")
        omega = float(c / n)
    elif omega is None:
        frequency = str(symbol) if c == 1 else f"{c}*{symbol}"
        raise InputError("--omega: the subharmonic's frequency is required (the drive's "
                         f"frequency {frequency} is {n}*omega)")
    if not (math.isfinite(omega) and omega > 0):
        raise InputError(f"--omega {omega!r}: must be finite and > 0")
    terms = form.floats()
    if not any(a + b >= 2 for a, b in terms):
        raise InputError(where + "a linear force has no subharmonic (give a nonlinear term)")
    notes = n == 3 and set(terms) <= {(1, 0), (3, 0)} and terms.get((1, 0)) == 1.0 \
        and terms.get((3, 0), 0.0) != 0
    return SubharmonicProblem(terms, force, float(omega), n, form.values,
                              terms[(3, 0)] if notes else None)


# --- any polynomial force, any n: balance, shooting, onset ------------------------------------

def check_n(n: object) -> None:
    """``n`` an integer in 2..MAX_N (1 is the drive's own period: ``response``)."""
    check_int(n, 2, MAX_N, f"--n {n!r}: the subharmonic's order must be an integer in 2..{MAX_N} "
              "(the orbit of n drive periods; n = 1 is `lindstedt response`)")


def coupling_note(terms: dict[tuple[int, int], float], n: int) -> str | None:
    """Why the 1/n subharmonic may be weak or absent, or ``None``: at first order the drive's
    harmonic n reaches the first only through a term of degree d ≡ n (mod 2)
    (``q̄₁^(d−1)·q_n`` and its like).  Without one it is not fed at first order — it can still
    appear at larger drives (symmetry breaking of an odd force, whose 1/2 orbits carry even
    harmonics) or through higher orders (a quadratic force's 1/3 at second order)."""
    degrees = sorted({a + b for a, b in terms if a + b >= 2})
    if not degrees:
        return "a linear force has no subharmonic"
    if any(d % 2 == n % 2 for d in degrees):
        return None
    kind = "even" if n % 2 == 0 else "odd"
    return (f"the force has no nonlinear term of {kind} degree (its degrees: "
            f"{', '.join(map(str, degrees))}): the 1/{n} subharmonic is not fed at first "
            "order; it can still appear at a larger drive (symmetry breaking) or through "
            "higher orders")


@dataclass(frozen=True)
class SubharmonicProblem:
    """``q̈ + g(q, q̇) = f cos(nωt)``: the force's terms, the drive, ω (the subharmonic's own
    frequency) and n; ``eps`` is eq. 10.83's ε when the equation is the notes' (else None)."""

    terms: dict[tuple[int, int], float]
    force: float
    omega: float
    n: int
    values: tuple[tuple[str, str], ...]
    eps: float | None = None

    @property
    def drive(self) -> float:
        """The drive frequency ``nω``."""
        return self.n * self.omega


@dataclass(frozen=True)
class SubharmonicOrbit:
    """One orbit of period ``n`` drive periods: its balance (harmonics of ω) and the true
    orbit shot from it, with its Floquet multipliers (None where shooting found none)."""

    A: dict[int, float]
    B: dict[int, float]
    residual: float
    orbit: PeriodicOrbit | None
    deviation: float | None  # |shot state − balance state| / |state|: the balance's error

    @property
    def r(self) -> float:
        """The first harmonic's amplitude √(A₁² + B₁²) (the shot orbit's where there is one)."""
        if self.orbit is not None:
            return math.hypot(self.orbit.A.get(1, 0.0), self.orbit.B.get(1, 0.0))
        return math.hypot(self.A.get(1, 0.0), self.B.get(1, 0.0))

    @property
    def stable(self) -> bool | None:
        """The shot orbit's Floquet verdict; ``None`` where shooting found no orbit."""
        return None if self.orbit is None else bool(self.orbit.stable)


@dataclass(frozen=True)
class SubharmonicResponse:
    """Every 1/n orbit the seeds reach at one drive, distinct up to the drive-period shifts
    (each orbit has n copies, shifted by one drive period), largest ``r`` first; the primary
    response (period one drive period) beside them; the onset."""

    problem: SubharmonicProblem
    harmonics: int
    orbits: tuple[SubharmonicOrbit, ...]
    primary: SubharmonicOrbit | None
    onset: Onset | None
    seeds: int
    note: str | None = None  # coupling_note: why the orbits may be weak or absent

    @property
    def exists(self) -> bool:
        """Whether any 1/n orbit was found."""
        return bool(self.orbits)

    @property
    def reason(self) -> str:
        """One line: how many orbits were found at this drive and ω, and from how many seeds,
        or that none was."""
        p = self.problem
        if self.orbits:
            return (f"{len(self.orbits)} orbit(s) of {p.n} drive periods at f = {p.force:g}, "
                    f"omega = {p.omega:g} (drive {p.drive:g}), from {self.seeds} seeds")
        return (f"no orbit of {p.n} drive periods from {self.seeds} seeds at f = {p.force:g}, "
                f"omega = {p.omega:g}: the drive is below the onset or omega outside the "
                "subharmonic's range")


SUBHARMONIC_SEEDS = (24, 12)
# NOTE: 24 first-harmonic amplitudes (geometric, 1/200 of the scale up to it) × 12 phases in a
# drive period's share 2π/n: 288 Newton starts on the balance with n + 2 harmonics, each
# distinct solution polished at the harmonics asked.  Eq. 10.83 at ε 0.1, f 1, ω 1.05: its
# unstable orbit draws 4 % of a uniform polar grid of starts (the stable one 26 %, the primary
# response the rest): 288 starts in a third of the plane put ~12 on it.
SAME_SUBHARMONIC = 1e-6
# NOTE: two balance solutions are one orbit when one equals a drive-period shift of the other
# (_shifts) to 1e-6 of its norm; Newton converges to ~1e-13, distinct orbits lie O(1) apart
# except within ~1e-12 of a fold.
ONSET_POINTS = 4000
# NOTE: continuation steps toward the onset, at most 1/50 of the orbit's size each: the onsets
# of the tests are reached in under 200; a branch that wanders past 4000 gives no onset.


def _shifts(system: PolynomialBalance, x: np.ndarray, n: int) -> list[np.ndarray]:
    """``x`` and its copies shifted by 1 … n − 1 drive periods: a shift by ``2π/(nω)``
    multiplies ``a_k − i b_k`` by ``e^{2πik/n}``."""
    A, B = system.amplitudes(x)
    out = []
    for s in range(n):
        turn = 2 * math.pi * s / n
        A2, B2 = {}, {}
        for k in A:
            c = complex(A[k], -B.get(k, 0.0)) * complex(math.cos(k * turn), math.sin(k * turn))
            A2[k], B2[k] = c.real, -c.imag
        out.append(system.vector(A2, {k: v for k, v in B2.items() if k > 0}))
    return out


def _canonical(system: PolynomialBalance, x: np.ndarray, n: int) -> np.ndarray:
    """The drive-period shift of ``x`` whose first harmonic's phase is nearest 0 (``A₁ > 0``,
    ``B₁ = 0`` for an undamped orbit), ties to the positive phase."""
    def key(c: np.ndarray) -> tuple[float, float]:
        A, B = system.amplitudes(c)
        phase = math.atan2(-B.get(1, 0.0), A.get(1, 0.0))
        return round(abs(phase), 9), -phase

    return min(_shifts(system, x, n), key=key)


def _new(system: PolynomialBalance, x: np.ndarray, n: int, found: list[np.ndarray]) -> bool:
    """``x`` is no drive-period shift of an orbit in ``found`` (:data:`SAME_SUBHARMONIC`)."""
    tol = SAME_SUBHARMONIC * (1 + float(np.max(np.abs(x))))
    return all(np.max(np.abs(c - y)) > tol for c in _shifts(system, x, n) for y in found)


def _scale(terms: dict[tuple[int, int], float], omega: float, force: float) -> float:
    """The amplitude scale the seeds span: the one-harmonic bound where there is one, else
    twice the amplitude where the strongest nonlinear term equals the linear one."""
    bound = amplitude_bound(terms, omega, abs(force))
    k = abs(terms.get((1, 0), 1.0))
    own = max((k / abs(c) * omega ** -b) ** (1 / (a + b - 1)) for (a, b), c in terms.items()
              if a + b >= 2)
    return float(min(bound, 4 * own)) if bound is not None else 2 * float(own)


def _first(system: PolynomialBalance, x: np.ndarray) -> float:
    A, B = system.amplitudes(x)
    return math.hypot(A.get(1, 0.0), B.get(1, 0.0))


def subharmonic_orbits(problem: SubharmonicProblem, harmonics: int = 12,
                       onset: bool = True) -> SubharmonicResponse:
    """Every 1/n orbit of ``q̈ + g(q, q̇) = f cos(nωt)`` the seeds reach (see the module), each
    shot over n drive periods (:func:`numerics.shoot_table`, its Floquet multipliers), and
    the onset of the first (largest) one (:func:`subharmonic_onset`)."""
    p = problem
    check_n(p.n)
    # odd harmonics only where both the force and n are odd: an odd force's 1/2 orbits break
    # its symmetry and carry the even harmonics too
    odd = p.n % 2 == 1 and all((a + b) % 2 == 1 for a, b in p.terms)
    harmonics = max(harmonics, p.n + 1)
    system = PolynomialBalance(p.terms, p.force, harmonics, odd, drive_harmonic=p.n)
    coarse = PolynomialBalance(p.terms, p.force, min(harmonics, p.n + 2), odd,
                               drive_harmonic=p.n)
    omega = p.omega
    primary_x = _primary(system, p, p.force)
    scale = _scale(p.terms, omega, p.force)
    base = np.zeros(coarse.size) if primary_x is None else coarse.vector(
        *system.amplitudes(primary_x))
    k1 = int(np.nonzero(coarse.orders == 1)[0][0])
    s1 = coarse.n_cos + int(np.nonzero(coarse.orders[coarse.orders > 0] == 1)[0][0])
    found: list[np.ndarray] = []
    count = 0
    amplitudes, phases = SUBHARMONIC_SEEDS
    with np.errstate(all="ignore"):
        for a in np.geomspace(scale / 200, scale, amplitudes):
            for j in range(phases):
                phi = 2 * math.pi / p.n * (j + 0.5) / phases
                x0 = base.copy()
                x0[k1], x0[s1] = a * math.cos(phi), -a * math.sin(phi)
                count += 1
                xc, converged, _ = coarse.solve(x0, omega)
                if not converged or _first(coarse, xc) <= 1e-7 * (1 + np.max(np.abs(xc))):
                    continue
                x, converged, _ = system.solve(system.vector(*coarse.amplitudes(xc)), omega)
                if converged and _first(system, x) > 1e-7 * (1 + np.max(np.abs(x))) \
                        and _new(system, x, p.n, found):
                    found.append(_canonical(system, x, p.n))
    table = ForceTable.of(p.terms)
    orbits = sorted((_shot(system, table, p, x) for x in found), key=lambda o: -o.r)
    primary = None if primary_x is None else _shot(system, table, p, primary_x, periods=1)
    start = onset and orbits
    return SubharmonicResponse(p, harmonics, tuple(orbits), primary,
                               subharmonic_onset(system, p, found) if start else None, count,
                               coupling_note(p.terms, p.n))


def _primary(system: PolynomialBalance, p: SubharmonicProblem, force: float,
             start: np.ndarray | None = None) -> np.ndarray | None:
    """The primary response (harmonics n, 2n, … of ω only) at drive amplitude ``force``:
    Newton from ``start``, or from the linear response ``f/(k − (nω)²)`` on cos nωt, then from
    rest; ``None`` where neither converges."""
    k = p.terms.get((1, 0), 1.0)
    linear = np.zeros(system.size)
    index = int(np.nonzero(system.orders == p.n)[0][0])
    gap = k - (p.n * p.omega) ** 2
    if gap:
        linear[index] = force / gap
    for x0 in ([start] if start is not None else []) + [linear, np.zeros(system.size)]:
        x, ok, _ = newton(lambda z: system.residual(z, p.omega, force),
                          lambda z: system.jacobian(z, p.omega), x0)
        if ok and _first(system, x) < 1e-9 * (1 + np.max(np.abs(x))):
            return x
    return None


def _shot(system: PolynomialBalance, table: ForceTable, p: SubharmonicProblem, x: np.ndarray,
          periods: int | None = None) -> SubharmonicOrbit:
    A, B = system.amplitudes(x)
    residual = float(np.max(np.abs(system.residual(x, p.omega))))
    state = system.state(x, p.omega)
    periods = p.n if periods is None else periods
    for tol in SHOOTING_TOLERANCES:
        shot = shoot_table(table, p.force, p.drive, state, harmonics=9, tol=tol,
                           periods=periods)
        if isinstance(shot, PeriodicOrbit):
            size = max(float(np.max(np.abs(state))), 1e-300)
            deviation = float(np.max(np.abs(shot.initial - state))) / size
            if deviation <= 1e-3:
                if periods == 1:  # harmonics of the drive: relabel as harmonics of ω
                    shot = PeriodicOrbit(shot.initial, {k * p.n: v for k, v in shot.A.items()},
                                         {k * p.n: v for k, v in shot.B.items()},
                                         shot.multipliers, shot.stable, shot.residual)
                return SubharmonicOrbit(A, B, residual, shot, deviation)
    return SubharmonicOrbit(A, B, residual, None, None)


BRANCH_SHARE = 0.25
# NOTE: where f turns back with the first harmonic below a quarter of the orbit's, the path
# went through the primary response: a branch point (period doubling for n = 2), not a fold;
# at a fold both orbits keep a first harmonic of the orbit's size.


def subharmonic_onset(system: PolynomialBalance, p: SubharmonicProblem,
                      starts: list[np.ndarray]) -> Onset:
    """Continue each orbit in the drive amplitude (:class:`continuation.Arclength`, f
    decreasing) to where it ends: a fold (f turns back; refined by the secant on the
    tangent's f-component), a branch point off the primary response (f turns back where the
    first harmonic passes 0; refined by bisection on the sign of the balance Jacobian's
    determinant along the primary), or f = 0; the smallest such f over the orbits."""
    fam = DriveFamily(system, p.omega)
    best = Onset("force", math.inf, "none")
    for x in starts:
        y = np.append(x, p.force)
        r_start = _first(system, x)
        size = 1 + float(np.max(np.abs(x))) + abs(p.force)
        low = None
        with np.errstate(all="ignore"):
            try:
                path = Arclength(fam, y, _oriented(fam, y, -1.0), size / 200, size * 1e-10,
                                 lambda _, h, top=size / 50: min(1.5 * h, top))  # f falling
            except np.linalg.LinAlgError:
                continue
            for _ in range(ONSET_POINTS):
                if not path.attempt():
                    if path.stuck:
                        break
                    continue
                if path.y[-1] <= 0:
                    low = Onset("force", 0.0, "none")
                    break
                if path.fold:  # f turned back over the last step
                    y, t, _ = path.previous
                    low = _turn(system, fam, p, y, t, path.y, r_start)
                    break
        if low is not None and low.value < best.value:
            best = low
    return best


def _turn(system: PolynomialBalance, fam: DriveFamily, p: SubharmonicProblem, y: np.ndarray,
          t: np.ndarray, y_new: np.ndarray, r_start: float) -> Onset:
    """The onset where the continuation turned back between ``y`` and ``y_new``: the point
    where the tangent's f-component vanishes (secant on the step), a branch point when the
    first harmonic there has fallen below :data:`BRANCH_SHARE` of the orbit's (its drive
    amplitude then polished on the primary response), a fold otherwise."""
    step = float(np.linalg.norm(y_new - y))
    try:
        z = _secant_turn(fam, y, t, step, t[-1], None)
    except np.linalg.LinAlgError:
        z = None
    lo, hi = min(y[-1], y_new[-1]), max(y[-1], y_new[-1])
    if z is None or not np.all(np.isfinite(z)) or not lo - step <= z[-1] <= hi + step:
        z = y_new if y_new[-1] < y[-1] else y
    r_turn = min(_first(system, z[:-1]), _first(system, y[:-1]), _first(system, y_new[:-1]))
    if r_turn < BRANCH_SHARE * r_start:
        f = _branch_point(system, p, min(lo, z[-1]), max(hi, z[-1]))
        return Onset("force", float(z[-1]) if f is None else f, "bifurcation")
    return Onset("force", float(z[-1]), "fold")


def _branch_point(system: PolynomialBalance, p: SubharmonicProblem, lo: float,
                  hi: float) -> float | None:
    """The drive amplitude in about ``[lo, hi]`` where the primary response's balance Jacobian
    is singular (the 1/n orbits leave it there), by bisection on the sign of its determinant
    (the bracket widened until the sign changes); ``None`` where no change is found."""
    def sign(f: float, start: np.ndarray | None) -> tuple[float, np.ndarray | None]:
        x = _primary(system, p, f, start)
        if x is None:
            return 0.0, None
        return float(np.linalg.slogdet(system.jacobian(x, p.omega))[0]), x

    width = max(hi - lo, 1e-9 * (1 + abs(hi)))
    for _ in range(20):
        s_lo, x_lo = sign(lo, None)
        s_hi, _ = sign(hi, x_lo)
        if s_lo and s_hi and s_lo != s_hi:
            break
        lo, hi, width = max(lo - width, 0.0), hi + width, 2 * width
    else:
        return None
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        s_mid, x_mid = sign(mid, x_lo)
        if not s_mid:
            return None
        if s_mid == s_lo:
            lo, x_lo = mid, x_mid
        else:
            hi = mid
        if hi - lo <= 1e-13 * (1 + abs(hi)):
            break
    return 0.5 * (lo + hi)
