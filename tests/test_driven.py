"""Driven Duffing: the notes' table, harmonic balance against shooting, Floquet closed forms."""

from __future__ import annotations

import itertools
import json
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
)
from lindstedt.analysis.mu_exact import first_order_secular
from lindstedt.errors import InputError
from lindstedt.numerics.shooting import shoot

NOTES = Drive(eps=0.1, force=1.0, omega=1.0)


def mu_amplitudes(d, order):
    (br,) = [b for b in first_order_branches(d) if b.A1 > 0][:1]
    mu = mu_expansion(d, br, order)
    return [amplitudes(*mu.partial(j), 5)[0] for j in range(order + 1)], mu


def test_notes_table_to_its_printed_digits():
    """Notes §10.4: μ-orders 0, 1, 2 give A₁ ≅ 2.371, 2.357, 2.355; A₃ ≅ 0.0417, 0.0453;
    A₅ ≅ 0.0007; numerically A₁ = 2.356, A₃ = 0.0456, A₅ = 0.0008."""
    A, _ = mu_amplitudes(NOTES, 2)
    assert round(A[0][1], 3) == 2.371
    assert round(A[1][1], 3) == 2.357 and round(A[1][3], 4) == 0.0417
    # the notes print 2.355 for 2.35575 (truncated, not rounded): within one unit of the digit
    assert abs(A[2][1] - 2.355) < 1e-3 and round(A[2][3], 4) == 0.0453
    assert round(A[2][5], 4) == 0.0007
    orbit = shoot(0.1, 1.0, 1.0, 0.0, np.array([2.4, 0.0]))
    assert round(orbit.A[1], 3) == 2.356 and round(orbit.A[3], 4) == 0.0456
    assert round(orbit.A[5], 4) == 0.0008


def test_mu_expansion_error_decreases_with_order():
    A, mu = mu_amplitudes(NOTES, 8)
    orbit = shoot(0.1, 1.0, 1.0, 0.0, np.array([2.4, 0.0]))
    errors = [abs(a[1] - orbit.A[1]) for a in A]
    assert all(e2 < e1 for e1, e2 in itertools.pairwise(errors[:7]))
    assert errors[8] < 1e-9 and mu.converged


@pytest.mark.parametrize("d", [NOTES, Drive(0.1, 0.3, 1.3, Q=20.0), Drive(0.05, 0.5, 0.8, Q=5)])
def test_harmonic_balance_against_shooting(d):
    for br in first_order_branches(d):
        hb = harmonic_balance(d, br, 10)
        A, B = amplitudes(hb.coefficients, 0.0, 19)
        guess = np.array([sum(A.values()), d.omega * sum(n * b for n, b in B.items())])
        orbit = shoot(d.eps, d.force, d.omega, d.damping, guess, harmonics=9)
        assert orbit is not None and hb.converged
        for n in (1, 3, 5, 7, 9):
            assert abs(A[n] - orbit.A[n]) <= 1e-10 and abs(B[n] - orbit.B[n]) <= 1e-10


def test_three_branches_and_their_stability():
    """Inside the hysteresis loop: large and small branches stable, the middle one not."""
    d = Drive(0.1, 0.3, 1.3, Q=20.0)
    branches = first_order_branches(d)
    assert len(branches) == 3
    verdicts = []
    for br in branches:
        hb = harmonic_balance(d, br, 6)
        A, B = amplitudes(hb.coefficients, 0.0, 11)
        orbit = shoot(d.eps, d.force, d.omega, d.damping,
                      np.array([sum(A.values()), d.omega * sum(n * b for n, b in B.items())]))
        verdicts.append(orbit.stable)
    assert verdicts == [True, False, True]


def test_first_order_cubic_and_damped_amplitude_equation_symbolically():
    cos_c, sin_c = first_order_secular()
    A1, w, eps, f, Q, d0 = sp.symbols("A_1 omega epsilon f Q delta_0", real=True)
    # undamped, δ₀ = 0: the notes' cubic (ω² − 1)A₁ − ¾εA₁³ + f = 0
    cubic = (w**2 - 1) * A1 - sp.Rational(3, 4) * eps * A1**3 + f
    assert sp.simplify(cos_c.subs(d0, 0) - cubic) == 0
    assert sp.simplify(sin_c.subs({Q: sp.oo, d0: 0})) == 0
    # damped: eliminate δ₀ — each condition gives f cos δ₀, f sin δ₀; square and add (= f²)
    fcos = sp.expand(f * sp.cos(d0) - cos_c)
    fsin = sp.expand(sin_c + f * sp.sin(d0))
    assert not fcos.has(d0) and not fsin.has(d0)
    r = sp.Symbol("r", positive=True)
    amp = sp.expand((fcos**2 + fsin**2).subs(A1, r))
    expected = sp.expand(r**2 * ((1 - w**2 + sp.Rational(3, 4) * eps * r**2) ** 2 + w**2 / Q**2))
    assert sp.simplify(amp - expected) == 0


def test_floquet_multipliers_of_linear_damped_oscillator():
    """q̈ + q̇/Q + q = f cos ωt: multipliers exp(λ±T), λ± = −1/(2Q) ± i√(1 − 1/(4Q²))."""
    Q, w = 7.0, 1.3
    T = 2 * np.pi / w
    orbit = shoot(0.0, 1.0, w, 1 / Q, np.array([1.0, 0.0]))
    lam = -1 / (2 * Q) + 1j * math.sqrt(1 - 1 / (4 * Q**2))
    expected = np.exp(np.array([lam, np.conj(lam)]) * T)
    got = sorted(orbit.multipliers, key=lambda z: z.imag)
    np.testing.assert_allclose(got, sorted(expected, key=lambda z: z.imag), atol=1e-12)


def test_fold_is_reported_not_summed():
    """At a fold of the undamped cubic the secular system is singular: say so (that reason,
    not any failure), keep the orders found before it, and only there: a little off the fold
    the same branch converges."""
    eps, f = 0.1, 1.0
    # double root of (ω² − 1)A − ¾εA³ + f: (ω² − 1) = (9/4)εA², f = −(3/2)εA³ → A < 0
    A = -((2 * f) / (3 * eps)) ** (1 / 3)
    w = math.sqrt(1 + 2.25 * eps * A**2)
    d = Drive(eps, f, w)
    br = min(first_order_branches(d), key=lambda b: abs(b.A1 - A))
    mu = mu_expansion(d, br, 4)
    assert not mu.converged
    where, reason = mu.reason.split(": ", 1)
    assert reason == "singular secular system (a fold: branches merge)", mu.reason
    # ω rounded to a double splits the double root into two real roots 6e-8 apart, each found
    # to rounding: the determinants are that small, and order 1..3 reports the fold
    j = int(where.removeprefix("order "))
    assert 1 <= j <= 4 and len(mu.coefficients) == j and len(mu.determinants) == j
    # the secular determinant is D = 1 − 1/ω² − 9εA₁²/(4ω²) up to a factor, and D = 0 here
    assert abs(1 - 1 / w**2 - 2.25 * eps * A**2 / w**2) < 1e-15
    assert all(abs(det) < 1e-6 for det in mu.determinants)
    near = Drive(eps, f, w * (1 + 1e-3))
    br = min(first_order_branches(near), key=lambda b: abs(b.A1 - A))
    assert mu_expansion(near, br, 4).converged


@pytest.mark.parametrize("kwargs", [dict(eps=float("nan"), force=1, omega=1),
                                    dict(eps=0.1, force=1, omega=0),
                                    dict(eps=0.1, force=1, omega=1, Q=-1),
                                    dict(eps=0.1, force=float("inf"), omega=1)])
def test_bad_drive(kwargs):
    with pytest.raises(InputError):
        Drive(**kwargs)


def test_driven_contract():
    out = run_forked("driven", "--eps", "0.1", "--force", "0.3", "--omega", "1.3", "--Q", "20",
                     "--order", "3", "--harmonics", "5", "--json", check=False)
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert {"parameters", "branches"} <= data.keys()
    a1 = [b["A1"] for b in data["branches"]]
    assert a1 == sorted(a1, reverse=True) and len(a1) == 3
    for br in data["branches"]:
        assert [e["order"] for e in br["mu_expansion"]] == [0, 1, 2, 3]
        assert "B" in br["mu_expansion"][0] and "1" in br["mu_expansion"][3]["A"]
        assert br["harmonic_balance"]["harmonics"] == 5
        num = br["numerical"]
        assert set(num) >= {"A", "floquet_moduli", "stable"}
        assert abs(num["A"]["1"] - br["harmonic_balance"]["A"]["1"]) < 1e-9
    bad = run_forked("driven", "--eps", "0.1", "--force", "1", "--omega", "1", "--Q", "0",
                     check=False)
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("kwargs,needle", [
    (dict(eps=0.1, force=0.0, omega=1.0), "force 0: no drive"),
    (dict(eps=0.1, force=1.0, omega=1e-300), "omega 1e-300"),
    (dict(eps=1e-308, force=1.0, omega=1.0), "eps 1e-308"),
    (dict(eps=0.1, force=1.0, omega=1.0, Q=1e-308), "Q 1e-308"),
])
def test_drive_domain_says_why(kwargs, needle):
    with pytest.raises(InputError, match=needle):
        Drive(**kwargs)


def test_shooting_resolves_every_harmonic_asked():
    """64 samples per orbit resolve harmonics up to 31; more take more samples (once an
    IndexError for ``driven --order 16``)."""
    low = shoot(0.1, 1.0, 1.0, 0.0, np.array([2.4, 0.0]), harmonics=9)
    high = shoot(0.1, 1.0, 1.0, 0.0, np.array([2.4, 0.0]), harmonics=199)
    assert sorted(high.A) == list(range(1, 200, 2))
    assert all(abs(high.A[n] - low.A[n]) < 1e-12 for n in low.A)
    assert abs(high.A[199]) < 1e-14


@pytest.mark.parametrize("eps,force,omega,Q", [
    (1e-16, 1e-16, 1e-16, math.inf), (10.0, 1e-16, 1e-16, 10.0), (1e16, 1e16, 1e16, 1e-16),
    (-1e16, 1e16, 1.0, 1e16), (1e-16, 1e16, 1e16, math.inf)])
def test_corners_of_the_domain_give_finite_answers_or_say_why(eps, force, omega, Q):
    """Each edge of ``Drive``'s window: the μ-series stays finite (a series whose terms would
    overflow, or a fold, stops early and says so), the balance ends without an error, and
    neither warns."""
    import warnings

    d = Drive(eps, force, omega, Q)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for br in first_order_branches(d):
            mu = mu_expansion(d, br, 12)
            assert all(np.all(np.isfinite(c)) for c in mu.coefficients)
            assert mu.converged or mu.reason.startswith("order ")
            harmonic_balance(d, br, 4)


def test_tiny_linear_response_is_found():
    """Q = 1e-16 puts u = r² ~ 1e-32 beside roots ~1e16 that np.roots cannot tell apart."""
    (br,) = first_order_branches(Drive(-0.1, 1.0, 0.5, 1e-16))
    r_linear = 1.0 / abs(1 - 0.25 + 0.5j * 1e16)
    assert abs(br.A1 / r_linear - 1) < 1e-9


def test_damped_output_shows_r_and_both_phases_parts():
    """Damped, the first harmonic is A₁ cos + B₁ sin: the JSON gives r = √(A₁² + B₁²) at every
    level (the branch's first-order r, each μ order, the balance, the true orbit) and the text
    table shows r, A1 and B1; checked against an independent shooting of the true orbit."""
    args = ["driven", "--eps", "0.1", "--force", "0.3", "--omega", "1.3", "--Q", "20"]
    data = json.loads(run_forked(*args, "--json", check=True).stdout)
    top = data["branches"][0]
    orbit = shoot(0.1, 0.3, 1.3, 0.05, np.array([2.3, 1.3 * 2.2]))
    r_true = math.hypot(orbit.A[1], orbit.B[1])
    assert abs(r_true - 3.150203) < 1e-6
    assert abs(top["numerical"]["r"] - r_true) < 1e-9
    assert abs(top["harmonic_balance"]["r"] - r_true) < 1e-8
    assert abs(top["mu_expansion"][-1]["r"] - r_true) < 1e-4
    assert top["r"] == top["A1"] > 0  # damped: the first-order amplitude r, its phase delta0
    assert abs(top["r"] - r_true) < 0.05
    text = run_forked(*args, check=True).stdout
    header = next(line for line in text.splitlines() if line.split()[:2] == ["r", "A1"])
    assert header.split() == ["r", "A1", "B1", "A3", "A5"]
    shooting = next(line for line in text.splitlines() if "shooting" in line).split()[-5:]
    assert abs(float(shooting[0]) - r_true) < 1e-6
    assert abs(float(shooting[1]) - orbit.A[1]) < 1e-6
    assert abs(float(shooting[2]) - orbit.B[1]) < 1e-6


# --- the one-harmonic solver against 30-digit roots -------------------------------------------

def reference_branches(eps: float, force: float, Q: float, omega: float) -> list[tuple]:
    """``(r, A₁, δ₀)`` of every real branch, largest r first, from mpmath's ``polyroots`` at 30
    digits on the exact values of the doubles: the cubic in ``u = r²`` (``A₁`` from the
    undamped cubic in ``A`` itself), the phase from ``f sin δ₀ = rω/Q``,
    ``f cos δ₀ = ¾εr³ − (ω² − 1)r``."""
    import mpmath

    with mpmath.workdps(30):
        e, f, w = mpmath.mpf(eps), mpmath.mpf(force), mpmath.mpf(omega)
        g = 0 if math.isinf(Q) else 1 / mpmath.mpf(Q)
        a = 1 - w**2
        if eps == 0:
            us = [f**2 / (a**2 + (w * g) ** 2)]
        else:
            us = mpmath.polyroots([9 * e**2 / 16, 3 * e * a / 2, a**2 + (w * g) ** 2, -f**2],
                                  maxsteps=500, extraprec=300)
        us = [mpmath.re(u) for u in us if abs(mpmath.im(u)) <= 1e-25 * abs(u) and
              mpmath.re(u) > 0]
        if math.isinf(Q):
            As = ([f / (1 - w**2)] if eps == 0 else
                  mpmath.polyroots([-3 * e / 4, 0, w**2 - 1, f], maxsteps=500, extraprec=300))
            As = sorted((mpmath.re(A) for A in As if abs(mpmath.im(A)) <= 1e-25 * abs(A)),
                        key=abs, reverse=True)
            assert len(As) == len(us)
            return [(float(abs(A)), float(A), 0.0) for A in As]
        out = []
        for u in sorted(us, reverse=True):
            r = mpmath.sqrt(u)
            delta = mpmath.atan2(r * w * g / f, (3 * e * r**3 / 4 - (w**2 - 1) * r) / f)
            out.append((float(r), float(r), float(delta)))
        return out


def reference_grid() -> list[tuple[float, float, float, np.ndarray]]:
    """Hardening and softening, damped and not, ε down to 1e-12 and 0, the force across three
    decades; ω on a grid through ω = 1 and at 1e-3, 1e-5 and 1e-7 (relative) on both sides of
    every fold."""
    from lindstedt.analysis.driven import Drive
    from lindstedt.analysis.response import OneHarmonic

    base = np.concatenate([np.geomspace(0.2, 5, 41), [1.0, 1 - 1e-9, 1 + 1e-9]])
    grid = []
    for eps, force, Q in itertools.product([0.1, -0.1, 2.0, 1e-12, 0.0], [0.3, -1.0, 30.0],
                                           [math.inf, 20.0, 3.0, 0.05]):
        omega = base
        if eps:
            folds = np.array(OneHarmonic(Drive(eps, force, 1.0, Q).terms, force).folds)
            if len(folds):
                near = np.array([-1e-3, -1e-5, -1e-7, 0.0, 1e-7, 1e-5, 1e-3])
                omega = np.concatenate([omega, (folds[:, None] * (1 + near)).ravel()])
        else:
            omega = omega[np.abs(omega - 1) > 1e-6] if math.isinf(Q) else omega
        grid.append((eps, force, Q, omega))
    return grid


def test_one_harmonic_solver_finds_every_root_to_1e12():
    """Every real branch r (A₁ signed, undamped) and δ₀ of :func:`driven.one_harmonic`, the
    count right, each to 1e-12 relative (δ₀ absolute) of 30-digit roots, over both fold
    windows; and :func:`first_order_branches` the same roots."""
    from lindstedt.analysis.driven import one_harmonic

    checked = folds = 0
    for eps, force, Q, omega in reference_grid():
        A, delta = one_harmonic(eps, force, Q, omega)
        for i, w in enumerate(omega):
            ref = reference_branches(eps, force, Q, float(w))
            got = [(abs(A[i, k]), A[i, k], delta[i, k]) for k in range(3)
                   if np.isfinite(A[i, k])]
            where = f"eps {eps}, f {force}, Q {Q}, omega {w!r}: {got} against {ref}"
            assert len(got) == len(ref), where
            for (r, a1, d0), (r_ref, a1_ref, d0_ref) in zip(got, ref, strict=True):
                assert abs(r - r_ref) <= 1e-12 * r_ref, where
                assert abs(a1 - a1_ref) <= 1e-12 * r_ref, where
                assert abs(d0 - d0_ref) <= 1e-12, where
            branches = first_order_branches(Drive(eps, force, float(w), Q))
            assert sorted(b.A1 for b in branches) == sorted(a for _, a, _ in got), where
            checked += len(ref)
            folds += len(ref) == 3
    assert checked > 2000 and folds > 200  # three branches: inside a fold window
