"""The smallest model a scene needs: for each quantity, every method at every order, verified
against an independent reference and timed; the cheapest within the tolerance wins.

* :func:`choose_period`: the Duffing period (below);
* :func:`choose_solution`: q(t) — L–P orders against the exact Fourier series (nome) of cn;
* :func:`choose_driven`: the driven amplitudes A_n(ω) and the response r(ω) — one harmonic,
  μ-expansion orders, harmonic balance, shooting; with ``emit``, the emitted modules;
* named scenes (:data:`SCENES`) and the appendix's pendulum claims.

The methods themselves — what each applies to, how it derives, evaluates and lowers, and its
reference — are the records of :mod:`methods`; this module verifies them on a range, times
them, and picks by the recorded :data:`COST_MODEL`.  With ``--out`` the choice goes through
:mod:`compiler`.
"""

from __future__ import annotations

import math
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import mpmath
import numpy as np
from scipy.special import ellipj, ellipk

from .analysis.driven import Drive, amplitudes, first_order_branches, harmonic_balance
from .compiler import generate, generate_method
from .derive.lindstedt import derive
from .derive.models import Model, duffing, pendulum
from .derive.system import System
from .display import html_table
from .emit.render import load_generated
from .errors import InputError
from .methods.kernels import cn_fourier
from .methods.references import (
    DRIVEN_MAX,
    INTEGRATION_RTOLS,
    SHOOTING_STEPS,
    integrated_period,
    one_harmonic_amplitudes,
    quadrature_period,
    reference_period,
    reference_q,
)
from .methods.registry import (
    METHODS,
    SIMPLEST_FIRST,
    Candidate,
    Method,
    candidates,
    method,
    methods_for,
)
from .methods.targets import Progress
from .numerics.shooting import shoot

# NOTE: ``progress(done, total)`` lets the command line draw a bar over the long loops.


def quiet(done: int, total: int) -> None:
    """The default progress report: none."""


VERIFY_POINTS = 2001
# NOTE: points (Chebyshev-spaced, ends included) on which every candidate is verified.



def verification_points(x_min: float, x_max: float, n: int = VERIFY_POINTS) -> np.ndarray:
    """Chebyshev points on ``[x_min, x_max]``, ends included (where truncation errors peak)."""
    return x_min + (x_max - x_min) * (1 - np.cos(np.linspace(0, np.pi, n))) / 2


def best_seconds(run: Callable[[], object], runs: int = 3) -> float:
    """Wall time of ``run()``: one warm-up call (compilation, first touch), then the best of
    ``runs``."""
    run()
    best = np.inf
    for _ in range(runs):
        t0 = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - t0)
    return best


def ns_per_point(c: Candidate, points: int = 1_000_000, x_min: float = 0.0,
                 x_max: float = 0.5) -> float:
    """Measured cost of the compiled candidate on uniform points of the range, into a
    preallocated output: best of 5 runs, each at least a million points (small arrays, which
    stay in cache, are evaluated repeatedly)."""
    x = np.random.default_rng(0).uniform(x_min, x_max, points)
    out = np.empty_like(x)
    repeats = max(1, 1_000_000 // points)

    def run() -> None:
        for _ in range(repeats):
            c(x, out)

    return best_seconds(run, 5) / (points * repeats) * 1e9


T = TypeVar("T")
TIE = 0.15
# NOTE: costs within 15 % of the cheapest count as a tie, broken by a fixed order of methods
# (the simplest formula first). Every choice compares the recorded COST_MODEL, so it never
# depends on this run's timings (and what --out writes is the same on every run).

COST_MODEL = {
    quantity: {**{m.name: m.cost for m in METHODS if m.quantity == quantity},
               **{f"{m.name}, emitted": m.emitted_cost for m in METHODS
                  if m.quantity == quantity and m.emitted_cost}}
    for quantity in ("period", "q", "driven")
}
# NOTE: the recorded cost of each method and of its emitted module (ns per point, a polynomial
# in the order), read off the method records (:attr:`methods.registry.Method.cost`,
# ``emitted_cost``), where they are fitted and explained; a view by quantity and name for
# `choose` and `benchmarks/cost_model.py`.


def modelled_ns(quantity: str, method: str | Method, order: int) -> float:
    """The recorded cost of ``method`` at ``order`` for ``quantity`` (ns per point)."""
    return sum(c * order**i for i, c in enumerate(COST_MODEL[quantity][str(method)]))


def cheapest(items: list[T], cost: Callable[[T], float],
             method: Callable[[T], str | Method]) -> T:
    """The cheapest item, ties (within ``TIE``) going to the simplest method."""
    floor = min(cost(i) for i in items)
    tied = [i for i in items if cost(i) <= (1 + TIE) * floor]
    return min(tied, key=lambda i: SIMPLEST_FIRST.index(str(method(i)).removesuffix(", emitted")))


@dataclass(frozen=True)
class Choice:
    """The cheapest verified evaluator of the period ``T/2π`` on a range (the free Duffing
    oscillator's in ``x = εA²``, or a user's oscillator's): method and order, max relative
    error, measured ns per point, verification points, each method considered ``(name,
    order, error, ns)`` and the verified candidate, which ``--out`` lowers."""

    method: Method
    order: int
    max_error: float
    ns_per_point: float
    verified_on: int
    considered: tuple[tuple[str, int, float, float], ...]  # per method: order, error, ns
    candidate: Candidate | None = None  # what was verified: what --out lowers

    def _repr_html_(self) -> str:
        return choice_table(self, "choose_period: T/2π, max relative error")


def choice_table(c: Choice | DrivenChoice | SolutionChoice, what: str) -> str:
    """The methods a choice considered (each at its smallest sufficient order), the chosen one
    marked: the HTML of every choice record in Jupyter."""
    chosen = next((i for i, (m, o, _, _) in enumerate(c.considered)
                   if m.removesuffix(", emitted") == c.method and o == c.order), None)
    return html_table(
        f"{what}: {c.method} order {c.order}, error {c.max_error:.1e}, "
        f"{c.ns_per_point:.3g} ns/point, verified on {c.verified_on} points",
        ("method", "order", "max error", "ns/point"),
        [(m, o, f"{e:.1e}", f"{ns:.3g}") for m, o, e, ns in c.considered], marked=chosen)


USER_VERIFY_POINTS = 401
# NOTE: a user's oscillator is judged by quadrature (methods.quadrature_period, ~1.6 ms a
# point): 401 Chebyshev points of the range, ends included, where truncation errors peak.


def choose_period(tol: float, x_min: float, x_max: float,
                  progress: Progress = quiet, model: Model | None = None) -> Choice:
    """The cheapest method whose verified relative error on ``[x_min, x_max]`` is ≤ ``tol``
    (``progress(done, total)`` follows the timing of the candidates).  ``model``: another free
    polynomial oscillator, judged by quadrature, in its own variable (the free Duffing one, in
    x = εA², by default); only the methods that apply to it compete."""
    for name, v in (("tol", tol), ("x-min", x_min), ("x-max", x_max)):
        if not np.isfinite(v):
            raise InputError(f"{name} {v}: not finite")
    if tol <= 0:
        raise InputError(f"tol {tol}: must be > 0")
    if not x_min < x_max:
        raise InputError(f"range [{x_min}, {x_max}]: empty or reversed")
    if model is not None:
        why = method("period", "lindstedt").why_not(model)
        if why is not None:
            raise InputError(f"{model.name} ({model.source or model.title}): choose period "
                             f"does not apply: {why}")
        x = verification_points(x_min, x_max, USER_VERIFY_POINTS)
        exact = quadrature_period(model, x)
        if np.any(np.isnan(exact)):
            bad = x[np.isnan(exact)]
            raise InputError(f"range [{x_min}, {x_max}]: no bounded periodic swing from "
                             f"q(0) = A at {model.variable} = {bad[0]:g} (of "
                             f"{len(bad)} verification points)")
    else:
        if x_min <= -1:
            raise InputError(f"range [{x_min}, {x_max}] reaches x = εA² ≤ -1: no periodic "
                             "orbit (the separatrix is at x = -1)")
        x = verification_points(x_min, x_max)
        exact = reference_period(x)
    best_per_method: dict[Method, tuple[Candidate, float]] = {}
    best_error = np.inf
    for c in candidates(model=model) if model is not None else candidates():
        if c.method in best_per_method:
            continue
        with np.errstate(invalid="ignore"):
            err = float(np.max(np.abs(c(x) / exact - 1)))
        if np.isnan(err):
            continue
        best_error = min(best_error, err)
        if err <= tol:
            best_per_method[c.method] = (c, err)
    if not best_per_method:
        raise InputError(f"tol {tol:g}: no method reaches it on [{x_min}, {x_max}]; the best "
                         f"reachable is {best_error:.1e}")
    timed = []
    for i, (c, err) in enumerate(best_per_method.values()):
        progress(i, len(best_per_method))
        timed.append((c, err, ns_per_point(c, x_min=x_min, x_max=x_max)))
    c, err, ns = cheapest(timed, lambda t: modelled_ns("period", t[0].method, t[0].order),
                          lambda t: t[0].method)
    return Choice(c.method, c.order, err, ns, len(x),
                  tuple((t[0].method.name, t[0].order, t[1], t[2]) for t in timed), c)


# --- the grandfather's clock: the notes' appendix claims --------------------------------------

APPENDIX_CLAIMS = (
    ("theta^2/2 - theta^4/24", 1e-4, 17.0), ("theta^2/2 - theta^4/24", 1e-3, 44.0),
    ("theta^2/2 - theta^4/24", 1e-2, 75.0), ("theta^2/2", 1e-4, 2.0),
    ("theta^2/2", 1e-3, 6.0), ("theta^2/2", 1e-2, 19.0),
)
# NOTE: the notes (App. 4.2): relative accuracy of each approximation of 1 − cos θ up to the angle.


@dataclass(frozen=True)
class Threshold:
    """One of the notes' appendix claims checked: an approximation of ``1 − cos θ``, its
    tolerance, the angle claimed and the true largest angles (degrees) within the
    tolerance, for the potential and for the period."""

    approximation: str
    tolerance: float
    claimed_deg: float
    potential_deg: float  # largest angle where |V_approx/V − 1| ≤ tolerance
    period_deg: float  # largest amplitude where the approximate period is within tolerance


def _potential_error(approx: str, th: float) -> float:
    v = 1 - mpmath.cos(th)
    a = th**2 / 2 - (th**4 / 24 if "theta^4" in approx else 0)
    return float(abs(a / v - 1))


def _period_error(approx: str, th: float) -> float:
    """Period of the approximate potential against the pendulum's ``4K(sin²(θ₀/2))``."""
    exact = 4 * mpmath.ellipk(mpmath.sin(th / 2) ** 2)
    if "theta^4" in approx:  # θ̈ + θ − θ³/6 = 0: Duffing with εA² = −θ₀²/6
        x = -th**2 / 6
        approx_t = 4 * mpmath.ellipk(x / (2 * (1 + x))) / mpmath.sqrt(1 + x)
    else:
        approx_t = 2 * mpmath.pi
    return float(abs(approx_t / exact - 1))


def appendix_thresholds() -> list[Threshold]:
    """The true threshold angles of the notes' appendix claims (bisection in mpmath)."""
    out = []
    for approx, tol, claimed in APPENDIX_CLAIMS:
        found = []
        for err in (_potential_error, _period_error):
            with mpmath.workdps(30):
                th = mpmath.findroot(lambda t, err=err, a=approx, e=tol: err(a, t) - e,
                                     (mpmath.mpf("1e-3"), mpmath.mpf(3.0)), solver="bisect")
            found.append(float(mpmath.degrees(th)))
        out.append(Threshold(approx, tol, claimed, *found))
    return out


# --- the data behind the speed–accuracy chart and the validity map ---------------------------

@dataclass(frozen=True)
class Tradeoff:
    """One candidate's measured cost and its relative error at each chart point."""

    method: str
    order: int
    ns_per_point: float
    errors: np.ndarray  # at the chart's x values (NaN: outside the candidate's domain)


def tradeoffs(xs: np.ndarray, points: int = 200_000) -> list[Tradeoff]:
    """Every candidate: measured ns/point (on [0, 0.5]) and its error at each ``x``; plus
    numerical integration at several tolerances (timed per call)."""
    xs = np.asarray(xs, dtype=float)
    ref = reference_period(xs)
    out = []
    for c in candidates():
        with np.errstate(invalid="ignore"):
            err = np.abs(c(xs) / ref - 1)
        out.append(Tradeoff(c.method.name, c.order, ns_per_point(c, points=points), err))
    for k, rtol in enumerate(INTEGRATION_RTOLS):
        t0 = time.perf_counter()
        values = np.array([integrated_period(x, rtol) for x in xs])
        ns = (time.perf_counter() - t0) / xs.size * 1e9
        out.append(Tradeoff("numerical", k, ns, np.abs(values / ref - 1)))
    return out


def pareto_front(costs: np.ndarray, errors: np.ndarray) -> np.ndarray:
    """Indices of the non-dominated (cost, error) pairs, cheapest first."""
    order = np.lexsort((errors, costs))
    front, best = [], np.inf
    for i in order:
        if np.isfinite(errors[i]) and errors[i] < best:
            front.append(i)
            best = errors[i]
    return np.array(front, dtype=int)


# --- named scenes ----------------------------------------------------------------------------

@dataclass(frozen=True)
class SceneResult:
    """A named scene's answer: the scene, its question, the answer in one line and its
    numbers (``details``, as the JSON gives them)."""

    scene: str
    question: str
    answer: str
    details: dict


def clock_scene(swing_deg: float = 10.0, seconds_per_day: float = 0.1) -> SceneResult:
    """Grandfather's clock: the lowest L–P order of the pendulum period whose error stays
    below ``seconds_per_day`` for every swing up to ``swing_deg`` (verified on 2001 angles)."""
    if not 0 < swing_deg < 180:
        raise InputError(f"swing {swing_deg}°: must be between 0° and 180° (no libration beyond)")
    tol = seconds_per_day / 86_400
    th = np.radians(verification_points(0.0, swing_deg))[1:]
    exact = 4 * ellipk(np.sin(th / 2) ** 2) / (2 * np.pi)
    t = th**2 / np.pi**2  # the series in θ₀² has radius π²: scaled to radius 1
    for k in range(0, 41):
        sol = derive(pendulum(k), k)
        coeffs = np.array([float(sol.ground.to_fraction(c)) * np.pi ** (2 * j)
                           for j, c in enumerate(sol.period)])
        cand = Candidate(k, coeffs, np.ones(1), method("period", "lindstedt"))
        err = float(np.max(np.abs(cand(t) / exact - 1)))
        if err <= tol:
            return SceneResult(
                "clock", f"pendulum period to {seconds_per_day} s/day up to a {swing_deg}° swing",
                f"L–P order {k} in θ₀² (T = 2π Σ τ_j θ₀^(2j), {k + 1} terms)",
                {"order": k, "max_error": err, "seconds_per_day": err * 86_400,
                 "ns_per_point": ns_per_point(cand, x_min=0.0, x_max=float(t.max())),
                 "verified_on": int(th.size)})
    raise InputError(f"swing {swing_deg}°: no L–P order up to 40 reaches {tol:.1e}")


def hard_spring_scene(x: float = 50.0, tol: float = 1e-8) -> SceneResult:
    """A hardening spring at ``εA² = x``: the cheapest verified period evaluator."""
    c = choose_period(tol, x, x * (1 + 1e-12))
    return SceneResult("hard-spring", f"Duffing period to {tol:g} at εA² = {x:g}",
                       f"{c.method} order {c.order}",
                       {"method": c.method.name, "order": c.order, "max_error": c.max_error,
                        "ns_per_point": c.ns_per_point})


# --- the driven amplitudes A_n(ω) and the response r(ω): methods side by side ---------------

DRIVEN_POINTS = 21
# NOTE: ω points (Chebyshev-spaced) on which a range is verified; each costs one shooting.
DRIVEN_QUANTITIES = ("amplitudes", "response")
# NOTE: amplitudes: max |error| of A_n, B_n for n = 1, 3, 5; response: |r − r_true| with
# r = √(A₁² + B₁²), the amplitude of the fundamental (eq. 10.79's r).


TRUTH_ROUNDING = 4 * np.finfo(float).eps
# NOTE: the shot truth is a double: its harmonics carry a few units of their last place, so no
# error is verified below 4 ulps of the largest (ω = 1, ε = 0.1, f = 1: the μ-expansion at
# order 11 once met r's last bit exactly and "verified" a tolerance of 1e-17).


@dataclass(frozen=True)
class DrivenTruth:
    """The true periodic orbit on the largest branch at each ω (shooting, Floquet-checked
    RK4 with Richardson extrapolation): its harmonics 1, 3, 5."""

    omega: np.ndarray
    A: np.ndarray  # (n, 3)
    B: np.ndarray  # (n, 3)

    @property
    def r(self) -> np.ndarray:
        """``r = √(A₁² + B₁²)`` at each ω: the amplitude of the fundamental."""
        return np.hypot(self.A[:, 0], self.B[:, 0])


def driven_truth(eps: float, force: float, Q: float, omegas: np.ndarray,
                 progress: Progress = quiet) -> DrivenTruth:
    """Shooting from harmonic balance with 12 harmonics on the largest first-order branch."""
    A, B = [], []
    for i, w in enumerate(omegas):
        progress(i, len(omegas))
        d = Drive(eps, force, float(w), Q)
        hb = harmonic_balance(d, first_order_branches(d)[0], DRIVEN_MAX)
        a, b = amplitudes(hb.coefficients, 0.0, 4 * DRIVEN_MAX)
        orbit = shoot(eps, force, float(w), d.damping,
                      np.array([sum(a.values()), w * sum(n * v for n, v in b.items())]))
        if orbit is None:
            raise InputError(f"omega {w:g}: no periodic orbit found by shooting from the balance "
                             "solution, so no verified choice is possible there")
        A.append([orbit.A[n] for n in (1, 3, 5)])
        B.append([orbit.B[n] for n in (1, 3, 5)])
    return DrivenTruth(np.asarray(omegas, dtype=float), np.array(A), np.array(B))


@dataclass(frozen=True)
class DrivenTradeoff:
    """One method at one order: measured cost per ω and its errors at each ω (NaN where
    it refuses: a fold, a diverging μ-series, a balance that does not converge)."""

    method: str  # "one_harmonic", "mu_expansion", "harmonic_balance" or "shooting"
    order: int  # μ-order, number of odd harmonics, or RK4 steps per period (one_harmonic: 1)
    ns_per_point: float
    errors: dict[str, np.ndarray]  # quantity -> error per ω


def driven_errors(truth: DrivenTruth, A: np.ndarray, B: np.ndarray) -> dict[str, np.ndarray]:
    """Both error measures per ω for ``(n, 3)`` arrays of ``A_n``, ``B_n`` (n = 1, 3, 5; a
    NaN row — a refused ω — stays NaN), never below the truth's own rounding
    (:data:`TRUTH_ROUNDING` × its largest harmonic): a method that happens to land on the
    truth's last bit is not verified to 0."""
    floor = TRUTH_ROUNDING * np.max(np.abs(np.hstack([truth.A, truth.B])), axis=1)
    return {"amplitudes": np.maximum(
                np.max(np.abs(np.hstack([A - truth.A, B - truth.B])), axis=1), floor),
            "response": np.maximum(np.abs(np.hypot(A[:, 0], B[:, 0]) - truth.r), floor)}


def _harmonics_135(values: tuple[dict, dict]) -> tuple[list[float], list[float]]:
    """``A_n``, ``B_n`` for n = 1, 3, 5 from the dicts of :func:`driven.amplitudes`."""
    A, B = values
    return [A.get(k, 0.0) for k in (1, 3, 5)], [B.get(k, 0.0) for k in (1, 3, 5)]


def driven_tradeoffs(truth: DrivenTruth, eps: float, force: float,
                     Q: float) -> list[DrivenTradeoff]:
    """The one-harmonic closed form, the μ-expansion at orders 0..12, harmonic balance with
    1..12 harmonics and shooting with plain RK4, each timed and judged at every ω of
    ``truth``."""
    n = truth.omega.size
    a1, b1 = one_harmonic_amplitudes(eps, force, Q, truth.omega)
    dense = np.resize(truth.omega, 100_000)  # timed where per-call overhead is amortised
    t0 = time.perf_counter()
    one_harmonic_amplitudes(eps, force, Q, dense)
    ns = (time.perf_counter() - t0) / dense.size * 1e9
    zeros = np.zeros((n, 2))
    out = [DrivenTradeoff("one_harmonic", 1, ns,
                          driven_errors(truth, np.column_stack([a1, zeros]),
                                        np.column_stack([b1, zeros])))]
    solved: dict[tuple[Callable, int], DrivenTradeoff] = {}  # two records, one solver
    for m in methods_for("driven", Drive(eps, force, 1.0, Q)):
        if m.solve is None:
            continue  # the one-harmonic closed form, vectorised above
        for order in m.driven_orders:
            if (m.solve, order) in solved:
                t = solved[m.solve, order]
                out.append(DrivenTradeoff(m.name, order, t.ns_per_point, t.errors))
                continue
            A, B = np.full((n, 3), np.nan), np.full((n, 3), np.nan)
            seconds = 0.0
            for i, w in enumerate(truth.omega):
                d = Drive(eps, force, float(w), Q)
                t0 = time.perf_counter()
                ok, values = m.solve(d, first_order_branches(d)[0], order)
                seconds += time.perf_counter() - t0
                if ok:
                    A[i], B[i] = _harmonics_135(values)
            out.append(DrivenTradeoff(m.name, order, seconds / n * 1e9,
                                      driven_errors(truth, A, B)))
            solved[m.solve, order] = out[-1]
    return out


def emitted_driven(name: str, order: int, truth: DrivenTruth, eps: float, force: float,
                   Q: float) -> DrivenTradeoff:
    """The emitted module of method ``name`` at ``order`` (``generate driven``: the undamped
    μ-expansion as compiled ufuncs, ``--damped`` the damped one; ``generate balance``: compiled
    Newton), generated into a
    temporary folder through the compiler, run by the record's ``run_emitted``, timed and
    judged at every ω of ``truth``."""
    m = method("driven", name)
    why = m.emittable(Drive(eps, force, 1.0, Q)) if m.target is not None else "no module"
    if why:
        raise InputError(why)
    with tempfile.TemporaryDirectory(prefix="lindstedt-emitted-") as tmp:
        paths = generate_method(m, order, Path(tmp), flag="--out")
        module = next(p for p in paths if p.suffix == ".py")
        mod = load_generated(module)
        try:
            A, B, run, points = m.run_emitted(mod, truth.omega, eps, force, Q, order)
            ns = best_seconds(run, 1) / points * 1e9
        finally:
            sys.modules.pop(module.stem, None)
    return DrivenTradeoff(f"{name}, emitted", order, ns, driven_errors(truth, A, B))


@dataclass(frozen=True)
class DrivenChoice:
    """The cheapest verified method for a driven quantity over ω points."""

    quantity: str
    method: Method
    order: int
    max_error: float
    ns_per_point: float  # measured wall time per ω
    verified_on: int
    considered: tuple[tuple[str, int, float, float], ...]  # per method: smallest order that
    # meets the tolerance, its error, its ns per point (measured); emitted modules after
    truth: DrivenTruth
    modelled_ns_per_point: float = math.nan  # COST_MODEL["driven"]: what the choice compared

    def _repr_html_(self) -> str:
        return choice_table(self, f"choose_driven: {self.quantity}, max error")


def choose_driven(quantity: str, tol: float, eps: float, force: float, Q: float,
                  omega_min: float, omega_max: float | None = None,
                  emit: tuple[int, int] | None = None,
                  progress: Progress = quiet) -> DrivenChoice:
    """The cheapest of one harmonic, the μ-expansion (smallest order), harmonic balance
    (fewest harmonics) and shooting (fewest RK4 steps) whose error in ``quantity`` is
    ≤ ``tol`` at every verified ω of ``[omega_min, omega_max]`` (one ω when ``omega_max`` is
    None), on the largest branch; "cheapest" by the recorded ``COST_MODEL["driven"]``, so the
    choice does not depend on this run's timings (which are reported).  ``emit`` = (highest
    μ-order, most harmonics): only what has an emitted module within those bounds competes —
    harmonic balance, and the μ-expansion (the undamped module for Q = inf, the damped one,
    ``mu_expansion_damped``, for a finite Q); the modules are generated in the order of
    their modelled cost, the first that meets ``tol`` is chosen (only it and the ones before
    it are generated)."""
    if quantity not in DRIVEN_QUANTITIES:
        raise InputError(f"quantity {quantity!r}: one of {', '.join(DRIVEN_QUANTITIES)}")
    for name, v in (("tol", tol), ("omega-min", omega_min), ("omega-max", omega_max)):
        if v is not None and not np.isfinite(v):
            raise InputError(f"{name} {v}: not finite")
    if tol <= 0:
        raise InputError(f"tol {tol}: must be > 0")
    drive = Drive(eps, force, omega_min, Q)  # validates the parameters
    if omega_max is None:
        omegas = np.array([omega_min])
    elif omega_min < omega_max:
        omegas = verification_points(omega_min, omega_max, DRIVEN_POINTS)
    else:
        raise InputError(f"range [{omega_min}, {omega_max}]: empty or reversed")
    truth = driven_truth(eps, force, Q, omegas, progress)
    best: dict[str, tuple[DrivenTradeoff, float]] = {}
    reachable = np.inf
    for t in driven_tradeoffs(truth, eps, force, Q):
        err = float(np.max(t.errors[quantity]))  # NaN anywhere: refused somewhere
        if np.isnan(err) or (t.method in best and best[t.method][0].order <= t.order):
            continue  # each method at its smallest sufficient order, whatever the list's order
        m = method("driven", t.method)
        if emit is not None and not (  # only what has an emitted module competes
                m.bound >= 0 and t.order <= emit[m.bound] and m.emittable(drive) is None):
            continue
        reachable = min(reachable, err)
        if err <= tol:
            best[t.method] = (t, err)
    if not best:
        within = ("" if emit is None else f" (emittable: μ-expansion to order {emit[0]}, "
                  f"balance to {emit[1]} harmonics; --allow-slow admits more)")
        raise InputError(f"tol {tol:g}: no {'emittable ' * (emit is not None)}method "
                         "reaches it on the range (one harmonic, "
                         f"μ-expansion to order {DRIVEN_MAX}, balance to {DRIVEN_MAX} harmonics, "
                         f"shooting to {SHOOTING_STEPS[-1]} RK4 steps){within}; the best "
                         f"reachable is {reachable:.1e}")
    suffix = "" if emit is None else ", emitted"
    pool, ranked = list(best.values()), []
    while pool:  # cheapest first by the model, ties to the simplest method
        ranked.append(cheapest(pool, lambda v: modelled_ns("driven", v[0].method + suffix,
                                                           v[0].order), lambda v: v[0].method))
        pool.remove(ranked[-1])
    considered = [(v.method, v.order, e, v.ns_per_point) for v, e in ranked]
    if emit is None:
        t, err = ranked[0]
    else:  # the emitted module's own error decides; its own timing is reported
        for v, _ in ranked:
            t = emitted_driven(v.method, v.order, truth, eps, force, Q)
            err = float(np.max(t.errors[quantity]))
            considered.append((t.method, t.order, err, t.ns_per_point))
            if err <= tol:
                break
        else:
            raise InputError(f"tol {tol:g}: the emitted modules miss it where the interpreted "
                             "methods met it (rounding in the compiled formulas); loosen tol")
    return DrivenChoice(quantity, method("driven", t.method.removesuffix(", emitted")), t.order,
                        err,
                        t.ns_per_point, omegas.size, tuple(considered), truth,
                        modelled_ns("driven", t.method, t.order))


def driven_scene(tol: float = 1e-4) -> SceneResult:
    """The notes' driven table (ε = 0.1, f = 1, ω = 1) to ``tol``."""
    c = choose_driven("amplitudes", tol, 0.1, 1.0, np.inf, 1.0)
    orders = {m: o for m, o, _, _ in c.considered}
    return SceneResult("notes-driven", f"Hand & Finch's driven table (A1, A3, A5) to {tol:g}",
                       f"μ-expansion order {orders.get('mu_expansion')}, or harmonic balance "
                       f"with {orders.get('harmonic_balance')} harmonics; faster: {c.method}",
                       {"mu_order": orders.get("mu_expansion"),
                        "harmonics": orders.get("harmonic_balance"),
                        "truth": c.truth.A[0].tolist()})


SCENES = {"clock": clock_scene, "hard-spring": hard_spring_scene, "notes-driven": driven_scene}


# --- q(t): the lowest L–P order, or the fewest exact Fourier harmonics, for a range ---------

FOURIER_MAX = 40
# NOTE: harmonics of the exact nome series: 12 reach 1e-13 for every x ≥ 0, 30 reach 1e-14
# at x = −0.99, next to the separatrix (the nome q → 1 there).


@dataclass(frozen=True)
class SolutionChoice:
    """The cheapest verified evaluator of the Duffing solution ``q(t)/A`` on a range of
    ``x = εA²`` (an L–P order, the exact Fourier series of cn, or SciPy's cn): its max
    error, measured ns per point, verification points and each method considered."""

    method: Method  # "lindstedt", "fourier" (exact nome series, N harmonics) or "exact" (ellipj)
    order: int  # L–P order, or number of odd harmonics
    max_error: float  # max |q − A cn| / A over the grid
    ns_per_point: float
    verified_on: int
    considered: tuple[tuple[str, int, float, float], ...] = ()  # method, order, error, ns

    def _repr_html_(self) -> str:
        return choice_table(self, "choose_solution: q(t)/A, max error")


def _fourier_cost(harmonics: int, x_min: float, x_max: float) -> float:
    """ns/point of :func:`cn_fourier` with t and x varying per point (best of 3)."""
    rng = np.random.default_rng(0)
    x = rng.uniform(x_min, x_max, 200_000)
    t = rng.uniform(0, 20, x.size)
    out = np.empty_like(t)
    return best_seconds(lambda: cn_fourier(t, x, harmonics, out)) / t.size * 1e9


def choose_solution(tol: float, x_min: float, x_max: float, t_max: float = 20.0,
                    max_order: int = 30, emittable: bool = False,
                    progress: Progress = quiet) -> SolutionChoice:
    """The cheapest of the lowest L–P order and the fewest exact Fourier harmonics whose
    q(t)/A is within ``tol`` of the exact solution for every ``x = εA² ∈ [x_min, x_max]`` and
    ``t ∈ [0, t_max]`` (and SciPy's cn when ``x ≥ 0``); ``emittable``: not SciPy's cn, which
    has no emitted evaluator (the Fourier series is emitted by ``generate fourier``)."""
    for name, v in (("tol", tol), ("x-min", x_min), ("x-max", x_max), ("t-max", t_max)):
        if not np.isfinite(v):
            raise InputError(f"{name} {v}: not finite")
    if tol <= 0 or t_max <= 0:
        raise InputError("tol and t-max must be > 0")
    if not x_min < x_max:
        raise InputError(f"range [{x_min}, {x_max}]: empty or reversed")
    if x_min <= -1:
        raise InputError(f"range [{x_min}, {x_max}] reaches x = εA² ≤ -1: no periodic orbit")
    xs = verification_points(x_min, x_max, 9)
    t = np.linspace(0.0, t_max, 401)
    exact = {x: reference_q(t, x) for x in xs}
    found: dict[str, tuple[int, float]] = {}
    reachable = np.inf
    if np.max(np.abs(xs)) < 1:  # beyond the radius the truncated series is no answer
        sol = derive(duffing(), max_order)
        g = sol.ground.to_fraction
        for k in range(max_order + 1):
            progress(k, max_order + 1)
            err = 0.0
            for x in xs:
                omega = sum(float(g(w)) * x**j for j, w in enumerate(sol.omega[: k + 1]))
                q = sum(x**j * sum(float(g(c)) * np.cos(n * omega * t) for n, c in qj.items())
                        for j, qj in enumerate(sol.q[: k + 1]))
                err = max(err, float(np.max(np.abs(q - exact[x]))))
            reachable = min(reachable, err)
            if err <= tol:
                found["lindstedt"] = (k, err)
                break
    out = np.empty_like(t)
    for n in range(1, FOURIER_MAX + 1):
        err = max(float(np.max(np.abs(cn_fourier(t, np.full_like(t, x), n, out) - exact[x])))
                  for x in xs)
        reachable = min(reachable, err)
        if err <= tol:
            found["fourier"] = (n, err)
            break
    if not found:
        raise InputError(f"tol {tol:g}: no L–P order nor exact Fourier series reaches it on "
                         f"[{x_min}, {x_max}]; the best reachable is {reachable:.1e}")
    timed = []
    q_costs = {"lindstedt": _generated_q_cost, "fourier": _fourier_cost}
    for name, (order, err) in found.items():
        timed.append((name, order, err, q_costs[name](order, x_min, x_max)))
    if x_min >= 0 and not emittable:
        x = np.random.default_rng(0).uniform(x_min, x_max, 200_000)
        tt = np.random.default_rng(1).uniform(0, t_max, x.size)
        t0 = time.perf_counter()
        ellipj(np.sqrt(1 + x) * tt, x / (2 * (1 + x)))
        timed.append(("exact", 0, 0.0, (time.perf_counter() - t0) / x.size * 1e9))
    name, order, err, ns = cheapest(timed, lambda v: modelled_ns("q", v[0], v[1]),
                                    lambda v: v[0])
    return SolutionChoice(method("q", name), order, err, ns, xs.size * t.size, tuple(timed))


def _generated_q_cost(order: int, x_min: float, x_max: float) -> float:
    """ns/point of the generated ``q(t, A, eps)`` at ``order`` (generated into a temp folder)."""
    with tempfile.TemporaryDirectory(prefix="lindstedt-choose-") as tmp:
        generate("duffing", order, Path(tmp))
        mod = load_generated(Path(tmp) / "duffing.py")
        rng = np.random.default_rng(0)
        eps = rng.uniform(x_min, x_max, 1_000_000)
        t = rng.uniform(0, 20, eps.size)
        out = np.empty_like(t)
        seconds = best_seconds(lambda: mod.q_into(out, t, 1.0, eps))
        sys.modules.pop("duffing", None)
    return seconds / t.size * 1e9


RESUMMED_COSTS = {
    "cycle": {"series": 3.0, "resummed": 5.2, "shooting": 1.5e9},
    "mathieu": {"series": 60.0, "pade": 3.5, "reference": 1.0e5},
}
# NOTE: ns per point, recorded on the 2-core reference machine by benchmarks/resum.py
# (docs/benchmarks.md, 2026-12-02): the emitted ufuncs' `_into` loops over a million points
# (the series and the Padé form, Mathieu's with its Newton step: 2.3–4.2 ns over the thirteen
# modules, 3.5 recorded), the NumPy Horner sum of Mathieu's
# series, one DOP853 shooting of the cycle (two tolerances) and one float64 tridiagonal
# eigenvalue solve.  The choice decides by
# these, so it does not depend on this run's load; each run's timings are reported beside.
RESUMMED_ORDER = {"cycle": 60, "mathieu": 100}
# NOTE: the default orders: the limit cycle's derivation at 60 is ~2 s (its resummed form is
# then verified to |ε| ≈ 3), Mathieu's at 100 well under a second.


@dataclass(frozen=True)
class ResummedChoice:
    """The cheapest of a quantity's partial sums, resummed evaluator and numerical reference
    that meets ``tol`` on the range, by :data:`RESUMMED_COSTS`; ``considered``: per method its
    order, largest measured error on the range (inf where it returns NaN) and the recorded and
    this run's ns per point."""

    quantity: str
    method: str
    order: int
    max_error: float
    ns_per_point: float
    verified_on: int
    considered: tuple[tuple[str, int, float, float, float], ...]

    def _repr_html_(self) -> str:
        return html_table(
            f"{self.quantity}: {self.method}, error {self.max_error:.1e}, "
            f"{self.ns_per_point:.3g} ns/point, verified on {self.verified_on} points",
            ("method", "order", "max error", "recorded ns/point", "this run"),
            [(m, o, f"{e:.1e}", f"{r:.3g}", f"{ns:.3g}") for m, o, e, r, ns in self.considered])


def _relative(value: np.ndarray, reference: np.ndarray, floor: float = 0.0) -> float:
    err = np.abs(np.asarray(value, float) - reference) / np.maximum(np.abs(reference), floor)
    return float(np.max(np.where(np.isfinite(err), err, np.inf)))


def _pick(quantity: str, kind: str, tol: float, order: int, n: int,
          rows: list[tuple[str, int, float, float, float]]) -> ResummedChoice:
    fits = [r for r in rows if r[2] <= tol]
    if not fits:
        best = min(rows, key=lambda r: r[2])
        raise InputError(f"--tol {tol:g}: no method meets it on the range (best: {best[0]}, "
                         f"{best[2]:.1e}); widen the tolerance or narrow the range")
    m = min(fits, key=lambda r: RESUMMED_COSTS[kind][r[0]])
    return ResummedChoice(quantity, m[0], m[1], m[2], m[4], n, tuple(rows))


def choose_limit_cycle(tol: float, eps_min: float, eps_max: float, order: int | None = None,
                       points: int = 7) -> ResummedChoice:
    """van der Pol's ω on ``[eps_min, eps_max]``: the emitted partial sums (``omega``), the
    resummed evaluator (``omega_resummed``) and DOP853 shooting, each measured against the
    shooting references at ``points`` Chebyshev points (shooting's own error: its
    two-tolerance difference there)."""
    from .compiler import generate_limit_cycle
    from .derive.models import series_model
    from .numerics.references import cycle_reference

    if not (0 < eps_min <= eps_max) or not (tol > 0):
        raise InputError(f"--range {eps_min}:{eps_max}, --tol {tol}: need "
                         "0 < A ≤ B and tol > 0 (the range of ε)")
    order = RESUMMED_ORDER["cycle"] if order is None else order
    vdp = series_model("van_der_pol", order)
    eps = verification_points(eps_min, eps_max, points)
    start = time.perf_counter()
    refs = [cycle_reference(vdp, float(e)) for e in eps]
    shoot_ns = (time.perf_counter() - start) / len(eps) * 1e9
    omega = np.array([2 * np.pi / r.period for r in refs])
    with tempfile.TemporaryDirectory() as out:
        generate_limit_cycle(vdp, order - 2, Path(out))
        mod = load_generated(Path(out) / "van_der_pol.py")
        rows = []
        for name, ufunc, into in (("series", mod.omega, mod.omega_into),
                                  ("resummed", mod.omega_resummed, mod.omega_resummed_into)):
            ns = ns_per_point(lambda x, o, f=into: f(o, x), 1_000_000, eps_min, eps_max)
            rows.append((name, order - 2, _relative(ufunc(eps), omega),
                         RESUMMED_COSTS["cycle"][name], ns))
    rows.append(("shooting", 0, max(r.accuracy for r in refs), RESUMMED_COSTS["cycle"]["shooting"],
                 shoot_ns))
    return _pick("limit cycle ω", "cycle", tol, order - 2, len(eps), rows)


def choose_mathieu(kind: str, m: int, tol: float, q_min: float, q_max: float,
                   order: int | None = None, points: int = 41) -> ResummedChoice:
    """Mathieu's ``a_m(q)`` or ``b_m(q)`` on ``[q_min, q_max]``: the series' partial sum
    (NumPy Horner), the emitted Padé evaluator and the eigenvalue solver, measured against the
    eigenvalue solver in mpmath (30 digits) at ``points`` Chebyshev points, relative to
    max(1, |a|)."""
    from .algebra.resum import horner_float
    from .compiler import generate_mathieu
    from .derive.hill import mathieu_series
    from .numerics.references import mathieu_reference

    if not (q_min <= q_max) or not (tol > 0):
        raise InputError(f"--range {q_min}:{q_max}, --tol {tol}: need A ≤ B "
                         "and tol > 0 (the range of q)")
    order = RESUMMED_ORDER["mathieu"] if order is None else order
    q = verification_points(q_min, q_max, points)
    truth = np.array([mathieu_reference(kind, m, float(x), dps=30) for x in q])
    start = time.perf_counter()
    solver = np.array([mathieu_reference(kind, m, float(x)) for x in q])
    solver_ns = (time.perf_counter() - start) / len(q) * 1e9
    coefficients = mathieu_series(kind, m, order)
    rows = []
    series_ns = ns_per_point(lambda x, o: horner_float(coefficients, x), 100_000, q_min, q_max)
    rows.append(("series", order, _relative(horner_float(coefficients, q), truth, 1.0),
                 RESUMMED_COSTS["mathieu"]["series"], series_ns))
    with tempfile.TemporaryDirectory() as out:
        generate_mathieu(kind, m, order, Path(out))
        mod = load_generated(Path(out) / f"mathieu_{kind}{m}.py")
        ufunc, into = getattr(mod, f"{kind}{m}"), getattr(mod, f"{kind}{m}_into")
        ns = ns_per_point(lambda x, o: into(o, x), 1_000_000, q_min, q_max)
        rows.append(("pade", order, _relative(ufunc(q), truth, 1.0),
                     RESUMMED_COSTS["mathieu"]["pade"], ns))
    rows.append(("reference", 0, _relative(solver, truth, 1.0),
                 RESUMMED_COSTS["mathieu"]["reference"], solver_ns))
    return _pick(f"mathieu {kind}_{m}", "mathieu", tol, order, len(q), rows)


# --- a system's backbone: the normal mode's L–P order for a tolerance ------------------------

BACKBONE_POINTS = 17
# NOTE: Chebyshev points of the amplitude range, ends included (where truncation peaks), each
# a shot orbit (~0.1–0.3 s for two coordinates).
BACKBONE_FIRST_ORDER = 24
BACKBONE_MAX_ORDER = 40
# NOTE: the series is derived to the first order (the radius estimate needs it: a few seconds
# over Q(λ)) and only where no order up to it meets the tolerance to the last (seconds to
# tens of seconds: the exact coefficients grow).
BACKBONE_FLOOR = 1e-11
# NOTE: the shot reference (DOP853 at 1e-13, Newton to 1e-12) is trusted to ~1e-12 in T: a
# tolerance below this floor cannot be verified.


@dataclass(frozen=True)
class BackboneChoice:
    """The smallest L–P order of a normal mode's period ``T(A)`` within ``tol`` of shot orbits
    on a range of amplitudes: the order, the max relative error there, the error of every
    order tried, and the points it was verified on."""

    mode: int
    order: int
    max_error: float
    errors: tuple[float, ...]  # order k -> max relative error on the points
    verified_on: int
    radius: float  # the series' estimated radius in A (its reach)


def choose_backbone(system: System, mode: int, tol: float, a_min: float, a_max: float,
                    amplitude: int = 0, progress: Progress = quiet) -> BackboneChoice:
    """The smallest order whose period is within ``tol`` (relative) of the shot orbits at
    :data:`BACKBONE_POINTS` Chebyshev amplitudes of ``[a_min, a_max]`` (each seeded by the
    last: a continuation); refused past the series' reach or below the reference's floor."""
    from .derive.nnm import normal_mode, radius
    from .numerics.references import check_shootable, mode_orbit

    if not (np.isfinite(tol) and tol > 0):
        raise InputError(f"--tol {tol}: must be finite and > 0")
    if tol < BACKBONE_FLOOR:
        raise InputError(f"--tol {tol:g}: below {BACKBONE_FLOOR:g}, what the shot orbits "
                         "verify")
    if not (np.isfinite(a_min) and np.isfinite(a_max) and 0 < a_min < a_max):
        raise InputError(f"--range {a_min}:{a_max}: amplitudes with 0 < A < B")
    check_shootable(system, "choose backbone")
    series = normal_mode(system, mode, BACKBONE_FIRST_ORDER, amplitude)
    found = radius(series)
    reach = np.inf if found is None else found.reach
    if a_max >= reach:
        raise InputError(f"--range {a_min}:{a_max}: the series of mode {mode} reaches "
                         f"A < {reach:.4g} (the lower bound of its estimated radius); shoot "
                         "beyond it")
    A = verification_points(a_min, a_max, BACKBONE_POINTS)
    truth = np.empty_like(A)
    guess = None
    for k, a in enumerate(A):
        progress(k, len(A))
        if guess is None:  # the series' own orbit seeds the first shot
            _, period, x0 = series.evaluate(a)
            guess = np.append(np.delete(x0, amplitude), period / 2)
        orbit = mode_orbit(system, float(a), guess, amplitude)
        if not orbit.converged:
            raise InputError(f"A = {a:g}: the shot orbit of mode {mode} did not converge")
        truth[k] = orbit.period
        guess = np.append(np.delete(orbit.start, amplitude), orbit.period / 2)
    y = A**series.step
    errors: list[float] = []
    for top in (BACKBONE_FIRST_ORDER, BACKBONE_MAX_ORDER):
        if series.order < top:  # not reached yet: the longer series (slower: Q(λ) grows)
            series = normal_mode(system, mode, top, amplitude)
        tau = np.array([float(c) for c in series.period()])
        for k in range(len(errors), series.order + 1):
            model = 2 * np.pi * np.polyval(tau[: k + 1][::-1], y)
            errors.append(float(np.max(np.abs(model / truth - 1))))
            if errors[-1] <= tol:
                return BackboneChoice(mode, k, errors[-1], tuple(errors), len(A),
                                      float(reach))
    raise InputError(f"--tol {tol:g}: not reached by order {series.order} on "
                     f"[{a_min:g}, {a_max:g}]; the best is {min(errors):.1e}")
