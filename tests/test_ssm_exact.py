"""The SSM's normal form exactly (derive.ssm_exact) against a hand derivation of the damped
Duffing oscillator's γ₁, the classical backbone coefficients of the undamped one, the
floating-point ground (analysis.ssm) to rounding, and its refusals."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sparse
import sympy as sp
from lindstedt.analysis.ssm import ssm
from lindstedt.derive.ssm_exact import exact_gamma
from lindstedt.derive.system import parse_system, read_model
from lindstedt.errors import InputError
from scipy.io import mmwrite

PAIR = ("x1'' + 1/50*x1' + 2*x1 - x2 + x1**3 = 0; "
        "x2'' + 1/50*x2' + 2*x2 - x1 + 1/2*x2**2 = 0")


def _hand_gamma1(c: sp.Rational, lam: sp.Expr, lambar: sp.Expr) -> sp.Expr:
    """γ₁ of x'' + c x' + x + x³ = 0 with φ = 1, from the invariance equations written out:
    x = W(p), x' = V(p), p₁' = λp₁ + γp₁²p₂, p₂' = λ̄p₂ + γ̄p₁p₂² (γ̄ its own unknown); at
    order 3, DW·R = V and DV·R + cV + W + W³ = 0, and on the resonant monomials the
    normalisation (c + λ)W₂₁ + V₂₁ = 0, (c + λ̄)W₁₂ + V₁₂ = 0."""
    p1, p2, g, gb = sp.symbols("p1 p2 g gb")
    monomials = [(3, 0), (2, 1), (1, 2), (0, 3)]
    w = {m: sp.Symbol(f"w{m[0]}{m[1]}") for m in monomials}
    v = {m: sp.Symbol(f"v{m[0]}{m[1]}") for m in monomials}
    W = p1 + p2 + sum(w[m] * p1 ** m[0] * p2 ** m[1] for m in monomials)
    V = lam * p1 + lambar * p2 + sum(v[m] * p1 ** m[0] * p2 ** m[1] for m in monomials)
    R1, R2 = lam * p1 + g * p1**2 * p2, lambar * p2 + gb * p1 * p2**2

    def flow(F):
        return sp.diff(F, p1) * R1 + sp.diff(F, p2) * R2

    equations = []
    for E in (flow(W) - V, flow(V) + c * V + W + W**3):
        poly = sp.Poly(sp.expand(E), p1, p2)
        equations += [poly.coeff_monomial(p1 ** m[0] * p2 ** m[1]) for m in monomials]
    equations += [(c + lam) * w[2, 1] + v[2, 1], (c + lambar) * w[1, 2] + v[1, 2]]
    solution = sp.solve(equations, [*w.values(), *v.values(), g, gb], dict=True)[0]
    return solution[g]


def _same(a: sp.Expr, b: sp.Expr) -> bool:
    return sp.simplify(sp.radsimp(sp.expand(a - b))) == 0


def test_damped_duffing_gamma1_against_the_hand_derivation():
    """x'' + x'/50 + x + x³ = 0: λ = −1/100 + i√9999/100; γ₁ exactly the hand derivation's,
    and in analysis.ssm's normalisation (ν = 1/4) the classical 3i/(8ω_d), ω_d = Im λ: the
    backbone ω = ω_d + 3ρ²/(8ω_d) with no cubic damping."""
    c = sp.Rational(1, 50)
    r = exact_gamma(parse_system("x'' + 1/50*x' + x + x**3 = 0", driven=True), 1, 3)
    lam = -c / 2 + sp.I * sp.sqrt(1 - c**2 / 4)
    lambar = sp.conjugate(lam)
    F = r.number_field
    assert r.minimal_polynomial == "x**2 + 1/50*x + 1" and r.degree == 2
    assert _same(F.expression(r.elements[0], lam, lambar), lam)
    assert _same(F.expression(F.lambar, lam, lambar), lambar)
    gamma1 = F.expression(r.elements[1], lam, lambar)
    assert _same(gamma1, _hand_gamma1(c, lam, lambar))
    assert _same(F.expression(r.nu, lam, lambar), sp.Rational(1, 4))
    converted = F.expression(F.mul(r.elements[1], r.nu), lam, lambar)
    assert _same(converted, 3 * sp.I / (8 * sp.im(lam)))
    assert r.converted[1][0] == "0"  # an exactly vanishing real part, decided in the field
    assert r.lam[0] == "-0.0100000000000000000000000000000"
    expected = sp.N(3 / (8 * sp.im(lam)), 30)
    assert abs(sp.Float(r.converted[1][1], 30) - expected) < sp.Float("1e-29")
    model = ssm(parse_system("x'' + 1/50*x' + x + x**3 = 0", driven=True), 1, 3)
    assert np.allclose(model.gamma, r.gamma, rtol=1e-14, atol=0)


def test_undamped_duffing_in_the_floating_normalisation():
    """x'' + x + x³ = 0: γ₁ = 3i/8 and γ₂ = −51i/256 in analysis.ssm's normalisation
    (φ = 1/2: ν = 1/4), exactly (λ = i) and against ssm()."""
    system = parse_system("x'' + x + x**3 = 0", driven=True)
    r = exact_gamma(system, 1, 5)
    F = r.number_field
    assert r.minimal_polynomial == "x**2 + 1" and r.conjugate_polynomial == "x + lambda"
    assert r.gamma_exact == ("lambda", "3/2*lambda", "-51/16*lambda") and r.factor == "1/4"
    nu2 = F.mul(r.nu, r.nu)
    assert F.expression(F.mul(r.elements[1], r.nu), sp.I, -sp.I) == sp.Rational(3, 8) * sp.I
    assert F.expression(F.mul(r.elements[2], nu2), sp.I, -sp.I) == sp.Rational(-51, 256) * sp.I
    assert r.converted[1] == ("0", "0.375000000000000000000000000000")
    assert r.converted[2] == ("0", "-0.199218750000000000000000000000")
    gamma = ssm(system, 1, 5).gamma
    assert abs(gamma[1] - 3j / 8) < 1e-15 and abs(gamma[2] + 51j / 256) < 1e-15


@pytest.mark.parametrize(("text", "mode", "order", "degree"), [
    (PAIR, 1, 7, 2),
    (PAIR, 2, 7, 2),
    ("x1'' + 1/50*x1' + 2*x1 - x2 + x1**3 = 0; "  # damping not proportional: Q(λ, λ̄) of
     "x2'' + 1/30*x2' + 2*x2 - x1 + 1/2*x2**2 + x1*x2' = 0", 1, 5, 12),  # degree 4·3
    ("2*x1'' + 1/2*x2'' + 1/40*x1' + 3*x1 - x2 + x1**3 = 0; "  # a full mass matrix
     "1/2*x1'' + x2'' + 2*x2 - x1 + x1*x2' + x2**3 = 0", 2, 5, 12),
    ("x1'' + 1/50*x1' + 2*x1 - x2 + x1**3 = 0; "  # three coordinates, degree 6·5
     "x2'' + 1/30*x2' + 3*x2 - x1 - x3 + 1/2*x2**2 = 0; "
     "x3'' + 1/20*x3' + 2*x3 - x2 + x3**3 = 0", 1, 3, 30),
])
def test_exact_gamma_equals_the_floating_ground(text, mode, order, degree):
    """The exact γ_j converted (γ_j ν^j) are analysis.ssm's to rounding."""
    system = parse_system(text, driven=True)
    r = exact_gamma(system, mode, order)
    assert r.degree == degree
    exact = np.array(r.gamma)
    floating = np.array(ssm(system, mode, order).gamma)
    assert len(exact) == (order - 1) // 2 + 1
    assert np.all(np.abs(exact - floating) <= 1e-12 * np.abs(floating))
    assert complex(float(r.lam[0]), float(r.lam[1])) == pytest.approx(floating[0], rel=1e-15)


def test_refusals(tmp_path):
    """n > 3, a model folder, a symbol left, an exact internal resonance, a repeated
    eigenvalue, a mode that does not exist: one line each."""
    chain = "; ".join(f"x{i}'' + 2*x{i}" + (f" - x{i - 1}" if i > 1 else "")
                      + (f" - x{i + 1}" if i < 4 else "") + (" + x1**3" if i == 1 else "")
                      + " = 0" for i in range(1, 5))
    with pytest.raises(InputError, match="4 coordinates; the exact ground takes at most 3"):
        exact_gamma(parse_system(chain, driven=True), 1, 3)
    mmwrite(tmp_path / "M.mtx", sparse.coo_matrix(np.eye(2)))
    mmwrite(tmp_path / "K.mtx", sparse.coo_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]])))
    (tmp_path / "nonlinear.txt").write_text("0 0 0 0 1\n")
    with pytest.raises(InputError, match="read in floating point has no exact form"):
        exact_gamma(read_model(tmp_path), 1, 3)
    symbolic = parse_system("x'' + x + a*x**3 = 0", driven=True, symbolic=True)
    with pytest.raises(InputError, match="a left symbolic: give it a value with --param"):
        exact_gamma(symbolic, 1, 3)
    resonant = parse_system("x1'' + x1 + x1**2 = 0; x2'' + 4*x2 + x1*x2 = 0", driven=True)
    assert exact_gamma(resonant, 1, 1).gamma_exact == ("lambda",)
    with pytest.raises(InputError, match=r"order 2, monomial p1\^2 p2\^0: .* exact internal"):
        exact_gamma(resonant, 1, 2)
    with pytest.raises(InputError, match="internal resonance"):
        ssm(resonant, 1, 2)  # the floating ground refuses it too
    twins = parse_system("x1'' + x1 + x1**3 = 0; x2'' + x2 + x2**3 = 0", driven=True)
    with pytest.raises(InputError, match="repeated"):
        exact_gamma(twins, 1, 3)
    with pytest.raises(InputError, match="the system has 1 oscillating mode"):
        exact_gamma(parse_system("x'' + x + x**3 = 0", driven=True), 2, 3)
