"""The one pseudo-arclength continuation (analysis.continuation.Arclength) following each kind
of parameter — a curve's own λ, the drive frequency ω, the drive amplitude f from rest, f down
to a fold (an onset) — against curves and folds known in closed form: a circle through its two
folds, the one-harmonic Duffing curves (undamped in ω, damped in f) and the folds of the cubic
frequency response."""

from __future__ import annotations

import math

import numpy as np
import pytest
from lindstedt.analysis.continuation import (
    Arclength,
    DriveFamily,
    _continue,
    _oriented,
    continue_in_drive,
    fold_point,
)
from lindstedt.analysis.driven import Drive
from lindstedt.analysis.polynomial import PolynomialBalance
from lindstedt.analysis.response import OneHarmonic
from lindstedt.analysis.systems import continue_balance

EPS, F, Q = 0.1, 0.3, 20.0


class Circle:
    """``x² + λ² = 1``: one unknown, λ the free parameter, folds at λ = ±1."""

    def residual(self, x: np.ndarray, lam: float) -> np.ndarray:
        return np.array([x[0] ** 2 + lam**2 - 1])

    def jacobian(self, x: np.ndarray, lam: float) -> np.ndarray:
        return np.array([[2 * x[0]]])

    def d_omega(self, x: np.ndarray, lam: float) -> np.ndarray:
        return np.array([2 * lam])


def test_a_circle_is_followed_through_both_folds_and_closes_on_its_start():
    start = (-0.5, np.array([math.sqrt(0.75)]), 1.0)
    cont = _continue(Circle(), lambda: ([start], True), -2.0, 2.0, 0.05, 200, 60.0, 1e-3,
                     20000, "circle")
    assert cont.pieces == (0,)  # one closed piece (an isola: the range holds the whole circle)
    assert np.array_equal(cont.x[0], cont.x[-1]) and cont.omega[0] == cont.omega[-1]
    assert np.max(np.abs(cont.x[:, 0] ** 2 + cont.omega**2 - 1)) < 1e-12
    assert cont.folds == pytest.approx([-1.0, 1.0], abs=1e-12)
    # round once: the arclength between points is the step (2π in about 2π/0.05 points)
    steps = np.hypot(np.diff(cont.x[:, 0]), np.diff(cont.omega))
    assert np.sum(steps) == pytest.approx(2 * math.pi, rel=1e-3)
    # each chord a little longer than the step along the tangent (1/cos of half the turn)
    assert np.max(steps) <= 0.05 / math.cos(0.05) and steps[-1] < 0.05


def test_the_step_loop_reports_each_fold_it_passes():
    path = Arclength(Circle(), np.array([math.sqrt(0.75), -0.5]),
                     _oriented(Circle(), np.array([math.sqrt(0.75), -0.5]), 1.0), 0.1, 1e-6,
                     lambda _, h: min(0.1, 1.5 * h))
    folds = []
    while len(folds) < 2:
        assert path.attempt()
        if path.fold:
            folds.append(fold_point(Circle(), *path.previous))
    assert [z[-1] for z in folds] == pytest.approx([1.0, -1.0], abs=1e-12)
    assert [z[0] for z in folds] == pytest.approx([0.0, 0.0], abs=1e-6)


def test_the_undamped_duffing_curve_in_omega_is_the_closed_form():
    """One harmonic, undamped: ``(1 − ω² + ¾εa²)a = f``, ``b = 0``, so ``ω² = 1 + ¾εa² − f/a``;
    its fold where ``dω/da = 0``: ``a³ = −2f/(3ε)``."""
    balance = PolynomialBalance({(1, 0): 1.0, (3, 0): EPS}, F, 1, True)
    w0 = 2.4
    a0 = np.roots([0.75 * EPS, 0.0, 1 - w0**2, -F])
    a0 = a0[(np.abs(a0.imag) < 1e-12) & (a0.real < 0)].real
    a0 = float(max(a0))  # a < 0, the small branch: down in ω to the fold, back up on the large
    x, converged, _ = balance.solve(np.array([a0, 0.0]), w0)
    assert converged and x == pytest.approx([a0, 0.0], abs=1e-12)
    cont = _continue(balance, lambda: ([(w0, x, -1.0)], True), 0.5, 2.5, 0.02, 1000, 60.0,
                     1e-3, 20000, "duffing")
    a, b, w = cont.x[:, 0], cont.x[:, 1], cont.omega
    inside = (w >= 0.5) & (w <= 2.5)
    assert np.max(np.abs(b)) < 1e-12
    assert np.max(np.abs(w[inside] ** 2 - (1 + 0.75 * EPS * a[inside] ** 2 - F / a[inside]))
                  ) < 1e-12
    a_fold = -((2 * F / (3 * EPS)) ** (1 / 3))
    w_fold = math.sqrt(1 + 0.75 * EPS * a_fold**2 - F / a_fold)
    assert cont.folds == pytest.approx([w_fold], abs=1e-12)


def test_the_damped_duffing_curve_in_omega_folds_where_the_cubic_does():
    """eq. 10.60 at one harmonic: every point on ``r²[(1 − ω² + ¾εr²)² + ω²/Q²] = f²`` and the
    folds those of the cubic's discriminant (:attr:`response.OneHarmonic.folds`)."""
    cont = continue_balance(Drive(EPS, F, 0.6, Q).equation, 1, 0.6, 1.9)
    r2 = np.sum(cont.x**2, axis=1)
    w = cont.omega
    G = r2 * ((1 - w**2 + 0.75 * EPS * r2) ** 2 + w**2 / Q**2) - F**2
    assert np.max(np.abs(G)) < 1e-12
    exact = OneHarmonic(Drive(EPS, F, 1.0, Q).terms, F).folds
    assert len(exact) == 2
    assert cont.folds == pytest.approx(exact, abs=1e-10)


def test_the_drive_amplitude_from_rest_is_the_closed_form():
    """At one ω the one-harmonic curve in the drive: ``f = r √((1 − ω² + ¾εr²)² + ω²/Q²)``,
    from rest past the bound asked."""
    balance = PolynomialBalance({(1, 0): 1.0, (3, 0): EPS, (0, 1): 1 / Q}, F, 1, True)
    omega = 1.4
    curve = continue_in_drive(balance, omega, 3.0)
    assert curve.complete
    r2 = np.sum(curve.x**2, axis=1)
    f = np.sqrt(r2) * np.sqrt((1 - omega**2 + 0.75 * EPS * r2) ** 2 + omega**2 / Q**2)
    assert np.max(np.abs(np.abs(curve.force) - f)) < 1e-12
    assert math.sqrt(r2[-1]) > 3.0 and curve.force[0] == 0.0


def test_the_drive_amplitude_down_to_its_fold_is_the_closed_form_onset():
    """f followed down from the resonant branch at ω = 1.4 (an onset's parameter) turns at the
    fold of the cubic ``G(u) = u[(1 − ω² + ¾εu)² + ω²/Q²] − f²`` in ``u = r²``: ``∂G/∂u = 0``."""
    balance = PolynomialBalance({(1, 0): 1.0, (3, 0): EPS, (0, 1): 1 / Q}, F, 1, True)
    omega, force = 1.4, F  # the balance's own drive, where it solves
    fam = DriveFamily(balance, omega)
    a = 1 - omega**2
    g2 = omega**2 / Q**2
    us = np.roots([27 / 16 * EPS**2, 3 * EPS * a, a * a + g2]).real
    f_folds = sorted(math.sqrt(u * ((a + 0.75 * EPS * u) ** 2 + g2)) for u in us)
    # the largest amplitude at this drive, on the resonant branch, by Newton from its r
    u = max(np.roots([9 / 16 * EPS**2, 1.5 * EPS * a, a * a + g2, -force**2]).real)
    x, converged, _ = balance.solve(np.array([math.sqrt(u), 0.0]), omega)
    assert converged
    y = np.append(x, force)
    path = Arclength(fam, y, _oriented(fam, y, -1.0), 0.01, 1e-10,
                     lambda _, h: min(1.5 * h, 0.02))
    for _ in range(2000):
        if path.attempt() and path.fold:
            break
    assert path.fold
    z = fold_point(fam, *path.previous)
    # the resonant branch ends, f falling, at the lower fold (the larger u of the two)
    assert f_folds[0] < force < f_folds[1]
    assert z[-1] == pytest.approx(f_folds[0], abs=1e-12)
    assert np.sum(z[:-1] ** 2) == pytest.approx(max(us), rel=1e-9)
