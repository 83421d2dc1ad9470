"""A system of coupled oscillators from text: one equation per coordinate, separated by ``;``.

``M x'' + C x' + K x + f(x, x') = F cos ωt`` with a constant mass matrix ``M`` (diagonal: each
equation holds its own acceleration; full: symmetric positive definite, the coordinates in the
order their accelerations first appear), the damping ``C``, the stiffness ``K``, the
nonlinear force ``f`` (terms of degree ≥ 2) and a drive ``F cos ωt`` (``response`` takes it;
``nnm`` and ``slowflow`` take ``C = 0``, ``F = 0``), every coefficient exact.  The linear
modes are the roots ``λ = ω₀²`` of ``det(K − λM) = 0``, kept exact: a rational, or an
algebraic number (SymPy's ``CRootOf`` with its minimal polynomial), never rounded; modes are
numbered by increasing linear frequency.

The same record holds the system as written in floating point, with sparse matrices
(:class:`Matrices`: ``M``, ``C``, ``K`` in CSR, the force as a table of terms, ``F``), for
every system — derived from the exact one (:attr:`System.matrices`) or read from a finite-element
code's files (:func:`read_model`, no exact form: ``System.exact`` is false, and the methods
that need exact modes say so).  Nothing of size n² is formed for it: memory grows with the
nonzeros.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np
import scipy.sparse as sparse
import sympy as sp

from ..errors import InputError
from .equation import TIME, derivative_symbols, parse_expression, parse_sides, renamed
from .problem import read_problem

MAX_COORDINATES = 12
# NOTE: a bound of the exact ground, not of the record: exact eigenvalues of a larger stiffness
# matrix (a characteristic polynomial of degree > 12) are not sought; the FPU chains and
# structures a user writes by hand stay far below.


DENSE_MODES = 200
# NOTE: up to this many coordinates the linear modes come from a dense generalized eigenvalue
# problem (every mode, LAPACK); above it from shift-invert Lanczos about 0 (ARPACK, the lowest
# few), which needs only M, K and a sparse factorization of K.


@dataclass(frozen=True)
class Polynomial:
    """A polynomial force of ``n`` coordinates as a table of terms, in floating point: term
    ``t`` adds ``coefficient[t] · Π_k z[factors[t, k]]`` to component ``equation[t]``, where
    ``z = (x, x')`` (an index ``k < n`` is ``x_k``, ``n + k`` is ``x'_k``) and ``factors`` is
    padded with ``-1`` (no factor).  Repeated terms add up."""

    size: int
    equation: np.ndarray  # (T,) int
    factors: np.ndarray  # (T, d) int, −1 padding
    coefficient: np.ndarray  # (T,) float

    @property
    def degree(self) -> int:
        """The highest degree of a term (0: no term)."""
        return int((self.factors >= 0).sum(axis=1).max()) if len(self.coefficient) else 0

    def __call__(self, x: np.ndarray, v: np.ndarray | None = None) -> np.ndarray:
        """``f(x, x')``: the force at one state (velocities zero where not given)."""
        z = np.concatenate([x, np.zeros(self.size) if v is None else v, [1.0]])
        terms = self.coefficient * np.prod(z[self.factors], axis=1)  # −1 picks the 1
        return np.bincount(self.equation, terms, minlength=self.size)

    def jacobian(self, x: np.ndarray) -> sparse.csr_array:
        """``∂f/∂x`` at ``x`` (velocities zero), sparse: one entry per term and factor."""
        z = np.concatenate([x, np.zeros(self.size), [1.0]])
        rows, cols, vals = [], [], []
        for k in range(self.factors.shape[1]):
            column = self.factors[:, k]
            rest = np.delete(self.factors, k, axis=1)
            keep = (column >= 0) & (column < self.size)
            rows.append(self.equation[keep])
            cols.append(column[keep])
            vals.append((self.coefficient * np.prod(z[rest], axis=1))[keep])
        shape = (self.size, self.size)
        if not rows:
            return sparse.csr_array(shape)
        return sparse.csr_array((np.concatenate(vals), (np.concatenate(rows),
                                                        np.concatenate(cols))), shape=shape)


@dataclass(frozen=True)
class Matrices:
    """``M x'' + C x' + K x + f(x, x') = F cos ωt`` as written, in floating point: ``M``,
    ``C``, ``K`` sparse (CSR; ``C`` ``None`` without linear damping), ``f`` a
    :class:`Polynomial` (degree ≥ 2), ``F`` (``None``: not driven)."""

    mass: sparse.csr_array
    stiffness: sparse.csr_array
    force: Polynomial
    damping: sparse.csr_array | None = None
    drive: np.ndarray | None = None

    @property
    def size(self) -> int:
        """The number of coordinates."""
        return self.mass.shape[0]

    def frequencies(self, count: int) -> np.ndarray:
        """The ``count`` lowest linear frequencies ω₀ (``K φ = ω₀² M φ``), ascending:
        dense (every mode) up to :data:`DENSE_MODES` coordinates, else shift-invert Lanczos
        about 0; refused where a mode is not an oscillation (ω₀² ≤ 0)."""
        n = self.size
        if not 1 <= count <= n:
            raise InputError(f"{count} modes: the model has {n} coordinates")
        if n <= DENSE_MODES or count >= n - 1:
            from scipy.linalg import eigh

            lam = eigh(self.stiffness.toarray(), self.mass.toarray(), eigvals_only=True)
        else:
            from scipy.sparse.linalg import eigsh

            lam = eigsh(self.stiffness.tocsc(), count, self.mass.tocsc(), sigma=0,
                        which="LM", return_eigenvectors=False)
        lam = np.sort(lam)[:count]
        if not lam[0] > 0:
            raise InputError(f"the lowest linear mode has ω0² = {lam[0]:.6g}: no oscillation "
                             "about the origin (every ω0² must be > 0)")
        return np.sqrt(lam)


@dataclass(frozen=True)
class System:
    """``M x'' + K x + f(x, x') = 0``: coordinates in the order of the equations, the mass
    matrix ``M`` and the lowered ``M⁻¹K`` exact rationals, the force ``M⁻¹f`` (the terms of
    degree ≥ 2) polynomials."""

    text: str
    coordinates: tuple[sp.Symbol, ...]
    velocities: tuple[sp.Symbol, ...]
    mass: sp.Matrix | None  # M: constant, symmetric positive definite (None: no exact form)
    stiffness: sp.Matrix | None  # M⁻¹K
    force: tuple[sp.Expr, ...]  # M⁻¹ f(x, x'), degree ≥ 2
    damping: sp.Matrix | None = None  # M⁻¹C (None: no linear velocity term)
    drive: tuple[sp.Rational, ...] = ()  # M⁻¹F: the amplitude of cos(ωt) in each equation
    frequency: sp.Symbol | None = None  # ω's name in the drive
    written: Matrices | None = field(default=None, compare=False)
    # the floating-point form where it was read so (read_model: then mass, stiffness and
    # force are None, no exact form); else made from the exact one on first use

    @property
    def exact(self) -> bool:
        """Whether the system has its exact form (a text): the ground of exact modes."""
        return self.stiffness is not None

    @cached_property
    def matrices(self) -> Matrices:
        """The system as written in floating point, sparse: ``M``, ``C = M·(M⁻¹C)``,
        ``K = M·(M⁻¹K)``, ``f = M·(M⁻¹f)`` as a table of terms, ``F``."""
        if self.written is not None:
            return self.written
        M = self.mass
        n = self.size

        def csr(A: sp.Matrix) -> sparse.csr_array:
            return sparse.csr_array(np.array(A, dtype=float).reshape(n, n))

        state = (*self.coordinates, *self.velocities)
        rows, factors, coefficients = [], [], []
        for i, f in enumerate(M * sp.Matrix(self.force)):
            f = sp.expand(f)
            if f == 0:
                continue
            for powers, c in sp.Poly(f, *state).terms():
                rows.append(i)
                factors.append([k for k, p in enumerate(powers) for _ in range(p)])
                coefficients.append(float(c))
        width = max((len(f) for f in factors), default=0)
        table = Polynomial(n, np.array(rows, dtype=np.int64),
                           np.array([f + [-1] * (width - len(f)) for f in factors],
                                    dtype=np.int64).reshape(len(rows), width),
                           np.array(coefficients, dtype=float))
        return Matrices(csr(M), csr(M * self.stiffness), table,
                        None if self.damping is None else csr(M * self.damping),
                        np.array(self.written_drive, dtype=float) if self.drive else None)

    @property
    def size(self) -> int:
        """The number of degrees of freedom."""
        return len(self.coordinates)

    @property
    def written_drive(self) -> tuple[sp.Rational, ...]:
        """The drive's amplitudes as the equations write them, ``F = M·(M⁻¹F)``."""
        return tuple(self.mass * sp.Matrix(self.drive)) if self.drive else ()

    @property
    def conservative(self) -> bool:
        """No velocity in any force and no drive (time-reversible: the cosine ansatz of
        ``nnm`` holds)."""
        if not self.exact:
            w = self.matrices
            return (w.damping is None and w.drive is None
                    and not np.any(w.force.factors >= self.size))
        return (self.damping is None and not self.drive
                and not any(f.has(*self.velocities) for f in self.force))

    def response_bound(self) -> tuple[float | None, str]:
        """``b`` with ``√Σ_i (A_i1² + B_i1²) ≤ b/ω`` for every periodic orbit of period
        ``2π/ω`` — and every harmonic-balance solution —, with the reason; ``None`` and why not
        where it does not hold.

        Multiply the equations by the masses: ``Mẍ + Cẋ + Kx + ∇V(x) = F cos ωt``.  Where ``K``
        is symmetric, the nonlinear force a gradient and ``C + Cᵀ`` positive definite, the
        power balance over a period is ``⟨ẋᵀCẋ⟩ = ½ Fᵀ V₁`` (``V₁`` the cos ωt part of ``ẋ``:
        ``Mẍ``, ``Kx`` and ``∇V`` do no net work round a closed orbit), so
        ``c_min ⟨|ẋ|²⟩ ≤ ½ |F| |V₁|`` with ``⟨|ẋ|²⟩ ≥ ½|V₁|²``: ``ω r₁ ≤ |V₁| ≤ |F|/c_min``.  A
        balance solution meets it too: ``ẋ`` lies in the span the residual is orthogonal to."""
        n = self.size
        M = self.mass
        K = M * self.stiffness
        g = [sp.expand(e) for e in M * sp.Matrix(self.force)]
        if self.damping is None:
            return None, "no damping"
        if any(f.has(*self.velocities) for f in g):
            return None, "a nonlinear velocity term (the power balance needs linear damping)"
        if K != K.T:
            return None, "the stiffness M·K is not symmetric"
        if any(sp.expand(sp.diff(g[i], self.coordinates[j]) - sp.diff(g[j], self.coordinates[i]))
               != 0 for i in range(n) for j in range(i)):
            return None, "the nonlinear force has no potential"
        C = M * self.damping
        c_min = float(np.linalg.eigvalsh(np.array((C + C.T) / 2, dtype=float)).min())
        if not c_min > 0:
            return None, "the damping M·C is not positive definite"
        F = math.sqrt(sum(float(d) ** 2 for d in M * sp.Matrix(self.drive)))
        return F / c_min, (f"power balance: |F| = {F:.6g}, c_min = {c_min:.6g}, the "
                           "damping's smallest eigenvalue")

    def equations(self) -> tuple[dict[tuple[int, ...], float], ...]:
        """Each equation's force ``g_i`` (``ẍ_i + g_i(x, ẋ) = d_i cos ωt``: stiffness, damping
        and the nonlinear terms) as ``{(a₁ … a_n, b₁ … b_n): c}`` in floats, the form of
        :class:`numerics.integrate.PolynomialField`."""
        n = self.size
        out = []
        for i in range(n):
            g = (sum(self.stiffness[i, j] * self.coordinates[j] for j in range(n))
                 + (0 if self.damping is None else
                    sum(self.damping[i, j] * self.velocities[j] for j in range(n)))
                 + self.force[i])
            poly = sp.Poly(g, *self.coordinates, *self.velocities)
            out.append({k: float(c) for k, c in poly.terms() if c != 0})
        return tuple(out)

    def modes(self) -> tuple[sp.Expr, ...]:
        """The exact ``λ = ω₀²`` of each linear mode, by increasing value (``M⁻¹K``'s
        eigenvalues; each root of the characteristic polynomial's irreducible factors),
        computed once per system."""
        return self._modes

    @cached_property
    def _modes(self) -> tuple[sp.Expr, ...]:
        if not self.exact:
            raise InputError(f"{self.text}: a model read in floating point has no exact "
                             "linear modes (they are sought for a system written as text); "
                             "its frequencies are System.matrices.frequencies(k)")
        if self.size > MAX_COORDINATES:
            raise InputError(f"system {self.text!r}: {self.size} coordinates; exact linear modes "
                             "(the roots of a characteristic polynomial of degree n) are "
                             f"sought for at most {MAX_COORDINATES}")
        lam = sp.Symbol("lambda")
        poly = sp.Poly(self.stiffness.charpoly(lam).as_expr(), lam)
        roots: list[sp.Expr] = []
        for factor, multiplicity in poly.factor_list()[1]:
            roots += _roots(factor) * multiplicity
        return tuple(sorted(roots, key=lambda r: float(sp.N(r, 30))))


def _roots(factor: sp.Poly) -> list[sp.Expr]:
    """The real roots of an irreducible factor: rationals, square roots, else ``CRootOf``."""
    if factor.degree() <= 2:
        roots = sp.roots(factor, multiple=True)
        if all(r.is_real for r in roots):
            return [_simpler(factor, r) for r in roots]
    return [sp.CRootOf(factor, k) for k in range(factor.count_roots())]


def _simpler(factor: sp.Poly, root: sp.Expr) -> sp.Expr:
    """``nsimplify``'s form of a quadratic's root where it is still a root, exactly: for a
    large coefficient (1e16) it returns a nearby rational instead, and ``L − λ`` would then
    have no null vector."""
    simpler = sp.nsimplify(root)
    return simpler if sp.expand(factor.as_expr().subs(factor.gen, simpler)) == 0 else root


def system_parameters(text: str) -> tuple[tuple[str, ...], str | None]:
    """The names of a (possibly driven) system's parameters, and its drive frequency's name
    (``None``: not driven); refused in one line as :func:`parse_system` refuses."""
    _, _, names, frequency = _read(text, True)
    return tuple(sorted(names)), None if frequency is None else str(frequency)


def _read(text: str, driven: bool
          ) -> tuple[list[str], list, set[str], sp.Symbol | None]:
    """The coordinates, each equation (with its drive's amplitude apart when driven), the
    parameters' names and the drive's frequency of ``text``."""
    parts = read_problem(text).equations if isinstance(text, str) else [text]
    if not parts:
        raise InputError(f"system {text!r}: no such preset; write its equations (one per "
                         "coordinate, separated by ';')")
    for i, part in enumerate(parts):
        if not part:
            raise InputError(f"system {text!r}: equation {i + 1} is empty (a ';' with nothing "
                             "beside it)")
    sides = [parse_sides(p, "equation") for p in parts]
    coordinates = []
    for i, (_, _, orders, _) in enumerate(sides):
        accelerations = [n for n, k in orders.items() if k == 2]  # in the text's order
        if not accelerations:
            raise InputError(f"system {text!r}: equation {i + 1} holds no acceleration; "
                             "write each coordinate's equation with its x''")
        coordinates += [n for n in accelerations if n not in coordinates]
    if len(coordinates) != len(parts):
        held = ", ".join(c + "''" for c in coordinates)
        raise InputError(f"system {text!r}: {len(parts)} equations hold the accelerations of "
                         f"{len(coordinates)} coordinate{'s' * (len(coordinates) > 1)} "
                         f"({held}); one equation per coordinate")
    bad = sorted({n for _, _, o, _ in sides for n in o} - set(coordinates))
    if bad:
        raise InputError(f"system {text!r}: {', '.join(bad)} has no equation of its own; each "
                         "coordinate needs its acceleration (x'') and its equation")
    exprs = [renamed(lhs - rhs, coordinates) for lhs, rhs, _, _ in sides]
    # NOTE: "-x1'' - 2*x1 + … = 0" is "x1'' + 2*x1 - … = 0": an equation whose own
    # acceleration enters with a negative number is taken negated (its row of M positive)
    for i, c in enumerate(coordinates):
        own = sp.expand(exprs[i]).coeff(derivative_symbols(c)[2])
        if own.is_Rational and own < 0:
            exprs[i] = -exprs[i]
    names = {n for _, _, _, ns in sides for n in ns if n.rstrip("_") not in coordinates}
    frequency = None
    if TIME in names:
        if not driven:
            raise InputError(f"system {text!r}: t appears explicitly; a driven system is not a "
                             "free one (nnm takes autonomous systems; lindstedt response "
                             "takes driven ones)")
        exprs, frequency = _drive_split(text, exprs)
        names -= {TIME, str(frequency)}
    return coordinates, exprs, names, frequency


def parse_system(text: str, values: dict[str, str] | None = None,
                 driven: bool = False, symbolic: bool = False) -> System:
    """A :class:`System` from ``"x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"``:
    every name but the coordinates needs an exact value (``values``, from ``--param``).
    ``driven``: the system may be driven, ``f*cos(w*t)`` on the right of one or more
    equations, one frequency ``w`` (left free: the response varies it)."""
    values = dict(values or {})
    coordinates, exprs, names, frequency = _read(text, driven)
    if frequency is not None and str(frequency) in values:
        raise InputError(f"--param {frequency}: {frequency} is the drive frequency; the "
                         "response varies it (give its range with --omega A:B)")
    given = {sp.Symbol(k): parse_expression(v, f"--param {k}") for k, v in values.items()}
    for k, v in given.items():
        if not v.is_Rational:
            raise InputError(f"--param {k}={values[str(k)]}: an exact rational, e.g. 1/3")
    unused = sorted(str(k) for k in given if str(k) not in names)
    if unused:
        raise InputError(f"--param {unused[0]}: no such name in the system")
    missing = sorted(names - set(values))
    if missing and symbolic:  # kept as symbols: the nonlinear terms' coefficients only
        return _symbolic(text, coordinates, exprs, names, given)
    if missing:
        raise InputError(f"system {text!r}: give {', '.join(missing)} a value with --param "
                         f"(e.g. --param {missing[0]}=1/2)"
                         + ("" if driven else "; a system's series are in the amplitude A"))
    if frequency is not None:
        exprs = [(e.xreplace(given), d.xreplace(given)) for e, d in exprs]
        for i, (_, d) in enumerate(exprs):
            if d.free_symbols & set(map(sp.Symbol, coordinates)) or d.has(*(
                    s for c in coordinates for s in derivative_symbols(c))):
                raise InputError(f"system {text!r}: equation {i + 1}: {sp.sstr(d)}*cos(...) "
                                 "is not a drive f*cos(w*t): it multiplies a coordinate "
                                 "(parametric excitation is not taken)")
            if not d.is_Rational:
                raise InputError(f"system {text!r}: equation {i + 1}: the drive's amplitude "
                                 f"{d} is not an exact number")
        if all(d == 0 for _, d in exprs):
            raise InputError(f"system {text!r}: the drive vanishes with the values given")
        system = _lowered(text, coordinates, [e for e, _ in exprs], allow_damping=True)
        return replace(system, frequency=frequency, drive=tuple(
            system.mass.solve(sp.Matrix([d for _, d in exprs]))))
    return _lowered(text, coordinates, [e.xreplace(given) for e in exprs],
                    allow_damping=driven)


def _symbolic(text: str, coordinates: list[str], exprs: list[sp.Expr], names: set[str],
              given: dict[sp.Symbol, sp.Rational]) -> System:
    """:func:`parse_system` with the names left without a value (not in ``given``) kept as
    symbols: allowed in the nonlinear terms, each coefficient a polynomial in them with
    rational coefficients; the mass and the linear part need numbers (the modes are exact
    numbers)."""
    exprs = [sp.expand(e.xreplace(given)) for e in exprs]
    params = sorted((s for e in exprs for s in e.free_symbols if str(s) in names), key=str)
    symbols = [derivative_symbols(c) for c in coordinates]
    variables = [s for triple in symbols for s in triple]
    for i, e in enumerate(exprs):
        for monom, c in sp.Poly(e, *variables).terms():
            if sum(monom) <= 1 and c.free_symbols:
                need = ", ".join(sorted(map(str, c.free_symbols)))
                raise InputError(f"system {text!r}: equation {i + 1}: {need} stands in the "
                                 f"linear part; give {need} a value with --param (symbols may "
                                 "stand in the nonlinear terms only: the modes are exact "
                                 "numbers)")
    system = _lowered(text, coordinates, [e.xreplace({p: sp.Integer(1) for p in params})
                                          for e in exprs])
    # the checks passed with every symbol at 1; the force is taken again with the symbols
    M = system.mass
    rest = (sp.Matrix(exprs) - M * sp.Matrix([s[2] for s in symbols])
            - M * system.stiffness * sp.Matrix(system.coordinates))
    return replace(system, force=tuple(sp.expand(f) for f in M.solve(rest)))


def _drive_split(text: str, exprs: list[sp.Expr]
                 ) -> tuple[list[tuple[sp.Expr, sp.Expr]], sp.Symbol]:
    """Each equation's autonomous part and its drive's amplitude ``d`` (``d cos(w t)`` on the
    right), with the one frequency ``w``; one line where a term in t is not ``d*cos(w*t)``."""
    t = sp.Symbol(TIME)
    out, frequencies = [], set()
    for i, e in enumerate(exprs):
        rest, timed = sp.expand(e).as_independent(t, as_Add=True)
        amplitude = sp.Integer(0)
        for term in sp.Add.make_args(timed):
            if term == 0:
                continue
            c, wave = term.as_independent(t, as_Add=False)
            if not isinstance(wave, sp.cos) or not wave.args[0].is_Mul \
                    or wave.args[0].as_independent(t, as_Add=False)[1] != t:
                raise InputError(f"system {text!r}: equation {i + 1}: the term "
                                 f"{sp.sstr(term)} is not a drive f*cos(w*t) (a sine, a "
                                 "parametric term or another function of t)")
            w = wave.args[0].as_independent(t, as_Add=False)[0]
            if not isinstance(w, sp.Symbol) or c.has(w):
                raise InputError(f"system {text!r}: equation {i + 1}: the drive's frequency "
                                 f"{sp.sstr(w)} must be one name, w in f*cos(w*t)")
            frequencies.add(w)
            amplitude -= c  # on the left: the drive is minus it
        out.append((rest, amplitude))
    if len(frequencies) != 1:
        raise InputError(f"system {text!r}: the drives name the frequencies "
                         f"{', '.join(sorted(map(str, frequencies)))}; one frequency w, "
                         "f*cos(w*t) on each driven equation")
    return out, frequencies.pop()


def _lowered(text: str, coordinates: list[str], exprs: list[sp.Expr],
             allow_damping: bool = False) -> System:
    """Mass, stiffness and force of each equation, checked."""
    symbols = [derivative_symbols(c) for c in coordinates]
    x = [s[0] for s in symbols]
    v = [s[1] for s in symbols]
    a = [s[2] for s in symbols]
    mass, rows, force, damp = [], [], [], []
    for i, e in enumerate(exprs):
        try:
            poly = sp.Poly(sp.expand(e), *a, *x, *v)
        except sp.PolynomialError:
            raise InputError(f"system {text!r}: equation {i + 1} is not a polynomial in the "
                             "coordinates and their derivatives") from None
        if any(not c.is_Rational for c in poly.coeffs()):
            raise InputError(f"system {text!r}: equation {i + 1} has a coefficient that is "
                             "not an exact number")
        m = [poly.coeff_monomial(s) for s in a]
        rest = sp.expand(poly.as_expr() - sum(c * s for c, s in zip(m, a, strict=True)))
        if rest.has(*a):
            raise InputError(f"system {text!r}: equation {i + 1}: the accelerations must "
                             "enter linearly, each with a constant mass")
        p = sp.Poly(rest, *x, *v)
        if p.coeff_monomial(1) != 0:
            raise InputError(f"system {text!r}: equation {i + 1} has a constant term; the "
                             "origin must be an equilibrium")
        linear = [p.coeff_monomial(s) for s in x]
        damping = [p.coeff_monomial(s) for s in v]
        if any(damping) and not allow_damping:
            raise InputError(f"system {text!r}: equation {i + 1} has a linear velocity term "
                             "(damping); nnm takes conservative systems (response takes "
                             "damped, driven ones)")
        mass.append(m)
        rows.append(linear)
        damp.append(damping)
        force.append(sp.expand(rest - sum(c * s for c, s in zip(linear, x, strict=True))
                               - sum(c * s for c, s in zip(damping, v, strict=True))))
    M = _mass_matrix(text, coordinates, sp.Matrix(mass))
    C = M.solve(sp.Matrix(damp))
    return System(text, tuple(x), tuple(v), M, M.solve(sp.Matrix(rows)),
                  tuple(sp.expand(f) for f in M.solve(sp.Matrix(force))),
                  None if C.is_zero_matrix else C)


def _mass_matrix(text: str, coordinates: list[str], M: sp.Matrix) -> sp.Matrix:
    """``M``, checked: a diagonal one positive, a full one symmetric positive definite (its
    rows the equations, its columns the coordinates in their order)."""
    n = M.rows
    if M.is_diagonal():
        for i in range(n):
            if M[i, i] <= 0:
                raise InputError(f"system {text!r}: equation {i + 1}: {coordinates[i]}'' must "
                                 "enter with a positive constant mass")
        return M
    shown = "[" + "; ".join(", ".join(sp.sstr(M[i, j]) for j in range(n))
                            for i in range(n)) + "]"
    if M != M.T:
        raise InputError(f"system {text!r}: the mass matrix {shown} (rows the equations, "
                         f"columns {', '.join(coordinates)}) is not symmetric; write equation "
                         "k as row k of M x'' + ... = 0")
    if not all(M[:k, :k].det() > 0 for k in range(1, n + 1)):
        raise InputError(f"system {text!r}: the mass matrix {shown} is not positive definite "
                         "(a kinetic energy ½ x'ᵀ M x' must be positive)")
    return M


MODEL_FILES = ("M.mtx", "K.mtx", "C.mtx", "nonlinear.txt", "drive.txt")
# NOTE: a model folder, as a finite-element code writes it: M, K and optional C in Matrix
# Market (scipy.io.mmwrite), the nonlinear terms and the optional drive as text, 0-based.
SYMMETRY = 1e-12
# NOTE: M and K are symmetric to this fraction of their largest entry (an assembled matrix
# written with 16 digits is symmetric to rounding).


def read_model(folder: str | Path) -> System:
    """The :class:`System` ``M x'' + C x' + K x + f(x) = F cos ωt`` of a model folder (its
    floating-point form only): ``M.mtx``, ``K.mtx`` and optional ``C.mtx`` in Matrix Market,
    ``nonlinear.txt`` (a term a line, 0-based: ``i j k c`` adds ``c·x_j·x_k`` to ``f_i``,
    ``i j k l c`` adds ``c·x_j·x_k·x_l``; ``#`` starts a comment; repeated terms add up) and
    optional ``drive.txt`` (``i F_i``).  Refused in one line naming the file: a missing or
    unreadable one, shapes that differ, ``M`` or ``K`` not symmetric, a mass not positive on
    its diagonal, an index out of range, a number that is not finite."""
    from scipy.io import mmread

    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"model {folder}: no such folder")

    def matrix(name: str, needed: bool) -> sparse.csr_array | None:
        path = folder / name
        if not path.is_file():
            if needed:
                raise InputError(f"model {folder}: {name} is missing (the folder holds "
                                 f"{', '.join(MODEL_FILES[:2])}, optionally "
                                 f"{', '.join(MODEL_FILES[2:])})")
            return None
        try:
            A = sparse.csr_array(mmread(path))
        except (ValueError, OSError) as exc:
            raise InputError(f"model {folder}: {name}: not a Matrix Market matrix "
                             f"({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})"
                             ) from None
        if A.shape[0] != A.shape[1] or A.shape[0] == 0:
            raise InputError(f"model {folder}: {name} is {A.shape[0]}×{A.shape[1]}; a "
                             "square matrix, one row per coordinate")
        if not np.all(np.isfinite(A.data)):
            raise InputError(f"model {folder}: {name} holds a number that is not finite")
        return A

    M, K, C = matrix("M.mtx", True), matrix("K.mtx", True), matrix("C.mtx", False)
    n = M.shape[0]
    for name, A in (("K.mtx", K), ("C.mtx", C)):
        if A is not None and A.shape[0] != n:
            raise InputError(f"model {folder}: {name} is {A.shape[0]}×{A.shape[0]} and M.mtx "
                             f"{n}×{n}: one size for every matrix")
    for name, A in (("M.mtx", M), ("K.mtx", K)):
        scale = float(abs(A).max()) if A.nnz else 0.0
        if A.nnz and float(abs(A - A.T).max()) > SYMMETRY * scale:
            raise InputError(f"model {folder}: {name} is not symmetric")
    diagonal = M.diagonal()
    if not np.all(diagonal > 0):
        k = int(np.argmin(diagonal > 0))
        raise InputError(f"model {folder}: M.mtx: M[{k},{k}] = {diagonal[k]:g}; a mass "
                         "matrix is positive on its diagonal")
    _check_definite(folder, M)
    force = _terms(folder / "nonlinear.txt", n)
    drive = _drive(folder / "drive.txt", n)
    names = sp.symbols(f"x0:{n}")
    velocities = tuple(sp.Symbol(f"{x}_") for x in names)
    return System(f"model {folder}", tuple(names), velocities, None, None, (),
                  written=Matrices(M, K, force, C, drive))


def _check_definite(folder: Path, M: sparse.csr_array) -> None:
    """Refuse a mass matrix that is not positive definite (a kinetic energy ½ x'ᵀ M x' must be
    positive): Cholesky up to :data:`DENSE_MODES` coordinates, else a sparse LU without
    pivoting in a symmetric fill-reducing order — for a symmetric matrix, every pivot
    positive (and no row exchange) is its LDLᵀ with a positive D, i.e. positive definite.
    (Lanczos' smallest eigenvalue of a consistent FE mass matrix need not converge.)"""
    from scipy.sparse.linalg import splu

    n = M.shape[0]
    if n <= DENSE_MODES:
        try:
            np.linalg.cholesky(M.toarray())
            return
        except np.linalg.LinAlgError:
            lowest = float(np.linalg.eigvalsh(M.toarray())[0])
            raise InputError(f"model {folder}: M.mtx is not positive definite (its smallest "
                             f"eigenvalue is {lowest:.6g}; a kinetic energy ½ x'ᵀ M x' must "
                             "be positive)") from None
    try:
        lu = splu(M.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0,
                  options={"SymmetricMode": True})
        pivots = lu.U.diagonal()
        ok = bool(np.all(lu.perm_r == lu.perm_c) and np.all(pivots > 0))
    except RuntimeError:  # a zero pivot
        ok, pivots = False, np.zeros(1)
    if not ok:
        raise InputError(f"model {folder}: M.mtx is not positive definite (its LDLᵀ has a "
                         f"pivot {float(np.min(pivots)):.6g} ≤ 0 or needs a row exchange; a "
                         "kinetic energy ½ x'ᵀ M x' must be positive)")


def _numbers(path: Path, n: int, widths: tuple[int, ...]) -> list[tuple[int, list[float]]]:
    """The lines of ``path`` (comments and blank lines skipped) as ``(line, numbers)``, each
    with one of ``widths`` fields, the leading ones indices in ``0 … n − 1``."""
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"model {path.parent}: {path.name}: {exc}") from None
    rows = [(number, line.split("#")[0].split())
            for number, line in enumerate(text.splitlines(), 1)]
    rows = [(number, fields) for number, fields in rows if fields]
    fast = _numbers_at_once(rows, n, widths)
    if fast is not None:
        return fast
    out = []
    for number, fields in rows:  # the slow reading, which names the first bad line
        line = " ".join(fields)
        where = f"model {path.parent}: {path.name} line {number}"
        if len(fields) not in widths:
            raise InputError(f"{where}: {len(fields)} fields; "
                             + " or ".join(str(w) for w in widths) + " expected")
        try:
            indices = [int(f) for f in fields[:-1]]
            value = float(fields[-1])
        except ValueError:
            raise InputError(f"{where}: {line!r} is not indices and a number") from None
        if not math.isfinite(value):
            raise InputError(f"{where}: the coefficient {fields[-1]} is not finite")
        bad = [i for i in indices if not 0 <= i < n]
        if bad:
            raise InputError(f"{where}: index {bad[0]} outside 0..{n - 1}")
        out.append((number, [*indices, value]))
    return out


def _numbers_at_once(rows: list[tuple[int, list[str]]], n: int, widths: tuple[int, ...]
                     ) -> list[tuple[int, list[float]]] | None:
    """:func:`_numbers` read with NumPy, a width at a time (a million terms in about a
    second); ``None`` where any line is wrong (the line-by-line reading then names it)."""
    out: list[tuple[int, list[float]]] = []
    for width in widths:
        group = [(number, fields) for number, fields in rows if len(fields) == width]
        if not group:
            continue
        table = np.array([fields for _, fields in group])
        try:
            indices = table[:, :-1].astype(np.int64)
            values = table[:, -1].astype(float)
        except ValueError:
            return None
        if (not np.all(np.isfinite(values)) or np.any(indices < 0) or np.any(indices >= n)
                or np.any(np.char.find(table[:, :-1], ".") >= 0)):
            return None
        out += [(number, [*map(int, i), float(v)])
                for (number, _), i, v in zip(group, indices.tolist(), values, strict=True)]
    if sum(len(fields) in widths for _, fields in rows) != len(rows):
        return None
    return sorted(out)


def _terms(path: Path, n: int) -> Polynomial:
    """``nonlinear.txt``'s terms (none where the file is absent: a linear model)."""
    rows = _numbers(path, n, (4, 5)) if path.is_file() else []
    width = max((len(r) - 2 for _, r in rows), default=0)
    return Polynomial(
        n, np.array([int(r[0]) for _, r in rows], dtype=np.int64),
        np.array([[int(i) for i in r[1:-1]] + [-1] * (width + 1 - (len(r) - 1))
                  for _, r in rows], dtype=np.int64).reshape(len(rows), width),
        np.array([r[-1] for _, r in rows], dtype=float))


def _drive(path: Path, n: int) -> np.ndarray | None:
    """``drive.txt``'s amplitudes ``F_i`` (``None`` where the file is absent)."""
    if not path.is_file():
        return None
    F = np.zeros(n)
    for _, (i, value) in _numbers(path, n, (2,)):
        F[int(i)] += value
    return F
