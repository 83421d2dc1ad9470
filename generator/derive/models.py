"""Oscillator definitions as data.

Every free oscillator here is written, with ``q = scale · u`` and ``s = ωt``, in the scaled
form the L–P engine solves (notes §10.3, EOM ``ω² q'' + q + ε q³ = 0``)::

    ω² u'' + u + Σ_k y^k Σ_n c_kn u^n = 0,     u(0) = 1, u'(0) = 0,

with ``y = coupling · order_factor`` the expansion variable (``y = εA²`` for Duffing,
``θ₀²`` for the pendulum) and ``forcing[k-1] = ((n, c_kn), ...)``.
"""

from __future__ import annotations

import keyword
import math
import os
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp
from sympy.polys.domains import QQ

from ..errors import InputError
from ..limits import SERIES_MAX_ORDER, check_int
from .equation import SMALL, Equation, parse_equation, parse_expression

t, eps, A, theta0 = sp.symbols("t epsilon A theta_0")
Y = sp.Symbol("Y")  # stands for the expansion variable y in conditions
ONE = sp.Integer(1)


@dataclass(frozen=True)
class Model:
    """One free oscillator ``q̈ + q + ε f(q) = 0`` in the engine's scaled form."""

    name: str
    title: str  # the equation of motion in plain text
    latex: str  # the equation of motion in LaTeX
    equation: sp.Eq  # the physical equation of motion, for display
    coordinate: sp.Symbol  # q or θ
    amplitude: sp.Symbol  # A or θ₀ (q(0) = amplitude, q̇(0) = 0)
    coupling: sp.Expr  # ε, or 1 when the amplitude is the only small quantity
    order_factor: sp.Expr  # y = coupling · order_factor
    variable: str  # the expansion variable as the JSON contract names it
    forcing: tuple[tuple[tuple[int, sp.Expr], ...], ...]
    radius: sp.Expr | None  # radius of convergence of ω(y), T(y) in |y| (None: unknown)
    parameters: tuple[tuple[str, sp.Symbol], ...] = ()  # argument name -> symbol, in order
    orbit_condition: sp.Basic = sp.true  # in the symbol Y = y: a periodic orbit exists
    exact_to: int | None = None  # the highest order its forcing is complete for (None: all)
    velocity_forcing: tuple[tuple[tuple[int, int, sp.Expr], ...], ...] = ()
    # NOTE: time-reversible terms ``y^k c ω^b u^a u'^b`` (b even), ``((a, b, c), ...)`` per order
    # k; ω^b comes from ``q̇ = A ω u'(s)`` (the frequency ω in units of ``frequency``).
    frequency: sp.Expr = ONE  # ω₀, the linear frequency: time is scaled by it
    source: str = ""  # the equation as the user wrote it ("" for the built-in constructors)
    given: tuple[tuple[str, str], ...] = ()  # parameter values given with it (--param)
    elementary: tuple[tuple[str, sp.Expr, sp.Expr], ...] = ()
    # NOTE: forces ``w (F(λAu) − λAu)/A`` with F = sin or sinh, ``(name, λ, w)``, every order of
    # y = A² (odd): summed by recurrence, not Taylor term by term (the pendulum: ("sin", 1, 1))

    @property
    def odd(self) -> bool:
        """All forcing powers odd: the solution holds odd harmonics only."""
        return (all(n % 2 == 1 for terms in self.forcing for n, _ in terms)
                and all(a % 2 == 1 for terms in self.velocity_forcing for a, _, _ in terms))

    @property
    def y(self) -> sp.Expr:
        """The expansion variable ``y = coupling · order_factor`` (``εA²`` for Duffing)."""
        return self.coupling * self.order_factor

    def coefficients(self) -> list[sp.Expr]:
        """Every coefficient of the forcing (the position and velocity terms, the elementary
        forces' λ and w): what fixes the derivation's exact ground ring."""
        return ([c for terms in self.forcing for _, c in terms]
                + [c for terms in self.velocity_forcing for _, _, c in terms]
                + [c for _, lam, w in self.elementary for c in (lam, w)])


def duffing() -> Model:
    """``q̈ + q + ε q³ = 0`` (notes §10.3); ``x = εA²``; radius 1 (separatrix at ``x = -1``)."""
    q = sp.Symbol("q")
    return Model(
        name="duffing",
        title="q'' + q + eps*q**3 = 0",
        latex=r"\ddot q + q + \varepsilon q^3 = 0",
        equation=sp.Eq(sp.Derivative(q, t, 2) + q + eps * q**3, 0),
        coordinate=q,
        amplitude=A,
        coupling=eps,
        order_factor=A**2,
        variable="y = eps*A**2",
        forcing=(((3, sp.Integer(1)),),),
        radius=sp.Integer(1),
        parameters=(("A", A), ("eps", eps)),
        orbit_condition=sp.Gt(Y, -1),  # εA² ≤ -1: the orbit reaches the separatrix
    )


def pendulum(order: int) -> Model:
    """``θ̈ + sin θ = 0`` (notes App. 4.1), expanded in ``θ₀²``.

    ``sin(θ₀u)/θ₀ − u`` enters every order of ``θ₀²``; the kernel sums it by the recurrence of
    sine and cosine of a series (``elementary``), so the model is exact at every order
    (``order`` only checks the argument: it once sized a Taylor polynomial).  The period
    ``4K(sin²(θ₀/2))`` is singular at the separatrix ``θ₀ = π``: radius ``π²``.
    """
    check_order(order)
    th = sp.Symbol("theta")
    return Model(
        name="pendulum",
        title="theta'' + sin(theta) = 0",
        latex=r"\ddot\theta + \sin\theta = 0",
        equation=sp.Eq(sp.Derivative(th, t, 2) + sp.sin(th), 0),
        coordinate=th,
        amplitude=theta0,
        coupling=sp.Integer(1),
        order_factor=theta0**2,
        variable="y = theta0**2",
        forcing=(),
        radius=sp.pi**2,
        parameters=(("theta0", theta0),),
        orbit_condition=sp.Lt(Y, sp.pi**2),  # |θ₀| ≥ π: over the top, no libration
        elementary=(("sin", sp.Integer(1), sp.Integer(1)),),
    )


def polynomial(coefficients: dict[int, object]) -> Model:
    """``q̈ + q + ε Σ c_n qⁿ = 0`` for powers ``n ≥ 2`` (odd and even).

    One power ``n``: ``y = εA^(n-1)`` and exact rational coefficients.  Several powers:
    ``y = ε`` and the coefficients ``c_n A^(n-1)`` live in ``QQ[A, …]``.  Coefficients may
    be numbers or SymPy symbols (which then stay symbolic in every result).
    """
    if not coefficients:
        raise InputError("polynomial force: give at least one power n ≥ 2 with its coefficient")
    terms = []
    for n, c in sorted(coefficients.items()):
        check_int(n, 2, None, f"polynomial force: power {n!r} is not an integer ≥ 2")
        value = _finite(c, f"coefficient of q^{n}")
        if value != 0:
            terms.append((n, value))
    if not terms:
        raise InputError("polynomial force: every coefficient is zero (a linear oscillator)")
    q = sp.Symbol("q")
    force = sum(c * q**n for n, c in terms)
    if len(terms) == 1:
        (n, c), = terms
        factor, forcing = A ** (n - 1), (((n, c),),)
        variable = f"y = eps*A**{n - 1}"
    else:
        factor, forcing = sp.Integer(1), (tuple((n, c * A ** (n - 1)) for n, c in terms),)
        variable = "eps"
    return Model(
        name="polynomial",
        title=f"q'' + q + eps*({sp.sstr(force)}) = 0",
        latex=rf"\ddot q + q + \varepsilon\left({sp.latex(force)}\right) = 0",
        equation=sp.Eq(sp.Derivative(q, t, 2) + q + eps * force, 0),
        coordinate=q,
        amplitude=A,
        coupling=eps,
        order_factor=factor,
        variable=variable,
        forcing=forcing,
        radius=None,
        parameters=(("A", A), ("eps", eps), *((str(s), s) for s in sorted(
            set().union(*(sp.sympify(c).free_symbols for _, c in terms)), key=str))),
    )


@dataclass(frozen=True)
class Oscillator:
    """A user's equation of motion, solved for the acceleration and sorted by what each term is.

    ``q̈ = -(force(q, q̇) + parametric(q, q̇, t)) + drive(t)``: ``force`` is autonomous (its
    linear part included), ``drive`` depends on t alone, ``parametric`` on both.  Given
    parameter values are substituted; the others stay symbols.
    """

    name: str
    equation: Equation
    values: tuple[tuple[sp.Symbol, sp.Rational], ...]
    force: sp.Expr
    drive: sp.Expr
    parametric: sp.Expr

    @property
    def coordinate(self) -> sp.Symbol:
        """The coordinate's symbol (``q``, ``theta``, …)."""
        return self.equation.coordinate

    @property
    def velocity(self) -> sp.Symbol:
        """The symbol of the coordinate's time derivative (``q'``)."""
        return self.equation.derivatives[1]

    @property
    def parameters(self) -> tuple[sp.Symbol, ...]:
        """The parameters left symbolic."""
        given = {s for s, _ in self.values}
        return tuple(p for p in self.equation.parameters if p not in given)

    def refuse(self, method: str, why: str) -> InputError:
        """The one-line :class:`InputError` saying that ``method`` does not apply to this
        oscillator, and ``why``."""
        return InputError(f"{self.name} ({self.equation.text}): {method} does not apply: {why}")


def oscillator(text: str, values: dict[str, str] | None = None, name: str = "oscillator"
               ) -> Oscillator:
    """Parse ``text`` (see :mod:`lindstedt.derive.equation`) with parameter ``values`` (exact
    text such as ``"1/3"``) into an :class:`Oscillator`; every value must name a parameter of
    the text."""
    check_module_name(name)
    eq = parse_equation(text)
    known = {str(p): p for p in eq.parameters}
    if eq.small is not None:  # a value for eps too: the amplitude is then the small quantity
        known[SMALL] = eq.small
    subs = {}
    for key, value in (values or {}).items():
        if key not in known:
            used = ", ".join(known) or "none"
            raise InputError(f"--param {key}: not a parameter of {text!r} (its parameters: "
                             f"{used})")
        number = parse_expression(str(value), f"--param {key}")
        if not number.is_Rational:
            raise InputError(f"--param {key}={value}: not a rational number")
        subs[known[key]] = number
    q, v, a = eq.derivatives
    expr = sp.expand(eq.expression.xreplace(subs))
    mass = expr.coeff(a)
    if mass == 0 or (expr.has(a) and (mass.has(q, v, a, eq.time)
                                     or sp.expand(expr - mass * a).has(a))):
        raise InputError(f"equation {text!r}: {a} must enter linearly with a constant "
                         "coefficient")
    if mass.free_symbols:
        raise InputError(f"equation {text!r}: the coefficient of {a} is {mass}; give its "
                         "parameters values (--param) or divide them out")
    rest = sp.expand(sp.expand(expr - mass * a) / mass)
    drive = parametric = force = sp.Integer(0)
    for term in sp.Add.make_args(rest):
        if not term.has(eq.time):
            force += term
        elif term.has(q, v):
            parametric += term
        else:
            drive -= term
    return Oscillator(name=name, equation=eq, values=tuple(sorted(subs.items(), key=str)),
                      force=force, drive=drive, parametric=parametric)


NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,31}")


def check_module_name(name: str) -> None:
    """Refuse a name for an emitted module that Python cannot import as it is, or that would
    shadow an importable module (every kind of ``generate`` names its files by it)."""
    if not NAME.fullmatch(name or "") or keyword.iskeyword(name):
        raise InputError(f"name {name!r}: letters, digits and '_' only, starting with a letter, "
                         "and no Python keyword (the module is imported by that name)")
    if shadows_a_module(name):
        raise InputError(f"name {name!r}: a module of that name is importable (Python's own or "
                         "installed); the written module would shadow it: choose another name")


def shadows_a_module(name: str) -> bool:
    """Whether a module ``name.py`` in the working folder would shadow one that scripts import:
    the standard library's, or any on ``sys.path`` (site-packages: ``numpy``, ``numba``,
    ``flint``, ``lindstedt``…); the working folder itself is not searched (a module written
    there before may be written again)."""
    from importlib.machinery import PathFinder

    if name in sys.stdlib_module_names or name in sys.builtin_module_names or name == "lindstedt":
        return True
    here = {"", os.getcwd()}
    return PathFinder.find_spec(name, [p for p in sys.path if p not in here]) is not None
LP = "free L–P"


def free_model(osc: Oscillator, order: int) -> Model:
    """The L–P model of a free, time-reversible oscillator ``q̈ + g(q, q̇²) = 0``, sized for
    ``order``; a one-line :class:`InputError` says why when L–P does not apply.

    ``q = A u(s)``, ``s = ω₀ Ω t`` turns each term ``c ε^e q^a q̇^b`` into
    ``c ε^e A^(a+b-1) ω₀^(b-2) Ω^b u^a u'^b``.  Every nonlinear term with ε: ``y = εA^p`` when
    they share one ``p = a + b - 1`` and ``e = 1`` (exact rationals), else ``y = ε`` with
    coefficients in ``QQ[A, params]``.  No ε: ``y = A^g``, the amplitude itself is small (the
    pendulum); a non-polynomial force is Taylor-expanded to exactly the degree order K needs.
    """
    order = check_order(order)
    if osc.drive != 0:
        raise osc.refuse(LP, f"it is driven by {sp.sstr(osc.drive)} (use `lindstedt driven`)")
    if osc.parametric != 0:
        raise osc.refuse(LP, f"{sp.sstr(osc.parametric)} excites it parametrically")
    q, v = osc.coordinate, osc.velocity
    small = osc.equation.small
    if A in osc.parameters:
        raise osc.refuse(LP, "A is the amplitude (q(0) = A): give the parameter another name")
    g = osc.force
    _check_analytic(osc, g)
    if small is not None and g.has(small) and not g.is_polynomial(q, v):
        raise osc.refuse(LP, "eps times a non-polynomial force has infinitely many terms at "
                         "each order of eps; drop eps (the amplitude is then the small "
                         "quantity) or give a polynomial")
    odd_joint = sp.expand(g.xreplace({q: -q, v: -v}) + g) == 0
    degree = (2 if odd_joint else 1) * order + 1  # highest q^a q̇^b an order-K series needs
    elementary, linear = [], sp.Integer(0)
    if small is None and odd_joint and not g.has(v):  # c sin(λq), c sinh(λq): by recurrence
        rest = sp.Integer(0)
        for term in sp.Add.make_args(sp.expand(g)):
            found = _elementary_term(term, q)
            if found is None:
                rest += term
            else:
                elementary.append(found)
                linear += found[2] * found[1]
        if elementary and rest.is_polynomial(q, v):
            g = rest
        else:
            elementary, linear = [], sp.Integer(0)
    polynomial_force = g.is_polynomial(q, v)
    if not polynomial_force:
        lam = sp.Dummy("lam")
        g = sp.series(g.xreplace({q: lam * q, v: lam * v}), lam, 0, degree + 1).removeO()
        g = sp.expand(g.subs(lam, 1))
    poly = sp.Poly(g, q, v)
    terms = {}
    for (a, b), c in zip(poly.monoms(), poly.coeffs(), strict=True):
        if sp.expand(c) != 0:
            terms[(a, b)] = sp.expand(c)
    if terms.get((0, 0), 0) != 0:
        raise osc.refuse(LP, f"q = 0 is no equilibrium (the force there is {terms[(0, 0)]})")
    if any(b % 2 for a, b in terms):
        raise osc.refuse(LP, f"a term odd in {v} dissipates or feeds energy, so there is no "
                         "family of periodic orbits (the limit cycles of q'' + q = eps*f(q, "
                         "q'): lindstedt series)")
    w2 = terms.pop((1, 0), sp.Integer(0)) + linear
    if w2.free_symbols:
        raise osc.refuse(LP, f"the linear frequency squared {w2} must be a number; give its "
                         "parameters values (--param)")
    if not w2.is_Rational:
        raise osc.refuse(LP, f"the linear frequency squared {w2} must be a rational number "
                         "(exact algebra)")
    if w2 <= 0:
        raise osc.refuse(LP, f"the linear term {w2}*{q} does not restore (q = 0 is unstable "
                         "or neutral): no oscillation about it")
    frequency = sp.sqrt(w2)
    nonlinear = {}
    params = osc.parameters
    for (a, b), c in terms.items():
        if small is not None and c.has(small) and not c.is_polynomial(small):
            raise osc.refuse(LP, f"eps enters the coefficient {c} of {q**a * v**b} other than "
                             "as a polynomial")
        for e, ce in (sp.Poly(c, small).terms() if small is not None and c.has(small)
                      else [((0,), c)]):
            _check_exact(osc, ce, params, f"the coefficient of {q**a * v**b}")
            nonlinear[(a, b, e[0])] = sp.expand(ce * w2 ** sp.Rational(b - 2, 2))
    for _, lam, c in elementary:
        _check_exact(osc, lam, (), "the argument's factor of sin or sinh")
        _check_exact(osc, c, (), "the factor of sin or sinh")
    if not nonlinear and not elementary and polynomial_force:
        raise osc.refuse(LP, "the force is linear (a harmonic oscillator): ω = ω₀ exactly")
    with_small = {e for _, _, e in nonlinear}
    if small is not None and 0 in with_small and len(with_small) > 1:
        raise osc.refuse(LP, "some nonlinear terms carry eps and some do not; put eps on every "
                         "nonlinear term or on none")
    p_values = {a + b - 1 for a, b, _ in nonlinear}
    if small is None or with_small <= {0}:
        # a Taylor-expanded force was cut at the degree of a step fixed by its symmetry (2 for
        # an odd force, else 1), whatever step its first terms happen to share
        step = (2 if odd_joint else 1) if elementary or not polynomial_force else \
            math.gcd(*p_values)
        orders = {key: (key[0] + key[1] - 1) // step for key in nonlinear}
        factor, coupling = A**step, sp.Integer(1)
        variable = "A" if step == 1 else f"y = A**{step}"
        scale = {key: sp.Integer(1) for key in nonlinear}
    elif with_small == {1} and len(p_values) == 1:
        (p,) = p_values
        orders = {key: 1 for key in nonlinear}
        factor, coupling = A**p, small
        variable = f"y = eps*A**{p}" if p > 1 else "y = eps*A"
        scale = {key: sp.Integer(1) for key in nonlinear}
    else:
        orders = {key: key[2] for key in nonlinear}
        factor, coupling, variable = sp.Integer(1), small, "eps"
        scale = {key: A ** (key[0] + key[1] - 1) for key in nonlinear}
    top = max(orders.values(), default=0)
    by_order = [[[], []] for _ in range(max(top, order))]
    for key in sorted(nonlinear):
        a, b, _ = key
        k = orders[key]
        if k > len(by_order):
            continue
        c = nonlinear[key] * scale[key]
        if b == 0:
            by_order[k - 1][0].append((a, c))
        else:
            by_order[k - 1][1].append((a, b, c))
    eq = osc.equation
    return Model(
        name=osc.name,
        title=_title(osc),
        latex=_latex(osc),
        equation=sp.Eq(sp.Derivative(q, t, 2) + osc.force, 0),
        coordinate=q,
        amplitude=A,
        coupling=coupling,
        order_factor=factor,
        variable=variable,
        forcing=tuple(tuple(f) for f, _ in by_order),
        radius=None,
        parameters=(("A", A), *((("eps", small),) if coupling == small else ()),
                    *((str(p), p) for p in osc.parameters)),
        exact_to=None if polynomial_force else order,
        elementary=tuple((name, lam, c / w2) for name, lam, c in elementary),
        velocity_forcing=tuple(tuple(vf) for _, vf in by_order),
        frequency=frequency,
        source=eq.text,
        given=tuple((str(p), str(v)) for p, v in osc.values),
    )


def _elementary_term(term: sp.Expr, q: sp.Symbol) -> tuple[str, sp.Expr, sp.Expr] | None:
    """``c·sin(λq)`` or ``c·sinh(λq)`` with constant c and λ as ``(name, λ, c)``, else None."""
    coefficient, functions = sp.S.One, []
    for factor in sp.Mul.make_args(term):
        if factor.has(q):
            functions.append(factor)
        else:
            coefficient *= factor
    if len(functions) != 1 or not isinstance(functions[0], sp.sin | sp.sinh):
        return None
    argument = sp.expand(functions[0].args[0])
    lam = argument.coeff(q)
    if lam == 0 or sp.expand(argument - lam * q) != 0 or lam.has(q):
        return None
    return (type(functions[0]).__name__, lam, coefficient)


@dataclass(frozen=True)
class SelfExcited:
    """``q̈ + q = ε f(q, q̇)`` with ``f`` polynomial and odd in ``q̇`` somewhere (van der Pol,
    Rayleigh, Liénard): no family of orbits but isolated limit cycles, whose amplitude the
    L–P series fixes order by order.  ``terms``: ``(a, b, c)`` of ``c q^a q̇^b`` in ``f``."""

    name: str
    title: str
    source: str
    terms: tuple[tuple[int, int, sp.Rational], ...]


def self_excited_model(osc: Oscillator) -> SelfExcited:
    """The :class:`SelfExcited` record of ``q'' + q - eps*f(q, q') = 0``, or a one-line
    :class:`InputError` naming what does not fit (every parameter needs a value)."""
    method = "the limit-cycle series"
    if osc.drive != 0 or osc.parametric != 0:
        raise osc.refuse(method, "it is driven or parametrically excited (terms in t)")
    q, v, small = osc.coordinate, osc.velocity, osc.equation.small
    if small is None:
        raise osc.refuse(method, "write the small parameter: q'' + q = eps*f(q, q')")
    g = sp.expand(osc.force)
    if not g.is_polynomial(q, v, small):
        raise osc.refuse(method, "f(q, q') must be a polynomial")
    poly = sp.Poly(g, q, v, small)
    f_terms, linear = [], sp.Integer(0)
    for (a, b, e), c in zip(poly.monoms(), poly.coeffs(), strict=True):
        if (a, b, e) == (1, 0, 0):
            linear = c
        elif e == 1:
            _check_exact(osc, c, (), f"the coefficient of eps*{q**a * v**b}", method)
            f_terms.append((a, b, -sp.Rational(c)))
        else:
            raise osc.refuse(method, f"the term {c * q**a * v**b * small**e} is not of the form "
                             "q'' + q = eps*f(q, q') (ω₀ = 1, eps to the first power)")
    if linear != 1:
        raise osc.refuse(method, f"the linear term is {linear}*{q}: write it as q (ω₀ = 1)")
    if not any(b % 2 for _, b, _ in f_terms):
        raise osc.refuse(method, "f is even in q': a conservative oscillator (use series, "
                         "which finds its family of orbits)")
    f = sum(c * q**a * v**b for a, b, c in f_terms)
    return SelfExcited(name=osc.name, title=f"{q}'' + {q} = eps*({sp.sstr(f)})",
                       source=osc.equation.text, terms=tuple(sorted(f_terms)))


def _check_exact(osc: Oscillator, c: sp.Expr, params: tuple[sp.Symbol, ...], what: str,
                 method: str = LP) -> None:
    """A coefficient the exact algebra can hold: a polynomial in the symbolic parameters with
    rational numbers (``QQ[params]``), not ``1/alpha``, ``sin(1)`` or ``sqrt(2)``."""
    try:
        sp.Poly(c, *params, domain=QQ) if params else QQ.from_sympy(c)
        ok = c.free_symbols <= set(params)
    except (sp.PolynomialError, sp.CoercionFailed, sp.GeneratorsNeeded, ValueError,
            TypeError):
        ok = False
    if not ok:
        raise osc.refuse(method, f"{what} is {sp.sstr(c)}: exact algebra needs rational numbers "
                         "and polynomials in the parameters (give values with --param, write "
                         "rationals)")


def _check_analytic(osc: Oscillator, g: sp.Expr) -> None:
    """A force analytic at the equilibrium: finite there, log and sqrt of positive values."""
    q, v = osc.coordinate, osc.velocity
    at_rest = {q: sp.Integer(0), v: sp.Integer(0)}
    for f in g.atoms(sp.log, sp.Pow):
        if isinstance(f, sp.Pow) and not ((f.exp.is_Rational and not f.exp.is_Integer)
                                          or f.exp.is_negative):
            continue
        inner = f.args[0] if isinstance(f, sp.log) else f.base
        if not inner.has(q, v):
            continue
        value = inner.xreplace(at_rest)
        if value.free_symbols:
            raise osc.refuse(LP, f"cannot tell whether {sp.sstr(f)} is analytic at {q} = 0 "
                             "(give its parameters values)")
        if not (value > 0 if isinstance(f, sp.log) or not f.exp.is_Integer else value != 0):
            raise osc.refuse(LP, f"{sp.sstr(f)} is not analytic at {q} = 0")


def _signed(text: str) -> str:
    """`` + text``, or `` - rest`` where ``text`` (a sum as SymPy prints it) starts with a minus."""
    return f" - {text[1:].lstrip()}" if text.startswith("-") else f" + {text}"


def _title(osc: Oscillator) -> str:
    return f"{osc.coordinate}''{_signed(sp.sstr(osc.force))} = 0"


def _latex(osc: Oscillator) -> str:
    q, v = osc.coordinate, osc.velocity
    name = sp.latex(q)
    shown = osc.force.xreplace({v: sp.Symbol(rf"\dot{{{name}}}")})
    names = {osc.equation.small: r"\varepsilon"} if osc.equation.small is not None else {}
    return rf"\ddot{{{name}}}{_signed(sp.latex(shown, symbol_names=names))} = 0"


@dataclass(frozen=True)
class Entry:
    """A named oscillator of the registry: its equation, and how to build its model."""

    name: str
    equation: str
    about: str
    build: Callable[[int], Model] | None = None  # a hand-made model (radius, orbit condition)

    def model(self, order: int) -> Model:
        """The entry's :class:`Model` sized for ``order``: its hand-made one, else
        :func:`free_model` of its equation."""
        if self.build is not None:
            return self.build(order)
        return free_model(oscillator(self.equation, name=self.name), order)


REGISTRY = {e.name: e for e in (
    Entry("duffing", "q'' + q + eps*q**3 = 0", "hardening (eps > 0) or softening cubic spring, "
          "Hand & Finch §10.3", lambda order: duffing()),
    Entry("pendulum", "theta'' + sin(theta) = 0", "the plane pendulum, Hand & Finch App. 4.1",
          pendulum),
    Entry("helmholtz_duffing", "q'' + q + eps*(alpha*q**2 + beta*q**3) = 0",
          "asymmetric spring: quadratic and cubic terms (parameters stay symbolic)"),
    Entry("quintic", "q'' + q + eps*q**5 = 0", "quintic spring"),
    Entry("cubic_quintic", "q'' + q + eps*(q**3 + q**5) = 0", "cubic and quintic spring"),
    Entry("velocity_squared", "q'' + q + eps*q*q'**2 = 0",
          "position-dependent mass, time-reversible (q q̇² term)"),
    Entry("sinh_spring", "q'' + sinh(q) = 0", "exponentially hardening spring"),
    Entry("van_der_pol", "q'' + q = eps*(1 - q**2)*q'", "self-excited: one limit cycle "
          "(series: its L–P series, amplitude fixed order by order)"),
    Entry("rayleigh", "q'' + q = eps*(q' - q'**3/3)", "self-excited (Rayleigh): one limit "
          "cycle"),
)}
MODELS = tuple(REGISTRY)
ALIASES = {"vdp": "van_der_pol"}
# NOTE: other names of an entry (the literature's short ones); `lindstedt models` lists each
# beside its entry, and what is derived carries the entry's own name.


def registry_entry(name: str) -> Entry | None:
    """The registry's entry of a name or of an alias (:data:`ALIASES`), else None."""
    return REGISTRY.get(ALIASES.get(name, name))


def model_by_name(name: str, order: int) -> Model:
    """The named model, sized for ``order`` (the pendulum takes exactly what it needs)."""
    entry = registry_entry(name)
    if entry is None:
        raise InputError(f"model {name!r}: unknown; choose one of {', '.join(MODELS)}")
    return entry.model(order)


def series_model(text: str, order: int, values: dict[str, str] | None = None,
                 name: str | None = None) -> Model | SelfExcited:
    """What ``lindstedt series`` derives for ``text``: the family of orbits of a conservative
    oscillator (:func:`model_from_text`), or the limit cycles of a self-excited one (a force
    odd in q', ``q'' + q = eps*f(q, q')``: :func:`self_excited_model`)."""
    entry = registry_entry(text) if NAME.fullmatch(text) else None
    equation = entry.equation if entry is not None and entry.build is None else None
    if not NAME.fullmatch(text):
        equation = text
    if equation is not None:
        osc = oscillator(equation, values, name or (entry.name if entry else "oscillator"))
        q, v = osc.coordinate, osc.velocity
        if osc.drive == 0 and osc.parametric == 0 and osc.force.is_polynomial(q, v) and \
                sp.expand(osc.force.xreplace({v: -v}) - osc.force) != 0:
            return self_excited_model(osc)
    return model_from_text(text, order, values, name)


def model_from_text(text: str, order: int, values: dict[str, str] | None = None,
                    name: str | None = None) -> Model:
    """A registry name or an equation (anything with a prime), sized for ``order``."""
    if NAME.fullmatch(text):  # a name (of the registry or not); anything else is an equation
        entry = registry_entry(text)
        if values:
            if entry is not None and entry.build is None:
                return free_model(oscillator(entry.equation, values, name or entry.name), order)
            raise InputError(f"--param: model {text!r} takes no parameters")
        if name is not None and name != (entry.name if entry else text):
            raise InputError(f"--name {name}: a built-in model keeps its name {text!r}")
        return model_by_name(text, order)
    return free_model(oscillator(text, values, name or "oscillator"), order)




def check_order(order: object) -> int:
    """A non-negative integer order, or :class:`InputError` naming the input."""
    if isinstance(order, bool) or not isinstance(order, int):
        raise InputError(f"order {order!r}: not an integer")
    if order < 0:
        raise InputError(f"order {order}: must be ≥ 0")
    if order > SERIES_MAX_ORDER:
        raise InputError(f"order {order}: above the limit {SERIES_MAX_ORDER}")
    return order


def _finite(value: object, what: str) -> sp.Expr:
    try:
        expr = sp.sympify(value, strict=True) if not isinstance(value, sp.Basic) else value
    except (sp.SympifyError, TypeError) as exc:
        raise InputError(f"{what} {value!r}: not a number or SymPy expression") from exc
    if expr.has(sp.nan, sp.zoo, sp.oo, -sp.oo):
        raise InputError(f"{what} {value!r}: not finite")
    if expr.is_number:
        if not expr.is_real:
            raise InputError(f"{what} {value!r}: not real")
        if isinstance(expr, sp.Float):
            if not math.isfinite(float(expr)):
                raise InputError(f"{what} {value!r}: not finite")
            expr = sp.Rational(str(expr))  # exact algebra needs exact input
        elif not expr.is_Rational:
            raise InputError(f"{what} {value!r}: must be rational or a symbol for exact algebra")
    return expr
