"""Bifurcations along a response branch and the attractors off it, against DOP853: a period
doubling's ω where the shot orbit's multiplier passes −1; a torus's spectral lines against an
independent simulation's FFT."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

QUADRATIC = "x'' + 0.05*x' + x + x**2 = f*cos(w*t)"
TWO_DOF = ("x1'' + 0.05*x1' + 1.5*x1 - 0.5*x2 + 0.3*x1**2 + x1**3 = f*cos(w*t); "
           "x2'' + 0.05*x2' + 2*x2 - 0.5*x1 + 0.5*x2**3 = 0")


def _field(w: float, f: float):
    def rhs(t, y):
        return [y[1], f * np.cos(w * t) - 0.05 * y[1] - y[0] - y[0] ** 2]
    return rhs


def _shot_multipliers(w: float, f: float, guess: np.ndarray) -> np.ndarray:
    """The period-1 orbit of the quadratic oscillator by Newton on DOP853's flow map (the
    monodromy by central differences), judged by its residual; its multipliers."""
    T = 2 * np.pi / w
    rhs = _field(w, f)

    def flow(y):
        return solve_ivp(rhs, (0, T), y, method="DOP853", rtol=1e-12, atol=1e-13).y[:, -1]

    def monodromy(y):
        h = 1e-6
        return np.column_stack([(flow(y + h * e) - flow(y - h * e)) / (2 * h)
                                for e in np.eye(2)])

    y = np.array(guess, dtype=float)
    for _ in range(20):
        r = flow(y) - y
        y = y - np.linalg.solve(monodromy(y) - np.eye(2), r)
    assert np.max(np.abs(flow(y) - y)) < 1e-9  # the reference judged by its residual
    return np.linalg.eigvals(monodromy(y))


def test_period_doubling_of_the_quadratic_oscillator_is_dop853s_multiplier_minus_one():
    from lindstedt.analysis.response import equation_response

    r = equation_response(QUADRATIC, {"f": "3/10"}, 6, omega_min=1.8, omega_max=2.2)
    found = [b for b in r.dynamics.bifurcations if b.kind == "period_doubling"]
    assert len(found) == 2, r.dynamics.bifurcations
    for b in found:
        assert min(abs(m + 1) for m in b.multipliers) < 1e-8
        x = r.cont.x[b.before]
        guess = r.fine.state(x, r.cont.omega[b.before])
        below = _shot_multipliers(b.omega - 2e-3, 0.3, guess)
        above = _shot_multipliers(b.omega + 2e-3, 0.3, guess)
        neg = [min(m.real for m in lam) for lam in (below, above)]
        assert all(abs(m.imag) < 1e-9 for m in (*below, *above))
        # a real multiplier passes −1 between the two sides of the reported ω
        assert (neg[0] + 1) * (neg[1] + 1) < 0, (b.omega, neg)
    # between them no period-1 orbit is stable: the simulation finds the period-2 orbit
    (gap,) = r.dynamics.unstable_intervals
    assert gap == pytest.approx((found[0].omega, found[1].omega))
    (a,) = r.dynamics.attractors
    assert a.kind == "period-2" and a.lines[0][0][0] == pytest.approx(a.omega / 2, rel=1e-4)


def test_torus_lines_are_dop853s():
    """The attractor of the 2-DOF system at ω = 1.8 from a start off its stable orbits: its
    lines ω, ω ± ν against a DOP853 simulation's FFT (independent of the package's RK4)."""
    from lindstedt.analysis.attractors import classify
    from lindstedt.analysis.systems import driven_system
    from lindstedt.numerics.integrate import PolynomialField, record_system

    system = driven_system(TWO_DOF, {"f": "2/5"})
    field = PolynomialField.of(system.equations())
    drive = np.array([float(d) for d in system.drive])
    w, start = 1.8, np.array([0.0473, 1.8019, -1.4234, 1.7946])
    record = record_system(field, drive, w, start, 300, 256, 32)
    kind, _, nu, lines, ranges, share = classify(record, w, 32, 256, 2)
    assert kind == "quasi-periodic" and share > 0.995
    T = 2 * np.pi / w

    def rhs(t, y):
        x1, x2, v1, v2 = y
        return [v1, v2, 0.4 * np.cos(w * t) - 0.05 * v1 - 1.5 * x1 + 0.5 * x2 - 0.3 * x1**2
                - x1**3, -0.05 * v2 - 2 * x2 + 0.5 * x1 - 0.5 * x2**3]

    t = 300 * T + np.arange(256 * 32) * T / 32
    sol = solve_ivp(rhs, (0, t[-1]), start, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=t)
    spec = np.abs(np.fft.rfft(sol.y[0] * np.hanning(len(t))))
    freq = np.arange(len(spec)) * w / 256
    peaks = [i for i in range(1, len(spec) - 1)
             if spec[i] > spec[i - 1] and spec[i] > spec[i + 1] and spec[i] > 0.05 * spec.max()]
    reference = sorted(freq[i] for i in peaks)
    for f, _ in lines[0][:4]:  # each main line within a bin of DOP853's
        assert min(abs(f - g) for g in reference) < w / 256
    assert nu == pytest.approx(abs(lines[0][1][0] - w), abs=w / 256)
    assert ranges[0][1] == pytest.approx(np.max(sol.y[0]), rel=0.02)
