"""The damped μ-expansion exact at every order (eq. 10.66–10.72 with q̇/Q): the equation of
motion satisfied exactly order by order, the undamped orders as its Q → ∞ limit, harmonic
balance approached like μ^(K+1), and the emitted A_n, B_n against shooting."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from commands import run_forked
from lindstedt.analysis.driven import (
    Drive,
    amplitudes,
    first_order_branches,
    harmonic_balance,
    mu_expansion,
    one_harmonic_roots,
)
from lindstedt.analysis.mu_exact import (
    A1_,
    Delta_,
    a_,
    damped_determinant,
    eps_,
    gamma_,
    mu_expansion_damped,
    mu_expansion_exact,
    omega_,
    x_,
)
from lindstedt.compiler import generate_driven
from lindstedt.emit.render import load_generated
from lindstedt.lower.driven import DAMPED_TRUNCATION, lower_driven_damped
from lindstedt.numerics.shooting import shoot

K = 4
SAMPLE = {x_: sp.Rational(1, 3), a_: sp.Integer(3), gamma_: sp.Rational(1, 7)}
# NOTE: exact rationals with ω² = 1 + a = 4 (every ω enters as ω^{2j}) and Δ ≠ 0.


def _laurent(parts: tuple[dict, dict], z: sp.Symbol) -> sp.Expr:
    """``Σ c_n cos nτ + s_n sin nτ`` as a Laurent polynomial in ``z = e^{iτ}``."""
    cos, sin = parts
    return sp.Add(*(c * (z**n + z**-n) / 2 for n, c in cos.items()),
                  *(s * (z**n - z**-n) / (2 * sp.I) for n, s in sin.items()))


def test_equation_of_motion_holds_exactly_order_by_order():
    """At exact rationals, Σ μ^j q_j with δ = δ₀ + Σ μ^j δ_j solves eq. 10.68 through μ^K
    (in z = e^{iτ}, with SymPy's series of e^{iη}: not the Trig kernel), and the secular
    (z^{±1}) part of F_{K+1} vanishes: b_K and δ_K are the ones the next order needs."""
    orders = mu_expansion_damped(K)
    Delta = damped_determinant().subs(SAMPLE)
    values = {**SAMPLE, A1_: 1, omega_: 2, Delta_: Delta}
    z, mu = sp.symbols("z mu")
    q = [z / 2 + 1 / (2 * z)] + [sp.expand(_laurent(
        tuple({n: c.subs(values) for n, c in part.items()} for part in o.q), z))
        for o in orders]
    deltas = [sp.Integer(0)] + [o.delta.subs(values) for o in orders]
    for o in orders:  # the convention: q_j has no sin τ term (that is δ_j)
        assert 1 not in o.q[1]
    x, a, gamma, w2 = SAMPLE[x_], SAMPLE[a_], SAMPLE[gamma_], 4
    drive = sp.Rational(3, 4) * x - a + sp.I * gamma  # f e^{iδ₀}/A₁ from order 1
    eta = sum(d * mu**j for j, d in enumerate(deltas))
    phase = sp.expand(sp.series(sp.exp(sp.I * eta), mu, 0, K + 2).removeO())
    Q = sum(c * mu**j for j, c in enumerate(q))

    def lhs(p: sp.Expr) -> sp.Expr:  # q'' + q: z^n -> (1 - n²) z^n
        terms = (t.as_coeff_exponent(z) for t in sp.Add.make_args(sp.expand(p)))
        return sp.Add(*(c * (1 - n**2) * z**n for c, n in terms))

    def derivative(p: sp.Expr) -> sp.Expr:
        return sp.expand(z * sp.diff(p, z) * sp.I)

    rhs = mu * (a / w2 * Q - gamma / w2 * derivative(Q) - x / w2 * sp.expand(Q**3)
                + (drive * phase * z + sp.conjugate(drive) * sp.conjugate(phase) / z) / (2 * w2))
    rhs = sp.expand(rhs.subs(sp.conjugate(mu), mu))
    for j in range(1, K + 1):
        residual = sp.expand(lhs(q[j]) - rhs.coeff(mu, j))
        assert residual == 0, j
    secular = sp.expand(rhs.coeff(mu, K + 1))
    assert secular.coeff(z, 1) == 0 and secular.coeff(z, -1) == 0


def test_undamped_limit_is_the_undamped_expansion():
    """γ = 0 gives :func:`mu_expansion_exact`'s orders (in A₁, ω, ε): no sines, δ_j = 0."""
    undamped = mu_expansion_exact(3)
    damped = mu_expansion_damped(3)
    limit = {gamma_: 0, Delta_: damped_determinant().subs(gamma_, 0)}
    back = {x_: eps_ * A1_**2, a_: omega_**2 - 1}
    for u, d in zip(undamped, damped, strict=True):
        assert sp.cancel(d.delta.subs(limit)) == 0
        assert all(sp.cancel(c.subs(limit)) == 0 for c in d.q[1].values())
        for n in set(u.q) | set(d.q[0]):
            assert sp.cancel(d.q[0].get(n, 0).subs(limit).subs(back) - u.q.get(n, 0)) == 0


def _exact_amplitudes(d: Drive, A1: float, delta0: float, order: int) -> tuple[dict, dict]:
    """A_n, B_n of q₀ + … + q_order from the exact orders, numerically."""
    x, a, gamma = d.eps * A1**2, d.omega**2 - 1, d.omega / d.Q
    values = {x_: x, a_: a, gamma_: gamma, A1_: A1, omega_: d.omega,
              Delta_: float(damped_determinant().subs({x_: x, a_: a, gamma_: gamma}))}
    orders = mu_expansion_damped(max(order, 1))[:order]
    delta = delta0 + sum(float(o.delta.subs(values)) for o in orders)
    A, B, zero = {}, {}, sp.Integer(0)
    for n in (1, 3, 5):
        alpha = (A1 if n == 1 else 0) + sum(float(o.q[0].get(n, zero).subs(values))
                                            for o in orders)
        beta = sum(float(o.q[1].get(n, zero).subs(values)) for o in orders)
        A[n] = alpha * math.cos(n * delta) - beta * math.sin(n * delta)
        B[n] = alpha * math.sin(n * delta) + beta * math.cos(n * delta)
    return A, B


def test_exact_orders_match_the_float_route():
    """The same expansion on the Laurent kernel (float64) at three branches (a sanity check:
    the same method)."""
    d = Drive(0.3, 0.5, 1.3, 5.0)
    branches = first_order_branches(d)
    assert len(branches) == 3
    for br in branches:
        mu = mu_expansion(d, br, 3)
        A, B = amplitudes(*mu.partial(3), 5)
        eA, eB = _exact_amplitudes(d, br.A1, br.delta0, 3)
        for n in (1, 3, 5):
            assert abs(A[n] - eA[n]) < 1e-11 and abs(B[n] - eB[n]) < 1e-11


def test_error_against_balance_shrinks_like_mu_to_the_order_plus_one():
    """Every small term of eq. 10.68 scaled together, ε = s, ω² − 1 = s/2, 1/Q = s/2,
    f = s/2 (the μ-expansion's ordering; at fixed ω ≠ 1 the detuning term is O(1) and no order
    is O(ε^{K+1})): A₁ stays O(1) and the order-K sum's distance to 10-harmonic balance falls
    like s^{K+1}: halving s divides it by about 2^{K+1}."""
    for order in (1, 2, 3, K):
        errors = []
        for s in (0.04, 0.02):
            d = Drive(s, s / 2, math.sqrt(1 + s / 2), 2 / s)
            (br,) = first_order_branches(d)
            hb = harmonic_balance(d, br, 10)
            assert hb.converged
            A, B = amplitudes(hb.coefficients, 0.0, 5)
            eA, eB = _exact_amplitudes(d, br.A1, br.delta0, order)
            errors.append(max(abs(A[1] - eA[1]), abs(B[1] - eB[1]), abs(A[3] - eA[3]),
                              abs(B[3] - eB[3])))
        rate = math.log2(errors[0] / errors[1])
        assert order + 0.7 < rate < order + 1.3, (order, errors, rate)


@pytest.fixture(scope="module")
def module(tmp_path_factory):
    out = tmp_path_factory.mktemp("damped")
    paths = generate_driven(2, out, damped=True)
    assert sorted(p.name for p in paths) == ["driven_damped.py", "driven_damped_derivation.tex"]
    return load_generated(out / "driven_damped.py")


def test_emitted_amplitudes_against_shooting(module):
    """A_n, B_n of the emitted order-2 module on every branch at a damped three-branch point
    against the exact orders (emission) and shooting's Fourier coefficients (accuracy: within
    the size of the next order, which the float route gives)."""
    d = Drive(0.1, 0.3, 1.2, 20.0)
    branches = first_order_branches(d)
    assert len(branches) == 3
    for k, br in enumerate(branches):
        args = (d.omega, d.eps, d.force, d.Q, k)
        emitted = {(c, n): getattr(module, f"{c}_{n}")(*args) for c in "AB" for n in (1, 3, 5)}
        eA, eB = _exact_amplitudes(d, br.A1, br.delta0, 2)
        for n in (1, 3, 5):
            assert abs(emitted["A", n] - eA[n]) < 1e-12 and abs(emitted["B", n] - eB[n]) < 1e-12
        guess = np.array([emitted["A", 1] + emitted["A", 3] + emitted["A", 5],
                          d.omega * (emitted["B", 1] + 3 * emitted["B", 3] + 5 * emitted["B", 5])])
        orbit = shoot(d.eps, d.force, d.omega, d.damping, guess)
        assert orbit is not None
        mu = mu_expansion(d, br, 4)
        nxt = np.abs(mu.coefficients[3]).sum() * 2  # the first term the order-2 sum leaves out
        for n in (1, 3, 5):
            assert abs(emitted["A", n] - orbit.A[n]) < 3 * nxt, (k, n)
            assert abs(emitted["B", n] - orbit.B[n]) < 3 * nxt, (k, n)
        assert 3 * nxt < 0.01 * br.A1  # the test is not vacuous


def test_emitted_branches_follow_the_one_harmonic_roots(module):
    """first_order is √u of driven.one_harmonic_roots, largest first, NaN where a branch does
    not exist, for ε of either sign; Q = inf is accepted (the undamped oscillator)."""
    for eps, force, Q in ((0.3, 0.5, 5.0), (-0.05, 0.2, 30.0), (0.1, 1.0, math.inf)):
        w = np.linspace(0.5, 1.6, 23)
        u = one_harmonic_roots(eps, force, Q, w)
        for k in range(3):
            got = module.first_order(w, eps, force, Q, k)
            want = np.sqrt(u[:, k])
            both = np.isfinite(want)
            assert np.array_equal(np.isfinite(got), both), (eps, k)
            np.testing.assert_allclose(got[both], want[both], rtol=1e-12)


def test_emitted_is_nan_outside_its_domain(module):
    """NaN at ε = 0, Q ≤ 0, a missing branch, beside a fold (the root is double) and where
    the series grows (far from resonance at large drive)."""
    assert math.isnan(module.A_1(1.2, 0.0, 0.3, 10.0, 0))
    assert math.isnan(module.A_1(1.2, 0.1, 0.3, -1.0, 0))
    assert math.isnan(module.B_3(0.8, 0.1, 0.3, 10.0, 2))  # one branch only below resonance
    # the fold of the upper branch at ε = 0.1, f = 0.3, Q = 20: its two roots merge
    w = np.linspace(1.0, 3.0, 4001)
    upper = np.isfinite(one_harmonic_roots(0.1, 0.3, 20.0, w)[:, 1])
    fold = w[np.flatnonzero(upper)[-1]]
    assert math.isnan(module.A_1(fold, 0.1, 0.3, 20.0, 1))
    assert math.isnan(module.A_1(1.0, 2.0, 20.0, 20.0, 0))  # εA₁² ≫ 1: terms grow


def test_emitted_within_its_verified_error_up_to_the_fold(module):
    """Along the upper branches up to their fold (ε = 0.1, f = 0.3, Q = 20, ω ≈ 1.49):
    every finite A_n, B_n is within 2·DAMPED_TRUNCATION·A₁ of shooting (the guard's first
    omitted term tracks the error), and beside the fold, where the branches still exist, the
    evaluators return NaN."""
    eps, force, Q = 0.1, 0.3, 20.0
    dense = np.linspace(1.3, 1.6, 30001)
    fold = dense[np.flatnonzero(np.isfinite(one_harmonic_roots(eps, force, Q, dense)[:, 1]))[-1]]
    w = np.concatenate([np.linspace(1.3, fold - 0.01, 10), np.linspace(fold - 0.008, fold, 10)])
    exists = np.isfinite(one_harmonic_roots(eps, force, Q, w)[:, :2])
    refused = 0
    for i, omega in enumerate(w):
        for k in range(2):
            A = {n: float(getattr(module, f"A_{n}")(omega, eps, force, Q, k)) for n in (1, 3, 5)}
            B = {n: float(getattr(module, f"B_{n}")(omega, eps, force, Q, k)) for n in (1, 3, 5)}
            if not math.isfinite(A[1]):
                refused += exists[i, k]
                continue
            assert all(map(math.isfinite, [*A.values(), *B.values()]))
            orbit = shoot(eps, force, omega, 1 / Q, np.array([sum(A.values()), omega * sum(
                n * b for n, b in B.items())]))
            assert orbit is not None
            A1 = math.hypot(A[1], B[1])
            for n in (1, 3, 5):
                assert abs(A[n] - orbit.A[n]) <= 2 * DAMPED_TRUNCATION * A1, (omega, k, n)
                assert abs(B[n] - orbit.B[n]) <= 2 * DAMPED_TRUNCATION * A1, (omega, k, n)
    assert refused >= 2  # the guard acts beside the fold


def test_emitted_into_twin_agrees_with_the_ufunc(module):
    """``B_3_into`` over an array of ω (other arguments scalars) gives the ufunc's values, NaN
    where it does, and refuses an out it cannot write."""
    w = np.linspace(0.6, 1.8, 301)
    want = module.B_3(w, 0.1, 0.3, 20.0, 0)
    got = module.B_3_into(np.empty(w.size), w, 0.1, 0.3, 20.0, 0)
    assert np.array_equal(np.isnan(got), np.isnan(want)) and np.isfinite(want).sum() > 200
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    with pytest.raises(TypeError):
        module.B_3_into(np.empty(w.size, np.int64), w, 0.1, 0.3, 20.0, 0)


def test_emitted_literals_fit_numba_at_order_four():
    """Every integer literal of the order-4 evaluators fits int64 (numba refuses larger ones):
    the numerators keep their rational coefficients, which print as doubles."""
    module = lower_driven_damped(mu_expansion_damped(5), "test")
    for ev in module.evaluators:
        for e in (ev.output, ev.guard, *(r for _, r in (*ev.prelude, *ev.body))):
            assert all(abs(n) < 2**63 for n in e.atoms(sp.Integer)), ev.name


def test_cli_damped(tmp_path):
    """`generate driven --damped` writes the damped pair; --damped elsewhere is one line, exit 2."""
    ok = run_forked("generate", "driven", "--order", "1", "--damped", "--out", tmp_path)
    assert ok.returncode == 0, ok.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["driven_damped.py",
                                                          "driven_damped_derivation.tex"]
    bad = run_forked("generate", "duffing", "--order", "2", "--damped", "--out", tmp_path)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1
    assert "--damped" in bad.stderr and "Traceback" not in bad.stderr
