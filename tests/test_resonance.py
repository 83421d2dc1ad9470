"""Internal resonance: the first-order slow flow of the resonant modes (averaging over one
angle, derive.averaging.slow_flow), exact (against the averages worked by hand, recorded exact
flows and a numerical average over the fast angles), its invariants, its coupled modes, and its
energy-exchange period against DOP853 on the full equations — the swing spring's polynomial
model and the elastic pendulum itself."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import sympy as sp
from commands import run
from lindstedt.derive.averaging import slow_flow
from lindstedt.derive.resonance import coupled_modes
from lindstedt.derive.system import parse_system
from lindstedt.numerics.references import exchange_period, simulated_exchange_period
from scipy.integrate import solve_ivp

SWING = "x'' + x + 3*x*y = 0; y'' + 4*y + 3*x**2/2 = 0"
# NOTE: the elastic pendulum in Cartesian coordinates (unit mass, g = 1, stretched length 1,
# spring k = 4: ω_z = 2ω_x), x'' = −4(1 − l₀/r)x, y'' = 1 − 4(1 − l₀/r)(1 + y) with l₀ = 3/4
# and r = √(x² + (1 + y)²), expanded to second order in (x, y).
CUBIC_1_3 = "x1'' + x1 + (x1 + x2)**3 = 0; x2'' + 9*x2 + (x1 + x2)**3 = 0"


def test_swing_spring_flow_equals_the_averages_worked_by_hand():
    """x = a₁cos θ₁, y = a₂cos θ₂, ⟨sin 2θ₁ cos θ₂⟩ = ½ sin(2φ₁ − φ₂) and the like give
    a₁' = ¾a₁a₂ sin γ, a₂' = −(3/16)a₁² sin γ, φ₁' = ¾a₂ cos γ, φ₂' = (3/16)(a₁²/a₂) cos γ,
    γ = 2φ₁ − φ₂."""
    flow = slow_flow(parse_system(SWING), 1)
    a1, a2 = flow.a
    p1, p2 = flow.phi
    g = 2 * p1 - p2
    R = sp.Rational
    expected = (R(3, 4) * a1 * a2 * sp.sin(g), -R(3, 16) * a1**2 * sp.sin(g),
                R(3, 4) * a2 * sp.cos(g), R(3, 16) * a1**2 / a2 * sp.cos(g))
    assert all(sp.simplify(e - f) == 0 for e, f in
               zip((*flow.amplitude, *flow.phase), expected, strict=True))
    assert flow.resonances == ("1:2 between mode 1 (ω0 = 1) and mode 2 (ω0 = 2)",)


@pytest.mark.parametrize("text", [SWING, CUBIC_1_3])
def test_the_averaged_flow_conserves_the_linear_energy(text):
    """Σ ω_k² a_k² is a first integral of the first-order flow (the system is conservative)."""
    flow = slow_flow(parse_system(text), 1)
    rate = sum(w**2 * a * da for w, a, da in zip(flow.omega, flow.a, flow.amplitude,
                                                 strict=True))
    assert sp.simplify(rate) == 0


def test_coupled_modes_of_the_swing_spring_stay_locked_in_the_full_equations():
    """a₂/a₁ = √2/4 at γ = 0 and π (γ' = ¾a₂·2 − (3/16)a₁²/a₂ = 0 by hand); started there, the
    full equations keep the pendulum's energy within 3 % over ten exchange periods, where a
    start off the ratio exchanges most of it."""
    system = parse_system(SWING)
    modes = coupled_modes(slow_flow(system, 1))
    assert modes == [(0, sp.sqrt(2) / 4), (sp.pi, sp.sqrt(2) / 4)]

    def rhs(t, z):
        x, y, vx, vy = z
        return [vx, vy, -x - 3 * x * y, -4 * y - 1.5 * x * x]

    a1 = 0.05
    for a2 in (a1 * np.sqrt(2) / 4, a1):  # locked, then off the ratio
        sol = solve_ivp(rhs, (0, 3000), [a1, a2, 0, 0], method="DOP853", rtol=1e-10,
                        atol=1e-13, max_step=0.5)
        energy = 0.5 * (sol.y[2] ** 2 + sol.y[0] ** 2)
        spread = (energy.max() - energy.min()) / energy.max()
        assert (spread < 0.03) if a2 < a1 else (spread > 0.5), (a2, spread)


@pytest.mark.parametrize("a2, tol", [(0.1, 0.03), (0.025, 0.015)])
def test_exchange_period_against_dop853(a2, tol):
    """The averaged flow's period against the full polynomial equations; the error shrinks
    with the amplitude (first order)."""
    system = parse_system(SWING)
    flow = slow_flow(system, 1)
    start = (a2 * 0.01, a2)
    predicted = exchange_period(flow, start)
    assert predicted == pytest.approx(169.0127 * 0.1 / a2, rel=1e-4)  # the flow scales as 1/a
    assert abs(predicted / simulated_exchange_period(system, flow, start) - 1) <= tol


def test_exchange_period_of_the_elastic_pendulum_itself():
    """The elastic pendulum (not its expansion) by DOP853, at a small amplitude."""
    system = parse_system(SWING)
    flow = slow_flow(system, 1)
    l0 = 0.75

    def rhs(t, z):
        x, y, vx, vy = z
        r = np.hypot(x, 1 + y)
        pull = 4 * (1 - l0 / r)
        return [vx, vy, -pull * x, 1 - pull * (1 + y)]

    start = (0.00025, 0.025)
    shot = simulated_exchange_period(system, flow, start, rhs=rhs)
    assert abs(exchange_period(flow, start) / shot - 1) <= 0.03


def test_slowflow_system_json_and_refusals():
    out = run("slowflow", SWING, "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["kind"] == "slowflow" and data["modes"] == [1, 2]
    assert data["omega0"] == ["1", "2"] and data["order"] == 1
    assert data["equations"]["a1'"] == "3*a1*a2*sin(2*phi1 - phi2)/4"
    assert data["coupled_modes"][0]["ratio"] == "sqrt(2)/4"
    assert data["exchange"]["period"] == pytest.approx(169.0127, rel=1e-4)
    for args, says in (
        (["x1'' + 2*x1 - x2 + x1**3/2 = 0; x2'' + 2*x2 - x1 = 0"], "no internal resonance"),
        ([SWING, "--order", "2"], "higher orders are not built"),
        ([SWING, "--start", "a3=1"], "--start 'a3=1'"),
        ([SWING, "--start", "a1=-1"], "must be > 0"),
        ([SWING, "--out", "x"], "--out: a system's slow flow is printed"),
        (["van_der_pol", "--start", "a1=1"], "--start: a system's flag"),
    ):
        bad = run("slowflow", *args)
        assert bad.returncode == 2 and bad.stdout == "", (args, bad.stderr)
        assert len(bad.stderr.strip().splitlines()) == 1 and says in bad.stderr, bad.stderr


QUADRATIC_1_2 = "x1'' + x1 + x1*x2 = 0; x2'' + 4*x2 + x1**2 = 0"


def test_exchange_period_at_a_large_amplitude_takes_the_steps_of_a_small_one():
    """From a₁ = a₂ = 1000 two maxima of a₁ come within the 200 steps that suffice at 0.1 (the
    integration is no longer over a span fixed in time, which a large amplitude's fast exchange
    filled with ~amplitude × more steps), and the period is that of SciPy's own events on the
    unscaled flow, integrated over a span fitted to it; the step bound is honoured (NaN)."""
    flow = slow_flow(parse_system(QUADRATIC_1_2), 1)
    rates = sp.lambdify([(*flow.a, *flow.phi)], [*flow.amplitude, *flow.phase], "numpy")

    def peak(t, y):
        return rates(y)[0]
    peak.direction = -1
    for a in (0.1, 1000.0):
        period = exchange_period(flow, (a, a), max_steps=200)
        sol = solve_ivp(lambda t, y: rates(y), (0, 30 / a), [a, a, 0, 0], method="DOP853",
                        rtol=1e-11, atol=1e-14 * a, events=peak)
        times = sol.t_events[0]
        assert period == pytest.approx(times[1] - times[0], rel=1e-8), a
    assert np.isnan(exchange_period(flow, (1000.0, 1000.0), max_steps=5))


@pytest.mark.parametrize("value", ["1000", "1e40"])
def test_slowflow_start_beyond_the_weak_nonlinearity_is_refused(value, capsys):
    """At a₁ = a₂ = a the peaks are x₁ = x₂ = a and the forces x₁x₂ = x₁² = a² against
    ω0₁²·a = a: a times the linear force, so a ≤ 0.1, the bound (by hand); refused in one
    line that says so, before any integration; a = 0.05 runs."""
    from lindstedt.cli import main

    status = main(["slowflow", QUADRATIC_1_2, "--start", f"a1={value}", "--start",
                   f"a2={value}"])
    out = capsys.readouterr()
    assert status == 2 and out.out == "", out
    line, = out.err.strip().splitlines()
    assert f"--start a1={float(value):g}, a2={float(value):g}" in line
    assert f"is {float(value):.3g} times" in line and "weak nonlinearity" in line
    assert "largest is ≤ 0.1" in line and "finite" not in line
    assert main(["slowflow", QUADRATIC_1_2, "--start", "a1=0.05", "--start", "a2=0.05"]) == 0


def test_slowflow_system_cost_does_not_grow_with_the_start():
    """The estimate is bounded (the integration is bounded by steps), whatever --start says."""
    import argparse

    from lindstedt.costs import resonant_flow_cost
    from lindstedt.limits import COST_LIMIT_SECONDS

    costs = {resonant_flow_cost(argparse.Namespace(model=QUADRATIC_1_2, order=None,
                                               start=[f"a1={a}"])).seconds
             for a in ("0.1", "1000", "1e40")}
    assert len(costs) == 1 and 2 < costs.pop() < COST_LIMIT_SECONDS


def test_slowflow_of_a_linear_resonant_system_is_refused_in_one_line():
    """1:3 in ω0 but no nonlinear term: nothing couples the modes (min() of no degree was a
    ValueError)."""
    out = run("slowflow", "x1'' + x1 = 0; x2'' + 9*x2 = 0")
    assert out.returncode == 2 and out.stdout == ""
    assert len(out.stderr.strip().splitlines()) == 1 and "no nonlinear term" in out.stderr


def test_coupled_modes_of_a_decimal_system_with_irrational_frequencies():
    """x1'' + 1.3 x1 + α x1 x2 = 0; x2'' + 5.2 x2 + β x1² = 0 (ω₀ = √1.3, 2√1.3: 1:2): averaging
    by hand gives φ1' = α a2 cos γ/(4ω₁), φ2' = β a1² cos γ/(4ω₂ a2), so a locked γ = 0 or π
    has (a2/a1)² = β ω₁/(2α ω₂) = β/(4α); the coefficients' surds must not stop the roots."""
    flow = slow_flow(parse_system("x1'' + 1.3*x1 + 0.37*x1*x2 = 0; "
                                  "x2'' + 5.2*x2 + 0.21*x1**2 = 0"), 1)
    found = coupled_modes(flow)
    assert sorted(float(g) for g, _ in found) == pytest.approx([0.0, math.pi])
    for _, r in found:
        assert float(r) == pytest.approx(math.sqrt(0.21 / (4 * 0.37)), rel=1e-14)


COUPLED_1_2 = ("x1'' + 2*x1 - 1.5*x2 + 0.45*x1*x2 - 0.15*x2**2 = 0; "
               "x2'' - 1.5*x1 + 4.25*x2 + 0.25*x1**2 + 0.6*x1*x2 = 0")
# NOTE: K = 1.25 v1 v1ᵀ/5 + 5 v2 v2ᵀ/5 with v1 = (2, 1), v2 = (1, −2): ω0² = 5/4 and 5 (1:2),
# the modes mixed in both coordinates, quadratic coupling, decimal coefficients.
COUPLED_1_3 = ("x1'' + 2.5*x1 - 2*x2 + 0.7*x1**3 + 0.2*x1*x2**2 = 0; "
               "x2'' - 2*x1 + 2.5*x2 + 0.35*x1**2*x2 + 1.1*x1**3 = 0")
# NOTE: K = [[2.5, −2], [−2, 2.5]]: ω0² = 1/2 and 9/2 (1:3), shapes (1, 1), (−1, 1), cubic.
DECIMAL_1_2 = "x1'' + 1.3*x1 + 0.37*x1*x2 = 0; x2'' + 5.2*x2 + 0.21*x1**2 = 0"

RECORDED = {
    # da1/dt, da2/dt, dφ1/dt, dφ2/dt: the first-order flows as the Laurent-polynomial average
    # over each mode's own angle (Σ m_k ω_k = 0 kept, exact SymPy) gave them
    SWING: ("3*a1*a2*sin(2*phi1 - phi2)/4", "-3*a1**2*sin(2*phi1 - phi2)/16",
            "3*a2*cos(2*phi1 - phi2)/4", "3*a1**2*cos(2*phi1 - phi2)/(16*a2)"),
    CUBIC_1_3: ("3*a1**2*a2*sin(3*phi1 - phi2)/8", "-a1**3*sin(3*phi1 - phi2)/24",
                "3*a1**2/8 + 3*a1*a2*cos(3*phi1 - phi2)/8 + 3*a2**2/4",
                "a1**3*cos(3*phi1 - phi2)/(24*a2) + a1**2/4 + a2**2/8"),
    QUADRATIC_1_2: ("a1*a2*sin(2*phi1 - phi2)/4", "-a1**2*sin(2*phi1 - phi2)/8",
                    "a2*cos(2*phi1 - phi2)/4", "a1**2*cos(2*phi1 - phi2)/(8*a2)"),
    DECIMAL_1_2: ("37*sqrt(130)*a1*a2*sin(2*phi1 - phi2)/5200",
                  "-21*sqrt(130)*a1**2*sin(2*phi1 - phi2)/10400",
                  "37*sqrt(130)*a2*cos(2*phi1 - phi2)/5200",
                  "21*sqrt(130)*a1**2*cos(2*phi1 - phi2)/(10400*a2)"),
    COUPLED_1_2: ("23*sqrt(5)*a1*a2*sin(2*phi1 - phi2)/1000",
                  "-73*sqrt(5)*a1**2*sin(2*phi1 - phi2)/1000",
                  "23*sqrt(5)*a2*cos(2*phi1 - phi2)/1000",
                  "73*sqrt(5)*a1**2*cos(2*phi1 - phi2)/(1000*a2)"),
    COUPLED_1_3: ("-111*sqrt(2)*a1**2*a2*sin(3*phi1 - phi2)/320",
                  "-11*sqrt(2)*a1**3*sin(3*phi1 - phi2)/960",
                  "sqrt(2)*(141*a1**2 - 111*a1*a2*cos(3*phi1 - phi2) + 194*a2**2)/320",
                  "sqrt(2)*(11*a1**3*cos(3*phi1 - phi2) - 70*a1**2*a2 + 9*a2**3)/(960*a2)"),
}


@pytest.mark.parametrize("text", list(RECORDED))
def test_the_flow_in_one_angle_equals_the_recorded_flows(text):
    """Averaging over the one base angle gives each recorded flow exactly; the JSON prints it
    in the same form."""
    flow = slow_flow(parse_system(text), 1)
    names = {str(s): s for s in (*flow.a, *flow.phi)}
    expected = [sp.sympify(e, locals=names) for e in RECORDED[text]]
    got = (*flow.amplitude, *flow.phase)
    assert all(sp.simplify(e - f) == 0 for e, f in zip(got, expected, strict=True))
    assert [str(e) for e in got] == list(RECORDED[text])


FORCES = {
    # the nonlinear force g(x) of x'' + K x + g(x) = 0, by hand, and K
    SWING: (lambda x, y: (3 * x * y, 1.5 * x * x), [[1, 0], [0, 4]]),
    CUBIC_1_3: (lambda x1, x2: ((x1 + x2) ** 3, (x1 + x2) ** 3), [[1, 0], [0, 9]]),
    DECIMAL_1_2: (lambda x1, x2: (0.37 * x1 * x2, 0.21 * x1 * x1), [[1.3, 0], [0, 5.2]]),
    COUPLED_1_2: (lambda x1, x2: (0.45 * x1 * x2 - 0.15 * x2**2, 0.25 * x1**2 + 0.6 * x1 * x2),
                  [[2, -1.5], [-1.5, 4.25]]),
    COUPLED_1_3: (lambda x1, x2: (0.7 * x1**3 + 0.2 * x1 * x2**2,
                                  0.35 * x1**2 * x2 + 1.1 * x1**3), [[2.5, -2], [-2, 2.5]]),
}


@pytest.mark.parametrize("text", list(FORCES))
def test_the_flow_equals_a_numerical_average_over_the_fast_angles(text):
    """At a random state (a_k, φ_k): ω_k a_k' = −⟨f_k sin θ_k⟩, ω_k a_k φ_k' = −⟨f_k cos θ_k⟩,
    f_k = −ψ_k·g(Σ φ_j a_j cos θ_j), θ_k = ω_k t + φ_k, the mean over the common period
    2π/ω₁ by the trapezoidal rule (exact for these trigonometric polynomials); ω_k and the left
    vectors ψ (rows of the shapes' inverse) from NumPy."""
    force, K = FORCES[text]
    flow = slow_flow(parse_system(text), 1)
    shapes = np.array([[float(v) for v in shape] for shape in flow.shapes]).T
    psi = np.linalg.inv(shapes)
    omega = np.sqrt(np.sort(np.linalg.eigvals(np.array(K, dtype=float)).real))
    assert np.allclose(np.array(K) @ shapes, shapes * omega**2)
    rng = np.random.default_rng(7)
    a, phi = rng.uniform(0.2, 1.0, 2), rng.uniform(-np.pi, np.pi, 2)
    t = np.arange(256) * (2 * np.pi / omega[0]) / 256
    theta = omega[:, None] * t + phi[:, None]
    x = shapes @ (a[:, None] * np.cos(theta))
    f = -psi @ np.array(force(*x))
    da = -np.mean(f * np.sin(theta), axis=1) / omega
    dphi = -np.mean(f * np.cos(theta), axis=1) / (omega * a)
    rates = sp.lambdify([(*flow.a, *flow.phi)], [*flow.amplitude, *flow.phase])
    assert np.allclose(rates([*a, *phi]), [*da, *dphi], rtol=1e-12, atol=1e-14)


def test_slowflow_refuses_a_resonance_it_cannot_average_over_one_angle():
    """ω0² = 2 ± √2 and 4(2 ± √2) (two 1:2 pairs, ω0² irrational); ω0 = 1, 2, √3, 2√3 (two 1:2
    pairs of incommensurate frequencies): each refused in one line, by the CLI too."""
    from lindstedt.errors import InputError

    pairs = ("x1'' + x1 + x1*x3 = 0; x2'' + 3*x2 + x2*x4 = 0; x3'' + 4*x3 + x1**2 = 0; "
             "x4'' + 12*x4 + x2**2 = 0")
    with pytest.raises(InputError, match="incommensurate"):
        slow_flow(parse_system(pairs), 1)
    irrational = ("x1'' + 3*x1 + x2 + x1*x3 = 0; x2'' + x1 + x2 = 0; "
                  "x3'' + 12*x3 + 4*x4 + x1**2 = 0; x4'' + 4*x3 + 4*x4 = 0")
    with pytest.raises(InputError, match="is irrational"):
        slow_flow(parse_system(irrational), 1)
    for text in (pairs, irrational):
        bad = run("slowflow", text)
        assert bad.returncode == 2 and bad.stdout == "", bad.stderr
        assert len(bad.stderr.strip().splitlines()) == 1, bad.stderr


def test_a_one_to_one_resonance_is_named_by_both_commands():
    """Two modes with one ω0 (a 1:1 resonance): nnm and slowflow both refuse in one line and
    say the same thing — the shapes are not unique and its slow flow is not built."""

    text = "x1'' + x1 + x1**3 + x1*x2**2 = 0; x2'' + x2 + x2**3 + x1**2*x2 = 0"
    for command in ("nnm", "slowflow"):
        out = run(command, text)
        assert out.returncode == 2 and out.stderr.count("\n") == 1, out.stderr
        assert "1:1 internal resonance" in out.stderr and "not built" in out.stderr
