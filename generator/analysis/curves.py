"""The curves a command draws (``--plot``) and writes (``--csv``), sampled once: a free
oscillator's ω(y) and T(y)/2π across where its series holds, a limit cycle's amplitude and ω
against ε, a slow flow's trajectories and fixed points, a normal mode's backbone, a system's
frequency–energy plot (every mode's backbone beside orbits shot by DOP853).  The figures
and the CSV files are printers of these records; nothing here draws or formats."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from ..derive.averaging import SIGMA, SlowFlow, fixed_points
from ..derive.averaging import R as R_SLOW
from ..derive.averaging import U as U_SLOW
from ..derive.averaging import V as V_SLOW
from ..derive.cycles import LimitCycle
from ..derive.lindstedt import SeriesSolution, Validity, nearest_singularity
from ..derive.nnm import NormalModeSeries, radius
from ..errors import InputError
from ..numerics.newton import newton

SERIES_POINTS = 401
# NOTE: points of ω(y), T(y) across the drawn range: the curves are smooth polynomials, and
# 401 puts a point on y = 0 of a symmetric range.
PAST_RADIUS = 1.25
# NOTE: the range drawn reaches this far past the radius (where no orbit edge stops it first),
# so that the partial sums' departure beyond it shows.
NO_RADIUS_SPAN = 1.0
# NOTE: the half-width of the range in y (or ε) when neither a radius nor an orbit edge bounds
# it (a series that stops, or too few orders for an estimate).


def _float_sum(coefficients: list[float], x: np.ndarray) -> np.ndarray:
    """``Σ c_j x^j`` by Horner's rule in doubles."""
    total = np.zeros_like(x)
    for c in reversed(coefficients):
        total = total * x + c
    return total


def _floats(coefficients) -> list[float]:
    """Exact coefficients (Fractions, SymPy's algebraic numbers) as doubles."""
    return [float(c) for c in coefficients]


@dataclass(frozen=True, eq=False)
class SeriesCurves:
    """ω and T/2π of a free oscillator's series summed at ``y`` (units of ω₀ and 1/ω₀), the
    expansion variable ``variable``, with its :class:`derive.lindstedt.Validity`."""

    model: str
    variable: str
    order: int
    valid: Validity
    y: np.ndarray
    omega: np.ndarray
    period: np.ndarray

    @property
    def inside(self) -> np.ndarray:
        """Where the sums converge and an orbit exists: ``|y| < radius``, inside the edges."""
        v = self.valid
        ok = (self.y > v.orbit.lower) & (self.y < v.orbit.upper)
        return ok if v.radius is None else ok & (np.abs(self.y) < v.radius)


def series_curves(sol: SeriesSolution, valid: Validity, what: str = "--plot/--csv",
                  points: int = SERIES_POINTS) -> SeriesCurves:
    """:class:`SeriesCurves` of ``sol``: ``y`` from the lower orbit edge (or ``−1.25 R``) to
    the upper one (or ``+1.25 R``), ``R`` the radius (the nearer orbit edge without one)."""
    if not sol.ground.is_rational:
        raise InputError(f"{what}: the coefficients stay symbolic; give every parameter a "
                         "value (--param)")
    omega = _floats(sol.ground.to_fraction(c) for c in sol.omega)
    period = _floats(sol.ground.to_fraction(c) for c in sol.period)
    orbit = valid.orbit
    scale = valid.radius if valid.radius is not None else (
        orbit.distance if math.isfinite(orbit.distance) and orbit.distance > 0
        else NO_RADIUS_SPAN / PAST_RADIUS)
    lo = max(orbit.lower, -PAST_RADIUS * scale)
    hi = min(orbit.upper, PAST_RADIUS * scale)
    y = np.linspace(lo, hi, points)
    return SeriesCurves(sol.model.name, sol.model.variable, sol.order, valid, y,
                        _float_sum(omega, y), _float_sum(period, y))


@dataclass(frozen=True)
class CycleRadius:
    """The radius of convergence in ε of a limit cycle's ω (:func:`nearest_singularity`), with
    its spread; ``value`` None when the series is too short for an estimate."""

    value: float | None
    spread: float


def cycle_radius(lc: LimitCycle) -> CycleRadius:
    """:class:`CycleRadius` of ``lc``'s ω (read in ε² where its odd terms vanish)."""
    est = nearest_singularity(list(lc.omega), "eps", None)
    if est is None:
        return CycleRadius(None, 0.0)
    if est.variable.endswith("**2"):
        r = math.sqrt(est.radius)
        return CycleRadius(r, est.spread / (2 * r))
    return CycleRadius(est.radius, est.spread)


@dataclass(frozen=True, eq=False)
class CycleCurves:
    """A limit cycle's amplitude ``q(0)`` (at ``q'(0) = 0``), ω and T/2π summed at ``eps``."""

    model: str
    order: int
    radius: CycleRadius
    stable_for: str
    eps: np.ndarray
    amplitude: np.ndarray
    omega: np.ndarray
    period: np.ndarray


def cycle_curves(lc: LimitCycle, found: CycleRadius, points: int = SERIES_POINTS
                 ) -> CycleCurves:
    """:class:`CycleCurves` of ``lc`` for ``0 ≤ ε ≤ 1.25 R`` (``R`` its radius ``found``;
    ``0 ≤ ε ≤ 1`` without an estimate)."""
    top = PAST_RADIUS * found.value if found.value is not None else NO_RADIUS_SPAN
    eps = np.linspace(0.0, top, points)
    return CycleCurves(lc.model.name, lc.order, found,
                       "eps > 0" if lc.slope > 0 else "eps < 0", eps,
                       _float_sum(_floats(lc.amplitude), eps),
                       _float_sum(_floats(lc.omega), eps), _float_sum(_floats(lc.period), eps))


PORTRAIT_STARTS = 8
PORTRAIT_SLOW_TIME = 40.0
# NOTE: each trajectory runs to t = 40/ε: forty slow times, in which a rate of order ε has
# brought it within e^-20 of where it settles (van der Pol: onto its cycle from r = 0.1).
PORTRAIT_SAMPLES = 1601
PORTRAIT_ESCAPE = 4.0
# NOTE: a trajectory stops once it is this many times the drawn window's radius from the
# origin (a flow that blows up in finite time is not followed there).
PORTRAIT_GUESSES = tuple((0.25 * i, k * math.pi / 4) for i in range(1, 17) for k in range(8))
# NOTE: a driven flow's steady states sought by Newton from each (r, φ) of this grid, r up to
# 4 (the notes' response at f = 1: three states within r < 2, the saddle between the others).
PORTRAIT_RTOL = 1e-10


@dataclass(frozen=True, eq=False)
class Portrait:
    """The phase portrait of a slow flow at ``eps`` and ``values`` (the parameters' numbers;
    ``sigma`` of a driven flow): ``trajectories`` each an array ``(t, r cos φ, r sin φ)`` of
    shape ``(3, n)``; ``cycles`` each limit cycle of an autonomous flow ``(r*, stable)`` (a
    circle in the plane), ``points`` each fixed point ``(r cos φ, r sin φ, stable)``."""

    name: str
    source: str
    order: int
    driven: bool
    eps: float
    values: tuple[tuple[str, float], ...]
    window: float
    trajectories: tuple[np.ndarray, ...]
    cycles: tuple[tuple[float, bool], ...] = field(default=())
    points: tuple[tuple[float, float, bool], ...] = field(default=())


def portrait(flow: SlowFlow, eps: float, values: dict[str, float] | None = None) -> Portrait:
    """:class:`Portrait` of ``flow``: its fixed points (an autonomous flow's origin and limit
    cycles; a driven one's steady states by Newton from :data:`PORTRAIT_GUESSES`, stable where
    the Jacobian's eigenvalues have negative real parts) and :data:`PORTRAIT_STARTS`
    trajectories integrated in van der Pol's plane (SciPy's DOP853) from starts spread over
    the window, 1.5 times the largest fixed point's r (1 without one)."""
    from scipy.integrate import solve_ivp

    values = dict(values or {})
    eps_s = sp.Symbol("eps")
    subs = {eps_s: eps, **{sp.Symbol(k): v for k, v in values.items()}}
    rates = [sp.Add(*(eps_s ** (k + 1) * G[i] for k, G in enumerate(flow.cartesian)))
             .subs(subs) for i in range(2)]
    left = sorted({str(s) for e in rates for s in e.free_symbols} - {str(U_SLOW), str(V_SLOW)})
    if left:
        raise InputError(f"--plot/--csv: give {', '.join(left)} a value (--param"
                         + (", --sigma" if str(SIGMA) in left else "") + ")")
    field_ = sp.lambdify((U_SLOW, V_SLOW), rates, "numpy")
    jacobian = sp.lambdify((U_SLOW, V_SLOW), sp.Matrix(
        [[sp.diff(e, x) for x in (U_SLOW, V_SLOW)] for e in rates]), "numpy")

    def stable(u: float, v: float) -> bool:
        return bool(np.all(np.linalg.eigvals(np.asarray(jacobian(u, v), dtype=float)).real < 0))

    cycles, points = [], []
    if flow.driven:
        seen = set()
        for r0, phi0 in PORTRAIT_GUESSES:
            x, ok, _ = newton(lambda x: np.asarray(field_(*x), dtype=float),
                              lambda x: np.asarray(jacobian(*x), dtype=float),
                              np.array([r0 * math.cos(phi0), -r0 * math.sin(phi0)]))
            key = tuple(np.round(x, 8))
            if ok and key not in seen:
                seen.add(key)
                points.append((float(x[0]), float(-x[1]), stable(*x)))
        points.sort()
    else:
        points.append((0.0, 0.0, stable(0.0, 0.0)))
        dr = sp.diff(sp.Add(*(eps_s ** (k + 1) * c for k, c in enumerate(flow.radial)))
                     .subs(subs), R_SLOW)
        cycles = [(r, bool(float(dr.subs(R_SLOW, r)) < 0))
                  for r, _ in fixed_points(flow, eps, values)]
    far = max([r for r, _ in cycles] + [math.hypot(x, y) for x, y, _ in points], default=0.0)
    window = 1.5 * far if far > 0 else 1.0
    escape = PORTRAIT_ESCAPE * window

    def leaves(_t: float, x: np.ndarray) -> float:
        return math.hypot(x[0], x[1]) - escape

    leaves.terminal = True
    end = PORTRAIT_SLOW_TIME / abs(eps)
    times = np.linspace(0.0, end, PORTRAIT_SAMPLES)
    trajectories = []
    for k in range(PORTRAIT_STARTS):
        r0 = window * (k + 1) / PORTRAIT_STARTS
        angle = 2 * math.pi * k / PORTRAIT_STARTS + math.pi / PORTRAIT_STARTS
        start = np.array([r0 * math.cos(angle), -r0 * math.sin(angle)])
        sol = solve_ivp(lambda _t, x: np.asarray(field_(x[0], x[1]), dtype=float),
                        (0.0, end), start, method="DOP853", t_eval=times, rtol=PORTRAIT_RTOL,
                        atol=PORTRAIT_RTOL * window, events=leaves)
        trajectories.append(np.array([sol.t, sol.y[0], -sol.y[1]]))
    return Portrait(flow.name, flow.source, flow.order, flow.driven, eps,
                    tuple(sorted(values.items())), window, tuple(trajectories),
                    tuple(cycles), tuple(points))


@dataclass(frozen=True, eq=False)
class Backbone:
    """A normal mode's backbone: ω(A), T(A) summed from its series at amplitudes ``A`` up to
    95 % of its estimated reach (``reach`` None: no estimate, ``A`` up to 1)."""

    mode: int
    amplitude: str
    reach: float | None
    A: np.ndarray
    omega: np.ndarray
    period: np.ndarray


BACKBONE_POINTS = 200


def backbone(mode: NormalModeSeries, points: int = BACKBONE_POINTS) -> Backbone:
    """:class:`Backbone` of ``mode`` (:meth:`NormalModeSeries.evaluate` on its amplitudes)."""
    found = radius(mode)
    reach = None if found is None or not found.lower > 0 else found.reach
    A = np.linspace(0.0, 0.95 * (1.0 if reach is None else reach), points)
    omega, period, _ = mode.evaluate(A)
    return Backbone(mode.mode, str(mode.system.coordinates[mode.amplitude]), reach, A,
                    np.asarray(omega, dtype=float), np.asarray(period, dtype=float))


FEP_ORDER = 24
# NOTE: the backbone drawn from the series to this order (and its radius estimated from it);
# the order-12 backbone already meets shooting to 1e-14 at A = 0.3 on Kerschen's system.
FEP_SHOTS = 8
# NOTE: orbits shot per mode, from 5 % of the series' reach to 120 % (past it: where only
# shooting answers), each seeded by the last.
FEP_MAX_MODES = 4
FEP_POINTS = 200
RESONANCES = (2, 3)
# NOTE: the ratios marked: 1:2 (quadratic couplings) and 1:3 (cubic ones), where the n-th
# harmonic of one mode meets another mode's linear frequency.


@dataclass(frozen=True, eq=False)
class ModeCurve:
    """One mode of a :class:`FrequencyEnergy`: the series' backbone (energy ``E`` at the
    turning point, ``omega``) up to 95 % of its ``reach`` in A, the energy ``edge`` at the
    reach, and orbits shot beside it (``shots``: rows of energy and ω); or, for a mode without
    a series (an internal resonance), only ``note``, the reason."""

    mode: int
    omega0: str = ""
    E: np.ndarray = field(default_factory=lambda: np.empty(0))
    omega: np.ndarray = field(default_factory=lambda: np.empty(0))
    reach: float = math.nan
    edge: float = math.nan
    shots: np.ndarray = field(default_factory=lambda: np.empty((0, 2)))
    note: str | None = None


@dataclass(frozen=True, eq=False)
class FrequencyEnergy:
    """The frequency–energy plot of a system's modes, computed once: each mode's
    :class:`ModeCurve` from its series to ``order``, and the internal-resonance lines
    ``n ω = ω₀,j`` near another mode's backbone (``lines``: (j, n, ω₀,j/n), each once)."""

    text: str
    order: int
    modes: tuple[ModeCurve, ...]
    lines: tuple[tuple[int, int, float], ...]


def frequency_energy(system: object, order: int = FEP_ORDER) -> FrequencyEnergy:
    """:class:`FrequencyEnergy` of every mode of ``system`` (a :class:`derive.system.System`
    of at most :data:`FEP_MAX_MODES` modes, not stiff: its orbits are shot)."""
    from ..derive.nnm import normal_mode
    from ..numerics.references import check_shootable, mode_orbit, system_energy

    lams = system.modes()
    if len(lams) > FEP_MAX_MODES:
        raise InputError(f"--plot: the chart draws systems of up to {FEP_MAX_MODES} modes; "
                         f"this one has {len(lams)}")
    check_shootable(system, "--plot")
    energy = system_energy(system)
    curves = []
    for k in range(1, len(lams) + 1):
        try:
            mode = normal_mode(system, k, order)
        except InputError as exc:  # an internal resonance: no series, said in the legend
            curves.append(ModeCurve(k, note=f"mode {k}: no series "
                                    f"({str(exc).split(': ', 2)[-1][:60]}…)"))
            continue
        found = radius(mode)
        reach = 1.0 if found is None or not found.lower > 0 else found.reach
        A = np.linspace(reach / FEP_POINTS, 0.95 * reach, FEP_POINTS)
        omega, _, starts = mode.evaluate(A)
        shots = []
        guess = None
        for a in np.linspace(0.05, 1.2, FEP_SHOTS) * reach:
            if guess is None:
                _, period, x0 = mode.evaluate(a)
                guess = np.append(np.delete(x0, mode.amplitude), period / 2)
            orbit = mode_orbit(system, float(a), guess, mode.amplitude)
            if not orbit.converged:
                break
            guess = np.append(np.delete(orbit.start, mode.amplitude), orbit.period / 2)
            shots.append((orbit.energy, 2 * np.pi / orbit.period))
        curves.append(ModeCurve(k, str(mode.omega0), np.array([energy(x) for x in starts.T]),
                                np.asarray(omega, dtype=float), reach,
                                float(energy(mode.evaluate(reach)[2])),
                                np.array(shots).reshape(-1, 2)))
    w0 = np.sqrt([float(x) for x in lams])
    lines = tuple(dict.fromkeys((j, n, float(wj / n)) for i, wi in enumerate(w0, 1)
                                for j, wj in enumerate(w0, 1) for n in RESONANCES
                                if i != j and wi / 2 < wj / n < wi * 2))
    return FrequencyEnergy(system.text, order, tuple(curves), lines)


SUBHARMONIC_OMEGA = (1.0, 2.0, 161)
# NOTE: the notes' 1/3 subharmonic drawn over 1 ≤ ω ≤ 2 (the drive at 3ω) in steps of
# 0.00625: eq. 10.87's roots exist from ω² = 1 + 3εa²/4-ish up.


@dataclass(frozen=True, eq=False)
class SubharmonicCurve:
    """eq. 10.87's roots across ω: at each ``omega``, :func:`analysis.subharmonic.subharmonic`'s
    ``(exists, reason, solutions)`` (each root with its Hill, full-Hill and shot verdicts)."""

    eps: float
    force: float
    omega: np.ndarray
    answers: tuple


def subharmonic_curve(eps: float, force: float) -> SubharmonicCurve:
    """:class:`SubharmonicCurve` of ``ω² q'' + q + εq³ = f cos 3τ`` over
    :data:`SUBHARMONIC_OMEGA`."""
    from .subharmonic import subharmonic

    omega = np.linspace(*SUBHARMONIC_OMEGA)
    return SubharmonicCurve(eps, force, omega,
                            tuple(subharmonic(eps, force, float(w)) for w in omega))
