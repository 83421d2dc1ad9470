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
    from lindstedt.analysis.systems import driven_problem, response

    r = response(driven_problem(QUADRATIC, {"f": "3/10"}), 6, omega_min=1.8, omega_max=2.2)
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


def _two_dof_shot(w: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 2-DOF system's period-1 orbit at ``w`` (f = 2/5) by Newton on DOP853's flow map,
    the monodromy from the variational equation integrated alongside, judged by its residual;
    the orbit's state and its multipliers."""
    T = 2 * np.pi / w

    def rhs(t, z):
        x1, x2, v1, v2 = z[:4]
        A = np.array([[0, 0, 1, 0], [0, 0, 0, 1],
                      [-1.5 - 0.6 * x1 - 3 * x1**2, 0.5, -0.05, 0],
                      [0.5, -2 - 1.5 * x2**2, 0, -0.05]])
        return np.concatenate([[v1, v2, 0.4 * np.cos(w * t) - 0.05 * v1 - 1.5 * x1 + 0.5 * x2
                                - 0.3 * x1**2 - x1**3, -0.05 * v2 - 2 * x2 + 0.5 * x1
                                - 0.5 * x2**3], (A @ z[4:].reshape(4, 4)).ravel()])

    for _ in range(15):
        end = solve_ivp(rhs, (0, T), np.concatenate([y, np.eye(4).ravel()]), method="DOP853",
                        rtol=1e-12, atol=1e-13).y[:, -1]
        r, M = end[:4] - y, end[4:].reshape(4, 4)
        if np.max(np.abs(r)) < 1e-11:
            break
        y = y - np.linalg.solve(M - np.eye(4), r)
    assert np.max(np.abs(r)) <= 1e-9  # the reference judged by its residual
    return y, np.linalg.eigvals(M)


def _pair_excess(mu: np.ndarray) -> float:
    """``|μ| − 1`` of the outer complex pair."""
    return float(np.max(np.abs(mu[np.abs(mu.imag) > 1e-9 * np.abs(mu)]))) - 1


def test_neimark_sacker_point_is_where_dop853s_complex_pair_leaves_the_circle():
    """A short piece of the 2-DOF system's branch through its Neimark–Sacker point near
    ω = 1.7754 (f = 2/5, the balance at 6 harmonics, seeded by its first harmonics): the point
    the locator reports against the shot orbit's multipliers — the pair inside the circle
    2e-3 below, outside 2e-3 above, and |μ| = 1 where Illinois' secant on the shot |μ| − 1
    puts it."""
    from lindstedt.analysis.attractors import bifurcations, orbit_multipliers
    from lindstedt.analysis.continuation import _continue
    from lindstedt.analysis.polynomial import PolynomialBalance
    from lindstedt.analysis.systems import driven_system

    system = driven_system(TWO_DOF, {"f": "2/5"})
    fine = PolynomialBalance(system.equations(), 0.4, 6, False, shape=(1.0, 0.0))
    top = float(np.sqrt(max(float(m) for m in system.modes())))
    seed = np.concatenate([fine.vector({0: -0.043, 1: -0.4728}, {1: 0.6775}),
                           fine.vector({0: -0.0054, 1: 0.4135}, {1: -1.4818})])
    w0, w1 = 1.7694, 1.7814
    x, converged, _ = fine.solve(seed, w0)
    assert converged
    # the branch is steep here (|dx/dω| ≈ 27): a step of 0.05 in arclength is ~2e-3 in ω
    cont = _continue(fine, lambda: ([(w0, x, 1.0)], True), w0, w1, 0.05, 10, 5.0, 1e-3, 100,
                     "test")
    lam = orbit_multipliers(fine, cont.x, cont.omega, top)
    (ns,) = bifurcations(fine, cont, lam, top)
    assert ns.kind == "neimark_sacker" and ns.stable_side == "lower"
    assert abs(ns.residual) < 1e-9
    y = fine.state(cont.x[ns.before], cont.omega[ns.before])
    a, b = ns.omega - 2e-3, ns.omega + 2e-3
    ya, mu_a = _two_dof_shot(a, y)
    _, mu_b = _two_dof_shot(b, ya)
    fa, fb = _pair_excess(mu_a), _pair_excess(mu_b)
    assert fa < 0 < fb, (fa, fb)  # the pair inside below the reported ω, outside above
    side = 0
    for _ in range(30):  # Illinois on the shot |μ| − 1 (sharp: a Krein collision just below)
        s = b - fb * (b - a) / (fb - fa)
        ys, mu = _two_dof_shot(s, ya)
        g = _pair_excess(mu)
        if abs(g) < 1e-10:
            break
        if (g > 0) == (fa > 0):
            a, fa, ya = s, g, ys
            fb, side = (fb / 2 if side == -1 else fb), -1
        else:
            b, fb = s, g
            fa, side = (fa / 2 if side == 1 else fa), 1
    assert abs(g) < 1e-10
    assert ns.omega == pytest.approx(s, abs=1e-5)


def test_the_stretch_after_a_neimark_sacker_point_ends_at_the_fold():
    """The same branch traced on past its fold at ω ≈ 1.9611 and back down: the unstable
    stretch the Neimark–Sacker point begins (the one a simulation samples at its middle) runs
    from the point to the fold, not on down the returning branch."""
    from lindstedt.analysis.attractors import (
        NEUTRAL,
        bifurcations,
        neimark_sacker_stretches,
        orbit_multipliers,
    )
    from lindstedt.analysis.continuation import _continue
    from lindstedt.analysis.polynomial import PolynomialBalance
    from lindstedt.analysis.systems import driven_system

    system = driven_system(TWO_DOF, {"f": "2/5"})
    fine = PolynomialBalance(system.equations(), 0.4, 6, False, shape=(1.0, 0.0))
    top = float(np.sqrt(max(float(m) for m in system.modes())))
    seed = np.concatenate([fine.vector({0: -0.043, 1: -0.4728}, {1: 0.6775}),
                           fine.vector({0: -0.0054, 1: 0.4135}, {1: -1.4818})])
    w0 = 1.7694
    x, converged, _ = fine.solve(seed, w0)
    assert converged
    cont = _continue(fine, lambda: ([(w0, x, 1.0)], True), w0, 1.97, 0.2, 30, 5.0, 1e-2, 100,
                     "test")
    lam = orbit_multipliers(fine, cont.x, cont.omega, top)
    found = bifurcations(fine, cont, lam, top)
    assert [e.kind for e in found] == ["neimark_sacker", "fold"], found
    ns, fold = found
    assert fold.omega == pytest.approx(1.96106, abs=1e-4)
    assert cont.omega[-1] < 1.8  # the returning branch, unstable, back below the middle
    (stretch,) = neimark_sacker_stretches(found, cont, np.all(np.abs(lam) < NEUTRAL, axis=1))
    a, b, _, point = stretch
    assert (a, b) == (ns.omega, fold.omega)
    assert abs(cont.omega[point] - 0.5 * (a + b)) < 0.02


def _record(x: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.vstack([x, v])


def test_a_record_that_outruns_the_step_or_keeps_growing_gets_no_attractor():
    """classify on synthetic records (known answers): a motion at 13 rad per unit time where
    RK4 steps 0.0245 (ωh = 0.32) is "unresolved" — RK4's own damping would pass for a bound;
    an oscillation whose amplitude climbs by 20 % over the record is "growing"; the same one
    steady is period-1 (its spectrum on the drive's harmonics)."""
    from lindstedt.analysis.attractors import RECORD_SAMPLES, classify

    omega, periods = 1.0, 64
    t = np.arange(periods * RECORD_SAMPLES + 1) * 2 * np.pi / omega / RECORD_SAMPLES
    fast = 13.0
    kind, *_ = classify(_record(np.cos(fast * t)[None], -fast * np.sin(fast * t)[None]),
                        omega, RECORD_SAMPLES, periods, 1)
    assert kind == "unresolved"
    grow = 1 + 0.2 * t / t[-1]
    kind, *_ = classify(_record((grow * np.cos(1.5 * t))[None], (-1.5 * grow * np.sin(
        1.5 * t))[None]), omega, RECORD_SAMPLES, periods, 1)
    assert kind == "growing"
    kind, *_ = classify(_record(np.cos(t)[None], -np.sin(t)[None]), omega, RECORD_SAMPLES,
                        periods, 1)
    assert kind == "period-1"
