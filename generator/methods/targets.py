"""What ``generate`` derives and lowers, per target: its files, its derivation and its
lowering (:class:`Target`), from one :class:`Request`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

from ..analysis.driven import (
    Drive,
    amplitudes,
    first_order_branches,
    harmonic_balance,
    mu_expansion,
)
from ..analysis.mu_exact import (
    BalanceEquations,
    MuDampedOrder,
    MuOrder,
    balance_equations,
    damped_determinant,
    mu_expansion_damped,
    mu_expansion_exact,
)
from ..analysis.ssm_forced import Reduction, reduce
from ..derive.averaging import SlowFlow, slow_flow
from ..derive.cycles import LimitCycle, derive_limit_cycle
from ..derive.lindstedt import SeriesSolution, derive
from ..derive.models import Model, Oscillator, SelfExcited
from ..derive.nnm import NormalModeSeries, normal_mode
from ..derive.system import System
from ..errors import InputError
from ..limits import FOURIER_MAX_HARMONICS, check_int
from ..lower.documents import (
    lower_choice,
    lower_cycle_derivation,
    lower_fourier,
    lower_series_derivation,
    lower_slow_flow,
    lower_tables,
)
from ..lower.driven import lower_balance, lower_driven, lower_driven_damped
from ..lower.records import (
    MuDampedDerivation,
    MuDerivation,
    NotesTable,
    PeriodFormula,
    ResummedCycle,
    ResummedMathieu,
    ResummedTongue,
    Unit,
)
from ..lower.series import lower_limit_cycle, lower_mathieu, lower_periodic, lower_tongue
from ..lower.ssm import lower_reduction
from ..numerics.shooting import shoot
from .verify import resum_cycle, resum_mathieu, resum_tongue

Progress = Callable[[int, int], None]
# NOTE: the one progress callback (done, total) every long derivation takes; the command line
# draws it (cli.common.ProgressBar).

# --- emission: what `generate` derives and lowers ------------------------------------------------

@dataclass(frozen=True)
class Request:
    """One emission asked for: the order of the series (or the count a target is sized by)
    and the command that asked; each target's own request adds what it needs."""

    order: int
    command: str


@dataclass(frozen=True)
class FreeRequest(Request):
    """A free oscillator's module: its model, and whether a divergent series may be emitted."""

    model: Model
    allow_divergent: bool = False


@dataclass(frozen=True)
class CycleRequest(Request):
    """A limit cycle's module: its self-excited model and the order of the ω series that the
    radius and the resummation use (``None``: :data:`RADIUS_ORDER`)."""

    model: SelfExcited
    resum_order: int | None = None


@dataclass(frozen=True)
class HarmonicsRequest(Request):
    """A module sized by its harmonics (the balance, the Fourier period): ``order`` is the
    number of harmonics."""

    @property
    def harmonics(self) -> int:
        """The number of harmonics (the request's ``order``)."""
        return self.order


@dataclass(frozen=True)
class ChoiceRequest(Request):
    """``choose --out``: the chosen period formula and the range it was verified on."""

    formula: PeriodFormula
    verified: tuple[float, float]


@dataclass(frozen=True)
class SlowFlowRequest(Request):
    """The slow flow of a user's oscillator (an :class:`Oscillator`, driven or not)."""

    model: Oscillator


@dataclass(frozen=True)
class MathieuRequest(Request):
    """Mathieu's ``a_m`` (kind "a") or ``b_m`` (kind "b") resummed."""

    kind: str
    m: int


@dataclass(frozen=True)
class NormalModeRequest(Request):
    """One nonlinear normal mode of a system: the mode, its amplitude coordinate (an index),
    the module's name and whether it may be evaluated past its radius."""

    system: System
    mode: int
    amplitude: int
    name: str
    allow_divergent: bool = False


@dataclass(frozen=True)
class ReductionRequest(Request):
    """The SSM of one mode of a system (text or model folder): its outputs (indices, None:
    the default), the forced response's range (None: the default, where driven) and the
    module's name."""

    system: System
    mode: int
    outputs: tuple[int, ...] | None
    span: tuple[float, float] | None
    name: str


@dataclass(frozen=True)
class TongueRequest(Request):
    """The transition curves of tongue ``n`` of Hill's equation with ``p(t)`` (text)."""

    p: str
    n: int


Asked = TypeVar("Asked", bound=Request)
Derived = TypeVar("Derived")


@dataclass(frozen=True)
class Target(Generic[Asked, Derived]):
    """What a method emits: its files, and its derive and lower stages (the compiler calls
    each once, in order, then renders and writes), typed in its request and in what the
    derivation hands the lowering (``Target[FreeRequest, SeriesSolution]``, …)."""

    files: Callable[[Asked], tuple[str, ...]]
    derive: Callable[[Asked, Progress | None], Derived]
    lower: Callable[[Derived, Asked], Unit]


def _free_files(r: FreeRequest) -> tuple[str, ...]:
    name = r.model.name
    return (f"{name}.py", f"{name}_tables.tex", f"{name}_derivation.tex")


def _free_derive(r: FreeRequest, progress: Progress | None) -> SeriesSolution:
    return derive(r.model, r.order + 2, progress)


def _free_lower(solution: SeriesSolution, r: FreeRequest) -> Unit:
    module = lower_periodic(solution, r.command, allow_divergent=r.allow_divergent)
    return Unit(module, (lower_tables(solution, r.order),
                         lower_series_derivation(solution, r.order)))


def _cycle_files(r: CycleRequest) -> tuple[str, ...]:
    return (f"{r.model.name}.py", f"{r.model.name}_derivation.tex")


RADIUS_ORDER = 60
# NOTE: a limit cycle's radius is estimated from ω to at least this order (1 % from order 60
# for van der Pol), whatever order its evaluators sum.


def cycle_series_order(order: int, resum_order: int | None) -> int:
    """The order a limit cycle's exact series is derived to when its evaluators sum
    ``order``: ``resum_order`` when given (its radius estimate and resummed ω use every
    term), else :data:`RADIUS_ORDER`, and never below ``order + 2``."""
    return max(order + 2, RADIUS_ORDER if resum_order is None else resum_order)


def _cycle_derive(r: CycleRequest, progress: Progress | None
                  ) -> tuple[LimitCycle, ResummedCycle | None]:
    from ..derive.cycles import limit_cycles

    first = limit_cycles(r.model)[0]
    if not first.rational:
        raise InputError(f"{r.model.name}: the limit cycle's amplitude {first.amplitude} is "
                         "irrational: `lindstedt series` gives its exact series in "
                         f"Q({first.amplitude}); the evaluators and their resummation need "
                         "rational coefficients and are not emitted for it")
    lc = derive_limit_cycle(r.model, cycle_series_order(r.order, r.resum_order))
    resummed = resum_cycle(lc)
    if isinstance(resummed, str) and r.resum_order is not None:
        raise InputError(f"--resum-order {r.resum_order}: {r.model.name}'s ω(ε) is not "
                         f"resummed: {resummed}; without --resum-order, generate emits the "
                         "partial sums and their error estimate")
    return lc, None if isinstance(resummed, str) else resummed


def _cycle_lower(derived: tuple[LimitCycle, ResummedCycle | None], r: CycleRequest) -> Unit:
    import sys

    cycle, resummed = derived
    # NOTE: the exact coefficients pass Python's 4300-digit int → str limit from order ~150
    # (the module's OMEGA_EXACT, AMPLITUDE_EXACT and the LaTeX); lifted while lowering.
    limit = sys.get_int_max_str_digits()
    sys.set_int_max_str_digits(0)
    try:
        return Unit(lower_limit_cycle(cycle, r.command, r.order, resummed),
                    (lower_cycle_derivation(cycle, r.order),))
    finally:
        sys.set_int_max_str_digits(limit)


def _mathieu_files(r: MathieuRequest) -> tuple[str, ...]:
    return (f"mathieu_{r.kind}{r.m}.py",)


def _mathieu_derive(r: MathieuRequest, progress: Progress | None) -> ResummedMathieu:
    return resum_mathieu(r.kind, r.m, r.order)


def _mathieu_lower(derived: ResummedMathieu, r: MathieuRequest) -> Unit:
    return Unit(lower_mathieu(derived, r.command))


def _tongue_derive(r: TongueRequest, progress: Progress | None) -> ResummedTongue:
    return resum_tongue(r.p, r.n, r.order)


def _tongue_lower(derived: ResummedTongue, r: TongueRequest) -> Unit:
    return Unit(lower_tongue(derived, r.command))


NOTES_DRIVE = (0.1, 1.0, 1.0)
# NOTE: ε, f, ω of the notes' table (§10.4, undamped), reproduced in every driven derivation.
NOTES_TABLE_ORDERS = 6


def notes_table() -> NotesTable:
    """The notes' table: A₁, A₃, A₅ by μ-order, harmonic balance and shooting."""
    eps, force, omega = NOTES_DRIVE
    d = Drive(eps, force, omega)
    (branch,) = first_order_branches(d)
    mu = mu_expansion(d, branch, NOTES_TABLE_ORDERS)

    def cells(A: dict) -> tuple[tuple[int, float | str], ...]:
        return tuple((n, A[n] if A.get(n) else "") for n in (1, 3, 5))

    rows = [(f"$\\mu$-expansion, order {j}", cells(amplitudes(*mu.partial(j), 2 * j + 1)[0]))
            for j in range(NOTES_TABLE_ORDERS + 1)]
    hb = harmonic_balance(d, branch, 8)
    A, _ = amplitudes(hb.coefficients, 0.0, 15)
    rows.append(("harmonic balance, $N = 8$", cells(A)))
    orbit = shoot(eps, force, omega, 0.0, np.array([sum(A.values()), 0.0]))
    rows.append(("numerical (shooting)", cells(orbit.A)))
    rows.append(("notes: numerical", ((1, "2.356"), (3, "0.0456"), (5, "0.0008"))))
    return NotesTable(eps, force, omega, tuple(rows))


def _mu_derive(r: Request, progress: Progress | None
               ) -> tuple[tuple[MuOrder, ...], NotesTable]:
    return mu_expansion_exact(r.order), notes_table()


def _mu_lower(derived: tuple[tuple[MuOrder, ...], NotesTable], r: Request) -> Unit:
    orders, table = derived
    return Unit(lower_driven(orders, r.command), (MuDerivation(r.order, orders, table),))


def _balance_derive(r: HarmonicsRequest, progress: Progress | None) -> BalanceEquations:
    return balance_equations(r.harmonics)


def _balance_lower(eqs: BalanceEquations, r: HarmonicsRequest) -> Unit:
    return Unit(lower_balance(eqs, r.command))


def _fourier_derive(r: HarmonicsRequest, progress: Progress | None) -> int:
    harmonics = r.harmonics
    return check_int(harmonics, 1, FOURIER_MAX_HARMONICS,
                     f"harmonics {harmonics!r}: must be an integer in 1..{FOURIER_MAX_HARMONICS}")


def _fourier_lower(harmonics: int, r: HarmonicsRequest) -> Unit:
    return Unit(lower_fourier(harmonics, r.command))


def _choice_derive(r: ChoiceRequest, progress: Progress | None) -> PeriodFormula:
    return r.formula  # derived and verified by choose


def _choice_lower(formula: PeriodFormula, r: ChoiceRequest) -> Unit:
    return Unit(lower_choice(formula, r.command, r.verified))


FREE: Target[FreeRequest, SeriesSolution] = Target(_free_files, _free_derive, _free_lower)
LIMIT_CYCLE: Target[CycleRequest, tuple[LimitCycle, ResummedCycle | None]] = Target(
    _cycle_files, _cycle_derive, _cycle_lower)
MU: Target[Request, tuple[tuple[MuOrder, ...], NotesTable]] = Target(
    lambda r: ("driven.py", "driven_derivation.tex"), _mu_derive, _mu_lower)
BALANCE: Target[HarmonicsRequest, BalanceEquations] = Target(
    lambda r: ("balance.py",), _balance_derive, _balance_lower)


DAMPED_MAX = 11
# NOTE: the damped μ-expansion is emitted at orders 1..11 (its derivation's bound, one order
# more estimates the truncation error); interpreted, it is the float μ-expansion's solve.


def _mu_damped_derive(r: Request, progress: Progress | None) -> tuple[MuDampedOrder, ...]:
    check_int(r.order, 1, DAMPED_MAX, f"order {r.order!r}: the damped μ-expansion is emitted "
              f"at orders 1..{DAMPED_MAX}")
    return mu_expansion_damped(r.order + 1)  # one order more: the truncation error's estimate


def _mu_damped_lower(orders: tuple[MuDampedOrder, ...], r: Request) -> Unit:
    return Unit(lower_driven_damped(orders, r.command),
                (MuDampedDerivation(r.order, orders[: r.order], damped_determinant()),))


MU_DAMPED: Target[Request, tuple[MuDampedOrder, ...]] = Target(
    lambda r: ("driven_damped.py", "driven_damped_derivation.tex"), _mu_damped_derive,
    _mu_damped_lower)
FOURIER: Target[HarmonicsRequest, int] = Target(
    lambda r: ("fourier.py",), _fourier_derive, _fourier_lower)
CHOSEN_PERIOD: Target[ChoiceRequest, PeriodFormula] = Target(
    lambda r: ("chosen_period.py",), _choice_derive, _choice_lower)
SLOW_FLOW: Target[SlowFlowRequest, SlowFlow] = Target(
    lambda r: (f"{r.model.name}_slow_flow.py", f"{r.model.name}_slow_flow.tex"),
    lambda r, progress: slow_flow(r.model, r.order),
    lambda flow, r: lower_slow_flow(flow, r.command))
MATHIEU: Target[MathieuRequest, ResummedMathieu] = Target(
    _mathieu_files, _mathieu_derive, _mathieu_lower)
TONGUE: Target[TongueRequest, ResummedTongue] = Target(
    lambda r: (f"tongue_{r.n}.py",), _tongue_derive, _tongue_lower)

NNM_RADIUS_ORDER = 24
# NOTE: a mode's radius is estimated from ω to at least this order (nearest_singularity needs
# 12 coefficients in y; 24 keep the estimate's spread small), whatever order the module sums.
NNM: Target[NormalModeRequest, NormalModeSeries] = Target(
    lambda r: (f"{r.name}.py", f"{r.name}_tables.tex", f"{r.name}_derivation.tex"),
    lambda r, progress: normal_mode(r.system, r.mode, max(r.order + 2, NNM_RADIUS_ORDER),
                                    r.amplitude, progress),
    lambda series, r: Unit(lower_periodic(series, r.command, r.order, r.name,
                                          r.allow_divergent),
                           (lower_tables(series, r.order),
                            lower_series_derivation(series, r.order))))


SSM_FRC_POINTS = 41
# NOTE: the forced response the derivation samples (its states are not emitted: the module
# solves each w itself); the module's forcing is fitted over the range by lower.ssm (forcing_fit,
# in pieces where one fit misses its tolerance).
SSM: Target[ReductionRequest, Reduction] = Target(
    lambda r: (f"{r.name}.py", f"{r.name}_reduced.tex"),
    lambda r, progress: reduce(r.system, r.mode, r.order,
                               None if r.outputs is None else list(r.outputs), None, r.span,
                               SSM_FRC_POINTS),
    lambda red, r: Unit(lower_reduction(red, r.name, r.command)))
