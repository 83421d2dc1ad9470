"""The lowering's IR records: what a template lays out (no code strings), and the
documents' records (SymPy objects the LaTeX printer prints)."""

from __future__ import annotations

import hashlib
import json
import unicodedata
from dataclasses import dataclass
from typing import NamedTuple

import sympy as sp

from .. import __version__
from ..algebra.resum import Resummed
from ..analysis.mu_exact import MuDampedOrder, MuOrder
from ..derive.equation import Equation
from ..derive.lindstedt import Validity
from ..derive.orbits import RuntimeScan

Assign = tuple[sp.Symbol, sp.Expr]


def _unsafe(ch: str) -> bool:
    """Control, format, surrogate, private or unassigned, line or paragraph separator."""
    category = unicodedata.category(ch)
    return category[0] == "C" or category in ("Zl", "Zp")


def one_line(text: str) -> str:
    """``text`` as data on one line of a generated file: every character that could end a
    comment line or hide text (newline, other controls, separators) becomes a visible escape.

    >>> one_line("lindstedt generate\\nimport os")
    'lindstedt generate\\\\nimport os'
    """
    return "".join(ch.encode("unicode_escape").decode("ascii") if _unsafe(ch) else ch
                   for ch in str(text))


def docstring_text(text: str) -> str:
    """``text`` as data inside a generated ``\"\"\"`` docstring: backslashes and quotes
    escaped (no quote can close it), lines kept, other unsafe characters escaped."""
    text = str(text).replace("\\", "\\\\").replace('"', '\\"')
    return "\n".join(one_line(line) for line in text.split("\n"))


@dataclass(frozen=True)
class Evaluator:
    """Everything needed to emit one numba ufunc."""

    name: str
    doc: str
    args: tuple[sp.Symbol, ...]
    prelude: tuple[Assign, ...]
    guard: sp.Basic  # SymPy boolean; false -> NaN
    body: tuple[Assign, ...]
    output: sp.Expr

    def __post_init__(self) -> None:
        object.__setattr__(self, "doc", docstring_text(self.doc))


@dataclass(frozen=True)
class ArrayKernel:
    """One numba ``@njit`` function returning an array: ``x`` unpacked into named symbols,
    shared subexpressions, then ``out[index] = value`` entries."""

    name: str
    doc: str
    unpack: tuple[sp.Symbol, ...]  # x[0], x[1], … bound to these names
    args: tuple[sp.Symbol, ...]  # scalar arguments after x
    shape: tuple[int, ...]
    subexprs: tuple[Assign, ...]
    entries: tuple[tuple[tuple[int, ...], sp.Expr], ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "doc", docstring_text(self.doc))


@dataclass(frozen=True)
class Provenance:
    """What a generated file says about where it came from (no timestamp: reproducible)."""

    model: str
    order: int
    command: str
    inputs: str  # sha256 of the canonical description of the inputs

    def __post_init__(self) -> None:
        # NOTE: the command is the caller's text: it reaches the banner only as one line of data.
        object.__setattr__(self, "command", one_line(self.command))

    @property
    def version(self) -> str:
        """The lindstedt version the banner names (``lindstedt.__version__``)."""
        return __version__


@dataclass(frozen=True)
class Module:
    """One generated Python module: constants and evaluators."""

    name: str
    doc: str
    constants: tuple[tuple[str, object], ...]  # name -> int, float, str or tuple of them
    evaluators: tuple[Evaluator, ...]
    provenance: Provenance
    kernels: tuple[ArrayKernel, ...] = ()
    newton: bool = False  # emit newton(x0, …) driving the kernels "residual" and "jacobian"
    barrier: tuple[tuple[float, ...], ...] = ()
    # NOTE: V'(q)/q = Σ_j g_j(ε) q^j, barrier[j][i] the ε^i coefficient of g_j: where non-empty
    # the module finds the orbit domain at each (A, ε) (derive.orbits.RuntimeBarrier)
    barrier_weight: tuple[tuple[float, ...], ...] = ()
    # NOTE: 2H(q) = 2∫₀^q h, h the factor of q'² in the force, by powers of q and ε as barrier:
    # where non-empty the barrier compares W = ∫ 2 g₀ e^{2H} by quadrature, not V
    scan: RuntimeScan | None = None
    # NOTE: the force with its symbolic parameters: where given the module finds the orbit
    # domain at each call by a scan for the zeros of g₀ (derive.orbits.RuntimeScan)

    def __post_init__(self) -> None:
        object.__setattr__(self, "doc", docstring_text(self.doc))


def provenance(model: str, order: int, command: str, **inputs: object) -> Provenance:
    """Provenance with a hash over the canonical JSON of every input that shapes the output."""
    payload = json.dumps(
        {"version": __version__, "model": model, "order": order, **inputs},
        sort_keys=True, default=str,
    )
    return Provenance(model, order, command, hashlib.sha256(payload.encode()).hexdigest())


@dataclass(frozen=True)
class ResummedCycle:
    """A limit cycle's resummed frequency and where it was verified: ``|ε| ≤ limit``, with
    the largest measured error ``checked`` against the numerical references at ``points``;
    the same for its amplitude q(0) when its Padé form verified anywhere."""

    form: Resummed
    limit: float
    points: tuple[float, ...]
    checked: float
    tolerance: float
    amplitude: Resummed | None = None  # q(0), Padé in ε², with its (limit, points, checked)
    amplitude_verified: tuple[float, tuple[float, ...], float] = (0.0, (), float("nan"))
    harmonics: tuple[tuple[str, int, Resummed], ...] = ()  # q(s): ("cos"|"sin", n, a_n(ε))
    harmonics_verified: tuple[float, tuple[float, ...], float] = (0.0, (), float("nan"))


@dataclass(frozen=True)
class ResummedMathieu:
    """Mathieu's ``a_m(q)`` or ``b_m(q)``: the Padé of its exact series to ``order`` as the
    start of ``steps`` Newton steps on the determinant of the recurrence truncated to ``rows``
    rows, and where it was verified against the high-precision reference: ``0 ≤ q ≤ limit``
    (``|q|`` when the series is even in q), the largest error ``checked`` there, relative to
    max(1, |a|)."""

    kind: str
    m: int
    order: int
    form: Resummed
    limit: float
    tolerance: float
    checked: float
    rows: int
    steps: int


@dataclass(frozen=True)
class ResummedCurve:
    """One transition curve ``δ(ε)`` as the Padé of its exact series, verified against the
    Floquet boundary on ``0 ≤ ε ≤ limit`` (``|ε|`` when the series is even in ε), with the
    largest error ``checked`` there (absolute, in δ)."""

    label: str
    form: Resummed
    limit: float
    checked: float


@dataclass(frozen=True)
class ResummedTongue:
    """The transition curves of tongue ``n`` of ``ẍ + (δ + ε p(t))x = 0`` (``p`` as its user
    text, data only), each resummed and verified to ``tolerance`` in δ."""

    p: str
    n: int
    order: int
    tolerance: float
    curves: tuple[ResummedCurve, ...]


x_ = sp.Symbol("x")
# NOTE: x = εA², the variable of every period formula (:class:`PeriodFormula`).


@dataclass(frozen=True)
class PeriodFormula:
    """``T/2π`` of one verified period candidate in ``x = εA²``: assignments, then the value,
    inside the method's domain; its coefficients as the verified doubles (provenance)."""

    method: str
    order: int
    domain: sp.Basic  # SymPy boolean in x_
    body: tuple[Assign, ...]
    value: sp.Expr
    num: tuple[float, ...]
    den: tuple[float, ...]


# --- documents: the LaTeX beside a module, as SymPy objects (printed by emit) ---------------

@dataclass(frozen=True)
class SeriesTables:
    """The tables of a family of periodic orbits' L–P series to ``order`` (``tables.tex.j2``),
    one coordinate or several: the equations, ``ω = ω₀ Σ ω_j y^j``, ``T = (2π/ω₀) Σ τ_j y^j``
    and each coordinate's coefficient of ``A y^j cos ns`` per order, exact (the printer shows
    a long one as its decimal)."""

    title: str
    equations: tuple[str, ...]  # LaTeX, each as its model or system typesets it
    omega0: sp.Expr
    y: sp.Expr  # the expansion variable, in the amplitude (and ε)
    order: int
    omega: tuple[sp.Expr, ...]  # ω_j/ω₀
    period: tuple[sp.Expr, ...]  # τ_j ω₀
    coordinates: tuple[tuple[sp.Symbol, tuple[tuple[tuple[int, sp.Expr], ...], ...]], ...]
    amplitude: sp.Symbol  # the coordinate at its turning point at t = 0
    amplitude_value: sp.Expr  # its value there: A, θ₀
    validity: Validity | None = None  # a free oscillator's orbits and radius
    radius: tuple[float, float, float] | None = None
    # NOTE: a mode's ω series: the radius estimated in y, its spread and the lower bound its
    # module stops at (derive.nnm.radius); NaN where not estimated


@dataclass(frozen=True)
class DerivationOrder:
    """Order ``j`` of an L–P derivation: per coordinate the known part of the right side by
    harmonic (``(n, R_jn)``), the secular condition's known part (``ψ·R_j1``), the frequency
    correction it fixes (ω_j of one coordinate, Ω_j of a system) and the solution by harmonic
    (``(n, c_jn)``), exact."""

    j: int
    right: tuple[tuple[tuple[int, sp.Expr], ...], ...]
    secular: sp.Expr
    value: sp.Expr
    solution: tuple[tuple[tuple[int, sp.Expr], ...], ...]


@dataclass(frozen=True)
class LinearPart:
    """A system's linear part ``ẍ + Lx``: ``L = M⁻¹K``, ``λ = ω₀²`` of the mode, the mode's
    shape ``φ`` (right null vector of ``L − λ``) and ``ψ`` (left)."""

    stiffness: sp.Matrix
    lam: sp.Expr
    right: tuple[sp.Expr, ...]
    left: tuple[sp.Expr, ...]


@dataclass(frozen=True)
class SeriesDerivation:
    """The order-by-order L–P derivation of a family of periodic orbits
    (``derivation.tex.j2``), one coordinate or several.  With ``s = ωt``, order ``j`` of
    ``x = Σ_j coupling^j x_j(s)`` (each ``x_j``'s coefficients per ``unit·order_factor^j``)
    solves a linear equation whose right side's resonant ``cos s`` part,
    ``secular + weights·unknown_j``, must vanish (along ``ψ``): one coordinate's ω_j
    (weights ``2A``, ``unit`` A), a system's ``Ω_j`` of ``Ω = ω²`` (weights ``φ``, ``linear``
    given, ``unit`` 1: the coefficients of ``u = x/A``)."""

    title: str
    equations: tuple[str, ...]
    coordinates: tuple[sp.Symbol, ...]
    amplitude: sp.Symbol
    amplitude_value: sp.Expr  # the amplitude coordinate at t = 0: A, θ₀
    unit: sp.Expr
    y: sp.Expr
    coupling: sp.Expr
    order_factor: sp.Expr
    order: int
    unknown: str  # the frequency correction's LaTeX name: \omega, \Omega
    weights: tuple[sp.Expr, ...]
    orders: tuple[DerivationOrder, ...]
    validity: Validity | None = None
    linear: LinearPart | None = None


@dataclass(frozen=True)
class NotesTable:
    """The notes' driven table: A₁, A₃, A₅ by μ-order, harmonic balance and shooting at
    ``(eps, force, omega)``; a cell is a number, or the notes' own printed digits."""

    eps: float
    force: float
    omega: float
    rows: tuple[tuple[str, tuple[tuple[int, float | str], ...]], ...]


@dataclass(frozen=True)
class MuDerivation:
    """The μ-expansion's derivation to ``order`` and the notes' table (``mu_derivation.tex.j2``)."""

    order: int
    orders: tuple[MuOrder, ...]
    table: NotesTable


@dataclass(frozen=True)
class MuDampedDerivation:
    """The damped μ-expansion's derivation to ``order`` (``mu_damped_derivation.tex.j2``):
    ``F_j``, both secular conditions, ``b_{j−1}``, ``δ_{j−1}``, ``q_j`` and ``δ_j`` per order."""

    order: int
    orders: tuple[MuDampedOrder, ...]
    determinant: sp.Expr  # Δ in x, a, γ


@dataclass(frozen=True)
class CycleOrderPieces:
    """Order j of a limit cycle's document: ``F_j = K_j + a_(j−1) L + a₀ W_j cos s``, the two
    secular conditions and ``q_j`` (exact rationals; :class:`lindstedt.CycleOrder`)."""

    j: int
    known_cos: tuple[tuple[int, sp.Rational], ...]
    known_sin: tuple[tuple[int, sp.Rational], ...]
    a_prev: sp.Rational | None  # a_(j−1), from the sin s condition (None at j = 1)
    W: sp.Rational
    omega: sp.Rational
    q_cos: tuple[tuple[int, sp.Rational], ...]
    q_sin: tuple[tuple[int, sp.Rational], ...]


@dataclass(frozen=True)
class CycleDerivation:
    """The order-by-order derivation of a limit cycle (``cycle_derivation.tex.j2``): the
    amplitude equation ``S(a₀) = 0``, the linearisation ``L`` and the first orders."""

    model: str
    equation: Equation  # q'' + q = eps*f(q, q') as the user wrote it, parsed
    a0: sp.Rational
    slope: sp.Rational
    lin_cos: tuple[tuple[int, sp.Rational], ...]
    lin_sin: tuple[tuple[int, sp.Rational], ...]
    orders: tuple[CycleOrderPieces, ...]


@dataclass(frozen=True)
class Unit:
    """What one command writes: a module and the documents beside it."""

    module: Module
    documents: tuple[SeriesTables | SeriesDerivation | MuDerivation | MuDampedDerivation
                     | SlowFlowDocument | CycleDerivation, ...] = ()


# --- the slow flow (averaging) ---------------------------------------------------------------


@dataclass(frozen=True)
class SlowFlowDocument:
    """The slow flow's equations for ``slow_flow.tex.j2``: ``R_k``, ``Φ_k`` by order."""

    name: str
    equation: Equation  # as the user wrote it, parsed
    order: int
    driven: bool
    radial: tuple[sp.Expr, ...]
    phase: tuple[sp.Expr, ...]


# --- a spectral submanifold's reduced model --------------------------------------------------


class ForcingPiece(NamedTuple):
    """One piece of the drive's range in a reduced module: its ends, its first node's index in
    the module's table and its node count (0: unverified), the interpolation error reached at
    its midpoints (relative to the largest term), and whether that met the tolerance."""

    lo: float
    hi: float
    first: int
    count: int
    error: float
    verified: bool


@dataclass(frozen=True)
class ReducedModule:
    """The numbers of an SSM's reduced model for ``ssm.py.j2`` and ``ssm.tex.j2``: the normal
    form's ``γ_j`` (real and imaginary parts), the radius in ρ, each output's Fourier
    coefficients of ``ρ^k e^{ihθ}`` (``(K + 1) × (2K + 1) × outputs``), and the forced terms
    on Chebyshev nodes over the pieces of ``[lo, hi]`` (:class:`ForcingPiece`; an unverified
    piece holds no nodes); per node ``A_j``, ``B_j``, then the outputs' ``W¹``
    order by order; ``sizes``: how many ``A_j``, ``B_j`` and the order of ``W¹``; empty: not
    driven; ``tolerance``: the error a piece must reach)."""

    name: str
    doc: str
    provenance: Provenance
    mode: int
    order: int
    outputs: tuple[str, ...]
    gamma: tuple[tuple[float, float], ...]
    radius: float
    shape: tuple[tuple[tuple[tuple[float, float], ...], ...], ...]
    span: tuple[float, float] | None
    pieces: tuple[ForcingPiece, ...]
    nodes: tuple[float, ...]
    forcing: tuple[tuple[tuple[float, float], ...], ...]  # per node: A, B, W¹ flattened
    sizes: tuple[int, int, int]
    tolerance: float  # the interpolation error a piece must reach to be verified

    def __post_init__(self) -> None:
        object.__setattr__(self, "doc", docstring_text(self.doc))

    @property
    def interpolation_error(self) -> float:
        """The forced terms' largest interpolation error over the verified pieces (NaN: none
        is, or not driven)."""
        return max((p.error for p in self.pieces if p.verified), default=float("nan"))

