"""``subharmonic EQUATION --n N`` and ``mixing EQUATION`` for any polynomial force, against
DOP853 (SciPy): every orbit found closes after n drive periods, its Floquet multipliers are
the monodromy's by finite differences of the DOP853 flow, the attractors a grid of
simulations reaches are among the stable orbits, and the notes' eq. 10.83 gives the same orbits
by its closed form; the mixing tones against the DOP853 steady state's spectrum."""

from __future__ import annotations

import math

import numpy as np
import pytest
from lindstedt.analysis.mixing import mixing_equation, mixing_series
from lindstedt.analysis.subharmonic import subharmonic, subharmonic_equation, subharmonic_orbits
from scipy.integrate import solve_ivp

QUADRATIC = ("x'' + 0.05*x' + x + x**2 = f*cos(w*t)", {"f": "1/2"}, 2, 1.0)
CUBIC = ("x'' + 0.02*x' + x + x**3/10 = f*cos(w*t)", {"f": "2"}, 3, 1.1)


def _rhs(terms, force, drive):
    def rhs(t, y):
        g = sum(c * y[0] ** a * y[1] ** b for (a, b), c in terms.items())
        return [y[1], force * math.cos(drive * t) - g]
    return rhs


def _flow(problem, y0, periods, rtol=1e-12):
    T = 2 * math.pi / problem.drive
    sol = solve_ivp(_rhs(problem.terms, problem.force, problem.drive), (0, periods * T), y0,
                    method="DOP853", rtol=rtol, atol=1e-13)
    return sol.y[:, -1]


@pytest.fixture(scope="module", params=[QUADRATIC, CUBIC], ids=["1/2 of q^2", "1/3 of q^3"])
def found(request):
    text, values, n, omega = request.param
    problem = subharmonic_equation(text, values, omega, n)
    return problem, subharmonic_orbits(problem)


def test_every_orbit_closes_after_n_drive_periods(found):
    problem, response = found
    assert response.exists
    for o in response.orbits:
        y0 = o.orbit.initial
        end = _flow(problem, y0, problem.n)
        assert np.max(np.abs(end - y0)) < 1e-8, (end, y0)
        for k in range(1, problem.n):  # and not after fewer: a true subharmonic
            assert np.max(np.abs(_flow(problem, y0, k) - y0)) > 1e-3
        # the first harmonic of ω against the DOP853 orbit's Fourier coefficient
        T = problem.n * 2 * math.pi / problem.drive
        t = np.linspace(0, T, 257)[:-1]
        sol = solve_ivp(_rhs(problem.terms, problem.force, problem.drive), (0, T), y0,
                        method="DOP853", rtol=1e-12, atol=1e-13, t_eval=t)
        c = np.fft.rfft(sol.y[0]) / t.size
        assert abs(2 * abs(c[1]) - o.r) < 1e-8


def test_floquet_multipliers_against_the_dop853_monodromy(found):
    problem, response = found
    for o in response.orbits:
        y0, h = o.orbit.initial, 1e-6
        M = np.column_stack([(_flow(problem, y0 + h * e, problem.n)
                              - _flow(problem, y0 - h * e, problem.n)) / (2 * h)
                             for e in np.eye(2)])
        mine = sorted(abs(m) for m in o.orbit.multipliers)
        assert mine == pytest.approx(sorted(abs(m) for m in np.linalg.eigvals(M)), abs=1e-5)
        assert o.stable == bool(max(mine) < 1)


ESCAPED = 100.0
# NOTE: a state past this has gone over the barrier (q'' ~ -q² blows up in finite time): it is
# frozen there, so that the one stacked run below is not held up by it; no bounded orbit here
# comes near (|q|, |q'| < 5).


def _grid_flow(problem, starts: np.ndarray, periods: int) -> np.ndarray:
    """Every start at once: one DOP853 run (rtol 1e-10) of the stacked states, the right side
    vectorised over them, so sixteen runs cost about one; escaped states are frozen."""
    terms, force, drive = problem.terms, problem.force, problem.drive

    def rhs(t, z):
        q, v = z.reshape(2, -1)
        g = sum(c * q**a * v**b for (a, b), c in terms.items())
        moving = (np.abs(q) < ESCAPED) & (np.abs(v) < ESCAPED)
        return np.concatenate([v * moving, (force * math.cos(drive * t) - g) * moving])

    T = 2 * math.pi / drive
    sol = solve_ivp(rhs, (0, periods * T), starts.T.ravel(), method="DOP853", rtol=1e-10,
                    atol=1e-12)
    return sol.y[:, -1].reshape(2, -1).T


def test_the_attractors_of_a_grid_of_simulations_are_among_the_stable_orbits(found):
    """From 16 initial states up to 1.2 times the largest orbit's r, 250·n drive periods of
    DOP853: each run that does not escape
    ends on the primary response or on a drive-period shift of a stable orbit found (within
    1e-3: what is left of the transients)."""
    problem, response = found
    stable = [o for o in response.orbits if o.stable]
    shifts = [_flow(problem, o.orbit.initial, k, rtol=1e-10)
              for o in stable for k in range(problem.n)]
    primary = response.primary.orbit.initial
    span = 1.2 * max(o.r for o in response.orbits)
    grid = np.linspace(-span, span, 4)
    starts = np.array([[q0, v0] for q0 in grid for v0 in grid])
    settled = 0
    for y in _grid_flow(problem, starts, 250 * problem.n):
        if not np.all(np.isfinite(y)) or np.max(np.abs(y)) > 10:
            continue  # escaped over the barrier
        if np.max(np.abs(y - primary)) < 1e-3:
            continue
        settled += 1
        assert min(np.max(np.abs(s - y)) for s in shifts) < 1e-3, y
    assert settled > 0


def test_the_onset_bounds_the_orbits(found):
    """Just above the onset force orbits exist; just below, none of the seeds finds one."""
    problem, response = found
    onset = response.onset
    assert onset.kind in {"fold", "bifurcation"} and 0 < onset.value < problem.force
    for factor, exists in ((1.02, True), (0.98, False)):
        other = subharmonic_orbits(type(problem)(problem.terms, onset.value * factor,
                                                 problem.omega, problem.n, problem.values),
                                   onset=False)
        assert other.exists is exists, factor


def test_the_notes_subharmonic_by_both_routes():
    """Eq. 10.83 at ε 0.1, f 1, ω 1.05: the closed form's two true orbits are the general
    path's two (its a₁ of roots + and −, up to a drive-period shift and sign), with the same
    stability."""
    problem = subharmonic_equation("x'' + x + eps*x**3 = f*cos(3*w*t)",
                                   {"eps": "1/10", "f": "1"}, 1.05)
    assert problem.eps == 0.1
    general = subharmonic_orbits(problem, onset=False).orbits
    _, _, notes = subharmonic(0.1, 1.0, 1.05)
    assert [round(o.r, 9) for o in general] == [round(abs(s.orbit.A[1]), 9) for s in notes]
    assert [o.stable for o in general] == [s.orbit.stable for s in notes]


def test_mixing_of_a_quadratic_and_cubic_force_against_dop853():
    """A quadratic term makes ω₂ − ω₁ and ω₁ + ω₂, which εq³ cannot: each predicted tone within
    its next order of the DOP853 steady state's spectrum (drives at multiples of 0.1: one FFT
    over 2π/0.1 after the transients gives every tone exactly)."""
    text = "x'' + x'/20 + x + x**2/5 + x**3/10 = 3/20*cos(13*t/10) + 3/20*cos(17*t/10)"
    table, drives, _ = mixing_equation(text, {})
    series = mixing_series(table, drives)
    assert series.converged
    terms = table.terms
    rhs = _rhs(terms, 0.0, 1.0)

    def full(t, y):
        return [y[1], rhs(t, y)[1] + sum(f * math.cos(w * t) for f, w in drives)]

    period, settle, samples = 2 * math.pi / 0.1, 1000.0, 4096
    sol = solve_ivp(full, (0, settle + period), [0.0, 0.0], method="DOP853", rtol=1e-11,
                    atol=1e-13, dense_output=True)
    q = sol.sol(settle + np.arange(samples) * period / samples)[0]
    truth = 2 * np.abs(np.fft.rfft(q)) / samples
    labels = set()
    size = sum(t.predicted for t in series.tones if t.order == 0)
    for tone in series.tones:
        k = round(tone.frequency * 10)
        assert abs(tone.frequency * 10 - k) < 1e-9
        # the first omitted order: ~rho^3 of q0 (the series' own claim), and relative 1e-3 on
        # the drives' own tones
        tol = series.expansion_parameter**3 * size
        assert abs(tone.predicted - truth[k]) <= tol, (tone, truth[k], tol)
        if tone.order == 0:
            assert abs(tone.predicted - truth[k]) <= 1e-3 * truth[k]
        labels.add(tone.combination)
    assert (-1, 1) in labels and (1, 1) in labels  # ω₂ − ω₁, ω₁ + ω₂
    mean = np.mean(q)  # the quadratic term's offset, against the series' constant part
    assert abs(series.mean - mean) <= series.expansion_parameter**3 * size
    assert abs(series.mean - mean) <= 0.05 * abs(mean)


def _primary_multipliers(problem, force, y0):
    """The primary response's Floquet multipliers over one drive period by DOP853: Newton on
    its period map from ``y0``, the monodromy by central differences."""
    T = 2 * math.pi / problem.drive
    rhs = _rhs(problem.terms, force, problem.drive)

    def flow(y):
        return solve_ivp(rhs, (0, T), y, method="DOP853", rtol=1e-12, atol=1e-13).y[:, -1]

    def monodromy(y, h=1e-6):
        return np.column_stack([(flow(y + h * e) - flow(y - h * e)) / (2 * h)
                                for e in np.eye(2)])

    y = np.array(y0, dtype=float)
    for _ in range(20):
        step = np.linalg.solve(monodromy(y) - np.eye(2), -(flow(y) - y))
        y = y + step
        if np.max(np.abs(step)) < 1e-11:
            break
    return np.linalg.eigvals(monodromy(y))


def test_a_branch_point_onset_is_the_primary_period_doubling():
    """The 1/2 orbit of q² grows out of the primary response: its onset is where the primary's
    Floquet multiplier (one drive period, by DOP853) passes −1 — inside (−1, 0) 1e-5 below
    it, below −1 1e-5 above; and it says so ("bifurcation")."""
    text, values, n, omega = QUADRATIC
    problem = subharmonic_equation(text, values, omega, n)
    onset = subharmonic_orbits(problem).onset
    assert onset.kind == "bifurcation"
    start = subharmonic_orbits(problem, onset=False).primary.orbit.initial
    below = _primary_multipliers(problem, onset.value * (1 - 1e-5), start)
    above = _primary_multipliers(problem, onset.value * (1 + 1e-5), start)
    assert min(below.real) > -1 > min(above.real)
    assert np.all(np.abs(below.imag) < 1e-9) and np.all(np.abs(above.imag) < 1e-9)


def test_an_odd_force_breaks_its_symmetry_into_a_half_subharmonic():
    """q³ alone does not feed the 1/2 subharmonic at first order (a note says so), yet at a
    strong drive its symmetry breaks: orbits of 2 drive periods with even harmonics, which
    DOP853 closes after two drive periods and not after one."""
    weak = subharmonic_orbits(subharmonic_equation("x'' + 0.1*x' + x + x**3 = f*cos(w*t)",
                                                   {"f": "1/2"}, 1.0, 2), onset=False)
    assert not weak.exists and "no nonlinear term of even degree" in weak.note
    problem = subharmonic_equation("x'' + 0.1*x' + x + x**3 = f*cos(w*t)", {"f": "10"}, 2.0, 2)
    found = subharmonic_orbits(problem, onset=False)
    stable = [o for o in found.orbits if o.stable]
    assert stable and all(abs(o.A.get(0, 0.0)) > 0.1 for o in stable)  # a mean: even terms
    for o in stable:
        y0 = o.orbit.initial
        assert np.max(np.abs(_flow(problem, y0, 2) - y0)) < 1e-8
        assert np.max(np.abs(_flow(problem, y0, 1) - y0)) > 1e-2
