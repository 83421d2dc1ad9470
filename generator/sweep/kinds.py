"""Maps of the driven oscillator ``q̈ + q̇/Q + q + εq³ = f cos ωt`` over parameter grids.

A grid is a few named axes (``omega``, ``force``, ``eps``, ``Q``), each a list of values; a
*kind* of map (:class:`Kind`) says which axes it takes, what it computes at one point and
what it stores:

* ``response``: the steady amplitude ``r = √(A₁² + B₁²)`` of every 1:1 branch (harmonic
  balance with 10 harmonics from each first-order root), its one-harmonic stability
  (``∂G/∂u > 0``), and the largest and smallest stable amplitude;
* ``stability``: every distinct periodic orbit (:func:`analysis.periodic.periodic_orbits`: shooting
  from each branch's balance solution and from the crossings of the continued balance, which
  find the orbits the one-harmonic roots miss near a fold), how many are Floquet-stable, their
  largest Floquet modulus, and the orbit each first-order branch stands for;
* ``subharmonic``: the 1/3 subharmonic (eq. 10.87, undamped; ``omega`` is its frequency, the
  drive is at ``3ω``): whether it exists, both roots, Hill and true-orbit stability, and the
  full Hill verdict (about the harmonic-balance orbit, :func:`numerics.orbit_hill_multipliers`)
  with its largest multiplier modulus;
* ``validity``: the μ-expansion's and low-order harmonic balance's error in ``A₁`` against
  harmonic balance with 10 harmonics on the largest branch (the driven validity chart);
* ``ssm`` (a system or an equation only, :func:`_ssm_kind`): the spectral submanifold of one
  mode at each point (:mod:`analysis.ssm`) and its forced response over a grid of drive
  frequencies: each coordinate's peak amplitude over every steady state, the ω and ρ of the
  largest state, the number of folds, the linear ``|λ|`` and damping ratio, the first
  normal-form coefficient ``γ₁``. The SSM depends on M, C, K and f only, so it is computed
  once per distinct value of the parameters that enter them (:func:`ssm_of`, cached in each
  process) and only the forced response, linear in the drive, per point.

Every point is computed by the existing solvers of :mod:`driven`, :mod:`response`,
:mod:`analysis.ssm` and :mod:`numerics`; nothing here solves anything itself.

One table (:data:`KINDS`) says which problems each kind takes: the notes' axes, a user's
equation, a system; with an equation or a system (:func:`kind_of`) a kind is made of its
own: any of its parameters an axis, every orbit stored with its r and Floquet verdict (or,
for ``ssm``, its reduced model's forced response).
"""

from __future__ import annotations

import functools
import itertools
import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING

import numpy as np
from distributed import WorkerPlugin

from ..analysis.continuation import CONTINUATION_HARMONICS
from ..analysis.driven import Drive, amplitude_slope, amplitudes, first_order_branches, mu_expansion
from ..analysis.periodic import SAME_ORBIT, periodic_orbits, try_balance
from ..analysis.subharmonic import SUBHARMONIC_HARMONICS, subharmonic
from ..errors import InputError

if TYPE_CHECKING:
    from ..derive.problem import Problem

# NOTE: xarray and zarr are imported where the client uses them: every worker imports this
# module to run its blocks and needs neither (~1.3 s of each worker's start-up, measured).



# --- what one point computes -------------------------------------------------------------------

BRANCHES = 3
# NOTE: the first-order amplitude equation is a cubic in r²: at most three 1:1 branches.
RESPONSE_HARMONICS = 10
# NOTE: harmonic balance with 10 odd harmonics equals the true orbit to ~1e-10 at the notes'
# parameters (the judge of the validity chart), at ~1 ms a branch.
ORBIT_HARMONICS = 8
# NOTE: the balance each orbit is shot from (response.periodic_orbits' default).
MU_ORDERS = (1, 2, 4, 6, 10)
VALIDITY_BALANCE_HARMONICS = (2, 4)
JUDGE_HARMONICS = 10
# NOTE: the methods and the judge of charts.driven_validity_figure (its VALIDITY_METHODS).


def _response(omega: float, force: float, eps: float, Q: float) -> dict:
    d = Drive(eps, force, omega, Q)
    branches = first_order_branches(d)[:BRANCHES]
    r, stable = [math.nan] * BRANCHES, [-1] * BRANCHES
    for k, br in enumerate(branches):
        stable[k] = int(amplitude_slope(br.A1**2, omega, d) > 0)
        hb = try_balance(d, br, RESPONSE_HARMONICS, converged=True)
        if hb is not None:
            A, B = amplitudes(hb.coefficients, 0.0, 1)
            r[k] = math.hypot(A[1], B[1])
    kept = [r[k] for k in range(len(branches)) if stable[k] == 1 and math.isfinite(r[k])]
    return {"branches": len(branches), "r": r, "stable": stable,
            "r_stable_max": max(kept, default=math.nan),
            "r_stable_min": min(kept, default=math.nan)}


def _stability(omega: float, force: float, eps: float, Q: float) -> dict:
    """Every distinct 1:1 orbit (:func:`analysis.periodic.periodic_orbits`: the one-harmonic
    roots and the crossings of the balance continued in the drive, shot and deduplicated); per
    first-order branch, the orbit it stands for (NaN / −1 where it stands for none)."""
    found = periodic_orbits(Drive(eps, force, omega, Q), ORBIT_HARMONICS, shoot_harmonics=1)
    shot = [o.orbit for o in found.orbits if o.orbit is not None]
    r, floquet, stable = [math.nan] * BRANCHES, [math.nan] * BRANCHES, [-1] * BRANCHES
    for k, (_, j) in enumerate(found.roots[:BRANCHES]):
        orbit = None if j is None else found.orbits[j].orbit
        if orbit is not None:
            r[k] = math.hypot(orbit.A[1], orbit.B[1])
            floquet[k] = float(np.max(np.abs(orbit.multipliers)))
            stable[k] = int(orbit.stable)
    return {"branches": min(len(found.roots), BRANCHES), "orbits": len(shot),
            "stable_orbits": sum(o.stable for o in shot),
            "max_floquet": max((float(np.max(np.abs(o.multipliers))) for o in shot),
                               default=math.nan),
            "r": r, "floquet": floquet, "orbit_stable": stable}


def _subharmonic(omega: float, force: float, eps: float) -> dict:
    exists, _, solutions = subharmonic(eps, force, omega)
    out = {"exists": int(exists), "F": solutions[0].F if solutions else math.nan,
           "a": [math.nan] * 2, "hill_stable": [-1] * 2, "orbit_a1": [math.nan] * 2,
           "orbit_floquet": [math.nan] * 2, "orbit_stable": [-1] * 2, "locked": [-1] * 2,
           "full_hill_stable": [-1] * 2, "full_hill_modulus": [math.nan] * 2}
    for s in solutions:
        k = 0 if s.root == "+" else 1
        out["a"][k], out["hill_stable"][k] = s.a, int(s.hill_stable)
        if s.full_hill_stable is not None:  # None: the balance did not converge to this root
            out["full_hill_stable"][k] = int(s.full_hill_stable)
            out["full_hill_modulus"][k] = float(np.max(np.abs(s.full_hill_multipliers)))
        if s.orbit is not None:
            out["orbit_a1"][k] = s.orbit.A[1]
            out["orbit_floquet"][k] = float(np.max(np.abs(s.orbit.multipliers)))
            out["orbit_stable"][k] = int(s.orbit.stable)
            out["locked"][k] = int(bool(s.locked))
    out["stable_roots"] = sum(v == 1 for v in out["orbit_stable"])
    return out


def validity_errors(d: Drive) -> tuple[np.ndarray, np.ndarray, int]:
    """``|A₁ − A₁(balance, N = 10)|`` on the largest branch for the μ-expansion at
    :data:`MU_ORDERS` and harmonic balance with :data:`VALIDITY_BALANCE_HARMONICS` harmonics
    (NaN where a method refuses: a fold, a diverging μ-series, a balance that does not
    converge — and everywhere when the judge itself does not converge), and the branch count.

    The measure of ``charts._validity_errors``, with the judge's convergence checked."""
    mu_err = np.full(len(MU_ORDERS), np.nan)
    hb_err = np.full(len(VALIDITY_BALANCE_HARMONICS), np.nan)
    branches = first_order_branches(d)
    judge = try_balance(d, branches[0], JUDGE_HARMONICS, converged=True) if branches else None
    if judge is None:
        return mu_err, hb_err, len(branches)
    truth = amplitudes(judge.coefficients, 0.0, 1)[0][1]
    for k, order in enumerate(MU_ORDERS):
        mu = mu_expansion(d, branches[0], order)
        if len(mu.coefficients) > order and mu.converged:
            mu_err[k] = abs(amplitudes(*mu.partial(order), 1)[0][1] - truth)
    for k, harmonics in enumerate(VALIDITY_BALANCE_HARMONICS):
        hb = try_balance(d, branches[0], harmonics, converged=True)
        if hb is not None:
            hb_err[k] = abs(amplitudes(hb.coefficients, 0.0, 1)[0][1] - truth)
    return mu_err, hb_err, len(branches)


def _validity(omega: float, force: float, eps: float, Q: float) -> dict:
    mu_err, hb_err, count = validity_errors(Drive(eps, force, omega, Q))
    return {"mu_error": mu_err, "balance_error": hb_err, "branches": count}


# --- the kinds of map ----------------------------------------------------------------------------

@dataclass(frozen=True)
class Field:
    """One stored variable: ``float64`` (NaN = none) or an ``int8`` count or flag (−1 = none)."""

    name: str
    long_name: str
    dtype: str = "float64"
    dims: tuple[str, ...] = ()  # beyond the grid's axes
    flag: bool = False  # int8 verdict: 1 yes, 0 no, −1 none
    unset: str = "not computed"  # what −1 means in an int8 count

    @property
    def fill(self) -> float | int:
        """The value of a point not computed: NaN for ``float64``, −1 for ``int8``."""
        return math.nan if self.dtype == "float64" else -1

    def attrs(self) -> dict:
        """The variable's attributes in the store: its ``long_name``, with the flag values and
        their meanings for a flag, or a note on −1 for a count."""
        out: dict = {"long_name": self.long_name}
        if self.flag:
            out |= {"flag_values": [-1, 0, 1], "flag_meanings": "none no yes"}
        elif self.dtype == "int8":
            out["comment"] = f"-1: {self.unset}"
        return out


@dataclass(frozen=True)
class Kind:
    """A kind of map: its axes, the dimensions its fields add, what one point computes."""

    name: str
    description: str
    axes: tuple[str, ...]
    extra: tuple[tuple[str, tuple[int, ...]], ...]  # dimension -> coordinate values
    fields: tuple[Field, ...]
    point: Callable[..., dict]  # axis values (floats, by name) -> field values
    warm_up: tuple[tuple[str, float], ...]  # a point that runs every compiled kernel it uses
    points_per_chunk: int  # default block size: ~1 s of work
    headline: str  # the field a figure draws (its last entry along any extra dimension)
    settings: tuple[tuple[str, object], ...]  # constants its numbers depend on
    builtin: bool = True  # the notes' axes (omega, force, eps, Q), checked as a Drive's
    positive: tuple[str, ...] = ()  # an equation's axes that must be > 0 (its drive frequency)

    @property
    def point_seconds(self) -> float:
        """The wall time of one point on one worker: a default block is ~1 s of work."""
        return 1.0 / self.points_per_chunk

    @property
    def extra_sizes(self) -> dict[str, int]:
        """The length of each dimension the fields add beyond the grid's axes."""
        return {dim: len(values) for dim, values in self.extra}


AXES = ("omega", "force", "eps", "Q")
# NOTE: the order of every grid's dimensions. Blocks take whole trailing axes, so the axes that
# usually have few values (ε, Q) come last and ω, the one swept finely, first.
BRANCH = ("branch", (1, 2, 3))
# NOTE: branches are numbered by first-order amplitude, largest first (first_order_branches).

RESPONSE = Kind(
    "response", "steady 1:1 amplitude r of every branch (harmonic balance, N = 10) and its "
    "one-harmonic stability", AXES, (BRANCH,),
    (Field("branches", "number of first-order 1:1 branches", "int8"),
     Field("r", "r = sqrt(A1^2 + B1^2), harmonic balance N = 10", dims=("branch",)),
     Field("stable", "one-harmonic stability dG/du > 0", "int8", ("branch",), flag=True),
     Field("r_stable_max", "largest stable r"),
     Field("r_stable_min", "smallest stable r")),
    _response, (("omega", 1.2), ("force", 0.3), ("eps", 0.1), ("Q", 20.0)),
    256, "r_stable_max", (("harmonics", RESPONSE_HARMONICS),))
# NOTE: 256 points: ~3 ms a point (balance on up to three branches), ~1 s a task.

STABILITY = Kind(
    "stability", "Floquet stability of every distinct 1:1 orbit (shooting from every branch "
    "and from the continued harmonic balance)",
    AXES, (BRANCH,),
    (Field("branches", "number of first-order 1:1 branches", "int8"),
     Field("orbits", "distinct periodic orbits found by shooting", "int8"),
     Field("stable_orbits", "distinct Floquet-stable orbits", "int8"),
     Field("max_floquet", "largest Floquet modulus over the orbits"),
     Field("r", "r = sqrt(A1^2 + B1^2) of the orbit the branch stands for", dims=("branch",)),
     Field("floquet", "largest Floquet modulus of the orbit the branch stands for",
           dims=("branch",)),
     Field("orbit_stable", "Floquet stability of the orbit the branch stands for", "int8",
           ("branch",), flag=True)),
    _stability, (("omega", 1.2), ("force", 0.3), ("eps", 0.1), ("Q", 20.0)),
    20, "stable_orbits",
    (("orbit_harmonics", ORBIT_HARMONICS), ("continuation_harmonics", CONTINUATION_HARMONICS),
     ("same_orbit", SAME_ORBIT)))
# NOTE: 20 points: ~50 ms a point damped (the balance continued in the drive from rest at each
# point, its crossings and the one-harmonic roots shot; a 64-point ω line on [0.5, 2] at
# ε 0.1, f 0.3, Q 20), ~110 ms undamped (whose seeds are now complete where the continuation
# passes no singular point); ~1 s a task.

SUBHARMONIC = Kind(
    "subharmonic", "the 1/3 subharmonic of the undamped oscillator (eq. 10.87), omega its "
    "frequency, the drive at 3 omega", ("omega", "force", "eps"), (("root", (1, -1)),),
    (Field("exists", "eq. 10.87 has real amplitudes", "int8", flag=True),
     Field("F", "F = f/(1 - 9 omega^2), the cos 3tau amplitude"),
     Field("a", "a(f), the first harmonic of root +/-", dims=("root",)),
     Field("hill_stable", "Hill-equation stability", "int8", ("root",), flag=True),
     Field("orbit_a1", "first harmonic of the true orbit (shooting, 3 drive periods)",
           dims=("root",)),
     Field("orbit_floquet", "largest Floquet modulus of the true orbit", dims=("root",)),
     Field("orbit_stable", "Floquet stability of the true orbit", "int8", ("root",),
           flag=True),
     Field("locked", "a simulation 1 % off the true orbit stays on it", "int8", ("root",),
           flag=True),
     Field("stable_roots", "roots whose true orbit is stable", "int8"),
     Field("full_hill_stable", "full Hill stability: the variational equation about the "
           "harmonic-balance orbit, not the notes' q0 = a cos tau + F cos 3tau", "int8",
           ("root",), flag=True),
     Field("full_hill_modulus", "largest multiplier modulus of the full Hill equation",
           dims=("root",))),
    _subharmonic, (("omega", 1.5), ("force", 0.1), ("eps", 0.1)),
    8, "stable_roots", (("full_hill_harmonics", SUBHARMONIC_HARMONICS),))
# NOTE: 8 points: ~0.12 s a point (Hill, shooting over 3 periods, a locking simulation).

VALIDITY = Kind(
    "validity", "error in A1 of the mu-expansion and of low-order harmonic balance against "
    "harmonic balance N = 10, largest branch", AXES,
    (("mu_order", MU_ORDERS), ("harmonics", VALIDITY_BALANCE_HARMONICS)),
    (Field("mu_error", "|A1 - A1(balance N = 10)|, mu-expansion", dims=("mu_order",)),
     Field("balance_error", "|A1 - A1(balance N = 10)|, harmonic balance",
           dims=("harmonics",)),
     Field("branches", "number of first-order 1:1 branches", "int8")),
    _validity, (("omega", 0.6), ("force", 1.0), ("eps", 0.1), ("Q", math.inf)),
    32, "mu_error", (("judge_harmonics", JUDGE_HARMONICS),))
# NOTE: 32 points: ~25 ms a point (μ-expansion to order 10 five times, three balances).

# --- computing blocks ----------------------------------------------------------------------------

def compute_block(kind: str | Kind, values: tuple[np.ndarray, ...]) -> dict[str, np.ndarray]:
    """Every field of ``kind`` (a :class:`Kind` or the name of a built-in one) on the block
    spanned by ``values`` (one array per axis): the task each worker runs, and the serial
    loop's body."""
    kind = kind if isinstance(kind, Kind) else kind_named(kind)
    shape = tuple(v.size for v in values)
    sizes = kind.extra_sizes
    out = {f.name: np.full(shape + tuple(sizes[d] for d in f.dims), f.fill, dtype=f.dtype)
           for f in kind.fields}
    for index in itertools.product(*(range(n) for n in shape)):
        point = {a: float(v[i]) for a, v, i in zip(kind.axes, values, index, strict=True)}
        for name, value in kind.point(**point).items():
            out[name][index] = value
    return out


def kernel_signatures() -> dict[str, int]:
    """Compiled signatures of each numba kernel in :mod:`numerics` in this process: a warm
    worker's counts stay fixed from task to task (no recompiling)."""
    from numba.core.registry import CPUDispatcher

    from ..numerics import floquet, integrate, shooting

    return {name: len(f.signatures) for module in (integrate, floquet, shooting)
            for name, f in vars(module).items() if isinstance(f, CPUDispatcher)}


def warm_up(kind: str | Kind) -> dict[str, int]:
    """Run the kind's warm-up point: loads (or compiles, once, into numba's on-disk cache)
    every kernel its tasks call, so that no task pays for it. Returns
    :func:`kernel_signatures`."""
    kind = kind if isinstance(kind, Kind) else kind_named(kind)
    compute_block(kind, tuple(np.array([dict(kind.warm_up)[a]]) for a in kind.axes))
    return kernel_signatures()


class WarmUp(WorkerPlugin):
    """A worker plugin: :func:`warm_up` once on every worker, including workers that join
    later (``distributed`` runs ``setup`` when a worker starts or the plugin is registered)."""

    def __init__(self, kind: str | Kind) -> None:
        kind = kind if isinstance(kind, Kind) else kind_named(kind)
        self.kind = kind
        import hashlib

        digest = hashlib.sha256(json.dumps(kind.settings, default=str).encode()).hexdigest()
        self.name = f"lindstedt-sweep-warm-up-{kind.name}-{digest[:12]}"

    def setup(self, worker: object) -> None:
        """Run :func:`warm_up` for the plugin's kind on ``worker`` as it starts."""
        warm_up(self.kind)


# --- a user's equation: any of its parameters an axis ------------------------------------------

EQUATION_BRANCHES = 5
# NOTE: orbits stored per point, largest r first: a quadratic-and-cubic force has up to five
# 1:1 orbits near its folds (three is the cubic's most); more are counted, not stored.


@dataclass(frozen=True)
class EquationSpec:
    """What one point of an equation's map needs: the text, the values fixed for the whole
    map, the drive frequency's name (passed as ω to the response), the subharmonic's n."""

    kind: str
    text: str
    values: tuple[tuple[str, str], ...]
    frequency: str
    n: int
    name: str


def _exact(value: float) -> str:
    """A float axis value as the exact rational the equation's parser takes (0.3 -> 3/10)."""
    return str(Fraction(repr(value)))


def _point_values(spec: EquationSpec, axis: Mapping[str, float]) -> dict[str, str]:
    return {**dict(spec.values), **{k: _exact(v) for k, v in axis.items()}}


def _equation_response(spec: EquationSpec, **axis: float) -> dict:
    """Every 1:1 orbit at one point (:func:`analysis.periodic.periodic_orbits`: the balance
    continued in the drive amplitude, each crossing shot), largest r first, with its Floquet
    verdict."""
    from ..analysis.periodic import periodic_orbits
    from ..analysis.polynomial import driven_equation

    values = _point_values(spec, axis)
    omega = float(Fraction(values.pop(spec.frequency)))
    try:
        de = driven_equation(spec.text, values, omega, spec.name)
    except InputError:  # refused at this point (e.g. a coefficient made 0): no orbit stored
        linear = _undriven_linear_part(spec, values)
        if linear is None:
            return {}
        return _rest_state(*linear, omega)
    found = periodic_orbits(de, ORBIT_HARMONICS, shoot_harmonics=1)
    shot = [o.orbit for o in found.orbits if o.orbit is not None]
    return _branches(shot, len(shot))


def _undriven_linear_part(spec: EquationSpec, values: dict[str, str]
                          ) -> tuple[np.ndarray, np.ndarray] | None:
    """``(K, C)`` of ``q̈ + C q̇ + K q + … = 0`` where the drive vanishes at ``values`` (its
    amplitude 0, e.g. an axis f = 0) and q = 0 is an equilibrium; ``None`` where the equation
    is refused for any other reason."""
    import sympy as sp

    from ..derive.models import oscillator

    values = dict(values)
    small = values.pop("eps", None)
    try:
        osc = oscillator(spec.text, values, spec.name)
    except InputError:
        return None
    subs = {} if small is None else {osc.equation.small: sp.Rational(small)}
    force = sp.expand(osc.force.xreplace(subs))
    q, v = osc.coordinate, osc.velocity
    if osc.drive.xreplace(subs) != 0 or osc.parametric != 0 or force.free_symbols - {q, v} \
            or not force.is_polynomial(q, v):
        return None
    poly = sp.Poly(force, q, v)
    if poly.coeff_monomial(1) != 0:
        return None  # q = 0 is no equilibrium
    k, c = (float(poly.coeff_monomial(m)) for m in (q, v))
    if k == 0 and c == 0:
        return None  # no linear term: refused as driven_equation refuses it
    return np.array([[k]]), np.array([[c]])


def _system_undriven_linear_part(spec: EquationSpec, values: dict[str, str]
                                 ) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]] | None:
    """:func:`_undriven_linear_part` of a system ``ẍ + M⁻¹C ẋ + M⁻¹K x + … = 0``, with its
    coordinates (its checks those of :func:`analysis.systems.driven_system`: damped, every
    linear mode an oscillation); ``None`` where it is refused for any other reason."""
    import sympy as sp

    from ..derive.system import _lowered, _read

    try:
        coordinates, exprs, _, _ = _read(spec.text, True)
        given = {sp.Symbol(k): sp.Rational(v) for k, v in values.items()}
        if any(d.xreplace(given) != 0 for _, d in exprs):
            return None  # driven here: refused for another reason
        system = _lowered(spec.text, coordinates, [e.xreplace(given) for e, _ in exprs],
                          allow_damping=True)
    except InputError:
        return None
    if system.damping is None and not any(f.has(*system.velocities) for f in system.force):
        return None  # no damping: no steady state (as driven_system refuses)
    if not all(sp.N(lam, 30) > 0 for lam in system.modes()):
        return None
    K = np.array(system.stiffness, dtype=float)
    C = np.zeros_like(K) if system.damping is None else np.array(system.damping, dtype=float)
    return K, C, tuple(map(str, system.coordinates))


def _rest_state(K: np.ndarray, C: np.ndarray, omega: float, coordinates: Sequence[str] = ()
                ) -> dict:
    """The fields of the response where the drive vanishes: the rest state ``x = 0`` (the
    start of the continuation from rest, and every orbit there is, where the power balance
    holds: ``⟨ẋᵀCẋ⟩ = 0`` with C positive definite leaves no motion), ``r = 0``, its Floquet
    multipliers ``exp(λT)`` over one drive period ``T = 2π/ω``, λ the eigenvalues of the linear
    system ``ẍ + Cẋ + Kx = 0``."""
    n = len(K)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-K, -C]])
    modulus = float(np.max(np.abs(np.exp(np.linalg.eigvals(A) * 2 * math.pi / omega))))
    out = _orbit_fields([0.0], [modulus], 1)
    zero = [0.0] + [math.nan] * (EQUATION_BRANCHES - 1)
    out.update({f"r_{x}": zero for x in coordinates})
    return out


def _branches(shot: list, count: int) -> dict:
    """The fields of the shot orbits ``shot`` (``count`` found)."""
    return _orbit_fields([math.hypot(o.A.get(1, 0.0), o.B.get(1, 0.0)) for o in shot],
                         [float(np.max(np.abs(o.multipliers))) for o in shot], count)


def _orbit_fields(r_all: list[float], floquet_all: list[float], count: int) -> dict:
    """The stored fields of orbits of first-harmonic sizes ``r_all`` and largest Floquet
    moduli ``floquet_all`` (stable below 1, a damped system's verdict), the first
    :data:`EQUATION_BRANCHES` kept."""
    r, stable = [math.nan] * EQUATION_BRANCHES, [-1] * EQUATION_BRANCHES
    floquet = [math.nan] * EQUATION_BRANCHES
    for k, (size, modulus) in enumerate(zip(r_all[:EQUATION_BRANCHES],
                                            floquet_all[:EQUATION_BRANCHES], strict=True)):
        r[k], stable[k], floquet[k] = size, int(modulus < 1), modulus
    kept = [x for x, s in zip(r, stable, strict=True) if s == 1]
    return {"orbits": count, "stable_orbits": sum(m < 1 for m in floquet_all), "r": r,
            "stable": stable, "floquet": floquet, "r_stable_max": max(kept, default=math.nan),
            "r_stable_min": min(kept, default=math.nan)}


def _system_response(spec: EquationSpec, **axis: float) -> dict:
    """Every periodic response of a driven system at one point (the balance at
    :data:`ORBIT_HARMONICS` harmonics, seeded by the drive continued from rest up to the
    power-balance bound: :meth:`analysis.systems.SystemBalance.solutions`), largest first,
    with the Floquet verdict of its variational equation; ``r`` is the first harmonic over
    every coordinate, ``√Σ_i (A_i1² + B_i1²)``, and ``r_<x>`` each coordinate's."""
    from ..analysis.systems import SystemBalance, driven_system

    values = _point_values(spec, axis)
    omega = float(Fraction(values.pop(spec.frequency)))
    try:
        sb = SystemBalance.of(driven_system(spec.text, values), ORBIT_HARMONICS)
    except InputError:  # refused at this point (e.g. the damping made 0): no orbit stored
        linear = _system_undriven_linear_part(spec, values)
        if linear is None:
            return {}
        K, C, coordinates = linear
        return _rest_state(K, C, omega, coordinates)
    found, _, _ = sb.solutions(omega)
    found.sort(key=sb.fine.first_harmonic, reverse=True)
    floquet = list(sb.multiplier(np.array(found), np.full(len(found), omega))) if found else []
    out = _orbit_fields([sb.fine.first_harmonic(x) for x in found], floquet, len(found))
    each = np.full((sb.system.size, EQUATION_BRANCHES), math.nan)  # in r's order
    for k, z in enumerate(found[:EQUATION_BRANCHES]):
        each[:, k] = sb.fine.first_harmonics(z)
    out.update({f"r_{x}": list(row) for x, row in zip(sb.system.coordinates, each, strict=True)})
    return out


def _equation_subharmonic(spec: EquationSpec, **axis: float) -> dict:
    """Every orbit of n drive periods at one point (:func:`subharmonic.subharmonic_orbits`,
    without the onset), largest r first, with its Floquet verdict."""
    from ..analysis.subharmonic import subharmonic_equation, subharmonic_orbits

    values = _point_values(spec, axis)
    try:
        problem = subharmonic_equation(spec.text, values, None, spec.n, spec.name)
    except InputError:  # refused at this point (e.g. the coupling term made 0): none stored
        return {}
    found = subharmonic_orbits(problem, onset=False)
    shot = [o.orbit for o in found.orbits if o.orbit is not None]
    return {"exists": int(found.exists), **_branches(shot, len(found.orbits))}


@dataclass(frozen=True)
class KindOfMap:
    """One kind of map for every problem it takes: the notes' Duffing over its axes
    (``notes``: a fixed :class:`Kind`), one user's equation and a system (each a builder of
    the :class:`Kind` of that problem, its parameters the axes; ``None``: refused, and
    :meth:`why_not` says why)."""

    name: str
    notes: Kind | None
    equation: Callable[..., Kind] | None = None
    system: Callable[..., Kind] | None = None
    what: str = ""  # a system's map in a few words (the refusal that lists them)
    template: Kind | None = None  # without a notes' map: what the cost estimate reads

    def why_not(self, problem: Problem | None) -> str | None:
        """``None`` where this kind takes ``problem`` (``None``: the notes' flags), else why
        not, in one line."""
        if problem is None:
            return None if self.notes is not None else (
                f"sweep {self.name}: give a SYSTEM (or an equation): its parameters are the "
                "axes, --axis NAME=A:B:N")
        if problem.one_coordinate and self.equation is None:
            takes = ", ".join(k.name for k in KINDS.values() if k.equation is not None)
            return (f"sweep {self.name} EQUATION: the {self.name} map is the notes' "
                    f"(μ-expansion of q + eps q^3); with an equation use {takes}")
        if not problem.one_coordinate and self.system is None:
            takes = " or ".join(f"{k.name} ({k.what})" for k in KINDS.values()
                                if k.system is not None)
            return f"sweep {self.name} SYSTEM: a system's map is {takes}"
        return None


def _orbits_kind(kind: str, text: str, spec: EquationSpec, axes: tuple[str, ...],
                 common: tuple[Field, ...], settings: tuple, frequency: str) -> Kind:
    """One equation's ``response`` or ``stability`` map (one map: every orbit shot, its
    Floquet verdict)."""
    return Kind(kind, f"every 1:1 orbit of {text} with its Floquet verdict", axes,
                (_EQUATION_BRANCH,), common, functools.partial(_equation_response, spec),
                tuple((a, 1.0) for a in axes), 4, "r_stable_max", settings, builtin=False,
                positive=(frequency,))


def _subharmonic_kind(kind: str, text: str, spec: EquationSpec, axes: tuple[str, ...],
                      common: tuple[Field, ...], settings: tuple, frequency: str) -> Kind:
    """One equation's orbits of n drive periods."""
    return Kind("subharmonic", f"orbits of {spec.n} drive periods of {text}", axes,
                (_EQUATION_BRANCH,), (Field("exists", "an orbit of n drive periods was found",
                                            "int8", flag=True), *common),
                functools.partial(_equation_subharmonic, spec), tuple((a, 1.0) for a in axes),
                4, "stable_orbits", settings, builtin=False, positive=(frequency,))


def _system_kind(kind: str, text: str, spec: EquationSpec, axes: tuple[str, ...],
                 common: tuple[Field, ...], settings: tuple, frequency: str,
                 coordinates: tuple[str, ...] = ()) -> Kind:
    """A system's map: every periodic response with the Floquet verdict of its variational
    equation, ``r`` over every coordinate and ``r_<x>`` each coordinate's."""
    each = tuple(Field(f"r_{x}", f"r of {x} = sqrt(A1^2 + B1^2) of each orbit (in r's "
                       "order)", dims=("branch",)) for x in coordinates)
    clash = sorted(set(axes) & {f.name for f in each})
    if clash:
        raise InputError(f"--axis {clash[0]}: the store holds a field of that name; rename "
                         "the parameter in the system")
    return Kind(kind, f"every periodic response of the system {text} (harmonic balance, "
                "r over every coordinate) with the Floquet verdict of its variational "
                "equation", axes, (_EQUATION_BRANCH,), (*common, *each),
                functools.partial(_system_response, spec), tuple((a, 1.0) for a in axes), 4,
                "r_stable_max", settings, builtin=False, positive=(frequency,))


# --- a system's spectral submanifold: any of its parameters an axis ----------------------------

SSM_ORDER = 7
# NOTE: ``lindstedt ssm``'s default order (cli.ssm.DEFAULT_ORDER).
SSM_FRC_POINTS = 500
# NOTE: the forced response's default grid (cli.ssm.FRC_POINTS), ±20 % about each point's
# |λ| (analysis.ssm.DEFAULT_SPAN): for two coordinates ~0.17 s a point (500 bordered solves
# batched, the steady states' polynomial roots and amplitudes), the SSM itself ~15 ms at
# order 7 (measured): the forced response is the point's work, the SSM a large model's.
SSM_CACHE = 64
# NOTE: SSMs kept in each process by ssm_of (an SSM of a system written as text is a few
# KiB): a sweep over drive amplitudes alone needs one, a grid of damping values one each.
SSM_POINTS_PER_CHUNK = 6
FOLDS_MAX = 127
# NOTE: the int8 count's largest value (more folds than that are stored as 127).


@dataclass(frozen=True)
class SsmSpec:
    """What one point of an ``ssm`` map needs: the system's text, the values fixed for the
    whole map (exact rationals), the mode, the order, and the forced response's grid
    ``(A, B, N)`` (``None``: ±20 % about each point's ``|λ|``, :data:`SSM_FRC_POINTS`)."""

    text: str
    values: tuple[tuple[str, str], ...]
    mode: int
    order: int
    omega: tuple[float, float, int] | None


@functools.lru_cache(maxsize=8)
def _system_parts(text: str) -> tuple[tuple[str, ...], tuple, frozenset[str]]:
    """The coordinates of the (driven) system ``text``, each equation's autonomous part and
    its drive's amplitude (:func:`derive.system._read`), and the parameters of the autonomous
    parts: those of M, C, K and f, on which the SSM depends (the drive's alone do not)."""
    from ..derive.system import _read

    coordinates, exprs, names, _ = _read(text, True)
    autonomous = frozenset(str(x) for e, _ in exprs for x in e.free_symbols) & names
    return tuple(coordinates), tuple(exprs), autonomous


def _rationals(values: Sequence[tuple[str, str]]) -> dict:
    import sympy as sp

    return {sp.Symbol(k): sp.Rational(v) for k, v in values}


@functools.lru_cache(maxsize=SSM_CACHE)
def ssm_of(text: str, autonomous: tuple[tuple[str, str], ...], mode: int, order: int
           ) -> object:
    """The SSM (:func:`analysis.ssm.ssm`) of ``mode`` to ``order`` of the autonomous part
    ``M x'' + C x' + K x + f(x, x') = 0`` of the system ``text`` at the exact values
    ``autonomous`` (every parameter of M, C, K and f, none of the drive's), or the first line
    of its refusal (an internal resonance, a mode that does not oscillate, …). Cached in each
    process (:data:`SSM_CACHE`): a sweep computes one SSM per distinct value of these
    parameters on each worker, whatever the drive's axes; its ``matrices`` have no drive."""
    from ..analysis.ssm import ssm
    from ..derive.system import _lowered

    coordinates, exprs, _ = _system_parts(text)
    given = _rationals(autonomous)
    try:
        system = _lowered(text, list(coordinates), [e.xreplace(given) for e, _ in exprs],
                          allow_damping=True)
        return ssm(system, mode, order)
    except (InputError, np.linalg.LinAlgError, ArithmeticError) as e:
        return (str(e).splitlines() or [type(e).__name__])[0]


def _system_ssm(spec: SsmSpec, **axis: float) -> dict:
    """One point of an ``ssm`` map: the SSM of the point's M, C, K, f (:func:`ssm_of`,
    computed once per distinct value of their parameters), its forced response
    (:func:`analysis.ssm.forced_response`, every steady state at each drive frequency, as
    :func:`analysis.ssm.reduce` computes it) under this point's drive. Refused SSM: nothing
    stored (NaN, ``folds`` −1); refused forced response (the drive resonant with another
    mode, a drive amplitude holding a coordinate): the SSM's fields alone; a drive that
    vanishes: the rest state, every peak 0. The peaks are over the steady states inside the
    SSM's estimated radius (``reduce`` drops the others; ``beyond_radius`` says where)."""
    from dataclasses import replace

    from ..analysis.ssm_forced import DEFAULT_SPAN, forced_response

    values = _point_values(spec, axis)
    coordinates, exprs, autonomous = _system_parts(spec.text)
    model = ssm_of(spec.text, tuple(sorted((k, v) for k, v in values.items() if k in autonomous)),
                   spec.mode, spec.order)
    if isinstance(model, str):
        return {}
    lam = complex(model.lam)
    gamma1 = complex(model.gamma[1]) if len(model.gamma) > 1 else complex(math.nan, math.nan)
    out = {"omega0": abs(lam), "damping_ratio0": -lam.real / abs(lam),
           "gamma1_re": gamma1.real, "gamma1_im": gamma1.imag}
    given = _rationals(tuple(values.items()))
    drive = [d.xreplace(given) for _, d in exprs]
    if not all(d.is_Rational for d in drive):
        return out  # a coordinate in a drive's amplitude: parametric, no forced response
    F = np.array(drive, dtype=float)
    if not F.any():  # no drive at this point: the rest state
        return {**out, **{f"peak_{x}": 0.0 for x in coordinates}, "rho_peak": 0.0,
                "folds": 0, "beyond_radius": 0}
    lo, hi, points = spec.omega or ((1 - DEFAULT_SPAN) * abs(model.lam),
                                    (1 + DEFAULT_SPAN) * abs(model.lam), SSM_FRC_POINTS)
    driven = replace(model, matrices=replace(model.matrices, drive=F))
    try:
        response = forced_response(driven, np.linspace(lo, hi, points),
                                   np.arange(len(coordinates)))
    except (InputError, np.linalg.LinAlgError, ArithmeticError):
        return out
    out["folds"] = min(len(response.folds), FOLDS_MAX)
    out["beyond_radius"] = int(response.beyond > 0)
    if response.states:
        peaks = np.max([s.amplitude for s in response.states], axis=0)
        out.update({f"peak_{x}": float(a) for x, a in zip(coordinates, peaks, strict=True)})
        top = max(response.states, key=lambda s: s.rho)
        out["omega_peak"], out["rho_peak"] = top.omega, top.rho
    return out


def _ssm_kind(text: str, values: Mapping[str, str], axes: tuple[str, ...], mode: int,
              order: int, omega: tuple[float, float, int] | None) -> Kind:
    """A system's (or an equation's) ``ssm`` map: any of its parameters but the drive
    frequency an axis (the forced response at each point spans the frequencies ``omega``),
    the rest exact values; refused in one line: no drive, the drive frequency an axis or a
    value, a parameter not an axis or a value or both, a value that is no exact rational, a
    mode, order or grid out of range, an axis named as a field."""
    from ..derive.equation import parse_expression
    from ..derive.system import system_parameters
    from ..limits import SSM_MAX_ORDER, SSM_MAX_POINTS, check_int

    check_int(mode, 1, None, f"--mode {mode!r}: a mode number 1, 2, …")
    check_int(order, 1, SSM_MAX_ORDER, f"--order {order!r}: the SSM is computed to order "
              f"1..{SSM_MAX_ORDER}")
    parameters, frequency = system_parameters(text)
    if frequency is None:
        raise InputError(f"system {text!r}: no drive; sweep ssm SYSTEM needs f*cos(w*t) on "
                         "the right of an equation")
    for flag, given in (("--axis", axes), ("--param", values)):
        if frequency in given:
            raise InputError(f"{flag} {frequency}: {frequency} is the drive frequency; each "
                             "point's forced response spans it (--omega A:B:N)")
    _check_names(text, set(parameters), axes, values)
    exact = {}
    for k, v in values.items():
        x = parse_expression(v, f"--param {k}")
        if not x.is_Rational:
            raise InputError(f"--param {k}={v}: an exact rational, e.g. 1/3")
        exact[k] = str(x)
    if omega is not None:
        lo, hi, points = omega
        check_int(points, 2, SSM_MAX_POINTS, f"--omega …:{points}: the forced response takes "
                  f"2..{SSM_MAX_POINTS} drive frequencies")
        if not 0 < lo < hi < math.inf:
            raise InputError(f"--omega {lo:g}:{hi:g}:{points}: give 0 < A < B")
        omega = (float(lo), float(hi), int(points))
    coordinates, _, _ = _system_parts(text)
    fields = (
        *(Field(f"peak_{x}", f"peak of max |{x}| over the forced response")
          for x in coordinates),
        Field("omega_peak", "drive frequency of the forced response's largest steady state "
              "(largest rho)"),
        Field("rho_peak", "rho (normal-form amplitude) of the largest steady state"),
        Field("beyond_radius", "steady states past the SSM's estimated radius were dropped "
              "(the peaks are those inside it)", "int8", flag=True),
        Field("folds", "folds of the forced response over the drive frequencies", "int8",
              unset="not computed, or the SSM or its forced response is refused at this "
              "point (lindstedt ssm SYSTEM there says why)"),
        Field("omega0", "|lambda|: the mode's linear natural frequency"),
        Field("damping_ratio0", "-Re(lambda)/|lambda|: the mode's linear damping ratio"),
        Field("gamma1_re", "Re gamma_1: rho' = rho (Re lambda + Re gamma_1 rho^2 + ...)"),
        Field("gamma1_im", "Im gamma_1: the backbone omega(rho) = Im lambda + Im gamma_1 "
              "rho^2 + ..."))
    clash = sorted(set(axes) & ({f.name for f in fields} | {"chunk", "done"}))
    if clash:
        raise InputError(f"--axis {clash[0]}: the store holds a field of that name; rename "
                         "the parameter in the system")
    grid = (f"±20 % about |lambda|, {SSM_FRC_POINTS} frequencies" if omega is None else
            f"omega {omega[0]:g}..{omega[1]:g}, {omega[2]} frequencies")
    settings = (("system", text), ("values", dict(sorted(exact.items()))), ("mode", mode),
                ("order", order), ("omega", None if omega is None else list(omega)))
    spec = SsmSpec(text, tuple(sorted(exact.items())), mode, order, omega)
    return Kind("ssm", f"the SSM of mode {mode} of {text} to order {order} and its forced "
                f"response ({grid})", axes, (), fields, functools.partial(_system_ssm, spec),
                tuple((a, 1.0) for a in axes), SSM_POINTS_PER_CHUNK, f"peak_{coordinates[0]}",
                settings, builtin=False)


def _ssm_needs_a_problem(**axis: float) -> dict:
    raise InputError(KINDS["ssm"].why_not(None))


SSM_TEMPLATE = Kind("ssm", "the SSM of one mode of a system at each point (the template: "
                    "give a SYSTEM)", (), (), (), _ssm_needs_a_problem, (),
                    SSM_POINTS_PER_CHUNK, "omega0", ())


_EQUATION_BRANCH = ("branch", tuple(range(1, EQUATION_BRANCHES + 1)))

KINDS: Mapping[str, KindOfMap] = {k.name: k for k in (
    KindOfMap("response", RESPONSE, _orbits_kind, _system_kind,
              "every periodic response with its Floquet verdict"),
    KindOfMap("stability", STABILITY, _orbits_kind),
    KindOfMap("subharmonic", SUBHARMONIC, _subharmonic_kind),
    KindOfMap("validity", VALIDITY),
    KindOfMap("ssm", None, _ssm_kind, _ssm_kind,
              "one mode's spectral submanifold and its forced response", SSM_TEMPLATE),
)}
# NOTE: the one table of kinds: with an equation, response and stability are one map (every
# orbit shot, its Floquet verdict); validity is the notes' μ-expansion's and takes no equation;
# a system's map is response or ssm; ssm takes no notes' axes (its builder, _ssm_kind, takes
# the mode, the order and the forced response's ω grid besides).


def kind_named(name: str) -> Kind:
    """The notes' :class:`Kind` called ``name``, or :class:`InputError` listing the kinds; a
    kind without a notes' map (``ssm``) gives its template, no axes, whose cost per point is
    what the cost estimate reads before the problem is (its point refuses: give a system)."""
    entry = KINDS.get(name)
    if entry is not None and entry.notes is None and entry.template is not None:
        return entry.template
    return kind_of(name)


def kind_of(kind: str, text: str | None = None, values: Mapping[str, str] | None = None,
            axes: Sequence[str] = (), n: int = 3, name: str = "oscillator", *,
            mode: int = 1, order: int = SSM_ORDER,
            omega: tuple[float, float, int] | None = None) -> Kind:
    """The :class:`Kind` of ``sweep KIND [PROBLEM]`` from :data:`KINDS`: without ``text`` the
    notes' (over omega, force, eps, Q); with an equation or a system, its parameters the axes
    (its drive frequency included), every other parameter a value in ``values``; refused in
    one line: a kind that does not take the problem (:meth:`KindOfMap.why_not`), an axis that
    names no parameter, a parameter both an axis and a value, a parameter with neither.
    ``ssm`` (:func:`_ssm_kind`) takes ``mode``, ``order`` and ``omega``, the forced response's
    grid ``(A, B, N)`` (``None``: ±20 % about each point's ``|λ|``, 500 frequencies); its
    drive frequency is no axis."""
    from ..analysis.polynomial import driven_form
    from ..analysis.subharmonic import check_n
    from ..analysis.systems import driven_system
    from ..derive.models import oscillator
    from ..derive.problem import read_problem
    from ..derive.system import system_parameters

    if kind not in KINDS:
        raise InputError(f"sweep kind {kind!r}: use one of {', '.join(KINDS)}")
    entry = KINDS[kind]
    problem = None if text is None else read_problem(text)
    why = entry.why_not(problem)
    if why is not None:
        raise InputError(why)
    if problem is None:
        return entry.notes
    values = dict(values or {})
    if kind == "subharmonic":
        check_n(n)
    if not axes:
        raise InputError("sweep EQUATION: give at least one axis, --axis NAME=A:B:N")
    if kind == "ssm":
        return _ssm_kind(text, values, tuple(axes), mode, order, omega)
    # NOTE: a system's map holds a field per coordinate (r_x1, …): another Kind's fields
    system = not problem.one_coordinate
    if system:
        parameters, frequency = system_parameters(text)
        if frequency is None:
            raise InputError(f"system {text!r}: no drive; sweep {kind} SYSTEM needs "
                             "f*cos(w*t) on the right of an equation")
        names = {*parameters, frequency}
    else:
        osc = oscillator(text, {}, name)
        names = {str(p) for p in osc.equation.parameters}
        if osc.equation.small is not None:
            names.add("eps")
    _check_names(text, names, axes, values)
    taken = {f.name for f in (*STABILITY.fields, *SUBHARMONIC.fields)} | {"branch", "chunk",
                                                                          "done"}
    clash = sorted(set(axes) & taken)
    if clash:
        raise InputError(f"--axis {clash[0]}: the store holds a field of that name; rename the "
                         "parameter in the equation")
    if system:
        coordinates = tuple(str(x) for x in driven_system(
            text, {**values, **{a: "1" for a in axes if a != frequency}}).coordinates)
    else:
        frequency = _frequency_name(osc, text, name)
        form = driven_form(text, {**values, **{a: "1" for a in axes if a != frequency}},
                           name, f"sweep {kind}", "a polynomial force and one drive "
                           "f*cos(w*t)", True)
        if len(form.drives) != 1:
            raise InputError(f"{name} ({text}): sweep {kind} takes one drive f*cos(w*t), not "
                             f"{len(form.drives)}")
    spec = EquationSpec(kind, text, tuple(sorted(values.items())), frequency, n, name)
    common = (
        Field("orbits", "distinct periodic orbits found (shooting)", "int8",
              unset="not computed, or the equation is refused at this point (e.g. a damping "
              "axis at 0)"),
        Field("stable_orbits", "distinct Floquet-stable orbits", "int8"),
        Field("r", "r = sqrt(A1^2 + B1^2) of each orbit, largest first", dims=("branch",)),
        Field("stable", "Floquet stability of each orbit", "int8", ("branch",), flag=True),
        Field("floquet", "largest Floquet modulus of each orbit", dims=("branch",)),
        Field("r_stable_max", "largest stable r"),
        Field("r_stable_min", "smallest stable r"))
    settings = (("equation", text), ("values", dict(sorted(values.items()))), ("n", n),
                ("orbit_harmonics", ORBIT_HARMONICS))
    if system:
        return entry.system(kind, text, spec, tuple(axes), common, settings, frequency,
                            coordinates)
    return entry.equation(kind, text, spec, tuple(axes), common, settings, frequency)


def _check_names(text: str, names: set[str], axes: Sequence[str], values: Mapping[str, str]
                 ) -> None:
    """Every parameter in ``names`` an axis or a value, not both, and nothing else: else one
    line."""
    both = sorted(set(axes) & set(values))
    if both:
        raise InputError(f"--axis {both[0]} and --param {both[0]}: a parameter is an axis or a "
                         "value, not both")
    unknown = sorted(set(axes) - names) + sorted(set(values) - names)
    if unknown:
        raise InputError(f"{unknown[0]}: not a parameter of {text!r} (its parameters: "
                         f"{', '.join(sorted(names)) or 'none'})")
    missing = sorted(names - set(axes) - set(values))
    if missing:
        raise InputError(f"{missing[0]}: give it a value (--param {missing[0]}=...) or an axis "
                         f"(--axis {missing[0]}=A:B:N)")


def _frequency_name(osc: object, text: str, name: str) -> str:
    """The name ``w`` of the drive's ``f*cos(w*t)`` (an axis or a value); one line where the
    drive's argument is not a name times t."""
    import sympy as sp

    t = osc.equation.time
    for wave in sorted(osc.drive.atoms(sp.cos), key=str):
        c, _ = wave.args[0].as_independent(t, as_Add=False)
        symbols = sorted(str(s) for s in c.free_symbols)
        if len(symbols) == 1:
            return symbols[0]
    raise InputError(f"{name} ({text}): sweep needs the drive as f*cos(w*t) with the frequency "
                     "a parameter w (an axis or a --param)")
