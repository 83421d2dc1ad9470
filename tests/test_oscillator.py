"""A user's oscillator from its equation, against references that never call the package.

* periods by quadrature at 30 digits (mpmath): ``T = 2∫ dq / sqrt(q'²)`` between the two
  turning points, ``q'² = 2(V(A) − V(q))`` for a potential, the first integral of a velocity
  term otherwise; the substitutions ``q = A − u²`` and ``q = q_min + u²`` make both ends smooth
  for Gauss–Legendre;
* exact period series of symmetric oscillators from ``q = A sin θ`` (``T/2π`` is the mean over
  θ of ``H(x, sin²θ)^(−1/2)``, averaged with ``⟨sin^2m θ⟩ = (2m)!/(4^m m!²)``), and the
  elliptic-integral series of ``reference.py``;
* SciPy's DOP853 for velocity terms and the trajectory itself.

Each check is on the partial sums of the series, the truncation error predicted by the first
omitted terms, and on the numba evaluators ``lindstedt generate`` writes.
"""

from __future__ import annotations

import contextlib
import inspect
import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy as sp
from lindstedt.cli import main
from lindstedt.derive.lindstedt import derive
from lindstedt.derive.models import model_from_text
from lindstedt.emit.render import load_generated
from lindstedt.errors import InputError
from reference import pendulum_period
from scipy.integrate import solve_ivp

mp = mpmath.mp
DPS = 40  # working digits: the periods are good to 30 and more
A_SYM, EPS_SYM = sp.Symbol("A"), sp.Symbol("eps")


# --- the references --------------------------------------------------------------------------

def quadrature_period(W, A, qmin):
    """``2∫_{qmin}^{A} dq / sqrt(W(q))`` for ``W`` vanishing linearly at both ends."""
    A, qmin = mp.mpf(A), mp.mpf(qmin)
    mid = (A + qmin) / 2

    def top(u):
        return 2 * u / mp.sqrt(W(A - u * u))

    def bottom(u):
        return 2 * u / mp.sqrt(W(qmin + u * u))

    return 2 * (mp.quad(top, [0, mp.sqrt(A - mid)], method="gauss-legendre")
                + mp.quad(bottom, [0, mp.sqrt(mid - qmin)], method="gauss-legendre"))


def potential_period(V, A):
    """The period through ``q(0) = A > 0`` in the potential ``V`` (minimum at 0) and the other
    turning point ``q_min < 0`` (``V(q_min) = V(A)``)."""
    with mp.workdps(DPS):
        A = mp.mpf(A)
        VA = V(A)
        qmin = mp.findroot(lambda q: V(q) - VA, -A)
        assert -10 * A < qmin < 0 and abs(V(qmin) - VA) < mp.mpf(10) ** (5 - DPS)
        return quadrature_period(lambda q: 2 * (VA - V(q)), A, qmin), qmin


def numeric(c, **values) -> mpmath.mpf:
    """A coefficient (a SymPy number or polynomial in A, eps, …) at exact decimal values."""
    subs = {sp.Symbol(k): sp.Rational(v) for k, v in values.items()}
    r = sp.Rational(sp.sympify(c).xreplace(subs))
    return mp.mpf(int(r.p)) / int(r.q)


def mean_sin_power(m: int) -> Fraction:
    """``(2/π)∫_0^{π/2} sin^{2m}θ dθ``."""
    return Fraction(math.factorial(2 * m), 4**m * math.factorial(m) ** 2)


def symmetric_period_series(H: sp.Expr, x: sp.Symbol, sigma: sp.Symbol, order: int
                            ) -> list[Fraction]:
    """``T/2π = ⟨H(x, σ)^(−1/2)⟩`` with ``σ = sin²θ``, coefficient by coefficient in ``x``."""
    expansion = sp.series(H ** sp.Rational(-1, 2), x, 0, order + 1).removeO()
    out = []
    for j in range(order + 1):
        poly = sp.Poly(sp.expand(expansion.coeff(x, j)), sigma)
        out.append(sum((Fraction(int(c.p), int(c.q)) * mean_sin_power(m)
                        for (m,), c in poly.terms()), Fraction(0)))
    return out


def fractions(sol, field: str = "period") -> list[Fraction]:
    to = sol.ground.to_sympy
    return [Fraction(int(r.p), int(r.q)) for r in (sp.Rational(to(c)) for c in getattr(sol, field))]


def assert_truncation(taus, y, exact, top):
    """Partial sums ``S_K = Σ_{j≤K} τ_j y^j`` of ``exact``: ``exact − S_K`` is the first omitted
    term up to the next two (so every τ_j is checked), for K = 0..top, and it shrinks."""
    total, errors = mp.mpf(0), []
    floor = mp.mpf(10) ** -28
    for k in range(top + 1):
        total += taus[k] * y**k
        err = exact - total
        predicted = taus[k + 1] * y ** (k + 1)
        slack = 3 * (abs(taus[k + 2] * y ** (k + 2)) + abs(taus[k + 3] * y ** (k + 3))) + floor
        assert abs(err - predicted) <= slack, (k, err, predicted)
        errors.append(abs(err))
    assert errors[-1] < 1e-3 * errors[0] or errors[-1] < 1e-20
    return errors


@pytest.fixture(scope="module")
def series():
    """Derivations shared by the tests, keyed by (text, order)."""
    cache = {}

    def get(text, order, **values):
        key = (text, order, tuple(sorted(values.items())))
        if key not in cache:
            cache[key] = derive(model_from_text(text, order, values or None), order)
        return cache[key]

    return get


def test_the_quadrature_reproduces_the_elliptic_integrals():
    """The reference itself: the pendulum's ``4K(sin²(θ₀/2))`` and Duffing's
    ``4K(m)/sqrt(1 + x)``, ``m = x/(2(1 + x))``, to 30 digits."""
    with mp.workdps(DPS):
        for a in ("0.5", "2.5"):
            T, qmin = potential_period(lambda q: 1 - mp.cos(q), a)
            exact = 4 * mp.ellipk(mp.sin(mp.mpf(a) / 2) ** 2)
            assert abs(T - exact) < mp.mpf(10) ** -30 * exact
            assert abs(qmin + mp.mpf(a)) < mp.mpf(10) ** -30
        x = mp.mpf("0.7")
        T, _ = potential_period(lambda q: q**2 / 2 + x * q**4 / 4, 1)
        exact = 4 * mp.ellipk(x / (2 * (1 + x))) / mp.sqrt(1 + x)
        assert abs(T - exact) < mp.mpf(10) ** -30 * exact


# --- periods of conservative oscillators by quadrature ----------------------------------------

def _hd(q, e):
    return q**2 / 2 + e * (q**3 / 3 + q**4 / 4)


CONSERVATIVE = {
    # text: (V(q, eps), y(A, eps), the model's variable, ω₀, points (A, eps))
    "q'' + q + eps*(q**2 + q**3) = 0": (
        _hd, lambda a, e: e, "eps", 1, [("0.5", "0.2"), ("1", "0.1"), ("0.6", "-0.15")]),
    "q'' + q + eps*q**5 = 0": (
        lambda q, e: q**2 / 2 + e * q**6 / 6, lambda a, e: e * a**4, "y = eps*A**4", 1,
        [("0.8", "0.5"), ("1", "-0.2")]),
    "q'' + sinh(q) = 0": (
        lambda q, e: mp.cosh(q) - 1, lambda a, e: a**2, "y = A**2", 1, [("0.5", "0"), ("1", "0")]),
    "theta'' + sin(theta) = 0": (
        lambda q, e: 1 - mp.cos(q), lambda a, e: a**2, "y = A**2", 1, [("0.5", "0"), ("1", "0")]),
    "x'' + 4*x + eps*x**3 = 0": (
        lambda q, e: 2 * q**2 + e * q**4 / 4, lambda a, e: e * a**2, "y = eps*A**2", 2,
        [("1", "0.4"), ("0.5", "-1")]),
    "q'' + log(1+q) = 0": (
        lambda q, e: (1 + q) * mp.log(1 + q) - q, lambda a, e: a, "A", 1,
        [("0.2", "0"), ("0.4", "0")]),
}


@pytest.mark.parametrize("text", list(CONSERVATIVE))
def test_series_period_against_quadrature(text, series):
    V, y_of, variable, w0, points = CONSERVATIVE[text]
    top = 8
    sol = series(text, top + 3)
    assert sol.model.variable == variable
    assert sp.sympify(sol.model.frequency) == w0
    with mp.workdps(DPS):
        for a, e in points:
            A, eps = mp.mpf(a), mp.mpf(e)
            T, _ = potential_period(lambda q, eps=eps: V(q, eps), A)
            taus = [numeric(sol.ground.to_sympy(c), A=a) for c in sol.period]
            omegas = [numeric(sol.ground.to_sympy(c), A=a) for c in sol.omega]
            y = y_of(A, eps)
            assert_truncation(taus, y, T * w0 / (2 * mp.pi), top)
            # ω/ω₀ = 2π/(ω₀T): the frequency series is checked the same way
            assert_truncation(omegas, y, 2 * mp.pi / (w0 * T), top)


def test_pendulum_equation_is_the_built_in_pendulum(series):
    """``theta'' + sin(theta) = 0`` and ``pendulum``: the same exact numbers, which are the
    elliptic integral's; ``sinh`` is the pendulum at an imaginary amplitude."""
    order = 10
    by_text, built_in = series("theta'' + sin(theta) = 0", order), series("pendulum", order)
    exact = pendulum_period(order)
    assert fractions(by_text) == fractions(built_in) == exact
    assert fractions(by_text, "omega") == fractions(built_in, "omega")
    to_a, to_b = by_text.ground.to_sympy, built_in.ground.to_sympy
    assert [{n: to_a(c) for n, c in qj.items()} for qj in by_text.q] == \
           [{n: to_b(c) for n, c in qj.items()} for qj in built_in.q]
    sinh = fractions(series("q'' + sinh(q) = 0", order))
    assert sinh == [(-1) ** j * c for j, c in enumerate(exact)]


X, SIGMA = sp.symbols("x sigma")


def _relative(z):
    """``(e^z − 1)/z`` as a polynomial, enough terms for order 10."""
    return sum(z**k / sp.factorial(k + 1) for k in range(12))


SYMMETRIC = {
    # q = A sin θ: q'² = A² cos²θ · H(x, σ)
    "q'' + q + eps*q**3 = 0": 1 + X * (1 + SIGMA) / 2,
    "q'' + q + eps*q**5 = 0": 1 + X * (1 + SIGMA + SIGMA**2) / 3,
    "q'' + q*(1 + eps*q**2) = 0": 1 + X * (1 + SIGMA) / 2,
    "2*q'' = -2*q - 2*eps*q**3": 1 + X * (1 + SIGMA) / 2,
    # q'' + q + eps q q'² = 0: q'² = (exp(ε(A² − q²)) − 1)/ε
    "q'' + q + eps*q*q'**2 = 0": _relative(X * (1 - SIGMA)),
    # q'' + q + eps(q³ + q q'²) = 0: q'² = A² exp(ε(A² − q²)) − q²
    "q'' + q + eps*(q**3 + q*q'**2) = 0": 1 + X * _relative(X * (1 - SIGMA)),
}


@pytest.mark.parametrize("text", list(SYMMETRIC))
def test_symmetric_oscillators_exact_period_coefficients(text, series):
    order = 7
    exact = symmetric_period_series(SYMMETRIC[text], X, SIGMA, order)
    sol = series(text, order)
    assert sol.model.variable == ("y = eps*A**4" if "q**5" in text else "y = eps*A**2")
    assert fractions(sol) == exact


# --- velocity terms -----------------------------------------------------------------------------

def test_velocity_squared_period_against_its_first_integral(series):
    """``q'² = (exp(ε(A² − q²)) − 1)/ε`` on the orbit of ``q'' + q + εqq'² = 0``."""
    text = "q'' + q + eps*q*q'**2 = 0"
    top = 8
    sol = series(text, top + 3)
    taus = [numeric(c) for c in fractions(sol)]
    with mp.workdps(DPS):
        for a, e in (("1", "0.2"), ("0.5", "-0.6"), ("2", "0.05")):
            A, eps = mp.mpf(a), mp.mpf(e)
            T = quadrature_period(lambda q, A=A, eps=eps: mp.expm1(eps * (A * A - q * q)) / eps,
                                  A, -A)
            assert_truncation(taus, eps * A**2, T / (2 * mp.pi), top)


def _dop853_period(rhs, A):
    """The period of the orbit through (A, 0): the second time q' falls through zero."""
    def returned(t, s):
        return s[1]

    returned.direction = 1.0  # q' from − to +: the far turning point, at T/2 by reversibility
    returned.terminal = True
    sol = solve_ivp(rhs, (0, 100), [A, 0.0], method="DOP853", rtol=1e-12, atol=1e-14,
                    events=returned)
    (half,) = sol.t_events[0]
    return 2 * half, sol.y_events[0][0][0]


@pytest.mark.parametrize("text, rhs, points, y_of", [
    ("q'' + q + eps*(q**3 + q*q'**2) = 0",
     lambda e: (lambda t, s: [s[1], -s[0] - e * (s[0] ** 3 + s[0] * s[1] ** 2)]),
     [(1.0, 0.1), (0.7, -0.3)], lambda a, e: e * a**2),
    ("q'' + q + eps*q'**2 = 0",
     lambda e: (lambda t, s: [s[1], -s[0] - e * s[1] ** 2]),
     [(1.0, 0.1), (0.5, -0.3)], lambda a, e: e * a),
    ("q'' + q + eps*q**2*q'**2 = 0",
     lambda e: (lambda t, s: [s[1], -s[0] - e * s[0] ** 2 * s[1] ** 2]),
     [(1.0, 0.2)], lambda a, e: e * a**3),
])
def test_velocity_terms_period_against_dop853(text, rhs, points, y_of, series):
    top = 8
    sol = series(text, top + 1)
    taus = [float(c) for c in fractions(sol)]
    for a, e in points:
        T, _ = _dop853_period(rhs(e), a)
        y = y_of(a, e)
        partial = 2 * math.pi * sum(t * y**j for j, t in enumerate(taus[: top + 1]))
        first_omitted = 2 * math.pi * abs(taus[top + 1] * y ** (top + 1))
        assert abs(partial - T) <= 3 * first_omitted + 1e-10 * T
        one_term = 2 * math.pi * (1 + taus[1] * y)
        assert abs(partial - T) < 0.01 * abs(one_term - T)  # the orders do their work


# --- the emitted evaluators -------------------------------------------------------------------

EMITTED_ORDER = 10


def emit(text, order, out, name):
    """``lindstedt generate TEXT --order K --out OUT --name NAME``."""
    assert main(["generate", text, "--order", str(order), "--out", str(out), "--name", name]) == 0


EMITTED_NAMES = {"q'' + q + eps*(q**2 + q**3) = 0": "user_hd",
                 "theta'' + sin(theta) = 0": "user_pendulum",
                 "x'' + 4*x + eps*x**3 = 0": "user_rescaled", "q'' + log(1+q) = 0": "user_log"}


class _Emitted(dict):
    """Each module written by ``lindstedt generate`` and loaded when a test first asks for
    it (a worker compiles only the modules its own tests use)."""

    def __init__(self, out) -> None:
        super().__init__()
        self.out = out

    def __missing__(self, text: str):
        emit(text, EMITTED_ORDER, self.out, EMITTED_NAMES[text])
        self[text] = load_generated(self.out / f"{EMITTED_NAMES[text]}.py")
        return self[text]


@pytest.fixture(scope="module")
def emitted(tmp_path_factory):
    """The modules of :data:`EMITTED_NAMES`, each generated and loaded once, when first used."""
    return _Emitted(tmp_path_factory.mktemp("emitted"))


def arguments(module) -> list[str]:
    """The evaluators' parameters in order (``PARAMETERS`` if the module has it)."""
    names = getattr(module, "PARAMETERS", None)
    if names is None:
        names = list(inspect.signature(module.period_into).parameters)[1:]
    return [str(n) for n in names]


@pytest.mark.parametrize("text, expected_args", [
    ("q'' + q + eps*(q**2 + q**3) = 0", ["A", "eps"]),
    ("theta'' + sin(theta) = 0", ["A"]),
    ("x'' + 4*x + eps*x**3 = 0", ["A", "eps"]),
    ("q'' + log(1+q) = 0", ["A"]),
])
def test_emitted_period_omega_and_q_against_quadrature(text, expected_args, emitted):
    module = emitted[text]
    assert arguments(module) == expected_args
    V, _, _, w0, points = CONSERVATIVE[text]
    coordinate = text.split("'")[0]
    q_of, qdot_of = getattr(module, coordinate), getattr(module, coordinate + "dot")
    for a, e in points:
        args = (float(a), float(e))[: len(expected_args)]
        with mp.workdps(DPS):
            eps = mp.mpf(e)
            T_exact, qmin = potential_period(lambda q, eps=eps: V(q, eps), a)
        T_exact, qmin = float(T_exact), float(qmin)
        T, w, estimate = module.period(*args), module.omega(*args), module.error_estimate(*args)
        relative = abs(T - T_exact) / T_exact
        assert relative <= 3 * estimate + 1e-13, (relative, estimate)
        assert estimate <= 3 * relative + 1e-13, (relative, estimate)  # a fair estimate
        assert abs(w - 2 * math.pi / T_exact) <= (3 * estimate + 1e-13) * w
        assert w0 * 0.5 < w < w0 * 2
        # q(0) = A, q'(0) = 0; half a period on, the other turning point
        assert q_of(0.0, *args) == pytest.approx(float(a), abs=1e-14)
        assert abs(qdot_of(0.0, *args)) < 1e-14
        assert q_of(T / 2, *args) == pytest.approx(qmin, abs=1e-6 * float(a))
        assert abs(qdot_of(T / 2, *args)) < 1e-6 * float(a) * w0
        assert q_of(T, *args) == pytest.approx(float(a), abs=1e-6 * float(a))


def test_emitted_trajectory_against_dop853(emitted):
    """q(t) and q'(t) of the asymmetric Helmholtz–Duffing evaluator along three periods."""
    module = emitted["q'' + q + eps*(q**2 + q**3) = 0"]
    A, eps = 0.5, 0.2
    t = np.linspace(0.0, 3 * module.period(A, eps), 301)
    sol = solve_ivp(lambda _, s: [s[1], -s[0] - eps * (s[0] ** 2 + s[0] ** 3)], (0, t[-1]),
                    [A, 0.0], method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t)
    assert np.max(np.abs(module.q(t, A, eps) - sol.y[0])) < 1e-8
    assert np.max(np.abs(module.qdot(t, A, eps) - sol.y[1])) < 1e-8


# --- parameters ----------------------------------------------------------------------------

def test_symbolic_parameter_specialised_equals_the_given_value(series):
    """alpha left symbolic then set to 1/3, and alpha = 1/3 given: the same exact series."""
    text = "q'' + q + eps*(alpha*q**2 + beta*q**3) = 0"
    alpha, beta = sp.symbols("alpha beta")
    symbolic = series(text, 6)
    given = series(text, 6, alpha="1/3")
    both = series(text, 6, alpha="1/3", beta="-2")
    assert given.model.parameters == (("A", A_SYM), ("eps", EPS_SYM), ("beta", beta))
    for field in ("omega", "period"):
        for c_sym, c_one, c_two in zip(getattr(symbolic, field), getattr(given, field),
                                       getattr(both, field), strict=True):
            c_sym = symbolic.ground.to_sympy(c_sym)
            assert sp.expand(c_sym.subs(alpha, sp.Rational(1, 3))
                             - given.ground.to_sympy(c_one)) == 0
            assert sp.expand(c_sym.subs({alpha: sp.Rational(1, 3), beta: -2})
                             - both.ground.to_sympy(c_two)) == 0
    for q_sym, q_one in zip(symbolic.q, given.q, strict=True):
        left = {n: sp.expand(symbolic.ground.to_sympy(c).subs(alpha, sp.Rational(1, 3)))
                for n, c in q_sym.items()}
        right = {n: sp.expand(given.ground.to_sympy(c)) for n, c in q_one.items()}
        assert {n: c for n, c in left.items() if c != 0} == right


def test_helmholtz_duffing_second_order_by_quadrature(series):
    """τ₂(A, α) = 57A⁴/256 − αA³/4 + 5α²A²/12 (the package's) recovered from periods at small
    ε: (T/2π − 1 − τ₁ε)/ε² at three (A, α) fixes the three coefficients."""
    sol = series("q'' + q + eps*(alpha*q**2 + q**3) = 0", 2)
    tau2 = sol.ground.to_sympy(sol.period[2])
    alpha = sp.Symbol("alpha")
    expected = sp.Poly(tau2, A_SYM, alpha)
    assert set(expected.monoms()) == {(4, 0), (3, 1), (2, 2)}
    rows, rhs = [], []
    with mp.workdps(DPS):
        eps = mp.mpf(10) ** -8
        for a, al in (("1", "1"), ("0.5", "2"), ("1", "-0.5")):
            A, al_ = mp.mpf(a), mp.mpf(al)
            T, _ = potential_period(lambda q, al_=al_: q**2 / 2 + eps * (al_ * q**3 / 3
                                                                         + q**4 / 4), A)
            rows.append([A**4, A**3 * al_, A**2 * al_**2])
            rhs.append((T / (2 * mp.pi) - 1 + mp.mpf(3) / 8 * A**2 * eps) / eps**2)
        fitted = mp.lu_solve(mp.matrix(rows), mp.matrix(rhs))
    for value, monom in zip(fitted, [(4, 0), (3, 1), (2, 2)], strict=True):
        c = expected.coeff_monomial(A_SYM ** monom[0] * alpha ** monom[1])
        assert abs(value - numeric(c)) < 1e-5


def test_given_eps_makes_the_amplitude_the_small_quantity(series):
    """--param eps=1/10: a series in A whose coefficients regroup the ε-series by powers of A."""
    text = "q'' + q + eps*(q**2 + q**3) = 0"
    order = 6
    in_eps = series(text, order)
    in_a = series(text, order, eps="1/10")
    assert in_a.model.variable == "A"
    regrouped = sp.expand(sum(in_eps.ground.to_sympy(c) * sp.Rational(1, 10) ** j
                              for j, c in enumerate(in_eps.period)))
    for k, c in enumerate(in_a.period):
        assert sp.Rational(in_a.ground.to_sympy(c)) == regrouped.coeff(A_SYM, k)


# --- found wrong ------------------------------------------------------------------------------

def test_taylor_degree_follows_the_step_of_the_powers():
    """``q'' + q + q⁴exp(q³) = 0``: a Taylor-expanded force is cut by its symmetry (not odd:
    y = A, whatever step its first terms share), so every τ_j holds against the quadrature."""
    text = "q'' + q + q**4*exp(q**3) = 0"
    top = 4  # in A³: the series in y = A holds A^(3j) only
    sol = derive(model_from_text(text, 3 * (top + 3)), 3 * (top + 3))
    assert sol.model.variable == "A"
    with mp.workdps(DPS):
        A = mp.mpf("0.3")

        def V(q):
            return q**2 / 2 + mp.nsum(lambda k: q ** (3 * k + 5) / (mp.factorial(k)
                                                                    * (3 * k + 5)), [0, mp.inf])

        T, _ = potential_period(V, A)
        taus = [numeric(c) for c in fractions(sol)]
        assert all(t == 0 for j, t in enumerate(taus) if j % 3)  # only powers of A³ appear
        assert_truncation(taus[::3], A**3, T / (2 * mp.pi), top)
    derive(model_from_text(text, 2), 2)  # order 2 exists (q⁴ enters at order 3): not "linear"


def test_emitted_parameter_named_x(tmp_path):
    emit("q'' + q + eps*x*q**3 = 0", 3, tmp_path, "user_param_x")
    module = load_generated(tmp_path / "user_param_x.py")
    assert arguments(module) == ["A", "eps", "x"]
    A, eps, x = 0.5, 0.3, 0.4
    with mp.workdps(DPS):
        T, _ = potential_period(lambda q: q**2 / 2 + mp.mpf(eps * x) * q**4 / 4, A)
    assert module.period(A, eps, x) == pytest.approx(float(T), rel=1e-5)


def test_emitted_parameter_named_out(tmp_path, capsys):
    """``out`` is the _into twins' first argument: refused, in one line, before any work."""
    with contextlib.suppress(SystemExit):
        main(["generate", "q'' + q + eps*out*q**3 = 0", "--order", "3", "--out", str(tmp_path),
              "--name", "user_param_out"])
    assert not (tmp_path / "user_param_out.py").exists()
    assert "parameter 'out': the emitted module uses this name" in capsys.readouterr().err


def test_parameter_named_like_the_amplitude():
    """A is the amplitude q(0) = A: a parameter of that name is refused, not merged."""
    with pytest.raises(InputError, match="A is the amplitude"):
        model_from_text("q'' + q + eps*A*q**3 = 0", 3)


def test_series_json_at_order_20_matches_the_quadrature_period(capsys):
    """``lindstedt series "q'' + q + eps*(q**2 + q**3) = 0" --order 20 --json``: its period,
    summed from the JSON's monomial → "p/q" objects at (A, ε), is the quadrature period to the
    size of its first omitted terms, at three amplitudes."""
    import json

    text = "q'' + q + eps*(q**2 + q**3) = 0"
    assert main(["series", text, "--order", "20", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["variable"] == "eps" and data["order"] == 20

    def value(coefficient: dict, A: mp.mpf) -> mp.mpf:
        """Σ p/q A^k over the object's monomials "1", "A", "A**k"."""
        total = mp.mpf(0)
        for monomial, rational in coefficient.items():
            p, q = rational.split("/")
            k = {"1": 0, "A": 1}[monomial] if monomial in ("1", "A") else \
                int(monomial.removeprefix("A**"))
            total += mp.mpf(int(p)) / int(q) * A**k
        return total

    for a, e in (("0.5", "0.1"), ("1", "0.05"), ("0.3", "-0.2")):
        with mp.workdps(DPS):
            A, eps = mp.mpf(a), mp.mpf(e)
            T, _ = potential_period(lambda q, eps=eps: q**2 / 2 + eps * (q**3 / 3 + q**4 / 4), A)
            terms = [value(c, A) * eps**j for j, c in enumerate(data["period"])]
            partial = 2 * mp.pi * sum(terms)
            tail = 2 * mp.pi * (abs(terms[-1]) + abs(terms[-2]))  # the series' last steps
            assert abs(partial - T) <= 10 * tail + mp.mpf(10) ** -25, (a, e, partial - T, tail)
            assert abs(partial / T - 1) < 1e-12


def test_emitted_user_module_is_nan_beyond_its_estimated_radius(tmp_path):
    """No silent divergent numbers: a user's module guards |y| < R with R estimated from its
    own coefficients.  The quintic's period is singular at the separatrix x = εA⁴ = −1 (where
    u = 1 is the top of the potential u²/2 + x u⁶/6): Domb–Sykes puts R within 2 % below it;
    beyond, NaN.  Symbolic coefficients (series in ε, A free): the guard is evaluated at A."""
    emit("q'' + q + eps*q**5 = 0", 8, tmp_path, "quintic_guard")
    mod = load_generated(tmp_path / "quintic_guard.py")
    assert 0.98 <= mod.RADIUS <= 1.0
    assert math.isnan(mod.period(1.0, -1.2)) and math.isnan(mod.period(1.0, 3.0))
    with mp.workdps(DPS):
        T, _ = potential_period(lambda q: q**2 / 2 + mp.mpf("0.3") * q**6 / 6, 1)
    assert mod.period(1.0, 0.3) == pytest.approx(float(T), rel=1e-5)
    emit("q'' + q + eps*(q**2 + q**3) = 0", 6, tmp_path, "asym_guard")
    asym = load_generated(tmp_path / "asym_guard.py")
    assert math.isnan(asym.period(3.0, 1.0))  # εA ~ 3: far outside any convergence
    assert math.isfinite(asym.period(0.5, 0.1))



def test_a_symbolic_eps_module_finds_its_orbit_domain_at_each_eps(emitted):
    """q'' + q + ε(q² + q³) = 0 with ε symbolic: its orbits depend on ε and A separately (no
    single edge in ε), so the module finds the domain at the ε it is called with — NaN past
    the first integral's barrier (the saddles and V's level there by mpmath here), where it
    once answered a period (`q'' + q + eps*(q**2 - q**4)` gave period(-1.80, 0.1) = 7.666 past
    A = -1.78398); inside, error_estimate bounds period()'s error against quadrature."""
    m = emitted["q'' + q + eps*(q**2 + q**3) = 0"]
    for e in (-0.1, -0.3):
        with mp.workdps(30):
            E = mp.mpf(e)
            V = lambda q, E=E: q**2 / 2 + E * (q**3 / 3 + q**4 / 4)  # noqa: E731
            low, high = sorted(mp.polyroots([E, E, 1]))  # V'(q)/q = 1 + ε(q + q²) = 0
            # A > 0 reaches the saddle at `high` first; A < 0 the level V(high) first
            negative = float(mp.findroot(lambda q, V=V, h=high: V(q) - V(h), low / 2))
            high = float(high)
        for A, inside in ((high - 1e-4, True), (high + 1e-4, False),
                          (negative + 1e-4, True), (negative - 1e-4, False)):
            assert math.isnan(m.period(A, e)) != inside, (e, A)
            assert math.isnan(m.error_estimate(A, e)) != inside, (e, A)
    for A, e in ((-1.8, -0.1), (2.5, -0.1), (1.0, -0.3), (-0.8, -0.3), (1.5, 0.1)):
        sign = 1 if A > 0 else -1
        with mp.workdps(DPS):
            T, _ = potential_period(
                lambda q, e=e, s=sign: (s * q)**2 / 2 + mp.mpf(e) * ((s * q)**3 / 3
                                                                     + (s * q)**4 / 4), abs(A))
        error = abs(m.period(A, e) / float(T) - 1)
        assert error <= m.error_estimate(A, e), (A, e, error, m.error_estimate(A, e))


def test_series_table_shows_a_long_rational_as_its_decimal_and_exact_on_request(capsys):
    """``series duffing --order 12``'s table: a long τ_j as 12 significant digits of the
    exact rational in --json (Fraction, not the printer's float), every number exact with
    --exact; the JSON's decimals are the same digits."""
    import json
    from fractions import Fraction

    assert main(["series", "duffing", "--order", "12", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    tau = Fraction(data["period"][12])
    assert len(data["period"][12]) > 24
    digits = f"{float(tau):.12g}"
    assert abs(float(data["period_decimal"][12]) / float(tau) - 1) < 1e-11
    assert main(["series", "duffing", "--order", "12"]) == 0
    table = capsys.readouterr().out
    row = next(line.split() for line in table.splitlines() if line.split()[:1] == ["12"])
    assert abs(float(row[2]) / float(tau) - 1) < 1e-11 and row[2] == digits
    assert main(["series", "duffing", "--order", "12", "--exact"]) == 0
    assert data["period"][12] in capsys.readouterr().out
