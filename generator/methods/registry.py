"""The methods, one record each: what it answers and for which oscillators (and why not), how it
derives, evaluates and lowers, and what it is checked against.

``choose`` loops over :data:`METHODS`; the compiler asks a record's :class:`Target`
(:mod:`.targets`) what to derive and lower for ``generate`` and ``choose --out``; the kernels,
references and verified resummations live beside it (:mod:`.kernels`, :mod:`.references`,
:mod:`.verify`).  Adding a method is adding a record.

The free Duffing period ``T/2π`` as a function of ``x = εA²`` (``choose period``):

* ``lindstedt``: the L–P series ``Σ τ_j x^j`` truncated at order k (radius |x| < 1, set by the
  separatrix at x = −1);
* ``resummed``: the same series re-expanded in ``m = x/(2(1+x))``:
  ``T/2π = √(1 − 2m) Σ c_n m^n`` — analytic for ``|m| < 1``, i.e. ``x > −2/3``, and
  ``m < 1/2`` for every ``x ≥ 0``, so it converges out to ``εA² → ∞``;
* ``pade``: the diagonal Padé approximant ``[k/k]`` of the L–P series;
* ``modified``: the modified L–P of Cheung, Chen & Lau, re-expanded from the exact series;
* ``agm``: the exact period through Gauss's arithmetic–geometric mean,
  ``T/2π = 1/AGM(√(1+x), √(1+x/2))`` (``K(m) = π/(2 AGM(1, √(1−m)))``, scaled), stopped after
  n steps — the order; each step squares the relative error, so 2–3 steps are exact to
  double precision everywhere except next to the separatrix;
* ``exact``: ``4K(m)/√(1+x)`` (SciPy's ``ellipk``), the baseline any method must beat.

Each is checked against :func:`reference_period` (mpmath, 30 digits).  The solution q(t)
(``choose q``): the L–P series, the exact Fourier series in the nome (:func:`cn_fourier`) and
SciPy's cn, checked against cn.  The driven amplitudes (``choose amplitudes|response``): one
harmonic, the μ-expansion (its emitted module undamped, ``mu_expansion``, or for a finite Q,
``mu_expansion_damped``), harmonic balance and shooting, checked against shooting with
Richardson-combined RK4.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..analysis.driven import Branch, Drive
from ..derive.lindstedt import derive
from ..derive.models import Model, check_order, duffing
from ..limits import PERIOD_SERIES_ORDER
from ..lower.records import (
    PeriodFormula,
    x_,
)
from ..numerics.references import duffing_period_exact
from .kernels import (
    Coefficients,
    PeriodSeries,
    PeriodTerms,
    _agm_orders,
    _evaluate,
    _exact_orders,
    _lower_agm,
    _lower_lp,
    _lower_modified,
    _lower_pade,
    _lower_resummed,
    _lp_orders,
    _modified_orders,
    _not_lowered,
    _pade_orders,
    _resummed_orders,
)
from .references import (
    DRIVEN_MAX,
    SHOOTING_STEPS,
    Emitted,
    Solved,
    _run_balance_module,
    _run_mu_damped_module,
    _run_mu_module,
    _solve_balance,
    _solve_mu,
    _solve_shooting,
)
from .targets import (
    BALANCE,
    CHOSEN_PERIOD,
    DAMPED_MAX,
    FOURIER,
    FREE,
    MU,
    MU_DAMPED,
    Target,
)

# --- what a method applies to ------------------------------------------------------------------

def _free(subject: object) -> str | None:
    if not isinstance(subject, Model):
        return "a free oscillator's series: give an equation without a drive"
    return None


def _series_period(subject: object) -> str | None:
    """The L–P series and its Padé: the free Duffing oscillator, or a free polynomial one
    whose period is one exact rational series in one variable (every parameter given)."""
    if _free_duffing(subject) is None:
        return None
    return _polynomial_free(subject)


def _polynomial_free(subject: object) -> str | None:
    if not isinstance(subject, Model):
        return "a free oscillator's series: give an equation without a drive"
    if any(subject.velocity_forcing) or subject.elementary or subject.exact_to is not None:
        return ("its period is checked by quadrature of a polynomial potential: no velocity "
                "terms, no sin/sinh or Taylor-expanded force")
    values = [c for terms in subject.forcing for _, c in terms]
    if not all(sp.sympify(c).is_Rational for c in values):
        return ("its series must be one rational series in one variable: give every "
                "parameter a value (--param) and one power p = a + b - 1 or no eps")
    return None


def _free_duffing(subject: object) -> str | None:
    if not isinstance(subject, Model) or subject.name != "duffing" or subject.source:
        return ("its closed form is the free Duffing oscillator's (x = εA², the separatrix "
                "at x = -1)")
    return None


def _driven(subject: object) -> str | None:
    if not isinstance(subject, Drive):
        return "a driven oscillator's steady state: give a drive f cos(ωt)"
    return None


def _undamped(subject: object) -> str | None:
    if _driven(subject):
        return _driven(subject)
    if subject.damping != 0:
        return ("a finite Q: the undamped module has no q̇/Q term; the damped one is "
                "mu_expansion_damped's")
    return None


def _damped(subject: object) -> str | None:
    if _driven(subject):
        return _driven(subject)
    if subject.damping == 0:
        return ("the damped μ-expansion is for a finite Q (q̇/Q in the equation); Q = inf is "
                "the undamped mu_expansion's")
    return None


def _always(subject: object) -> str | None:
    return None


# --- the records ---------------------------------------------------------------------------------

Lowered = tuple[tuple, sp.Expr]


@dataclass(frozen=True, eq=False)
class Method:
    """One method for one quantity.  A method is known by its name: it compares equal to it
    (``choice.method == "agm"``) and prints as it, so tables and JSON show the name."""

    name: str
    quantity: str  # "period", "q" or "driven"
    about: str
    reference: str  # what its answers are checked against
    applies: Callable[[object], str | None] = _always  # why not, for a Model or a Drive
    kind: int = -1  # period: the compiled kernel's branch (-1: SciPy's ellipk)
    steps: bool = False  # period: the order counts steps, not terms (listed first)
    domain: sp.Basic = sp.true  # period: where the formula holds, in x_
    orders: Callable[[PeriodSeries, int], list[tuple[int, Coefficients]]] | None = None
    lowered: Callable[[PeriodTerms], Lowered] = _not_lowered
    solve: Callable[[Drive, Branch, int], Solved] | None = None  # driven: one ω, one order
    driven_orders: tuple[int, ...] = ()
    target: Target | None = None  # what `generate` / `--out` writes for it
    bound: int = -1  # driven: which of ``choose``'s emit bounds caps its order (-1: none)
    run_emitted: Callable[..., Emitted] | None = None  # driven: read its emitted module
    emittable: Callable[[object], str | None] = _always  # why its module cannot be emitted
    describe: Callable[[int], str] | None = None  # its name at an order (default: "NAME order K")
    cost: tuple[float, ...] = ()  # ns per point ≈ Σ c_i order^i, as `choose` runs it
    emitted_cost: tuple[float, ...] = ()  # the same of its emitted module (driven: per ω)

    def label(self, order: int) -> str:
        """What the method is at ``order``, as tables print it ("lindstedt order 8",
        "[12/12] Padé, 25 coefficients")."""
        return self.describe(order) if self.describe is not None else f"{self.name} order {order}"

    def why_not(self, subject: object) -> str | None:
        """None when the method applies to ``subject`` (a Model or a Drive), else why not."""
        return self.applies(subject)

    def evaluate(self, c: Candidate, x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """``T/2π`` of candidate ``c`` at ``x`` (period methods)."""
        if self.kind < 0:
            return duffing_period_exact(1.0, x) / (2 * np.pi)
        out = np.empty_like(x) if out is None else out
        _evaluate(self.kind, c.num, c.den, c.order, x, out, c.masked)
        return out

    def formula(self, c: Candidate) -> PeriodFormula:
        """Candidate ``c`` lowered: its assignments and value in x_, inside the domain."""
        body, value = self.lowered(c)
        return PeriodFormula(self.name, c.order, self.domain, body, value,
                             tuple(float(v) for v in c.num), tuple(float(v) for v in c.den))

    @property
    def rank(self) -> int:
        """Ties of cost go to the simplest formula: its place in :data:`SIMPLEST_FIRST`."""
        return SIMPLEST_FIRST.index(self.name)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Method):
            return (self.name, self.quantity) == (other.name, other.quantity)
        return isinstance(other, str) and self.name == other

    def __hash__(self) -> int:
        return hash(self.name)

    def __str__(self) -> str:
        return self.name

    def __format__(self, spec: str) -> str:
        return format(self.name, spec)


SIMPLEST_FIRST = ("lindstedt", "one_harmonic", "pade", "resummed", "modified", "agm",
                  "mu_expansion", "mu_expansion_damped", "harmonic_balance", "fourier",
                  "shooting", "exact")
# NOTE: the tie order of methods (the simplest formula first).

# NOTE: each method's cost, ns/point ≈ c₀ + c₁·order + c₂·order² (the coefficients ≥ 0), per
# quantity: period and q(t) of the compiled evaluators; for the driven quantities, each method
# per ω as `choose` runs it (interpreted: the μ-expansion's series products grow with the
# order squared) and, as ``emitted_cost``, its emitted module. Fitted once on the 2-core
# reference machine by `benchmarks/cost_model.py --fit` (docs/benchmarks.md). Every `choose`
# decides by these figures, so the choice — and what --out writes — does not depend on the
# machine's load; each run's own timings are reported beside.  mu_expansion_damped's emitted
# module (six ufuncs: A_n, B_n, n = 1, 3, 5) is fitted like the others at orders 1–4
# (`cost_model.py --fit --only "driven/mu_expansion_damped, emitted"`); the line 129 + 286·K
# fitted by hand at another ω underestimated order 4 by 4× (1.27 µs against the 5.08 µs
# measured on ω ∈ [1.2, 1.4]).

_PERIOD = "free Duffing T/2π against mpmath's K(m) at 30 digits"
_Q = "free Duffing q(t)/A against cn (SciPy's ellipj for m ≥ 0, mpmath below)"
_DRIVEN = "A₁, A₃, A₅ and B_n against shooting (RK4, Richardson-combined, Floquet-checked)"

METHODS: tuple[Method, ...] = (
    # the period, in the order its candidates are listed
    Method("exact", "period", "4K(m)/√(1+x), SciPy's ellipk", _PERIOD, _free_duffing,
           steps=True, orders=_exact_orders, cost=(22.0, 0.0)),
    Method("agm", "period", "1/AGM(√(1+x), √(1+x/2)), n steps", _PERIOD, _free_duffing,
           kind=4, steps=True, domain=x_ > -1, orders=_agm_orders, lowered=_lower_agm,
           target=CHOSEN_PERIOD, cost=(0.64, 0.24)),
    Method("lindstedt", "period", "the L–P series Σ τ_j x^j", _PERIOD, _series_period,
           kind=0, domain=sp.And(x_ > -1, sp.Abs(x_) < 1), orders=_lp_orders,
           lowered=_lower_lp, target=CHOSEN_PERIOD, cost=(0.33, 0.058)),
    Method("resummed", "period", "the series in m = x/(2(1+x)) times √(1 − 2m)", _PERIOD,
           _free_duffing, kind=1, domain=x_ > sp.Rational(-2, 3), orders=_resummed_orders,
           lowered=_lower_resummed, target=CHOSEN_PERIOD, cost=(0.43, 0.05)),
    Method("modified", "period", "modified L–P (Cheung, Chen & Lau)", _PERIOD, _free_duffing,
           kind=3, domain=x_ > -1, orders=_modified_orders, lowered=_lower_modified,
           target=CHOSEN_PERIOD, cost=(0.56, 0.05)),
    Method("pade", "period", "diagonal Padé [k/k] of the L–P series", _PERIOD, _series_period,
           kind=2, domain=x_ > -1, orders=_pade_orders, lowered=_lower_pade,
           target=CHOSEN_PERIOD, describe=lambda k: f"[{k}/{k}] Padé, {2 * k + 1} coefficients",
           cost=(0.24, 0.17)),
    # q(t)
    Method("lindstedt", "q", "the L–P series of q(t) (generate NAME)",
           "q(t) against cn; any free oscillator's period against quadrature", _free,
           target=FREE, cost=(3.1, 0.21)),
    Method("fourier", "q", "the exact Fourier series of cn in the nome, N odd harmonics", _Q,
           _free_duffing, target=FOURIER, cost=(86.0, 1.2)),
    Method("exact", "q", "cn by SciPy's ellipj (x ≥ 0; no emitted evaluator)", _Q,
           _free_duffing, cost=(73.0, 0.0)),
    # the driven amplitudes A_n(ω) and the response r(ω)
    Method("one_harmonic", "driven", "the one-harmonic cubic in closed form", _DRIVEN,
           _driven, driven_orders=(1,), cost=(800.0,)),
    Method("mu_expansion", "driven", "the μ-expansion with phase, order K", _DRIVEN, _driven,
           solve=_solve_mu, driven_orders=tuple(range(DRIVEN_MAX + 1)), target=MU,
           bound=0, run_emitted=_run_mu_module, emittable=_undamped,
           cost=(9.98e5, 0.0, 7.27e4), emitted_cost=(110.0, 26.0)),
    Method("mu_expansion_damped", "driven",
           "the μ-expansion with phase for a finite Q, exact orders (generate driven --damped)",
           _DRIVEN, _damped, solve=_solve_mu, driven_orders=tuple(range(1, DAMPED_MAX + 1)),
           target=MU_DAMPED, bound=0, run_emitted=_run_mu_damped_module, emittable=_damped,
           cost=(9.98e5, 0.0, 7.27e4), emitted_cost=(161.0, 0.0, 293.0)),
    Method("harmonic_balance", "driven", "Galerkin harmonic balance, N odd harmonics", _DRIVEN,
           _driven, solve=_solve_balance, driven_orders=tuple(range(1, DRIVEN_MAX + 1)),
           target=BALANCE, bound=1, run_emitted=_run_balance_module,
           cost=(6.61e5, 8.42e4), emitted_cost=(1960.0, 3794.0)),
    Method("shooting", "driven", "shooting with plain RK4, N steps a period", _DRIVEN, _driven,
           solve=_solve_shooting, driven_orders=SHOOTING_STEPS, cost=(5.09e5, 920.0)),
)


def method(quantity: str, name: str) -> Method:
    """The record of ``name`` for ``quantity``."""
    for m in METHODS:
        if m.quantity == quantity and m.name == name:
            return m
    raise KeyError(f"no method {name!r} for {quantity}")


def methods_for(quantity: str, subject: object | None = None) -> tuple[Method, ...]:
    """The methods of ``quantity`` (that apply to ``subject``, when given), in registry order."""
    return tuple(m for m in METHODS if m.quantity == quantity
                 and (subject is None or m.why_not(subject) is None))


# --- period candidates: every method at every order ----------------------------------------------

@dataclass(frozen=True)
class Candidate(PeriodTerms):
    """One period method at one order with its coefficients (as verified doubles)."""

    method: Method | None = None
    masked: bool = True  # NaN outside the free Duffing oscillator's domain (see _evaluate)

    def __call__(self, x: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        return self.method.evaluate(self, x, out)


def period_series(max_order: int, model: Model | None = None) -> PeriodSeries:
    """The exact τ_j and ω_j of ``model`` (the free Duffing oscillator by default)."""
    sol = derive(model or duffing(), check_order(max_order))
    return PeriodSeries([sol.ground.to_fraction(c) for c in sol.period],
                        [sol.ground.to_fraction(c) for c in sol.omega])


@functools.cache
def candidates(max_order: int = PERIOD_SERIES_ORDER, model: Model | None = None
               ) -> tuple[Candidate, ...]:
    """Every period method at every order up to ``max_order`` (Padé up to [12/12]) for
    ``model`` (the free Duffing oscillator by default), derived once: the fixed-order ones
    (exact, the AGM's steps) first, then order by order."""
    subject = model or duffing()
    series = period_series(max_order, subject)
    masked = model is None or _free_duffing(model) is None
    found = []
    for rank, m in enumerate(methods_for("period", subject)):
        for order, (num, den) in m.orders(series, max_order):
            found.append(((not m.steps, 0 if m.steps else order, rank),
                          Candidate(order, num, den, m, masked)))
    found.sort(key=lambda item: item[0])
    return tuple(c for _, c in found)
