"""Nonlinear normal modes: exact identities (a system that holds Duffing's oscillator as an
invariant mode), the backbone against shooting (SciPy's DOP853 and a root finder, another
route), the JSON contract and the refusals."""

from __future__ import annotations

import json
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp
from commands import run
from lindstedt.derive.lindstedt import derive
from lindstedt.derive.models import duffing
from lindstedt.derive.nnm import normal_mode
from lindstedt.derive.system import parse_system
from reference import duffing_period, reciprocal
from scipy.integrate import solve_ivp
from scipy.optimize import root

KERSCHEN = "x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"
SYMMETRIC = "x1'' + 2*x1 - x2 + x1**3 = 0; x2'' + 2*x2 - x1 + x2**3 = 0"
# NOTE: x1 = x2 = x gives Duffing's x'' + x + x³ = 0 (mode 1); x1 = −x2 = x gives
# x'' + 3x + x³ = 0, Duffing with ω₀² = 3 (mode 2): ω(A) = √3 ω_D(A²/3).



def test_in_phase_mode_is_duffing_exactly():
    K = 12
    mode = normal_mode(parse_system(SYMMETRIC), 1, K)
    assert mode.variable == "y = A**2" and mode.omega0 == 1
    exact = duffing_period(K)  # the elliptic integral's series, another route
    assert [sp.Rational(c) for c in mode.period()] == [sp.Rational(c.numerator, c.denominator)
                                                      for c in exact]
    assert mode.omega() == [sp.Rational(c.numerator, c.denominator) for c in reciprocal(exact)]
    assert mode.coordinate(0) == mode.coordinate(1)


def test_out_of_phase_mode_is_duffing_scaled_exactly_in_q_sqrt3():
    K = 10
    mode = normal_mode(parse_system(SYMMETRIC), 2, K)
    r3 = sp.sqrt(3)
    tau = duffing_period(K)
    assert mode.omega0 == r3
    assert mode.period() == [sp.Rational(c.numerator, c.denominator) / 3**j / r3
                             for j, c in enumerate(tau)]
    assert mode.omega() == [r3 * sp.Rational(c.numerator, c.denominator) / 3**j
                            for j, c in enumerate(reciprocal(tau))]
    one = derive(duffing(), K)  # Duffing's own q_j, from the one-coordinate engine
    x1, x2 = mode.coordinate(0), mode.coordinate(1)
    for j in range(K + 1):
        expected = {n: one.ground.to_sympy(c) / 3**j for n, c in one.q[j].items() if c}
        assert x1[j] == expected
        assert x2[j] == {n: -c for n, c in expected.items()}


RESIDUAL = 1e-11
# the velocities at the half period: DOP853 at rtol 1e-13 holds them to ~1e-14, so a converged
# orbit has them below this, and an orbit wrong by the tolerances the tests assert (≥ 1e-8) not.


def _shoot(system: str, amplitude: float, guess: list[float], half: float):
    """The periodic orbit through x1(0) = A with every velocity zero: the unknowns are the
    other coordinates at t = 0 and the half period, where every velocity vanishes again."""
    s = parse_system(system)
    d = s.size
    f = sp.lambdify([s.coordinates], [-(s.stiffness * sp.Matrix(s.coordinates))[i] - s.force[i]
                                      for i in range(d)], "numpy")

    def rhs(t, z):
        return np.concatenate([z[d:], f(z[:d])])

    def at_half(u):
        x0 = np.concatenate([[amplitude], u[:-1], np.zeros(d)])
        sol = solve_ivp(rhs, (0, u[-1]), x0, method="DOP853", rtol=1e-13, atol=1e-15)
        return sol.y[d:, -1]

    # NOTE: judged by its residual, never by ``out.success``: MINPACK flags "xtol too small"
    # on some builds when the residual is already at rounding (1e-16).
    out = root(at_half, [*guess, half], method="hybr", tol=1e-14)
    residual = np.max(np.abs(at_half(out.x)))
    assert residual <= RESIDUAL, f"reference shooting: residual {residual:.1e} > {RESIDUAL:.0e}"
    return out.x[:-1], 2 * out.x[-1]


def _evaluate(mode, A: float) -> tuple[float, list[float]]:
    y = A ** (2 if mode.variable.startswith("y") else 1)
    period = 2 * np.pi * sum(float(c) * y**j for j, c in enumerate(mode.period()))
    starts = [A * sum(float(c) * y**j for j, order in enumerate(mode.coordinate(i))
                      for c in order.values()) for i in range(mode.system.size)]
    return period, starts


@pytest.mark.parametrize("which", [1, 2])
@pytest.mark.parametrize("A, tol", [(0.1, 1e-8), (0.3, 1e-5)])
def test_kerschen_backbone_against_shooting(which, A, tol):
    """Kerschen et al.'s 2-DOF system, order 12: the period and the mode shape x2(0) against
    the orbit shot by DOP853 (relative error of T, absolute of x2(0)/A)."""
    mode = normal_mode(parse_system(KERSCHEN), which, 12)
    period, starts = _evaluate(mode, A)
    others, shot = _shoot(KERSCHEN, A, starts[1:], period / 2)
    assert abs(period / shot - 1) <= tol
    assert abs(starts[1] - others[0]) / A <= tol


def test_fpu_beta_chain_lowest_mode_against_shooting():
    """The FPU-β chain of 8 masses with fixed ends: ω₀² is a root of a cubic (exact in that
    number field), and the order-6 backbone meets shooting at A = 0.05."""
    n = 8
    eqs = []
    for i in range(1, n + 1):
        left = f"x{i - 1}" if i > 1 else "0"
        right = f"x{i + 1}" if i < n else "0"
        eqs.append(f"x{i}'' + 2*x{i} - {left} - {right} + (x{i} - {left})**3 "
                   f"- ({right} - x{i})**3 = 0")
    text = "; ".join(eqs)
    mode = normal_mode(parse_system(text), 1, 6)
    assert float(mode.lam) == pytest.approx(4 * np.sin(np.pi / 18) ** 2, rel=1e-15)
    assert not mode.lam.is_Rational
    A = 0.05
    period, starts = _evaluate(mode, A)
    others, shot = _shoot(text, A, starts[1:], period / 2)
    assert abs(period / shot - 1) <= 1e-10
    assert np.max(np.abs(np.array(starts[1:]) - others)) / A <= 1e-9


def test_contract_mode_2_order_20_in_q_sqrt3():
    out = run("nnm", KERSCHEN, "--mode", "2", "--order", "20", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert {"kind", "mode", "omega0", "variable", "omega", "period", "coordinates"} <= data.keys()
    assert data["kind"] == "nnm" and data["mode"] == 2 and data["omega0"] == "sqrt(3)"
    assert data["variable"] == "y = A**2" and len(data["omega"]) == 21
    r3 = sp.sqrt(3)
    for text in data["omega"] + data["period"]:
        ratio = sp.nsimplify(sp.sympify(text) / r3)  # an exact rational multiple of √3
        assert ratio.is_Rational
        assert Fraction(str(ratio)) == Fraction(str(sp.sympify(text) / r3))
    assert set(data["coordinates"]) == {"x1", "x2"}
    assert data["coordinates"]["x1"][0] == {"1": "1"}
    assert data["coordinates"]["x2"][0] == {"1": "-1"}  # mode 2 is out of phase
    assert all(sum(Fraction(c) for c in order.values()) == 0
               for order in data["coordinates"]["x1"][1:])  # x1(0) = A exactly


@pytest.mark.parametrize("args, says", [
    (["x1'' + x1 + (x1 + x2)**3 = 0; x2'' + 9*x2 + (x1 + x2)**3 = 0"],
     "mode 1 (ω0² = 1) is in 1:3 internal resonance with mode 2 (ω0² = 9): harmonic 3 of "
     "order 1"),
    (["x1'' + x1 + x1*x2 = 0; x2'' + 4*x2 + x1**2 = 0"], "1:2 internal resonance"),
    (["x1'' + x1 - x2 + x1**3 = 0; x2'' + x2 - x1 = 0"], "a rigid-body linear mode"),
    (["x1'' - x1 + x1**3 = 0; x2'' + x2 = 0"], "an unstable linear mode"),
    (["x1'' + x1 + x2 = 0; x1'' + x1 = 0"],
     "2 equations hold the accelerations of 1 coordinate (x1'')"),
    (["x1'' + x1 + x2' = 0; x3'' + x3 = 0"], "x2 has no equation of its own"),
    (["x1'' + x1 + x1'/10 = 0; x2'' + x2 = 0"], "damping"),
    (["x1'' + x1 + x1**2*x1' = 0; x2'' + 4*x2 = 0"], "not conservative"),
    ([KERSCHEN, "--mode", "3"], "--mode 3: the system has modes 1..2"),
    (["x1'' + x1 + x1**3 = 0; x2'' + 4*x2 + x2**3 = 0", "--mode", "2"],
     "--amplitude x1: this coordinate does not move in mode 2"),
    ([KERSCHEN, "--amplitude", "x3"], "--amplitude x3: not a coordinate"),
    (["x1'' + k*x1 + x1**3 = 0; x2'' + x2 = 0"], "give k a value with --param"),
    (["x1'' + x1 + __import__('os') = 0; x2'' + x2 = 0"], "equation"),
    ([KERSCHEN, "--order", "500"], "--allow-slow"),
])
def test_refusals_one_line_exit_2(args, says):
    out = run("nnm", *args)
    assert out.returncode == 2 and out.stdout == ""
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and says in lines[0], out.stderr


def test_amplitude_on_another_coordinate_is_the_same_orbit():
    """--amplitude x2 parametrises the same family: at the same orbit, both conventions give
    the same period (x2(0) of one is the other's amplitude)."""
    by_x1 = normal_mode(parse_system(KERSCHEN), 1, 12)
    by_x2 = normal_mode(parse_system(KERSCHEN), 1, 12, amplitude=1)
    period1, starts = _evaluate(by_x1, 0.1)
    period2, _ = _evaluate(by_x2, starts[1])
    assert abs(period1 / period2 - 1) <= 1e-9


def test_choose_backbone_picks_the_smallest_order_that_meets_the_tolerance():
    """choose backbone: its order meets 1e-8 at the range's end against this file's own
    shooting (another route), and the order below it does not."""
    out = run("choose", "backbone", KERSCHEN, "--mode", "2", "--tol", "1e-8", "--range",
              "0.05:0.5", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    k = data["order"]
    assert data["quantity"] == "backbone" and data["verified_on"] >= 10
    series = normal_mode(parse_system(KERSCHEN), 2, 12)
    A = 0.5
    _, starts = _evaluate(series, A)
    period_guess = 2 * np.pi / float(sum(float(c) * A ** (2 * j)
                                         for j, c in enumerate(series.omega())))
    _, shot = _shoot(KERSCHEN, A, starts[1:], period_guess / 2)
    tau = [float(c) for c in series.period()]

    def error(order):
        return abs(2 * np.pi * sum(tau[j] * A ** (2 * j) for j in range(order + 1)) / shot - 1)
    assert error(k) <= 1e-8 < error(k - 1)


@pytest.mark.parametrize("args, says", [
    (["--tol", "1e-8", "--range", "0.05:3"], "the series of mode 1 reaches A <"),
    (["--tol", "1e-14", "--range", "0.05:0.5"], "below 1e-11"),
    (["--tol", "1e-8", "--range", "0:0.5"], "0 < A < B"),
])
def test_choose_backbone_refusals(args, says):
    out = run("choose", "backbone", KERSCHEN, *args)
    assert out.returncode == 2 and says in out.stderr, out.stderr
    assert len(out.stderr.strip().splitlines()) == 1


def test_the_derivation_document_s_equations_hold_exactly():
    """Each order the mode's derivation prints: ``(L − n²λ) c_jn = R_jn + δ_n1 Ω_j φ`` for every
    harmonic, the secular condition ``ψ·(R_j1 + Ω_j φ) = 0``, ``ψ`` a left null vector, and
    the turning point ``x₁(0) = A`` (order j ≥ 1 sums to 0), all checked in exact arithmetic
    over Q(√3) on the record the LaTeX is rendered from."""
    from lindstedt.lower.documents import lower_series_derivation

    for text, mode in ((KERSCHEN, 2), (SYMMETRIC, 1),
                       ("x1'' + 3*x1 - x2 + x1**2 = 0; x2'' + x2 - x1/2 = 0", 2)):
        d = lower_series_derivation(normal_mode(parse_system(text), mode, 5), 5)
        L, lam = d.linear.stiffness, d.linear.lam
        phi, psi = sp.Matrix(d.linear.right), sp.Matrix(d.linear.left)
        assert d.weights == d.linear.right  # Ω_j enters along φ
        assert sp.simplify((L - lam * sp.eye(2)) * phi) == sp.zeros(2, 1)
        assert sp.simplify(psi.T * (L - lam * sp.eye(2))) == sp.zeros(1, 2)
        assert len(d.orders) == 5
        for o in d.orders:
            right = [dict(r) for r in o.right]
            solved = [dict(c) for c in o.solution]
            amplitude = 0
            for n in sorted({n for part in (*right, *solved) for n in part}):
                R = sp.Matrix([part.get(n, 0) for part in right])
                c = sp.Matrix([part.get(n, 0) for part in solved])
                lhs = (L - n * n * lam * sp.eye(2)) * c
                rhs = R + (o.value * phi if n == 1 else sp.zeros(2, 1))
                assert sp.simplify(lhs - rhs) == sp.zeros(2, 1), (text, o.j, n)
                if n == 1:
                    assert sp.simplify(psi.dot(rhs)) == 0
                    assert sp.simplify(psi.dot(R) - o.secular) == 0
                amplitude += c[0]
            assert sp.simplify(amplitude) == 0


def test_a_symbolic_nonlinear_parameter_gives_polynomial_coefficients_exactly():
    """``alpha`` left without a value in the symmetric system: mode 1 is Duffing's
    ``x'' + x + αx³ = 0``, so T/2π's order j is the elliptic integral's coefficient times α^j
    (another route); mode 2 at α = 1/2 is Kerschen's own series.  The CLI's JSON names the
    symbol; a symbol in the linear part is refused."""
    alpha = sp.Symbol("alpha")
    text = "x1'' + 2*x1 - x2 + alpha*x1**3 = 0; x2'' + 2*x2 - x1 + alpha*x2**3 = 0"
    mode = normal_mode(parse_system(text, symbolic=True), 1, 8)
    exact = duffing_period(8)
    assert [sp.expand(c) for c in mode.period()] == [
        sp.Rational(c.numerator, c.denominator) * alpha**j for j, c in enumerate(exact)]
    half = normal_mode(parse_system(KERSCHEN.replace("x1**3/2", "alpha*x1**3"),
                                    symbolic=True), 2, 6)
    numeric = normal_mode(parse_system(KERSCHEN), 2, 6)
    assert [sp.simplify(c.subs(alpha, sp.Rational(1, 2)) - d)
            for c, d in zip(half.omega(), numeric.omega(), strict=True)] == [0] * 7
    out = run("nnm", text, "--order", "2", "--json")
    assert out.returncode == 0 and json.loads(out.stdout)["parameters"] == ["alpha"]
    assert json.loads(out.stdout)["period"][1] == "-3*alpha/8"
    bad = run("nnm", "x1'' + k*x1 - x2 + alpha*x1**3 = 0; x2'' + 2*x2 - x1 = 0")
    assert bad.returncode == 2 and "k stands in the linear part" in bad.stderr


def test_number_field_products_equal_sympy_s_field_arithmetic():
    """NFPoly (FLINT parts in Q(θ), reduced by θ's minimal polynomial) against SymPy's own
    field arithmetic (DensePoly over the AlgebraicField), another route: products, sums and
    scalar multiples agree exactly, in a quadratic and a cubic field."""
    from lindstedt.algebra.series import DensePoly, Ground
    from sympy.polys.domains import QQ

    x = sp.Symbol("x")
    for theta in (sp.Rational(321, 200) - sp.sqrt(10441) / 200,
                  sp.CRootOf(x**3 - 3 * x + 1, 1)):
        K = QQ.algebraic_field(theta)
        g = Ground(K)
        t = K.from_sympy(theta)
        a = [K.one * 3, t, t * t / 7 + 1, K.zero, -t]
        b = [t / 5, K.one, t * 2 - 3]
        fast = (g.poly(a) * g.poly(b) + g.poly(b) * t - g.poly(a).left_shift(2) * 4).coeffs()
        slow = (DensePoly(a, K) * DensePoly(b, K) + DensePoly(b, K) * t
                - DensePoly(a, K).left_shift(2) * 4).coeffs()
        assert fast == slow


@pytest.mark.parametrize("stiff", ["1e10", "1e16", "1e30", "10**20"])
def test_a_stiff_coupling_keeps_omega0_an_exact_root(stiff):
    """x1'' + k x1 − x2 + x1³/2 = 0 with k up to 1e30: ω0² stays an exact root of det(L − λ)
    (nsimplify used to round it to a rational: no null vector, StopIteration), equal to
    mpmath's eigenvalue at 120 digits; ω's first correction exact in Q(ω0²)."""
    import mpmath

    text = f"x1'' + {stiff}*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"
    system = parse_system(text)
    lam = sp.Symbol("lam")
    charpoly = system.stiffness.charpoly(lam).as_expr()
    with mpmath.workdps(120):  # k = 1e30 costs 30 of them in the small eigenvalue
        L = mpmath.matrix([[mpmath.mpf(c.p) / c.q for c in row]
                           for row in system.stiffness.tolist()])
        truth = sorted(mpmath.eig(L)[0], key=abs)
    for which in (1, 2):
        mode = normal_mode(system, which, 2)
        assert sp.expand(charpoly.subs(lam, mode.lam)) == 0
        exact = sp.N(mode.lam, 80)
        assert abs(exact - sp.Float(mpmath.nstr(truth[which - 1].real, 80), 80)) <= 1e-40 * exact
        assert len(mode.omega()) == 3 and mode.omega()[1] != 0


def test_stiff_shooting_and_a_linear_system_answer_in_one_line_or_exactly():
    stiff = "x1'' + 1e16*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"
    out = run("choose", "backbone", stiff, "--tol", "1e-6", "--range", "0.01:0.1")
    assert out.returncode == 2 and "stiff" in out.stderr, out.stderr
    assert len(out.stderr.strip().splitlines()) == 1
    linear = normal_mode(parse_system("x1'' + 2*x1 - x2 = 0; x2'' + 2*x2 - x1 = 0"), 2, 6)
    assert linear.omega() == [sp.sqrt(3)] + [0] * 6  # no nonlinear term: ω = ω0 exactly
    out = run("nnm", "x1'' + x1 + x1**3 = 0; x2'' + x2 + x2**3 = 0")
    assert out.returncode == 2 and "1:1 internal resonance" in out.stderr


@pytest.mark.parametrize("text", ["q'' + q + q**3/2 = 0", "q'' + 1.3*q + 0.7*q**2 + q**3 = 0",
                                  "q'' + 2*q + q**2 - 0.25*q**5 = 0"])
def test_one_coordinate_normal_mode_is_the_free_lindstedt_series(text):
    """Free L–P is the normal-mode method at n = 1: the system of one coordinate (the normal
    mode's left-null-vector recursion in Q or Q(ω₀)) and the one-coordinate kernel (its fast
    path, in units of ω₀) give the same ω_j, T_j and q_j, exactly."""
    from lindstedt.derive.models import model_from_text

    K = 8
    mode = normal_mode(parse_system(text), 1, K)
    one = derive(model_from_text(text, K), K)
    g = one.ground.to_sympy
    assert mode.variable in (sp.sstr(one.model.y), f"y = {sp.sstr(one.model.y)}")
    w0 = mode.omega0
    assert [sp.simplify(c - w0 * g(d)) for c, d in zip(mode.omega(), one.omega, strict=True)] \
        == [0] * (K + 1)
    assert [sp.simplify(c - g(d) / w0) for c, d in zip(mode.period(), one.period, strict=True)] \
        == [0] * (K + 1)
    assert [{n: sp.simplify(c - g(one.q[j].get(n, 0))) for n, c in order.items()}
            for j, order in enumerate(mode.coordinate(0))] == \
        [dict.fromkeys(order, 0) for order in mode.coordinate(0)]
    assert all(set(one.q[j]) <= set(order) | {n for n, c in one.q[j].items() if not c}
               for j, order in enumerate(mode.coordinate(0)))


def test_nnm_states_the_reach_of_its_series():
    """``nnm`` prints where its series holds: one coordinate's mode is Duffing's free series in
    y = A², whose radius is exactly 1 (the singularity at the separatrix y = −1, the notes'
    registry): the estimate lies within its spread of 1 and the lower bound below it; the
    table says it in one line, and a symbolic coefficient leaves it unestimated."""
    out = run("nnm", "x1'' + x1 + x1**3 = 0", "--order", "24", "--json")
    r = json.loads(out.stdout)["radius_estimate"]
    assert abs(r["value"] - 1) <= r["spread"] + 1e-3 and r["lower"] <= 1
    assert r["reach"] == pytest.approx(r["lower"] ** 0.5, rel=1e-15)
    table = run("nnm", "x1'' + x1 + x1**3 = 0", "--order", "24").stdout
    assert "is where emitted modules stop" in table
    symbolic = run("nnm", "x1'' + x1 + a*x1**3 = 0", "--order", "8", "--json")
    assert json.loads(symbolic.stdout)["radius_estimate"] is None
